/* test_metrics.c - RMSE, relMSE, PSNR, SSIM, FLIP, heat maps.
 * The FLIP validation pairs live in ../shared/flip (PT_FLIP_DATA_DIR); the
 * tests that need them are skipped when that folder is absent. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "diag.h"
#include "framebuffer.h"
#include "img_flip.h"
#include "img_io.h"
#include "img_metrics.h"

#ifndef PT_FLIP_DATA_DIR
#define PT_FLIP_DATA_DIR "../shared/flip"
#endif

static void set_px(framebuffer *fb, int x, int y, float r, float g, float b)
{
    float *p = fb_px(fb, x, y);
    p[0] = r;
    p[1] = g;
    p[2] = b;
}

/* Deterministic pseudo-random numbers in [0,1). */
static double rnd(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return (double)(*s >> 8) / 16777216.0;
}

static framebuffer *random_fb(int w, int h, uint32_t seed, double scale)
{
    framebuffer *fb = fb_new(w, h);
    assert_non_null(fb);
    for (size_t i = 0; i < (size_t)w * (size_t)h * 3u; i++) fb->rgb[i] = (float)(scale * rnd(&seed));
    return fb;
}

/* ---- RMSE, relMSE, PSNR against hand-computed values ---- */

/* ref: (0.5,0.25,0) (1,0.5,0.2); test: (0.6,0.25,0.1) (0.8,0.5,0.2).
 * Differences 0.1,0,0.1 / -0.2,0,0: squared sum 0.06 over 6 values, MSE 0.01,
 * RMSE 0.1, PSNR 20 dB. Per channel: R sqrt(0.05/2), G 0, B sqrt(0.01/2).
 * relMSE: R (0.01/0.26 + 0.04/1.01)/2, G 0, B (0.01/0.01 + 0)/2 = 0.5. */
static void test_rmse_relmse_psnr(void **st)
{
    (void)st;
    framebuffer *r = fb_new(2, 1), *t = fb_new(2, 1);
    set_px(r, 0, 0, 0.5f, 0.25f, 0.0f);
    set_px(r, 1, 0, 1.0f, 0.5f, 0.2f);
    set_px(t, 0, 0, 0.6f, 0.25f, 0.1f);
    set_px(t, 1, 0, 0.8f, 0.5f, 0.2f);
    double all, ch[3];
    assert_int_equal(img_rmse(r, t, &all, ch, NULL), PT_OK);
    assert_true(fabs(all - 0.1) < 1e-6);
    assert_true(fabs(ch[0] - sqrt(0.025)) < 1e-6);
    assert_true(fabs(ch[1]) < 1e-9);
    assert_true(fabs(ch[2] - sqrt(0.005)) < 1e-6);

    double rel_r = (0.01 / 0.26 + 0.04 / 1.01) / 2.0;
    assert_int_equal(img_relmse(r, t, &all, ch, NULL), PT_OK);
    assert_true(fabs(ch[0] - rel_r) < 1e-6);
    assert_true(fabs(ch[1]) < 1e-9);
    assert_true(fabs(ch[2] - 0.5) < 1e-5);
    assert_true(fabs(all - (rel_r + 0.5) / 3.0) < 1e-5);

    double psnr;
    assert_int_equal(img_psnr(r, t, &psnr, NULL), PT_OK);
    assert_true(fabs(psnr - 20.0) < 1e-4);
    assert_int_equal(img_psnr(r, r, &psnr, NULL), PT_OK);
    assert_true(isinf(psnr) && psnr > 0);

    /* PSNR's peak is 1.0 on values clamped to [0,1]: 0.5 vs 1.5 differ by
     * 0.5 after clamping (MSE 0.25, 6.0206 dB); 1 vs 3 not at all. */
    framebuffer *a = fb_new(1, 1), *b = fb_new(1, 1);
    set_px(a, 0, 0, 0.5f, 0.5f, 0.5f);
    set_px(b, 0, 0, 1.5f, 1.5f, 1.5f);
    assert_int_equal(img_psnr(a, b, &psnr, NULL), PT_OK);
    assert_true(fabs(psnr - 10.0 * log10(4.0)) < 1e-9);
    set_px(a, 0, 0, 1.0f, 1.0f, 1.0f);
    set_px(b, 0, 0, 3.0f, 3.0f, 3.0f);
    assert_int_equal(img_psnr(a, b, &psnr, NULL), PT_OK);
    assert_true(isinf(psnr));
    /* RMSE is on unclamped values. */
    assert_int_equal(img_rmse(a, b, &all, NULL, NULL), PT_OK);
    assert_true(fabs(all - 2.0) < 1e-9);
    fb_free(a);
    fb_free(b);
    fb_free(r);
    fb_free(t);
}

static void test_size_mismatch(void **st)
{
    (void)st;
    framebuffer *r = fb_new(4, 4), *t = fb_new(4, 3);
    diag *d = diag_new();
    double v, ch[3];
    assert_int_equal(img_rmse(r, t, &v, ch, d), PT_ERR_USAGE);
    assert_int_equal(img_relmse(r, t, &v, ch, d), PT_ERR_USAGE);
    assert_int_equal(img_psnr(r, t, &v, d), PT_ERR_USAGE);
    assert_int_equal(img_ssim(r, t, &v, ch, d), PT_ERR_USAGE);
    img_compare_result res;
    framebuffer *map = (framebuffer *)1;
    assert_int_equal(img_compare(r, t, 0, &res, &map, d), PT_ERR_USAGE);
    assert_null(map);
    float err[16];
    img_flip_params p;
    img_flip_default_params(&p);
    assert_int_equal(img_flip_ldr(r, t, &p, err, d), PT_ERR_USAGE);
    assert_int_equal(img_flip_hdr(r, t, &p, err, d), PT_ERR_USAGE);
    assert_true(diag_errors(d) >= 7);
    char *msg = diag_format(diag_get(d, 0));
    assert_non_null(strstr(msg, "4x4"));
    assert_non_null(strstr(msg, "4x3"));
    free(msg);
    diag_free(d);
    fb_free(r);
    fb_free(t);
}

/* ---- SSIM ---- */

/* Straightforward SSIM of one channel: for every window position fully
 * inside the image, explicit Gaussian-weighted sums over the window. */
static double ssim_brute(const framebuffer *x, const framebuffer *y, int c, int r)
{
    double wts[11][11], ws = 0;
    for (int j = -r; j <= r; j++)
        for (int i = -r; i <= r; i++) {
            wts[j + r][i + r] = exp(-(i * i + j * j) / (2.0 * 1.5 * 1.5));
            ws += wts[j + r][i + r];
        }
    double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03, total = 0;
    int cnt = 0;
    for (int py = r; py < x->height - r; py++)
        for (int px = r; px < x->width - r; px++) {
            double mx = 0, my = 0;
            for (int j = -r; j <= r; j++)
                for (int i = -r; i <= r; i++) {
                    double wv = wts[j + r][i + r] / ws;
                    mx += wv * fb_px((framebuffer *)x, px + i, py + j)[c];
                    my += wv * fb_px((framebuffer *)y, px + i, py + j)[c];
                }
            double vx = 0, vy = 0, cxy = 0;
            for (int j = -r; j <= r; j++)
                for (int i = -r; i <= r; i++) {
                    double wv = wts[j + r][i + r] / ws;
                    double a = fb_px((framebuffer *)x, px + i, py + j)[c] - mx;
                    double b = fb_px((framebuffer *)y, px + i, py + j)[c] - my;
                    vx += wv * a * a;
                    vy += wv * b * b;
                    cxy += wv * a * b;
                }
            total += (2 * mx * my + c1) * (2 * cxy + c2) / ((mx * mx + my * my + c1) * (vx + vy + c2));
            cnt++;
        }
    return total / cnt;
}

static void test_ssim(void **st)
{
    (void)st;
    double s, ch[3];
    /* Identical images: exactly 1. */
    framebuffer *a = random_fb(32, 24, 7u, 1.0);
    assert_int_equal(img_ssim(a, a, &s, ch, NULL), PT_OK);
    assert_true(fabs(s - 1.0) < 1e-12);

    /* Constant images: sigma = 0, so SSIM = (2ab + C1) / (a^2 + b^2 + C1).
     * a = 0.5, b = 0.25 gives 0.2501 / 0.3126 = 0.80006398. */
    framebuffer *c0 = fb_new(11, 11), *c1 = fb_new(11, 11);
    for (int y = 0; y < 11; y++)
        for (int x = 0; x < 11; x++) {
            set_px(c0, x, y, 0.5f, 0.5f, 0.5f);
            set_px(c1, x, y, 0.25f, 0.5f, 0.25f);
        }
    assert_int_equal(img_ssim(c0, c1, &s, ch, NULL), PT_OK);
    assert_true(fabs(ch[0] - 0.2501 / 0.3126) < 1e-9);
    assert_true(fabs(ch[1] - 1.0) < 1e-12);
    assert_true(fabs(s - (2.0 * 0.2501 / 0.3126 + 1.0) / 3.0) < 1e-9);

    /* A noisy pair: ref random in [0,1], test = ref + uniform noise in
     * [-0.1, 0.1] (clamped); the result matches the brute-force formula
     * per channel, and the pooled value is 0.979202. */
    framebuffer *b = fb_new(32, 24);
    uint32_t seed = 99u;
    for (size_t i = 0; i < 32u * 24u * 3u; i++) {
        double v = a->rgb[i] + 0.2 * (rnd(&seed) - 0.5);
        b->rgb[i] = (float)(v < 0 ? 0 : (v > 1 ? 1 : v));
    }
    assert_int_equal(img_ssim(a, b, &s, ch, NULL), PT_OK);
    double ref_s = 0;
    for (int c = 0; c < 3; c++) {
        double bc = ssim_brute(a, b, c, 5);
        assert_true(fabs(ch[c] - bc) < 1e-9);
        ref_s += bc / 3.0;
    }
    assert_true(fabs(s - ref_s) < 1e-9);
    print_message("SSIM of the noisy pair: %.6f\n", s);
    assert_true(fabs(s - 0.979202) < 1e-6);

    /* Images smaller than the window use the largest odd window that fits. */
    framebuffer *sa = random_fb(7, 9, 3u, 1.0), *sb = random_fb(7, 9, 4u, 1.0);
    assert_int_equal(img_ssim(sa, sb, &s, ch, NULL), PT_OK);
    assert_true(fabs(ch[1] - ssim_brute(sa, sb, 1, 3)) < 1e-9);

    fb_free(sa);
    fb_free(sb);
    fb_free(a);
    fb_free(b);
    fb_free(c0);
    fb_free(c1);
}

/* ---- FLIP ---- */

static void test_flip_identical(void **st)
{
    (void)st;
    framebuffer *a = random_fb(40, 30, 11u, 1.0);
    float err[40 * 30];
    img_flip_params p;
    img_flip_default_params(&p);
    assert_int_equal(img_flip_ldr(a, a, &p, err, NULL), PT_OK);
    for (int i = 0; i < 40 * 30; i++) assert_true(err[i] == 0.0f);

    framebuffer *h = random_fb(40, 30, 12u, 8.0); /* linear HDR values up to 8 */
    img_flip_default_params(&p);
    assert_int_equal(img_flip_hdr(h, h, &p, err, NULL), PT_OK);
    for (int i = 0; i < 40 * 30; i++) assert_true(err[i] == 0.0f);
    assert_true(p.nexposures >= 2);
    assert_true(p.exp_start <= p.exp_stop);
    /* A given range: n = max(2, ceil(stop - start)). */
    img_flip_default_params(&p);
    p.exp_start = -1.0;
    p.exp_stop = 1.5;
    assert_int_equal(img_flip_hdr(h, h, &p, err, NULL), PT_OK);
    assert_int_equal(p.nexposures, 3);
    assert_true(p.exp_start == -1.0 && p.exp_stop == 1.5);
    p.exp_start = 2.0;
    p.nexposures = 0;
    assert_int_equal(img_flip_hdr(h, h, &p, err, NULL), PT_ERR_USAGE); /* start > stop */

    img_compare_result r;
    assert_int_equal(img_compare(a, a, 0, &r, NULL, NULL), PT_OK);
    assert_true(r.flip_mean == 0.0 && r.flip_wmedian == 0.0);
    assert_true(r.rmse == 0.0 && r.relmse == 0.0 && isinf(r.psnr));
    assert_true(fabs(r.ssim - 1.0) < 1e-12);
    fb_free(a);
    fb_free(h);
}

/* Uniform black against uniform white: no features, so FLIP is the remapped
 * colour difference alone (LDR-FLIP paper). Black is L* = 0, white L* = 100
 * with a* = b* = 0, so HyAB = 100. cmax is the HyAB distance between
 * Hunt-adjusted sRGB green and blue, computed here from the textbook sRGB
 * matrix (4 decimals) and CIELAB formulas. */
static void lab_of(double r, double g, double b, double lab[3])
{
    double X = 0.4124 * r + 0.3576 * g + 0.1805 * b;
    double Y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
    double Z = 0.0193 * r + 0.1192 * g + 0.9505 * b;
    double wx = 0.4124 + 0.3576 + 0.1805, wz = 0.0193 + 0.1192 + 0.9505;
    double v[3] = {X / wx, Y, Z / wz}, f[3];
    for (int i = 0; i < 3; i++)
        f[i] = v[i] > pow(6.0 / 29.0, 3) ? cbrt(v[i]) : v[i] / (3 * pow(6.0 / 29.0, 2)) + 4.0 / 29.0;
    lab[0] = 116 * f[1] - 16;
    lab[1] = 500 * (f[0] - f[1]) * 0.01 * lab[0]; /* Hunt-adjusted */
    lab[2] = 200 * (f[1] - f[2]) * 0.01 * lab[0];
}

static void test_flip_black_white(void **st)
{
    (void)st;
    double g[3], b[3];
    lab_of(0, 1, 0, g);
    lab_of(0, 0, 1, b);
    double cmax = pow(fabs(g[0] - b[0]) + hypot(g[1] - b[1], g[2] - b[2]), 0.7);
    double dc = pow(100.0, 0.7);
    double want = 0.95 + (dc - 0.4 * cmax) / (cmax - 0.4 * cmax) * 0.05;

    framebuffer *k = fb_new(24, 24), *w = fb_new(24, 24);
    for (size_t i = 0; i < 24u * 24u * 3u; i++) w->rgb[i] = 1.0f;
    float err[24 * 24];
    img_flip_params p;
    img_flip_default_params(&p);
    assert_int_equal(img_flip_ldr(k, w, &p, err, NULL), PT_OK);
    print_message("FLIP(black, white) = %.6f (hand: %.6f)\n", err[0], want);
    for (int i = 0; i < 24 * 24; i++) assert_true(fabs(err[i] - want) < 1e-3);
    fb_free(k);
    fb_free(w);
}

static void test_flip_pooling(void **st)
{
    (void)st;
    /* Weighted percentiles: sorted 0.1 0.2 0.3 0.4, total 1.0; running sums
     * 0.1 0.3 0.6 1.0 -> the first above 0.5 is at 0.3 (weighted median),
     * above 0.25 at 0.2, above 0.75 at 0.4. */
    float v[4] = {0.4f, 0.1f, 0.3f, 0.2f};
    assert_true(fabs(img_flip_mean(v, 4) - 0.25) < 1e-7);
    assert_true(fabs(img_flip_weighted_percentile(v, 4, 0.5) - 0.3) < 1e-7);
    assert_true(fabs(img_flip_weighted_percentile(v, 4, 0.25) - 0.2) < 1e-7);
    assert_true(fabs(img_flip_weighted_percentile(v, 4, 0.75) - 0.4) < 1e-7);
    /* Histogram form: bins 10, 20, 30, 40 weighted by their centres 0.105,
     * 0.205, 0.305, 0.405 (total 1.02); half is 0.51, reached inside bin 30
     * at (0.51 - 0.31) / 0.305 of its width: 0.01 (30 + 0.2 / 0.305). */
    assert_true(fabs(img_flip_hist_weighted_percentile(v, 4, 0.5) - 0.01 * (30.0 + 0.2 / 0.305)) < 1e-6);
    /* Default viewing conditions: 0.7 m, 3840 px over 0.7 m -> 67.02 ppd. */
    assert_true(fabs(img_flip_ppd(0.7, 3840, 0.7) - 67.0206) < 1e-4);
    assert_true(fabs(IMG_FLIP_DEFAULT_PPD - img_flip_ppd(0.7, 3840, 0.7)) < 1e-9);
}

/* ---- the validation table in ../shared/flip/README.md ---- */

typedef struct {
    const char *name;
    double ldr_mean, ldr_wmed, hdr_mean, hdr_wmed;
} flip_row;

static const flip_row readme_rows[] = {
    {"cornell_direct", 0.435051, 0.497841, 0.595782, 0.960494},
    {"cornell_low", 0.104192, 0.132877, 0.157704, 0.223195},
};

static framebuffer *load(const char *name, const char *ext, int raw)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.%s", PT_FLIP_DATA_DIR, name, ext);
    diag *d = diag_new();
    framebuffer *fb = NULL;
    pt_status s = img_read(path, raw, &fb, d);
    if (s != PT_OK) {
        char *m = diag_count(d) ? diag_format(diag_get(d, 0)) : NULL;
        print_error("cannot read %s: %s\n", path, m ? m : pt_status_name(s));
        free(m);
    }
    diag_free(d);
    assert_int_equal(s, PT_OK);
    return fb;
}

static int have_data(void)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/README.md", PT_FLIP_DATA_DIR);
    return access(path, R_OK) == 0;
}

static void test_flip_readme_ldr(void **st)
{
    (void)st;
    if (!have_data()) {
        print_message("FLIP validation data not found at %s; skipping\n", PT_FLIP_DATA_DIR);
        skip();
    }
    framebuffer *ref = load("cornell", "png", 1);
    for (size_t k = 0; k < sizeof readme_rows / sizeof readme_rows[0]; k++) {
        const flip_row *row = &readme_rows[k];
        framebuffer *test = load(row->name, "png", 1);
        img_compare_result r;
        framebuffer *map = NULL;
        assert_int_equal(img_compare(ref, test, 0, &r, &map, NULL), PT_OK);
        print_message("LDR %-15s mean %.6f (tool %.6f)  weighted median %.6f (tool %.6f)\n",
                      row->name, r.flip_mean, row->ldr_mean, r.flip_wmedian, row->ldr_wmed);
        print_message("    rmse %.5f relmse %.5f psnr %.3f ssim %.5f\n", r.rmse, r.relmse, r.psnr, r.ssim);
        assert_true(fabs(r.flip_mean - row->ldr_mean) < 5e-4);
        assert_true(fabs(r.flip_wmedian - row->ldr_wmed) < 5e-4);
        assert_int_equal(r.flip_hdr, 0);
        assert_non_null(map);
        assert_int_equal(map->width, ref->width);
        assert_int_equal(map->height, ref->height + img_heatmap_legend_height(ref->width, ref->height));
        fb_free(map);
        fb_free(test);
    }
    fb_free(ref);
}

static void test_flip_readme_hdr(void **st)
{
    (void)st;
    if (!have_data()) {
        print_message("FLIP validation data not found at %s; skipping\n", PT_FLIP_DATA_DIR);
        skip();
    }
    framebuffer *ref = load("cornell", "exr", 0);
    double s, e;
    int n;
    assert_int_equal(img_flip_exposures(ref, &s, &e, &n, NULL), PT_OK);
    print_message("HDR exposures %.4f to %.4f, %d (tool: 1.5445 to 4.7584, 4)\n", s, e, n);
    assert_true(fabs(s - 1.5445) < 1e-4);
    assert_true(fabs(e - 4.7584) < 1e-4);
    assert_int_equal(n, 4);
    for (size_t k = 0; k < sizeof readme_rows / sizeof readme_rows[0]; k++) {
        const flip_row *row = &readme_rows[k];
        framebuffer *test = load(row->name, "exr", 0);
        img_compare_result r;
        assert_int_equal(img_compare(ref, test, 1, &r, NULL, NULL), PT_OK);
        print_message("HDR %-15s mean %.6f (tool %.6f)  weighted median %.6f (tool %.6f)\n",
                      row->name, r.flip_mean, row->hdr_mean, r.flip_wmedian, row->hdr_wmed);
        assert_true(fabs(r.flip_mean - row->hdr_mean) < 5e-4);
        assert_true(fabs(r.flip_wmedian - row->hdr_wmed) < 5e-4);
        assert_int_equal(r.flip_hdr, 1);
        assert_int_equal(r.nexposures, 4);
        assert_true(fabs(r.exp_start - 1.5445) < 1e-4 && fabs(r.exp_stop - 4.7584) < 1e-4);
        fb_free(test);
    }
    fb_free(ref);
}

/* ---- heat maps ---- */

static double lin(double e)
{
    return e <= 0.04045 ? e / 12.92 : pow((e + 0.055) / 1.055, 2.4);
}

/* Mean luminance: Rec.709 weights on linear values; on sRGB-encoded values
 * decoded first (encoded 0.5 decodes to ((0.5 + 0.055) / 1.055)^2.4 =
 * 0.2140411, IEC 61966-2-1); img_compare reports both images' means. */
static void test_mean_luminance(void **st)
{
    (void)st;
    framebuffer *r = fb_new(2, 1), *t = fb_new(2, 1);
    float px[6] = {1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.5f};
    for (int i = 0; i < 6; i++) {
        r->rgb[i] = px[i];
        t->rgb[i] = 1.1f * px[i];
    }
    double want = 0.5 * (0.2126 + 0.7152 + 0.0722 * 0.5);
    assert_true(fabs(img_mean_luminance(r, 0) - want) < 1e-12);
    diag *d = diag_new();
    img_compare_result res;
    assert_int_equal(img_compare(r, t, 1, &res, NULL, d), PT_OK);
    assert_true(fabs(res.lum_ref - want) < 1e-12);
    assert_true(fabs(res.lum_test / res.lum_ref - 1.1) < 1e-6);
    for (int i = 0; i < 6; i++) r->rgb[i] = 0.5f;
    assert_true(fabs(img_mean_luminance(r, 1) - 0.2140411) < 1e-6);
    diag_free(d);
    fb_free(r);
    fb_free(t);
}

static void test_heatmap(void **st)
{
    (void)st;
    float c[3];
    img_magma(0.0, c);
    assert_true(fabs(c[0] - 0.001462) < 1e-6 && fabs(c[1] - 0.000466) < 1e-6 && fabs(c[2] - 0.013866) < 1e-6);
    img_magma(1.0, c);
    assert_true(fabs(c[0] - 0.987053) < 1e-6 && fabs(c[1] - 0.991438) < 1e-6 && fabs(c[2] - 0.749504) < 1e-6);
    img_magma(128.0 / 255.0, c); /* entry 128 of the 256-entry map */
    assert_true(fabs(c[0] - 0.716387) < 1e-6 && fabs(c[1] - 0.214982) < 1e-6 && fabs(c[2] - 0.475290) < 1e-6);

    float v[8] = {0.0f, 0.25f, 0.5f, 1.0f, 2.0f, -1.0f, 0.5f, 0.5f};
    framebuffer *fb = NULL;
    assert_int_equal(img_heatmap(v, 4, 2, 0.0, 1.0, 0, &fb, NULL), PT_OK);
    assert_int_equal(fb->width, 4);
    assert_int_equal(fb->height, 2);
    img_magma(0.0, c);
    assert_true(fabs(fb_px(fb, 0, 0)[0] - lin(c[0])) < 1e-6);
    assert_true(fabs(fb_px(fb, 1, 1)[2] - lin(c[2])) < 1e-6); /* -1 clamps to 0 */
    img_magma(1.0, c);
    assert_true(fabs(fb_px(fb, 3, 0)[1] - lin(c[1])) < 1e-6);
    assert_true(fabs(fb_px(fb, 0, 1)[1] - lin(c[1])) < 1e-6); /* 2 clamps to 1 */
    fb_free(fb);

    /* With the legend: a strip below, the colour bar running from magma(0)
     * at the left to magma(1) at the right. */
    float big[256 * 64];
    for (int i = 0; i < 256 * 64; i++) big[i] = 0.5f;
    assert_int_equal(img_heatmap(big, 256, 64, 0.0, 1.0, 1, &fb, NULL), PT_OK);
    int lh = img_heatmap_legend_height(256, 64);
    assert_true(lh > 0);
    assert_int_equal(fb->height, 64 + lh);
    int sc = lh / 17, bary = 64 + 2 * sc + 1;
    img_magma(0.0, c);
    assert_true(fabs(fb_px(fb, 2 * sc, bary)[0] - lin(c[0])) < 1e-6);
    img_magma(1.0, c);
    assert_true(fabs(fb_px(fb, 255 - 2 * sc, bary)[0] - lin(c[0])) < 1e-6);
    fb_free(fb);

    /* Absolute error map: per-pixel mean |t - r| over RGB, auto scale to the max. */
    framebuffer *r = fb_new(2, 1), *t = fb_new(2, 1);
    set_px(t, 0, 0, 0.3f, 0.3f, 0.3f);
    set_px(t, 1, 0, 0.15f, 0.15f, 0.15f);
    assert_int_equal(img_abs_error_map(r, t, 0.0, 0, &fb, NULL), PT_OK);
    img_magma(1.0, c);
    assert_true(fabs(fb_px(fb, 0, 0)[0] - lin(c[0])) < 1e-6);
    img_magma(128.0 / 255.0, c); /* 0.5 -> round(127.5) = 128 */
    assert_true(fabs(fb_px(fb, 1, 0)[0] - lin(c[0])) < 1e-6);
    fb_free(fb);
    fb_free(r);
    fb_free(t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rmse_relmse_psnr),
        cmocka_unit_test(test_size_mismatch),
        cmocka_unit_test(test_ssim),
        cmocka_unit_test(test_flip_identical),
        cmocka_unit_test(test_flip_black_white),
        cmocka_unit_test(test_flip_pooling),
        cmocka_unit_test(test_flip_readme_ldr),
        cmocka_unit_test(test_flip_readme_hdr),
        cmocka_unit_test(test_heatmap),
        cmocka_unit_test(test_mean_luminance),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
