/* sdl_hfimage.c - height_field images (sdl_hfimage.h): decoded by the one
 * image reader (sdl_imgread.h), then turned into POV-Ray's 16-bit heights. */
#include "sdl_hfimage.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "sdl_imgread.h"

static unsigned short grey16(double r, double g, double b)
{
    double v = (0.297 * r + 0.589 * g + 0.114 * b) * 65535.0;
    return (unsigned short)(v < 0 ? 0 : (v > 65535.0 ? 65535.0 : v));
}

static int is_pot_name(const char *path)
{
    size_t len = path ? strlen(path) : 0;
    return len > 4 && (strcmp(path + len - 4, ".pot") == 0 || strcmp(path + len - 4, ".POT") == 0);
}

int sdl_hf_read(const char *path, unsigned long long max_pixels, sdl_hf_image *out, char *why, size_t whycap)
{
    memset(out, 0, sizeof *out);
    sdl_img img;
    int r = sdl_img_read(path, NULL, 0, max_pixels, &img, why, whycap);
    if (r != SDL_IMG_OK) return r == SDL_IMG_UNSUPPORTED ? SDL_HF_UNSUPPORTED : SDL_HF_ERROR;
    /* POT (Fractint continuous potential): a GIF whose right half holds each
     * pixel's low byte (POV-Ray's gif.cpp) */
    int pot = img.format == SDL_IMGF_GIF && is_pot_name(path);
    if (pot && (img.width & 1)) {
        sdl_img_free(&img);
        snprintf(why, whycap, "POT image of odd width");
        return SDL_HF_ERROR;
    }
    int w = pot ? img.width / 2 : img.width, h = img.height;
    out->values = malloc(sizeof *out->values * (size_t)w * (size_t)h);
    if (!out->values) {
        sdl_img_free(&img);
        snprintf(why, whycap, "out of memory");
        return SDL_HF_ERROR;
    }
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * img.width + x;
            const unsigned short *s = img.rgba + i * 4;
            unsigned short v;
            if (pot) v = (unsigned short)(img.index[i] << 8 | img.index[i + (size_t)w]);
            else if (img.colour == SDL_IMG_PALETTE && img.index) v = (unsigned short)(img.index[i] * 256u);
            else if (img.colour == SDL_IMG_GREY) v = s[0];
            else if (img.depth16) v = grey16(s[0] / 65535.0, s[1] / 65535.0, s[2] / 65535.0);
            else v = (unsigned short)((s[0] / 257u) * 256u + s[1] / 257u);
            out->values[(size_t)y * w + x] = v;
        }
    sdl_img_free(&img);
    out->width = w;
    out->height = h;
    return SDL_HF_OK;
}
