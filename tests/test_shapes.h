/* test_shapes.h - what test_shapes.c (the further shapes end to end) and
 * test_shapes_hfield.c (height fields and the image formats they read)
 * share: a scene built from text, hit and miss checks against closed forms,
 * the one leaf shape of a scene and a brute-force march of its inside test.
 * Both files are one test executable, test_shapes. */
#ifndef PT_TEST_SHAPES_H
#define PT_TEST_SHAPES_H
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

static inline void assert_near(double a, double b, double tol)
{
    if (!(fabs(a - b) <= tol)) fail_msg("got %.17g, expected %.17g (tol %g)", a, b, tol);
}

static inline void assert_vec(vec3 a, vec3 b, double tol)
{
    if (!(fabs(a.x - b.x) <= tol && fabs(a.y - b.y) <= tol && fabs(a.z - b.z) <= tol))
        fail_msg("got <%.12g,%.12g,%.12g>, expected <%.12g,%.12g,%.12g> (tol %g)", a.x, a.y, a.z, b.x, b.y, b.z, tol);
}

typedef tu_world world;

static inline world build(const char *src) { return tu_world_build("shapes.pov", src); }

static inline void done(world *w) { tu_world_free(w); }

static inline int hit(const world *w, vec3 o, vec3 d, accel_hit *h) { return accel_intersect(w->a, o, d, 0.0, INFINITY, h); }

static inline void expect_hit(const world *w, vec3 o, vec3 d, double t, vec3 n, double ttol, double ntol)
{
    accel_hit h;
    if (!hit(w, o, d, &h)) fail_msg("expected a hit at t = %.17g", t);
    assert_near(h.t, t, ttol);
    if (ntol > 0) assert_vec(h.ng, v3_norm(n), ntol);
}

static inline void expect_miss(const world *w, vec3 o, vec3 d)
{
    accel_hit h;
    if (hit(w, o, d, &h)) fail_msg("expected a miss, got t = %.17g", h.t);
}

/* The only leaf shape of the scene (first object, or its first kid). */
static inline geom_shape shape_of(const world *w)
{
    const scene_object *o = w->s->objects[0];
    geom_shape sh;
    assert_int_equal(geom_shape_init(&sh, o), 0);
    return sh;
}

/* Brute force: the first change of the inside test along o + t d for t in
 * (t0, t1], marched in n steps and bisected. */
static inline double march(const geom_shape *sh, vec3 o, vec3 d, double t0, double t1, int n)
{
    int in0 = geom_shape_inside(sh, v3_madd(o, d, t0));
    double prev = t0;
    for (int i = 1; i <= n; i++) {
        double t = t0 + (t1 - t0) * i / n;
        if (geom_shape_inside(sh, v3_madd(o, d, t)) != in0) {
            double a = prev, b = t;
            for (int k = 0; k < 80; k++) {
                double m = 0.5 * (a + b);
                if (geom_shape_inside(sh, v3_madd(o, d, m)) != in0) b = m;
                else a = m;
            }
            return 0.5 * (a + b);
        }
        prev = t;
    }
    return INFINITY;
}


/* An 8-bit PGM (P5) of w x h values. */
static inline void write_pgm(const char *path, int w, int h, const unsigned char *v)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fprintf(f, "P5\n%d %d\n255\n", w, h);
    fwrite(v, 1, (size_t)w * h, f);
    fclose(f);
}

/* test_shapes_hfield.c */
void test_height_field(void **st);
void test_height_field_cut(void **st);
void test_crossings_walk_surface(void **st);
void test_height_field_png(void **st);
void test_height_field_gif(void **st);
void test_height_field_formats(void **st);
void test_height_field_function(void **st);

#endif
