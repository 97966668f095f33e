/* img_metrics.c - RMSE, relative MSE, PSNR, SSIM, FLIP pooling, heat maps.
 * Definitions are in img_metrics.h. */
#include "img_metrics.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "img_flip.h"
#include "img_io.h"
#include "pool.h"

static double fin(float v)
{
    return isfinite(v) ? (double)v : 0.0;
}

static double clamp01(double v)
{
    return v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v);
}

static pt_status check_pair(const framebuffer *ref, const framebuffer *test, const char *what, diag *d)
{
    if (!ref || !test || !ref->rgb || !test->rgb || ref->width <= 0 || ref->height <= 0) {
        diag_report(d, DIAG_ERROR, (src_loc){0}, NULL, "%s: missing or empty image", what);
        return PT_ERR_USAGE;
    }
    if (ref->width != test->width || ref->height != test->height) {
        diag_report(d, DIAG_ERROR, (src_loc){0}, NULL,
                    "%s: image sizes differ: reference %dx%d, test %dx%d", what,
                    ref->width, ref->height, test->width, test->height);
        return PT_ERR_USAGE;
    }
    return PT_OK;
}

/* ---- RMSE, relMSE, PSNR ---- */

/* Per-channel sums over the pixels of the squared error test - ref,
 * divided by ref^2 + 0.01 when relative (relMSE). */
static void error_sums(const framebuffer *ref, const framebuffer *test, int relative, double s[3])
{
    size_t n = (size_t)ref->width * (size_t)ref->height;
    s[0] = s[1] = s[2] = 0.0;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            double r = fin(ref->rgb[3 * i + (size_t)c]);
            double e = fin(test->rgb[3 * i + (size_t)c]) - r;
            s[c] += relative ? e * e / (r * r + 0.01) : e * e;
        }
}

pt_status img_rmse(const framebuffer *ref, const framebuffer *test, double *all, double ch[3], diag *d)
{
    pt_status st = check_pair(ref, test, "RMSE", d);
    if (st != PT_OK) return st;
    double n = (double)ref->width * (double)ref->height, s[3];
    error_sums(ref, test, 0, s);
    if (all) *all = sqrt((s[0] + s[1] + s[2]) / (3.0 * n));
    if (ch)
        for (int c = 0; c < 3; c++) ch[c] = sqrt(s[c] / n);
    return PT_OK;
}

pt_status img_relmse(const framebuffer *ref, const framebuffer *test, double *all, double ch[3], diag *d)
{
    pt_status st = check_pair(ref, test, "relMSE", d);
    if (st != PT_OK) return st;
    double n = (double)ref->width * (double)ref->height, s[3];
    error_sums(ref, test, 1, s);
    if (all) *all = (s[0] + s[1] + s[2]) / (3.0 * n);
    if (ch)
        for (int c = 0; c < 3; c++) ch[c] = s[c] / n;
    return PT_OK;
}

pt_status img_psnr(const framebuffer *ref, const framebuffer *test, double *psnr, diag *d)
{
    pt_status st = check_pair(ref, test, "PSNR", d);
    if (st != PT_OK) return st;
    size_t n = (size_t)ref->width * (size_t)ref->height * 3u;
    double s = 0.0;
    for (size_t i = 0; i < n; i++) {
        double e = clamp01(fin(test->rgb[i])) - clamp01(fin(ref->rgb[i]));
        s += e * e;
    }
    double mse = s / (double)n;
    *psnr = mse > 0.0 ? 10.0 * log10(1.0 / mse) : INFINITY;
    return PT_OK;
}

/* ---- SSIM (Wang et al. 2004) ---- */

#define SSIM_K1 0.01
#define SSIM_K2 0.03
#define SSIM_L 1.0
#define SSIM_SIGMA 1.5
#define SSIM_RADIUS 5 /* 11x11 window */

/* SSIM is computed in bands of output rows, one job per (channel, band),
 * each with its own scratch; band sums are added in a fixed order, so the
 * result does not depend on the thread count. */
#define SSIM_BAND 32

typedef struct {
    const framebuffer *ref, *test;
    const double *k;
    int r, ow, oh, nbands, nthreads;
    double *scratch;   /* per thread: 5 * w (row products) + 5 * ow * (SSIM_BAND + 2r) */
    size_t per_thread; /* doubles per thread */
    double *band_sum;  /* 3 * nbands */
} ssim_job;

static void ssim_band(void *ctx, int index, int thread)
{
    const ssim_job *j = ctx;
    int c = index / j->nbands, band = index % j->nbands;
    int w = j->ref->width, r = j->r, ow = j->ow, taps = 2 * r + 1;
    int oy0 = band * SSIM_BAND, oy1 = oy0 + SSIM_BAND;
    if (oy1 > j->oh) oy1 = j->oh;
    int rows = oy1 - oy0 + 2 * r; /* input rows oy0 .. oy1 + 2r - 1 */
    double *prod = j->scratch + (size_t)thread * j->per_thread; /* 5 * w */
    double *hp = prod + 5 * (size_t)w;                           /* 5 planes of ow * rows */
    size_t plane = (size_t)ow * (size_t)rows;
    for (int ry = 0; ry < rows; ry++) {
        int y = oy0 + ry;
        for (int x = 0; x < w; x++) {
            size_t o = ((size_t)y * (size_t)w + (size_t)x) * 3u + (size_t)c;
            double a = clamp01(fin(j->ref->rgb[o])), b = clamp01(fin(j->test->rgb[o]));
            prod[x] = a;
            prod[w + x] = b;
            prod[2 * w + x] = a * a;
            prod[3 * w + x] = b * b;
            prod[4 * w + x] = a * b;
        }
        for (int p = 0; p < 5; p++) {
            double *out = hp + (size_t)p * plane + (size_t)ry * (size_t)ow;
            const double *in = prod + (size_t)p * (size_t)w;
            for (int x = 0; x < ow; x++) out[x] = 0.0;
            for (int i = 0; i < taps; i++) {
                double kv = j->k[i];
                for (int x = 0; x < ow; x++) out[x] += kv * in[x + i];
            }
        }
    }
    const double c1 = (SSIM_K1 * SSIM_L) * (SSIM_K1 * SSIM_L);
    const double c2 = (SSIM_K2 * SSIM_L) * (SSIM_K2 * SSIM_L);
    double total = 0.0;
    for (int oy = 0; oy < oy1 - oy0; oy++)
        for (int x = 0; x < ow; x++) {
            double m[5];
            for (int p = 0; p < 5; p++) {
                const double *col = hp + (size_t)p * plane + (size_t)oy * (size_t)ow + (size_t)x;
                double s = 0.0;
                for (int i = 0; i < taps; i++) s += j->k[i] * col[(size_t)i * (size_t)ow];
                m[p] = s;
            }
            double mx = m[0], my = m[1];
            double vx = m[2] - mx * mx, vy = m[3] - my * my, cxy = m[4] - mx * my;
            total += ((2.0 * mx * my + c1) * (2.0 * cxy + c2)) /
                     ((mx * mx + my * my + c1) * (vx + vy + c2));
        }
    j->band_sum[index] = total;
}

pt_status img_ssim(const framebuffer *ref, const framebuffer *test, double *ssim, double ch[3], diag *d)
{
    pt_status st = check_pair(ref, test, "SSIM", d);
    if (st != PT_OK) return st;
    int w = ref->width, h = ref->height;
    int minwh = w < h ? w : h;
    int r = SSIM_RADIUS;
    if (2 * r + 1 > minwh) r = (minwh - 1) / 2;
    double k[2 * SSIM_RADIUS + 1], ks = 0.0;
    for (int i = -r; i <= r; i++) {
        k[i + r] = exp(-(double)(i * i) / (2.0 * SSIM_SIGMA * SSIM_SIGMA));
        ks += k[i + r];
    }
    for (int i = 0; i <= 2 * r; i++) k[i] /= ks;

    ssim_job j;
    j.ref = ref;
    j.test = test;
    j.k = k;
    j.r = r;
    j.ow = w - 2 * r;
    j.oh = h - 2 * r;
    j.nbands = (j.oh + SSIM_BAND - 1) / SSIM_BAND;
    j.nthreads = pool_default_threads();
    if (j.nthreads > 3 * j.nbands) j.nthreads = 3 * j.nbands;
    j.per_thread = 5 * (size_t)w + 5 * (size_t)j.ow * (size_t)(SSIM_BAND + 2 * r);
    j.scratch = malloc((size_t)j.nthreads * j.per_thread * sizeof(double));
    j.band_sum = malloc(3 * (size_t)j.nbands * sizeof(double));
    if (!j.scratch || !j.band_sum) {
        free(j.scratch);
        free(j.band_sum);
        diag_report(d, DIAG_ERROR, (src_loc){0}, NULL, "SSIM: out of memory");
        return PT_ERR_NOMEM;
    }
    pool_run(j.nthreads, 3 * j.nbands, ssim_band, &j);
    double v[3], sum = 0.0;
    for (int c = 0; c < 3; c++) {
        double t = 0.0;
        for (int b = 0; b < j.nbands; b++) t += j.band_sum[c * j.nbands + b];
        v[c] = t / ((double)j.ow * (double)j.oh);
        sum += v[c];
    }
    free(j.scratch);
    free(j.band_sum);
    if (ssim) *ssim = sum / 3.0;
    if (ch)
        for (int c = 0; c < 3; c++) ch[c] = v[c];
    return PT_OK;
}

/* ---- colour scale and heat maps ---- */

/* The magma colour map (matplotlib, by Stefan van der Walt and Nathaniel
 * Smith, CC0; also the FLIP tool's map), sampled at indices 0, 8, ..., 248
 * and 255 of its 256 entries; linear interpolation in between. Display
 * (sRGB-encoded) values. */
static const float magma_knots[33][3] = {
    {0.001462f, 0.000466f, 0.013866f}, {0.013708f, 0.011771f, 0.068667f},
    {0.039608f, 0.031090f, 0.133515f}, {0.074257f, 0.052017f, 0.202660f},
    {0.113094f, 0.065492f, 0.276784f}, {0.159018f, 0.068354f, 0.352688f},
    {0.211718f, 0.061992f, 0.418647f}, {0.265447f, 0.060237f, 0.461840f},
    {0.316654f, 0.071690f, 0.485380f}, {0.366012f, 0.090314f, 0.497960f},
    {0.414709f, 0.110431f, 0.504662f}, {0.463508f, 0.129893f, 0.507652f},
    {0.512831f, 0.148179f, 0.507648f}, {0.562866f, 0.165368f, 0.504692f},
    {0.613617f, 0.181811f, 0.498536f}, {0.664915f, 0.198075f, 0.488836f},
    {0.716387f, 0.214982f, 0.475290f}, {0.767398f, 0.233705f, 0.457755f},
    {0.816914f, 0.255895f, 0.436461f}, {0.863320f, 0.283729f, 0.412403f},
    {0.904281f, 0.319610f, 0.388137f}, {0.937221f, 0.364929f, 0.368567f},
    {0.960949f, 0.418323f, 0.359630f}, {0.976690f, 0.476226f, 0.364466f},
    {0.986700f, 0.535582f, 0.382210f}, {0.992785f, 0.594891f, 0.410283f},
    {0.996096f, 0.653659f, 0.446213f}, {0.997325f, 0.711848f, 0.488154f},
    {0.996898f, 0.769591f, 0.534892f}, {0.995131f, 0.827052f, 0.585701f},
    {0.992440f, 0.884330f, 0.640099f}, {0.989434f, 0.941470f, 0.697519f},
    {0.987053f, 0.991438f, 0.749504f},
};

void img_magma(double t, float rgb[3])
{
    if (!(t >= 0.0)) t = 0.0;
    if (t > 1.0) t = 1.0;
    double idx = t * 255.0; /* position in the 256-entry map */
    int k = (int)(idx / 8.0);
    if (k > 31) k = 31;
    double i0 = 8.0 * k, i1 = k == 31 ? 255.0 : 8.0 * (k + 1);
    double f = (idx - i0) / (i1 - i0);
    if (f > 1.0) f = 1.0;
    for (int c = 0; c < 3; c++)
        rgb[c] = (float)((1.0 - f) * magma_knots[k][c] + f * magma_knots[k + 1][c]);
}

/* A 3x5 pixel font for numeric labels: rows top to bottom, 3 bits each
 * (4 = left column). */
static const char glyph_chars[] = "0123456789.-+e";
static const unsigned char glyphs[][5] = {
    {7, 5, 5, 5, 7}, {2, 6, 2, 2, 7}, {7, 1, 7, 4, 7}, {7, 1, 7, 1, 7}, {5, 5, 7, 1, 1},
    {7, 4, 7, 1, 7}, {7, 4, 7, 5, 7}, {7, 1, 1, 1, 1}, {7, 5, 7, 5, 7}, {7, 5, 7, 1, 7},
    {0, 0, 0, 0, 2}, {0, 0, 7, 0, 0}, {0, 2, 7, 2, 0}, {3, 5, 7, 4, 3},
};

static void put_px(framebuffer *fb, int x, int y, const float lin[3])
{
    if (x < 0 || y < 0 || x >= fb->width || y >= fb->height) return;
    float *p = fb_px(fb, x, y);
    p[0] = lin[0];
    p[1] = lin[1];
    p[2] = lin[2];
}

/* Width in pixels of `s` at scale `sc` (3 px glyph + 1 px space). */
static int text_width(const char *s, int sc)
{
    int n = (int)strlen(s);
    return n > 0 ? (4 * n - 1) * sc : 0;
}

static void draw_text(framebuffer *fb, int x0, int y0, int sc, const char *s, const float lin[3])
{
    for (int ci = 0; s[ci]; ci++) {
        const char *g = strchr(glyph_chars, s[ci]);
        if (g && *g) {
            const unsigned char *rows = glyphs[g - glyph_chars];
            for (int ry = 0; ry < 5; ry++)
                for (int rx = 0; rx < 3; rx++)
                    if (rows[ry] & (4 >> rx))
                        for (int dy = 0; dy < sc; dy++)
                            for (int dx = 0; dx < sc; dx++)
                                put_px(fb, x0 + (4 * ci + rx) * sc + dx, y0 + ry * sc + dy, lin);
        }
    }
}

static int legend_scale(int w, int h)
{
    int m = w < h ? w : h;
    int sc = m / 128;
    return sc < 1 ? 1 : (sc > 8 ? 8 : sc);
}

int img_heatmap_legend_height(int w, int h)
{
    /* padding 2, bar 6, gap 2, text 5, padding 2 (times the scale) */
    return 17 * legend_scale(w, h);
}

static void format_label(char *buf, size_t n, double v)
{
    snprintf(buf, n, "%.3g", v);
    /* Keep only characters the font has. */
    char *o = buf;
    for (char *p = buf; *p; p++)
        if (strchr(glyph_chars, *p)) *o++ = *p;
    *o = 0;
}

pt_status img_heatmap(const float *v, int w, int h, double vmin, double vmax, int legend,
                      framebuffer **out, diag *d)
{
    *out = NULL;
    if (!v || w <= 0 || h <= 0) {
        diag_report(d, DIAG_ERROR, (src_loc){0}, NULL, "heat map: empty input");
        return PT_ERR_USAGE;
    }
    if (!(vmax > vmin)) vmax = vmin + 1.0;
    int lh = legend ? img_heatmap_legend_height(w, h) : 0;
    framebuffer *fb = fb_new(w, h + lh);
    if (!fb) {
        diag_report(d, DIAG_ERROR, (src_loc){0}, NULL, "heat map: cannot allocate %dx%d", w, h + lh);
        return PT_ERR_NOMEM;
    }
    /* Linear values for the 256 quantised colours (as an 8-bit map is used). */
    float lut[256][3];
    for (int i = 0; i < 256; i++) {
        float c[3];
        img_magma(i / 255.0, c);
        for (int k = 0; k < 3; k++) lut[i][k] = (float)img_srgb_decode(c[k]);
    }
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double t = (fin(v[(size_t)y * (size_t)w + (size_t)x]) - vmin) / (vmax - vmin);
            int i = (int)(clamp01(t) * 255.0 + 0.5);
            put_px(fb, x, y, lut[i]);
        }
    if (legend) {
        int sc = legend_scale(w, h);
        float bg[3], fg[3];
        bg[0] = bg[1] = bg[2] = (float)img_srgb_decode(0.12);
        fg[0] = fg[1] = fg[2] = 1.0f;
        for (int y = h; y < h + lh; y++)
            for (int x = 0; x < w; x++) put_px(fb, x, y, bg);
        int x0 = 2 * sc, x1 = w - 1 - 2 * sc;
        if (x1 <= x0) {
            x0 = 0;
            x1 = w - 1;
        }
        int by = h + 2 * sc;
        for (int x = x0; x <= x1; x++) {
            double t = x1 > x0 ? (double)(x - x0) / (double)(x1 - x0) : 0.0;
            const float *c = lut[(int)(t * 255.0 + 0.5)];
            for (int y = by; y < by + 6 * sc; y++) put_px(fb, x, y, c);
        }
        char lo[32], mid[32], hi[32];
        format_label(lo, sizeof lo, vmin);
        format_label(mid, sizeof mid, 0.5 * (vmin + vmax));
        format_label(hi, sizeof hi, vmax);
        int ty = by + 8 * sc;
        int wl = text_width(lo, sc), wm = text_width(mid, sc), wh = text_width(hi, sc);
        if (wl + wh + 2 * sc <= x1 - x0 + 1) {
            draw_text(fb, x0, ty, sc, lo, fg);
            draw_text(fb, x1 + 1 - wh, ty, sc, hi, fg);
            int xm = (x0 + x1 + 1 - wm) / 2;
            if (xm > x0 + wl + 2 * sc && xm + wm + 2 * sc < x1 + 1 - wh)
                draw_text(fb, xm, ty, sc, mid, fg);
        }
    }
    *out = fb;
    return PT_OK;
}

pt_status img_abs_error_map(const framebuffer *ref, const framebuffer *test, double vmax, int legend,
                            framebuffer **out, diag *d)
{
    *out = NULL;
    pt_status st = check_pair(ref, test, "error map", d);
    if (st != PT_OK) return st;
    size_t n = (size_t)ref->width * (size_t)ref->height;
    float *e = malloc(n * sizeof *e);
    if (!e) {
        diag_report(d, DIAG_ERROR, (src_loc){0}, NULL, "error map: out of memory");
        return PT_ERR_NOMEM;
    }
    double emax = 0.0;
    for (size_t i = 0; i < n; i++) {
        double s = 0.0;
        for (int c = 0; c < 3; c++)
            s += fabs(fin(test->rgb[3 * i + (size_t)c]) - fin(ref->rgb[3 * i + (size_t)c]));
        e[i] = (float)(s / 3.0);
        if (e[i] > emax) emax = e[i];
    }
    if (!(vmax > 0.0)) vmax = emax > 0.0 ? emax : 1.0;
    st = img_heatmap(e, ref->width, ref->height, 0.0, vmax, legend, out, d);
    free(e);
    return st;
}

/* ---- everything at once ---- */

double img_mean_luminance(const framebuffer *fb, int srgb)
{
    size_t n = (size_t)fb->width * (size_t)fb->height;
    double s = 0.0;
    for (size_t i = 0; i < n; i++) {
        double c[3];
        for (int k = 0; k < 3; k++) {
            double v = fb->rgb[3 * i + (size_t)k];
            c[k] = srgb ? img_srgb_decode(v) : v;
        }
        s += 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    }
    return n ? s / (double)n : 0.0;
}

pt_status img_compare(const framebuffer *ref, const framebuffer *test, int hdr,
                      img_compare_result *r, framebuffer **flip_map_out, diag *d)
{
    if (flip_map_out) *flip_map_out = NULL;
    memset(r, 0, sizeof *r);
    pt_status st = check_pair(ref, test, "compare", d);
    if (st != PT_OK) return st;
    if ((st = img_rmse(ref, test, &r->rmse, r->rmse_ch, d)) != PT_OK) return st;
    if ((st = img_relmse(ref, test, &r->relmse, r->relmse_ch, d)) != PT_OK) return st;
    if ((st = img_psnr(ref, test, &r->psnr, d)) != PT_OK) return st;
    if ((st = img_ssim(ref, test, &r->ssim, r->ssim_ch, d)) != PT_OK) return st;
    r->lum_ref = img_mean_luminance(ref, !hdr);
    r->lum_test = img_mean_luminance(test, !hdr);

    size_t n = (size_t)ref->width * (size_t)ref->height;
    float *err = malloc(n * sizeof *err);
    if (!err) {
        diag_report(d, DIAG_ERROR, (src_loc){0}, NULL, "compare: out of memory");
        return PT_ERR_NOMEM;
    }
    img_flip_params p;
    img_flip_default_params(&p);
    r->flip_hdr = hdr ? 1 : 0;
    if (hdr) {
        st = img_flip_hdr(ref, test, &p, err, d);
        r->exp_start = p.exp_start;
        r->exp_stop = p.exp_stop;
        r->nexposures = p.nexposures;
    } else {
        st = img_flip_ldr(ref, test, &p, err, d);
    }
    if (st == PT_OK) {
        r->flip_mean = img_flip_mean(err, n);
        r->flip_wmedian = img_flip_weighted_percentile(err, n, 0.5);
        if (flip_map_out)
            st = img_heatmap(err, ref->width, ref->height, 0.0, 1.0, 1, flip_map_out, d);
    }
    free(err);
    return st;
}
