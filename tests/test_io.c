/* test_io.c - image I/O: EXR, PNG, PFM round trips, crash-safe writing,
 * damaged files, sRGB transfer functions. Every test works in a fresh
 * mkdtemp() directory that the teardown removes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <openexr.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "diag.h"
#include "framebuffer.h"
#include "img_io.h"
#include "test_util.h"

/* ---- fixture: a temporary directory -------------------------------------- */

typedef struct {
    char dir[64];
    char path[256];
} tmpdir;

static int setup_dir(void **state)
{
    tmpdir *t = calloc(1, sizeof *t);
    if (!t) return -1;
    if (tu_mkdtemp(t->dir, sizeof t->dir, "pt_test_io") != 0) {
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

static int count_entries(const char *dir)
{
    int n = 0;
    DIR *dp = opendir(dir);
    if (!dp) return -1;
    struct dirent *e;
    while ((e = readdir(dp)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) n++;
    closedir(dp);
    return n;
}

static int file_exists(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0;
}

static long file_size(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 ? (long)st.st_size : -1;
}

/* Open file descriptors of this process (-1 where /proc is unavailable). */
static int count_fds(void)
{
    int n = count_entries("/proc/self/fd");
    return n < 0 ? -1 : n - 1; /* minus the one opendir itself holds */
}

/* Does any recorded message contain `needle`? */
static int diag_has(const diag *d, const char *needle)
{
    for (int i = 0; i < diag_count(d); i++)
        if (strstr(diag_get(d, i)->text, needle)) return 1;
    return 0;
}

/* Deterministic pseudo-random numbers in [0,1) (splitmix64). */
static double urand(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

/* An image with values spanning the float range: zeros, negatives, tiny
 * (denormal) and huge magnitudes, plus ordinary radiances. */
static framebuffer *varied_fb(int w, int h, int with_alpha)
{
    framebuffer *fb = fb_new(w, h);
    assert_non_null(fb);
    uint64_t s = 12345;
    static const float specials[] = {0.0f, -0.0f, 1.0f, 0.5f, -2.5f, 1e-30f, 1.4e-45f, 1.17549435e-38f,
                                     3.0e38f, 65504.0f, 1e6f, 123456.789f, 1e-7f};
    size_t n = (size_t)w * (size_t)h * 3u;
    for (size_t i = 0; i < n; i++) {
        if (i % 7 == 3)
            fb->rgb[i] = specials[(i / 7) % (sizeof specials / sizeof specials[0])];
        else
            fb->rgb[i] = (float)(urand(&s) * pow(10.0, urand(&s) * 8.0 - 4.0));
    }
    if (with_alpha) {
        fb->alpha = malloc(sizeof(float) * (size_t)w * (size_t)h);
        assert_non_null(fb->alpha);
        for (int i = 0; i < w * h; i++) fb->alpha[i] = (float)urand(&s);
    }
    return fb;
}

/* ---- sRGB ------------------------------------------------------------------ */

static void test_srgb_functions(void **st)
{
    (void)st;
    /* IEC 61966-2-1: 1.055 * 0.5^(1/2.4) - 0.055 = 0.735356983... */
    assert_true(fabs(img_srgb_encode(0.5) - 0.735357) < 1e-6);
    assert_true(fabs(img_srgb_encode(0.0)) < 1e-15);
    assert_true(fabs(img_srgb_encode(1.0) - 1.0) < 1e-12);
    assert_true(fabs(img_srgb_encode(0.001) - 0.01292) < 1e-12); /* linear segment */
    /* Decode of the standard's knee value 0.04045 stays within 3e-9 of 0.04045/12.92. */
    assert_true(fabs(img_srgb_decode(0.04045) - 0.04045 / 12.92) < 3e-9);
    /* Inverses within 1e-12 on a dense grid and around both knees (see
     * img_io.c for the 2.2e-9 wide window above L=0.0031308 where the
     * standard's curve itself is not invertible). */
    for (int i = 0; i <= 100000; i++) {
        double x = i / 100000.0;
        assert_true(fabs(img_srgb_decode(img_srgb_encode(x)) - x) < 1e-12);
        assert_true(fabs(img_srgb_encode(img_srgb_decode(x)) - x) < 1e-12);
    }
    static const double lin[] = {0.0031308, 0.0031308 - 1e-9, 0.0031307, 0.0031309, 0.00314, 1e-9, 0.999999};
    for (size_t i = 0; i < sizeof lin / sizeof lin[0]; i++)
        assert_true(fabs(img_srgb_decode(img_srgb_encode(lin[i])) - lin[i]) < 1e-12);
    static const double enc[] = {0.04045, 0.040449936, 0.0404499, 0.04044995, 0.0405, 1e-9};
    for (size_t i = 0; i < sizeof enc / sizeof enc[0]; i++)
        assert_true(fabs(img_srgb_encode(img_srgb_decode(enc[i])) - enc[i]) < 1e-12);
}

static void test_format_from_path(void **st)
{
    (void)st;
    assert_int_equal(img_format_from_path("a/b.exr"), IMG_FMT_EXR);
    assert_int_equal(img_format_from_path("B.PNG"), IMG_FMT_PNG);
    assert_int_equal(img_format_from_path("x.y/z.pfm"), IMG_FMT_PFM);
    assert_int_equal(img_format_from_path("x.png/z"), IMG_FMT_UNKNOWN);
    assert_int_equal(img_format_from_path(".exr"), IMG_FMT_UNKNOWN);
    assert_int_equal(img_format_from_path("out.tiff"), IMG_FMT_UNKNOWN);
}

/* ---- EXR --------------------------------------------------------------------- */

static void test_exr_float_roundtrip(void **state)
{
    tmpdir *t = *state;
    for (int alpha = 0; alpha <= 1; alpha++) {
        framebuffer *fb = varied_fb(37, 45, alpha); /* > one PIZ block (32 lines) */
        for (int comp = 0; comp <= 2; comp++) {
            img_write_opts o;
            img_default_write_opts(&o);
            o.exr_float = 1;
            o.exr_compression = comp;
            diag *d = diag_new();
            const char *p = tpath(t, "f.exr");
            assert_int_equal(img_write(p, fb, &o, d), PT_OK);
            framebuffer *in = NULL;
            assert_int_equal(img_read(p, 0, &in, d), PT_OK);
            assert_int_equal(diag_errors(d), 0);
            assert_int_equal(in->width, 37);
            assert_int_equal(in->height, 45);
            assert_memory_equal(in->rgb, fb->rgb, sizeof(float) * 37 * 45 * 3);
            if (alpha) {
                assert_non_null(in->alpha);
                assert_memory_equal(in->alpha, fb->alpha, sizeof(float) * 37 * 45);
            } else {
                assert_null(in->alpha);
            }
            fb_free(in);
            diag_free(d);
        }
        fb_free(fb);
    }
    assert_int_equal(count_entries(t->dir), 1); /* no temporary files left */
}

static void test_exr_half_roundtrip(void **state)
{
    tmpdir *t = *state;
    const int w = 29, h = 70;
    framebuffer *fb = fb_new(w, h);
    uint64_t s = 99;
    /* Normal half range [6.1e-5, 65504]: relative error <= 2^-11. */
    for (int i = 0; i < w * h * 3; i++) fb->rgb[i] = (float)(1e-4 * pow(6.0e8, urand(&s)) * (i % 5 == 0 ? -1 : 1));
    for (int comp = 0; comp <= 2; comp++) {
        img_write_opts o;
        img_default_write_opts(&o);
        o.exr_compression = comp;
        diag *d = diag_new();
        const char *p = tpath(t, "h.exr");
        assert_int_equal(img_write(p, fb, &o, d), PT_OK);
        framebuffer *in = NULL;
        assert_int_equal(img_read(p, 0, &in, d), PT_OK);
        double worst = 0.0;
        for (int i = 0; i < w * h * 3; i++) {
            double rel = fabs((double)in->rgb[i] - fb->rgb[i]) / fabs((double)fb->rgb[i]);
            if (rel > worst) worst = rel;
        }
        assert_true(worst < 1e-3);
        assert_true(worst <= 1.0 / 2048.0 + 1e-9); /* round to nearest */
        fb_free(in);
        diag_free(d);
    }
    fb_free(fb);
}

/* Non-finite values become 0; half output clamps to +-65504 (no Inf). */
static void test_exr_nonfinite_and_clamp(void **state)
{
    tmpdir *t = *state;
    framebuffer *fb = fb_new(2, 2);
    float v[12] = {NAN, INFINITY, -INFINITY, 1e6f, -1e6f, 65504.0f, 70000.0f, 0.25f, -3.0f, 1.0f, 2.0f, 3.0f};
    memcpy(fb->rgb, v, sizeof v);
    diag *d = diag_new();
    const char *p = tpath(t, "nf.exr");
    for (int fl = 0; fl <= 1; fl++) {
        img_write_opts o;
        img_default_write_opts(&o);
        o.exr_float = fl;
        assert_int_equal(img_write(p, fb, &o, d), PT_OK);
        framebuffer *in = NULL;
        assert_int_equal(img_read(p, 0, &in, d), PT_OK);
        for (int i = 0; i < 12; i++) assert_true(isfinite(in->rgb[i]));
        assert_true(in->rgb[0] == 0.0f && in->rgb[1] == 0.0f && in->rgb[2] == 0.0f);
        if (fl) {
            assert_true(in->rgb[3] == 1e6f && in->rgb[6] == 70000.0f);
        } else {
            assert_true(in->rgb[3] == 65504.0f && in->rgb[4] == -65504.0f && in->rgb[6] == 65504.0f);
        }
        assert_true(in->rgb[7] == 0.25f && in->rgb[8] == -3.0f);
        fb_free(in);
    }
    diag_free(d);
    fb_free(fb);
}

static void test_exr_metadata(void **state)
{
    tmpdir *t = *state;
    framebuffer *fb = varied_fb(8, 5, 0);
    const char *keys[] = {"partray:scene", "partray:gi"};
    const char *vals[] = {"scenes/cbox.pov", "particle"};
    img_write_opts o;
    img_default_write_opts(&o);
    o.meta_keys = keys;
    o.meta_values = vals;
    o.nmeta = 2;
    diag *d = diag_new();
    const char *p = tpath(t, "m.exr");
    assert_int_equal(img_write(p, fb, &o, d), PT_OK);

    exr_context_t ctx = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    assert_int_equal(exr_start_read(&ctx, p, &init), EXR_ERR_SUCCESS);
    for (int i = 0; i < 2; i++) {
        int32_t len = 0;
        const char *s = NULL;
        assert_int_equal(exr_attr_get_string(ctx, 0, keys[i], &len, &s), EXR_ERR_SUCCESS);
        assert_int_equal(len, (int32_t)strlen(vals[i]));
        assert_memory_equal(s, vals[i], (size_t)len);
    }
    exr_attr_chromaticities_t c;
    assert_int_equal(exr_attr_get_chromaticities(ctx, 0, "chromaticities", &c), EXR_ERR_SUCCESS);
    /* Rec. 709 primaries, D65 white. */
    assert_true(fabsf(c.red_x - 0.64f) < 1e-6f && fabsf(c.red_y - 0.33f) < 1e-6f);
    assert_true(fabsf(c.green_x - 0.30f) < 1e-6f && fabsf(c.green_y - 0.60f) < 1e-6f);
    assert_true(fabsf(c.blue_x - 0.15f) < 1e-6f && fabsf(c.blue_y - 0.06f) < 1e-6f);
    assert_true(fabsf(c.white_x - 0.3127f) < 1e-6f && fabsf(c.white_y - 0.3290f) < 1e-6f);
    exr_compression_t comp;
    assert_int_equal(exr_get_compression(ctx, 0, &comp), EXR_ERR_SUCCESS);
    assert_int_equal(comp, EXR_COMPRESSION_ZIP); /* the default */
    const exr_attr_chlist_t *chl = NULL;
    assert_int_equal(exr_get_channels(ctx, 0, &chl), EXR_ERR_SUCCESS);
    assert_int_equal(chl->num_channels, 3);
    assert_int_equal(chl->entries[0].pixel_type, EXR_PIXEL_HALF);
    exr_finish(&ctx);

    /* A key that names a required attribute of another type cannot be set:
     * an I/O error, and nothing is left behind. */
    const char *badk[] = {"compression"};
    const char *badv[] = {"zip"};
    o.meta_keys = badk;
    o.meta_values = badv;
    o.nmeta = 1;
    const char *q = tpath(t, "bad.exr");
    assert_int_equal(img_write(q, fb, &o, d), PT_ERR_IO);
    assert_true(diag_has(d, "compression"));
    assert_false(file_exists(q));
    assert_int_equal(count_entries(t->dir), 1);
    diag_free(d);
    fb_free(fb);
}

/* Write an EXR through the core API with arbitrary channels (planar float or
 * uint source data), a data window at (x0,y0), scanline or 16x8 tiles. */
typedef struct {
    const char *name;
    exr_pixel_type_t type;
} chan_spec;

typedef double (*val_fn)(int x, int y, int c);

static void write_custom_exr(const char *path, int tiled, int x0, int y0, int w, int h, const chan_spec *cs, int nc,
                             val_fn val)
{
    exr_context_t ctx = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    int part = 0;
    assert_int_equal(exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init), EXR_ERR_SUCCESS);
    assert_int_equal(exr_add_part(ctx, NULL, tiled ? EXR_STORAGE_TILED : EXR_STORAGE_SCANLINE, &part),
                     EXR_ERR_SUCCESS);
    exr_attr_box2i_t dw;
    dw.min.x = x0;
    dw.min.y = y0;
    dw.max.x = x0 + w - 1;
    dw.max.y = y0 + h - 1;
    exr_attr_v2f_t swc;
    swc.x = swc.y = 0.0f;
    assert_int_equal(exr_initialize_required_attr(ctx, part, &dw, &dw, 1.0f, &swc, 1.0f, EXR_LINEORDER_INCREASING_Y,
                                                  EXR_COMPRESSION_ZIP),
                     EXR_ERR_SUCCESS);
    for (int c = 0; c < nc; c++)
        assert_int_equal(exr_add_channel(ctx, part, cs[c].name, cs[c].type, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1),
                         EXR_ERR_SUCCESS);
    const int tw = 16, th = 8;
    if (tiled)
        assert_int_equal(exr_set_tile_descriptor(ctx, part, tw, th, EXR_TILE_ONE_LEVEL, EXR_TILE_ROUND_DOWN),
                         EXR_ERR_SUCCESS);
    assert_int_equal(exr_write_header(ctx), EXR_ERR_SUCCESS);

    uint32_t *data[8];
    for (int c = 0; c < nc; c++) {
        data[c] = malloc(sizeof(uint32_t) * (size_t)w * (size_t)h);
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                double v = val(x, y, c);
                if (cs[c].type == EXR_PIXEL_UINT) {
                    data[c][y * w + x] = (uint32_t)v;
                } else {
                    float f = (float)v;
                    memcpy(&data[c][y * w + x], &f, 4);
                }
            }
    }
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    int first = 1;
    int nbx = tiled ? (w + tw - 1) / tw : 1, nby = tiled ? (h + th - 1) / th : 0;
    int32_t lpc = 1;
    if (!tiled) {
        assert_int_equal(exr_get_scanlines_per_chunk(ctx, part, &lpc), EXR_ERR_SUCCESS);
        nby = (h + lpc - 1) / lpc;
    }
    for (int by = 0; by < nby; by++) {
        for (int bx = 0; bx < nbx; bx++) {
            exr_chunk_info_t ci;
            int px, py;
            if (tiled) {
                assert_int_equal(exr_write_tile_chunk_info(ctx, part, bx, by, 0, 0, &ci), EXR_ERR_SUCCESS);
                px = bx * tw;
                py = by * th;
            } else {
                assert_int_equal(exr_write_scanline_chunk_info(ctx, part, y0 + by * lpc, &ci), EXR_ERR_SUCCESS);
                px = 0;
                py = by * lpc;
            }
            if (first)
                assert_int_equal(exr_encoding_initialize(ctx, part, &ci, &enc), EXR_ERR_SUCCESS);
            else
                assert_int_equal(exr_encoding_update(ctx, part, &ci, &enc), EXR_ERR_SUCCESS);
            for (int k = 0; k < enc.channel_count; k++) {
                int c = 0;
                while (strcmp(cs[c].name, enc.channels[k].channel_name)) c++;
                enc.channels[k].user_data_type = cs[c].type == EXR_PIXEL_UINT ? EXR_PIXEL_UINT : EXR_PIXEL_FLOAT;
                enc.channels[k].user_bytes_per_element = 4;
                enc.channels[k].user_pixel_stride = 4;
                enc.channels[k].user_line_stride = 4 * w;
                enc.channels[k].encode_from_ptr = (const uint8_t *)(data[c] + (size_t)py * (size_t)w + (size_t)px);
            }
            if (first) assert_int_equal(exr_encoding_choose_default_routines(ctx, part, &enc), EXR_ERR_SUCCESS);
            first = 0;
            assert_int_equal(exr_encoding_run(ctx, part, &enc), EXR_ERR_SUCCESS);
        }
    }
    exr_encoding_destroy(ctx, &enc);
    assert_int_equal(exr_finish(&ctx), EXR_ERR_SUCCESS);
    for (int c = 0; c < nc; c++) free(data[c]);
}

static double val_a(int x, int y, int c) { return (double)(x + 3 * y + 100 * c) * 0.25; }

/* Luminance-only image with an offset data window reads as grey. */
static void test_exr_read_y_only(void **state)
{
    tmpdir *t = *state;
    const chan_spec cs[] = {{"Y", EXR_PIXEL_HALF}};
    const char *p = tpath(t, "y.exr");
    write_custom_exr(p, 0, -5, 10, 21, 19, cs, 1, val_a);
    framebuffer *in = NULL;
    diag *d = diag_new();
    assert_int_equal(img_read(p, 0, &in, d), PT_OK);
    assert_int_equal(diag_count(d), 0);
    assert_int_equal(in->width, 21);
    assert_int_equal(in->height, 19);
    for (int y = 0; y < 19; y++)
        for (int x = 0; x < 21; x++) {
            float *px = fb_px(in, x, y);
            assert_true(px[0] == (float)val_a(x, y, 0)); /* exact in half: multiples of 1/4 below 2048 */
            assert_true(px[1] == px[0] && px[2] == px[0]);
        }
    fb_free(in);
    diag_free(d);
}

/* uint R, half G, float A, no B (-> 0), extra channel ignored. */
static void test_exr_read_mixed_types(void **state)
{
    tmpdir *t = *state;
    const chan_spec cs[] = {{"R", EXR_PIXEL_UINT}, {"G", EXR_PIXEL_HALF}, {"A", EXR_PIXEL_FLOAT}, {"Z", EXR_PIXEL_FLOAT}};
    const char *p = tpath(t, "mixed.exr");
    write_custom_exr(p, 0, 3, -2, 17, 40, cs, 4, val_a);
    framebuffer *in = NULL;
    diag *d = diag_new();
    assert_int_equal(img_read(p, 0, &in, d), PT_OK);
    assert_int_equal(in->width, 17);
    assert_int_equal(in->height, 40);
    assert_non_null(in->alpha);
    for (int y = 0; y < 40; y++)
        for (int x = 0; x < 17; x++) {
            float *px = fb_px(in, x, y);
            assert_true(px[0] == (float)(uint32_t)val_a(x, y, 0));
            assert_true(px[1] == (float)val_a(x, y, 1));
            assert_true(px[2] == 0.0f);
            assert_true(in->alpha[y * 17 + x] == (float)val_a(x, y, 2));
        }
    fb_free(in);
    diag_free(d);
}

static void test_exr_read_tiled(void **state)
{
    tmpdir *t = *state;
    const chan_spec cs[] = {{"R", EXR_PIXEL_HALF}, {"G", EXR_PIXEL_HALF}, {"B", EXR_PIXEL_HALF}};
    const char *p = tpath(t, "tiled.exr");
    write_custom_exr(p, 1, 7, 11, 37, 21, cs, 3, val_a); /* partial tiles at the right and bottom */
    framebuffer *in = NULL;
    diag *d = diag_new();
    assert_int_equal(img_read(p, 0, &in, d), PT_OK);
    assert_int_equal(in->width, 37);
    assert_int_equal(in->height, 21);
    for (int y = 0; y < 21; y++)
        for (int x = 0; x < 37; x++)
            for (int c = 0; c < 3; c++) assert_true(fb_px(in, x, y)[c] == (float)val_a(x, y, c));
    fb_free(in);
    diag_free(d);
}

static void test_exr_truncated(void **state)
{
    tmpdir *t = *state;
    framebuffer *fb = varied_fb(40, 40, 0);
    int fds = count_fds();
    for (int comp = 0; comp <= 2; comp++) {
        img_write_opts o;
        img_default_write_opts(&o);
        o.exr_compression = comp;
        diag *d = diag_new();
        const char *p = tpath(t, "t.exr");
        assert_int_equal(img_write(p, fb, &o, d), PT_OK);
        long size = file_size(p);
        assert_true(size > 200);
        const long cuts[] = {size - 1, size / 2, 100, 8, 4};
        for (size_t k = 0; k < sizeof cuts / sizeof cuts[0]; k++) {
            assert_int_equal(truncate(p, cuts[k]), 0);
            framebuffer *in = (framebuffer *)(uintptr_t)1;
            int before = diag_errors(d);
            assert_int_equal(img_read(p, 0, &in, d), PT_ERR_IO);
            assert_null(in);
            assert_true(diag_errors(d) > before);
            assert_true(diag_has(d, p));
        }
        diag_free(d);
    }
    assert_int_equal(count_fds(), fds); /* no descriptor leaked on any path */
    fb_free(fb);
}

/* ---- PNG --------------------------------------------------------------------- */

static void test_png_codes(void **state)
{
    tmpdir *t = *state;
    framebuffer *fb = fb_new(4, 2);
    const float v[24] = {0.0f, 1.0f, 0.5f, 2.0f, -1.0f, NAN, INFINITY, 0.001f, 0.2f,
                         0.0031308f, 1e-4f, 0.99f, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    memcpy(fb->rgb, v, sizeof v);
    diag *d = diag_new();
    const char *p = tpath(t, "c.png");
    assert_int_equal(img_write(p, fb, NULL, d), PT_OK);
    framebuffer *in = NULL;
    assert_int_equal(img_read(p, 1, &in, d), PT_OK); /* raw: code / 255 */
    int code[12];
    for (int i = 0; i < 12; i++) {
        double c = in->rgb[i] * 255.0;
        code[i] = (int)lround(c);
        assert_true(fabs(c - code[i]) < 1e-4);
    }
    assert_int_equal(code[0], 0);   /* linear 0 */
    assert_int_equal(code[1], 255); /* linear 1 */
    assert_int_equal(code[2], 188); /* 0.735357 * 255 = 187.516 -> 188 */
    assert_int_equal(code[3], 255); /* clamped */
    assert_int_equal(code[4], 0);   /* clamped */
    assert_int_equal(code[5], 0);   /* NaN -> 0 */
    assert_int_equal(code[6], 0);   /* Inf -> 0 (non-finite) */
    assert_int_equal(code[7], 3);   /* 12.92 * 0.001 * 255 = 3.29 */
    assert_int_equal(code[8], 124); /* 0.484529 * 255 = 123.55 */
    assert_int_equal(code[9], 10);  /* 0.0404499 * 255 = 10.31 */
    fb_free(in);
    /* The file carries an sRGB chunk with perceptual intent (0) and the
     * matching gAMA (1/2.2 -> 45455); chunk = length, type, data, CRC. */
    FILE *f = fopen(p, "rb");
    assert_non_null(f);
    unsigned char buf[4096];
    size_t n = fread(buf, 1, sizeof buf, f);
    fclose(f);
    int found_srgb = 0, found_gama = 0;
    for (size_t i = 8; i + 12 <= n;) {
        uint32_t len = (uint32_t)buf[i] << 24 | (uint32_t)buf[i + 1] << 16 | (uint32_t)buf[i + 2] << 8 | buf[i + 3];
        const unsigned char *ty = buf + i + 4, *data = buf + i + 8;
        if (!memcmp(ty, "sRGB", 4) && len == 1 && data[0] == 0) found_srgb = 1;
        if (!memcmp(ty, "gAMA", 4) && len == 4 &&
            ((uint32_t)data[0] << 24 | (uint32_t)data[1] << 16 | (uint32_t)data[2] << 8 | data[3]) == 45455)
            found_gama = 1;
        if (!memcmp(ty, "IDAT", 4)) break;
        i += 12 + len;
    }
    assert_true(found_srgb);
    assert_true(found_gama);
    diag_free(d);
    fb_free(fb);
}

/* 8-bit codes over a sweep of the floats in [0, 1.01] (every 2^13-th bit
 * pattern, plus the exact 2^-k steps near 0): each the nearest code to
 * the sRGB encoding, as the transfer function says (the writer takes
 * them from a table of the codes' first floats; any float it misplaced
 * would be a code off here). */
static void test_png_codes_sweep(void **state)
{
    tmpdir *t = *state;
    const int w = 512, h = 256;
    framebuffer *fb = fb_new(w, h);
    uint32_t top;
    float one = 1.01f;
    memcpy(&top, &one, sizeof top);
    int n = 0;
    for (uint32_t b = 0; b <= top && n < w * h * 3; b += 1u << 13) {
        float v;
        memcpy(&v, &b, sizeof v);
        fb->rgb[n++] = v;
    }
    assert_true(n > 3 * 40000); /* the sweep covers (0, 1.01] */
    for (; n < w * h * 3; n++) fb->rgb[n] = ldexpf(1.0f, -(n % 40)); /* 1 down to 2^-39 */
    diag *d = diag_new();
    const char *p = tpath(t, "sweep.png");
    assert_int_equal(img_write(p, fb, NULL, d), PT_OK);
    framebuffer *in = NULL;
    assert_int_equal(img_read(p, 1, &in, d), PT_OK); /* raw: code / 255 */
    for (int i = 0; i < w * h * 3; i++) {
        double v = fb->rgb[i], e = v > 0.0 ? img_srgb_encode(v) : 0.0;
        int want = e >= 1.0 ? 255 : (int)floor(e * 255.0 + 0.5);
        int got = (int)lround(in->rgb[i] * 255.0);
        if (got != want) fail_msg("linear %.9g: code %d, want %d", v, got, want);
    }
    fb_free(in);
    diag_free(d);
    fb_free(fb);
}

static void test_png_roundtrip(void **state)
{
    tmpdir *t = *state;
    const int w = 33, h = 17;
    for (int bits16 = 0; bits16 <= 1; bits16++) {
        for (int alpha = 0; alpha <= 1; alpha++) {
            framebuffer *fb = fb_new(w, h);
            uint64_t s = 7 + (uint64_t)bits16;
            for (int i = 0; i < w * h * 3; i++) fb->rgb[i] = (float)urand(&s);
            if (alpha) {
                fb->alpha = malloc(sizeof(float) * (size_t)(w * h));
                for (int i = 0; i < w * h; i++) fb->alpha[i] = (float)urand(&s);
            }
            img_write_opts o;
            img_default_write_opts(&o);
            o.png_16bit = bits16;
            diag *d = diag_new();
            const char *p = tpath(t, "rt.png");
            assert_int_equal(img_write(p, fb, &o, d), PT_OK);
            framebuffer *in = NULL;
            assert_int_equal(img_read(p, 0, &in, d), PT_OK);
            assert_int_equal(in->width, w);
            assert_int_equal(in->height, h);
            /* Rounding to the nearest code: within half a code in encoded
             * space (the brief's bound is one code, 1/255). */
            const double maxc = bits16 ? 65535.0 : 255.0;
            const double tol = 0.5 / maxc + 1e-6;
            for (int i = 0; i < w * h * 3; i++)
                assert_true(fabs(img_srgb_encode(in->rgb[i]) - img_srgb_encode(fb->rgb[i])) <= tol);
            if (alpha) {
                assert_non_null(in->alpha);
                for (int i = 0; i < w * h; i++) assert_true(fabs(in->alpha[i] - fb->alpha[i]) <= tol);
            } else {
                assert_null(in->alpha);
            }
            fb_free(in);
            diag_free(d);
            fb_free(fb);
        }
    }
}

/* Grey, grey+alpha and palette files written by libpng's simplified API. */
static void test_png_read_other_layouts(void **state)
{
    tmpdir *t = *state;
    const int w = 5, h = 3;
    diag *d = diag_new();
    png_byte grey[15], ga[30];
    for (int i = 0; i < 15; i++) {
        grey[i] = (png_byte)(i * 17);
        ga[2 * i] = (png_byte)(i * 17);
        ga[2 * i + 1] = (png_byte)(255 - i);
    }
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    img.width = (png_uint_32)w;
    img.height = (png_uint_32)h;
    img.format = PNG_FORMAT_GRAY;
    const char *p = tpath(t, "g.png");
    assert_true(png_image_write_to_file(&img, p, 0, grey, 0, NULL));
    framebuffer *in = NULL;
    assert_int_equal(img_read(p, 1, &in, d), PT_OK);
    for (int i = 0; i < 15; i++)
        for (int c = 0; c < 3; c++) assert_true(fabs(in->rgb[i * 3 + c] * 255.0 - grey[i]) < 1e-4);
    assert_null(in->alpha);
    fb_free(in);
    assert_int_equal(img_read(p, 0, &in, d), PT_OK); /* decoded */
    for (int i = 0; i < 15; i++) assert_true(fabs(in->rgb[i * 3] - img_srgb_decode(grey[i] / 255.0)) < 1e-6);
    fb_free(in);

    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    img.width = (png_uint_32)w;
    img.height = (png_uint_32)h;
    img.format = PNG_FORMAT_GA;
    p = tpath(t, "ga.png");
    assert_true(png_image_write_to_file(&img, p, 0, ga, 0, NULL));
    assert_int_equal(img_read(p, 1, &in, d), PT_OK);
    assert_non_null(in->alpha);
    for (int i = 0; i < 15; i++) {
        assert_true(fabs(in->rgb[i * 3 + 2] * 255.0 - ga[2 * i]) < 1e-4);
        assert_true(fabs(in->alpha[i] * 255.0 - ga[2 * i + 1]) < 1e-4);
    }
    fb_free(in);

    /* Palette image: 4 colours, RGB colormap. */
    png_byte cmap[12] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 10, 20, 30};
    png_byte idx[15];
    for (int i = 0; i < 15; i++) idx[i] = (png_byte)(i % 4);
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    img.width = (png_uint_32)w;
    img.height = (png_uint_32)h;
    img.format = PNG_FORMAT_RGB_COLORMAP;
    img.colormap_entries = 4;
    p = tpath(t, "pal.png");
    assert_true(png_image_write_to_file(&img, p, 0, idx, 0, cmap));
    assert_int_equal(img_read(p, 1, &in, d), PT_OK);
    for (int i = 0; i < 15; i++)
        for (int c = 0; c < 3; c++) assert_true(fabs(in->rgb[i * 3 + c] * 255.0 - cmap[idx[i] * 3 + c]) < 1e-4);
    fb_free(in);
    assert_int_equal(diag_errors(d), 0);
    diag_free(d);
}

static void test_png_truncated(void **state)
{
    tmpdir *t = *state;
    framebuffer *fb = varied_fb(64, 64, 0);
    int fds = count_fds();
    diag *d = diag_new();
    const char *p = tpath(t, "t.png");
    assert_int_equal(img_write(p, fb, NULL, d), PT_OK);
    long size = file_size(p);
    assert_true(size > 1000);
    const long cuts[] = {size - 1, size - 12, size / 2, 40, 8, 3};
    for (size_t k = 0; k < sizeof cuts / sizeof cuts[0]; k++) {
        assert_int_equal(truncate(p, cuts[k]), 0);
        framebuffer *in = (framebuffer *)(uintptr_t)1;
        int before = diag_errors(d);
        assert_int_equal(img_read(p, 0, &in, d), PT_ERR_IO);
        assert_null(in);
        assert_true(diag_errors(d) > before);
    }
    assert_true(diag_has(d, "truncated"));
    assert_int_equal(count_fds(), fds);
    diag_free(d);
    fb_free(fb);
}

/* ---- PFM --------------------------------------------------------------------- */

static void test_pfm_roundtrip(void **state)
{
    tmpdir *t = *state;
    const int w = 6, h = 4;
    framebuffer *fb = varied_fb(w, h, 0);
    fb_px(fb, 0, 0)[0] = 111.0f; /* top-left */
    fb_px(fb, 0, h - 1)[0] = 222.0f; /* bottom-left */
    diag *d = diag_new();
    const char *p = tpath(t, "r.pfm");
    assert_int_equal(img_write(p, fb, NULL, d), PT_OK);

    /* Raw layout: exact header, then the bottom row first, little-endian. */
    FILE *f = fopen(p, "rb");
    assert_non_null(f);
    char hdr[32];
    const char *want = "PF\n6 4\n-1.0\n";
    assert_int_equal(fread(hdr, 1, strlen(want), f), strlen(want));
    assert_memory_equal(hdr, want, strlen(want));
    unsigned char b[4];
    assert_int_equal(fread(b, 1, 4, f), 4);
    fclose(f);
    uint32_t u = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
    float first;
    memcpy(&first, &u, 4);
    assert_true(first == 222.0f);
    assert_int_equal(file_size(p), (long)strlen(want) + w * h * 12);

    framebuffer *in = NULL;
    assert_int_equal(img_read(p, 0, &in, d), PT_OK);
    assert_int_equal(in->width, w);
    assert_int_equal(in->height, h);
    assert_true(fb_px(in, 0, 0)[0] == 111.0f); /* top stays top */
    assert_memory_equal(in->rgb, fb->rgb, sizeof(float) * (size_t)(w * h * 3));
    fb_free(in);
    diag_free(d);
    fb_free(fb);
}

/* "Pf" greyscale, big-endian (positive scale), written by hand. */
static void test_pfm_read_grey_big_endian(void **state)
{
    tmpdir *t = *state;
    const char *p = tpath(t, "g.pfm");
    FILE *f = fopen(p, "wb");
    assert_non_null(f);
    fputs("Pf\n3 2\n1.0\n", f);
    const float vals[6] = {1.5f, 2.5f, 3.5f, -4.0f, 5.0f, 6.0f}; /* file order: bottom row first */
    for (int i = 0; i < 6; i++) {
        uint32_t u;
        memcpy(&u, &vals[i], 4);
        unsigned char b[4] = {(unsigned char)(u >> 24), (unsigned char)(u >> 16), (unsigned char)(u >> 8),
                              (unsigned char)u};
        fwrite(b, 1, 4, f);
    }
    fclose(f);
    framebuffer *in = NULL;
    diag *d = diag_new();
    assert_int_equal(img_read(p, 0, &in, d), PT_OK);
    assert_int_equal(in->width, 3);
    assert_int_equal(in->height, 2);
    for (int x = 0; x < 3; x++)
        for (int c = 0; c < 3; c++) {
            assert_true(fb_px(in, x, 1)[c] == vals[x]);
            assert_true(fb_px(in, x, 0)[c] == vals[3 + x]);
        }
    fb_free(in);
    diag_free(d);
}

static void write_text(const char *p, const char *s)
{
    FILE *f = fopen(p, "wb");
    assert_non_null(f);
    fputs(s, f);
    fclose(f);
}

static void test_bad_files(void **state)
{
    tmpdir *t = *state;
    diag *d = diag_new();
    framebuffer *in = NULL;
    int fds = count_fds();
    /* Absurd dimensions are refused before any allocation. */
    const char *p = tpath(t, "big.pfm");
    write_text(p, "PF\n70000 10\n-1.0\n");
    assert_int_equal(img_read(p, 0, &in, d), PT_ERR_IO);
    assert_true(diag_has(d, "exceeds the limit"));
    write_text(p, "PF\n20000 20000\n-1.0\n"); /* 4e8 > 2^28 pixels */
    assert_int_equal(img_read(p, 0, &in, d), PT_ERR_IO);
    write_text(p, "PF\n4 4\n-1.0\nabc"); /* truncated data */
    assert_int_equal(img_read(p, 0, &in, d), PT_ERR_IO);
    assert_true(diag_has(d, "truncated"));
    write_text(p, "PF\n4 x\n-1.0\n");
    assert_int_equal(img_read(p, 0, &in, d), PT_ERR_IO);
    /* Wrong magic, empty and missing files. */
    p = tpath(t, "junk.exr");
    write_text(p, "this is not an image at all");
    assert_int_equal(img_read(p, 0, &in, d), PT_ERR_IO);
    assert_true(diag_has(d, "magic"));
    write_text(p, "");
    assert_int_equal(img_read(p, 0, &in, d), PT_ERR_IO);
    p = tpath(t, "missing.png");
    assert_int_equal(img_read(p, 0, &in, d), PT_ERR_IO);
    assert_true(diag_has(d, "No such file"));
    assert_null(in);
    assert_int_equal(count_fds(), fds);
    diag_free(d);
}

/* ---- img_write contract --------------------------------------------------------- */

static void test_write_errors(void **state)
{
    tmpdir *t = *state;
    framebuffer *fb = varied_fb(4, 4, 0);
    int fds = count_fds();
    diag *d = diag_new();
    static const char *names[] = {"nodir/x.exr", "nodir/x.png", "nodir/x.pfm"};
    for (int i = 0; i < 3; i++) {
        const char *p = tpath(t, names[i]);
        assert_int_equal(img_write(p, fb, NULL, d), PT_ERR_IO);
        assert_false(file_exists(p));
        assert_true(diag_has(d, p));
        assert_true(diag_has(d, "No such file or directory"));
    }
    assert_int_equal(count_entries(t->dir), 0);
    /* Unknown extension and bad options are usage errors; nothing is created. */
    assert_int_equal(img_write(tpath(t, "x.tiff"), fb, NULL, d), PT_ERR_USAGE);
    assert_int_equal(img_write(tpath(t, "noext"), fb, NULL, d), PT_ERR_USAGE);
    img_write_opts o;
    img_default_write_opts(&o);
    o.exr_compression = 7;
    assert_int_equal(img_write(tpath(t, "x.exr"), fb, &o, d), PT_ERR_USAGE);
    assert_int_equal(count_entries(t->dir), 0);
    /* Overwriting an existing file replaces it in one step. */
    const char *p = tpath(t, "o.pfm");
    write_text(p, "old");
    assert_int_equal(img_write(p, fb, NULL, d), PT_OK);
    assert_int_equal(file_size(p), (long)strlen("PF\n4 4\n-1.0\n") + 4 * 4 * 12);
    assert_int_equal(count_entries(t->dir), 1);
    assert_int_equal(count_fds(), fds);
    diag_free(d);
    fb_free(fb);
}

/* A write that fails half way (file size limit: EFBIG) leaves neither the
 * destination nor the temporary file behind, for every format. */
static void test_write_fails_midway(void **state)
{
    tmpdir *t = *state;
    framebuffer *fb = varied_fb(200, 200, 0);
    struct rlimit old, lim;
    assert_int_equal(getrlimit(RLIMIT_FSIZE, &old), 0);
    void (*oldsig)(int) = signal(SIGXFSZ, SIG_IGN);
    lim = old;
    lim.rlim_cur = 20000;
    assert_int_equal(setrlimit(RLIMIT_FSIZE, &lim), 0);
    static const char *names[] = {"big.exr", "big.png", "big.pfm"};
    diag *d = diag_new();
    for (int i = 0; i < 3; i++) {
        img_write_opts o;
        img_default_write_opts(&o);
        o.exr_float = 1;
        o.exr_compression = 0;
        o.png_16bit = 1;
        const char *p = tpath(t, names[i]);
        int before = diag_errors(d);
        pt_status st = img_write(p, fb, &o, d);
        assert_int_equal(st, PT_ERR_IO);
        assert_true(diag_errors(d) > before);
        assert_true(diag_has(d, p));
        assert_true(diag_has(d, "File too large"));
        assert_false(file_exists(p));
        assert_int_equal(count_entries(t->dir), 0);
    }
    assert_int_equal(setrlimit(RLIMIT_FSIZE, &old), 0);
    signal(SIGXFSZ, oldsig);
    diag_free(d);
    fb_free(fb);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_srgb_functions),
        cmocka_unit_test(test_format_from_path),
        cmocka_unit_test_setup_teardown(test_exr_float_roundtrip, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_exr_half_roundtrip, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_exr_nonfinite_and_clamp, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_exr_metadata, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_exr_read_y_only, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_exr_read_mixed_types, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_exr_read_tiled, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_exr_truncated, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_png_codes, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_png_codes_sweep, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_png_roundtrip, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_png_read_other_layouts, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_png_truncated, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_pfm_roundtrip, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_pfm_read_grey_big_endian, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_bad_files, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_write_errors, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_write_fails_midway, setup_dir, teardown_dir),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
