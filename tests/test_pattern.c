/* test_pattern.c - pattern values against POV-Ray 3.7 itself.
 *
 * Every pattern is shown through a grey colour_map on its own tile (a
 * polygon) seen by an orthographic camera with ambient 1, diffuse 0, so each
 * pixel of POV-Ray's 16-bit PNG is the pattern's value at a known point; one
 * POV-Ray run renders all tiles. partray parses the same scene and evaluates
 * each box's pigment at each pixel's point directly (parser + IR +
 * shade_pattern, no renderer). A pixel agrees when the values differ by less
 * than 2e-3; at most 1% of a tile's pixels may disagree (points on a
 * discontinuity can fall either way; POV-Ray keeps colours in single
 * precision). Measured: every tile agrees on every pixel. Also closed-form
 * checks of the noise (ranges, generator 1 vs 2, determinism) and of the
 * blend-map search. */
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
#include "func_internal.h"
#include "img_io.h"
#include "sdl.h"
#include "shade.h"
#include "shade_noise.h"
#include "shade_pattern.h"
#include "shade_pavement.h"
#include "shade_tiling.h"
#include "test_world.h"

#define TILE 24        /* pixels per pattern tile */
#define COLS 8
#define TSPAN 3.0      /* world units per tile */
#define MAX_BAD 0.01   /* fraction of a tile's pixels allowed to disagree */

static char tmpdir[256];

static double clamp01(double v) { return v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v); }

static int run(const char *cmd)
{
    int rc = system(cmd);
    return rc == -1 ? -1 : WEXITSTATUS(rc);
}

#define GREY "color_map { [0 rgb 0] [1 rgb 1] }"

typedef struct {
    const char *name, *pigment;
} pattern_case;

static const pattern_case cases[] = {
    {"checker", "checker rgb 0, rgb 1 scale 0.7"},
    {"hexagon", "hexagon rgb 0, rgb 0.5, rgb 1 rotate x*90 scale 0.6"},
    {"brick", "brick rgb 0, rgb 1 brick_size <1.2, 0.5, 1> mortar 0.1"},
    {"gradient", "gradient <1, 0.5, 0> " GREY},
    {"radial", "radial frequency 3 rotate x*90 " GREY},
    {"onion", "onion scale 0.8 " GREY},
    {"leopard", "leopard scale 0.2 " GREY},
    {"bozo", "bozo scale 0.5 " GREY},
    {"bozo_gen1", "bozo noise_generator 1 scale 0.5 " GREY},
    {"bozo_gen3", "bozo noise_generator 3 scale 0.5 " GREY},
    {"spotted", "spotted turbulence 0.5 scale 0.7 " GREY},
    {"granite", "granite scale 2 " GREY},
    {"marble", "marble turbulence 0.8 scale 1.5 " GREY},
    {"wood", "wood turbulence 0.05 scale 0.3 rotate x*30 " GREY},
    {"agate", "agate agate_turb 0.7 " GREY},
    {"ripples", "ripples frequency 2 phase 0.3 " GREY},
    {"waves", "waves frequency 3 " GREY},
    {"wrinkles", "wrinkles scale 0.8 " GREY},
    {"bumps", "bumps scale 0.3 " GREY},
    {"dents", "dents scale 0.4 " GREY},
    {"crackle", "crackle scale 0.6 " GREY},
    {"crackle_solid", "crackle solid scale 0.6 " GREY},
    {"crackle_form", "crackle form <1, -0.5, 0.3> metric 1.5 offset 0.1 scale 0.6 " GREY},
    {"cells", "cells scale 0.5 " GREY},
    {"spiral1", "spiral1 3 scale 0.5 " GREY},
    {"spiral2", "spiral2 5 scale 0.7 " GREY},
    {"planar", "planar scale 2 " GREY},
    {"spherical", "spherical scale 2.5 " GREY},
    {"boxed", "boxed scale 2.5 " GREY},
    {"cylindrical", "cylindrical rotate x*90 scale 2 " GREY},
    {"quilted", "quilted control0 0.2 control1 0.9 scale 0.8 " GREY},
    {"square", "square rgb 0, rgb 0.3, rgb 0.6, rgb 1 rotate x*90 scale 0.4"},
    {"triangular", "triangular rgb 0, rgb 0.2, rgb 0.4, rgb 0.6, rgb 0.8, rgb 1 rotate x*90 scale 0.5"},
    {"sine_wave", "gradient x sine_wave frequency 0.7 phase 0.2 " GREY},
    {"scallop_wave", "onion scallop_wave scale 1.3 " GREY},
    {"poly_wave", "bozo poly_wave 2.5 scale 0.6 " GREY},
    {"cubic_wave", "granite cubic_wave " GREY},
    {"turb_warp", "checker rgb 0, rgb 1 scale 0.5 warp { turbulence <0.4, 0.2, 0> octaves 3 lambda 2.5 omega 0.6 } "
                  "rotate z*20 warp { repeat x*1.5 flip y offset <0, 0.3, 0> }"},
    {"spherical_warp", "gradient y " GREY " warp { spherical orientation y dist_exp 0.5 } scale 0.4"},
    {"cylindrical_warp", "checker rgb 0, rgb 1 warp { cylindrical } scale 0.25 rotate x*30"},
    {"black_hole", "checker rgb 0, rgb 1 warp { black_hole <0.2, 0.1, 0>, 2 strength 1.5 falloff 1.5 } scale 0.4"},
    {"colour_map", "bozo color_map { [0 rgb <1,0,0>] [0.3 rgb <0,1,0>] [0.3 rgb <0,0,1>] [0.8 rgb <1,1,0>] } scale 0.5"},
    {"pigment_map", "gradient x pigment_map { [0 checker rgb 0, rgb 1 scale 0.2] [1 granite " GREY "] } scale 3"},
    {"average", "average pigment_map { [1 rgb <1,0,0>] [2 bozo " GREY " scale 0.4] }"},
    {"pigment_pattern", "pigment_pattern { checker rgb 0, rgb 1 scale 0.5 } " GREY " turbulence 0.3"},
    {"old_colour_map", "granite color_map { [0.0 0.4 color rgb 0 color rgb 0.5] [0.4 1.0 color rgb 0.5 color rgb 1] }"},
    {"function", "function { 0.3 * x * y + 0.5 * sin(2 * x) } " GREY},
    {"ridged_mf", "function { f_ridged_mf(x, y, z, 0.07, 2.2, 7, 0.6, 0.9, 1) * 0.5 } scale 0.6 " GREY},
    {"mandel", "mandel 40 scale 0.8 translate -x*0.5 " GREY},
    {"mandel5", "mandel 30 exponent 5 exterior 6, 0.3 interior 1, 2 scale 0.7 " GREY},
    {"julia3", "julia <0.35, 0.2>, 30 exponent 3 interior 2, 1 scale 0.6 " GREY},
    {"magnet1m", "magnet 1 mandel 30 exterior 7, 5 scale 1.5 translate x*1.2 " GREY},
    {"magnet2j", "magnet 2 julia <1.1, 0.4>, 25 exterior 4, 0.1 scale 1.2 " GREY},
    {"tiling1", "tiling 1 rotate x*90 scale 0.7 " GREY},
    {"tiling2", "tiling 2 rotate x*90 scale 0.5 " GREY},
    {"tiling3", "tiling 3 rotate x*90 scale 0.6 " GREY},
    {"tiling4", "tiling 4 rotate x*90 scale 0.6 " GREY},
    {"tiling5", "tiling 5 rotate x*90 scale 0.5 " GREY},
    {"tiling6", "tiling 6 rotate x*90 scale 0.4 " GREY},
    {"tiling7", "tiling 7 rotate x*90 rotate y*20 scale 0.5 " GREY},
    {"tiling8", "tiling 8 rotate x*90 scale 0.5 " GREY},
    {"tiling9", "tiling 9 rotate x*90 scale 0.4 " GREY},
    {"tiling10", "tiling 10 rotate x*90 rotate y*15 scale 0.6 " GREY},
    {"tiling11", "tiling 11 rotate x*90 scale 0.4 " GREY},
    {"tiling12", "tiling 12 rotate x*90 scale 0.3 " GREY},
    {"tiling13", "tiling 13 rotate x*90 scale 0.4 " GREY},
    {"tiling14", "tiling 14 rotate x*90 scale 0.4 " GREY},
    {"tiling15", "tiling 15 rotate x*90 scale 0.35 " GREY},
    {"tiling16", "tiling 16 rotate x*90 scale 0.3 " GREY},
    {"tiling17", "tiling 17 rotate x*90 scale 0.3 " GREY},
    {"tiling18", "tiling 18 rotate x*90 scale 0.4 " GREY},
    {"tiling19", "tiling 19 rotate x*90 scale 0.3 " GREY},
    {"tiling20", "tiling 20 rotate x*90 scale 0.3 " GREY},
    {"tiling21", "tiling 21 rotate x*90 rotate y*15 scale 0.5 " GREY},
    {"tiling22", "tiling 22 rotate x*90 scale 0.3 " GREY},
    {"tiling23", "tiling 23 rotate x*90 scale 0.25 " GREY},
    {"tiling24", "tiling 24 rotate x*90 scale 0.25 " GREY},
    {"tiling25", "tiling 25 rotate x*90 scale 0.5 " GREY},
    {"tiling26", "tiling 26 rotate x*90 rotate y*15 scale 0.6 " GREY},
    {"tiling27", "tiling 27 rotate x*90 scale 0.6 " GREY},
    {"df3_nearest", "density_file df3 \"spiral.df3\" warp { repeat x } warp { repeat y } translate -z*0.4 scale 3 " GREY},
    {"df3_linear", "density_file df3 \"spiral.df3\" interpolate 1 warp { repeat x } warp { repeat y } translate -z*0.5 scale 3 " GREY},
    {"df3_cubic", "density_file df3 \"spiral.df3\" interpolate 2 warp { repeat x } warp { repeat y } translate -z*0.6 scale 3 " GREY},
};
#define NCASES ((int)(sizeof cases / sizeof cases[0]))

/* One POV-Ray render shows every case on its own tile (a box face at
 * z = 0); partray parses the same scene and evaluates each box's pigment at
 * every pixel's point. With a black background POV-Ray's pixel is the
 * pigment's rgb * (1 - filter - transmit) (ambient 1, 3.7's attenuation). */
static int run_tiles(const pattern_case *cs, int ncases, const char *tag)
{
    int rows = (ncases + COLS - 1) / COLS;
    int w = COLS * TILE, h = rows * TILE;
    double ww = COLS * TSPAN, wh = rows * TSPAN;
    size_t cap = 65536, len = 0;
    char *src = malloc(cap);
    assert_non_null(src);
    len += (size_t)snprintf(src + len, cap - len,
                            "#version 3.7;\n#include \"functions.inc\"\nglobal_settings { assumed_gamma 1.0 }\n"
                            "camera { orthographic location <%g, %g, -10> direction z right x*%g up y*%g }\n",
                            ww / 2, -wh / 2, ww, wh);
    for (int i = 0; i < ncases; i++) {
        double x0 = (i % COLS) * TSPAN, y0 = -(i / COLS + 1) * TSPAN;
        /* a polygon, so a transparent pigment shows the black background */
        len += (size_t)snprintf(src + len, cap - len,
                                "polygon { 4, <%g, %g, 0>, <%g, %g, 0>, <%g, %g, 0>, <%g, %g, 0> pigment { %s } finish { ambient 1 diffuse 0 } }\n",
                                x0, y0, x0 + TSPAN, y0, x0 + TSPAN, y0 + TSPAN, x0, y0 + TSPAN, cs[i].pigment);
        assert_true(len < cap);
    }
    char path[512], png[512], cmd[2048];
    snprintf(path, sizeof path, "%s/%s.pov", tmpdir, tag);
    snprintf(png, sizeof png, "%s/%s.png", tmpdir, tag);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(src, f);
    fclose(f);
    snprintf(cmd, sizeof cmd, "cd '%s' && povray +I%s.pov +O%s.png +W%d +H%d -A -D -V -GA +FN16 >%s.log 2>&1", tmpdir, tag, tag,
             w, h, tag);
    if (run(cmd) != 0) fail_msg("povray failed (see %s/%s.log)", tmpdir, tag);
    framebuffer *fb = NULL;
    assert_int_equal(img_read(png, 0, &fb, NULL), PT_OK);
    assert_int_equal(fb->width, w);

    sdl_options so;
    sdl_default_options(&so);
    scene *sc = NULL;
    diag *d = diag_new();
    char cwd[1024];
    assert_non_null(getcwd(cwd, sizeof cwd));
    assert_int_equal(chdir(tmpdir), 0); /* image files are found beside the scene */
    pt_status st = sdl_parse_string(tag, src, &so, &sc, d);
    assert_int_equal(chdir(cwd), 0);
    assert_int_equal(st, PT_OK);
    assert_int_equal(sc->nobjects, ncases);
    shade_pattern_ctx pc = shade_pattern_ctx_plain(sc);
    int failed = 0;
    for (int i = 0; i < ncases; i++) {
        const scene_texture *tex = sc->objects[i]->texture;
        assert_non_null(tex);
        int tx = (i % COLS) * TILE, ty = (i / COLS) * TILE, bad = 0, n = 0;
        double worst = 0.0;
        for (int y = ty + 1; y < ty + TILE - 1; y++) {
            for (int x = tx + 1; x < tx + TILE - 1; x++) {
                vec3 p = v3((x + 0.5) / w * ww, -(y + 0.5) / h * wh, 0.0);
                colour5 c;
                shade_pigment_eval(&tex->pigment, xform_inv_point(&tex->transform, p), &pc, &c);
                double k = 1.0 - c.f - c.t;
                const float *px = fb_px(fb, x, y);
                /* the PNG holds 0..1 (bicubic images overshoot) */
                double dmax = fmax(fabs(clamp01(c.r * k) - px[0]), fmax(fabs(clamp01(c.g * k) - px[1]), fabs(clamp01(c.b * k) - px[2])));
                if (dmax > 2e-3) bad++;
                if (dmax > worst) worst = dmax;
                n++;
            }
        }
        double frac = (double)bad / n;
        printf("%s %-16s %6.2f%% of pixels differ (worst %.4f)\n", tag, cs[i].name, 100.0 * frac, worst);
        if (frac > MAX_BAD) failed++;
    }
    scene_free(sc);
    diag_free(d);
    fb_free(fb);
    free(src);
    return failed;
}

/* f_ridged_mf's weights from its first call (func_internal.h): one declared
 * f_ridged_mf called by two tiles with different H and lacunarity, the top
 * tile first in POV-Ray's order (one thread: its 32-pixel blocks row by row).
 * partray finds that call (shade_ridged_mf_first) and evaluates both tiles
 * with its weights; each tile agrees with POV-Ray as run_tiles asks
 * (measured: every pixel). With every call's own weights over a fifth of the
 * second tile's pixels disagree (measured 32%). */
static void test_ridged_mf_first_call(void **st)
{
    (void)st;
    const char *fn[2] = {"R(x, y, z, 0.5, 2.0, 6, 0.6, 0.9, 1) * 0.5", "R(x, y, z, 0.07, 2.2, 7, 0.6, 0.9, 1) * 0.5"};
    int w = TILE, h = 2 * TILE;
    double span = TSPAN;
    char src[2048];
    int len = snprintf(src, sizeof src,
                       "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
                       "#declare R = function { internal(59) }\n"
                       "camera { orthographic location <%g, %g, -10> direction z right x*%g up y*%g }\n",
                       span / 2, -span, span, 2 * span);
    for (int i = 0; i < 2; i++)
        len += snprintf(src + len, sizeof src - (size_t)len,
                        "polygon { 4, <0, %g, 0>, <%g, %g, 0>, <%g, %g, 0>, <0, %g, 0> pigment { function { %s } " GREY
                        " } finish { ambient 1 diffuse 0 } }\n",
                        -(i + 1) * span, span, -(i + 1) * span, span, -i * span, -i * span, fn[i]);
    assert_true(len < (int)sizeof src);
    char path[512], cmd[2048];
    snprintf(path, sizeof path, "%s/ridged.pov", tmpdir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(src, f);
    fclose(f);
    snprintf(cmd, sizeof cmd, "cd '%s' && povray +Iridged.pov +Oridged.png +W%d +H%d -A -D -V -GA +FN16 +WT1 >ridged.log 2>&1",
             tmpdir, w, h);
    if (run(cmd) != 0) fail_msg("povray failed (see %s/ridged.log)", tmpdir);
    snprintf(path, sizeof path, "%s/ridged.png", tmpdir);
    framebuffer *fb = NULL;
    assert_int_equal(img_read(path, 0, &fb, NULL), PT_OK);

    tu_world wd = tu_world_build("ridged.pov", src);
    assert_int_equal(wd.s->ridged_mf_callers, 2);
    double fh = 0.0, flac = 0.0;
    for (int pass = 0; pass < 2; pass++) {
        /* pass 0: the render's rule; pass 1: each call its own weights */
        if (pass == 0) {
            shade_ridged_mf_first(wd.s, wd.a, w, h);
            assert_true(func_ridged_mf_fixed(&fh, &flac));
            assert_true(fh == 0.5 && flac == 2.0); /* the top tile's, exactly */
        } else {
            func_ridged_mf_reset();
            assert_false(func_ridged_mf_fixed(NULL, NULL));
        }
        shade_pattern_ctx pc = shade_pattern_ctx_plain(wd.s);
        for (int i = 0; i < 2; i++) {
            const scene_texture *tex = wd.s->objects[i]->texture;
            int bad = 0, n = 0;
            for (int y = i * TILE + 1; y < (i + 1) * TILE - 1; y++)
                for (int x = 1; x < TILE - 1; x++) {
                    vec3 p = v3((x + 0.5) / w * span, -(y + 0.5) / h * 2 * span, 0.0);
                    colour5 c;
                    shade_pigment_eval(&tex->pigment, xform_inv_point(&tex->transform, p), &pc, &c);
                    if (fabs(clamp01(c.r) - fb_px(fb, x, y)[0]) > 2e-3) bad++;
                    n++;
                }
            printf("ridged_mf tile %d, %s: %6.2f%% of pixels differ\n", i, pass ? "own weights" : "first call's", 100.0 * bad / n);
            if (pass == 0 || i == 0) assert_true(bad <= MAX_BAD * n);
            else assert_true(bad > n / 5);
        }
    }
    tu_world_free(&wd);
    fb_free(fb);
}

static void test_patterns(void **st)
{
    (void)st;
    assert_int_equal(run_tiles(cases, NCASES, "patterns"), 0);
}

/* pavement: every paving POV-Ray 3.7 defines (number_of_sides 3, 4, 6;
 * number_of_tiles 1-6; each pattern number), the corner treatments
 * cycling through interior 0-2, exterior 0-2 and form 0-3 from case to
 * case so each paving is seen with a different combination. */
static void test_pavement(void **st)
{
    (void)st;
    static const struct { int sides, tiles, count; } pavings[] = {
        {3, 1, 1}, {3, 2, 1}, {3, 3, 1}, {3, 4, 3}, {3, 5, 4}, {3, 6, 12},
        {4, 1, 1}, {4, 2, 1}, {4, 3, 2}, {4, 4, 5}, {4, 5, 12}, {4, 6, 35},
        {6, 1, 1}, {6, 2, 1}, {6, 3, 3}, {6, 4, 7}, {6, 5, 22},
    };
    static char names[128][32], pigments[128][192];
    static pattern_case pc[128];
    int n = 0;
    for (size_t k = 0; k < sizeof pavings / sizeof pavings[0]; k++) {
        for (int num = 1; num <= pavings[k].count; num++, n++) {
            int s = pavings[k].sides, t = pavings[k].tiles;
            /* cells about a tenth of the tile's width: a whole period shows */
            double scale = s == 4 ? 0.3 : 0.35;
            snprintf(names[n], sizeof names[n], "pave_s%d_t%d_p%d", s, t, num);
            snprintf(pigments[n], sizeof pigments[n],
                     "pavement number_of_sides %d number_of_tiles %d pattern %d interior %d exterior %d form %d "
                     "rotate x*90 rotate z*%d scale %g " GREY,
                     s, t, num, n % 3, (n / 3) % 3, (n / 9) % 4, (n % 4) * 10, scale);
            pc[n].name = names[n];
            pc[n].pigment = pigments[n];
        }
    }
    assert_int_equal(n, 112);
    assert_int_equal(run_tiles(pc, n, "pavement"), 0);
}

/* A pattern number the paving lacks is a located error (POV-Ray reads past
 * its tables); numbers it ignores (one tile, two triangles) are accepted;
 * points far out or NaN give 0, never NaN. */
static void test_pavement_errors(void **st)
{
    (void)st;
    static const struct { const char *body; int ok; } cs[] = {
        {"pavement number_of_sides 4 number_of_tiles 5 pattern 13", 0},
        {"pavement number_of_sides 4 number_of_tiles 5 pattern 12", 1},
        {"pavement pattern 4 number_of_tiles 6", 1},
        {"pavement pattern 13 number_of_tiles 6", 0},
        {"pavement number_of_sides 6 number_of_tiles 5 pattern 23", 0},
        {"pavement number_of_sides 6 number_of_tiles 2 pattern 2", 0},
        {"pavement number_of_tiles 2 pattern 9", 1},
        {"pavement number_of_sides 4 pattern 0", 1},
    };
    for (size_t i = 0; i < sizeof cs / sizeof cs[0]; i++) {
        char src[256];
        snprintf(src, sizeof src, "plane { y, 0\n  pigment { %s } }", cs[i].body);
        sdl_options so;
        sdl_default_options(&so);
        scene *sc = NULL;
        diag *d = diag_new();
        pt_status stt = sdl_parse_string("pave.pov", src, &so, &sc, d);
        if (cs[i].ok) {
            assert_int_equal(stt, PT_OK);
            scene_free(sc);
        } else {
            assert_int_equal(stt, PT_ERR_SYNTAX);
            char *msg = NULL;
            for (int k = 0; k < diag_count(d) && !msg; k++)
                if (diag_get(d, k)->severity == DIAG_ERROR) msg = diag_format(diag_get(d, k));
            assert_non_null(msg);
            printf("%s\n", msg);
            assert_true(strncmp(msg, "pave.pov:2:", 11) == 0);
            assert_non_null(strstr(msg, "error: pavement with number_of_sides"));
            free(msg);
        }
        diag_free(d);
    }
    shade_pavement_params pv = {4, 6, 35, 2, 2, 2};
    assert_true(shade_pavement_value(&pv, v3(NAN, 0, 1)) == 0.0);
    assert_true(shade_pavement_value(&pv, v3(1e300, 0, -1e300)) == 0.0);
    for (int t = 1; t <= 27; t++) {
        assert_true(shade_tiling_value(t, v3(INFINITY, 0, 1)) == 0.0);
        double v = shade_tiling_value(t, v3(123456.7, 0, -98765.4));
        assert_true(v >= 0.0 && v <= 1.0 + 1e-6); /* 8, 9, ...: POV-Ray nudges edges past 1 by 1e-7 */
    }
}

/* ------------------------------------------------------------ image_map options */

/* A minimal PNG writer (stored deflate blocks) for the test images: 8-bit
 * RGB (colour type 2) or palette (type 3, with a tRNS chunk when given). */
static unsigned long crc_table[256];
static unsigned long crc32_of(const unsigned char *b, size_t n, unsigned long c)
{
    if (!crc_table[1])
        for (unsigned long i = 0; i < 256; i++) {
            unsigned long v = i;
            for (int k = 0; k < 8; k++) v = (v & 1) ? 0xEDB88320UL ^ (v >> 1) : v >> 1;
            crc_table[i] = v;
        }
    c ^= 0xFFFFFFFFUL;
    for (size_t i = 0; i < n; i++) c = crc_table[(c ^ b[i]) & 0xFF] ^ (c >> 8);
    return c ^ 0xFFFFFFFFUL;
}

static void put32(unsigned char *b, unsigned long v)
{
    b[0] = (unsigned char)(v >> 24); b[1] = (unsigned char)(v >> 16); b[2] = (unsigned char)(v >> 8); b[3] = (unsigned char)v;
}

static void chunk(FILE *f, const char *type, const unsigned char *data, size_t n)
{
    unsigned char h[8];
    put32(h, (unsigned long)n);
    memcpy(h + 4, type, 4);
    fwrite(h, 1, 8, f);
    if (n) fwrite(data, 1, n, f);
    unsigned long c = crc32_of((const unsigned char *)type, 4, 0);
    c = crc32_of(data, n, c);
    put32(h, c);
    fwrite(h, 1, 4, f);
}

static void write_png(const char *name, int w, int h, int bpp, const unsigned char *pix, const unsigned char *plte, int nplte,
                      const unsigned char *trns, int ntrns)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fwrite("\x89PNG\r\n\x1a\n", 1, 8, f);
    unsigned char ihdr[13];
    put32(ihdr, (unsigned long)w);
    put32(ihdr + 4, (unsigned long)h);
    ihdr[8] = 8;
    ihdr[9] = bpp == 1 ? 3 : 2;
    ihdr[10] = ihdr[11] = ihdr[12] = 0;
    chunk(f, "IHDR", ihdr, 13);
    if (plte) chunk(f, "PLTE", plte, (size_t)nplte * 3);
    if (trns) chunk(f, "tRNS", trns, (size_t)ntrns);
    size_t row = (size_t)w * bpp + 1, raw = row * h;
    unsigned char *z = malloc(raw + raw / 65535 * 5 + 16);
    assert_non_null(z);
    size_t n = 0;
    z[n++] = 0x78;
    z[n++] = 0x01;
    unsigned long a = 1, b = 0;
    unsigned char *flat = malloc(raw);
    assert_non_null(flat);
    for (int y = 0; y < h; y++) {
        flat[y * row] = 0;
        memcpy(flat + y * row + 1, pix + (size_t)y * w * bpp, (size_t)w * bpp);
    }
    for (size_t i = 0; i < raw; i++) {
        a = (a + flat[i]) % 65521;
        b = (b + a) % 65521;
    }
    for (size_t off = 0; off < raw;) {
        size_t len = raw - off > 65535 ? 65535 : raw - off;
        z[n++] = off + len == raw ? 1 : 0;
        z[n++] = (unsigned char)(len & 0xFF);
        z[n++] = (unsigned char)(len >> 8);
        z[n++] = (unsigned char)(~len & 0xFF);
        z[n++] = (unsigned char)((~len >> 8) & 0xFF);
        memcpy(z + n, flat + off, len);
        n += len;
        off += len;
    }
    put32(z + n, (b << 16) | a);
    n += 4;
    chunk(f, "IDAT", z, n);
    chunk(f, "IEND", NULL, 0);
    fclose(f);
    free(z);
    free(flat);
}

/* image_map and image_pattern options against POV-Ray 3.7: repeat, offset,
 * bicubic interpolation, the mapping types, once, filter/transmit of a
 * palette entry and of all entries, transmit all on an RGB image. */
static const pattern_case image_cases[] = {
    {"planar", "image_map { png \"xi_rgb.png\" } scale 1.5"},
    {"repeat", "image_map { png \"xi_rgb.png\" repeat <2, 3> } scale 1.5"},
    {"offset", "image_map { png \"xi_rgb.png\" offset <0.3, -0.2> } scale 1.5"},
    {"rep_offset", "image_map { png \"xi_rgb.png\" repeat <0.5, 2> offset <0.25, 0.5> } scale 2"},
    {"bilinear", "image_map { png \"xi_rgb.png\" interpolate 2 } scale 1.3"},
    {"bicubic", "image_map { png \"xi_rgb.png\" interpolate 3 } scale 1.3"},
    {"normdist", "image_map { png \"xi_rgb.png\" interpolate 4 } scale 1.3"},
    {"once", "image_map { png \"xi_rgb.png\" once interpolate 3 } scale 1.2 translate <0.4, 0.6, 0>"},
    {"spherical", "image_map { png \"xi_rgb.png\" map_type 1 } translate <1.5, 1.5, 0.5>"},
    {"cylindrical", "image_map { png \"xi_rgb.png\" map_type 2 repeat <1, 2> } translate <1.5, 0, 0.5> scale <1, 0.5, 1>"},
    {"torus", "image_map { png \"xi_rgb.png\" map_type 5 interpolate 2 } rotate x*90 translate <1.5, 1.5, 0.3>"},
    {"pal_filter", "image_map { png \"xi_pal.png\" filter 1, 0.7 transmit 2, 0.4 } scale 1.5"},
    {"pal_all", "image_map { png \"xi_pal.png\" transmit all 0.3 filter 3, 0.5 } scale 1.5"},
    {"pal_trns_all", "image_map { png \"xi_trns.png\" transmit all 0.2 } scale 1.5"},
    {"rgb_all", "image_map { png \"xi_rgb.png\" transmit all 0.3 filter all 0.2 } scale 1.5"},
    {"pattern_rep", "image_pattern { png \"xi_rgb.png\" repeat <3, 1> offset <0.1, 0> interpolate 3 } " GREY " scale 1.5"},
};
#define NIMAGE ((int)(sizeof image_cases / sizeof image_cases[0]))

static void test_image_options(void **st)
{
    (void)st;
    enum { IW = 7, IH = 5 };
    unsigned char rgb[IW * IH * 3], pal[IW * IH];
    for (int y = 0; y < IH; y++)
        for (int x = 0; x < IW; x++) {
            unsigned char *q = rgb + (y * IW + x) * 3;
            q[0] = (unsigned char)(x * 255 / (IW - 1));
            q[1] = (unsigned char)(y * 255 / (IH - 1));
            q[2] = (unsigned char)(((x + y) & 1) ? 230 : 25);
            pal[y * IW + x] = (unsigned char)((x + 2 * y) % 4);
        }
    static const unsigned char plte[12] = {250, 40, 40, 40, 220, 40, 40, 60, 240, 230, 230, 60};
    static const unsigned char trns[4] = {255, 128, 0, 200};
    write_png("xi_rgb.png", IW, IH, 3, rgb, NULL, 0, NULL, 0);
    write_png("xi_pal.png", IW, IH, 1, pal, plte, 4, NULL, 0);
    write_png("xi_trns.png", IW, IH, 1, pal, plte, 4, trns, 4);
    assert_int_equal(run_tiles(image_cases, NIMAGE, "images"), 0);
}

/* The octave batch (two lattice noises per pass, down the lanes) gives
 * each octave's value bit for bit as one shade_noise_value at the same
 * scaled point, and Turbulence built on it (and DTurbulence, two DNoise at
 * a time) the sum POV-Ray forms octave by octave; points on both sides of zero and just off lattice planes. */
static void test_noise_octaves_exact(void **st)
{
    (void)st;
    const double lambdas[3] = {2.0, 1.7, 3.1};
    for (int g = 1; g <= 3; g++)
        for (int li = 0; li < 3; li++)
            for (int i = 0; i < 3000; i++) {
                double off = (i % 7 == 0) ? 1e-11 : 0.0;
                vec3 p = v3(i * 0.173 - 250.0 + off, 40.0 - i * 0.0311 - off, (i % 13) * 0.5 - 3.0 + i * 1e-4);
                int n = 1 + i % 11;
                double v[11];
                shade_noise_octaves(p, n, lambdas[li], g, v);
                double l = 1.0, turb = 0.0, o = 0.5;
                for (int k = 0; k < n; k++) {
                    double ref = shade_noise_value(k ? v3_scale(p, l) : p, g);
                    if (v[k] != ref) fail_msg("gen %d lambda %g octave %d at point %d: %.17g != %.17g", g, lambdas[li], k, i, v[k], ref);
                    if (k == 0) turb = g > 1 ? fmin(fmax(2.0 * ref - 0.5, 0.0), 1.0) : ref;
                    else {
                        turb += o * (g > 1 ? 2.0 * ref - 0.5 : ref);
                        if (k < n - 1) o *= 0.5;
                    }
                    l *= lambdas[li];
                }
                assert_true(shade_noise_turbulence(p, n, 0.5, lambdas[li], g) == turb);
                if (g == 1) { /* DNoise's octaves (two at a time) against one DNoise each */
                    vec3 dv[11];
                    shade_noise_dvector_octaves(p, n, lambdas[li], dv);
                    double dl2 = 1.0;
                    for (int k = 0; k < n; k++) {
                        vec3 w = shade_noise_dvector(k ? v3_scale(p, dl2) : p);
                        if (w.x != dv[k].x || w.y != dv[k].y || w.z != dv[k].z) fail_msg("dnoise octave %d at point %d", k, i);
                        dl2 *= lambdas[li];
                    }
                }
                if (g == 1) { /* DTurbulence (two octaves at a time) against DNoise octave by octave */
                    vec3 d = shade_noise_dvector(p), dt = shade_noise_dturbulence(p, n, 0.5, lambdas[li]);
                    double dl = lambdas[li], dO = 0.5;
                    for (int k = 2; k <= n; k++) {
                        vec3 w = shade_noise_dvector(v3_scale(p, dl));
                        d.x += dO * w.x;
                        d.y += dO * w.y;
                        d.z += dO * w.z;
                        if (k < n) {
                            dl *= lambdas[li];
                            dO *= 0.5;
                        }
                    }
                    if (d.x != dt.x || d.y != dt.y || d.z != dt.z) fail_msg("dturbulence %d octaves at point %d", n, i);
                }
            }
}

/* Crackle with a metric of halves (1.5, 2.5, 4, 6) rules points out by a
 * product-and-root sum before taking pow's, and metric 2 rules whole sides
 * of the scan out by their distance; the values are the full scan's.
 * The same pattern with the metric moved by 1e-9 takes the scan that asks
 * pow of every point within the largest-coordinate bound: its three
 * distances move by about 1e-9 (they are continuous in the metric), while
 * a point wrongly ruled out would move a value by the gap to the next
 * point's distance. Over 20000 points (default form, a form with three
 * weights, an offset), no value may differ by 1e-6. */
static void test_crackle_half_metrics(void **st)
{
    (void)st;
    static const double metrics[5] = {1.5, 2.0, 2.5, 4.0, 6.0};
    for (int mi = 0; mi < 5; mi++) {
        char src[1024];
        double m = metrics[mi], m2 = m + 1e-9;
        snprintf(src, sizeof src,
                 "plane { y, 0 pigment { crackle metric %.17g " GREY " } }\n"
                 "plane { y, 0 pigment { crackle metric %.17g " GREY " } }\n"
                 "plane { y, 0 pigment { crackle form <0.8, -0.6, 0.4> offset 0.3 metric %.17g " GREY " } }\n"
                 "plane { y, 0 pigment { crackle form <0.8, -0.6, 0.4> offset 0.3 metric %.17g " GREY " } }\n",
                 m, m2, m, m2);
        sdl_options so;
        sdl_default_options(&so);
        scene *sc = NULL;
        diag *d = diag_new();
        assert_int_equal(sdl_parse_string("crackle.pov", src, &so, &sc, d), PT_OK);
        assert_int_equal(sc->nobjects, 4);
        shade_pattern_ctx pc = shade_pattern_ctx_plain(sc);
        double worst = 0.0;
        for (int k = 0; k < 2; k++)
            for (int i = 0; i < 10000; i++) {
                vec3 p = v3(i * 0.0731 - 300.0, (i % 97) * 0.0413 - 2.0, i * 0.00917 + 0.5);
                colour5 a, b;
                shade_pigment_eval(&sc->objects[2 * k]->texture->pigment, p, &pc, &a);
                shade_pigment_eval(&sc->objects[2 * k + 1]->texture->pigment, p, &pc, &b);
                double e = fabs(a.r - b.r);
                if (e > worst) worst = e;
                if (e > 1e-6) fail_msg("metric %g case %d point %d: %.17g against %.17g", m, k, i, a.r, b.r);
            }
        printf("crackle metric %g: largest difference from metric + 1e-9 %.3g\n", m, worst);
        scene_free(sc);
        diag_free(d);
    }
}

/* Closed forms: ranges and the blend-map search. */
static void test_noise_closed_form(void **st)
{
    (void)st;
    for (int g = 1; g <= 3; g++) {
        double lo = 1, hi = 0;
        for (int i = 0; i < 20000; i++) {
            vec3 p = v3(i * 0.137 - 700.0, i * 0.0731 + 3.0, i * 0.311 - 9.0);
            double v = shade_noise_value(p, g);
            assert_true(v >= 0.0 && v <= 1.0);
            lo = fmin(lo, v);
            hi = fmax(hi, v);
            assert_true(v == shade_noise_value(p, g)); /* deterministic */
        }
        assert_true(hi - lo > 0.5);
    }
    /* generator 1 and 2 are the same lattice sum, rescaled: n2 = (n1 - 0.5 + 1.05242) * 0.48985582 unclamped */
    vec3 p = v3(1.3, -2.7, 0.4);
    double n1 = shade_noise_value(p, 1), n2 = shade_noise_value(p, 2);
    assert_true(fabs(n2 - (n1 - 0.5 + 1.05242) * 0.48985582) < 1e-12);
    assert_true(fabs(shade_noise_cycloidal(0.25) - 1.0) < 1e-12);
    assert_true(fabs(shade_noise_triangle_wave(0.25) - 0.5) < 1e-12);
    assert_true(fabs(shade_noise_triangle_wave(-0.25) - 0.5) < 1e-12);
    scene_map_entry e[3] = {{0.2, {0}, 0, 0, 0, 0, 0}, {0.5, {0}, 0, 0, 0, 0, 0}, {0.5, {0}, 0, 0, 0, 0, 0}};
    scene_blend_map m = {MAP_COLOUR, 3, e};
    int ip, ic;
    shade_blend_map_search(&m, 0.1, &ip, &ic);
    assert_int_equal(ip, 0);
    assert_int_equal(ic, 0);
    shade_blend_map_search(&m, 0.3, &ip, &ic);
    assert_int_equal(ip, 0);
    assert_int_equal(ic, 1);
    shade_blend_map_search(&m, 0.5, &ip, &ic); /* at or past the last value: the last entry */
    assert_int_equal(ip, 2);
    assert_int_equal(ic, 2);
    e[2].value = 0.7;
    shade_blend_map_search(&m, 0.5, &ip, &ic); /* on an inner value: that entry alone */
    assert_int_equal(ip, 1);
    assert_int_equal(ic, 1);
    shade_blend_map_search(&m, 0.9, &ip, &ic);
    assert_int_equal(ip, 2);
    assert_int_equal(ic, 2);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/partray-pat-XXXXXX");
    if (!mkdtemp(tmpdir)) return 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_noise_closed_form),
        cmocka_unit_test(test_noise_octaves_exact),
        cmocka_unit_test(test_crackle_half_metrics),
        cmocka_unit_test(test_patterns),
        cmocka_unit_test(test_ridged_mf_first_call),
        cmocka_unit_test(test_pavement),
        cmocka_unit_test(test_pavement_errors),
        cmocka_unit_test(test_image_options),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    if (rc == 0) {
        char cmd[600];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
        run(cmd);
    } else {
        printf("images kept in %s\n", tmpdir);
    }
    return rc;
}
