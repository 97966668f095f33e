/* glossy_lobe.h - the glossy lobe's formula (glossy.h) in the subset that C11
 * and OpenCL C share, so that the host (core/glossy.c, in double) and the GI
 * kernels (gi/kernels, in float, embedded into the OpenCL program and
 * compiled as C by gi/gi_cl_c.c) evaluate one implementation.
 *
 * The includer may define GLOSSY_REAL (default double) and GLOSSY_GLOBAL
 * (the address space of the table: __global in kernels, empty in C). The
 * table is E(mu) at mu = (k / (GLOSSY_NMU - 1))^2, k = 0 .. GLOSSY_NMU - 1,
 * interpolated linearly in sqrt(mu). */
#ifndef PT_GLOSSY_LOBE_H
#define PT_GLOSSY_LOBE_H

#ifndef GLOSSY_REAL
#define GLOSSY_REAL double
#endif
#ifndef GLOSSY_GLOBAL
#define GLOSSY_GLOBAL
#endif
#define GLOSSY_NMU 65
#define GLOSSY_PI 3.14159265358979323846

/* E(mu) from the table */
static inline GLOSSY_REAL glossy_lobe_albedo(GLOSSY_GLOBAL const GLOSSY_REAL *tab, GLOSSY_REAL mu)
{
    GLOSSY_REAL m = mu < (GLOSSY_REAL)0 ? (GLOSSY_REAL)0 : (mu > (GLOSSY_REAL)1 ? (GLOSSY_REAL)1 : mu);
    GLOSSY_REAL s = sqrt(m) * (GLOSSY_REAL)(GLOSSY_NMU - 1);
    int i = (int)s;
    if (i >= GLOSSY_NMU - 1) return tab[GLOSSY_NMU - 1];
    GLOSSY_REAL f = s - (GLOSSY_REAL)i;
    return tab[i] * ((GLOSSY_REAL)1 - f) + tab[i + 1] * f;
}

/* f(wi, wo) of the lobe of exponent e (no cosine) from mi = cos(n, wi),
 * mo = cos(n, wo) and c = r(wo) . wi (r the mirror direction of wo):
 *   (e+1)/(2 pi) max(c, 0)^e / max(mi, mo)
 *   + (1 - E(mi)) (1 - E(mo)) / (pi (1 - Eavg));
 * 0 unless mi > 0 and mo > 0. */
static inline GLOSSY_REAL glossy_lobe_f(GLOSSY_REAL e, GLOSSY_GLOBAL const GLOSSY_REAL *tab, GLOSSY_REAL eavg,
                                        GLOSSY_REAL mi, GLOSSY_REAL mo, GLOSSY_REAL c)
{
    if (!(mi > (GLOSSY_REAL)0) || !(mo > (GLOSSY_REAL)0)) return (GLOSSY_REAL)0;
    GLOSSY_REAL g = (GLOSSY_REAL)0;
    if (c > (GLOSSY_REAL)0) {
        GLOSSY_REAL cc = c < (GLOSSY_REAL)1 ? c : (GLOSSY_REAL)1;
        g = (e + (GLOSSY_REAL)1) / (GLOSSY_REAL)(2.0 * GLOSSY_PI) * pow(cc, e) / (mi > mo ? mi : mo);
    }
    GLOSSY_REAL ms = (GLOSSY_REAL)0;
    if (eavg < (GLOSSY_REAL)(1.0 - 1e-6))
        ms = ((GLOSSY_REAL)1 - glossy_lobe_albedo(tab, mi)) * ((GLOSSY_REAL)1 - glossy_lobe_albedo(tab, mo)) /
             ((GLOSSY_REAL)GLOSSY_PI * ((GLOSSY_REAL)1 - eavg));
    return g + ms;
}

#endif
