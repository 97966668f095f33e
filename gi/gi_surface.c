/* gi_surface.c - surface patches for particle GI (see gi_surface.h): patches
 * from the scene's objects, sampling and access; CSG members, grids of
 * implicit shapes and the layout are in gi_surface_csg.c, gi_surface_mesh.c
 * and gi_surface_layout.c (gi_surface_internal.h). */
#include "gi_surface_internal.h"
#include "grow.h"
#include <math.h>
#include "geom_shape.h"
#include "geom_hfield.h"
#include "accel_surface.h"
#include "geom_sweep.h"
#include "geom_tess.h"
#include "camera.h"
#include "rng.h"
#include <limits.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------ helpers */

int gi_surface_add_patch(gi_surface *g, const patch *p)
{
    if (!grow_array_int((void **)&g->p, &g->capp, g->np + 1, sizeof *g->p)) return -1;
    g->p[g->np] = *p;
    return g->np++;
}

int gi_surface_add_obj(gi_surface *g, const scene_object *o)
{
    if (!grow_array_int((void **)&g->o, &g->capo, g->no + 1, sizeof *g->o)) return -1;
    g->o[g->no].obj = o;
    g->o[g->no].first = g->np;
    g->o[g->no].count = 0;
    g->o[g->no].kind = o->kind;
    return g->no++;
}

static int build_hash(gi_surface *g)
{
    int cap = 16;
    while (cap < 2 * g->no + 2) cap *= 2;
    g->hash = malloc((size_t)cap * sizeof *g->hash);
    if (!g->hash) return 0;
    g->hcap = cap;
    for (int i = 0; i < cap; i++) g->hash[i] = -1;
    for (int i = 0; i < g->no; i++) {
        unsigned h = (unsigned)(pt_mix64((uint64_t)(uintptr_t)g->o[i].obj) & (uint64_t)(cap - 1));
        while (g->hash[h] >= 0) h = (h + 1) & (unsigned)(cap - 1);
        g->hash[h] = i;
    }
    return 1;
}

const obj_rec *gi_surface_find_obj(const gi_surface *g, const scene_object *o)
{
    if (!g->hash) return NULL;
    unsigned h = (unsigned)(pt_mix64((uint64_t)(uintptr_t)o) & (uint64_t)(g->hcap - 1));
    while (g->hash[h] >= 0) {
        if (g->o[g->hash[h]].obj == o) return &g->o[g->hash[h]];
        h = (h + 1) & (unsigned)(g->hcap - 1);
    }
    return NULL;
}

static double det3(const xform *x)
{
    const double (*m)[4] = x->m;
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}



/* A CSG member's sides: both exist, particles go on the one facing out of
 * the result (cur_mask); triangles have no inside and keep both. */
static void member_sides(const gi_surface *g, patch *p)
{
    p->cnode = g->cur_node;
    p->mask = 3;
    if (g->cur_node < 0 || p->nsides == 0) return;
    shape_kind k = g->o[p->obj].kind;
    p->nsides = 2;
    if (k != SHAPE_TRIANGLE && k != SHAPE_SMOOTH_TRIANGLE && k != SHAPE_MESH) p->mask = g->cur_mask;
}

/* Add a world triangle patch; skips degenerate ones. */
static int add_tri(gi_surface *g, int obj, vec3 a, vec3 b, vec3 c, vec3 front, int nsides, int probe,
                   const scene_texture *tex)
{
    patch p = {.kind = PATCH_TRI, .v0 = a, .e1 = v3_sub(b, a), .e2 = v3_sub(c, a)};
    vec3 cr = v3_cross(p.e1, p.e2);
    double l = v3_len(cr);
    if (!(l > 0.0) || !isfinite(l)) return 0;
    p.area = 0.5 * l;
    p.nrm = v3_scale(cr, 1.0 / l);
    if (v3_dot(front, front) > 0.0 && v3_dot(p.nrm, front) < 0.0) p.nrm = v3_neg(p.nrm);
    p.lu = fmax(v3_len(p.e1), fmax(v3_len(p.e2), v3_len(v3_sub(c, b))));
    p.nsides = (unsigned char)nsides;
    p.probe = (unsigned char)probe;
    p.obj = obj;
    p.tex = tex;
    member_sides(g, &p);
    gi_surface_set_resolution(g, &p);
    if (gi_surface_add_patch(g, &p) < 0) return -1;
    g->o[obj].count++;
    return 1;
}

/* Point and front (outward) normal of a grid patch at (u, v); world. */
void gi_surface_grid_eval(const gi_surface *g, const patch *p, double u, double v, vec3 *pos, vec3 *nrm)
{
    const xform *x = &g->o[p->obj].obj->transform;
    double ph = 2.0 * M_PI * u;
    vec3 po, no;
    if (p->kind == PATCH_SPHERE) {
        double y = p->r0 * (2.0 * v - 1.0);
        double rr = sqrt(fmax(0.0, p->r0 * p->r0 - y * y));
        vec3 d = v3(rr * cos(ph), y, rr * sin(ph));
        po = v3_add(p->c, d);
        no = v3_scale(d, 1.0 / p->r0);
    } else {
        double rr = sqrt(p->r0 * p->r0 + v * (p->r1 * p->r1 - p->r0 * p->r0));
        po = v3_add(p->c, v3_add(v3_scale(p->ga, rr * cos(ph)), v3_scale(p->gb, rr * sin(ph))));
        no = p->gn;
    }
    if (pos) *pos = xform_point(x, po);
    if (nrm) *nrm = v3_norm(xform_normal(x, no));
}

/* World area density of a grid at (u, v), relative to object space. */
static double grid_jac(const gi_surface *g, const patch *p, double u, double v)
{
    const xform *x = &g->o[p->obj].obj->transform;
    vec3 no;
    if (p->kind == PATCH_SPHERE) {
        double y = p->r0 * (2.0 * v - 1.0);
        double rr = sqrt(fmax(0.0, p->r0 * p->r0 - y * y));
        double ph = 2.0 * M_PI * u;
        no = v3(rr * cos(ph) / p->r0, y / p->r0, rr * sin(ph) / p->r0);
    } else {
        no = p->gn;
    }
    return p->jobj * p->detm * v3_len(xform_normal(x, no));
}

/* Cells for a length at the tessellation bound tess: ceil(len / tess)
 * within [lo, hi]. */
int gi_surface_grid_count(double len, double tess, int lo, int hi)
{
    double c = ceil(len / tess);
    return c < lo ? lo : (c > hi ? hi : (int)c);
}

/* Sub-tessellation / grid resolution from the tessellation bound. */
void gi_surface_set_resolution(const gi_surface *g, patch *p)
{
    if (p->kind == PATCH_PIECE) return; /* rp_count: its grid's vertices (gi_surface_build_meshes) */
    if (p->kind == PATCH_TRI) {
        if (p->nsides == 0) return;
        p->k = gi_surface_grid_count(p->lu, g->tess, 1, 2048);
        p->rp_count = (long)(p->k + 1) * (p->k + 2) / 2;
        return;
    }
    p->nu = gi_surface_grid_count(p->lu, g->tess, 3, 4096);
    p->nv = gi_surface_grid_count(p->lv, g->tess, 1, 4096);
    p->rp_count = (long)(p->nu + 1) * (p->nv + 1);
}

/* Grid area and longest grid lines, from world lengths measured along the grid. */
static int finish_grid(gi_surface *g, int obj, patch *p)
{
    p->detm = fabs(det3(&g->o[obj].obj->transform));
    if (!(p->detm > 0.0) || !isfinite(p->detm)) return 0;
    const int S = 48;
    double area = 0.0, jmax = 0.0, jmin = INFINITY;
    for (int j = 0; j < S; j++) {
        for (int i = 0; i < S; i++) {
            double jac = grid_jac(g, p, (i + 0.5) / S, (j + 0.5) / S);
            area += jac;
            jmax = fmax(jmax, jac);
            jmin = fmin(jmin, jac);
        }
    }
    p->area = area / (S * S);
    p->jmax = jmax;
    p->jmin = jmin;
    if (!(p->area > 0.0) || !isfinite(p->area)) return 0;
    /* longest u line and v line */
    double lu = 0.0, lv = 0.0;
    for (int k = 0; k <= 4; k++) {
        double fixed = (k + 0.5) / 5.0, su = 0.0, sv = 0.0;
        vec3 a, b;
        gi_surface_grid_eval(g, p, 0.0, fixed, &a, NULL);
        for (int i = 1; i <= S; i++) {
            gi_surface_grid_eval(g, p, (double)i / S, fixed, &b, NULL);
            su += v3_len(v3_sub(b, a));
            a = b;
        }
        gi_surface_grid_eval(g, p, fixed, 0.0, &a, NULL);
        for (int i = 1; i <= S; i++) {
            gi_surface_grid_eval(g, p, fixed, (double)i / S, &b, NULL);
            sv += v3_len(v3_sub(b, a));
            a = b;
        }
        lu = fmax(lu, su);
        lv = fmax(lv, sv);
    }
    p->lu = lu;
    p->lv = lv;
    gi_surface_set_resolution(g, p);
    return 1;
}

int gi_surface_inside_solid(const scene_object *o, vec3 q)
{
    vec3 qo = xform_inv_point(&o->transform, q);
    if (o->kind == SHAPE_SPHERE) return v3_len(v3_sub(qo, o->u.sphere.centre)) < fabs(o->u.sphere.radius);
    if (o->kind == SHAPE_BOX) {
        vec3 a = v3_min(o->u.box.c1, o->u.box.c2), b = v3_max(o->u.box.c1, o->u.box.c2);
        return qo.x > a.x && qo.x < b.x && qo.y > a.y && qo.y < b.y && qo.z > a.z && qo.z < b.z;
    }
    return 0;
}

static int solid_sides(const gi_surface *g, const scene_object *o)
{
    if (o->flags & OBJ_INVERSE) return 2;
    const scene *s = g->sc;
    if (s->camera_set && gi_surface_inside_solid(o, s->camera.location)) return 2;
    for (int i = 0; i < s->nlights; i++)
        if (gi_surface_inside_solid(o, s->lights[i].position)) return 2;
    return 1;
}

/* Sutherland-Hodgman clip of a convex polygon against n.p <= d. */
static int clip_poly(vec3 *in, int n, vec3 *out, vec3 pn, double d)
{
    int m = 0;
    for (int i = 0; i < n; i++) {
        vec3 a = in[i], b = in[(i + 1) % n];
        double da = v3_dot(pn, a) - d, db = v3_dot(pn, b) - d;
        if (da <= 0.0) out[m++] = a;
        if ((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) {
            double t = da / (da - db);
            out[m++] = v3_add(a, v3_scale(v3_sub(b, a), t));
        }
    }
    return m;
}

static pt_status add_plane(gi_surface *g, int obj, const scene_object *o, int probe, const scene_texture *tex)
{
    vec3 n = o->u.plane.normal;
    double l2 = v3_len2(n);
    if (!(l2 > 0.0)) return PT_OK;
    vec3 p0 = xform_point(&o->transform, v3_scale(n, o->u.plane.offset / l2));
    vec3 nw = v3_norm(xform_normal(&o->transform, n));
    if (!v3_finite(p0) || !v3_finite(nw)) return PT_OK;
    vec3 c = v3_scale(v3_add(g->lo, g->hi), 0.5);
    double half = v3_len(v3_sub(g->hi, g->lo));
    vec3 q = v3_sub(c, v3_scale(nw, v3_dot(v3_sub(c, p0), nw)));
    vec3 t, b;
    v3_basis(nw, &t, &b);
    vec3 poly[16], tmp[16];
    poly[0] = v3_add(q, v3_add(v3_scale(t, -half), v3_scale(b, -half)));
    poly[1] = v3_add(q, v3_add(v3_scale(t, half), v3_scale(b, -half)));
    poly[2] = v3_add(q, v3_add(v3_scale(t, half), v3_scale(b, half)));
    poly[3] = v3_add(q, v3_add(v3_scale(t, -half), v3_scale(b, half)));
    int m = 4;
    for (int ax = 0; ax < 3 && m > 0; ax++) {
        vec3 e = v3(ax == 0, ax == 1, ax == 2);
        m = clip_poly(poly, m, tmp, e, v3_idx(g->hi, ax));
        m = clip_poly(tmp, m, poly, v3_neg(e), -v3_idx(g->lo, ax));
    }
    for (int i = 1; i + 1 < m; i++)
        if (add_tri(g, obj, poly[0], poly[i], poly[i + 1], nw, 2, probe, tex) < 0) return PT_ERR_NOMEM;
    return PT_OK;
}

static pt_status add_box(gi_surface *g, int obj, const scene_object *o, int probe, const scene_texture *tex)
{
    vec3 a = v3_min(o->u.box.c1, o->u.box.c2), b = v3_max(o->u.box.c1, o->u.box.c2);
    int sides = solid_sides(g, o);
    const xform *x = &o->transform;
    for (int ax = 0; ax < 3; ax++) {
        int u = (ax + 1) % 3, v = (ax + 2) % 3;
        for (int hiside = 0; hiside < 2; hiside++) {
            double val = v3_idx(hiside ? b : a, ax);
            vec3 corner[4];
            for (int k = 0; k < 4; k++) {
                double cu = (k == 1 || k == 2) ? v3_idx(b, u) : v3_idx(a, u);
                double cv = (k >= 2) ? v3_idx(b, v) : v3_idx(a, v);
                double w[3];
                w[ax] = val;
                w[u] = cu;
                w[v] = cv;
                corner[k] = xform_point(x, v3(w[0], w[1], w[2]));
            }
            vec3 no = v3(ax == 0 ? (hiside ? 1 : -1) : 0, ax == 1 ? (hiside ? 1 : -1) : 0, ax == 2 ? (hiside ? 1 : -1) : 0);
            vec3 nw = v3_norm(xform_normal(x, no));
            if (add_tri(g, obj, corner[0], corner[1], corner[2], nw, sides, probe, tex) < 0) return PT_ERR_NOMEM;
            if (add_tri(g, obj, corner[0], corner[2], corner[3], nw, sides, probe, tex) < 0) return PT_ERR_NOMEM;
        }
    }
    return PT_OK;
}

/* The accel_surface pieces of leaf o: one for an analytic or implicit
 * shape, one per triangle for polygons and height fields (added
 * consecutively by accel_surface). */
static void piece_range(const gi_surface *g, const scene_object *o, int *first, int *count)
{
    *first = -1;
    *count = 0;
    if (!g->as) return;
    int i = accel_surf_find(g->as, o, ACCEL_SURF_ANY);
    if (i < 0) i = accel_surf_find(g->as, o, 0u); /* height fields are keyed by triangle */
    if (i < 0) return;
    int n = accel_surf_count(g->as), lo = i, hi = i;
    while (lo > 0 && accel_surf_piece_at(g->as, lo - 1)->obj == o) lo--;
    while (hi + 1 < n && accel_surf_piece_at(g->as, hi + 1)->obj == o) hi++;
    *first = lo;
    *count = hi - lo + 1;
}

/* Sides of a PIECE patch: sheets (polygons, height fields, lathe and sor,
 * whose ends may be open, unbounded quadric/poly clipped like planes) and
 * open or inverse objects get both; closed solids their outside, plus the
 * inside when the camera or a light is in them (geom_shape_inside). */
static int piece_sides(const gi_surface *g, const scene_object *o)
{
    if (o->flags & (OBJ_OPEN | OBJ_INVERSE)) return 2;
    switch (o->kind) {
    case SHAPE_CYLINDER: case SHAPE_CONE: case SHAPE_TORUS: return 1;
    case SHAPE_POLYGON: case SHAPE_HEIGHT_FIELD: case SHAPE_LATHE: case SHAPE_SOR: return 2;
    default: break;
    }
    geom_shape sh;
    if (geom_shape_init(&sh, o) != 0) return 1;
    int sides = sh.infinite ? 2 : 1;
    const scene *s = g->sc;
    if (sides == 1 && s->camera_set && geom_shape_inside(&sh, s->camera.location)) sides = 2;
    for (int i = 0; sides == 1 && i < s->nlights; i++)
        if (geom_shape_inside(&sh, s->lights[i].position)) sides = 2;
    geom_shape_release(&sh);
    return sides;
}

/* Shapes whose radiance particles are the vertices of their grid
 * (geom_shape_grid: marching tetrahedra, vertices on the exact surface;
 * superellipsoids their own parametric grid). */
int gi_surface_has_grid(shape_kind k)
{
    switch (k) {
    case SHAPE_QUADRIC: case SHAPE_POLY: case SHAPE_BLOB: case SHAPE_ISOSURFACE: case SHAPE_JULIA:
    case SHAPE_SUPERELLIPSOID: case SHAPE_OVUS:
    case SHAPE_CYLINDER: case SHAPE_CONE: case SHAPE_TORUS: /* analytic_grid */
    case SHAPE_POLYGON: case SHAPE_HEIGHT_FIELD: /* their triangles, split (split_grid) */
    case SHAPE_LATHE: case SHAPE_SOR: case SHAPE_PRISM: case SHAPE_TEXT: /* geom_sweep_grid_cell */
        return 1;
    default: return 0;
    }
}

void gi_surface_free_patch(patch *p)
{
    if (p->sh && p->own_sh == 1) geom_shape_release(p->sh);
    if (p->own_sh) free(p->sh);
    p->sh = NULL;
    free(p->ks);
    p->ks = NULL;
}


pt_status gi_surface_add_leaf(gi_surface *g, const scene_object *o, const scene_texture *tex, int probe)
{
    int two = 2;
    switch (o->kind) {
    case SHAPE_TRIANGLE:
    case SHAPE_SMOOTH_TRIANGLE:
    case SHAPE_MESH:
    case SHAPE_PLANE:
    case SHAPE_BOX:
    case SHAPE_SPHERE:
    case SHAPE_DISC: break;
    default: {
        /* every other shape accel_surface samples (accel_surface.h):
         * cylinders, cones, tori; polygons and height fields (their
         * triangles); lathe, sor, prism, text; and the implicit shapes
         * (quadric, poly, blob, isosurface, julia_fractal, ovus,
         * superellipsoid) by Crofton lines (geom_tess.h). Area particles;
         * radiance particles on the implicit shapes' grids (build_mesh);
         * the others are estimated at the hit. CSG members: their own
         * Crofton sampler keeping only the result's surface (gi_surface_csg_keep). */
        if (g->cur_node >= 0) return gi_surface_csg_add_piece(g, o, tex);
        int first = -1, count = 0;
        piece_range(g, o, &first, &count);
        double area = 0.0;
        for (int i = 0; i < count; i++) area += accel_surf_piece_at(g->as, first + i)->area;
        if (!(area > 0.0) || !isfinite(area)) break;
        long c0 = 0;
        if (count > 1) {
            /* cumulative piece areas: gi_surface_sample picks a piece by area */
            c0 = g->ncdf;
            if (g->ncdf + count > g->capcdf) {
                long nc = g->capcdf ? g->capcdf : 1024;
                while (nc < g->ncdf + count) nc *= 2;
                double *nd = realloc(g->cdf, (size_t)nc * sizeof *nd);
                if (!nd) return PT_ERR_NOMEM;
                g->cdf = nd;
                g->capcdf = nc;
            }
            double acc = 0.0;
            for (int i = 0; i < count; i++) {
                acc += accel_surf_piece_at(g->as, first + i)->area;
                g->cdf[c0 + i] = acc;
            }
            g->ncdf += count;
        }
        int obj = gi_surface_add_obj(g, o);
        if (obj < 0) return PT_ERR_NOMEM;
        patch p = {.kind = PATCH_PIECE, .obj = obj, .piece = first, .npieces = count, .cdf0 = c0, .area = area,
                   .tex = tex, .nsides = (unsigned char)piece_sides(g, o), .mask = 3, .cnode = -1};
        if (gi_surface_has_grid(o->kind)) {
            p.sh = malloc(sizeof *p.sh);
            if (!p.sh) return PT_ERR_NOMEM;
            if (geom_shape_init(p.sh, o) != 0) {
                free(p.sh);
                p.sh = NULL;
            } else {
                p.own_sh = 1;
                if (p.sh->infinite) geom_shape_clip_plane(p.sh, g->lo, g->hi);
            }
        }
        if (gi_surface_add_patch(g, &p) < 0) {
            gi_surface_free_patch(&p);
            return PT_ERR_NOMEM;
        }
        g->o[obj].count++;
        return PT_OK;
    }
    }
    if (o->kind != SHAPE_TRIANGLE && o->kind != SHAPE_SMOOTH_TRIANGLE && o->kind != SHAPE_MESH &&
        o->kind != SHAPE_PLANE && o->kind != SHAPE_BOX && o->kind != SHAPE_SPHERE && o->kind != SHAPE_DISC) {
        g->skipped++;
        diag_warn_once(g->d, o->loc, "particle GI: no particles on %s objects (they get no indirect light)",
                       o->name ? o->name : "these");
        return PT_OK;
    }
    int obj = gi_surface_add_obj(g, o);
    if (obj < 0) return PT_ERR_NOMEM;
    const xform *x = &o->transform;
    if (o->kind == SHAPE_TRIANGLE || o->kind == SHAPE_SMOOTH_TRIANGLE) {
        vec3 v[3];
        for (int k = 0; k < 3; k++) v[k] = xform_point(x, o->u.triangle.v[k]);
        if (add_tri(g, obj, v[0], v[1], v[2], v3(0, 0, 0), two, probe, tex) < 0) return PT_ERR_NOMEM;
    } else if (o->kind == SHAPE_MESH) {
        const scene_mesh *m = o->u.mesh.mesh;
        for (int t = 0; t < m->ntris; t++) {
            const int *tv = m->tris[t];
            int ok = tv[0] >= 0 && tv[0] < m->nverts && tv[1] >= 0 && tv[1] < m->nverts && tv[2] >= 0 &&
                     tv[2] < m->nverts;
            const scene_texture *tt = scene_mesh_tri_texture(o, t);
            if (!tt) tt = tex;
            vec3 v[3];
            for (int k = 0; k < 3; k++) {
                int vi = ok ? tv[k] : 0;
                v[k] = xform_point(x, v3(m->verts[vi][0], m->verts[vi][1], m->verts[vi][2]));
            }
            /* keep patch index == triangle index: degenerate triangles get an empty patch */
            int r = ok ? add_tri(g, obj, v[0], v[1], v[2], v3(0, 0, 0), two, probe, tt) : 0;
            if (r < 0) return PT_ERR_NOMEM;
            if (r == 0) {
                patch p = {.kind = PATCH_TRI, .obj = obj, .k = 1, .nsides = 0, .tex = tt, .cnode = -1, .mask = 3};
                if (gi_surface_add_patch(g, &p) < 0) return PT_ERR_NOMEM;
                g->o[obj].count++;
            }
        }
    } else if (o->kind == SHAPE_PLANE) {
        pt_status st = add_plane(g, obj, o, probe, tex);
        if (st != PT_OK) return st;
    } else if (o->kind == SHAPE_BOX) {
        pt_status st = add_box(g, obj, o, probe, tex);
        if (st != PT_OK) return st;
    } else {
        patch p = {.obj = obj, .probe = (unsigned char)probe, .tex = tex};
        if (o->kind == SHAPE_SPHERE) {
            p.kind = PATCH_SPHERE;
            p.c = o->u.sphere.centre;
            p.r0 = fabs(o->u.sphere.radius);
            p.jobj = 4.0 * M_PI * p.r0 * p.r0;
            p.nsides = (unsigned char)solid_sides(g, o);
            if (!(p.r0 > 0.0)) return PT_OK;
        } else {
            p.kind = PATCH_DISC;
            p.c = o->u.disc.centre;
            p.gn = v3_norm(o->u.disc.normal);
            if (!(v3_len2(p.gn) > 0.0)) return PT_OK;
            v3_basis(p.gn, &p.ga, &p.gb);
            p.r0 = fabs(o->u.disc.hole_radius);
            p.r1 = fabs(o->u.disc.radius);
            if (!(p.r1 > p.r0)) return PT_OK;
            p.jobj = M_PI * (p.r1 * p.r1 - p.r0 * p.r0);
            p.nsides = 2;
        }
        if (!finish_grid(g, obj, &p)) return PT_OK;
        member_sides(g, &p);
        p.piece = probe || !g->as ? -1 : accel_surf_find(g->as, o, ACCEL_SURF_ANY);
        if (gi_surface_add_patch(g, &p) < 0) return PT_ERR_NOMEM;
        g->o[obj].count++;
    }
    return PT_OK;
}

static pt_status walk(gi_surface *g, const scene_object *o, const scene_texture *tex, int probe)
{
    if (o->texture) tex = o->texture;
    if (o->flags & OBJ_NO_RADIOSITY) return PT_OK;
    pt_status cst;
    if (o->clip && gi_surface_csg_walk(g, o, tex, &cst)) return cst; /* clipped_by: a CSG tree */
    switch (o->kind) {
    case SHAPE_UNION:
    case SHAPE_MERGE:
    case SHAPE_INTERSECTION:
    case SHAPE_DIFFERENCE: {
        pt_status st;
        if (gi_surface_csg_walk(g, o, tex, &st)) return st;
        for (int i = 0; i < o->u.csg.nkids; i++) {
            st = walk(g, o->u.csg.kids[i], tex, probe);
            if (st != PT_OK) return st;
        }
        return PT_OK;
    }
    default: return gi_surface_add_leaf(g, o, tex, probe);
    }
}

/* What the camera sees bounds what gets particles: a 64 x 48 grid of
 * camera rays; the box of the camera's position and the hits on finite
 * objects (not planes, quadrics or polys; inside the finite bounds before
 * they grew), grown by its diagonal on every side (a room seen from near
 * one wall keeps the wall behind the camera), and [lo, hi] becomes its
 * intersection with [lo, hi]. Objects far from everything the camera sees (a scene's
 * stray blocks a kilometre away, the horizon of an infinite plane) then
 * get no particles: a link or a pixel that reaches them takes the far
 * field (gi_links.c, gi_particle_indirect). Rooms keep their walls behind
 * the camera: the camera's position is in the box. No camera, or no
 * finite hit: [lo, hi] stays. */
#define VIEW_W 64
#define VIEW_H 48
#define VIEW_FAR 10.0
static int cmp_double(const void *x, const void *y)
{
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

/* The camera probe: a VIEW_W x VIEW_H grid of camera rays. Each ray's first
 * hit object goes to seen[] (view_coverage reads it); the finite hits bound
 * the clip box. */
static void view_clip(const scene *s, const accel *a, vec3 *lo, vec3 *hi, const scene_object **seen)
{
    if (!s->camera_set) return;
    vec3 flo, fhi;
    accel_bounds(a, &flo, &fhi);
    int bounded = flo.x <= fhi.x;
    vec3 t = v3s(1e-6 * (1.0 + v3_len(v3_sub(fhi, flo))));
    flo = v3_sub(flo, t);
    fhi = v3_add(fhi, t);
    vec3 *hp = malloc((size_t)VIEW_W * VIEW_H * sizeof *hp);
    double *dist = malloc((size_t)VIEW_W * VIEW_H * sizeof *dist), *sorted = malloc((size_t)VIEW_W * VIEW_H * sizeof *sorted);
    if (!hp || !dist || !sorted) {
        free(hp);
        free(dist);
        free(sorted);
        return;
    }
    int n = 0;
    for (int y = 0; y < VIEW_H; y++)
        for (int x = 0; x < VIEW_W; x++) {
            vec3 org, dir;
            if (!camera_ray(&s->camera, x + 0.5, y + 0.5, VIEW_W, VIEW_H, 0.5, 0.5, &org, &dir)) continue;
            accel_hit h;
            if (!accel_intersect(a, org, dir, 0.0, INFINITY, &h)) continue;
            if (seen) seen[y * VIEW_W + x] = h.obj;
            if (!bounded) continue;
            vec3 p = h.p;
            /* planes and the shapes that may be unbounded stand for the far
             * ground and the horizon, not for what the view is about */
            if (!h.obj || h.obj->kind == SHAPE_PLANE || h.obj->kind == SHAPE_QUADRIC || h.obj->kind == SHAPE_POLY)
                continue;
            if (!v3_finite(p) || p.x < flo.x || p.y < flo.y || p.z < flo.z || p.x > fhi.x || p.y > fhi.y ||
                p.z > fhi.z)
                continue;
            hp[n] = p;
            dist[n] = sorted[n] = v3_len(v3_sub(p, s->camera.location));
            n++;
        }
    /* A finite object far beyond the view's subject (a sky dome of radius
     * 1e5, hills at the horizon) is the far field too: hits farther than
     * VIEW_FAR times the nearer third of the hits' distance are left out */
    double limit = INFINITY;
    if (n > 0) {
        qsort(sorted, (size_t)n, sizeof *sorted, cmp_double);
        limit = VIEW_FAR * sorted[n / 3];
    }
    vec3 vlo = s->camera.location, vhi = s->camera.location;
    int any = 0;
    for (int i = 0; i < n; i++)
        if (dist[i] <= limit) {
            vlo = v3_min(vlo, hp[i]);
            vhi = v3_max(vhi, hp[i]);
            any = 1;
        }
    free(hp);
    free(dist);
    free(sorted);
    if (!any || !v3_finite(vlo) || !v3_finite(vhi)) return;
    vec3 m = v3s(v3_len(v3_sub(vhi, vlo)));
    vlo = v3_sub(vlo, m);
    vhi = v3_add(vhi, m);
    vec3 nlo = v3_max(*lo, vlo), nhi = v3_min(*hi, vhi);
    if (nlo.x <= nhi.x && nlo.y <= nhi.y && nlo.z <= nhi.z) {
        *lo = nlo;
        *hi = nhi;
    }
}

/* What the camera sees of each object: each of view_clip's probe rays
 * (seen) credited to its first hit's object record. Without a camera, or
 * without memory, every share stays 0 (particles then go by area alone). */
static void view_coverage(gi_surface *g, const scene_object *const *seen)
{
    if (!g->sc->camera_set || g->no <= 0 || !seen) return;
    g->view = calloc((size_t)g->no, sizeof *g->view);
    if (!g->view) return;
    const double w = 1.0 / ((double)VIEW_W * VIEW_H);
    for (int i = 0; i < VIEW_W * VIEW_H; i++) {
        const obj_rec *r = seen[i] ? gi_surface_find_obj(g, seen[i]) : NULL;
        if (r) g->view[r - g->o] += (float)w;
    }
}

int gi_surface_nobjs(const gi_surface *g) { return g->no; }
int gi_surface_obj_index(const gi_surface *g, int i) { return g->p[i].obj; }
double gi_surface_view_share(const gi_surface *g, int k) { return g->view && k >= 0 && k < g->no ? g->view[k] : 0.0; }

gi_surface *gi_surface_build(const scene *s, const accel *a, double tess, int threads, diag *d, pt_status *status)
{
    pt_status dummy;
    if (!status) status = &dummy;
    gi_surface *g = calloc(1, sizeof *g);
    if (!g) { *status = PT_ERR_NOMEM; return NULL; }
    g->sc = s;
    g->d = d;
    g->cur_node = -1;
    g->tess = tess > 0.0 ? tess : 1.0;
    accel_bounds(a, &g->lo, &g->hi);
    if (!(g->lo.x <= g->hi.x) || v3_len(v3_sub(g->hi, g->lo)) <= 0.0) {
        /* only planes: bound them by the camera and lights */
        vec3 lo = v3s(INFINITY), hi = v3s(-INFINITY);
        if (s->camera_set) { lo = v3_min(lo, s->camera.location); hi = v3_max(hi, s->camera.location); }
        for (int i = 0; i < s->nlights; i++) {
            lo = v3_min(lo, s->lights[i].position);
            hi = v3_max(hi, s->lights[i].position);
        }
        if (!(lo.x <= hi.x)) { lo = v3s(-1.0); hi = v3s(1.0); }
        double e = fmax(1.0, v3_len(v3_sub(hi, lo)));
        g->lo = v3_sub(lo, v3s(e));
        g->hi = v3_add(hi, v3s(e));
    } else {
        /* Infinite surfaces (planes, unbounded quadrics) are clipped to the
         * finite geometry's bounds grown by half their diagonal on every
         * side: the ground around the objects, where their shadows and
         * their light fall, gets particles; beyond it an infinite surface
         * is the far field (gi_surface_in_clip: the hook answers there from
         * the unoccluded sky). The particle count then never depends on
         * the size of a plane. */
        vec3 m = v3s(0.5 * v3_len(v3_sub(g->hi, g->lo)));
        g->lo = v3_sub(g->lo, m);
        g->hi = v3_add(g->hi, m);
    }
    const scene_object **seen = calloc((size_t)VIEW_W * VIEW_H, sizeof *seen);
    view_clip(s, a, &g->lo, &g->hi, seen);
    pt_status ast = PT_OK;
    g->as = accel_surf_build_in(s, a, NULL, NULL, NULL, NULL, threads, d, &ast);
    if (!g->as) {
        free(seen);
        gi_surface_free(g);
        *status = ast != PT_OK ? ast : PT_ERR_NOMEM;
        return NULL;
    }
    const scene_texture *deft = &s->default_texture;
    for (int i = 0; i < s->nobjects; i++) {
        pt_status st = walk(g, s->objects[i], deft, 0);
        if (st != PT_OK) {
            free(seen);
            gi_surface_free(g);
            *status = st;
            return NULL;
        }
    }
    /* the CSG members' areas, all at once */
    pt_status cst = gi_surface_csg_finish(g, threads);
    if (cst != PT_OK || !build_hash(g)) {
        free(seen);
        gi_surface_free(g);
        *status = cst != PT_OK ? cst : PT_ERR_NOMEM;
        return NULL;
    }
    for (int i = 0; i < g->np; i++) g->total_area += g->p[i].area;
    gi_surface_layout(g);
    view_coverage(g, seen);
    free(seen);
    *status = PT_OK;
    return g;
}


void gi_surface_free(gi_surface *g)
{
    if (!g) return;
    accel_surf_free(g->as);
    free(g->view);
    for (int i = 0; i < g->np; i++) gi_surface_free_patch(&g->p[i]);
    gi_surface_csg_free(g);
    free(g->mv);
    free(g->mn);
    free(g->mt);
    free(g->mtp);
    free(g->ce);
    free(g->slot_rp);
    free(g->rp_slot);
    free(g->rp_patch);
    free(g->tl);
    free(g->cdf);
    free(g->p);
    free(g->o);
    free(g->hash);
    free(g);
}

int gi_surface_in_clip(const gi_surface *g, vec3 p)
{
    vec3 t = v3s(1e-6 * v3_len(v3_sub(g->hi, g->lo)));
    return p.x >= g->lo.x - t.x && p.y >= g->lo.y - t.y && p.z >= g->lo.z - t.z && p.x <= g->hi.x + t.x &&
           p.y <= g->hi.y + t.y && p.z <= g->hi.z + t.z;
}

/* The fraction of patch i inside the clip box (gi_surface_in_clip), from
 * CLIP_PROBES points of its own sampler: 1 and 0 exactly when all or none
 * are in (a patch far from what the camera sees gets no particles). */
#define CLIP_PROBES 16

/* World bounds of patch p where they are known without sampling (a
 * triangle's corners, a finite shape's box); 0 otherwise. */
static int patch_bounds(const patch *p, vec3 *lo, vec3 *hi)
{
    if (p->kind == PATCH_TRI) {
        vec3 b = v3_add(p->v0, p->e1), c = v3_add(p->v0, p->e2);
        *lo = v3_min(p->v0, v3_min(b, c));
        *hi = v3_max(p->v0, v3_max(b, c));
    } else if (p->sh && !p->sh->infinite && !p->sh->clipped) {
        *lo = p->sh->lo;
        *hi = p->sh->hi;
    } else {
        return 0;
    }
    return v3_finite(*lo) && v3_finite(*hi) && lo->x <= hi->x && lo->y <= hi->y && lo->z <= hi->z;
}

float gi_surface_clip_fraction(const gi_surface *g, int i, uint64_t seed)
{
    /* a patch whose bounds lie in the box: every probe would be in */
    vec3 lo, hi;
    if (patch_bounds(&g->p[i], &lo, &hi) && lo.x >= g->lo.x && lo.y >= g->lo.y && lo.z >= g->lo.z &&
        hi.x <= g->hi.x && hi.y <= g->hi.y && hi.z <= g->hi.z)
        return 1.0f;
    rng r;
    rng_seed(&r, seed ^ 0xc11bULL, (uint64_t)i);
    int in = 0, n = 0;
    for (int q = 0; q < CLIP_PROBES * 4 && n < CLIP_PROBES; q++) {
        vec3 pos, nrm;
        if (!gi_surface_sample(g, i, rng_f64(&r), rng_f64(&r), &r, &pos, &nrm)) continue;
        n++;
        in += gi_surface_in_clip(g, pos);
    }
    return n ? (float)in / (float)n : 1.0f;
}

int gi_surface_npatches(const gi_surface *g) { return g->np; }
double gi_surface_area(const gi_surface *g, int i) { return g->p[i].area; }
int gi_surface_sides(const gi_surface *g, int i) { return g->p[i].nsides; }
int gi_surface_probe(const gi_surface *g, int i) { return g->p[i].probe; }
int gi_surface_side_mask(const gi_surface *g, int i) { return g->p[i].mask ? g->p[i].mask : 3; }
int gi_surface_csg_member(const gi_surface *g, int i) { return g->p[i].cnode >= 0; }
const scene_object *gi_surface_object(const gi_surface *g, int i) { return g->o[g->p[i].obj].obj; }
const scene_texture *gi_surface_texture(const gi_surface *g, int i) { return g->p[i].tex; }
long gi_surface_nrp(const gi_surface *g) { return g->nrp; }
long gi_surface_rp_slots(const gi_surface *g) { return g->nslot; }
long gi_surface_skipped(const gi_surface *g) { return g->skipped; }

int gi_surface_has_particles(const gi_surface *g, const accel_hit *hit)
{
    const obj_rec *o = hit && hit->obj ? gi_surface_find_obj(g, hit->obj) : NULL;
    return o && o->count > 0;
}

size_t gi_surface_bytes(const gi_surface *g)
{
    return (size_t)g->capp * sizeof(patch) + (size_t)g->capo * sizeof(obj_rec) + (size_t)g->hcap * sizeof(int) +
           (size_t)g->capcdf * sizeof(double) + (size_t)g->capct * sizeof(geom_csg) + (size_t)g->capcm * sizeof(csg_member) +
           (size_t)g->capmv * 2 * sizeof(vec3) + (size_t)g->capmt * 4 * sizeof(int) +
           (size_t)g->nce * sizeof(cell_entry) + (g->slot_rp ? (size_t)(g->nslot + g->nrp) * sizeof(int) : 0) +
           (g->rp_patch ? (size_t)g->nrp * sizeof(int) : 0) +
           (g->tl ? (size_t)g->np * sizeof *g->tl : 0);
}

int gi_surface_sample(const gi_surface *g, int i, double u, double v, rng *r, vec3 *pos, vec3 *nrm)
{
    const patch *p = &g->p[i];
    if (p->piece >= 0 && p->kind != PATCH_TRI) {
        /* analytic shapes: accel_surface's sampler (uniform by world area,
         * rejection under non-similarity transforms) */
        accel_surf_sample smp;
        int piece = p->piece;
        if (p->kind == PATCH_PIECE && p->npieces > 1) {
            /* a piece of a polygon / height field with probability by area */
            const double *c = g->cdf + p->cdf0;
            double t = rng_f64(r) * c[p->npieces - 1];
            int lo = 0, hi = p->npieces - 1;
            while (lo < hi) {
                int mid = (lo + hi) / 2;
                if (t < c[mid]) hi = mid;
                else lo = mid + 1;
            }
            piece += lo;
        }
        /* (v, u): the R2 sequence's second coordinate drives the polar
         * direction; this order spreads the points more evenly over a
         * sphere (test_gi's integrating sphere is less biased with it) */
        if (!accel_surf_sample_piece(g->as, piece, v, u, r, &smp)) return 0;
        *pos = smp.p;
        *nrm = smp.n;
        if (p->kind == PATCH_DISC) {
            /* side 0 is the disc's own normal, as in locate */
            vec3 front;
            gi_surface_grid_eval(g, p, 0.0, 0.0, NULL, &front);
            if (v3_dot(*nrm, front) < 0.0) *nrm = v3_neg(*nrm);
        }
        return v3_finite(*pos) && v3_finite(*nrm);
    }
    if (p->ks) {
        /* CSG member: its own lines, keeping the result's surface */
        unsigned part;
        if (!geom_tess_sample(&p->ks->cs, v, u, r, pos, nrm, &part)) return 0;
        return v3_finite(*pos) && v3_finite(*nrm);
    }
    if (p->kind == PATCH_PIECE) return 0;
    double xi = rng_f64(r);
    if (p->kind == PATCH_TRI) {
        /* fold the unit square onto the triangle (uniform, keeps stratification) */
        if (u + v > 1.0) {
            u = 1.0 - u;
            v = 1.0 - v;
        }
        *pos = v3_add(p->v0, v3_add(v3_scale(p->e1, u), v3_scale(p->e2, v)));
        *nrm = p->nrm;
        return 1;
    }
    if (p->jmax > p->jmin * (1.0 + 1e-9)) {
        double jac = grid_jac(g, p, u, v);
        if (xi * p->jmax > jac) return 0;
    }
    gi_surface_grid_eval(g, p, u, v, pos, nrm);
    return v3_finite(*pos) && v3_finite(*nrm);
}

