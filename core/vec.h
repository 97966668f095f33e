/* vec.h - 3-component double vectors, all inline. */
#ifndef PT_VEC_H
#define PT_VEC_H
#include <math.h>

typedef struct { double x, y, z; } vec3;

static inline vec3 v3(double x, double y, double z) { vec3 r = {x, y, z}; return r; }
static inline vec3 v3s(double s) { return v3(s, s, s); }
static inline vec3 v3_add(vec3 a, vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline vec3 v3_sub(vec3 a, vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline vec3 v3_mul(vec3 a, vec3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline vec3 v3_scale(vec3 a, double s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline vec3 v3_madd(vec3 a, vec3 b, double s) { return v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s); }
static inline vec3 v3_neg(vec3 a) { return v3(-a.x, -a.y, -a.z); }
static inline double v3_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3 v3_cross(vec3 a, vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double v3_len2(vec3 a) { return v3_dot(a, a); }
static inline double v3_len(vec3 a) { return sqrt(v3_dot(a, a)); }
static inline vec3 v3_norm(vec3 a)
{
    double l = v3_len(a);
    return l > 0.0 ? v3_scale(a, 1.0 / l) : a;
}
/* fmin and fmax inline, with the values glibc's x86-64 versions return
 * (minsd/maxsd on ordered arguments: the second one when the two compare
 * equal, so also for +0 and -0; the number when one is a NaN): libm's are
 * calls, which the compiler may not replace under IEEE NaN rules, and the
 * box and interval tests of a render make millions of them. Written so
 * that the compiler emits one minsd/maxsd after a NaN test that is never
 * taken in practice (a select of a or b on a < b || b != b became two
 * branches, one of them unpredictable). */
static inline double fmin_inline(double a, double b) { return b != b ? a : (a < b ? a : b); }
static inline double fmax_inline(double a, double b) { return b != b ? a : (a > b ? a : b); }
static inline vec3 v3_min(vec3 a, vec3 b) { return v3(fmin_inline(a.x, b.x), fmin_inline(a.y, b.y), fmin_inline(a.z, b.z)); }
static inline vec3 v3_max(vec3 a, vec3 b) { return v3(fmax_inline(a.x, b.x), fmax_inline(a.y, b.y), fmax_inline(a.z, b.z)); }
static inline double v3_maxc(vec3 a) { return fmax_inline(a.x, fmax_inline(a.y, a.z)); }
static inline double v3_idx(vec3 a, int i) { return i == 0 ? a.x : (i == 1 ? a.y : a.z); }
/* a in single precision, into f[0..2] (device records, photon and mesh arrays) */
static inline void v3_store_f(float f[3], vec3 a)
{
    f[0] = (float)a.x;
    f[1] = (float)a.y;
    f[2] = (float)a.z;
}
static inline int v3_finite(vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
/* One axis of the slab tests below: the ray's interval [*a, *b] narrowed
 * to the slab [l, u] (x and y its two distances), or, where the ray runs
 * parallel to it (flat), whether its origin lies within it. The tests call
 * it once per axis, written out: a loop over v3_idx was not unrolled and
 * its selects and tests took a sixth of a CSG scene's instructions. */
static inline int v3_slab_axis(int flat, double oi, double l, double u, double x, double y, double *a, double *b)
{
    if (flat) return !(oi < l || oi > u);
    if (x > y) { double t = x; x = y; y = t; }
    if (x > *a) *a = x;
    if (y < *b) *b = y;
    return 1;
}
/* Ray o + t d against the box [lo, hi] (slab method): the parameter interval
 * [*t0, *t1] inside the box; 0 if the ray misses it. */
static inline int v3_slab(vec3 o, vec3 d, vec3 lo, vec3 hi, double *t0, double *t1)
{
    double a = -INFINITY, b = INFINITY;
    if (!v3_slab_axis(d.x == 0.0, o.x, lo.x, hi.x, (lo.x - o.x) / d.x, (hi.x - o.x) / d.x, &a, &b) ||
        !v3_slab_axis(d.y == 0.0, o.y, lo.y, hi.y, (lo.y - o.y) / d.y, (hi.y - o.y) / d.y, &a, &b) ||
        !v3_slab_axis(d.z == 0.0, o.z, lo.z, hi.z, (lo.z - o.z) / d.z, (hi.z - o.z) / d.z, &a, &b))
        return 0;
    if (!(a <= b)) return 0;
    *t0 = a;
    *t1 = b;
    return 1;
}
/* v3_slab with inv = 1 / d precomputed per component (for one ray tested
 * against many boxes): a product in place of each division, so t0 and t1
 * may differ from v3_slab's by an ulp; a zero component of d (or one so
 * small that its inverse overflows) is handled as v3_slab's zero. */
static inline int v3_slab_inv(vec3 o, vec3 d, vec3 inv, vec3 lo, vec3 hi, double *t0, double *t1)
{
    double a = -INFINITY, b = INFINITY;
    if (!v3_slab_axis(d.x == 0.0 || !isfinite(inv.x), o.x, lo.x, hi.x, (lo.x - o.x) * inv.x, (hi.x - o.x) * inv.x, &a,
                      &b) ||
        !v3_slab_axis(d.y == 0.0 || !isfinite(inv.y), o.y, lo.y, hi.y, (lo.y - o.y) * inv.y, (hi.y - o.y) * inv.y, &a,
                      &b) ||
        !v3_slab_axis(d.z == 0.0 || !isfinite(inv.z), o.z, lo.z, hi.z, (lo.z - o.z) * inv.z, (hi.z - o.z) * inv.z, &a,
                      &b))
        return 0;
    if (!(a <= b)) return 0;
    *t0 = a;
    *t1 = b;
    return 1;
}
/* Whether the segment o + t d, t in [0, tmax], meets the box [lo, hi]. */
static inline int v3_segment_meets_box(vec3 o, vec3 d, vec3 lo, vec3 hi, double tmax)
{
    double t0, t1;
    return v3_slab(o, d, lo, hi, &t0, &t1) && t1 >= 0.0 && t0 <= tmax;
}
/* Build an orthonormal basis (t, b) around unit vector n (Duff et al. 2017). */
static inline void v3_basis(vec3 n, vec3 *t, vec3 *b)
{
    double s = copysign(1.0, n.z);
    double a = -1.0 / (s + n.z);
    double c = n.x * n.y * a;
    *t = v3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
    *b = v3(c, s + n.y * n.y * a, -n.y);
}
/* The cosine-weighted direction about unit n for uniforms u1, u2 in [0, 1)
 * (Malley's method: a uniform point of the unit disc lifted to the
 * hemisphere; pdf cos / pi). */
static inline vec3 v3_cosine_dir(vec3 n, double u1, double u2)
{
    double r = sqrt(u1), phi = 2.0 * M_PI * u2;
    double x = r * cos(phi), y = r * sin(phi), z = sqrt(fmax(0.0, 1.0 - u1));
    vec3 t, bt;
    v3_basis(n, &t, &bt);
    return v3_add(v3_add(v3_scale(t, x), v3_scale(bt, y)), v3_scale(n, z));
}

#endif
