/* bench_gi_util.c - particle-GI timing shared by bench_gi and bench_relight (see bench_gi_util.h). */
#include "bench_gi_util.h"
#include "timer.h"

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
