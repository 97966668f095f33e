/* geom_sweep.c - lathe, sor, prism, text and polygon (geom_sweep.h).
 *
 * Conditioning: every shape is moved to local coordinates q' = (q - c) / L
 * (c the centre of its extent, L its size; conic prisms keep their apex at
 * the origin) and a ray's origin is moved to where it enters the padded
 * bounding box, with a unit direction, so the polynomial coefficients are
 * O(1) whatever the scale of the scene or the distance of the origin.
 *
 * Spline segments (POV-Ray's lathe.cpp/prism.cpp define the point roles):
 *   linear     P0 -> P1:                      p = P0 + (P1 - P0) t
 *   quadratic  P0 control, P1 -> P2:          p = P1 + (P2 - P0)/2 t + (P0/2 - P1 + P2/2) t^2
 *   cubic      P0, P3 controls, P1 -> P2:     Catmull-Rom
 *   Bezier     P0 -> P3 with P1, P2 controls: Bernstein form
 * A lathe uses consecutive points (segments n-1, n-2, n-3, n/4); a prism
 * steps over the point that closes each sub-curve (the closing rules are in
 * parser/sdl_shape.c). A sor segment i fits r^2 as a cubic in y through
 * P[i+1] and P[i+2] with the slopes of the chords P[i]P[i+2] and
 * P[i+1]P[i+3] (POV-Ray's sor.cpp Hermite conditions). */
#include "geom_sweep_internal.h"
#include <float.h>
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include "geom_poly.h"


/* ------------------------------------------------------------ small helpers */

static void seg_poly(const sw_seg *s, int k, double c[4])
{
    c[0] = s->d[k];
    c[1] = s->c[k];
    c[2] = s->b[k];
    c[3] = s->a[k];
}

/* Segment from the four power-basis vectors and its exact end points. */
static void seg_set(sw_seg *s, const double a[2], const double b[2], const double c[2], const double d[2],
                    const double *e0, const double *e1, int deg)
{
    memset(s, 0, sizeof *s);
    for (int k = 0; k < 2; k++) {
        s->a[k] = a[k];
        s->b[k] = b[k];
        s->c[k] = c[k];
        s->d[k] = d[k];
        s->e0[k] = e0[k];
        s->e1[k] = e1[k];
    }
    s->deg = deg;
    for (int k = 0; k < 2; k++) {
        double lo = fmin(e0[k], e1[k]), hi = fmax(e0[k], e1[k]);
        if (deg > 1) {
            double dc[3] = {c[k], 2.0 * b[k], 3.0 * a[k]}, r[2];
            int nr = geom_poly_solve(dc, 2, 0.0, 1.0, r, 0);
            for (int i = 0; i < nr; i++) {
                double p[2];
                seg_eval(s, r[i], p, NULL);
                lo = fmin(lo, p[k]);
                hi = fmax(hi, p[k]);
            }
        }
        s->lo[k] = lo;
        s->hi[k] = hi;
    }
    s->nk = 0;
    s->tk[0] = 0.0;
    s->yk[0] = e0[1];
    if (deg > 1) {
        double dc[3] = {c[1], 2.0 * b[1], 3.0 * a[1]}, crit[2];
        int nc = geom_poly_solve(dc, 2, 0.0, 1.0, crit, 0);
        for (int i = 0; i < nc; i++)
            if (crit[i] > s->tk[s->nk] && crit[i] < 1.0) {
                double p[2];
                seg_eval(s, crit[i], p, NULL);
                s->nk++;
                s->tk[s->nk] = crit[i];
                s->yk[s->nk] = p[1];
            }
    }
    s->nk++;
    s->tk[s->nk] = 1.0;
    s->yk[s->nk] = e1[1];
    double xc[2];
    int nx = 0;
    if (deg > 1) {
        double dc[3] = {c[0], 2.0 * b[0], 3.0 * a[0]};
        nx = geom_poly_solve(dc, 2, 0.0, 1.0, xc, 0);
    }
    for (int j = 0; j < s->nk; j++) {
        double p0[2], p1[2];
        seg_eval(s, s->tk[j], p0, NULL);
        seg_eval(s, s->tk[j + 1], p1, NULL);
        double lo = fmin(p0[0], p1[0]), hi = fmax(p0[0], p1[0]);
        for (int i = 0; i < nx; i++)
            if (xc[i] > s->tk[j] && xc[i] < s->tk[j + 1]) {
                double p[2];
                seg_eval(s, xc[i], p, NULL);
                lo = fmin(lo, p[0]);
                hi = fmax(hi, p[0]);
            }
        /* the bisection's point is evaluated as these are: rounding apart,
         * it lies in [lo, hi] */
        double pad = 1e-9 * (1.0 + fabs(lo) + fabs(hi));
        s->xk_lo[j] = lo - pad;
        s->xk_hi[j] = hi + pad;
    }
    s->out = 1.0;
}

/* Segment `type` from points P (P[0..3] as the spline rule needs). */
void geom_sweep_coeffs(scene_spline type, const double (*P)[2], double a[2], double b[2], double c[2], double d[2])
{
    for (int k = 0; k < 2; k++) {
        switch (type) {
        case SPLINE_LINEAR:
            a[k] = b[k] = 0.0;
            c[k] = P[1][k] - P[0][k];
            d[k] = P[0][k];
            break;
        case SPLINE_QUADRATIC:
            a[k] = 0.0;
            b[k] = 0.5 * P[0][k] - P[1][k] + 0.5 * P[2][k];
            c[k] = -0.5 * P[0][k] + 0.5 * P[2][k];
            d[k] = P[1][k];
            break;
        case SPLINE_CUBIC:
            a[k] = -0.5 * P[0][k] + 1.5 * P[1][k] - 1.5 * P[2][k] + 0.5 * P[3][k];
            b[k] = P[0][k] - 2.5 * P[1][k] + 2.0 * P[2][k] - 0.5 * P[3][k];
            c[k] = -0.5 * P[0][k] + 0.5 * P[2][k];
            d[k] = P[1][k];
            break;
        default: /* Bezier */
            a[k] = -P[0][k] + 3.0 * P[1][k] - 3.0 * P[2][k] + P[3][k];
            b[k] = 3.0 * P[0][k] - 6.0 * P[1][k] + 3.0 * P[2][k];
            c[k] = -3.0 * P[0][k] + 3.0 * P[1][k];
            d[k] = P[0][k];
            break;
        }
    }
}

static void seg_from_points(sw_seg *s, scene_spline type, const double (*P)[2])
{
    double a[2], b[2], c[2], d[2];
    const double *e0, *e1;
    int deg = 3;
    geom_sweep_coeffs(type, P, a, b, c, d);
    switch (type) {
    case SPLINE_LINEAR: e0 = P[0]; e1 = P[1]; deg = 1; break;
    case SPLINE_QUADRATIC: e0 = P[1]; e1 = P[2]; break;
    case SPLINE_CUBIC: e0 = P[1]; e1 = P[2]; break;
    default: e0 = P[0]; e1 = P[3]; break;
    }
    seg_set(s, a, b, c, d, e0, e1, deg);
}

/* ------------------------------------------------------------ 2-D inside test */

/* Crossings, in +u direction from (u, v), of segment s: each monotonic
 * piece of p_v between the exact end values counts when v lies in it
 * (half-open: a value equal to v counts as above) and the crossing is at
 * u' >= u. */
static int seg_crossings(const sw_seg *s, double u, double v)
{
    if (v < s->lo[1] || v > s->hi[1] || u > s->hi[0]) return 0;
    if (s->deg == 1) {
        int a = s->e0[1] >= v, b = s->e1[1] >= v;
        if (a == b) return 0;
        double t = (v - s->e0[1]) / (s->e1[1] - s->e0[1]);
        double x = s->e0[0] + t * (s->e1[0] - s->e0[0]);
        return x >= u;
    }
    int count = 0, have_pv = 0;
    double pv[4];
    for (int j = 0; j < s->nk; j++) {
        if ((s->yk[j] >= v) == (s->yk[j + 1] >= v)) continue;
        /* the crossing lies on the segment, so at u' >= lo[0]; on this
         * piece, within [xk_lo, xk_hi] */
        if (u <= s->lo[0] || u < s->xk_lo[j]) { count++; continue; }
        if (u > s->xk_hi[j]) continue;
        if (!have_pv) {
            seg_poly(s, 1, pv);
            pv[0] -= v;
            have_pv = 1;
        }
        /* one crossing in the monotonic piece: bisection */
        double lo = s->tk[j], hi = s->tk[j + 1], flo = s->yk[j] - v;
        for (int it = 0; it < 60 && hi - lo > 1e-15; it++) {
            double mid = 0.5 * (lo + hi), fm = geom_poly_eval(pv, 3, mid);
            if ((fm >= 0.0) == (flo >= 0.0)) { lo = mid; flo = fm; } else hi = mid;
        }
        double p[2];
        seg_eval(s, 0.5 * (lo + hi), p, NULL);
        if (p[0] >= u) count++;
    }
    return count;
}

static int band_of(const sw_data *w, double v)
{
    int b = (int)((v - w->clo[1]) * w->band_inv);
    return b < 0 ? 0 : (b >= w->nband ? w->nband - 1 : b);
}

/* The band index of in_curve (its bands cover the curve's v range). A
 * segment is listed in every band from band_of(lo) to band_of(hi), and
 * band_of is monotonic, so a query v in [lo, hi] finds it. Without memory,
 * or for few segments, no index: in_curve then visits every segment. */
static void band_index(sw_data *w)
{
    free(w->band_off);
    free(w->band_seg);
    w->band_off = w->band_seg = NULL;
    w->nband = 0;
    double h = w->chi[1] - w->clo[1];
    if (w->nseg < 16 || !(h > 0.0)) return;
    int nb = w->nseg;
    w->nband = nb;
    w->band_inv = nb / h;
    long total = 0;
    for (int i = 0; i < w->nseg; i++) total += band_of(w, w->seg[i].hi[1]) - band_of(w, w->seg[i].lo[1]) + 1;
    w->band_off = calloc((size_t)nb + 1, sizeof *w->band_off);
    w->band_seg = total <= INT_MAX ? malloc(sizeof *w->band_seg * (size_t)total) : NULL;
    int *fill = calloc((size_t)nb, sizeof *fill);
    if (!w->band_off || !w->band_seg || !fill) {
        free(w->band_off);
        free(w->band_seg);
        w->band_off = w->band_seg = NULL;
        w->nband = 0;
    } else {
        for (int i = 0; i < w->nseg; i++)
            for (int b = band_of(w, w->seg[i].lo[1]); b <= band_of(w, w->seg[i].hi[1]); b++) w->band_off[b + 1]++;
        for (int b = 0; b < nb; b++) w->band_off[b + 1] += w->band_off[b];
        for (int i = 0; i < w->nseg; i++)
            for (int b = band_of(w, w->seg[i].lo[1]); b <= band_of(w, w->seg[i].hi[1]); b++)
                w->band_seg[w->band_off[b] + fill[b]++] = i;
    }
    free(fill);
}

static int in_curve(const sw_data *w, double u, double v)
{
    if (u < w->clo[0] || u > w->chi[0] || v < w->clo[1] || v > w->chi[1]) return 0;
    int n = 0;
    if (w->nband > 0) {
        int b = band_of(w, v);
        for (int k = w->band_off[b]; k < w->band_off[b + 1]; k++) n += seg_crossings(&w->seg[w->band_seg[k]], u, v);
        return n & 1;
    }
    for (int i = 0; i < w->nseg; i++) n += seg_crossings(&w->seg[i], u, v);
    return n & 1;
}

/* Closest parameter on segment s to the 2-D point q. */
static double seg_closest(const sw_seg *s, const double q[2])
{
    double best = 0.0, bd = INFINITY;
    for (int i = 0; i <= 16; i++) {
        double t = i / 16.0, p[2];
        seg_eval(s, t, p, NULL);
        double d = (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]);
        if (d < bd) { bd = d; best = t; }
    }
    double t = best;
    for (int it = 0; it < 20; it++) {
        double p[2], dp[2];
        seg_eval(s, t, p, dp);
        double dd[2] = {6.0 * s->a[0] * t + 2.0 * s->b[0], 6.0 * s->a[1] * t + 2.0 * s->b[1]};
        double r0 = p[0] - q[0], r1 = p[1] - q[1];
        double g = r0 * dp[0] + r1 * dp[1];
        double h = dp[0] * dp[0] + dp[1] * dp[1] + r0 * dd[0] + r1 * dd[1];
        if (!(h > 0.0)) break;
        double tn = t - g / h;
        tn = tn < 0.0 ? 0.0 : (tn > 1.0 ? 1.0 : tn);
        if (fabs(tn - t) < 1e-15) { t = tn; break; }
        t = tn;
    }
    return t;
}

/* Orient every segment's normal away from the region (mid-point test). */
static void orient_segments(sw_data *w)
{
    double ext = fmax(w->chi[0] - w->clo[0], w->chi[1] - w->clo[1]);
    for (int i = 0; i < w->nseg; i++) {
        sw_seg *s = &w->seg[i];
        double p[2], n[2];
        s->out = 1.0;
        seg_eval(s, 0.5, p, NULL);
        seg_normal(s, 0.5, n);
        double l = sqrt(n[0] * n[0] + n[1] * n[1]);
        if (!(l > 0.0)) continue;
        double delta = 1e-7 * ext;
        if (in_curve(w, p[0] + delta * n[0] / l, p[1] + delta * n[1] / l)) s->out = -1.0;
    }
}

static void curve_bounds(sw_data *w)
{
    w->clo[0] = w->clo[1] = INFINITY;
    w->chi[0] = w->chi[1] = -INFINITY;
    for (int i = 0; i < w->nseg; i++)
        for (int k = 0; k < 2; k++) {
            w->clo[k] = fmin(w->clo[k], w->seg[i].lo[k]);
            w->chi[k] = fmax(w->chi[k], w->seg[i].hi[k]);
        }
    band_index(w);
}

/* ------------------------------------------------------------ local rays */

typedef struct {
    vec3 o, e;     /* local origin (moved to the box entry) and unit direction */
    double s, te;  /* t = te + tau / s */
    double ta, tb; /* tau range */
} lray;

static int make_lray(const sw_data *w, vec3 o, vec3 d, double tmin, double tmax, lray *r)
{
    vec3 lo = v3_scale(v3_sub(o, w->c), 1.0 / w->L), ld = v3_scale(d, 1.0 / w->L);
    double s = v3_len(ld);
    if (!(s > 0.0) || !isfinite(s)) return 0;
    vec3 pad = v3s(0.01);
    double b0, b1;
    if (!v3_slab(lo, ld, v3_sub(w->blo, pad), v3_add(w->bhi, pad), &b0, &b1)) return 0;
    double t0 = fmax(tmin, b0), t1 = fmin(tmax, b1);
    if (!(t0 < t1)) return 0;
    r->te = t0;
    r->s = s;
    r->e = v3_scale(ld, 1.0 / s);
    r->o = v3_madd(lo, ld, t0);
    r->ta = 0.0;
    r->tb = (t1 - t0) * s;
    return 1;
}

static double lray_t(const lray *r, double tau) { return r->te + tau / r->s; }

/* ------------------------------------------------------------ lathe */

/* Newton on (t, tau): Y(t) = Py + tau ey, |Pxz + tau exz| = R(t). */
static void lathe_polish(const sw_seg *s, const lray *r, double *pt, double *ptau)
{
    double t = *pt, tau = *ptau;
    vec3 P = r->o, e = r->e;
    for (int it = 0; it < 8; it++) {
        double p[2], dp[2];
        seg_eval(s, t, p, dp);
        double x = P.x + tau * e.x, z = P.z + tau * e.z;
        double f1 = p[1] - P.y - tau * e.y;
        double f2 = x * x + z * z - p[0] * p[0];
        double j11 = dp[1], j12 = -e.y, j21 = -2.0 * p[0] * dp[0], j22 = 2.0 * (x * e.x + z * e.z);
        double det = j11 * j22 - j12 * j21;
        if (!(fabs(det) > 0.0) || !isfinite(det)) break;
        double dt = (f1 * j22 - f2 * j12) / det, dtau = (j11 * f2 - j21 * f1) / det;
        if (!isfinite(dt) || !isfinite(dtau) || fabs(dt) > 0.1) break;
        t -= dt;
        tau -= dtau;
        if (fabs(dt) < 1e-15 && fabs(dtau) < 1e-15 * (1.0 + fabs(tau))) break;
    }
    if (isfinite(t) && isfinite(tau) && t > -1e-6 && t < 1.0 + 1e-6) {
        *pt = t;
        *ptau = tau;
    }
}

static int lathe_hits(const sw_data *w, const lray *r, double tmin, double tmax, geom_shape_hit *out, int n,
                      int max)
{
    vec3 P = r->o, e = r->e;
    double rxz = e.x * e.x + e.z * e.z, m = P.x * e.x + P.z * e.z, P2 = P.x * P.x + P.z * P.z;
    for (int k = 0; k < w->nseg; k++) {
        const sw_seg *s = &w->seg[k];
        if (s->hi[0] <= 0.0 && s->lo[0] >= 0.0) continue; /* on the axis: no surface */
        /* cull: the ray's y range and its distance from the axis there */
        double ta = r->ta, tb = r->tb;
        if (e.y != 0.0) {
            double y0 = (s->lo[1] - P.y) / e.y, y1 = (s->hi[1] - P.y) / e.y;
            if (y0 > y1) { double t = y0; y0 = y1; y1 = t; }
            ta = fmax(ta, y0 - 1e-9);
            tb = fmin(tb, y1 + 1e-9);
        } else if (P.y < s->lo[1] - 1e-9 || P.y > s->hi[1] + 1e-9) {
            continue;
        }
        if (!(ta <= tb)) continue;
        double qa = P2 + 2.0 * m * ta + rxz * ta * ta, qb = P2 + 2.0 * m * tb + rxz * tb * tb;
        double tv = rxz > 0.0 ? -m / rxz : ta, qmin = fmin(qa, qb);
        if (tv > ta && tv < tb) qmin = fmin(qmin, P2 + 2.0 * m * tv + rxz * tv * tv);
        double rh = s->hi[0] + 1e-9, rl = fmax(0.0, s->lo[0] - 1e-9);
        if (qmin > rh * rh || fmax(qa, qb) < rl * rl) continue;

        double Y[4], R[4];
        seg_poly(s, 1, Y);
        seg_poly(s, 0, R);
        Y[0] -= P.y;
        double cand_t[12], cand_tau[12];
        int nc = 0;
        if (fabs(e.y) > FLAT_RAY) {
            /* G(t) = rxz Y^2 + 2 ey m Y + ey^2 (P2 - R^2) */
            double G[7] = {0};
            for (int i = 0; i < 4; i++)
                for (int j = 0; j < 4; j++) {
                    G[i + j] += rxz * Y[i] * Y[j];
                    G[i + j] -= e.y * e.y * R[i] * R[j];
                }
            for (int i = 0; i < 4; i++) G[i] += 2.0 * e.y * m * Y[i];
            G[0] += e.y * e.y * P2;
            double roots[6];
            int nr = geom_poly_solve(G, s->deg == 1 ? 2 : 6, -T_SLACK, 1.0 + T_SLACK, roots, w->sturm);
            for (int i = 0; i < nr; i++) {
                cand_t[nc] = roots[i];
                cand_tau[nc] = geom_poly_eval(Y, 3, roots[i]) / e.y;
                nc++;
            }
        } else {
            /* nearly horizontal: heights first, then the circle at that height */
            double roots[3];
            int nr = geom_poly_solve(Y, s->deg == 1 ? 1 : 3, -T_SLACK, 1.0 + T_SLACK, roots, w->sturm);
            for (int i = 0; i < nr && rxz > 0.0; i++) {
                double p[2];
                seg_eval(s, roots[i], p, NULL);
                double tq[2];
                double qc[3] = {P2 - p[0] * p[0], 2.0 * m, rxz};
                int nq = geom_poly_solve(qc, 2, -INFINITY, INFINITY, tq, 0);
                for (int j = 0; j < nq; j++) {
                    cand_t[nc] = roots[i];
                    cand_tau[nc] = tq[j];
                    nc++;
                }
            }
        }
        for (int i = 0; i < nc; i++) {
            double t = cand_t[i], tau = cand_tau[i];
            lathe_polish(s, r, &t, &tau);
            if (t < -T_SLACK || t > 1.0 + T_SLACK) continue;
            double tt = lray_t(r, tau);
            if (tt > tmin && tt < tmax) n = geom_shape_hit_put(out, n, max, tt, 2 + k);
        }
    }
    return n;
}

/* ------------------------------------------------------------ sor */

static int sor_hits(const sw_data *w, const lray *r, double tmin, double tmax, geom_shape_hit *out, int n, int max)
{
    vec3 P = r->o, e = r->e;
    double rxz = e.x * e.x + e.z * e.z, m = P.x * e.x + P.z * e.z, P2 = P.x * P.x + P.z * P.z;
    for (int k = 0; k < w->nseg; k++) {
        const sor_seg *s = &w->sor[k];
        double h = s->y1 - s->y0;
        double ta = r->ta, tb = r->tb;
        if (e.y != 0.0) {
            double y0 = (s->y0 - P.y) / e.y, y1 = (s->y1 - P.y) / e.y;
            if (y0 > y1) { double t = y0; y0 = y1; y1 = t; }
            ta = fmax(ta, y0);
            tb = fmin(tb, y1);
        } else if (P.y < s->y0 || P.y > s->y1) {
            continue;
        }
        if (!(ta <= tb)) continue;
        double qa = P2 + 2.0 * m * ta + rxz * ta * ta, qb = P2 + 2.0 * m * tb + rxz * tb * tb;
        double tv = rxz > 0.0 ? -m / rxz : ta, qmin = fmin(qa, qb);
        if (tv > ta && tv < tb) qmin = fmin(qmin, P2 + 2.0 * m * tv + rxz * tv * tv);
        if (qmin > s->rmax2 * (1.0 + 1e-9) + 1e-12) continue;
        /* P2 + 2 m tau + rxz tau^2 - g(s0 + s1 tau) = 0 */
        double s0 = (P.y - s->y0) / h, s1 = e.y / h;
        double c[4] = {P2, 2.0 * m, rxz, 0.0};
        double pw[4] = {1.0, 0, 0, 0}; /* (s0 + s1 tau)^i */
        for (int i = 0; i < 4; i++) {
            for (int j = 0; j <= i; j++) c[j] -= s->g[i] * pw[j];
            double nw[4] = {0};
            for (int j = 0; j <= i && j < 3; j++) {
                nw[j] += pw[j] * s0;
                nw[j + 1] += pw[j] * s1;
            }
            memcpy(pw, nw, sizeof pw);
        }
        double roots[3];
        int nr = geom_poly_solve(c, 3, ta, tb, roots, w->sturm);
        for (int i = 0; i < nr; i++) {
            double tt = lray_t(r, roots[i]);
            if (tt > tmin && tt < tmax) n = geom_shape_hit_put(out, n, max, tt, 2 + k);
        }
    }
    if (!w->open && e.y != 0.0) {
        double ycap[2] = {w->sor[0].y0, w->sor[w->nseg - 1].y1}, r2[2] = {w->base_r2, w->cap_r2};
        for (int c = 0; c < 2; c++) {
            if (!(r2[c] > 0.0)) continue;
            double tau = (ycap[c] - P.y) / e.y;
            double x = P.x + tau * e.x, z = P.z + tau * e.z;
            if (x * x + z * z > r2[c]) continue;
            double tt = lray_t(r, tau);
            if (tt > tmin && tt < tmax) n = geom_shape_hit_put(out, n, max, tt, c);
        }
    }
    return n;
}

static int sor_segment_at(const sw_data *w, double y)
{
    int lo = 0, hi = w->nseg - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (y > w->sor[mid].y1) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

/* ------------------------------------------------------------ prism, text */

/* Newton on (t, tau) for a prism side. */
static void prism_polish(const sw_data *w, const sw_seg *s, double Pu, double Pw, double Pv, double eu, double ew,
                         double ev, double *pt, double *ptau)
{
    double t = *pt, tau = *ptau;
    for (int it = 0; it < 8; it++) {
        double p[2], dp[2];
        seg_eval(s, t, p, dp);
        double sc = w->conic ? Pw + tau * ew : 1.0;
        double f1 = Pu + tau * eu - sc * p[0], f2 = Pv + tau * ev - sc * p[1];
        double j11 = eu - (w->conic ? ew * p[0] : 0.0), j12 = -sc * dp[0];
        double j21 = ev - (w->conic ? ew * p[1] : 0.0), j22 = -sc * dp[1];
        double det = j11 * j22 - j12 * j21;
        if (!(fabs(det) > 0.0) || !isfinite(det)) break;
        double dtau = (f1 * j22 - f2 * j12) / det, dt = (j11 * f2 - j21 * f1) / det;
        if (!isfinite(dt) || !isfinite(dtau) || fabs(dt) > 0.1) break;
        t -= dt;
        tau -= dtau;
        if (fabs(dt) < 1e-15 && fabs(dtau) < 1e-15 * (1.0 + fabs(tau))) break;
    }
    if (isfinite(t) && isfinite(tau) && t > -1e-6 && t < 1.0 + 1e-6) {
        *pt = t;
        *ptau = tau;
    }
}

static int prism_hits(const sw_data *w, const lray *r, double tmin, double tmax, geom_shape_hit *out, int n,
                      int max)
{
    double Pu = v3_idx(r->o, w->ax[0]), Pw = v3_idx(r->o, w->ax[1]), Pv = v3_idx(r->o, w->ax[2]);
    double eu = v3_idx(r->e, w->ax[0]), ew = v3_idx(r->e, w->ax[1]), ev = v3_idx(r->e, w->ax[2]);
    /* caps */
    if (!w->open && ew != 0.0) {
        double hh[2] = {w->h1, w->h2};
        for (int c = 0; c < 2; c++) {
            if (w->conic && hh[c] == 0.0) continue;
            double tau = (hh[c] - Pw) / ew;
            if (tau < r->ta - 1e-9 || tau > r->tb + 1e-9) continue;
            double u = Pu + tau * eu, v = Pv + tau * ev;
            if (w->conic) { u /= hh[c]; v /= hh[c]; }
            if (!in_curve(w, u, v)) continue;
            double tt = lray_t(r, tau);
            if (tt > tmin && tt < tmax) n = geom_shape_hit_put(out, n, max, tt, c);
        }
    }
    if (fabs(eu) < 1e-12 && fabs(ev) < 1e-12 && !w->conic) return n; /* along the sweep axis */
    /* tau range where the ray is within the sweep heights */
    double ta = r->ta, tb = r->tb;
    if (ew != 0.0) {
        double a = (w->h1 - Pw) / ew, b = (w->h2 - Pw) / ew;
        if (a > b) { double t = a; a = b; b = t; }
        ta = fmax(ta, a - 1e-9);
        tb = fmin(tb, b + 1e-9);
    } else if (Pw < w->h1 || Pw > w->h2) {
        return n;
    }
    if (!(ta <= tb)) return n;
    for (int k = 0; k < w->nseg; k++) {
        const sw_seg *s = &w->seg[k];
        if (!w->conic) {
            /* cull by the segment's 2-D box against the 2-D ray over [ta, tb] */
            double ua = Pu + ta * eu, ub = Pu + tb * eu, va = Pv + ta * ev, vb = Pv + tb * ev;
            if (fmax(ua, ub) < s->lo[0] - 1e-9 || fmin(ua, ub) > s->hi[0] + 1e-9 || fmax(va, vb) < s->lo[1] - 1e-9 ||
                fmin(va, vb) > s->hi[1] + 1e-9)
                continue;
        }
        double X[4], Z[4], f[4];
        seg_poly(s, 0, X);
        seg_poly(s, 1, Z);
        if (!w->conic) {
            for (int i = 0; i < 4; i++) f[i] = ev * X[i] - eu * Z[i];
            f[0] += eu * Pv - ev * Pu;
        } else {
            double cx = Pw * ev - Pv * ew, cz = Pu * ew - Pw * eu;
            for (int i = 0; i < 4; i++) f[i] = cx * X[i] + cz * Z[i];
            f[0] += Pv * eu - Pu * ev;
        }
        double roots[3];
        int nr = geom_poly_solve(f, s->deg == 1 ? 1 : 3, -T_SLACK, 1.0 + T_SLACK, roots, w->sturm);
        for (int i = 0; i < nr; i++) {
            double t = roots[i], p[2];
            seg_eval(s, t, p, NULL);
            double tau;
            if (!w->conic) {
                tau = fabs(eu) >= fabs(ev) ? (p[0] - Pu) / eu : (p[1] - Pv) / ev;
            } else {
                double du = eu - ew * p[0], dv = ev - ew * p[1];
                if (fabs(du) >= fabs(dv)) tau = (Pw * p[0] - Pu) / du;
                else tau = (Pw * p[1] - Pv) / dv;
            }
            if (!isfinite(tau)) continue;
            prism_polish(w, s, Pu, Pw, Pv, eu, ew, ev, &t, &tau);
            double hw = Pw + tau * ew;
            if (hw < w->h1 || hw > w->h2) continue;
            double tt = lray_t(r, tau);
            if (tt > tmin && tt < tmax) n = geom_shape_hit_put(out, n, max, tt, 2 + k);
        }
    }
    return n;
}

/* ------------------------------------------------------------ polygon */

static int polygon_hits(const sw_data *w, vec3 o, vec3 d, double tmin, double tmax, geom_shape_hit *out, int max)
{
    double den = v3_dot(w->pn, d);
    if (den == 0.0) return 0;
    double t = v3_dot(w->pn, v3_sub(w->p0, o)) / den;
    if (!(t > tmin && t < tmax)) return 0;
    vec3 q = v3_sub(v3_madd(o, d, t), w->p0);
    if (!in_curve(w, v3_dot(q, w->pu) / w->L, v3_dot(q, w->pv) / w->L)) return 0;
    return geom_shape_hit_put(out, 0, max, t, 2);
}

/* ------------------------------------------------------------ setup */

static int alloc_segs(sw_data *w, int n)
{
    w->seg = calloc((size_t)(n > 0 ? n : 1), sizeof *w->seg);
    return w->seg != NULL;
}

/* Normalised copy of 2-D points: ((p - c) / L). */
static double (*norm_points(const double (*pts)[2], int n, double c0, double c1, double L))[2]
{
    double(*q)[2] = malloc(sizeof *q * (size_t)(n > 0 ? n : 1));
    if (!q) return NULL;
    for (int i = 0; i < n; i++) {
        q[i][0] = (pts[i][0] - c0) / L;
        q[i][1] = (pts[i][1] - c1) / L;
    }
    return q;
}

static void extent2(const double (*pts)[2], int n, double lo[2], double hi[2])
{
    lo[0] = lo[1] = INFINITY;
    hi[0] = hi[1] = -INFINITY;
    for (int i = 0; i < n; i++)
        for (int k = 0; k < 2; k++) {
            lo[k] = fmin(lo[k], pts[i][k]);
            hi[k] = fmax(hi[k], pts[i][k]);
        }
}

static int setup_lathe(sw_data *w, const scene_lathe *l)
{
    int n = l->npoints;
    if (!l->points || n < 2) return -1;
    double lo[2], hi[2];
    extent2(l->points, n, lo, hi);
    double L = fmax(fmax(fabs(lo[0]), fabs(hi[0])), hi[1] - lo[1]);
    if (!(L > 0.0) || !isfinite(L)) return -1;
    w->L = L;
    w->c = v3(0.0, 0.5 * (lo[1] + hi[1]), 0.0);
    double(*P)[2] = norm_points(l->points, n, 0.0, w->c.y, L);
    if (!P) return -1;
    int ns = l->spline == SPLINE_LINEAR ? n - 1 : l->spline == SPLINE_QUADRATIC ? n - 2 : l->spline == SPLINE_CUBIC ? n - 3 : n / 4;
    if (ns < 1 || !alloc_segs(w, ns)) { free(P); return -1; }
    for (int i = 0; i < ns; i++) seg_from_points(&w->seg[i], l->spline, P + (l->spline == SPLINE_BEZIER ? 4 * i : i));
    free(P);
    w->nseg = ns;
    curve_bounds(w);
    orient_segments(w);
    double R = fmax(fabs(w->clo[0]), fabs(w->chi[0]));
    w->blo = v3(-R, w->clo[1], -R);
    w->bhi = v3(R, w->chi[1], R);
    return 0;
}

static int setup_sor(sw_data *w, const scene_lathe *l)
{
    int n = l->npoints;
    if (!l->points || n < 4) return -1;
    double lo[2], hi[2];
    extent2(l->points, n, lo, hi);
    double L = fmax(hi[0], hi[1] - lo[1]);
    if (!(L > 0.0) || !isfinite(L)) return -1;
    w->L = L;
    w->c = v3(0.0, 0.5 * (lo[1] + hi[1]), 0.0);
    double(*P)[2] = norm_points(l->points, n, 0.0, w->c.y, L);
    w->sor = calloc((size_t)(n - 3), sizeof *w->sor);
    if (!P || !w->sor) { free(P); return -1; }
    w->nseg = n - 3;
    double rmax2 = 0.0, ylo = INFINITY, yhi = -INFINITY;
    for (int i = 0; i < n - 3; i++) {
        sor_seg *s = &w->sor[i];
        double y0 = P[i + 1][1], y1 = P[i + 2][1], h = y1 - y0;
        if (!(h > 0.0)) { free(P); return -1; }
        double r0 = P[i + 1][0], r1 = P[i + 2][0];
        double k0 = 2.0 * r0 * (P[i + 2][0] - P[i][0]) / (P[i + 2][1] - P[i][1]);
        double k1 = 2.0 * r1 * (P[i + 3][0] - P[i + 1][0]) / (P[i + 3][1] - P[i + 1][1]);
        /* Hermite in s: values r0^2, r1^2, slopes k0 h, k1 h */
        double v0 = r0 * r0, v1 = r1 * r1, m0 = k0 * h, m1 = k1 * h;
        s->g[0] = v0;
        s->g[1] = m0;
        s->g[2] = -3.0 * v0 + 3.0 * v1 - 2.0 * m0 - m1;
        s->g[3] = 2.0 * v0 - 2.0 * v1 + m0 + m1;
        s->y0 = y0;
        s->y1 = y1;
        double mx = fmax(v0, v1), dc[3] = {s->g[1], 2.0 * s->g[2], 3.0 * s->g[3]}, rr[2];
        int nr = geom_poly_solve(dc, 2, 0.0, 1.0, rr, 0);
        for (int j = 0; j < nr; j++) mx = fmax(mx, geom_poly_eval(s->g, 3, rr[j]));
        s->rmax2 = mx;
        rmax2 = fmax(rmax2, mx);
        ylo = fmin(ylo, y0);
        yhi = fmax(yhi, y1);
    }
    free(P);
    w->base_r2 = fmax(0.0, w->sor[0].g[0]);
    const sor_seg *last = &w->sor[w->nseg - 1];
    w->cap_r2 = fmax(0.0, last->g[0] + last->g[1] + last->g[2] + last->g[3]);
    double R = sqrt(rmax2);
    w->blo = v3(-R, ylo, -R);
    w->bhi = v3(R, yhi, R);
    return 0;
}

/* Prism segments from the points with POV-Ray's sub-curve stepping. */
static int prism_segments(sw_data *w, scene_spline sp, double (*P)[2], int n)
{
    if (!alloc_segs(w, n)) return -1;
    int ns = 0;
    if (sp == SPLINE_BEZIER) {
        for (int i = 0; i + 3 < n; i += 4) seg_from_points(&w->seg[ns++], sp, P + i);
    } else {
        const double *first = sp == SPLINE_LINEAR ? P[0] : P[1];
        for (int i = 0; i < n - 1; i++) {
            int need = sp == SPLINE_LINEAR ? 1 : sp == SPLINE_QUADRATIC ? 2 : 3;
            if (i + need >= n) break;
            seg_from_points(&w->seg[ns++], sp, P + i);
            int close_idx = sp == SPLINE_LINEAR ? i + 1 : i + 2;
            if (fabs(P[close_idx][0] - first[0]) < 1e-10 && fabs(P[close_idx][1] - first[1]) < 1e-10) {
                i += sp == SPLINE_LINEAR ? 1 : sp == SPLINE_QUADRATIC ? 2 : 3;
                int next = sp == SPLINE_LINEAR ? i + 1 : i + 2;
                if (next < n) first = P[next];
            }
        }
    }
    w->nseg = ns;
    return ns > 0 ? 0 : -1;
}

static int setup_prism(sw_data *w, const scene_prism *pr)
{
    int n = pr->npoints;
    if (!pr->points || n < 3) return -1;
    w->ax[0] = 0; w->ax[1] = 1; w->ax[2] = 2;
    w->conic = pr->conic;
    double lo[2], hi[2];
    extent2(pr->points, n, lo, hi);
    double c0 = 0.0, c1 = 0.0, cw = 0.0, L;
    if (pr->conic) {
        L = fmax(fmax(fabs(pr->height1), fabs(pr->height2)), 1e-300);
    } else {
        c0 = 0.5 * (lo[0] + hi[0]);
        c1 = 0.5 * (lo[1] + hi[1]);
        cw = 0.5 * (pr->height1 + pr->height2);
        L = fmax(fmax(hi[0] - lo[0], hi[1] - lo[1]), pr->height2 - pr->height1);
    }
    if (!(L > 0.0) || !isfinite(L)) return -1;
    w->L = L;
    w->c = v3(c0, cw, c1);
    /* conic: the curve stays in its own units (it is scaled by the height) */
    double(*P)[2] = pr->conic ? norm_points(pr->points, n, 0.0, 0.0, 1.0) : norm_points(pr->points, n, c0, c1, L);
    if (!P) return -1;
    int st = prism_segments(w, pr->spline, P, n);
    free(P);
    if (st) return -1;
    w->h1 = (pr->height1 - cw) / L;
    w->h2 = (pr->height2 - cw) / L;
    if (!(w->h2 >= w->h1)) return -1;
    curve_bounds(w);
    orient_segments(w);
    if (!pr->conic) {
        w->blo = v3(w->clo[0], w->h1, w->clo[1]);
        w->bhi = v3(w->chi[0], w->h2, w->chi[1]);
    } else {
        double xs[4] = {w->clo[0] * w->h1, w->clo[0] * w->h2, w->chi[0] * w->h1, w->chi[0] * w->h2};
        double zs[4] = {w->clo[1] * w->h1, w->clo[1] * w->h2, w->chi[1] * w->h1, w->chi[1] * w->h2};
        w->blo = v3(fmin(fmin(xs[0], xs[1]), fmin(xs[2], xs[3])), w->h1, fmin(fmin(zs[0], zs[1]), fmin(zs[2], zs[3])));
        w->bhi = v3(fmax(fmax(xs[0], xs[1]), fmax(xs[2], xs[3])), w->h2, fmax(fmax(zs[0], zs[1]), fmax(zs[2], zs[3])));
        /* the apex when the heights straddle 0 */
        w->blo = v3_min(w->blo, v3(0, w->h1, 0));
        w->bhi = v3_max(w->bhi, v3(0, w->h2, 0));
    }
    return 0;
}

static int setup_text(sw_data *w, const scene_text *tx)
{
    if (!tx->segments || tx->nsegments < 1 || !(tx->depth != 0.0)) return -1;
    w->ax[0] = 0; w->ax[1] = 2; w->ax[2] = 1; /* curve in (x, y), swept along z */
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int i = 0; i < tx->nsegments; i++)
        for (int j = 0; j < 4; j++)
            for (int k = 0; k < 2; k++) {
                lo[k] = fmin(lo[k], tx->segments[i][2 * j + k]);
                hi[k] = fmax(hi[k], tx->segments[i][2 * j + k]);
            }
    double z1 = fmin(0.0, tx->depth), z2 = fmax(0.0, tx->depth);
    double L = fmax(fmax(hi[0] - lo[0], hi[1] - lo[1]), z2 - z1);
    if (!(L > 0.0) || !isfinite(L)) return -1;
    double c0 = 0.5 * (lo[0] + hi[0]), c1 = 0.5 * (lo[1] + hi[1]), cw = 0.5 * (z1 + z2);
    w->L = L;
    w->c = v3(c0, c1, cw);
    if (!alloc_segs(w, tx->nsegments)) return -1;
    for (int i = 0; i < tx->nsegments; i++) {
        double P[4][2];
        for (int j = 0; j < 4; j++) {
            P[j][0] = (tx->segments[i][2 * j] - c0) / L;
            P[j][1] = (tx->segments[i][2 * j + 1] - c1) / L;
        }
        /* a straight line stored as a cubic: keep it linear (exact crossings) */
        double d1[2] = {P[1][0] - P[0][0] - (P[3][0] - P[0][0]) / 3.0, P[1][1] - P[0][1] - (P[3][1] - P[0][1]) / 3.0};
        double d2[2] = {P[2][0] - P[0][0] - 2.0 * (P[3][0] - P[0][0]) / 3.0,
                        P[2][1] - P[0][1] - 2.0 * (P[3][1] - P[0][1]) / 3.0};
        if (fabs(d1[0]) + fabs(d1[1]) + fabs(d2[0]) + fabs(d2[1]) < 1e-12) {
            double Q[2][2] = {{P[0][0], P[0][1]}, {P[3][0], P[3][1]}};
            seg_from_points(&w->seg[i], SPLINE_LINEAR, Q);
        } else {
            seg_from_points(&w->seg[i], SPLINE_BEZIER, P);
        }
    }
    w->nseg = tx->nsegments;
    w->h1 = (z1 - cw) / L;
    w->h2 = (z2 - cw) / L;
    curve_bounds(w);
    orient_segments(w);
    w->blo = v3(w->clo[0], w->clo[1], w->h1);
    w->bhi = v3(w->chi[0], w->chi[1], w->h2);
    return 0;
}

static int setup_polygon(sw_data *w, const scene_polygon *pg, vec3 *lo, vec3 *hi)
{
    int n = pg->npoints;
    const vec3 *p = pg->points;
    if (!p || n < 3) return -1;
    /* Newell normal and the centroid */
    vec3 nn = v3s(0), c = v3s(0);
    for (int i = 0; i < n; i++) {
        vec3 a = p[i], b = p[(i + 1) % n];
        nn.x += (a.y - b.y) * (a.z + b.z);
        nn.y += (a.z - b.z) * (a.x + b.x);
        nn.z += (a.x - b.x) * (a.y + b.y);
        c = v3_add(c, a);
    }
    double l = v3_len(nn);
    if (!(l > 0.0) || !isfinite(l)) return -1;
    w->pn = v3_scale(nn, 1.0 / l);
    w->p0 = v3_scale(c, 1.0 / n);
    v3_basis(w->pn, &w->pu, &w->pv);
    vec3 blo = v3s(INFINITY), bhi = v3s(-INFINITY);
    double ext = 0.0;
    for (int i = 0; i < n; i++) {
        blo = v3_min(blo, p[i]);
        bhi = v3_max(bhi, p[i]);
    }
    ext = v3_maxc(v3_sub(bhi, blo));
    if (!(ext > 0.0)) return -1;
    w->L = ext;
    w->c = v3s(0);
    if (!alloc_segs(w, n)) return -1;
    /* sub-polygons: each ends where its first point repeats */
    int ns = 0, start = 0;
    for (int i = 1; i < n; i++) {
        vec3 a = v3_sub(p[i - 1], w->p0), b = v3_sub(p[i], w->p0);
        double P[2][2] = {{v3_dot(a, w->pu) / ext, v3_dot(a, w->pv) / ext}, {v3_dot(b, w->pu) / ext, v3_dot(b, w->pv) / ext}};
        seg_from_points(&w->seg[ns++], SPLINE_LINEAR, P);
        if (p[i].x == p[start].x && p[i].y == p[start].y && p[i].z == p[start].z && i > start) {
            start = i + 1;
            i++; /* the next sub-polygon starts at i + 1 */
        }
    }
    w->nseg = ns;
    curve_bounds(w);
    *lo = blo;
    *hi = bhi;
    return 0;
}

/* ------------------------------------------------------------ areas and sampling */

/* 5-point Gauss-Legendre on [0,1] (exact for degree 9), composite over 8
 * pieces for the non-polynomial integrands. */
static const double GL_X[5] = {0.04691007703066800, 0.23076534494715845, 0.5, 0.76923465505284155,
                               0.95308992296933200};
static const double GL_W[5] = {0.11846344252809454, 0.23931433524968324, 0.28444444444444444, 0.23931433524968324,
                               0.11846344252809454};

/* Densities over a part's parameter (local units). */
static double lathe_density(const sw_seg *s, double t)
{
    double p[2], dp[2];
    seg_eval(s, t, p, dp);
    return fabs(p[0]) * sqrt(dp[0] * dp[0] + dp[1] * dp[1]);
}

static double side_density(const sw_seg *s, double t)
{
    double p[2], dp[2];
    seg_eval(s, t, p, dp);
    return sqrt(dp[0] * dp[0] + dp[1] * dp[1]);
}

static double sor_density(const sor_seg *s, double u)
{
    double h = s->y1 - s->y0, y = s->y0 + u * h, dg;
    double g = sor_g(s, y, &dg);
    return sqrt(fmax(0.0, g + 0.25 * dg * dg)) * h;
}

static double part_density(const sw_data *w, int part, double t)
{
    int k = part - 2;
    if (w->type == SW_LATHE) return lathe_density(&w->seg[k], t);
    if (w->type == SW_SOR) return sor_density(&w->sor[k], t);
    return side_density(&w->seg[k], t);
}

/* Integral over [0,1] and a bound of the density (dense samples + 10 %). */
static void integrate_part(const sw_data *w, int part, double *area, double *bound)
{
    double acc = 0.0, mx = 0.0;
    for (int piece = 0; piece < 8; piece++)
        for (int i = 0; i < 5; i++) acc += GL_W[i] * part_density(w, part, (piece + GL_X[i]) / 8.0) / 8.0;
    for (int i = 0; i <= 128; i++) mx = fmax(mx, part_density(w, part, i / 128.0));
    *area = acc;
    *bound = 1.1 * mx + 1e-300;
}

/* Area of the cap region, 1/2 sum of the integral of p . n_out ds. */
static double cap_area(const sw_data *w)
{
    double a = 0.0;
    for (int k = 0; k < w->nseg; k++) {
        const sw_seg *s = &w->seg[k];
        for (int i = 0; i < 5; i++) {
            double p[2], n[2];
            seg_eval(s, GL_X[i], p, NULL);
            seg_normal(s, GL_X[i], n);
            a += 0.5 * GL_W[i] * (p[0] * n[0] + p[1] * n[1]);
        }
    }
    return fabs(a);
}

static void setup_areas(sw_data *w)
{
    if (w->type == SW_POLYGON || (w->type == SW_PRISM && w->conic)) return;
    int np = 2 + w->nseg;
    w->part_area = calloc((size_t)np, sizeof(double));
    w->part_cdf = calloc((size_t)np, sizeof(double));
    w->part_max = calloc((size_t)np, sizeof(double));
    if (!w->part_area || !w->part_cdf || !w->part_max) return;
    w->nparts = np;
    if (w->type == SW_SOR) {
        if (!w->open) {
            w->part_area[0] = M_PI * w->base_r2;
            w->part_area[1] = M_PI * w->cap_r2;
        }
        for (int k = 0; k < w->nseg; k++) {
            integrate_part(w, 2 + k, &w->part_area[2 + k], &w->part_max[2 + k]);
            w->part_area[2 + k] *= 2.0 * M_PI;
        }
    } else if (w->type == SW_LATHE) {
        for (int k = 0; k < w->nseg; k++) {
            integrate_part(w, 2 + k, &w->part_area[2 + k], &w->part_max[2 + k]);
            w->part_area[2 + k] *= 2.0 * M_PI;
        }
    } else {
        if (!w->open) w->part_area[0] = w->part_area[1] = cap_area(w);
        for (int k = 0; k < w->nseg; k++) {
            integrate_part(w, 2 + k, &w->part_area[2 + k], &w->part_max[2 + k]);
            w->part_area[2 + k] *= w->h2 - w->h1;
        }
    }
    double tot = 0.0;
    for (int i = 0; i < np; i++) tot += w->part_area[i];
    double acc = 0.0;
    for (int i = 0; i < np; i++) {
        acc += w->part_area[i];
        w->part_cdf[i] = tot > 0.0 ? acc / tot : (double)(i + 1) / np;
    }
    w->total_area = isfinite(tot) ? tot * w->L * w->L : 0.0;
}

/* The areas on first use: most renders never sample a sweep's surface
 * (the GI modes and area sampling do), and the integrals cost about two
 * hundred density evaluations per segment, once per shape built. The
 * first caller computes them under the lock; later ones see areas_done. */
static pthread_mutex_t areas_lock = PTHREAD_MUTEX_INITIALIZER;

static const sw_data *areas_ready(const geom_shape *sh)
{
    sw_data *w = sh->data;
    if (!w || atomic_load_explicit(&w->areas_done, memory_order_acquire)) return w;
    pthread_mutex_lock(&areas_lock);
    if (!atomic_load_explicit(&w->areas_done, memory_order_relaxed)) {
        setup_areas(w);
        atomic_store_explicit(&w->areas_done, 1, memory_order_release);
    }
    pthread_mutex_unlock(&areas_lock);
    return w;
}

double geom_sweep_area(const geom_shape *sh)
{
    const sw_data *w = areas_ready(sh);
    return w && w->nparts ? w->total_area : 0.0;
}

static double next_rand(rng *r, int *k, double u)
{
    /* with no generator: an additive recurrence from u (deterministic) */
    if (r) return rng_f64(r);
    double v = u + 0.6180339887498949 * ++*k;
    return v - floor(v);
}

void geom_sweep_sample(const geom_shape *sh, double u1, double u2, rng *r, vec3 *p, vec3 *n, unsigned *part)
{
    const sw_data *w = areas_ready(sh);
    *p = v3s(0.0);
    *n = v3(0, 1, 0);
    *part = 0;
    if (!w || !w->nparts) return;
    int i = 0;
    while (i < w->nparts - 1 && u1 >= w->part_cdf[i]) i++;
    double a = i > 0 ? w->part_cdf[i - 1] : 0.0, b = w->part_cdf[i];
    double v = b > a ? (u1 - a) / (b - a) : 0.5;
    v = fmin(fmax(v, 0.0), 0x1.fffffffffffffp-1);
    *part = (unsigned)i;
    int k = 0;
    vec3 lp = v3s(0.0), ln = v3(0, 1, 0);
    if (i >= 2) {
        /* the curve parameter by rejection against the density bound */
        double t = v;
        for (int it = 0; it < 4096 && r; it++) {
            if (next_rand(r, &k, u2) * w->part_max[i] <= part_density(w, i, t)) break;
            t = next_rand(r, &k, u2);
        }
        double u = u2;
        if (w->type == SW_LATHE) {
            const sw_seg *s = &w->seg[i - 2];
            double c[2], n2[2], phi = 2.0 * M_PI * u;
            seg_eval(s, t, c, NULL);
            seg_normal(s, t, n2);
            lp = v3(c[0] * cos(phi), c[1], c[0] * sin(phi));
            ln = v3(n2[0] * cos(phi), n2[1], n2[0] * sin(phi));
        } else if (w->type == SW_SOR) {
            const sor_seg *s = &w->sor[i - 2];
            double y = s->y0 + t * (s->y1 - s->y0), dg, phi = 2.0 * M_PI * u;
            double rr = sqrt(fmax(0.0, sor_g(s, y, &dg)));
            lp = v3(rr * cos(phi), y, rr * sin(phi));
            ln = v3(lp.x, -0.5 * dg, lp.z);
        } else {
            const sw_seg *s = &w->seg[i - 2];
            double c[2], n2[2], h = w->h1 + u * (w->h2 - w->h1);
            seg_eval(s, t, c, NULL);
            seg_normal(s, t, n2);
            lp = from_local_axes(w->ax, c[0], h, c[1]);
            ln = from_local_axes(w->ax, n2[0], 0.0, n2[1]);
        }
    } else if (w->type == SW_SOR) {
        double r2 = i == 0 ? w->base_r2 : w->cap_r2, rho = sqrt(r2 * v), phi = 2.0 * M_PI * u2;
        double y = i == 0 ? w->sor[0].y0 : w->sor[w->nseg - 1].y1;
        lp = v3(rho * cos(phi), y, rho * sin(phi));
        ln = v3(0, i == 0 ? -1 : 1, 0);
    } else {
        /* a prism cap: rejection in the curve's box */
        double x = v, y = u2;
        for (int it = 0; it < 100000; it++) {
            double cu = w->clo[0] + x * (w->chi[0] - w->clo[0]), cv = w->clo[1] + y * (w->chi[1] - w->clo[1]);
            if (in_curve(w, cu, cv) || it == 99999) {
                lp = from_local_axes(w->ax, cu, i == 0 ? w->h1 : w->h2, cv);
                break;
            }
            x = next_rand(r, &k, v);
            y = next_rand(r, &k, u2 + 0.5);
        }
        ln = from_local_axes(w->ax, 0.0, i == 0 ? -1.0 : 1.0, 0.0);
    }
    *p = v3_add(w->c, v3_scale(lp, w->L));
    *n = v3_norm(ln);
}

int geom_sweep_init(geom_shape *sh, const scene_object *o, vec3 *lo, vec3 *hi)
{
    sw_data *w = calloc(1, sizeof *w);
    if (!w) return -1;
    w->sturm = (o->flags & OBJ_STURM) != 0;
    w->open = (o->flags & OBJ_OPEN) != 0;
    int st = -1;
    switch (o->kind) {
    case SHAPE_LATHE: w->type = SW_LATHE; st = o->u.lathe ? setup_lathe(w, o->u.lathe) : -1; break;
    case SHAPE_SOR: w->type = SW_SOR; st = o->u.lathe ? setup_sor(w, o->u.lathe) : -1; break;
    case SHAPE_PRISM: w->type = SW_PRISM; st = o->u.prism ? setup_prism(w, o->u.prism) : -1; break;
    case SHAPE_TEXT: w->type = SW_PRISM; w->open = 0; st = o->u.text ? setup_text(w, o->u.text) : -1; break;
    case SHAPE_POLYGON: w->type = SW_POLYGON; st = o->u.polygon ? setup_polygon(w, o->u.polygon, lo, hi) : -1; break;
    default: break;
    }
    if (st != 0) {
        geom_sweep_free(w);
        return -1;
    }
    if (w->type != SW_POLYGON) {
        *lo = v3_add(w->c, v3_scale(w->blo, w->L));
        *hi = v3_add(w->c, v3_scale(w->bhi, w->L));
    }
    sh->data = w;
    return 0;
}

void geom_sweep_free(void *data)
{
    sw_data *w = data;
    if (!w) return;
    free(w->part_area);
    free(w->part_cdf);
    free(w->part_max);
    free(w->seg);
    free(w->sor);
    free(w->band_off);
    free(w->band_seg);
    free(w);
}

int geom_sweep_hits(const geom_shape *sh, vec3 o, vec3 d, double tmin, double tmax, geom_shape_hit *out, int max)
{
    const sw_data *w = sh->data;
    if (!w || max <= 0) return 0;
    if (w->type == SW_POLYGON) return polygon_hits(w, o, d, tmin, tmax, out, max);
    lray r;
    if (!make_lray(w, o, d, tmin, tmax, &r)) return 0;
    switch (w->type) {
    case SW_LATHE: return lathe_hits(w, &r, tmin, tmax, out, 0, max);
    case SW_SOR: return sor_hits(w, &r, tmin, tmax, out, 0, max);
    default: return prism_hits(w, &r, tmin, tmax, out, 0, max);
    }
}

int geom_sweep_inside(const geom_shape *sh, vec3 q)
{
    const sw_data *w = sh->data;
    if (!w || w->type == SW_POLYGON) return 0;
    vec3 l = v3_scale(v3_sub(q, w->c), 1.0 / w->L);
    switch (w->type) {
    case SW_LATHE: {
        double r = sqrt(l.x * l.x + l.z * l.z);
        return in_curve(w, r, l.y);
    }
    case SW_SOR: {
        if (l.y < w->sor[0].y0 || l.y > w->sor[w->nseg - 1].y1) return 0;
        const sor_seg *s = &w->sor[sor_segment_at(w, l.y)];
        return l.x * l.x + l.z * l.z <= sor_g(s, l.y, NULL);
    }
    default: {
        double u = v3_idx(l, w->ax[0]), h = v3_idx(l, w->ax[1]), v = v3_idx(l, w->ax[2]);
        if (!(h > w->h1 && h < w->h2)) return 0;
        if (w->conic) {
            if (h == 0.0) return 0;
            u /= h;
            v /= h;
        }
        return in_curve(w, u, v);
    }
    }
}

void geom_sweep_surface(const geom_shape *sh, vec3 q, int part, vec3 *n, double *u, double *v)
{
    const sw_data *w = sh->data;
    *n = v3(0, 1, 0);
    *u = *v = 0.0;
    if (!w) return;
    if (w->type == SW_POLYGON) {
        *n = w->pn;
        vec3 rel = v3_sub(q, w->p0);
        *u = v3_dot(rel, w->pu) / w->L + 0.5;
        *v = v3_dot(rel, w->pv) / w->L + 0.5;
        return;
    }
    vec3 l = v3_scale(v3_sub(q, w->c), 1.0 / w->L);
    int k = part - 2;
    switch (w->type) {
    case SW_LATHE: {
        double r = sqrt(l.x * l.x + l.z * l.z);
        if (k < 0 || k >= w->nseg) k = 0;
        const sw_seg *s = &w->seg[k];
        double p2[2] = {r, l.y}, n2[2];
        double t = seg_closest(s, p2);
        seg_normal(s, t, n2);
        if (r > 0.0) *n = v3(n2[0] * l.x / r, n2[1], n2[0] * l.z / r);
        else *n = v3(0.0, n2[1] >= 0.0 ? 1.0 : -1.0, 0.0);
        double th = atan2(l.z, l.x);
        *u = (th < 0 ? th + TWO_PI : th) / TWO_PI;
        *v = fmin(1.0, (k + t) / w->nseg);
        break;
    }
    case SW_SOR: {
        double th = atan2(l.z, l.x);
        *u = (th < 0 ? th + TWO_PI : th) / TWO_PI;
        if (part == 0) { *n = v3(0, -1, 0); *v = 0.0; break; }
        if (part == 1) { *n = v3(0, 1, 0); *v = 1.0; break; }
        if (k < 0 || k >= w->nseg) k = sor_segment_at(w, l.y);
        double dg;
        sor_g(&w->sor[k], l.y, &dg);
        *n = v3(l.x, -0.5 * dg, l.z);
        *v = (k + (l.y - w->sor[k].y0) / (w->sor[k].y1 - w->sor[k].y0)) / w->nseg;
        break;
    }
    default: {
        double pu = v3_idx(l, w->ax[0]), h = v3_idx(l, w->ax[1]), pv = v3_idx(l, w->ax[2]);
        *v = w->h2 > w->h1 ? (h - w->h1) / (w->h2 - w->h1) : 0.0;
        if (part == 0 || part == 1) {
            *n = from_local_axes(w->ax, 0.0, part == 0 ? -1.0 : 1.0, 0.0);
            *u = 0.0;
            break;
        }
        if (k < 0 || k >= w->nseg) k = 0;
        const sw_seg *s = &w->seg[k];
        double sc = w->conic && h != 0.0 ? h : 1.0;
        double p2[2] = {pu / sc, pv / sc}, n2[2];
        double t = seg_closest(s, p2);
        seg_normal(s, t, n2);
        if (!w->conic) {
            *n = from_local_axes(w->ax, n2[0], 0.0, n2[1]);
        } else {
            double pc[2];
            seg_eval(s, t, pc, NULL);
            double sg = h < 0.0 ? -1.0 : 1.0;
            *n = from_local_axes(w->ax, sg * n2[0], -sg * (pc[0] * n2[0] + pc[1] * n2[1]), sg * n2[1]);
        }
        *u = (k + t) / w->nseg;
        break;
    }
    }
}

/* POV-Ray 3.7's Lathe::UVCoord and Sor::UVCoord (backend/shape/lathe.cpp,
 * sor.cpp): u the angle around y from +x over 2 pi; lathe v = (segment +
 * its curve parameter) / segments (at most 1); sor v = (segment + height
 * fraction in it) / segments on the curve, r / base radius - 1 on the base
 * (-1..0) and 2 - r / cap radius on the cap (1..2). */
void geom_sweep_uv(const geom_shape *sh, vec3 q, int part, double uv[2])
{
    const sw_data *w = sh->data;
    vec3 n;
    double u = 0.0, v = 0.0;
    geom_sweep_surface(sh, q, part, &n, &u, &v);
    if (w && w->type == SW_SOR && (part == 0 || part == 1)) {
        vec3 l = v3_scale(v3_sub(q, w->c), 1.0 / w->L);
        double r = sqrt(l.x * l.x + l.z * l.z), r2 = part == 0 ? w->base_r2 : w->cap_r2;
        double f = r2 > 0.0 ? r / sqrt(r2) : 0.0;
        v = part == 0 ? f - 1.0 : 2.0 - f;
    }
    uv[0] = u;
    uv[1] = v;
}
