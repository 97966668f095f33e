/* img_falsecolor.c - log-scale false-colour maps with a legend, and their
 * inverse. The ramp is a polyline through eight display sRGB colours with
 * its knots spaced by the Euclidean length of each segment, so equal steps of
 * t are equal steps of colour; that keeps the inverse equally precise along
 * the whole ramp. The ramp is 5.1 sRGB units long (~1300 8-bit codes): with a
 * 4-decade range one code along it is ~0.7% of value. The legend's text
 * uses a 5x7 pixel font drawn for this file. */
#include "img_falsecolor.h"
#include "img_io.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- the ramp ------------------------------------------------------------- */

#define NKNOTS 8
static const float knots[NKNOTS][3] = {
    {0.00f, 0.00f, 0.40f}, /* dark blue */
    {0.00f, 0.30f, 1.00f}, /* blue */
    {0.00f, 0.90f, 1.00f}, /* cyan */
    {0.10f, 0.85f, 0.10f}, /* green */
    {1.00f, 1.00f, 0.00f}, /* yellow */
    {1.00f, 0.50f, 0.00f}, /* orange */
    {1.00f, 0.00f, 0.00f}, /* red */
    {1.00f, 0.60f, 0.80f}, /* pink */
};

/* Ramp position of each knot: cumulative segment length, normalised. */
static void knot_positions(double pos[NKNOTS])
{
    pos[0] = 0.0;
    for (int i = 1; i < NKNOTS; i++) {
        double s = 0;
        for (int k = 0; k < 3; k++) s += ((double)knots[i][k] - knots[i - 1][k]) * ((double)knots[i][k] - knots[i - 1][k]);
        pos[i] = pos[i - 1] + sqrt(s);
    }
    for (int i = 1; i < NKNOTS; i++) pos[i] /= pos[NKNOTS - 1];
}

void img_fc_ramp(double t, float srgb[3])
{
    double pos[NKNOTS];
    knot_positions(pos);
    if (!(t > 0.0)) t = 0.0; /* also NaN */
    if (t > 1.0) t = 1.0;
    int i = 1;
    while (i < NKNOTS - 1 && t > pos[i]) i++;
    double f = (t - pos[i - 1]) / (pos[i] - pos[i - 1]);
    for (int k = 0; k < 3; k++) srgb[k] = (float)(knots[i - 1][k] + f * ((double)knots[i][k] - knots[i - 1][k]));
}

double img_fc_unramp(const float srgb[3], double *dist)
{
    double pos[NKNOTS];
    knot_positions(pos);
    double best_t = 0.0, best_d2 = INFINITY;
    for (int i = 1; i < NKNOTS; i++) {
        double ab[3], ap[3], l2 = 0, dot = 0;
        for (int k = 0; k < 3; k++) {
            ab[k] = (double)knots[i][k] - knots[i - 1][k];
            ap[k] = (double)srgb[k] - knots[i - 1][k];
            l2 += ab[k] * ab[k];
            dot += ab[k] * ap[k];
        }
        double f = l2 > 0 ? dot / l2 : 0.0;
        if (f < 0) f = 0;
        if (f > 1) f = 1;
        double d2 = 0;
        for (int k = 0; k < 3; k++) d2 += (ap[k] - f * ab[k]) * (ap[k] - f * ab[k]);
        if (d2 < best_d2) {
            best_d2 = d2;
            best_t = pos[i - 1] + f * (pos[i] - pos[i - 1]);
        }
    }
    if (dist) *dist = sqrt(best_d2);
    return best_t;
}

double img_fc_position(double value, double lo, double hi)
{
    if (!(value > 0.0) || !(lo > 0.0) || !(hi > lo)) return NAN;
    double t = (log10(value) - log10(lo)) / (log10(hi) - log10(lo));
    return t < 0 ? 0 : t > 1 ? 1 : t;
}

double img_fc_value_at(double t, double lo, double hi)
{
    if (!(lo > 0.0) || !(hi > lo)) return NAN;
    return pow(10.0, log10(lo) + t * (log10(hi) - log10(lo)));
}

/* ---- inputs --------------------------------------------------------------- */

void img_fc_default_opts(img_fc_opts *o)
{
    if (!o) return;
    memset(o, 0, sizeof *o);
    o->legend = 1;
}

float *img_fc_luminance(const framebuffer *fb, double scale)
{
    if (!fb || !fb->rgb || fb->width <= 0 || fb->height <= 0) return NULL;
    size_t n = (size_t)fb->width * (size_t)fb->height;
    float *y = malloc(sizeof(float) * n);
    if (!y) return NULL;
    for (size_t i = 0; i < n; i++) {
        const float *p = fb->rgb + 3 * i;
        y[i] = (float)(scale * (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]));
    }
    return y;
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

pt_status img_fc_auto_range(const float *values, size_t n, double *lo, double *hi, diag *d)
{
    size_t m = 0;
    for (size_t i = 0; i < n; i++) m += isfinite(values[i]) && values[i] > 0.0f;
    if (m == 0) {
        diag_error(d, "false colour: no positive values to choose a range from (give one)");
        return PT_ERR_USAGE;
    }
    float *v = malloc(sizeof(float) * m);
    if (!v) {
        diag_error(d, "false colour: out of memory");
        return PT_ERR_NOMEM;
    }
    m = 0;
    for (size_t i = 0; i < n; i++)
        if (isfinite(values[i]) && values[i] > 0.0f) v[m++] = values[i];
    qsort(v, m, sizeof(float), cmp_float);
    double a = v[(size_t)floor(0.005 * (double)(m - 1))];
    double b = v[(size_t)ceil(0.995 * (double)(m - 1))];
    free(v);
    double la = floor(log10(a)), lb = ceil(log10(b));
    if (lb <= la) { /* a single value, or one exact decade */
        la -= 1;
        lb += 1;
    }
    *lo = pow(10.0, la);
    *hi = pow(10.0, lb);
    return PT_OK;
}

double img_fc_probe(const float *values, int w, int h, int x, int y, int r)
{
    double sum = 0;
    long n = 0;
    for (int j = y - r; j <= y + r; j++) {
        if (j < 0 || j >= h) continue;
        for (int i = x - r; i <= x + r; i++) {
            if (i < 0 || i >= w) continue;
            float v = values[(size_t)j * (size_t)w + (size_t)i];
            if (!isfinite(v)) continue;
            sum += v;
            n++;
        }
    }
    return n ? sum / (double)n : NAN;
}

/* ---- the legend ----------------------------------------------------------- */

/* 5x7 glyphs, one byte per row, bit 4 = leftmost column. */
typedef struct {
    char c;
    uint8_t rows[7];
} glyph;

static const glyph font[] = {
    {'0', {0x0e, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0e}}, {'1', {0x04, 0x0c, 0x04, 0x04, 0x04, 0x04, 0x0e}},
    {'2', {0x0e, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1f}}, {'3', {0x1e, 0x01, 0x01, 0x0e, 0x01, 0x01, 0x1e}},
    {'4', {0x02, 0x06, 0x0a, 0x12, 0x1f, 0x02, 0x02}}, {'5', {0x1f, 0x10, 0x1e, 0x01, 0x01, 0x11, 0x0e}},
    {'6', {0x06, 0x08, 0x10, 0x1e, 0x11, 0x11, 0x0e}}, {'7', {0x1f, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0e, 0x11, 0x11, 0x0e, 0x11, 0x11, 0x0e}}, {'9', {0x0e, 0x11, 0x11, 0x0f, 0x01, 0x02, 0x0c}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0c, 0x0c}}, {'-', {0x00, 0x00, 0x00, 0x1f, 0x00, 0x00, 0x00}},
    {'+', {0x00, 0x04, 0x04, 0x1f, 0x04, 0x04, 0x00}}, {'/', {0x01, 0x02, 0x02, 0x04, 0x08, 0x08, 0x10}},
    {'c', {0x00, 0x00, 0x0e, 0x10, 0x10, 0x11, 0x0e}}, {'d', {0x01, 0x01, 0x0d, 0x13, 0x11, 0x13, 0x0d}},
    {'e', {0x00, 0x00, 0x0e, 0x11, 0x1f, 0x10, 0x0e}}, {'i', {0x04, 0x00, 0x0c, 0x04, 0x04, 0x04, 0x0e}},
    {'l', {0x0c, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0e}}, {'m', {0x00, 0x00, 0x1a, 0x15, 0x15, 0x15, 0x15}},
    {'n', {0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11}}, {'r', {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10}},
    {'s', {0x00, 0x00, 0x0f, 0x10, 0x0e, 0x01, 0x1e}}, {'t', {0x08, 0x08, 0x1c, 0x08, 0x08, 0x09, 0x06}},
    {'u', {0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0d}}, {'x', {0x00, 0x00, 0x11, 0x0a, 0x04, 0x0a, 0x11}},
    {'W', {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0a}},
    /* added for plot labels (img_fc_text) */
    {'a', {0x00, 0x00, 0x0e, 0x01, 0x0f, 0x11, 0x0f}}, {'b', {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x1e}},
    {'f', {0x06, 0x09, 0x08, 0x1c, 0x08, 0x08, 0x08}}, {'g', {0x00, 0x0f, 0x11, 0x11, 0x0f, 0x01, 0x0e}},
    {'h', {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x11}}, {'k', {0x10, 0x10, 0x12, 0x14, 0x18, 0x14, 0x12}},
    {'o', {0x00, 0x00, 0x0e, 0x11, 0x11, 0x11, 0x0e}}, {'p', {0x00, 0x1e, 0x11, 0x11, 0x1e, 0x10, 0x10}},
    {'v', {0x00, 0x00, 0x11, 0x11, 0x11, 0x0a, 0x04}}, {'w', {0x00, 0x00, 0x11, 0x11, 0x15, 0x15, 0x0a}},
    {'y', {0x00, 0x00, 0x11, 0x11, 0x0f, 0x01, 0x0e}}, {'z', {0x00, 0x00, 0x1f, 0x02, 0x04, 0x08, 0x1f}},
    {'=', {0x00, 0x00, 0x1f, 0x00, 0x1f, 0x00, 0x00}}, {',', {0x00, 0x00, 0x00, 0x00, 0x0c, 0x04, 0x08}},
    {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}}, {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
    {'_', {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1f}}, {':', {0x00, 0x0c, 0x0c, 0x00, 0x0c, 0x0c, 0x00}},
};

static const uint8_t *glyph_rows(char c)
{
    for (size_t i = 0; i < sizeof font / sizeof font[0]; i++)
        if (font[i].c == c) return font[i].rows;
    return NULL;
}

/* Linear value of a display sRGB component. */
static float lin(float v) { return (float)img_srgb_decode((double)v); }

static void put(framebuffer *fb, int x, int y, const float srgb[3])
{
    if (x < 0 || y < 0 || x >= fb->width || y >= fb->height) return;
    float *p = fb_px(fb, x, y);
    for (int k = 0; k < 3; k++) p[k] = lin(srgb[k]);
}

/* Draw text with its top-left corner at (x, y), glyphs scaled by s; each
 * character advances 6s pixels. */
static void draw_text(framebuffer *fb, int x, int y, int s, const char *text, const float srgb[3])
{
    for (const char *c = text; *c; c++, x += 6 * s) {
        const uint8_t *rows = glyph_rows(*c);
        if (!rows) continue;
        for (int r = 0; r < 7; r++)
            for (int col = 0; col < 5; col++)
                if (rows[r] & (0x10 >> col))
                    for (int dy = 0; dy < s; dy++)
                        for (int dx = 0; dx < s; dx++) put(fb, x + col * s + dx, y + r * s + dy, srgb);
    }
}

int img_fc_text(framebuffer *fb, int x, int y, int s, const char *text, const float srgb[3])
{
    if (!fb || !text) return 0;
    if (s < 1) s = 1;
    draw_text(fb, x, y, s, text, srgb);
    return img_fc_text_width(text, s);
}

int img_fc_text_width(const char *text, int s)
{
    size_t n = text ? strlen(text) : 0;
    if (s < 1) s = 1;
    return n ? (int)n * 6 * s - s : 0;
}

/* A decade label: plain for 0.01 .. 1000, "1e<k>" otherwise. */
static void decade_label(int k, char *buf, size_t n)
{
    if (k >= -2 && k <= 3)
        snprintf(buf, n, "%g", pow(10.0, k));
    else
        snprintf(buf, n, "1e%d", k);
}

/* Any value (the range ends): 3 significant digits. */
static void value_label(double v, char *buf, size_t n)
{
    if (v >= 0.01 && v < 10000.0)
        snprintf(buf, n, "%.3g", v);
    else
        snprintf(buf, n, "%.1e", v);
    /* "1.0e+05" -> "1.0e5", "2.5e-03" -> "2.5e-3" */
    char *e = strchr(buf, 'e');
    if (e) {
        char *p = e + 1;
        int neg = *p == '-';
        if (*p == '+' || *p == '-') p++;
        while (*p == '0' && p[1]) p++;
        char tail[16];
        snprintf(tail, sizeof tail, "%s%s", neg ? "-" : "", p);
        snprintf(e + 1, n - (size_t)(e + 1 - buf), "%s", tail);
    }
}

/* Legend layout for an image of height h. */
typedef struct {
    int s;           /* glyph scale */
    int width;       /* strip width */
    int bar_x, bar_w;
    int bar_top, bar_bottom; /* inclusive rows of the colour bar */
    int text_x;
    int labels;      /* 0: too small for text */
} legend_layout;

static legend_layout layout_legend(int h, const char *unit)
{
    legend_layout L;
    L.s = h >= 480 ? h / 240 : 1;
    if (L.s > 4) L.s = 4;
    const int s = L.s;
    const int chars = 7; /* widest label, e.g. "1.0e-12" */
    int unit_chars = unit ? (int)strlen(unit) : 0;
    if (unit_chars > 12) unit_chars = 12;
    L.labels = h >= 7 * s * 4 + 8 * s;
    L.bar_w = 6 * s + 6;
    L.bar_x = 6 * s;
    L.text_x = L.bar_x + L.bar_w + 5 * s; /* tick 2s, gap 3s */
    int text_w = (chars > unit_chars ? chars : unit_chars) * 6 * s;
    L.width = L.labels ? L.text_x + text_w + 3 * s : L.bar_x + L.bar_w + 6 * s;
    int title = L.labels && unit && *unit ? 7 * s + 4 * s : 0;
    L.bar_top = (L.labels ? 4 * s : 2) + title;
    L.bar_bottom = h - 1 - (L.labels ? 4 * s : 2);
    if (L.bar_bottom <= L.bar_top) {
        L.bar_top = 0;
        L.bar_bottom = h - 1;
    }
    return L;
}

static void draw_legend(framebuffer *fb, int x0, const legend_layout *L, double lo, double hi, const char *unit)
{
    static const float bg[3] = {0.12f, 0.12f, 0.12f}, fg[3] = {1.0f, 1.0f, 1.0f};
    const int s = L->s;
    for (int y = 0; y < fb->height; y++)
        for (int x = x0; x < fb->width; x++) put(fb, x, y, bg);
    const int span = L->bar_bottom - L->bar_top;
    /* Colour bar: top = hi (t = 1), bottom = lo (t = 0). */
    for (int y = L->bar_top; y <= L->bar_bottom; y++) {
        float c[3];
        img_fc_ramp(span > 0 ? (double)(L->bar_bottom - y) / span : 0.0, c);
        for (int x = 0; x < L->bar_w; x++) put(fb, x0 + L->bar_x + x, y, c);
    }
    if (!L->labels) return;
    if (unit && *unit) {
        char u[13];
        snprintf(u, sizeof u, "%s", unit);
        draw_text(fb, x0 + L->bar_x, 3 * s, s, u, fg);
    }
    /* Labels: the ends, then every decade that keeps clear of the others. */
    const int th = 7 * s, gap = 3 * s;
    int used_top[64], used_n = 0;
    char buf[32];
    for (int pass = 0; pass < 2; pass++) {
        double k0 = ceil(log10(lo) - 1e-9), k1 = floor(log10(hi) + 1e-9);
        int n = pass == 0 ? 2 : (int)(k1 - k0) + 1;
        if (n > 64) n = 64;
        for (int i = 0; i < n; i++) {
            double v = pass == 0 ? (i == 0 ? hi : lo) : pow(10.0, k0 + i);
            if (pass == 0)
                value_label(v, buf, sizeof buf);
            else
                decade_label((int)(k0 + i), buf, sizeof buf);
            double t = img_fc_position(v, lo, hi);
            int yc = L->bar_bottom - (int)lround(t * span);
            int top = yc - th / 2;
            if (top < 0) top = 0;
            if (top + th > fb->height) top = fb->height - th;
            int clear = 1;
            for (int j = 0; j < used_n; j++)
                if (abs(used_top[j] - top) < th + gap) clear = 0;
            if (!clear || used_n == 64) continue;
            used_top[used_n++] = top;
            for (int x = 0; x < 2 * s; x++)
                for (int dy = 0; dy < s; dy++) put(fb, x0 + L->bar_x + L->bar_w + x, yc + dy - s / 2, fg);
            draw_text(fb, x0 + L->text_x, top, s, buf, fg);
        }
    }
}

/* ---- the map -------------------------------------------------------------- */

pt_status img_falsecolor(const float *values, int w, int h, const img_fc_opts *o, framebuffer **out,
                         double *lo_used, double *hi_used, diag *d)
{
    if (!out) return PT_ERR_USAGE;
    *out = NULL;
    img_fc_opts defaults;
    if (!o) {
        img_fc_default_opts(&defaults);
        o = &defaults;
    }
    if (!values || w <= 0 || h <= 0 || w > IMG_MAX_SIDE || h > IMG_MAX_SIDE) {
        diag_error(d, "false colour: invalid image");
        return PT_ERR_USAGE;
    }
    double lo = o->lo, hi = o->hi;
    if (lo == 0.0 && hi == 0.0) {
        pt_status st = img_fc_auto_range(values, (size_t)w * (size_t)h, &lo, &hi, d);
        if (st != PT_OK) return st;
    } else if (!(lo > 0.0) || !(hi > lo) || !isfinite(hi)) {
        diag_error(d, "false colour: range %g..%g is invalid (need 0 < low < high)", lo, hi);
        return PT_ERR_USAGE;
    }
    legend_layout L = layout_legend(h, o->unit);
    const int total_w = o->legend ? w + L.width : w;
    if (total_w > IMG_MAX_SIDE) {
        diag_error(d, "false colour: image too wide for a legend");
        return PT_ERR_USAGE;
    }
    framebuffer *fb = fb_new(total_w, h);
    if (!fb) {
        diag_error(d, "false colour: out of memory for %dx%d image", total_w, h);
        return PT_ERR_NOMEM;
    }
    /* Every pixel is mapped exactly (no lookup table: it would round t). */
    const double llo = log10(lo), lspan = log10(hi) - llo;
    for (int y = 0; y < h; y++) {
        for (int x = 0; x < w; x++) {
            float v = values[(size_t)y * (size_t)w + (size_t)x];
            float *p = fb_px(fb, x, y);
            if (!isfinite(v) || v <= 0.0f) {
                p[0] = p[1] = p[2] = 0.0f;
                continue;
            }
            double t = (log10((double)v) - llo) / lspan;
            float c[3];
            img_fc_ramp(t, c);
            for (int k = 0; k < 3; k++) p[k] = lin(c[k]);
        }
    }
    if (o->legend) draw_legend(fb, w, &L, lo, hi, o->unit);
    if (lo_used) *lo_used = lo;
    if (hi_used) *hi_used = hi;
    *out = fb;
    return PT_OK;
}
