/* shade_spectral.c - spectral bands for dispersion (see shade_spectral.h).
 *
 * Facts from POV-Ray 3.7.0's backend/colour/spectral.[h|cpp] (studied for
 * semantics, nothing copied):
 *  - The visible range is 380 (violet) .. 730 nm (red); its centre 555 nm.
 *  - Element i of n has the wavelength 380 + 350 (i + 0.5) / n and the
 *    width 350 / n, both kept in single precision.
 *  - A band's ior is ior * disp^(-(wavelength - 555) / 350) (ior and disp
 *    being the ratios across the surface), so violet bends most for a
 *    dispersion above 1.
 *  - A band's hue is (I(wl + w/2) - I(wl - w/2)) * 350 / w, where I is a
 *    cumulative RGB table over 375..740 nm in 5 nm steps, interpolated
 *    linearly and clamped at its ends.
 *  - 3.7 ships three variants of that table and compiles the third, which
 *    it describes as derived from the hue formula of earlier versions.
 *    That formula (POV-Ray 3.6's ComputeDispersion) maps a position hc to
 *      blue  = max(0, 0.98 (1 - (4 (hc - 0.28))^2))
 *      green = max(0, 0.97 (1.1 - (4.5 (hc - 0.57))^2))
 *      red   = 1.15 - (5 (hc - 0.75))^2, else 0.12 - (4 (hc - 0.12))^2
 *              where the first is negative, clamped at 0,
 *    with hc = 0.964 - 0.934 (1 - x) running from violet (x = 0) to red
 *    (x = 1).
 * The table is generated here from that formula: entry k (375 + 5k nm) is
 * the running sum over the 5 nm steps m = 1..k of the formula at
 * x = m / 73, divided per channel by the sum over all 73 steps and rounded
 * to 4 decimals. This reproduces every one of the 74 x 3 numbers of 3.7's
 * compiled table (the rounding included); tests/test_look.c checks a few of
 * them and the bands' hues. */
#include "shade_spectral.h"
#include <math.h>
#include <pthread.h>

#define SPEC_VIOLET 380.0
#define SPEC_RED 730.0
#define SPEC_WIDTH (SPEC_RED - SPEC_VIOLET)
#define SPEC_CENTRE ((SPEC_VIOLET + SPEC_RED) / 2.0)
#define HUE_STEPS 73 /* 5 nm steps of the table, 375..740 nm */
#define HUE_BASE 375.0
#define HUE_STEP 5.0

static rgb hue_table[HUE_STEPS + 1];
static pthread_once_t hue_once = PTHREAD_ONCE_INIT;

/* POV-Ray 3.6's hue of position hc (formula in the header comment). */
static rgb old_hue(double hc)
{
    rgb c;
    double b = 4.0 * (hc - 0.28);
    c.b = fmax(0.0, 0.98 * (1.0 - b * b));
    double g = 4.5 * (hc - 0.57);
    c.g = fmax(0.0, 0.97 * (1.1 - g * g));
    double r = 5.0 * (hc - 0.75);
    c.r = 1.15 - r * r;
    if (c.r < 0.0) {
        r = 4.0 * (hc - 0.12);
        c.r = 0.12 - r * r;
    }
    c.r = fmax(0.0, c.r);
    return c;
}

static double round4(double v) { return floor(v * 1.0e4 + 0.5) / 1.0e4; }

static void build_hue_table(void)
{
    rgb sum = {0, 0, 0};
    rgb run[HUE_STEPS + 1];
    run[0] = sum;
    for (int m = 1; m <= HUE_STEPS; m++) {
        rgb h = old_hue(0.964 - 0.934 * (1.0 - (double)m / HUE_STEPS));
        sum.r += h.r;
        sum.g += h.g;
        sum.b += h.b;
        run[m] = sum;
    }
    for (int k = 0; k <= HUE_STEPS; k++) {
        hue_table[k].r = round4(run[k].r / sum.r);
        hue_table[k].g = round4(run[k].g / sum.g);
        hue_table[k].b = round4(run[k].b / sum.b);
    }
}

rgb shade_spectral_hue_integral(double wavelength)
{
    pthread_once(&hue_once, build_hue_table);
    double off = (wavelength - HUE_BASE) / HUE_STEP;
    off = fmin(fmax(off, 0.0), (double)HUE_STEPS);
    int k = (int)off;
    if (k > HUE_STEPS - 1) k = HUE_STEPS - 1;
    double f = off - k;
    rgb a = hue_table[k], b = hue_table[k + 1], c;
    c.r = (1.0 - f) * a.r + f * b.r;
    c.g = (1.0 - f) * a.g + f * b.g;
    c.b = (1.0 - f) * a.b + f * b.b;
    return c;
}

shade_spectral_band shade_spectral_band_of(unsigned i, unsigned n)
{
    shade_spectral_band b;
    b.wavelength = (float)(SPEC_VIOLET + SPEC_WIDTH * (((float)i + 0.5) / (float)n));
    b.bandwidth = (float)(SPEC_WIDTH / (float)n);
    return b;
}

double shade_spectral_ior(float wavelength, double ior, double disp)
{
    return ior * pow(disp, -((double)wavelength - SPEC_CENTRE) / SPEC_WIDTH);
}

rgb shade_spectral_hue(shade_spectral_band b)
{
    float half = b.bandwidth / 2.0f;
    rgb hi = shade_spectral_hue_integral((double)(b.wavelength + half));
    rgb lo = shade_spectral_hue_integral((double)(b.wavelength - half));
    double s = SPEC_WIDTH / (double)b.bandwidth;
    rgb c = {(hi.r - lo.r) * s, (hi.g - lo.g) * s, (hi.b - lo.b) * s};
    return c;
}
