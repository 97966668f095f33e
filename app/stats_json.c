/* stats_json.c - a tiny JSON object writer. */
#include "stats_json.h"
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void put(stats_json *j, const char *fmt, ...)
{
    va_list ap;
    for (;;) {
        size_t room = j->cap - j->len;
        va_start(ap, fmt);
        int n = j->buf ? vsnprintf(j->buf + j->len, room, fmt, ap) : -1;
        va_end(ap);
        if (n >= 0 && (size_t)n < room) {
            j->len += (size_t)n;
            return;
        }
        size_t nc = j->cap ? j->cap * 2 : 1024;
        if (n > 0 && nc < j->len + (size_t)n + 1) nc = j->len + (size_t)n + 1;
        char *nb = realloc(j->buf, nc);
        if (!nb) return;
        j->buf = nb;
        j->cap = nc;
    }
}

static void key(stats_json *j, const char *k)
{
    if (!j->first[j->depth]) put(j, ",");
    j->first[j->depth] = 0;
    put(j, "\n%*s\"", 2 * j->depth, "");
    for (const char *p = k; *p; p++) put(j, (*p == '"' || *p == '\\') ? "\\%c" : "%c", *p);
    put(j, "\": ");
}

void stats_begin(stats_json *j)
{
    memset(j, 0, sizeof *j);
    put(j, "{");
    j->depth = 1;
    j->first[1] = 1;
}

void stats_obj_begin(stats_json *j, const char *k)
{
    key(j, k);
    put(j, "{");
    if (j->depth < 15) j->depth++;
    j->first[j->depth] = 1;
}

void stats_obj_end(stats_json *j)
{
    j->depth--;
    put(j, "\n%*s}", 2 * j->depth, "");
}

void stats_num(stats_json *j, const char *k, double v)
{
    key(j, k);
    if (isfinite(v)) put(j, "%.9g", v);
    else put(j, "null");
}

void stats_int(stats_json *j, const char *k, long long v)
{
    key(j, k);
    put(j, "%lld", v);
}

void stats_str(stats_json *j, const char *k, const char *v)
{
    key(j, k);
    put(j, "\"");
    for (const unsigned char *p = (const unsigned char *)(v ? v : ""); *p; p++) {
        if (*p == '"' || *p == '\\') put(j, "\\%c", *p);
        else if (*p < 0x20) put(j, "\\u%04x", *p);
        else put(j, "%c", *p);
    }
    put(j, "\"");
}

const char *stats_end(stats_json *j)
{
    put(j, "\n}\n");
    return j->buf;
}

int stats_write(stats_json *j, const char *path)
{
    const char *text = stats_end(j);
    size_t n = strlen(path) + 32;
    char *tmp = malloc(n);
    int ok = 0;
    if (tmp && text) {
        snprintf(tmp, n, "%s.tmp-%ld", path, (long)getpid());
        FILE *f = fopen(tmp, "wb");
        if (f) {
            ok = fwrite(text, 1, strlen(text), f) == strlen(text);
            ok = (fclose(f) == 0) && ok;
            if (ok) ok = rename(tmp, path) == 0;
            if (!ok) remove(tmp);
        }
    }
    free(tmp);
    stats_free(j);
    return ok;
}

void stats_free(stats_json *j)
{
    free(j->buf);
    j->buf = NULL;
    j->len = j->cap = 0;
}
