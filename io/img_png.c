/* img_png.c - PNG reading and writing through libpng (1.6 API).
 *
 * libpng reports errors by calling the error callback, which must not
 * return; ours records the message and long-jumps back with png_longjmp()
 * to the setjmp(png_jmpbuf()) point of the running call (libpng manual,
 * section "Setting up error handling"). Warnings are dropped: nothing in
 * here prints. Multi-byte samples are big-endian in the file (PNG spec,
 * section 7.1) and are packed/unpacked by hand, so no byte-swap transform
 * is needed. */
#include "img_png.h"

#include <errno.h>
#include <math.h>
#include <png.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef struct {
    int fd;        /* write target */
    int err;       /* errno of a failed write, 0 otherwise */
    char msg[256]; /* last libpng error message */
} png_ctx;

static void on_error(png_structp png, png_const_charp msg)
{
    png_ctx *c = png_get_error_ptr(png);
    if (c) snprintf(c->msg, sizeof c->msg, "%s", msg ? msg : "unknown libpng error");
    png_longjmp(png, 1);
}

/* libpng's own allocations (chunk data, zlib state, a row or two) never
 * need much: the image itself is allocated here. libpng 1.6.39 warns that a
 * tEXt chunk's length is too large and then allocates it anyway (fuzz_image:
 * a 57 KB file asked for 1.5 GB), so its allocator refuses anything above
 * 64 MiB, which libpng reports as an error. */
#define PNG_LIB_ALLOC_MAX ((png_alloc_size_t)64 << 20)

static png_voidp lib_malloc(png_structp png, png_alloc_size_t n)
{
    (void)png;
    return n <= PNG_LIB_ALLOC_MAX ? malloc(n) : NULL;
}

static void lib_free(png_structp png, png_voidp p)
{
    (void)png;
    free(p);
}

static void on_warning(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg;
}

static void on_write(png_structp png, png_bytep data, png_size_t len)
{
    png_ctx *c = png_get_io_ptr(png);
    while (len > 0) {
        ssize_t w = write(c->fd, data, len);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {
            c->err = w < 0 ? errno : EIO;
            png_error(png, "write failed");
        }
        data += w;
        len -= (size_t)w;
    }
}

static void on_flush(png_structp png) { (void)png; }

/* Like libpng's default stdio reader, but says why a read came up short. */
static void on_read(png_structp png, png_bytep data, png_size_t len)
{
    FILE *f = png_get_io_ptr(png);
    if (fread(data, 1, len, f) == len) return;
    if (ferror(f)) {
        png_ctx *c = png_get_error_ptr(png);
        if (c) c->err = errno ? errno : EIO;
        png_error(png, "read failed");
    }
    png_error(png, "unexpected end of file (truncated PNG)");
}

/* Linear value -> code in [0, maxcode]: sRGB-encode, clamp to [0,1], round
 * to nearest (half-way cases up). Non-finite values give 0. */
static unsigned encode_code(float v, double maxcode)
{
    if (!isfinite(v) || v <= 0.0f) return 0;
    double e = img_srgb_encode((double)v);
    if (e >= 1.0) return (unsigned)maxcode;
    return (unsigned)floor(e * maxcode + 0.5);
}

/* encode_code's 8-bit codes without a power per sample. encode_code is
 * non-decreasing over the floats (the transfer function increases, each
 * rounding keeps order, and neighbouring floats lie far more than the
 * power's error apart), and non-negative floats order as their bit
 * patterns do. So code c is taken from the least float whose code is c
 * (thr[c], found by bisection over the bit patterns: 255 searches of 31
 * steps, once per image) up to the next one's; start[] holds the code at
 * the first float of each run of 2^15 bit patterns, from which a sample
 * steps up over the thresholds in its run (a run is narrower than one
 * code's floats everywhere in [0, 1], so one step at most). The codes are
 * encode_code's, to the bit (checked over every float in [0, 1]). */
#define SRGB8_RUN_SHIFT 15
typedef struct {
    uint32_t thr[257];                          /* thr[c]: bits of the least float of code c; thr[256] past all */
    unsigned char start[1u << (32 - SRGB8_RUN_SHIFT)];
} srgb8_table;

static uint32_t float_bits(float v)
{
    uint32_t b;
    memcpy(&b, &v, sizeof b);
    return b;
}

static float bits_float(uint32_t b)
{
    float v;
    memcpy(&v, &b, sizeof v);
    return v;
}

static void srgb8_build(srgb8_table *t)
{
    const uint32_t one = float_bits(1.0f); /* encode_code(1) = 255 */
    t->thr[0] = 0;
    for (unsigned c = 1; c <= 255; c++) {
        uint32_t lo = t->thr[c - 1], hi = one; /* every float below lo has a code below c; hi's is c or more */
        while (lo < hi) {
            uint32_t mid = lo + (hi - lo) / 2;
            if (encode_code(bits_float(mid), 255.0) >= c) hi = mid;
            else lo = mid + 1;
        }
        t->thr[c] = lo;
    }
    t->thr[256] = UINT32_MAX;
    unsigned c = 0;
    for (uint32_t k = 0; k < (1u << (32 - SRGB8_RUN_SHIFT)); k++) {
        uint32_t b = k << SRGB8_RUN_SHIFT;
        while (c < 255 && b >= t->thr[c + 1]) c++;
        t->start[k] = (unsigned char)c;
    }
}

/* encode_code(v, 255) from the table (non-finite and negative values as
 * there: 0; sign bit set: 0). */
static unsigned srgb8_code(const srgb8_table *t, float v)
{
    if (!isfinite(v) || v <= 0.0f) return 0;
    uint32_t b = float_bits(v);
    unsigned c = t->start[b >> SRGB8_RUN_SHIFT];
    while (c < 255 && b >= t->thr[c + 1]) c++;
    return c;
}

/* Display-encoded value -> code: clamp to [0,1], round to nearest. */
static unsigned display_code(float v, double maxcode)
{
    if (!isfinite(v) || v <= 0.0f) return 0;
    if (v >= 1.0f) return (unsigned)maxcode;
    return (unsigned)floor((double)v * maxcode + 0.5);
}

static unsigned alpha_code(float v, double maxcode)
{
    if (!isfinite(v) || v <= 0.0f) return 0;
    if (v >= 1.0f) return (unsigned)maxcode;
    return (unsigned)floor((double)v * maxcode + 0.5);
}

static pt_status write_png(int fd, const char *name, const framebuffer *fb, const img_write_opts *o,
                           int encoded, img_png_tag tag, diag *d);

pt_status img_png_write(int fd, const char *name, const framebuffer *fb, const img_write_opts *o,
                        diag *d)
{
    return write_png(fd, name, fb, o, 0, IMG_PNG_TAG_SRGB, d);
}

pt_status img_png_write_display(int fd, const char *name, const framebuffer *fb, const img_write_opts *o,
                                img_png_tag tag, diag *d)
{
    return write_png(fd, name, fb, o, 1, tag, d);
}

/* `encoded`: fb holds display-encoded values (no transfer function here). */
static pt_status write_png(int fd, const char *name, const framebuffer *fb, const img_write_opts *o,
                           int encoded, img_png_tag tag, diag *d)
{
    png_ctx ctx = {fd, 0, {0}};
    const int bits = o && o->png_16bit ? 16 : 8;
    const int ch = fb->alpha ? 4 : 3;
    const double maxcode = bits == 16 ? 65535.0 : 255.0;
    const size_t rowbytes = (size_t)fb->width * (size_t)ch * (size_t)(bits / 8);
    /* volatile: freed on the longjmp path (C11 7.13.2.1) */
    unsigned char *volatile row = malloc(rowbytes);
    srgb8_table *volatile t8 = !encoded && bits == 8 ? malloc(sizeof(srgb8_table)) : NULL; /* NULL: encode_code per sample */
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &ctx, on_error, on_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!row || !png || !info) {
        if (png) png_destroy_write_struct(&png, info ? &info : NULL);
        free(t8);
        free(row);
        diag_error(d, "cannot write '%s': out of memory", name);
        return PT_ERR_NOMEM;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        free(t8);
        free(row);
        if (ctx.err)
            diag_error(d, "cannot write '%s': %s", name, strerror(ctx.err));
        else
            diag_error(d, "cannot write '%s': PNG error: %s", name, ctx.msg);
        return PT_ERR_IO;
    }
    png_set_write_fn(png, &ctx, on_write, on_flush);
    png_set_IHDR(png, info, (png_uint_32)fb->width, (png_uint_32)fb->height, bits,
                 ch == 4 ? PNG_COLOR_TYPE_RGB_ALPHA : PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    if (tag == IMG_PNG_TAG_SRGB) {
        /* sRGB chunk (perceptual rendering intent) plus the gAMA and cHRM
         * values the PNG spec (section 11.3.3.5) recommends alongside it. */
        png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    } else if (tag == IMG_PNG_TAG_REC1886) {
        /* BT.1886 with zero black level is a pure 2.4 power law: gAMA holds
         * the encoding exponent 1/2.4 (x 100000, PNG spec 11.3.3.2), cHRM the
         * BT.709-6 primaries and D65 white (x 100000, 11.3.3.1). No sRGB or
         * iCCP chunk. */
        png_set_gAMA_fixed(png, info, 41667);
        png_set_cHRM_fixed(png, info, 31270, 32900, 64000, 33000, 30000, 60000, 15000, 6000);
    }
    /* zlib level 3 and every row filtered by its left neighbour (Sub):
     * the image is written on one thread after the render, and libpng's
     * defaults (level 6, the best of five filters tried on each row) took
     * about as long as a small scene's rest of that thread's work, for a
     * file a few percent smaller */
    png_set_compression_level(png, 3);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
    png_write_info(png, info);
    srgb8_table *tab = t8;
    if (tab) srgb8_build(tab);
    for (int y = 0; y < fb->height; y++) {
        const float *src = fb->rgb + (size_t)y * (size_t)fb->width * 3u;
        const float *asrc = fb->alpha ? fb->alpha + (size_t)y * (size_t)fb->width : NULL;
        unsigned char *p = row;
        for (int x = 0; x < fb->width; x++) {
            unsigned codes[4];
            for (int k = 0; k < 3; k++)
                codes[k] = encoded ? display_code(src[x * 3 + k], maxcode)
                           : tab   ? srgb8_code(tab, src[x * 3 + k])
                                   : encode_code(src[x * 3 + k], maxcode);
            if (asrc) codes[3] = alpha_code(asrc[x], maxcode);
            for (int k = 0; k < ch; k++) {
                if (bits == 16) {
                    *p++ = (unsigned char)(codes[k] >> 8);
                    *p++ = (unsigned char)(codes[k] & 0xffu);
                } else {
                    *p++ = (unsigned char)codes[k];
                }
            }
        }
        png_write_row(png, row);
    }
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    free(t8);
    free(row);
    return PT_OK;
}

pt_status img_png_read(const char *path, int raw, uint64_t max_pixels, framebuffer **out, diag *d)
{
    *out = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) {
        diag_error(d, "cannot read '%s': %s", path, strerror(errno));
        return PT_ERR_IO;
    }
    char why[256];
    if (imgcheck_png(f, max_pixels, why, sizeof why)) {
        diag_error(d, "cannot read '%s': %s", path, why);
        fclose(f);
        return PT_ERR_IO;
    }
    png_ctx ctx = {-1, 0, {0}};
    png_structp png = png_create_read_struct_2(PNG_LIBPNG_VER_STRING, &ctx, on_error, on_warning, NULL, lib_malloc, lib_free);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!png || !info) {
        if (png) png_destroy_read_struct(&png, info ? &info : NULL, NULL);
        fclose(f);
        diag_error(d, "cannot read '%s': out of memory", path);
        return PT_ERR_NOMEM;
    }
    /* Assigned after setjmp and used after a longjmp: must be volatile
     * (C11 7.13.2.1p3). */
    unsigned char *volatile image = NULL;
    png_bytep *volatile rows = NULL;
    framebuffer *volatile fb = NULL;
    volatile pt_status fail = PT_ERR_IO;
    volatile int reported = 0;
    if (setjmp(png_jmpbuf(png))) {
        if (reported)
            ;
        else if (fail == PT_ERR_NOMEM)
            diag_error(d, "cannot read '%s': out of memory", path);
        else if (ctx.err)
            diag_error(d, "cannot read '%s': %s", path, strerror(ctx.err));
        else
            diag_error(d, "cannot read '%s': PNG error: %s", path, ctx.msg[0] ? ctx.msg : "unknown error");
        png_destroy_read_struct(&png, &info, NULL);
        free(image);
        free(rows);
        fb_free(fb);
        fclose(f);
        return fail;
    }
    png_set_read_fn(png, f, on_read);
    png_set_user_limits(png, IMG_MAX_SIDE, IMG_MAX_SIDE);
    png_read_info(png, info);

    png_uint_32 w, h;
    int bit_depth, color_type, interlace;
    png_get_IHDR(png, info, &w, &h, &bit_depth, &color_type, &interlace, NULL, NULL);
    if (imgcheck_size(w, h, max_pixels, why, sizeof why)) {
        diag_error(d, "cannot read '%s': %s", path, why);
        reported = 1;
        png_longjmp(png, 1);
    }
    /* Normalize everything to 8- or 16-bit RGB or RGBA. */
    if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
    if (color_type == PNG_COLOR_TYPE_GRAY && bit_depth < 8) png_set_expand_gray_1_2_4_to_8(png);
    if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
    if (color_type == PNG_COLOR_TYPE_GRAY || color_type == PNG_COLOR_TYPE_GRAY_ALPHA) png_set_gray_to_rgb(png);
    if (interlace != PNG_INTERLACE_NONE) png_set_interlace_handling(png);
    png_read_update_info(png, info);

    const int ch = png_get_channels(png, info);
    const int bits = png_get_bit_depth(png, info);
    const size_t rowbytes = png_get_rowbytes(png, info);
    if ((ch != 3 && ch != 4) || (bits != 8 && bits != 16) || rowbytes < (size_t)w * (size_t)ch * (size_t)(bits / 8)) {
        snprintf(ctx.msg, sizeof ctx.msg, "unexpected layout after transforms (%d channels, %d bits)", ch, bits);
        png_longjmp(png, 1);
    }
    fail = PT_ERR_NOMEM;
    image = malloc(rowbytes * (size_t)h);
    rows = malloc(sizeof(png_bytep) * (size_t)h);
    fb = fb_new((int)w, (int)h);
    if (!image || !rows || !fb) png_longjmp(png, 1);
    if (ch == 4) {
        fb->alpha = malloc(sizeof(float) * (size_t)w * (size_t)h);
        if (!fb->alpha) png_longjmp(png, 1);
    }
    fail = PT_ERR_IO;
    for (png_uint_32 y = 0; y < h; y++) rows[y] = image + (size_t)y * rowbytes;
    png_read_image(png, rows);
    png_read_end(png, NULL); /* also catches a file cut after the image data */

    const double maxcode = bits == 16 ? 65535.0 : 255.0;
    float lut8[256];
    if (bits == 8)
        for (int i = 0; i < 256; i++) lut8[i] = raw ? (float)(i / 255.0) : (float)img_srgb_decode(i / 255.0);
    for (png_uint_32 y = 0; y < h; y++) {
        const unsigned char *p = rows[y];
        float *dst = fb_px(fb, 0, (int)y);
        float *adst = fb->alpha ? fb->alpha + (size_t)y * (size_t)w : NULL;
        for (png_uint_32 x = 0; x < w; x++) {
            for (int k = 0; k < ch; k++) {
                unsigned code;
                if (bits == 16) {
                    code = (unsigned)p[0] << 8 | p[1];
                    p += 2;
                } else {
                    code = *p++;
                }
                if (k == 3)
                    adst[x] = (float)(code / maxcode);
                else if (bits == 8)
                    dst[x * 3 + (png_uint_32)k] = lut8[code];
                else
                    dst[x * 3 + (png_uint_32)k] = (float)(raw ? code / maxcode : img_srgb_decode(code / maxcode));
            }
        }
    }
    png_destroy_read_struct(&png, &info, NULL);
    free(image);
    free(rows);
    fclose(f);
    *out = fb;
    return PT_OK;
}
