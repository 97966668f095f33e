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
