/* sdl_imgread.h - the one image reader of the scene language: image_map,
 * image_pattern and friends (sdl_image.c) and height_field (sdl_hfimage.c)
 * decode through sdl_img_read.
 *
 * Formats, recognised by content (never by name): PNG (libpng), GIF
 * (giflib, first image), TGA (own decoder: types 1, 2, 3 and their RLE
 * forms 9, 10, 11), PGM/PPM (P2, P3, P5, P6, 8 or 16 bit), JPEG (libjpeg)
 * and TIFF (libtiff). Declared sizes are checked before anything is
 * allocated for pixels (at most SDL_IMG_MAX_SIDE a side and
 * SDL_IMG_MAX_PIXELS in all; uncompressed data must fit in the bytes
 * given), so a small file cannot make the reader allocate much. */
#ifndef PT_SDL_IMGREAD_H
#define PT_SDL_IMGREAD_H
#include <stddef.h>

#define SDL_IMG_MAX_SIDE 65536
#define SDL_IMG_MAX_PIXELS (1ull << 28)
#define SDL_IMG_MAX_FILE (1ull << 30) /* bytes read from a path */

enum { SDL_IMG_OK = 0, SDL_IMG_ERROR = 1, SDL_IMG_UNSUPPORTED = 2 };

typedef enum { SDL_IMGF_PNG, SDL_IMGF_GIF, SDL_IMGF_TGA, SDL_IMGF_PNM, SDL_IMGF_JPEG, SDL_IMGF_TIFF } sdl_img_format;
typedef enum { SDL_IMG_GREY, SDL_IMG_PALETTE, SDL_IMG_RGB } sdl_img_colour;

typedef struct {
    int width, height;
    sdl_img_format format;
    sdl_img_colour colour;  /* what the file stores */
    int depth16;            /* the file's samples had more than 8 bits */
    int has_alpha;          /* alpha channel or transparent palette entries / colour key */
    unsigned short *rgba;   /* width * height * 4 samples 0..65535 (codes as stored,
                               no gamma applied), row 0 = top of the image */
    unsigned char *index;   /* palette images: width * height indices, else NULL */
    int png_srgb;           /* PNG: sRGB chunk present */
    double png_gamma;       /* PNG: gAMA value (file gamma, e.g. 0.45455), 0 when absent */
} sdl_img;

/* Decode `bytes` (n of them) when bytes is not NULL, else the file at
 * `path`, refusing images of more than max_pixels pixels (0 or more than
 * SDL_IMG_MAX_PIXELS: SDL_IMG_MAX_PIXELS; --max-image-pixels). SDL_IMG_OK and a filled `out` (free with sdl_img_free), or
 * SDL_IMG_ERROR / SDL_IMG_UNSUPPORTED with a reason in `why`; on failure
 * `out` holds nothing to free. */
int sdl_img_read(const char *path, const unsigned char *bytes, size_t n, unsigned long long max_pixels, sdl_img *out,
                 char *why, size_t whycap);
void sdl_img_free(sdl_img *img);

#endif
