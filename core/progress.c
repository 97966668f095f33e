/* progress.c - stage name and counts behind a mutex and an atomic counter. */
#include "progress.h"
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include "timer.h"

struct progress {
    pthread_mutex_t mu; /* name, total, serial, t_stage */
    const char *name;
    long long total;
    unsigned serial;
    double t_stage;
    _Atomic long long done;
};

progress *progress_new(void)
{
    progress *p = calloc(1, sizeof *p);
    if (!p) return NULL;
    pthread_mutex_init(&p->mu, NULL);
    atomic_init(&p->done, 0);
    return p;
}

void progress_free(progress *p)
{
    if (!p) return;
    pthread_mutex_destroy(&p->mu);
    free(p);
}

void progress_stage(progress *p, const char *name, long long total)
{
    if (!p) return;
    pthread_mutex_lock(&p->mu);
    p->name = name;
    p->total = total > 0 ? total : 0;
    p->serial++;
    p->t_stage = timer_now();
    atomic_store(&p->done, 0);
    pthread_mutex_unlock(&p->mu);
}

void progress_add(progress *p, long long n)
{
    if (p) atomic_fetch_add_explicit(&p->done, n, memory_order_relaxed);
}

void progress_set(progress *p, long long done)
{
    if (p) atomic_store_explicit(&p->done, done, memory_order_relaxed);
}

void progress_set_total(progress *p, long long total)
{
    if (!p) return;
    pthread_mutex_lock(&p->mu);
    p->total = total > 0 ? total : 0;
    pthread_mutex_unlock(&p->mu);
}

void progress_get(progress *p, progress_state *s)
{
    if (!p) {
        s->name = NULL;
        s->done = s->total = 0;
        s->serial = 0;
        s->t_stage = 0;
        return;
    }
    pthread_mutex_lock(&p->mu);
    s->name = p->name;
    s->total = p->total;
    s->serial = p->serial;
    s->t_stage = p->t_stage;
    s->done = atomic_load_explicit(&p->done, memory_order_relaxed);
    pthread_mutex_unlock(&p->mu);
    if (s->total > 0 && s->done > s->total) s->done = s->total;
}
