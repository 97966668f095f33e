/* test_look.c - appearance features rendered by partray (--gi
 * none) and by POV-Ray 3.7 itself, compared as test_crosscheck does: both
 * at 160x120 with +A0.3, sRGB PNGs box-downsampled 4x4, mean absolute
 * difference over all channels in 0..1 of white.
 *
 * The agreement bound is 0.02; each scene also has its own regression
 * bound a little above what this renderer gives (the test prints it) and,
 * where noted, below what a render without the feature gives, so a
 * feature that breaks shows up even when the image stays under 0.02. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include "img_io.h"
#include "shade.h"
#include "shade_spectral.h"
#include "test_util.h"
#include "test_world.h"

#define W 160
#define H 120
#define TOLERANCE 0.02

static char tmpdir[256];

/* Render tests/scenes/<scene>.pov with both renderers in the temporary
 * directory (where its images are); `decl` is NAME=VALUE or NULL. */
static double crosscheck(const char *scene, const char *decl, const char *tag)
{
    char path[512];
    snprintf(path, sizeof path, "%s/scenes/%s.pov", TESTS_DIR, scene);
    double mad = tu_crosscheck(PARTRAY_BIN, tmpdir, path, tag, W, H, decl);
    printf("look %-18s mean |diff| after 4x4 downsample = %.5f (tolerance %.3f)\n", tag, mad, TOLERANCE);
    return mad;
}

static void check(const char *scene, const char *decl, const char *tag, double regression)
{
    double mad = crosscheck(scene, decl, tag);
    assert_true(mad <= TOLERANCE);
    assert_true(mad <= regression);
}

/* The renders are deterministic: each bound is a margin over the printed
 * difference. */
static void test_textures(void **st) { (void)st; check("xl_textures", NULL, "textures", 0.007); }
static void test_glass(void **st) { (void)st; check("xl_glass", NULL, "glass", 0.006); }
static void test_atmosphere(void **st) { (void)st; check("xl_atmosphere", NULL, "atmosphere", 0.002); }
/* facets normal */
static void test_facets(void **st) { (void)st; check("xl_facets", NULL, "facets", 0.004); }
/* finish irid (3.6's wavelengths give ~0.03, above the bound) */
static void test_irid(void **st) { (void)st; check("xl_irid", NULL, "irid", 0.006); }
/* light_group (nested, global_lights; keeping the inner group's own
 * global_lights setting lands above the bound) */
static void test_light_group(void **st) { (void)st; check("xl_lightgroup", NULL, "light_group", 0.002); }
/* uv_mapping on spheres */
static void test_uv_mapping(void **st) { (void)st; check("xl_uv", NULL, "uv_mapping", 0.003); }
/* uv_mapping on every shape POV-Ray 3.7 gives UV coordinates (patterns
 * evaluated in 3D instead land above the bound; image_map gives no image) */
static void test_uv_shapes(void **st) { (void)st; check("xl_uv_shapes", NULL, "uv_shapes", 0.003); }
static void test_uv_mesh(void **st) { (void)st; check("xl_uv_mesh", NULL, "uv_mesh", 0.003); }
/* a uv-mapped texture's normal on rotated meshes: its bumps turn with the
 * object (without the uv texture's outer warps on the normal: 0.0101) */
static void test_uv_normal(void **st) { (void)st; check("xl_uv_normal", NULL, "uv_normal", 0.001); }
/* uv_mapping inherited by CSG members (keeping the member's own texture
 * from the union's transforms, or not uv-mapping that member, lands above
 * the bound) */
static void test_uv_csg(void **st) { (void)st; check("xl_uv_csg", NULL, "uv_csg", 0.002); }
/* interior_texture on meshes (the side taken from the winding normal
 * lands far above the bound) */
static void test_interior_texture(void **st) { (void)st; check("xl_interior_tex", NULL, "interior_texture", 0.002); }
static void write_image(void);
static void test_uv_levels(void **st)
{
    (void)st;
    write_image();
    check("xl_uv_levels", NULL, "uv_levels", 0.003);
}
/* object pattern (identical to POV-Ray; without clipped_by applied 0.0013) */
static void test_object_pattern(void **st) { (void)st; check("xl_objpattern", NULL, "object_pattern", 0.0005); }
static void test_cameras(void **st)
{
    (void)st;
    static const char *const names[] = {"fisheye", "panoramic", "spherical", "cylinder1", "ultra_wide"};
    for (int i = 1; i <= 5; i++) {
        char decl[32];
        snprintf(decl, sizeof decl, "CAM=%d", i);
        check("xl_camera", decl, names[i - 1], 0.005);
    }
}

/* The image the gamma scene maps: 32x24 RGB, written with partray's PNG
 * writer (sRGB encoded, sRGB chunk). */
static void write_image(void)
{
    framebuffer *fb = fb_new(32, 24);
    assert_non_null(fb);
    for (int y = 0; y < 24; y++)
        for (int x = 0; x < 32; x++) {
            float *px = fb_px(fb, x, y);
            px[0] = (float)(x / 31.0);
            px[1] = (float)(y / 23.0);
            px[2] = (float)(((x / 4 + y / 4) & 1) ? 0.9 : 0.1);
        }
    char path[512];
    snprintf(path, sizeof path, "%s/xl_image.png", tmpdir);
    img_write_opts o;
    img_default_write_opts(&o);
    assert_int_equal(img_write(path, fb, &o, NULL), PT_OK);
    fb_free(fb);
}

static void test_gamma_image(void **st)
{
    (void)st;
    write_image();
    check("xl_gamma", NULL, "gamma_image", 0.004);
}

/* interior dispersion (a prism with the default 7 bands, a sphere with
 * 12): the ior used for every colour lands far above the bound, so it also
 * fails a render that ignores dispersion. */
static void test_dispersion(void **st) { (void)st; check("xl_dispersion", NULL, "dispersion", 0.006); }
/* a dispersive slab (5 bands) in front of a dispersive sphere (9); the
 * slab not dispersing lands above the bound */
static void test_dispersion_chain(void **st) { (void)st; check("xl_dispersion2", NULL, "dispersion_chain", 0.008); }

/* The hue table partray generates from POV-Ray 3.6's hue formula against
 * numbers of the table POV-Ray 3.7.0 compiles (backend/colour/spectral.cpp,
 * 4 decimals), the band layout and the band ior (closed forms). */
static void test_spectral(void **st)
{
    (void)st;
    static const struct { double wl, r, g, b; } pov[] = {
        {375, 0, 0, 0}, {380, 0.0009, 0, 0.0038}, {440, 0.0404, 0, 0.2753}, {500, 0.0404, 0.0045, 0.7218},
        {575, 0.0429, 0.4297, 1}, {600, 0.1215, 0.6340, 1}, {670, 0.6573, 0.9981, 1}, {735, 0.9998, 1, 1},
        {740, 1, 1, 1},
    };
    for (size_t i = 0; i < sizeof pov / sizeof pov[0]; i++) {
        rgb c = shade_spectral_hue_integral(pov[i].wl);
        assert_true(fabs(c.r - pov[i].r) < 1e-9 && fabs(c.g - pov[i].g) < 1e-9 && fabs(c.b - pov[i].b) < 1e-9);
    }
    /* linear between entries, clamped outside 375..740 */
    rgb m = shade_spectral_hue_integral(437.5), lo = shade_spectral_hue_integral(300), hi = shade_spectral_hue_integral(800);
    assert_true(fabs(m.b - 0.5 * (0.2412 + 0.2753)) < 1e-9 && lo.b == 0.0 && hi.r == 1.0);
    /* element i of n: 380 + 350 (i + 0.5) / n nm, 350 / n wide; the n hues
     * average to I(730) - I(380) = (0.9938, 1, 0.9962) */
    shade_spectral_band b0 = shade_spectral_band_of(0, 7);
    assert_true(fabs(b0.wavelength - 405.0f) < 1e-4f && fabs(b0.bandwidth - 50.0f) < 1e-4f);
    rgb avg = {0, 0, 0};
    for (unsigned i = 0; i < 7; i++) {
        rgb h = shade_spectral_hue(shade_spectral_band_of(i, 7));
        avg.r += h.r / 7;
        avg.g += h.g / 7;
        avg.b += h.b / 7;
    }
    assert_true(fabs(avg.r - 0.9938) < 1e-6 && fabs(avg.g - 1.0) < 1e-6 && fabs(avg.b - 0.9962) < 1e-6);
    /* ior * disp^(-(wl - 555) / 350): violet (405 nm) entering ior 1.5,
     * dispersion 1.3 sees 1.5 * 1.3^(150/350) */
    assert_true(fabs(1.0 / shade_spectral_ior(405.0f, 1.0 / 1.5, 1.0 / 1.3) - 1.5 * pow(1.3, 150.0 / 350.0)) < 1e-9);
}

/* Trace levels of straight rays (closed forms along the view axis, to
 * 1e-6): a ray that goes on unbent through a surface between equal iors
 * keeps its level (POV-Ray 3.7's ComputeRefraction traces it as a continued
 * ray), and still ends where its level is at the limit. Four transparent
 * planes without ior (transmit 0.8, no light of their own) in front of a
 * wall of ambient 0.5: 0.5 * 0.8^4 = 0.2048 with max_trace_level 2, black
 * with 1. Two overlapping boxes of ior 1.5 (filter 1) crossed at normal
 * incidence: entering the second inside the first and leaving the first
 * inside the second bend nothing, so the wall is the third level: 0.5 with
 * max_trace_level 3, black with 2. povray renders the same four cases as
 * sRGB 125, 0, 188, 0 (0.2051, 0, 0.5029, 0); with every surface counting
 * a level all four were black. */
static double straight_ray(const char *objects, int max_level)
{
    char src[1024];
    snprintf(src, sizeof src,
             "#version 3.7;\n"
             "global_settings { assumed_gamma 1.0 max_trace_level %d }\n"
             "background { rgb 0 }\n"
             "#default { finish { ambient 0 diffuse 0 } }\n"
             "plane { z, 10 pigment { rgb 0.5 } finish { ambient 1 } }\n%s",
             max_level, objects);
    tu_world w = tu_world_build("levels.pov", src);
    shade_settings ss;
    shade_default_settings(&ss);
    rng r;
    rng_seed(&r, 1, 2);
    rgb c = shade_trace(w.s, w.a, &ss, v3(0, 0, -5), v3(0, 0, 1), 0, &r);
    tu_world_free(&w);
    printf("look straight rays, max_trace_level %d: %.6f %.6f %.6f\n", max_level, c.r, c.g, c.b);
    assert_true(fabs(c.r - c.g) < 1e-9 && fabs(c.g - c.b) < 1e-9);
    return c.r;
}

static void test_straight_ray_levels(void **st)
{
    (void)st;
    static const char panes[] = "#declare I = 0;\n"
                                "#while (I < 4) plane { z, I pigment { rgbt <1, 1, 1, 0.8> } } #declare I = I + 1; #end\n";
    static const char boxes[] = "box { <-5, -5, 0>, <5, 5, 2> pigment { rgbf 1 } interior { ior 1.5 } }\n"
                                "box { <-5, -5, 1>, <5, 5, 3> pigment { rgbf 1 } interior { ior 1.5 } }\n";
    assert_true(fabs(straight_ray(panes, 2) - 0.2048) < 1e-6);
    assert_true(fabs(straight_ray(panes, 1)) < 1e-6);
    assert_true(fabs(straight_ray(boxes, 3) - 0.5) < 1e-6);
    assert_true(fabs(straight_ray(boxes, 2)) < 1e-6);
}

int main(void)
{
    if (tu_mkdtemp(tmpdir, sizeof tmpdir, "partray-look") != 0) return 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_textures),
        cmocka_unit_test(test_glass),
        cmocka_unit_test(test_atmosphere),
        cmocka_unit_test(test_facets),
        cmocka_unit_test(test_irid),
        cmocka_unit_test(test_light_group),
        cmocka_unit_test(test_uv_mapping),
        cmocka_unit_test(test_uv_normal),
        cmocka_unit_test(test_uv_shapes),
        cmocka_unit_test(test_uv_mesh),
        cmocka_unit_test(test_uv_levels),
        cmocka_unit_test(test_uv_csg),
        cmocka_unit_test(test_interior_texture),
        cmocka_unit_test(test_object_pattern),
        cmocka_unit_test(test_cameras),
        cmocka_unit_test(test_gamma_image),
        cmocka_unit_test(test_dispersion),
        cmocka_unit_test(test_dispersion_chain),
        cmocka_unit_test(test_spectral),
        cmocka_unit_test(test_straight_ray_levels),
    };
    return tu_finish(cmocka_run_group_tests(tests, NULL, NULL), tmpdir);
}
