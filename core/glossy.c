/* glossy.c - the energy-compensated Phong lobe (model and normalisation in
 * glossy.h).
 *
 * E(mu_o) in closed form over the azimuth. About r (polar angle a, azimuth
 * phi; r has the polar angle of wo about n), mu_i = x mu_o - sqrt(1-x^2)
 * sqrt(1-mu_o^2) cos(phi) with x = cos a, and mu_i / max(mu_i, mu_o) on the
 * upper side is min(mu_i+, mu_o) / mu_o = ((mu_i)+ - (mu_i - mu_o)+) / mu_o.
 * With F(a, b) = int_0^2pi max(a + b cos phi, 0) dphi (closed form below),
 *   E(mu_o) = (e+1)/(2 pi) int_0^1 x^e G(x) dx,
 *   G(x) = (F(x mu_o, b) - F(x mu_o - mu_o, b)) / mu_o,  b = sqrt(1-x^2) sqrt(1-mu_o^2),
 * and x = t^(1/(e+1)) turns the radial integral into (1/2 pi) int_0^1 G dt,
 * taken by the midpoint rule on 256 points. */
#include "glossy.h"
#include <math.h>
#include "glossy_lobe.h"
#include <stdatomic.h>
#include <stdlib.h>

#define Q_PER_OCTAVE 64
#define Q_MIN (-6 * Q_PER_OCTAVE)
#define Q_MAX (20 * Q_PER_OCTAVE)
#define NQ (Q_MAX - Q_MIN + 1)
#define NMU GLOSSY_NMU /* E at mu = (k / 64)^2: denser towards grazing, where E changes */
#define NT 256       /* radial quadrature points */
#define NAVG 2048    /* quadrature points for Eavg over the interpolated table */

struct glossy_table {
    double e;
    double tab[NMU];
    double eavg;
};

static _Atomic(glossy_table *) cache[NQ];

/* int_0^2pi max(a + b cos phi, 0) dphi for b >= 0 */
static double azimuth_clip(double a, double b)
{
    if (a >= b) return 2.0 * M_PI * a;
    if (a <= -b) return 0.0;
    return 2.0 * (a * acos(-a / b) + sqrt(b * b - a * a));
}

double glossy_albedo_exact(double e, double mu)
{
    if (mu < 1e-6) mu = 1e-6;
    if (mu > 1.0) mu = 1.0;
    double so = sqrt(fmax(0.0, 1.0 - mu * mu)), sum = 0.0;
    for (int k = 0; k < NT; k++) {
        double t = (k + 0.5) / NT;
        double x = exp(log(t) / (e + 1.0));
        double b = sqrt(fmax(0.0, 1.0 - x * x)) * so;
        sum += (azimuth_clip(x * mu, b) - azimuth_clip(x * mu - mu, b)) / mu;
    }
    return sum / NT / (2.0 * M_PI);
}

static double table_lookup(const double *tab, double mu) { return glossy_lobe_albedo(tab, mu); }

static glossy_table *table_build(double e)
{
    glossy_table *t = malloc(sizeof *t);
    if (!t) return NULL;
    t->e = e;
    for (int k = 0; k < NMU; k++) {
        double s = (double)k / (NMU - 1);
        t->tab[k] = fmin(1.0, glossy_albedo_exact(e, s * s));
    }
    /* Eavg of the interpolated table, so that the compensation term returns
     * exactly 1 - E_table(mu_o) */
    double sum = 0.0;
    for (int k = 0; k < NAVG; k++) {
        double mu = (k + 0.5) / NAVG;
        sum += table_lookup(t->tab, mu) * mu;
    }
    t->eavg = fmin(1.0, 2.0 * sum / NAVG);
    return t;
}

const glossy_table *glossy_table_for(double e)
{
    if (!(e > 0.0)) e = 0.0;
    double l = e > 0.0 ? log2(e) * Q_PER_OCTAVE : Q_MIN;
    long q = isfinite(l) ? lround(l) : (l > 0 ? Q_MAX : Q_MIN);
    if (q < Q_MIN) q = Q_MIN;
    if (q > Q_MAX) q = Q_MAX;
    int i = (int)(q - Q_MIN);
    glossy_table *t = atomic_load_explicit(&cache[i], memory_order_acquire);
    if (t) return t;
    glossy_table *mine = table_build(exp2((double)q / Q_PER_OCTAVE));
    if (!mine) return NULL;
    glossy_table *expected = NULL;
    if (atomic_compare_exchange_strong_explicit(&cache[i], &expected, mine, memory_order_acq_rel, memory_order_acquire))
        return mine;
    free(mine); /* another thread built the same table first */
    return expected;
}

double glossy_exponent(const glossy_table *t) { return t->e; }
double glossy_table_eavg(const glossy_table *t) { return t->eavg; }
const double *glossy_table_values(const glossy_table *t) { return t->tab; }

static inline vec3 mirror(vec3 n, vec3 wo) { return v3_sub(v3_scale(n, 2.0 * v3_dot(n, wo)), wo); }

double glossy_eval(const glossy_table *t, vec3 n, vec3 wo, vec3 wi)
{
    return glossy_lobe_f(t->e, t->tab, t->eavg, v3_dot(n, wi), v3_dot(n, wo), v3_dot(mirror(n, wo), wi));
}

double glossy_pdf(const glossy_table *t, vec3 n, vec3 wo, vec3 wi)
{
    double mi = v3_dot(n, wi), mo = v3_dot(n, wo);
    if (!(mo > 0.0)) return 0.0;
    double P = table_lookup(t->tab, mo);
    double c = v3_dot(mirror(n, wo), wi);
    double pg = c > 0.0 ? (t->e + 1.0) / (2.0 * M_PI) * pow(fmin(c, 1.0), t->e) : 0.0;
    double pc = mi > 0.0 ? mi / M_PI : 0.0;
    return P * pg + (1.0 - P) * pc;
}

int glossy_sample(const glossy_table *t, vec3 n, vec3 wo, double u0, double u1, double u2, vec3 *wi, double *pdf,
                  double *weight)
{
    *weight = 0.0;
    *pdf = 0.0;
    double mo = v3_dot(n, wo);
    if (!(mo > 0.0)) return 0;
    double P = table_lookup(t->tab, mo);
    vec3 axis = u0 < P ? mirror(n, wo) : n;
    double ca = u0 < P ? exp(log(fmax(u1, 1e-300)) / (t->e + 1.0)) : sqrt(fmax(0.0, 1.0 - u1));
    double sa = sqrt(fmax(0.0, 1.0 - ca * ca)), phi = 2.0 * M_PI * u2;
    vec3 ta, tb;
    v3_basis(axis, &ta, &tb);
    *wi = v3_add(v3_scale(axis, ca), v3_add(v3_scale(ta, sa * cos(phi)), v3_scale(tb, sa * sin(phi))));
    double mi = v3_dot(n, *wi);
    if (!(mi > 0.0)) return 0;
    *pdf = glossy_pdf(t, n, wo, *wi);
    if (!(*pdf > 0.0)) return 0;
    *weight = glossy_eval(t, n, wo, *wi) * mi / *pdf;
    return isfinite(*weight);
}
