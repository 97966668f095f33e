/* bench_gi.c - particle-space GI (gi/gi_particle.h) figures: geometry stage
 * time and memory, lighting stage time, frame time with GI against the
 * same frame without (shade.c Whitted), and optionally a sweep of particle
 * counts and bounce counts. Prints figures; never fails on a number.
 *
 *   bench_gi [SCENE.pov] [--size N] [--count N] [--nb N] [--threads N]
 *            [--device SPEC] [--reps N] [--out PREFIX] [--sweep] [--spp N] [--full]
 *            [--area-samples N] [--ref REF.exr] [--ref-spp N] [--stride N] [--no-keep]
 *
 * --full scatters along all links every bounce (GI_PARTICLE_SCATTER_FULL)
 * instead of the paper's random walks; --area-samples N caps the shadow rays
 * per particle per area light (0: the whole grid). --stride N: the view pre-pass traces every Nth pixel
 * in x and y (prepass_stride; 0 the default). --no-keep: the render traces
 * its own camera rays (keep_hits 0, the coarse pre-pass); by default, at 1
 * spp, the pre-pass traces every pixel and the render takes its hits
 * (keep_hits, gi_particle_primary_hit).
 * --spp N renders N stratified samples per pixel (shade.c fixed
 * supersampling) in both modes, for image comparisons against references.
 * --out PREFIX writes PREFIX_none.exr and PREFIX_particle.exr. --sweep runs
 * counts 50K/100K/200K/400K x n_b 1/3/6/9 and prints lighting and frame
 * times with the image's mean against the first setting's.
 * --ref REF.exr (an image of the same size, e.g. a converged --gi path
 * render) adds the error of every frame against it: mean FLIP (HDR), RMSE
 * and the mean luminance relative to the reference's. A reference of another
 * (square) size than --size gets one more frame of the same particles at its
 * size with --ref-spp N eye samples per pixel (default --spp), compared with
 * it (written as PREFIX_ref_particle.exr with --out). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include "accel.h"
#include "bench_gi_util.h"
#include "bench_util.h"
#include "gi_particle.h"
#include "img_io.h"
#include "img_metrics.h"
#include "sdl.h"
#include "shade.h"
#include "shade_texture.h"
#include "timer.h"
#include "pipeline.h"

#ifndef BENCH_SCENE_DIR
#define BENCH_SCENE_DIR "scenes"
#endif

typedef struct {
    const char *scene;
    int size, threads, nb, reps, sweep, spp, full, area_samples, ref_spp, stride, no_keep;
    long count;
    const char *device, *out, *ref;
} opts;

static framebuffer *g_ref;

/* Error against the reference: mean FLIP, RMSE, mean luminance ratio - 1. */
static int ref_error(const framebuffer *fb, double *flip, double *rmse, double *lum, diag *d);

static int ref_error(const framebuffer *fb, double *flip, double *rmse, double *lum, diag *d)
{
    *flip = *rmse = *lum = NAN;
    if (!g_ref || g_ref->width != fb->width || g_ref->height != fb->height) return 0;
    img_compare_result r;
    if (img_compare(g_ref, fb, 1, &r, NULL, d) != PT_OK) return 0;
    *flip = r.flip_mean;
    *rmse = r.rmse;
    double lr = img_mean_luminance(g_ref, 0);
    *lum = lr > 0.0 ? img_mean_luminance(fb, 0) / lr - 1.0 : NAN;
    return 1;
}

static int g_spp = 1;

static double render(const scene *sc, const accel *a, int size, int threads, gi_particle *gp, framebuffer *fb,
                     shade_stats *ss, diag *d)
{
    shade_settings s;
    shade_default_settings(&s);
    s.width = s.height = size;
    s.threads = threads;
    if (g_spp > 1) {
        s.antialias = 2;
        s.spp = g_spp;
    }
    if (gp) {
        s.use_ambient = 0;
        s.indirect = gi_particle_indirect;
        s.indirect_ctx = gp;
        s.primary_begin = gi_particle_primary_begin; /* kept hits, when keep_hits (else it declines) */
        s.primary = gi_particle_primary_hit;
        s.primary_ctx = gp;
    }
    double t0 = timer_now();
    shade_render(sc, a, &s, fb, ss, d);
    return timer_now() - t0;
}

/* One full GI frame: lighting + view + render. Returns the frame time. */
static double gi_frame(const scene *sc, const accel *a, const opts *o, gi_particle *gp, framebuffer *fb, double *t_light,
                       double *t_view, double *t_render, diag *d)
{
    double t0 = timer_now();
    gi_particle_relight(gp, d);
    double t1 = timer_now();
    gi_particle_prepare_view(gp, &sc->camera, o->size, o->size, d);
    double t2 = timer_now();
    shade_stats ss;
    render(sc, a, o->size, o->threads, gp, fb, &ss, d);
    double t3 = timer_now();
    *t_light = t1 - t0;
    *t_view = t2 - t1;
    *t_render = t3 - t2;
    return t3 - t0;
}

static void sweep(const scene *sc, const accel *a, const opts *o, diag *d)
{
    static const long counts[] = {50000, 100000, 200000, 400000};
    static const int nbs[] = {1, 3, 6, 9};
    framebuffer *fb = fb_new(o->size, o->size);
    double means[4][4], rows[4][4][10];
    memset(means, 0, sizeof means);
    memset(rows, 0, sizeof rows);
    for (int ci = 0; ci < 4; ci++) {
        gi_particle_settings s;
        gi_particle_settings_from_scene(&s, sc);
        s.pigment = shade_tex_pigment_at;
        s.count = counts[ci];
        s.threads = o->threads;
        s.cl_device = o->device;
        if (o->full) s.scatter = GI_PARTICLE_SCATTER_FULL;
        if (o->area_samples >= 0) s.area_samples = o->area_samples;
        gi_particle_stats st;
        pt_status status;
        double c0 = timer_cpu_now();
        gi_particle *gp = gi_particle_build(sc, a, &s, &st, d, &status);
        double cg = timer_cpu_now() - c0;
        if (!gp) {
            bench_report_diag(d);
            continue;
        }
        for (int bi = 0; bi < 4; bi++) {
            gi_particle_set_scattering(gp, nbs[bi], s.scatter);
            /* one frame first, timed apart: the lighting stage after a
             * bounce count that grew rebuilds the walk's path table (and
             * the first bounce's cut link lists) once; the row's times
             * are the frame after it */
            double tl, tv, tr;
            gi_frame(sc, a, o, gp, fb, &rows[ci][bi][9], &tv, &tr, d);
            double tf = gi_frame(sc, a, o, gp, fb, &tl, &tv, &tr, d);
            means[ci][bi] = img_mean_luminance(fb, 0);
            rows[ci][bi][0] = st.t_geometry;
            rows[ci][bi][1] = cg;
            rows[ci][bi][2] = tl;
            rows[ci][bi][3] = tv;
            rows[ci][bi][4] = tr;
            rows[ci][bi][5] = tf;
            ref_error(fb, &rows[ci][bi][6], &rows[ci][bi][7], &rows[ci][bi][8], d);
        }
        gi_particle_free(gp);
    }
    double ref = means[3][3] > 0.0 ? means[3][3] : 1.0;
    printf("\nsweep, %dx%d (mean luminance relative to 400K particles, n_b 9)\n", o->size, o->size);
    if (g_ref) printf("error against %s: mean FLIP, RMSE, mean luminance relative to the reference's\n", o->ref);
    printf("(light 1st ms: the first lighting stage after n_b changed, with a grown walk table's rebuild; the other "
           "times are the frame after it)\n");
    printf("%8s %4s %9s %9s %12s %10s %10s %10s %10s %10s %8s %9s %9s\n", "count", "n_b", "geom s", "geom cpu",
           "light 1st ms", "light ms", "view ms", "render ms", "frame ms", "mean rel", "FLIP", "RMSE", "lum err");
    for (int ci = 0; ci < 4; ci++)
        for (int bi = 0; bi < 4; bi++)
            printf("%8ld %4d %9.2f %9.2f %12.2f %10.2f %10.2f %10.2f %10.2f %10.4f %8.4f %9.5f %+8.2f%%\n", counts[ci],
                   nbs[bi], rows[ci][bi][0], rows[ci][bi][1], 1e3 * rows[ci][bi][9], 1e3 * rows[ci][bi][2],
                   1e3 * rows[ci][bi][3],
                   1e3 * rows[ci][bi][4], 1e3 * rows[ci][bi][5], means[ci][bi] / ref, rows[ci][bi][6],
                   rows[ci][bi][7], 100.0 * rows[ci][bi][8]);
    fb_free(fb);
}

int main(int argc, char **argv)
{
    opts o = {BENCH_SCENE_DIR "/cbox.pov", 512, 0, 8, 3, 0, 1, 0, -1, 0, 0, 0, 50000, NULL, NULL, NULL};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--size") && v) { o.size = atoi(v); i++; }
        else if (!strcmp(a, "--count") && v) { o.count = atol(v); i++; }
        else if (!strcmp(a, "--nb") && v) { o.nb = atoi(v); i++; }
        else if (!strcmp(a, "--threads") && v) { o.threads = atoi(v); i++; }
        else if (!strcmp(a, "--device") && v) { o.device = v; i++; }
        else if (!strcmp(a, "--reps") && v) { o.reps = atoi(v); i++; }
        else if (!strcmp(a, "--out") && v) { o.out = v; i++; }
        else if (!strcmp(a, "--sweep")) o.sweep = 1;
        else if (!strcmp(a, "--ref") && v) { o.ref = v; i++; }
        else if (!strcmp(a, "--ref-spp") && v) { o.ref_spp = atoi(v); i++; }
        else if (!strcmp(a, "--spp") && v) { o.spp = atoi(v); i++; }
        else if (!strcmp(a, "--full")) o.full = 1;
        else if (!strcmp(a, "--no-keep")) o.no_keep = 1;
        else if (!strcmp(a, "--stride") && v) { o.stride = atoi(v); i++; }
        else if (!strcmp(a, "--area-samples") && v) { o.area_samples = atoi(v); i++; }
        else if (a[0] != '-') o.scene = a;
        else { fprintf(stderr, "bench_gi: unknown option %s\n", a); return 2; }
    }
    if (o.reps < 1) o.reps = 1;
    g_spp = o.spp;
    diag *d = diag_new();
    if (o.ref && img_read(o.ref, 0, &g_ref, d) != PT_OK) {
        bench_report_diag(d);
        return 1;
    }
    sdl_options so;
    pipeline_sdl_options(&so, NULL, o.size, o.size);
    pipeline pl;
    if (pipeline_open(&pl, o.scene, &so, o.threads, d) != PT_OK) {
        bench_report_diag(d);
        return 1;
    }
    scene *sc = pl.sc;
    accel *a = pl.acc;
    double t_parse = pl.t_parse, t_accel = pl.t_accel;
    pt_status st = PT_OK;
    scene_counts cnt = scene_count(sc);
    printf("scene %s: %ld objects, %ld triangles, %ld lights; parse %.3f s, accel %.3f s; %dx%d\n", o.scene, cnt.objects,
           cnt.triangles, cnt.lights, t_parse, t_accel, o.size, o.size);

    gi_particle_settings s;
    gi_particle_settings_from_scene(&s, sc);
    s.pigment = shade_tex_pigment_at;
    s.count = o.count;
    s.bounces = o.nb;
    s.threads = o.threads;
    s.cl_device = o.device;
    if (o.full) s.scatter = GI_PARTICLE_SCATTER_FULL;
    if (o.area_samples >= 0) s.area_samples = o.area_samples;
    s.prepass_stride = o.stride;
    s.keep_hits = !o.no_keep && o.spp <= 1;
    gi_particle_stats gs;
    double c0 = timer_cpu_now();
    gi_particle *gp = gi_particle_build(sc, a, &s, &gs, d, &st);
    double cpu_geom = timer_cpu_now() - c0;
    if (!gp) {
        bench_report_diag(d);
        fprintf(stderr, "bench_gi: GI build failed: %s\n", pt_status_name(st));
        return 1;
    }
    printf("device: %s (kernel build %.3f s)\n", gs.device, gs.t_kernel_build);
    printf("geometry stage %.3f s: surfaces %.3f, sampling %.3f, pruning %.3f, 4x4 links %.3f, 16x16 links %.3f, "
           "lists %.3f, upload %.3f\n",
           gs.t_geometry, gs.t_surfaces, gs.t_sampling, gs.t_prune, gs.t_scatter_links, gs.t_gather_links, gs.t_lists,
           gs.t_upload);
    printf("  CPU time %.3f s (all threads; kernel build included): stage %.3f = pruning %.3f, 4x4 links %.3f, 16x16 "
           "links %.3f, lists %.3f, rest %.3f\n",
           cpu_geom, gs.c_geometry, gs.c_prune, gs.c_scatter_links, gs.c_gather_links, gs.c_lists,
           gs.c_geometry - gs.c_prune - gs.c_scatter_links - gs.c_gather_links - gs.c_lists);
    printf("  particles %ld (candidates %ld, pruned %ld), spacing %.4f, tess %.4f, radius %.4f\n", gs.particles,
           gs.candidates, gs.pruned, gs.spacing, gs.tess, gs.radius);
    printf("  link rays %ld (%.1f%% miss, %.2f%% unresolved), radiance particles %ld (%ld before "
           "sharing), list entries %ld (%.1f per list; %ld widened, %ld empty)\n",
           gs.link_rays, 100.0 * gs.link_misses / fmax(1, gs.link_rays), 100.0 * gs.link_unresolved / fmax(1, gs.link_rays),
           gs.radiance_particles, gs.radiance_slots, gs.list_entries, (double)gs.list_entries / fmax(1, gs.radiance_particles),
           gs.lists_widened, gs.lists_empty);
    printf("  link hits by the hit triangle's list %ld (%.1f%% of the rays), left to the grid %ld; %ld lists, %ld "
           "entries, %.1f MiB\n",
           gs.link_tri, 100.0 * gs.link_tri / fmax(1, gs.link_rays), gs.link_tri_fallback, gs.trilook_lists,
           gs.trilook_entries, gs.bytes_trilook / 1048576.0);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("  memory %.1f MiB: particles %.1f, links %.1f, lists %.1f, surfaces %.1f, device %.1f; peak RSS %.1f MiB "
           "after the geometry stage\n",
           gs.bytes_total / 1048576.0, gs.bytes_particles / 1048576.0, gs.bytes_links / 1048576.0,
           gs.bytes_lists / 1048576.0, gs.bytes_surfaces / 1048576.0, gs.bytes_device / 1048576.0,
           ru.ru_maxrss / 1024.0);

    /* lighting stage: median of reps (relighting reruns only this stage) */
    double *tl = calloc((size_t)o.reps, sizeof *tl), *tk = calloc((size_t)o.reps, sizeof *tk);
    double *tvis = calloc((size_t)o.reps, sizeof *tvis);
    double *tcpu = calloc((size_t)o.reps, sizeof *tcpu);
    long colour_rays = 0;
    for (int r = 0; r < o.reps; r++) {
        double cc = timer_cpu_now();
        gi_particle_relight(gp, d);
        tcpu[r] = timer_cpu_now() - cc;
        colour_rays = gi_particle_get_stats(gp)->shadow_rays;
        const gi_particle_stats *x = gi_particle_get_stats(gp);
        tl[r] = x->t_lighting;
        tk[r] = x->t_emit + x->t_scatter;
        tvis[r] = x->t_visibility;
    }
    /* the same after moving the lights a little: visibility traced again */
    double *tm = calloc((size_t)o.reps, sizeof *tm), *tmc = calloc((size_t)o.reps, sizeof *tmc);
    long moved_rays = bench_time_moves(gp, sc, sc->nlights, o.reps, tm, tmc, d);
    printf("lighting stage after a light moved (all lights moved; median of %d): %.2f ms wall, %.2f ms CPU, %ld "
           "shadow rays\n",
           o.reps, 1e3 * bench_median(tm, o.reps), 1e3 * bench_median(tmc, o.reps), moved_rays);
    /* the same moving the first light only: the others keep their visibility */
    if (sc->nlights > 1) {
        moved_rays = bench_time_moves(gp, sc, 1, o.reps, tm, tmc, d);
        printf("  the first of the %d lights moved alone: %.2f ms wall, %.2f ms CPU, %ld shadow rays\n", sc->nlights,
               1e3 * bench_median(tm, o.reps), 1e3 * bench_median(tmc, o.reps), moved_rays);
    }
    free(tm);
    free(tmc);
    const gi_particle_stats *x = gi_particle_get_stats(gp);
    printf("lighting stage, colour change only (n_b %d, %s scattering, median of %d): %.2f ms = visibility %.2f ms "
           "(%ld shadow rays) + emission and scattering kernels %.2f ms; %ld sources\n",
           x->bounces, s.scatter == GI_PARTICLE_SCATTER_FULL ? "full" : "walk", o.reps, 1e3 * bench_median(tl, o.reps),
           1e3 * bench_median(tvis, o.reps), colour_rays, 1e3 * bench_median(tk, o.reps), x->sources);
    printf("  CPU time per lighting stage %.2f ms (all threads, median)\n", 1e3 * bench_median(tcpu, o.reps));
    printf("  flux: direct %.4g, emitted %.4g, scattered %.4g\n", x->flux_direct, x->flux_emitted, x->flux_scattered);

    framebuffer *fb_none = fb_new(o.size, o.size), *fb_gi = fb_new(o.size, o.size);
    double *tn = calloc((size_t)o.reps, sizeof *tn), *tf = calloc((size_t)o.reps, sizeof *tf);
    double *tfl = calloc((size_t)o.reps, sizeof *tfl), *tfv = calloc((size_t)o.reps, sizeof *tfv);
    double *tfr = calloc((size_t)o.reps, sizeof *tfr);
    double *cn = calloc((size_t)o.reps, sizeof *cn), *cf = calloc((size_t)o.reps, sizeof *cf);
    /* per particle frame: pre-pass CPU, gather wall, cells tested, page
     * faults (minor) of the frame; none frame's page faults */
    double *fpc = calloc((size_t)o.reps, sizeof *fpc), *fga = calloc((size_t)o.reps, sizeof *fga);
    double *fcl = calloc((size_t)o.reps, sizeof *fcl), *fpf = calloc((size_t)o.reps, sizeof *fpf);
    double *npf = calloc((size_t)o.reps, sizeof *npf);
    shade_stats ss;
    for (int r = 0; r < o.reps; r++) {
        long f0 = bench_minflt_now();
        double c = timer_cpu_now();
        tn[r] = render(sc, a, o.size, o.threads, NULL, fb_none, &ss, d);
        cn[r] = timer_cpu_now() - c;
        npf[r] = (double)(bench_minflt_now() - f0);
        long cells0 = gi_particle_get_stats(gp)->cells;
        f0 = bench_minflt_now();
        c = timer_cpu_now();
        tf[r] = gi_frame(sc, a, &o, gp, fb_gi, &tfl[r], &tfv[r], &tfr[r], d);
        cf[r] = timer_cpu_now() - c;
        fpf[r] = (double)(bench_minflt_now() - f0);
        const gi_particle_stats *y = gi_particle_get_stats(gp);
        fpc[r] = y->c_prepass;
        fga[r] = y->t_gather;
        fcl[r] = (double)(y->cells - cells0);
    }
    x = gi_particle_get_stats(gp);
    /* the first frame also tests the light-leak guard's cells (kept for the
     * frames after it): printed apart, before the medians sort the arrays */
    double first_w = tf[0], first_c = cf[0], first_r = tfr[0];
    double first_l = tfl[0], first_v = tfv[0], first_pc = fpc[0], first_ga = fga[0], first_cl = fcl[0];
    double first_pf = fpf[0], first_npf = npf[0];
    double mn = bench_median(tn, o.reps), mf = bench_median(tf, o.reps);
    printf("frame --gi none: %.1f ms (%ld primary, %ld shadow rays)\n", 1e3 * mn, ss.primary_rays, ss.shadow_rays);
    printf("frame --gi particle: %.1f ms = lighting %.1f + view %.1f (pre-pass %.1f, gather %.1f, estimate %.1f; "
           "found %ld radiance, used %ld area particles) + render %.1f; ratio %.2f\n",
           1e3 * mf, 1e3 * bench_median(tfl, o.reps), 1e3 * bench_median(tfv, o.reps), 1e3 * x->t_prepass, 1e3 * x->t_gather,
           1e3 * x->t_estimate, x->found, x->used, 1e3 * bench_median(tfr, o.reps), mf / mn);
    printf("  CPU time per frame (all threads, median): none %.1f ms, particle %.1f ms; ratio %.2f\n",
           1e3 * bench_median(cn, o.reps), 1e3 * bench_median(cf, o.reps), bench_median(cf, o.reps) / bench_median(cn, o.reps));
    printf("  first particle frame: %.1f ms wall (render %.1f), %.1f ms CPU; ratio to the median none frame %.2f wall, "
           "%.2f CPU\n",
           1e3 * first_w, 1e3 * first_r, 1e3 * first_c, first_w / mn, first_c / bench_median(cn, o.reps));
    printf("    first frame: lighting %.1f + view %.1f ms wall (pre-pass %.1f ms CPU, gather %.1f ms wall, %.0f cells "
           "tested), %.0f page faults (first none frame %.0f)\n",
           1e3 * first_l, 1e3 * first_v, 1e3 * first_pc, 1e3 * first_ga, first_cl, first_pf, first_npf);
    printf("    median frame: lighting %.1f + view %.1f ms wall (pre-pass %.1f ms CPU, gather %.1f ms wall, %.0f cells "
           "tested), %.0f page faults (none frame %.0f)\n",
           1e3 * bench_median(tfl, o.reps), 1e3 * bench_median(tfv, o.reps), 1e3 * bench_median(fpc, o.reps),
           1e3 * bench_median(fga, o.reps), bench_median(fcl, o.reps), bench_median(fpf, o.reps),
           bench_median(npf, o.reps));
    printf("  hook, per frame (mean of %d): %.0f lookups, %.0f late (%.0f radiance, %.0f area particles computed in "
           "the hook), %.0f without particles, %.0f discarded; %.0f visibility rays\n",
           o.reps, (double)x->lookups / o.reps, (double)x->lookups_late / o.reps, (double)x->late_radiance / o.reps,
           (double)x->late_area / o.reps, (double)x->lookups_none / o.reps, (double)x->discarded / o.reps,
           (double)(x->visibility_rays - gs.visibility_rays) / o.reps);
    printf("  pre-pass (last frame): %.1f ms CPU; stride %d, %ld rays, %ld pixels on their neighbours' plane, %ld "
           "between misses; %ld hits kept for the render (%.1f MiB), %.1f%% of lookups took their cell from one\n",
           1e3 * x->c_prepass, o.stride > 0 ? o.stride : (s.keep_hits ? 1 : 2), x->prepass_rays, x->prepass_planar,
           x->prepass_missed, x->prepass_kept, x->bytes_view / 1048576.0, 100.0 * x->lookups_kept / fmax(1, x->lookups));
    printf("  light-leak guard: %ld cells tested (%ld clear, %.1f%%), %.1f%% of lookups in clear cells, "
           "table %.1f MiB\n",
           x->cells, x->cells_clear, 100.0 * x->cells_clear / fmax(1, x->cells),
           100.0 * x->lookups_clear / fmax(1, x->lookups), x->bytes_cells / 1048576.0);
    printf("mean luminance: none %.5f, particle %.5f\n", img_mean_luminance(fb_none, 0), img_mean_luminance(fb_gi, 0));
    {
        double fl, rm, lu;
        if (ref_error(fb_gi, &fl, &rm, &lu, d))
            printf("against %s: mean FLIP %.4f, RMSE %.5f, mean luminance %+.2f%%\n", o.ref, fl, rm, 100.0 * lu);
    }
    if (g_ref && (g_ref->width != o.size || g_ref->height != o.size)) {
        /* a reference of another size (a converged path render is affordable
         * only small): one more frame of the same particles at its size,
         * --ref-spp stratified eye samples per pixel, compared with it */
        if (g_ref->width != g_ref->height) {
            fprintf(stderr, "bench_gi: the reference %s is not square\n", o.ref);
        } else {
            opts oq = o;
            oq.size = g_ref->width;
            int keep = g_spp;
            g_spp = o.ref_spp > 0 ? o.ref_spp : o.spp;
            framebuffer *fq = fb_new(oq.size, oq.size);
            double q1, q2, q3, cq = timer_cpu_now();
            double tq = gi_frame(sc, a, &oq, gp, fq, &q1, &q2, &q3, d);
            cq = timer_cpu_now() - cq;
            double fl, rm, lu;
            if (ref_error(fq, &fl, &rm, &lu, d))
                printf("against %s (%dx%d frame, %d spp, %.2f s wall, %.2f s CPU): mean FLIP %.4f, RMSE %.5f, mean "
                       "luminance %+.2f%%\n",
                       o.ref, oq.size, oq.size, g_spp, tq, cq, fl, rm, 100.0 * lu);
            if (o.out) {
                char path[4096];
                img_write_opts wo;
                img_default_write_opts(&wo);
                snprintf(path, sizeof path, "%s_ref_particle.exr", o.out);
                img_write(path, fq, &wo, d);
            }
            g_spp = keep;
            fb_free(fq);
        }
    }
    if (o.out) {
        char path[4096];
        img_write_opts wo;
        img_default_write_opts(&wo);
        snprintf(path, sizeof path, "%s_none.exr", o.out);
        img_write(path, fb_none, &wo, d);
        snprintf(path, sizeof path, "%s_particle.exr", o.out);
        img_write(path, fb_gi, &wo, d);
        snprintf(path, sizeof path, "%s_particle.png", o.out);
        img_write(path, fb_gi, &wo, d);
    }
    if (o.sweep) sweep(sc, a, &o, d);
    bench_report_diag(d);
    free(tl);
    free(tk);
    free(tvis);
    free(tcpu);
    free(tn);
    free(tf);
    free(cn);
    free(cf);
    free(fpc);
    free(fga);
    free(fcl);
    free(fpf);
    free(npf);
    free(tfl);
    free(tfv);
    free(tfr);
    fb_free(fb_none);
    fb_free(fb_gi);
    gi_particle_free(gp);
    pipeline_close(&pl);
    fb_free(g_ref);
    diag_free(d);
    return 0;
}
