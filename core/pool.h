/* pool.h - run a job function over indices [0, n) on T threads (dynamic scheduling). */
#ifndef PT_POOL_H
#define PT_POOL_H

typedef void (*pool_job)(void *ctx, int index, int thread);

/* Calls job(ctx, i, thread) for every i in [0, n); returns when all are done.
 * threads <= 0 means the number of online CPUs. */
void pool_run(int threads, int n, pool_job job, void *ctx);
/* The same, handing out no further index once *cancel is non-zero (cancel
 * may be NULL: never); returns 1 when every job ran, 0 when it stopped. */
int pool_run_cancel(int threads, int n, pool_job job, void *ctx, volatile int *cancel);
/* The same, counting each finished index on `p` (core/progress.h), whose
 * current stage's total becomes n; p may be NULL. */
struct progress;
int pool_run_counted(int threads, int n, pool_job job, void *ctx, volatile int *cancel, struct progress *p);
int pool_default_threads(void);

#endif
