/* img_io.h - image files: EXR (OpenEXRCore C API), PNG (libpng), PFM.
 * Writers go to a temporary name in the same directory and rename on
 * success, so a failed write never leaves a partial file under the final name. */
#ifndef PT_IMG_IO_H
#define PT_IMG_IO_H
#include <stdint.h>
#include "diag.h"
#include "framebuffer.h"
#include "imgcheck.h"

/* Readers refuse images larger than this (a guard against corrupt headers);
 * writers refuse framebuffers beyond it too. img_read_limited lowers the
 * pixel limit. */
#define IMG_MAX_SIDE IMGCHECK_MAX_SIDE
#define IMG_MAX_PIXELS IMGCHECK_MAX_PIXELS

typedef enum { IMG_FMT_UNKNOWN, IMG_FMT_EXR, IMG_FMT_PNG, IMG_FMT_PFM } img_format;

/* An extra EXR layer (an AOV): channels "name.<letter>" beside the beauty's
 * R,G,B in the same part, as OpenEXR's layer naming convention has it. */
typedef struct {
    const char *name;      /* layer name, e.g. "direct" */
    const char *suffixes;  /* one letter per channel: "RGB", "XYZ", "Z"... (1 to 4) */
    const float *data;     /* width*height*strlen(suffixes) floats, interleaved, row 0 at the top */
    int colour;            /* 1: RGB in the beauty's colour space, converted into the working space with it */
    int full_float;        /* 1: 32-bit float channels even when the beauty is half (depth) */
} img_layer;

typedef struct {
    int exr_float;        /* 1 = 32-bit float channels, 0 = half (default) */
    int exr_compression;  /* 0 none, 1 zip (default), 2 piz */
    int png_16bit;        /* 1 = 16 bits per channel */
    /* key/value string metadata for EXR headers (scene file, GI mode, times). */
    const char *const *meta_keys;
    const char *const *meta_values;
    int nmeta;

    /* Colour management through OpenColorIO (io/img_ocio.h). With all of
     * these NULL/0 (the default) no OCIO config is loaded: a PNG is the plain
     * sRGB encoding of the linear values (as POV-Ray writes it) and an EXR
     * holds the values as given, tagged with Rec.709 chromaticities. */
    struct img_ocio *ocio;     /* an open config to use; NULL = open ocio_config */
    const char *ocio_config;   /* config file; NULL = $OCIO if set, else the built-in one */
    const char *fb_space;      /* colour space of fb's values; NULL = "Linear Rec.709 (sRGB)" */
    /* EXR: the scene-linear space written; fb is converted into it and the
     * chromaticities attribute describes it. NULL = fb_space. */
    const char *working_space;
    /* PNG: any of display/view/look set = encode through OCIO's
     * DisplayViewTransform (NULL display/view = the config's defaults:
     * sRGB / Standard), with colour chunks for that display: sRGB display
     * -> sRGB chunk; Rec.1886 -> gAMA 1/2.4 + Rec.709 cHRM; Raw view or an
     * unrecognised display -> none. Ignored for EXR and PFM. */
    const char *display, *view, *look;
    double exposure;           /* PNG only: values x 2^exposure before the view or the sRGB encoding */
    /* EXR only (lighting studies). */
    const img_layer *layers;   /* extra layers of the same size as fb (AOVs); ignored by PNG and PFM */
    int nlayers;
    double white_luminance;    /* > 0: the standard `whiteLuminance` attribute, cd/m^2 of RGB (1,1,1) */
    /* EXR only: a tile. x0,y0,x1,y1 (x1,y1 exclusive) of fb written as the
     * data window, fb's whole size as the display window; all 0 = all of fb. */
    int window[4];
} img_write_opts;

void img_default_write_opts(img_write_opts *o);
img_format img_format_from_path(const char *path);
/* PNG: linear values are encoded with the sRGB transfer function (IEC 61966-2-1)
 * unless a display/view/look is set (see img_write_opts). PFM: values as given.
 * Colour-management name errors are PT_ERR_USAGE, found before any file is made. */
pt_status img_write(const char *path, const framebuffer *fb, const img_write_opts *o, diag *d);
/* Reads EXR (R,G,B channels, half or float), PFM, PNG (8/16 bit; sRGB decoded
 * to linear unless `png_raw` is set, then values are code/max). */
pt_status img_read(const char *path, int png_raw, framebuffer **out, diag *d);
/* img_read with at most max_pixels pixels (0 = IMG_MAX_PIXELS; never more).
 * Every reader checks the declared size against it, and that the file can
 * hold that many pixels (PNG: enough compressed data, core/imgcheck.h; EXR:
 * every chunk of the offset table inside the file; PFM: the pixel bytes),
 * before the framebuffer is allocated: a corrupt or truncated file that
 * declares a huge image is a PT_ERR_IO error naming the reason. */
pt_status img_read_limited(const char *path, int png_raw, uint64_t max_pixels, framebuffer **out, diag *d);
/* Reads the channels "layer.<letter>" of an EXR's part 0 for each letter of
 * `suffixes` (e.g. "direct", "RGB"; layer NULL or "" = the unprefixed
 * channels) into *out: width*height*strlen(suffixes) interleaved floats
 * (malloc'd). PT_ERR_IO when a channel is missing or the file unreadable. */
pt_status img_read_exr_layer(const char *path, const char *layer, const char *suffixes, float **out, int *width,
                             int *height, diag *d);

/* sRGB transfer functions (IEC 61966-2-1). */
double img_srgb_encode(double linear);
double img_srgb_decode(double encoded);

#endif
