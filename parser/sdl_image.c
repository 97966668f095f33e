/* sdl_image.c - image_map images (sdl_image.h).
 *
 * POV-Ray 3.7's rules for a PNG read for image_map (its png.cpp, studied):
 * a `gamma` given in the scene overrides the file; else an sRGB chunk means
 * the sRGB curve; else a gAMA chunk gives a power law (decoded value =
 * code^(1/gAMA)); else sRGB is assumed (the PNG/W3C recommendation). The
 * working space is linear (assumed_gamma 1.0). Alpha is straight; transmit
 * = 1 - alpha, filter 0. */
#include "sdl_image.h"
#include <math.h>
#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define IMG_MAX_SIDE 65536
#define IMG_MAX_PIXELS (1ull << 28)

static double srgb_decode(double v) { return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4); }

/* The palette indices of a palette PNG (for material_map), or NULL. */
static unsigned char *read_indices(const char *path, arena *mem, int w, int h)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    unsigned char *idx = NULL;
    png_bytep *rows = NULL;
    if (!png || !info) {
        png_destroy_read_struct(&png, &info, NULL);
        fclose(f);
        return NULL;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_read_struct(&png, &info, NULL);
        fclose(f);
        free(rows);
        return NULL;
    }
    png_init_io(png, f);
    png_read_info(png, info);
    if (png_get_color_type(png, info) != PNG_COLOR_TYPE_PALETTE || (int)png_get_image_width(png, info) != w ||
        (int)png_get_image_height(png, info) != h)
        png_error(png, "not a palette image");
    png_set_packing(png);
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
    idx = arena_alloc(mem, (size_t)w * h);
    rows = malloc(sizeof *rows * (size_t)h);
    if (!idx || !rows) png_error(png, "memory");
    for (int y = 0; y < h; y++) rows[y] = idx + (size_t)y * w;
    png_read_image(png, rows);
    png_destroy_read_struct(&png, &info, NULL);
    fclose(f);
    free(rows);
    return idx;
}

int sdl_image_load(scene_image *img, arena *mem, double working_gamma, char *why, size_t whycap)
{
    FILE *f = fopen(img->path, "rb");
    if (!f) {
        snprintf(why, whycap, "cannot open '%s'", img->path);
        return 1;
    }
    unsigned char sig[8];
    if (fread(sig, 1, 8, f) != 8 || png_sig_cmp(sig, 0, 8) != 0) {
        fclose(f);
        snprintf(why, whycap, "'%s' is not a PNG file (only PNG images are read)", img->path);
        return 1;
    }
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    unsigned short *buf = NULL;
    png_bytep *rows = NULL;
    float *px = NULL, *lut = NULL;
    if (!png || !info) {
        png_destroy_read_struct(&png, &info, NULL);
        fclose(f);
        snprintf(why, whycap, "out of memory");
        return 1;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_read_struct(&png, &info, NULL);
        fclose(f);
        free(buf);
        free(rows);
        free(lut);
        snprintf(why, whycap, "'%s' is not a readable PNG file", img->path);
        return 1;
    }
    png_init_io(png, f);
    png_set_sig_bytes(png, 8);
    png_read_info(png, info);
    png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
    if (w == 0 || h == 0 || w > IMG_MAX_SIDE || h > IMG_MAX_SIDE || (unsigned long long)w * h > IMG_MAX_PIXELS)
        png_error(png, "size");
    /* the decoding curve, from the scene or the file */
    int curve = 0; /* 0 sRGB, 1 power law */
    double exponent = 1.0;
    if (img->gamma > 0.0) {
        curve = 1;
        exponent = img->gamma;
    } else if (img->gamma < 0.0 || png_get_valid(png, info, PNG_INFO_sRGB)) {
        curve = 0;
    } else if (png_get_valid(png, info, PNG_INFO_gAMA)) {
        double fg = 1.0 / 2.2;
        png_get_gAMA(png, info, &fg);
        curve = 1;
        exponent = fg > 0.0 ? 1.0 / fg : 2.2;
    }
    int ct = png_get_color_type(png, info);
    int palette = ct == PNG_COLOR_TYPE_PALETTE;
    img->has_alpha = (ct & PNG_COLOR_MASK_ALPHA) || png_get_valid(png, info, PNG_INFO_tRNS);
    png_set_expand(png);
    png_set_expand_16(png);
    png_set_gray_to_rgb(png);
    png_set_add_alpha(png, 0xffff, PNG_FILLER_AFTER);
    png_set_swap(png);
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
    if (png_get_rowbytes(png, info) != (size_t)w * 8) png_error(png, "layout");
    buf = malloc((size_t)w * h * 8);
    rows = malloc(sizeof *rows * h);
    px = arena_alloc(mem, sizeof *px * (size_t)w * h * 5);
    lut = malloc(sizeof *lut * 65536);
    if (!buf || !rows || !px || !lut) png_error(png, "memory");
    for (png_uint_32 y = 0; y < h; y++) rows[y] = (png_bytep)(buf + (size_t)y * w * 4);
    png_read_image(png, rows);
    png_read_end(png, NULL);
    png_destroy_read_struct(&png, &info, NULL);
    fclose(f);
    for (int i = 0; i < 65536; i++) {
        double v = i / 65535.0;
        double lin = curve == 0 ? srgb_decode(v) : pow(v, exponent);
        if (working_gamma == 0.0) {
            if (img->gamma == 0.0) lin = v; /* gamma handling off: the codes as they are */
        } else if (working_gamma != 1.0) {
            lin = pow(lin, 1.0 / working_gamma);
        }
        lut[i] = (float)lin;
    }
    for (size_t i = 0; i < (size_t)w * h; i++) {
        const unsigned short *s = buf + i * 4;
        float *d = px + i * 5;
        d[0] = lut[s[0]];
        d[1] = lut[s[1]];
        d[2] = lut[s[2]];
        d[3] = 0.0f;
        d[4] = 1.0f - s[3] / 65535.0f;
    }
    free(buf);
    free(rows);
    free(lut);
    img->width = (int)w;
    img->height = (int)h;
    img->pixels = px;
    if (palette) img->indices = read_indices(img->path, mem, (int)w, (int)h);
    return 0;
}
