/* shade_focal.h - focal blur's sampling budget: how many lens rays a
 * sample takes and where they go on the lens.
 *
 * POV-Ray 3.7 (TracePixel::TraceRayWithFocalBlur and FocalBlurData, read
 * for their semantics) traces a sample's lens rays in batches (7, 6, 6, 4,
 * 4, 4, 4, 2 for 37 or more blur_samples; 7, 6, 6 for 19 or more; 7 for 7
 * or more; then 4 at a time) and after each batch stops when it has taken
 * at least blur_samples_min rays and the variance of the mean colour,
 * (S2/n - (S1/n)^2)/n per channel, is below
 *   threshold(n) = variance * chi2inv(n, confidence) / chi2inv(blur_samples - 1, confidence)
 * for every channel, chi2inv(df, y) being the x with P(chi^2_df > x) = y
 * (Cephes' chdtri, shade_chi2.h); it never takes more than blur_samples rays. */
#ifndef PT_SHADE_FOCAL_H
#define PT_SHADE_FOCAL_H
#include "scene_camera.h"

typedef struct {
    int max, min;       /* blur_samples and blur_samples_min */
    double *threshold;  /* [n - 1]: the bound after n rays; NULL when max is 0 */
    int batch[9];       /* POV-Ray's batch sizes, 0-terminated; 4 each beyond */
} shade_focal;

/* The budget of camera c (c->blur_samples rays at most). Returns 0 when out
 * of memory (f is then a budget of blur_samples rays with no early stop). */
int shade_focal_init(shade_focal *f, const scene_camera *c);
void shade_focal_release(shade_focal *f);
/* Rays in batch number `level` (0 first). */
int shade_focal_batch(const shade_focal *f, int level);
/* After n rays whose channel sums are s1[3] and squared sums s2[3]: stop? */
int shade_focal_done(const shade_focal *f, int n, const double s1[3], const double s2[3]);
/* Ray i of a sample: its lens point in the unit-diameter disc
 * (|(lu, lv)| <= 0.5) and its place in the pixel (jx, jy in [0, 1)), from
 * a 4-D low-discrepancy sequence shifted by the sample's own shift[4] in
 * [0,1)^4, so every prefix covers lens and pixel evenly and a sample that
 * stops early has still seen the whole lens. */
void shade_focal_point(int i, const double shift[4], double *lu, double *lv, double *jx, double *jy);

#endif
