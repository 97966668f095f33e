/* test_shapes_xc.c - new shapes and image formats against POV-Ray
 * 3.7's own image: ovus (tests/scenes/xs_ovus.pov), height fields from a
 * function and from TGA, JPEG and PPM files that POV-Ray writes first
 * (xs_hf.pov, xs_hf_src.pov), bounded_by's culling (xs_bounded.pov) and
 * noise-displaced isosurfaces (xs_iso.pov).
 * Criterion: mean absolute sRGB difference after a 4x4 downsample <= 0.01
 * (agreement is 0.02; the differences are printed; bounded_by without the
 * cull by the dropped bound's box lands above 0.01). Most of its time is
 * the two renderers. Skipped when povray is not installed. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include "test_util.h"

#define TOL 0.01

static char dir[128];

static int have_povray(void) { return tu_run("command -v povray >/dev/null 2>&1") == 0; }

static void check(const char *scene, const char *tag, const char *decl)
{
    char path[512];
    snprintf(path, sizeof path, "%s/scenes/%s", TESTS_DIR, scene);
    double mad = tu_crosscheck(PARTRAY_BIN, dir, path, tag, 96, 72, decl);
    print_message("%-12s mean |diff| %.5f\n", tag, mad);
    if (!(mad <= TOL)) fail_msg("%s: mean |diff| %.5f > %.3f (images in %s)", tag, mad, TOL, dir);
}

static void test_ovus(void **st)
{
    (void)st;
    check("xs_ovus.pov", "ovus", NULL);
}

static void test_hf(void **st)
{
    (void)st;
    check("xs_hf.pov", "hf_function", NULL);
    static const char *const fmt[][2] = {{"+FT", "src.tga"}, {"+FJ", "src.jpg"}, {"+FP", "src.ppm"}, {"+FC", "src_rle.tga"}};
    for (int i = 0; i < 4; i++) {
        char cmd[1024], decl[256], tag[32];
        snprintf(cmd, sizeof cmd, "cd '%s' && povray +I'%s/scenes/xs_hf_src.pov' +O%s +W64 +H64 %s -D -V -GA >/dev/null 2>&1",
                 dir, TESTS_DIR, fmt[i][1], fmt[i][0]);
        assert_int_equal(tu_run(cmd), 0);
        /* (POV-Ray's Declare= takes numbers only: a wrapper scene names the file) */
        snprintf(tag, sizeof tag, "hf_%d", i);
        snprintf(decl, sizeof decl, "%s/%s.pov", dir, tag);
        snprintf(cmd, sizeof cmd,
                 "#declare HF_FILE = 1;\n#include \"%s/scenes/xs_hf.pov\"\n"
                 "height_field { \"%s\" smooth pigment { gradient y color_map { [0 rgb <1,0,0>] [1 rgb <0,0,1>] } } }\n",
                 TESTS_DIR, fmt[i][1]);
        tu_write_file(decl, cmd);
        double mad = tu_crosscheck(PARTRAY_BIN, dir, decl, tag, 96, 72, NULL);
        print_message("%-12s mean |diff| %.5f (%s)\n", tag, mad, fmt[i][1]);
        if (!(mad <= TOL)) fail_msg("%s: mean |diff| %.5f > %.3f (images in %s)", tag, mad, TOL, dir);
    }
}

/* Noise-displaced isosurfaces lit at a grazing angle, with coarse
 * accuracy: POV-Ray's forward-difference normal (geom_implicit.c).
 * Regression bound 0.0018: with the exact gradient the difference was
 * 0.0025. The rest is the terminator's self-shadow (docs/shapes.md). */
static void test_isosurface(void **st)
{
    (void)st;
    if (!have_povray()) skip();
    char path[512];
    snprintf(path, sizeof path, "%s/scenes/xs_iso.pov", TESTS_DIR);
    double mad = tu_crosscheck(PARTRAY_BIN, dir, path, "isosurface", 96, 72, NULL);
    print_message("%-12s mean |diff| %.5f (regression bound 0.0018)\n", "isosurface", mad);
    if (!(mad <= 0.0018)) fail_msg("isosurface: mean |diff| %.5f > 0.0018 (images in %s)", mad, dir);
}

static void test_bounded(void **st)
{
    (void)st;
    check("xs_bounded.pov", "bounded", NULL);
}

int main(void)
{
    if (!have_povray()) {
        fprintf(stderr, "test_shapes_xc: povray not installed; skipped\n");
        return 0;
    }
    if (tu_mkdtemp(dir, sizeof dir, "test_shapes_xc") != 0) return 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ovus),
        cmocka_unit_test(test_hf),
        cmocka_unit_test(test_isosurface),
        cmocka_unit_test(test_bounded),
    };
    int r = cmocka_run_group_tests(tests, NULL, NULL);
    if (r == 0) tu_rm_rf(dir);
    return r;
}
