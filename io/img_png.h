/* img_png.h - PNG files through libpng. */
#ifndef PT_IMG_PNG_H
#define PT_IMG_PNG_H
#include "img_io.h"

/* Write `fb` as 8-bit (default) or 16-bit (o->png_16bit) RGB, RGBA when
 * fb->alpha is set, to the open file `fd` (the caller closes it). Colour
 * values are encoded with img_srgb_encode, clamped to [0,1] and rounded to
 * the nearest code (0.5 -> 188 in 8 bits); non-finite values become 0.
 * Alpha is stored linearly (straight, clamped). An sRGB chunk (perceptual
 * intent, with gAMA/cHRM fallbacks) is written. `name` is for messages. */
pt_status img_png_write(int fd, const char *name, const framebuffer *fb, const img_write_opts *o,
                        diag *d);

/* Read any PNG (1-16 bit grey, grey+alpha, RGB, RGBA, palette; interlaced or
 * not). Colour codes are decoded with img_srgb_decode unless `raw`, then
 * values are code/max. Alpha (incl. tRNS) goes to fb->alpha as code/max. */
pt_status img_png_read(const char *path, int raw, framebuffer **out, diag *d);

#endif
