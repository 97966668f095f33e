/* test_glossy.c - the glossy lobe of phong/specular (core/glossy.h) and its
 * use by the reference renderers (shade/shade_material.h).
 *
 *  - reciprocity: f(wi, wo) = f(wo, wi) over a sweep of exponents (exact up
 *    to rounding: both terms are symmetric by construction);
 *  - the closed-form albedo E(mu) of the Phong part against an independent
 *    estimate (stratified sampling of the Phong density about the mirror
 *    direction, no closed form), within 0.3%;
 *  - the whole lobe's albedo by its own importance sampling: 1 within 0.5%
 *    for every exponent and angle (energy conservation: never above 1 by
 *    more than that, never lost at grazing angles either);
 *  - the density integrates to at most 1 over the sphere;
 *  - the furnace: white glossy spheres (phong, specular, metallic, mixed
 *    with diffuse) under a uniform white sky show the sky's radiance within
 *    1% in the path tracer and in pmfg;
 *  - blurred reflection (reflection under a micro-scale normal{}, POV-Ray's
 *    idiom averaged by antialiasing): a mirror sphere with bumps 0.3 at
 *    scale 0.0005 reflecting a sky with a sharp horizon, path against
 *    --gi none with 256 fixed samples per pixel (which perturbs the normal
 *    at every sample): the blurred horizon's profile down the middle within
 *    0.06 at every row, mean luminance within 2%; the sharp mirror differs
 *    from it by more than 0.15 somewhere (the blur is there to measure);
 *  - where only direct light exists (one glossy metallic sphere, a point
 *    light and a spotlight, black sky), the path tracer at full depth and
 *    pmfg show --gi none's highlights exactly (POV-Ray's own formula for
 *    light from light sources; the glossy lobe finds only the black sky);
 *  - reflection's exponent e (--gi none): a black mirror plane with
 *    reflection { r exponent e } under a sky of radiance L shows
 *    r L^(1/e) in every pixel (POV-Ray 3.7 raises the reflected colour to
 *    1 / e: parstxtr.cpp stores Reflect_Exp = 1 / e, trace.cpp applies it),
 *    within 1e-6. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "framebuffer.h"
#include "glossy.h"
#include "pm.h"
#include "pm_fg.h"
#include "pm_path.h"
#include "rng.h"
#include "shade.h"
#include "test_world.h"

static const double exponents[] = {0.5, 1, 2, 5, 10, 40, 100, 400, 2000, 20000};
#define NEXP ((int)(sizeof exponents / sizeof exponents[0]))
static const double mus[] = {1.0, 0.8, 0.5, 0.2, 0.05};
#define NMUS ((int)(sizeof mus / sizeof mus[0]))

static vec3 dir_at(double mu, double phi)
{
    double s = sqrt(fmax(0.0, 1.0 - mu * mu));
    return v3(s * cos(phi), s * sin(phi), mu);
}

static void test_reciprocity(void **state)
{
    (void)state;
    rng r;
    rng_seed(&r, 5, 1);
    const vec3 n = v3(0, 0, 1);
    double worst = 0.0;
    for (int i = 0; i < NEXP; i++) {
        const glossy_table *t = glossy_table_for(exponents[i]);
        assert_non_null(t);
        for (int k = 0; k < 2000; k++) {
            vec3 a = dir_at(rng_f64(&r), 2 * M_PI * rng_f64(&r));
            /* half the pairs near the mirror direction, where the lobe is large */
            vec3 b = k % 2 ? dir_at(rng_f64(&r), 2 * M_PI * rng_f64(&r))
                           : v3_norm(v3_add(v3(-a.x, -a.y, a.z), v3_scale(dir_at(rng_f64(&r), 2 * M_PI * rng_f64(&r)), 0.05)));
            if (b.z <= 0.0) continue;
            double f1 = glossy_eval(t, n, a, b), f2 = glossy_eval(t, n, b, a);
            assert_true(f1 >= 0.0 && isfinite(f1));
            double d = fabs(f1 - f2) / fmax(fmax(f1, f2), 1e-300);
            if (d > worst) worst = d;
        }
    }
    printf("glossy reciprocity: worst relative |f(a,b) - f(b,a)| %.3g over %d exponents\n", worst, NEXP);
    assert_true(worst < 1e-9);
}

/* E(mu) = int g mu_i dwi estimated by sampling the Phong density about the
 * mirror direction (128 x 128 strata): g mu_i / p = mu_i / max(mu_i, mu_o). */
static double phong_albedo_sampled(double e, double mu)
{
    vec3 wo = dir_at(mu, 0.0), r = v3(-wo.x, -wo.y, wo.z), ta, tb;
    v3_basis(r, &ta, &tb);
    const int g = 128;
    double sum = 0.0;
    for (int i = 0; i < g; i++)
        for (int j = 0; j < g; j++) {
            double u1 = (i + 0.5) / g, u2 = (j + 0.5) / g;
            double ca = pow(u1, 1.0 / (e + 1.0)), sa = sqrt(fmax(0.0, 1.0 - ca * ca)), ph = 2 * M_PI * u2;
            vec3 w = v3_add(v3_scale(r, ca), v3_add(v3_scale(ta, sa * cos(ph)), v3_scale(tb, sa * sin(ph))));
            if (w.z > 0.0) sum += w.z / fmax(w.z, mu);
        }
    return sum / (g * g);
}

static void test_albedo_closed_form(void **state)
{
    (void)state;
    double worst = 0.0;
    for (int i = 0; i < NEXP; i++)
        for (int k = 0; k < NMUS; k++) {
            double a = glossy_albedo_exact(exponents[i], mus[k]), b = phong_albedo_sampled(exponents[i], mus[k]);
            double d = fabs(a - b);
            if (d > worst) worst = d;
            if (d > 3e-3) printf("  e %g mu %g: closed form %.5f, sampled %.5f\n", exponents[i], mus[k], a, b);
        }
    printf("glossy E(mu) closed form against sampling: worst |difference| %.2e (tol 3e-3)\n", worst);
    assert_true(worst < 3e-3);
}

static void test_albedo_energy(void **state)
{
    (void)state;
    const vec3 n = v3(0, 0, 1);
    double lo = 2.0, hi = 0.0, pmax = 0.0;
    rng r;
    rng_seed(&r, 9, 3);
    for (int i = 0; i < NEXP; i++) {
        const glossy_table *t = glossy_table_for(exponents[i]);
        for (int k = 0; k < NMUS; k++) {
            vec3 wo = dir_at(mus[k], 0.3);
            const int g = 128;
            double sum = 0.0, psum = 0.0;
            for (int a = 0; a < g; a++)
                for (int b = 0; b < g; b++) {
                    vec3 wi;
                    double pdf, w;
                    /* the branch number spread evenly over the strata (golden-ratio sequence) */
                    double u0 = fmod((a * g + b + 0.5) * 0.6180339887498949, 1.0);
                    if (glossy_sample(t, n, wo, u0, (a + 0.5) / g, (b + 0.5) / g, &wi, &pdf, &w)) {
                        assert_true(w >= 0.0 && isfinite(w));
                        assert_true(fabs(pdf - glossy_pdf(t, n, wo, wi)) <= 1e-9 * pdf);
                        sum += w;
                    }
                    /* int pdf over the sphere by uniform directions (z stratified) */
                    vec3 d = dir_at(2.0 * (a + 0.5) / g - 1.0, 2 * M_PI * (b + rng_f64(&r)) / g);
                    psum += glossy_pdf(t, n, wo, d) * 4.0 * M_PI;
                }
            double A = sum / (g * g), P = psum / (g * g);
            if (fabs(A - 1.0) > 0.005) printf("  e %g mu %g: albedo %.5f\n", exponents[i], mus[k], A);
            lo = fmin(lo, A);
            hi = fmax(hi, A);
            if (exponents[i] <= 10) pmax = fmax(pmax, P); /* a uniform grid resolves only broad lobes */
        }
    }
    printf("glossy albedo by importance sampling over %d exponents x %d angles: %.5f .. %.5f (expect 1, tol 0.005); "
           "int pdf <= %.4f\n",
           NEXP, NMUS, lo, hi, pmax);
    assert_true(hi <= 1.005);
    assert_true(lo >= 0.995);
    assert_true(pmax <= 1.01);
}

/* --gi none (no ambient; aa_spp > 0: that many fixed samples per pixel)
 * and the path tracer's settings at W x H on 2 threads. */
static void render_none(const tu_world *w, int W, int H, int aa_spp, framebuffer *fb)
{
    shade_settings ss;
    shade_default_settings(&ss);
    ss.width = W;
    ss.height = H;
    ss.threads = 2;
    ss.use_ambient = 0;
    if (aa_spp > 0) {
        ss.antialias = 2;
        ss.spp = aa_spp;
    }
    assert_int_equal(shade_render(w->s, w->a, &ss, fb, NULL, NULL), PT_OK);
}

static void path_settings(pm_path_settings *ps, int W, int H, int spp)
{
    pm_path_default_settings(ps);
    ps->c.width = W;
    ps->c.height = H;
    ps->c.threads = 2;
    ps->c.spp = spp;
}

/* A white glossy sphere under a uniform sky of radiance 1 (sky_sphere),
 * camera outside: the sphere fills the view to its silhouette (grazing
 * angles at the edges), the corners see the sky. */
static const char *furnace_fmt = "#version 3.7;\n"
                                 "global_settings { assumed_gamma 1.0 }\n"
                                 "camera { location <0, 0, -3> look_at <0, 0, 0> angle 40 }\n"
                                 "sky_sphere { pigment { rgb 1 } }\n"
                                 "sphere { 0, 1 pigment { rgb 1 } finish { ambient 0 %s } }\n";

static void stats(const framebuffer *fb, double *mean, double *maxdev)
{
    double s = 0.0, md = 0.0;
    int n = fb->width * fb->height;
    for (int i = 0; i < n; i++) {
        const float *p = &fb->rgb[3 * (size_t)i];
        for (int c = 0; c < 3; c++) {
            s += p[c];
            md = fmax(md, fabs(p[c] - 1.0));
        }
    }
    *mean = s / (3.0 * n);
    *maxdev = md;
}

static const char *finishes[] = {
    "diffuse 0 phong 1 phong_size 40",
    "diffuse 0 phong 1 phong_size 1",
    "diffuse 0 specular 1 roughness 0.002",
    "diffuse 0.5 phong 0.5 phong_size 200",
    "diffuse 0 phong 0.6 phong_size 10 specular 0.4 roughness 0.01 metallic 1",
};
#define NFIN ((int)(sizeof finishes / sizeof finishes[0]))

static void test_furnace_path(void **state)
{
    (void)state;
    for (int i = 0; i < NFIN; i++) {
        char text[1024];
        snprintf(text, sizeof text, furnace_fmt, finishes[i]);
        tu_world w = tu_world_build("glossy_furnace.pov", text);
        pm_path_settings s;
        path_settings(&s, 16, 16, 256);
        s.c.seed = 3;
        framebuffer *fb = fb_new(16, 16);
        pm_stats st;
        assert_int_equal(pm_path_render(w.s, w.a, &s, fb, &st, NULL), PT_OK);
        double mean, maxdev;
        stats(fb, &mean, &maxdev);
        /* pixel noise at 256 samples near the silhouette reaches ~0.07 (one
         * sample's weight f cos / pdf varies by up to 1/E(mu_o) there) */
        printf("glossy furnace path %-70s: mean %.5f (expect 1, tol 0.01), max pixel dev %.4f (tol 0.1), %.2f s\n",
               finishes[i], mean, maxdev, st.t_total);
        assert_true(fabs(mean - 1.0) <= 0.01);
        assert_true(maxdev <= 0.1);
        assert_int_equal(st.discarded_samples, 0);
        fb_free(fb);
        tu_world_free(&w);
    }
}

static void test_furnace_pmfg(void **state)
{
    (void)state;
    for (int i = 0; i < NFIN; i++) {
        char text[1024];
        snprintf(text, sizeof text, furnace_fmt, finishes[i]);
        tu_world w = tu_world_build("glossy_furnace.pov", text);
        pm_fg_settings s;
        pm_fg_default_settings(&s);
        s.c.width = s.c.height = 16;
        s.c.threads = 2;
        s.c.spp = 16;
        s.c.seed = 5;
        s.fg_rays = 512;
        s.photons = 20000;
        framebuffer *fb = fb_new(16, 16);
        pm_stats st;
        assert_int_equal(pm_fg_render(w.s, w.a, &s, fb, &st, NULL), PT_OK);
        double mean, maxdev;
        stats(fb, &mean, &maxdev);
        printf("glossy furnace pmfg %-70s: mean %.5f (expect 1, tol 0.01), max pixel dev %.4f (tol 0.05), %.2f s\n",
               finishes[i], mean, maxdev, st.t_total);
        assert_true(fabs(mean - 1.0) <= 0.01);
        assert_true(maxdev <= 0.05);
        fb_free(fb);
        tu_world_free(&w);
    }
}

static void test_highlights_direct(void **state)
{
    (void)state;
    tu_world w = tu_world_build("glossy_direct.pov",
                                "#version 3.7;\n"
                                "global_settings { assumed_gamma 1.0 }\n"
                                "camera { location <0, 0.5, -4> look_at <0, 0, 0> angle 40 }\n"
                                "light_source { <3, 4, -4> color rgb <1, 0.9, 0.8> }\n"
                                "light_source { <-3, 3, -2> color rgb 0.6 spotlight point_at <0,0,0> radius 15 "
                                "falloff 25 tightness 5 }\n"
                                "sphere { 0, 1 pigment { rgb <0.9, 0.6, 0.3> } finish { ambient 0 diffuse 0.3 "
                                "phong 0.6 phong_size 60 specular 0.4 roughness 0.01 metallic 1 } }\n");
    const int W = 40, H = 30;
    framebuffer *ref = fb_new(W, H), *fp = fb_new(W, H), *ff = fb_new(W, H);
    render_none(&w, W, H, 0, ref);
    pm_path_settings ps;
    path_settings(&ps, W, H, 1);
    ps.c.jitter = 0;
    assert_int_equal(pm_path_render(w.s, w.a, &ps, fp, NULL, NULL), PT_OK);
    pm_fg_settings fs;
    pm_fg_default_settings(&fs);
    fs.c.width = W;
    fs.c.height = H;
    fs.c.threads = 2;
    fs.c.spp = 1;
    fs.c.jitter = 0;
    fs.fg_rays = 64;
    fs.photons = 5000;
    assert_int_equal(pm_fg_render(w.s, w.a, &fs, ff, NULL, NULL), PT_OK);
    double dp = 0.0, df = 0.0, mx = 0.0;
    for (int i = 0; i < W * H * 3; i++) {
        dp = fmax(dp, fabs(fp->rgb[i] - ref->rgb[i]));
        df = fmax(df, fabs(ff->rgb[i] - ref->rgb[i]));
        mx = fmax(mx, ref->rgb[i]);
    }
    printf("glossy sphere, direct light only: max |path - none| %.3g, max |pmfg - none| %.3g (largest value %.3g, "
           "tol 1e-5 relative)\n",
           dp, df, mx);
    assert_true(mx > 0.5); /* the highlights are there */
    assert_true(dp <= 1e-5 * mx);
    assert_true(df <= 1e-5 * mx);
    fb_free(ref);
    fb_free(fp);
    fb_free(ff);
    tu_world_free(&w);
}

static const char *blur_fmt = "#version 3.7;\n"
                              "global_settings { assumed_gamma 1.0 }\n"
                              "camera { location <0, 0, -4> look_at <0, 0, 0> angle 35 }\n"
                              "sky_sphere { pigment { gradient y color_map { [0.5 rgb 0.05] [0.5 rgb 1] } scale 2 "
                              "translate -1 } }\n"
                              "sphere { 0, 1 pigment { rgb 1 } finish { ambient 0 diffuse 0 reflection 0.9 } %s }\n";

/* Mean luminance of rows of columns [w/2 - 4, w/2 + 4) into prof[h]; returns the image mean. */
static double profile(const framebuffer *fb, double *prof)
{
    const int W = fb->width, H = fb->height;
    double all = 0.0;
    for (int y = 0; y < H; y++) {
        prof[y] = 0.0;
        for (int x = 0; x < W; x++) {
            const float *p = &fb->rgb[3 * ((size_t)y * W + x)];
            double l = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
            all += l;
            if (x >= W / 2 - 4 && x < W / 2 + 4) prof[y] += l / 8.0;
        }
    }
    return all / (W * H);
}

static void test_blurred_reflection(void **state)
{
    (void)state;
    const int W = 48, H = 36;
    char text[1024];
    snprintf(text, sizeof text, blur_fmt, "normal { bumps 0.3 scale 0.0005 }");
    tu_world w = tu_world_build("glossy_blur.pov", text);
    snprintf(text, sizeof text, blur_fmt, "");
    tu_world ws = tu_world_build("glossy_sharp.pov", text);
    framebuffer *fn = fb_new(W, H), *fp = fb_new(W, H), *fs = fb_new(W, H);
    render_none(&w, W, H, 256, fn);
    pm_path_settings ps;
    path_settings(&ps, W, H, 256);
    ps.c.seed = 4;
    assert_int_equal(pm_path_render(w.s, w.a, &ps, fp, NULL, NULL), PT_OK);
    ps.c.spp = 16;
    assert_int_equal(pm_path_render(ws.s, ws.a, &ps, fs, NULL, NULL), PT_OK);
    double pn[64], pp[64], psh[64];
    double mn = profile(fn, pn), mp = profile(fp, pp);
    profile(fs, psh);
    double dblur = 0.0, dsharp = 0.0;
    for (int y = 0; y < H; y++) {
        dblur = fmax(dblur, fabs(pp[y] - pn[y]));
        dsharp = fmax(dsharp, fabs(psh[y] - pn[y]));
    }
    printf("blurred reflection: profile down the middle, max |path - none(256 AA)| %.4f (tol 0.06), "
           "max |sharp mirror - none| %.4f (> 0.15); mean luminance path %.5f, none %.5f (%+.2f%%, tol 2%%)\n",
           dblur, dsharp, mp, mn, 100.0 * (mp / mn - 1.0));
    assert_true(dblur <= 0.06);
    assert_true(dsharp > 0.15);
    assert_true(fabs(mp / mn - 1.0) <= 0.02);
    fb_free(fn);
    fb_free(fp);
    fb_free(fs);
    tu_world_free(&w);
    tu_world_free(&ws);
}

static void test_reflection_exponent(void **state)
{
    (void)state;
    static const double es[] = {0.5, 0.8, 1.0, 2.0};
    for (int i = 0; i < 4; i++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "#version 3.7;\n"
                 "global_settings { assumed_gamma 1.0 }\n"
                 "camera { location <0, 1, 0> look_at <0, 0, 0> angle 40 }\n"
                 "sky_sphere { pigment { rgb 0.25 } }\n"
                 "plane { y, 0 pigment { rgb 0 } finish { ambient 0 diffuse 0 reflection { 0.7 exponent %g } } }\n",
                 es[i]);
        tu_world w = tu_world_build("glossy_reflexp.pov", text);
        framebuffer *fb = fb_new(8, 8);
        render_none(&w, 8, 8, 0, fb);
        double want = 0.7 * pow(0.25, 1.0 / es[i]), maxdev = 0.0;
        for (int k = 0; k < 3 * 8 * 8; k++) maxdev = fmax(maxdev, fabs(fb->rgb[k] - want));
        printf("reflection exponent %.1f: expect %.6f, max pixel dev %.2e (tol 1e-6)\n", es[i], want, maxdev);
        assert_true(maxdev <= 1e-6);
        fb_free(fb);
        tu_world_free(&w);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reciprocity),
        cmocka_unit_test(test_albedo_closed_form),
        cmocka_unit_test(test_albedo_energy),
        cmocka_unit_test(test_furnace_path),
        cmocka_unit_test(test_furnace_pmfg),
        cmocka_unit_test(test_highlights_direct),
        cmocka_unit_test(test_blurred_reflection),
        cmocka_unit_test(test_reflection_exponent),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
