/* img_plot.h - a small raster plotter for error-against-time charts
 * (`partray sweep`): axes with ticks and numeric labels, linear or log10
 * scales, one coloured polyline with markers per series, and a legend.
 *
 * The picture is a framebuffer of linear values chosen so that img_write's
 * sRGB PNG shows the intended display colours (white background, black
 * axes, the series colours of img_plot_color). Text uses the 5x7 font of
 * img_falsecolor.h (img_fc_text). */
#ifndef PT_IMG_PLOT_H
#define PT_IMG_PLOT_H
#include "diag.h"
#include "framebuffer.h"

typedef struct {
    const char *name;    /* legend text (may be NULL) */
    int n;               /* number of points */
    const double *x, *y; /* n values each; points are joined in order of x.
                            Non-finite points, and points <= 0 on a log
                            axis, are left out */
} img_plot_series;

typedef struct {
    int width, height;       /* picture size in pixels (>= 160 x 120) */
    const char *x_label;     /* text under the x axis (may be NULL) */
    const char *y_label;     /* text above the y axis (may be NULL) */
    int x_log, y_log;        /* 1 log10 axis, 0 linear, -1 automatic: log
                                when every value is > 0 and max/min > 10 */
} img_plot_opts;

/* 720 x 480, no labels, both axes automatic. */
void img_plot_default_opts(img_plot_opts *o);

/* Draws the chart. PT_ERR_USAGE for a bad size or a negative series count;
 * series without a single drawable point still get their legend entry, and
 * a chart with no points at all gets axes over [0,1]. */
pt_status img_plot(const img_plot_series *s, int ns, const img_plot_opts *o, framebuffer **out, diag *d);

/* The display sRGB colour of series i (a colour-blind-safe cycle of 7). */
void img_plot_color(int i, float srgb[3]);

#endif
