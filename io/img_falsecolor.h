/* img_falsecolor.h - false-colour maps of luminance or illuminance for
 * lighting studies: a log-scale colour ramp, a legend with values, and the
 * inverse (a colour read from the image back to a value).
 *
 * This module maps numbers it is given; where the numbers come from is the
 * caller's business. For a rendered image, img_fc_luminance gives
 * Y = 0.2126 R + 0.7152 G + 0.0722 B (the Y row of the BT.709 / sRGB
 * RGB->XYZ matrix, for linear Rec.709 values) times a scale: with the scene's
 * light units known (e.g. a point light of colour 1 emitting I1 candela, and
 * lengths in metres) that scale turns the renderer's relative radiance into
 * cd/m^2. Illuminance on a white Lambertian surface of reflectance rho
 * follows as E = pi * L / rho (lux), or is rendered directly as irradiance.
 *
 * The ramp runs through dark blue, blue, cyan, green, yellow, orange, red and
 * pink (its colours are display sRGB values, chosen for this project); the
 * value range [lo, hi] is spread over it on a log10 scale, so every decade
 * gets the same length of ramp. Values at or below 0 (and NaN) are black,
 * which is not on the ramp. */
#ifndef PT_IMG_FALSECOLOR_H
#define PT_IMG_FALSECOLOR_H
#include <stddef.h>

#include "diag.h"
#include "framebuffer.h"

typedef struct {
    double lo, hi;    /* values mapped to the ends of the ramp; 0 < lo < hi. Both 0 = automatic */
    int legend;       /* 1: a legend strip (colour bar, values at the decades) right of the image */
    const char *unit; /* legend title, e.g. "cd/m2" or "lx" (glyphs: see img_fc_text;
                         others are left blank); NULL = none */
} img_fc_opts;

void img_fc_default_opts(img_fc_opts *o); /* automatic range, legend on, no unit */

/* Per-pixel luminance scale * (0.2126 R + 0.7152 G + 0.0722 B); malloc'd
 * width*height floats (row 0 at the top), NULL when out of memory. */
float *img_fc_luminance(const framebuffer *fb, double scale);

/* Automatic range of n values: the 0.5th and 99.5th percentiles of the
 * finite positive values, widened to whole decades (one decade either side
 * of a single value). PT_ERR_USAGE when there are no positive values. */
pt_status img_fc_auto_range(const float *values, size_t n, double *lo, double *hi, diag *d);

/* The false-colour image of `values` (w x h): w (+ the legend's width) x h
 * pixels. Its RGB values are linear, the sRGB decoding of the ramp's
 * display colours, so that img_write's default PNG encoding (and any sRGB
 * viewer) shows the ramp colours exactly. The range used is stored back into
 * *lo_used / *hi_used when those are non-NULL. */
pt_status img_falsecolor(const float *values, int w, int h, const img_fc_opts *o, framebuffer **out,
                         double *lo_used, double *hi_used, diag *d);

/* The display sRGB colour at ramp position t (clamped to [0,1]). */
void img_fc_ramp(double t, float srgb[3]);
/* The ramp position nearest to a display sRGB colour; *dist (may be NULL)
 * gets the distance in sRGB units (~0.004 for an 8-bit code's rounding). */
double img_fc_unramp(const float srgb[3], double *dist);
/* Value <-> ramp position for the range [lo, hi] (log10 scale). */
double img_fc_position(double value, double lo, double hi);
double img_fc_value_at(double t, double lo, double hi);

/* The legend's 5x7 pixel font, for other drawings (plots, labels): draws
 * `text` with its top-left corner at (x, y), every glyph scaled by s (>= 1)
 * and advancing 6s pixels, in the display sRGB colour `srgb` (stored as its
 * linear value, like the rest of the image); pixels outside fb are skipped.
 * Glyphs: digits, . - + / = , ( ) _ : and a b c d e f g h i k l m n o p r s
 * t u v w x y z W; other characters (space included) leave a blank cell.
 * Returns the text's width in pixels (img_fc_text_width). */
int img_fc_text(framebuffer *fb, int x, int y, int s, const char *text, const float srgb[3]);
/* Width in pixels of `text` at scale s: 6s per character less the last gap. */
int img_fc_text_width(const char *text, int s);

/* Readout: the mean of the finite values in the (2r+1)^2 window around
 * (x, y), clipped to the image; NaN when the window holds none. */
double img_fc_probe(const float *values, int w, int h, int x, int y, int r);

#endif
