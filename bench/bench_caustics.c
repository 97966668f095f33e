/* bench_caustics.c - the caustic layer's radiance estimate by scattering
 * (seed 002's photon volumes, gi_k_caustic_splat) against a kd-tree gather
 * over the same photons (pmfg's reference/pm_kdtree.h, the k-nearest
 * search its caustic map uses: k = 32 within 0.02 x the scene size) at the
 * same G-buffer points, as the paper's Table 3 compares ISPM with Purcell's
 * gather; and the photons' attrition per bounce (the paper's Fig. 10):
 * photons shot, reaching their target, and still travelling after each
 * bounce, twice: as partray renders them (POV-Ray's weights: photons end
 * where a surface has no specular lobe, by adc_bailout or by
 * max_trace_level) and with the paper's Russian roulette at each surface
 * (appendix A, `--photon-roulette`), whose attrition Fig. 10 plots; the
 * flux each way (the roulette's expected flux is the weights').
 *
 * The scene's photons{} as partray renders it (run from the scene's
 * directory). Median of --reps runs of each estimate. Prints figures; not a
 * test.
 *
 *   bench_caustics SCENE.pov [--size WxH] [--threads N] [--reps N] [--device SPEC]
 *                  [--photon-scale F] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench_util.h"
#include "caustics.h"
#include "gi_caustic.h"
#include "pipeline.h"
#include "pm_kdtree.h"
#include "pool.h"
#include "timer.h"

typedef struct {
    const pm_kdtree *t;
    const gi_caus_pixel *gb;
    int n;
    double r2;
    float *out;
} gather_job;

#define GK 32

/* Attrition per bounce of one build of the layer. */
static void print_attrition(const char *what, const gi_caustic_stats *s, double flux)
{
    printf("attrition (paper Fig. 10), %s: of %ld photons at their target, %ld ended at the bounce map (%.1f%%); "
           "stored flux %.6g\n",
           what, s->first_hits, s->absorbed_first, s->first_hits ? 100.0 * s->absorbed_first / s->first_hits : 0.0, flux);
    for (int b = 1; b <= s->max_bounce; b++)
        printf("  going on after bounce %2d: %9ld  (%.1f%% of those at their target; a split counts once)\n", b,
               s->alive[b], s->first_hits ? 100.0 * s->alive[b] / s->first_hits : 0.0);
}

/* Sum of the stored photons' power (all three channels). */
static double stored_flux(const gi_caustic *layer)
{
    long n;
    const gi_caus_photon *p = gi_caustic_photons(layer, &n);
    double f = 0.0;
    for (long i = 0; i < n; i++) f += (double)p[i].phi[0] + p[i].phi[1] + p[i].phi[2];
    return f;
}

static void gather_rows(void *ctx, int chunk, int thread)
{
    (void)thread;
    gather_job *j = ctx;
    const pm_photon *ph = pm_kdtree_photons(j->t);
    pm_neighbour nb[GK];
    for (int i = chunk * 256; i < (chunk + 1) * 256 && i < j->n; i++) {
        const gi_caus_pixel *px = &j->gb[i];
        float *o = &j->out[4 * (size_t)i];
        o[0] = o[1] = o[2] = 0.0f;
        if (!(px->valid > 0.0f)) continue;
        vec3 p = v3(px->s[0], px->s[1], px->s[2]), n = v3(px->n[0], px->n[1], px->n[2]);
        int k = pm_kdtree_knn(j->t, p, n, 0, 0.0, GK, j->r2, nb);
        if (k == 0) continue;
        double r2 = nb[0].d2 > 0.0f ? nb[0].d2 : j->r2;
        double s[3] = {0, 0, 0};
        for (int q = 0; q < k; q++)
            for (int c = 0; c < 3; c++) s[c] += ph[nb[q].idx].power[c];
        for (int c = 0; c < 3; c++) o[c] = (float)(s[c] / (M_PI * r2));
    }
}

int main(int argc, char **argv)
{
    const char *path = NULL, *device = NULL;
    int w = 160, h = 120, threads = 0, reps = 3;
    double scale = 0.0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--size") == 0 && i + 1 < argc) {
            if (sscanf(argv[++i], "%dx%d", &w, &h) != 2) return 2;
        } else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
            threads = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--reps") == 0 && i + 1 < argc) {
            reps = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--device") == 0 && i + 1 < argc) {
            device = argv[++i];
        } else if (strcmp(argv[i], "--photon-scale") == 0 && i + 1 < argc) {
            scale = atof(argv[++i]);
        } else if (!path) {
            path = argv[i];
        } else {
            fprintf(stderr, "usage: bench_caustics SCENE.pov [--size WxH] [--threads N] [--reps N] [--device SPEC] "
                            "[--photon-scale F]\n");
            return 2;
        }
    }
    if (!path || reps < 1) {
        fprintf(stderr, "usage: bench_caustics SCENE.pov [--size WxH] [--threads N] [--reps N]\n");
        return 2;
    }
    if (threads <= 0) threads = pool_default_threads();
    sdl_options so;
    pipeline_sdl_options(&so, NULL, w, h);
    diag *d = diag_new();
    pipeline pl;
    pt_status st = pipeline_open(&pl, path, &so, threads, d);
    if (st != PT_OK) {
        bench_report_diag(d);
        return 1;
    }
    caustics c;
    st = caustics_build(&c, pl.sc, pl.acc, w, h, threads, 1, device, 0, scale, 0, NULL, d);
    if (st != PT_OK || !c.layer) {
        bench_report_diag(d);
        fprintf(stderr, "bench_caustics: %s shoots no photons\n", path);
        return 1;
    }
    gi_caustic_stats s;
    gi_caustic_get_stats(c.layer, &s);
    long n;
    const gi_caus_photon *cp = gi_caustic_photons(c.layer, &n);
    printf("%s %dx%d, %d threads, %s\n", path, w, h, threads, s.device);
    printf("photons: %ld shot (bounce map cells, %d light-target pairs, spacing %.4g), %ld reached their target, "
           "%ld stored, %ld rays\n",
           s.emitted, s.combos, s.spacing, s.first_hits, s.stored, s.rays);
    print_attrition("POV-Ray's weights (partray's default)", &s, stored_flux(c.layer));
    {
        caustics cr;
        if (caustics_build(&cr, pl.sc, pl.acc, w, h, threads, 1, device, 0, scale, 1, NULL, d) != PT_OK || !cr.layer) {
            bench_report_diag(d);
            return 1;
        }
        gi_caustic_stats sr;
        gi_caustic_get_stats(cr.layer, &sr);
        print_attrition("Russian roulette (seed 002 appendix A, --photon-roulette)", &sr, stored_flux(cr.layer));
        caustics_free(&cr);
    }
    if (s.stored_media > 0)
        printf("media photons: %ld stored (sphere radius median %.4g, thinned %ldx at most)\n", s.stored_media,
               s.r_media_median, s.media_thinned);
    printf("stages: trace %.3f s, G-buffer %.3f s\n", s.t_trace, s.t_gbuffer);

    double tb[16], ts[16], tk[16], tg[16];
    if (reps > 16) reps = 16;
    for (int r = 0; r < reps; r++)
        if (gi_caustic_resplat(c.layer, &tb[r], &ts[r], d) != PT_OK) {
            bench_report_diag(d);
            return 1;
        }
    gi_caustic_get_stats(c.layer, &s);
    /* the same photons in pmfg's kd-tree, gathered at the same G-buffer points */
    const gi_caus_pixel *gb = gi_caustic_gbuffer(c.layer);
    float *out = malloc(sizeof(float) * 4 * (size_t)w * h);
    double r2 = 0.02 * accel_scale(pl.acc);
    r2 *= r2;
    for (int r = 0; r < reps; r++) {
        pm_photon *ph = malloc(sizeof *ph * (size_t)(n > 0 ? n : 1));
        if (!ph || !out) return 1;
        for (long i = 0; i < n; i++)
            pm_photon_set(&ph[i], v3(cp[i].x[0], cp[i].x[1], cp[i].x[2]), (rgb){cp[i].phi[0], cp[i].phi[1], cp[i].phi[2]},
                          v3(cp[i].n[0], cp[i].n[1], cp[i].n[2]), 0);
        double t0 = timer_now();
        pm_kdtree *t = pm_kdtree_build(ph, n, threads);
        tk[r] = timer_now() - t0;
        gather_job j = {t, gb, w * h, r2, out};
        t0 = timer_now();
        pool_run(threads, (w * h + 255) / 256, gather_rows, &j);
        tg[r] = timer_now() - t0;
        pm_kdtree_free(t);
    }
    /* the two estimates' means over the lit G-buffer (the gather's is its
     * own k-nearest estimate: a check that both see the same light) */
    const float *img = gi_caustic_image(c.layer);
    double ms = 0.0, mg = 0.0;
    for (int i = 0; i < w * h; i++) {
        ms += img[4 * (size_t)i + 1];
        mg += out[4 * (size_t)i + 1];
    }
    double bin = bench_median(tb, reps), splat = bench_median(ts, reps), kd = bench_median(tk, reps),
           gat = bench_median(tg, reps);
    printf("radiance estimate over the %dx%d G-buffer (median of %d):\n", w, h, reps);
    printf("  scatter (photon volumes): binning %.4f s + splat %.4f s = %.4f s (%ld photon-tile pairs), mean %.5g\n",
           bin, splat, bin + splat, s.tile_entries, ms / (w * h));
    printf("  kd-tree gather (pmfg's, k = %d): build %.4f s + gather %.4f s = %.4f s, mean %.5g\n", GK, kd, gat,
           kd + gat, mg / (w * h));
    printf("  gather / scatter time: %.2fx\n", (kd + gat) / (bin + splat));
    free(out);
    caustics_free(&c);
    pipeline_close(&pl);
    diag_free(d);
    return 0;
}
