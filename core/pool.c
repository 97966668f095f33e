/* pool.c - minimal parallel-for on pthreads with an atomic work counter. */
#include "pool.h"
#include <pthread.h>
#include "progress.h"
#include <stdatomic.h>
#include <stdlib.h>
#include <unistd.h>

typedef struct {
    pool_job job;
    void *ctx;
    int n;
    atomic_int next;
    volatile int *cancel;
    atomic_int stopped;
    progress *progress;
} pool_state;

typedef struct {
    pool_state *st;
    int thread;
} worker_arg;

static void *worker(void *p)
{
    worker_arg *w = p;
    for (;;) {
        if (w->st->cancel && *w->st->cancel) {
            atomic_store(&w->st->stopped, 1);
            break;
        }
        int i = atomic_fetch_add(&w->st->next, 1);
        if (i >= w->st->n) break;
        w->st->job(w->st->ctx, i, w->thread);
        progress_add(w->st->progress, 1);
    }
    return NULL;
}

int pool_default_threads(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (int)n : 1;
}

void pool_run(int threads, int n, pool_job job, void *ctx) { (void)pool_run_counted(threads, n, job, ctx, NULL, NULL); }

int pool_run_cancel(int threads, int n, pool_job job, void *ctx, volatile int *cancel)
{
    return pool_run_counted(threads, n, job, ctx, cancel, NULL);
}

int pool_run_counted(int threads, int n, pool_job job, void *ctx, volatile int *cancel, progress *p)
{
    if (threads <= 0) threads = pool_default_threads();
    if (threads > n) threads = n;
    progress_set_total(p, n);
    pool_state st = {job, ctx, n, 0, cancel, 0, p};
    pthread_t *tid = threads > 1 ? malloc(sizeof(pthread_t) * (size_t)threads) : NULL;
    worker_arg *args = threads > 1 ? malloc(sizeof(worker_arg) * (size_t)threads) : NULL;
    if (!tid || !args) {
        /* one thread (or no memory for more): this one */
        free(tid);
        free(args);
        worker_arg w = {&st, 0};
        worker(&w);
        return !atomic_load(&st.stopped);
    }
    int started = 0;
    for (int t = 1; t < threads; t++) {
        args[t].st = &st;
        args[t].thread = t;
        if (pthread_create(&tid[t], NULL, worker, &args[t]) == 0) started = t;
        else break;
    }
    args[0].st = &st;
    args[0].thread = 0;
    worker(&args[0]);
    for (int t = 1; t <= started; t++) pthread_join(tid[t], NULL);
    free(tid);
    free(args);
    return !atomic_load(&st.stopped);
}
