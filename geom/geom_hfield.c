/* geom_hfield.c - height_field (geom_hfield.h).
 *
 * Work happens in grid coordinates (X, Y, Z) = (x (W-1), y, z (H-1)), where
 * cells are unit squares; the ray parameter is the same in both. Node
 * (level l, ix, iz) of the quadtree covers cells [ix 2^l, (ix+1) 2^l) x
 * [iz 2^l, (iz+1) 2^l) and stores their height range. A ray walks the
 * nodes along its path front to back (geom_hfield_hits), going down where
 * its height meets a node's range and on to the next node where it does
 * not, so the search can stop at the first hit. */
#include "geom_hfield.h"
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define MAX_LEVELS 40

typedef struct {
    int W, H;            /* grid points */
    int nx, nz;          /* cells */
    const float *h;      /* W * H heights (scene IR) */
    double water;
    int smooth;
    int nlev;
    int lw[MAX_LEVELS], lh[MAX_LEVELS]; /* nodes per level */
    float *mn[MAX_LEVELS], *mx[MAX_LEVELS];
    double ylo, yhi;
} hf_data;

static double H_at(const hf_data *f, int i, int j)
{
    double v = f->h[(size_t)j * (size_t)f->W + (size_t)i];
    return v > f->water ? v : f->water;
}

/* nextafterf(x, dir * INFINITY) without the library call for a finite,
 * non-zero x (the next float's bit pattern is one away in the direction
 * of its magnitude); the call for the rest. The node ranges of a large
 * field take a million of these. */
static float float_step(float x, int dir)
{
    if (x == 0.0f || !isfinite(x)) return nextafterf(x, dir * INFINITY);
    uint32_t b;
    memcpy(&b, &x, sizeof b);
    if ((x > 0.0f) == (dir > 0)) b++;
    else b--;
    memcpy(&x, &b, sizeof b);
    return x;
}

int geom_hfield_init(geom_shape *sh, const scene_object *o, vec3 *lo, vec3 *hi)
{
    const scene_height_field *s = o->u.height_field;
    if (!s || !s->heights || s->width < 2 || s->height < 2) return -1;
    hf_data *f = calloc(1, sizeof *f);
    if (!f) return -1;
    f->W = s->width;
    f->H = s->height;
    f->nx = f->W - 1;
    f->nz = f->H - 1;
    f->h = s->heights;
    f->water = s->water_level;
    f->smooth = s->smooth;
    /* level 0: the cells */
    int lw = f->nx, lh = f->nz, lev = 0;
    for (;;) {
        f->lw[lev] = lw;
        f->lh[lev] = lh;
        f->mn[lev] = malloc(sizeof(float) * (size_t)lw * (size_t)lh);
        f->mx[lev] = malloc(sizeof(float) * (size_t)lw * (size_t)lh);
        if (!f->mn[lev] || !f->mx[lev]) {
            f->nlev = lev + 1;
            geom_hfield_free(f);
            return -1;
        }
        for (int j = 0; j < lh; j++)
            for (int i = 0; i < lw; i++) {
                double a = INFINITY, b = -INFINITY;
                if (lev == 0) {
                    for (int dj = 0; dj < 2; dj++)
                        for (int di = 0; di < 2; di++) {
                            double v = H_at(f, i + di, j + dj);
                            a = v < a ? v : a;
                            b = v > b ? v : b;
                        }
                } else {
                    int pw = f->lw[lev - 1], ph = f->lh[lev - 1];
                    for (int dj = 0; dj < 2; dj++)
                        for (int di = 0; di < 2; di++) {
                            int ci = 2 * i + di, cj = 2 * j + dj;
                            if (ci >= pw || cj >= ph) continue;
                            double cmn = f->mn[lev - 1][(size_t)cj * pw + ci], cmx = f->mx[lev - 1][(size_t)cj * pw + ci];
                            a = cmn < a ? cmn : a;
                            b = cmx > b ? cmx : b;
                        }
                }
                /* float storage: round outwards */
                f->mn[lev][(size_t)j * lw + i] = float_step((float)a, -1);
                f->mx[lev][(size_t)j * lw + i] = float_step((float)b, 1);
            }
        lev++;
        if ((lw == 1 && lh == 1) || lev == MAX_LEVELS) break;
        lw = (lw + 1) / 2;
        lh = (lh + 1) / 2;
    }
    f->nlev = lev;
    f->ylo = f->mn[lev - 1][0];
    f->yhi = f->mx[lev - 1][0];
    *lo = v3(0.0, f->ylo, 0.0);
    *hi = v3(1.0, f->yhi, 1.0);
    sh->data = f;
    return 0;
}

void geom_hfield_free(void *data)
{
    hf_data *f = data;
    if (!f) return;
    for (int i = 0; i < f->nlev; i++) {
        free(f->mn[i]);
        free(f->mx[i]);
    }
    free(f);
}

/* Double-precision ray / triangle (Moller & Trumbore 1997), no culling. */
static int tri_hit(vec3 o, vec3 d, vec3 a, vec3 b, vec3 c, double *t)
{
    vec3 e1 = v3_sub(b, a), e2 = v3_sub(c, a);
    vec3 pv = v3_cross(d, e2);
    double det = v3_dot(e1, pv);
    if (det == 0.0 || !isfinite(det)) return 0;
    double inv = 1.0 / det;
    vec3 tv = v3_sub(o, a);
    double u = v3_dot(tv, pv) * inv;
    if (u < 0.0 || u > 1.0) return 0;
    vec3 qv = v3_cross(tv, e1);
    double v = v3_dot(d, qv) * inv;
    if (v < 0.0 || u + v > 1.0) return 0;
    *t = v3_dot(e2, qv) * inv;
    return 1;
}

static void cell_tri(const hf_data *f, int i, int j, int k, vec3 *a, vec3 *b, vec3 *c)
{
    if (k == 0) {
        *a = v3(i, H_at(f, i, j), j);
        *b = v3(i + 1, H_at(f, i + 1, j), j);
        *c = v3(i, H_at(f, i, j + 1), j + 1);
    } else {
        *a = v3(i + 1, H_at(f, i + 1, j + 1), j + 1);
        *b = v3(i, H_at(f, i, j + 1), j + 1);
        *c = v3(i + 1, H_at(f, i + 1, j), j);
    }
}

/* The hits of one cell's two triangles with t in (tmin, tmax) go into out
 * (n held so far, at most max). */
static int cell_hits(const hf_data *f, int ix, int iz, vec3 o, vec3 d, double tmin, double tmax, geom_shape_hit *out,
                     int n, int max)
{
    for (int tri = 0; tri < 2; tri++) {
        vec3 a, b, c;
        double t;
        cell_tri(f, ix, iz, tri, &a, &b, &c);
        if (tri_hit(o, d, a, b, c, &t) && t > tmin && t < tmax)
            n = geom_shape_hit_put(out, n, max, t, (int)(2 * ((size_t)iz * f->nx + ix) + tri));
    }
    return n;
}

/* Node (lev, ix, iz)'s footprint on axis k (0: X, 1: Z): [*lo, *hi]. */
static void node_span(const hf_data *f, int lev, int i, int k, double *lo, double *hi)
{
    double s = (double)(1 << lev), n = k ? f->nz : f->nx;
    *lo = (double)i * s;
    *hi = fmin_inline((double)(i + 1) * s, n);
}

/* The ray's parameter where it leaves [lo, hi] on an axis with origin o
 * and inverse direction inv (0: parallel, never). */
static double axis_exit(double o, double inv, double lo, double hi)
{
    if (inv == 0.0) return INFINITY;
    return ((inv > 0.0 ? hi : lo) - o) * inv;
}

/* The cell index along one axis of a point at grid coordinate p on a ray
 * with direction component d, as the walk's descent picks children: on a
 * cell line the one the ray goes on into (the lower one for d <= 0), then
 * clamped to [0, n - 1]. */
static int leaf_index(double p, double d, int n)
{
    if (!(p > 0.0)) return 0;
    if (p >= (double)n) return n - 1;
    int i = (int)p; /* p in (0, n): truncation is floor */
    if ((double)i == p && !(d > 0.0)) i--;
    return i < 0 ? 0 : i;
}

int geom_hfield_hits(const geom_shape *sh, vec3 o, vec3 d, double tmin, double tmax, geom_shape_hit *out, int max)
{
    const hf_data *f = sh->data;
    if (!f || max <= 0) return 0;
    /* grid space: cells are unit squares, t is unchanged */
    vec3 go = v3(o.x * f->nx, o.y, o.z * f->nz), gd = v3(d.x * f->nx, d.y, d.z * f->nz);
    double ta, tb;
    /* the grid's box, a hair wider so its faces do not leak */
    vec3 pad = v3(1e-9 * f->nx, 1e-9 * (f->yhi - f->ylo) + 1e-300, 1e-9 * f->nz);
    if (!v3_slab(go, gd, v3_sub(v3(0.0, f->ylo, 0.0), pad), v3_add(v3(f->nx, f->yhi, f->nz), pad), &ta, &tb)) return 0;
    ta = fmax_inline(ta, tmin);
    tb = fmin_inline(tb, tmax);
    if (!(ta <= tb)) return 0;
    double inv_x = gd.x != 0.0 ? 1.0 / gd.x : 0.0, inv_z = gd.z != 0.0 ? 1.0 / gd.z : 0.0;
    int sx = gd.x < 0.0 ? -1 : 1, sz = gd.z < 0.0 ? -1 : 1;
    /* A front-to-back walk of the min/max quadtree along the ray, as a
     * hierarchical grid traversal: the node the ray is in at t is entered
     * when the ray's height over the node's stretch of it meets the node's
     * height range (a leaf: its triangles are tested), else the ray moves
     * on to the neighbouring node, up a level when it leaves the parent.
     * Node indices change by whole steps, so the walk ends after at most
     * one visit per node along the ray.
     *
     * The walk starts at the cell holding the ray at ta (on a cell line:
     * the one the ray goes on into, the lower one for a ray along the
     * line; clamped into the grid as the box's padding may reach past
     * it), the cell a descent from the root would reach: the descent's
     * tests of the cell's ancestors could only skip stretches where the
     * cell itself is not met, and they made up most of the walk's steps
     * for the shadow rays that leave a height field's surface (every
     * ancestor of the cell under a surface point meets the ray there). */
    int top = f->nlev - 1, lev = 0, n = 0;
    double t = ta;
    int ix = leaf_index(go.x + t * gd.x, gd.x, f->nx), iz = leaf_index(go.z + t * gd.z, gd.z, f->nz);
    for (;;) {
        double x0, x1, z0, z1;
        node_span(f, lev, ix, 0, &x0, &x1);
        node_span(f, lev, iz, 1, &z0, &z1);
        double ex = axis_exit(go.x, inv_x, x0, x1), ez = axis_exit(go.z, inv_z, z0, z1);
        double te = fmin_inline(fmin_inline(ex, ez), tb);
        if (te < t) te = t;
        double y0 = go.y + t * gd.y, y1 = go.y + te * gd.y;
        double ylo = fmin_inline(y0, y1), yhi = fmax_inline(y0, y1), sl = 1e-12 * (fabs(ylo) + fabs(yhi)) + 1e-300;
        size_t k = (size_t)iz * f->lw[lev] + ix;
        if (yhi + sl >= f->mn[lev][k] && ylo - sl <= f->mx[lev][k]) {
            if (lev > 0) {
                /* down to the child holding the ray at t (on a split line:
                 * the one the ray goes on into; the lower one for a ray
                 * along the line) */
                double px = go.x + t * gd.x, pz = go.z + t * gd.z, mx = (ix * 2 + 1) * (double)(1 << (lev - 1)),
                       mz = (iz * 2 + 1) * (double)(1 << (lev - 1));
                lev--;
                int cx = px > mx || (px == mx && gd.x > 0.0), cz = pz > mz || (pz == mz && gd.z > 0.0);
                ix = 2 * ix + cx;
                iz = 2 * iz + cz;
                if (ix >= f->lw[lev]) ix = f->lw[lev] - 1;
                if (iz >= f->lh[lev]) iz = f->lh[lev] - 1;
                continue;
            }
            n = cell_hits(f, ix, iz, go, gd, tmin, tmax, out, n, max);
        }
        /* a cell's hits lie within its stretch of the ray: once `max` are
         * held and the nearest `max` end before the next node, none can
         * replace them */
        if (te >= tb || (n == max && out[max - 1].t <= te)) break;
        t = te;
        int ox = ix, oz = iz;
        if (ex <= ez) ix += sx;
        else iz += sz;
        if (ix < 0 || iz < 0 || ix >= f->lw[lev] || iz >= f->lh[lev]) break;
        /* up while the step left the parent */
        while (lev < top && ((ox >> 1) != (ix >> 1) || (oz >> 1) != (iz >> 1))) {
            ox >>= 1;
            oz >>= 1;
            ix >>= 1;
            iz >>= 1;
            lev++;
        }
    }
    return n;
}

/* Cell and local coordinates of a grid point (clamped into the grid). */
static void locate(const hf_data *f, double X, double Z, int *i, int *j, double *fx, double *fz)
{
    int a = (int)floor(X), b = (int)floor(Z);
    a = a < 0 ? 0 : (a > f->nx - 1 ? f->nx - 1 : a);
    b = b < 0 ? 0 : (b > f->nz - 1 ? f->nz - 1 : b);
    *i = a;
    *j = b;
    *fx = X - a;
    *fz = Z - b;
}

int geom_hfield_inside(const geom_shape *sh, vec3 q)
{
    const hf_data *f = sh->data;
    if (!f) return 0;
    double X = q.x * f->nx, Z = q.z * f->nz;
    if (X < 0.0 || X >= f->nx || Z < 0.0 || Z >= f->nz) return 0;
    if (q.y >= f->yhi) return 0;
    if (q.y < f->water) return 1;
    int i, j;
    double fx, fz;
    locate(f, X, Z, &i, &j, &fx, &fz);
    vec3 a, b, c;
    cell_tri(f, i, j, fx + fz < 1.0 ? 0 : 1, &a, &b, &c);
    vec3 n = v3_cross(v3_sub(b, a), v3_sub(c, a));
    if (n.y < 0.0) n = v3_neg(n);
    return v3_dot(v3_sub(v3(X, q.y, Z), a), n) < 0.0;
}

void geom_hfield_surface(const geom_shape *sh, vec3 q, int part, vec3 *n, double *u, double *v)
{
    const hf_data *f = sh->data;
    *n = v3(0, 1, 0);
    *u = q.x;
    *v = q.z;
    if (!f) return;
    int cell = part / 2, tri = part & 1;
    int i = cell % f->nx, j = cell / f->nx;
    if (part < 0 || j >= f->nz) {
        double fx, fz;
        locate(f, q.x * f->nx, q.z * f->nz, &i, &j, &fx, &fz);
        tri = fx + fz < 1.0 ? 0 : 1;
    }
    vec3 a, b, c;
    cell_tri(f, i, j, tri, &a, &b, &c);
    vec3 g = v3_cross(v3_sub(b, a), v3_sub(c, a));
    if (g.y < 0.0) g = v3_neg(g);
    *n = v3(g.x * f->nx, g.y, g.z * f->nz);
}

/* Object-space vertex normal from central differences. */
static vec3 vertex_normal(const hf_data *f, int i, int j)
{
    int i0 = i > 0 ? i - 1 : i, i1 = i < f->W - 1 ? i + 1 : i;
    int j0 = j > 0 ? j - 1 : j, j1 = j < f->H - 1 ? j + 1 : j;
    double dx = (H_at(f, i1, j) - H_at(f, i0, j)) / (double)(i1 - i0);
    double dz = (H_at(f, i, j1) - H_at(f, i, j0)) / (double)(j1 - j0);
    return v3_norm(v3(-dx * f->nx, 1.0, -dz * f->nz));
}

vec3 geom_hfield_shading(const geom_shape *sh, vec3 q)
{
    const hf_data *f = sh->data;
    if (!f || !f->smooth) return v3s(0.0);
    int i, j;
    double fx, fz;
    locate(f, q.x * f->nx, q.z * f->nz, &i, &j, &fx, &fz);
    fx = fmin_inline(1.0, fmax_inline(0.0, fx));
    fz = fmin_inline(1.0, fmax_inline(0.0, fz));
    vec3 n;
    if (fx + fz < 1.0) {
        double w0 = 1.0 - fx - fz;
        n = v3_add(v3_add(v3_scale(vertex_normal(f, i, j), w0), v3_scale(vertex_normal(f, i + 1, j), fx)),
                   v3_scale(vertex_normal(f, i, j + 1), fz));
    } else {
        double w0 = fx + fz - 1.0; /* weight of (i+1, j+1) */
        n = v3_add(v3_add(v3_scale(vertex_normal(f, i + 1, j + 1), w0), v3_scale(vertex_normal(f, i, j + 1), 1.0 - fx)),
                   v3_scale(vertex_normal(f, i + 1, j), 1.0 - fz));
    }
    return n;
}

int geom_hfield_ntriangles(const geom_shape *sh)
{
    const hf_data *f = sh->data;
    return f ? 2 * f->nx * f->nz : 0;
}

void geom_hfield_triangle(const geom_shape *sh, int part, vec3 *a, vec3 *b, vec3 *c)
{
    const hf_data *f = sh->data;
    int cell = part / 2, i = cell % f->nx, j = cell / f->nx;
    cell_tri(f, i, j, part & 1, a, b, c);
    /* grid -> object space */
    a->x /= f->nx; b->x /= f->nx; c->x /= f->nx;
    a->z /= f->nz; b->z /= f->nz; c->z /= f->nz;
}

void geom_hfield_cells(const geom_shape *sh, int *nx, int *nz)
{
    const hf_data *f = sh->data;
    *nx = f ? f->nx : 0;
    *nz = f ? f->nz : 0;
}

/* Index of coarse line k of a field with n cells at stride s (the last one n). */
static int coarse_at(int k, int s, int n) { return k * s < n ? k * s : n; }

int geom_hfield_coarse_grid(const geom_shape *sh, int sx, int sz, geom_grid_fn fn, void *ctx)
{
    const hf_data *f = sh->data;
    if (!f || f->nx < 1 || f->nz < 1) return 0;
    if (sx < 1) sx = 1;
    if (sz < 1) sz = 1;
    int cx = (f->nx + sx - 1) / sx, cz = (f->nz + sz - 1) / sz, count = 0;
    for (int j = 0; j < cz; j++)
        for (int i = 0; i < cx; i++) {
            /* corners (i, j) (i+1, j) (i, j+1) (i+1, j+1) of the coarse cell, with the
             * coarse neighbours around each for its normal */
            vec3 P[4], N[4];
            for (int q = 0; q < 4; q++) {
                int ki = i + (q & 1), kj = j + (q >> 1);
                int gi = coarse_at(ki, sx, f->nx), gj = coarse_at(kj, sz, f->nz);
                int i0 = coarse_at(ki > 0 ? ki - 1 : ki, sx, f->nx), i1 = coarse_at(ki < cx ? ki + 1 : ki, sx, f->nx);
                int j0 = coarse_at(kj > 0 ? kj - 1 : kj, sz, f->nz), j1 = coarse_at(kj < cz ? kj + 1 : kj, sz, f->nz);
                /* slopes dh/dx, dh/dz in object units (x = i / nx, z = j / nz) */
                double dx = (H_at(f, i1, gj) - H_at(f, i0, gj)) * f->nx / (double)(i1 > i0 ? i1 - i0 : 1);
                double dz = (H_at(f, gi, j1) - H_at(f, gi, j0)) * f->nz / (double)(j1 > j0 ? j1 - j0 : 1);
                P[q] = v3((double)gi / f->nx, H_at(f, gi, gj), (double)gj / f->nz);
                N[q] = v3_norm(v3(-dx, 1.0, -dz));
            }
            vec3 a[3] = {P[0], P[1], P[2]}, na[3] = {N[0], N[1], N[2]};
            vec3 b[3] = {P[3], P[2], P[1]}, nb[3] = {N[3], N[2], N[1]};
            if (!fn(ctx, a, na) || !fn(ctx, b, nb)) return -1;
            count += 2;
        }
    return count;
}
