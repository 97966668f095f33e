/* uspline.c - spline entries and evaluation (semantics of POV-Ray 3.7.0's
 * splines: segment search, end handling and the four interpolations). */
#include "uspline.h"
#include <stdlib.h>
#include <string.h>

/* Segment index for t: 0 if t <= first t, n if t >= last t, else the index
 * of the first entry whose t is >= the given t (the segment's end). */
static int segment_end(const user_spline *s, double t)
{
    if (s->n == 0 || t <= s->pts[0].t) return 0;
    if (t >= s->pts[s->n - 1].t) return s->n;
    int lo = 0, hi = s->n - 1; /* pts[lo].t < t <= pts[hi].t */
    while (hi - lo > 1) {
        int mid = lo + (hi - lo) / 2;
        if (t > s->pts[mid].t) lo = mid;
        else hi = mid;
    }
    return hi;
}

void uspline_insert(user_spline *s, double t, const double v[5])
{
    int i = segment_end(s, t);
    if (s->n > 0 && i < s->n && s->pts[i].t == t) {
        memcpy(s->pts[i].v, v, sizeof s->pts[i].v);
        return;
    }
    if (s->n > 0 && i == s->n && s->pts[s->n - 1].t == t) {
        memcpy(s->pts[s->n - 1].v, v, sizeof s->pts[0].v);
        return;
    }
    memmove(&s->pts[i + 1], &s->pts[i], sizeof s->pts[0] * (size_t)(s->n - i));
    s->pts[i].t = t;
    memcpy(s->pts[i].v, v, sizeof s->pts[i].v);
    s->n++;
    s->m = NULL; /* coefficients are stale */
}

/* Natural cubic spline: solve the tridiagonal system for the second
 * derivatives M_1..M_{n-2} with M_0 = M_{n-1} = 0. */
void uspline_natural_coeffs(const user_spline *s, double *m)
{
    int n = s->n;
    memset(m, 0, sizeof(double) * 5 * (size_t)(n > 0 ? n : 1));
    if (n < 3) return;
    double *h = malloc(sizeof(double) * 4 * (size_t)n);
    if (!h) return;
    double *slope = h + n, *diag = h + 2 * n, *rhs = h + 3 * n;
    for (int k = 0; k < 5; k++) {
        for (int i = 0; i < n - 1; i++) {
            h[i] = s->pts[i + 1].t - s->pts[i].t;
            slope[i] = (s->pts[i + 1].v[k] - s->pts[i].v[k]) / h[i];
        }
        /* forward elimination */
        diag[1] = 2 * (h[0] + h[1]);
        rhs[1] = 6 * (slope[1] - slope[0]);
        for (int i = 2; i < n - 1; i++) {
            double f = h[i - 1] / diag[i - 1];
            diag[i] = 2 * (h[i - 1] + h[i]) - f * h[i - 1];
            rhs[i] = 6 * (slope[i] - slope[i - 1]) - f * rhs[i - 1];
        }
        /* back substitution */
        for (int i = n - 2; i >= 1; i--) m[5 * i + k] = (rhs[i] - h[i] * m[5 * (i + 1) + k]) / diag[i];
    }
    free(h);
}

static double lerp_entry(const uspline_point *a, const uspline_point *b, int k, double t)
{
    return a->v[k] + (t - a->t) * (b->v[k] - a->v[k]) / (b->t - a->t);
}

/* The parabola through three entries, at t (Lagrange form). */
static double quadratic_entry(const uspline_point *p, int k, double t)
{
    double t0 = p[0].t, t1 = p[1].t, t2 = p[2].t;
    return p[0].v[k] * (t - t1) * (t - t2) / ((t0 - t1) * (t0 - t2)) +
           p[1].v[k] * (t - t0) * (t - t2) / ((t1 - t0) * (t1 - t2)) +
           p[2].v[k] * (t - t0) * (t - t1) / ((t2 - t0) * (t2 - t1));
}

/* Natural cubic between entries i and i+1 from the second derivatives. */
static double natural_entry(const user_spline *s, const double *m, int i, int k, double t)
{
    const uspline_point *a = &s->pts[i], *b = &s->pts[i + 1];
    double h = b->t - a->t, u = t - a->t;
    double ma = m[5 * i + k], mb = m[5 * (i + 1) + k];
    double slope = (b->v[k] - a->v[k]) / h - h * (mb + 2 * ma) / 6;
    return a->v[k] + u * (slope + u * (ma / 2 + u * (mb - ma) / (6 * h)));
}

/* Catmull-Rom between entries i and i+1 (entries i-1 and i+2 give the
 * tangents, averaged slopes scaled to the segment), Hermite form. */
static double catmull_rom_entry(const uspline_point *p, int i, int k, double t)
{
    double dt = p[i + 1].t - p[i].t, u = (t - p[i].t) / dt;
    double s0 = (p[i].v[k] - p[i - 1].v[k]) / (p[i].t - p[i - 1].t);
    double s1 = (p[i + 1].v[k] - p[i].v[k]) / dt;
    double s2 = (p[i + 2].v[k] - p[i + 1].v[k]) / (p[i + 2].t - p[i + 1].t);
    double d0 = (s0 + s1) / 2 * dt, d1 = (s1 + s2) / 2 * dt;
    double u2 = u * u, u3 = u2 * u;
    return p[i].v[k] * (2 * u3 - 3 * u2 + 1) + p[i + 1].v[k] * (3 * u2 - 2 * u3) + d0 * (u3 - 2 * u2 + u) + d1 * (u3 - u2);
}

void uspline_eval(const user_spline *s, uspline_kind kind, const double *m, double t, double out[5])
{
    memset(out, 0, sizeof(double) * 5);
    int n = s->n, last = n - 1;
    if (n == 0) return;
    if (n == 1) {
        memcpy(out, s->pts[0].v, sizeof(double) * 5);
        return;
    }
    int i = segment_end(s, t);
    double *own = NULL;
    if (kind == USPLINE_NATURAL && !m) {
        own = malloc(sizeof(double) * 5 * (size_t)n);
        if (own) uspline_natural_coeffs(s, own);
        m = own;
    }
    for (int k = 0; k < 5; k++) {
        const uspline_point *p = s->pts;
        if (kind == USPLINE_CUBIC) {
            if (last == 1) out[k] = (p[0].v[k] + p[1].v[k]) / 2;
            else if (i < 2) out[k] = p[1].v[k];
            else if (i >= last) out[k] = p[last - 1].v[k];
            else out[k] = catmull_rom_entry(p, i - 1, k, t);
            continue;
        }
        if (i == 0) out[k] = p[0].v[k];
        else if (i > last) out[k] = p[last].v[k];
        else if (kind == USPLINE_LINEAR || (kind == USPLINE_QUADRATIC && last == 1)) out[k] = lerp_entry(&p[i - 1], &p[i], k, t);
        else if (kind == USPLINE_QUADRATIC) out[k] = quadratic_entry(&p[i > 1 ? i - 2 : 0], k, t);
        else out[k] = m ? natural_entry(s, m, i - 1, k, t) : lerp_entry(&p[i - 1], &p[i], k, t);
    }
    free(own);
}
