/* progress.h - how far a long computation has come, read by another thread.
 *
 * Deep code names its stages and counts work units; it never prints (the
 * app draws a bar from snapshots: app/progress_bar.h). Every function takes
 * a NULL progress and then does nothing, so code that reports progress
 * needs no test for it. Counting is one atomic add: cheap enough per tile
 * row or per job, not per ray. */
#ifndef PT_PROGRESS_H
#define PT_PROGRESS_H

typedef struct progress progress;

progress *progress_new(void);
void progress_free(progress *p);

/* Begin a stage: `name` is a string that outlives the stage (a literal);
 * `total` its work units, 0 when unknown (the bar then shows only the time
 * spent). The count starts at 0. */
void progress_stage(progress *p, const char *name, long long total);
/* Add `n` units done (any thread). */
void progress_add(progress *p, long long n);
/* Set the units done (one thread: e.g. the position in a file). */
void progress_set(progress *p, long long done);
/* Change the total of the current stage (once it is known). */
void progress_set_total(progress *p, long long total);

typedef struct {
    const char *name;   /* NULL before the first stage */
    long long done, total;
    unsigned serial;    /* changes with every progress_stage */
    double t_stage;     /* timer_now() when the stage began */
} progress_state;

/* A snapshot (any thread). */
void progress_get(progress *p, progress_state *s);

#endif
