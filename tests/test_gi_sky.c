/* test_gi_sky.c - particle GI under the sky: the white furnace of the
 * reference modes (tu_sky_furnace) in the particle mode, and a sky that
 * varies with direction against its closed form. Part of test_gi. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include "test_gi.h"
#include "test_world.h"

/* White furnace under the sky (tu_sky_furnace, the reference modes' scene):
 * a white diffuse sphere under a uniform sky of radiance L reflects L, so
 * the hook's E/pi is L at every point the camera sees, within 1%: a
 * background (the sky function NULL), and a sky_sphere through a sky
 * function; and a sky whose radiance varies, L(d) = 1 + 0.5 d.y, for which
 * a point of the sphere with normal n (nothing occluding) gathers the
 * cosine-weighted mean over the hemisphere about n, 1 + 0.5 * (2/3) n.y
 * (probed on the upper cap, n.y >= 0.95; the estimation lists average E
 * over normals within 25.8 degrees, a bias that shrinks with the count:
 * 16,000 particles). Both
 * gathering (recursion_limit 1: n_b 0) and the sky's scattered bounce
 * (n_b 1: on a convex sphere no link ends on another particle, so the
 * result is the same) are exercised. */
static double g_sky_L;
static rgb sky_const(const scene *sc, vec3 dir)
{
    (void)sc;
    (void)dir;
    return (rgb){g_sky_L, g_sky_L, g_sky_L};
}
static rgb sky_grad(const scene *sc, vec3 dir)
{
    (void)sc;
    double v = 1.0 + 0.5 * dir.y;
    return (rgb){v, v, v};
}

static void sky_case(const char *what, int background, double L, gi_sky_fn fn, int nb, int top_only, double L0)
{
    fixture f;
    char text[1024];
    tg_load(&f, tu_sky_furnace(text, sizeof text, L, background, 1));
    gi_particle_settings s;
    gi_particle_settings_from_scene(&s, f.sc);
    s.count = top_only ? 16000 : 4000;
    s.bounces = nb;
    s.threads = 2;
    s.seed = 5;
    s.cl_device = tg_device_c;
    s.sky = fn;
    gi_particle *gp = tg_build_with(&f, &s);
    double sum = 0.0, worst = 0.0;
    int m = 0;
    for (int j = 0; j < 24; j++)
        for (int i = 0; i < 24; i++) {
            vec3 org = top_only ? v3(-0.3 + 0.6 * (i + 0.5) / 24, 3.0, -0.3 + 0.6 * (j + 0.5) / 24)
                                : v3(-0.9 + 1.8 * (i + 0.5) / 24, -0.9 + 1.8 * (j + 0.5) / 24, -3.0);
            vec3 dir = top_only ? v3(0, -1, 0) : v3(0, 0, 1);
            accel_hit h;
            if (!accel_intersect(f.a, org, dir, 0.0, INFINITY, &h)) continue;
            vec3 n = v3_dot(dir, h.ns) > 0.0 ? v3_neg(h.ns) : h.ns;
            if (top_only && n.y < 0.95) continue;
            rgb e = gi_particle_indirect(gp, &h, n, 0);
            assert_true(isfinite(e.r) && isfinite(e.g) && isfinite(e.b));
            double expect = top_only ? L0 + 0.5 * (2.0 / 3.0) * n.y : L0;
            sum += e.g / expect;
            worst = fmax(worst, fabs(e.g / expect - 1.0));
            m++;
        }
    assert_true(m > 20);
    double mean = sum / m, expect = 1.0;
    printf("  sky furnace %-22s n_b %d: %3d probes, mean E/pi over expected %.5f (rel err %+.4f), worst %.4f\n", what,
           nb, m, mean, mean / expect - 1.0, worst);
    assert_true(fabs(mean / expect - 1.0) <= 0.01);
    gi_particle_free(gp);
    tg_unload(&f);
}

void test_sky_furnace(void **state)
{
    (void)state;
    for (int nb = 0; nb <= 1; nb++) {
        sky_case("background L 1", 1, 1.0, NULL, nb, 0, 1.0);
        sky_case("background L 2.5", 1, 2.5, NULL, nb, 0, 2.5);
        g_sky_L = 2.5;
        sky_case("sky function L 2.5", 0, 2.5, sky_const, nb, 0, 2.5);
    }
    sky_case("1 + 0.5 y, top", 0, 1.0, sky_grad, 0, 1, 1.0);
}

