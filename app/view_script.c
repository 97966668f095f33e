/* view_script.c - reading and running `--script` files. */
#include "view_script.h"
#include "grow.h"
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "gi.h"

#define MAX_WORDS 8

typedef struct {
    double time;
    view_action a;
} script_event;

struct view_script {
    script_event *ev;
    int n, cap;
    int next;
    int started;
    double origin; /* wall time at script time 0 */
    int waiting;   /* a wait-idle is due and holds */
    char **strings;
    int nstrings;
};

typedef struct {
    const char *s;
    int len, col;
} word;

static char *keep(view_script *vs, const char *s, int len)
{
    char **ns = realloc(vs->strings, (size_t)(vs->nstrings + 1) * sizeof *ns);
    if (!ns) return NULL;
    vs->strings = ns;
    char *c = malloc((size_t)len + 1);
    if (!c) return NULL;
    memcpy(c, s, (size_t)len);
    c[len] = 0;
    vs->strings[vs->nstrings++] = c;
    return c;
}

static int word_is(const word *w, const char *s) { return (int)strlen(s) == w->len && strncmp(w->s, s, (size_t)w->len) == 0; }

/* A number filling the whole word. */
static int word_num(const word *w, double *v)
{
    char buf[64];
    if (w->len <= 0 || w->len >= (int)sizeof buf) return 0;
    memcpy(buf, w->s, (size_t)w->len);
    buf[w->len] = 0;
    char *end;
    errno = 0;
    double x = strtod(buf, &end);
    if (*end || errno || !isfinite(x)) return 0;
    *v = x;
    return 1;
}

typedef struct {
    const char *name;
    diag *d;
    int line;
    int errors;
} ctx;

static void err_at(ctx *c, int col, const char *fmt, const char *arg)
{
    src_loc loc = {diag_intern(c->d, c->name), c->line, col};
    diag_report(c->d, DIAG_ERROR, loc, NULL, fmt, arg);
    c->errors++;
}

/* Parses the words after TIME into a; returns 1 if fine. */
static int parse_command(ctx *c, view_script *vs, word *w, int n, int eol_col, view_action *a)
{
    memset(a, 0, sizeof *a);
    char cmd[64];
    snprintf(cmd, sizeof cmd, "%.*s", w[0].len < 60 ? w[0].len : 60, w[0].s);
    int need = -1; /* exact word count wanted */
    if (word_is(&w[0], "screenshot")) {
        a->kind = VIEW_ACT_SCREENSHOT;
        if (n > 2) { err_at(c, w[2].col, "screenshot takes one PATH at most%s", ""); return 0; }
        if (n == 2) a->text = keep(vs, w[1].s, w[1].len);
        return 1;
    }
    if (word_is(&w[0], "window")) {
        a->kind = VIEW_ACT_WINDOW_SHOT;
        if (n != 2) { err_at(c, n > 2 ? w[2].col : eol_col, "window takes one PATH (.png)%s", ""); return 0; }
        a->text = keep(vs, w[1].s, w[1].len);
        return 1;
    }
    if (word_is(&w[0], "wait-idle")) { a->kind = VIEW_ACT_WAIT_IDLE; need = 1; }
    else if (word_is(&w[0], "quit")) { a->kind = VIEW_ACT_QUIT; need = 1; }
    else if (word_is(&w[0], "mark")) {
        a->kind = VIEW_ACT_MARK;
        if (n != 2) { err_at(c, n > 2 ? w[2].col : eol_col, "mark takes one NAME%s", ""); return 0; }
        a->text = keep(vs, w[1].s, w[1].len);
        return 1;
    } else if (word_is(&w[0], "gi")) {
        a->kind = VIEW_ACT_GI;
        if (n != 2) { err_at(c, n > 2 ? w[2].col : eol_col, "gi takes one MODE (none, particle, path, pmfg, next)%s", ""); return 0; }
        char m[32];
        snprintf(m, sizeof m, "%.*s", w[1].len < 30 ? w[1].len : 30, w[1].s);
        a->mode = strcmp(m, "next") == 0 ? -1 : gi_mode_parse(m);
        if (strcmp(m, "next") != 0 && a->mode < 0) { err_at(c, w[1].col, "unknown GI mode '%s' (none, particle, path, pmfg, next)", m); return 0; }
        return 1;
    } else if (word_is(&w[0], "key")) {
        a->kind = VIEW_ACT_KEY;
        if (n < 2 || n > 3) { err_at(c, n > 3 ? w[3].col : eol_col, "key takes NAME [HOLD]%s", ""); return 0; }
        a->text = keep(vs, w[1].s, w[1].len);
        if (n == 3 && (!word_num(&w[2], &a->v[0]) || a->v[0] < 0)) { err_at(c, w[2].col, "key HOLD must be seconds >= 0%s", ""); return 0; }
        return 1;
    } else if (word_is(&w[0], "drag")) {
        a->kind = VIEW_ACT_DRAG;
        if (n != 4) { err_at(c, n > 4 ? w[4].col : eol_col, "drag takes left|right DX DY%s", ""); return 0; }
        if (word_is(&w[1], "left")) a->mode = 1;
        else if (word_is(&w[1], "right")) a->mode = 3;
        else { err_at(c, w[1].col, "drag wants left or right%s", ""); return 0; }
        for (int i = 0; i < 2; i++)
            if (!word_num(&w[2 + i], &a->v[i]) || fabs(a->v[i]) > 1e5) { err_at(c, w[2 + i].col, "expected a number of pixels%s", ""); return 0; }
        return 1;
    } else if (word_is(&w[0], "clock")) {
        a->kind = VIEW_ACT_CLOCK;
        if (n != 2) { err_at(c, n > 2 ? w[2].col : eol_col, "clock takes one number%s", ""); return 0; }
        if (!word_num(&w[1], &a->v[0]) || !(fabs(a->v[0]) <= 1e9)) { err_at(c, w[1].col, "expected the clock value%s", ""); return 0; }
        return 1;
    } else if (word_is(&w[0], "wheel")) {
        a->kind = VIEW_ACT_WHEEL;
        if (n != 2) { err_at(c, n > 2 ? w[2].col : eol_col, "wheel takes one number of clicks%s", ""); return 0; }
        if (!word_num(&w[1], &a->v[0]) || fabs(a->v[0]) > 1e4 || a->v[0] != floor(a->v[0])) { err_at(c, w[1].col, "expected a whole number of clicks%s", ""); return 0; }
        return 1;
    } else if (word_is(&w[0], "light")) {
        double idx;
        if (n < 3) { err_at(c, n > 1 ? w[1].col + w[1].len : eol_col, "light needs N and an action (select, move, scale)%s", ""); return 0; }
        if (!word_num(&w[1], &idx) || idx < 1 || idx > 1e6 || idx != floor(idx)) {
            err_at(c, w[1].col, "light number must be an integer >= 1%s", "");
            return 0;
        }
        a->light = (int)idx;
        int nums = 0;
        if (word_is(&w[2], "select")) { a->kind = VIEW_ACT_LIGHT_SELECT; nums = 0; }
        else if (word_is(&w[2], "move")) { a->kind = VIEW_ACT_LIGHT_MOVE; nums = 3; }
        else if (word_is(&w[2], "scale")) { a->kind = VIEW_ACT_LIGHT_SCALE; nums = 1; }
        else {
            char m[32];
            snprintf(m, sizeof m, "%.*s", w[2].len < 30 ? w[2].len : 30, w[2].s);
            err_at(c, w[2].col, "unknown light action '%s' (select, move, scale)", m);
            return 0;
        }
        if (n != 3 + nums) {
            err_at(c, n > 3 + nums ? w[3 + nums].col : eol_col, "wrong number of values for light %s", a->kind == VIEW_ACT_LIGHT_MOVE ? "move (DX DY DZ)" : (a->kind == VIEW_ACT_LIGHT_SCALE ? "scale (F)" : "select (none)"));
            return 0;
        }
        for (int i = 0; i < nums; i++)
            if (!word_num(&w[3 + i], &a->v[i])) { err_at(c, w[3 + i].col, "expected a number%s", ""); return 0; }
        if (a->kind == VIEW_ACT_LIGHT_SCALE && a->v[0] < 0) { err_at(c, w[3].col, "light scale must be >= 0%s", ""); return 0; }
        return 1;
    } else if (word_is(&w[0], "camera")) {
        if (n < 2) { err_at(c, eol_col, "camera needs an action (orbit, look, move, zoom, write)%s", ""); return 0; }
        int nums = 0;
        if (word_is(&w[1], "orbit")) { a->kind = VIEW_ACT_CAMERA_ORBIT; nums = 2; }
        else if (word_is(&w[1], "look")) { a->kind = VIEW_ACT_CAMERA_LOOK; nums = 2; }
        else if (word_is(&w[1], "move")) { a->kind = VIEW_ACT_CAMERA_MOVE; nums = 3; }
        else if (word_is(&w[1], "zoom")) { a->kind = VIEW_ACT_CAMERA_ZOOM; nums = 1; }
        else if (word_is(&w[1], "write")) {
            a->kind = VIEW_ACT_CAMERA_WRITE;
            if (n > 3) { err_at(c, w[3].col, "camera write takes one PATH at most%s", ""); return 0; }
            if (n == 3) a->text = keep(vs, w[2].s, w[2].len);
            return 1;
        } else {
            char m[32];
            snprintf(m, sizeof m, "%.*s", w[1].len < 30 ? w[1].len : 30, w[1].s);
            err_at(c, w[1].col, "unknown camera action '%s' (orbit, look, move, zoom, write)", m);
            return 0;
        }
        if (n != 2 + nums) {
            err_at(c, n > 2 + nums ? w[2 + nums].col : eol_col, "wrong number of values for camera %s", nums == 2 ? "orbit/look (YAW PITCH)" : (nums == 3 ? "move (F R U)" : "zoom (K)"));
            return 0;
        }
        for (int i = 0; i < nums; i++)
            if (!word_num(&w[2 + i], &a->v[i])) { err_at(c, w[2 + i].col, "expected a number%s", ""); return 0; }
        if (a->kind == VIEW_ACT_CAMERA_ZOOM && !(a->v[0] > 0)) { err_at(c, w[2].col, "camera zoom must be > 0%s", ""); return 0; }
        return 1;
    } else {
        err_at(c, w[0].col, "unknown command '%s' (screenshot, window, light, camera, gi, key, drag, wheel, wait-idle, mark, quit)", cmd);
        return 0;
    }
    if (n != need) {
        err_at(c, n > need ? w[need].col : eol_col, "%s takes no arguments", cmd);
        return 0;
    }
    return 1;
}

static int cmp_event(const void *pa, const void *pb)
{
    const script_event *a = pa, *b = pb;
    if (a->time < b->time) return -1;
    if (a->time > b->time) return 1;
    return 0;
}

pt_status view_script_parse(const char *name, const char *text, view_script **out, diag *d)
{
    *out = NULL;
    view_script *vs = calloc(1, sizeof *vs);
    if (!vs) return PT_ERR_NOMEM;
    ctx c = {name, d, 0, 0};
    const char *p = text;
    while (*p) {
        c.line++;
        const char *eol = strchr(p, '\n');
        if (!eol) eol = p + strlen(p);
        word w[MAX_WORDS + 1];
        int n = 0, too_many = 0;
        const char *q = p;
        while (q < eol && *q != '#') {
            if (isspace((unsigned char)*q)) { q++; continue; }
            const char *s = q;
            while (q < eol && *q != '#' && !isspace((unsigned char)*q)) q++;
            if (n < MAX_WORDS + 1) w[n++] = (word){s, (int)(q - s), (int)(s - p) + 1};
            else too_many = 1;
        }
        int eol_col = (int)(q - p) + 1;
        if (n > 0) {
            double t;
            if (too_many || n > MAX_WORDS) err_at(&c, w[MAX_WORDS].col, "too many words on a line%s", "");
            else if (!word_num(&w[0], &t) || t < 0) err_at(&c, w[0].col, "expected a time in seconds (>= 0) first%s", "");
            else if (n < 2) err_at(&c, eol_col, "expected a command after the time%s", "");
            else {
                view_action a;
                if (parse_command(&c, vs, w + 1, n - 1, eol_col, &a)) {
                    if (!grow_array_int((void **)&vs->ev, &vs->cap, vs->n + 1, sizeof *vs->ev)) {
                        view_script_free(vs);
                        return PT_ERR_NOMEM;
                    }
                    vs->ev[vs->n].time = t;
                    vs->ev[vs->n].a = a;
                    vs->n++;
                }
            }
        }
        p = *eol ? eol + 1 : eol;
    }
    if (c.errors) {
        view_script_free(vs);
        return PT_ERR_SYNTAX;
    }
    /* stable order by time: insertion sort keeps ties in file order */
    for (int i = 1; i < vs->n; i++) {
        script_event e = vs->ev[i];
        int j = i - 1;
        while (j >= 0 && cmp_event(&vs->ev[j], &e) > 0) {
            vs->ev[j + 1] = vs->ev[j];
            j--;
        }
        vs->ev[j + 1] = e;
    }
    *out = vs;
    return PT_OK;
}

pt_status view_script_load(const char *path, view_script **out, diag *d)
{
    *out = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) {
        diag_error(d, "%s: cannot read the script: %s", path, strerror(errno));
        return PT_ERR_IO;
    }
    size_t cap = 4096, n = 0;
    char *buf = malloc(cap);
    for (;;) {
        if (!buf) { fclose(f); return PT_ERR_NOMEM; }
        size_t got = fread(buf + n, 1, cap - n - 1, f);
        n += got;
        if (n < cap - 1) break;
        if (cap > (64u << 20)) {
            free(buf);
            fclose(f);
            diag_error(d, "%s: script larger than 64 MiB", path);
            return PT_ERR_LIMIT;
        }
        cap *= 2;
        char *nb = realloc(buf, cap);
        if (!nb) free(buf);
        buf = nb;
    }
    int bad = ferror(f);
    fclose(f);
    if (bad) {
        free(buf);
        diag_error(d, "%s: read error", path);
        return PT_ERR_IO;
    }
    buf[n] = 0;
    if (memchr(buf, 0, n)) {
        free(buf);
        diag_error(d, "%s: not a text file", path);
        return PT_ERR_SYNTAX;
    }
    pt_status st = view_script_parse(path, buf, out, d);
    free(buf);
    return st;
}

void view_script_free(view_script *vs)
{
    if (!vs) return;
    for (int i = 0; i < vs->nstrings; i++) free(vs->strings[i]);
    free(vs->strings);
    free(vs->ev);
    free(vs);
}

void view_script_start(view_script *vs, double now)
{
    if (vs->started) return;
    vs->started = 1;
    vs->origin = now;
}

int view_script_next(view_script *vs, double now, int idle, view_action *a)
{
    if (!vs->started) return 0;
    while (vs->next < vs->n) {
        script_event *e = &vs->ev[vs->next];
        if (now - vs->origin < e->time) return 0;
        if (e->a.kind == VIEW_ACT_WAIT_IDLE) {
            if (!idle) {
                vs->waiting = 1;
                return 0;
            }
            /* resume the clock at this event's time */
            if (vs->waiting) vs->origin = now - e->time;
            vs->waiting = 0;
            vs->next++;
            continue;
        }
        *a = e->a;
        vs->next++;
        return 1;
    }
    return 0;
}

const view_action *view_script_action(const view_script *vs, int i) { return &vs->ev[i].a; }

int view_script_done(const view_script *vs) { return vs->next >= vs->n; }
int view_script_count(const view_script *vs) { return vs->n; }
