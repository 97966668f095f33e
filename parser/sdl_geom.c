/* sdl_geom.c - parse-time ray intersection, inside tests and bounding boxes
 * on scene IR objects (see sdl_geom.h for what is exact). */
#include "sdl_geom.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "sdl_directive.h"
#include "func.h"
#include "geom_env.h"
#include "sdl_expr.h"

#define DEPTH_TOLERANCE 1e-6    /* POV-Ray's shapes ignore hits closer than this */
#define BOUND_HUGE 2.0e10       /* POV-Ray 3.7's unbounded box is +-BOUND_HUGE/2 */
#define CRITICAL_LENGTH 1.0e6   /* a CSG box longer than this becomes unbounded */
#define SMALL_TOLERANCE 0.001   /* the disc's box thickness */
#define MESH_LEAF 4

typedef struct {
    double t;
    vec3 n;                     /* world normal (not yet flipped for inverse) */
    const scene_object *leaf;
} geom_hit;

typedef struct {
    geom_hit *h;
    int n, cap;
} hit_list;

/* A mesh's BVH in object space. */
typedef struct {
    vec3 lo, hi;
    int left, right;            /* children; -1 for a leaf */
    int first, count;           /* leaf: range in `order` */
} bvh_node;

typedef struct mesh_bvh {
    const scene_mesh *mesh;
    bvh_node *nodes;
    int nnodes;
    int *order;
    struct mesh_bvh *next;
} mesh_bvh;

typedef struct {
    sdl_parser *p;
    const char *unsupported;    /* shape the evaluator cannot handle */
    int nomem;
} geom;

typedef struct {
    vec3 lo, hi;
} bbox;

/* ------------------------------------------------------------ hit lists */

static void add_hit(geom *g, hit_list *l, double t, vec3 n, const scene_object *leaf)
{
    if (l->n == l->cap) {
        int nc = l->cap ? l->cap * 2 : 16;
        geom_hit *nh = realloc(l->h, sizeof *nh * (size_t)nc);
        if (!nh) {
            g->nomem = 1;
            return;
        }
        l->h = nh;
        l->cap = nc;
    }
    l->h[l->n].t = t;
    l->h[l->n].n = n;
    l->h[l->n].leaf = leaf;
    l->n++;
}

static vec3 world_normal(const scene_object *o, vec3 n) { return v3_norm(xform_normal(&o->transform, n)); }

/* ------------------------------------------------------------ primitives */

/* The ray in the object's own space (the parameter t is unchanged). */
static void local_ray(const scene_object *o, vec3 org, vec3 dir, vec3 *lo, vec3 *ld)
{
    *lo = xform_inv_point(&o->transform, org);
    *ld = xform_inv_vector(&o->transform, dir);
}

static void sphere_hits(geom *g, const scene_object *o, vec3 org, vec3 dir, hit_list *l)
{
    vec3 ro, rd;
    local_ray(o, org, dir, &ro, &rd);
    vec3 oc = v3_sub(ro, o->u.sphere.centre);
    double a = v3_dot(rd, rd), b = v3_dot(oc, rd), c = v3_dot(oc, oc) - o->u.sphere.radius * o->u.sphere.radius;
    double disc = b * b - a * c;
    if (disc < 0 || a == 0) return;
    double s = sqrt(disc);
    for (int k = 0; k < 2; k++) {
        double t = (-b + (k ? s : -s)) / a;
        vec3 pl = v3_madd(ro, rd, t);
        add_hit(g, l, t, world_normal(o, v3_sub(pl, o->u.sphere.centre)), o);
    }
}

static void box_hits(geom *g, const scene_object *o, vec3 org, vec3 dir, hit_list *l)
{
    vec3 ro, rd;
    local_ray(o, org, dir, &ro, &rd);
    double tmin = -INFINITY, tmax = INFINITY;
    int amin = -1, amax = -1;
    double smin = 0, smax = 0;
    for (int i = 0; i < 3; i++) {
        double o_ = v3_idx(ro, i), d = v3_idx(rd, i), lo = v3_idx(o->u.box.c1, i), hi = v3_idx(o->u.box.c2, i);
        if (fabs(d) < 1e-300) {
            if (o_ < lo || o_ > hi) return;
            continue;
        }
        double t1 = (lo - o_) / d, t2 = (hi - o_) / d, s1 = -1, s2 = 1;
        if (t1 > t2) {
            double tt = t1;
            t1 = t2;
            t2 = tt;
            s1 = 1;
            s2 = -1;
        }
        if (t1 > tmin) { tmin = t1; amin = i; smin = s1; }
        if (t2 < tmax) { tmax = t2; amax = i; smax = s2; }
    }
    if (tmin > tmax || amin < 0 || amax < 0) return;
    vec3 n1 = v3(amin == 0 ? smin : 0, amin == 1 ? smin : 0, amin == 2 ? smin : 0);
    vec3 n2 = v3(amax == 0 ? smax : 0, amax == 1 ? smax : 0, amax == 2 ? smax : 0);
    add_hit(g, l, tmin, world_normal(o, n1), o);
    add_hit(g, l, tmax, world_normal(o, n2), o);
}

static void plane_hits(geom *g, const scene_object *o, vec3 org, vec3 dir, hit_list *l)
{
    vec3 ro, rd;
    local_ray(o, org, dir, &ro, &rd);
    double dn = v3_dot(o->u.plane.normal, rd);
    if (fabs(dn) < 1e-300) return;
    double t = (o->u.plane.offset - v3_dot(o->u.plane.normal, ro)) / dn;
    add_hit(g, l, t, world_normal(o, o->u.plane.normal), o);
}

/* Ray/triangle (Moller-Trumbore); barycentrics of v1 and v2 in *u, *v. */
static int tri_hit(vec3 org, vec3 dir, vec3 a, vec3 b, vec3 c, double *t, double *u, double *v)
{
    vec3 e1 = v3_sub(b, a), e2 = v3_sub(c, a), pv = v3_cross(dir, e2);
    double det = v3_dot(e1, pv);
    if (fabs(det) < 1e-300) return 0;
    double inv = 1.0 / det;
    vec3 tv = v3_sub(org, a);
    *u = v3_dot(tv, pv) * inv;
    if (*u < 0 || *u > 1) return 0;
    vec3 qv = v3_cross(tv, e1);
    *v = v3_dot(dir, qv) * inv;
    if (*v < 0 || *u + *v > 1) return 0;
    *t = v3_dot(e2, qv) * inv;
    return 1;
}

/* POV-Ray's flat triangle normal: (P1 - P2) x (P3 - P2) of the placed vertices. */
static vec3 flat_normal(vec3 a, vec3 b, vec3 c) { return v3_norm(v3_cross(v3_sub(a, b), v3_sub(c, b))); }

static void triangle_hits(geom *g, const scene_object *o, vec3 org, vec3 dir, hit_list *l)
{
    vec3 w[3];
    for (int i = 0; i < 3; i++) w[i] = xform_point(&o->transform, o->u.triangle.v[i]);
    double t, u, v;
    if (!tri_hit(org, dir, w[0], w[1], w[2], &t, &u, &v)) return;
    vec3 n = flat_normal(w[0], w[1], w[2]);
    if (o->kind == SHAPE_SMOOTH_TRIANGLE) {
        vec3 s = v3(0, 0, 0);
        double wt[3] = {1 - u - v, u, v};
        for (int i = 0; i < 3; i++) s = v3_madd(s, world_normal(o, o->u.triangle.n[i]), wt[i]);
        if (v3_len2(s) > 0) n = v3_norm(s);
    }
    add_hit(g, l, t, n, o);
}

/* ------------------------------------------------------------ meshes */

static vec3 mesh_vert(const scene_mesh *m, int i) { return v3(m->verts[i][0], m->verts[i][1], m->verts[i][2]); }

static void tri_bounds(const scene_mesh *m, int t, vec3 *lo, vec3 *hi)
{
    vec3 a = mesh_vert(m, m->tris[t][0]), b = mesh_vert(m, m->tris[t][1]), c = mesh_vert(m, m->tris[t][2]);
    *lo = v3_min(a, v3_min(b, c));
    *hi = v3_max(a, v3_max(b, c));
}

typedef struct {
    const scene_mesh *m;
    vec3 *cen;
    int *order;
    bvh_node *nodes;
    int n, cap;
} bvh_build;

static int bvh_node_new(bvh_build *b)
{
    if (b->n == b->cap) {
        int nc = b->cap ? b->cap * 2 : 64;
        bvh_node *nn = realloc(b->nodes, sizeof *nn * (size_t)nc);
        if (!nn) return -1;
        b->nodes = nn;
        b->cap = nc;
    }
    return b->n++;
}

/* Median split on the longest axis of the centroids (iterative pieces are
 * bounded: depth is about log2(n)). */
static int bvh_split(bvh_build *b, int first, int count, int depth)
{
    int id = bvh_node_new(b);
    if (id < 0) return -1;
    vec3 lo = v3s(INFINITY), hi = v3s(-INFINITY), clo = v3s(INFINITY), chi = v3s(-INFINITY);
    for (int i = first; i < first + count; i++) {
        vec3 tl, th;
        tri_bounds(b->m, b->order[i], &tl, &th);
        lo = v3_min(lo, tl);
        hi = v3_max(hi, th);
        clo = v3_min(clo, b->cen[b->order[i]]);
        chi = v3_max(chi, b->cen[b->order[i]]);
    }
    b->nodes[id].lo = lo;
    b->nodes[id].hi = hi;
    b->nodes[id].left = b->nodes[id].right = -1;
    b->nodes[id].first = first;
    b->nodes[id].count = count;
    if (count <= MESH_LEAF || depth > 60) return id;
    vec3 ext = v3_sub(chi, clo);
    int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    if (v3_idx(ext, axis) <= 0) return id;
    /* partial sort around the median (nth element by repeated partition) */
    int lo_i = first, hi_i = first + count - 1, mid = first + count / 2;
    while (lo_i < hi_i) {
        double pivot = v3_idx(b->cen[b->order[(lo_i + hi_i) / 2]], axis);
        int i = lo_i, j = hi_i;
        while (i <= j) {
            while (v3_idx(b->cen[b->order[i]], axis) < pivot) i++;
            while (v3_idx(b->cen[b->order[j]], axis) > pivot) j--;
            if (i <= j) {
                int tmp = b->order[i];
                b->order[i] = b->order[j];
                b->order[j] = tmp;
                i++;
                j--;
            }
        }
        if (mid <= j) hi_i = j;
        else if (mid >= i) lo_i = i;
        else break;
    }
    int left = bvh_split(b, first, mid - first, depth + 1);
    int right = left < 0 ? -1 : bvh_split(b, mid, first + count - mid, depth + 1);
    if (right < 0) return -1;
    b->nodes[id].left = left;
    b->nodes[id].right = right;
    return id;
}

static mesh_bvh *mesh_bvh_get(geom *g, const scene_mesh *m)
{
    for (mesh_bvh *h = g->p->geom_cache; h; h = h->next)
        if (h->mesh == m) return h;
    mesh_bvh *h = calloc(1, sizeof *h);
    bvh_build b;
    memset(&b, 0, sizeof b);
    b.m = m;
    b.cen = malloc(sizeof *b.cen * (size_t)(m->ntris ? m->ntris : 1));
    b.order = malloc(sizeof *b.order * (size_t)(m->ntris ? m->ntris : 1));
    if (!h || !b.cen || !b.order) {
        free(h);
        free(b.cen);
        free(b.order);
        g->nomem = 1;
        return NULL;
    }
    for (int i = 0; i < m->ntris; i++) {
        vec3 lo, hi;
        tri_bounds(m, i, &lo, &hi);
        b.cen[i] = v3_scale(v3_add(lo, hi), 0.5);
        b.order[i] = i;
    }
    if (m->ntris > 0 && bvh_split(&b, 0, m->ntris, 0) < 0) g->nomem = 1;
    free(b.cen);
    h->mesh = m;
    h->nodes = b.nodes;
    h->nnodes = b.n;
    h->order = b.order;
    h->next = g->p->geom_cache;
    g->p->geom_cache = h;
    return h;
}

static int slab_overlap(vec3 lo, vec3 hi, vec3 org, vec3 inv)
{
    double t0 = -INFINITY, t1 = INFINITY;
    for (int i = 0; i < 3; i++) {
        double a = (v3_idx(lo, i) - v3_idx(org, i)) * v3_idx(inv, i), b = (v3_idx(hi, i) - v3_idx(org, i)) * v3_idx(inv, i);
        if (isnan(a) || isnan(b)) continue; /* 0 * inf: the ray lies in the slab's plane */
        if (a > b) {
            double t = a;
            a = b;
            b = t;
        }
        if (a > t0) t0 = a;
        if (b < t1) t1 = b;
    }
    return t0 <= t1 * (1 + 1e-12) + 1e-12;
}

static vec3 mesh_normal(const scene_object *o, const scene_mesh *m, int t, double u, double v)
{
    vec3 a = mesh_vert(m, m->tris[t][0]), b = mesh_vert(m, m->tris[t][1]), c = mesh_vert(m, m->tris[t][2]);
    vec3 n = v3_cross(v3_sub(c, a), v3_sub(b, a)); /* POV-Ray's mesh triangle normal */
    /* normals per corner (tri_normals), or per vertex when there are as many
     * (bicubic_patch meshes), as the renderer reads them */
    const int *ni = m->normals ? (m->tri_normals ? m->tri_normals[t] : (m->nnormals == m->nverts ? m->tris[t] : NULL)) : NULL;
    if (ni) {
        vec3 s = v3(0, 0, 0);
        double w[3] = {1 - u - v, u, v};
        for (int i = 0; i < 3; i++)
            if (ni[i] >= 0 && ni[i] < m->nnormals) /* POV-Ray keeps mesh normals normalised */
                s = v3_madd(s, v3_norm(v3(m->normals[ni[i]][0], m->normals[ni[i]][1], m->normals[ni[i]][2])), w[i]);
        if (v3_len2(s) > 0) n = s;
    }
    return world_normal(o, n);
}

static void mesh_hits(geom *g, const scene_object *o, vec3 org, vec3 dir, hit_list *l)
{
    const scene_mesh *m = o->u.mesh.mesh;
    if (!m || m->ntris == 0) return;
    mesh_bvh *h = mesh_bvh_get(g, m);
    if (!h || !h->nodes) return;
    vec3 ro, rd;
    local_ray(o, org, dir, &ro, &rd);
    vec3 inv = v3(1.0 / rd.x, 1.0 / rd.y, 1.0 / rd.z);
    int stack[128], sp = 0;
    stack[sp++] = 0;
    while (sp > 0) {
        const bvh_node *nd = &h->nodes[stack[--sp]];
        if (!slab_overlap(nd->lo, nd->hi, ro, inv)) continue;
        if (nd->left < 0) {
            for (int i = nd->first; i < nd->first + nd->count; i++) {
                int t = h->order[i];
                double tt, u, v;
                if (tri_hit(ro, rd, mesh_vert(m, m->tris[t][0]), mesh_vert(m, m->tris[t][1]), mesh_vert(m, m->tris[t][2]), &tt, &u, &v))
                    add_hit(g, l, tt, mesh_normal(o, m, t, u, v), o);
            }
            continue;
        }
        if (sp + 2 <= (int)(sizeof stack / sizeof stack[0])) {
            stack[sp++] = nd->left;
            stack[sp++] = nd->right;
        }
    }
}

/* ------------------------------------------------------------ cones */

/* Cylinder/cone frame: axis from base to cap. */
typedef struct {
    vec3 base, w;
    double len, r0, r1, k;
} cone_frame;

static cone_frame cone_of(const scene_object *o)
{
    cone_frame f;
    f.base = o->u.cone.base;
    vec3 ax = v3_sub(o->u.cone.cap, o->u.cone.base);
    f.len = v3_len(ax);
    f.w = f.len > 0 ? v3_scale(ax, 1.0 / f.len) : v3(0, 1, 0);
    f.r0 = o->u.cone.base_radius;
    f.r1 = o->u.cone.cap_radius;
    f.k = f.len > 0 ? (f.r1 - f.r0) / f.len : 0;
    return f;
}

static void cone_hits(geom *g, const scene_object *o, vec3 org, vec3 dir, hit_list *l)
{
    cone_frame f = cone_of(o);
    if (f.len <= 0) return;
    vec3 ro, rd;
    local_ray(o, org, dir, &ro, &rd);
    vec3 a = v3_sub(ro, f.base);
    double aw = v3_dot(a, f.w), dw = v3_dot(rd, f.w);
    vec3 qa = v3_madd(a, f.w, -aw), qd = v3_madd(rd, f.w, -dw);
    double ra = f.r0 + f.k * aw;
    double A = v3_dot(qd, qd) - f.k * f.k * dw * dw;
    double B = 2 * (v3_dot(qa, qd) - f.k * ra * dw);
    double C = v3_dot(qa, qa) - ra * ra;
    double roots[2];
    int nr = 0;
    if (fabs(A) > 1e-300) {
        double disc = B * B - 4 * A * C;
        if (disc >= 0) {
            double s = sqrt(disc);
            roots[nr++] = (-B - s) / (2 * A);
            roots[nr++] = (-B + s) / (2 * A);
        }
    } else if (fabs(B) > 1e-300) {
        roots[nr++] = -C / B;
    }
    for (int i = 0; i < nr; i++) {
        double t = roots[i], h = aw + t * dw;
        if (h < 0 || h > f.len || f.r0 + f.k * h < 0) continue;
        vec3 q = v3_madd(qa, qd, t);
        double ql = v3_len(q);
        if (ql <= 0) continue;
        vec3 n = v3_madd(v3_scale(q, 1.0 / ql), f.w, -f.k);
        add_hit(g, l, t, world_normal(o, n), o);
    }
    if ((o->flags & OBJ_OPEN) || fabs(dw) < 1e-300) return;
    for (int cap = 0; cap < 2; cap++) {
        double h = cap ? f.len : 0, r = cap ? f.r1 : f.r0;
        double t = (h - aw) / dw;
        vec3 q = v3_madd(qa, qd, t);
        if (v3_dot(q, q) <= r * r) add_hit(g, l, t, world_normal(o, v3_scale(f.w, cap ? 1 : -1)), o);
    }
}

static int cone_inside(const scene_object *o, vec3 pl)
{
    cone_frame f = cone_of(o);
    vec3 a = v3_sub(pl, f.base);
    double h = v3_dot(a, f.w);
    if (h < 0 || h > f.len) return 0;
    vec3 q = v3_madd(a, f.w, -h);
    double r = f.r0 + f.k * h;
    return v3_dot(q, q) < r * r;
}

static void disc_hits(geom *g, const scene_object *o, vec3 org, vec3 dir, hit_list *l)
{
    vec3 ro, rd;
    local_ray(o, org, dir, &ro, &rd);
    vec3 n = o->u.disc.normal;
    double dn = v3_dot(n, rd);
    if (fabs(dn) < 1e-300) return;
    double t = v3_dot(n, v3_sub(o->u.disc.centre, ro)) / dn;
    vec3 d = v3_sub(v3_madd(ro, rd, t), o->u.disc.centre);
    double r2 = v3_dot(d, d), ro2 = o->u.disc.radius * o->u.disc.radius, ri2 = o->u.disc.hole_radius * o->u.disc.hole_radius;
    if (r2 <= ro2 && r2 >= ri2) add_hit(g, l, t, world_normal(o, n), o);
}

/* ------------------------------------------------------------ marched shapes */

static double torus_f(const scene_object *o, vec3 q)
{
    double R = o->u.torus.major, r = o->u.torus.minor, rho = sqrt(q.x * q.x + q.z * q.z) - R;
    return rho * rho + q.y * q.y - r * r;
}

static double superellipsoid_f(const scene_object *o, vec3 q)
{
    double e = o->u.superellipsoid.e, n = o->u.superellipsoid.n;
    double xy = pow(pow(fabs(q.x), 2 / e) + pow(fabs(q.y), 2 / e), e / n);
    return xy + pow(fabs(q.z), 2 / n) - 1;
}

static double quadric_f(const scene_object *o, vec3 q)
{
    const double *a = o->u.quadric.a;
    return a[0] * q.x * q.x + a[1] * q.y * q.y + a[2] * q.z * q.z + a[3] * q.x * q.y + a[4] * q.x * q.z + a[5] * q.y * q.z +
           a[6] * q.x + a[7] * q.y + a[8] * q.z + a[9];
}

static double implicit_f(const scene_object *o, vec3 q)
{
    switch (o->kind) {
    case SHAPE_TORUS: return torus_f(o, q);
    case SHAPE_SUPERELLIPSOID: return superellipsoid_f(o, q);
    default: return quadric_f(o, q);
    }
}

static vec3 implicit_gradient(const scene_object *o, vec3 q)
{
    if (o->kind == SHAPE_TORUS) {
        double rho = sqrt(q.x * q.x + q.z * q.z), R = o->u.torus.major;
        double s = rho > 0 ? 1 - R / rho : 0;
        return v3(q.x * s, q.y, q.z * s);
    }
    if (o->kind == SHAPE_QUADRIC) {
        const double *a = o->u.quadric.a;
        return v3(2 * a[0] * q.x + a[3] * q.y + a[4] * q.z + a[6], 2 * a[1] * q.y + a[3] * q.x + a[5] * q.z + a[7],
                  2 * a[2] * q.z + a[4] * q.x + a[5] * q.y + a[8]);
    }
    double h = 1e-7;
    return v3(implicit_f(o, v3(q.x + h, q.y, q.z)) - implicit_f(o, v3(q.x - h, q.y, q.z)),
              implicit_f(o, v3(q.x, q.y + h, q.z)) - implicit_f(o, v3(q.x, q.y - h, q.z)),
              implicit_f(o, v3(q.x, q.y, q.z + h)) - implicit_f(o, v3(q.x, q.y, q.z - h)));
}

/* Quadric: the quadratic in t, solved in closed form. */
static void quadric_hits(geom *g, const scene_object *o, vec3 org, vec3 dir, hit_list *l)
{
    vec3 ro, rd;
    local_ray(o, org, dir, &ro, &rd);
    double c = quadric_f(o, ro), f1 = quadric_f(o, v3_add(ro, rd)), fm = quadric_f(o, v3_sub(ro, rd));
    double A = (f1 + fm) / 2 - c, B = (f1 - fm) / 2; /* f(t) = A t^2 + B t + c exactly */
    double roots[2];
    int nr = 0;
    if (fabs(A) > 1e-300) {
        double disc = B * B - 4 * A * c;
        if (disc >= 0) {
            double s = sqrt(disc);
            roots[nr++] = (-B - s) / (2 * A);
            roots[nr++] = (-B + s) / (2 * A);
        }
    } else if (fabs(B) > 1e-300) {
        roots[nr++] = -c / B;
    }
    for (int i = 0; i < nr; i++) add_hit(g, l, roots[i], world_normal(o, implicit_gradient(o, v3_madd(ro, rd, roots[i]))), o);
}

/* Torus and superellipsoid: march the part of the ray inside the shape's
 * box, bisect every sign change of the implicit function. */
static void marched_hits(geom *g, const scene_object *o, vec3 org, vec3 dir, hit_list *l)
{
    vec3 ro, rd;
    local_ray(o, org, dir, &ro, &rd);
    vec3 lo, hi;
    double step;
    if (o->kind == SHAPE_TORUS) {
        double R = o->u.torus.major + o->u.torus.minor, r = o->u.torus.minor;
        lo = v3(-R, -r, -R);
        hi = v3(R, r, R);
        step = r / 16;
    } else {
        lo = v3s(-1);
        hi = v3s(1);
        step = 1.0 / 64;
    }
    double t0 = -INFINITY, t1 = INFINITY;
    for (int i = 0; i < 3; i++) {
        double d = v3_idx(rd, i), oo = v3_idx(ro, i), a = v3_idx(lo, i) - 1e-9, b = v3_idx(hi, i) + 1e-9;
        if (fabs(d) < 1e-300) {
            if (oo < a || oo > b) return;
            continue;
        }
        double ta = (a - oo) / d, tb = (b - oo) / d;
        if (ta > tb) { double t = ta; ta = tb; tb = t; }
        if (ta > t0) t0 = ta;
        if (tb < t1) t1 = tb;
    }
    if (t0 > t1) return;
    double len = v3_len(rd);
    if (len <= 0) return;
    double dt = step / len;
    long n = (long)ceil((t1 - t0) / dt);
    if (n > 1000000) n = 1000000;
    if (n < 1) n = 1;
    dt = (t1 - t0) / (double)n;
    double ta = t0, fa = implicit_f(o, v3_madd(ro, rd, ta));
    for (long i = 1; i <= n; i++) {
        double tb = t0 + dt * (double)i, fb = implicit_f(o, v3_madd(ro, rd, tb));
        if ((fa < 0) != (fb < 0)) {
            double a = ta, b = tb, va = fa;
            for (int k = 0; k < 100 && b - a > 1e-14 * (1 + fabs(a)); k++) {
                double m = 0.5 * (a + b), vm = implicit_f(o, v3_madd(ro, rd, m));
                if ((vm < 0) == (va < 0)) { a = m; va = vm; } else b = m;
            }
            double t = 0.5 * (a + b);
            add_hit(g, l, t, world_normal(o, implicit_gradient(o, v3_madd(ro, rd, t))), o);
        }
        ta = tb;
        fa = fb;
    }
}

/* ------------------------------------------------------------ lathe, prism, blob */

/* One cubic segment of a lathe/prism curve: (u, v)(w) = A w^3 + B w^2 + C w + D,
 * w in [0, 1] (u = radius or x, v = height or z). */
typedef struct {
    double a[2], b[2], c[2], d[2];
} curve_seg;

/* Segment coefficients for POV-Ray's four curve types from the points
 * starting at i (3.7's lathe/prism formulas). */
static void curve_coeffs(scene_spline type, double (*pt)[2], int i, curve_seg *s)
{
    for (int k = 0; k < 2; k++) {
        double p0 = pt[i][k], p1 = type == SPLINE_LINEAR ? 0 : pt[i + 1][k], p2 = 0, p3 = 0;
        switch (type) {
        case SPLINE_LINEAR:
            s->a[k] = s->b[k] = 0;
            s->c[k] = pt[i + 1][k] - p0;
            s->d[k] = p0;
            break;
        case SPLINE_QUADRATIC:
            p2 = pt[i + 2][k];
            s->a[k] = 0;
            s->b[k] = 0.5 * p0 - p1 + 0.5 * p2;
            s->c[k] = -0.5 * p0 + 0.5 * p2;
            s->d[k] = p1;
            break;
        case SPLINE_CUBIC:
            p2 = pt[i + 2][k];
            p3 = pt[i + 3][k];
            s->a[k] = -0.5 * p0 + 1.5 * p1 - 1.5 * p2 + 0.5 * p3;
            s->b[k] = p0 - 2.5 * p1 + 2.0 * p2 - 0.5 * p3;
            s->c[k] = -0.5 * p0 + 0.5 * p2;
            s->d[k] = p1;
            break;
        default: /* bezier */
            p2 = pt[i + 2][k];
            p3 = pt[i + 3][k];
            s->a[k] = p3 - 3 * p2 + 3 * p1 - p0;
            s->b[k] = 3 * p2 - 6 * p1 + 3 * p0;
            s->c[k] = 3 * p1 - 3 * p0;
            s->d[k] = p0;
            break;
        }
    }
}

static double seg_at(const curve_seg *s, int k, double w) { return ((s->a[k] * w + s->b[k]) * w + s->c[k]) * w + s->d[k]; }
static double seg_slope(const curve_seg *s, int k, double w) { return (3 * s->a[k] * w + 2 * s->b[k]) * w + s->c[k]; }

/* Roots in [0, 1] of the segment's v(w) = v0 (monotone pieces between the
 * derivative's roots, then bisection). Returns the count (at most 3). */
static int seg_roots(const curve_seg *s, double v0, double *w)
{
    double cuts[4] = {0, 0, 0, 1};
    int nc = 1;
    double qa = 3 * s->a[1], qb = 2 * s->b[1], qc = s->c[1];
    if (fabs(qa) > 1e-300) {
        double disc = qb * qb - 4 * qa * qc;
        if (disc > 0) {
            double r1 = (-qb - sqrt(disc)) / (2 * qa), r2 = (-qb + sqrt(disc)) / (2 * qa);
            if (r1 > r2) { double t = r1; r1 = r2; r2 = t; }
            if (r1 > 0 && r1 < 1) cuts[nc++] = r1;
            if (r2 > 0 && r2 < 1) cuts[nc++] = r2;
        }
    } else if (fabs(qb) > 1e-300) {
        double r = -qc / qb;
        if (r > 0 && r < 1) cuts[nc++] = r;
    }
    cuts[nc++] = 1;
    int n = 0;
    for (int i = 0; i + 1 < nc; i++) {
        double a = cuts[i], b = cuts[i + 1], fa = seg_at(s, 1, a) - v0, fb = seg_at(s, 1, b) - v0;
        if (fa == 0 && i > 0) continue; /* counted as the previous piece's end */
        if ((fa > 0 && fb > 0) || (fa < 0 && fb < 0)) continue;
        for (int k = 0; k < 80 && b - a > 1e-15; k++) {
            double m = 0.5 * (a + b), fm = seg_at(s, 1, m) - v0;
            if ((fm < 0) == (fa < 0) && fm != 0) { a = m; fa = fm; } else b = m;
        }
        if (n < 3) w[n++] = 0.5 * (a + b);
    }
    return n;
}

typedef struct {
    curve_seg *segs;
    int n;
} curve;

/* The lathe's segments: linear/quadratic/cubic advance one point, bezier four. */
static int lathe_curve(const scene_lathe *la, curve *c)
{
    int n = la->npoints, count;
    switch (la->spline) {
    case SPLINE_LINEAR: count = n - 1; break;
    case SPLINE_QUADRATIC: count = n - 2; break;
    case SPLINE_CUBIC: count = n - 3; break;
    default: count = n / 4; break;
    }
    if (count < 1) return 0;
    c->segs = malloc(sizeof *c->segs * (size_t)count);
    if (!c->segs) return 0;
    for (int s = 0, i = 0; s < count; s++, i += la->spline == SPLINE_BEZIER ? 4 : 1) curve_coeffs(la->spline, la->points, i, &c->segs[s]);
    c->n = count;
    return 1;
}

/* The prism's segments: sub-polygons end where a point repeats the
 * sub-polygon's first point (POV-Ray 3.7's Compute_Prism walk). */
static int prism_curve(const scene_prism *pr, curve *c)
{
    int n = pr->npoints;
    c->segs = malloc(sizeof *c->segs * (size_t)(n > 0 ? n : 1));
    c->n = 0;
    if (!c->segs || n < 2) return c->segs != NULL;
    double (*p)[2] = pr->points;
    double first[2] = {p[0][0], p[0][1]};
    if (pr->spline == SPLINE_QUADRATIC || pr->spline == SPLINE_CUBIC) {
        first[0] = p[1][0];
        first[1] = p[1][1];
    }
    int need = pr->spline == SPLINE_LINEAR ? 1 : (pr->spline == SPLINE_QUADRATIC ? 2 : 3);
    for (int i = 0; i < n - 1; i++) {
        if (i + need >= n) break;
        curve_coeffs(pr->spline, p, i, &c->segs[c->n++]);
        int close = pr->spline == SPLINE_LINEAR ? i + 1 : i + 2;
        int same = fabs(p[close][0] - first[0]) < 1e-10 && fabs(p[close][1] - first[1]) < 1e-10;
        if (pr->spline == SPLINE_BEZIER) {
            i += 3;
        } else if (same) {
            int skip = pr->spline == SPLINE_LINEAR ? 1 : (pr->spline == SPLINE_QUADRATIC ? 2 : 3);
            i += skip;
            int nf = i + (pr->spline == SPLINE_LINEAR ? 1 : 2);
            if (nf < n) {
                first[0] = p[nf][0];
                first[1] = p[nf][1];
            }
        }
    }
    return 1;
}

/* POV-Ray's crossing rule: count the curve points at height v whose u is
 * not left of the point; odd = inside. */
static int curve_inside(const curve *c, double u, double v)
{
    int nc = 0;
    for (int i = 0; i < c->n; i++) {
        double w[3];
        int n = seg_roots(&c->segs[i], v, w);
        for (int k = 0; k < n; k++)
            if (seg_at(&c->segs[i], 0, w[k]) - u >= 0) nc++;
    }
    return nc & 1;
}

/* The 2-D outward normal of the curve near (u, v) (the closest crossing). */
static int curve_normal(const curve *c, double u, double v, double *nu, double *nv)
{
    double best = INFINITY;
    for (int i = 0; i < c->n; i++) {
        double w[3];
        int n = seg_roots(&c->segs[i], v, w);
        for (int k = 0; k < n; k++) {
            double du = fabs(seg_at(&c->segs[i], 0, w[k]) - u);
            if (du < best) {
                best = du;
                *nu = seg_slope(&c->segs[i], 1, w[k]);
                *nv = -seg_slope(&c->segs[i], 0, w[k]);
            }
        }
    }
    return best < INFINITY;
}

static int lathe_inside_local(const scene_object *o, vec3 q)
{
    curve c = {NULL, 0};
    if (!o->u.lathe || !lathe_curve(o->u.lathe, &c)) return 0;
    int in = curve_inside(&c, sqrt(q.x * q.x + q.z * q.z), q.y);
    free(c.segs);
    return in;
}

static int prism_inside_local(const scene_object *o, vec3 q)
{
    const scene_prism *pr = o->u.prism;
    if (!pr) return 0;
    double h1 = fmin(pr->height1, pr->height2), h2 = fmax(pr->height1, pr->height2);
    if (!(q.y >= h1 && q.y < h2)) return 0;
    double u = q.x, v = q.z;
    if (pr->conic) {
        if (fabs(q.y) <= 1e-10) return 0;
        u /= q.y;
        v /= q.y;
    }
    curve c = {NULL, 0};
    if (!prism_curve(pr, &c)) return 0;
    int in = curve_inside(&c, u, v);
    free(c.segs);
    return in;
}

/* Blob density at a point of blob space (POV-Ray: strength * (1 - d^2/r^2)^2
 * inside each component's radius; d to the centre or to the cylinder's axis
 * segment). */
static double blob_density(const scene_blob *b, vec3 q)
{
    double sum = 0;
    for (int i = 0; i < b->ncomponents; i++) {
        const scene_blob_component *c = &b->components[i];
        vec3 l = xform_inv_point(&c->transform, q), d;
        if (c->cylinder) {
            vec3 ax = v3_sub(c->b, c->a);
            double len2 = v3_dot(ax, ax), t = len2 > 0 ? v3_dot(v3_sub(l, c->a), ax) / len2 : 0;
            t = t < 0 ? 0 : (t > 1 ? 1 : t);
            d = v3_sub(l, v3_madd(c->a, ax, t));
        } else {
            d = v3_sub(l, c->a);
        }
        double r2 = c->radius * c->radius, d2 = v3_dot(d, d);
        if (d2 < r2) {
            double f = 1 - d2 / r2;
            sum += c->strength * f * f;
        }
    }
    return sum;
}

/* The curved and blobby shapes as an implicit function f (inside: f < 0). */
static double shape_f(const scene_object *o, vec3 q)
{
    switch (o->kind) {
    case SHAPE_LATHE: return lathe_inside_local(o, q) ? -1 : 1;
    case SHAPE_PRISM: return prism_inside_local(o, q) ? -1 : 1;
    default: return o->u.blob->threshold - blob_density(o->u.blob, q);
    }
}

static bbox leaf_box_local(const scene_object *o, vec3 *lo, vec3 *hi);

/* Normal of a marched hit in the object's space. */
static vec3 shape_normal(const scene_object *o, vec3 q, vec3 rd)
{
    vec3 n = v3(0, 0, 0);
    if (o->kind == SHAPE_BLOB) {
        double h = 1e-7;
        n = v3(shape_f(o, v3(q.x + h, q.y, q.z)) - shape_f(o, v3(q.x - h, q.y, q.z)),
               shape_f(o, v3(q.x, q.y + h, q.z)) - shape_f(o, v3(q.x, q.y - h, q.z)),
               shape_f(o, v3(q.x, q.y, q.z + h)) - shape_f(o, v3(q.x, q.y, q.z - h)));
    } else if (o->kind == SHAPE_PRISM) {
        const scene_prism *pr = o->u.prism;
        double h1 = fmin(pr->height1, pr->height2), h2 = fmax(pr->height1, pr->height2), tol = 1e-7 * (1 + fabs(h2 - h1));
        curve c = {NULL, 0};
        double nu = 0, nv = 0;
        double u = q.x, v = q.z, y = q.y;
        if (pr->conic && fabs(y) > 1e-10) {
            u /= y;
            v /= y;
        }
        if (fabs(q.y - h1) < tol) n = v3(0, -1, 0);
        else if (fabs(q.y - h2) < tol) n = v3(0, 1, 0);
        else if (prism_curve(pr, &c) && curve_normal(&c, u, v, &nu, &nv)) n = v3(nu, 0, nv);
        free(c.segs);
    } else {
        curve c = {NULL, 0};
        double r = sqrt(q.x * q.x + q.z * q.z), nr = 0, ny = 0;
        if (o->u.lathe && lathe_curve(o->u.lathe, &c) && r > 0) {
            /* the profile's normal, found at the crossing with the hit's height */
            double ur, uy;
            if (curve_normal(&c, r, q.y, &ur, &uy)) {
                nr = ur;
                ny = uy;
            }
        }
        free(c.segs);
        n = r > 0 ? v3(nr * q.x / r, ny, nr * q.z / r) : v3(0, ny, 0);
    }
    if (v3_len2(n) == 0) n = v3_neg(rd);
    n = v3_norm(n);
    /* outward: a small step along it leaves the solid */
    double eps = 1e-6 * (1 + v3_len(q));
    if (o->kind != SHAPE_BLOB && shape_f(o, v3_madd(q, n, eps)) < 0) n = v3_neg(n);
    return n;
}

/* March the ray through the shape's box with small steps, bisect each change
 * between inside and outside. */
static void shape_marched_hits(geom *g, const scene_object *o, vec3 org, vec3 dir, hit_list *l)
{
    vec3 ro, rd, lo, hi;
    local_ray(o, org, dir, &ro, &rd);
    bbox lb = leaf_box_local(o, &lo, &hi);
    (void)lb;
    double t0 = -INFINITY, t1 = INFINITY;
    for (int i = 0; i < 3; i++) {
        double d = v3_idx(rd, i), oo = v3_idx(ro, i), a = v3_idx(lo, i), b = v3_idx(hi, i);
        double pad = 1e-9 * (1 + fabs(b - a));
        a -= pad;
        b += pad;
        if (fabs(d) < 1e-300) {
            if (oo < a || oo > b) return;
            continue;
        }
        double ta = (a - oo) / d, tb = (b - oo) / d;
        if (ta > tb) { double t = ta; ta = tb; tb = t; }
        if (ta > t0) t0 = ta;
        if (tb < t1) t1 = tb;
    }
    if (t0 > t1) return;
    double diag = v3_len(v3_sub(hi, lo)), len = v3_len(rd);
    double step = diag / 4000;
    if (o->kind == SHAPE_BLOB) {
        double rmin = INFINITY;
        for (int i = 0; i < o->u.blob->ncomponents; i++) rmin = fmin(rmin, o->u.blob->components[i].radius);
        if (rmin < INFINITY) step = fmin(step, rmin / 16);
    }
    if (len <= 0 || step <= 0) return;
    long n = (long)ceil((t1 - t0) * len / step);
    if (n > 200000) n = 200000;
    if (n < 1) n = 1;
    double dt = (t1 - t0) / (double)n;
    double ta = t0, fa = shape_f(o, v3_madd(ro, rd, ta));
    for (long i = 1; i <= n; i++) {
        double tb = t0 + dt * (double)i, fb = shape_f(o, v3_madd(ro, rd, tb));
        if ((fa < 0) != (fb < 0)) {
            double a = ta, b = tb, va = fa;
            for (int k = 0; k < 100 && b - a > 1e-14 * (1 + fabs(a)); k++) {
                double m = 0.5 * (a + b), vm = shape_f(o, v3_madd(ro, rd, m));
                if ((vm < 0) == (va < 0)) { a = m; va = vm; } else b = m;
            }
            double t = 0.5 * (a + b);
            add_hit(g, l, t, world_normal(o, shape_normal(o, v3_madd(ro, rd, t), rd)), o);
        }
        ta = tb;
        fa = fb;
    }
}

/* ------------------------------------------------------------ isosurface */

/* function - threshold at q (inside: < 0); on a function the parse cannot
 * evaluate, g->unsupported says why. */
static double iso_f(geom *g, const scene_object *o, vec3 q)
{
    const scene_isosurface *iso = o->u.isosurface;
    double args[FUNC_MAX_SLOTS], out[5];
    memset(args, 0, sizeof args);
    args[0] = q.x;
    args[1] = q.y;
    args[2] = q.z;
    const char *why = NULL;
    if (func_eval(iso->fn, args, out, g->p->opt.func_env, &why) != PT_OK) {
        if (!g->unsupported) {
            char buf[160];
            snprintf(buf, sizeof buf, "isosurface (its function needs %s)", why ? why : "an evaluator");
            g->unsupported = sdl_strndup(g->p, buf, strlen(buf));
        }
        return 1;
    }
    return out[0] - iso->threshold;
}

static int iso_in_container(const scene_isosurface *iso, vec3 q)
{
    if (iso->sphere) {
        vec3 d = v3_sub(q, iso->c1);
        return v3_dot(d, d) <= iso->radius * iso->radius;
    }
    return q.x >= iso->c1.x && q.x <= iso->c2.x && q.y >= iso->c1.y && q.y <= iso->c2.y && q.z >= iso->c1.z && q.z <= iso->c2.z;
}

/* Entry and exit of the local ray through the container, with the
 * container's outward normals there. 0 if it misses. */
static int iso_span(const scene_isosurface *iso, vec3 ro, vec3 rd, double *t0, double *t1, vec3 *n0, vec3 *n1)
{
    if (iso->sphere) {
        vec3 oc = v3_sub(ro, iso->c1);
        double a = v3_dot(rd, rd), b = v3_dot(oc, rd), c = v3_dot(oc, oc) - iso->radius * iso->radius, disc = b * b - a * c;
        if (disc < 0 || a == 0) return 0;
        *t0 = (-b - sqrt(disc)) / a;
        *t1 = (-b + sqrt(disc)) / a;
        *n0 = v3_sub(v3_madd(ro, rd, *t0), iso->c1);
        *n1 = v3_sub(v3_madd(ro, rd, *t1), iso->c1);
        return 1;
    }
    *t0 = -INFINITY;
    *t1 = INFINITY;
    for (int i = 0; i < 3; i++) {
        double d = v3_idx(rd, i), o = v3_idx(ro, i), lo = v3_idx(iso->c1, i), hi = v3_idx(iso->c2, i);
        if (fabs(d) < 1e-300) {
            if (o < lo || o > hi) return 0;
            continue;
        }
        double ta = (lo - o) / d, tb = (hi - o) / d, sa = -1;
        if (ta > tb) {
            double t = ta;
            ta = tb;
            tb = t;
            sa = 1;
        }
        vec3 na = v3(i == 0 ? sa : 0, i == 1 ? sa : 0, i == 2 ? sa : 0);
        if (ta > *t0) { *t0 = ta; *n0 = na; }
        if (tb < *t1) { *t1 = tb; *n1 = v3_neg(na); }
    }
    return *t0 <= *t1 && isfinite(*t0) && isfinite(*t1);
}

/* March the ray through the container (at least 512 steps, none longer than
 * 1/1000 of the container), bisect every change of sign of the function;
 * where the function is below the threshold at the container's wall, the
 * wall is the surface (a closed isosurface). */
static void iso_hits(geom *g, const scene_object *o, vec3 org, vec3 dir, hit_list *l)
{
    const scene_isosurface *iso = o->u.isosurface;
    if (!iso || !iso->fn) return;
    vec3 ro, rd, n0 = v3(0, 0, 0), n1 = v3(0, 0, 0);
    local_ray(o, org, dir, &ro, &rd);
    double t0, t1;
    if (!iso_span(iso, ro, rd, &t0, &t1, &n0, &n1)) return;
    double diag = iso->sphere ? 2 * iso->radius : v3_len(v3_sub(iso->c2, iso->c1)), len = v3_len(rd);
    if (len <= 0) return;
    long n = (long)ceil((t1 - t0) * len / (diag / 1000));
    if (n < 512) n = 512;
    if (n > 100000) n = 100000;
    double dt = (t1 - t0) / (double)n, ta = t0, fa = iso_f(g, o, v3_madd(ro, rd, t0));
    if (fa < 0) add_hit(g, l, t0, world_normal(o, n0), o);
    for (long i = 1; i <= n && !g->unsupported; i++) {
        double tb = t0 + dt * (double)i, fb = iso_f(g, o, v3_madd(ro, rd, tb));
        if ((fa < 0) != (fb < 0)) {
            double a = ta, b = tb, va = fa;
            for (int k = 0; k < 100 && b - a > 1e-14 * (1 + fabs(a)); k++) {
                double m = 0.5 * (a + b), vm = iso_f(g, o, v3_madd(ro, rd, m));
                if ((vm < 0) == (va < 0)) { a = m; va = vm; } else b = m;
            }
            double t = 0.5 * (a + b);
            vec3 q = v3_madd(ro, rd, t);
            double h = 1e-6 * (1 + v3_len(q));
            vec3 grad = v3(iso_f(g, o, v3(q.x + h, q.y, q.z)) - iso_f(g, o, v3(q.x - h, q.y, q.z)),
                           iso_f(g, o, v3(q.x, q.y + h, q.z)) - iso_f(g, o, v3(q.x, q.y - h, q.z)),
                           iso_f(g, o, v3(q.x, q.y, q.z + h)) - iso_f(g, o, v3(q.x, q.y, q.z - h)));
            add_hit(g, l, t, world_normal(o, v3_len2(grad) > 0 ? grad : v3_neg(rd)), o);
        }
        ta = tb;
        fa = fb;
    }
    if (fa < 0) add_hit(g, l, t1, world_normal(o, n1), o);
}

/* ------------------------------------------------------------ the renderer's shapes */

/* Shapes without a parse-time intersector here are asked of the renderer's
 * (sdl_options.geom_env): each object is prepared once per parse. */
#define ENV_BUCKETS 256
#define ENV_MAX_HITS 256

typedef struct env_shape {
    const scene_object *o;
    void *sh;                   /* NULL: degenerate, no hits, never inside */
    struct env_shape *next;
} env_shape;

static int env_kind(shape_kind k)
{
    return k == SHAPE_SOR || k == SHAPE_POLY || k == SHAPE_TEXT || k == SHAPE_JULIA || k == SHAPE_POLYGON ||
           k == SHAPE_HEIGHT_FIELD;
}

/* The prepared shape of o; sets g->unsupported without an environment. */
static const env_shape *env_get(geom *g, const scene_object *o)
{
    const geom_env *env = g->p->opt.geom_env;
    if (!env) {
        if (!g->unsupported) g->unsupported = o->name ? o->name : "object";
        return NULL;
    }
    if (o->kind == SHAPE_HEIGHT_FIELD && (!o->u.height_field || !o->u.height_field->heights)) {
        /* kept without height data (e.g. height_field { function ... }):
         * no answer rather than a wrong one */
        if (!g->unsupported) g->unsupported = "height_field without height data";
        return NULL;
    }
    env_shape **tab = g->p->geom_shapes;
    if (!tab) {
        tab = calloc(ENV_BUCKETS, sizeof *tab);
        if (!tab) {
            g->nomem = 1;
            return NULL;
        }
        g->p->geom_shapes = tab;
    }
    size_t b = ((size_t)o >> 4) % ENV_BUCKETS;
    for (env_shape *e = tab[b]; e; e = e->next)
        if (e->o == o) return e;
    env_shape *e = calloc(1, sizeof *e);
    if (!e) {
        g->nomem = 1;
        return NULL;
    }
    int nomem = 0;
    e->o = o;
    e->sh = env->prepare(o, &nomem);
    if (nomem) g->nomem = 1;
    e->next = tab[b];
    tab[b] = e;
    return e;
}

static void env_hits(geom *g, const scene_object *o, vec3 org, vec3 dir, hit_list *l)
{
    const env_shape *e = env_get(g, o);
    if (!e || !e->sh) return;
    double t[ENV_MAX_HITS];
    vec3 n[ENV_MAX_HITS];
    /* from behind the origin too: CSG filters and inside tests count them */
    int k = g->p->opt.geom_env->hits(e->sh, org, dir, -INFINITY, INFINITY, t, n, ENV_MAX_HITS);
    for (int i = 0; i < k; i++) add_hit(g, l, t[i], n[i], o);
}

/* -1: cannot say */
static int env_inside(geom *g, const scene_object *o, vec3 pw)
{
    const env_shape *e = env_get(g, o);
    if (!e) return -1;
    return e->sh ? g->p->opt.geom_env->inside(e->sh, pw) != 0 : 0;
}

/* ------------------------------------------------------------ objects */

static int obj_inside(geom *g, const scene_object *o, vec3 p);
static void obj_hits(geom *g, const scene_object *o, vec3 org, vec3 dir, hit_list *l);

static int is_csg(const scene_object *o)
{
    return o->kind == SHAPE_UNION || o->kind == SHAPE_MERGE || o->kind == SHAPE_INTERSECTION || o->kind == SHAPE_DIFFERENCE;
}

/* Inside test of a leaf at q in its own space (pw in the world), before
 * `inverse`. -1: cannot. */
static int leaf_inside(geom *g, const scene_object *o, vec3 q, vec3 pw)
{
    if (env_kind(o->kind) && o->kind != SHAPE_POLYGON) return env_inside(g, o, pw);
    switch (o->kind) {
    case SHAPE_SPHERE: {
        vec3 d = v3_sub(q, o->u.sphere.centre);
        return v3_dot(d, d) < o->u.sphere.radius * o->u.sphere.radius;
    }
    case SHAPE_BOX:
        return q.x >= o->u.box.c1.x && q.x <= o->u.box.c2.x && q.y >= o->u.box.c1.y && q.y <= o->u.box.c2.y && q.z >= o->u.box.c1.z &&
               q.z <= o->u.box.c2.z;
    case SHAPE_PLANE: return v3_dot(o->u.plane.normal, q) < o->u.plane.offset;
    case SHAPE_CYLINDER: case SHAPE_CONE: return cone_inside(o, q);
    case SHAPE_TORUS: case SHAPE_SUPERELLIPSOID: case SHAPE_QUADRIC: return implicit_f(o, q) < 0;
    case SHAPE_DISC: case SHAPE_POLYGON: return 0;
    case SHAPE_LATHE: case SHAPE_PRISM: return shape_f(o, q) < 0;
    case SHAPE_ISOSURFACE: {
        if (!o->u.isosurface || !o->u.isosurface->fn) break;
        if (!iso_in_container(o->u.isosurface, q)) return 0;
        int in = iso_f(g, o, q) < 0;
        return g->unsupported ? -1 : in;
    }
    case SHAPE_BLOB: if (!o->u.blob) break; return shape_f(o, q) < 0;
    case SHAPE_MESH: {
        if (!o->u.mesh.inside_vector_set) break;
        /* parity of the crossings along inside_vector (POV-Ray's rule) */
        hit_list l = {NULL, 0, 0};
        vec3 wp = xform_point(&o->transform, q), wd = xform_vector(&o->transform, o->u.mesh.inside_vector);
        mesh_hits(g, o, wp, wd, &l);
        int c = 0;
        for (int i = 0; i < l.n; i++) c += l.h[i].t > DEPTH_TOLERANCE;
        free(l.h);
        return c & 1;
    }
    default: break;
    }
    if (!g->unsupported) g->unsupported = o->name ? o->name : "object";
    return -1;
}

/* Is world point p inside o? 1, 0, or -1 when the shape cannot say. */
static int obj_inside(geom *g, const scene_object *o, vec3 p)
{
    int in;
    if (is_csg(o)) {
        int n = o->u.csg.nkids;
        if (o->kind == SHAPE_UNION || o->kind == SHAPE_MERGE) {
            in = 0;
            for (int i = 0; i < n && !in; i++) {
                int k = obj_inside(g, o->u.csg.kids[i], p);
                if (k < 0) return -1;
                in = k;
            }
        } else {
            in = 1;
            for (int i = 0; i < n && in; i++) {
                int k = obj_inside(g, o->u.csg.kids[i], p);
                if (k < 0) return -1;
                in = o->kind == SHAPE_DIFFERENCE && i > 0 ? !k : k;
            }
        }
    } else {
        in = leaf_inside(g, o, xform_inv_point(&o->transform, p), p);
        if (in < 0) return -1;
    }
    if (o->flags & OBJ_INVERSE) in = !in;
    if (in && o->clip) {
        int c = obj_inside(g, o->clip, xform_inv_point(&o->transform, p));
        if (c < 0) return -1;
        in = c;
    }
    return in;
}

static void leaf_hits(geom *g, const scene_object *o, vec3 org, vec3 dir, hit_list *l)
{
    switch (o->kind) {
    case SHAPE_SPHERE: sphere_hits(g, o, org, dir, l); return;
    case SHAPE_BOX: box_hits(g, o, org, dir, l); return;
    case SHAPE_PLANE: plane_hits(g, o, org, dir, l); return;
    case SHAPE_TRIANGLE: case SHAPE_SMOOTH_TRIANGLE: triangle_hits(g, o, org, dir, l); return;
    case SHAPE_MESH: mesh_hits(g, o, org, dir, l); return;
    case SHAPE_CYLINDER: case SHAPE_CONE: cone_hits(g, o, org, dir, l); return;
    case SHAPE_DISC: disc_hits(g, o, org, dir, l); return;
    case SHAPE_QUADRIC: quadric_hits(g, o, org, dir, l); return;
    case SHAPE_TORUS: case SHAPE_SUPERELLIPSOID: marched_hits(g, o, org, dir, l); return;
    case SHAPE_LATHE: case SHAPE_PRISM: case SHAPE_BLOB:
        if (o->u.lathe) shape_marched_hits(g, o, org, dir, l); /* u.lathe/u.prism/u.blob share the slot */
        return;
    case SHAPE_ISOSURFACE: iso_hits(g, o, org, dir, l); return;
    case SHAPE_SOR: case SHAPE_POLY: case SHAPE_TEXT: case SHAPE_JULIA: case SHAPE_POLYGON: case SHAPE_HEIGHT_FIELD:
        env_hits(g, o, org, dir, l);
        return;
    default:
        if (!g->unsupported) g->unsupported = o->name ? o->name : "object";
        return;
    }
}

/* Keep the hits of member `i` of a CSG node that its siblings allow. */
static void csg_filter(geom *g, const scene_object *o, int i, vec3 org, vec3 dir, const hit_list *in, hit_list *out)
{
    for (int h = 0; h < in->n; h++) {
        vec3 p = v3_madd(org, dir, in->h[h].t);
        int keep = 1;
        for (int j = 0; j < o->u.csg.nkids && keep; j++) {
            if (j == i) continue;
            int k = obj_inside(g, o->u.csg.kids[j], p);
            if (k < 0) return;
            if (o->kind == SHAPE_MERGE) keep = !k;
            else if (o->kind == SHAPE_DIFFERENCE && j > 0) keep = !k;
            else if (o->kind != SHAPE_UNION) keep = k;
        }
        if (keep) add_hit(g, out, in->h[h].t, in->h[h].n, in->h[h].leaf);
    }
}

/* All intersections of the world ray with o (any t). */
static void obj_hits(geom *g, const scene_object *o, vec3 org, vec3 dir, hit_list *l)
{
    hit_list own = {NULL, 0, 0};
    if (is_csg(o)) {
        for (int i = 0; i < o->u.csg.nkids && !g->unsupported; i++) {
            hit_list kid = {NULL, 0, 0};
            obj_hits(g, o->u.csg.kids[i], org, dir, &kid);
            if (o->kind == SHAPE_DIFFERENCE && i > 0) /* POV-Ray inverts the subtracted members */
                for (int h = 0; h < kid.n; h++) kid.h[h].n = v3_neg(kid.h[h].n);
            if (o->kind == SHAPE_UNION) {
                for (int h = 0; h < kid.n; h++) add_hit(g, &own, kid.h[h].t, kid.h[h].n, kid.h[h].leaf);
            } else {
                csg_filter(g, o, i, org, dir, &kid, &own);
            }
            free(kid.h);
        }
    } else {
        leaf_hits(g, o, org, dir, &own);
    }
    for (int h = 0; h < own.n; h++) {
        if (o->clip) {
            int c = obj_inside(g, o->clip, xform_inv_point(&o->transform, v3_madd(org, dir, own.h[h].t)));
            if (c <= 0) continue;
        }
        add_hit(g, l, own.h[h].t, own.h[h].n, own.h[h].leaf);
    }
    free(own.h);
}

/* ------------------------------------------------------------ bounding boxes */

static bbox box_of(vec3 lo, vec3 hi)
{
    bbox b = {lo, hi};
    return b;
}

static bbox huge_box(void) { return box_of(v3s(-BOUND_HUGE / 2), v3s(BOUND_HUGE / 2)); }

/* The box [lo, hi] of some space mapped by x, corner by corner. */
static bbox transformed_box(const xform *x, vec3 lo, vec3 hi)
{
    vec3 a = v3s(INFINITY), b = v3s(-INFINITY);
    for (int c = 0; c < 8; c++) {
        vec3 p = v3(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
        vec3 q = xform_point(x, p);
        a = v3_min(a, q);
        b = v3_max(b, q);
    }
    return box_of(a, b);
}

/* POV-Ray's frame for cylinders, cones and discs: scale (r, r, len), rotate
 * z onto the axis about z x axis, move to the origin. */
static xform axis_frame(vec3 origin, vec3 up, double radius, double length)
{
    xform x = xform_scale(v3(radius, radius, length));
    vec3 k;
    double angle;
    if (fabs(up.z) > 1.0 - 1e-10) {
        k = v3(1, 0, 0);
        angle = up.z < 0 ? M_PI : 0;
    } else {
        k = v3_norm(v3(-up.y, up.x, 0));
        angle = acos(up.z);
    }
    double c = cos(angle), s = sin(angle), m[12];
    /* rotation about unit k by angle taking z to up (Rodrigues), row-vector layout */
    double r[3][3];
    double kk[3] = {k.x, k.y, k.z};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) r[i][j] = (i == j ? c : 0) + (1 - c) * kk[i] * kk[j];
    r[0][1] -= s * kk[2]; r[0][2] += s * kk[1];
    r[1][0] += s * kk[2]; r[1][2] -= s * kk[0];
    r[2][0] -= s * kk[1]; r[2][1] += s * kk[0];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) m[i * 3 + j] = r[j][i]; /* p' = p * M: rows are the images of the axes */
    m[9] = m[10] = m[11] = 0;
    x = xform_then(x, xform_matrix(m));
    return xform_then(x, xform_translate(origin));
}

/* A transform whose linear part is a rotation times a uniform scale? */
static int is_similarity(const xform *x, double *scale)
{
    vec3 c[3];
    for (int j = 0; j < 3; j++) c[j] = v3(x->m[0][j], x->m[1][j], x->m[2][j]);
    double s = v3_len(c[0]);
    for (int j = 0; j < 3; j++)
        if (fabs(v3_len(c[j]) - s) > 1e-12 * (1 + s)) return 0;
    if (fabs(v3_dot(c[0], c[1])) > 1e-12 * (1 + s * s) || fabs(v3_dot(c[0], c[2])) > 1e-12 * (1 + s * s) ||
        fabs(v3_dot(c[1], c[2])) > 1e-12 * (1 + s * s))
        return 0;
    *scale = s;
    return 1;
}

static bbox cone_box(const scene_object *o)
{
    cone_frame f = cone_of(o);
    vec3 base = o->u.cone.base, cap = o->u.cone.cap, w = f.w;
    double rb = f.r0, rc = f.r1, len = f.len, dist = 0;
    xform frame;
    if (fabs(rc - rb) < 1e-10 || len <= 0) {
        frame = axis_frame(base, w, rc, len);
    } else {
        if (rc < rb) { /* bigger end on top, as POV-Ray orders it */
            vec3 t = base;
            base = cap;
            cap = t;
            double r = rb;
            rb = rc;
            rc = r;
            w = v3_neg(w);
        }
        double lead = rb * len / (rc - rb), total = lead + len;
        dist = lead / total;
        frame = axis_frame(v3_madd(base, w, -lead), w, rc, total);
    }
    xform full = xform_then(frame, o->transform);
    return transformed_box(&full, v3(-1, -1, dist), v3(1, 1, 1));
}

static bbox points_box(const xform *x, const vec3 *pts, int n)
{
    vec3 lo = v3s(INFINITY), hi = v3s(-INFINITY);
    for (int i = 0; i < n; i++) {
        lo = v3_min(lo, pts[i]);
        hi = v3_max(hi, pts[i]);
    }
    if (n == 0) lo = hi = v3s(0);
    return transformed_box(x, lo, hi);
}

/* A plane's limits inside an intersection: an axis-aligned plane bounds one
 * side of the box (POV-Ray's Compute_Plane_Min_Max). */
static bbox plane_limits(const scene_object *o)
{
    bbox b = huge_box();
    vec3 n = v3_norm(xform_normal(&o->transform, o->u.plane.normal));
    double d = v3_dot(n, xform_point(&o->transform, v3_scale(o->u.plane.normal, o->u.plane.offset)));
    double e = 1e-10;
    if (fabs(n.y) < e && fabs(n.z) < e) { if (n.x > 0) b.hi.x = d; else b.lo.x = -d; }
    if (fabs(n.x) < e && fabs(n.z) < e) { if (n.y > 0) b.hi.y = d; else b.lo.y = -d; }
    if (fabs(n.x) < e && fabs(n.y) < e) { if (n.z > 0) b.hi.z = d; else b.lo.z = -d; }
    return b;
}

static bbox obj_box(geom *g, const scene_object *o);

static bbox csg_box(geom *g, const scene_object *o)
{
    int isect = o->kind == SHAPE_INTERSECTION || o->kind == SHAPE_DIFFERENCE;
    bbox b = isect ? box_of(v3s(-BOUND_HUGE), v3s(BOUND_HUGE)) : box_of(v3s(BOUND_HUGE), v3s(-BOUND_HUGE));
    for (int i = 0; i < o->u.csg.nkids; i++) {
        const scene_object *k = o->u.csg.kids[i];
        if (isect) {
            /* inverted members (difference's later ones) and height fields do not bound */
            int inverted = ((k->flags & OBJ_INVERSE) != 0) != (o->kind == SHAPE_DIFFERENCE && i > 0);
            if (inverted || k->kind == SHAPE_HEIGHT_FIELD) continue;
            bbox kb = k->kind == SHAPE_PLANE ? plane_limits(k) : obj_box(g, k);
            b.lo = v3_max(b.lo, kb.lo);
            b.hi = v3_min(b.hi, kb.hi);
        } else {
            bbox kb = obj_box(g, k);
            b.lo = v3_min(b.lo, kb.lo);
            b.hi = v3_max(b.hi, kb.hi);
        }
    }
    if (b.lo.x > b.hi.x || b.lo.y > b.hi.y || b.lo.z > b.hi.z) return huge_box(); /* degenerate: not used */
    vec3 len = v3_sub(b.hi, b.lo);
    if (len.x > CRITICAL_LENGTH || len.y > CRITICAL_LENGTH || len.z > CRITICAL_LENGTH) return huge_box();
    return b;
}

static bbox leaf_box(geom *g, const scene_object *o)
{
    const xform *x = &o->transform;
    switch (o->kind) {
    case SHAPE_SPHERE: {
        double s, r = o->u.sphere.radius;
        vec3 c = o->u.sphere.centre;
        if (is_similarity(x, &s)) {
            vec3 wc = xform_point(x, c);
            return box_of(v3_sub(wc, v3s(r * s)), v3_add(wc, v3s(r * s)));
        }
        return transformed_box(x, v3_sub(c, v3s(r)), v3_add(c, v3s(r)));
    }
    case SHAPE_BOX: return transformed_box(x, o->u.box.c1, o->u.box.c2);
    case SHAPE_PLANE: return huge_box();
    case SHAPE_TRIANGLE: case SHAPE_SMOOTH_TRIANGLE: {
        vec3 lo = v3s(INFINITY), hi = v3s(-INFINITY);
        for (int i = 0; i < 3; i++) {
            vec3 w = xform_point(x, o->u.triangle.v[i]);
            lo = v3_min(lo, w);
            hi = v3_max(hi, w);
        }
        return box_of(v3_sub(lo, v3s(1e-10)), v3_add(hi, v3s(1e-10)));
    }
    case SHAPE_MESH: {
        const scene_mesh *m = o->u.mesh.mesh;
        vec3 lo = v3s(INFINITY), hi = v3s(-INFINITY);
        for (int i = 0; m && i < m->nverts; i++) {
            lo = v3_min(lo, mesh_vert(m, i));
            hi = v3_max(hi, mesh_vert(m, i));
        }
        if (!m || m->nverts == 0) lo = hi = v3s(0);
        return transformed_box(x, lo, hi);
    }
    case SHAPE_CYLINDER: case SHAPE_CONE: return cone_box(o);
    case SHAPE_DISC: {
        vec3 n = v3_norm(o->u.disc.normal);
        xform f = xform_then(axis_frame(o->u.disc.centre, n, 1, 1), *x);
        double r = o->u.disc.radius;
        return transformed_box(&f, v3(-r, -r, -SMALL_TOLERANCE), v3(r, r, SMALL_TOLERANCE));
    }
    case SHAPE_TORUS: {
        double R = o->u.torus.major + o->u.torus.minor, r = o->u.torus.minor;
        return transformed_box(x, v3(-R, -r, -R), v3(R, r, R));
    }
    case SHAPE_SUPERELLIPSOID: return transformed_box(x, v3s(-1), v3s(1));
    case SHAPE_POLYGON: return o->u.polygon ? points_box(x, o->u.polygon->points, o->u.polygon->npoints) : huge_box();
    case SHAPE_LATHE: {
        vec3 lo, hi;
        leaf_box_local(o, &lo, &hi);
        return transformed_box(x, lo, hi);
    }
    case SHAPE_SOR: {
        const scene_lathe *la = o->u.lathe;
        double rmax = 0, ylo = INFINITY, yhi = -INFINITY;
        for (int i = 0; la && i < la->npoints; i++) {
            rmax = fmax(rmax, fabs(la->points[i][0]));
            ylo = fmin(ylo, la->points[i][1]);
            yhi = fmax(yhi, la->points[i][1]);
        }
        if (!la || la->npoints == 0) return huge_box();
        return transformed_box(x, v3(-rmax, ylo, -rmax), v3(rmax, yhi, rmax));
    }
    case SHAPE_PRISM: {
        const scene_prism *pr = o->u.prism;
        if (!pr || pr->npoints == 0) return huge_box();
        double xl = INFINITY, xh = -INFINITY, zl = INFINITY, zh = -INFINITY;
        for (int i = 0; i < pr->npoints; i++) {
            xl = fmin(xl, pr->points[i][0]);
            xh = fmax(xh, pr->points[i][0]);
            zl = fmin(zl, pr->points[i][1]);
            zh = fmax(zh, pr->points[i][1]);
        }
        double y0 = fmin(pr->height1, pr->height2), y1 = fmax(pr->height1, pr->height2);
        if (pr->conic) { /* the profile is scaled by y */
            double s = fmax(fabs(y0), fabs(y1));
            xl = fmin(xl * s, 0); xh = fmax(xh * s, 0); zl = fmin(zl * s, 0); zh = fmax(zh * s, 0);
        }
        return transformed_box(x, v3(xl, y0, zl), v3(xh, y1, zh));
    }
    case SHAPE_BLOB: {
        const scene_blob *bl = o->u.blob;
        vec3 lo = v3s(INFINITY), hi = v3s(-INFINITY);
        for (int i = 0; bl && i < bl->ncomponents; i++) {
            const scene_blob_component *c = &bl->components[i];
            vec3 a = c->a, b2 = c->cylinder ? c->b : c->a;
            bbox cb = transformed_box(&c->transform, v3_sub(v3_min(a, b2), v3s(c->radius)), v3_add(v3_max(a, b2), v3s(c->radius)));
            lo = v3_min(lo, cb.lo);
            hi = v3_max(hi, cb.hi);
        }
        if (!bl || bl->ncomponents == 0) return huge_box();
        return transformed_box(x, lo, hi);
    }
    case SHAPE_HEIGHT_FIELD: {
        const scene_height_field *h = o->u.height_field;
        double lo = 1, hi = 0;
        for (long i = 0; h && i < (long)h->width * h->height; i++) {
            lo = fmin(lo, h->heights[i]);
            hi = fmax(hi, h->heights[i]);
        }
        if (!h || lo > hi) lo = hi = 0;
        return transformed_box(x, v3(0, lo, 0), v3(1, hi, 1));
    }
    case SHAPE_TEXT: {
        const scene_text *t = o->u.text;
        double xl = INFINITY, xh = -INFINITY, yl = INFINITY, yh = -INFINITY;
        for (int i = 0; t && i < t->nsegments; i++)
            for (int k = 0; k < 4; k++) {
                xl = fmin(xl, t->segments[i][2 * k]);
                xh = fmax(xh, t->segments[i][2 * k]);
                yl = fmin(yl, t->segments[i][2 * k + 1]);
                yh = fmax(yh, t->segments[i][2 * k + 1]);
            }
        if (!t || t->nsegments == 0) return transformed_box(x, v3s(0), v3s(0));
        return transformed_box(x, v3(xl, yl, 0), v3(xh, yh, t->depth));
    }
    case SHAPE_QUADRIC: case SHAPE_POLY: return huge_box();
    case SHAPE_ISOSURFACE: {
        const scene_isosurface *iso = o->u.isosurface;
        if (!iso) return huge_box();
        if (iso->sphere) {
            double r = iso->radius;
            return transformed_box(x, v3_sub(iso->c1, v3s(r)), v3_add(iso->c1, v3s(r)));
        }
        return transformed_box(x, iso->c1, iso->c2);
    }
    default:
        if (!g->unsupported) g->unsupported = o->name ? o->name : "object";
        return huge_box();
    }
}

static bbox obj_box(geom *g, const scene_object *o)
{
    bbox b = is_csg(o) ? csg_box(g, o) : leaf_box(g, o);
    if (o->clip && !(o->flags & OBJ_INVERSE)) {
        /* a clipped object is bounded by its clipping solid too */
        scene_object c = *o->clip;
        c.transform = xform_then(o->clip->transform, o->transform);
        if (!is_csg(&c)) {
            bbox cb = obj_box(g, &c);
            bbox in = {v3_max(b.lo, cb.lo), v3_min(b.hi, cb.hi)};
            if (in.lo.x <= in.hi.x && in.lo.y <= in.hi.y && in.lo.z <= in.hi.z) b = in;
        }
    }
    return b;
}

/* ------------------------------------------------------------ built-ins */

/* object_param := object identifier (a declared object, not a bare light) */
static const scene_object *object_param(sdl_parser *p, const char *fn)
{
    sdl_tok t = sdl_next(p);
    if (t.tk.kind == TOK_IDENT && t.val.kind == VAL_OBJECT && t.val.ptr && ((const sdl_obj *)t.val.ptr)->obj)
        return ((const sdl_obj *)t.val.ptr)->obj;
    char what[64];
    snprintf(what, sizeof what, "object identifier in %s", fn);
    sdl_unexpected(p, &t, what);
    return NULL;
}

static void unsupported(sdl_parser *p, src_loc loc, const char *fn, const geom *g)
{
    if (g->nomem) sdl_error(p, loc, PT_ERR_NOMEM, "out of memory");
    else sdl_error(p, loc, PT_ERR_UNSUPPORTED, "%s: shape '%s' is not supported by the parse-time geometry", fn, g->unsupported);
}

vec3 sdl_trace_fn(sdl_parser *p, src_loc loc)
{
    vec3 res = v3(0, 0, 0), normal = v3(0, 0, 0);
    sdl_expect(p, TOK_LPAREN, "'('");
    const scene_object *o = object_param(p, "trace");
    sdl_accept(p, TOK_COMMA);
    vec3 org = sdl_vector(p);
    sdl_accept(p, TOK_COMMA);
    src_loc dloc = sdl_peek(p)->tk.loc;
    vec3 dir = sdl_vector(p);
    if (!sdl_ok(p) || !o) return res;
    if (v3_len2(dir) == 0) {
        sdl_error(p, dloc, PT_ERR_SYNTAX, "trace direction has zero length");
        return res;
    }
    dir = v3_norm(dir);
    geom g = {p, NULL, 0};
    hit_list l = {NULL, 0, 0};
    obj_hits(&g, o, org, dir, &l);
    if (g.unsupported || g.nomem) {
        free(l.h);
        unsupported(p, loc, "trace", &g);
        return res;
    }
    int best = -1;
    for (int i = 0; i < l.n; i++)
        if (l.h[i].t > DEPTH_TOLERANCE && (best < 0 || l.h[i].t < l.h[best].t)) best = i;
    if (best >= 0) {
        res = v3_madd(org, dir, l.h[best].t);
        normal = l.h[best].n;
        if (l.h[best].leaf->flags & OBJ_INVERSE) normal = v3_neg(normal);
    }
    free(l.h);
    if (sdl_accept(p, TOK_COMMA) && !sdl_is(sdl_peek(p), TOK_RPAREN)) {
        p->hold_arrays++;
        sdl_tok id = sdl_next(p);
        p->hold_arrays--;
        if (id.tk.kind != TOK_IDENT || id.val.kind != VAL_VECTOR || id.val.dim != 3) {
            sdl_error(p, id.tk.loc, PT_ERR_SYNTAX, "trace's fourth argument must be a declared vector identifier (it receives the normal)");
            return res;
        }
        sdl_value v = id.val;
        v.v[0] = normal.x;
        v.v[1] = normal.y;
        v.v[2] = normal.z;
        sdl_symtarget tg = sdl_symtab_target(p->sym, id.tk.text, (size_t)id.tk.len, 0);
        if (sdl_symtab_assign(p->sym, &tg, id.tk.text, (size_t)id.tk.len, &v) == 0) sdl_error(p, id.tk.loc, PT_ERR_NOMEM, "out of memory");
    }
    sdl_expect(p, TOK_RPAREN, "')'");
    return res;
}

/* Patch objects have no inside (POV-Ray: "Solid object identifier expected"). */
static int is_patch(const scene_object *o)
{
    return o->kind == SHAPE_TRIANGLE || o->kind == SHAPE_SMOOTH_TRIANGLE || (o->kind == SHAPE_MESH && !o->u.mesh.inside_vector_set);
}

double sdl_inside_fn(sdl_parser *p, src_loc loc)
{
    sdl_expect(p, TOK_LPAREN, "'('");
    src_loc oloc = sdl_peek(p)->tk.loc;
    const scene_object *o = object_param(p, "inside");
    sdl_accept(p, TOK_COMMA);
    vec3 pt = sdl_vector(p);
    sdl_expect(p, TOK_RPAREN, "')'");
    if (!sdl_ok(p) || !o) return 0;
    if (is_patch(o)) {
        sdl_error(p, oloc, PT_ERR_SYNTAX, "inside needs a solid object; a %s has no inside (a mesh needs inside_vector)", o->name ? o->name : "patch");
        return 0;
    }
    geom g = {p, NULL, 0};
    int in = obj_inside(&g, o, pt);
    if (in < 0 || g.nomem) {
        unsupported(p, loc, "inside", &g);
        return 0;
    }
    return in;
}

vec3 sdl_extent_fn(sdl_parser *p, src_loc loc, int max)
{
    const char *fn = max ? "max_extent" : "min_extent";
    sdl_expect(p, TOK_LPAREN, "'('");
    const sdl_tok *t = sdl_peek(p);
    if (max && t->tk.kind == TOK_IDENT && t->val.kind == VAL_PIGMENT) {
        sdl_error(p, t->tk.loc, PT_ERR_UNSUPPORTED, "max_extent of an image_map pigment (the image size) is not supported at parse time");
        return v3(0, 0, 0);
    }
    const scene_object *o = object_param(p, fn);
    sdl_expect(p, TOK_RPAREN, "')'");
    if (!sdl_ok(p) || !o) return v3(0, 0, 0);
    geom g = {p, NULL, 0};
    bbox b = obj_box(&g, o);
    if (g.unsupported) {
        unsupported(p, loc, fn, &g);
        return v3(0, 0, 0);
    }
    return max ? b.hi : b.lo;
}

void sdl_geom_free(sdl_parser *p)
{
    mesh_bvh *h = p->geom_cache;
    while (h) {
        mesh_bvh *n = h->next;
        free(h->nodes);
        free(h->order);
        free(h);
        h = n;
    }
    p->geom_cache = NULL;
    env_shape **tab = p->geom_shapes;
    if (tab) {
        for (int b = 0; b < ENV_BUCKETS; b++) {
            env_shape *e = tab[b];
            while (e) {
                env_shape *n = e->next;
                if (e->sh) p->opt.geom_env->release(e->sh);
                free(e);
                e = n;
            }
        }
        free(tab);
    }
    p->geom_shapes = NULL;
}

/* Boxes in the shape's own space for the marched shapes (lathe: POV-Ray's
 * bounding cylinder from the segments' extremes). */
static bbox leaf_box_local(const scene_object *o, vec3 *lo, vec3 *hi)
{
    *lo = v3s(-1);
    *hi = v3s(1);
    if (o->kind == SHAPE_LATHE && o->u.lathe) {
        curve c = {NULL, 0};
        double rmax = 0, ylo = INFINITY, yhi = -INFINITY;
        if (lathe_curve(o->u.lathe, &c)) {
            for (int i = 0; i < c.n; i++) {
                const curve_seg *s = &c.segs[i];
                double ws[4] = {0, 1, -1, -1};
                for (int k = 0; k < 2; k++) { /* extremes where the derivative vanishes */
                    double qa = 3 * s->a[k], qb = 2 * s->b[k], qc = s->c[k];
                    double cand[2];
                    int nc = 0;
                    if (fabs(qa) > 1e-300) {
                        double disc = qb * qb - 4 * qa * qc;
                        if (disc >= 0) {
                            cand[nc++] = (-qb - sqrt(disc)) / (2 * qa);
                            cand[nc++] = (-qb + sqrt(disc)) / (2 * qa);
                        }
                    } else if (fabs(qb) > 1e-300) {
                        cand[nc++] = -qc / qb;
                    }
                    for (int j = 0; j < nc; j++) ws[2 + j] = cand[j];
                    for (int j = 0; j < 4; j++) {
                        double w = ws[j];
                        if (w < 0 || w > 1) continue;
                        if (k == 0) rmax = fmax(rmax, fabs(seg_at(s, 0, w)));
                        else {
                            ylo = fmin(ylo, seg_at(s, 1, w));
                            yhi = fmax(yhi, seg_at(s, 1, w));
                        }
                    }
                    ws[2] = ws[3] = -1;
                }
            }
            free(c.segs);
            if (o->u.lathe->spline == SPLINE_BEZIER) /* POV-Ray bounds a bezier segment by its 4 points */
                for (int i = 0; i < c.n * 4 && i < o->u.lathe->npoints; i++) {
                    rmax = fmax(rmax, fabs(o->u.lathe->points[i][0]));
                    ylo = fmin(ylo, o->u.lathe->points[i][1]);
                    yhi = fmax(yhi, o->u.lathe->points[i][1]);
                }
        }
        if (ylo > yhi) ylo = yhi = 0;
        *lo = v3(-rmax, ylo, -rmax);
        *hi = v3(rmax, yhi, rmax);
    } else if (o->kind == SHAPE_PRISM && o->u.prism) {
        const scene_prism *pr = o->u.prism;
        double xl = INFINITY, xh = -INFINITY, zl = INFINITY, zh = -INFINITY;
        for (int i = 0; i < pr->npoints; i++) {
            xl = fmin(xl, pr->points[i][0]);
            xh = fmax(xh, pr->points[i][0]);
            zl = fmin(zl, pr->points[i][1]);
            zh = fmax(zh, pr->points[i][1]);
        }
        double y0 = fmin(pr->height1, pr->height2), y1 = fmax(pr->height1, pr->height2);
        if (pr->conic) {
            double s = fmax(fabs(y0), fabs(y1));
            xl = fmin(xl * s, 0);
            xh = fmax(xh * s, 0);
            zl = fmin(zl * s, 0);
            zh = fmax(zh * s, 0);
        }
        *lo = v3(xl, y0, zl);
        *hi = v3(xh, y1, zh);
    } else if (o->kind == SHAPE_BLOB && o->u.blob) {
        *lo = v3s(INFINITY);
        *hi = v3s(-INFINITY);
        for (int i = 0; i < o->u.blob->ncomponents; i++) {
            const scene_blob_component *c = &o->u.blob->components[i];
            vec3 b2 = c->cylinder ? c->b : c->a;
            bbox cb = transformed_box(&c->transform, v3_sub(v3_min(c->a, b2), v3s(c->radius)), v3_add(v3_max(c->a, b2), v3s(c->radius)));
            *lo = v3_min(*lo, cb.lo);
            *hi = v3_max(*hi, cb.hi);
        }
        if (o->u.blob->ncomponents == 0) *lo = *hi = v3s(0);
    }
    return box_of(*lo, *hi);
}
