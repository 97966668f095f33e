/* test_cli.c - the partray command end to end: exit codes, located errors,
 * no output file on failure, --stats keys, POV-Ray style options. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include "framebuffer.h"
#include "img_io.h"
#include "test_util.h"

#ifndef PT_TESTS_DIR
#define PT_TESTS_DIR "tests"
#endif

static char tmpdir[256];
/* Render SCENE_TEXT; expect exit `code`, `needle` in the output and no file. */
static void expect_failure(const char *scene_text, int code, const char *needle)
{
    char scene[512], out[512], cmd[2048];
    snprintf(scene, sizeof scene, "%s/bad.pov", tmpdir);
    snprintf(out, sizeof out, "%s/bad.png", tmpdir);
    remove(out);
    if (scene_text) tu_write_file(scene, scene_text);
    else remove(scene);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' -o '%s' --size 16x16", PARTRAY_BIN, scene, out);
    int rc = tu_run_capture(cmd);
    printf("exit %d: %s", rc, tu_out);
    assert_int_equal(rc, code);
    assert_non_null(strstr(tu_out, needle));
    assert_false(tu_exists(out));
}

static void test_missing_file(void **st)
{
    (void)st;
    char needle[600];
    snprintf(needle, sizeof needle, "%s/bad.pov", tmpdir);
    expect_failure(NULL, 3, needle);
}

static void test_unknown_keyword(void **st)
{
    (void)st;
    char needle[600];
    snprintf(needle, sizeof needle, "%s/bad.pov:3:1: error:", tmpdir);
    expect_failure("// a scene\nsphere { 0, 1 }\nspehre { 0, 1 }\n", 1, needle);
}

static void test_unterminated_block(void **st)
{
    (void)st;
    char needle[600];
    snprintf(needle, sizeof needle, "%s/bad.pov:", tmpdir);
    expect_failure("camera { location -5*z look_at 0 }\nsphere { 0, 1\n  pigment { rgb 1 }\n", 1, needle);
    assert_non_null(strstr(tu_out, "error:"));
}

static void test_include_chain(void **st)
{
    (void)st;
    char inc[512];
    snprintf(inc, sizeof inc, "%s/inc_bad.inc", tmpdir);
    tu_write_file(inc, "#declare A = 1;\nbogus_word\n");
    char needle[600];
    snprintf(needle, sizeof needle, "%s/inc_bad.inc:2:1: error:", tmpdir);
    expect_failure("#include \"inc_bad.inc\"\n", 1, needle);
    assert_non_null(strstr(tu_out, "bad.pov:1"));
}

static void test_usage(void **st)
{
    (void)st;
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "'%s' render", PARTRAY_BIN);
    assert_int_equal(tu_run_capture(cmd), 2);
    snprintf(cmd, sizeof cmd, "'%s' render x.pov --size 12", PARTRAY_BIN);
    assert_int_equal(tu_run_capture(cmd), 2);
    snprintf(cmd, sizeof cmd, "'%s' frobnicate", PARTRAY_BIN);
    assert_int_equal(tu_run_capture(cmd), 2);
    snprintf(cmd, sizeof cmd, "'%s' --version", PARTRAY_BIN);
    assert_int_equal(tu_run_capture(cmd), 0);
    assert_non_null(strstr(tu_out, "partray "));
    snprintf(cmd, sizeof cmd, "'%s' --help", PARTRAY_BIN);
    assert_int_equal(tu_run_capture(cmd), 0);
    assert_non_null(strstr(tu_out, "partray render"));
}

/* Every command answers --help (or -h) with its own options on stdout,
 * exit 0, whatever else is on the line; `partray --help` and `render
 * --help` list the exit codes. */
static void test_help(void **st)
{
    (void)st;
    struct { const char *cmd, *option; } c[] = {
        {"render", "--gi MODE"}, {"parse", "--max-loop"}, {"compare", "--heatmap"}, {"sweep", "--vary"},
        {"crosscheck", "--povray"}, {"view", "--script"}, {"merge", "TILE.exr"}, {"farm", "--tiles"},
    };
    char cmd[1024];
    for (size_t i = 0; i < sizeof c / sizeof c[0]; i++) {
        snprintf(cmd, sizeof cmd, "'%s' %s --help 2>/dev/null", PARTRAY_BIN, c[i].cmd);
        assert_int_equal(tu_run_stdout(cmd), 0);
        if (!strstr(tu_out, c[i].option)) fail_msg("%s --help lacks %s:\n%s", c[i].cmd, c[i].option, tu_out);
        snprintf(cmd, sizeof cmd, "'%s' %s some.pov -h 2>/dev/null", PARTRAY_BIN, c[i].cmd);
        assert_int_equal(tu_run_stdout(cmd), 0);
        assert_non_null(strstr(tu_out, c[i].option));
    }
    snprintf(cmd, sizeof cmd, "'%s' --help", PARTRAY_BIN);
    assert_int_equal(tu_run_stdout(cmd), 0);
    assert_non_null(strstr(tu_out, "130  interrupted"));
    snprintf(cmd, sizeof cmd, "'%s' render --help", PARTRAY_BIN);
    assert_int_equal(tu_run_stdout(cmd), 0);
    assert_non_null(strstr(tu_out, "3    I/O"));
}

/* Exit codes as cli.h lists them: a missing include is a scene error (1)
 * like a syntax error; a missing output directory is I/O (3) and is found
 * before the scene is parsed (the scene here is broken too: 3 wins, and no
 * parse error is printed); a size too large says why (2). */
static void test_exit_codes(void **st)
{
    (void)st;
    char needle[600];
    snprintf(needle, sizeof needle, "%s/bad.pov:2:1: error: cannot find include file \"no_such.inc\"", tmpdir);
    expect_failure("// a scene\n#include \"no_such.inc\"\n", 1, needle);

    char scene[512], cmd[2048];
    snprintf(scene, sizeof scene, "%s/broken.pov", tmpdir);
    tu_write_file(scene, "sphere { 0, 1 \n");
    snprintf(cmd, sizeof cmd, "'%s' render '%s' -o '%s/no_dir/x.png' --size 8x8", PARTRAY_BIN, scene, tmpdir);
    assert_int_equal(tu_run_capture(cmd), 3);
    assert_non_null(strstr(tu_out, "no_dir' does not exist"));
    assert_null(strstr(tu_out, "error:")); /* the scene was never read */
    /* the same for --stats and a path that is a directory */
    snprintf(cmd, sizeof cmd, "'%s' render '%s' -o '%s/x.png' --stats '%s/no_dir/s.json' --size 8x8", PARTRAY_BIN, scene,
             tmpdir, tmpdir);
    assert_int_equal(tu_run_capture(cmd), 3);
    snprintf(cmd, sizeof cmd, "mkdir -p '%s/dir.png' && '%s' render '%s' -o '%s/dir.png' --size 8x8", tmpdir, PARTRAY_BIN,
             scene, tmpdir);
    assert_int_equal(tu_run_capture(cmd), 3);
    assert_non_null(strstr(tu_out, "is a directory"));

    snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 100000x100000", PARTRAY_BIN, scene);
    assert_int_equal(tu_run_capture(cmd), 2);
    assert_non_null(strstr(tu_out, "image size 100000x100000: a side is larger than 65536 pixels"));
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 30000x30000", PARTRAY_BIN, scene);
    assert_int_equal(tu_run_capture(cmd), 2);
    assert_non_null(strstr(tu_out, "900000000 pixels, more than the 268435456 an image may have"));
}

/* A scene without objects warns, as POV-Ray does, and renders its
 * background: every pixel is the background colour (0.25 0.5 0.75 linear,
 * PFM). Without -o and a size, the default name and size are stated and
 * used: SCENE.png, 320x240, in the current directory. */
static void test_empty_scene_and_defaults(void **st)
{
    (void)st;
    char scene[512], cmd[2048], out[512];
    snprintf(scene, sizeof scene, "%s/empty.pov", tmpdir);
    tu_write_file(scene, "global_settings { assumed_gamma 1 }\ncamera { location -5*z look_at 0 }\n"
                         "light_source { <0, 5, -5> rgb 1 }\nbackground { rgb <0.25, 0.5, 0.75> }\n");
    snprintf(out, sizeof out, "%s/empty.pfm", tmpdir);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' -o '%s' --size 8x6", PARTRAY_BIN, scene, out);
    assert_int_equal(tu_run_capture(cmd), 0);
    assert_non_null(strstr(tu_out, "warning: no objects in scene"));
    framebuffer *fb = NULL;
    assert_int_equal(img_read(out, 0, &fb, NULL), PT_OK);
    for (int y = 0; y < fb->height; y++)
        for (int x = 0; x < fb->width; x++) {
            const float *p = fb_px(fb, x, y);
            assert_true(fabs(p[0] - 0.25) < 1e-6 && fabs(p[1] - 0.5) < 1e-6 && fabs(p[2] - 0.75) < 1e-6);
        }
    fb_free(fb);
    snprintf(cmd, sizeof cmd, "cd '%s' && '%s' parse empty.pov", tmpdir, PARTRAY_BIN);
    assert_int_equal(tu_run_capture(cmd), 0);
    assert_non_null(strstr(tu_out, "warning: no objects in scene"));

    snprintf(cmd, sizeof cmd, "cd '%s' && '%s' render empty.pov", tmpdir, PARTRAY_BIN);
    assert_int_equal(tu_run_capture(cmd), 0);
    assert_non_null(strstr(tu_out, "no output given (-o or +O): writing empty.png"));
    assert_non_null(strstr(tu_out, "no size given (--size WxH or +W +H): 320x240"));
    snprintf(out, sizeof out, "%s/empty.png", tmpdir);
    assert_int_equal(img_read(out, 0, &fb, NULL), PT_OK);
    assert_int_equal(fb->width, 320);
    assert_int_equal(fb->height, 240);
    fb_free(fb);
}

/* POV-Ray's working gamma in every GI mode: under `assumed_gamma 2.2` the
 * scene's colours and the shading's arithmetic are in the working space
 * and the image leaves it as v^2.2 (shade_gamma.h). A white diffuse
 * sphere in a uniform background of working value 0.5 reflects 0.5 there
 * (the furnace), so every pixel on it is 0.5^2.2 = 0.2176 in the linear
 * PFM, within 2% of the mean: the Whitted modes and the references alike
 * (a mode that wrote the working value would give 0.5). */
static void test_working_gamma_all_modes(void **st)
{
    (void)st;
    char scene[512], cmd[2048], out[512];
    snprintf(scene, sizeof scene, "%s/gamma_furnace.pov", tmpdir);
    tu_write_file(scene, "#version 3.7;\nglobal_settings { assumed_gamma 2.2 radiosity { count 100 } }\n"
                         "camera { location -4*z look_at 0 angle 20 }\nbackground { rgb 0.5 }\n"
                         "sphere { 0, 1 pigment { rgb 1 } finish { ambient 0 diffuse 1 } }\n");
    const char *modes[] = {"particle", "path --spp 64", "pmfg --spp 4"};
    const double expect = pow(0.5, 2.2);
    for (int m = 0; m < 3; m++) {
        snprintf(out, sizeof out, "%s/gamma_furnace_%d.pfm", tmpdir, m);
        snprintf(cmd, sizeof cmd, "'%s' render '%s' -o '%s' --size 16x16 --threads 2 --quiet --gi %s", PARTRAY_BIN,
                 scene, out, modes[m]);
        assert_int_equal(tu_run_capture(cmd), 0);
        framebuffer *fb = NULL;
        assert_int_equal(img_read(out, 0, &fb, NULL), PT_OK);
        double s = 0.0;
        int n = 0;
        for (int y = 6; y < 10; y++)
            for (int x = 6; x < 10; x++) {
                s += fb_px(fb, x, y)[1];
                n++;
            }
        fb_free(fb);
        printf("  assumed_gamma 2.2 furnace, --gi %-14s centre mean %.5f (expected %.5f)\n", modes[m], s / n, expect);
        assert_true(fabs(s / n / expect - 1.0) <= 0.02);
    }
}

/* A white furnace lit by radiosity alone with no bounce after the gather
 * (recursion_limit 1), antialiased: a diffuse white sphere under a
 * uniform sky of 0.5 reflects 0.5 everywhere, so every pixel, edges and
 * their antialiasing rays included, is 0.5; and since the final gather
 * answers every hit, the geometry stage places no particles
 * (gi_particle_final_only). */
static void test_exact_gather_furnace(void **st)
{
    (void)st;
    char scene[512], cmd[2048], out[512], stats[512];
    snprintf(scene, sizeof scene, "%s/exact_furnace.pov", tmpdir);
    snprintf(out, sizeof out, "%s/exact_furnace.pfm", tmpdir);
    snprintf(stats, sizeof stats, "%s/exact_furnace.json", tmpdir);
    tu_write_file(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1 radiosity { count 100 recursion_limit 1 "
                         "error_bound 0.3 } }\ncamera { location -4*z look_at 0 angle 30 }\nsky_sphere { pigment { rgb 0.5 } }\n"
                         "sphere { 0, 1 pigment { rgb 1 } finish { ambient 0 diffuse 1 } }\n");
    snprintf(cmd, sizeof cmd, "'%s' render '%s' -o '%s' --size 24x24 +A0.05 --threads 2 --quiet --stats '%s'", PARTRAY_BIN,
             scene, out, stats);
    assert_int_equal(tu_run_capture(cmd), 0);
    framebuffer *fb = NULL;
    assert_int_equal(img_read(out, 0, &fb, NULL), PT_OK);
    double worst = 0.0;
    for (int i = 0; i < fb->width * fb->height * 3; i++) worst = fmax(worst, fabs(fb->rgb[i] / 0.5 - 1.0));
    fb_free(fb);
    const char *js = tu_read_file(stats); /* a static buffer */
    assert_non_null(js);
    printf("  recursion_limit 1 furnace +A: worst pixel off by %.4f (bound 0.01); stats %s %s\n", worst,
           strstr(js, "\"particles\": 0,") ? "0 particles" : "particles placed",
           strstr(js, "\"lookups_gathered_here\": 0,") ? "no hit gathered itself" : "hits gathered themselves");
    assert_true(worst <= 0.01);
    assert_non_null(strstr(js, "\"particles\": 0,"));
    assert_null(strstr(js, "\"lookups_gathered_here\": 0,"));
}

/* radiosity's `normal on`: the particle mode's final gather gathers about
 * the perturbed normal (core/radrules.h rule 5), so a bumped white sphere
 * under a uniform sky of 0.5 (no lights, recursion_limit 1) takes less
 * than 0.5 where its perturbed normals lean into the sphere (the sphere
 * hides the part of their hemisphere below its tangent plane), and 0.5
 * within 2% with `normal off` (the raw normal's hemisphere is all sky);
 * neither is warned about. The paper's estimate (--spp 4) cannot take the
 * perturbation: `normal on` is warned about once there and counted in
 * --stats (light_not_modelled.normal 1). */
static void test_radiosity_normal(void **st)
{
    (void)st;
    char scene[512], cmd[2048], out[512], stats[512];
    snprintf(out, sizeof out, "%s/rnormal.pfm", tmpdir);
    snprintf(stats, sizeof stats, "%s/rnormal.json", tmpdir);
    double mean[2] = {0.0, 0.0};
    for (int run = 0; run < 3; run++) {
        const int on = run != 0, spp = run == 2;
        snprintf(scene, sizeof scene, "%s/rnormal%d.pov", tmpdir, on);
        char text[1024];
        snprintf(text, sizeof text,
                 "#version 3.7;\nglobal_settings { assumed_gamma 1 radiosity { count 100 recursion_limit 1 normal %s } }\n"
                 "camera { location -4*z look_at 0 angle 30 }\nsky_sphere { pigment { rgb 0.5 } }\n"
                 "sphere { 0, 1 pigment { rgb 1 } normal { bumps 2 scale 0.2 } finish { ambient 0 diffuse 1 } }\n",
                 on ? "on" : "off");
        tu_write_file(scene, text);
        snprintf(cmd, sizeof cmd, "'%s' render '%s' -o '%s' --size 16x16 --threads 2 --stats '%s'%s", PARTRAY_BIN, scene,
                 out, stats, spp ? " --spp 4" : "");
        assert_int_equal(tu_run_capture(cmd), 0);
        const char *w = strstr(tu_out, "radiosity normal on is not modelled");
        const char *js = tu_read_file(stats); /* a static buffer */
        assert_non_null(js);
        const char *k = strstr(js, "\"normal\": 1");
        printf("  radiosity normal %s%s: warned %s, counted %s\n", on ? "on" : "off", spp ? " --spp 4" : "",
               w ? "yes" : "no", k ? "yes" : "no");
        if (spp) {
            assert_non_null(w);
            assert_null(strstr(w + 1, "radiosity normal on is not modelled")); /* once */
            assert_non_null(k);
            continue;
        }
        assert_null(w);
        assert_null(k);
        framebuffer *fb = NULL;
        assert_int_equal(img_read(out, 0, &fb, NULL), PT_OK);
        for (int y = 6; y < 10; y++)
            for (int x = 6; x < 10; x++) mean[on] += fb_px(fb, x, y)[1] / 16.0;
        fb_free(fb);
    }
    printf("  centre mean: normal off %.4f (expected 0.5), normal on %.4f\n", mean[0], mean[1]);
    assert_true(fabs(mean[0] / 0.5 - 1.0) <= 0.02);
    assert_true(mean[1] < 0.99 * mean[0]);
    assert_true(mean[1] > 0.75 * mean[0]);
}

/* --clock, +K and the animation switches: the predeclared identifiers as
 * POV-Ray 3.7.0 gives them (each expected pair printed by
 * `povray +Ik.pov -F -D +W8 +H6 OPTIONS` with the same scene). */
static void test_animation(void **st)
{
    (void)st;
    static const struct {
        const char *opts, *k, *c;
    } cases[] = {
        {"", "K 0.000000 0 fn 0 if 0 ff 0", "C 0.000000 0.000000 0.000000"},
        {"+K0.5", "K 0.500000 1 fn 0 if 0 ff 0", "C 0.000000 0.000000 0.000000"},
        {"--clock 0.25", "K 0.250000 1 fn 0 if 0 ff 0", "C 0.000000 0.000000 0.000000"},
        {"+KFI1 +KFF10 +SF4 +EF4", "K 0.333333 1 fn 4 if 1 ff 10", "C 0.000000 1.000000 0.111111"},
        {"+KFI1 +KFF10", "K 0.000000 1 fn 1 if 1 ff 10", "C 0.000000 1.000000 0.111111"},
        {"+KFI0 +KFF4 +KI2 +KF3 +SF2 +EF2", "K 2.500000 1 fn 2 if 0 ff 4", "C 2.000000 3.000000 0.250000"},
        {"+KFI1 +KFF5 +KC +SF3 +EF3", "K 0.400000 1 fn 3 if 1 ff 6", "C 0.000000 1.000000 0.200000"},
        {"+KFF3 +SF2 +EF2", "K 0.500000 1 fn 2 if 1 ff 3", "C 0.000000 1.000000 0.500000"},
        {"+K0.5 +KFF3 --frame 2", "K 0.500000 1 fn 2 if 1 ff 3", "C 0.000000 1.000000 0.500000"},
        {"+KI1 +KF2", "K 0.000000 0 fn 0 if 0 ff 0", "C 0.000000 0.000000 0.000000"},
        {"+KFI2 +KFF4 +KI1 +KF0 +SF4 +EF4", "K 0.000000 1 fn 4 if 2 ff 4", "C 1.000000 0.000000 -0.500000"},
        {"+KFI2 +KFF4 +KC +SF2 +EF2", "K 0.000000 1 fn 2 if 2 ff 5", "C 0.000000 1.000000 0.333333"},
        {"+K2 +KFI1 +KFF1", "K 2.000000 1 fn 0 if 0 ff 0", "C 0.000000 0.000000 0.000000"},
    };
    char scene[512], cmd[2048];
    snprintf(scene, sizeof scene, "%s/anim.pov", tmpdir);
    tu_write_file(scene, "#debug concat(\"K \", str(clock,0,6), \" \", str(clock_on,0,0), \" fn \", str(frame_number,0,0), "
                         "\" if \", str(initial_frame,0,0), \" ff \", str(final_frame,0,0), \"\\n\")\n"
                         "#debug concat(\"C \", str(initial_clock,0,6), \" \", str(final_clock,0,6), \" \", "
                         "str(clock_delta,0,6), \"\\n\")\nsphere { 0, 1 }\n");
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        snprintf(cmd, sizeof cmd, "'%s' parse '%s' %s", PARTRAY_BIN, scene, cases[i].opts);
        int rc = tu_run_capture(cmd);
        if (rc != 0 || !strstr(tu_out, cases[i].k) || !strstr(tu_out, cases[i].c))
            printf("%s\n  want \"%s\" and \"%s\"\n  got %s", cases[i].opts, cases[i].k, cases[i].c, tu_out);
        assert_int_equal(rc, 0);
        assert_non_null(strstr(tu_out, cases[i].k));
        assert_non_null(strstr(tu_out, cases[i].c));
    }
    /* a frame needs an animation and must be in it (frames in one run:
     * tests/test_anim.c) */
    const char *bad[] = {"--frame 3", "+KFI1 +KFF3 --frame 9", "+KFI5 +KFF2", "--clock x"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        snprintf(cmd, sizeof cmd, "'%s' parse '%s' %s", PARTRAY_BIN, scene, bad[i]);
        assert_int_equal(tu_run_capture(cmd), 2);
    }
}

/* mesh_camera renders as POV-Ray 3.7.0 does: distribution 0 with one
 * triangle per pixel (tests/scenes/meshcam.pov) and the same with 2 rays per
 * pixel from 2 meshes, averaged (meshcam2.pov). Mean absolute sRGB
 * difference under 0.005 and no pixel off by more than 0.02 from povray's own
 * image (NAME_povray.png, `povray +W32 +H24 -A`; the two scenes differ from
 * each other by far more than that, so each image is checked). The
 * rows follow POV-Ray's indexing (row r > 0 shoots from face row r-1). */
static void test_mesh_camera(void **st)
{
    (void)st;
    const char *names[] = {"meshcam", "meshcam2"};
    for (int k = 0; k < 2; k++) {
        char scene[1024], ref[1024], out[512], cmd[2048];
        snprintf(scene, sizeof scene, "%s/scenes/%s.pov", PT_TESTS_DIR, names[k]);
        snprintf(ref, sizeof ref, "%s/scenes/%s_povray.png", PT_TESTS_DIR, names[k]);
        snprintf(out, sizeof out, "%s/%s.png", tmpdir, names[k]);
        snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 32x24 -o '%s'", PARTRAY_BIN, scene, out);
        int rc = tu_run_capture(cmd);
        if (rc) printf("%s", tu_out);
        assert_int_equal(rc, 0);
        assert_null(strstr(tu_out, "mesh_camera")); /* no "not supported" warning */
        framebuffer *a = NULL, *b = NULL;
        diag *d = diag_new();
        assert_int_equal(img_read(ref, 1, &a, d), PT_OK);
        assert_int_equal(img_read(out, 1, &b, d), PT_OK);
        assert_int_equal(a->width, b->width);
        assert_int_equal(a->height, b->height);
        double sum = 0, worst = 0;
        size_t n = (size_t)a->width * (size_t)a->height * 3;
        for (size_t i = 0; i < n; i++) {
            double e = fabs((double)a->rgb[i] - (double)b->rgb[i]);
            sum += e;
            if (e > worst) worst = e;
        }
        printf("%s vs povray: mean abs %.4f, max %.4f\n", names[k], sum / (double)n, worst);
        assert_true(sum / (double)n < 0.005);
        assert_true(worst < 0.02);
        fb_free(a);
        fb_free(b);
        diag_free(d);
    }
}

/* A white diffuse plane under a point light straight above: the pixel in the
 * image centre sees radiance L = diffuse * I * cos(0) = 0.5 * 1 * 1 (POV-Ray's
 * lights do not fall off with distance unless fade is given). Checks -D, the
 * +W/+H/+O options, every output format and the --stats keys. */
static void test_render_outputs_and_stats(void **st)
{
    (void)st;
    char scene[512], cmd[4096], stats[512];
    snprintf(scene, sizeof scene, "%s/plane.pov", tmpdir);
    tu_write_file(scene,
               "#version 3.7;\n"
               "global_settings { assumed_gamma 1.0 }\n"
               "camera { orthographic location <0, 5, 0> direction -y right x*2 up z*2 }\n"
               "light_source { <0, 10, 0> color rgb Power }\n"
               "plane { y, 0 pigment { rgb 1 } finish { ambient 0 diffuse 0.5 } }\n");
    snprintf(stats, sizeof stats, "%s/stats.json", tmpdir);
    snprintf(cmd, sizeof cmd,
             "'%s' render '%s' -D Power=1 +W32 +H24 +O%s/a.pfm -o %s/a.exr -o %s/a.png --stats '%s' --seed 3 --threads 2",
             PARTRAY_BIN, scene, tmpdir, tmpdir, tmpdir, stats);
    int rc = tu_run_capture(cmd);
    printf("%s", tu_out);
    assert_int_equal(rc, 0);
    const char *exts[] = {"pfm", "exr", "png"};
    for (int i = 0; i < 3; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/a.%s", tmpdir, exts[i]);
        framebuffer *fb = NULL;
        assert_int_equal(img_read(path, 0, &fb, NULL), PT_OK);
        assert_int_equal(fb->width, 32);
        assert_int_equal(fb->height, 24);
        double v = fb_px(fb, 16, 12)[1];
        printf("%s centre value %.5f (expect 0.5)\n", exts[i], v);
        assert_true(fabs(v - 0.5) < (i == 2 ? 0.004 : 1e-3));
        fb_free(fb);
    }
    FILE *f = fopen(stats, "rb");
    assert_non_null(f);
    size_t n = fread(tu_out, 1, sizeof tu_out - 1, f);
    tu_out[n] = 0;
    fclose(f);
    const char *keys[] = {"\"timings\"", "\"parse\"", "\"accel\"", "\"gi_geometry\"", "\"gi_lighting\"", "\"render\"",
                          "\"total\"", "\"rays\"", "\"width\": 32", "\"height\": 24", "\"gi\": \"none\""};
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
        if (!strstr(tu_out, keys[i])) fail_msg("stats lacks %s:\n%s", keys[i], tu_out);
    }
}

/* Ctrl-C during a long render: exit 130 within a second or so, the partial
 * image kept as NAME.partial.png, nothing under the final name. */
static void test_sigint_partial(void **st)
{
    (void)st;
    char scene[512], out[512], partial[512], cmd[2048];
    snprintf(scene, sizeof scene, "%s/slow.pov", tmpdir);
    snprintf(out, sizeof out, "%s/slow.png", tmpdir);
    snprintf(partial, sizeof partial, "%s/slow.partial.png", tmpdir);
    tu_write_file(scene,
               "camera { location <0, 3, -6> look_at 0 }\n"
               "light_source { <0, 5, 0> rgb 1 area_light 2*x, 2*z, 16, 16 jitter }\n"
               "plane { y, 0 pigment { rgb 1 } }\n"
               "sphere { <0, 1, 0>, 1 pigment { rgb 0.5 } }\n");
    /* Start the render in the background, interrupt it once it renders (after
     * 1.5 s: a sanitizer build starts slower), and time the stop: until the
     * partial file's temporary appears, i.e. the render loop has ended (the
     * write of 4 Mpx that follows is not part of stopping). */
    snprintf(cmd, sizeof cmd,
             "'%s' render '%s' -o '%s' --size 2000x2000 --threads 2 --quiet & pid=$!; sleep 1.5; "
             "t0=$(date +%%s%%N); kill -INT $pid; "
             "while kill -0 $pid 2>/dev/null && ! ls -a '%s' | grep -q '^\\.slow\\.partial\\.png\\.tmp-'; do sleep 0.005; done; "
             "t1=$(date +%%s%%N); wait $pid; rc=$?; echo \"rc=$rc ms=$(( (t1 - t0) / 1000000 ))\"",
             PARTRAY_BIN, scene, out, tmpdir);
    tu_run_capture(cmd);
    printf("%s", tu_out);
    int rc = -1, ms = -1;
    const char *p = strstr(tu_out, "rc=");
    assert_non_null(p);
    assert_int_equal(sscanf(p, "rc=%d ms=%d", &rc, &ms), 2);
    assert_int_equal(rc, 130);
    assert_true(ms >= 0 && ms < 1000);
    assert_true(tu_exists(partial));
    assert_false(tu_exists(out));
    framebuffer *fb = NULL;
    assert_int_equal(img_read(partial, 0, &fb, NULL), PT_OK);
    assert_int_equal(fb->width, 2000);
    fb_free(fb);
}

/* adaptive 0: the grid from its corners, subdivided where they differ (a
 * render of a second or two, whose bar fits the captured output) */
static const char progress_scene[] =
    "#debug \"debug text from the parse\\n\"\n"
    "camera { location <0, 3, -6> look_at 0 }\n"
    "light_source { <0, 5, 0> rgb 1 area_light 2*x, 2*z, 16, 16 jitter adaptive 0 }\n"
    "plane { y, 0 pigment { rgb 1 } }\n"
    "sphere { <0, 1, 0>, 1 pigment { rgb 0.5 } }\n";

/* On a terminal (script(1) gives the render one) a bar per stage is
 * redrawn in place (every 2 ms here, $PARTRAY_PROGRESS_REDRAW, so that a
 * render of a fraction of a second shows it too): the render's percent rises through several values,
 * an ETA is shown, and the stage ends with its time. The scene's #debug
 * text appears before the render's first bar, i.e. while it runs, not
 * at exit. */
static void test_progress_terminal(void **st)
{
    (void)st;
    char scene[512], cmd[2048];
    snprintf(scene, sizeof scene, "%s/progress.pov", tmpdir);
    tu_write_file(scene, progress_scene);
    snprintf(cmd, sizeof cmd,
             "script -q -e -c \"PARTRAY_PROGRESS_ETA_AFTER=0 PARTRAY_PROGRESS_REDRAW=0.002 '%s' render '%s' --size 640x480 "
             "--threads 2 -o "
             "'%s/progress.png'\" /dev/null",
             PARTRAY_BIN, scene, tmpdir);
    int rc = tu_run_capture(cmd);
    assert_int_equal(rc, 0);
    const char *debug = strstr(tu_out, "progress.pov:1:1: note: debug text from the parse");
    const char *bar = strstr(tu_out, "\033[Krender ");
    assert_non_null(debug);
    assert_non_null(bar);
    assert_true(debug < bar);
    /* the percents drawn, in order: at least three distinct, never falling */
    int last = -1, distinct = 0, eta = 0;
    for (const char *p = bar; (p = strstr(p, "\033[Krender ")) != NULL; p++) {
        const char *close = strchr(p, ']');
        int pct;
        if (!close || sscanf(close + 1, "%d%%", &pct) != 1) continue;
        assert_true(pct >= last);
        if (pct != last) distinct++;
        last = pct;
        const char *eol = strchr(p + 1, '\r');
        const char *e = strstr(p, "ETA ");
        if (e && (!eol || e < eol)) eta = 1;
    }
    printf("render bar: %d distinct percents, last %d%%, ETA shown %d\n", distinct, last, eta);
    assert_true(distinct >= 3);
    assert_true(eta);
    assert_non_null(strstr(tu_out, "render                       done in"));
}

/* Not on a terminal: no bar, a plain line now and then for a stage that
 * runs long ($PARTRAY_PROGRESS_SECONDS apart); -q: nothing at all on a
 * render that succeeds. */
static void test_progress_plain_and_quiet(void **st)
{
    (void)st;
    char scene[512], cmd[2048];
    snprintf(scene, sizeof scene, "%s/progress.pov", tmpdir);
    tu_write_file(scene, progress_scene);
    snprintf(cmd, sizeof cmd, "PARTRAY_PROGRESS_SECONDS=0.01 '%s' render '%s' --size 640x480 --threads 2 -o '%s/progress.png'",
             PARTRAY_BIN, scene, tmpdir);
    assert_int_equal(tu_run_capture(cmd), 0);
    printf("%s", tu_out);
    assert_null(strstr(tu_out, "\033[K"));
    int pct = -1;
    const char *p = strstr(tu_out, "partray: render ");
    assert_non_null(p);
    assert_int_equal(sscanf(p, "partray: render %d%% after", &pct), 1);
    assert_true(pct >= 0 && pct <= 100);
    snprintf(cmd, sizeof cmd, "PARTRAY_PROGRESS_SECONDS=0.2 '%s' render '%s' --size 320x240 --threads 2 -q -o '%s/progress.png'",
             PARTRAY_BIN, scene, tmpdir);
    assert_int_equal(tu_run_capture(cmd), 0);
    assert_string_equal(tu_out, "");
}

/* Ctrl-C during the particle GI's geometry stage, before any pixel was
 * rendered: exit 130, and no partial image (it would be black); the
 * message says why. */
static void test_sigint_during_gi(void **st)
{
    (void)st;
    char scene[512], out[512], partial[512], cmd[2048];
    snprintf(scene, sizeof scene, "%s/gi_slow.pov", tmpdir);
    snprintf(out, sizeof out, "%s/gi_slow.png", tmpdir);
    snprintf(partial, sizeof partial, "%s/gi_slow.partial.png", tmpdir);
    tu_write_file(scene, "camera { location <0, 3, -6> look_at 0 }\nlight_source { <0, 5, 0> rgb 1 }\n"
                         "plane { y, 0 pigment { rgb 1 } }\nsphere { <0, 1, 0>, 1 pigment { rgb 0.5 } }\n");
    snprintf(cmd, sizeof cmd,
             "('%s' render '%s' -o '%s' --gi particle --particles 1000000 --size 64x48 --threads 2 & pid=$!; sleep 1.5; "
             "kill -INT $pid; wait $pid; echo rc=$?)",
             PARTRAY_BIN, scene, out);
    tu_run_capture(cmd);
    printf("%s", tu_out);
    assert_non_null(strstr(tu_out, "rc=130"));
    assert_non_null(strstr(tu_out, "interrupted before any pixel was rendered: no partial image"));
    assert_false(tu_exists(partial));
    assert_false(tu_exists(out));
}

/* Red (c 0) or blue (c 2) of pixel (x, y) of a PFM (rows stored bottom-up). */
static double pfm_px(const char *path, int x, int y, int c)
{
    framebuffer *fb = NULL;
    assert_int_equal(img_read(path, 0, &fb, NULL), PT_OK);
    double v = fb_px(fb, x, y)[c];
    fb_free(fb);
    return v;
}

/* Lambert at a plane point (x, 0, z) under the light at (-3, 9, 0):
 * ambient 0.1 + diffuse 0.5 * cos (POV-Ray: no distance fall-off). */
static double plane_lit(double x, double z)
{
    double dx = -3 - x, dy = 9, dz = -z;
    return 0.1 + 0.5 * dy / sqrt(dx * dx + dy * dy + dz * dz);
}

/* +Q0..+Q11 as POV-Ray 3.7's quality flags (povrayold.h QUALITY_n): a
 * white plane (ambient 0.1, diffuse 0.5, reflection 0.5) seen from above
 * (orthographic, 8 x 6 units on 64 x 48 pixels), a red sphere shadowing it
 * from an area light, a fully transparent sphere, a blue background. Pixel
 * centres: O (16, 24) at (-1.9375, -0.0625) lit; S (44, 24) at (1.5625,
 * -0.0625) in the red sphere's shadow; T (16, 8) on the transparent sphere
 * over (-1.9375, 1.9375). Expected: 0-1 the pigment's colour, unlit; 2-3
 * Lambert without shadows; 4 shadows, the area light as a point light at its
 * centre (the image equals the point light's); 5 the area light's soft
 * shadow; 6 the transparent sphere shows the plane; 8 the plane reflects the
 * background (blue + 0.5); 10 and 11 are 9 (POV-Ray clips), 12 is refused. */
static void test_quality_levels(void **st)
{
    (void)st;
    char scene[512], cmd[4096], out[600];
    snprintf(scene, sizeof scene, "%s/q.pov", tmpdir);
    tu_write_file(scene, "global_settings { assumed_gamma 1 }\n"
                         "camera { orthographic location <0, 10, 0> direction -y right 8*x up 6*z }\n"
                         "background { rgb <0, 0, 1> }\n"
                         "#ifndef (Point) #declare Point = 0; #end\n"
                         "light_source { <-3, 9, 0> rgb 1 #if (!Point) area_light 2*x, 2*z, 5, 5 #end }\n"
                         "plane { y, 0 pigment { rgb 1 } finish { ambient 0.1 diffuse 0.5 reflection 0.5 } }\n"
                         "sphere { <0, 3, 0>, 0.5 pigment { rgb <1, 0, 0> } }\n"
                         "sphere { <-2, 2, 2>, 0.5 pigment { rgbt <1, 1, 1, 1> } }\n");
    const double o_lit = plane_lit(-1.9375, -0.0625), s_lit = plane_lit(1.5625, -0.0625), t_lit = plane_lit(-1.9375, 1.9375);
    for (int q = 0; q <= 11; q++) {
        snprintf(out, sizeof out, "%s/q%d.pfm", tmpdir, q);
        snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 64x48 --threads 2 +Q%d -o '%s'", PARTRAY_BIN, scene, q, out);
        assert_int_equal(tu_run_capture(cmd), 0);
        if (q <= 5) assert_non_null(strstr(tu_out, "quick colours (levels 0-5) are not modelled"));
        double O = pfm_px(out, 16, 24, 0), Ob = pfm_px(out, 16, 24, 2), S = pfm_px(out, 44, 24, 0), T = pfm_px(out, 16, 8, 0);
        printf("+Q%d: O %.5f (blue %.5f), S %.5f, T %.5f\n", q, O, Ob, S, T);
        double eO = q <= 1 ? 1.0 : o_lit;
        double eOb = q <= 1 ? 1.0 : (q >= 8 ? o_lit + 0.5 : o_lit);
        double eT = q <= 1 ? 1.0 : (q >= 6 ? t_lit : 0.0);
        assert_true(fabs(O - eO) < 1e-4);
        assert_true(fabs(Ob - eOb) < 1e-4);
        assert_true(fabs(T - eT) < 1e-4);
        if (q <= 1) assert_true(fabs(S - 1.0) < 1e-4);
        else if (q <= 3) assert_true(fabs(S - s_lit) < 1e-4);
        else if (q == 4) assert_true(fabs(S - 0.1) < 1e-4);
        else assert_true(S > 0.1 + 1e-3 && S < s_lit); /* part of the area light reaches S */
    }
    /* +Q4: the area light is its centre point */
    snprintf(out, sizeof out, "%s/p4.pfm", tmpdir);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 64x48 --threads 2 +Q4 -D Point=1 -q -o '%s' && cmp '%s' '%s/q4.pfm'",
             PARTRAY_BIN, scene, out, out, tmpdir);
    assert_int_equal(tu_run_capture(cmd), 0);
    snprintf(cmd, sizeof cmd, "cmp '%s/q9.pfm' '%s/q11.pfm'", tmpdir, tmpdir);
    assert_int_equal(tu_run_capture(cmd), 0);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 64x48 +Q12", PARTRAY_BIN, scene);
    assert_int_equal(tu_run_capture(cmd), 2);
    assert_non_null(strstr(tu_out, "+Q wants a quality level 0 to 11"));
}

/* The fraction of pixel (x, y)'s 3 x 3 stratified sample points inside the
 * disc of radius 2 at the centre of an 8 x 6 unit orthographic view on
 * 64 x 48 pixels. */
static double disc_coverage(int x, int y)
{
    int in = 0;
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++) {
            double wx = -4 + (x + (i + 0.5) / 3) / 8, wy = 3 - (y + (j + 0.5) / 3) / 8;
            in += wx * wx + wy * wy < 4;
        }
    return in / 9.0;
}

/* +UA (Output_Alpha): PNG (RGBA) and EXR (A) carry each pixel's coverage:
 * with +A the fraction of 3 x 3 stratified rays meeting the sphere, where a
 * ray leaving the scene is clear without background{} (POV-Ray 3.7's
 * default <0,0,0,0,1>) and opaque with an opaque background{}; before
 * #version 3.7 the background is clear under +UA. Compared with the disc's
 * analytic coverage at every pixel (PNG 8-bit: 0.5/255; EXR half: 1e-3). */
static void test_alpha_output(void **st)
{
    (void)st;
    char scene[512], cmd[4096], png[600], exr[600];
    snprintf(scene, sizeof scene, "%s/ua.pov", tmpdir);
    snprintf(png, sizeof png, "%s/ua.png", tmpdir);
    snprintf(exr, sizeof exr, "%s/ua.exr", tmpdir);
    const char *body = "global_settings { assumed_gamma 1 }\n"
                       "camera { orthographic location <0, 0, -10> look_at 0 right 8*x up 6*y }\n"
                       "light_source { <0, 0, -10> rgb 1 }\n"
                       "#ifdef (Bg) background { rgb 0.5 } #end\n"
                       "sphere { 0, 2 pigment { rgb <1, 0.5, 0.25> } }\n";
    char text[1024];
    snprintf(text, sizeof text, "#version 3.7;\n%s", body);
    tu_write_file(scene, text);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 64x48 +A +UA -q -o '%s' -o '%s'", PARTRAY_BIN, scene, png, exr);
    assert_int_equal(tu_run_capture(cmd), 0);
    const char *paths[] = {png, exr};
    const double tol[] = {0.5 / 255 + 1e-6, 1e-3};
    int partial = 0;
    for (int k = 0; k < 2; k++) {
        framebuffer *fb = NULL;
        assert_int_equal(img_read(paths[k], 0, &fb, NULL), PT_OK);
        assert_non_null(fb->alpha);
        for (int y = 0; y < 48; y++)
            for (int x = 0; x < 64; x++) {
                double want = disc_coverage(x, y), got = fb->alpha[y * 64 + x];
                if (fabs(got - want) > tol[k]) fail_msg("%s pixel %d,%d alpha %.4f, want %.4f", paths[k], x, y, got, want);
                partial += k == 0 && want > 0 && want < 1;
            }
        fb_free(fb);
    }
    assert_true(partial > 20); /* the edge has fractional coverage */
    /* an opaque background{}: opaque everywhere; before 3.7: clear again */
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 64x48 +UA -D Bg=1 -q -o '%s'", PARTRAY_BIN, scene, png);
    assert_int_equal(tu_run_capture(cmd), 0);
    framebuffer *fb = NULL;
    assert_int_equal(img_read(png, 0, &fb, NULL), PT_OK);
    assert_non_null(fb->alpha);
    assert_true(fb->alpha[0] == 1.0f && fb->alpha[24 * 64 + 32] == 1.0f);
    fb_free(fb);
    snprintf(text, sizeof text, "#version 3.6;\n%s", body);
    tu_write_file(scene, text);
    assert_int_equal(tu_run_capture(cmd), 0);
    assert_int_equal(img_read(png, 0, &fb, NULL), PT_OK);
    assert_true(fb->alpha[0] == 0.0f && fb->alpha[24 * 64 + 32] == 1.0f);
    fb_free(fb);
    /* without +UA: no alpha channel */
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 64x48 -q -o '%s'", PARTRAY_BIN, scene, png);
    assert_int_equal(tu_run_capture(cmd), 0);
    assert_int_equal(img_read(png, 0, &fb, NULL), PT_OK);
    assert_null(fb->alpha);
    fb_free(fb);
}

/* PNG bit depth: IHDR byte 24 of the file. */
static int png_bit_depth(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return -1;
    unsigned char b[32];
    size_t n = fread(b, 1, sizeof b, f);
    fclose(f);
    return n >= 25 ? b[24] : -1;
}

/* +O and +F as POV-Ray 3.7 names outputs (imageprocessing.cpp,
 * GetOutputFilename): +O without an extension takes the +F type's (PNG
 * unless +FE), +O ending in '/' writes SCENE.EXT there; +FN16 is a 16-bit
 * PNG, +FN8 an 8-bit one; +FC and the other types partray does not write
 * are refused by name. */
static void test_output_names_and_types(void **st)
{
    (void)st;
    char scene[512], dir[512], cmd[4096], path[700];
    snprintf(scene, sizeof scene, "%s/names.pov", tmpdir);
    snprintf(dir, sizeof dir, "%s/names_out", tmpdir);
    tu_write_file(scene, "camera { location -5*z look_at 0 } light_source { -5*z, 1 } sphere { 0, 1 pigment { rgb 1 } }\n");
    snprintf(cmd, sizeof cmd, "mkdir -p '%s' && '%s' render '%s' --size 16x12 -q +O%s/pov2", dir, PARTRAY_BIN, scene, dir);
    assert_int_equal(tu_run_capture(cmd), 0);
    snprintf(path, sizeof path, "%s/pov2.png", dir);
    assert_int_equal(png_bit_depth(path), 8);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 16x12 -q +FE +O%s/pov2", PARTRAY_BIN, scene, dir);
    assert_int_equal(tu_run_capture(cmd), 0);
    snprintf(path, sizeof path, "%s/pov2.exr", dir);
    framebuffer *fb = NULL;
    assert_int_equal(img_read(path, 0, &fb, NULL), PT_OK);
    assert_int_equal(fb->width, 16);
    fb_free(fb);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 16x12 -q +FN16 +O%s/pov3", PARTRAY_BIN, scene, dir);
    assert_int_equal(tu_run_capture(cmd), 0);
    snprintf(path, sizeof path, "%s/pov3.png", dir);
    assert_int_equal(png_bit_depth(path), 16);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 16x12 -q +FN8 +O%s/", PARTRAY_BIN, scene, dir);
    assert_int_equal(tu_run_capture(cmd), 0);
    snprintf(path, sizeof path, "%s/names.png", dir);
    assert_int_equal(png_bit_depth(path), 8);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 16x12 +FC +O%s/pov4", PARTRAY_BIN, scene, dir);
    assert_int_equal(tu_run_capture(cmd), 2);
    assert_non_null(strstr(tu_out, "+FC: Targa output is not written"));
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/partray-cli-XXXXXX");
    if (!mkdtemp(tmpdir)) return 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_missing_file),
        cmocka_unit_test(test_unknown_keyword),
        cmocka_unit_test(test_unterminated_block),
        cmocka_unit_test(test_include_chain),
        cmocka_unit_test(test_usage),
        cmocka_unit_test(test_help),
        cmocka_unit_test(test_exit_codes),
        cmocka_unit_test(test_empty_scene_and_defaults),
        cmocka_unit_test(test_working_gamma_all_modes),
        cmocka_unit_test(test_exact_gather_furnace),
        cmocka_unit_test(test_animation),
        cmocka_unit_test(test_mesh_camera),
        cmocka_unit_test(test_render_outputs_and_stats),
        cmocka_unit_test(test_sigint_partial),
        cmocka_unit_test(test_progress_terminal),
        cmocka_unit_test(test_progress_plain_and_quiet),
        cmocka_unit_test(test_sigint_during_gi),
        cmocka_unit_test(test_quality_levels),
        cmocka_unit_test(test_radiosity_normal),
        cmocka_unit_test(test_alpha_output),
        cmocka_unit_test(test_output_names_and_types),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (rc == 0) tu_run_capture(cmd);
    return rc;
}
