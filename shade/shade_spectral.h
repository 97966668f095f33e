/* shade_spectral.h - POV-Ray 3.7's spectral bands for interior dispersion:
 * the wavelength and width of dispersion element i of n, the ior a band
 * sees, and the colour (hue) a band's radiance is weighted with when the
 * elements are summed back into RGB. */
#ifndef PT_SHADE_SPECTRAL_H
#define PT_SHADE_SPECTRAL_H
#include "scene.h"

/* A band of the visible range, in nm; single precision as POV-Ray keeps it.
 * A ray with wavelength 0 carries every colour (not yet dispersed). */
typedef struct {
    float wavelength;
    float bandwidth;
} shade_spectral_band;

/* Element i (0 = violet end) of n equal bands of 380..730 nm. */
shade_spectral_band shade_spectral_band_of(unsigned i, unsigned n);

/* The ior ratio `ior` (outside/inside as the refraction uses it) corrected
 * for a band of the given wavelength with the dispersion ratio `disp`. */
double shade_spectral_ior(float wavelength, double ior, double disp);

/* The RGB weight of a band: the hue integral over the band, scaled so that
 * the bands of a full set average to (nearly) white. */
rgb shade_spectral_hue(shade_spectral_band b);

/* The cumulative hue table value at a wavelength (exposed for tests). */
rgb shade_spectral_hue_integral(double wavelength);

#endif
