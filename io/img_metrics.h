/* img_metrics.h - image comparison metrics for `partray compare`: RMSE,
 * relative MSE, PSNR, SSIM, FLIP (img_flip.h), and heat maps.
 *
 * Conventions (all metrics):
 *  - `ref` is the reference, `test` the image being judged; sizes must match
 *    (PT_ERR_USAGE otherwise).
 *  - Non-finite values (NaN, +-Inf) count as 0.
 *  - RMSE = sqrt(mean over all pixels and channels of (t - r)^2).
 *  - relMSE (pbrt's form) = mean over all channel values of
 *    (t - r)^2 / (r^2 + 0.01).
 *  - PSNR = 10 log10(1 / MSE) with peak 1.0, the MSE taken on values clamped
 *    to [0,1] (display range for LDR images, the [0,1] part of linear HDR
 *    values). Identical images give +INFINITY.
 *  - SSIM (Wang, Bovik, Sheikh, Simoncelli 2004): 11x11 Gaussian window,
 *    sigma 1.5, K1 = 0.01, K2 = 0.03, L = 1, on values clamped to [0,1],
 *    computed per RGB channel over the windows that lie fully inside the
 *    image ("valid" region, as in the authors' reference code), averaged over
 *    the window positions and then over the three channels. Images smaller
 *    than 11 pixels in a dimension use the largest odd window that fits
 *    (the Gaussian truncated and renormalised). */
#ifndef PT_IMG_METRICS_H
#define PT_IMG_METRICS_H
#include "diag.h"
#include "framebuffer.h"

typedef struct {
    double rmse, relmse, psnr, ssim;
    double rmse_ch[3], relmse_ch[3], ssim_ch[3];
    double flip_mean, flip_wmedian; /* FLIP mean and the tool's weighted median */
    int flip_hdr;                   /* 1: HDR-FLIP was used */
    double exp_start, exp_stop;     /* HDR-FLIP exposure range (0 for LDR) */
    int nexposures;                 /* HDR-FLIP exposure count (0 for LDR) */
    double lum_ref, lum_test;       /* mean Rec.709 luminance of the linear values (img_mean_luminance) */
} img_compare_result;

/* Mean Rec.709 luminance Y = 0.2126 R + 0.7152 G + 0.0722 B (ITU-R BT.709
 * primaries, the sRGB ones) over all pixels, of linear values; srgb = 1:
 * the framebuffer holds sRGB-encoded values, decoded first. */
double img_mean_luminance(const framebuffer *fb, int srgb);

/* All metrics at once.
 * hdr = 0: both images hold display-encoded (sRGB) values in [0,1], as a PNG
 *          read with png_raw = 1 gives; FLIP is LDR-FLIP.
 * hdr = 1: both hold scene-linear values (EXR, PFM); FLIP is HDR-FLIP with the
 *          exposure range computed from the reference.
 * Default FLIP viewing conditions: 67 pixels per degree.
 * flip_map_out (may be NULL): receives a new framebuffer with the FLIP error
 * map in the magma colour scale over [0,1] and a legend strip below
 * (img_heatmap); free with fb_free. */
pt_status img_compare(const framebuffer *ref, const framebuffer *test, int hdr,
                      img_compare_result *r, framebuffer **flip_map_out, diag *d);

/* Single metrics. `ch` (may be NULL) receives the per-channel values. */
pt_status img_rmse(const framebuffer *ref, const framebuffer *test, double *all, double ch[3], diag *d);
pt_status img_relmse(const framebuffer *ref, const framebuffer *test, double *all, double ch[3], diag *d);
pt_status img_psnr(const framebuffer *ref, const framebuffer *test, double *psnr, diag *d);
pt_status img_ssim(const framebuffer *ref, const framebuffer *test, double *ssim, double ch[3], diag *d);

/* Heat maps. The returned framebuffer holds linear values chosen so that an
 * sRGB-encoded PNG (img_write) shows the colour scale's display colours.
 *
 * img_heatmap: `v` is w*h values (row 0 at the top) mapped through the magma
 * colour scale (the matplotlib/FLIP map; vmin -> black-purple, vmax -> pale
 * yellow), clamped to [vmin, vmax]. With `legend`, a strip is added below the
 * image: a colour bar spanning the width, labelled with vmin, the midpoint
 * and vmax. */
pt_status img_heatmap(const float *v, int w, int h, double vmin, double vmax, int legend,
                      framebuffer **out, diag *d);
/* Per-pixel absolute error, mean over R, G, B of |t - r|, as a magma heat
 * map from 0 to `vmax` (vmax <= 0: the largest error, or 1 if there is none). */
pt_status img_abs_error_map(const framebuffer *ref, const framebuffer *test, double vmax, int legend,
                            framebuffer **out, diag *d);
/* The magma colour for t in [0,1] as display (sRGB-encoded) values. */
void img_magma(double t, float rgb[3]);
/* Height in pixels of the legend strip img_heatmap adds to a w x h image. */
int img_heatmap_legend_height(int w, int h);

#endif
