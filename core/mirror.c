/* mirror.c - POV-Ray 3.7's mirror reflectivity (see mirror.h). */
#include "mirror.h"
#include <math.h>
#include "vec.h"

/* POV-Ray's EPSILON for the falloff tests (trace.cpp) */
#define MIRROR_EPSILON 1.0e-10

static inline double max3(rgb a) { return fmax_inline(a.r, fmax_inline(a.g, a.b)); }

static inline rgb blend(rgb hi, rgb lo, double t)
{
    rgb c = {hi.r * t + lo.r * (1.0 - t), hi.g * t + lo.g * (1.0 - t), hi.b * t + lo.b * (1.0 - t)};
    return c;
}

int mirror_reflects(const scene_finish *f)
{
    return max3(f->reflection_max) > 0.0 || max3(f->reflection_min) > 0.0;
}

rgb mirror_reflectivity(const scene_finish *f, double cos_i, double rel_ior, double *weight)
{
    rgb rmax = f->reflection_max, rmin = f->reflection_min;
    if (f->fresnel) {
        /* the unpolarised dielectric reflectance in the form POV-Ray's
         * ComputeReflectivity writes it: g = sqrt(n^2 + c^2 - 1), F = 1/2
         * ((g - c)/(g + c))^2 (1 + ((c (g + c) - 1)/(c (g - c) + 1))^2);
         * no real g is total internal reflection */
        rgb refl = rmax;
        double sqx = rel_ior * rel_ior + cos_i * cos_i - 1.0;
        if (sqx > 0.0) {
            double g = sqrt(sqx);
            double fr = 0.5 * ((g - cos_i) * (g - cos_i) / ((g + cos_i) * (g + cos_i)));
            double a = cos_i * (g + cos_i) - 1.0, b = cos_i * (g - cos_i) + 1.0;
            fr = fr * (1.0 + a * a / (b * b));
            fr = fmin_inline(1.0, fmax_inline(0.0, fr));
            refl = blend(rmax, rmin, fr);
        }
        *weight *= max3(refl);
        return refl;
    }
    *weight *= fmax_inline(max3(rmax), max3(rmin));
    double frac = fabs(f->reflection_falloff - 1.0) > MIRROR_EPSILON ? pow(1.0 - cos_i, f->reflection_falloff) : 1.0 - cos_i;
    if (fabs(frac) < MIRROR_EPSILON) return rmin;
    if (fabs(frac - 1.0) < MIRROR_EPSILON) return rmax;
    return blend(rmax, rmin, frac);
}

void mirror_metallic_tint(rgb *cs, double metallic, rgb pigment, double cos_angle)
{
    if (metallic == 0.0) return;
    double x = fabs(acos(fmax(-1.0, fmin(1.0, cos_angle)))) / (M_PI / 2.0);
    double f = 0.014567225 / ((x - 1.12) * (x - 1.12)) - 0.011612903;
    f = fmin(1.0, fmax(0.0, f));
    double k = metallic * (1.0 - f);
    cs->r *= 1.0 + k * (pigment.r - 1.0);
    cs->g *= 1.0 + k * (pigment.g - 1.0);
    cs->b *= 1.0 + k * (pigment.b - 1.0);
}
