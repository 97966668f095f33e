/* bench_util.h - what every benchmark in bench/ prints its figures with
 * (CPU seconds: timer_cpu_now in core/timer.h), and the particle-GI relight
 * timing bench_gi and bench_relight share. */
#ifndef PT_BENCH_UTIL_H
#define PT_BENCH_UTIL_H
#include "diag.h"
#include "gi_particle.h"
#include "scene.h"

/* Minor page faults of the whole process so far (getrusage): first touches
 * of fresh memory. */
long bench_minflt_now(void);

/* Median of v[0..n-1] (sorts v in place; the mean of the two middle values
 * when n is even). */
double bench_median(double *v, int n);

/* Every diagnostic of d on stderr. */
void bench_report_diag(const diag *d);

/* Relights gp reps times, each after moving the first nmove lights of sc by
 * 1e-4 in x (back and forth, so visibility is traced again), recording the
 * stage's wall (tm[r], its own timer) and CPU (tmc[r], timer_cpu_now) times;
 * the lights end where they started, relit. Returns the last relight's
 * shadow rays. */
long bench_time_moves(gi_particle *gp, scene *sc, int nmove, int reps, double *tm, double *tmc, diag *d);

#endif
