/* sdl_image.c - image_map images (sdl_image.h), decoded by the one image
 * reader (sdl_imgread.h: PNG, GIF, TGA, PGM/PPM, JPEG, TIFF).
 *
 * POV-Ray 3.7's rules for a PNG read for image_map (its png.cpp, studied):
 * a `gamma` given in the scene overrides the file; else an sRGB chunk means
 * the sRGB curve; else a gAMA chunk gives a power law (decoded value =
 * code^(1/gAMA)); else sRGB is assumed (the PNG/W3C recommendation). The
 * working space is linear (assumed_gamma 1.0). Alpha is straight; transmit
 * = 1 - alpha, filter 0. */
#include "sdl_image.h"
#include "sdl_imgread.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

double sdl_srgb_decode(double v) { return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4); }

int sdl_image_load(scene_image *img, arena *mem, double working_gamma, unsigned long long max_pixels, char *why,
                   size_t whycap)
{
    int legacy = working_gamma < 0.0; /* pre-3.7 scene with assumed_gamma (sdl_image.h) */
    if (legacy) working_gamma = -working_gamma;
    sdl_img raw;
    int r = sdl_img_read(img->path, NULL, 0, max_pixels, &raw, why, whycap);
    if (r != SDL_IMG_OK) {
        char reason[256];
        snprintf(reason, sizeof reason, "%s", why);
        snprintf(why, whycap, "'%s': %s", img->path, reason);
        return 1;
    }
    size_t w = (size_t)raw.width, h = (size_t)raw.height;
    /* the decoding curve, from the scene or the file; formats without
     * gamma information are taken as sRGB, as PNGs without chunks */
    int curve = 0; /* 0 sRGB, 1 power law */
    double exponent = 1.0;
    if (img->gamma > 0.0) {
        curve = 1;
        exponent = img->gamma;
    } else if (img->gamma < 0.0 || raw.png_srgb) {
        curve = 0;
    } else if (raw.png_gamma > 0.0) {
        curve = 1;
        exponent = 1.0 / raw.png_gamma;
    }
    int stated = img->gamma != 0.0 || raw.png_srgb || raw.png_gamma > 0.0;
    img->has_alpha = raw.has_alpha;
    float *px = arena_alloc(mem, sizeof *px * w * h * 5);
    float *lut = malloc(sizeof *lut * 65536);
    unsigned char *idx = raw.index && raw.colour == SDL_IMG_PALETTE ? arena_alloc(mem, w * h) : NULL;
    if (!px || !lut || (raw.index && raw.colour == SDL_IMG_PALETTE && !idx)) {
        free(lut);
        sdl_img_free(&raw);
        snprintf(why, whycap, "out of memory");
        return 1;
    }
    for (int i = 0; i < 65536; i++) {
        double v = i / 65535.0;
        double lin = curve == 0 ? sdl_srgb_decode(v) : pow(v, exponent);
        if (legacy && !stated) {
            lin = v; /* decoded with the working gamma into the working space: the codes */
        } else if (working_gamma == 0.0) {
            if (img->gamma == 0.0) lin = v; /* gamma handling off: the codes as they are */
        } else if (working_gamma != 1.0) {
            lin = pow(lin, 1.0 / working_gamma);
        }
        lut[i] = (float)lin;
    }
    for (size_t i = 0; i < w * h; i++) {
        const unsigned short *s = raw.rgba + i * 4;
        float *d = px + i * 5;
        d[0] = lut[s[0]];
        d[1] = lut[s[1]];
        d[2] = lut[s[2]];
        d[3] = 0.0f;
        d[4] = 1.0f - s[3] / 65535.0f;
    }
    if (idx) memcpy(idx, raw.index, w * h);
    free(lut);
    sdl_img_free(&raw);
    img->width = (int)w;
    img->height = (int)h;
    img->pixels = px;
    if (idx) img->indices = idx;
    sdl_image_note_clear(img);
    return 0;
}

void sdl_image_note_clear(scene_image *img)
{
    size_t n = img->pixels ? (size_t)img->width * (size_t)img->height : 0;
    img->clear = 0;
    for (size_t i = 0; i < n && !img->clear; i++)
        img->clear = img->pixels[i * 5 + 3] != 0.0f || img->pixels[i * 5 + 4] != 0.0f;
}
