/* bench_util.h - what every benchmark in bench/ prints its figures with. */
#ifndef PT_BENCH_UTIL_H
#define PT_BENCH_UTIL_H
#include "diag.h"

/* CPU seconds of the whole process (getrusage: all threads, PoCL's and
 * Embree's included); on a shared machine this says more than wall time,
 * which other processes' load stretches. */
double bench_cpu_now(void);

/* Median of v[0..n-1] (sorts v in place; the mean of the two middle values
 * when n is even). */
double bench_median(double *v, int n);

/* Every diagnostic of d on stderr. */
void bench_report_diag(const diag *d);

#endif
