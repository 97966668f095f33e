/* glossy.h - the glossy lobe of POV-Ray's phong and specular highlights as a
 * reciprocal, energy-conserving BRDF for the GI modes (path, pmfg, vpl).
 * One implementation, in core/ so that shade/ (the BSDF every reference
 * mode uses) and gi/ can both reach it.
 *
 * Conventions: n the unit normal on the viewer's side, wo the unit direction
 * towards the viewer, wi the unit direction towards where light comes from;
 * mu = cos(n, w). Lobes of exponent e about the mirror direction
 * r = 2 (n.wo) n - wo:
 *
 *   g(wi, wo)  = (e + 1) / (2 pi) * max(r.wi, 0)^e / max(mu_i, mu_o)
 *   f(wi, wo)  = g(wi, wo) + (1 - E(mu_i)) (1 - E(mu_o)) / (pi (1 - Eavg))
 *
 * with E(mu) = int g mu_i dwi (the albedo of g seen from mu_o = mu) and
 * Eavg = 2 int_0^1 E(mu) mu dmu. Both terms are symmetric in wi and wo
 * ((r(wo).wi = r(wi).wo), so f is reciprocal. g's albedo is at most 1
 * (mu_i / max(mu_i, mu_o) <= 1 and (e+1)/(2 pi) max(r.w, 0)^e integrates to
 * 1 over the sphere); the second term (Kulla and Conty's energy
 * compensation, 2017) returns what g loses below the horizon at grazing
 * angles, so int f mu_i dwi = 1 for every wo: a white glossy surface under
 * a uniform sky shows the sky exactly (the furnace test). Near the peak
 * mu_i = mu_o, so g is the normalised Phong lobe (e+1)/(2 pi) cos^e / mu
 * whose reflected energy does not depend on e.
 *
 * Normalisation of POV-Ray's lobes (shade_material.c maps the finish):
 * `phong p` with `phong_size e` is the lobe of exponent e with weight p, i.e.
 * it reflects the fraction p of the light it receives, whatever e;
 * `specular s` with `roughness r` (Blinn, cos(n, h)^(1/r)) is the lobe of
 * exponent 1/(4 r) about the mirror direction (cos^k of the half-angle
 * ~ exp(-k a^2 / 8) against cos^e ~ exp(-e a^2 / 2) for the angle a between
 * wi and r) with weight s. POV-Ray's own formula (p cos^e per unit light
 * colour) is unnormalised: read with its light units as a BRDF it reflects
 * 2p/(e+1) of the incident energy (5% for phong 1, phong_size 40), so
 * glossy interreflection would all but vanish and sharper highlights would
 * be darker. We keep POV-Ray's formula for light that comes straight from
 * POV-Ray light sources (`--gi none`'s highlights, exactly), and this
 * energy-normalised lobe for all other (gathered) light.
 *
 * E(mu) is tabulated per exponent (exponents are rounded to 1/64 of an
 * octave: 1.1% at most; the lobe uses the rounded value, so table and lobe
 * agree) on first use and cached for the process (thread-safe, lock-free
 * readers). */
#ifndef PT_GLOSSY_H
#define PT_GLOSSY_H
#include "vec.h"

typedef struct glossy_table glossy_table;

/* The lobe of exponent e (clamped to [2^-6, 2^20], rounded as above);
 * NULL only when out of memory. */
const glossy_table *glossy_table_for(double e);
double glossy_exponent(const glossy_table *t);
/* Eavg, the cosine-weighted mean of the tabulated albedo E(mu). */
double glossy_table_eavg(const glossy_table *t);
/* The GLOSSY_NMU values E(mu_k) of glossy_lobe.h's table (for copies into
 * device memory: the kernels evaluate the lobe with glossy_lobe.h too). */
const double *glossy_table_values(const glossy_table *t);

/* f(wi, wo) (no cosine); 0 unless both are on n's side. */
double glossy_eval(const glossy_table *t, vec3 n, vec3 wo, vec3 wi);
/* Density (solid angle) of glossy_sample choosing wi. */
double glossy_pdf(const glossy_table *t, vec3 n, vec3 wo, vec3 wi);
/* Sample wi for wo from u0, u1, u2 in [0,1): with probability E(mu_o)
 * about r with density (e+1)/(2 pi) max(r.wi, 0)^e, else cosine-weighted.
 * *weight = f mu_i / pdf (<= ~1), *pdf as glossy_pdf. Returns 0 (weight 0)
 * when wi falls below the horizon. */
int glossy_sample(const glossy_table *t, vec3 n, vec3 wo, double u0, double u1, double u2, vec3 *wi, double *pdf,
                  double *weight);

/* E(mu) of g computed directly (no table): for tests and table building. */
double glossy_albedo_exact(double e, double mu);

#endif
