/* timer.h - monotonic wall clock and the process's CPU time, in seconds. */
#ifndef PT_TIMER_H
#define PT_TIMER_H
#include <sys/resource.h>
#include <time.h>
static inline double timer_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* CPU seconds of the whole process (getrusage: user + system, every thread,
 * OpenCL's and Embree's included); on a shared machine they say more than
 * wall time, which other processes' load stretches. */
static inline double timer_cpu_now(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * (double)(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}
#endif
