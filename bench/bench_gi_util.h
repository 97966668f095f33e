/* bench_gi_util.h - the particle-GI relight timing bench_gi and
 * bench_relight share (apart from bench_util, which every benchmark links
 * without the GI library). */
#ifndef PT_BENCH_GI_UTIL_H
#define PT_BENCH_GI_UTIL_H
#include "diag.h"
#include "gi_particle.h"
#include "scene.h"

/* Relights gp reps times, each after moving the first nmove lights of sc by
 * 1e-4 in x (back and forth, so visibility is traced again), recording the
 * stage's wall (tm[r], its own timer) and CPU (tmc[r], timer_cpu_now) times;
 * the lights end where they started, relit. Returns the last relight's
 * shadow rays. */
long bench_time_moves(gi_particle *gp, scene *sc, int nmove, int reps, double *tm, double *tmc, diag *d);

#endif
