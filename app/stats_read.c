/* stats_read.c - a small JSON reader: walks the text once, following a
 * dotted key path through nested objects, and skips everything else. */
#include "stats_read.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    const char *p;
    int depth;
} reader;

static void ws(reader *r)
{
    while (*r->p == ' ' || *r->p == '\t' || *r->p == '\n' || *r->p == '\r') r->p++;
}

/* Parses a string at r->p (at the opening quote); copies it into buf when
 * buf is non-NULL. Returns 1 on success. */
static int string(reader *r, char *buf, size_t n)
{
    if (*r->p != '"') return 0;
    r->p++;
    size_t k = 0;
    while (*r->p && *r->p != '"') {
        char c = *r->p++;
        if (c == '\\') {
            char e = *r->p++;
            switch (e) {
            case 'n': c = '\n'; break;
            case 't': c = '\t'; break;
            case 'r': c = '\r'; break;
            case 'b': c = '\b'; break;
            case 'f': c = '\f'; break;
            case 'u': {
                unsigned v = 0;
                for (int i = 0; i < 4; i++) {
                    char h = *r->p;
                    if (!h) return 0;
                    r->p++;
                    v = v * 16u + (unsigned)(h >= 'a' ? h - 'a' + 10 : h >= 'A' ? h - 'A' + 10 : h - '0');
                }
                c = v < 128 ? (char)v : '?';
                break;
            }
            case 0: return 0;
            default: c = e; break;
            }
        }
        if (buf && k + 1 < n) buf[k++] = c;
    }
    if (*r->p != '"') return 0;
    r->p++;
    if (buf && n) buf[k] = 0;
    return 1;
}

static int value(reader *r);

static int skip_container(reader *r, char open, char close)
{
    if (++r->depth > 64) return 0;
    r->p++;
    ws(r);
    if (*r->p == close) {
        r->p++;
        r->depth--;
        return 1;
    }
    for (;;) {
        ws(r);
        if (open == '{') {
            if (!string(r, NULL, 0)) return 0;
            ws(r);
            if (*r->p++ != ':') return 0;
        }
        if (!value(r)) return 0;
        ws(r);
        if (*r->p == ',') {
            r->p++;
            continue;
        }
        if (*r->p == close) {
            r->p++;
            r->depth--;
            return 1;
        }
        return 0;
    }
}

/* Skips any value. */
static int value(reader *r)
{
    ws(r);
    char c = *r->p;
    if (c == '{') return skip_container(r, '{', '}');
    if (c == '[') return skip_container(r, '[', ']');
    if (c == '"') return string(r, NULL, 0);
    if (strncmp(r->p, "true", 4) == 0 || strncmp(r->p, "null", 4) == 0) {
        r->p += 4;
        return 1;
    }
    if (strncmp(r->p, "false", 5) == 0) {
        r->p += 5;
        return 1;
    }
    char *end;
    strtod(r->p, &end);
    if (end == r->p) return 0;
    r->p = end;
    return 1;
}

/* Positions r->p at the value for `path` inside the object at r->p. */
static int find(reader *r, const char *path)
{
    ws(r);
    if (*r->p != '{') return 0;
    const char *dot = strchr(path, '.');
    size_t klen = dot ? (size_t)(dot - path) : strlen(path);
    r->p++;
    for (;;) {
        ws(r);
        if (*r->p == '}') return 0;
        char key[256];
        if (!string(r, key, sizeof key)) return 0;
        ws(r);
        if (*r->p++ != ':') return 0;
        ws(r);
        if (strlen(key) == klen && strncmp(key, path, klen) == 0) return dot ? find(r, dot + 1) : 1;
        if (!value(r)) return 0;
        ws(r);
        if (*r->p == ',') {
            r->p++;
            continue;
        }
        return 0;
    }
}

int stats_read_num(const char *json, const char *path, double *out)
{
    if (!json || !path) return 0;
    reader r = {json, 0};
    if (!find(&r, path)) return 0;
    if (strncmp(r.p, "null", 4) == 0) {
        *out = NAN;
        return 1;
    }
    char *end;
    double v = strtod(r.p, &end);
    if (end == r.p) return 0;
    *out = v;
    return 1;
}

int stats_read_str(const char *json, const char *path, char *buf, size_t n)
{
    if (!json || !path || !buf || !n) return 0;
    reader r = {json, 0};
    if (!find(&r, path)) return 0;
    return string(&r, buf, n);
}
