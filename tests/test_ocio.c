/* test_ocio.c - colour management (io/img_ocio.h) and colour-managed EXR and
 * PNG writing: display values, ACEScg conversions, chromaticities, PNG
 * chunks, name and config errors. The built-in config is used throughout
 * ($OCIO is unset at start); measured values are printed. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <openexr.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "diag.h"
#include "framebuffer.h"
#include "img_io.h"
#include "test_util.h"
#include "img_ocio.h"

/* ---- helpers ------------------------------------------------------------- */

typedef struct {
    char dir[64];
    char path[256];
} tmpdir;

static int setup_dir(void **state)
{
    tmpdir *t = calloc(1, sizeof *t);
    if (!t) return -1;
    if (tu_mkdtemp(t->dir, sizeof t->dir, "pt_test_ocio") != 0) {
        free(t);
        return -1;
    }
    *state = t;
    return 0;
}

static int teardown_dir(void **state)
{
    tmpdir *t = *state;
    tu_rm_rf(t->dir);
    free(t);
    return 0;
}

static const char *tpath(tmpdir *t, const char *name)
{
    snprintf(t->path, sizeof t->path, "%s/%s", t->dir, name);
    return t->path;
}

static img_ocio *open_builtin(diag *d)
{
    img_ocio *o = NULL;
    assert_int_equal(img_ocio_open(NULL, &o, d), PT_OK);
    assert_non_null(o);
    return o;
}

/* A 1-pixel-high framebuffer holding grey values v[i]. */
static framebuffer *grey_fb(const float *v, int n)
{
    framebuffer *fb = fb_new(n, 1);
    assert_non_null(fb);
    for (int i = 0; i < n; i++) fb->rgb[3 * i] = fb->rgb[3 * i + 1] = fb->rgb[3 * i + 2] = v[i];
    return fb;
}

/* The error text of the last message in d ("" if none). */
static const char *last_msg(const diag *d)
{
    int n = diag_count(d);
    return n > 0 ? diag_get(d, n - 1)->text : "";
}

/* Apply one display/view to grey 0.5 and 0.18 (exposure 0). */
static void display_of(img_ocio *o, const char *display, const char *view, float out_half[3], float out_mid[3])
{
    diag *d = diag_new();
    const float v[2] = {0.5f, 0.18f};
    framebuffer *fb = grey_fb(v, 2);
    assert_int_equal(img_ocio_apply(o, fb, NULL, display, view, NULL, 0.0, d), PT_OK);
    assert_int_equal(diag_errors(d), 0);
    memcpy(out_half, fb->rgb, sizeof(float) * 3);
    memcpy(out_mid, fb->rgb + 3, sizeof(float) * 3);
    fb_free(fb);
    diag_free(d);
}

/* ---- the config ----------------------------------------------------------- */

static void test_builtin_config(void **st)
{
    (void)st;
    diag *d = diag_new();
    img_ocio *o = open_builtin(d);
    assert_string_equal(img_ocio_source(o), "built-in");
    assert_int_equal(img_ocio_display_count(o), 2);
    assert_string_equal(img_ocio_display_name(o, 0), "sRGB");
    assert_string_equal(img_ocio_display_name(o, 1), "Rec.1886");
    assert_null(img_ocio_display_name(o, 2));
    assert_string_equal(img_ocio_default_display(o), "sRGB");
    for (int i = 0; i < 2; i++) {
        const char *dn = img_ocio_display_name(o, i);
        assert_int_equal(img_ocio_view_count(o, dn), 3);
        assert_string_equal(img_ocio_view_name(o, dn, 0), "Standard");
        assert_string_equal(img_ocio_view_name(o, dn, 1), "ACES");
        assert_string_equal(img_ocio_view_name(o, dn, 2), "Raw");
        assert_string_equal(img_ocio_default_view(o, dn), "Standard");
    }
    int found = 0;
    for (int i = 0; i < img_ocio_space_count(o); i++) {
        const char *n = img_ocio_space_name(o, i);
        found += !strcmp(n, "Linear Rec.709 (sRGB)") + !strcmp(n, "ACEScg") + !strcmp(n, "ACES2065-1");
    }
    assert_int_equal(found, 3);
    assert_int_equal(img_ocio_look_count(o), 1);
    assert_string_equal(img_ocio_look_name(o, 0), "ACES Gamut Compression");
    assert_int_equal(img_ocio_check(o, "ACEScg", "Rec.1886", "ACES", "+ACES Gamut Compression", d), PT_OK);
    /* roles and aliases resolve */
    assert_int_equal(img_ocio_check(o, "scene_linear", NULL, NULL, NULL, d), PT_OK);
    assert_int_equal(img_ocio_check(o, "lin_ap1", NULL, NULL, NULL, d), PT_OK);
    assert_int_equal(diag_count(d), 0); /* no OCIO warnings either */
    img_ocio_close(o);
    diag_free(d);
}

/* The compiled-in text is io/ocio/config.ocio byte for byte, and the file
 * loads through the path argument as well. */
static void test_builtin_matches_source_file(void **st)
{
    (void)st;
    const char *path = PT_SOURCE_DIR "/io/ocio/config.ocio";
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    static char buf[1 << 16];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    assert_true(n > 1000);
    assert_string_equal(buf, img_ocio_builtin_config());

    diag *d = diag_new();
    img_ocio *o = NULL;
    assert_int_equal(img_ocio_open(path, &o, d), PT_OK);
    assert_string_equal(img_ocio_source(o), path);
    float half[3], mid[3];
    display_of(o, "sRGB", "Standard", half, mid);
    assert_float_equal(half[0], 0.735357, 1e-5);
    img_ocio_close(o);
    diag_free(d);
}

/* $OCIO, --ocio-config (the path argument) and the built-in config. */
static void test_config_sources(void **state)
{
    tmpdir *t = *state;
    diag *d = diag_new();
    img_ocio *o = NULL;

    /* $OCIO names a missing file: I/O error. */
    setenv("OCIO", tpath(t, "missing.ocio"), 1);
    assert_int_equal(img_ocio_open(NULL, &o, d), PT_ERR_IO);
    assert_null(o);
    assert_non_null(strstr(last_msg(d), "$OCIO"));

    /* An explicit path wins over $OCIO; IMG_OCIO_BUILTIN ignores $OCIO. */
    assert_int_equal(img_ocio_open(PT_SOURCE_DIR "/io/ocio/config.ocio", &o, d), PT_OK);
    img_ocio_close(o);
    o = NULL;
    assert_int_equal(img_ocio_open(IMG_OCIO_BUILTIN, &o, d), PT_OK);
    assert_string_equal(img_ocio_source(o), "built-in");
    img_ocio_close(o);
    o = NULL;

    /* Not a config: usage error. */
    const char *bad = tpath(t, "bad.ocio");
    FILE *f = fopen(bad, "w");
    assert_non_null(f);
    fputs("ocio_profile_version: 2\nroles: [this is not a map\n", f);
    fclose(f);
    setenv("OCIO", bad, 1);
    assert_int_equal(img_ocio_open(NULL, &o, d), PT_ERR_USAGE);
    assert_null(o);
    assert_non_null(strstr(last_msg(d), "invalid OCIO config"));

    /* A config that parses but fails validate(): a view on a missing space. */
    f = fopen(bad, "w");
    assert_non_null(f);
    fputs("ocio_profile_version: 2\n"
          "roles: {default: lin}\n"
          "file_rules: [!<Rule> {name: Default, colorspace: default}]\n"
          "displays: {d: [!<View> {name: v, colorspace: nowhere}]}\n"
          "colorspaces: [!<ColorSpace> {name: lin}]\n",
          f);
    fclose(f);
    assert_int_equal(img_ocio_open(bad, &o, d), PT_ERR_USAGE);
    assert_null(o);
    unsetenv("OCIO");
    diag_free(d);
}

/* ---- display values ------------------------------------------------------- */

static void test_srgb_standard(void **st)
{
    (void)st;
    diag *d = diag_new();
    img_ocio *o = open_builtin(d);
    float half[3], mid[3];
    display_of(o, "sRGB", "Standard", half, mid);
    printf("sRGB/Standard: 0.5 -> %.7f %.7f %.7f (IEC 61966-2-1: 0.735357), 0.18 -> %.7f\n", half[0], half[1],
           half[2], mid[0]);
    for (int k = 0; k < 3; k++) {
        assert_float_equal(half[k], 0.735357, 1e-5);
        assert_float_equal(mid[k], img_srgb_encode(0.18), 1e-5);
    }
    /* A ramp through both pieces of the curve, against the formula. OCIO's
     * sRGB (ExponentWithLinear, gamma 2.4, offset 0.055) joins its pieces
     * exactly: linear slope 12.9235 below L = 0.0030399, where IEC 61966-2-1
     * has 12.92 below 0.0031308; just under the knee the two differ by up to
     * about 1e-5, hence 1.2e-5 here. */
    float v[64];
    for (int i = 0; i < 64; i++) v[i] = i < 8 ? 0.0004f * (float)i : (float)(i - 7) / 56.0f;
    framebuffer *fb = grey_fb(v, 64);
    assert_int_equal(img_ocio_apply(o, fb, NULL, NULL, NULL, NULL, 0.0, d), PT_OK); /* defaults: sRGB/Standard */
    double maxerr = 0;
    for (int i = 0; i < 64; i++) maxerr = fmax(maxerr, fabs(fb->rgb[3 * i] - img_srgb_encode(v[i])));
    printf("sRGB/Standard vs img_srgb_encode over a 64-step ramp: max |diff| = %.2e\n", maxerr);
    assert_true(maxerr < 1.2e-5);
    fb_free(fb);
    img_ocio_close(o);
    diag_free(d);
}

static void test_rec1886_standard(void **st)
{
    (void)st;
    diag *d = diag_new();
    img_ocio *o = open_builtin(d);
    float half[3], mid[3];
    display_of(o, "Rec.1886", "Standard", half, mid);
    printf("Rec.1886/Standard: 0.5 -> %.7f (0.5^(1/2.4) = %.7f)\n", half[0], pow(0.5, 1 / 2.4));
    for (int k = 0; k < 3; k++) {
        assert_float_equal(half[k], pow(0.5, 1 / 2.4), 1e-5);
        assert_float_equal(mid[k], pow(0.18, 1 / 2.4), 1e-5);
    }
    img_ocio_close(o);
    diag_free(d);
}

/* The ACES 1.0 SDR output transform (RRT + ODT): mid grey 0.18 lands near
 * 10% of display luminance (the RRT's 0.18 -> 4.8 of 48 cd/m2), which the
 * sRGB curve encodes as ~0.356 and a 2.4 gamma as ~0.39. Measured with OCIO
 * 2.1.2: sRGB 0.3559543, Rec.1886 0.3895301. */
static void test_aces_view(void **st)
{
    (void)st;
    diag *d = diag_new();
    img_ocio *o = open_builtin(d);
    float half[3], mid[3], std_half[3], std_mid[3];
    display_of(o, "sRGB", "ACES", half, mid);
    display_of(o, "sRGB", "Standard", std_half, std_mid);
    printf("sRGB/ACES: 0.18 -> %.7f %.7f %.7f, 0.5 -> %.7f\n", mid[0], mid[1], mid[2], half[0]);
    assert_float_equal(mid[0], mid[1], 1e-5);
    assert_float_equal(mid[0], mid[2], 1e-5);
    assert_in_range((long)(mid[0] * 1e4), 3500, 3650); /* 0.350 .. 0.365 */
    assert_true(mid[0] < std_mid[0] - 0.05);            /* darker than the plain curve */
    assert_true(half[0] > mid[0]);
    display_of(o, "Rec.1886", "ACES", half, mid);
    printf("Rec.1886/ACES: 0.18 -> %.7f %.7f %.7f\n", mid[0], mid[1], mid[2]);
    assert_float_equal(mid[0], mid[1], 1e-5);
    assert_float_equal(mid[0], mid[2], 1e-5);
    assert_in_range((long)(mid[0] * 1e4), 3800, 4000); /* 0.380 .. 0.400 */
    /* Highlights are rolled off: scene 16 stays below display 1. */
    const float hi = 16.0f;
    framebuffer *fb = grey_fb(&hi, 1);
    assert_int_equal(img_ocio_apply(o, fb, NULL, "sRGB", "ACES", NULL, 0.0, d), PT_OK);
    printf("sRGB/ACES: 16 -> %.7f\n", fb->rgb[0]);
    assert_true(fb->rgb[0] > 0.9f && fb->rgb[0] <= 1.0f);
    fb_free(fb);
    img_ocio_close(o);
    diag_free(d);
}

static void test_raw_view_and_exposure(void **st)
{
    (void)st;
    diag *d = diag_new();
    img_ocio *o = open_builtin(d);
    float half[3], mid[3];
    display_of(o, "Rec.1886", "Raw", half, mid);
    assert_float_equal(half[0], 0.5, 1e-7);
    assert_float_equal(mid[2], 0.18, 1e-7);
    /* +1 stop: 0.25 displays as 0.5 does. */
    const float q = 0.25f;
    framebuffer *fb = grey_fb(&q, 1);
    assert_int_equal(img_ocio_apply(o, fb, NULL, "sRGB", "Standard", NULL, 1.0, d), PT_OK);
    assert_float_equal(fb->rgb[0], 0.735357, 1e-5);
    fb_free(fb);
    /* A look (gamut compression) leaves in-gamut grey alone. */
    const float g = 0.18f;
    fb = grey_fb(&g, 1);
    assert_int_equal(img_ocio_apply(o, fb, NULL, "sRGB", "Standard", "ACES Gamut Compression", 0.0, d), PT_OK);
    assert_float_equal(fb->rgb[0], img_srgb_encode(0.18), 1e-5);
    fb_free(fb);
    assert_int_equal(img_ocio_apply(o, NULL, NULL, NULL, NULL, NULL, 0.0, d), PT_ERR_USAGE);
    img_ocio_close(o);
    diag_free(d);
}

/* ---- ACEScg ---------------------------------------------------------------- */

static void test_acescg_grey(void **st)
{
    (void)st;
    diag *d = diag_new();
    img_ocio *o = open_builtin(d);
    const float g = 0.18f;
    framebuffer *fb = grey_fb(&g, 1);
    assert_int_equal(img_ocio_convert(o, fb, "ACEScg", "Linear Rec.709 (sRGB)", d), PT_OK);
    printf("ACEScg 0.18 grey -> Linear Rec.709: %.8f %.8f %.8f\n", fb->rgb[0], fb->rgb[1], fb->rgb[2]);
    for (int k = 0; k < 3; k++) assert_float_equal(fb->rgb[k], 0.18, 1e-4);
    assert_float_equal(fb->rgb[0], fb->rgb[1], 1e-4);
    assert_float_equal(fb->rgb[0], fb->rgb[2], 1e-4);
    fb->rgb[0] = fb->rgb[1] = fb->rgb[2] = 0.18f;
    assert_int_equal(img_ocio_convert(o, fb, "Linear Rec.709 (sRGB)", "ACEScg", d), PT_OK);
    printf("Linear Rec.709 0.18 grey -> ACEScg: %.8f %.8f %.8f\n", fb->rgb[0], fb->rgb[1], fb->rgb[2]);
    for (int k = 0; k < 3; k++) assert_float_equal(fb->rgb[k], 0.18, 1e-4);
    assert_float_equal(fb->rgb[0], fb->rgb[1], 1e-4);
    assert_float_equal(fb->rgb[0], fb->rgb[2], 1e-4);
    /* ACEScg red in Rec.709: the first column of the Bradford-adapted
     * AP1 -> Rec.709 matrix, (1.70505, -0.13026, -0.02400). */
    fb->rgb[0] = 1.0f;
    fb->rgb[1] = fb->rgb[2] = 0.0f;
    assert_int_equal(img_ocio_convert(o, fb, "ACEScg", NULL, d), PT_OK);
    assert_float_equal(fb->rgb[0], 1.70505, 1e-4);
    assert_float_equal(fb->rgb[1], -0.13026, 1e-4);
    assert_float_equal(fb->rgb[2], -0.02400, 1e-4);
    fb_free(fb);
    img_ocio_close(o);
    diag_free(d);
}

/* ---- EXR ------------------------------------------------------------------ */

static void read_chromaticities(const char *path, exr_attr_chromaticities_t *c, int *present)
{
    exr_context_t ctx = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    assert_int_equal(exr_start_read(&ctx, path, &init), EXR_ERR_SUCCESS);
    exr_result_t rv = exr_attr_get_chromaticities(ctx, 0, "chromaticities", c);
    *present = rv == EXR_ERR_SUCCESS;
    exr_finish(&ctx);
}

static framebuffer *test_image(void)
{
    framebuffer *fb = fb_new(7, 5);
    assert_non_null(fb);
    for (int i = 0; i < 7 * 5 * 3; i++) fb->rgb[i] = (float)(0.013 * i * i) - 0.1f * (float)(i % 3);
    return fb;
}

static void test_exr_acescg(void **state)
{
    tmpdir *t = *state;
    diag *d = diag_new();
    img_ocio *o = open_builtin(d);
    framebuffer *fb = test_image();
    img_write_opts opt;
    img_default_write_opts(&opt);
    opt.exr_float = 1;
    opt.working_space = "ACEScg";
    const char *p = tpath(t, "acescg.exr");
    assert_int_equal(img_write(p, fb, &opt, d), PT_OK);

    /* The file holds exactly what img_ocio_convert gives, bit for bit. */
    framebuffer *expect = test_image();
    assert_int_equal(img_ocio_convert(o, expect, NULL, "ACEScg", d), PT_OK);
    framebuffer *back = NULL;
    assert_int_equal(img_read(p, 0, &back, d), PT_OK);
    assert_int_equal(back->width, 7);
    assert_int_equal(back->height, 5);
    assert_memory_equal(back->rgb, expect->rgb, sizeof(float) * 7 * 5 * 3);
    /* and differs from the input (it was converted) */
    assert_true(fabsf(back->rgb[3 * 20] - fb->rgb[3 * 20]) > 1e-3f);

    exr_attr_chromaticities_t c;
    int present = 0;
    read_chromaticities(p, &c, &present);
    assert_true(present);
    printf("ACEScg EXR chromaticities: R %.5f,%.5f G %.5f,%.5f B %.5f,%.5f W %.5f,%.5f\n", c.red_x, c.red_y,
           c.green_x, c.green_y, c.blue_x, c.blue_y, c.white_x, c.white_y);
    /* ACES AP1, Academy S-2014-004; white x=0.32168, y=0.33767 */
    assert_float_equal(c.red_x, 0.713, 1e-6);
    assert_float_equal(c.red_y, 0.293, 1e-6);
    assert_float_equal(c.green_x, 0.165, 1e-6);
    assert_float_equal(c.green_y, 0.830, 1e-6);
    assert_float_equal(c.blue_x, 0.128, 1e-6);
    assert_float_equal(c.blue_y, 0.044, 1e-6);
    assert_float_equal(c.white_x, 0.32168, 1e-6);
    assert_float_equal(c.white_y, 0.33767, 1e-6);

    /* Linear Rec.709 named explicitly: values bit-identical, Rec.709 tags. */
    opt.working_space = "Linear Rec.709 (sRGB)";
    p = tpath(t, "rec709.exr");
    assert_int_equal(img_write(p, fb, &opt, d), PT_OK);
    fb_free(back);
    back = NULL;
    assert_int_equal(img_read(p, 0, &back, d), PT_OK);
    assert_memory_equal(back->rgb, fb->rgb, sizeof(float) * 7 * 5 * 3);
    read_chromaticities(p, &c, &present);
    assert_true(present);
    assert_float_equal(c.red_x, 0.64, 1e-6);
    assert_float_equal(c.green_y, 0.60, 1e-6);
    assert_float_equal(c.blue_y, 0.06, 1e-6);
    assert_float_equal(c.white_x, 0.3127, 1e-6);
    assert_float_equal(c.white_y, 0.3290, 1e-6);

    /* ACES2065-1: AP0 tags. */
    opt.working_space = "ACES2065-1";
    p = tpath(t, "ap0.exr");
    assert_int_equal(img_write(p, fb, &opt, d), PT_OK);
    read_chromaticities(p, &c, &present);
    assert_true(present);
    assert_float_equal(c.red_x, 0.7347, 1e-6);
    assert_float_equal(c.blue_y, -0.0770, 1e-6);
    assert_float_equal(c.white_x, 0.32168, 1e-6);

    /* An unknown working space: usage error, no file. */
    opt.working_space = "ACEScgg";
    p = tpath(t, "bad.exr");
    assert_int_equal(img_write(p, fb, &opt, d), PT_ERR_USAGE);
    assert_non_null(strstr(last_msg(d), "ACEScg"));
    assert_int_equal(access(p, F_OK), -1);

    fb_free(back);
    fb_free(expect);
    fb_free(fb);
    img_ocio_close(o);
    diag_free(d);
}

/* Chromaticities measured through the config's XYZ role for a space that is
 * not in the table: sRGB-encoded Rec.709 maps 0 and 1 as linear does, so
 * its primaries measure as Rec.709's. */
static void test_measured_chromaticities(void **st)
{
    (void)st;
    diag *d = diag_new();
    img_ocio *o = open_builtin(d);
    float xy[8];
    assert_int_equal(img_ocio_chromaticities(o, "sRGB Encoded Rec.709 (sRGB)", xy, d), 1);
    const double want[8] = {0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.3127, 0.3290};
    double maxerr = 0;
    for (int i = 0; i < 8; i++) maxerr = fmax(maxerr, fabs(xy[i] - want[i]));
    printf("measured Rec.709 chromaticities: max |diff| from BT.709 = %.2e\n", maxerr);
    assert_true(maxerr < 1e-4);
    assert_int_equal(img_ocio_chromaticities(o, "no such space", xy, d), 0);
    img_ocio_close(o);
    diag_free(d);
}

/* ---- PNG ------------------------------------------------------------------ */

typedef struct {
    int srgb, gama, chrm, iccp;
    png_fixed_point gamma;
    png_fixed_point wx, wy, rx, ry, gx, gy, bx, by;
} png_chunks;

static png_chunks read_chunks(const char *path)
{
    png_chunks c;
    memset(&c, 0, sizeof c);
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png_create_info_struct(png);
    assert_non_null(info);
    if (setjmp(png_jmpbuf(png))) fail_msg("libpng error reading %s", path);
    png_init_io(png, f);
    png_read_info(png, info);
    c.srgb = png_get_valid(png, info, PNG_INFO_sRGB) != 0;
    c.gama = png_get_valid(png, info, PNG_INFO_gAMA) != 0;
    c.chrm = png_get_valid(png, info, PNG_INFO_cHRM) != 0;
    c.iccp = png_get_valid(png, info, PNG_INFO_iCCP) != 0;
    if (c.gama) png_get_gAMA_fixed(png, info, &c.gamma);
    if (c.chrm) png_get_cHRM_fixed(png, info, &c.wx, &c.wy, &c.rx, &c.ry, &c.gx, &c.gy, &c.bx, &c.by);
    png_destroy_read_struct(&png, &info, NULL);
    fclose(f);
    return c;
}

/* Write fb to `name` with display/view (NULL = plain) and read the codes back. */
static framebuffer *png_through(tmpdir *t, const char *name, const framebuffer *fb, const char *display,
                                const char *view, int bits16, png_chunks *chunks)
{
    diag *d = diag_new();
    img_write_opts opt;
    img_default_write_opts(&opt);
    opt.png_16bit = bits16;
    opt.display = display;
    opt.view = view;
    const char *p = tpath(t, name);
    assert_int_equal(img_write(p, fb, &opt, d), PT_OK);
    assert_int_equal(diag_count(d), 0);
    *chunks = read_chunks(p);
    framebuffer *back = NULL;
    assert_int_equal(img_read(p, 1, &back, d), PT_OK);
    diag_free(d);
    return back;
}

static void test_png_views(void **state)
{
    tmpdir *t = *state;
    float v[32];
    for (int i = 0; i < 32; i++) v[i] = (float)i / 31.0f * 1.2f;
    v[0] = 0.5f;
    v[1] = 0.18f;
    framebuffer *fb = grey_fb(v, 32);
    png_chunks c;

    for (int bits16 = 0; bits16 <= 1; bits16++) {
        const double maxcode = bits16 ? 65535.0 : 255.0;
        framebuffer *plain = png_through(t, "plain.png", fb, NULL, NULL, bits16, &c);
        assert_true(c.srgb && c.gama && c.chrm && !c.iccp);

        /* sRGB / Standard is the plain encoding: same codes (16 bit: within 1). */
        framebuffer *std = png_through(t, "std.png", fb, "sRGB", "Standard", bits16, &c);
        assert_true(c.srgb && !c.iccp);
        double maxdiff = 0;
        for (int i = 0; i < 32 * 3; i++) maxdiff = fmax(maxdiff, fabs(std->rgb[i] - plain->rgb[i]) * maxcode);
        printf("%d-bit PNG: sRGB/Standard vs plain sRGB encoding: max %.0f code(s) apart; 0.5 -> code %.0f\n",
               bits16 ? 16 : 8, maxdiff, std->rgb[0] * maxcode);
        assert_true(maxdiff <= (bits16 ? 1.0 : 0.0));
        if (!bits16) assert_float_equal(plain->rgb[0] * 255.0, 188.0, 1e-6); /* round(0.735357 * 255) */

        /* sRGB / ACES: tone mapped, mid grey darker; same sRGB chunk. */
        framebuffer *aces = png_through(t, "aces.png", fb, "sRGB", "ACES", bits16, &c);
        assert_true(c.srgb && !c.iccp);
        printf("%d-bit PNG: sRGB/ACES 0.18 -> code %.0f (plain %.0f)\n", bits16 ? 16 : 8, aces->rgb[3] * maxcode,
               plain->rgb[3] * maxcode);
        assert_true(aces->rgb[3] < plain->rgb[3] - 0.05);
        assert_float_equal(aces->rgb[3], aces->rgb[4], 1.0 / maxcode);

        /* Rec.1886: gAMA 1/2.4, Rec.709 cHRM, no sRGB chunk; 0.5 -> 0.5^(1/2.4). */
        framebuffer *r1886 = png_through(t, "r1886.png", fb, "Rec.1886", NULL, bits16, &c);
        assert_true(!c.srgb && c.gama && c.chrm && !c.iccp);
        assert_int_equal(c.gamma, 41667);
        assert_int_equal(c.wx, 31270);
        assert_int_equal(c.wy, 32900);
        assert_int_equal(c.rx, 64000);
        assert_int_equal(c.ry, 33000);
        assert_int_equal(c.gx, 30000);
        assert_int_equal(c.gy, 60000);
        assert_int_equal(c.bx, 15000);
        assert_int_equal(c.by, 6000);
        assert_float_equal(r1886->rgb[0] * maxcode, floor(pow(0.5, 1 / 2.4) * maxcode + 0.5), 1e-6);

        /* Raw: the values as codes, no colour chunks. */
        framebuffer *raw = png_through(t, "raw.png", fb, "sRGB", "Raw", bits16, &c);
        assert_true(!c.srgb && !c.gama && !c.chrm && !c.iccp);
        assert_float_equal(raw->rgb[0] * maxcode, floor(0.5 * maxcode + 0.5), 1e-6);
        assert_float_equal(raw->rgb[3 * 31] * maxcode, maxcode, 1e-6); /* 1.2 clamps */

        fb_free(plain);
        fb_free(std);
        fb_free(aces);
        fb_free(r1886);
        fb_free(raw);
    }
    fb_free(fb);
}

static void test_png_exposure_without_view(void **state)
{
    tmpdir *t = *state;
    const float q = 0.25f;
    framebuffer *fb = grey_fb(&q, 1);
    diag *d = diag_new();
    img_write_opts opt;
    img_default_write_opts(&opt);
    opt.exposure = 1.0;
    const char *p = tpath(t, "exp.png");
    assert_int_equal(img_write(p, fb, &opt, d), PT_OK);
    framebuffer *back = NULL;
    assert_int_equal(img_read(p, 1, &back, d), PT_OK);
    assert_float_equal(back->rgb[0] * 255.0, 188.0, 1e-6); /* as 0.5 unexposed */
    assert_float_equal(fb->rgb[0], 0.25, 0);                /* input untouched */
    png_chunks c = read_chunks(p);
    assert_true(c.srgb);
    fb_free(back);
    fb_free(fb);
    diag_free(d);
}

/* ---- errors --------------------------------------------------------------- */

static void test_bad_names(void **state)
{
    tmpdir *t = *state;
    diag *d = diag_new();
    img_ocio *o = open_builtin(d);
    const float g = 0.5f;
    framebuffer *fb = grey_fb(&g, 1);

    assert_int_equal(img_ocio_apply(o, fb, NULL, "sRBG", NULL, NULL, 0.0, d), PT_ERR_USAGE);
    printf("bad display: %s\n", last_msg(d));
    assert_non_null(strstr(last_msg(d), "'sRBG'"));
    assert_non_null(strstr(last_msg(d), "'sRGB', 'Rec.1886'"));
    assert_float_equal(fb->rgb[0], 0.5, 0); /* untouched */

    assert_int_equal(img_ocio_apply(o, fb, NULL, "sRGB", "Filmic", NULL, 0.0, d), PT_ERR_USAGE);
    assert_non_null(strstr(last_msg(d), "'Standard', 'ACES', 'Raw'"));
    assert_int_equal(img_ocio_apply(o, fb, "XYZ", NULL, NULL, NULL, 0.0, d), PT_ERR_USAGE);
    assert_non_null(strstr(last_msg(d), "'ACEScg'"));
    assert_int_equal(img_ocio_apply(o, fb, NULL, NULL, NULL, "Sepia", 0.0, d), PT_ERR_USAGE);
    assert_non_null(strstr(last_msg(d), "'ACES Gamut Compression'"));
    assert_int_equal(img_ocio_apply(o, fb, NULL, NULL, NULL, NULL, NAN, d), PT_ERR_USAGE);
    assert_int_equal(img_ocio_check(o, NULL, "Rec.1886", "Nope", NULL, d), PT_ERR_USAGE);
    assert_int_equal(img_ocio_convert(o, fb, "ACEScg", "nowhere", d), PT_ERR_USAGE);

    /* Through img_write: usage error before any file exists. */
    img_write_opts opt;
    img_default_write_opts(&opt);
    opt.display = "sRBG";
    const char *p = tpath(t, "bad.png");
    assert_int_equal(img_write(p, fb, &opt, d), PT_ERR_USAGE);
    assert_int_equal(access(p, F_OK), -1);
    DIR *dp = opendir(t->dir);
    int n = 0;
    for (struct dirent *e; (e = readdir(dp));) n += e->d_name[0] != '.';
    closedir(dp);
    assert_int_equal(n, 0);

    fb_free(fb);
    img_ocio_close(o);
    diag_free(d);
}

int main(void)
{
    unsetenv("OCIO");
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_builtin_config),
        cmocka_unit_test(test_builtin_matches_source_file),
        cmocka_unit_test_setup_teardown(test_config_sources, setup_dir, teardown_dir),
        cmocka_unit_test(test_srgb_standard),
        cmocka_unit_test(test_rec1886_standard),
        cmocka_unit_test(test_aces_view),
        cmocka_unit_test(test_raw_view_and_exposure),
        cmocka_unit_test(test_acescg_grey),
        cmocka_unit_test_setup_teardown(test_exr_acescg, setup_dir, teardown_dir),
        cmocka_unit_test(test_measured_chromaticities),
        cmocka_unit_test_setup_teardown(test_png_views, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_png_exposure_without_view, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_bad_names, setup_dir, teardown_dir),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
