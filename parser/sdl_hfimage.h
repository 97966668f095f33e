/* sdl_hfimage.h - height_field images, decoded by the one image reader
 * (sdl_imgread.h: PNG, GIF, TGA, PGM/PPM, JPEG, TIFF; POT = a GIF named
 * .pot) and read into POV-Ray's 16-bit heights (its image_height_at; POT:
 * index of the left half * 256 + index of the right half): greyscale value
 * * 65535, palette index * 256, 8-bit colour red * 256 + green (the "high
 * byte / low byte" convention), 16-bit colour the grey value 0.297 r +
 * 0.589 g + 0.114 b times 65535. Other formats (IFF, EXR, HDR, BMP, sys)
 * are reported as unsupported. */
#ifndef PT_SDL_HFIMAGE_H
#define PT_SDL_HFIMAGE_H
#include <stddef.h>

enum { SDL_HF_OK = 0, SDL_HF_ERROR = 1, SDL_HF_UNSUPPORTED = 2 };

typedef struct {
    int width, height;
    unsigned short *values; /* malloc'd, width * height, row 0 = top of the image */
} sdl_hf_image;

/* SDL_HF_OK, or an error / unsupported format with a reason in `why`. */
int sdl_hf_read(const char *path, unsigned long long max_pixels, sdl_hf_image *out, char *why, size_t whycap);

#endif
