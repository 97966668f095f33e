/* bench_reference.c - throughput of the reference renderers on the
 * Cornell box, beside a bare Embree loop on comparable rays:
 *
 *  - photon tracing: photon paths emitted per second, segments (rays) per
 *    second, photons stored per second; kd-tree build time;
 *  - final gathering: gather rays per second in pm_fg_render (each gather
 *    ray also costs its shadow rays and a photon-map lookup), all rays/s;
 *  - path tracing: samples per second, rays per second;
 *  - bare Embree: incoherent rays (origins uniform on all surfaces, cosine
 *    directions: what gather rays look like) through rtcIntersect1 and
 *    through accel_intersect, Mrays/s;
 *  - time to a converged 512x512 reference, extrapolated from the rates
 *    (pmfg: 4096 gather rays per pixel; path: 16384 samples per pixel), or
 *    measured with --converged (long).
 *
 * Median of --reps runs. Prints figures; not a test.
 *
 *   bench_reference [--scene FILE] [--threads N] [--reps N] [--photons N]
 *                   [--size WxH] [--fg-rays N] [--spp N] [--converged] */
#include <embree3/rtcore.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "accel.h"
#include "bench_util.h"
#include "accel_surface.h"
#include "pm.h"
#include "pm_fg.h"
#include "pm_kdtree.h"
#include "pm_nee.h"
#include "pm_path.h"
#include "pm_photon.h"
#include "pool.h"
#include "sdl.h"
#include "shade_material.h"
#include "timer.h"
#include "pipeline.h"

#ifndef BENCH_SCENE_DIR
#define BENCH_SCENE_DIR "scenes"
#endif

/* ------------------------------------------------------------ bare Embree */

typedef struct {
    const accel *a;
    RTCScene rs;
    const vec3 *org, *dir;
    long n;
    long *hits;
    int bare;
} ray_job;

#define RAY_BLOCK 4096

static void ray_block(void *ctx, int bi, int thread)
{
    ray_job *j = ctx;
    long i0 = (long)bi * RAY_BLOCK, i1 = i0 + RAY_BLOCK < j->n ? i0 + RAY_BLOCK : j->n;
    long hits = 0;
    if (j->bare) {
        struct RTCIntersectContext ictx;
        rtcInitIntersectContext(&ictx);
        for (long i = i0; i < i1; i++) {
            struct RTCRayHit rh;
            memset(&rh, 0, sizeof rh);
            rh.ray.org_x = (float)j->org[i].x;
            rh.ray.org_y = (float)j->org[i].y;
            rh.ray.org_z = (float)j->org[i].z;
            rh.ray.dir_x = (float)j->dir[i].x;
            rh.ray.dir_y = (float)j->dir[i].y;
            rh.ray.dir_z = (float)j->dir[i].z;
            rh.ray.tnear = (float)accel_epsilon(j->a, j->org[i], j->dir[i]);
            rh.ray.tfar = 1e30f;
            rh.ray.mask = 0xffffffffu;
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(j->rs, &ictx, &rh);
            hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
        }
    } else {
        for (long i = i0; i < i1; i++) {
            accel_hit h;
            hits += accel_intersect(j->a, j->org[i], j->dir[i], 0.0, INFINITY, &h);
        }
    }
    j->hits[thread] += hits;
}

int main(int argc, char **argv)
{
    const char *scene_path = NULL;
    int threads = 0, reps = 3, w = 32, h = 32, fg_rays = 1024, spp = 64, converged = 0;
    long photons = 500000;
    for (int i = 1; i < argc; i++) {
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(argv[i], "--scene") && v) scene_path = argv[++i];
        else if (!strcmp(argv[i], "--threads") && v) threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--reps") && v) reps = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--photons") && v) photons = atol(argv[++i]);
        else if (!strcmp(argv[i], "--size") && v) sscanf(argv[++i], "%dx%d", &w, &h);
        else if (!strcmp(argv[i], "--fg-rays") && v) fg_rays = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--spp") && v) spp = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--converged")) converged = 1;
        else {
            fprintf(stderr, "usage: bench_reference [--scene FILE] [--threads N] [--reps N] [--photons N] [--size WxH]\n"
                            "                       [--fg-rays N] [--spp N] [--converged]\n");
            return 2;
        }
    }
    if (reps < 1) reps = 1;
    threads = pm_threads(threads);
    const char *fallback = BENCH_SCENE_DIR "/cbox.pov";
    if (!scene_path) {
        FILE *f = fopen("/usr/share/povray-3.7/scenes/radiosity/cornell.pov", "r");
        scene_path = f ? "/usr/share/povray-3.7/scenes/radiosity/cornell.pov" : fallback;
        if (f) fclose(f);
    }
    sdl_options so;
    pipeline_sdl_options(&so, NULL, 320, 240);
    diag *d = diag_new();
    pipeline pl;
    pt_status st = pipeline_open(&pl, scene_path, &so, threads, d);
    if (st != PT_OK) {
        fprintf(stderr, "bench_reference: cannot open %s\n", scene_path);
        bench_report_diag(d);
        return 1;
    }
    scene *sc = pl.sc;
    accel *a = pl.acc;
    pm_lights *L = pm_lights_new(sc, a, d, &st);
    if (!L) return 1;
    printf("bench_reference: %s, %d threads, %d reps (median), %d lights, %d emitter pieces, radiosity %s\n",
           scene_path, threads, reps, sc->nlights, accel_surf_count(pm_lights_emitters(L)),
           sc->global.radiosity.enabled ? "on" : "off");

    /* photons */
    double *t = malloc(sizeof(double) * (size_t)reps), *tb = malloc(sizeof(double) * (size_t)reps);
    pm_photon_result pr;
    memset(&pr, 0, sizeof pr);
    for (int r = 0; r < reps; r++) {
        pm_photon_settings ps = {photons, 0, 256, 1, threads, NULL, NULL};
        double t0 = timer_now();
        if (pm_photons_trace(sc, a, L, &ps, &pr) != PT_OK) return 1;
        t[r] = timer_now() - t0;
        double t1 = timer_now();
        pm_kdtree *kd = pm_kdtree_build(pr.global, pr.nglobal, threads);
        tb[r] = timer_now() - t1;
        pm_kdtree_free(kd);
        free(pr.caustic);
    }
    double tp = bench_median(t, reps), tk = bench_median(tb, reps);
    printf("  photons:   %ld paths, %ld segments, %ld stored (global) in %.3f s: %.3f M paths/s, %.3f M segments/s, "
           "%.3f M stored/s; kd-tree build %.3f s (%.2f M photons/s)\n",
           pr.emitted, pr.rays, pr.nglobal, tp, pr.emitted / tp * 1e-6, pr.rays / tp * 1e-6, pr.nglobal / tp * 1e-6,
           tk, pr.nglobal / tk * 1e-6);

    /* final gathering */
    pm_stats fs;
    double gather_rate = 0.0;
    for (int r = 0; r < reps; r++) {
        pm_fg_settings s;
        pm_fg_default_settings(&s);
        s.c.width = w;
        s.c.height = h;
        s.c.threads = threads;
        s.fg_rays = fg_rays;
        s.photons = photons;
        framebuffer *fb = fb_new(w, h);
        pm_fg_render(sc, a, &s, fb, &fs, d);
        fb_free(fb);
        t[r] = fs.t_render;
        tb[r] = fs.t_irradiance;
    }
    double tg = bench_median(t, reps), ti = bench_median(tb, reps);
    long all = fs.camera_rays + fs.bsdf_rays + fs.gather_rays + fs.shadow_rays;
    gather_rate = fs.gather_rays / tg;
    printf("  gather:    %dx%d, %d rays/pixel: %ld gather rays (+%ld shadow, %ld other) in %.3f s: %.3f M gather rays/s, "
           "%.3f M rays/s all; irradiance precompute %ld points in %.3f s\n",
           w, h, fg_rays, fs.gather_rays, fs.shadow_rays, fs.camera_rays + fs.bsdf_rays, tg, gather_rate * 1e-6,
           all / tg * 1e-6, fs.irradiance_points, ti);

    /* path tracing */
    pm_stats pst;
    for (int r = 0; r < reps; r++) {
        pm_path_settings s;
        pm_path_default_settings(&s);
        s.c.width = w;
        s.c.height = h;
        s.c.threads = threads;
        s.c.spp = spp;
        framebuffer *fb = fb_new(w, h);
        pm_path_render(sc, a, &s, fb, &pst, d);
        fb_free(fb);
        t[r] = pst.t_render;
    }
    double tpath = bench_median(t, reps);
    long prays = pst.camera_rays + pst.bsdf_rays + pst.shadow_rays;
    double sample_rate = pst.samples / tpath;
    printf("  path:      %dx%d, %d spp: %ld samples, %ld rays in %.3f s: %.3f M samples/s, %.3f M rays/s "
           "(%.2f rays/sample)\n",
           w, h, spp, pst.samples, prays, tpath, sample_rate * 1e-6, prays / tpath * 1e-6,
           (double)prays / (double)pst.samples);

    /* bare Embree on gather-like rays */
    long n = fs.gather_rays > 200000 ? fs.gather_rays : 200000;
    accel_surf *all_s = accel_surf_build(sc, a, NULL, NULL, d, &st);
    vec3 *org = malloc(sizeof(vec3) * (size_t)n), *dir = malloc(sizeof(vec3) * (size_t)n);
    long *hits = calloc((size_t)threads, sizeof(long));
    rng rg;
    rng_seed(&rg, 1, 1);
    for (long i = 0; i < n; i++) {
        accel_surf_sample s;
        accel_surf_sample_point(all_s, rng_f64(&rg), rng_f64(&rg), rng_f64(&rg), &rg, &s);
        vec3 nn = rng_f64(&rg) < 0.5 ? s.n : v3_neg(s.n);
        org[i] = v3_madd(s.p, nn, 1e-4 * accel_scale(a));
        dir[i] = v3_cosine_dir(nn, rng_f64(&rg), rng_f64(&rg));
    }
    double tr[2];
    long hc[2];
    for (int bare = 0; bare < 2; bare++) {
        for (int r = 0; r < reps; r++) {
            memset(hits, 0, sizeof(long) * (size_t)threads);
            ray_job j = {a, (RTCScene)accel_rtc_scene(a), org, dir, n, hits, bare};
            double t0 = timer_now();
            pool_run(threads, (int)((n + RAY_BLOCK - 1) / RAY_BLOCK), ray_block, &j);
            t[r] = timer_now() - t0;
        }
        tr[bare] = bench_median(t, reps);
        hc[bare] = 0;
        for (int k = 0; k < threads; k++) hc[bare] += hits[k];
    }
    printf("  rays:      %ld incoherent rays from surfaces: accel_intersect %.3f Mrays/s, bare rtcIntersect1 %.3f "
           "Mrays/s (hits %ld / %ld); gather rays run at %.2f of bare Embree speed\n",
           n, n / tr[0] * 1e-6, n / tr[1] * 1e-6, hc[0], hc[1], gather_rate / (n / tr[1]));

    /* converged 512x512 */
    double px = 512.0 * 512.0;
    printf("  512x512 converged (extrapolated): pmfg 4096 gather rays/pixel %.0f s (+ photons); path 16384 spp %.0f s\n",
           px * 4096 / gather_rate, px * 16384 / sample_rate);
    if (converged) {
        pm_fg_settings s;
        pm_fg_default_settings(&s);
        s.c.width = s.c.height = 512;
        s.c.threads = threads;
        framebuffer *fb = fb_new(512, 512);
        pm_fg_render(sc, a, &s, fb, &fs, d);
        printf("  512x512 pmfg measured: %.1f s total (photons %.1f s, irradiance %.1f s, render %.1f s)\n", fs.t_total,
               fs.t_photons, fs.t_irradiance, fs.t_render);
        fb_free(fb);
    }
    free(org);
    free(dir);
    free(hits);
    free(t);
    free(tb);
    accel_surf_free(all_s);
    pm_lights_free(L);
    pipeline_close(&pl);
    diag_free(d);
    return 0;
}
