/* img_ocio.h - colour management through OpenColorIO 2.1 (C interface to the
 * one C++ file of the project, io/img_ocio.cpp; no C++ exception ever
 * crosses it: every failure is a pt_status plus a message in `d`).
 *
 * The config is io/ocio/config.ocio, compiled into the binary. It has the
 * scene-linear spaces "Linear Rec.709 (sRGB)" (what partray renders in),
 * "ACEScg", "ACES2065-1", "ACEScct", the displays "sRGB" and "Rec.1886" with
 * the views "Standard" (inverse display EOTF, no tone mapping), "ACES" (the
 * ACES 1.0 SDR video output transform) and "Raw", and the look
 * "ACES Gamut Compression".
 *
 * Name errors (unknown colour space, display, view, look) are PT_ERR_USAGE
 * with a message that lists the valid names. OCIO's own log messages are
 * turned into warnings in `d`; nothing here prints. */
#ifndef PT_IMG_OCIO_H
#define PT_IMG_OCIO_H
#ifdef __cplusplus
extern "C" { /* diag.h and framebuffer.h are C headers without guards */
#endif
#include "diag.h"
#include "framebuffer.h"

/* The colour space partray renders in (the framebuffer's values). */
#define IMG_OCIO_RENDER_SPACE "Linear Rec.709 (sRGB)"
/* A config_path that asks for the built-in config even when $OCIO is set. */
#define IMG_OCIO_BUILTIN "builtin:"

typedef struct img_ocio img_ocio;

/* Open a config: `config_path` when given (non-NULL, non-empty; the
 * --ocio-config option), else the file named by $OCIO when set and
 * non-empty, else the built-in config. The config is validated.
 * Errors: file unreadable -> PT_ERR_IO; not a valid config -> PT_ERR_USAGE. */
pt_status img_ocio_open(const char *config_path, img_ocio **out, diag *d);
void img_ocio_close(img_ocio *o);

/* "built-in", or the path of the file the config came from. */
const char *img_ocio_source(const img_ocio *o);
/* The text of the built-in config (NUL-terminated). */
const char *img_ocio_builtin_config(void);

/* Active displays, views of a display, active colour spaces and looks.
 * Returned names live as long as `o`; index out of range -> NULL. */
int img_ocio_display_count(const img_ocio *o);
const char *img_ocio_display_name(const img_ocio *o, int i);
const char *img_ocio_default_display(const img_ocio *o);
int img_ocio_view_count(const img_ocio *o, const char *display);
const char *img_ocio_view_name(const img_ocio *o, const char *display, int i);
const char *img_ocio_default_view(const img_ocio *o, const char *display);
int img_ocio_space_count(const img_ocio *o);
const char *img_ocio_space_name(const img_ocio *o, int i);
int img_ocio_look_count(const img_ocio *o);
const char *img_ocio_look_name(const img_ocio *o, int i);

/* Check names without converting anything (for the command line, before a
 * render). NULL arguments are not checked; view is checked against
 * `display` (NULL = the default display). `look` may list several looks
 * separated by commas, each optionally prefixed by + or -. */
pt_status img_ocio_check(const img_ocio *o, const char *space, const char *display, const char *view,
                         const char *look, diag *d);

/* Convert fb (RGB only; alpha untouched) in place from scene-linear values in
 * `space` (NULL = IMG_OCIO_RENDER_SPACE) to display-encoded values through
 * `display` (NULL = default display) and `view` (NULL = that display's
 * default view), with the looks `look` (NULL/"" = none) applied in their
 * process spaces first, and the values first multiplied by 2^exposure_stops.
 * Display values are in [0,1] for in-gamut input; nothing is clamped here. */
pt_status img_ocio_apply(img_ocio *o, framebuffer *fb, const char *space, const char *display, const char *view,
                         const char *look, double exposure_stops, diag *d);

/* Convert fb's RGB in place between two colour spaces of the config. */
pt_status img_ocio_convert(img_ocio *o, framebuffer *fb, const char *src_space, const char *dst_space, diag *d);

/* CIE 1931 xy of the red, green, blue primaries and the white point of a
 * scene-linear colour space, in the order of the EXR `chromaticities`
 * attribute (rx ry gx gy bx by wx wy). Linear Rec.709 (sRGB), ACEScg and
 * ACES2065-1 (found by name or alias, also through roles) come from the
 * published values (see img_exr.c). For any other space they are measured by
 * converting unit R, G, B and R=G=B=1 to the config's
 * cie_xyz_d65_interchange role, so they describe the space as adapted to
 * D65. Returns 1 on success, 0 when they cannot be determined (no such role,
 * or a degenerate result); `d` then gets a warning. */
int img_ocio_chromaticities(img_ocio *o, const char *space, float xy[8], diag *d);

/* What a display/view pair produces, for the tags of a PNG file. */
typedef enum {
    IMG_DISPLAY_SRGB,    /* IEC 61966-2-1: sRGB chunk */
    IMG_DISPLAY_REC1886, /* gamma 2.4, Rec.709 primaries: gAMA + cHRM */
    IMG_DISPLAY_DATA,    /* data (the Raw view): no colour chunks */
    IMG_DISPLAY_OTHER    /* not recognised: no colour chunks */
} img_display_kind;

/* Classify by the view's colour space: data -> DATA; otherwise by the name of
 * the display colour space or the display ("sRGB", "1886"). NULL = defaults. */
img_display_kind img_ocio_display_kind(const img_ocio *o, const char *display, const char *view);

#ifdef __cplusplus
}
#endif
#endif
