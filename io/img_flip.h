/* img_flip.h - the FLIP image difference evaluator.
 *
 * LDR-FLIP: Andersson, Nilsson, Akenine-Moller, Oskarsson, Astrom, Fairchild,
 *   "FLIP: A Difference Evaluator for Alternating Images", HPG 2020.
 * HDR-FLIP: Andersson, Nilsson, Shirley, Akenine-Moller,
 *   "Visualizing Errors in Rendered High Dynamic Range Images", EG 2021.
 *
 * The error map holds one value in [0,1] per pixel (0 = no perceived
 * difference). Pooled values follow the authors' tool: the mean, and the
 * "weighted median" (each error weighted by itself; see
 * img_flip_weighted_percentile). Non-finite input values count as 0. */
#ifndef PT_IMG_FLIP_H
#define PT_IMG_FLIP_H
#include <stddef.h>
#include "diag.h"
#include "framebuffer.h"

/* Pixels per degree for a viewer `dist_m` metres from a monitor `width_m`
 * metres wide showing `res_x` pixels across. */
double img_flip_ppd(double dist_m, double res_x, double width_m);
/* Default viewing conditions: 0.7 m from a 0.7 m wide 3840-pixel monitor,
 * about 67.02 pixels per degree. */
#define IMG_FLIP_DEFAULT_PPD 67.02064327658226

typedef struct {
    double ppd;          /* pixels per degree; <= 0 selects IMG_FLIP_DEFAULT_PPD */
    /* HDR-FLIP only. Inputs: a NaN start/stop or nexposures <= 0 is computed
     * from the reference (img_flip_exposures). Outputs: the values used. */
    double exp_start, exp_stop;
    int nexposures;
} img_flip_params;

/* ppd = default, exposures all automatic. */
void img_flip_default_params(img_flip_params *p);

/* LDR-FLIP. `ref` and `test` hold sRGB-encoded display values (a PNG read
 * with png_raw = 1); values are clamped to [0,1]. `err` receives
 * width*height values, row 0 at the top. Size mismatch: PT_ERR_USAGE. */
pt_status img_flip_ldr(const framebuffer *ref, const framebuffer *test,
                       const img_flip_params *p, float *err, diag *d);

/* HDR-FLIP. `ref` and `test` hold scene-linear values (negatives count as 0,
 * before the tone curve). The exposure range
 * is taken from `p` or computed from the reference; the values used are
 * written back into *p. */
pt_status img_flip_hdr(const framebuffer *ref, const framebuffer *test,
                       img_flip_params *p, float *err, diag *d);

/* HDR-FLIP's automatic exposure range (EG 2021): with t(x) the ACES tone
 * curve, start = log2(x85 / Ymax) and stop = log2(x85 / Ymedian), where
 * t(x85) = 0.85 and Y is the reference's luminance (Rec. 709 weights; the
 * median is the element at index n/2 of the sorted values, as in the
 * authors' tool); n = max(2, ceil(stop - start)). Our additions for
 * degenerate references: a median of 0 is replaced by the median of the
 * positive luminances, and an all-black reference gets 0 to 1 (with a
 * warning). PT_ERR_USAGE for an empty image. */
pt_status img_flip_exposures(const framebuffer *ref, double *start, double *stop,
                             int *n, diag *d);

/* Pooling. */
double img_flip_mean(const float *err, size_t n);
/* The FLIP tool's weighted percentile: sort the errors ascending and return
 * the first one at which the running sum of errors exceeds `q` times their
 * total (so larger errors count more). q = 0.5 is the "weighted median". */
double img_flip_weighted_percentile(const float *err, size_t n, double q);
/* The histogram form the tool also carries (100 bins on [0,1], each bin
 * weighted by its centre, linear interpolation inside the bin). Kept for
 * comparison; the tool prints img_flip_weighted_percentile. */
double img_flip_hist_weighted_percentile(const float *err, size_t n, double q);

#endif
