/* geom_implicit.c - superellipsoid, quadric, poly and blob (geom_implicit.h).
 *
 * Rays are moved to the start of their interval with a unit direction
 * before polynomial coefficients are formed, so the coefficients stay O(size)
 * whatever the distance of the ray origin. Blob field facts are POV-Ray's
 * (blob.cpp): a component contributes strength (1 - d^2/r^2)^2 for d < r;
 * a cylinder component is the capsule around its axis segment (hemispherical
 * ends); the surface is where the sum equals the threshold, the inside where
 * it exceeds it. */
#include "geom_implicit.h"
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "geom_bvh.h"
#include "geom_poly.h"
#include "func.h"

enum { IM_SUPER, IM_QUADRIC, IM_POLY, IM_BLOB, IM_ISO };

typedef struct {
    int cylinder;
    xform x;          /* component space -> blob space */
    vec3 a, axis;     /* centre / first end and unit axis (component space) */
    double len, r2, s;
    const scene_texture *tex;
    vec3 bc;          /* blob space: a sphere holding the component's reach */
    double br2;       /* (its squared radius) */
} blob_comp;

typedef struct {
    int type, sturm;
    /* superellipsoid: exponents p = 2/e (x, y), q = 2/n (the z blend) */
    double p, q;
    int pint, qint;   /* p, q when they are whole numbers (powers by multiplication), else 0 */
    int convex;
    /* quadric */
    double a[10];
    int solid_bounded;
    /* poly */
    int order, nterms;
    const double *coef;
    int (*pw)[3];
    /* blob */
    double threshold;
    int ncomp;
    blob_comp *comp;
    geom_bvh comp_bvh; /* over the components' blob-space boxes */
    int comp_tex;      /* some component has its own texture */
    vec3 blo, bhi;
    /* isosurface */
    const scene_function *fn;
    const func_env *env; /* the function's evaluators (scene_isosurface.env) */
    int iso_sphere, open;
    vec3 ic1, ic2;
    double ir, thr, acc, grad, size;
    int max_trace; /* crossings per ray (POV-Ray's max_trace, 1 to ISO_MAX_TRACE) */
} im_data;

/* POV-Ray 3.7's ISOSURFACE_MAXTRACE (isosurf.h): the most crossings an
 * isosurface reports per ray, all_intersections' count */
#define ISO_MAX_TRACE 10

/* ------------------------------------------------------------ superellipsoid */

/* x^n for a whole n >= 1 by repeated squaring: |x|^p for the common
 * exponents (e = 0.05 gives p = 40) costs a few products, not a pow(). */
static double ipow(double x, int n)
{
    double r = 1.0;
    while (n > 0) {
        if (n & 1) r *= x;
        x *= x;
        n >>= 1;
    }
    return r;
}

static double se_pow(double x, double p, int pint) { return pint ? ipow(x, pint) : pow(x, p); }

/* N(v) = ((|x|^p + |y|^p)^(q/p) + |z|^q)^(1/q), evaluated with the largest
 * term factored out so huge exponents neither overflow nor underflow; for
 * p = q it is (|x|^p + |y|^p + |z|^p)^(1/p), one root instead of two. */
static double se_norm(const im_data *m, vec3 v, double *pa)
{
    double ax = fabs(v.x), ay = fabs(v.y), az = fabs(v.z);
    if (!pa && m->p == m->q) {
        double mm = fmax_inline(fmax_inline(ax, ay), az);
        if (!(mm > 0.0)) return 0.0;
        double s = se_pow(ax / mm, m->p, m->pint) + se_pow(ay / mm, m->p, m->pint) + se_pow(az / mm, m->p, m->pint);
        return mm * pow(s, 1.0 / m->p);
    }
    double mxy = fmax_inline(ax, ay), a = 0.0;
    if (mxy > 0.0) a = mxy * pow(se_pow(ax / mxy, m->p, m->pint) + se_pow(ay / mxy, m->p, m->pint), 1.0 / m->p);
    if (pa) *pa = a;
    double mm = fmax_inline(a, az);
    if (!(mm > 0.0)) return 0.0;
    return mm * pow(se_pow(a / mm, m->q, m->qint) + se_pow(az / mm, m->q, m->qint), 1.0 / m->q);
}

static vec3 se_grad(const im_data *m, vec3 v)
{
    double a, N = se_norm(m, v, &a);
    if (!(N > 0.0)) return v3(0, 0, 1);
    double ax = fabs(v.x), ay = fabs(v.y), az = fabs(v.z);
    double gxy = a > 0.0 ? pow(a / N, m->q - 1.0) : 0.0;
    double gx = a > 0.0 ? gxy * pow(ax / a, m->p - 1.0) : 0.0;
    double gy = a > 0.0 ? gxy * pow(ay / a, m->p - 1.0) : 0.0;
    double gz = pow(az / N, m->q - 1.0);
    if (!isfinite(gx)) gx = 0.0;
    if (!isfinite(gy)) gy = 0.0;
    if (!isfinite(gz)) gz = 0.0;
    vec3 g = v3(copysign(gx, v.x), copysign(gy, v.y), copysign(gz, v.z));
    if (!(v3_len2(g) > 0.0)) g = v3(copysign(1.0, v.x), copysign(1.0, v.y), copysign(1.0, v.z));
    return g;
}

static double se_g(const im_data *m, vec3 o, vec3 d, double t) { return se_norm(m, v3_madd(o, d, t), NULL) - 1.0; }

/* Whether N < 1 at tau, for the sample scan: N^q < 1 with the powers of
 * the coordinates themselves, without se_norm's largest-term factoring or
 * its final root (the scan is within the box |v| <= 1 + 1e-9, where no
 * power overflows and an underflow only rounds a sum that is below 1
 * anyway). The sign can differ from se_g's only where g is within
 * rounding of 0; the scan takes se_g's values at a bracket's ends. */
static int se_inside(const im_data *m, vec3 o, vec3 d, double t)
{
    vec3 v = v3_madd(o, d, t);
    double ax = fabs(v.x), ay = fabs(v.y), az = fabs(v.z);
    if (m->p == m->q) return se_pow(ax, m->p, m->pint) + se_pow(ay, m->p, m->pint) + se_pow(az, m->p, m->pint) < 1.0;
    double sxy = se_pow(ax, m->p, m->pint) + se_pow(ay, m->p, m->pint);
    return pow(sxy, m->q / m->p) + se_pow(az, m->q, m->qint) < 1.0;
}

/* Root of g in [a, b] with g(a), g(b) of opposite signs (Illinois regula falsi). */
static double se_root(const im_data *m, vec3 o, vec3 d, double a, double b, double ga, double gb)
{
    int side = 0;
    for (int it = 0; it < 100; it++) {
        double c = (a * gb - b * ga) / (gb - ga);
        if (!(c > a && c < b)) c = 0.5 * (a + b);
        double gc = se_g(m, o, d, c);
        if (gc == 0.0) return c;
        if ((gc < 0.0) == (ga < 0.0)) {
            a = c;
            ga = gc;
            if (side == -1) gb *= 0.5;
            side = -1;
        } else {
            b = c;
            gb = gc;
            if (side == 1) ga *= 0.5;
            side = 1;
        }
        if (b - a <= 1e-15 * (fabs(a) + fabs(b)) + 1e-300) break;
    }
    return 0.5 * (a + b);
}

/* g at tau and its derivative along the ray, d/dtau N = grad N . d, from
 * one evaluation: g as se_g computes it, and se_grad's gradient from the
 * same powers, (|x|/N)^(p-1) = (|x|/mm)^p / S * N / |x| (p = q; with
 * p != q the chain through a = (|x|^p + |y|^p)^(1/p) likewise), with no
 * pow of its own. At a coordinate 0 (the pieces' ends) the factor is
 * se_grad's pow(0, p - 1): 1 for p = 1, else 0 (p < 1 gives an infinity
 * there, which se_grad drops). */
static double se_gd(const im_data *m, vec3 o, vec3 d, double t, double *dg)
{
    vec3 v = v3_madd(o, d, t);
    double ax = fabs(v.x), ay = fabs(v.y), az = fabs(v.z), gx = 0.0, gy = 0.0, gz = 0.0, N;
    if (m->p == m->q) {
        double mm = fmax_inline(fmax_inline(ax, ay), az);
        if (!(mm > 0.0)) {
            /* se_grad's fallback for a zero gradient */
            *dg = copysign(1.0, v.x) * d.x + copysign(1.0, v.y) * d.y + copysign(1.0, v.z) * d.z;
            return -1.0;
        }
        double tx = se_pow(ax / mm, m->p, m->pint), ty = se_pow(ay / mm, m->p, m->pint),
               tz = se_pow(az / mm, m->p, m->pint), S = tx + ty + tz;
        N = mm * pow(S, 1.0 / m->p);
        /* se_grad takes x and y through a, which is 0 on the z axis */
        double k = N / S, at0 = m->p == 1.0 && (ax > 0.0 || ay > 0.0) ? 1.0 : 0.0;
        gx = ax > 0.0 ? tx * k / ax : at0;
        gy = ay > 0.0 ? ty * k / ay : at0;
        gz = az > 0.0 ? tz * k / az : m->p == 1.0 ? 1.0 : 0.0;
    } else {
        double mxy = fmax_inline(ax, ay), a = 0.0, tx = 0.0, ty = 0.0, Sxy = 0.0;
        if (mxy > 0.0) {
            tx = se_pow(ax / mxy, m->p, m->pint);
            ty = se_pow(ay / mxy, m->p, m->pint);
            Sxy = tx + ty;
            a = mxy * pow(Sxy, 1.0 / m->p);
        }
        double mm = fmax_inline(a, az);
        if (!(mm > 0.0)) {
            *dg = copysign(1.0, v.x) * d.x + copysign(1.0, v.y) * d.y + copysign(1.0, v.z) * d.z;
            return -1.0;
        }
        double ua = se_pow(a / mm, m->q, m->qint), uz = se_pow(az / mm, m->q, m->qint), So = ua + uz;
        N = mm * pow(So, 1.0 / m->q);
        if (a > 0.0) {
            double gxy = ua * N / (So * a), at0 = m->p == 1.0 ? gxy : 0.0;
            gx = ax > 0.0 ? gxy * tx * a / (Sxy * ax) : at0;
            gy = ay > 0.0 ? gxy * ty * a / (Sxy * ay) : at0;
        }
        gz = az > 0.0 ? uz * N / (So * az) : (m->q == 1.0 ? 1.0 : 0.0);
    }
    if (!isfinite(gx)) gx = 0.0;
    if (!isfinite(gy)) gy = 0.0;
    if (!isfinite(gz)) gz = 0.0;
    if (!(gx * gx + gy * gy + gz * gz > 0.0)) gx = gy = gz = 1.0;
    *dg = copysign(gx, v.x) * d.x + copysign(gy, v.y) * d.y + copysign(gz, v.z) * d.z;
    return N - 1.0;
}

/* Crossings on [a, b] of g, convex there: tangent lines bound g from below
 * (Kelley's cutting planes), so the search either finds a point with
 * g < 0 (two crossings, bracketed on both sides), proves the minimum
 * positive (no crossing) or closes in on a touching point (grazing). */
/* The caller's view of the crossings: distance tau along the unit ray is
 * t = t0 + tau / s, kept when tmin < t < tmax; `max` are wanted. */
typedef struct {
    double t0, s, tmin, tmax;
    int max;
} se_range;

static int se_kept(const se_range *r, double tau)
{
    double t = r->t0 + tau / r->s;
    return t > r->tmin && t < r->tmax;
}

static int se_piece(const im_data *m, vec3 o, vec3 d, double a, double b, double *roots, int nr, const se_range *rg)
{
    double da, db, ga = se_gd(m, o, d, a, &da), gb = se_gd(m, o, d, b, &db);
    if ((ga < 0.0) != (gb < 0.0)) {
        roots[nr++] = se_root(m, o, d, a, b, ga, gb);
        return nr;
    }
    if (ga < 0.0) return nr; /* inside at both ends of a convex piece: no crossing */
    double a0 = a, b0 = b, ga0 = ga, gb0 = gb;
    for (int it = 0; it < 100; it++) {
        if (da >= 0.0 || db <= 0.0) return nr; /* the minimum is at an end, where g >= 0 */
        double t = (gb - ga + da * a - db * b) / (da - db);
        if (!(t > a && t < b)) t = 0.5 * (a + b);
        double lower = ga + da * (t - a);
        if (lower > 0.0) return nr;
        double dt, gt = se_gd(m, o, d, t, &dt);
        if (gt < 0.0) {
            roots[nr++] = se_root(m, o, d, a0, t, ga0, gt);
            /* the far crossing only when the caller wants more than one */
            if (rg->max > 1 || !se_kept(rg, roots[nr - 1])) roots[nr++] = se_root(m, o, d, t, b0, gt, gb0);
            return nr;
        }
        if (b - a <= 1e-13 * (fabs(a) + fabs(b)) + 1e-300 || gt - lower <= 1e-15) {
            if (gt <= 1e-12) roots[nr++] = t; /* grazing */
            return nr;
        }
        if (dt < 0.0) { a = t; ga = gt; da = dt; }
        else { b = t; gb = gt; db = dt; }
    }
    return nr;
}

/* The stretch [*c0, *c1] of the unit ray p + tau e (tau in [0, L]) that
 * can hold the surface of a non-convex superellipsoid; 0 when there is
 * none. With exponent p <= 1 the inner norm (|x|^p + |y|^p)^(1/p) is at
 * least |x| + |y| (and always at least max(|x|, |y|)); with q <= 1 the
 * outer one is at least the sum of its two parts: where the bound exceeds
 * 1 so does the norm, so the solid lies in the polytope
 * {|x| + |y| + |z| <= 1} (p, q <= 1), {max(|x|, |y|) + |z| <= 1} (q <= 1)
 * or {|x| + |y| <= 1} (p <= 1), each an intersection of half-spaces
 * s . v <= 1. The planes are padded by 1e-9 so that rounding in the norm
 * cannot put a crossing outside. */
static int se_polytope(const im_data *m, vec3 p, vec3 e, double L, double *c0, double *c1)
{
    int pl = m->p <= 1.0, ql = m->q <= 1.0;
    double a = 0.0, b = L;
    for (int k = 0; k < 8; k++) {
        double sx = k & 1 ? -1.0 : 1.0, sy = k & 2 ? -1.0 : 1.0, sz = k & 4 ? -1.0 : 1.0;
        /* the normals of this case; the last one is tried in both halves */
        vec3 ns[2];
        int nn = 0;
        if (pl && ql) ns[nn++] = v3(sx, sy, sz);
        else if (ql) {
            ns[nn++] = v3(sx, 0.0, sz);
            ns[nn++] = v3(0.0, sy, sz);
        } else if (k < 4) ns[nn++] = v3(sx, sy, 0.0);
        for (int i = 0; i < nn; i++) {
            double np = v3_dot(ns[i], p), ne = v3_dot(ns[i], e), lim = 1.0 + 1e-9;
            if (ne == 0.0) {
                if (np > lim) return 0;
                continue;
            }
            double t = (lim - np) / ne;
            if (ne > 0.0) b = t < b ? t : b;
            else a = t > a ? t : a;
        }
    }
    if (!(a <= b)) return 0;
    *c0 = a;
    *c1 = b;
    return 1;
}

static int se_hits(const im_data *m, vec3 o, vec3 d, double tmin, double tmax, geom_shape_hit *out, int max)
{
    double t0, t1;
    if (!v3_slab(o, d, v3s(-1.0 - 1e-9), v3s(1.0 + 1e-9), &t0, &t1)) return 0;
    t0 = fmax_inline(t0, tmin);
    t1 = fmin_inline(t1, tmax);
    if (!(t0 < t1)) return 0;
    /* move the origin into the box, unit direction */
    double s = v3_len(d);
    vec3 e = v3_scale(d, 1.0 / s), p = v3_madd(o, d, t0);
    double L = (t1 - t0) * s;
    /* split where a coordinate changes sign (the function's kinks) */
    double cuts[5];
    int nc = 0;
    cuts[nc++] = 0.0;
    double zs[3];
    int nz = 0;
    for (int i = 0; i < 3; i++) {
        double ei = v3_idx(e, i);
        if (ei != 0.0) {
            double z = -v3_idx(p, i) / ei;
            if (z > 0.0 && z < L) zs[nz++] = z;
        }
    }
    for (int i = 0; i < nz; i++)
        for (int j = i + 1; j < nz; j++)
            if (zs[j] < zs[i]) { double t = zs[i]; zs[i] = zs[j]; zs[j] = t; }
    for (int i = 0; i < nz; i++) cuts[nc++] = zs[i];
    cuts[nc++] = L;
    double roots[64];
    int nr = 0;
    /* Crossings are found in ascending order: the search stops once `max`
     * lie strictly inside the range (the caller's interval is open, so a
     * crossing at its very start does not count). */
    se_range rg = {t0, s, tmin, tmax, max};
    if (m->convex) {
        /* convex along the ray: at most two crossings; a norm is smooth
         * enough across the kinks for the bracket search on the whole range */
        nr = se_piece(m, p, e, 0.0, L, roots, nr, &rg);
    } else {
        /* Sample steps wholly outside the polytope's stretch have the
         * function positive at both ends: they are passed over without
         * evaluating it (the samples are where they would be, so the
         * crossings found are the same). */
        double c0, c1;
        if (!se_polytope(m, p, e, L, &c0, &c1)) return 0;
        int kept = 0;
        for (int c = 0; c + 1 < nc && nr < 56 && kept < max; c++) {
            const int N = 24;
            double a = cuts[c], b = cuts[c + 1];
            if (a > c1) break;
            double prev = a;
            int have_prev = 0, iprev = 0;
            for (int k = 1; k <= N && nr < 56 && kept < max; k++) {
                double x = a + (b - a) * k / N;
                if (x < c0) {
                    prev = x;
                    continue;
                }
                if (prev > c1) break;
                if (!have_prev) {
                    iprev = se_inside(m, p, e, prev);
                    have_prev = 1;
                }
                int ix = se_inside(m, p, e, x);
                if (iprev != ix) {
                    double gprev = se_g(m, p, e, prev), gx = se_g(m, p, e, x);
                    if ((gprev < 0.0) != (gx < 0.0)) {
                        roots[nr++] = se_root(m, p, e, prev, x, gprev, gx);
                        kept += se_kept(&rg, roots[nr - 1]);
                    }
                }
                prev = x;
                iprev = ix;
            }
        }
    }
    int n = 0;
    for (int i = 0; i < nr; i++) {
        double t = t0 + roots[i] / s;
        if (t > tmin && t < tmax) n = geom_shape_hit_put(out, n, max, t, 0);
    }
    return n;
}

/* ------------------------------------------------------------ quadric */

static double quadric_eval(const double *a, vec3 p)
{
    return a[0] * p.x * p.x + a[1] * p.y * p.y + a[2] * p.z * p.z + a[3] * p.x * p.y + a[4] * p.x * p.z +
           a[5] * p.y * p.z + a[6] * p.x + a[7] * p.y + a[8] * p.z + a[9];
}

static vec3 quadric_grad(const double *a, vec3 p)
{
    return v3(2.0 * a[0] * p.x + a[3] * p.y + a[4] * p.z + a[6], 2.0 * a[1] * p.y + a[3] * p.x + a[5] * p.z + a[7],
              2.0 * a[2] * p.z + a[4] * p.x + a[5] * p.y + a[8]);
}

static int quadric_hits(const im_data *m, vec3 o, vec3 d, double tmin, double tmax, geom_shape_hit *out, int max)
{
    if (!isfinite(tmin)) tmin = -1e300;
    double t0 = tmin;
    if (!isfinite(tmax)) return 0; /* unbounded ranges come clipped by geom_shape_clip_plane */
    double s = v3_len(d);
    vec3 e = v3_scale(d, 1.0 / s), p = v3_madd(o, d, t0);
    const double *a = m->a;
    double A = a[0] * e.x * e.x + a[1] * e.y * e.y + a[2] * e.z * e.z + a[3] * e.x * e.y + a[4] * e.x * e.z +
               a[5] * e.y * e.z;
    vec3 g = quadric_grad(a, p);
    double B = v3_dot(g, e), C = quadric_eval(a, p);
    double c[3] = {C, B, A}, roots[2];
    int nr = geom_poly_solve(c, 2, 0.0, (tmax - t0) * s, roots, 0);
    int n = 0;
    for (int i = 0; i < nr; i++) {
        double t = t0 + roots[i] / s;
        if (t > tmin && t < tmax) n = geom_shape_hit_put(out, n, max, t, 0);
    }
    return n;
}

/* Bounds of an ellipsoidal quadric (positive definite form, negative value
 * at the centre): centre -M^-1 g / 2, half extents sqrt(-k (M^-1)_ii). */
static int quadric_bounds(im_data *m, vec3 *lo, vec3 *hi)
{
    const double *a = m->a;
    double M[3][3] = {{a[0], 0.5 * a[3], 0.5 * a[4]}, {0.5 * a[3], a[1], 0.5 * a[5]}, {0.5 * a[4], 0.5 * a[5], a[2]}};
    double d1 = M[0][0], d2 = M[0][0] * M[1][1] - M[0][1] * M[1][0];
    double det = M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                 M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]);
    if (!(d1 > 0.0 && d2 > 0.0 && det > 0.0)) return 0;
    double inv[3][3];
    inv[0][0] = (M[1][1] * M[2][2] - M[1][2] * M[2][1]) / det;
    inv[0][1] = (M[0][2] * M[2][1] - M[0][1] * M[2][2]) / det;
    inv[0][2] = (M[0][1] * M[1][2] - M[0][2] * M[1][1]) / det;
    inv[1][0] = inv[0][1];
    inv[1][1] = (M[0][0] * M[2][2] - M[0][2] * M[2][0]) / det;
    inv[1][2] = (M[0][2] * M[1][0] - M[0][0] * M[1][2]) / det;
    inv[2][0] = inv[0][2];
    inv[2][1] = inv[1][2];
    inv[2][2] = (M[0][0] * M[1][1] - M[0][1] * M[1][0]) / det;
    double g[3] = {a[6], a[7], a[8]}, c[3];
    for (int i = 0; i < 3; i++) c[i] = -0.5 * (inv[i][0] * g[0] + inv[i][1] * g[1] + inv[i][2] * g[2]);
    vec3 cv = v3(c[0], c[1], c[2]);
    double k = quadric_eval(a, cv);
    if (!(k < 0.0)) return -1; /* empty (or a single point) */
    vec3 h = v3(sqrt(-k * inv[0][0]), sqrt(-k * inv[1][1]), sqrt(-k * inv[2][2]));
    *lo = v3_sub(cv, h);
    *hi = v3_add(cv, h);
    return 1;
}

/* min over x in [l, h] (either may be infinite) of A x^2 + B x */
static double quad_min(double A, double B, double l, double h)
{
    double m = INFINITY;
    if (A < 0.0 || (A == 0.0 && B > 0.0)) {
        if (!isfinite(l)) return -INFINITY;
    }
    if (A < 0.0 || (A == 0.0 && B < 0.0)) {
        if (!isfinite(h)) return -INFINITY;
    }
    if (isfinite(l)) m = fmin_inline(m, A * l * l + B * l);
    if (isfinite(h)) m = fmin_inline(m, A * h * h + B * h);
    if (A > 0.0) {
        double v = -B / (2.0 * A);
        if (v >= l && v <= h) m = fmin_inline(m, A * v * v + B * v);
    }
    if (A == 0.0 && B == 0.0) m = 0.0;
    return m;
}

/* Hull of {x in [l, h] : A x^2 + B x < R}; 0 when empty. */
static int quad_below(double A, double B, double R, double l, double h, double *lo, double *hi)
{
    if (R == INFINITY) { *lo = l; *hi = h; return l <= h; }
    double a = l, b = h;
    if (A == 0.0) {
        if (B > 0.0) b = fmin_inline(h, R / B);
        else if (B < 0.0) a = fmax_inline(l, R / B);
        else if (!(0.0 < R)) return 0;
    } else {
        double disc = B * B + 4.0 * A * R;
        if (A > 0.0) {
            if (!(disc > 0.0)) return 0;
            double sq = sqrt(disc);
            a = fmax_inline(l, (-B - sq) / (2.0 * A));
            b = fmin_inline(h, (-B + sq) / (2.0 * A));
        } else if (disc > 0.0) {
            /* outside the two roots: the hull within [l, h] */
            double sq = sqrt(disc), r1 = (-B + sq) / (2.0 * A), r2 = (-B - sq) / (2.0 * A); /* r1 < r2 */
            int left = l < r1, right = h > r2;
            if (!left && !right) return 0;
            if (!left) a = fmax_inline(l, r2);
            if (!right) b = fmin_inline(h, r1);
        }
    }
    *lo = a;
    *hi = b;
    return a <= b;
}

int geom_quadric_solid_box(const geom_shape *sh, int local, vec3 clo, vec3 chi, vec3 *lo, vec3 *hi)
{
    if (sh->kind != SHAPE_QUADRIC || !sh->data) return 0;
    const im_data *m = sh->data;
    const double *a = m->a;
    /* world form: with y = L p + c (the world -> object map),
     * f = y'Q y + b.y + J = p'(L'QL)p + (2 L'Q c + L'b).p + (c'Qc + b.c + J);
     * in the object's own space L = I, c = 0 */
    double Q[3][3] = {{a[0], 0.5 * a[3], 0.5 * a[4]}, {0.5 * a[3], a[1], 0.5 * a[5]}, {0.5 * a[4], 0.5 * a[5], a[2]}};
    double b[3] = {a[6], a[7], a[8]}, L[3][3], c[3];
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) L[i][j] = local ? (i == j) : sh->x.inv[i][j];
        c[i] = local ? 0.0 : sh->x.inv[i][3];
    }
    double QL[3][3], W[3][3], w[3], Qc[3], J = a[9];
    for (int i = 0; i < 3; i++) {
        Qc[i] = Q[i][0] * c[0] + Q[i][1] * c[1] + Q[i][2] * c[2];
        J += c[i] * Qc[i] + b[i] * c[i];
        for (int j = 0; j < 3; j++) QL[i][j] = Q[i][0] * L[0][j] + Q[i][1] * L[1][j] + Q[i][2] * L[2][j];
    }
    double big = 0.0;
    for (int i = 0; i < 3; i++) {
        w[i] = 0.0;
        for (int k = 0; k < 3; k++) w[i] += L[k][i] * (2.0 * Qc[k] + b[k]);
        for (int j = 0; j < 3; j++) {
            W[i][j] = L[0][i] * QL[0][j] + L[1][i] * QL[1][j] + L[2][i] * QL[2][j];
            big = fmax_inline(big, fabs(W[i][j]));
        }
    }
    if (!(big > 0.0) || !isfinite(big) || !isfinite(J)) return 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (i != j && fabs(W[i][j]) > 1e-12 * big) return 0; /* mixed terms */
    /* separable: f = sum_k (W_kk x_k^2 + w_k x_k) + J; along axis k the
     * others contribute at least their minimum over the box */
    double l[3] = {clo.x, clo.y, clo.z}, h[3] = {chi.x, chi.y, chi.z}, mn[3], out_lo[3], out_hi[3];
    for (int k = 0; k < 3; k++) {
        double A = fabs(W[k][k]) > 1e-12 * big ? W[k][k] : 0.0;
        mn[k] = quad_min(A, w[k], l[k], h[k]);
    }
    for (int k = 0; k < 3; k++) {
        double rest = J;
        for (int j = 0; j < 3; j++)
            if (j != k) rest += mn[j];
        double A = fabs(W[k][k]) > 1e-12 * big ? W[k][k] : 0.0;
        double R = isnan(rest) ? INFINITY : -rest;
        if (!quad_below(A, w[k], R, l[k], h[k], &out_lo[k], &out_hi[k])) return 0;
        double pad = 1e-7 * (fabs(out_lo[k]) + fabs(out_hi[k])) + 1e-12;
        if (isfinite(out_lo[k])) out_lo[k] -= pad;
        if (isfinite(out_hi[k])) out_hi[k] += pad;
    }
    *lo = v3(out_lo[0], out_lo[1], out_lo[2]);
    *hi = v3(out_hi[0], out_hi[1], out_hi[2]);
    return 1;
}

/* ------------------------------------------------------------ poly */

static double poly_eval3(const im_data *m, vec3 p)
{
    double xs[GEOM_POLY_MAX + 1], ys[GEOM_POLY_MAX + 1], zs[GEOM_POLY_MAX + 1];
    xs[0] = ys[0] = zs[0] = 1.0;
    for (int i = 1; i <= m->order; i++) {
        xs[i] = xs[i - 1] * p.x;
        ys[i] = ys[i - 1] * p.y;
        zs[i] = zs[i - 1] * p.z;
    }
    double f = 0.0;
    for (int t = 0; t < m->nterms; t++)
        if (m->coef[t] != 0.0) f += m->coef[t] * xs[m->pw[t][0]] * ys[m->pw[t][1]] * zs[m->pw[t][2]];
    return f;
}

static vec3 poly_grad(const im_data *m, vec3 p)
{
    vec3 g = v3s(0.0);
    for (int t = 0; t < m->nterms; t++) {
        double c = m->coef[t];
        if (c == 0.0) continue;
        int i = m->pw[t][0], j = m->pw[t][1], k = m->pw[t][2];
        double px = ipow(p.x, i), py = ipow(p.y, j), pz = ipow(p.z, k);
        if (i) g.x += c * i * ipow(p.x, i - 1) * py * pz;
        if (j) g.y += c * j * px * ipow(p.y, j - 1) * pz;
        if (k) g.z += c * k * px * py * ipow(p.z, k - 1);
    }
    return g;
}

/* Coefficients of (a + b t)^i for i = 0..n: row i, entry j = C(i,j) a^(i-j) b^j. */
static void lin_powers(double a, double b, int n, double P[][GEOM_POLY_MAX + 1])
{
    P[0][0] = 1.0;
    for (int i = 1; i <= n; i++) {
        for (int j = 0; j <= i; j++) {
            double v = 0.0;
            if (j < i) v += P[i - 1][j] * a;
            if (j > 0) v += P[i - 1][j - 1] * b;
            P[i][j] = v;
        }
    }
}

static int poly_hits(const im_data *m, vec3 o, vec3 d, double tmin, double tmax, geom_shape_hit *out, int max)
{
    if (!isfinite(tmax) || !isfinite(tmin)) return 0;
    double t0 = tmin;
    double s = v3_len(d);
    vec3 e = v3_scale(d, 1.0 / s), p = v3_madd(o, d, t0);
    int n = m->order;
    static _Thread_local double X[GEOM_POLY_MAX + 1][GEOM_POLY_MAX + 1], Y[GEOM_POLY_MAX + 1][GEOM_POLY_MAX + 1],
        Z[GEOM_POLY_MAX + 1][GEOM_POLY_MAX + 1];
    lin_powers(p.x, e.x, n, X);
    lin_powers(p.y, e.y, n, Y);
    lin_powers(p.z, e.z, n, Z);
    double c[GEOM_POLY_MAX + 1] = {0}, xy[2 * GEOM_POLY_MAX + 1];
    for (int t = 0; t < m->nterms; t++) {
        double cf = m->coef[t];
        if (cf == 0.0) continue;
        int i = m->pw[t][0], j = m->pw[t][1], k = m->pw[t][2];
        for (int a = 0; a <= i + j; a++) xy[a] = 0.0;
        for (int a = 0; a <= i; a++)
            for (int b = 0; b <= j; b++) xy[a + b] += X[i][a] * Y[j][b];
        for (int a = 0; a <= i + j; a++)
            for (int b = 0; b <= k; b++) c[a + b] += cf * xy[a] * Z[k][b];
    }
    double roots[GEOM_POLY_MAX];
    int nr = geom_poly_solve(c, n, 0.0, (tmax - t0) * s, roots, m->sturm);
    int nh = 0;
    for (int i = 0; i < nr; i++) {
        double t = t0 + roots[i] / s;
        if (t > tmin && t < tmax) nh = geom_shape_hit_put(out, nh, max, t, 0);
    }
    return nh;
}

/* ------------------------------------------------------------ blob */

/* One reach interval of a component along the local ray p + tau e, with
 * the quadratic d^2(tau) = q0 + q1 tau + q2 tau^2 (component space). */
typedef struct {
    double a, b;
    double q[3];
    double r2, s;
} blob_span;

/* The span [a, b] of component c with the quadratic q0 + q1 tau + q2 tau^2. */
static blob_span span_of(const blob_comp *c, double a, double b, double q0, double q1, double q2)
{
    blob_span sp;
    sp.a = a;
    sp.b = b;
    sp.q[0] = q0;
    sp.q[1] = q1;
    sp.q[2] = q2;
    sp.r2 = c->r2;
    sp.s = c->s;
    return sp;
}

/* Quadratic |o + tau d - c|^2 and, for a cylinder body, distance to the
 * axis line; spans where the component reaches (d^2 < r^2). */
static int blob_spans(const blob_comp *c, vec3 p, vec3 e, double ta, double tb, blob_span *sp)
{
    vec3 oc = xform_inv_point(&c->x, p), dc = xform_inv_vector(&c->x, e);
    int n = 0;
    /* sphere (or a cylinder's end caps): distance to a point */
    for (int end = 0; end < (c->cylinder ? 2 : 1); end++) {
        vec3 ctr = end ? v3_madd(c->a, c->axis, c->len) : c->a;
        vec3 rel = v3_sub(oc, ctr);
        double q2 = v3_dot(dc, dc), q1 = 2.0 * v3_dot(rel, dc), q0 = v3_dot(rel, rel);
        double qc[3] = {q0 - c->r2, q1, q2}, r[2];
        if (geom_poly_solve(qc, 2, -INFINITY, INFINITY, r, 0) < 2) continue;
        double a = r[0], b = r[1];
        if (c->cylinder) {
            /* hemispheres: the part beyond the end along the axis */
            double w0 = v3_dot(rel, c->axis), w1 = v3_dot(dc, c->axis);
            /* end 0: w < 0; end 1: w > 0 (w measured from this end) */
            if (w1 != 0.0) {
                double tw = -w0 / w1;
                int below_after = end == 0 ? (w1 < 0.0) : (w1 > 0.0); /* the cap side is reached after tw */
                if (below_after) a = fmax_inline(a, tw);
                else b = fmin_inline(b, tw);
            } else if ((end == 0 && w0 >= 0.0) || (end == 1 && w0 <= 0.0)) {
                continue;
            }
        }
        a = fmax_inline(a, ta);
        b = fmin_inline(b, tb);
        if (!(a < b)) continue;
        sp[n++] = span_of(c, a, b, q0, q1, q2);
    }
    if (c->cylinder) {
        /* body: distance to the axis line while 0 <= w <= len */
        vec3 rel = v3_sub(oc, c->a);
        double w0 = v3_dot(rel, c->axis), w1 = v3_dot(dc, c->axis);
        vec3 pr = v3_madd(rel, c->axis, -w0), dr = v3_madd(dc, c->axis, -w1);
        double q2 = v3_dot(dr, dr), q1 = 2.0 * v3_dot(pr, dr), q0 = v3_dot(pr, pr);
        double a, b;
        if (q2 > 0.0) {
            double qc[3] = {q0 - c->r2, q1, q2}, r[2];
            if (geom_poly_solve(qc, 2, -INFINITY, INFINITY, r, 0) < 2) return n;
            a = r[0];
            b = r[1];
        } else {
            if (q0 >= c->r2) return n;
            a = -INFINITY;
            b = INFINITY;
        }
        if (w1 != 0.0) {
            double x = -w0 / w1, y = (c->len - w0) / w1;
            if (x > y) { double t = x; x = y; y = t; }
            a = fmax_inline(a, x);
            b = fmin_inline(b, y);
        } else if (w0 < 0.0 || w0 > c->len) {
            return n;
        }
        a = fmax_inline(a, ta);
        b = fmin_inline(b, tb);
        if (a < b) {
            sp[n++] = span_of(c, a, b, q0, q1, q2);
        }
    }
    return n;
}

typedef struct {
    double t;
    int span, enter;
} blob_event;

static int cmp_event(const void *x, const void *y)
{
    const blob_event *a = x, *b = y;
    return a->t < b->t ? -1 : (a->t > b->t);
}

/* The components a query may meet, in ascending order (the order the
 * field's terms are summed in, whichever leaves the hierarchy visits
 * first). */
typedef struct {
    int *idx, n, cap;
    int local[128];
} blob_cands;

static void cands_put(void *ctx, int item)
{
    blob_cands *c = ctx;
    if (c->n == c->cap) {
        int cap = 2 * c->cap;
        int *p = c->idx == c->local ? malloc(sizeof *p * (size_t)cap) : realloc(c->idx, sizeof *p * (size_t)cap);
        if (!p) return; /* the candidate is lost only when memory ran out */
        if (c->idx == c->local) memcpy(p, c->local, sizeof c->local);
        c->idx = p;
        c->cap = cap;
    }
    c->idx[c->n++] = item;
}

static int cmp_int(const void *x, const void *y)
{
    int a = *(const int *)x, b = *(const int *)y;
    return (a > b) - (a < b);
}

static void cands_init(blob_cands *c)
{
    c->idx = c->local;
    c->n = 0;
    c->cap = (int)(sizeof c->local / sizeof c->local[0]);
}

static void cands_sort(blob_cands *c)
{
    if (c->n > 32) {
        qsort(c->idx, (size_t)c->n, sizeof *c->idx, cmp_int);
        return;
    }
    for (int i = 1; i < c->n; i++) {
        int v = c->idx[i], j = i;
        for (; j > 0 && c->idx[j - 1] > v; j--) c->idx[j] = c->idx[j - 1];
        c->idx[j] = v;
    }
}

static void cands_free(blob_cands *c)
{
    if (c->idx != c->local) free(c->idx);
}

/* The components whose box holds blob-space point q, ascending. */
static void cands_at(const im_data *m, vec3 q, blob_cands *c)
{
    cands_init(c);
    geom_bvh_point(&m->comp_bvh, q, cands_put, c);
    cands_sort(c);
}

static int blob_hits(const im_data *m, vec3 o, vec3 d, double tmin, double tmax, geom_shape_hit *out, int max)
{
    double b0, b1;
    if (!v3_slab(o, d, m->blo, m->bhi, &b0, &b1)) return 0;
    double t0 = fmax_inline(tmin, b0), t1 = fmin_inline(tmax, b1);
    if (!(t0 < t1)) return 0;
    double s = v3_len(d);
    vec3 e = v3_scale(d, 1.0 / s), p = v3_madd(o, d, t0);
    double L = (t1 - t0) * s;
    blob_cands cd;
    cands_init(&cd);
    geom_bvh_ray(&m->comp_bvh, p, e, 0.0, L, cands_put, &cd);
    cands_sort(&cd);
    blob_span local[64];
    blob_span *sp = local;
    size_t need = (size_t)cd.n * 3;
    if (need > 64) {
        sp = malloc(need * sizeof *sp);
        if (!sp) {
            cands_free(&cd);
            return 0;
        }
    }
    int ns = 0;
    for (int k = 0; k < cd.n; k++) {
        /* the ray must pass through the component's bounding sphere within [0, L] */
        const blob_comp *c = &m->comp[cd.idx[k]];
        vec3 rel = v3_sub(p, c->bc);
        double bq = v3_dot(rel, e), cq = v3_dot(rel, rel) - c->br2, disc = bq * bq - cq;
        if (cq > 0.0 && (bq > 0.0 || disc < 0.0 || -bq - sqrt(disc) > L)) continue;
        ns += blob_spans(c, p, e, 0.0, L, sp + ns);
    }
    int n = 0;
    if (ns > 0) {
        blob_event lev[128];
        blob_event *ev = 2 * (size_t)ns > 128 ? malloc(sizeof *ev * 2 * (size_t)ns) : lev;
        int lact[64];
        int *active = ns > 64 ? malloc(sizeof *active * (size_t)ns) : lact;
        if (ev && active) {
            for (int i = 0; i < ns; i++) {
                ev[2 * i] = (blob_event){sp[i].a, i, 1};
                ev[2 * i + 1] = (blob_event){sp[i].b, i, 0};
            }
            /* stable, as glibc's qsort (a merge sort) is on these sizes:
             * events at equal t keep their order */
            if (ns > 16) {
                qsort(ev, 2 * (size_t)ns, sizeof *ev, cmp_event);
            } else {
                for (int i = 1; i < 2 * ns; i++) {
                    blob_event v = ev[i];
                    int j = i;
                    for (; j > 0 && ev[j - 1].t > v.t; j--) ev[j] = ev[j - 1];
                    ev[j] = v;
                }
            }
            int na = 0;
            for (int k = 0; k + 1 < 2 * ns; k++) {
                /* the roots of this stretch and the ones after it are at
                 * tau >= ev[k].t (the solver returns roots inside its
                 * interval): once `max` hits are held and the farthest is
                 * no farther, none of them can enter */
                if (n == max && out[max - 1].t <= t0 + ev[k].t / s) break;
                if (ev[k].enter) active[na++] = ev[k].span;
                else
                    for (int j = 0; j < na; j++)
                        if (active[j] == ev[k].span) { active[j] = active[--na]; break; }
                double a = ev[k].t, b = ev[k + 1].t;
                if (!(b > a) || na == 0) continue;
                /* field - threshold as a quartic in tau */
                double c[5] = {-m->threshold, 0, 0, 0, 0};
                for (int j = 0; j < na; j++) {
                    const blob_span *q = &sp[active[j]];
                    /* s (1 - d^2/r^2)^2 with u = 1 - d^2/r^2 = u0 + u1 tau + u2 tau^2 */
                    double u0 = 1.0 - q->q[0] / q->r2, u1 = -q->q[1] / q->r2, u2 = -q->q[2] / q->r2;
                    c[0] += q->s * u0 * u0;
                    c[1] += q->s * 2.0 * u0 * u1;
                    c[2] += q->s * (u1 * u1 + 2.0 * u0 * u2);
                    c[3] += q->s * 2.0 * u1 * u2;
                    c[4] += q->s * u2 * u2;
                }
                double roots[4];
                int nr = geom_poly_solve(c, 4, a, b, roots, m->sturm);
                for (int i = 0; i < nr; i++) {
                    double t = t0 + roots[i] / s;
                    if (t > tmin && t < tmax) n = geom_shape_hit_put(out, n, max, t, 0);
                }
            }
        }
        if (ev != lev) free(ev);
        if (active != lact) free(active);
    }
    if (sp != local) free(sp);
    cands_free(&cd);
    return n;
}

/* Field of component c at blob-space point q, and its blob-space gradient. */
static double blob_comp_field(const blob_comp *c, vec3 q, vec3 *grad)
{
    vec3 pc = xform_inv_point(&c->x, q), rel = v3_sub(pc, c->a), dv;
    if (c->cylinder) {
        double w = v3_dot(rel, c->axis);
        if (w < 0.0) dv = rel;
        else if (w > c->len) dv = v3_sub(pc, v3_madd(c->a, c->axis, c->len));
        else dv = v3_madd(rel, c->axis, -w);
    } else {
        dv = rel;
    }
    double d2 = v3_dot(dv, dv);
    if (grad) *grad = v3s(0.0);
    if (d2 >= c->r2) return 0.0;
    double u = 1.0 - d2 / c->r2;
    if (grad) {
        /* d/dp of s u^2 = s 2 u (-2 dv / r2), to blob space by the inverse transpose */
        vec3 g = v3_scale(dv, -4.0 * c->s * u / c->r2);
        *grad = xform_normal(&c->x, g);
    }
    return c->s * u * u;
}

static double blob_field(const im_data *m, vec3 q, vec3 *grad)
{
    double f = 0.0;
    vec3 g = v3s(0.0);
    blob_cands cd;
    cands_at(m, q, &cd);
    for (int k = 0; k < cd.n; k++) {
        /* a point outside a component's bounding sphere gets nothing from
         * it (blob_hits skips rays the same way): no transform needed */
        const blob_comp *c = &m->comp[cd.idx[k]];
        if (v3_len2(v3_sub(q, c->bc)) > c->br2) continue;
        vec3 gi;
        f += blob_comp_field(c, q, grad ? &gi : NULL);
        if (grad) g = v3_add(g, gi);
    }
    cands_free(&cd);
    if (grad) *grad = g;
    return f;
}

static int blob_setup(im_data *m, const scene_blob *b, vec3 *lo, vec3 *hi)
{
    if (!b || b->ncomponents <= 0) return -1;
    m->comp = calloc((size_t)b->ncomponents, sizeof *m->comp);
    if (!m->comp) return -1;
    m->threshold = b->threshold;
    vec3 blo = v3s(INFINITY), bhi = v3s(-INFINITY);
    /* each kept component's blob-space box, for the hierarchy */
    vec3 *clos = malloc(sizeof *clos * (size_t)b->ncomponents), *chis = malloc(sizeof *chis * (size_t)b->ncomponents);
    if (!clos || !chis) {
        free(clos);
        free(chis);
        return -1;
    }
    for (int i = 0; i < b->ncomponents; i++) {
        const scene_blob_component *sc = &b->components[i];
        blob_comp *c = &m->comp[m->ncomp];
        double r = fabs(sc->radius);
        if (!(r > 0.0) || !isfinite(r) || !isfinite(sc->strength) || sc->strength == 0.0) continue;
        c->cylinder = sc->cylinder;
        c->x = sc->transform;
        c->a = sc->a;
        c->r2 = r * r;
        c->s = sc->strength;
        c->tex = sc->texture;
        vec3 clo = v3_sub(sc->a, v3s(r)), chi = v3_add(sc->a, v3s(r));
        if (sc->cylinder) {
            vec3 ax = v3_sub(sc->b, sc->a);
            c->len = v3_len(ax);
            if (!(c->len > 0.0)) continue;
            c->axis = v3_scale(ax, 1.0 / c->len);
            clo = v3_min(clo, v3_sub(sc->b, v3s(r)));
            chi = v3_max(chi, v3_add(sc->b, v3s(r)));
        }
        /* the reach's bounding sphere in blob space: the component-space
         * one stretched by at most the linear part's Frobenius norm */
        double fro = 0.0;
        for (int ii = 0; ii < 3; ii++)
            for (int jj = 0; jj < 3; jj++) fro += c->x.m[ii][jj] * c->x.m[ii][jj];
        double R0 = sc->cylinder ? 0.5 * c->len + r : r;
        c->bc = xform_point(&c->x, sc->cylinder ? v3_scale(v3_add(sc->a, sc->b), 0.5) : sc->a);
        c->br2 = R0 * R0 * fro * (1.0 + 1e-9);
        if (c->tex) m->comp_tex = 1;
        /* the reach's box in blob space: the component-space box's corners
         * carried over, within the bounding sphere's box */
        vec3 wlo = v3s(INFINITY), whi = v3s(-INFINITY);
        for (int k = 0; k < 8; k++) {
            vec3 pk = v3(k & 1 ? chi.x : clo.x, k & 2 ? chi.y : clo.y, k & 4 ? chi.z : clo.z);
            vec3 w = xform_point(&c->x, pk);
            wlo = v3_min(wlo, w);
            whi = v3_max(whi, w);
        }
        double br = sqrt(c->br2);
        clos[m->ncomp] = v3_max(wlo, v3_sub(c->bc, v3s(br)));
        chis[m->ncomp] = v3_min(whi, v3_add(c->bc, v3s(br)));
        m->ncomp++;
        if (c->s <= 0.0 && m->threshold > 0.0) continue; /* cannot make surface on its own */
        blo = v3_min(blo, wlo);
        bhi = v3_max(bhi, whi);
    }
    /* a few components per leaf: the sphere test in blob_hits and
     * blob_field sorts them out */
    int built = m->ncomp > 0 && geom_bvh_build(&m->comp_bvh, m->ncomp, clos, chis, 4) == 0;
    free(clos);
    free(chis);
    if (!built || !(blo.x <= bhi.x)) return -1;
    if (!(m->threshold > 0.0)) {
        /* threshold <= 0: the surface can lie anywhere the field is
         * positive... or everywhere (0 > threshold far away); keep the
         * components' reach and report the solid as unbounded */
        m->solid_bounded = 0;
    } else {
        m->solid_bounded = 1;
    }
    m->blo = blo;
    m->bhi = bhi;
    *lo = blo;
    *hi = bhi;
    return 0;
}

/* ------------------------------------------------------------ isosurface */

/* f(p) - threshold; NaN where the function cannot be evaluated. */
static double iso_f(const im_data *m, vec3 p)
{
    /* the function reads args[0..nparams): x, y, z and zeros; clearing
     * all FUNC_MAX_SLOTS of them per evaluation was a 1 KiB memset */
    if (m->fn->nparams <= 8) {
        double args[8] = {p.x, p.y, p.z, 0, 0, 0, 0, 0};
        return func_eval_float(m->fn, args, m->env) - m->thr;
    }
    double args[FUNC_MAX_SLOTS] = {p.x, p.y, p.z};
    return func_eval_float(m->fn, args, m->env) - m->thr;
}

static int iso_container(const im_data *m, vec3 o, vec3 d, double *a, double *b)
{
    if (!m->iso_sphere) return v3_slab(o, d, m->ic1, m->ic2, a, b);
    vec3 oc = v3_sub(o, m->ic1);
    double qc[3] = {v3_dot(oc, oc) - m->ir * m->ir, 2.0 * v3_dot(oc, d), v3_dot(d, d)}, r[2];
    if (geom_poly_solve(qc, 2, -INFINITY, INFINITY, r, 0) < 2) return 0;
    *a = r[0];
    *b = r[1];
    return 1;
}

static int iso_in_container(const im_data *m, vec3 q)
{
    if (m->iso_sphere) return v3_len2(v3_sub(q, m->ic1)) <= m->ir * m->ir;
    return q.x >= m->ic1.x && q.x <= m->ic2.x && q.y >= m->ic1.y && q.y <= m->ic2.y && q.z >= m->ic1.z && q.z <= m->ic2.z;
}

/* Crossings: steps no longer than |f - threshold| / max_gradient (a
 * crossing cannot be jumped while max_gradient bounds the slope, POV-Ray's
 * rule), at least `accuracy`; each sign change bisected to rounding. The
 * container's surface counts where it is inside (unless `open`). */
/* The crossing of f along p0 + tau e in [lo, hi] (f(lo) = flo and f(hi) =
 * fhi of opposite signs) to within tol: Illinois regula falsi, which on a
 * smooth f needs a handful of evaluations where bisection needs fifty;
 * a step that does not halve the bracket twice in a row is followed by a
 * bisection, so it never takes more than twice bisection's count. */
static double iso_root(const im_data *m, vec3 p0, vec3 e, double lo, double hi, double flo, double fhi, double tol)
{
    int side = 0, slow = 0;
    for (int it = 0; it < 400 && hi - lo > tol; it++) {
        double w = hi - lo;
        double mid = slow >= 2 ? 0.5 * (lo + hi) : (lo * fhi - hi * flo) / (fhi - flo);
        if (!(mid > lo && mid < hi)) mid = 0.5 * (lo + hi);
        double fm = iso_f(m, v3_madd(p0, e, mid));
        if (!isfinite(fm)) break;
        if (fm == 0.0) return mid;
        if ((fm < 0.0) == (flo < 0.0)) {
            lo = mid;
            flo = fm;
            if (side == -1) fhi *= 0.5;
            side = -1;
        } else {
            hi = mid;
            fhi = fm;
            if (side == 1) flo *= 0.5;
            side = 1;
        }
        slow = hi - lo > 0.5 * w ? slow + 1 : 0;
        if (slow > 2) slow = 0;
    }
    return 0.5 * (lo + hi);
}

/* The crossings of f along p0 + tau e in a range, nearest first, by
 * POV-Ray's rule for isosurfaces (isosurface.cpp Function_Find_Root_R):
 * with max_gradient L, f cannot reach 0 inside [t1, t2] when
 * f1 + f2 > L (t2 - t1) (values of one sign), so such a piece is dropped
 * after its two ends; others are halved down to `accuracy`. A piece whose
 * ends differ in sign holds exactly one crossing once L (t2 - t1) <=
 * |f1| + |f2| (a second and third would need more variation than L allows);
 * that crossing is polished by iso_root. Under POV-Ray's placement
 * (`pov`), a piece whose ends differ in sign is halved on until it is
 * shorter than `accuracy` along the world ray, and the crossing is its far
 * end (Function_Find_Root_R returns the end of the first such piece beyond
 * the crossing, up to accuracy past the surface), not the root. */
typedef struct {
    const im_data *m;
    vec3 p0, e;
    double a, s, tmin, tmax, minstep;
    geom_shape_hit *out;
    int n, max;
    int pov; /* POV-Ray's placement: minstep is accuracy in object length along this ray */
} iso_walk;

static void iso_split(iso_walk *w, double t1, double f1, double t2, double f2, int depth)
{
    if (w->n == w->max && w->a + t1 / w->s > w->out[w->max - 1].t) return; /* nothing nearer can follow */
    double len = t2 - t1, reach = w->m->grad * len;
    /* POV-Ray's leaf is a piece strictly shorter than accuracy */
    int fine = (w->pov ? len < w->minstep : len <= w->minstep) || depth >= 60;
    if (isfinite(f1) && isfinite(f2)) {
        if ((f1 < 0.0) == (f2 < 0.0)) {
            if (fabs(f1) + fabs(f2) > reach || fine) return;
        } else if (w->pov) {
            if (fine) {
                double t = w->a + t2 / w->s;
                if (t > w->tmin && t < w->tmax) w->n = geom_shape_hit_put(w->out, w->n, w->max, t, 0);
                return;
            }
        } else if (fabs(f1) + fabs(f2) >= reach || fine) {
            double t = w->a + iso_root(w->m, w->p0, w->e, t1, t2, f1, f2, 1e-15 * (fabs(t2) + len)) / w->s;
            if (t > w->tmin && t < w->tmax) w->n = geom_shape_hit_put(w->out, w->n, w->max, t, 0);
            return;
        }
    } else if (fine) {
        return;
    }
    double mid = t1 + 0.5 * len, fm = iso_f(w->m, v3_madd(w->p0, w->e, mid));
    iso_split(w, t1, f1, mid, fm, depth + 1);
    iso_split(w, mid, fm, t2, f2, depth + 1);
}

/* wl: the world length of d (the ray's t counts world length wl per unit,
 * which POV-Ray's accuracy rules measure). */
static int iso_hits(const im_data *m, vec3 o, vec3 d, double wl, double tmin, double tmax, geom_shape_hit *out,
                    int max, int traced, geom_ray_rule rule)
{
    double ca, cb;
    if (!iso_container(m, o, d, &ca, &cb)) return 0;
    double s = v3_len(d);
    int pov = traced && rule == GEOM_RAY_POV && wl > 0.0 && isfinite(wl);
    if (pov && ca * wl < m->acc) {
        /* POV-Ray's start (isosurface.cpp All_Intersections): a ray that
         * starts within accuracy of the container's entry or inside it, at
         * a point where f is within 4 max_gradient accuracy of the
         * threshold (below it when closed: any point inside), starts
         * its search 5 accuracy on; a ray leaving the surface does not
         * find the surface it leaves, but on a noise-displaced surface
         * it may meet the next fold within a few accuracies (the
         * terminator of a grazing light shadows itself there) */
        double t0 = ca > 0.0 ? ca : 0.0, f0 = iso_f(m, v3_madd(o, d, t0));
        double near = 4.0 * m->grad * m->acc;
        if (m->open ? fabs(f0) < near : f0 < near) {
            double t5 = 5.0 * m->acc / wl;
            if (t5 > tmin) tmin = t5;
        }
    }
    double a = fmax_inline(ca, tmin), b = fmin_inline(cb, tmax);
    if (!(a < b)) return 0;
    vec3 e = v3_scale(d, 1.0 / s), p0 = v3_madd(o, d, a);
    double len = (b - a) * s;
    /* A traced ray: POV-Ray's max_trace (isosurface.cpp All_Intersections):
     * at most max_trace crossings, the container's face where the ray enters
     * it counting as one; the face where it leaves is added (not counted)
     * only for a ray that starts inside the container. Otherwise every
     * crossing and both faces where the inside reaches them. */
    int n = 0, budget = traced ? m->max_trace : max;
    /* f at the container's entry, when the face test below asks for it:
     * a walk that starts at that point (bit for bit) takes it rather than
     * evaluating f there again (f is a function of the point alone) */
    vec3 pca = v3_madd(o, d, ca);
    double fca = NAN;
    int have_fca = 0;
    if (!m->open) {
        if (!traced) {
            if (ca > tmin && ca < tmax && (have_fca = 1, fca = iso_f(m, pca)) < 0.0) n = geom_shape_hit_put(out, n, max, ca, 1);
            if (cb > tmin && cb < tmax && iso_f(m, v3_madd(o, d, cb)) < 0.0) n = geom_shape_hit_put(out, n, max, cb, 1);
        } else if (ca > tmin) {
            if (ca < tmax && (have_fca = 1, fca = iso_f(m, pca)) < 0.0) {
                n = geom_shape_hit_put(out, n, max, ca, 1);
                budget--;
            }
        } else if (cb < tmax && iso_f(m, v3_madd(o, d, cb)) < 0.0) {
            n = geom_shape_hit_put(out, n, max, cb, 1);
        }
    }
    if (budget <= 0) return n;
    /* accuracy in object length along this ray: POV-Ray measures it along
     * the world ray (its t), the exact search in object space */
    double minstep = pov ? m->acc * s / wl : fmax_inline(m->acc, 1e-9 * m->size);
    double fa = have_fca && memcmp(&pca, &p0, sizeof p0) == 0 ? fca : iso_f(m, p0);
    if (!traced) {
        iso_walk w = {m, p0, e, a, s, tmin, tmax, minstep, out, n, max, 0};
        iso_split(&w, 0.0, fa, len, iso_f(m, v3_madd(p0, e, len)), 0);
        return w.n;
    }
    geom_shape_hit roots[ISO_MAX_TRACE];
    iso_walk w = {m, p0, e, a, s, tmin, tmax, minstep, roots, 0, budget < max ? budget : max, pov};
    iso_split(&w, 0.0, fa, len, iso_f(m, v3_madd(p0, e, len)), 0);
    for (int i = 0; i < w.n; i++) n = geom_shape_hit_put(out, n, max, roots[i].t, roots[i].part);
    return n;
}

static vec3 iso_normal(const im_data *m, vec3 q, int part)
{
    if (part == 1) {
        if (m->iso_sphere) return v3_sub(q, m->ic1);
        double best = INFINITY;
        vec3 n = v3(0, 1, 0);
        for (int i = 0; i < 3; i++) {
            double lo = v3_idx(m->ic1, i), hi = v3_idx(m->ic2, i), x = v3_idx(q, i);
            if (fabs(x - lo) < best) { best = fabs(x - lo); n = v3(i == 0 ? -1 : 0, i == 1 ? -1 : 0, i == 2 ? -1 : 0); }
            if (fabs(x - hi) < best) { best = fabs(x - hi); n = v3(i == 0 ? 1 : 0, i == 1 ? 1 : 0, i == 2 ? 1 : 0); }
        }
        return n;
    }
    /* POV-Ray 3.7's rule (isosurf.cpp, IsoSurface::Normal): the forward
     * difference of f over `accuracy` along each axis, so that detail of f
     * finer than accuracy is smoothed out of the shading as in its images
     * (a noise-displaced surface's shading follows it); a zero difference
     * is +x, as there. */
    double h = m->acc, f0 = iso_f(m, q);
    vec3 g = v3(iso_f(m, v3_add(q, v3(h, 0, 0))) - f0, iso_f(m, v3_add(q, v3(0, h, 0))) - f0,
                iso_f(m, v3_add(q, v3(0, 0, h))) - f0);
    if (!v3_finite(g)) return v3(0, 1, 0);
    return v3_len2(g) > 0.0 ? g : v3(1, 0, 0);
}

/* ------------------------------------------------------------ public */

static const int *poly_powers_alloc(im_data *m, int order, int nterms)
{
    m->pw = malloc(sizeof *m->pw * (size_t)nterms);
    if (!m->pw) return NULL;
    int idx = 0;
    for (int a = order; a >= 0; a--)
        for (int b = order - a; b >= 0; b--)
            for (int c = order - a - b; c >= 0; c--) {
                if (idx < nterms) {
                    m->pw[idx][0] = a;
                    m->pw[idx][1] = b;
                    m->pw[idx][2] = c;
                }
                idx++;
            }
    return idx == nterms ? &m->pw[0][0] : NULL;
}

int geom_implicit_init(geom_shape *sh, const scene_object *o, vec3 *lo, vec3 *hi)
{
    im_data *m = calloc(1, sizeof *m);
    if (!m) return -1;
    m->sturm = (o->flags & OBJ_STURM) != 0;
    int st = -1;
    switch (o->kind) {
    case SHAPE_SUPERELLIPSOID: {
        double e = o->u.superellipsoid.e, n = o->u.superellipsoid.n;
        if (!(e > 0.0) || !(n > 0.0) || !isfinite(e) || !isfinite(n)) break;
        m->type = IM_SUPER;
        m->p = 2.0 / e;
        m->q = 2.0 / n;
        /* whole exponents (to rounding) are multiplied out exactly */
        if (fabs(m->p - nearbyint(m->p)) <= 1e-12 * m->p && m->p <= 4096.0) m->pint = (int)nearbyint(m->p);
        if (fabs(m->q - nearbyint(m->q)) <= 1e-12 * m->q && m->q <= 4096.0) m->qint = (int)nearbyint(m->q);
        if (m->pint) m->p = m->pint;
        if (m->qint) m->q = m->qint;
        m->convex = e <= 2.0 && n <= 2.0;
        m->solid_bounded = 1;
        *lo = v3s(-1.0);
        *hi = v3s(1.0);
        st = 0;
        break;
    }
    case SHAPE_QUADRIC: {
        m->type = IM_QUADRIC;
        memcpy(m->a, o->u.quadric.a, sizeof m->a);
        int ok = 0;
        for (int i = 0; i < 10; i++) {
            if (!isfinite(m->a[i])) { ok = -1; break; }
            if (i < 9 && m->a[i] != 0.0) ok = 1;
        }
        if (ok <= 0) break;
        int b = quadric_bounds(m, lo, hi);
        if (b < 0) break; /* empty */
        if (b == 1) {
            m->solid_bounded = 1;
        } else {
            *lo = v3s(-INFINITY);
            *hi = v3s(INFINITY);
            sh->infinite = 1;
        }
        st = 0;
        break;
    }
    case SHAPE_POLY: {
        const scene_poly *pl = o->u.poly;
        if (!pl || pl->order < 1 || pl->order > GEOM_POLY_MAX || !pl->coefs) break;
        m->type = IM_POLY;
        m->order = pl->order;
        m->nterms = pl->ncoefs;
        m->coef = pl->coefs;
        if (!poly_powers_alloc(m, pl->order, pl->ncoefs)) break;
        int any = 0;
        for (int i = 0; i < pl->ncoefs; i++) {
            if (!isfinite(pl->coefs[i])) { any = -1; break; }
            if (pl->coefs[i] != 0.0 && i + 1 < pl->ncoefs) any = 1;
        }
        if (any <= 0) break;
        *lo = v3s(-INFINITY);
        *hi = v3s(INFINITY);
        sh->infinite = 1;
        st = 0;
        break;
    }
    case SHAPE_BLOB:
        m->type = IM_BLOB;
        st = blob_setup(m, o->u.blob, lo, hi);
        break;
    case SHAPE_ISOSURFACE: {
        const scene_isosurface *is = o->u.isosurface;
        if (!is || !is->fn) break;
        m->type = IM_ISO;
        m->fn = is->fn;
        m->env = is->env;
        m->iso_sphere = is->sphere;
        m->ic1 = is->c1;
        m->ic2 = is->c2;
        m->ir = is->radius;
        m->thr = is->threshold;
        m->acc = is->accuracy > 0.0 ? is->accuracy : 0.001;
        m->grad = is->max_gradient > 0.0 ? is->max_gradient : 1.1;
        m->open = (o->flags & OBJ_OPEN) != 0;
        /* max_trace below 1 is 1, above ISOSURFACE_MAXTRACE (10) is 10;
         * all_intersections is 10 (POV-Ray 3.7 parse.cpp, isosurf.h) */
        m->max_trace = is->max_trace == 0 ? ISO_MAX_TRACE : is->max_trace < 1 ? 1 : is->max_trace > ISO_MAX_TRACE ? ISO_MAX_TRACE : is->max_trace;
        m->solid_bounded = 1;
        if (m->iso_sphere) {
            if (!(m->ir > 0.0)) break;
            *lo = v3_sub(m->ic1, v3s(m->ir));
            *hi = v3_add(m->ic1, v3s(m->ir));
        } else {
            *lo = m->ic1;
            *hi = m->ic2;
        }
        m->size = v3_maxc(v3_sub(*hi, *lo));
        if (!(m->size > 0.0) || !isfinite(m->size)) break;
        st = 0;
        break;
    }
    default:
        break;
    }
    if (st != 0) {
        geom_implicit_free(m);
        return -1;
    }
    sh->data = m;
    return 0;
}

void geom_implicit_free(void *data)
{
    im_data *m = data;
    if (!m) return;
    free(m->pw);
    free(m->comp);
    geom_bvh_free(&m->comp_bvh);
    free(m);
}

int geom_implicit_hits(const geom_shape *sh, vec3 o, vec3 d, double wl, double tmin, double tmax,
                        geom_shape_hit *out, int max, int traced, geom_ray_rule rule)
{
    const im_data *m = sh->data;
    if (!m || max <= 0) return 0;
    switch (m->type) {
    case IM_SUPER: return se_hits(m, o, d, tmin, tmax, out, max);
    case IM_QUADRIC: return quadric_hits(m, o, d, tmin, tmax, out, max);
    case IM_POLY: return poly_hits(m, o, d, tmin, tmax, out, max);
    case IM_ISO: return iso_hits(m, o, d, wl, tmin, tmax, out, max, traced, rule);
    default: return blob_hits(m, o, d, tmin, tmax, out, max);
    }
}

int geom_implicit_inside(const geom_shape *sh, vec3 q)
{
    const im_data *m = sh->data;
    if (!m) return 0;
    switch (m->type) {
    case IM_SUPER: return se_norm(m, q, NULL) < 1.0;
    case IM_QUADRIC: return quadric_eval(m->a, q) < 0.0;
    case IM_POLY: return poly_eval3(m, q) < 0.0;
    case IM_ISO: return iso_in_container(m, q) && iso_f(m, q) < 0.0;
    default: return blob_field(m, q, NULL) > m->threshold;
    }
}

vec3 geom_implicit_normal(const geom_shape *sh, vec3 q, int part)
{
    const im_data *m = sh->data;
    if (!m) return v3(0, 1, 0);
    switch (m->type) {
    case IM_ISO: return iso_normal(m, q, part);
    case IM_SUPER: return se_grad(m, q);
    case IM_QUADRIC: return quadric_grad(m->a, q);
    case IM_POLY: return poly_grad(m, q);
    default: {
        vec3 g;
        blob_field(m, q, &g);
        return v3_neg(g);
    }
    }
}

int geom_implicit_solid_bounded(const geom_shape *sh)
{
    const im_data *m = sh->data;
    return m && m->solid_bounded;
}

const scene_texture *geom_blob_texture(const geom_shape *sh, vec3 q)
{
    const im_data *m = sh->data;
    if (!m || m->type != IM_BLOB) return NULL;
    if (!m->comp_tex) return NULL;
    double best = 0.0;
    const scene_texture *t = NULL;
    /* a component whose box does not hold q gives it no field */
    blob_cands cd;
    cands_at(m, q, &cd);
    for (int k = 0; k < cd.n; k++) {
        const blob_comp *c = &m->comp[cd.idx[k]];
        double f = blob_comp_field(c, q, NULL);
        if (f > best) {
            best = f;
            t = c->tex;
        }
    }
    cands_free(&cd);
    return t;
}

/* ------------------------------------------------------------ grid */

static double spow(double x, double p) { return copysign(pow(fabs(x), p), x); }

int geom_implicit_grid(const geom_shape *sh, int n, geom_grid_fn fn, void *ctx)
{
    const im_data *m = sh->data;
    if (!m || m->type != IM_SUPER) return 0;
    /* POV-Ray's superellipsoid as the signed-power sphere: angle u around z
     * for the x, y exponent 2/p = e, angle v from the equator for n = 2/q */
    int nu = 4 * n, nv = 2 * n, count = 0;
    double e = 2.0 / m->p, nn = 2.0 / m->q;
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            vec3 P[4], N[4];
            for (int c = 0; c < 4; c++) {
                double u = 2.0 * M_PI * (i + (c == 1 || c == 2)) / nu - M_PI;
                double v = M_PI * (j + (c >= 2)) / nv - 0.5 * M_PI;
                double cv = spow(cos(v), nn);
                P[c] = v3(cv * spow(cos(u), e), cv * spow(sin(u), e), spow(sin(v), nn));
                N[c] = se_grad(m, P[c]);
            }
            vec3 t1[3] = {P[0], P[1], P[2]}, n1[3] = {N[0], N[1], N[2]};
            vec3 t2[3] = {P[0], P[2], P[3]}, n2[3] = {N[0], N[2], N[3]};
            if (v3_len2(v3_cross(v3_sub(P[1], P[0]), v3_sub(P[2], P[0]))) > 0.0) {
                if (!fn(ctx, t1, n1)) return -1;
                count++;
            }
            if (v3_len2(v3_cross(v3_sub(P[2], P[0]), v3_sub(P[3], P[0]))) > 0.0) {
                if (!fn(ctx, t2, n2)) return -1;
                count++;
            }
        }
    return count;
}
