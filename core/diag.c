/* diag.c - diagnostics context. */
#include "diag.h"
#include "grow.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct diag {
    diag_msg *msgs;
    int n, cap, nerr;
    char **strs;
    int nstr, capstr;
    diag_sink_fn sink;
    void *sink_ctx;
};

void diag_set_sink(diag *d, diag_sink_fn fn, void *ctx)
{
    if (!d) return;
    d->sink = fn;
    d->sink_ctx = ctx;
}

const char *pt_status_name(pt_status s)
{
    switch (s) {
    case PT_OK: return "ok";
    case PT_ERR_SYNTAX: return "scene error";
    case PT_ERR_LIMIT: return "limit exceeded";
    case PT_ERR_UNSUPPORTED: return "unsupported";
    case PT_ERR_IO: return "I/O error";
    case PT_ERR_NOMEM: return "out of memory";
    case PT_ERR_DEVICE: return "device error";
    case PT_ERR_USAGE: return "usage error";
    case PT_ERR_INTERNAL: return "internal error";
    case PT_CANCELLED: return "cancelled";
    }
    return "unknown";
}

diag *diag_new(void) { return calloc(1, sizeof(diag)); }

void diag_free(diag *d)
{
    if (!d) return;
    for (int i = 0; i < d->n; i++) free(d->msgs[i].text);
    for (int i = 0; i < d->nstr; i++) free(d->strs[i]);
    free(d->msgs);
    free(d->strs);
    free(d);
}

const char *diag_intern(diag *d, const char *s)
{
    if (!s) return NULL;
    for (int i = 0; i < d->nstr; i++)
        if (strcmp(d->strs[i], s) == 0) return d->strs[i];
    if (!grow_array_int((void **)&d->strs, &d->capstr, d->nstr + 1, sizeof *d->strs)) return s;
    d->strs[d->nstr] = strdup(s);
    return d->strs[d->nstr] ? d->strs[d->nstr++] : s;
}

void diag_vreport(diag *d, diag_severity sev, src_loc loc, const char *chain, const char *fmt, va_list ap)
{
    if (!d) return;
    char buf[2048];
    vsnprintf(buf, sizeof buf, fmt, ap);
    size_t n = strlen(buf) + (chain ? strlen(chain) + 2 : 1);
    char *text = malloc(n);
    if (!text) return;
    if (chain && *chain)
        snprintf(text, n, "%s\n%s", buf, chain);
    else
        snprintf(text, n, "%s", buf);
    if (!grow_array_int((void **)&d->msgs, &d->cap, d->n + 1, sizeof *d->msgs)) {
        free(text);
        return;
    }
    loc.file = diag_intern(d, loc.file);
    d->msgs[d->n].severity = sev;
    d->msgs[d->n].loc = loc;
    d->msgs[d->n].text = text;
    d->n++;
    if (sev == DIAG_ERROR) d->nerr++;
    if (d->sink) d->sink(d->sink_ctx, &d->msgs[d->n - 1]);
}

void diag_report(diag *d, diag_severity sev, src_loc loc, const char *chain, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    diag_vreport(d, sev, loc, chain, fmt, ap);
    va_end(ap);
}

void diag_error(diag *d, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    src_loc none = {NULL, 0, 0};
    diag_vreport(d, DIAG_ERROR, none, NULL, fmt, ap);
    va_end(ap);
}

void diag_warn_once(diag *d, src_loc loc, const char *fmt, ...)
{
    if (!d) return;
    char buf[2048];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    for (int i = 0; i < d->n; i++)
        if (d->msgs[i].severity == DIAG_WARNING && strcmp(d->msgs[i].text, buf) == 0) return;
    diag_report(d, DIAG_WARNING, loc, NULL, "%s", buf);
}

int diag_count(const diag *d) { return d ? d->n : 0; }
int diag_errors(const diag *d) { return d ? d->nerr : 0; }
const diag_msg *diag_get(const diag *d, int i) { return (d && i >= 0 && i < d->n) ? &d->msgs[i] : NULL; }

char *diag_format(const diag_msg *m)
{
    static const char *sevname[] = {"error", "warning", "note"};
    size_t n = strlen(m->text) + (m->loc.file ? strlen(m->loc.file) : 0) + 64;
    char *s = malloc(n);
    if (!s) return NULL;
    if (m->loc.file && m->loc.line > 0)
        snprintf(s, n, "%s:%d:%d: %s: %s", m->loc.file, m->loc.line, m->loc.col, sevname[m->severity], m->text);
    else if (m->loc.file)
        snprintf(s, n, "%s: %s: %s", m->loc.file, sevname[m->severity], m->text);
    else
        snprintf(s, n, "partray: %s: %s", sevname[m->severity], m->text);
    return s;
}
