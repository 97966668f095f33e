/* geom_sweep_grid.c - lathe, sor, prism, text and polygon as triangles:
 * a polygon's triangulation and the shapes' parametric grids (geom_sweep.h). */
#include "geom_sweep_internal.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------ polygon triangles */

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : (x > y);
}

typedef struct { double um, u0, u1; } slab_edge;

static int cmp_edge(const void *a, const void *b)
{
    const slab_edge *x = a, *y = b;
    return x->um < y->um ? -1 : (x->um > y->um);
}

int geom_polygon_triangles(const geom_shape *sh, int (*emit)(void *ctx, vec3 a, vec3 b, vec3 c), void *ctx)
{
    const sw_data *w = sh->data;
    if (!w || w->type != SW_POLYGON || w->nseg < 1) return 0;
    int n = w->nseg;
    double *vs = malloc(sizeof *vs * 2 * (size_t)n);
    slab_edge *ed = malloc(sizeof *ed * (size_t)n);
    if (!vs || !ed) {
        free(vs);
        free(ed);
        return -1;
    }
    for (int i = 0; i < n; i++) {
        vs[2 * i] = w->seg[i].e0[1];
        vs[2 * i + 1] = w->seg[i].e1[1];
    }
    qsort(vs, 2 * (size_t)n, sizeof *vs, cmp_double);
    int count = 0;
    for (int k = 0; k + 1 < 2 * n && count >= 0; k++) {
        double va = vs[k], vb = vs[k + 1];
        if (!(vb > va)) continue;
        double vm = 0.5 * (va + vb);
        int ne = 0;
        for (int i = 0; i < n; i++) {
            const sw_seg *s = &w->seg[i];
            double y0 = s->e0[1], y1 = s->e1[1];
            if (!(fmin(y0, y1) <= va && fmax(y0, y1) >= vb) || y0 == y1) continue;
            double du = (s->e1[0] - s->e0[0]) / (y1 - y0);
            ed[ne].u0 = s->e0[0] + (va - y0) * du;
            ed[ne].u1 = s->e0[0] + (vb - y0) * du;
            ed[ne].um = s->e0[0] + (vm - y0) * du;
            ne++;
        }
        qsort(ed, (size_t)ne, sizeof *ed, cmp_edge);
        for (int e = 0; e + 1 < ne; e += 2) {
            const slab_edge *l = &ed[e], *r = &ed[e + 1];
            double q[4][2] = {{l->u0, va}, {r->u0, va}, {r->u1, vb}, {l->u1, vb}};
            vec3 P[4];
            for (int c = 0; c < 4; c++)
                P[c] = v3_add(w->p0, v3_add(v3_scale(w->pu, q[c][0] * w->L), v3_scale(w->pv, q[c][1] * w->L)));
            if (r->u0 > l->u0) {
                if (!emit(ctx, P[0], P[1], P[2])) { count = -1; break; }
                count++;
            }
            if (r->u1 > l->u1) {
                if (!emit(ctx, P[0], P[2], P[3])) { count = -1; break; }
                count++;
            } else if (r->u0 > l->u0) {
                /* (the first triangle already covers a trapezoid degenerate at the top) */
            }
        }
    }
    free(vs);
    free(ed);
    return count;
}

/* ------------------------------------------------------------ grid */

typedef struct {
    const sw_data *w;
    geom_grid_fn fn;
    void *ctx;
    int count;
} grid_out;

static vec3 to_object(const sw_data *w, vec3 l) { return v3_add(w->c, v3_scale(l, w->L)); }

/* A quad of local points/normals as two triangles (degenerate ones dropped). */
static int emit_quad(grid_out *g, const vec3 P[4], const vec3 N[4])
{
    static const int tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
    for (int t = 0; t < 2; t++) {
        vec3 p[3], n[3];
        for (int k = 0; k < 3; k++) {
            p[k] = to_object(g->w, P[tri[t][k]]);
            n[k] = v3_norm(N[tri[t][k]]);
        }
        if (!(v3_len2(v3_cross(v3_sub(p[1], p[0]), v3_sub(p[2], p[0]))) > 0.0)) continue;
        if (!g->fn(g->ctx, p, n)) return 0;
        g->count++;
    }
    return 1;
}

/* Surface point and normal of part `part` at (a, b) in [0,1]^2 (local). */
static void grid_point(const sw_data *w, int part, double a, double b, vec3 *p, vec3 *n)
{
    int k = part - 2;
    if (w->type == SW_LATHE) {
        const sw_seg *s = &w->seg[k];
        double c[2], n2[2], phi = 2.0 * M_PI * b;
        seg_eval(s, a, c, NULL);
        seg_normal(s, a, n2);
        *p = v3(c[0] * cos(phi), c[1], c[0] * sin(phi));
        *n = v3(n2[0] * cos(phi), n2[1], n2[0] * sin(phi));
    } else if (w->type == SW_SOR) {
        double phi = 2.0 * M_PI * b;
        if (part < 2) {
            double r2 = part == 0 ? w->base_r2 : w->cap_r2, rho = sqrt(r2) * a;
            *p = v3(rho * cos(phi), part == 0 ? w->sor[0].y0 : w->sor[w->nseg - 1].y1, rho * sin(phi));
            *n = v3(0, part == 0 ? -1 : 1, 0);
            return;
        }
        const sor_seg *s = &w->sor[k];
        double y = s->y0 + a * (s->y1 - s->y0), dg, rr = sqrt(fmax(0.0, sor_g(s, y, &dg)));
        *p = v3(rr * cos(phi), y, rr * sin(phi));
        *n = v3(p->x, -0.5 * dg, p->z);
    } else {
        const sw_seg *s = &w->seg[k];
        double c[2], n2[2], h = w->h1 + b * (w->h2 - w->h1);
        seg_eval(s, a, c, NULL);
        seg_normal(s, a, n2);
        if (!w->conic) {
            *p = from_local_axes(w->ax, c[0], h, c[1]);
            *n = from_local_axes(w->ax, n2[0], 0.0, n2[1]);
        } else {
            double sg = h < 0.0 ? -1.0 : 1.0;
            *p = from_local_axes(w->ax, h * c[0], h, h * c[1]);
            *n = from_local_axes(w->ax, sg * n2[0], -sg * (c[0] * n2[0] + c[1] * n2[1]), sg * n2[1]);
        }
    }
}

/* Grid with na[k] cells along segment k, nb around (lathe, sor) or along
 * the sweep (prism), nr along the radius of a sor's caps; prism caps from
 * the curves polygonised into na[k] pieces each. */
static int grid_sized(const sw_data *w, const int *na, int nb, int nr, geom_grid_fn fn, void *ctx)
{
    grid_out g = {w, fn, ctx, 0};
    for (int k = 0; k < w->nseg; k++) {
        if (w->type == SW_LATHE && w->seg[k].hi[0] <= 0.0 && w->seg[k].lo[0] >= 0.0) continue;
        for (int j = 0; j < nb; j++)
            for (int i = 0; i < na[k]; i++) {
                vec3 P[4], N[4];
                double as[4] = {(double)i / na[k], (double)(i + 1) / na[k], (double)(i + 1) / na[k], (double)i / na[k]};
                double bs[4] = {(double)j / nb, (double)j / nb, (double)(j + 1) / nb, (double)(j + 1) / nb};
                for (int c = 0; c < 4; c++) grid_point(w, 2 + k, as[c], bs[c], &P[c], &N[c]);
                if (!emit_quad(&g, P, N)) return -1;
            }
    }
    if (w->type == SW_SOR && !w->open) {
        for (int part = 0; part < 2; part++)
            for (int j = 0; j < nb; j++)
                for (int i = 0; i < nr; i++) {
                    vec3 P[4], N[4];
                    double as[4] = {(double)i / nr, (double)(i + 1) / nr, (double)(i + 1) / nr, (double)i / nr};
                    double bs[4] = {(double)j / nb, (double)j / nb, (double)(j + 1) / nb, (double)(j + 1) / nb};
                    for (int c = 0; c < 4; c++) grid_point(w, part, as[c], bs[c], &P[c], &N[c]);
                    if (!emit_quad(&g, P, N)) return -1;
                }
    }
    if (w->type == SW_PRISM && !w->open) {
        /* caps: the curves polygonised (na[k] pieces for segment k), cut
         * into trapezoids between vertex heights (even-odd) */
        int m = 0;
        for (int k = 0; k < w->nseg; k++) m += na[k];
        double *vs = malloc(sizeof *vs * (size_t)m);
        double(*pts)[2] = malloc(sizeof *pts * (size_t)m * 2);
        if (!vs || !pts) {
            free(vs);
            free(pts);
            return g.count;
        }
        for (int k = 0, e = 0; k < w->nseg; k++)
            for (int i = 0; i < na[k]; i++, e++) {
                seg_eval(&w->seg[k], (double)i / na[k], pts[2 * e], NULL);
                seg_eval(&w->seg[k], (double)(i + 1) / na[k], pts[2 * e + 1], NULL);
                vs[e] = pts[2 * e][1];
            }
        qsort(vs, (size_t)m, sizeof *vs, cmp_double);
        double(*ed)[3] = malloc(sizeof *ed * (size_t)m);
        for (int s2 = 0; ed && s2 + 1 < m; s2++) {
            double va = vs[s2], vb = vs[s2 + 1];
            if (!(vb > va)) continue;
            double vm = 0.5 * (va + vb);
            int ne = 0;
            for (int e = 0; e < m; e++) {
                const double *p0 = pts[2 * e], *p1 = pts[2 * e + 1];
                if (!(fmin(p0[1], p1[1]) <= va && fmax(p0[1], p1[1]) >= vb) || p0[1] == p1[1]) continue;
                double du = (p1[0] - p0[0]) / (p1[1] - p0[1]);
                ed[ne][0] = p0[0] + (vm - p0[1]) * du;
                ed[ne][1] = p0[0] + (va - p0[1]) * du;
                ed[ne][2] = p0[0] + (vb - p0[1]) * du;
                ne++;
            }
            for (int x = 1; x < ne; x++)
                for (int y = x; y > 0 && ed[y][0] < ed[y - 1][0]; y--) {
                    double t[3];
                    memcpy(t, ed[y], sizeof t);
                    memcpy(ed[y], ed[y - 1], sizeof t);
                    memcpy(ed[y - 1], t, sizeof t);
                }
            for (int e = 0; e + 1 < ne; e += 2)
                for (int cap = 0; cap < 2; cap++) {
                    double h = cap ? w->h2 : w->h1, sc = w->conic ? h : 1.0;
                    if (w->conic && h == 0.0) continue;
                    double q[4][2] = {{ed[e][1], va}, {ed[e + 1][1], va}, {ed[e + 1][2], vb}, {ed[e][2], vb}};
                    vec3 P[4], N[4];
                    for (int c = 0; c < 4; c++) {
                        P[c] = from_local_axes(w->ax, sc * q[c][0], h, sc * q[c][1]);
                        N[c] = from_local_axes(w->ax, 0.0, cap ? 1.0 : -1.0, 0.0);
                    }
                    if (!emit_quad(&g, P, N)) {
                        free(vs);
                        free(pts);
                        free(ed);
                        return -1;
                    }
                }
        }
        free(vs);
        free(pts);
        free(ed);
    }
    return g.count;
}

int geom_sweep_grid(const geom_shape *sh, int n, geom_grid_fn fn, void *ctx)
{
    const sw_data *w = sh->data;
    if (!w || n < 1) return 0;
    int *na = malloc(sizeof *na * (size_t)(w->nseg > 0 ? w->nseg : 1));
    if (!na) return -1;
    for (int k = 0; k < w->nseg; k++) na[k] = n;
    int r = grid_sized(w, na, w->type == SW_PRISM ? n : 4 * n, n, fn, ctx);
    free(na);
    return r;
}

/* Cells for a length, or for an angle with cell the most turn of one cell:
 * ceil(len / cell) within [lo, 4096]. */
static int cells_for(double len, double cell, int lo)
{
    double c = ceil(len / cell);
    return !(c >= lo) ? lo : (c > 4096.0 ? 4096 : (int)c);
}

/* How far (radians) the normal of segment k turns along it: the angles
 * between successive normals at s + 1 points (the sweep's first position:
 * a lathe's or sor's profile normal turns alike at every angle). */
static double seg_turn(const sw_data *w, int k, int s)
{
    double turn = 0.0;
    vec3 p, n0, n1;
    grid_point(w, 2 + k, 0.0, 0.0, &p, &n0);
    for (int i = 1; i <= s; i++) {
        grid_point(w, 2 + k, (double)i / s, 0.0, &p, &n1);
        double l0 = v3_len(n0), l1 = v3_len(n1);
        if (l0 > 0.0 && l1 > 0.0) {
            double c = v3_dot(n0, n1) / (l0 * l1);
            if (isfinite(c)) turn += acos(c > 1.0 ? 1.0 : (c < -1.0 ? -1.0 : c));
        }
        n0 = n1;
    }
    return turn;
}

int geom_sweep_grid_cell(const geom_shape *sh, double cell, double turn, geom_grid_fn fn, void *ctx)
{
    const sw_data *w = sh->data;
    if (!w || w->type == SW_POLYGON || !(cell > 0.0) || !isfinite(cell)) return 0;
    if (!(turn > 0.0) || !isfinite(turn)) turn = INFINITY;
    double c = cell / w->L; /* the bound in local units */
    enum { S = 32 };
    int *na = malloc(sizeof *na * (size_t)(w->nseg > 0 ? w->nseg : 1));
    if (!na) return -1;
    double around = 0.0, rmax = 0.0;
    for (int k = 0; k < w->nseg; k++) {
        /* the segment's arc length (longest of the curve at the sweep's two
         * ends, for conic prisms) and its ruling's or circle's length */
        double arc = 0.0;
        for (int e = 0; e < 2; e++) {
            double len = 0.0;
            vec3 a, b, nn;
            grid_point(w, 2 + k, 0.0, (double)e, &a, &nn);
            for (int i = 1; i <= S; i++) {
                grid_point(w, 2 + k, (double)i / S, (double)e, &b, &nn);
                len += v3_len(v3_sub(b, a));
                rmax = fmax(rmax, sqrt(b.x * b.x + b.z * b.z));
                a = b;
            }
            arc = fmax(arc, len);
            if (w->type != SW_PRISM) break;
        }
        na[k] = cells_for(arc, c, 1);
        if (isfinite(turn)) {
            int t = cells_for(seg_turn(w, k, S), turn, 1);
            if (t > na[k]) na[k] = t;
        }
        if (w->type == SW_PRISM) {
            for (int i = 0; i <= 4; i++) {
                vec3 a, b, nn;
                grid_point(w, 2 + k, i / 4.0, 0.0, &a, &nn);
                grid_point(w, 2 + k, i / 4.0, 1.0, &b, &nn);
                around = fmax(around, v3_len(v3_sub(b, a)));
            }
        }
    }
    if (w->type == SW_SOR) rmax = fmax(rmax, sqrt(fmax(w->base_r2, w->cap_r2)));
    int nb = w->type == SW_PRISM ? cells_for(around, c, 1) : cells_for(2.0 * M_PI * rmax, c, 3);
    if (w->type != SW_PRISM && isfinite(turn)) {
        int t = cells_for(2.0 * M_PI, turn, 3);
        if (t > nb) nb = t;
    }
    int nr = cells_for(sqrt(fmax(w->base_r2, w->cap_r2)), c, 1);
    int r = grid_sized(w, na, nb, nr, fn, ctx);
    free(na);
    return r;
}
