/* test_falsecolor.c - false-colour maps (io/img_falsecolor.h): the ramp and
 * its inverse, 8-bit precision, a point light's illuminance read back from
 * a written PNG, the legend, luminance, errors. Measured values are printed. */
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
#include "img_falsecolor.h"
#include "img_io.h"

/* Display sRGB value of one pixel of a false-colour framebuffer. */
static void display_px(framebuffer *fb, int x, int y, float srgb[3])
{
    const float *p = fb_px(fb, x, y);
    for (int k = 0; k < 3; k++) srgb[k] = (float)img_srgb_encode(p[k]);
}

static void test_ramp_inverse(void **st)
{
    (void)st;
    double worst = 0;
    for (int i = 0; i <= 1000; i++) {
        double t = i / 1000.0, dist = 1;
        float c[3];
        img_fc_ramp(t, c);
        double back = img_fc_unramp(c, &dist);
        worst = fmax(worst, fabs(back - t));
        assert_true(dist < 1e-6);
    }
    printf("ramp -> unramp: max |dt| = %.2e\n", worst);
    assert_true(worst < 1e-6);
    float c[3];
    img_fc_ramp(-1.0, c);
    assert_float_equal(c[2], 0.40, 1e-7); /* clamped to the dark-blue end */
    img_fc_ramp(NAN, c);
    assert_float_equal(c[2], 0.40, 1e-7);
    img_fc_ramp(2.0, c);
    assert_float_equal(c[0], 1.0, 1e-7);
    assert_float_equal(c[1], 0.6, 1e-7);
    /* black (values <= 0) is far from the ramp */
    const float black[3] = {0, 0, 0};
    double dist;
    img_fc_unramp(black, &dist);
    assert_true(dist > 0.3);
    /* log mapping */
    assert_float_equal(img_fc_position(10.0, 1.0, 1000.0), 1.0 / 3.0, 1e-12);
    assert_float_equal(img_fc_value_at(0.5, 1.0, 100.0), 10.0, 1e-9);
    assert_true(isnan(img_fc_position(0.0, 1.0, 10.0)));
}

/* 8-bit codes along the ramp: how far off the value read back is. */
static void test_ramp_8bit_precision(void **st)
{
    (void)st;
    const double decades = 4.0;
    double worst = 0;
    for (int i = 0; i <= 4000; i++) {
        double t = i / 4000.0;
        float c[3], q[3];
        img_fc_ramp(t, c);
        for (int k = 0; k < 3; k++) q[k] = (float)(floor(c[k] * 255.0 + 0.5) / 255.0);
        double back = img_fc_unramp(q, NULL);
        double rel = pow(10.0, fabs(back - t) * decades) - 1.0;
        worst = fmax(worst, rel);
    }
    printf("8-bit false colour over 4 decades: worst value error %.3f%%\n", 100 * worst);
    assert_true(worst < 0.01);
}

/* A point light of I candela at height d over a plane: illuminance
 * E(r) = I d / (d^2 + r^2)^(3/2) lux, E = I/d^2 at the foot. The map is
 * written as an 8-bit PNG, read back, and the colours turned into values. */
static void test_point_light_readback(void **st)
{
    (void)st;
    const double I = 100.0, dh = 2.0, half = 4.0; /* cd, m, plane half-size in m */
    const int n = 201, c = 100;                    /* pixel c = the foot */
    float *E = malloc(sizeof(float) * n * n);
    assert_non_null(E);
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            double px = (x - c) * half / c, py = (y - c) * half / c;
            double r2 = px * px + py * py;
            E[y * n + x] = (float)(I * dh / pow(dh * dh + r2, 1.5));
        }
    diag *d = diag_new();
    img_fc_opts o;
    img_fc_default_opts(&o);
    o.unit = "lx";
    framebuffer *fb = NULL;
    double lo = 0, hi = 0;
    assert_int_equal(img_falsecolor(E, n, n, &o, &fb, &lo, &hi, d), PT_OK);
    printf("point light: auto range %g .. %g lx; map %dx%d\n", lo, hi, fb->width, fb->height);
    /* E runs from 0.926 lx (corners) to 25 lx; the 0.5th percentile is above
     * 1 lx, so the range is 1 .. 100 lx and the corners clamp to 1 lx. */
    assert_float_equal(lo, 1.0, 1e-12);
    assert_float_equal(hi, 100.0, 1e-9);
    assert_true(fb->width > n);

    char dir[] = "/tmp/pt_test_fc_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[64];
    snprintf(path, sizeof path, "%s/fc.png", dir);
    assert_int_equal(img_write(path, fb, NULL, d), PT_OK);
    framebuffer *png = NULL;
    assert_int_equal(img_read(path, 1, &png, d), PT_OK); /* raw codes / 255 */
    unlink(path);
    rmdir(dir);

    const int probes[][2] = {{c, c}, {c + 50, c}, {c, c + 100}, {0, 0}};
    for (size_t i = 0; i < sizeof probes / sizeof probes[0]; i++) {
        int x = probes[i][0], y = probes[i][1];
        const float *p = fb_px(png, x, y);
        double dist;
        double t = img_fc_unramp(p, &dist);
        double v = img_fc_value_at(t, lo, hi);
        double truth = fmax(E[y * n + x], lo);
        double exact = img_fc_probe(E, n, n, x, y, 0);
        printf("  pixel (%d,%d): E = %.4f lx (clamped to the range: %.4f), read from the PNG %.4f lx (%+.2f%%), probe %.4f\n", x, y, E[y * n + x], truth, v,
               100 * (v / truth - 1), exact);
        assert_true(dist < 0.01);
        assert_float_equal(v / truth, 1.0, 0.01);
        assert_float_equal(exact, E[y * n + x], 1e-12);
    }
    /* I/d^2 at the foot */
    assert_float_equal(E[c * n + c], I / (dh * dh), 1e-5);
    fb_free(png);
    fb_free(fb);
    free(E);
    diag_free(d);
}

static void test_legend(void **st)
{
    (void)st;
    diag *d = diag_new();
    const int w = 64, h = 240;
    float *v = malloc(sizeof(float) * w * h);
    for (int i = 0; i < w * h; i++) v[i] = (float)pow(10.0, -1.0 + 3.0 * i / (w * h - 1));
    img_fc_opts o;
    img_fc_default_opts(&o);
    o.unit = "cd/m2";
    framebuffer *fb = NULL;
    double lo, hi;
    assert_int_equal(img_falsecolor(v, w, h, &o, &fb, &lo, &hi, d), PT_OK);
    assert_float_equal(lo, 0.1, 1e-12);
    assert_float_equal(hi, 100.0, 1e-9);
    const int lw = fb->width - w;
    printf("legend strip %d px wide for a %d px high image\n", lw, h);
    assert_true(lw >= 40 && lw <= 120);
    /* The bar: find its column (the first legend column whose rows vary). */
    int bx = -1;
    for (int x = w; x < fb->width && bx < 0; x++) {
        float a[3], b[3];
        display_px(fb, x, h / 2, a);
        display_px(fb, x, h / 2 + 20, b);
        if (fabsf(a[0] - b[0]) + fabsf(a[1] - b[1]) + fabsf(a[2] - b[2]) > 0.05f) bx = x;
    }
    assert_true(bx >= w);
    /* top of the bar = hi end, bottom = lo end */
    int top = -1, bottom = -1;
    for (int y = 0; y < h; y++) {
        float a[3];
        display_px(fb, bx, y, a);
        double dist;
        img_fc_unramp(a, &dist);
        if (dist < 1e-4) {
            if (top < 0) top = y;
            bottom = y;
        }
    }
    float a[3], c1[3], c0[3];
    img_fc_ramp(1.0, c1);
    img_fc_ramp(0.0, c0);
    display_px(fb, bx, top, a);
    for (int k = 0; k < 3; k++) assert_float_equal(a[k], c1[k], 1e-5);
    display_px(fb, bx, bottom, a);
    for (int k = 0; k < 3; k++) assert_float_equal(a[k], c0[k], 1e-5);
    /* text: white pixels right of the bar */
    int white = 0;
    for (int y = 0; y < h; y++)
        for (int x = bx + 1; x < fb->width; x++) white += fb_px(fb, x, y)[0] == 1.0f && fb_px(fb, x, y)[2] == 1.0f;
    printf("legend: bar rows %d..%d, %d text pixels\n", top, bottom, white);
    assert_true(white > 100);
    fb_free(fb);

    /* No legend: the image alone. A tiny image: a bar without text. */
    o.legend = 0;
    assert_int_equal(img_falsecolor(v, w, h, &o, &fb, NULL, NULL, d), PT_OK);
    assert_int_equal(fb->width, w);
    fb_free(fb);
    o.legend = 1;
    assert_int_equal(img_falsecolor(v, w, 8, &o, &fb, NULL, NULL, d), PT_OK);
    assert_true(fb->width > w && fb->width < w + 40);
    fb_free(fb);
    free(v);
    assert_int_equal(diag_count(d), 0);
    diag_free(d);
}

static void test_luminance_and_errors(void **st)
{
    (void)st;
    diag *d = diag_new();
    framebuffer *fb = fb_new(3, 1);
    const float px[9] = {1, 1, 1, 1, 0, 0, 0, 0, 1};
    memcpy(fb->rgb, px, sizeof px);
    float *y = img_fc_luminance(fb, 683.0);
    assert_non_null(y);
    assert_float_equal(y[0], 683.0, 1e-3);
    assert_float_equal(y[1], 0.2126 * 683.0, 1e-3);
    assert_float_equal(y[2], 0.0722 * 683.0, 1e-3);
    free(y);
    fb_free(fb);

    const float vals[4] = {0.0f, -1.0f, NAN, 5.0f};
    framebuffer *out = NULL;
    img_fc_opts o;
    img_fc_default_opts(&o);
    o.legend = 0;
    double lo, hi;
    assert_int_equal(img_falsecolor(vals, 4, 1, &o, &out, &lo, &hi, d), PT_OK);
    assert_float_equal(lo, 1.0, 1e-12); /* 5 -> 1 .. 10 */
    assert_float_equal(hi, 10.0, 1e-9);
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++) assert_float_equal(out->rgb[3 * i + k], 0.0, 0);
    fb_free(out);

    o.lo = 10;
    o.hi = 1;
    assert_int_equal(img_falsecolor(vals, 4, 1, &o, &out, NULL, NULL, d), PT_ERR_USAGE);
    assert_null(out);
    o.lo = o.hi = 0;
    const float zeros[2] = {0, 0};
    assert_int_equal(img_falsecolor(zeros, 2, 1, &o, &out, NULL, NULL, d), PT_ERR_USAGE);
    assert_int_equal(img_falsecolor(NULL, 2, 1, &o, &out, NULL, NULL, d), PT_ERR_USAGE);
    const float ten = 10.0f;
    assert_int_equal(img_fc_auto_range(&ten, 1, &lo, &hi, d), PT_OK);
    assert_float_equal(lo, 1.0, 1e-12);
    assert_float_equal(hi, 100.0, 1e-9);
    assert_true(isnan(img_fc_probe(vals, 4, 1, 2, 0, 0)));
    assert_float_equal(img_fc_probe(vals, 4, 1, 1, 0, 5), (0.0 - 1.0 + 5.0) / 3.0, 1e-12);
    diag_free(d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ramp_inverse),
        cmocka_unit_test(test_ramp_8bit_precision),
        cmocka_unit_test(test_point_light_readback),
        cmocka_unit_test(test_legend),
        cmocka_unit_test(test_luminance_and_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
