/* img_io.h - image files: EXR (OpenEXRCore C API), PNG (libpng), PFM.
 * Writers go to a temporary name in the same directory and rename on
 * success, so a failed write never leaves a partial file under the final name. */
#ifndef PT_IMG_IO_H
#define PT_IMG_IO_H
#include "diag.h"
#include "framebuffer.h"

/* Readers refuse images larger than this (a guard against corrupt headers);
 * writers refuse framebuffers beyond it too. */
#define IMG_MAX_SIDE 65536
#define IMG_MAX_PIXELS (1ull << 28)

typedef enum { IMG_FMT_UNKNOWN, IMG_FMT_EXR, IMG_FMT_PNG, IMG_FMT_PFM } img_format;

typedef struct {
    int exr_float;        /* 1 = 32-bit float channels, 0 = half (default) */
    int exr_compression;  /* 0 none, 1 zip (default), 2 piz */
    int png_16bit;        /* 1 = 16 bits per channel */
    /* key/value string metadata for EXR headers (scene file, GI mode, times). */
    const char *const *meta_keys;
    const char *const *meta_values;
    int nmeta;
} img_write_opts;

void img_default_write_opts(img_write_opts *o);
img_format img_format_from_path(const char *path);
/* PNG: linear values are encoded with the sRGB transfer function (IEC 61966-2-1). */
pt_status img_write(const char *path, const framebuffer *fb, const img_write_opts *o, diag *d);
/* Reads EXR (R,G,B channels, half or float), PFM, PNG (8/16 bit; sRGB decoded
 * to linear unless `png_raw` is set, then values are code/max). */
pt_status img_read(const char *path, int png_raw, framebuffer **out, diag *d);

/* sRGB transfer functions (IEC 61966-2-1). */
double img_srgb_encode(double linear);
double img_srgb_decode(double encoded);

#endif
