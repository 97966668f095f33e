/* img_exr.h - OpenEXR files through the OpenEXRCore C API. */
#ifndef PT_IMG_EXR_H
#define PT_IMG_EXR_H
#include "img_io.h"

/* Colour primaries written to the `chromaticities` header attribute.
 * img_write uses REC709 (= sRGB primaries, D65 white) unless
 * img_write_opts.working_space names another space; then the values come
 * from img_ocio_chromaticities (which uses this table for the ACES spaces). */
typedef enum { IMG_PRIMARIES_REC709 = 0, IMG_PRIMARIES_ACESCG, IMG_PRIMARIES_ACES2065_1 } img_primaries;

/* The chromaticities of `prim` as rx ry gx gy bx by wx wy (CIE 1931 xy). */
void img_exr_primaries(img_primaries prim, float xy[8]);

/* Write `fb` as a single-part scanline EXR to the open file `fd` (positioned
 * writes; the caller closes it). `name` is only used in messages. Channels
 * R,G,B (+A when fb->alpha) as half (default) or float (o->exr_float),
 * then the channels "name.X" of every layer in o->layers (AOVs; float when
 * the layer asks for it), and whiteLuminance when o->white_luminance > 0;
 * non-finite values are written as 0 and, for half channels, finite values
 * are clamped to +-65504 (the largest half) so no Inf ever reaches the file.
 * xy: the chromaticities as rx ry gx gy bx by wx wy (img_exr_primaries);
 * NULL writes no chromaticities attribute. */
pt_status img_exr_write_xy(int fd, const char *name, const framebuffer *fb, const img_write_opts *o,
                           const float *xy, diag *d);

/* Read part 0 of a scanline or tiled EXR (level 0 of a mip/rip-mapped file).
 * R,G,B (half/float/uint, missing ones are 0) or, without any of those, Y as
 * grey; A into fb->alpha when present. The data window becomes the image. */
/* At most max_pixels pixels (img_read_limited). */
pt_status img_exr_read(const char *path, uint64_t max_pixels, framebuffer **out, diag *d);

/* The header of part 0 of an EXR file: the display window's size, the
 * data window (x0,y0,x1,y1 with x1,y1 exclusive, in display coordinates)
 * and the string attributes named in keys (vals[i] malloc'd, NULL when the
 * file has none of that name). PT_ERR_IO when unreadable. */
pt_status img_exr_info(const char *path, int *disp_w, int *disp_h, int win[4], const char *const *keys, int nkeys,
                       char **vals, diag *d);
#endif
