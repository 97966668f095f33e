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

/* Colour chunks of a PNG holding display-encoded values. */
typedef enum {
    IMG_PNG_TAG_SRGB,    /* sRGB chunk (+ the gAMA/cHRM fallbacks): an sRGB display */
    IMG_PNG_TAG_REC1886, /* gAMA 1/2.4 and Rec.709/D65 cHRM, no sRGB chunk: a BT.1886 display */
    IMG_PNG_TAG_NONE     /* no colour chunks (data, or a display we cannot describe) */
} img_png_tag;

/* As img_png_write for values already encoded for a display (e.g. by
 * img_ocio_apply): codes are the values clamped to [0,1] and rounded, with
 * no transfer function applied; colour chunks as `tag` says. */
pt_status img_png_write_display(int fd, const char *name, const framebuffer *fb, const img_write_opts *o,
                                img_png_tag tag, diag *d);

/* Read any PNG (1-16 bit grey, grey+alpha, RGB, RGBA, palette; interlaced or
 * not). Colour codes are decoded with img_srgb_decode unless `raw`, then
 * values are code/max. Alpha (incl. tRNS) goes to fb->alpha as code/max. */
/* At most max_pixels pixels (img_read_limited); the file is checked by
 * imgcheck_png before anything is allocated for its pixels. */
pt_status img_png_read(const char *path, int raw, uint64_t max_pixels, framebuffer **out, diag *d);

#endif
