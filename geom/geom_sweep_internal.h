/* geom_sweep_internal.h - the records of lathe, sor, prism, text and polygon
 * and the small helpers shared by geom_sweep.c (setup, hits, inside,
 * surface, areas and sampling) and geom_sweep_grid.c (polygon triangles and
 * grids). Not for use outside them. */
#ifndef PT_GEOM_SWEEP_INTERNAL_H
#define PT_GEOM_SWEEP_INTERNAL_H
#include <stdatomic.h>
#include "geom_sweep.h"

#define TWO_PI 6.283185307179586476925
#define T_SLACK 1e-9   /* roots this far outside [0,1] still belong to a segment */
#define FLAT_RAY 1e-5  /* |e.y| below this: the lathe's horizontal-ray method */

enum { SW_LATHE, SW_SOR, SW_PRISM, SW_POLYGON };

typedef struct {
    double a[2], b[2], c[2], d[2]; /* p(t) = ((a t + b) t + c) t + d */
    double e0[2], e1[2];           /* exact end points */
    double lo[2], hi[2];           /* bounds over t in [0,1] */
    int deg;                       /* 1 or 3 */
    /* p_v's monotonic pieces: t bounds tk[0] = 0 < ... < tk[nk] = 1 (the
     * critical points of p_v in between) and p_v there (yk; exact end points
     * at 0 and 1). Independent of the query, so set once. */
    double tk[4], yk[4];
    int nk;
    /* p_u's range over each piece, padded beyond rounding: a crossing of
     * the line v on piece j lies at u' in [xk_lo[j], xk_hi[j]], so a
     * query u outside it is decided without finding the crossing */
    double xk_lo[3], xk_hi[3];
    double out;                    /* outward 2-D normal = out * (p1', -p0') */
} sw_seg;

typedef struct {
    double g[4];  /* r^2 = g(s), s = (y - y0) / (y1 - y0) in [0,1] */
    double y0, y1;
    double rmax2;
} sor_seg;

typedef struct {
    int type;
    int nseg;
    sw_seg *seg;
    sor_seg *sor;
    double clo[2], chi[2];  /* curve bounds (local) */
    /* Bands of equal height over [clo[1], chi[1]]: band b lists (band_seg
     * from band_off[b] to band_off[b + 1]) every segment whose v range meets
     * it, so an inside test visits only the segments at its height. nband 0:
     * no index (every segment is visited). */
    int nband;
    double band_inv;
    int *band_off, *band_seg;
    vec3 c;                 /* object -> local: (q - c) / L */
    double L;
    vec3 blo, bhi;          /* local bounding box of the shape */
    /* prism/text: local axes (u, w, v) = object components ax[0], ax[1], ax[2] */
    int ax[3];
    double h1, h2;          /* local sweep range */
    int conic, open, sturm;
    /* sor caps */
    double base_r2, cap_r2;
    /* polygon: object-space plane and in-plane frame */
    vec3 pn, pu, pv, p0;
    /* GI sampling: parts 0 base cap, 1 top cap, 2 + k segment k (local
     * areas), set up on the first geom_sweep_area or geom_sweep_sample
     * (areas_done) */
    atomic_int areas_done;
    int nparts;
    double *part_area, *part_cdf, *part_max;
    double total_area;       /* object space */
} sw_data;

static inline vec3 from_local_axes(const int ax[3], double u, double w, double v)
{
    double r[3];
    r[ax[0]] = u;
    r[ax[1]] = w;
    r[ax[2]] = v;
    return v3(r[0], r[1], r[2]);
}

static inline void seg_eval(const sw_seg *s, double t, double p[2], double dp[2])
{
    for (int k = 0; k < 2; k++) {
        p[k] = ((s->a[k] * t + s->b[k]) * t + s->c[k]) * t + s->d[k];
        if (dp) dp[k] = (3.0 * s->a[k] * t + 2.0 * s->b[k]) * t + s->c[k];
    }
}

/* Outward 2-D normal of segment s at t (not unit). */
static inline void seg_normal(const sw_seg *s, double t, double n[2])
{
    double p[2], dp[2];
    seg_eval(s, t, p, dp);
    if (dp[0] == 0.0 && dp[1] == 0.0) { /* a cusp: the chord's normal */
        dp[0] = s->e1[0] - s->e0[0];
        dp[1] = s->e1[1] - s->e0[1];
    }
    n[0] = s->out * dp[1];
    n[1] = -s->out * dp[0];
}

static inline double sor_g(const sor_seg *s, double y, double *dg)
{
    double h = s->y1 - s->y0, t = (y - s->y0) / h;
    if (dg) *dg = ((3.0 * s->g[3] * t + 2.0 * s->g[2]) * t + s->g[1]) / h;
    return ((s->g[3] * t + s->g[2]) * t + s->g[1]) * t + s->g[0];
}

#endif
