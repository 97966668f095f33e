/* img_plot.c - a small raster plotter (see img_plot.h). Everything is drawn
 * with hard-edged primitives (rectangles, square-brush lines, filled marker
 * shapes) into a framebuffer of linear values; colours are given as display
 * sRGB and decoded once when set. */
#include "img_plot.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "img_falsecolor.h"
#include "img_io.h"

#define MAX_TICKS 32

/* Okabe & Ito's colour-blind-safe palette (display sRGB), black last. */
static const float palette[7][3] = {
    {0.000f, 0.447f, 0.698f}, /* blue */
    {0.835f, 0.369f, 0.000f}, /* vermillion */
    {0.000f, 0.620f, 0.451f}, /* bluish green */
    {0.800f, 0.475f, 0.655f}, /* reddish purple */
    {0.902f, 0.624f, 0.000f}, /* orange */
    {0.337f, 0.706f, 0.914f}, /* sky blue */
    {0.000f, 0.000f, 0.000f}, /* black */
};

void img_plot_color(int i, float srgb[3])
{
    int k = ((i % 7) + 7) % 7;
    for (int c = 0; c < 3; c++) srgb[c] = palette[k][c];
}

void img_plot_default_opts(img_plot_opts *o)
{
    memset(o, 0, sizeof *o);
    o->width = 720;
    o->height = 480;
    o->x_log = -1;
    o->y_log = -1;
}

/* ---- drawing primitives ---------------------------------------------------- */

typedef struct {
    framebuffer *fb;
    int cx0, cy0, cx1, cy1; /* clip rectangle, inclusive */
} canvas;

static void set_px(const canvas *c, int x, int y, const float lin[3])
{
    if (x < c->cx0 || y < c->cy0 || x > c->cx1 || y > c->cy1) return;
    float *p = fb_px(c->fb, x, y);
    p[0] = lin[0];
    p[1] = lin[1];
    p[2] = lin[2];
}

static void to_linear(const float srgb[3], float lin[3])
{
    for (int k = 0; k < 3; k++) lin[k] = (float)img_srgb_decode((double)srgb[k]);
}

static void fill_rect(const canvas *c, int x0, int y0, int x1, int y1, const float lin[3])
{
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) set_px(c, x, y, lin);
}

/* A line with a square brush of half-width r (Bresenham). */
static void line(const canvas *c, int x0, int y0, int x1, int y1, int r, const float lin[3])
{
    int dx = abs(x1 - x0), dy = -abs(y1 - y0);
    int sx = x0 < x1 ? 1 : -1, sy = y0 < y1 ? 1 : -1;
    int err = dx + dy;
    for (;;) {
        fill_rect(c, x0 - r, y0 - r, x0 + r, y0 + r, lin);
        if (x0 == x1 && y0 == y1) break;
        int e2 = 2 * err;
        if (e2 >= dy) {
            err += dy;
            x0 += sx;
        }
        if (e2 <= dx) {
            err += dx;
            y0 += sy;
        }
    }
}

/* Filled marker of radius r centred on (x, y): square, circle, triangle,
 * diamond by `shape` (mod 4). */
static void marker(const canvas *c, int x, int y, int r, int shape, const float lin[3])
{
    for (int j = -r; j <= r; j++) {
        for (int i = -r; i <= r; i++) {
            int in = 0;
            switch (((shape % 4) + 4) % 4) {
            case 0: in = 1; break;
            case 1: in = i * i + j * j <= r * r + r; break;
            case 2: in = 2 * abs(i) <= j + r; break; /* apex up: wider towards the bottom */
            default: in = abs(i) + abs(j) <= r; break;
            }
            if (in) set_px(c, x + i, y + j, lin);
        }
    }
}

/* Text through img_fc_text, clipped to the whole picture. */
static void text(framebuffer *fb, int x, int y, int s, const char *t, const float srgb[3])
{
    img_fc_text(fb, x, y, s, t, srgb);
}

/* ---- axes ------------------------------------------------------------------- */

/* A short tick label: "0.25", "120", "1e-4", "2e6", "-3". */
static void img_plot_label(double v, char *buf, int n)
{
    if (n <= 0) return;
    double a = fabs(v);
    if (a == 0.0 || !isfinite(v)) {
        snprintf(buf, (size_t)n, "%s", isfinite(v) ? "0" : "nan");
        return;
    }
    if (a >= 1e-3 && a < 1e5) {
        snprintf(buf, (size_t)n, "%.4g", v);
        return;
    }
    char tmp[48];
    snprintf(tmp, sizeof tmp, "%.1e", v); /* "-2.5e-05" */
    char *e = strchr(tmp, 'e');
    if (!e) {
        snprintf(buf, (size_t)n, "%s", tmp);
        return;
    }
    *e = 0;
    char mant[48];
    snprintf(mant, sizeof mant, "%s", tmp);
    size_t ml = strlen(mant);
    if (ml >= 2 && strcmp(mant + ml - 2, ".0") == 0) mant[ml - 2] = 0;
    int ex = atoi(e + 1);
    snprintf(buf, (size_t)n, "%se%d", mant, ex);
}

static double clean_zero(double t, double step) { return fabs(t) < step * 1e-9 ? 0.0 : t; }

/* Axis range and ticks for data in [lo, hi] (lo <= hi, both finite; > 0 for
 * log). The range is padded by 5% of its span (measured in decades on a log
 * axis, at least 0.05 decade there); a single value gets +-10% of itself
 * (+-1 at 0) or +-half a decade. Ticks are chosen at
 * 1, 2, 5 x 10^k (linear) or at decades, with 2 and 5 added when the range
 * spans fewer than two decades (log). Writes at most `max` ticks inside
 * [*axis_lo, *axis_hi], returns their number. */
static int img_plot_axis(double lo, double hi, int log_scale, double *axis_lo, double *axis_hi, double *ticks, int max)
{
    int nt = 0;
    if (log_scale) {
        double a = log10(lo), b = log10(hi);
        if (b - a < 1e-12) {
            a -= 0.5;
            b += 0.5;
        } else {
            double pad = fmax(0.05, 0.05 * (b - a));
            a -= pad;
            b += pad;
        }
        *axis_lo = pow(10.0, a);
        *axis_hi = pow(10.0, b);
        static const int m1[] = {1}, m3[] = {1, 2, 5}, m9[] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
        const int *m = m9;
        int nm = 9;
        if (b - a >= 2.0) {
            m = m1;
            nm = 1;
        } else if (b - a >= 0.7) {
            m = m3;
            nm = 3;
        }
        int step = 1;
        /* Thin out decades so at most ~8 ticks remain. */
        if (nm == 1 && (b - a) > 8) step = (int)ceil((b - a) / 8);
        for (int k = (int)floor(a); k <= (int)ceil(b) && nt < max; k++) {
            if (nm == 1 && ((k % step) + step) % step) continue;
            for (int i = 0; i < nm && nt < max; i++) {
                double t = m[i] * pow(10.0, k);
                double lt = log10(t);
                if (lt >= a - 1e-9 && lt <= b + 1e-9) ticks[nt++] = t;
            }
        }
        return nt;
    }
    double a = lo, b = hi;
    if (b - a <= 1e-12 * fmax(fabs(a), fabs(b))) {
        double h = a != 0.0 ? 0.1 * fabs(a) : 1.0;
        a -= h;
        b += h;
    } else {
        double pad = 0.05 * (b - a);
        a -= pad;
        b += pad;
    }
    *axis_lo = a;
    *axis_hi = b;
    double raw = (b - a) / 5.0;
    double mag = pow(10.0, floor(log10(raw)));
    double norm = raw / mag;
    double step = (norm < 1.5 ? 1.0 : norm < 3.5 ? 2.0 : norm < 7.5 ? 5.0 : 10.0) * mag;
    for (double k = ceil(a / step); nt < max; k += 1.0) {
        double t = clean_zero(k * step, step);
        if (t > b + step * 1e-9) break;
        ticks[nt++] = t;
    }
    return nt;
}

typedef struct {
    int log_scale;
    double lo, hi;     /* axis range (data units) */
    int p0, p1;        /* pixel positions of lo and hi */
} axis_map;

static double map_pos(const axis_map *m, double v)
{
    double t = m->log_scale ? (log10(v) - log10(m->lo)) / (log10(m->hi) - log10(m->lo)) : (v - m->lo) / (m->hi - m->lo);
    return m->p0 + t * (m->p1 - m->p0);
}

static int drawable(double v, int log_scale) { return isfinite(v) && (!log_scale || v > 0.0); }

/* Data range of one coordinate over all series; 0 when there is no point. */
static int data_range(const img_plot_series *s, int ns, int use_y, int x_log, int y_log, double *lo, double *hi)
{
    int any = 0;
    for (int i = 0; i < ns; i++) {
        for (int k = 0; k < s[i].n; k++) {
            double x = s[i].x[k], y = s[i].y[k];
            if (!drawable(x, x_log) || !drawable(y, y_log)) continue;
            double v = use_y ? y : x;
            if (!any || v < *lo) *lo = v;
            if (!any || v > *hi) *hi = v;
            any = 1;
        }
    }
    return any;
}

/* Automatic scale choice: log when every finite value is > 0 and max/min > 10. */
static int auto_log(const img_plot_series *s, int ns, int use_y)
{
    double lo = 0, hi = 0;
    int any = 0;
    for (int i = 0; i < ns; i++) {
        for (int k = 0; k < s[i].n; k++) {
            double v = use_y ? s[i].y[k] : s[i].x[k];
            if (!isfinite(v)) continue;
            if (v <= 0.0) return 0;
            if (!any || v < lo) lo = v;
            if (!any || v > hi) hi = v;
            any = 1;
        }
    }
    return any && hi > 10.0 * lo;
}

typedef struct {
    double x, y;
} point;

static int cmp_point(const void *a, const void *b)
{
    double xa = ((const point *)a)->x, xb = ((const point *)b)->x;
    return xa < xb ? -1 : xa > xb;
}

pt_status img_plot(const img_plot_series *s, int ns, const img_plot_opts *o, framebuffer **out, diag *d)
{
    if (!out) return PT_ERR_USAGE;
    *out = NULL;
    img_plot_opts def;
    if (!o) {
        img_plot_default_opts(&def);
        o = &def;
    }
    if (ns < 0 || (ns > 0 && !s) || o->width < 160 || o->height < 120 || o->width > 8192 || o->height > 8192) {
        diag_error(d, "plot: invalid size %dx%d or series count %d", o->width, o->height, ns);
        return PT_ERR_USAGE;
    }
    for (int i = 0; i < ns; i++) {
        if (s[i].n < 0 || (s[i].n > 0 && (!s[i].x || !s[i].y))) {
            diag_error(d, "plot: series %d is invalid", i);
            return PT_ERR_USAGE;
        }
    }
    const int W = o->width, H = o->height;
    framebuffer *fb = fb_new(W, H);
    if (!fb) {
        diag_error(d, "plot: out of memory for %dx%d", W, H);
        return PT_ERR_NOMEM;
    }
    for (size_t i = 0; i < (size_t)W * (size_t)H * 3u; i++) fb->rgb[i] = 1.0f;

    int x_log = o->x_log < 0 ? auto_log(s, ns, 0) : o->x_log != 0;
    int y_log = o->y_log < 0 ? auto_log(s, ns, 1) : o->y_log != 0;
    double xlo = 0, xhi = 1, ylo = 0, yhi = 1;
    int any = data_range(s, ns, 0, x_log, y_log, &xlo, &xhi);
    data_range(s, ns, 1, x_log, y_log, &ylo, &yhi);
    if (!any) {
        x_log = y_log = 0;
        xlo = ylo = 0.0;
        xhi = yhi = 1.0;
    }
    axis_map mx = {x_log, 0, 0, 0, 0}, my = {y_log, 0, 0, 0, 0};
    double xt[MAX_TICKS], yt[MAX_TICKS];
    int nxt = img_plot_axis(xlo, xhi, x_log, &mx.lo, &mx.hi, xt, MAX_TICKS);
    int nyt = img_plot_axis(ylo, yhi, y_log, &my.lo, &my.hi, yt, MAX_TICKS);

    /* Layout. */
    const int sc = H >= 360 && W >= 480 ? 2 : 1;
    const int th = 7 * sc, tick = 4 * sc;
    char lab[32];
    int ylab_w = 0;
    for (int i = 0; i < nyt; i++) {
        img_plot_label(yt[i], lab, sizeof lab);
        int w = img_fc_text_width(lab, sc);
        if (w > ylab_w) ylab_w = w;
    }
    const int left = 6 * sc + ylab_w + 3 * sc + tick;
    const int right = 16 * sc;
    const int top = o->y_label ? th + 10 * sc : 10 * sc;
    const int bottom = tick + 3 * sc + th + (o->x_label ? 6 * sc + th : 0) + 6 * sc;
    const int px0 = left, px1 = W - 1 - right, py0 = top, py1 = H - 1 - bottom;
    mx.p0 = px0;
    mx.p1 = px1;
    my.p0 = py1; /* y grows upwards */
    my.p1 = py0;

    canvas all = {fb, 0, 0, W - 1, H - 1};
    canvas plot = {fb, px0, py0, px1, py1};
    static const float black_s[3] = {0, 0, 0}, grid_s[3] = {0.88f, 0.88f, 0.88f}, grey_s[3] = {0.55f, 0.55f, 0.55f};
    float black[3], grid[3], grey[3], white[3] = {1, 1, 1};
    to_linear(black_s, black);
    to_linear(grid_s, grid);
    to_linear(grey_s, grey);

    /* Grid, frame, ticks, labels. */
    int last_x_label_end = -1000000;
    for (int i = 0; i < nxt; i++) {
        int x = (int)lround(map_pos(&mx, xt[i]));
        line(&plot, x, py0, x, py1, 0, grid);
        line(&all, x, py1, x, py1 + tick, 0, black);
        img_plot_label(xt[i], lab, sizeof lab);
        int w = img_fc_text_width(lab, sc);
        int lx = x - w / 2;
        if (lx < 0) lx = 0;
        if (lx + w > W - 1) lx = W - 1 - w;
        if (lx > last_x_label_end + 4 * sc) {
            text(fb, lx, py1 + tick + 3 * sc, sc, lab, black_s);
            last_x_label_end = lx + w;
        }
    }
    int last_y_label_top = 1000000;
    for (int i = 0; i < nyt; i++) {
        int y = (int)lround(map_pos(&my, yt[i]));
        line(&plot, px0, y, px1, y, 0, grid);
        line(&all, px0 - tick, y, px0, y, 0, black);
        img_plot_label(yt[i], lab, sizeof lab);
        int w = img_fc_text_width(lab, sc);
        int ly = y - th / 2;
        if (ly < 0) ly = 0;
        if (ly + th > H) ly = H - th;
        if (ly + th + 2 * sc < last_y_label_top) {
            text(fb, px0 - tick - 3 * sc - w, ly, sc, lab, black_s);
            last_y_label_top = ly;
        }
    }
    line(&all, px0, py0, px1, py0, 0, black);
    line(&all, px0, py1, px1, py1, 0, black);
    line(&all, px0, py0, px0, py1, 0, black);
    line(&all, px1, py0, px1, py1, 0, black);
    if (o->x_label) {
        int w = img_fc_text_width(o->x_label, sc);
        text(fb, (px0 + px1) / 2 - w / 2, py1 + tick + 3 * sc + th + 6 * sc, sc, o->x_label, black_s);
    }
    if (o->y_label) text(fb, 6 * sc, 4 * sc, sc, o->y_label, black_s);

    /* Series. */
    int maxn = 0;
    for (int i = 0; i < ns; i++)
        if (s[i].n > maxn) maxn = s[i].n;
    point *pts = maxn ? malloc((size_t)maxn * sizeof *pts) : NULL;
    if (maxn && !pts) {
        fb_free(fb);
        diag_error(d, "plot: out of memory");
        return PT_ERR_NOMEM;
    }
    const int lw = sc >= 2 ? 1 : 0, mr = 3 * sc;
    for (int i = 0; i < ns; i++) {
        float cs[3], cl[3];
        img_plot_color(i, cs);
        to_linear(cs, cl);
        int np = 0;
        for (int k = 0; k < s[i].n; k++) {
            if (!drawable(s[i].x[k], x_log) || !drawable(s[i].y[k], y_log)) continue;
            pts[np].x = s[i].x[k];
            pts[np].y = s[i].y[k];
            np++;
        }
        qsort(pts, (size_t)np, sizeof *pts, cmp_point);
        for (int k = 0; k + 1 < np; k++)
            line(&plot, (int)lround(map_pos(&mx, pts[k].x)), (int)lround(map_pos(&my, pts[k].y)),
                 (int)lround(map_pos(&mx, pts[k + 1].x)), (int)lround(map_pos(&my, pts[k + 1].y)), lw, cl);
        for (int k = 0; k < np; k++)
            marker(&plot, (int)lround(map_pos(&mx, pts[k].x)), (int)lround(map_pos(&my, pts[k].y)), mr, i, cl);
    }
    free(pts);

    /* Legend, top right inside the plot. */
    int named = 0, name_w = 0;
    for (int i = 0; i < ns; i++) {
        if (!s[i].name) continue;
        named++;
        int w = img_fc_text_width(s[i].name, sc);
        if (w > name_w) name_w = w;
    }
    if (named) {
        const int row = th + 5 * sc, sw = 18 * sc;
        int bw = 4 * sc + sw + 4 * sc + name_w + 5 * sc, bh = 4 * sc + named * row;
        int bx1 = px1 - 6 * sc, bx0 = bx1 - bw, by0 = py0 + 6 * sc, by1 = by0 + bh;
        if (bx0 < px0 + 1) bx0 = px0 + 1;
        fill_rect(&plot, bx0, by0, bx1, by1, white);
        line(&plot, bx0, by0, bx1, by0, 0, grey);
        line(&plot, bx0, by1, bx1, by1, 0, grey);
        line(&plot, bx0, by0, bx0, by1, 0, grey);
        line(&plot, bx1, by0, bx1, by1, 0, grey);
        int r = 0;
        for (int i = 0; i < ns; i++) {
            if (!s[i].name) continue;
            float cs[3], cl[3];
            img_plot_color(i, cs);
            to_linear(cs, cl);
            int yc = by0 + 4 * sc + r * row + th / 2;
            line(&plot, bx0 + 4 * sc, yc, bx0 + 4 * sc + sw, yc, lw, cl);
            marker(&plot, bx0 + 4 * sc + sw / 2, yc, mr, i, cl);
            text(fb, bx0 + 8 * sc + sw, yc - th / 2, sc, s[i].name, black_s);
            r++;
        }
    }
    *out = fb;
    return PT_OK;
}
