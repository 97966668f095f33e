/* geom_fractal.c - julia_fractal (geom_fractal.h).
 *
 * Hypercomplex numbers x + y i + z j + w k (POV-Ray's commutative algebra:
 * its square is (x2 + w2 - y2 - z2, 2(xy - zw), 2(xz - wy), 2(xw + yz)))
 * are handled as the pair of complex numbers a = (x - w) + i (y + z),
 * b = (x + w) + i (y - z): products act on a and b separately, so
 * f(x + y i + z j + w k) is (f(a), f(b)) for any analytic f. */
#include "geom_fractal.h"
#include <complex.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* glibc defines CMPLX only for GCC >= 4.7; clang (the sanitizer and fuzz
 * build) has the same builtin. */
#ifndef CMPLX
#define CMPLX(x, y) __builtin_complex((double)(x), (double)(y))
#endif

#define FRACTAL_TOLERANCE 1e-7

typedef struct {
    double c[4];
    int hyper;
    scene_julia_func func;
    double complex pwr;
    int n;                /* max_iteration */
    double step;          /* 1 / precision */
    double slice[4], sdist;
    double inv_s3;        /* 1 / slice[3] where that is exact (a power of two), else 0 */
    double R, exit;       /* bounding radius, bailout on |z|^2 */
    double complex ca, cb; /* c as the complex pair (hypercomplex) */
    double rho;           /* every point farther from the centre escapes (jf_escape_radius); 0: none known */
    double rho_a, rho_b;  /* hypercomplex: the same for either number of the pair alone; 0: none */
} jf_data;

/* The slice: z0 = (x, y, z, w(x, y, z)). */
static void lift(const jf_data *f, vec3 p, double q[4])
{
    q[0] = p.x;
    q[1] = p.y;
    q[2] = p.z;
    double w = f->sdist - f->slice[0] * p.x - f->slice[1] * p.y - f->slice[2] * p.z;
    /* the quotient by a power of two is the product by its reciprocal, bit
     * for bit, and a division is the longest step of a test's first
     * iteration (the default slice's w component is 1) */
    q[3] = f->inv_s3 != 0.0 ? w * f->inv_s3 : w / f->slice[3];
}

static void qmul(const double a[4], const double b[4], double r[4])
{
    double t[4];
    t[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
    t[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
    t[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
    t[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
    memcpy(r, t, sizeof t);
}

static void to_pair(const double q[4], double complex *a, double complex *b)
{
    *a = CMPLX(q[0] - q[3], q[1] + q[2]);
    *b = CMPLX(q[0] + q[3], q[1] - q[2]);
}

/* Plain complex product (C's `*` goes through the Annex G inf/nan
 * handling, several times slower). */
static inline double complex cmul(double complex a, double complex b)
{
    double ar = creal(a), ai = cimag(a), br = creal(b), bi = cimag(b);
    return CMPLX(ar * br - ai * bi, ar * bi + ai * br);
}

static double complex cfun(const jf_data *f, double complex z)
{
    switch (f->func) {
    case JULIA_SQR: return cmul(z, z);
    case JULIA_CUBE: return cmul(cmul(z, z), z);
    case JULIA_EXP: return cexp(z);
    case JULIA_LN: return clog(z);
    case JULIA_SIN: return csin(z);
    case JULIA_ASIN: return casin(z);
    case JULIA_COS: return ccos(z);
    case JULIA_ACOS: return cacos(z);
    case JULIA_TAN: return ctan(z);
    case JULIA_ATAN: return catan(z);
    case JULIA_SINH: return csinh(z);
    case JULIA_ASINH: return casinh(z);
    case JULIA_COSH: return ccosh(z);
    case JULIA_ACOSH: return cacosh(z);
    case JULIA_TANH: return ctanh(z);
    case JULIA_ATANH: return catanh(z);
    case JULIA_RECIPROCAL: return 1.0 / z;
    default: return cpow(z, f->pwr);
    }
}

static double complex cderiv(const jf_data *f, double complex z)
{
    switch (f->func) {
    case JULIA_SQR: return 2.0 * z;
    case JULIA_CUBE: return 3.0 * cmul(z, z);
    case JULIA_EXP: return cexp(z);
    case JULIA_LN: return 1.0 / z;
    case JULIA_SIN: return ccos(z);
    case JULIA_ASIN: return 1.0 / csqrt(1.0 - z * z);
    case JULIA_COS: return -csin(z);
    case JULIA_ACOS: return -1.0 / csqrt(1.0 - z * z);
    case JULIA_TAN: { double complex c = ccos(z); return 1.0 / (c * c); }
    case JULIA_ATAN: return 1.0 / (1.0 + z * z);
    case JULIA_SINH: return ccosh(z);
    case JULIA_ASINH: return 1.0 / csqrt(1.0 + z * z);
    case JULIA_COSH: return csinh(z);
    case JULIA_ACOSH: return 1.0 / (csqrt(z - 1.0) * csqrt(z + 1.0));
    case JULIA_TANH: { double complex c = ccosh(z); return 1.0 / (c * c); }
    case JULIA_ATANH: return 1.0 / (1.0 - z * z);
    case JULIA_RECIPROCAL: return -1.0 / (z * z);
    default: return f->pwr * cpow(z, f->pwr - 1.0);
    }
}

/* The direction e of a ray in the slice, as the complex pair: a step
 * along e moves w by -(slice . e) / slice_w (lift). The same for every
 * point of the ray, so taken once per ray. */
static void jf_dir_pair(const jf_data *f, vec3 e, double complex dp[2])
{
    double dq[4] = {e.x, e.y, e.z, -(f->slice[0] * e.x + f->slice[1] * e.y + f->slice[2] * e.z) / f->slice[3]};
    to_pair(dq, &dp[0], &dp[1]);
}

/* Inside test; when outside and `de` is given, a step estimate: for
 * quaternions POV-Ray's distance estimate |z| ln|z|^2 / (k^i prod |z_j|)
 * (k = 2 or 3); for hypercomplex numbers POV-Ray's rule F / (2 |dF/dt|)
 * along the ray direction (F = |z|^2 at the escape, used only while the
 * ray approaches and the step stays within 1 to 30 precision steps), else 0.
 * For hypercomplex numbers (da0, db0) is that direction lifted to the slice
 * as the complex pair (jf_dir_pair), read only when `de` is given. */
static int jf_inside(const jf_data *f, double px, double py, double pz, double complex da0, double complex db0,
                     double *de)
{
    /* the point as three numbers, not a vec3: a structure of three is
     * passed through memory, and the march's caller stored it in pieces
     * just before the callee loaded it whole, a stalled store forwarding */
    double q[4];
    lift(f, v3(px, py, pz), q);
    if (de) *de = 0.0;
    if (!f->hyper && (f->func == JULIA_SQR || f->func == JULIA_CUBE)) {
        /* q^2 + c and q^3 + c written out as POV-Ray's Iteration_Julia and
         * Iteration_z3 do (quatern.cpp): with d = y^2 + z^2 + w^2,
         * q^2 = (x^2 - d, 2x (y, z, w)), q^3 = (x (x^2 - 3d), (3x^2 - d) (y, z, w));
         * the distance estimate's product of |z_j| is kept squared, one
         * root at the escape */
        const int cube = f->func == JULIA_CUBE;
        const double k = cube ? 3.0 : 2.0;
        double x = q[0], y = q[1], z = q[2], w = q[3], prod2 = 1.0, pw = 1.0;
        for (int i = 1; i <= f->n; i++) {
            double d = y * y + z * z + w * w, x2 = x * x, r2 = d + x2;
            prod2 *= r2;
            pw *= k;
            if (r2 > f->exit) {
                if (de && prod2 > 0.0) *de = sqrt(r2 / prod2) * log(r2) / pw;
                return 0;
            }
            double s = cube ? 3.0 * x2 - d : 2.0 * x;
            x = (cube ? x * (x2 - 3.0 * d) : x2 - d) + f->c[0];
            y = s * y + f->c[1];
            z = s * z + f->c[2];
            w = s * w + f->c[3];
        }
        return 1;
    }
    if (!f->hyper) {
        double k = f->func == JULIA_CUBE ? 3.0 : 2.0, prod = 1.0, pw = 1.0;
        for (int i = 1; i <= f->n; i++) {
            double r2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
            prod *= sqrt(r2);
            pw *= k;
            if (r2 > f->exit) {
                if (de && prod > 0.0) *de = sqrt(r2) * log(r2) / (pw * prod);
                return 0;
            }
            double t[4];
            qmul(q, q, t);
            if (f->func == JULIA_CUBE) qmul(t, q, t);
            for (int j = 0; j < 4; j++) q[j] = t[j] + f->c[j];
        }
        return 1;
    }
    double complex a, b, da = 0, db = 0;
    to_pair(q, &a, &b);
    if (de) {
        da = da0;
        db = db0;
    }
    if (f->func == JULIA_SQR) {
        /* the same iteration with the squares written out (no call per step) */
        double ar = creal(a), ai = cimag(a), br = creal(b), bi = cimag(b);
        double dar = creal(da), dai = cimag(da), dbr = creal(db), dbi = cimag(db);
        const double car = creal(f->ca), cai = cimag(f->ca), cbr = creal(f->cb), cbi = cimag(f->cb);
        for (int i = 1; i <= f->n; i++) {
            double ar2 = ar * ar, ai2 = ai * ai, br2 = br * br, bi2 = bi * bi;
            double r2 = 0.5 * (ar2 + ai2 + br2 + bi2);
            if (!(r2 <= f->exit)) {
                if (de) {
                    double dF = (ar * dar + ai * dai) + (br * dbr + bi * dbi);
                    if (dF < -1e-7) {
                        double S = -2.0 * dF;
                        if (r2 > f->step * S && r2 < 30.0 * f->step * S) *de = r2 / S;
                    }
                }
                return 0;
            }
            if (de) { /* d(z^2) = 2 z dz */
                double t = 2.0 * (dar * ar - dai * ai);
                dai = 2.0 * (dar * ai + dai * ar);
                dar = t;
                t = 2.0 * (dbr * br - dbi * bi);
                dbi = 2.0 * (dbr * bi + dbi * br);
                dbr = t;
            }
            ai = 2.0 * ar * ai + cai;
            ar = ar2 - ai2 + car;
            bi = 2.0 * br * bi + cbi;
            br = br2 - bi2 + cbr;
        }
        return 1;
    }
    for (int i = 1; i <= f->n; i++) {
        double r2 = 0.5 * (creal(a) * creal(a) + cimag(a) * cimag(a) + creal(b) * creal(b) + cimag(b) * cimag(b));
        if (!(r2 <= f->exit)) {
            if (de) {
                double dF = creal(cmul(conj(a), da)) + creal(cmul(conj(b), db));
                if (dF < -1e-7) {
                    double S = -2.0 * dF;
                    if (r2 > f->step * S && r2 < 30.0 * f->step * S) *de = r2 / S;
                }
            }
            return 0;
        }
        if (de) {
            da = cmul(da, cderiv(f, a));
            db = cmul(db, cderiv(f, b));
        }
        a = cfun(f, a) + f->ca;
        b = cfun(f, b) + f->cb;
    }
    return 1;
}

/* jf_inside without the step estimate */
static int jf_at(const jf_data *f, vec3 p) { return jf_inside(f, p.x, p.y, p.z, 0, 0, NULL); }

typedef double jf_v2 __attribute__((vector_size(16)));
typedef long long jf_m2 __attribute__((vector_size(16))); /* a lane comparison: -1 or 0 */

/* g^-(n-1)(E) for g(r) = r^k - c (k = 2, 3), widened by a relative 1e-6,
 * far beyond the rounding of the iteration: a start with |z_0| beyond it
 * has |z_(n-1)| > E, as |z^k + c| >= |z|^k - |c| and g is increasing. */
static double jf_back_radius(const jf_data *f, double c, double E)
{
    double r = E;
    for (int i = 1; i < f->n; i++) r = f->func == JULIA_CUBE ? cbrt(r + c) : sqrt(r + c);
    return r * (1.0 + 1e-6);
}

/* A radius beyond which every point escapes within max_iteration, for the
 * iterations z -> z^k + c (k = 2, 3) whose norm grows as |z|^k
 * (jf_back_radius). Quaternions: the norm is multiplicative, E^2 the
 * bailout. Hypercomplex numbers: the complex pair (a, b) iterates
 * a -> a^k + ca and b -> b^k + cb apart, with |z|^2 = (|a|^2 + |b|^2) / 2,
 * so either of |a|, |b| alone exceeds the bailout once its square passes
 * twice it: ra and rb get the radii for a and b apart (the larger of
 * |a|, |b| is at least |z|, so the larger radius holds for |z|). The
 * lifted point's norm is at least the 3-D point's (lift adds w). Returns
 * 0 for the other functions or where the radius is not below R (then ra
 * and rb are 0 too). */
static double jf_escape_radius(const jf_data *f, double *ra, double *rb)
{
    const int cube = f->func == JULIA_CUBE;
    *ra = *rb = 0.0;
    if (f->hyper && f->func != JULIA_SQR && !cube) return 0.0;
    double r;
    if (f->hyper) {
        const double E = sqrt(2.0 * f->exit);
        *ra = jf_back_radius(f, cabs(f->ca), E);
        *rb = jf_back_radius(f, cabs(f->cb), E);
        r = fmax(*ra, *rb);
    } else {
        /* jf_inside iterates the square for every quaternion function but the cube */
        r = jf_back_radius(f, sqrt(f->c[0] * f->c[0] + f->c[1] * f->c[1] + f->c[2] * f->c[2] + f->c[3] * f->c[3]),
                           sqrt(f->exit));
    }
    if (isfinite(r) && r < f->R && isfinite(*ra) && isfinite(*rb)) return r;
    *ra = *rb = 0.0;
    return 0.0;
}

int geom_fractal_init(geom_shape *sh, const scene_object *o, vec3 *lo, vec3 *hi)
{
    const scene_julia *j = o->u.julia;
    if (!j) return -1;
    jf_data *f = calloc(1, sizeof *f);
    if (!f) return -1;
    memcpy(f->c, j->c, sizeof f->c);
    f->hyper = j->hypercomplex;
    f->func = j->func;
    f->pwr = CMPLX(j->pwr[0], j->pwr[1]);
    f->n = j->max_iteration > 0 ? j->max_iteration : 1;
    f->step = 1.0 / (j->precision >= 1.0 ? j->precision : 1.0);
    memcpy(f->slice, j->slice, sizeof f->slice);
    f->sdist = j->slice_dist;
    if (!(fabs(f->slice[3]) > 0.0)) {
        free(f);
        return -1;
    }
    int ex;
    f->inv_s3 = fabs(frexp(f->slice[3], &ex)) == 0.5 && isfinite(1.0 / f->slice[3]) ? 1.0 / f->slice[3] : 0.0;
    if (!f->hyper) {
        double R = 1.0 + sqrt(f->c[0] * f->c[0] + f->c[1] * f->c[1] + f->c[2] * f->c[2] + f->c[3] * f->c[3]) + 1e-7;
        f->R = R > 2.0 ? 2.0 : R;
        f->exit = f->R * f->R + 1e-7;
    } else {
        f->R = 4.0;
        f->exit = 16.0;
        to_pair(f->c, &f->ca, &f->cb);
    }
    f->rho = jf_escape_radius(f, &f->rho_a, &f->rho_b);
    *lo = v3s(-f->R);
    *hi = v3s(f->R);
    sh->data = f;
    return 0;
}

void geom_fractal_free(void *data) { free(data); }

/* The crossing between lo (answer `cur`) and hi (the other answer) by
 * POV-Ray's bisection (jf_polish), one test per halving: for the fractals
 * without jf_level3. */
static double jf_bisect(const jf_data *f, vec3 p0, vec3 e, double lo, double hi, int cur)
{
    for (int it = 0; it < 200 && hi - lo > FRACTAL_TOLERANCE; it++) {
        double m = 0.5 * (lo + hi);
        if (jf_at(f, v3_madd(p0, e, m)) == cur) lo = m;
        else hi = m;
    }
    return 0.5 * (lo + hi);
}

/* jf_inside's answers at three points at once, for the fractals whose
 * iteration is written out there (quaternion sqr and cube, hypercomplex
 * sqr): p[0] on its own and p[1], p[2] in a two-lane vector, each doing
 * jf_inside's operations in its order up to its escape, so each answer is
 * jf_inside's. In F[k] a smooth function of p[k] whose sign is nearly
 * always the answer's: (u - 1) / (u + 1) with u = |z_(n-1)|^2 over the
 * bailout, the iteration run on past the escape (past the bailout
 * |z^k + c| >= |z|^k - |c| exceeds |z|: the iterates do not come back), 1
 * where they grow past 1e100. Returns 0 (nothing written) for the other
 * fractals. */
static int jf_level3(const jf_data *f, const vec3 p[3], int res[3], double F[3])
{
    const int quat = !f->hyper && (f->func == JULIA_SQR || f->func == JULIA_CUBE), cube = f->func == JULIA_CUBE;
    if (!quat && !(f->hyper && f->func == JULIA_SQR)) return 0;
    double q[3][4];
    for (int k = 0; k < 3; k++) lift(f, p[k], q[k]);
    const double exit = f->exit, big = 1e100;
    const jf_v2 ex = {exit, exit}, bg = {big, big};
    jf_m2 e1 = {0, 0}, g1 = {0, 0};
    jf_v2 r21 = {0, 0};
    int e0 = 0, g0 = 0;
    double r20 = 0.0;
    if (quat) {
        double x0 = q[0][0], y0 = q[0][1], z0 = q[0][2], w0 = q[0][3];
        jf_v2 x1 = {q[1][0], q[2][0]}, y1 = {q[1][1], q[2][1]}, z1 = {q[1][2], q[2][2]}, w1 = {q[1][3], q[2][3]};
        const jf_v2 c0 = {f->c[0], f->c[0]}, c1 = {f->c[1], f->c[1]}, c2 = {f->c[2], f->c[2]}, c3 = {f->c[3], f->c[3]};
        for (int i = 1; i <= f->n; i++) {
            double d0 = y0 * y0 + z0 * z0 + w0 * w0, x20 = x0 * x0;
            jf_v2 d1 = y1 * y1 + z1 * z1 + w1 * w1, x21 = x1 * x1;
            r20 = d0 + x20;
            r21 = d1 + x21;
            e0 |= r20 > exit;
            e1 |= r21 > ex;
            g0 = !(r20 <= big);
            g1 = ~(r21 <= bg);
            if (g0 && g1[0] && g1[1]) break;
            double s0 = cube ? 3.0 * x20 - d0 : 2.0 * x0;
            jf_v2 s1 = cube ? 3.0 * x21 - d1 : 2.0 * x1;
            x0 = (cube ? x0 * (x20 - 3.0 * d0) : x20 - d0) + c0[0];
            x1 = (cube ? x1 * (x21 - 3.0 * d1) : x21 - d1) + c0;
            y0 = s0 * y0 + c1[0];
            y1 = s1 * y1 + c1;
            z0 = s0 * z0 + c2[0];
            z1 = s1 * z1 + c2;
            w0 = s0 * w0 + c3[0];
            w1 = s1 * w1 + c3;
        }
    } else {
        /* to_pair: a = (x - w) + i (y + z), b = (x + w) + i (y - z) */
        double ar0 = q[0][0] - q[0][3], ai0 = q[0][1] + q[0][2], br0 = q[0][0] + q[0][3], bi0 = q[0][1] - q[0][2];
        jf_v2 ar1 = {q[1][0] - q[1][3], q[2][0] - q[2][3]}, ai1 = {q[1][1] + q[1][2], q[2][1] + q[2][2]};
        jf_v2 br1 = {q[1][0] + q[1][3], q[2][0] + q[2][3]}, bi1 = {q[1][1] - q[1][2], q[2][1] - q[2][2]};
        const double car = creal(f->ca), cai = cimag(f->ca), cbr = creal(f->cb), cbi = cimag(f->cb);
        for (int i = 1; i <= f->n; i++) {
            double ar20 = ar0 * ar0, ai20 = ai0 * ai0, br20 = br0 * br0, bi20 = bi0 * bi0;
            jf_v2 ar21 = ar1 * ar1, ai21 = ai1 * ai1, br21 = br1 * br1, bi21 = bi1 * bi1;
            r20 = 0.5 * (ar20 + ai20 + br20 + bi20);
            r21 = 0.5 * (ar21 + ai21 + br21 + bi21);
            e0 |= !(r20 <= exit);
            e1 |= ~(r21 <= ex);
            g0 = !(r20 <= big);
            g1 = ~(r21 <= bg);
            if (g0 && g1[0] && g1[1]) break;
            ai0 = 2.0 * ar0 * ai0 + cai;
            ai1 = 2.0 * ar1 * ai1 + cai;
            ar0 = ar20 - ai20 + car;
            ar1 = ar21 - ai21 + car;
            bi0 = 2.0 * br0 * bi0 + cbi;
            bi1 = 2.0 * br1 * bi1 + cbi;
            br0 = br20 - bi20 + cbr;
            br1 = br21 - bi21 + cbr;
        }
    }
    res[0] = !e0;
    res[1] = !e1[0];
    res[2] = !e1[1];
    const double u[3] = {r20 / exit, r21[0] / exit, r21[1] / exit};
    const int g[3] = {g0, g1[0] != 0, g1[1] != 0};
    for (int j = 0; j < 3; j++) F[j] = g[j] ? 1.0 : (u[j] - 1.0) / (u[j] + 1.0);
    return 1;
}

/* The crossing between the march's points lo (answer `cur`) and hi (the
 * other answer), in the ray's length from p0 along the unit e, placed as
 * POV-Ray places it: by bisection to Fractal_Tolerance (1e-7 in the
 * fractal's space, fractal.cpp), halving [lo, hi] and keeping the half
 * whose ends' answers differ until it is shorter than that, at the last
 * piece's middle. Far finer than the set's detail at any usable
 * precision, so the halvings are taken three at a time: jf_level3 tests
 * the next three midpoints of the path the crossing's estimate predicts
 * (regula falsi on jf_level3's smooth function at the ends, or the secant
 * through an end's last two places), and the halvings follow the answers
 * while each midpoint is the one the halving itself computes from its
 * ends. Every point and answer is the one-at-a-time bisection's; a wrong
 * prediction only wastes the lanes after it. The first call takes the
 * midpoint and both quarter points, two halvings, whichever way they go. */
static double jf_polish(const jf_data *f, vec3 p0, vec3 e, double lo, double hi, int cur)
{
    double m = 0.5 * (lo + hi), x[3] = {m, 0.5 * (lo + m), 0.5 * (m + hi)}, F[3];
    int r[3];
    vec3 pts[3] = {v3_madd(p0, e, x[0]), v3_madd(p0, e, x[1]), v3_madd(p0, e, x[2])};
    if (!(hi - lo > FRACTAL_TOLERANCE)) return m;
    if (!jf_level3(f, pts, r, F)) return jf_bisect(f, p0, e, lo, hi, cur);
    /* each end's smooth value where known, and the end's place and value before it last moved */
    double Flo = NAN, Fhi = NAN, plo = NAN, Fplo = NAN, phi = NAN, Fphi = NAN;
    int it = 0, first = 1;
    for (;;) {
        for (int j = 0; j < 3 && it < 200 && hi - lo > FRACTAL_TOLERANCE; j++) {
            double mj = 0.5 * (lo + hi);
            /* the first call's lanes: the midpoint, then a quarter point */
            int k = first ? (j == 0 ? 0 : (r[0] == cur ? 2 : 1)) : j;
            if (mj != x[k] || (first && j > 1)) break;
            if (r[k] == cur) {
                plo = lo, Fplo = Flo;
                lo = mj, Flo = F[k];
            } else {
                phi = hi, Fphi = Fhi;
                hi = mj, Fhi = F[k];
            }
            it++;
        }
        first = 0;
        if (!(it < 200 && hi - lo > FRACTAL_TOLERANCE)) break;
        double est = NAN;
        if (Flo * Fhi < 0.0) est = lo + (hi - lo) * (Flo / (Flo - Fhi));
        else if (isfinite(Flo) && isfinite(Fplo)) est = lo - Flo * ((lo - plo) / (Flo - Fplo));
        else if (isfinite(Fhi) && isfinite(Fphi)) est = hi - Fhi * ((hi - phi) / (Fhi - Fphi));
        /* the path to the estimate (a point at or below it has lo's answer) */
        double a = lo, b = hi;
        for (int j = 0; j < 3; j++) {
            x[j] = 0.5 * (a + b);
            if (x[j] <= est) a = x[j];
            else b = x[j];
            pts[j] = v3_madd(p0, e, x[j]);
        }
        jf_level3(f, pts, r, F);
    }
    return 0.5 * (lo + hi);
}

/* The parameters t0 <= t1 where a line x + t v meets a ball, from
 * A = v.v, B = x.v, C = x.x - r^2 (x relative to the centre): 0 when it
 * misses or only grazes it. */
static int ball_chord(double A, double B, double C, double *t0, double *t1)
{
    double disc = B * B - A * C;
    if (!(disc > 0.0)) return 0;
    double sq = sqrt(disc);
    *t0 = (-B - sq) / A;
    *t1 = (-B + sq) / A;
    return 1;
}

int geom_fractal_hits(const geom_shape *sh, vec3 o, vec3 d, double tmin, double tmax, geom_shape_hit *out, int max)
{
    const jf_data *f = sh->data;
    if (!f || max <= 0) return 0;
    /* the bounding sphere */
    double A = v3_dot(d, d), t0, t1;
    if (!ball_chord(A, v3_dot(o, d), v3_dot(o, o) - f->R * f->R, &t0, &t1)) return 0;
    double a = fmax_inline(t0, tmin), b = fmin_inline(t1, tmax);
    if (!(a < b)) return 0;
    double s = sqrt(A);
    vec3 e = v3_scale(d, 1.0 / s), p0 = v3_madd(o, d, a);
    double len = (b - a) * s, tau = 0.0, de;
    /* the march's points follow POV-Ray's from the bounding sphere on, but
     * it ends where the ray leaves the ball every point beyond which
     * escapes: past it every answer is outside and no crossing follows */
    double end = len;
    if (f->rho > 0.0) {
        double r0, r1;
        if (!ball_chord(1.0, v3_dot(p0, e), v3_dot(p0, p0) - f->rho * f->rho, &r0, &r1)) return 0;
        if (!(r1 > 0.0) || !(r0 < len)) return 0;
        end = fmin_inline(len, r1);
    }
    double complex dp[2] = {0, 0};
    if (f->hyper) jf_dir_pair(f, e, dp);
    if (f->rho_a > 0.0) {
        /* the same for the pair's numbers apart: the ray's a and b are
         * a0 + t da and b0 + t db (the direction's pair, jf_dir_pair) */
        double q[4];
        double complex pa[2];
        lift(f, p0, q);
        to_pair(q, &pa[0], &pa[1]);
        const double rr[2] = {f->rho_a, f->rho_b};
        for (int k = 0; k < 2; k++) {
            double A2 = creal(dp[k]) * creal(dp[k]) + cimag(dp[k]) * cimag(dp[k]);
            double B2 = creal(pa[k]) * creal(dp[k]) + cimag(pa[k]) * cimag(dp[k]);
            double C2 = creal(pa[k]) * creal(pa[k]) + cimag(pa[k]) * cimag(pa[k]) - rr[k] * rr[k];
            if (!(A2 > 0.0)) {
                if (C2 > 0.0) return 0;
                continue;
            }
            double r0, r1;
            if (!ball_chord(A2, B2, C2, &r0, &r1)) return 0;
            if (!(r1 > 0.0) || !(r0 < len)) return 0;
            end = fmin_inline(end, r1);
        }
    }
    int cur = jf_inside(f, p0.x, p0.y, p0.z, dp[0], dp[1], &de), n = 0;
    for (long guard = 0; tau < end && guard < 10000000; guard++) {
        if (n == max && a + tau / s > out[max - 1].t) break;
        double step = cur ? f->step : fmax_inline(de, f->step);
        double tn = fmin_inline(tau + step, len);
        double den;
        vec3 pn = v3_madd(p0, e, tn);
        int next = jf_inside(f, pn.x, pn.y, pn.z, dp[0], dp[1], &den);
        if (next != cur) {
            double t = a + jf_polish(f, p0, e, tau, tn, cur) / s;
            if (t > tmin && t < tmax) n = geom_shape_hit_put(out, n, max, t, 0);
        }
        tau = tn;
        cur = next;
        de = den;
    }
    return n;
}

int geom_fractal_inside(const geom_shape *sh, vec3 q)
{
    const jf_data *f = sh->data;
    if (!f || v3_len2(q) > f->R * f->R || (f->rho > 0.0 && v3_len2(q) > f->rho * f->rho)) return 0;
    return jf_at(f, q);
}

/* Gradient of |z_N|^2 with respect to (x, y, z): z0 moves along the slice. */
vec3 geom_fractal_normal(const geom_shape *sh, vec3 p)
{
    const jf_data *f = sh->data;
    if (!f) return v3(0, 1, 0);
    /* the point just inside, where all N iterates exist */
    double q[4], dq[3][4];
    lift(f, p, q);
    for (int k = 0; k < 3; k++) {
        memset(dq[k], 0, sizeof dq[k]);
        dq[k][k] = 1.0;
        dq[k][3] = -f->slice[k] / f->slice[3];
    }
    double g[3] = {0, 0, 0};
    if (!f->hyper) {
        for (int i = 1; i <= f->n; i++) {
            double q2[4], t[4], u[4];
            qmul(q, q, q2);
            for (int k = 0; k < 3; k++) {
                if (f->func == JULIA_CUBE) {
                    /* d(q^3) = dq q^2 + q dq q + q^2 dq */
                    double a1[4], a2[4], a3[4];
                    qmul(dq[k], q2, a1);
                    qmul(q, dq[k], t);
                    qmul(t, q, a2);
                    qmul(q2, dq[k], a3);
                    for (int j = 0; j < 4; j++) dq[k][j] = a1[j] + a2[j] + a3[j];
                } else {
                    /* d(q^2) = q dq + dq q */
                    qmul(q, dq[k], t);
                    qmul(dq[k], q, u);
                    for (int j = 0; j < 4; j++) dq[k][j] = t[j] + u[j];
                }
            }
            double nq[4];
            if (f->func == JULIA_CUBE) qmul(q2, q, nq);
            else memcpy(nq, q2, sizeof nq);
            for (int j = 0; j < 4; j++) q[j] = nq[j] + f->c[j];
            if (!(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] < 1e200)) break;
        }
        for (int k = 0; k < 3; k++) g[k] = q[0] * dq[k][0] + q[1] * dq[k][1] + q[2] * dq[k][2] + q[3] * dq[k][3];
    } else {
        double complex a, b, da[3], db[3];
        to_pair(q, &a, &b);
        for (int k = 0; k < 3; k++) to_pair(dq[k], &da[k], &db[k]);
        for (int i = 1; i <= f->n; i++) {
            double complex fa = cderiv(f, a), fb = cderiv(f, b);
            for (int k = 0; k < 3; k++) {
                da[k] = cmul(da[k], fa);
                db[k] = cmul(db[k], fb);
            }
            a = cfun(f, a) + f->ca;
            b = cfun(f, b) + f->cb;
            if (!(cabs(a) + cabs(b) < 1e100)) break;
        }
        for (int k = 0; k < 3; k++) g[k] = creal(cmul(conj(a), da[k])) + creal(cmul(conj(b), db[k]));
    }
    vec3 n = v3(g[0], g[1], g[2]);
    return v3_finite(n) && v3_len2(n) > 0.0 ? n : v3_norm(p);
}
