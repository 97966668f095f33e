/* geom_poly.c - polynomial roots in an interval (geom_poly.h).
 *
 * Derivative brackets: between consecutive critical points a polynomial is
 * monotonic, so a sign change there brackets exactly one root (the
 * isolation idea of Yuksel, "High-Performance Polynomial Root Finding for
 * Graphics", HPG 2022, applied recursively to any degree). A critical point
 * where the value is zero within the rounding bound of the evaluation is a
 * touching (double) root: a ray grazing the surface.
 *
 * Sturm: Sturm's theorem (the number of distinct real roots in (a, b] is
 * V(a) - V(b), V the sign changes of the sequence p, p', -rem(p, p'), ...),
 * with bisection until every interval isolates one root. */
#include "geom_poly.h"
#include <float.h>
#include <math.h>
#include <string.h>

double geom_poly_eval(const double *c, int n, double x)
{
    double f = c[n];
    for (int i = n - 1; i >= 0; i--) f = f * x + c[i];
    return f;
}

/* Rounding bound of Horner's evaluation at x (Higham, Accuracy and
 * Stability of Numerical Algorithms, 5.1: about 2n u sum |c_i| |x|^i). */
static double eval_bound(const double *c, int n, double x)
{
    double ax = fabs(x), s = fabs(c[n]);
    for (int i = n - 1; i >= 0; i--) s = s * ax + fabs(c[i]);
    return 2.0 * (n + 1) * DBL_EPSILON * s;
}

/* f monotonic on [lo, hi] with f(lo) = flo, f(hi) = fhi of opposite
 * signs. Newton from the secant point (the chord's zero is inside the
 * bracket and near the root when the bracket is wide, where the midpoint
 * costs bisections first), bisecting when a step leaves the bracket. */
static double refine(const double *c, int n, double lo, double hi, double flo, double fhi)
{
    double width = hi - lo;
    double x = lo - flo * (hi - lo) / (fhi - flo);
    if (!(x > lo && x < hi)) x = 0.5 * (lo + hi);
    for (int it = 0; it < 200; it++) {
        double f = c[n], df = 0.0;
        for (int i = n - 1; i >= 0; i--) {
            df = df * x + f;
            f = f * x + c[i];
        }
        if (f == 0.0) return x;
        if ((f < 0.0) == (flo < 0.0)) lo = x; else hi = x;
        double xn = (df != 0.0) ? x - f / df : 0.5 * (lo + hi);
        if (!(xn > lo && xn < hi)) xn = 0.5 * (lo + hi);
        double step = fabs(xn - x);
        x = xn;
        /* a few ulps: below one ulp of x a Newton step at the root can
         * alternate between neighbouring doubles for all 200 iterations */
        if (step <= 4.0 * DBL_EPSILON * (fabs(x) + width) || hi - lo <= 4.0 * DBL_EPSILON * (fabs(x) + width)) break;
    }
    return x;
}

static int push_root(double *roots, int nr, double r)
{
    if (nr > 0 && r <= roots[nr - 1]) return nr;
    roots[nr] = r;
    return nr + 1;
}

static int trim(const double *c, int n)
{
    while (n > 0 && c[n] == 0.0) n--;
    return n;
}

/* ------------------------------------------------------------ derivative brackets */

static int solve_brackets(const double *c, int n, double a, double b, double *roots)
{
    n = trim(c, n);
    if (n <= 0) return 0;
    if (n == 1) {
        double r = -c[0] / c[1];
        if (r >= a && r <= b) {
            roots[0] = r;
            return 1;
        }
        return 0;
    }
    if (n == 2) {
        double A = c[2], B = c[1], C = c[0];
        double disc = B * B - 4.0 * A * C;
        if (disc < 0.0) {
            /* touching within rounding: the vertex */
            double xv = -B / (2.0 * A);
            if (xv >= a && xv <= b && fabs(geom_poly_eval(c, 2, xv)) <= eval_bound(c, 2, xv)) {
                roots[0] = xv;
                return 1;
            }
            return 0;
        }
        double q = -0.5 * (B + copysign(sqrt(disc), B));
        double r0 = q / A, r1 = (q != 0.0) ? C / q : r0;
        if (r0 > r1) { double t = r0; r0 = r1; r1 = t; }
        int nr = 0;
        if (r0 >= a && r0 <= b) roots[nr++] = r0;
        if (r1 >= a && r1 <= b && (nr == 0 || r1 > roots[0])) roots[nr++] = r1;
        return nr;
    }
    double d[GEOM_POLY_MAX + 1], crit[GEOM_POLY_MAX + 1], xs[GEOM_POLY_MAX + 2];
    for (int i = 0; i < n; i++) d[i] = (double)(i + 1) * c[i + 1];
    int nc = solve_brackets(d, n - 1, a, b, crit);
    xs[0] = a;
    int m = 1;
    for (int i = 0; i < nc; i++)
        if (crit[i] > xs[m - 1] && crit[i] < b) xs[m++] = crit[i];
    xs[m++] = b;
    int nr = 0;
    double f0 = geom_poly_eval(c, n, a);
    if (f0 == 0.0) nr = push_root(roots, nr, a);
    for (int j = 0; j + 1 < m; j++) {
        double x0 = xs[j], x1 = xs[j + 1];
        double f1 = geom_poly_eval(c, n, x1);
        if (f1 == 0.0) {
            nr = push_root(roots, nr, x1);
        } else if (f0 != 0.0 && (f0 < 0.0) != (f1 < 0.0)) {
            nr = push_root(roots, nr, refine(c, n, x0, x1, f0, f1));
        } else if (j + 2 < m && fabs(f1) <= eval_bound(c, n, x1)) {
            /* an interior critical point touching zero: a double root */
            double f2 = geom_poly_eval(c, n, xs[j + 2]);
            if ((f0 < 0.0) == (f1 < 0.0) && (f2 < 0.0) == (f1 < 0.0)) nr = push_root(roots, nr, x1);
        }
        f0 = f1;
    }
    return nr;
}

/* ------------------------------------------------------------ Sturm */

typedef struct {
    double c[GEOM_POLY_MAX + 2][GEOM_POLY_MAX + 1];
    int deg[GEOM_POLY_MAX + 2];
    int len;
} sturm_seq;

static void sturm_build(sturm_seq *s, const double *c, int n)
{
    memcpy(s->c[0], c, sizeof(double) * (size_t)(n + 1));
    s->deg[0] = n;
    for (int i = 0; i < n; i++) s->c[1][i] = (double)(i + 1) * c[i + 1] / n;
    s->deg[1] = n - 1;
    s->len = 2;
    while (s->deg[s->len - 1] > 0 && s->len < GEOM_POLY_MAX + 2) {
        const double *u = s->c[s->len - 2], *v = s->c[s->len - 1];
        int du = s->deg[s->len - 2], dv = s->deg[s->len - 1];
        double r[GEOM_POLY_MAX + 1];
        memcpy(r, u, sizeof(double) * (size_t)(du + 1));
        /* r = u mod v */
        for (int k = du - dv; k >= 0; k--) {
            double q = r[dv + k] / v[dv];
            for (int j = 0; j <= dv; j++) r[j + k] -= q * v[j];
            r[dv + k] = 0.0;
        }
        int dr = dv - 1;
        double mx = 0.0;
        for (int j = 0; j <= du; j++) mx = fmax(mx, fabs(u[j]));
        while (dr >= 0 && fabs(r[dr]) <= 1e-13 * mx) dr--;
        if (dr < 0) break; /* v divides u: the sequence ends (multiple roots) */
        double sc = 0.0;
        for (int j = 0; j <= dr; j++) sc = fmax(sc, fabs(r[j]));
        for (int j = 0; j <= dr; j++) s->c[s->len][j] = -r[j] / sc;
        s->deg[s->len] = dr;
        s->len++;
    }
}

static int sturm_changes(const sturm_seq *s, double x)
{
    int changes = 0;
    double last = 0.0;
    for (int i = 0; i < s->len; i++) {
        double f = geom_poly_eval(s->c[i], s->deg[i], x);
        if (f == 0.0) continue;
        if (last != 0.0 && (f < 0.0) != (last < 0.0)) changes++;
        last = f;
    }
    return changes;
}

static int sturm_isolate(const sturm_seq *s, const double *c, int n, double a, double b, int va, int vb, double *roots,
                         int nr, int depth)
{
    int count = va - vb;
    if (count <= 0) return nr;
    double fa = geom_poly_eval(c, n, a), fb = geom_poly_eval(c, n, b);
    if (count == 1 && fa != 0.0 && fb != 0.0 && (fa < 0.0) != (fb < 0.0))
        return push_root(roots, nr, refine(c, n, a, b, fa, fb));
    double m = 0.5 * (a + b);
    if (depth > 80 || !(m > a && m < b) || b - a <= 1e-15 * (fabs(a) + fabs(b))) {
        if (count == 1 && fb == 0.0) return push_root(roots, nr, b);
        return push_root(roots, nr, m); /* a multiple root */
    }
    int vm = sturm_changes(s, m);
    nr = sturm_isolate(s, c, n, a, m, va, vm, roots, nr, depth + 1);
    return sturm_isolate(s, c, n, m, b, vm, vb, roots, nr, depth + 1);
}

static int solve_sturm(const double *c, int n, double a, double b, double *roots)
{
    n = trim(c, n);
    if (n <= 2) return solve_brackets(c, n, a, b, roots);
    sturm_seq s;
    sturm_build(&s, c, n);
    int nr = 0;
    if (geom_poly_eval(c, n, a) == 0.0) nr = push_root(roots, nr, a);
    return sturm_isolate(&s, c, n, a, b, sturm_changes(&s, a), sturm_changes(&s, b), roots, nr, 0);
}

int geom_poly_solve(const double *c, int n, double a, double b, double *roots, int sturm)
{
    if (n > GEOM_POLY_MAX || n < 0 || !(a <= b)) return 0;
    for (int i = 0; i <= n; i++)
        if (!isfinite(c[i])) return 0;
    return sturm ? solve_sturm(c, n, a, b, roots) : solve_brackets(c, n, a, b, roots);
}
