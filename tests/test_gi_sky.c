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
#include "gi_links.h"
#include "gi_sky.h"
#include "shade_texture.h"
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


/* A particle GI state of f's scene with the final gather on (256 rays a
 * point, every 2nd pixel), nb further bounces, its view prepared at w x h. */
static gi_particle *gather_state(fixture *f, long count, uint64_t seed, gi_sky_fn fn, int w, int h, gi_pigment_fn pig,
                                 int nb)
{
    gi_particle_settings s;
    gi_particle_settings_from_scene(&s, f->sc);
    s.count = count;
    s.bounces = nb;
    s.threads = 2;
    s.seed = seed;
    s.cl_device = tg_device_c;
    s.sky = fn;
    s.keep_hits = 1;
    s.view_gather_side = 16;
    s.view_gather_stride = 2;
    s.pigment = pig;
    gi_particle *gp = tg_build_with(f, &s);
    assert_int_equal(gi_particle_prepare_view(gp, &f->sc->camera, w, h, f->d), PT_OK);
    return gp;
}

/* Pixel i's kept hit (row-major in a view w wide) and its ray direction,
 * NULL where it has none. */
static const accel_hit *kept_hit(gi_particle *gp, int i, int w, vec3 *dir)
{
    vec3 org;
    const accel_hit *h = NULL;
    if (!gi_particle_primary_hit(gp, i % w, i / w, &org, dir, &h)) return NULL;
    return h;
}

/* The kept pixels of gp's w x h view for which expect(h, n, ctx) gives an
 * expected E/pi (> 0; n the hit's normal turned to the camera): how many,
 * and the mean and worst of the hook's E/pi (green) over it. */
typedef double (*expect_fn)(const accel_hit *h, vec3 n, const void *ctx);
static int kept_ratios(gi_particle *gp, int w, int h, expect_fn expect, const void *ctx, double *mean, double *worst)
{
    double sum = 0.0;
    int m = 0;
    *worst = 0.0;
    for (int i = 0; i < w * h; i++) {
        vec3 dir;
        const accel_hit *hit = kept_hit(gp, i, w, &dir);
        if (!hit) continue;
        vec3 n = v3_dot(dir, hit->ns) > 0.0 ? v3_neg(hit->ns) : hit->ns;
        double x = expect(hit, n, ctx);
        if (!(x > 0.0)) continue;
        rgb e = gi_particle_indirect(gp, hit, n, 0);
        assert_true(isfinite(e.r) && isfinite(e.g) && isfinite(e.b));
        sum += e.g / x;
        *worst = fmax(*worst, fabs(e.g / x - 1.0));
        m++;
    }
    *mean = m > 0 ? sum / m : 0.0;
    return m;
}

/* expected E/pi: ctx's L, or with ctx NULL the gradient sky's 1 + n.y/3 */
static double expect_sky(const accel_hit *h, vec3 n, const void *ctx)
{
    (void)h;
    return ctx ? *(const double *)ctx : 1.0 + (1.0 / 3.0) * n.y;
}

/* The final gather at the camera's hits (gi_particle_gather.c) in the same
 * furnaces: every kept pixel on the sphere gathers (or interpolates, or
 * takes the edge-aware filter of) side x side rays of its own, so under the
 * uniform sky E/pi is L at every pixel, and under L(d) = 1 + 0.5 d.y it is
 * the closed form 1 + (1/3) n.y at the pixel's own normal, over the whole
 * visible half of the sphere (no estimation-list average over normals).
 * Mean within 1%, every pixel within 5% (the filter averages neighbours
 * whose normals differ by up to 25.8 degrees over 2 pixels; the gather's
 * own noise with 256 stratified rays is far below that). */
static void gather_case(const char *what, int background, double L, gi_sky_fn fn, int gradient)
{
    fixture f;
    char text[1024];
    tg_load(&f, tu_sky_furnace(text, sizeof text, L, background, 1));
    const int W = 32, H = 32;
    gi_particle *gp = gather_state(&f, 2000, 5, fn, W, H, NULL, 0);
    double mean, worst;
    int m = kept_ratios(gp, W, H, expect_sky, gradient ? NULL : &L, &mean, &worst);
    const gi_particle_stats *st = gi_particle_get_stats(gp);
    printf("  final gather %-20s: %3d pixels (%ld gathers, %ld rays), mean E/pi over expected %.5f, worst %.4f\n", what,
           m, st->view_gathers, st->view_gather_rays, mean, worst);
    assert_true(m > 100);
    assert_true(st->view_gathers > 0);
    assert_true(fabs(mean - 1.0) <= 0.01);
    assert_true(worst <= 0.05);
    gi_particle_free(gp);
    tg_unload(&f);
}

/* A layered emitter: the furnace's sky is a hollow dome whose texture is
 * an emitting layer of radiance L under a clear layer (rgbt 1, as
 * balcony.pov's sky sphere carries its clouds). The GI's pigment
 * (shade_tex_pigment_at) composites the layers as the camera sees them, so
 * every kept pixel on the white sphere inside gathers E/pi = L (mean within
 * 1%, worst 5%); taking the top layer alone made it 0. */
/* L on the white sphere's pixels (not the dome's) */
static double expect_dome_inside(const accel_hit *h, vec3 n, const void *ctx)
{
    return v3_len(h->p) > 2.0 ? 0.0 : expect_sky(h, n, ctx);
}

static void layered_dome_case(double L)
{
    fixture f;
    char text[1024];
    snprintf(text, sizeof text,
             "#version 3.7;\n"
             "global_settings { assumed_gamma 1.0 radiosity { recursion_limit 1 } }\n"
             "camera { location <0, 0, -3> look_at <0, 0, 0> angle 20 }\n"
             "sphere { 0, 10 hollow\n"
             "  texture { pigment { rgb %.17g } finish { emission 1 diffuse 0 } }\n"
             "  texture { pigment { rgbt 1 } finish { emission 1 diffuse 0 } } }\n"
             "sphere { 0, 1 pigment { rgb 1 } finish { ambient 0 diffuse 1 } }\n",
             L);
    tg_load(&f, text);
    const int W = 32, H = 32;
    gi_particle *gp = gather_state(&f, 2000, 9, NULL, W, H, shade_tex_pigment_at, 0);
    double mean, worst;
    int m = kept_ratios(gp, W, H, expect_dome_inside, &L, &mean, &worst);
    printf("  final gather layered dome L %.2f: %3d pixels, mean E/pi over L %.5f, worst %.4f\n", L, m, mean, worst);
    assert_true(m > 100);
    assert_true(fabs(mean - 1.0) <= 0.01);
    assert_true(worst <= 0.05);
    gi_particle_free(gp);
    tg_unload(&f);
}

/* A uv-mapped emitter: a mesh2 square of half-size 1000 at height 1 above
 * a white floor, every corner at uv <0.8, 0.5>, under a `uv_mapping`
 * pigment `gradient x` from black to white and `emission 1`: Le = 0.8 all
 * over it. The final gather's rays that end on it read the mesh's
 * uv_vectors as the camera's rays do (accel_mesh_uv, POV-Ray shading its
 * radiosity rays' hits in full), so the floor's kept pixels gather E/pi =
 * 0.8 F, F the square's form factor (within 1e-5 of 1); with the world's
 * x and z as uv they gathered 0.62 of it (the ramp over x). Mean
 * within 1%, worst 5%. */
static double expect_uv_floor(const accel_hit *h, vec3 n, const void *ctx)
{
    (void)n;
    return fabs(h->p.y) < 1e-6 ? *(const double *)ctx : 0.0;
}

static void uv_emitter_case(void)
{
    fixture f;
    tg_load(&f, "#version 3.7;\n"
                "global_settings { assumed_gamma 1.0 radiosity { recursion_limit 1 } }\n"
                "camera { location <0, 0.5, -1> look_at <0, 0, 0.5> angle 50 }\n"
                "plane { y, 0 pigment { rgb 1 } finish { ambient 0 diffuse 1 } }\n"
                "mesh2 { vertex_vectors { 4, <-1000, 1, -1000>, <1000, 1, -1000>, <1000, 1, 1000>, <-1000, 1, 1000> }\n"
                "  uv_vectors { 1, <0.8, 0.5> }\n"
                "  face_indices { 2, <0, 1, 2>, <0, 2, 3> }\n"
                "  uv_indices { 2, <0, 0, 0>, <0, 0, 0> }\n"
                "  texture { uv_mapping pigment { gradient x color_map { [0 rgb 0] [1 rgb 1] } }\n"
                "            finish { emission 1 diffuse 0 } } }\n");
    const int W = 32, H = 32;
    const double L = 0.8;
    gi_particle *gp = gather_state(&f, 2000, 9, NULL, W, H, shade_tex_pigment_at, 0);
    double mean, worst;
    int m = kept_ratios(gp, W, H, expect_uv_floor, &L, &mean, &worst);
    printf("  final gather uv-mapped mesh emitter: %3d pixels, mean E/pi over 0.8 %.5f, worst %.4f\n", m, mean, worst);
    assert_true(m > 100);
    assert_true(fabs(mean - 1.0) <= 0.01);
    assert_true(worst <= 0.05);
    gi_particle_free(gp);
    tg_unload(&f);
}

/* Radiosity `normal on` over a bumped floor: the floor's normal pattern
 * (gradient x, triangle_wave) tilts its normal one way on one half of
 * each stripe and the other way on the other, under a sky that brightens
 * along x (L = 1 + 0.9 d.x), so each stripe half gathers its own light.
 * POV-Ray files each irradiance record under the perturbed normal and
 * reuses it only where the perturbed normals agree within the error bound
 * (radiosity.cpp ComputeAmbient's effectiveNormal), so every kept floor
 * pixel takes the light about its own perturbed normal, against a 32 x
 * 32-ray gather at that pixel about that normal (the gatherer): mean
 * within 1%, at most 1 pixel in 20 over 3% off, none over 13% (where the
 * pattern's kink blends the normals a record is reused within the error
 * bound 0.3, up to 12 degrees, worth up to 13% under this sky), while the
 * two halves' light differs by over 25%. Reusing and filtering by the
 * surface's own normal put a fifth of the pixels over 3% off, the worst
 * 18%. */
static rgb sky_xgrad(const scene *sc, vec3 dir)
{
    (void)sc;
    double v = 1.0 + 0.9 * dir.x;
    return (rgb){v, v, v};
}

void test_normal_on_gather(void **state)
{
    (void)state;
    fixture f;
    tg_load(&f, "#version 3.7;\n"
                "global_settings { assumed_gamma 1.0 radiosity { recursion_limit 1 error_bound 0.3 normal on } }\n"
                "camera { location <0, 1.5, -1.5> look_at <0, 0, 0.3> angle 40 }\n"
                "plane { y, 0 pigment { rgb 1 } finish { ambient 0 diffuse 1 }\n"
                "  normal { gradient x 1 triangle_wave scale 0.8 } }\n");
    gi_particle_settings s;
    gi_particle_settings_from_scene(&s, f.sc);
    s.count = 2000;
    s.bounces = 0;
    s.threads = 2;
    s.seed = 3;
    s.cl_device = tg_device_c;
    s.sky = sky_xgrad;
    s.keep_hits = 1;
    s.view_gather_side = 16;
    s.view_gather_stride = 2;
    s.normal_at = shade_tex_normal_at;
    gi_particle *gp = tg_build_with(&f, &s);
    const int W = 48, H = 48;
    assert_int_equal(gi_particle_prepare_view(gp, &f.sc->camera, W, H, f.d), PT_OK);
    gi_sky *sky = gi_sky_new(f.sc, sky_xgrad);
    assert_non_null(sky);
    gi_gatherer *g = gi_gatherer_new(f.a, NULL, 32, 7, sky, f.sc, NULL);
    assert_non_null(g);
    double sum = 0.0, worst = 0.0, lo = INFINITY, hi = 0.0;
    int m = 0, off = 0;
    for (int i = 0; i < W * H; i++) {
        vec3 dir;
        const accel_hit *hit = kept_hit(gp, i, W, &dir);
        if (!hit || fabs(hit->p.y) > 1e-6) continue;
        vec3 n = v3_dot(dir, hit->ns) > 0.0 ? v3_neg(hit->ns) : hit->ns, pn;
        shade_tex_normal_at(f.sc, hit, n, &pn);
        float e[3];
        assert_int_equal(gi_gatherer_point(g, 0, hit->p, pn, (uint64_t)i, e, NULL), 1);
        rgb v = gi_particle_indirect(gp, hit, n, 0);
        assert_true(isfinite(v.g) && e[1] > 0.0f);
        sum += v.g / e[1];
        worst = fmax(worst, fabs(v.g / e[1] - 1.0));
        off += fabs(v.g / e[1] - 1.0) > 0.03;
        lo = fmin(lo, e[1]);
        hi = fmax(hi, e[1]);
        m++;
    }
    printf("  normal on, bumped floor: %d pixels, own-normal E/pi %.3f to %.3f, mean over it %.5f, worst %.4f, "
           "%d over 3%% off\n", m, lo, hi, sum / m, worst, off);
    assert_true(m > 500);
    assert_true(hi > 1.25 * lo);
    assert_true(fabs(sum / m - 1.0) <= 0.01);
    assert_true(worst <= 0.13);
    assert_true(off <= m / 20);
    gi_gatherer_free(g);
    gi_sky_free(sky);
    gi_particle_free(gp);
    tg_unload(&f);
}

static double expect_ceiling(const accel_hit *h, vec3 n, const void *ctx)
{
    (void)n;
    return fabs(h->p.y - 1.0) < 1e-6 ? *(const double *)ctx : 0.0;
}

/* A surface on a pattern's cell boundary: an emitting floor (plane y = 0,
 * `emission 1`) whose checker's cells are 1000 wide in x and z and 1 high
 * in y, so the floor lies exactly on the boundary between the white cell
 * above (y in [0, 1)) and the black one below. POV-Ray intersects in
 * double precision and its checker's 1e-10 offset puts the whole floor in
 * the white cell: Le = 1 all over. The final gather's rays read the
 * texture where their hit lies in double precision (found again by
 * accel_intersect), so the ceiling's kept pixels above it gather E/pi = 1
 * F, F within 1e-5 of 1: mean within 1%, worst 5%. At Embree's float hit,
 * a few 1e-7 off the plane on either side, about half the rays took the
 * black cell (0.5 of it). */
static void boundary_case(void)
{
    fixture f;
    tg_load(&f, "#version 3.7;\n"
                "global_settings { assumed_gamma 1.0 radiosity { recursion_limit 1 } }\n"
                "camera { location <0, 0.3, -1> look_at <0, 1, 0.5> angle 50 }\n"
                "plane { y, 1 pigment { rgb 1 } finish { ambient 0 diffuse 1 } }\n"
                "plane { y, 0 pigment { checker rgb 1, rgb 0 scale <1000, 1, 1000> translate <-500, 0, -500> }\n"
                "  finish { emission 1 diffuse 0 } }\n");
    const int W = 32, H = 32;
    const double L = 1.0;
    gi_particle *gp = gather_state(&f, 2000, 9, NULL, W, H, shade_tex_pigment_at, 0);
    double mean, worst;
    int m = kept_ratios(gp, W, H, expect_ceiling, &L, &mean, &worst);
    printf("  final gather floor on a checker's cell boundary: %3d pixels, mean E/pi over 1 %.5f, worst %.4f\n", m, mean,
           worst);
    assert_true(m > 100);
    assert_true(fabs(mean - 1.0) <= 0.01);
    assert_true(worst <= 0.05);
    gi_particle_free(gp);
    tg_unload(&f);
}

/* A contact: a box (2 wide, 0.5 high, 1 deep) standing on a floor under a
 * uniform sky, no lights and no bounce, so a point's E/pi is the sky it
 * sees. Near the box's foot the floor and the face see less of it the
 * nearer the contact, so a pixel there that took the gathers of its block's
 * corners, all farther from the contact, would be too bright. A gather
 * point's reach shrinks toward the nearest surface its rays found (POV-Ray's
 * To_Nearest_Surface and Nearest_Distance, radiosity.cpp), so those pixels
 * gather themselves: over the kept pixels within 0.03 of the contact the
 * mean of E/pi over the exact gatherer's (32 x 32 rays) lies within 1.3%
 * (with the corners' reach unshrunk it was 1.8% high). error_bound 0.3:
 * at the default 1.8 a corner is reused over its whole block. */
static void contact_case(void)
{
    fixture f;
    tg_load(&f, "#version 3.7;\n"
                "global_settings { assumed_gamma 1.0 radiosity { recursion_limit 1 error_bound 0.3 } }\n"
                "camera { location <0, 0.9, -1.4> look_at <0, 0.05, 0> angle 40 }\n"
                "plane { y, 0 pigment { rgb 0.5 } finish { ambient 0 diffuse 1 } }\n"
                "box { <-1, 0, 0>, <1, 0.5, 1> pigment { rgb 0.5 } finish { ambient 0 diffuse 1 } }\n");
    const int W = 64, H = 64;
    g_sky_L = 1.0;
    gi_particle *gp = gather_state(&f, 2000, 5, sky_const, W, H, NULL, 0);
    gi_sky *sky = gi_sky_new(f.sc, sky_const);
    assert_non_null(sky);
    gi_gatherer *g = gi_gatherer_new(f.a, NULL, 32, 7, sky, f.sc, NULL);
    assert_non_null(g);
    double sum = 0.0;
    int m = 0;
    for (int i = 0; i < W * H; i++) {
        vec3 dir;
        const accel_hit *hit = kept_hit(gp, i, W, &dir);
        if (!hit || fabs(hit->p.x) > 0.8) continue;
        int on_floor = fabs(hit->p.y) < 1e-6 && hit->p.z < 0.0, on_face = fabs(hit->p.z) < 1e-6;
        if (!((on_floor && hit->p.z > -0.03) || (on_face && hit->p.y < 0.03))) continue;
        vec3 n = v3_dot(dir, hit->ns) > 0.0 ? v3_neg(hit->ns) : hit->ns;
        float e[3];
        assert_int_equal(gi_gatherer_point(g, 0, hit->p, n, (uint64_t)i, e, NULL), 1);
        rgb v = gi_particle_indirect(gp, hit, n, 0);
        assert_true(isfinite(v.g) && e[1] > 0.0f);
        sum += v.g / e[1];
        m++;
    }
    printf("  final gather at a box's foot: %d pixels within 0.03 of the contact, mean E/pi over the exact %.4f\n", m,
           sum / m);
    assert_true(m > 100);
    assert_true(fabs(sum / m - 1.0) <= 0.013);
    gi_gatherer_free(g);
    gi_sky_free(sky);
    gi_particle_free(gp);
    tg_unload(&f);
}

void test_sky_final_gather(void **state)
{
    (void)state;
    gather_case("background L 2.5", 1, 2.5, NULL, 0);
    gather_case("1 + 0.5 y, all", 0, 1.0, sky_grad, 1);
    layered_dome_case(1.5);
    uv_emitter_case();
    boundary_case();
    contact_case();
}

/* Emission through a CSG result: a 2 x 2 emitting slab (a difference whose
 * subtracted sphere lies far away, so the slab is whole) at height 1 above a
 * white floor, no lights, a black sky. A floor point (px, 0, pz) under it
 * gathers E/pi = Le F, F the point-to-parallel-rectangle form factor, the
 * sum over the four rectangles the point's foot cuts the slab into of the
 * corner formula (1/2pi) [X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2)
 * atan(X/sqrt(1+Y^2))], X and Y their sides over the height (Siegel and
 * Howell's configuration for a differential area below a rectangle's
 * corner). The final gather's rays that end on the slab take the emission
 * of the CSG member they hit (accel_rtc_leaf). Kept pixels within 0.3 of
 * the centre: mean within 2%, each within 6%. */
static double corner_ff(double a, double b)
{
    double X = a, Y = b; /* height 1 */
    double sx = sqrt(1.0 + X * X), sy = sqrt(1.0 + Y * Y);
    return (X / sx * atan(Y / sx) + Y / sy * atan(X / sy)) / (2.0 * M_PI);
}

/* Le F under the slab (Le 2), floor pixels within 0.3 of its centre */
static double expect_slab(const accel_hit *h, vec3 n, const void *ctx)
{
    (void)n;
    (void)ctx;
    double px = h->p.x, pz = h->p.z;
    if (fabs(h->p.y) > 1e-6 || fabs(px) > 0.3 || fabs(pz) > 0.3) return 0.0;
    return 2.0 * (corner_ff(1.0 - px, 1.0 - pz) + corner_ff(1.0 + px, 1.0 - pz) + corner_ff(1.0 - px, 1.0 + pz) +
                  corner_ff(1.0 + px, 1.0 + pz));
}

void test_csg_emitter_gather(void **state)
{
    (void)state;
    fixture f;
    const char *text = "#version 3.7;\n"
                       "global_settings { assumed_gamma 1.0 radiosity { count 100 recursion_limit 1 } }\n"
                       "camera { location <0, 0.8, -0.6> look_at <0, 0, 0> angle 60 }\n"
                       "difference { box { <-1, 1, -1>, <1, 1.2, 1> } sphere { <20, 20, 20>, 0.5 }\n"
                       "  pigment { rgb 1 } finish { emission 2 diffuse 0 } }\n"
                       "plane { y, 0 pigment { rgb 1 } finish { diffuse 1 } }\n";
    tg_load(&f, text);
    const int W = 40, H = 40;
    gi_particle *gp = gather_state(&f, 3000, 7, NULL, W, H, NULL, 0);
    double mean, worst;
    int m = kept_ratios(gp, W, H, expect_slab, NULL, &mean, &worst);
    printf("  CSG emitter over a floor: %d pixels, mean E/pi over the form factor's %.5f, worst %.4f\n", m, mean, worst);
    assert_true(m > 30);
    assert_true(fabs(mean - 1.0) <= 0.02);
    assert_true(worst <= 0.06);
    gi_particle_free(gp);
    tg_unload(&f);
}

/* A mirror in the final gather: a white diffuse floor (y = 0) beside an
 * infinite vertical mirror wall (x = 1, black, diffuse 0) under a uniform
 * sky of radiance L (a background), recursion_limit 1, no lights. A floor
 * point's gather rays with d.x < 0 see the sky (L); those with d.x > 0 meet
 * the wall at incidence cos_i = d.x and, as POV-Ray's radiosity rays
 * (traced in full), follow its reflection, which keeps d.y > 0 and so
 * leaves for the sky: they bring R(cos_i) L. The wall is vertical, so it
 * takes half the floor's cosine-weighted hemisphere, and
 *   E/pi = L/2 + L <R(d.x)>, the mean over cosine-weighted d with d.x > 0
 * counted over the whole hemisphere: (1 + R)/2 L for a constant
 * `reflection R`; for `reflection { 0, 1 fresnel on }` with interior ior n,
 * R is the unpolarised Fresnel reflectance (rs^2 + rp^2)/2 of a ray
 * entering (Hecht, Optics, 4.5), integrated here on a 256 x 256 stratified
 * grid. Without the reflection followed E/pi is L/2. Kept floor pixels: mean
 * within 1%, each within 5%; and the gatherer (gi_links.h, what hits that
 * no gather point answers take) at three floor points, each within 2%. */
static double fresnel_entering(double c, double n)
{
    double s2 = (1.0 - c * c) / (n * n), ct = sqrt(fmax(0.0, 1.0 - s2));
    double rs = (c - n * ct) / (c + n * ct), rp = (n * c - ct) / (n * c + ct);
    return 0.5 * (rs * rs + rp * rp);
}

/* L/2 + L <R(d.x)> over the floor's cosine-weighted hemisphere (about +y) */
static double mirror_expect(double L, double R, double ior)
{
    if (ior <= 0.0) return 0.5 * L * (1.0 + R);
    const int N = 256;
    double sum = 0.0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            /* Malley: a uniform point of the unit disc lifted to the hemisphere */
            double u = (i + 0.5) / N, v = (j + 0.5) / N, r = sqrt(u), phi = 2.0 * M_PI * v;
            double dx = r * cos(phi);
            sum += dx > 0.0 ? fresnel_entering(dx, ior) : 1.0;
        }
    return L * sum / ((double)N * N);
}

static double expect_floor(const accel_hit *h, vec3 n, const void *ctx)
{
    (void)n;
    return fabs(h->p.y) < 1e-6 && h->p.x < 0.9 ? *(const double *)ctx : 0.0;
}

/* A floor scene's gather against E/pi = expect: the kept floor pixels
 * (x < 0.9) of a 32 x 32 view, mean within 1% and each within 5%, and the
 * gatherer at floor points x = xs[k], z = 0.3, each within 2%. */
static void floor_case(const char *what, const char *text, double L, double expect, const double xs[3])
{
    fixture f;
    tg_load(&f, text);
    const int W = 32, H = 32;
    gi_particle *gp = gather_state(&f, 2000, 11, NULL, W, H, NULL, 0);
    double mean, worst;
    int m = kept_ratios(gp, W, H, expect_floor, &expect, &mean, &worst);
    printf("  %-38s: %3d floor pixels, expected E/pi %.5f (%.4f L), mean over it %.5f, worst %.4f\n",
           what, m, expect, expect / L, mean, worst);
    assert_true(m > 100);
    assert_true(fabs(mean - 1.0) <= 0.01);
    assert_true(worst <= 0.05);
    gi_particle_free(gp);
    gi_sky *sky = gi_sky_new(f.sc, NULL);
    assert_non_null(sky);
    gi_gatherer *g = gi_gatherer_new(f.a, NULL, 16, 3, sky, f.sc, NULL);
    assert_non_null(g);
    for (int k = 0; k < 3; k++) {
        float e[3];
        assert_int_equal(gi_gatherer_point(g, 0, v3(xs[k], 0.0, 0.3), v3(0, 1, 0), (uint64_t)k, e, NULL), 1);
        printf("    gatherer at x = %5.2f: E/pi %.5f, over expected %.5f\n", xs[k], e[1], e[1] / expect);
        assert_true(fabs(e[1] / expect - 1.0) <= 0.02);
    }
    gi_gatherer_free(g);
    gi_sky_free(sky);
    tg_unload(&f);
}

static void mirror_case(const char *what, double L, const char *wall_finish, double R, double ior)
{
    char text[1024], label[64];
    snprintf(text, sizeof text,
             "#version 3.7;\n"
             "global_settings { assumed_gamma 1.0 radiosity { count 100 recursion_limit 1 } }\n"
             "background { rgb %.17g }\n"
             "camera { location <0, 2, -1> look_at <0.3, 0, 0.5> angle 50 }\n"
             "plane { y, 0 pigment { rgb 1 } finish { ambient 0 diffuse 1 } }\n"
             "plane { -x, -1 pigment { rgb 0 } finish { ambient 0 diffuse 0 %s } interior { ior %.17g } }\n",
             L, wall_finish, ior > 0.0 ? ior : 1.0);
    snprintf(label, sizeof label, "mirror wall %s", what);
    /* the gatherer at floor points 0.05, 0.5 and 2 from the wall */
    const double xs[3] = {0.95, 0.5, -1.0};
    floor_case(label, text, L, mirror_expect(L, R, ior), xs);
}

void test_mirror_gather(void **state)
{
    (void)state;
    mirror_case("reflection 0.6", 1.5, "reflection 0.6", 0.6, 0.0);
    mirror_case("fresnel, ior 1.5", 2.0, "reflection { 0, 1 fresnel on }", 1.0, 1.5);
}

/* Glass in the final gather: a white diffuse floor (y = 0) under a clear
 * slab (a box from y = 1 to y = 1 + D, 200 wide: what misses it is below
 * 1e-4 of the cosine-weighted hemisphere) under a uniform sky of radiance L
 * (a background), recursion_limit 1, no lights; the slab's finish neither
 * diffuses nor reflects, its pigment transmits t. A floor point's gather
 * ray with direction d enters the slab's bottom face and leaves its top
 * face, as POV-Ray's radiosity rays (traced in full) do; each face passes
 * t (POV-Ray's filter colour, trace.cpp ComputeLightedTexture), and the
 * top face, which the ray leaves, the interior's fade over the way inside,
 * D / cos_t at the refracted angle (Snell: cos_t = sqrt(1 - (1 - d.y^2) /
 * n^2); the faces are parallel, so the ray leaves as it came, for the
 * sky):
 *   E/pi = L t^2 <fade(D / cos_t)>, the mean over cosine-weighted d,
 * which is L t^2 without a fade (here integrated on a 256 x 256 grid).
 * Without the transmission followed the slab is black and E/pi is 0. Kept
 * floor pixels (the camera under the slab): mean within 1%, each within
 * 5%; the gatherer at three floor points, each within 2%. */
static double slab_expect(double L, double t, double ior, double D, double fade_distance)
{
    const int N = 256;
    double sum = 0.0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            double u = (i + 0.5) / N, dy = sqrt(fmax(0.0, 1.0 - u));
            double ct = sqrt(fmax(0.0, 1.0 - (1.0 - dy * dy) / (ior * ior)));
            /* fade_power 1001, fade_colour 0: exp(-d / fade_distance) */
            sum += fade_distance > 0.0 ? exp(-D / ct / fade_distance) : 1.0;
        }
    return L * t * t * sum / ((double)N * N);
}

static void slab_case(const char *what, double L, double t, double ior, double fade_distance)
{
    char text[1024], label[64], fade[128] = "";
    const double D = 0.2;
    if (fade_distance > 0.0)
        snprintf(fade, sizeof fade, "fade_distance %.17g fade_power 1001 fade_color rgb 0", fade_distance);
    snprintf(text, sizeof text,
             "#version 3.7;\n"
             "global_settings { assumed_gamma 1.0 radiosity { count 100 recursion_limit 1 } }\n"
             "background { rgb %.17g }\n"
             "camera { location <0, 0.9, -1> look_at <0, 0, 0.3> angle 50 }\n"
             "plane { y, 0 pigment { rgb 1 } finish { ambient 0 diffuse 1 } }\n"
             "box { <-100, 1, -100>, <100, %.17g, 100> pigment { rgbt <1, 1, 1, %.17g> }\n"
             "  finish { ambient 0 diffuse 0 } interior { ior %.17g %s } }\n",
             L, 1.0 + D, t, ior, fade);
    snprintf(label, sizeof label, "clear slab %s", what);
    const double xs[3] = {0.0, 0.5, -2.0};
    floor_case(label, text, L, slab_expect(L, t, ior, D, fade_distance), xs);
}

void test_transmit_gather(void **state)
{
    (void)state;
    slab_case("transmit 0.7", 1.5, 0.7, 1.0, 0.0);
    slab_case("transmit 0.9, ior 1.5, fade", 2.0, 0.9, 1.5, 0.5);
}

/* A closed room under a bright sky (background rgb 6), no light and
 * nothing that emits inside, recursion_limit 2 (the gather's hits take
 * the particles' light): no light reaches any surface inside, so every
 * kept pixel's E/pi is exactly 0. The room holds a mirror panel, a clear
 * glass sphere and a white post that reflects 0.2: the final gather's rays
 * follow the mirror and the glass (hit_specular), and where such a
 * continuation ends on a wall the wall's particle answers (gi_link_cont);
 * taking the sky there as if nothing occluded it would light the room. */
static double expect_zero(const accel_hit *h, vec3 n, const void *ctx)
{
    (void)h;
    (void)n;
    (void)ctx;
    return 1.0; /* every kept pixel, and the ratio is E/pi itself */
}

void test_closed_room_gather(void **state)
{
    (void)state;
    fixture f;
    tg_load(&f, "#version 3.7;\n"
                "global_settings { assumed_gamma 1.0 radiosity { count 200 recursion_limit 2 } }\n"
                "background { rgb 6 }\n"
                "camera { location <0.5, 0.5, 0.05> look_at <0.5, 0.45, 1> angle 90 }\n"
                "box { <0,0,0>, <1,1,1> inverse pigment { rgb 1 } finish { ambient 0 diffuse 0.7 } }\n"
                "box { <0.25, 0.2, 0.98>, <0.75, 0.8, 0.999> pigment { rgb 0 } "
                "finish { ambient 0 diffuse 0 reflection 0.9 } }\n"
                "sphere { <0.5, 0.3, 0.6>, 0.15 pigment { rgbf 1 } finish { ambient 0 diffuse 0 } "
                "interior { ior 1.5 } }\n"
                "cylinder { <0.2, 0, 0.7>, <0.2, 0.6, 0.7>, 0.05 pigment { rgb 1 } "
                "finish { ambient 0 diffuse 0.8 reflection 0.2 } }\n");
    const int W = 32, H = 32;
    gi_particle *gp = gather_state(&f, 4000, 13, NULL, W, H, NULL, 1);
    double mean, worst;
    int m = kept_ratios(gp, W, H, expect_zero, NULL, &mean, &worst);
    printf("  closed room, sky rgb 6 outside, no light: %d kept pixels, E/pi mean %.3g\n", m, mean);
    assert_true(m > 500);
    assert_true(mean == 0.0);
    gi_particle_free(gp);
    tg_unload(&f);
}

/* diffuse_back at the final gather: a two-sided white sheet (the z = 0
 * square |x|, |y| <= 1, finish diffuse 0.5, 0.5) under a uniform sky of
 * radiance L, with a black half-plane h = 0.05 behind it over x < 0,
 * recursion_limit 2. The hook gives E/pi on the side seen plus B / A = 1
 * times E/pi on the other side: L in front, and behind L (1 - F), F the
 * view factor of the half-plane from a point u = -x in from its edge,
 * 1/2 + u / (2 sqrt(u^2 + h^2)) (a differential area to a parallel
 * half-plane). Pixels 0.25 or more from the shadow's edge: mean within 1%,
 * every one within 3%. Taken from the particles there, the back side's
 * light is smoothed over their spacing and fails both bounds. */
static double expect_back_sheet(const accel_hit *h, vec3 n, const void *ctx)
{
    (void)n;
    const double L = *(const double *)ctx, hh = 0.05, x = h->p.x;
    if (fabs(h->p.z) > 1e-3 || fabs(x) < 0.25 || fabs(h->p.y) > 0.9) return 0.0;
    double u = -x, F = 0.5 + 0.5 * u / sqrt(u * u + hh * hh);
    return L * (2.0 - F);
}

static void back_sheet_case(const char *what, const char *camera)
{
    fixture f;
    char text[1024];
    snprintf(text, sizeof text,
             "#version 3.7;\n"
             "global_settings { assumed_gamma 1.0 radiosity { count 200 recursion_limit 2 } }\n"
             "background { rgb 1.5 }\n"
             "%s\n"
             "polygon { 5, <-1,-1,0>, <1,-1,0>, <1,1,0>, <-1,1,0>, <-1,-1,0> pigment { rgb 1 } "
             "finish { ambient 0 diffuse 0.5, 0.5 } }\n"
             "box { <-30, -30, 0.05>, <0, 30, 0.06> pigment { rgb 0 } finish { ambient 0 diffuse 0 } }\n",
             camera);
    tg_load(&f, text);
    const int W = 32, H = 32;
    gi_particle *gp = gather_state(&f, 2000, 17, NULL, W, H, NULL, 1);
    /* the render takes the pre-pass's rays as its own (its tmin is
     * accel_surface_eps, shade.c): else no pixel meets a kept hit */
    assert_true(gi_particle_primary_begin(gp, f.sc, f.a, W, H, accel_surface_eps(f.a)));
    const double L = 1.5;
    double mean, worst;
    int m = kept_ratios(gp, W, H, expect_back_sheet, &L, &mean, &worst);
    /* hits between the kept ones (antialiasing rays, a quarter pixel off
     * the centres) take the points around them: every such lookup is
     * answered by the final gather, within the same bounds */
    const gi_particle_stats *st = gi_particle_get_stats(gp);
    long g0 = st->lookups_gathered, l0 = st->lookups;
    double sum = 0.0, worst_aa = 0.0;
    int naa = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            vec3 org, dir;
            scene_camera_ray(&f.sc->camera, x + 0.75, y + 0.75, W, H, &org, &dir);
            accel_hit hit;
            if (accel_intersect(f.a, org, dir, accel_surface_eps(f.a), INFINITY, &hit) <= 0) continue;
            vec3 n = v3_dot(dir, hit.ns) > 0.0 ? v3_neg(hit.ns) : hit.ns;
            double want = expect_back_sheet(&hit, n, &L);
            rgb e = gi_particle_indirect(gp, &hit, n, 0);
            if (!(want > 0.0)) continue;
            sum += e.g / want;
            worst_aa = fmax(worst_aa, fabs(e.g / want - 1.0));
            naa++;
        }
    st = gi_particle_get_stats(gp);
    long answered = st->lookups_gathered - g0, asked = st->lookups - l0;
    printf("  diffuse_back sheet behind a half-plane, %s: %d kept pixels, E/pi over the closed form mean %.4f, "
           "worst %.4f; %d hits between them: mean %.4f, worst %.4f, %ld of %ld lookups gathered (tol 1%%, 3%%)\n",
           what, m, mean, worst, naa, naa ? sum / naa : 0.0, worst_aa, answered, asked);
    assert_true(m > 500 && naa > 500);
    assert_true(fabs(mean - 1.0) <= 0.01 && fabs(sum / naa - 1.0) <= 0.01);
    assert_true(worst <= 0.03 && worst_aa <= 0.03);
    assert_true(answered == asked);
    gi_particle_free(gp);
    tg_unload(&f);
}

/* The same under a perspective and an orthographic camera (whose rays are
 * parallel: the points' reach is the distance between neighbouring rays,
 * not the angle between them, which is 0; with that reach no hit between
 * the kept ones meets a point). */
void test_diffuse_back_gather(void **state)
{
    (void)state;
    back_sheet_case("perspective", "camera { location <0, 0, -5> look_at 0 angle 22.62 }");
    back_sheet_case("orthographic", "camera { orthographic location <0, 0, -5> look_at 0 right x*2 up y*2 }");
}

/* A sky-lit scene of diffuse surfaces: a white floor (y = 0) beside a
 * white wall (a box from x = 1 to 1.2, height h = 0.8, 200 long in z)
 * under a uniform sky of radiance L (a background), recursion_limit 1, no
 * lights. A gather ray that hits the wall or the floor brings nothing, so
 * E/pi at a floor point d from the wall is L times the share of its
 * cosine-weighted hemisphere the wall leaves open: the view factor of a
 * horizontal element to an infinitely long strip rising from its plane is
 * (1 - d / sqrt(d^2 + h^2)) / 2 (Modest, "Radiative Heat Transfer",
 * appendix D), so E/pi = L (1 + d / sqrt(d^2 + h^2)) / 2; what the 200-long
 * wall leaves out is below 1e-4. The gatherer answers such rays by
 * occlusion tests (gi_gatherer_dark); the same scene with a black light
 * source (nothing changes but that it has a light) traces nearest hits.
 * Each of three floor points, the mean of 4 gathers of 32 x 32 rays: within
 * 1% in both; a wall that emits is not dark. */
static void wall_case(const char *light, int dark, const char *wall_finish, int check)
{
    const double L = 1.5, h = 0.8;
    char text[1024];
    snprintf(text, sizeof text,
             "#version 3.7;\n"
             "global_settings { assumed_gamma 1.0 radiosity { count 100 recursion_limit 1 } }\n"
             "background { rgb %.17g }\n"
             "camera { location <0, 2, -1> look_at <0.3, 0, 0.5> angle 50 }\n"
             "%s\n"
             "plane { y, 0 pigment { rgb 1 } finish { ambient 0 diffuse 1 } }\n"
             "box { <1, 0, -100>, <1.2, %.17g, 100> pigment { rgb 1 } finish { %s } }\n",
             L, light, h, wall_finish);
    fixture f;
    tg_load(&f, text);
    gi_sky *sky = gi_sky_new(f.sc, NULL);
    assert_non_null(sky);
    gi_gatherer *g = gi_gatherer_new(f.a, NULL, 32, 5, sky, f.sc, NULL);
    assert_non_null(g);
    assert_int_equal(gi_gatherer_dark(g), dark);
    const double xs[3] = {0.9, 0.5, -1.0};
    for (int k = 0; check && k < 3; k++) {
        double d = 1.0 - xs[k], expect = L * 0.5 * (1.0 + d / sqrt(d * d + h * h)), sum = 0.0;
        for (int r = 0; r < 4; r++) {
            float e[3];
            assert_int_equal(gi_gatherer_point(g, 0, v3(xs[k], 0.0, 0.3), v3(0, 1, 0), (uint64_t)(4 * k + r), e, NULL), 1);
            sum += e[1];
        }
        printf("    %s, d = %4.2f: E/pi %.5f, over expected %.5f\n", dark ? "occlusion tests" : "nearest hits", d,
               sum / 4.0, sum / 4.0 / expect);
        assert_true(fabs(sum / 4.0 / expect - 1.0) <= 0.01);
    }
    gi_gatherer_free(g);
    gi_sky_free(sky);
    tg_unload(&f);
}

void test_dark_gather(void **state)
{
    (void)state;
    wall_case("", 1, "ambient 0 diffuse 1", 1);
    wall_case("light_source { <0, 5, 0> color rgb 0 }", 0, "ambient 0 diffuse 1", 1);
    /* an emitting wall brings light back: not dark (its E/pi is not the
     * closed form above, so only the flag is checked) */
    wall_case("", 0, "ambient 0 diffuse 1 emission 0.5", 0);
}

/* The sky's second bounce at the final gather: a white sphere (radius
 * 0.3, centre height 2) over a finite floor (the 8 x 8 top of a thin box,
 * albedo 1/2) under a uniform sky of radiance L (a background), nothing
 * else. The floor reflects L/2 (its E/pi is L; the sphere's shadow on it
 * is under 2.5% right below and far less on average), so a sphere point
 * with normal n gathers E/pi = L (1 - F(n)) + (L/2) F(n), F(n) the
 * cosine-weighted share of its hemisphere that meets the floor, integrated
 * here on a 256 x 256 stratified grid. The floor's reflected sky is light
 * the particles carry (their one scattering bounce): the gather's rays that
 * end on the floor must take the particles' reflected radiance with the
 * sky's share in it. Pixels on the sphere's lower half (n.y < 0): mean
 * within 2%, each within 15% (near the silhouette the stride-2
 * interpolation and the filter mix normals up to 25.8 degrees apart, where
 * F changes fast); without the sky's share the floor reflects nothing and
 * the mean falls far below 1. */
static double floor_share(vec3 p, vec3 n)
{
    vec3 t = fabs(n.x) < 0.9 ? v3(1, 0, 0) : v3(0, 1, 0);
    t = v3_norm(v3_sub(t, v3_scale(n, v3_dot(t, n))));
    vec3 b = v3_cross(n, t);
    const int N = 256;
    long hit = 0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            /* Malley: a uniform point of the unit disc lifted to the hemisphere */
            double u = (i + 0.5) / N, v = (j + 0.5) / N, r = sqrt(u), phi = 2.0 * M_PI * v;
            double x = r * cos(phi), y = r * sin(phi), z = sqrt(fmax(0.0, 1.0 - u));
            vec3 d = v3_add(v3_add(v3_scale(t, x), v3_scale(b, y)), v3_scale(n, z));
            if (!(d.y < 0.0)) continue;
            double s = -p.y / d.y;
            double fx = p.x + s * d.x, fz = p.z + s * d.z;
            if (fabs(fx) <= 4.0 && fabs(fz) <= 4.0) hit++;
        }
    return (double)hit / ((double)N * N);
}

static double expect_two_bounce(const accel_hit *h, vec3 n, const void *ctx)
{
    if (v3_len(v3_sub(h->p, v3(0, 2, 0))) > 0.31 || !(n.y < 0.0)) return 0.0;
    double L = *(const double *)ctx, F = floor_share(h->p, n);
    return L * (1.0 - F) + 0.5 * L * F;
}

static void two_bounce_case(double L)
{
    fixture f;
    char text[1024];
    snprintf(text, sizeof text,
             "#version 3.7;\n"
             "global_settings { assumed_gamma 1.0 radiosity { recursion_limit 2 } }\n"
             "camera { location <0, 2, -2.5> look_at <0, 1.8, 0> angle 40 }\n"
             "background { rgb %.17g }\n"
             "sphere { <0, 2, 0>, 0.3 pigment { rgb 1 } finish { ambient 0 diffuse 1 } }\n"
             "box { <-4, -0.1, -4>, <4, 0, 4> pigment { rgb 0.5 } finish { ambient 0 diffuse 1 } }\n",
             L);
    tg_load(&f, text);
    const int W = 48, H = 48;
    gi_particle *gp = gather_state(&f, 4000, 11, NULL, W, H, shade_tex_pigment_at, 1);
    double mean, worst;
    int m = kept_ratios(gp, W, H, expect_two_bounce, &L, &mean, &worst);
    printf("  sky's second bounce, L %.2f: %3d pixels, mean E/pi over expected %.5f, worst %.4f\n", L, m, mean, worst);
    assert_true(m > 50);
    assert_true(fabs(mean - 1.0) <= 0.02);
    assert_true(worst <= 0.15);
    gi_particle_free(gp);
    tg_unload(&f);
}

void test_sky_second_bounce(void **state)
{
    (void)state;
    two_bounce_case(1.5);
}
