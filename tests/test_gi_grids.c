/* test_gi_grids.c - radiance particles on polygon, height_field, lathe,
 * sor, prism and text (radiance particles "at the vertices of a
 * sub-tessellation of each surface"; gi_surface_mesh.c split_grid).
 *
 * Each shape stands in a closed room (an inverse box) lit only indirectly:
 * a spotlight below the ceiling points up at it, so every other surface
 * receives only light the ceiling reflects. Particle GI (GRID_PARTICLES
 * particles, n_b 8, kernels as C) against the path tracer (GRID_SPP
 * samples a pixel) at GRID_W x GRID_W:
 *  - every lookup of the hook during the particle render interpolates
 *    radiance particles: none estimated at the hit (lookups_onthefly 0,
 *    before this test's change every hit on these shapes was) and none on a
 *    side without particles (lookups_none 0);
 *  - the shape carries radiance particles (gi_surface at the same bound);
 *  - mean luminance of the pixels whose primary ray hits the shape within
 *    GRID_SHAPE_TOL of the path tracer's, and of the whole image within
 *    GRID_IMAGE_TOL (the figures printed; measured in the commit message).
 * For the polygon, a second build with an infinite tessellation bound has
 * no grids: then every hit on it is estimated at the hit (the fallback
 * still works and is counted). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "gi_particle.h"
#include "gi_surface.h"
#include "pm_path.h"
#include "shade.h"
#include "test_util.h"
#include "test_world.h"

enum { GRID_W = 32, GRID_PARTICLES = 8000, GRID_SPP = 128 };
/* GRID_SHAPE_TOL: with sweep cells spanning at most the lists' normal
 * cone (gi_surface_mesh.c SWEEP_TURN) the six shapes read -2.2..+1.2%
 * (particle seeds 11-14 against path 1024 spp: lathe -0.4..-3.5%, sor
 * -1.1..+0.4%). A lathe whose cells span up to 58 degrees of normal
 * turning (the lit top's hits interpolating the dark underside's radiance
 * particles) reads -8.22% and fails it. */
#define GRID_SHAPE_TOL 0.05
#define GRID_IMAGE_TOL 0.06

static const char *const room =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 }\n"
    "camera { location <0.5, 0.55, 0.04> look_at <0.5, 0.3, 1> angle 80 }\n"
    "light_source { <0.5, 0.7, 0.5> color rgb 2 spotlight point_at <0.5, 1, 0.5> radius 50 falloff 60 }\n"
    "box { <0,0,0>, <1,1,1> inverse pigment { rgb 0.8 } finish { ambient 0 diffuse 0.7 } }\n"
    "#declare T = texture { pigment { rgb <0.9, 0.6, 0.3> } finish { ambient 0 diffuse 0.8 } }\n";

typedef struct {
    const char *name;
    shape_kind kind;
    const char *sdl;
} grid_shape;

static const grid_shape shapes[] = {
    {"polygon", SHAPE_POLYGON,
     "polygon { 9, <0.2,0.02,0.7>, <0.8,0.02,0.7>, <0.8,0.5,0.7>, <0.2,0.5,0.7>, <0.2,0.02,0.7>,"
     " <0.35,0.15,0.7>, <0.5,0.35,0.7>, <0.65,0.15,0.7>, <0.35,0.15,0.7> texture { T } }\n"},
    {"height_field", SHAPE_HEIGHT_FIELD,
     "height_field { function 96, 96 { 0.5 + 0.5 * sin(x * 9) * cos(y * 7) } texture { T }"
     " scale <0.8, 0.2, 0.7> translate <0.1, 0, 0.25> }\n"},
    {"lathe", SHAPE_LATHE,
     "lathe { cubic_spline 7, <0.02, -0.05>, <0.0, 0>, <0.2, 0.05>, <0.08, 0.25>, <0.14, 0.4>, <0.0, 0.45>,"
     " <0.1, 0.5> texture { T } translate <0.5, 0, 0.6> }\n"},
    {"sor", SHAPE_SOR,
     "sor { 6, <0.0, -0.05>, <0.2, 0.0>, <0.08, 0.15>, <0.16, 0.3>, <0.06, 0.42>, <0.1, 0.5> texture { T }"
     " translate <0.5, 0, 0.6> }\n"},
    {"prism", SHAPE_PRISM,
     "prism { bezier_spline 0, 0.35, 8, <-0.25, -0.2>, <-0.1, -0.3>, <0.1, -0.3>, <0.25, -0.2>, <0.25, -0.2>,"
     " <0.3, 0.2>, <-0.3, 0.2>, <-0.25, -0.2> texture { T } rotate <0, 20, 0> translate <0.5, 0, 0.6> }\n"},
    {"text", SHAPE_TEXT,
     "text { ttf \"timrom.ttf\" \"Go\" 0.15, 0 texture { T } scale 0.45 translate <0.2, 0.02, 0.6> }\n"},
};

static gi_particle *build(tu_world *w, double tess)
{
    gi_particle_settings s;
    gi_particle_default_settings(&s);
    s.count = GRID_PARTICLES;
    s.bounces = 8;
    s.threads = 2;
    s.seed = 11;
    s.cl_device = "c";
    s.tess = tess;
    pt_status st;
    gi_particle *gp = gi_particle_build(w->s, w->a, &s, NULL, w->d, &st);
    assert_non_null(gp);
    assert_int_equal(gi_particle_light(gp, w->d), PT_OK);
    return gp;
}

static void render_particle(tu_world *w, gi_particle *gp, framebuffer *fb)
{
    assert_int_equal(gi_particle_prepare_view(gp, &w->s->camera, GRID_W, GRID_W, w->d), PT_OK);
    shade_settings ss;
    shade_default_settings(&ss);
    ss.width = ss.height = GRID_W;
    ss.threads = 2;
    ss.use_ambient = 0;
    ss.indirect = gi_particle_indirect;
    ss.indirect_ctx = gp;
    shade_stats sst;
    assert_int_equal(shade_render(w->s, w->a, &ss, fb, &sst, w->d), PT_OK);
}

/* Radiance particles on objects of kind k, laid out as the particle GI
 * does at tessellation bound tess. */
static long shape_rp(tu_world *w, double tess, shape_kind k)
{
    pt_status st;
    gi_surface *g = gi_surface_build(w->s, w->a, tess, 1, w->d, &st);
    assert_non_null(g);
    long n = 0, nrp = gi_surface_nrp(g);
    for (long r = 0; r < nrp; r++) n += gi_surface_object(g, gi_surface_rp_patch(g, r))->kind == k;
    gi_surface_free(g);
    return n;
}

static void check_shape(const grid_shape *g, int fallback)
{
    char text[4096];
    snprintf(text, sizeof text, "%s%s", room, g->sdl);
    tu_world w = tu_world_build("grid.pov", text);
    gi_particle *gp = build(&w, 0.0);
    framebuffer *fp = fb_new(GRID_W, GRID_W), *fr = fb_new(GRID_W, GRID_W);
    render_particle(&w, gp, fp);
    const gi_particle_stats *st = gi_particle_get_stats(gp);
    long rp = shape_rp(&w, st->tess, g->kind), look = st->lookups, otf = st->lookups_onthefly,
         none = st->lookups_none;

    pm_path_settings ps;
    pm_path_default_settings(&ps);
    ps.c.width = ps.c.height = GRID_W;
    ps.c.threads = 2;
    ps.c.spp = GRID_SPP;
    ps.c.seed = 3;
    pm_stats pst;
    assert_int_equal(pm_path_render(w.s, w.a, &ps, fr, &pst, NULL), PT_OK);

    unsigned char on[GRID_W * GRID_W];
    int non = 0;
    for (int y = 0; y < GRID_W; y++)
        for (int x = 0; x < GRID_W; x++) {
            vec3 org, dir;
            scene_camera_ray(&w.s->camera, x + 0.5, y + 0.5, GRID_W, GRID_W, &org, &dir);
            accel_hit h;
            on[y * GRID_W + x] = accel_intersect(w.a, org, dir, 0.0, INFINITY, &h) && h.obj->kind == g->kind;
            non += on[y * GRID_W + x];
        }
    double lp = tu_luminance_mean(fp, NULL), lr = tu_luminance_mean(fr, NULL);
    double cp = tu_luminance_mean(fp, on), cr = tu_luminance_mean(fr, on);
    printf("  %-12s: %ld radiance particles on it, %ld lookups (%ld at the hit, %ld without particles); "
           "mean luminance particle vs path: image %+.2f%%, shape (%d px) %+.2f%%\n",
           g->name, rp, look, otf, none, 100.0 * (lp / lr - 1.0), non, 100.0 * (cp / cr - 1.0));
    assert_true(rp > 0);
    assert_true(look >= GRID_W * GRID_W);
    assert_int_equal(otf, 0);
    assert_int_equal(none, 0);
    assert_true(non >= 40);
    assert_true(fabs(cp / cr - 1.0) < GRID_SHAPE_TOL);
    assert_true(fabs(lp / lr - 1.0) < GRID_IMAGE_TOL);
    gi_particle_free(gp);

    if (fallback) {
        /* no grids (tessellation bound infinite): the shape is estimated at
         * every hit, as before, and the count says so */
        gp = build(&w, 1e30);
        render_particle(&w, gp, fp);
        st = gi_particle_get_stats(gp);
        printf("  %-12s: without grids %ld of %ld lookups estimated at the hit\n", g->name, st->lookups_onthefly,
               st->lookups);
        assert_true(st->lookups_onthefly >= non);
        gi_particle_free(gp);
    }
    fb_free(fp);
    fb_free(fr);
    tu_world_free(&w);
}

static void test_polygon(void **state) { (void)state; check_shape(&shapes[0], 1); }
static void test_height_field(void **state) { (void)state; check_shape(&shapes[1], 0); }
static void test_lathe(void **state) { (void)state; check_shape(&shapes[2], 0); }
static void test_sor(void **state) { (void)state; check_shape(&shapes[3], 0); }
static void test_prism(void **state) { (void)state; check_shape(&shapes[4], 0); }
static void test_text(void **state) { (void)state; check_shape(&shapes[5], 0); }

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_polygon), cmocka_unit_test(test_height_field),
        cmocka_unit_test(test_lathe),      cmocka_unit_test(test_sor),     cmocka_unit_test(test_prism),
        cmocka_unit_test(test_text),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
