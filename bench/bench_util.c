/* bench_util.c - shared helpers of the benchmarks (see bench_util.h). */
#include "bench_util.h"
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include "timer.h"

long bench_minflt_now(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_minflt;
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double bench_median(double *v, int n)
{
    if (n <= 0) return 0.0;
    qsort(v, (size_t)n, sizeof *v, cmp_d);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void bench_report_diag(const diag *d)
{
    for (int i = 0; i < diag_count(d); i++) {
        char *m = diag_format(diag_get(d, i));
        if (m) fprintf(stderr, "%s\n", m);
        free(m);
    }
}

long bench_time_moves(gi_particle *gp, scene *sc, int nmove, int reps, double *tm, double *tmc, diag *d)
{
    long rays = 0;
    for (int r = 0; r < reps; r++) {
        for (int l = 0; l < nmove; l++) sc->lights[l].position.x += (r % 2 ? -1e-4 : 1e-4);
        double cc = timer_cpu_now();
        gi_particle_relight(gp, d);
        tmc[r] = timer_cpu_now() - cc;
        const gi_particle_stats *x = gi_particle_get_stats(gp);
        tm[r] = x->t_lighting;
        rays = x->shadow_rays;
    }
    if (reps % 2)
        for (int l = 0; l < nmove; l++) sc->lights[l].position.x -= 1e-4;
    gi_particle_relight(gp, d);
    return rays;
}
