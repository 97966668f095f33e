/* test_shapes.c - further shapes end to end (SDL -> IR -> accel): hit
 * distances and normals against closed-form answers, grazing rays, rays
 * starting on the surface, scales 1e-4 to 1e5, inside tests, clipped_by;
 * where no closed form exists (Catmull-Rom lathe, sor, Bezier prism, text)
 * the first hit is checked against a brute-force march of the shape's
 * inside test along the ray (bisected to 1e-12 of the ray length). Plus the
 * polynomial solver (both isolation methods) and the height_field reader.
 * Tolerances: 1e-9 relative for distances unless stated, 1e-8 for normals. */
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
#include "accel.h"
#include "geom_csg.h"
#include "geom_implicit.h"
#include "geom_poly.h"
#include "geom_shape.h"
#include "accel_surface.h"
#include "rng.h"
#include "diag.h"
#include "scene.h"
#include "sdl.h"
#include "sdl_hfimage.h"
#include "sdl_imgread.h"
#include "test_world.h"
#include <jpeglib.h>
#include <tiffio.h>

#include "test_shapes.h"

/* ------------------------------------------------------------ polynomial roots */

static void test_poly_roots(void **st)
{
    (void)st;
    /* (x-0.1)(x-0.2)(x-0.3)(x-0.4)(x-0.5) expanded */
    double r[5] = {0.1, 0.2, 0.3, 0.4, 0.5}, c[6] = {1, 0, 0, 0, 0, 0};
    for (int k = 0; k < 5; k++) {
        for (int i = k + 1; i > 0; i--) c[i] = c[i - 1] - r[k] * c[i];
        c[0] = -r[k] * c[0];
    }
    for (int sturm = 0; sturm < 2; sturm++) {
        double out[5];
        assert_int_equal(geom_poly_solve(c, 5, 0.0, 1.0, out, sturm), 5);
        for (int i = 0; i < 5; i++) assert_near(out[i], r[i], 1e-12);
        assert_int_equal(geom_poly_solve(c, 5, 0.25, 0.45, out, sturm), 2);
        assert_near(out[0], 0.3, 1e-12);
    }
    /* degree 12: roots 1..12 scaled by 1/16 (Wilkinson-like clustering) */
    double w[13] = {1};
    for (int k = 1; k <= 12; k++) {
        double rk = k / 16.0;
        for (int i = k; i > 0; i--) w[i] = w[i - 1] - rk * w[i];
        w[0] = -rk * w[0];
    }
    for (int sturm = 0; sturm < 2; sturm++) {
        double out[12];
        int n = geom_poly_solve(w, 12, 0.0, 1.0, out, sturm);
        assert_int_equal(n, 12);
        for (int i = 0; i < 12; i++) assert_near(out[i], (i + 1) / 16.0, 1e-7);
    }
    /* double root (a grazing ray): (x - 0.5)^2 (x + 3) */
    double g[4] = {0.75, 2.0, 2.0, 1.0}; /* x^3 + 2x^2 - 2.75x... recomputed below */
    g[0] = 0.25 * 3.0;   /* 0.75 */
    g[1] = 0.25 - 3.0;   /* x coefficient: 0.25 - 3 = -2.75 */
    g[2] = -1.0 + 3.0;   /* 2 */
    g[3] = 1.0;
    double out[3];
    int n = geom_poly_solve(g, 3, 0.0, 1.0, out, 0);
    assert_true(n >= 1);
    assert_near(out[0], 0.5, 1e-7);
}

/* ------------------------------------------------------------ polygon */

static void test_polygon(void **st)
{
    (void)st;
    /* a 4x4 square with a 2x2 hole (two sub-polygons) in the z = 0 plane */
    world w = build("polygon { 10, <-2,-2>, <2,-2>, <2,2>, <-2,2>, <-2,-2>,"
                    " <-1,-1>, <1,-1>, <1,1>, <-1,1>, <-1,-1> }");
    assert_int_equal(w.s->objects[0]->kind, SHAPE_POLYGON);
    expect_hit(&w, v3(1.5, 0.5, -5), v3(0, 0, 1), 5.0, v3(0, 0, -1), 1e-12, -1);
    accel_hit h;
    assert_true(hit(&w, v3(1.5, 0.5, -5), v3(0, 0, 1), &h));
    assert_near(fabs(h.ng.z), 1.0, 1e-12);
    expect_miss(&w, v3(0, 0, -5), v3(0, 0, 1));      /* the hole */
    expect_miss(&w, v3(2.5, 0, -5), v3(0, 0, 1));    /* outside */
    expect_miss(&w, v3(-5, 1.5, 0), v3(1, 0, 0));    /* in the plane */
    expect_hit(&w, v3(-1.99, -1.99, 3), v3(0, 0, -2), 1.5, v3(0, 0, 1), 1e-12, -1);
    done(&w);
    /* unclosed: closed automatically (a warning) */
    w = build("polygon { 3, <0,0,1>, <1,0,1>, <0,1,1> }");
    expect_hit(&w, v3(0.2, 0.2, 0), v3(0, 0, 1), 1.0, v3(0, 0, 1), 1e-12, -1);
    done(&w);
}

/* ------------------------------------------------------------ lathe */

static void test_lathe_linear(void **st)
{
    (void)st;
    /* closed profile: a cylinder r = 1, 0 <= y <= 1 with flat ends */
    world w = build("lathe { linear_spline 5, <0,0>, <1,0>, <1,1>, <0,1>, <0,0> }");
    assert_int_equal(w.s->objects[0]->kind, SHAPE_LATHE);
    expect_hit(&w, v3(-5, 0.5, 0), v3(1, 0, 0), 4.0, v3(-1, 0, 0), 1e-12, 1e-12);
    expect_hit(&w, v3(0.3, 5, 0.2), v3(0, -1, 0), 4.0, v3(0, 1, 0), 1e-12, 1e-12);
    expect_hit(&w, v3(0.3, -5, 0.2), v3(0, 1, 0), 5.0, v3(0, -1, 0), 1e-12, 1e-12);
    /* a diagonal ray: enters the side at x = -1 */
    expect_hit(&w, v3(-3, 0.5, -2), v3(1, 0, 1), 2.0, v3(-1, 0, 0), 1e-12, 1e-12);
    expect_miss(&w, v3(-5, 1.5, 0), v3(1, 0, 0));
    /* starting on the side, going in: the far side */
    double xs = sqrt(0.99);
    expect_hit(&w, v3(-xs, 0.5, 0.1), v3(1, 0, 0), 2 * xs, v3(xs, 0, 0.1), 1e-12, 1e-12);
    geom_shape sh = shape_of(&w);
    assert_true(geom_shape_inside(&sh, v3(0.5, 0.5, 0.1)));
    assert_false(geom_shape_inside(&sh, v3(1.5, 0.5, 0)));
    assert_false(geom_shape_inside(&sh, v3(0.5, 1.5, 0)));
    geom_shape_release(&sh);
    done(&w);
}

/* r = 1 + y^2 for y in [0,1], reproduced exactly by quadratic, cubic
 * (Catmull-Rom: quadratics are reproduced) and Bezier segments. */
static void check_paraboloid_lathe(const char *src, double scale)
{
    world w = build(src);
    for (int i = 1; i < 10; i++) {
        double y = i / 10.0, r = 1.0 + y * y;
        vec3 o = v3(-5 * scale, y * scale, 0);
        vec3 n = v3(-1, -2 * y, 0);
        expect_hit(&w, o, v3(1, 0, 0), (5 - r) * scale, n, 1e-11 * 5 * scale, 1e-9);
    }
    /* nearly horizontal rays (the special method below 1e-5) and steeper ones agree */
    for (int k = 0; k < 4; k++) {
        double ey = k == 0 ? 3e-6 : k == 1 ? 2e-5 : k == 2 ? 0.01 : 0.3;
        vec3 d = v3_norm(v3(1, ey, 0.0));
        vec3 o = v3(-5 * scale, 0.5 * scale - 5 * scale * ey, 0.0);
        accel_hit h;
        assert_true(hit(&w, o, d, &h));
        vec3 p = v3_scale(h.p, 1.0 / scale);
        double r = sqrt(p.x * p.x + p.z * p.z);
        assert_near(r, 1.0 + p.y * p.y, 1e-9);
    }
    done(&w);
}

static void test_lathe_splines(void **st)
{
    (void)st;
    char buf[1024];
    const double scales[] = {1e-4, 1.0, 1e5};
    for (int s = 0; s < 3; s++) {
        double k = scales[s];
        /* quadratic: first point is a control point; points on r = 1 + y^2, y step 0.25 */
        snprintf(buf, sizeof buf,
                 "lathe { quadratic_spline 6, <1.0625,-0.25>, <1,0>, <1.0625,0.25>, <1.25,0.5>, <1.5625,0.75>, <2,1> scale %g }", k);
        check_paraboloid_lathe(buf, k);
        snprintf(buf, sizeof buf,
                 "lathe { cubic_spline 7, <1.0625,-0.25>, <1,0>, <1.0625,0.25>, <1.25,0.5>, <1.5625,0.75>, <2,1>, <2.5625,1.25> scale %g }", k);
        check_paraboloid_lathe(buf, k);
        snprintf(buf, sizeof buf, "lathe { bezier_spline 4, <1,0>, <1,0.333333333333333333>, <1.333333333333333333,0.66666666666666667>, <2,1> scale %g }", k);
        check_paraboloid_lathe(buf, k);
    }
}

static void test_lathe_brute(void **st)
{
    (void)st;
    /* a vase-like closed Catmull-Rom profile: first hit = inside-test march */
    world w = build("lathe { cubic_spline 8, <0,-0.2>, <0,0>, <1,0.2>, <0.5,0.6>, <0.8,1.2>, <0.6,1.6>, <0,1.7>, <-0.3,1.8> sturm }");
    geom_shape sh = shape_of(&w);
    int checked = 0;
    for (int i = 0; i < 40; i++) {
        double y = 0.05 + 1.6 * i / 40.0, a = 0.3 * i;
        vec3 o = v3(-3 * cos(a), y + 0.4, -3 * sin(a));
        vec3 d = v3_norm(v3(3 * cos(a), -0.4 + 0.01 * i, 3 * sin(a) + 0.2));
        accel_hit h;
        double tb = march(&sh, o, d, 1e-9, 6.0, 4000);
        int got = hit(&w, o, d, &h);
        if (isinf(tb)) {
            if (got) fail_msg("ray %d: hit at %g, march found none", i, h.t);
            continue;
        }
        assert_true(got);
        assert_near(h.t, tb, 1e-9);
        checked++;
    }
    assert_true(checked > 20);
    geom_shape_release(&sh);
    done(&w);
}

/* ------------------------------------------------------------ sor */

static void test_sor(void **st)
{
    (void)st;
    /* points on r = 1 (a cylinder, exact), caps at y = 0 and y = 1 */
    world w = build("sor { 4, <1,-1>, <1,0>, <1,1>, <1,2> }");
    assert_int_equal(w.s->objects[0]->kind, SHAPE_SOR);
    expect_hit(&w, v3(-5, 0.5, 0), v3(1, 0, 0), 4.0, v3(-1, 0, 0), 1e-12, 1e-12);
    expect_hit(&w, v3(0.2, 5, 0.3), v3(0, -1, 0), 4.0, v3(0, 1, 0), 1e-12, 1e-12);
    expect_hit(&w, v3(0.2, -5, 0.3), v3(0, 1, 0), 5.0, v3(0, -1, 0), 1e-12, 1e-12);
    expect_miss(&w, v3(-5, 1.5, 0), v3(1, 0, 0));
    done(&w);
    w = build("sor { 4, <1,-1>, <1,0>, <1,1>, <1,2> open }");
    expect_miss(&w, v3(0.2, 5, 0.3), v3(0, -1, 0)); /* down the open tube */
    expect_hit(&w, v3(-5, 0.5, 0), v3(1, 0, 0), 4.0, v3(-1, 0, 0), 1e-12, 1e-12);
    done(&w);
}

static void test_sor_brute(void **st)
{
    (void)st;
    world w = build("sor { 6, <0.5,-0.5>, <1,0>, <0.4,0.5>, <0.8,1.3>, <0.2,1.6>, <0.3,2> }");
    geom_shape sh = shape_of(&w);
    int checked = 0;
    for (int i = 0; i < 30; i++) {
        double a = 0.21 * i;
        vec3 o = v3(-3 * cos(a), 0.1 + 0.05 * i, -3 * sin(a));
        vec3 d = v3_norm(v3(3 * cos(a) + 0.1, 0.5 - 0.03 * i, 3 * sin(a)));
        double tb = march(&sh, o, d, 1e-9, 6.0, 4000);
        accel_hit h;
        int got = hit(&w, o, d, &h);
        if (isinf(tb)) {
            assert_false(got);
            continue;
        }
        assert_true(got);
        assert_near(h.t, tb, 1e-9);
        checked++;
    }
    assert_true(checked > 10);
    geom_shape_release(&sh);
    done(&w);
}

/* ------------------------------------------------------------ prism */

static void test_prism(void **st)
{
    (void)st;
    const double scales[] = {1e-4, 1.0, 1e5};
    char buf[512];
    for (int s = 0; s < 3; s++) {
        double k = scales[s];
        /* a 2x2 square with a 1x1 hole, y from 0 to 1 */
        snprintf(buf, sizeof buf,
                 "prism { linear_sweep linear_spline 0, 1, 10, <-1,-1>, <1,-1>, <1,1>, <-1,1>, <-1,-1>,"
                 " <-0.5,-0.5>, <0.5,-0.5>, <0.5,0.5>, <-0.5,0.5>, <-0.5,-0.5> scale %g translate <%g,0,0> }", k, 3 * k);
        world w = build(buf);
        vec3 c = v3(3 * k, 0, 0);
        expect_hit(&w, v3_add(c, v3(-5 * k, 0.5 * k, 0.75 * k)), v3(1, 0, 0), 4 * k, v3(-1, 0, 0), 1e-11 * k, 1e-9);
        /* through the hole along x at z = 0: outer wall, then the hole's wall */
        expect_hit(&w, v3_add(c, v3(-0.75 * k, 0.5 * k, 0)), v3(1, 0, 0), 0.25 * k, v3(1, 0, 0), 1e-11 * k, 1e-9);
        expect_hit(&w, v3_add(c, v3(0.75 * k, 3 * k, 0.1 * k)), v3(0, -1, 0), 2 * k, v3(0, 1, 0), 1e-11 * k, 1e-9);
        expect_miss(&w, v3_add(c, v3(0, 3 * k, 0)), v3(0, -1, 0)); /* down the hole */
        done(&w);
    }
    /* conic sweep: a pyramid |x|, |z| < y for 0 < y < 1 */
    world w = build("prism { conic_sweep linear_spline 0, 1, 5, <-1,-1>, <1,-1>, <1,1>, <-1,1>, <-1,-1> }");
    expect_hit(&w, v3(-5, 0.5, 0), v3(1, 0, 0), 4.5, v3(-1, -1, 0), 1e-12, 1e-9);
    expect_hit(&w, v3(0.3, 5, -0.2), v3(0, -1, 0), 4.0, v3(0, 1, 0), 1e-12, 1e-12);
    done(&w);
    /* open: no caps */
    w = build("prism { 0, 1, 4, <-1,-1>, <1,-1>, <1,1>, <-1,1> open }");
    expect_miss(&w, v3(0, 5, 0), v3(0, -1, 0));
    expect_hit(&w, v3(-5, 0.5, 0), v3(1, 0, 0), 4.0, v3(-1, 0, 0), 1e-12, 1e-12);
    done(&w);
}

static void test_prism_brute(void **st)
{
    (void)st;
    const char *src[] = {
        "prism { bezier_spline 0, 1, 8, <0,0>, <1,0>, <1,1>, <1,1>, <1,1>, <0,1>, <0,0.5>, <0,0> }",
        "prism { quadratic_spline 0, 1, 6, <0,-1>, <1,0>, <0,1>, <-1,0>, <0,-1>, <1,0> }",
        "prism { cubic_spline -0.5, 0.5, 7, <0,-1>, <1,0>, <0,1>, <-1,0>, <0,-1>, <1,0>, <0,1> }",
        "prism { conic_sweep cubic_spline 0.5, 1, 7, <0,-1>, <1,0>, <0,1>, <-1,0>, <0,-1>, <1,0>, <0,1> }",
    };
    for (int s = 0; s < 4; s++) {
        world w = build(src[s]);
        geom_shape sh = shape_of(&w);
        int checked = 0;
        for (int i = 0; i < 30; i++) {
            double a = 0.37 * i;
            vec3 o = v3(-3 * cos(a) + 0.3, 0.3 + 0.02 * i, -3 * sin(a));
            vec3 d = v3_norm(v3(3 * cos(a), 0.3 - 0.02 * i, 3 * sin(a) + 0.1));
            double tb = march(&sh, o, d, 1e-9, 6.0, 4000);
            accel_hit h;
            int got = hit(&w, o, d, &h);
            if (isinf(tb)) {
                if (got) fail_msg("shape %d ray %d: hit %g, march none", s, i, h.t);
                continue;
            }
            if (!got) fail_msg("shape %d ray %d: march %g, no hit", s, i, tb);
            assert_near(h.t, tb, 1e-9);
            checked++;
        }
        if (checked < 3) fail_msg("shape %d: only %d rays hit", s, checked);
        geom_shape_release(&sh);
        done(&w);
    }
}

/* A prism with many segments (the inside test's band index is built from
 * 16 on): a regular 64-gon with a regular 48-gon hole; a point is inside iff
 * it lies within the outer polygon's apothem of every outer edge normal and
 * outside the hole's, the closed form. Points closer than 1e-9 to an edge
 * are skipped (either answer is right there). */
static void test_prism_many_segments(void **st)
{
    (void)st;
    char buf[16384];
    int n = snprintf(buf, sizeof buf, "prism { linear_sweep linear_spline 0, 1, %d", 65 + 49);
    const int ns[2] = {64, 48};
    const double rs[2] = {1.0, 0.5};
    for (int ring = 0; ring < 2; ring++)
        for (int k = 0; k <= ns[ring]; k++) {
            double a = 2.0 * M_PI * (k % ns[ring]) / ns[ring];
            n += snprintf(buf + n, sizeof buf - (size_t)n, ", <%.17g,%.17g>", rs[ring] * cos(a), rs[ring] * sin(a));
        }
    snprintf(buf + n, sizeof buf - (size_t)n, " }");
    world w = build(buf);
    geom_shape sh = shape_of(&w);
    int tested = 0, inside = 0;
    for (int i = 0; i < 4000; i++) {
        double x = -1.2 + 2.4 * ((i * 0.6180339887498949) - floor(i * 0.6180339887498949));
        double z = -1.2 + 2.4 * ((i * 0.7548776662466927) - floor(i * 0.7548776662466927));
        int in_ring[2];
        double margin = INFINITY;
        for (int ring = 0; ring < 2; ring++) {
            in_ring[ring] = 1;
            for (int k = 0; k < ns[ring]; k++) {
                double a = 2.0 * M_PI * (k + 0.5) / ns[ring];
                double dd = x * cos(a) + z * sin(a) - rs[ring] * cos(M_PI / ns[ring]);
                if (dd > 0.0) in_ring[ring] = 0;
                margin = fmin(margin, fabs(dd));
            }
        }
        if (margin < 1e-9) continue;
        int want = in_ring[0] && !in_ring[1];
        if (geom_shape_inside(&sh, v3(x, 0.5, z)) != want) fail_msg("point %d (%g, %g): inside %d, want %d", i, x, z, !want, want);
        tested++;
        inside += want;
    }
    assert_true(tested > 3900 && inside > 1000);
    geom_shape_release(&sh);
    done(&w);
}

/* ------------------------------------------------------------ text */

static void test_text(void **st)
{
    (void)st;
    if (access("/usr/share/povray-3.7/include/timrom.ttf", R_OK) != 0) skip();
    world w = build("text { ttf \"timrom.ttf\" \"I-I\" 0.25, 0 }");
    const scene_object *o = w.s->objects[0];
    assert_int_equal(o->kind, SHAPE_TEXT);
    assert_true(o->u.text->nsegments > 8);
    int nseg = o->u.text->nsegments;
    /* the front face lies in z = 0 (up to POV-Ray's 0.001 degree turn), the back in z = 0.25 */
    geom_shape sh = shape_of(&w);
    vec3 lo = sh.lo, hi = sh.hi;
    assert_near(lo.z, 0.0, 1e-4);
    assert_near(hi.z, 0.25, 1e-4);
    assert_true(hi.y > 0.5 && hi.y < 1.0); /* caps height of a Roman face, em = 1 */
    int front = 0;
    for (int i = 0; i < 200; i++) {
        double x = lo.x + (hi.x - lo.x) * (i + 0.5) / 200.0, y = 0.3;
        accel_hit h;
        vec3 org = v3(x, y, -2);
        int in = geom_shape_inside(&sh, v3(x, y, 0.125));
        int got = hit(&w, org, v3(0, 0, 1), &h);
        assert_int_equal(in, got);
        if (got) {
            assert_near(h.t, 2.0, 1e-4);
            assert_true(h.ng.z < -0.9999);
            front++;
        }
    }
    assert_true(front > 10);
    /* side hits agree with the inside march */
    for (int i = 0; i < 20; i++) {
        vec3 org = v3(lo.x - 1, 0.05 + 0.03 * i, 0.1);
        vec3 d = v3(1, 0.001 * i, 0.0);
        double tb = march(&sh, org, d, 1e-9, hi.x - lo.x + 2, 20000);
        accel_hit h;
        int got = hit(&w, org, d, &h);
        if (isinf(tb)) continue;
        assert_true(got);
        assert_near(h.t, tb, 1e-8);
    }
    geom_shape_release(&sh);
    done(&w);
    /* POV-Ray's built-in font 1 is timrom.ttf: the same outline */
    w = build("text { internal 1 \"I-I\" 0.25, 0 }");
    assert_int_equal(w.s->objects[0]->kind, SHAPE_TEXT);
    assert_int_equal(w.s->objects[0]->u.text->nsegments, nseg);
    done(&w);
    /* one parse keeps each font file open for all its texts: the outlines
     * are those of separate parses, whatever the face set before */
    if (access("/usr/share/povray-3.7/include/cyrvetic.ttf", R_OK) != 0) return;
    world a = build("text { ttf \"timrom.ttf\" \"AVA\" 0.25, 0 }");
    world b = build("text { ttf \"cyrvetic.ttf\" \"Wo\" 0.5, <0.1,0,0> }");
    w = build("text { ttf \"timrom.ttf\" \"I-I\" 0.25, 0 }"
              "text { ttf \"cyrvetic.ttf\" \"Wo\" 0.5, <0.1,0,0> }"
              "text { ttf \"timrom.ttf\" \"AVA\" 0.25, 0 }");
    assert_int_equal(w.s->nobjects, 3);
    const scene_text *want[3] = {NULL, b.s->objects[0]->u.text, a.s->objects[0]->u.text};
    for (int i = 1; i < 3; i++) {
        const scene_text *got = w.s->objects[i]->u.text;
        assert_int_equal(got->nsegments, want[i]->nsegments);
        assert_true(memcmp(got->segments, want[i]->segments, sizeof *got->segments * (size_t)got->nsegments) == 0);
    }
    assert_int_equal(w.s->objects[0]->u.text->nsegments, nseg);
    done(&w);
    done(&a);
    done(&b);
}

/* ------------------------------------------------------------ superellipsoid */

static void test_superellipsoid(void **st)
{
    (void)st;
    const double scales[] = {1e-4, 1.0, 1e5};
    char buf[256];
    for (int s = 0; s < 3; s++) {
        double k = scales[s];
        /* <1,1>: the unit sphere */
        snprintf(buf, sizeof buf, "superellipsoid { <1,1> scale %g }", k);
        world w = build(buf);
        for (int i = 0; i < 8; i++) {
            double y = 0.11 * i, z = -0.07 * i;
            double x = sqrt(1 - y * y - z * z);
            expect_hit(&w, v3(-5 * k, y * k, z * k), v3(1, 0, 0), (5 - x) * k, v3(-x, y, z), 1e-10 * k, 1e-8);
        }
        /* grazing: just inside touches, just outside misses */
        accel_hit h;
        assert_true(hit(&w, v3(-5 * k, (1 - 1e-7) * k, 0), v3(1, 0, 0), &h));
        assert_near(h.t, 5 * k, 1e-3 * k);
        expect_miss(&w, v3(-5 * k, (1 + 1e-7) * k, 0), v3(1, 0, 0));
        /* from the surface inwards: the far side */
        expect_hit(&w, v3(-k, 0, 0), v3(1, 0, 0), 2 * k, v3(1, 0, 0), 1e-9 * k, 1e-8);
        done(&w);
    }
    /* <2,2>: the octahedron |x| + |y| + |z| = 1 */
    world w = build("superellipsoid { <2,2> }");
    expect_hit(&w, v3(-5, 0.2, 0.1), v3(1, 0, 0), 4.3, v3(-1, 1, 1), 1e-10, 1e-8);
    done(&w);
    /* <0.5, 3> (not convex in z: sampled), against the inside march */
    w = build("superellipsoid { <0.5, 3> }");
    geom_shape sh = shape_of(&w);
    for (int i = 0; i < 20; i++) {
        vec3 o = v3(-3, -0.9 + 0.09 * i, 0.3 - 0.05 * i);
        vec3 d = v3_norm(v3(1, 0.05, 0.1 * sin(i)));
        double tb = march(&sh, o, d, 1e-9, 6, 6000);
        accel_hit h;
        int got = hit(&w, o, d, &h);
        if (isinf(tb)) continue;
        assert_true(got);
        assert_near(h.t, tb, 1e-9);
    }
    geom_shape_release(&sh);
    done(&w);
}

/* ------------------------------------------------------------ quadric, poly */

static void test_quadric(void **st)
{
    (void)st;
    /* sphere radius 2 centred at <1,0,0>: x2 + y2 + z2 - 2x - 3 */
    world w = build("quadric { <1,1,1>, <0,0,0>, <-2,0,0>, -3 }");
    expect_hit(&w, v3(-5, 0, 0), v3(1, 0, 0), 4.0, v3(-1, 0, 0), 1e-12, 1e-12);
    expect_hit(&w, v3(1, 5, 0), v3(0, -1, 0), 3.0, v3(0, 1, 0), 1e-12, 1e-12);
    done(&w);
    /* infinite cylinder x2 + z2 = 1 along y (clipped like a plane), 1e5 away */
    w = build("quadric { <1,0,1>, <0,0,0>, <0,0,0>, -1 } sphere { <0,0,0>, 0.1 }");
    expect_hit(&w, v3(-5, 1e3, 0), v3(1, 0, 0), 4.0, v3(-1, 0, 0), 1e-9, 1e-9);
    expect_hit(&w, v3(0.5, 3, 0), v3(1, 0, 0), 0.5, v3(1, 0, 0), 1e-12, 1e-12);
    geom_shape sh = shape_of(&w);
    assert_true(geom_shape_inside(&sh, v3(0.2, 1e6, 0.2)));
    assert_false(geom_shape_inside(&sh, v3(1.2, 0, 0)));
    geom_shape_release(&sh);
    done(&w);
    /* clipped_by { bounded_by }: the cylinder between y = -1 and 1 */
    w = build("quadric { <1,0,1>, <0,0,0>, <0,0,0>, -1 bounded_by { box { <-2,-1,-2>, <2,1,2> } } clipped_by { bounded_by } }");
    expect_hit(&w, v3(-5, 0.5, 0), v3(1, 0, 0), 4.0, v3(-1, 0, 0), 1e-12, 1e-12);
    expect_miss(&w, v3(-5, 1.5, 0), v3(1, 0, 0));
    done(&w);
}

/* The box of an unbounded quadric's inside within the other members of an
 * intersection (POV-Ray's CSG bounding): the one-sheet hyperboloid
 * 4x2 + 4z2 - (y-5)2 < 1 (shapes.inc's Hyperboloid_Y scaled <0.5,1,0.5>,
 * moved up 5) between y = 2.5 and 5.5 reaches |x|, |z| < 0.5 sqrt(1 + 2.5^2). */
static void test_quadric_csg_box(void **st)
{
    (void)st;
    const char *src = "intersection { plane { y, 5.5 } quadric { <1,-1,1>, <0,0,0>, <0,0,0>, -1 translate 5*y scale <0.5,1,0.5> }"
                      " plane { -y, -2.5 } }";
    world w = build(src);
    double r = 0.5 * sqrt(1.0 + 2.5 * 2.5);
    geom_csg c;
    memset(&c, 0, sizeof c);
    geom_csg_builder b = {NULL, NULL, 0, 0, NULL, 0};
    assert_int_equal(geom_csg_build(&c, w.s->objects[0], NULL, 0, -1, 0, &b), PT_OK);
    assert_true(geom_csg_finish(&c));
    assert_near(c.lo.x, -r, 1e-6);
    assert_near(c.hi.x, r, 1e-6);
    assert_near(c.lo.z, -r, 1e-6);
    assert_near(c.hi.z, r, 1e-6);
    assert_near(c.lo.y, 2.5, 1e-6);
    assert_near(c.hi.y, 5.5, 1e-6);
    /* the surface is still found at the box's edge: the widest ring at y = 2.5 + 1e-3 */
    double y = 2.5 + 1e-3, rx = 0.5 * sqrt(1.0 + (y - 5.0) * (y - 5.0));
    expect_hit(&w, v3(-5, y, 0), v3(1, 0, 0), 5.0 - rx, v3_norm(v3(-8.0 * rx, -2.0 * (y - 5.0), 0)), 1e-9, 1e-9);
    geom_csg_free(&c);
    done(&w);
    /* the same intersection turned as a whole (nested as clipped_by nests
     * its solids): the box is worked out in the quadric's own space and
     * carried back, so it is finite and holds the turned solid */
    w = build("intersection { quadric { <1,-1,1>, <0,0,0>, <0,0,0>, -1 translate 5*y scale <0.5,1,0.5> }"
              " intersection { plane { y, 5.5 } plane { -y, -2.5 } } rotate <-30, 0, 30> }");
    memset(&c, 0, sizeof c);
    assert_int_equal(geom_csg_build(&c, w.s->objects[0], NULL, 0, -1, 0, &b), PT_OK);
    assert_true(geom_csg_finish(&c));
    assert_true(v3_finite(c.lo) && v3_finite(c.hi));
    /* every corner of the solid's own box (|x|, |z| <= r, 2.5 <= y <= 5.5)
     * lies within R = sqrt(2 r^2 + 5.5^2) of the origin the turn keeps */
    double R = sqrt(2.0 * r * r + 5.5 * 5.5);
    assert_true(c.lo.x >= -R - 1e-6 && c.lo.y >= -R - 1e-6 && c.lo.z >= -R - 1e-6);
    assert_true(c.hi.x <= R + 1e-6 && c.hi.y <= R + 1e-6 && c.hi.z <= R + 1e-6);
    geom_csg_free(&c);
    done(&w);
    /* a blob with the half-spaces x < 0 and z > 0 of its own frame
     * subtracted, turned 30 degrees about y (abyss's hull quarters): the box
     * is the quarter's, worked out before the turn, about half as wide as
     * the whole blob's turned box (2 R (cos 30 + sin 30) = 2.73 R), and the
     * quarter is still hit */
    w = build("difference { blob { threshold 0.5 sphere { 0, 2, 1 } } plane { x, 0 } plane { z, 0 inverse } rotate 30*y }");
    memset(&c, 0, sizeof c);
    assert_int_equal(geom_csg_build(&c, w.s->objects[0], NULL, 0, -1, 0, &b), PT_OK);
    assert_true(geom_csg_finish(&c));
    {
        double Rb = fmax(v3_maxc(v3_neg(c.shapes[0].olo)), v3_maxc(c.shapes[0].ohi));
        double k = cos(M_PI / 6) + sin(M_PI / 6);
        printf("  turned blob quarter: box %.3f x %.3f x %.3f, blob reach %.3f\n", c.hi.x - c.lo.x, c.hi.y - c.lo.y,
               c.hi.z - c.lo.z, Rb);
        assert_true(Rb > 1.0 && Rb < 2.5);
        assert_true(c.hi.x - c.lo.x <= Rb * k * (1 + 1e-6) && c.hi.z - c.lo.z <= Rb * k * (1 + 1e-6));
        assert_true(c.hi.y - c.lo.y >= 2.0 * Rb * (1 - 1e-6) - 1e-9);
    }
    geom_csg_free(&c);
    /* the kept quarter (object x > 0, z < 0) turned: POV-Ray's rotate 30*y
     * takes object (1, 0, -1) to world (cos30 - sin30, 0, -sin30 - cos30) */
    {
        vec3 q = v3(cos(M_PI / 6) - sin(M_PI / 6), 0, -sin(M_PI / 6) - cos(M_PI / 6));
        vec3 o = v3_scale(q, 10.0), dir = v3_norm(v3_neg(q));
        accel_hit h;
        assert_true(accel_intersect(w.a, o, dir, 0.0, INFINITY, &h));
        assert_true(h.t < 10.0 * v3_len(q));
    }
    done(&w);
    /* turned 45 degrees about z: mixed terms, no box (left to the clip cube) */
    w = build("quadric { <1,-1,1>, <0,0,0>, <0,0,0>, -1 rotate 45*z }");
    geom_shape sh = shape_of(&w);
    vec3 lo, hi;
    assert_false(geom_quadric_solid_box(&sh, 0, v3(-1, -1, -1), v3(1, 1, 1), &lo, &hi));
    geom_shape_release(&sh);
    done(&w);
    /* a quarter turn about x: the cylinder x2 + y2 < 1 along z, within |z| < 3 */
    w = build("quadric { <1,0,1>, <0,0,0>, <0,0,0>, -1 rotate 90*x }");
    sh = shape_of(&w);
    assert_true(geom_quadric_solid_box(&sh, 0, v3(-INFINITY, -INFINITY, -3), v3(INFINITY, INFINITY, 3), &lo, &hi));
    assert_near(lo.x, -1.0, 1e-6);
    assert_near(hi.y, 1.0, 1e-6);
    assert_near(hi.z, 3.0, 1e-6);
    /* the paraboloid's inside x2 + z2 < y under y = 4: |x| < 2, y > 0 */
    geom_shape_release(&sh);
    done(&w);
    w = build("quadric { <1,0,1>, <0,0,0>, <0,-1,0>, 0 }");
    sh = shape_of(&w);
    assert_true(geom_quadric_solid_box(&sh, 0, v3s(-INFINITY), v3(INFINITY, 4, INFINITY), &lo, &hi));
    assert_near(lo.x, -2.0, 1e-6);
    assert_near(hi.z, 2.0, 1e-6);
    assert_near(lo.y, 0.0, 1e-6);
    geom_shape_release(&sh);
    done(&w);
}

static void test_poly(void **st)
{
    (void)st;
    /* torus R = 1, r = 0.25 as a quartic: (x2+y2+z2+R2-r2)^2 - 4R2(x2+z2) */
    double R2 = 1.0, r2 = 0.0625, k = R2 - r2;
    /* POV-Ray quartic order: x4 x3y x3z x3 x2y2 x2yz x2y x2z2 x2z x2 | xy3 .. x | y4 y3z y3 y2z2 y2z y2 yz3 yz2 yz y | z4 z3 z2 z c */
    double c[35] = {0};
    c[0] = 1;            /* x4 */
    c[4] = 2;            /* x2y2 */
    c[7] = 2;            /* x2z2 */
    c[9] = 2 * k - 4 * R2; /* x2 */
    c[20] = 1;           /* y4 */
    c[23] = 2;           /* y2z2 */
    c[25] = 2 * k;       /* y2 */
    c[30] = 1;           /* z4 */
    c[32] = 2 * k - 4 * R2; /* z2 */
    c[34] = k * k;
    char buf[2048];
    for (int sturm = 0; sturm < 2; sturm++) {
        int n = snprintf(buf, sizeof buf, "quartic { <");
        for (int i = 0; i < 35; i++) n += snprintf(buf + n, sizeof buf - n, "%s%.17g", i ? "," : "", c[i]);
        snprintf(buf + n, sizeof buf - n, "> %s clipped_by { box { -2, 2 } } }", sturm ? "sturm" : "");
        world w = build(buf);
        assert_int_equal(w.s->objects[0]->kind, SHAPE_POLY);
        assert_int_equal(w.s->objects[0]->u.poly->order, 4);
        expect_hit(&w, v3(-5, 0, 0), v3(1, 0, 0), 3.75, v3(-1, 0, 0), 1e-10, 1e-8);
        expect_hit(&w, v3(-1, 5, 0), v3(0, -1, 0), 4.75, v3(0, 1, 0), 1e-10, 1e-8);
        /* from the hole's middle outwards: the inner wall at x = 0.75 */
        expect_hit(&w, v3(0, 0, 0), v3(1, 0, 0), 0.75, v3(-1, 0, 0), 1e-10, 1e-8);
        /* grazing the tube's top: y = 0.25 - 1e-6 hits, + 1e-6 misses */
        accel_hit h;
        assert_true(hit(&w, v3(-1, 0.25 - 1e-6, -5), v3(0, 0, 1), &h));
        expect_miss(&w, v3(-1, 0.25 + 1e-6, -5), v3(0, 0, 1));
        done(&w);
    }
    /* poly syntax and the 3.7 polynomial syntax describe the same cubic: y = x^3 */
    world w = build("polynomial { 3, xyz(3,0,0): 1, xyz(0,1,0): -1 clipped_by { box { -3, 3 } } }");
    for (int i = -4; i <= 4; i++) {
        double x = 0.3 * i;
        expect_hit(&w, v3(x, -20, 0.5), v3(0, 1, 0), 20 + x * x * x, v3(0, 0, 0), 1e-10, -1);
    }
    done(&w);
}

/* ------------------------------------------------------------ blob */

static void test_blob(void **st)
{
    (void)st;
    /* one sphere component: s (1 - d2/r2)^2 = T at d = r sqrt(1 - sqrt(T/s)) */
    const double scales[] = {1e-4, 1.0, 1e5};
    char buf[256];
    for (int s = 0; s < 3; s++) {
        double k = scales[s];
        snprintf(buf, sizeof buf, "blob { threshold 0.25 sphere { <0,0,0>, 2, 1 } scale %g }", k);
        world w = build(buf);
        double d = 2 * sqrt(1 - sqrt(0.25));
        expect_hit(&w, v3(-5 * k, 0, 0), v3(1, 0, 0), (5 - d) * k, v3(-1, 0, 0), 1e-10 * k, 1e-9);
        expect_hit(&w, v3(0.3 * d * k, -5 * k, 0), v3(0, 1, 0), (5 - d * sqrt(1 - 0.09)) * k, v3(0.3, -sqrt(1 - 0.09), 0), 1e-10 * k, 1e-9);
        /* from inside: the far side */
        expect_hit(&w, v3(0, 0, 0), v3(0, 0, 1), d * k, v3(0, 0, 1), 1e-10 * k, 1e-9);
        done(&w);
    }
    /* two far components are two spheres; a cylinder component is a capsule */
    world w = build("blob { threshold 0.5 sphere { <-3,0,0>, 1, 2 } cylinder { <2,0,0>, <2,4,0>, 1, 2 } }");
    double d = sqrt(1 - sqrt(0.25));
    expect_hit(&w, v3(-3, 0, -5), v3(0, 0, 1), 5 - d, v3(0, 0, -1), 1e-10, 1e-9);
    expect_hit(&w, v3(2, 2, -5), v3(0, 0, 1), 5 - d, v3(0, 0, -1), 1e-10, 1e-9);
    expect_hit(&w, v3(2, 10, 0), v3(0, -1, 0), 6 - d, v3(0, 1, 0), 1e-10, 1e-9);
    expect_miss(&w, v3(0, 0, -5), v3(0, 0, 1));
    geom_shape sh = shape_of(&w);
    assert_true(geom_shape_inside(&sh, v3(2, 1, 0)));
    assert_false(geom_shape_inside(&sh, v3(0, 0, 0)));
    /* a general ray against the march */
    for (int i = 0; i < 10; i++) {
        vec3 o = v3(-6, -1 + 0.3 * i, 0.2);
        vec3 dd = v3_norm(v3(1, 0.1, 0.02 * i));
        double tb = march(&sh, o, dd, 1e-9, 14, 14000);
        accel_hit h;
        int got = hit(&w, o, dd, &h);
        if (isinf(tb)) { assert_false(got); continue; }
        assert_true(got);
        assert_near(h.t, tb, 1e-9);
    }
    geom_shape_release(&sh);
    done(&w);
}

/* ------------------------------------------------------------ sphere_sweep, bicubic_patch */

static void test_sphere_sweep(void **st)
{
    (void)st;
    /* linear: spheres r = 1 at x = 0 and r = 0.5 at x = 4 joined by the tangent cone */
    world w = build("sphere_sweep { linear_spline 2, <0,0,0>, 1, <4,0,0>, 0.5 }");
    expect_hit(&w, v3(-5, 0, 0), v3(1, 0, 0), 4.0, v3(-1, 0, 0), 1e-12, 1e-12);
    expect_hit(&w, v3(9, 0, 0), v3(-1, 0, 0), 4.5, v3(1, 0, 0), 1e-12, 1e-12);
    /* the cone's side: the envelope's distance from the axis at x = 2.
     * sin a = (r1 - r2) / d = 1/8; the tangent line is at distance
     * r(x) = (r1 - x sin a) / cos a from the axis */
    double sa = 0.125, ca = sqrt(1 - sa * sa), r = (1 - 2 * sa) / ca;
    expect_hit(&w, v3(2, 5, 0), v3(0, -1, 0), 5 - r, v3(sa, ca, 0), 1e-9, 1e-9);
    done(&w);
    /* b_spline sweeps are sampled into linear pieces: the tube stays within its radius */
    w = build("sphere_sweep { b_spline 4, <-2,0,0>, 0.5, <0,0,0>, 0.5, <2,0,0>, 0.5, <4,0,0>, 0.5 }");
    expect_hit(&w, v3(1, 5, 0), v3(0, -1, 0), 4.5, v3(0, 1, 0), 1e-9, 1e-9);
    done(&w);
}

static void test_bicubic_patch(void **st)
{
    (void)st;
    /* a flat patch (control points on z = 0): the mesh lies in the plane */
    world w = build("bicubic_patch { type 1 u_steps 3 v_steps 3 "
                    "<0,0,0>, <1,0,0>, <2,0,0>, <3,0,0>, <0,1,0>, <1,1,0>, <2,1,0>, <3,1,0>,"
                    "<0,2,0>, <1,2,0>, <2,2,0>, <3,2,0>, <0,3,0>, <1,3,0>, <2,3,0>, <3,3,0> }");
    assert_int_equal(w.s->objects[0]->kind, SHAPE_MESH);
    expect_hit(&w, v3(1.3, 2.2, -5), v3(0, 0, 1), 5.0, v3(0, 0, 0), 1e-6, -1);
    expect_miss(&w, v3(3.3, 2.2, -5), v3(0, 0, 1));
    done(&w);
}

/* ------------------------------------------------------------ clipped_by, CSG */

static void test_clipped_by(void **st)
{
    (void)st;
    /* a sphere clipped by a box: the sphere's surface only where inside the box */
    world w = build("sphere { 0, 1 clipped_by { box { <-2,-2,-2>, <2,0.5,2> } } translate <0,0,10> }");
    expect_hit(&w, v3(-5, 0, 10), v3(1, 0, 0), 4.0, v3(-1, 0, 0), 1e-12, 1e-12);
    /* above y = 0.5 the sphere is gone: the ray sees the inside of the far wall */
    double y = 0.8, x = sqrt(1 - y * y);
    expect_miss(&w, v3(-5, y, 10), v3(1, 0, 0) );
    (void)x;
    /* looking down into the open top: the inner surface at the bottom */
    expect_hit(&w, v3(0, 5, 10), v3(0, -1, 0), 6.0, v3(0, 1, 0), 1e-12, -1);
    done(&w);
    /* a lathe in a difference with a box (CSG members with many crossings) */
    w = build("difference { lathe { linear_spline 5, <0,0>, <1,0>, <1,1>, <0,1>, <0,0> } box { <0,-1,-2>, <2,2,2> } }");
    expect_hit(&w, v3(-5, 0.5, 0), v3(1, 0, 0), 4.0, v3(-1, 0, 0), 1e-12, 1e-12);
    expect_hit(&w, v3(5, 0.5, 0.5), v3(-1, 0, 0), 5.0, v3(1, 0, 0), 1e-12, 1e-12); /* the cut face at x = 0 */
    done(&w);
    /* a courtyard: a slab with a box cut through its top (the rays whose
     * stretch through the slab's box lies inside the cut skip the members,
     * geom_csg.h holes); each answer against the faces' closed form */
    w = build("difference { box { <-10,-0.1,-10>, <10,4,10> } box { <-4,0.1,-4>, <4,5,4> } }");
    expect_miss(&w, v3(0, 1, 0), v3(0, 1, 0));               /* straight up, out of the cut */
    expect_miss(&w, v3(0, 1, 0), v3(1, 1, 0));               /* leaves the slab's box at x = 3 */
    expect_hit(&w, v3(0, 1, 0), v3(1, 0.74, 0), 4.0, v3(-1, 0, 0), 1e-12, 1e-12); /* the cut's wall at y 3.96 */
    expect_hit(&w, v3(0, 1, 0), v3(1, 0, 0), 4.0, v3(-1, 0, 0), 1e-12, 1e-12);
    expect_hit(&w, v3(0, 1, 0), v3(0, -1, 0), 0.9, v3(0, 1, 0), 1e-12, 1e-12);   /* its floor */
    expect_hit(&w, v3(5, 6, 0), v3(0, -1, 0), 2.0, v3(0, 1, 0), 1e-12, 1e-12);   /* from above, onto its top */
    expect_hit(&w, v3(1, 6, 0), v3(0.5, -1, 0), 5.9, v3(0, 1, 0), 1e-12, 1e-12); /* down the cut to its floor */
    assert_false(accel_occluded(w.a, v3(0, 1, 0), v3(0, 1, 0), 0.0, INFINITY));
    assert_true(accel_occluded(w.a, v3(0, 1, 0), v3(1, 0.74, 0), 0.0, INFINITY));
    assert_false(accel_occluded(w.a, v3(0, 1, 0), v3(1, 0.74, 0), 0.0, 3.9));
    done(&w);
    /* two cuts a ray crosses one after the other (geom_csg.c hole_clear):
     * a column base, a ring cut through by a band, and a courtyard with an
     * arcade round it; each answer against the faces' closed form, where
     * the cuts chain to the box's far side, where the ray meets a face in
     * the second cut, and where solid lies between the two */
    w = build("difference { box { <-4.7,0,-4.7>, <4.7,3.6,4.7> } box { <-4.1,-0.1,-4.1>, <4.1,4,4.1> } "
              "box { <-5,0.5,-5>, <5,3.3,5> } }");
    expect_miss(&w, v3(0, 1, 0), v3(1, 0, 0));                                     /* both cuts, then out */
    expect_miss(&w, v3(10, 1, 0), v3(-1, 0, 0));                                   /* through the band from outside */
    expect_hit(&w, v3(0, 1, 0), v3(1, 0.5, 0), 4.6, v3(0, -1, 0), 1e-12, 1e-12);   /* the top ring's underside */
    expect_hit(&w, v3(0, 0.2, 0), v3(1, 0, 0), 4.1, v3(-1, 0, 0), 1e-12, 1e-12);   /* the bottom ring, below the band */
    expect_hit(&w, v3(10, 3.4, 0), v3(-1, 0, 0), 5.3, v3(1, 0, 0), 1e-12, 1e-12); /* the top ring from outside */
    assert_false(accel_occluded(w.a, v3(0, 1, 0), v3(1, 0, 0), 0.0, INFINITY));
    assert_true(accel_occluded(w.a, v3(0, 1, 0), v3(1, 0.5, 0), 0.0, INFINITY));
    assert_false(accel_occluded(w.a, v3(0, 1, 0), v3(1, 0.5, 0), 0.0, 4.59));
    done(&w);
    w = build("difference { box { <-10,-0.1,-10>, <10,4,10> } box { <-9,0.3,-9>, <9,3.5,9> } "
              "box { <-4,0.1,-4>, <4,5,4> } }");
    expect_hit(&w, v3(0, 1, 0), v3(1, 0, 0), 9.0, v3(-1, 0, 0), 1e-12, 1e-12);  /* across the arcade to its wall */
    expect_hit(&w, v3(0, 0.2, 0), v3(1, 0, 0), 4.0, v3(-1, 0, 0), 1e-12, 1e-12); /* the step between the floors */
    expect_hit(&w, v3(0, 1, 0), v3(1, 0.4, 0), 6.25, v3(0, -1, 0), 1e-12, 1e-12); /* the arcade's ceiling */
    expect_hit(&w, v3(0, 1, 0), v3(1, -0.1, 0), 7.0, v3(0, 1, 0), 1e-12, 1e-12); /* the arcade's floor */
    done(&w);
}

/* isosurface: user functions (core/func.h) against closed forms; the
 * normal is POV-Ray's forward difference over accuracy (isosurf.cpp),
 * within 1.5 accuracy / radius of the sphere's. */
/* An isosurface hit under both ray rules (accel.h): ACCEL_RAY_EXACT at the
 * root t to 1e-10, ACCEL_RAY_POV (accel_intersect) at the far end of
 * POV-Ray's halving piece holding it: in [t, t + accuracy]. */
static void expect_iso_hit(const world *w, vec3 o, vec3 d, double t, double acc)
{
    accel_hit h;
    if (!accel_intersect_rule(w->a, ACCEL_RAY_EXACT, o, d, 0.0, INFINITY, &h)) fail_msg("expected a hit at t = %.17g", t);
    assert_near(h.t, t, 1e-10);
    if (!hit(w, o, d, &h)) fail_msg("expected a hit at t = %.17g", t);
    if (!(h.t >= t - 1e-12 && h.t <= t + acc)) fail_msg("POV-Ray's placement: t = %.17g, not in [%.17g, +%g]", h.t, t, acc);
}

static void test_isosurface(void **st)
{
    (void)st;
    world w = build("isosurface { function { sqrt(x*x + y*y + z*z) - 0.5 } contained_by { box { -1, 1 } } "
                    "max_gradient 1.01 accuracy 1e-4 translate <0,0,3> }");
    assert_int_equal(w.s->objects[0]->kind, SHAPE_ISOSURFACE);
    assert_near(accel_hit_placement(w.s->objects[0]), 1e-4, 0.0);
    for (int i = 0; i < 6; i++) {
        double y = 0.08 * i, x = sqrt(0.25 - y * y);
        expect_iso_hit(&w, v3(-5, y, 3), v3(1, 0, 0), 5 - x, 1e-4);
        expect_hit(&w, v3(-5, y, 3), v3(1, 0, 0), 5 - x, v3(-x, y, 0), 1e-4, 3e-4);
    }
    expect_miss(&w, v3(-5, 0.6, 3), v3(1, 0, 0));
    done(&w);
    /* the half-space y < 0 in a box: the box's faces show where they are inside */
    w = build("isosurface { function { y } }");
    expect_iso_hit(&w, v3(0.3, 5, 0.2), v3(0, -1, 0), 5.0, 1e-3);
    expect_hit(&w, v3(-5, -0.5, 0.2), v3(1, 0, 0), 4.0, v3(-1, 0, 0), 1e-12, 1e-12);
    expect_miss(&w, v3(-5, 0.5, 0.2), v3(1, 0, 0));
    geom_shape sh = shape_of(&w);
    assert_true(geom_shape_inside(&sh, v3(0.2, -0.3, 0.1)));
    assert_false(geom_shape_inside(&sh, v3(0.2, 0.3, 0.1)));
    assert_false(geom_shape_inside(&sh, v3(0.2, -1.3, 0.1)));
    geom_shape_release(&sh);
    done(&w);
    /* a ray that starts on the surface (f within 4 max_gradient accuracy =
     * 0.044 of the threshold) searches from 5 accuracy (0.05) on under
     * POV-Ray's rule: from 0.004 below the plane y = 0 upwards it does not
     * find the plane it leaves (the exact rule does, at 0.004); one that
     * starts 0.1 below it does (f = -0.1 is not near) */
    w = build("isosurface { function { y } accuracy 0.01 }");
    accel_hit h;
    assert_true(accel_intersect_rule(w.a, ACCEL_RAY_EXACT, v3(0.2, -0.004, 0.1), v3(0, 1, 0), 0.0, INFINITY, &h));
    assert_near(h.t, 0.004, 1e-10);
    expect_miss(&w, v3(0.2, -0.004, 0.1), v3(0, 1, 0));
    expect_hit(&w, v3(0.2, -0.1, 0.1), v3(0, 1, 0), 0.1, v3(0, 1, 0), 0.01, 1e-6);
    /* downwards from just above the plane: 5 accuracy on it is inside, so
     * the search is for the way out: the box's bottom face, where the
     * inside reaches it (t = 1.004); the exact rule meets the plane */
    expect_hit(&w, v3(0.2, 0.004, 0.1), v3(0, -1, 0), 1.004, v3(0, -1, 0), 1e-9, 1e-9);
    assert_true(accel_intersect_rule(w.a, ACCEL_RAY_EXACT, v3(0.2, 0.004, 0.1), v3(0, -1, 0), 0.0, INFINITY, &h));
    assert_near(h.t, 0.004, 1e-10);
    done(&w);
    w = build("isosurface { function { y } open contained_by { sphere { 0, 1 } } threshold 0.25 }");
    expect_miss(&w, v3(-5, -0.5, 0.0), v3(1, 0, 0));
    expect_iso_hit(&w, v3(0.3, 5, 0.2), v3(0, -1, 0), 4.75, 1e-3);
    done(&w);
}

/* parametric: tessellated (96 x 96 quads); a unit sphere to within its chord error */
static void test_parametric(void **st)
{
    (void)st;
    world w = build("parametric { function { cos(u)*cos(v) } function { sin(v) } function { sin(u)*cos(v) }"
                    " <0,-pi/2>, <2*pi,pi/2> contained_by { box { -1, 1 } } precompute 10, x, y, z }");
    assert_int_equal(w.s->objects[0]->kind, SHAPE_MESH);
    for (int i = 0; i < 8; i++) {
        double y = 0.1 * i, x = sqrt(1 - y * y);
        accel_hit h;
        assert_true(hit(&w, v3(-5, y, 0.03), v3(1, 0, 0), &h));
        assert_near(v3_len(h.p), 1.0, 1e-3);
        assert_near(h.t, 5 - sqrt(x * x - 0.0009), 2e-3);
        assert_true(v3_dot(h.ns, v3_norm(h.p)) > 0.999 || v3_dot(h.ns, v3_norm(h.p)) < -0.999);
    }
    done(&w);
}

/* julia_fractal with c = 0: z -> z^2 keeps |z| <= 1, so the set is (to
 * ~1e-6 at 20 iterations) the unit ball for quaternions; for hypercomplex
 * numbers (two complex squares) the points with x^2 + (y +- z)^2 <= 1 */
static void test_julia(void **st)
{
    (void)st;
    world w = build("julia_fractal { <0,0,0,0> quaternion sqr max_iteration 20 precision 50 }");
    assert_int_equal(w.s->objects[0]->kind, SHAPE_JULIA);
    for (int i = 0; i < 5; i++) {
        double y = 0.15 * i, x = sqrt(1 - y * y);
        expect_hit(&w, v3(-5, y, 0.1), v3(1, 0, 0), 5 - sqrt(x * x - 0.01), v3(-sqrt(x * x - 0.01), y, 0.1), 1e-5, 1e-3);
    }
    expect_miss(&w, v3(-5, 1.01, 0), v3(1, 0, 0));
    geom_shape sh = shape_of(&w);
    assert_true(geom_shape_inside(&sh, v3(0.3, 0.4, 0.5)));
    assert_false(geom_shape_inside(&sh, v3(0.7, 0.6, 0.5)));
    geom_shape_release(&sh);
    done(&w);
    w = build("julia_fractal { <0,0,0,0> hypercomplex sqr }");
    expect_hit(&w, v3(-5, 0, 0), v3(1, 0, 0), 4.0, v3(-1, 0, 0), 1e-5, 1e-3);
    /* at y = 0.5 along x: x^2 + 0.25 = 1 */
    expect_hit(&w, v3(-5, 0.5, 0), v3(1, 0, 0), 5 - sqrt(0.75), v3(-sqrt(0.75), 0.5, 0), 1e-5, 1e-3);
    done(&w);
    /* the distribution's cube quaternion parses and renders something */
    w = build("julia_fractal { <-.54,.57,0,-.37> quaternion cube max_iteration 8 precision 20 }");
    accel_hit h;
    assert_true(hit(&w, v3(-5, 0, 0), v3(1, 0, 0), &h));
    assert_true(h.t > 3.0 && h.t < 5.0);
    done(&w);
}

/* GI sampling: polygons and height fields are sampled uniformly by area */
static void test_surface_sampling(void **st)
{
    (void)st;
    world w = build("polygon { 10, <-2,-2>, <2,-2>, <2,2>, <-2,2>, <-2,-2>,"
                    " <-1,-1>, <1,-1>, <1,1>, <-1,1>, <-1,-1> scale <2,1,1> rotate 30*y }");
    pt_status ps;
    accel_surf *as = accel_surf_build(w.s, w.a, NULL, NULL, w.d, &ps);
    assert_non_null(as);
    assert_near(accel_surf_total_area(as), 2 * 12.0, 1e-9);
    rng r;
    rng_seed(&r, 7, 1);
    double inner = 0;
    for (int i = 0; i < 4000; i++) {
        accel_surf_sample sm;
        assert_true(accel_surf_sample_point(as, rng_f64(&r), rng_f64(&r), rng_f64(&r), &r, &sm));
        assert_near(sm.pdf_area, 1.0 / 24.0, 1e-12);
        /* back to the polygon's plane: inside the square, outside the hole */
        vec3 q = xform_inv_point(&w.s->objects[0]->transform, sm.p);
        assert_near(q.z, 0.0, 1e-9);
        assert_true(fabs(q.x) <= 2 + 1e-9 && fabs(q.y) <= 2 + 1e-9);
        assert_false(fabs(q.x) < 1 - 1e-9 && fabs(q.y) < 1 - 1e-9);
        if (fabs(q.x) < 1.5 && fabs(q.y) < 1.5) inner++;
    }
    /* the ring 1 < max(|x|,|y|) < 1.5 holds 5 of the 12 area units */
    assert_near(inner / 4000.0, 5.0 / 12.0, 0.03);
    accel_hit h;
    assert_true(hit(&w, v3(3, 0.5, -10), v3(0, 0, 1), &h) || hit(&w, v3(0, 1.5, -10), v3(0, 0, 1), &h));
    assert_near(accel_surf_pdf(as, &h), 1.0 / 24.0, 1e-12);
    accel_surf_free(as);
    done(&w);

    char path[] = "/tmp/test_shapes_hf2XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    unsigned char v[9] = {0, 127, 254, 0, 127, 254, 0, 127, 254};
    write_pgm(path, 3, 3, v);
    char src[512];
    snprintf(src, sizeof src, "height_field { pgm \"%s\" scale <2,1,3> }", path);
    w = build(src);
    as = accel_surf_build(w.s, w.a, NULL, NULL, w.d, &ps);
    assert_non_null(as);
    double top = 254 * 257 / 65536.0;
    assert_near(accel_surf_total_area(as), 3.0 * sqrt(4.0 + top * top), 1e-9);
    assert_true(hit(&w, v3(1.1, 5, 1.7), v3(0, -1, 0), &h));
    assert_near(accel_surf_pdf(as, &h), 1.0 / accel_surf_total_area(as), 1e-12);
    accel_surf_free(as);
    done(&w);
    unlink(path);
}

/* GI sampling of the spline shapes: exact areas, points on the surface
 * with outward normals, parts in proportion to their areas */
static void check_sampled(const char *src, double area, unsigned side_lo, unsigned side_hi, double side_fraction)
{
    world w = build(src);
    pt_status ps;
    accel_surf *as = accel_surf_build(w.s, w.a, NULL, NULL, w.d, &ps);
    assert_non_null(as);
    assert_near(accel_surf_total_area(as), area, 1e-9 * area);
    geom_shape sh = shape_of(&w);
    rng r;
    rng_seed(&r, 11, 3);
    int side = 0, n = 4000;
    for (int i = 0; i < n; i++) {
        accel_surf_sample sm;
        assert_true(accel_surf_sample_point(as, rng_f64(&r), rng_f64(&r), rng_f64(&r), &r, &sm));
        assert_near(sm.pdf_area, 1.0 / area, 1e-9 / area);
        double e = 1e-6 * sqrt(area);
        assert_true(geom_shape_inside(&sh, v3_madd(sm.p, sm.n, -e)));
        assert_false(geom_shape_inside(&sh, v3_madd(sm.p, sm.n, e)));
        if (sm.prim >= side_lo && sm.prim <= side_hi) side++;
    }
    assert_near((double)side / n, side_fraction, 0.03);
    geom_shape_release(&sh);
    accel_surf_free(as);
    done(&w);
}

static void test_sweep_sampling(void **st)
{
    (void)st;
    /* cylinder r = 1, h = 1 with flat ends: 4 pi, half of it the side */
    check_sampled("lathe { linear_spline 5, <0,0>, <1,0>, <1,1>, <0,1>, <0,0> }", 4 * M_PI, 3, 3, 0.5);
    check_sampled("sor { 4, <1,-1>, <1,0>, <1,1>, <1,2> scale 2 translate x }", 16 * M_PI, 2, 2, 0.5);
    /* 2x2 square with a 1x1 hole, height 1: caps 2 x 3, walls 12 */
    check_sampled("prism { 0, 1, 10, <-1,-1>, <1,-1>, <1,1>, <-1,1>, <-1,-1>, <-0.5,-0.5>, <0.5,-0.5>, <0.5,0.5>,"
                  " <-0.5,0.5>, <-0.5,-0.5> rotate <10,20,30> }", 18.0, 2, 1000, 12.0 / 18.0);
    /* paraboloid lathe r = 1 + y^2, y in [0,1] (open): 2 pi int (1 + y^2) sqrt(1 + 4 y^2) dy */
    double a = 0.0;
    for (int i = 0; i < 200000; i++) {
        double y = (i + 0.5) / 200000.0;
        a += (1 + y * y) * sqrt(1 + 4 * y * y) / 200000.0;
    }
    world w = build("lathe { quadratic_spline 6, <1.0625,-0.25>, <1,0>, <1.0625,0.25>, <1.25,0.5>, <1.5625,0.75>, <2,1> }");
    pt_status ps;
    accel_surf *as = accel_surf_build(w.s, w.a, NULL, NULL, w.d, &ps);
    assert_near(accel_surf_total_area(as), 2 * M_PI * a, 1e-8);
    accel_surf_free(as);
    done(&w);
}

/* GI sampling of the implicit shapes by random lines (geom_tess.h):
 * the area estimate against closed forms, points on the surface with
 * outward normals, uniform by area (Archimedes: z uniform on a sphere).
 * The estimate's standard error is asked at 0.1% (CROFTON_REL_ERR);
 * tolerance 1%. */
static double only_kind_w(void *ctx, const scene_object *o, const scene_texture *t, unsigned f)
{
    (void)t; (void)f;
    return o->kind == *(const shape_kind *)ctx ? 1.0 : 0.0;
}

/* prolate spheroid x^2/a^2 + y^2/a^2 + z^2/c^2 = 1, c > a */
static double prolate_area(double a, double c)
{
    double e = sqrt(1.0 - a * a / (c * c));
    return 2.0 * M_PI * a * a * (1.0 + c / (a * e) * asin(e));
}

static void check_crofton(const char *src, shape_kind kind, double area, double zlo, double zhi, double zfrac)
{
    world w = build(src);
    pt_status ps;
    accel_surf *as = accel_surf_build(w.s, w.a, only_kind_w, &kind, w.d, &ps);
    assert_non_null(as);
    assert_int_equal(accel_surf_count(as), 1);
    double got = accel_surf_total_area(as);
    if (fabs(got - area) > 0.01 * area) fail_msg("%s: area %.6g, exact %.6g", src, got, area);
    print_message("crofton area %+.4f%% %s\n", 100.0 * (got - area) / area, src);
    const scene_object *o = NULL;
    for (int i = 0; i < w.s->nobjects; i++)
        if (w.s->objects[i]->kind == kind) o = w.s->objects[i];
    geom_shape sh;
    assert_int_equal(geom_shape_init(&sh, o), 0);
    if (sh.infinite) geom_shape_clip_plane(&sh, v3s(-1e3), v3s(1e3));
    rng r;
    rng_seed(&r, 5, 9);
    int n = 4000, band = 0;
    for (int i = 0; i < n; i++) {
        accel_surf_sample sm;
        assert_true(accel_surf_sample_point(as, rng_f64(&r), rng_f64(&r), rng_f64(&r), &r, &sm));
        assert_near(sm.pdf_area, 1.0 / got, 1e-9 / got);
        double e = 1e-6 * sqrt(area);
        if (!geom_shape_inside(&sh, v3_madd(sm.p, sm.n, -e)) || geom_shape_inside(&sh, v3_madd(sm.p, sm.n, e)))
            fail_msg("%s: sample %d not on the surface with an outward normal", src, i);
        if (sm.p.z > zlo && sm.p.z < zhi) band++;
        /* the sample's own hit gets the same density */
        accel_hit h;
        if (i < 200 && hit(&w, v3_madd(sm.p, sm.n, 1e-3), v3_neg(sm.n), &h) && h.obj == o)
            assert_near(accel_surf_pdf(as, &h), 1.0 / got, 1e-9 / got);
    }
    /* binomial: 4 standard deviations */
    double sd = sqrt(zfrac * (1 - zfrac) / n);
    if (fabs((double)band / n - zfrac) > 4 * sd) fail_msg("%s: band holds %.4f, expected %.4f", src, (double)band / n, zfrac);
    geom_shape_release(&sh);
    accel_surf_free(as);
    done(&w);
}

static void test_implicit_sampling(void **st)
{
    (void)st;
    /* one blob component: strength (1 - (d/r)^2)^2 = threshold at
     * d = r sqrt(1 - sqrt(threshold / strength)) */
    double d = 2.0 * sqrt(1.0 - sqrt(0.5));
    check_crofton("blob { threshold 0.5 sphere { <0,0,0>, 2, 1 } }", SHAPE_BLOB, 4 * M_PI * d * d, 0.5 * d, d, 0.25);
    /* the same under a non-uniform scale: a prolate spheroid */
    check_crofton("blob { threshold 0.5 sphere { <0,0,0>, 2, 1 } scale <1,1,2> }", SHAPE_BLOB,
                  prolate_area(d, 2 * d), -1e9, 1e9, 1.0);
    /* quadric ellipsoid x^2 + y^2 + z^2/4 = 1, rotated */
    check_crofton("quadric { <1,1,0.25>, <0,0,0>, <0,0,0>, -1 rotate <30,40,50> }", SHAPE_QUADRIC,
                  prolate_area(1, 2), -1e9, 1e9, 1.0);
    /* infinite cylinder quadric x^2 + y^2 = 1 inside the scene's finite extent
     * (a box, z in [-3, 3]): the side, 12 pi; z uniform on it */
    check_crofton("quadric { <1,1,0>, <0,0,0>, <0,0,0>, -1 } box { <-2,-2,-3>, <2,2,3> }", SHAPE_QUADRIC,
                  12 * M_PI, 1.5, 3.0, 0.25);
    /* the unit sphere as a poly (order 2: x2 xy xz x y2 yz y z2 z 1), an
     * isosurface, a superellipsoid and a julia_fractal (c = 0: |q| <= 1) */
    check_crofton("poly { 2, <1,0,0,0,1,0,0,1,0,-1> } box { <-2,-2,-2>, <2,2,2> }", SHAPE_POLY, 4 * M_PI, 0.5, 1,
                  0.25);
    check_crofton("isosurface { function { x*x + y*y + z*z - 1 } contained_by { box { -2, 2 } } max_gradient 8 }", SHAPE_ISOSURFACE,
                  4 * M_PI, 0.5, 1, 0.25);
    check_crofton("superellipsoid { <1, 1> }", SHAPE_SUPERELLIPSOID, 4 * M_PI, 0.5, 1, 0.25);
    check_crofton("julia_fractal { <0,0,0,0> quaternion sqr max_iteration 20 precision 50 }", SHAPE_JULIA, 4 * M_PI, 0.5, 1, 0.25);
}

/* parametric grids for GI: vertices on the surface with outward normals,
 * total area close to the exact one */
typedef struct {
    const geom_shape *sh;
    double area;
    int bad, inside_checks, verts;
    double tol; /* inside_checks 2: how far off the surface a vertex may be */
} grid_check;

static int grid_cb(void *ctx, const vec3 p[3], const vec3 n[3])
{
    grid_check *g = ctx;
    g->area += 0.5 * v3_len(v3_cross(v3_sub(p[1], p[0]), v3_sub(p[2], p[0])));
    for (int k = 0; k < 3; k++) {
        g->verts++;
        if (fabs(v3_len(n[k]) - 1.0) > 1e-9) g->bad += 1000;
        if (g->inside_checks == 2) {
            /* the vertex on the surface to g->tol, the normal outward */
            if (!geom_shape_inside(g->sh, v3_madd(p[k], n[k], -g->tol)) || geom_shape_inside(g->sh, v3_madd(p[k], n[k], g->tol)))
                g->bad++;
        } else if (g->inside_checks) {
            /* back along the normal from just outside: the surface at the
             * vertex, at its exact root (GEOM_RAY_EXACT) */
            /* nudged towards the triangle's centre, off edges and corners */
            vec3 c = v3_scale(v3_add(v3_add(p[0], p[1]), p[2]), 1.0 / 3.0);
            vec3 q = v3_madd(p[k], v3_sub(c, p[k]), 1e-6);
            double e = 1e-3;
            geom_shape_hit h;
            if (!geom_shape_intersect(g->sh, v3_madd(q, n[k], e), v3_neg(n[k]), 0.0, 1.0, &h, GEOM_RAY_EXACT) || fabs(h.t - e) > 1e-8)
                g->bad++;
        }
    }
    return 1;
}

static void check_grid_tol(const char *src, int inside_checks, double area, double rel, double tol)
{
    world w = build(src);
    geom_shape sh = shape_of(&w);
    grid_check g = {&sh, 0.0, 0, inside_checks, 0, tol};
    int nt = geom_shape_grid(&sh, 16, grid_cb, &g);
    if (nt <= 0) fail_msg("%s: no grid", src);
    /* (a vertex exactly on a cap's rim may miss the cap by rounding) */
    if (g.bad > g.verts / 100) fail_msg("%s: %d of %d vertices off the surface", src, g.bad, g.verts);
    assert_near(g.area, area, rel * area);
    geom_shape_release(&sh);
    done(&w);
}

static void check_grid(const char *src, int inside_checks, double area, double rel)
{
    check_grid_tol(src, inside_checks, area, rel, 1e-9);
}

static void test_grid(void **st)
{
    (void)st;
    /* areas: tessellation error ~ (2 pi / 64)^2 / 12 for the round parts */
    check_grid("lathe { linear_spline 5, <0,0>, <1,0>, <1,1>, <0,1>, <0,0> }", 1, 4 * M_PI, 2e-3);
    check_grid("sor { 4, <1,-1>, <1,0>, <1,1>, <1,2> }", 1, 4 * M_PI, 2e-3);
    check_grid("prism { 0, 1, 10, <-1,-1>, <1,-1>, <1,1>, <-1,1>, <-1,-1>, <-0.5,-0.5>, <0.5,-0.5>, <0.5,0.5>,"
               " <-0.5,0.5>, <-0.5,-0.5> }", 1, 18.0, 1e-12);
    check_grid("prism { conic_sweep 0.5, 1, 5, <-1,-1>, <1,-1>, <1,1>, <-1,1>, <-1,-1> }", 1,
               /* caps 4 (0.25 + 1), sides 4 x trapezoids of height sqrt(0.25 + 0.25) and widths 1, 2 */
               4 * 1.25 + 4 * 1.5 * sqrt(0.5), 1e-9);
    check_grid("polygon { 10, <-2,-2>, <2,-2>, <2,2>, <-2,2>, <-2,-2>, <-1,-1>, <1,-1>, <1,1>, <-1,1>, <-1,-1> }", 0,
               12.0, 1e-12);
    check_grid("superellipsoid { <1, 1> }", 1, 4 * M_PI, 5e-3);
    /* marching tetrahedra (geom_tess.h), 16 cells across: the inscribed
     * triangles' area falls short by O(h^2); 2% at this resolution */
    double d = 2.0 * sqrt(1.0 - sqrt(0.5));
    check_grid("blob { threshold 0.5 sphere { <0,0,0>, 2, 1 } }", 2, 4 * M_PI * d * d, 2e-2);
    check_grid("quadric { <1,1,0.25>, <0,0,0>, <0,0,0>, -1 }", 2, 2 * M_PI * (1 + 2 / sqrt(0.75) * asin(sqrt(0.75))), 2e-2);
    check_grid("isosurface { function { x*x + y*y + z*z - 1 } contained_by { box { -2, 2 } } max_gradient 8 }", 2, 4 * M_PI, 2e-2);
    /* a fractal's crossings are polished to POV-Ray's Fractal_Tolerance, 1e-7 */
    check_grid_tol("julia_fractal { <0,0,0,0> quaternion sqr max_iteration 20 precision 50 }", 2, 4 * M_PI, 2e-2, 2e-7);
    if (access("/usr/share/povray-3.7/include/timrom.ttf", R_OK) == 0) {
        world w = build("text { ttf \"timrom.ttf\" \"O\" 0.2, 0 }");
        geom_shape sh = shape_of(&w);
        grid_check g = {&sh, 0.0, 0, 0, 0};
        assert_true(geom_shape_grid(&sh, 8, grid_cb, &g) > 10);
        assert_int_equal(g.bad, 0);
        geom_shape_release(&sh);
        done(&w);
    }
}

/* ovus (POV-Ray 3.7's Parse_Ovus geometry): tube radius rc = 2 max(rb, rt),
 * generating circle centred at (-h, v), tangent inside both spheres;
 * closed-form hits, inside, the sphere substitute for rt >= 2 rb, area by
 * zones: 2 pi rb (yb + rb) + 2 pi rt (rb + rt - yt) + 2 pi rc [u - h asin(u / rc)]
 * between u = yb - v and yt - v */
/* A thin ring (torus 130, 2: its box is mostly its hole; hits_torus
 * leaves out the stretches whose distance from the axis stays clear of the
 * tube): hits against the circle's closed form, in the tube near its inner
 * and outer edges, and misses just beside it. */
static void test_thin_torus(void **st)
{
    (void)st;
    world w = build("torus { 130, 2 }");
    /* down through the tube at rho = 128.5: y = sqrt(4 - 1.5^2) */
    double y = sqrt(1.75);
    expect_hit(&w, v3(128.5, 10, 0), v3(0, -1, 0), 10.0 - y, v3(-0.75, y / 2.0, 0), 1e-7, 1e-6);
    expect_hit(&w, v3(0, 10, -131.5), v3(0, -1, 0), 10.0 - y, v3(0, y / 2.0, -0.75), 1e-7, 1e-6);
    expect_miss(&w, v3(127.95, 10, 0), v3(0, -1, 0));  /* in the hole, 0.05 from the tube */
    expect_miss(&w, v3(0, 10, 132.05), v3(0, -1, 0));  /* outside it */
    expect_hit(&w, v3(0, 0, 0), v3(1, 0, 0), 128.0, v3(-1, 0, 0), 1e-7, 1e-6); /* across the hole */
    expect_hit(&w, v3(0, 1, 0), v3(0, 0, 1), 130.0 - sqrt(3.0), v3(0, 0.5, -sqrt(3.0) / 2.0), 1e-7, 1e-6);
    expect_miss(&w, v3(0, 2.05, 0), v3(1, 0, 0)); /* over it */
    done(&w);
}

static void test_ovus(void **st)
{
    (void)st;
    double rb = 1.0, rt = 0.65, rc = 2.0;
    double v = (rb * rb + (rc - rb) * (rc - rb) - (rc - rt) * (rc - rt)) / (2 * rb);
    double h = sqrt((rc - rb) * (rc - rb) - v * v);
    double yb = -v * rb / (rc - rb), yt = (rc * rb - v * rt) / (rc - rt);
    /* POV-Ray's own expressions for the same numbers (Parse_Ovus) */
    assert_near(v, 2 * rt - rb - rt * rt / (2 * rb), 1e-15);
    assert_near(yt, (rb - v) * rt / (rc - rt) + rb, 1e-15);
    world w = build("ovus { 1, 0.65 }");
    assert_int_equal(w.s->objects[0]->kind, SHAPE_OVUS);
    expect_hit(&w, v3(0, -5, 0), v3(0, 1, 0), 4.0, v3(0, -1, 0), 1e-12, 1e-12);
    expect_hit(&w, v3(0, 5, 0), v3(0, -1, 0), 5 - (rb + rt), v3(0, 1, 0), 1e-12, 1e-12);
    /* across the lemon at heights inside (yb, yt): x = sqrt(rc^2 - (y - v)^2) - h */
    for (int i = 1; i < 6; i++) {
        double y = yb + (yt - yb) * i / 6.0, x = sqrt(rc * rc - (y - v) * (y - v)) - h;
        vec3 n = v3_norm(v3(-(x + h), y - v, 0));
        expect_hit(&w, v3(-5, y, 0), v3(1, 0, 0), 5 - x, n, 1e-12, 1e-12);
    }
    /* the bottom sphere below yb, the top sphere above yt */
    double y0 = -0.5, x0 = sqrt(rb * rb - y0 * y0);
    expect_hit(&w, v3(-5, y0, 0), v3(1, 0, 0), 5 - x0, v3(-x0, y0, 0), 1e-12, 1e-12);
    double y1 = 1.5, x1 = sqrt(rt * rt - (y1 - rb) * (y1 - rb));
    expect_hit(&w, v3(-5, y1, 0), v3(1, 0, 0), 5 - x1, v3_norm(v3(-x1, y1 - rb, 0)), 1e-12, 1e-12);
    /* scales 1e-4 .. 1e5 */
    done(&w);
    for (int e = -4; e <= 5; e += 3) {
        double sc = pow(10.0, e);
        char src[128];
        snprintf(src, sizeof src, "ovus { 1, 0.65 scale %g }", sc);
        w = build(src);
        expect_hit(&w, v3(-5 * sc, 0.3 * sc, 0), v3(1, 0, 0), sc * (5 - (sqrt(rc * rc - (0.3 - v) * (0.3 - v)) - h)),
                   v3_norm(v3(-(sqrt(rc * rc - (0.3 - v) * (0.3 - v))), 0.3 - v, 0)), 1e-11 * sc, 1e-9);
        done(&w);
    }
    w = build("ovus { 1, 0.65 }");
    geom_shape sh = shape_of(&w);
    assert_true(geom_shape_inside(&sh, v3(0, 1.5, 0)));
    assert_true(geom_shape_inside(&sh, v3(0.9, 0.3, 0)));
    assert_false(geom_shape_inside(&sh, v3(0, 1.66, 0)));
    assert_false(geom_shape_inside(&sh, v3(0.9, 1.0, 0)));
    geom_shape_release(&sh);
    done(&w);
    double u1 = yb - v, u2 = yt - v;
    double area = 2 * M_PI * rb * (yb + rb) + 2 * M_PI * rt * (rb + rt - yt) +
                  2 * M_PI * rc * ((u2 - h * asin(u2 / rc)) - (u1 - h * asin(u1 / rc)));
    check_crofton("ovus { 1, 0.65 rotate 30*x }", SHAPE_OVUS, area, -1e9, 1e9, 1.0);
    check_grid("ovus { 1, 0.65 }", 2, area, 2e-2);
    /* top >= 2 bottom: POV-Ray substitutes the top sphere */
    w = build("ovus { 0.5, 1 }");
    assert_int_equal(w.s->objects[0]->kind, SHAPE_SPHERE);
    expect_hit(&w, v3(0, 5, 0), v3(0, -1, 0), 5 - 1.5, v3(0, 1, 0), 1e-12, 1e-12);
    done(&w);
}

/* bounded_by with POV-Ray 3.7's semantics: a ray sees the object only if it
 * meets the bound (anywhere ahead) or starts inside it (Ray_In_Bound); the
 * bound never cuts the surface; top-level objects that are cheap to
 * intersect lose their bound (Link_To_Frame, remove_bounds on) but keep its
 * box when smaller than theirs; objects in unions and CSG objects, polys,
 * text and unbounded quadrics keep the bound */
static void test_bounded_by(void **st)
{
    (void)st;
    /* infinite cylinder x^2 + z^2 = 1 along y, bounded by the sphere r = 2 */
    world w = build("quadric { <1,0,1>, <0,0,0>, <0,0,0>, -1 bounded_by { sphere { 0, 2 } } }");
    expect_hit(&w, v3(-5, 0, 0), v3(1, 0, 0), 4.0, v3(-1, 0, 0), 1e-12, 1e-12);
    /* a ray missing the bound sees nothing, though it crosses the cylinder */
    expect_miss(&w, v3(-5, 3, 0), v3(1, 0, 0));
    /* a ray crossing the bound sees the surface outside it: (-1, 2, 0) is
     * sqrt(5) from the centre */
    vec3 dir = v3_norm(v3(1, -0.25, 0));
    expect_hit(&w, v3(-5, 3, 0), dir, 4.0 / dir.x, v3(-1, 0, 0), 1e-9, 1e-9);
    /* a ray starting inside the bound */
    expect_hit(&w, v3(0, 0, 0), v3(1, 0, 0), 1.0, v3(1, 0, 0), 1e-12, 1e-12);
    done(&w);
    /* a top-level sphere's bound is dropped (remove_bounds) but the sphere
     * keeps the bound's smaller box, which culls rays missing it */
    w = build("sphere { 0, 1 bounded_by { sphere { 0, 0.5 } } }");
    expect_miss(&w, v3(-5, 0.8, 0), v3(1, 0, 0));
    /* through the box's corner region, outside the bounding sphere itself */
    expect_hit(&w, v3(-5, 0.45, 0.45), v3(1, 0, 0), 5 - sqrt(1 - 2 * 0.45 * 0.45), v3(-sqrt(1 - 2 * 0.45 * 0.45), 0.45, 0.45),
               1e-12, 1e-12);
    done(&w);
    /* a bound larger than the object's own box changes nothing */
    w = build("sphere { 0, 1 bounded_by { sphere { 0, 3 } } }");
    expect_hit(&w, v3(-5, 0.8, 0), v3(1, 0, 0), 5 - 0.6, v3(-0.6, 0.8, 0), 1e-12, 1e-12);
    done(&w);
    /* ... kept inside a union; the union's own bound holds for its members */
    w = build("union { sphere { 0, 1 bounded_by { box { -0.5, 0.5 } } } }");
    expect_miss(&w, v3(-5, 0.8, 0), v3(1, 0, 0));
    expect_hit(&w, v3(-5, 0.2, 0), v3(1, 0, 0), 5 - sqrt(0.96), v3(-sqrt(0.96), 0.2, 0), 1e-12, 1e-12);
    done(&w);
    w = build("union { sphere { <-2,0,0>, 0.5 } sphere { <2,0,0>, 0.5 } bounded_by { box { <-3,-1,-1>, <0,1,1> } } }");
    expect_hit(&w, v3(-2, 5, 0), v3(0, -1, 0), 4.5, v3(0, 1, 0), 1e-12, 1e-12);
    expect_miss(&w, v3(2, 5, 0), v3(0, -1, 0));
    done(&w);
    /* a CSG intersection (a lens) whose bound lies elsewhere: only rays
     * through the bound see it */
    w = build("intersection { sphere { 0, 1 } sphere { <0.5,0,0>, 1 } bounded_by { sphere { <-3,0,0>, 0.5 } } }");
    expect_hit(&w, v3(-10, 0, 0), v3(1, 0, 0), 9.5, v3(-1, 0, 0), 1e-12, 1e-12);
    expect_miss(&w, v3(0.25, 5, 0), v3(0, -1, 0));
    done(&w);
    /* shadows obey it too: the occlusion query of a ray missing the bound */
    w = build("quartic { <0,0,0,0,0,0,0,0,0,0, 0,0,0,0,0,0,0,0,0,0, 0,0,0,0,0,1,0,0,0,0, 0,0,1,0,-1> "
              "bounded_by { sphere { 0, 2 } } }");
    assert_true(accel_occluded(w.a, v3(0, 0, -5), v3(0, 0, 1), 0.0, 10.0));
    /* y^2 + z^2 = 1 along x: at x = 5 the ray crosses it but misses the bound */
    assert_false(accel_occluded(w.a, v3(5, 0, -5), v3(0, 0, 1), 0.0, 10.0));
    done(&w);
}

/* malformed shapes give located errors; degenerate ones are skipped with a
 * warning; nothing crashes */
static void test_bad_input(void **st)
{
    (void)st;
    static const char *bad[] = {
        "lathe { 1, <0,0> }",
        "lathe { bezier_spline 5, <0,0>, <1,0>, <1,1>, <0,1>, <0,2> }",
        "prism { 0, 1, 2, <0,0>, <1,1> }",
        "sor { 4, <1,0>, <1,0>, <1,0>, <1,0> }",
        "sor { 4, <-1,0>, <1,1>, <1,2>, <1,3> }",
        "polygon { 2, <0,0>, <1,0> }",
        "polygon { 100000000, <0,0>, <1,0>, <1,1> }",
        "blob { cylinder { <0,0,0>, <0,0,0>, 1, 1 } }",
        "height_field { png \"no_such_file.png\" }",
        "text { ttf \"no_such_font.ttf\" \"a\" 1, 0 }",
        "quartic { <1, 2, 3> }",
        "poly { 99, <1> }",
        "julia_fractal { <0,0,0,0> quaternion exp }",
        "julia_fractal { <0,0,0,0> slice <0,0,0,0>, 0 }",
        "isosurface { threshold 1 }",
        "superellipsoid { <0, 1> }",
        "sphere_sweep { linear_spline 1, <0,0,0>, 1 }",
        "sphere_sweep { cubic_spline 3, <0,0,0>, 1, <1,0,0>, 1, <2,0,0>, 1 }",
        "polynomial { 3, xyz(4,0,0): 1 }",
        "clipped_by { sphere { 0, 1 } }",
        "sphere { 0, 1 clipped_by { 3 } }",
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        diag *d = diag_new();
        scene *sc = NULL;
        pt_status st2 = sdl_parse_string("bad.pov", bad[i], NULL, &sc, d);
        if (st2 == PT_OK) fail_msg("'%s' parsed", bad[i]);
        assert_null(sc);
        assert_true(diag_errors(d) >= 1);
        const diag_msg *m = diag_get(d, diag_count(d) - 1);
        assert_true(m->loc.line >= 1);
        diag_free(d);
    }
    /* degenerate but valid: parsed, skipped by the accel with a warning */
    static const char *degen[] = {
        "lathe { 2, <0,0>, <0,1> }",
        "prism { 0, 0, 4, <0,0>, <1,0>, <1,1>, <0,0> }",
        "prism { cubic_spline 0, 1, 6, <0,0>, <1,0>, <1,1>, <0,1>, <2,2>, <3,3> }",
        "blob { threshold 1 sphere { 0, 0, 1 } }",
        "quadric { <1,1,1>, <0,0,0>, <0,0,0>, 1 }",
        "text { ttf \"timrom.ttf\" \"\" 0.1, 0 }",
    };
    for (size_t i = 0; i < sizeof degen / sizeof degen[0]; i++) {
        world w = build(degen[i]);
        expect_miss(&w, v3(-5, 0.5, 0.5), v3(1, 0, 0));
        done(&w);
    }
}

/* unsupported shapes are reported once and skipped */
static void test_unsupported(void **st)
{
    (void)st;
    /* every shape keyword is handled now; a height field from an image
     * format the reader does not know (BMP) stands for them */
    char path[] = "/tmp/test_shapes_bmpXXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    assert_int_equal(write(fd, "BM\x3e\0\0\0\0\0\0\0\x36\0\0\0", 14), 14);
    close(fd);
    char src[256];
    snprintf(src, sizeof src, "height_field { \"%s\" } height_field { \"%s\" } sphere { 0, 1 }", path, path);
    world w = build(src);
    unlink(path);
    assert_int_equal(w.s->objects[0]->kind, SHAPE_UNSUPPORTED);
    accel_stats s = accel_get_stats(w.a);
    assert_int_equal(s.unsupported, 2);
    expect_hit(&w, v3(-5, 0, 0), v3(1, 0, 0), 4.0, v3(-1, 0, 0), 1e-12, 1e-12);
    done(&w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_poly_roots),
        cmocka_unit_test(test_polygon),
        cmocka_unit_test(test_lathe_linear),
        cmocka_unit_test(test_lathe_splines),
        cmocka_unit_test(test_lathe_brute),
        cmocka_unit_test(test_sor),
        cmocka_unit_test(test_sor_brute),
        cmocka_unit_test(test_prism),
        cmocka_unit_test(test_prism_brute),
        cmocka_unit_test(test_prism_many_segments),
        cmocka_unit_test(test_text),
        cmocka_unit_test(test_superellipsoid),
        cmocka_unit_test(test_quadric),
        cmocka_unit_test(test_quadric_csg_box),
        cmocka_unit_test(test_poly),
        cmocka_unit_test(test_blob),
        cmocka_unit_test(test_height_field),
        cmocka_unit_test(test_height_field_cut),
        cmocka_unit_test(test_crossings_walk_surface),
        cmocka_unit_test(test_height_field_png),
        cmocka_unit_test(test_height_field_gif),
        cmocka_unit_test(test_height_field_formats),
        cmocka_unit_test(test_height_field_function),
        cmocka_unit_test(test_sphere_sweep),
        cmocka_unit_test(test_bicubic_patch),
        cmocka_unit_test(test_clipped_by),
        cmocka_unit_test(test_isosurface),
        cmocka_unit_test(test_parametric),
        cmocka_unit_test(test_julia),
        cmocka_unit_test(test_surface_sampling),
        cmocka_unit_test(test_sweep_sampling),
        cmocka_unit_test(test_implicit_sampling),
        cmocka_unit_test(test_grid),
        cmocka_unit_test(test_thin_torus),
        cmocka_unit_test(test_ovus),
        cmocka_unit_test(test_bounded_by),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_unsupported),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
