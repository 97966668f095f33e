/* shade_focal.c - focal blur's sampling budget (shade_focal.h). */
#include "shade_focal.h"
#include "shade_chi2.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

int shade_focal_init(shade_focal *f, const scene_camera *c)
{
    memset(f, 0, sizeof *f);
    f->max = c->blur_samples > 0 ? c->blur_samples : 0;
    f->min = c->blur_samples_min;
    /* POV-Ray's batch lists by the number of blur samples: its hexagonal
     * grids of 37, 19 and 7 points are traced ring by ring */
    static const int b37[] = {7, 6, 6, 4, 4, 4, 4, 2, 0}, b19[] = {7, 6, 6, 0}, b7[] = {7, 0};
    const int *b = f->max >= 37 ? b37 : f->max >= 19 ? b19 : f->max >= 7 ? b7 : NULL;
    for (int i = 0; b && b[i]; i++) f->batch[i] = b[i];
    if (f->max == 0) return 1;
    f->threshold = calloc((size_t)f->max, sizeof *f->threshold);
    if (!f->threshold) {
        f->min = f->max; /* no early stop */
        return 0;
    }
    if (f->max > 1) {
        /* a threshold of 0 for blur_samples 1: never met, as POV-Ray */
        double t1 = c->variance / shade_chi2_inv_q(f->max - 1, c->confidence);
        for (int i = 0; i < f->max; i++) f->threshold[i] = t1 * shade_chi2_inv_q(i + 1, c->confidence);
    }
    return 1;
}

void shade_focal_release(shade_focal *f)
{
    free(f->threshold);
    f->threshold = NULL;
}

int shade_focal_batch(const shade_focal *f, int level)
{
    for (int i = 0; i < 9 && f->batch[i]; i++)
        if (i == level) return f->batch[i];
    return 4;
}

int shade_focal_done(const shade_focal *f, int n, const double s1[3], const double s2[3])
{
    if (n >= f->max) return 1;
    if (n < f->min || n < 1 || !f->threshold) return 0;
    double t = f->threshold[n - 1];
    for (int k = 0; k < 3; k++) {
        double m = s1[k] / n, v = (s2[k] / n - m * m) / n;
        if (!(v < t)) return 0;
    }
    return 1;
}

void shade_focal_point(int i, const double shift[4], double *lu, double *lv, double *jx, double *jy)
{
    /* R4: the powers of the root of x^5 = x + 1 as the four irrational
     * steps (Roberts 2018, "The unreasonable effectiveness of quasirandom
     * sequences"); the polar map keeps the lens area uniform */
    const double a[4] = {0.8566748838545029, 0.7338918566271260, 0.6287067210378087, 0.5385972572236101};
    double u[4];
    for (int k = 0; k < 4; k++) {
        u[k] = shift[k] + a[k] * i;
        u[k] -= floor(u[k]);
    }
    double r = 0.5 * sqrt(u[0]), phi = 2.0 * M_PI * u[1];
    *lu = r * cos(phi);
    *lv = r * sin(phi);
    *jx = u[2];
    *jy = u[3];
}
