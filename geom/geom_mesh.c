/* geom_mesh.c - meshes as geom shapes (see geom_mesh.h): a median-split BVH
 * over the triangles' boxes, built once per shape. */
#include "geom_mesh.h"
#include "geom_bvh.h"
#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MESH_LEAF 4
/* POV-Ray's shapes ignore crossings closer than this (DEPTH_TOLERANCE):
 * the inside_vector parity starts just off the point. */
#define MESH_DEPTH_TOLERANCE 1e-6

typedef struct {
    const scene_mesh *m;
    vec3 inside_vector;
    int has_inside;
    geom_bvh bvh; /* over the triangles' boxes */
} mesh_data;

static vec3 vert(const scene_mesh *m, int i) { return v3(m->verts[i][0], m->verts[i][1], m->verts[i][2]); }

static void tri_box(const scene_mesh *m, int t, vec3 *lo, vec3 *hi)
{
    vec3 a = vert(m, m->tris[t][0]), b = vert(m, m->tris[t][1]), c = vert(m, m->tris[t][2]);
    *lo = v3_min(a, v3_min(b, c));
    *hi = v3_max(a, v3_max(b, c));
}

void geom_mesh_free(void *data)
{
    mesh_data *md = data;
    if (!md) return;
    geom_bvh_free(&md->bvh);
    free(md);
}

int geom_mesh_init(geom_shape *sh, const scene_object *o)
{
    const scene_mesh *m = o->u.mesh.mesh;
    if (!m || m->ntris <= 0) return -1;
    for (int t = 0; t < m->ntris; t++)
        for (int k = 0; k < 3; k++)
            if (m->tris[t][k] < 0 || m->tris[t][k] >= m->nverts) return -1;
    mesh_data *md = calloc(1, sizeof *md);
    if (!md) return -1;
    md->m = m;
    md->has_inside = o->u.mesh.inside_vector_set;
    md->inside_vector = o->u.mesh.inside_vector;
    vec3 *tlo = malloc(sizeof *tlo * (size_t)m->ntris), *thi = malloc(sizeof *thi * (size_t)m->ntris);
    vec3 lo = v3s(INFINITY), hi = v3s(-INFINITY);
    int ok = tlo && thi;
    for (int i = 0; ok && i < m->ntris; i++) {
        tri_box(m, i, &tlo[i], &thi[i]);
        lo = v3_min(lo, tlo[i]);
        hi = v3_max(hi, thi[i]);
    }
    ok = ok && v3_finite(lo) && v3_finite(hi) && geom_bvh_build(&md->bvh, m->ntris, tlo, thi, MESH_LEAF) == 0;
    free(tlo);
    free(thi);
    if (!ok) {
        geom_mesh_free(md);
        return -1;
    }
    sh->data = md;
    sh->olo = lo;
    sh->ohi = hi;
    return 0;
}

/* Moller-Trumbore in double precision; barycentrics of v1 and v2 in *u, *v. */
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

typedef struct {
    const scene_mesh *m;
    vec3 o, d;
    double tmin, tmax;
    geom_shape_hit *out;
    int max, n;
} mesh_query;

static void mesh_visit(void *ctx, int t)
{
    mesh_query *q = ctx;
    const scene_mesh *m = q->m;
    assert(t >= 0 && t < m->ntris);
    double tt, u, v;
    if (tri_hit(q->o, q->d, vert(m, m->tris[t][0]), vert(m, m->tris[t][1]), vert(m, m->tris[t][2]), &tt, &u, &v) &&
        tt > q->tmin && tt < q->tmax)
        q->n = geom_shape_hit_put(q->out, q->n, q->max, tt, t);
}

int geom_mesh_hits(const geom_shape *sh, vec3 o, vec3 d, double tmin, double tmax, geom_shape_hit *out, int max)
{
    const mesh_data *md = sh->data;
    if (!md) return 0;
    mesh_query q = {md->m, o, d, tmin, tmax, out, max, 0};
    geom_bvh_ray(&md->bvh, o, d, tmin, tmax, mesh_visit, &q);
    return q.n;
}

int geom_mesh_inside(const geom_shape *sh, vec3 q)
{
    const mesh_data *md = sh->data;
    if (!md || !md->has_inside) return 0;
    geom_shape_hit h[64];
    int crossings = 0;
    double from = MESH_DEPTH_TOLERANCE;
    /* walk the crossings a chunk at a time: the parity needs them all */
    for (;;) {
        int k = geom_mesh_hits(sh, q, md->inside_vector, from, INFINITY, h, 64);
        crossings += k;
        if (k < 64 || !(h[k - 1].t > from)) break;
        from = h[k - 1].t;
    }
    return crossings & 1;
}

vec3 geom_mesh_normal(const geom_shape *sh, vec3 q, int part)
{
    const mesh_data *md = sh->data;
    const scene_mesh *m = md->m;
    assert(part >= 0 && part < m->ntris);
    vec3 a = vert(m, m->tris[part][0]), b = vert(m, m->tris[part][1]), c = vert(m, m->tris[part][2]);
    vec3 n = v3_cross(v3_sub(c, a), v3_sub(b, a)); /* POV-Ray's mesh triangle normal */
    /* normals per corner (tri_normals), or per vertex when there are as many
     * (bicubic_patch meshes), as the renderer reads them */
    const int *ni = m->normals ? (m->tri_normals ? m->tri_normals[part] : (m->nnormals == m->nverts ? m->tris[part] : NULL)) : NULL;
    if (ni) {
        /* barycentrics of q in the triangle's plane */
        vec3 e1 = v3_sub(b, a), e2 = v3_sub(c, a), w = v3_sub(q, a);
        double d11 = v3_dot(e1, e1), d12 = v3_dot(e1, e2), d22 = v3_dot(e2, e2), w1 = v3_dot(w, e1), w2 = v3_dot(w, e2);
        double den = d11 * d22 - d12 * d12, u = 0, v = 0;
        if (den != 0) {
            u = (d22 * w1 - d12 * w2) / den;
            v = (d11 * w2 - d12 * w1) / den;
        }
        vec3 s = v3(0, 0, 0);
        double wt[3] = {1 - u - v, u, v};
        for (int i = 0; i < 3; i++)
            if (ni[i] >= 0 && ni[i] < m->nnormals) /* POV-Ray keeps mesh normals normalised */
                s = v3_madd(s, v3_norm(v3(m->normals[ni[i]][0], m->normals[ni[i]][1], m->normals[ni[i]][2])), wt[i]);
        if (v3_len2(s) > 0) n = s;
    }
    return n;
}

/* Barycentrics of the point at t along the edge from vertex i to vertex j
 * (t = 0: vertex i itself). */
static void edge_point(double w[3], int i, int j, double t)
{
    w[0] = w[1] = w[2] = 0.0;
    w[i] = 1.0 - t;
    w[j] = t;
}

/* Ericson, Real-Time Collision Detection, 2005, 5.1.5: the Voronoi regions
 * of the vertices, then of the edges, then the face. */
double geom_tri_closest(vec3 q, vec3 a, vec3 b, vec3 c, double w[3])
{
    vec3 ab = v3_sub(b, a), ac = v3_sub(c, a), ap = v3_sub(q, a);
    double d1 = v3_dot(ab, ap), d2 = v3_dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) { edge_point(w, 0, 1, 0.0); goto out; }
    vec3 bp = v3_sub(q, b);
    double d3 = v3_dot(ab, bp), d4 = v3_dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) { edge_point(w, 1, 2, 0.0); goto out; }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) { edge_point(w, 0, 1, d1 / (d1 - d3)); goto out; }
    vec3 cp = v3_sub(q, c);
    double d5 = v3_dot(ab, cp), d6 = v3_dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) { edge_point(w, 2, 0, 0.0); goto out; }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) { edge_point(w, 0, 2, d2 / (d2 - d6)); goto out; }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        edge_point(w, 1, 2, (d4 - d3) / ((d4 - d3) + (d5 - d6)));
        goto out;
    }
    {
        double den = va + vb + vc;
        if (!(fabs(den) > 0.0)) { edge_point(w, 0, 1, 0.0); goto out; }
        w[1] = vb / den;
        w[2] = vc / den;
        w[0] = 1.0 - w[1] - w[2];
    }
out:;
    vec3 r = v3_add(v3_add(v3_scale(a, w[0]), v3_scale(b, w[1])), v3_scale(c, w[2]));
    return v3_len2(v3_sub(q, r));
}
