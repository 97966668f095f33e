/* bench_relight.c - the particle-GI lighting stage alone (gi_particle_relight:
 * emission, the first bounce along all links, the single-link random
 * bounces, the reflected radiance), timed many times on one geometry stage,
 * and its per-particle results written or compared. Prints figures; never
 * fails on a number (a comparison prints its differences, exit 0).
 *
 *   bench_relight [SCENE.pov] [--count N] [--nb N] [--threads N] [--device SPEC]
 *                 [--reps N] [--full] [--dump FILE] [--cmp FILE]
 *
 * Times (median of --reps, default 20): a colour change (visibility reused)
 * and all lights moved (shadow rays traced again), wall (the stage's own
 * timer) and CPU (getrusage, all threads, PoCL's included).
 * --dump FILE writes the particle count, then edir, phi and lout (4 floats
 * per particle each) after a colour-change relight; --cmp FILE reads such a
 * file (of the same scene, count, seed and n_b) and prints, for phi and lout,
 * the largest relative difference per particle (|a - b| / max(|a|, |b|),
 * over colour channels; 0/0 counts 0), how many particles differ at all, and
 * the relative difference of the summed flux. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "accel.h"
#include "bench_gi_util.h"
#include "bench_util.h"
#include "gi_particle.h"
#include "sdl.h"
#include "shade_texture.h"
#include "timer.h"
#include "pipeline.h"

#ifndef BENCH_SCENE_DIR
#define BENCH_SCENE_DIR "scenes"
#endif

/* Largest relative difference per particle between a and b (n x 4 floats,
 * 3 colours), the particles that differ, and the summed values' difference. */
static void compare(const char *what, const float *a, const float *b, int n)
{
    double worst = 0.0, sa = 0.0, sb = 0.0;
    long differ = 0, worst_i = -1;
    for (int i = 0; i < n; i++) {
        double w = 0.0;
        for (int c = 0; c < 3; c++) {
            double x = a[4 * (size_t)i + c], y = b[4 * (size_t)i + c];
            sa += x;
            sb += y;
            double m = fmax(fabs(x), fabs(y));
            double r = m > 0.0 ? fabs(x - y) / m : (x == y ? 0.0 : 1.0);
            if (r > w) w = r;
        }
        if (w > 0.0) differ++;
        if (w > worst) {
            worst = w;
            worst_i = i;
        }
    }
    printf("  %s: max relative difference per particle %.3g (particle %ld), %ld of %d particles differ; sums %.9g "
           "vs %.9g (relative %.3g)\n",
           what, worst, worst_i, differ, n, sa, sb, sb != 0.0 ? (sa - sb) / sb : sa);
}

int main(int argc, char **argv)
{
    const char *scene_path = BENCH_SCENE_DIR "/cbox.pov", *device = NULL, *dump = NULL, *cmp = NULL;
    long count = 50000;
    int nb = 8, threads = 2, reps = 20, full = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--count") && v) { count = atol(v); i++; }
        else if (!strcmp(a, "--nb") && v) { nb = atoi(v); i++; }
        else if (!strcmp(a, "--threads") && v) { threads = atoi(v); i++; }
        else if (!strcmp(a, "--device") && v) { device = v; i++; }
        else if (!strcmp(a, "--reps") && v) { reps = atoi(v); i++; }
        else if (!strcmp(a, "--dump") && v) { dump = v; i++; }
        else if (!strcmp(a, "--cmp") && v) { cmp = v; i++; }
        else if (!strcmp(a, "--full")) full = 1;
        else if (a[0] != '-') scene_path = a;
        else { fprintf(stderr, "bench_relight: unknown option %s\n", a); return 2; }
    }
    if (reps < 1) reps = 1;
    diag *d = diag_new();
    sdl_options so;
    pipeline_sdl_options(&so, NULL, 320, 240);
    pipeline pl;
    pt_status st = pipeline_open(&pl, scene_path, &so, threads, d);
    if (st != PT_OK) {
        bench_report_diag(d);
        return 1;
    }
    scene *sc = pl.sc;
    accel *a = pl.acc;
    gi_particle_settings s;
    gi_particle_settings_from_scene(&s, sc);
    s.pigment = shade_tex_pigment_at;
    s.count = count;
    s.bounces = nb;
    s.threads = threads;
    s.cl_device = device;
    if (full) s.scatter = GI_PARTICLE_SCATTER_FULL;
    gi_particle_stats gs;
    gi_particle *gp = gi_particle_build(sc, a, &s, &gs, d, &st);
    if (!gp) {
        bench_report_diag(d);
        fprintf(stderr, "bench_relight: GI build failed: %s\n", pt_status_name(st));
        return 1;
    }
    printf("%s: %ld particles, n_b %d, %s scattering, device %s\n", scene_path, gs.particles, nb,
           full ? "full" : "walk", gs.device);
    printf("memory after the geometry stage: links %.1f MiB (walk tables included), device %.1f MiB, total %.1f MiB\n",
           gs.bytes_links / 1048576.0, gs.bytes_device / 1048576.0, gs.bytes_total / 1048576.0);
    gi_particle_relight(gp, d); /* the first: visibility traced */
    double *tw = calloc((size_t)reps, sizeof *tw), *tc = calloc((size_t)reps, sizeof *tc);
    double *tk = calloc((size_t)reps, sizeof *tk);
    for (int r = 0; r < reps; r++) {
        double c0 = timer_cpu_now();
        gi_particle_relight(gp, d);
        tc[r] = timer_cpu_now() - c0;
        const gi_particle_stats *x = gi_particle_get_stats(gp);
        tw[r] = x->t_lighting;
        tk[r] = x->t_emit + x->t_scatter;
    }
    const gi_particle_stats *x = gi_particle_get_stats(gp);
    double mw = tw[0], mc = tc[0];
    for (int r = 1; r < reps; r++) {
        mw = fmin(mw, tw[r]);
        mc = fmin(mc, tc[r]);
    }
    printf("colour change (median of %d): %.2f ms wall (kernels %.2f ms), %.2f ms CPU; least %.2f ms wall, %.2f ms "
           "CPU; %ld sources\n",
           reps, 1e3 * bench_median(tw, reps), 1e3 * bench_median(tk, reps), 1e3 * bench_median(tc, reps), 1e3 * mw, 1e3 * mc,
           x->sources);
    long moved_rays = bench_time_moves(gp, sc, sc->nlights, reps, tw, tc, d);
    printf("all lights moved (median of %d): %.2f ms wall, %.2f ms CPU, %ld shadow rays\n", reps,
           1e3 * bench_median(tw, reps), 1e3 * bench_median(tc, reps), moved_rays);
    x = gi_particle_get_stats(gp);
    printf("flux: direct %.9g, emitted %.9g, scattered %.9g\n", x->flux_direct, x->flux_emitted, x->flux_scattered);
    const float *edir, *phi, *lout;
    int n = gi_particle_debug(gp, &edir, &phi, &lout, NULL, NULL);
    if (dump) {
        FILE *f = fopen(dump, "wb");
        if (!f || fwrite(&n, sizeof n, 1, f) != 1 || fwrite(edir, sizeof(float) * 4, (size_t)n, f) != (size_t)n ||
            fwrite(phi, sizeof(float) * 4, (size_t)n, f) != (size_t)n ||
            fwrite(lout, sizeof(float) * 4, (size_t)n, f) != (size_t)n) {
            fprintf(stderr, "bench_relight: cannot write %s\n", dump);
            return 3;
        }
        fclose(f);
    }
    if (cmp) {
        FILE *f = fopen(cmp, "rb");
        int m = 0;
        if (!f || fread(&m, sizeof m, 1, f) != 1 || m != n) {
            fprintf(stderr, "bench_relight: %s is missing or holds another particle count\n", cmp);
            return 3;
        }
        float *buf = malloc(sizeof(float) * 12 * (size_t)n);
        if (!buf || fread(buf, sizeof(float) * 4, 3 * (size_t)n, f) != 3 * (size_t)n) {
            fprintf(stderr, "bench_relight: %s is short\n", cmp);
            return 3;
        }
        fclose(f);
        printf("against %s:\n", cmp);
        compare("edir", edir, buf, n);
        compare("phi", phi, buf + 4 * (size_t)n, n);
        compare("lout", lout, buf + 8 * (size_t)n, n);
        free(buf);
    }
    free(tw);
    free(tc);
    free(tk);
    gi_particle_free(gp);
    pipeline_close(&pl);
    diag_free(d);
    return 0;
}
