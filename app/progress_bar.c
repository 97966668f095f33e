/* progress_bar.c - the drawing thread behind progress_bar.h. */
#include "progress_bar.h"
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "timer.h"

#define BAR_WIDTH 24

struct pbar {
    progress *p;
    int quiet, tty;
    double interval;        /* plain lines: seconds between two */
    double period;          /* seconds between two looks at the progress (at most interval) */
    pthread_t thread;
    int running;
    pthread_mutex_t mu;     /* stderr, and the fields below */
    pthread_cond_t wake;
    int stop;
    int drawn;              /* tty: a bar is on the current line */
    unsigned serial;        /* the stage last seen */
    const char *name;       /* its name and start */
    double t_stage;
    double last_plain;      /* plain: when the last line was printed */
};

/* "12.3 s", "4:05", "1:02:03" */
static void fmt_time(double t, char *buf, int n)
{
    if (t < 0) t = 0;
    if (t < 60) {
        snprintf(buf, (size_t)n, "%.1f s", t);
        return;
    }
    long s = (long)(t + 0.5);
    if (s < 3600) snprintf(buf, (size_t)n, "%ld:%02ld", s / 60, s % 60);
    else snprintf(buf, (size_t)n, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
}

/* Seconds into a stage before an ETA is drawn (a rate measured over less
 * says little); $PARTRAY_PROGRESS_ETA_AFTER sets it (tests: 0, so that a
 * fast render still shows one). */
static double g_eta_after = 0.5;

/* The line drawn for a state `elapsed` seconds into its stage, into buf.
 * tty: with a bar. */
static void pbar_format(const progress_state *s, double elapsed, int tty, char *buf, int n)
{
    char el[32], eta[48] = "";
    fmt_time(elapsed, el, sizeof el);
    const char *name = s->name ? s->name : "";
    if (s->total > 0) {
        double f = (double)s->done / (double)s->total;
        if (f > 1) f = 1;
        /* time left from the rate so far, once there is a rate to go by */
        if (s->done > 0 && elapsed >= g_eta_after && f < 1) {
            char left[32];
            fmt_time(elapsed * (1 - f) / f, left, sizeof left);
            snprintf(eta, sizeof eta, ", ETA %s", left);
        }
        if (tty) {
            char bar[BAR_WIDTH + 1];
            int k = (int)(f * BAR_WIDTH);
            for (int i = 0; i < BAR_WIDTH; i++) bar[i] = i < k ? '#' : '.';
            bar[BAR_WIDTH] = 0;
            snprintf(buf, (size_t)n, "%-28s [%s] %3d%%  %s%s", name, bar, (int)(f * 100), el, eta);
        } else {
            snprintf(buf, (size_t)n, "partray: %s %d%% after %s%s", name, (int)(f * 100), el, eta);
        }
    } else {
        if (tty) {
            /* no total: a marker moving to and fro says it is alive */
            char bar[BAR_WIDTH + 1];
            int span = BAR_WIDTH - 3, t = (int)(elapsed * 8) % (2 * span), at = t < span ? t : 2 * span - t;
            for (int i = 0; i < BAR_WIDTH; i++) bar[i] = i >= at && i < at + 3 ? '=' : ' ';
            bar[BAR_WIDTH] = 0;
            snprintf(buf, (size_t)n, "%-28s [%s]       %s", name, bar, el);
        } else {
            snprintf(buf, (size_t)n, "partray: %s after %s", name, el);
        }
    }
}

/* tty: the line of a finished stage */
static void finish_line(pbar *b, double t_end)
{
    if (!b->name) return;
    char el[32];
    fmt_time(t_end - b->t_stage, el, sizeof el);
    fprintf(stderr, "\r\033[K%-28s done in %s\n", b->name, el);
    b->drawn = 0;
}

/* One look at the progress; called with mu held. */
static void draw(pbar *b, double now, int final)
{
    progress_state s;
    progress_get(b->p, &s);
    if (s.serial != b->serial) {
        if (b->tty) finish_line(b, s.name ? s.t_stage : now);
        b->serial = s.serial;
        b->name = s.name;
        b->t_stage = s.t_stage;
        b->last_plain = now;
    }
    if (!s.name) return;
    char line[256];
    if (b->tty) {
        if (final) {
            finish_line(b, now);
            b->name = NULL;
        } else {
            pbar_format(&s, now - s.t_stage, 1, line, sizeof line);
            fprintf(stderr, "\r\033[K%s", line);
            b->drawn = 1;
        }
        fflush(stderr);
    } else if (!final && now - b->last_plain >= b->interval) {
        pbar_format(&s, now - s.t_stage, 0, line, sizeof line);
        fprintf(stderr, "%s\n", line);
        b->last_plain = now;
    }
}

static void *run(void *arg)
{
    pbar *b = arg;
    pthread_mutex_lock(&b->mu);
    while (!b->stop) {
        draw(b, timer_now(), 0);
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        ts.tv_nsec += (long)(b->period * 1e9);
        while (ts.tv_nsec >= 1000000000L) {
            ts.tv_sec++;
            ts.tv_nsec -= 1000000000L;
        }
        pthread_cond_timedwait(&b->wake, &b->mu, &ts);
    }
    pthread_mutex_unlock(&b->mu);
    return NULL;
}

pbar *pbar_start(int quiet)
{
    pbar *b = calloc(1, sizeof *b);
    if (!b) return NULL;
    progress *p = progress_new();
    if (!p) {
        free(b);
        return NULL;
    }
    b->p = p;
    b->quiet = quiet;
    b->tty = isatty(2);
    b->interval = 10;
    const char *e = getenv("PARTRAY_PROGRESS_SECONDS");
    if (e && atof(e) > 0) b->interval = atof(e);
    /* a look every 0.1 s ($PARTRAY_PROGRESS_REDRAW, at least 1 ms), and
     * never fewer than the plain lines need */
    b->period = 0.1;
    const char *er = getenv("PARTRAY_PROGRESS_REDRAW");
    if (er && atof(er) >= 0.001) b->period = atof(er);
    if (b->interval < b->period) b->period = b->interval < 0.001 ? 0.001 : b->interval;
    const char *ea = getenv("PARTRAY_PROGRESS_ETA_AFTER");
    if (ea && atof(ea) >= 0) g_eta_after = atof(ea);
    pthread_mutex_init(&b->mu, NULL);
    pthread_cond_init(&b->wake, NULL);
    if (!quiet && pthread_create(&b->thread, NULL, run, b) == 0) b->running = 1;
    return b;
}

progress *pbar_progress(pbar *b) { return b ? b->p : NULL; }

/* Prints one line of text (no newline at its end) above the bar. */
static void pbar_message(pbar *b, const char *text)
{
    if (!b) {
        fprintf(stderr, "%s\n", text);
        return;
    }
    pthread_mutex_lock(&b->mu);
    if (b->drawn) fputs("\r\033[K", stderr);
    fprintf(stderr, "%s\n", text);
    b->drawn = 0;
    fflush(stderr);
    pthread_mutex_unlock(&b->mu);
}

void pbar_diag_sink(void *ctx, const diag_msg *m)
{
    pbar *b = ctx;
    if (b && b->quiet && m->severity != DIAG_ERROR) return;
    char *s = diag_format(m);
    if (!s) return;
    pbar_message(b, s);
    free(s);
}

void pbar_stop(pbar *b)
{
    if (!b) return;
    if (b->running) {
        pthread_mutex_lock(&b->mu);
        b->stop = 1;
        pthread_cond_signal(&b->wake);
        pthread_mutex_unlock(&b->mu);
        pthread_join(b->thread, NULL);
        pthread_mutex_lock(&b->mu);
        draw(b, timer_now(), 1);
        b->running = 0;
        pthread_mutex_unlock(&b->mu);
    }
}

void pbar_free(pbar *b)
{
    if (!b) return;
    pbar_stop(b);
    pthread_cond_destroy(&b->wake);
    pthread_mutex_destroy(&b->mu);
    progress_free(b->p);
    free(b);
}
