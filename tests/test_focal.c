/* test_focal.c - focal blur's sampling budget (shade/shade_focal.h):
 * the chi-square quantiles its thresholds come from, the number of lens
 * rays a sample takes under POV-Ray's batches and stopping rule, and the
 * camera syntax that sets it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include "shade.h"
#include "shade_chi2.h"
#include "shade_focal.h"
#include "test_world.h"

static void assert_near(double got, double want, double tol)
{
    if (!(fabs(got - want) <= tol)) fail_msg("got %.12g, expected %.12g (tol %g)", got, want, tol);
}

/* chi^2 upper quantiles: df 2 in closed form (P(X > x) = exp(-x/2)), the
 * others from the standard tables (Abramowitz & Stegun table 26.8). */
static void test_chi2inv(void **st)
{
    (void)st;
    assert_near(shade_chi2_inv_q(2, 0.9), -2.0 * log(0.9), 1e-10);
    assert_near(shade_chi2_inv_q(2, 0.025), -2.0 * log(0.025), 1e-9);
    assert_near(shade_chi2_inv_q(1, 0.95), 0.00393214, 1e-7);
    assert_near(shade_chi2_inv_q(10, 0.95), 3.94030, 1e-5);
    assert_near(shade_chi2_inv_q(30, 0.975), 16.7908, 1e-4);
    assert_near(shade_chi2_inv_q(10, 0.05), 18.3070, 1e-4);
}

/* Lens rays per pixel of a render of `camera_items` (no antialiasing) over
 * a uniform background: every batch has zero variance. */
static double rays_per_pixel(const char *camera_items)
{
    char src[512];
    snprintf(src, sizeof src,
             "#version 3.7;\nbackground { rgb 0.5 }\n"
             "camera { location <0,0,-5> look_at 0 aperture 0.5 focal_point <0,0,0> %s }\n", camera_items);
    tu_world w = tu_world_build("focal.pov", src);
    shade_settings ss;
    shade_default_settings(&ss);
    ss.width = 8;
    ss.height = 6;
    ss.threads = 1;
    framebuffer *fb = fb_new(8, 6);
    assert_non_null(fb);
    shade_stats sst;
    assert_int_equal(shade_render(w.s, w.a, &ss, fb, &sst, NULL), PT_OK);
    for (int i = 0; i < 8 * 6 * 3; i++) assert_near(fb->rgb[i], 0.5, 1e-6);
    fb_free(fb);
    tu_world_free(&w);
    return sst.primary_rays / 48.0;
}

static void test_budget(void **st)
{
    (void)st;
    /* POV-Ray's first batch is 7 rays for 7 or more blur samples, 4 below */
    assert_near(rays_per_pixel("blur_samples 37"), 7.0, 0.0);
    assert_near(rays_per_pixel("blur_samples 19"), 7.0, 0.0);
    assert_near(rays_per_pixel("blur_samples 5"), 4.0, 0.0);
    /* blur_samples 1 has a zero threshold: one ray */
    assert_near(rays_per_pixel("blur_samples 1"), 1.0, 0.0);
    /* a minimum of 20 of 37: batches 7, 6, 6 reach 19, the next (4) 23 */
    assert_near(rays_per_pixel("blur_samples 20, 37"), 23.0, 0.0);
    /* 10 of 10 at least: the budget is the cap */
    assert_near(rays_per_pixel("blur_samples 10, 10"), 10.0, 0.0);
}

/* Thresholds: variance * chi2inv(n) / chi2inv(blur_samples - 1). */
static void test_thresholds(void **st)
{
    (void)st;
    scene_camera c;
    scene_default_camera(&c);
    c.blur_samples = 19;
    c.confidence = 0.9;
    c.variance = 1.0 / 128.0;
    shade_focal f;
    assert_true(shade_focal_init(&f, &c));
    double t1 = c.variance / shade_chi2_inv_q(18, 0.9);
    assert_near(f.threshold[6], t1 * shade_chi2_inv_q(7, 0.9), 1e-15);
    assert_near(f.threshold[17], c.variance, 1e-15);
    /* after 7 rays: a variance of the mean just under the bound stops, just over goes on */
    double m = 0.5, var_mean = 0.999 * f.threshold[6], var = var_mean * 7.0;
    double s1[3] = {7 * m, 7 * m, 7 * m}, s2[3];
    for (int k = 0; k < 3; k++) s2[k] = 7.0 * (var + m * m);
    assert_true(shade_focal_done(&f, 7, s1, s2));
    for (int k = 0; k < 3; k++) s2[k] = 7.0 * (var * 1.002 / 0.999 + m * m);
    assert_false(shade_focal_done(&f, 7, s1, s2));
    assert_int_equal(shade_focal_batch(&f, 0), 7);
    assert_int_equal(shade_focal_batch(&f, 2), 6);
    assert_int_equal(shade_focal_batch(&f, 3), 4);
    shade_focal_release(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_chi2inv),
        cmocka_unit_test(test_budget),
        cmocka_unit_test(test_thresholds),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
