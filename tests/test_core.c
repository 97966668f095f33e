/* test_core.c - transforms, arena, diagnostics, framebuffer sanitising. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "arena.h"
#include "diag.h"
#include "framebuffer.h"
#include "pool.h"
#include "scene.h"
#include "xform.h"

static void assert_vec(vec3 a, vec3 b, double tol)
{
    assert_true(fabs(a.x - b.x) <= tol);
    assert_true(fabs(a.y - b.y) <= tol);
    assert_true(fabs(a.z - b.z) <= tol);
}

/* POV-Ray: rotate <0,0,90> takes +x to +y; rotate <0,90,0> takes +z to +x;
 * rotate <90,0,0> takes +y to +z. */
static void test_rotate(void **st)
{
    (void)st;
    xform r = xform_rotate(v3(0, 0, 90));
    assert_vec(xform_point(&r, v3(1, 0, 0)), v3(0, 1, 0), 1e-12);
    r = xform_rotate(v3(0, 90, 0));
    assert_vec(xform_point(&r, v3(0, 0, 1)), v3(1, 0, 0), 1e-12);
    r = xform_rotate(v3(90, 0, 0));
    assert_vec(xform_point(&r, v3(0, 1, 0)), v3(0, 0, 1), 1e-12);
}

static void test_compose_inverse(void **st)
{
    (void)st;
    xform a = xform_then(xform_scale(v3(2, 3, 4)), xform_rotate(v3(10, 20, 30)));
    a = xform_then(a, xform_translate(v3(1, -2, 5)));
    vec3 p = v3(0.3, -1.7, 2.2);
    vec3 q = xform_point(&a, p);
    assert_vec(xform_inv_point(&a, q), p, 1e-12);
    /* scale then translate: order matters */
    xform b = xform_then(xform_scale(v3(2, 2, 2)), xform_translate(v3(1, 0, 0)));
    assert_vec(xform_point(&b, v3(1, 0, 0)), v3(3, 0, 0), 1e-12);
    /* normals stay perpendicular to transformed tangents */
    vec3 n = v3(0, 0, 1), t = v3(1, 1, 0);
    vec3 tn = xform_normal(&a, n), tt = xform_vector(&a, t);
    assert_true(fabs(v3_dot(tn, tt)) < 1e-12);
}

static void test_matrix(void **st)
{
    (void)st;
    /* matrix with translation row <1,2,3> and identity linear part */
    double m[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 2, 3};
    xform x = xform_matrix(m);
    assert_vec(xform_point(&x, v3(0, 0, 0)), v3(1, 2, 3), 1e-15);
    /* shear: row-vector convention p' = p*M; M[0][1] = 1 gives y' = y + x */
    double s[12] = {1, 1, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    x = xform_matrix(s);
    assert_vec(xform_point(&x, v3(1, 0, 0)), v3(1, 1, 0), 1e-15);
}

static void test_arena_diag(void **st)
{
    (void)st;
    arena *a = arena_new();
    char *big = arena_alloc(a, 3u << 20);
    assert_non_null(big);
    assert_int_equal(big[12345], 0);
    assert_string_equal(arena_strdup(a, "abc"), "abc");
    arena_free(a);

    diag *d = diag_new();
    src_loc loc = {"scene.pov", 3, 7};
    diag_report(d, DIAG_ERROR, loc, "  included from main.pov:1:1", "unknown keyword '%s'", "spehre");
    assert_int_equal(diag_errors(d), 1);
    char *s = diag_format(diag_get(d, 0));
    assert_string_equal(s, "scene.pov:3:7: error: unknown keyword 'spehre'\n  included from main.pov:1:1");
    free(s);
    diag_warn_once(d, loc, "unsupported: lathe");
    diag_warn_once(d, loc, "unsupported: lathe");
    assert_int_equal(diag_count(d), 2);
    diag_free(d);
}

/* pool_run_cancel: job 5 sets the flag; on one thread no job after it
 * runs and the call says it stopped; without a flag every job runs */
typedef struct {
    volatile int cancel;
    int ran;
} cancel_ctx;

static void cancel_job(void *ctx, int index, int thread)
{
    (void)thread;
    cancel_ctx *c = ctx;
    c->ran++;
    if (index == 5) c->cancel = 1;
}

static void test_pool_cancel(void **st)
{
    (void)st;
    cancel_ctx c = {0, 0};
    assert_int_equal(pool_run_cancel(1, 100, cancel_job, &c, &c.cancel), 0);
    assert_int_equal(c.ran, 6);
    cancel_ctx d = {0, 0};
    assert_int_equal(pool_run_cancel(1, 100, cancel_job, &d, NULL), 1);
    assert_int_equal(d.ran, 100);
    cancel_ctx e = {1, 0}; /* set before: nothing runs */
    assert_int_equal(pool_run_cancel(2, 100, cancel_job, &e, &e.cancel), 0);
    assert_int_equal(e.ran, 0);
}

static void test_fb_sanitize(void **st)
{
    (void)st;
    framebuffer *fb = fb_new(2, 1);
    fb->rgb[0] = NAN;
    fb->rgb[1] = INFINITY;
    fb->rgb[2] = -1.0f;
    fb->rgb[3] = 0.5f;
    assert_int_equal(fb_sanitize(fb), 2);
    assert_true(fb->rgb[0] == 0.0f && fb->rgb[1] == 0.0f && fb->rgb[2] == -1.0f && fb->rgb[3] == 0.5f);
    assert_true(fabs(fb_mean(fb, 0) - 0.25) < 1e-12);
    fb_free(fb);
    assert_null(fb_new(0, 5));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rotate),
        cmocka_unit_test(test_compose_inverse),
        cmocka_unit_test(test_matrix),
        cmocka_unit_test(test_arena_diag),
        cmocka_unit_test(test_fb_sanitize),
        cmocka_unit_test(test_pool_cancel),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
