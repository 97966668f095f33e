/* accel_surface.c - uniform-by-area sampling of scene surfaces (see the header).
 *
 * Area scale of a linear map A on a surface element with unit normal n:
 * dA' = |det A| |A^-T n| dA (Nanson's relation). For planar parts it is a
 * constant; for curved parts its maximum over all n is |det A| sigma_max(A^-1),
 * the bound used for rejection. */
#include "accel_surface.h"
#include "hash.h"
#include "grow.h"
#include <assert.h>
#include "geom_hfield.h"
#include "geom_sweep.h"
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "geom_shape.h"
#include "geom_tess.h"
#include "pool.h"

enum { INHERITED = OBJ_NO_SHADOW | OBJ_NO_IMAGE | OBJ_NO_REFLECTION | OBJ_NO_RADIOSITY };
#define MAX_DEPTH 256
#define MAX_REJECT 4096

typedef struct {
    vec3 v0, e1, e2, n;
} tri_geo;

typedef struct {
    geom_shape sh;
    int similar;           /* J constant over the shape */
    double jmax;           /* bound on J for rejection */
    int nparts;
    double part_cdf[6];    /* box faces / cone side, base, cap: by world area */
    int npoly;             /* plane: clipped polygon (fan triangulated) */
    vec3 poly[12];
    double tri_cdf[12];
    vec3 clip_lo, clip_hi;
    int crofton;           /* sampled by random lines (geom_tess.h) */
    geom_tess_sampler cro; /* its sh pointer is set at each use (the array moves) */
} shape_geo;

/* Crofton sampling: the relative standard error asked of the area estimate,
 * the most lines cast for it per shape, and a budget for the whole scene
 * (shared out evenly, at least CROFTON_MIN_LINES each): a scene of 100
 * blobs casts 2^19 lines in all, ~5,000 each (about 1% area error), a
 * single shape up to 16,384 (0.05-1%, well below the particles' own noise). */
#define CROFTON_REL_ERR 3e-3
#define CROFTON_MAX_LINES 16384
#define CROFTON_MIN_LINES 2048
#define CROFTON_BUDGET (1 << 19)

typedef struct {
    accel_surf_piece pub;
    int is_shape;
    int idx;
} piece_rec;

typedef struct {
    const scene_object *obj;
    unsigned prim;
    int piece;
} slot;

struct accel_surf {
    const scene *s;
    piece_rec *pieces;
    int npieces, cappieces;
    tri_geo *tris;
    int ntris, captris;
    shape_geo *shapes;
    int nshapes, capshapes;
    double *cdf;
    double total_w, total_area;
    slot *tab;
    size_t tabcap;
    vec3 lo, hi;
    int have_bounds;
    accel_surf_weight_fn fn;
    void *ctx;
};

/* ------------------------------------------------------------ linear algebra */

static void lin(const xform *x, double a[3][3])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) a[i][j] = x->m[i][j];
}

static double det3(double a[3][3])
{
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
}

/* A^T A = s^2 I (to 1e-9): a similarity, J constant. */
static int is_similarity(const xform *x)
{
    double a[3][3];
    lin(x, a);
    double g[3][3], tr = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            g[i][j] = a[0][i] * a[0][j] + a[1][i] * a[1][j] + a[2][i] * a[2][j];
            if (i == j) tr += g[i][j];
        }
    double s2 = tr / 3.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (fabs(g[i][j] - (i == j ? s2 : 0.0)) > 1e-9 * s2) return 0;
    return 1;
}

/* |det A| * sigma_max(A^-1): power iteration on B B^T with B = A^-1. */
static double jacobian_bound(const xform *x)
{
    double a[3][3], b[3][3];
    lin(x, a);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) b[i][j] = x->inv[i][j];
    double c[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) c[i][j] = b[i][0] * b[j][0] + b[i][1] * b[j][1] + b[i][2] * b[j][2];
    double v[3] = {0.57735, 0.57736, 0.57737}, lam = 0.0;
    for (int it = 0; it < 200; it++) {
        double w[3];
        for (int i = 0; i < 3; i++) w[i] = c[i][0] * v[0] + c[i][1] * v[1] + c[i][2] * v[2];
        double l = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        if (!(l > 0.0)) break;
        for (int i = 0; i < 3; i++) v[i] = w[i] / l;
        lam = l;
    }
    return fabs(det3(a)) * sqrt(lam) * 1.000001;
}

/* |det| of x's linear part (jac's first factor, the same for every normal). */
static double jac_det(const xform *x)
{
    double a[3][3];
    lin(x, a);
    return fabs(det3(a));
}

/* Local area scale for an object-space unit normal n. */
static double jac(const xform *x, vec3 n) { return jac_det(x) * v3_len(xform_normal(x, n)); }

/* ------------------------------------------------------------ object-space parametrisations */

static vec3 sphere_normal(double u1, double u2)
{
    double z = 1.0 - 2.0 * u1, s = sqrt(fmax(0.0, 1.0 - z * z)), phi = 2.0 * M_PI * u2;
    return v3(s * cos(phi), s * sin(phi), z);
}

static vec3 cone_side_normal(const geom_shape *sh, double phi)
{
    vec3 er = v3_add(v3_scale(sh->g.cone.u, cos(phi)), v3_scale(sh->g.cone.v, sin(phi)));
    return v3_norm(v3_sub(er, v3_scale(sh->g.cone.w, sh->g.cone.k)));
}

static vec3 torus_normal(double u, double v)
{
    return v3(cos(v) * cos(u), sin(v), cos(v) * sin(u));
}

/* World areas of the parts; fills part_cdf. Returns the total. */
static double shape_area(shape_geo *g)
{
    geom_shape *sh = &g->sh;
    const xform *x = &sh->x;
    double parts[6] = {0};
    g->nparts = 1;
    switch (sh->kind) {
    case SHAPE_SPHERE: {
        double r = sh->g.sphere.r, base = 4.0 * M_PI * r * r;
        if (g->similar) {
            parts[0] = base * jac(x, v3(0, 0, 1));
        } else {
            /* midpoint rule in z (smooth: error ~ 1/nz^2, below 1e-5 of
             * the area here) x phi (periodic: spectral, exact to rounding
             * for this quadratic form's square root well before 64) */
            enum { nz = 1024, np = 64 };
            double acc = 0.0, det = jac_det(x), cph[np], sph[np];
            /* sphere_normal's terms, its angles' sine and cosine once per
             * column rather than once per cell (65,536 of them) */
            for (int j = 0; j < np; j++) {
                double phi = 2.0 * M_PI * ((j + 0.5) / np);
                cph[j] = cos(phi);
                sph[j] = sin(phi);
            }
            for (int i = 0; i < nz; i++) {
                double z = 1.0 - 2.0 * ((i + 0.5) / nz), sz = sqrt(fmax(0.0, 1.0 - z * z));
                for (int j = 0; j < np; j++) acc += det * v3_len(xform_normal(x, v3(sz * cph[j], sz * sph[j], z)));
            }
            parts[0] = base * acc / ((double)nz * np);
        }
        break;
    }
    case SHAPE_BOX: {
        vec3 lo = sh->g.box.lo, hi = sh->g.box.hi, e = v3_sub(hi, lo);
        double fa[3] = {e.y * e.z, e.x * e.z, e.x * e.y};
        for (int f = 0; f < 6; f++) {
            int axis = f / 2;
            vec3 n = v3(axis == 0 ? 1 : 0, axis == 1 ? 1 : 0, axis == 2 ? 1 : 0);
            parts[f] = fa[axis] * jac(x, n);
        }
        g->nparts = 6;
        break;
    }
    case SHAPE_CYLINDER:
    case SHAPE_CONE: {
        double r0 = sh->g.cone.r0, r1 = sh->g.cone.r1, h = sh->g.cone.h;
        double slant = sqrt(h * h + (r1 - r0) * (r1 - r0));
        double side_obj = M_PI * (r0 + r1) * slant;
        if (g->similar) {
            parts[0] = side_obj * jac(x, cone_side_normal(sh, 0.0));
        } else {
            int np = 1024;
            double acc = 0.0;
            for (int j = 0; j < np; j++) acc += jac(x, cone_side_normal(sh, 2.0 * M_PI * (j + 0.5) / np));
            parts[0] = side_obj * acc / np;
        }
        if (!sh->open) {
            parts[1] = M_PI * r0 * r0 * jac(x, sh->g.cone.w);
            parts[2] = M_PI * r1 * r1 * jac(x, sh->g.cone.w);
        }
        g->nparts = 3;
        break;
    }
    case SHAPE_DISC:
        parts[0] = M_PI * (sh->g.disc.r2 - sh->g.disc.h2) * jac(x, sh->g.disc.n);
        break;
    case SHAPE_TORUS: {
        double R = sh->g.torus.R, r = sh->g.torus.r;
        if (g->similar) {
            parts[0] = 4.0 * M_PI * M_PI * R * r * jac(x, v3(0, 1, 0));
        } else {
            int n = 256;
            double acc = 0.0;
            for (int i = 0; i < n; i++)
                for (int j = 0; j < n; j++) {
                    double u = 2.0 * M_PI * (i + 0.5) / n, v = 2.0 * M_PI * (j + 0.5) / n;
                    acc += jac(x, torus_normal(u, v)) * r * fabs(R + r * cos(v));
                }
            parts[0] = acc * (2.0 * M_PI / n) * (2.0 * M_PI / n);
        }
        break;
    }
    case SHAPE_LATHE: case SHAPE_SOR: case SHAPE_PRISM: case SHAPE_TEXT:
        /* uniform in object space (geom_sweep), so only under similarities */
        if (g->similar) parts[0] = geom_sweep_area(sh) * jac(x, v3(0, 1, 0));
        break;
    default:
        break;
    }
    double total = 0.0;
    for (int i = 0; i < g->nparts; i++) total += parts[i];
    double acc = 0.0;
    for (int i = 0; i < g->nparts; i++) {
        acc += parts[i];
        g->part_cdf[i] = total > 0.0 ? acc / total : (double)(i + 1) / g->nparts;
    }
    return total;
}

/* Shapes sampled by random lines: those without a parametrisation of their
 * own, and the sweeps where theirs is not uniform (non-similar transforms,
 * conic prisms: geom_sweep_area 0). */
static int use_crofton(const shape_geo *g)
{
    switch (g->sh.kind) {
    case SHAPE_SUPERELLIPSOID: case SHAPE_QUADRIC: case SHAPE_POLY: case SHAPE_BLOB: case SHAPE_ISOSURFACE:
    case SHAPE_JULIA: case SHAPE_OVUS:
        return 1;
    case SHAPE_LATHE: case SHAPE_SOR: case SHAPE_PRISM: case SHAPE_TEXT:
        return !g->similar || !(geom_sweep_area(&g->sh) > 0.0);
    default:
        return 0;
    }
}

/* Plane clipped to the box [lo, hi]: convex polygon, fan-triangulated. */
static double plane_polygon(shape_geo *g, vec3 lo, vec3 hi)
{
    geom_shape *sh = &g->sh;
    vec3 p0 = xform_point(&sh->x, v3_scale(sh->g.plane.n, sh->g.plane.d));
    vec3 n = v3_norm(xform_normal(&sh->x, sh->g.plane.n));
    vec3 c[8];
    for (int i = 0; i < 8; i++) c[i] = v3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    double sd[8];
    for (int i = 0; i < 8; i++) sd[i] = v3_dot(v3_sub(c[i], p0), n);
    static const int edges[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                     {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
    vec3 pts[12];
    int np = 0;
    for (int e = 0; e < 12 && np < 12; e++) {
        double a = sd[edges[e][0]], b = sd[edges[e][1]];
        if ((a < 0.0) == (b < 0.0) && a != 0.0 && b != 0.0) continue;
        if (a == b) continue;
        double t = a / (a - b);
        if (t < 0.0 || t > 1.0) continue;
        vec3 q = v3_add(c[edges[e][0]], v3_scale(v3_sub(c[edges[e][1]], c[edges[e][0]]), t));
        int dup = 0;
        for (int k = 0; k < np; k++)
            if (v3_len2(v3_sub(pts[k], q)) < 1e-24 * (1.0 + v3_len2(q))) dup = 1;
        if (!dup) pts[np++] = q;
    }
    g->npoly = 0;
    if (np < 3) return 0.0;
    vec3 ctr = v3s(0.0);
    for (int k = 0; k < np; k++) ctr = v3_add(ctr, pts[k]);
    ctr = v3_scale(ctr, 1.0 / np);
    vec3 t, b;
    v3_basis(n, &t, &b);
    double ang[12];
    for (int k = 0; k < np; k++) {
        vec3 d = v3_sub(pts[k], ctr);
        ang[k] = atan2(v3_dot(d, b), v3_dot(d, t));
    }
    for (int i = 1; i < np; i++)
        for (int j = i; j > 0 && ang[j] < ang[j - 1]; j--) {
            double ta = ang[j]; ang[j] = ang[j - 1]; ang[j - 1] = ta;
            vec3 tp = pts[j]; pts[j] = pts[j - 1]; pts[j - 1] = tp;
        }
    double total = 0.0, area[12];
    for (int k = 1; k + 1 < np; k++) {
        area[k - 1] = 0.5 * v3_len(v3_cross(v3_sub(pts[k], pts[0]), v3_sub(pts[k + 1], pts[0])));
        total += area[k - 1];
    }
    double acc = 0.0;
    for (int k = 0; k + 2 < np; k++) {
        acc += area[k];
        g->tri_cdf[k] = total > 0.0 ? acc / total : 1.0;
    }
    memcpy(g->poly, pts, sizeof(vec3) * (size_t)np);
    g->npoly = np;
    g->clip_lo = lo;
    g->clip_hi = hi;
    return total;
}

/* ------------------------------------------------------------ building */

static int add_piece(accel_surf *as, const scene_object *o, const scene_texture *tex, unsigned flags, unsigned prim,
                     double area, double w, int is_shape, int idx)
{
    if (!grow_array_int((void **)&as->pieces, &as->cappieces, as->npieces + 1, sizeof(piece_rec))) return 0;
    piece_rec *p = &as->pieces[as->npieces++];
    p->pub.obj = o;
    p->pub.texture = tex;
    p->pub.flags = flags;
    p->pub.prim = prim;
    p->pub.area = area;
    p->pub.weight = w;
    p->is_shape = is_shape;
    p->idx = idx;
    return 1;
}

static double weight_of(accel_surf *as, const scene_object *o, const scene_texture *tex, unsigned flags)
{
    double w = as->fn ? as->fn(as->ctx, o, tex, flags) : 1.0;
    return w > 0.0 && isfinite(w) ? w : 0.0;
}

static int add_triangle(accel_surf *as, const scene_object *o, const scene_texture *tex, unsigned flags,
                        unsigned prim, vec3 a, vec3 b, vec3 c, double w)
{
    vec3 pa = xform_point(&o->transform, a), pb = xform_point(&o->transform, b), pc = xform_point(&o->transform, c);
    vec3 e1 = v3_sub(pb, pa), e2 = v3_sub(pc, pa), cr = v3_cross(e1, e2);
    double area = 0.5 * v3_len(cr);
    if (!(area > 0.0) || !isfinite(area)) return 1;
    if (!grow_array_int((void **)&as->tris, &as->captris, as->ntris + 1, sizeof(tri_geo))) return 0;
    tri_geo *t = &as->tris[as->ntris];
    t->v0 = pa;
    t->e1 = e1;
    t->e2 = e2;
    t->n = v3_scale(cr, 0.5 / area);
    if (!add_piece(as, o, tex, flags, prim, area, w, 0, as->ntris)) return 0;
    as->ntris++;
    return 1;
}

static int add_leaf(accel_surf *as, const scene_object *o, const scene_texture *tex, unsigned flags)
{
    if (o->kind == SHAPE_MESH) {
        const scene_mesh *m = o->u.mesh.mesh;
        if (!m) return 1;
        for (int t = 0; t < m->ntris; t++) {
            const int *v = m->tris[t];
            if (v[0] < 0 || v[0] >= m->nverts || v[1] < 0 || v[1] >= m->nverts || v[2] < 0 || v[2] >= m->nverts)
                continue;
            const scene_texture *tt = scene_mesh_tri_texture(o, t);
            if (!tt) tt = tex;
            double w = weight_of(as, o, tt, flags);
            if (w <= 0.0) continue;
            vec3 p[3];
            for (int k = 0; k < 3; k++) p[k] = v3(m->verts[v[k]][0], m->verts[v[k]][1], m->verts[v[k]][2]);
            if (!add_triangle(as, o, tt, flags, (unsigned)t, p[0], p[1], p[2], w)) return 0;
        }
        return 1;
    }
    double w = weight_of(as, o, tex, flags);
    if (w <= 0.0) return 1;
    if (o->kind == SHAPE_TRIANGLE || o->kind == SHAPE_SMOOTH_TRIANGLE)
        return add_triangle(as, o, tex, flags, ACCEL_SURF_ANY, o->u.triangle.v[0], o->u.triangle.v[1],
                            o->u.triangle.v[2], w);
    if (!grow_array_int((void **)&as->shapes, &as->capshapes, as->nshapes + 1, sizeof(shape_geo))) return 0;
    shape_geo *g = &as->shapes[as->nshapes];
    memset(g, 0, sizeof *g);
    if (geom_shape_init(&g->sh, o) != 0) return 1;
    double area;
    if (o->kind == SHAPE_PLANE) {
        if (!as->have_bounds) return 1;
        area = plane_polygon(g, as->lo, as->hi);
    } else {
        g->similar = is_similarity(&o->transform);
        g->jmax = jacobian_bound(&o->transform);
        area = use_crofton(g) ? 0.0 : shape_area(g);
        if (!(area > 0.0) && use_crofton(g)) {
            /* implicit shapes, and sweeps the own parametrisation cannot
             * sample under this transform: random lines (exact in
             * distribution); unbounded ones within the scene's extent */
            if (g->sh.infinite) {
                if (!as->have_bounds) {
                    geom_shape_release(&g->sh);
                    return 1;
                }
                geom_shape_clip_plane(&g->sh, as->lo, as->hi);
                g->clip_lo = as->lo;
                g->clip_hi = as->hi;
            }
            /* the area is estimated once all shapes are known (finish_crofton) */
            g->crofton = 1;
            area = 1.0;
        }
    }
    if (!(area > 0.0) || !isfinite(area)) {
        geom_shape_release(&g->sh);
        return 1;
    }
    if (!add_piece(as, o, tex, flags, ACCEL_SURF_ANY, area, w, 1, as->nshapes)) {
        geom_shape_release(&g->sh);
        return 0;
    }
    as->nshapes++;
    return 1;
}

/* Further shapes whose surfaces are exactly triangles: polygon (its
 * even-odd region cut into trapezoids) and height_field (its cells). The
 * curved ones (lathe, sor, prism, text, superellipsoid, quadric, poly,
 * blob) are not sampled yet: pdf 0, which keeps MIS unbiased. */
typedef struct {
    accel_surf *as;
    const scene_object *o;
    const scene_texture *tex;
    unsigned flags;
    double w;
} tri_sink;

static int sink_tri(void *ctx, vec3 a, vec3 b, vec3 c)
{
    tri_sink *k = ctx;
    return add_triangle(k->as, k->o, k->tex, k->flags, ACCEL_SURF_ANY, a, b, c, k->w);
}

static int add_issue4(accel_surf *as, const scene_object *o, const scene_texture *tex, unsigned flags)
{
    double w = weight_of(as, o, tex, flags);
    if (w <= 0.0) return 1;
    geom_shape sh;
    if (geom_shape_init(&sh, o) != 0) return 1;
    int ok = 1;
    if (o->kind == SHAPE_POLYGON) {
        tri_sink k = {as, o, tex, flags, w};
        ok = geom_polygon_triangles(&sh, sink_tri, &k) >= 0;
    } else {
        int n = geom_hfield_ntriangles(&sh);
        for (int i = 0; i < n && ok; i++) {
            vec3 a, b, c;
            geom_hfield_triangle(&sh, i, &a, &b, &c);
            ok = add_triangle(as, o, tex, flags, (unsigned)i, a, b, c, w);
        }
    }
    geom_shape_release(&sh);
    return ok;
}

static int collect(accel_surf *as, const scene_object *o, const scene_texture *ptex, unsigned pflags, int depth)
{
    if (!o || depth > MAX_DEPTH) return 1;
    if (o->clip) return 1; /* clipped_by: only part of the surface exists; not sampled */
    const scene_texture *tex = o->texture ? o->texture : ptex;
    unsigned flags = o->flags | (pflags & INHERITED);
    switch (o->kind) {
    case SHAPE_UNION:
        for (int i = 0; i < o->u.csg.nkids; i++)
            if (!collect(as, o->u.csg.kids[i], tex, flags, depth + 1)) return 0;
        return 1;
    case SHAPE_SPHERE: case SHAPE_BOX: case SHAPE_PLANE: case SHAPE_TRIANGLE: case SHAPE_SMOOTH_TRIANGLE:
    case SHAPE_MESH: case SHAPE_CYLINDER: case SHAPE_CONE: case SHAPE_DISC: case SHAPE_TORUS:
        return add_leaf(as, o, tex ? tex : &as->s->default_texture, flags);
    case SHAPE_POLYGON: case SHAPE_HEIGHT_FIELD:
        return add_issue4(as, o, tex ? tex : &as->s->default_texture, flags);
    case SHAPE_LATHE: case SHAPE_SOR: case SHAPE_PRISM: case SHAPE_TEXT:
    case SHAPE_SUPERELLIPSOID: case SHAPE_QUADRIC: case SHAPE_POLY: case SHAPE_BLOB: case SHAPE_ISOSURFACE:
    case SHAPE_JULIA: case SHAPE_OVUS:
        return add_leaf(as, o, tex ? tex : &as->s->default_texture, flags);
    default: /* merge, intersection, difference, unsupported: not sampled */
        return 1;
    }
}

/* Area estimates of the shapes sampled by lines, within the scene's budget.
 * Each shape's estimate depends only on its shape and the line count (its
 * lines are a fixed quasi-random sequence), so the shapes are estimated in
 * parallel and the result is the same for any thread count. */
typedef struct {
    accel_surf *as;
    const int *piece; /* the pieces sampled by lines */
    double *area;     /* their estimates */
    int lines;
    int inner;        /* threads each estimate counts its lines on: the
                         render's threads when there are fewer shapes */
} crofton_job;

static void crofton_one(void *ctx, int k, int thread)
{
    (void)thread;
    crofton_job *J = ctx;
    shape_geo *g = &J->as->shapes[J->as->pieces[J->piece[k]].idx];
    J->area[k] = geom_tess_sampler_init(&g->cro, &g->sh, NULL, NULL, CROFTON_REL_ERR, J->lines, J->inner);
}

static int finish_crofton(accel_surf *as, int threads)
{
    int n = 0;
    for (int i = 0; i < as->nshapes; i++) n += as->shapes[i].crofton;
    if (n == 0) return 1;
    int lines = CROFTON_BUDGET / n;
    if (lines > CROFTON_MAX_LINES) lines = CROFTON_MAX_LINES;
    if (lines < CROFTON_MIN_LINES) lines = CROFTON_MIN_LINES;
    int *piece = malloc((size_t)as->npieces * sizeof *piece);
    double *area = malloc((size_t)as->npieces * sizeof *area);
    if (!piece || !area) {
        free(piece);
        free(area);
        return 0;
    }
    int m = 0;
    for (int i = 0; i < as->npieces; i++)
        if (as->pieces[i].is_shape && as->shapes[as->pieces[i].idx].crofton) piece[m++] = i;
    if (threads <= 0) threads = 1;
    crofton_job J = {as, piece, area, lines, m > 0 && m < threads ? threads / m : 1};
    pool_run(threads, m, crofton_one, &J);
    for (int k = 0; k < m; k++) {
        piece_rec *p = &as->pieces[piece[k]];
        shape_geo *g = &as->shapes[p->idx];
        if (!(area[k] > 0.0) || !isfinite(area[k])) {
            /* no surface found: never chosen, pdf 0 */
            p->pub.area = 0.0;
            p->pub.weight = 0.0;
            g->crofton = 0;
            g->cro.area = 0.0;
            continue;
        }
        p->pub.area = area[k];
    }
    free(piece);
    free(area);
    return 1;
}

static uint64_t hash_key(const scene_object *o, unsigned prim)
{
    return pt_mix64((uint64_t)(uintptr_t)o ^ ((uint64_t)prim * 0x9e3779b97f4a7c15ULL));
}

static unsigned key_prim(const scene_object *o, unsigned prim)
{
    return o->kind == SHAPE_MESH || o->kind == SHAPE_HEIGHT_FIELD ? prim : ACCEL_SURF_ANY;
}

static int build_table(accel_surf *as)
{
    size_t cap = 16;
    while (cap < 2 * (size_t)as->npieces) cap *= 2;
    as->tab = calloc(cap, sizeof(slot));
    if (!as->tab) return 0;
    as->tabcap = cap;
    for (int i = 0; i < as->npieces; i++) {
        const accel_surf_piece *p = &as->pieces[i].pub;
        size_t h = (size_t)hash_key(p->obj, p->prim) & (cap - 1);
        while (as->tab[h].obj) h = (h + 1) & (cap - 1);
        as->tab[h].obj = p->obj;
        as->tab[h].prim = p->prim;
        as->tab[h].piece = i;
    }
    return 1;
}

accel_surf *accel_surf_build(const scene *s, const accel *a, accel_surf_weight_fn weight, void *ctx, diag *d,
                             pt_status *st)
{
    return accel_surf_build_in(s, a, NULL, NULL, weight, ctx, 1, d, st);
}

accel_surf *accel_surf_build_in(const scene *s, const accel *a, const vec3 *lo, const vec3 *hi,
                                accel_surf_weight_fn weight, void *ctx, int threads, diag *d, pt_status *st)
{
    (void)d;
    *st = PT_OK;
    accel_surf *as = calloc(1, sizeof *as);
    if (!as) {
        *st = PT_ERR_NOMEM;
        return NULL;
    }
    as->s = s;
    as->fn = weight;
    as->ctx = ctx;
    if (a || (lo && hi)) {
        if (lo && hi) {
            as->lo = *lo;
            as->hi = *hi;
        } else {
            accel_bounds(a, &as->lo, &as->hi);
        }
        as->have_bounds = as->lo.x < as->hi.x || as->lo.y < as->hi.y || as->lo.z < as->hi.z;
        /* a hair larger, so planes lying on the bounds are kept */
        double pad = 1e-6 * (1.0 + v3_len(v3_sub(as->hi, as->lo)));
        as->lo = v3_sub(as->lo, v3s(pad));
        as->hi = v3_add(as->hi, v3s(pad));
    }
    int ok = 1;
    for (int i = 0; i < s->nobjects && ok; i++) ok = collect(as, s->objects[i], &s->default_texture, 0u, 0);
    if (ok) ok = finish_crofton(as, threads);
    if (ok && as->npieces > 0) {
        as->cdf = malloc(sizeof(double) * (size_t)as->npieces);
        ok = as->cdf != NULL;
    }
    if (ok) {
        double acc = 0.0, area = 0.0;
        for (int i = 0; i < as->npieces; i++) {
            acc += as->pieces[i].pub.weight * as->pieces[i].pub.area;
            area += as->pieces[i].pub.area;
            as->cdf[i] = acc;
        }
        as->total_w = acc;
        as->total_area = area;
        ok = build_table(as);
    }
    if (!ok) {
        accel_surf_free(as);
        *st = PT_ERR_NOMEM;
        return NULL;
    }
    return as;
}

void accel_surf_free(accel_surf *as)
{
    if (!as) return;
    free(as->pieces);
    free(as->tris);
    for (int i = 0; i < as->nshapes; i++) geom_shape_release(&as->shapes[i].sh); /* the geom/ shapes' data */
    free(as->shapes);
    free(as->cdf);
    free(as->tab);
    free(as);
}

int accel_surf_count(const accel_surf *as) { return as ? as->npieces : 0; }
const accel_surf_piece *accel_surf_piece_at(const accel_surf *as, int i)
{
    return as && i >= 0 && i < as->npieces ? &as->pieces[i].pub : NULL;
}
double accel_surf_total_area(const accel_surf *as) { return as ? as->total_area : 0.0; }
double accel_surf_total_weight(const accel_surf *as) { return as ? as->total_w : 0.0; }

/* ------------------------------------------------------------ sampling */

static double next_u(rng *r, double fallback) { return r ? rng_f64(r) : fallback; }

static int pick_part(const double *cdf, int n, double u)
{
    for (int i = 0; i < n - 1; i++)
        if (u < cdf[i]) return i;
    return n - 1;
}

/* Reuse a uniform number after it has picked a part: rescale to [0,1). */
static double rescale(const double *cdf, int i, double u)
{
    double a = i > 0 ? cdf[i - 1] : 0.0, b = cdf[i];
    double v = b > a ? (u - a) / (b - a) : 0.5;
    return fmin(fmax(v, 0.0), 0x1.fffffffffffffp-1);
}

static void sample_shape(const shape_geo *g, double u1, double u2, rng *r, vec3 *p, vec3 *n, unsigned *part)
{
    const geom_shape *sh = &g->sh;
    const xform *x = &sh->x;
    vec3 po = v3s(0.0), no = v3(0, 0, 1);
    *part = 0;
    if (g->crofton) {
        geom_tess_sampler cs = g->cro;
        cs.sh = sh;
        if (!geom_tess_sample(&cs, u1, u2, r, p, n, part)) {
            *p = cs.c;
            *n = v3(0, 1, 0);
        }
        return;
    }
    switch (sh->kind) {
    case SHAPE_SPHERE:
        for (int t = 0; t < MAX_REJECT; t++) {
            no = sphere_normal(u1, u2);
            if (g->similar || !r || next_u(r, 0.0) * g->jmax <= jac(x, no)) break;
            u1 = rng_f64(r);
            u2 = rng_f64(r);
        }
        po = v3_madd(sh->g.sphere.c, no, sh->g.sphere.r);
        break;
    case SHAPE_BOX: {
        int f = pick_part(g->part_cdf, 6, u1);
        u1 = rescale(g->part_cdf, f, u1);
        int axis = f / 2;
        vec3 lo = sh->g.box.lo, hi = sh->g.box.hi;
        double c[3] = {0}, l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z};
        int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
        c[axis] = (f & 1) ? h[axis] : l[axis];
        c[a1] = l[a1] + u1 * (h[a1] - l[a1]);
        c[a2] = l[a2] + u2 * (h[a2] - l[a2]);
        po = v3(c[0], c[1], c[2]);
        double nn[3] = {0, 0, 0};
        nn[axis] = (f & 1) ? 1.0 : -1.0;
        no = v3(nn[0], nn[1], nn[2]);
        *part = (unsigned)f; /* GEOM_PART_BOX_NX.. order: -x, +x, -y, +y, -z, +z */
        break;
    }
    case SHAPE_CYLINDER:
    case SHAPE_CONE: {
        int part_i = pick_part(g->part_cdf, 3, u1);
        u1 = rescale(g->part_cdf, part_i, u1);
        double r0 = sh->g.cone.r0, r1 = sh->g.cone.r1, h = sh->g.cone.h;
        vec3 bu = sh->g.cone.u, bv = sh->g.cone.v, w = sh->g.cone.w;
        if (part_i == 0) {
            double phi = 0.0, t = 0.0;
            for (int k = 0; k < MAX_REJECT; k++) {
                /* t with density proportional to the radius r0 + (r1-r0) t/h */
                if (fabs(r1 - r0) < 1e-12 * fmax(r0, r1)) {
                    t = u1 * h;
                } else {
                    double rr = sqrt(r0 * r0 + u1 * (r1 * r1 - r0 * r0));
                    t = (rr - r0) / (r1 - r0) * h;
                }
                phi = 2.0 * M_PI * u2;
                no = cone_side_normal(sh, phi);
                if (g->similar || !r || next_u(r, 0.0) * g->jmax <= jac(x, no)) break;
                u1 = rng_f64(r);
                u2 = rng_f64(r);
            }
            double rad = r0 + (r1 - r0) * t / h;
            po = v3_add(v3_madd(sh->g.cone.base, w, t),
                        v3_add(v3_scale(bu, rad * cos(phi)), v3_scale(bv, rad * sin(phi))));
            *part = GEOM_PART_CONE_SIDE;
        } else {
            double rad = part_i == 1 ? r0 : r1;
            double rho = rad * sqrt(u1), phi = 2.0 * M_PI * u2;
            vec3 c = part_i == 1 ? sh->g.cone.base : v3_madd(sh->g.cone.base, w, h);
            po = v3_add(c, v3_add(v3_scale(bu, rho * cos(phi)), v3_scale(bv, rho * sin(phi))));
            no = part_i == 1 ? v3_neg(w) : w;
            *part = part_i == 1 ? GEOM_PART_CONE_BASE : GEOM_PART_CONE_CAP;
        }
        break;
    }
    case SHAPE_DISC: {
        double r2 = sh->g.disc.r2, h2 = sh->g.disc.h2;
        double rho = sqrt(h2 + u1 * (r2 - h2)), phi = 2.0 * M_PI * u2;
        vec3 t, b;
        v3_basis(sh->g.disc.n, &t, &b);
        po = v3_add(sh->g.disc.c, v3_add(v3_scale(t, rho * cos(phi)), v3_scale(b, rho * sin(phi))));
        no = sh->g.disc.n;
        break;
    }
    case SHAPE_TORUS: {
        double R = sh->g.torus.R, rr = sh->g.torus.r, u = 0.0, v = 0.0;
        for (int k = 0; k < MAX_REJECT; k++) {
            u = 2.0 * M_PI * u1;
            v = 2.0 * M_PI * u2;
            no = torus_normal(u, v);
            double acc = fabs(R + rr * cos(v)) / (R + rr);
            if (!g->similar) acc *= jac(x, no) / g->jmax;
            if (!r || next_u(r, 0.0) <= acc) break;
            u1 = rng_f64(r);
            u2 = rng_f64(r);
        }
        po = v3((R + rr * cos(v)) * cos(u), rr * sin(v), (R + rr * cos(v)) * sin(u));
        break;
    }
    case SHAPE_PLANE: {
        int nt = g->npoly - 2;
        int k = pick_part(g->tri_cdf, nt, u1);
        u1 = rescale(g->tri_cdf, k, u1);
        vec3 a = g->poly[0], b = g->poly[k + 1], c = g->poly[k + 2];
        double su = sqrt(u1);
        *p = v3_add(v3_add(v3_scale(a, 1.0 - su), v3_scale(b, su * (1.0 - u2))), v3_scale(c, su * u2));
        *n = v3_norm(xform_normal(x, sh->g.plane.n));
        return;
    }
    case SHAPE_LATHE: case SHAPE_SOR: case SHAPE_PRISM: case SHAPE_TEXT:
        geom_sweep_sample(sh, u1, u2, r, &po, &no, part);
        break;
    default:
        break;
    }
    *p = xform_point(x, po);
    *n = v3_norm(xform_normal(x, no));
}

int accel_surf_sample_piece(const accel_surf *as, int piece, double u1, double u2, rng *r, accel_surf_sample *out)
{
    if (!as || piece < 0 || piece >= as->npieces || !(as->total_w > 0.0)) return 0;
    const piece_rec *pr = &as->pieces[piece];
    out->obj = pr->pub.obj;
    out->texture = pr->pub.texture;
    out->flags = pr->pub.flags;
    out->piece = piece;
    out->pdf_area = pr->pub.weight / as->total_w;
    assert(u1 >= 0.0 && u1 <= 1.0 && u2 >= 0.0 && u2 <= 1.0);
    assert(out->pdf_area > 0.0 && isfinite(out->pdf_area));
    if (!pr->is_shape) {
        assert(pr->idx >= 0 && pr->idx < as->ntris);
        const tri_geo *t = &as->tris[pr->idx];
        double su = sqrt(u1);
        double b1 = su * (1.0 - u2), b2 = su * u2;
        out->p = v3_add(t->v0, v3_add(v3_scale(t->e1, b1), v3_scale(t->e2, b2)));
        out->n = t->n;
        out->prim = pr->pub.prim == ACCEL_SURF_ANY ? 0u : pr->pub.prim;
        return 1;
    }
    assert(pr->idx >= 0 && pr->idx < as->nshapes);
    sample_shape(&as->shapes[pr->idx], u1, u2, r, &out->p, &out->n, &out->prim);
    return 1;
}

int accel_surf_sample_point(const accel_surf *as, double u0, double u1, double u2, rng *r, accel_surf_sample *out)
{
    if (!as || as->npieces == 0 || !(as->total_w > 0.0)) return 0;
    double target = u0 * as->total_w;
    int lo = 0, hi = as->npieces - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (target < as->cdf[mid]) hi = mid;
        else lo = mid + 1;
    }
    assert(lo >= 0 && lo < as->npieces);
    return accel_surf_sample_piece(as, lo, u1, u2, r, out);
}

int accel_surf_find(const accel_surf *as, const scene_object *obj, unsigned prim)
{
    if (!as || !as->tab || !obj) return -1;
    unsigned kp = key_prim(obj, prim);
    size_t h = (size_t)hash_key(obj, kp) & (as->tabcap - 1);
    while (as->tab[h].obj) {
        if (as->tab[h].obj == obj && as->tab[h].prim == kp) return as->tab[h].piece;
        h = (h + 1) & (as->tabcap - 1);
    }
    return -1;
}

double accel_surf_pdf(const accel_surf *as, const accel_hit *h)
{
    int i = accel_surf_find(as, h->obj, h->prim);
    if (i < 0) return 0.0;
    assert(i < as->npieces);
    const piece_rec *pr = &as->pieces[i];
    if (pr->is_shape && (as->shapes[pr->idx].sh.kind == SHAPE_PLANE || as->shapes[pr->idx].sh.infinite)) {
        const shape_geo *g = &as->shapes[pr->idx];
        vec3 p = h->p;
        if (p.x < g->clip_lo.x || p.y < g->clip_lo.y || p.z < g->clip_lo.z || p.x > g->clip_hi.x ||
            p.y > g->clip_hi.y || p.z > g->clip_hi.z)
            return 0.0;
    }
    return pr->pub.weight / as->total_w;
}
