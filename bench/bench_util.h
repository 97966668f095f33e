/* bench_util.h - what every benchmark in bench/ prints its figures with
 * (CPU seconds: timer_cpu_now in core/timer.h). */
#ifndef PT_BENCH_UTIL_H
#define PT_BENCH_UTIL_H
#include "diag.h"

/* Minor page faults of the whole process so far (getrusage): first touches
 * of fresh memory. */
long bench_minflt_now(void);

/* Median of v[0..n-1] (sorts v in place; the mean of the two middle values
 * when n is even). */
double bench_median(double *v, int n);

/* Every diagnostic of d on stderr. */
void bench_report_diag(const diag *d);

#endif
