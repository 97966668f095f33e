/* progress_bar.h - draws a core/progress on stderr from its own thread.
 *
 * On a terminal: one line per stage (parse, accel, each GI step, render,
 * antialias), redrawn in place about ten times a second with a bar, the
 * percent, the time spent and an estimate of the time left; a finished
 * stage keeps its line with its time. Elsewhere (a log, a pipe): a plain
 * line now and then for a stage that runs long (every
 * $PARTRAY_PROGRESS_SECONDS, default 10). Messages go through
 * pbar_message (or the diag sink pbar_diag_sink) so a bar never hides
 * them. Quiet: no bar, and the sink prints errors only. */
#ifndef PT_PROGRESS_BAR_H
#define PT_PROGRESS_BAR_H
#include "diag.h"
#include "progress.h"

typedef struct pbar pbar;

/* A new progress (core/progress.h) and its drawing thread. quiet: draw
 * nothing. NULL when out of memory (then every call here still works and
 * pbar_progress is NULL, which counts nothing). */
pbar *pbar_start(int quiet);
/* The progress the render's stages count on (owned by b). */
progress *pbar_progress(pbar *b);
/* A diag_sink_fn (core/diag.h) that prints each message as it is recorded,
 * one line above the bar (ctx: the pbar); quiet: errors only. */
void pbar_diag_sink(void *ctx, const diag_msg *m);
/* Ends the last stage's line and stops drawing; messages still print
 * (plainly) until pbar_free, which frees the progress too. */
void pbar_stop(pbar *b);
void pbar_free(pbar *b);

#endif
