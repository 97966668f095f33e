/* gi_vlinks.c - vertex links (see gi_vlinks.h).
 *
 * Per frame:
 *  1. leaves and meshes (core/scene_leaves.h): every mesh leaf's vertices
 *     become elements; top-level objects whose hash changed moved;
 *  2. vertex positions and normals of the meshes (all on a full frame,
 *     the moved ones otherwise), and each element's reflectance;
 *  3. links of the elements that need them (all; or those of moved meshes
 *     and those with a ray that ended on a moved object or now meets one):
 *     n_C rays, three links a hit on a mesh, merged per peer;
 *  4. light links (every element, every light: a shadow ray);
 *  5. gathering sweeps and smoothing (gi_vlinks.cl). */
#include "gi_vlinks.h"
#include <embree3/rtcore.h>
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include "gi_particle_internal.h"
#include "grow.h"
#include "hash.h"
#include "gi_vlinks_c.h"
#include "pool.h"
#include "radrules.h"
#include "scene_leaves.h"
#include "timer.h"

#define LINK_CHUNK 16
#define LIGHT_CHUNK 256

typedef struct {
    int leaf;      /* leaf index */
    int top;       /* top-level object */
    long vbase;    /* first vertex (global numbering) */
    int nverts, ntris;
} vmesh;

/* A link ray's hit on an object that is not a mesh: what it reflects of
 * the lights is light the element gathers (one bounce; the object has no
 * vertices to carry more). */
typedef struct {
    vec3 p, n;     /* hit point, normal facing the element */
    float rho[3];  /* its diffuse reflectance */
    int leaf;
} farhit;

typedef struct {
    int n, raw;    /* merged links, raw links */
    int *peer;
    float *w;
    int nfar;
    farhit *far;
} elinks;

struct gi_vlinks {
    gi_vlinks_settings s;
    int have;
    /* structure: the previous frame's */
    int nobj, nleaves;
    uint64_t *obj_hash;
    vmesh *mesh;
    int nmesh;
    int *leaf_mesh;          /* leaf -> mesh, -1: not a mesh */
    long nv, ne;             /* vertices, elements (2 a vertex) */
    vec3 *pos, *nrm;         /* per vertex: world position, unit winding normal */
    vec3 *org;               /* per vertex: where its rays start (see mesh_geometry) */
    int *vmesh_of;           /* per vertex: its mesh */
    float *rho;              /* per element, 4 floats */
    float *le;               /* per element, 4 floats: emitted radiance (finish emission, POV-Ray's rules) */
    elinks *lk;              /* per element */
    int nc;                  /* rays per element */
    vec3 *dirs;              /* the n_C directions in the unit hemisphere about +z */
    float *ray_t;            /* per element and ray: hit distance (INFINITY: none) */
    int *ray_leaf;           /* per element and ray: leaf hit (-1 none, -2 unknown) */
    double off;              /* origin offset along the normal */
    /* kernels' arrays */
    int *off_csr, *peer_csr;
    float *w_csr;
    int *adj_off, *adj;
    float *edir, *efar, *b0, *b1, *itot, *ism;
    /* the frame the hook reads */
    const scene *sc;
    scene_leaves *lv;
    atomic_long lookups_other;
};

/* ---------------------------------------------------------------- directions */

/* Shirley and Chiu's concentric map of the unit square to the unit disc. */
static void concentric(double u, double v, double *x, double *y)
{
    double a = 2.0 * u - 1.0, b = 2.0 * v - 1.0, r, phi;
    if (a == 0.0 && b == 0.0) {
        *x = *y = 0.0;
        return;
    }
    if (fabs(a) > fabs(b)) {
        r = a;
        phi = (M_PI / 4.0) * (b / a);
    } else {
        r = b;
        phi = M_PI / 2.0 - (M_PI / 4.0) * (a / b);
    }
    *x = r * cos(phi);
    *y = r * sin(phi);
}

/* nside x nside cell centres of the unit square, taken block by block (4 x 4
 * cells a block, blocks row by row: neighbouring rays of one element are
 * traced together, the paper's coherent blocks), mapped to the disc and
 * projected up to the hemisphere (cosine-weighted: Malley's method). */
static vec3 *make_dirs(int nside)
{
    vec3 *d = malloc(sizeof *d * (size_t)nside * nside);
    if (!d) return NULL;
    int k = 0, nb = nside / 4;
    for (int by = 0; by < nb; by++)
        for (int bx = 0; bx < nb; bx++)
            for (int j = 0; j < 4; j++)
                for (int i = 0; i < 4; i++) {
                    double u = (bx * 4 + i + 0.5) / nside, v = (by * 4 + j + 0.5) / nside, x, y;
                    concentric(u, v, &x, &y);
                    d[k++] = v3(x, y, sqrt(fmax(0.0, 1.0 - x * x - y * y)));
                }
    return d;
}

/* ---------------------------------------------------------------- elements */

static vec3 vload(const float *f) { return v3(f[0], f[1], f[2]); }

/* World positions and area-weighted winding normals of mesh m's vertices,
 * and where their rays start: a little off the surface along the normal
 * (side 0; side 1 mirrors it), and moved in the tangent plane a hundredth
 * of the way towards the mean of the vertex's one-ring neighbours. A vertex on the border of a
 * mesh (a room's wall where it meets the next wall) would otherwise start
 * its rays in the next wall's plane: half of them would pass behind it and
 * leave the room. Inner vertices of an even mesh hardly move. */
static void mesh_geometry(gi_vlinks *v, const scene_object *o, const vmesh *m)
{
    const scene_mesh *sm = o->u.mesh.mesh;
    vec3 *P = v->pos + m->vbase, *N = v->nrm + m->vbase, *O = v->org + m->vbase;
    for (int i = 0; i < m->nverts; i++) {
        P[i] = xform_point(&o->transform, vload(sm->verts[i]));
        N[i] = v3(0, 0, 0);
        O[i] = v3(0, 0, 0); /* sum of one-ring neighbours (twice each) */
    }
    for (int t = 0; t < m->ntris; t++) {
        const int *tr = sm->tris[t];
        if (tr[0] < 0 || tr[1] < 0 || tr[2] < 0 || tr[0] >= m->nverts || tr[1] >= m->nverts || tr[2] >= m->nverts)
            continue;
        vec3 f = v3_cross(v3_sub(P[tr[1]], P[tr[0]]), v3_sub(P[tr[2]], P[tr[0]]));
        for (int c = 0; c < 3; c++) {
            N[tr[c]] = v3_add(N[tr[c]], f);
            O[tr[c]] = v3_add(O[tr[c]], v3_add(P[tr[(c + 1) % 3]], P[tr[(c + 2) % 3]]));
        }
    }
    int *cnt = calloc((size_t)(m->nverts > 0 ? m->nverts : 1), sizeof *cnt);
    if (cnt)
        for (int t = 0; t < m->ntris; t++) {
            const int *tr = sm->tris[t];
            if (tr[0] < 0 || tr[1] < 0 || tr[2] < 0 || tr[0] >= m->nverts || tr[1] >= m->nverts || tr[2] >= m->nverts)
                continue;
            for (int c = 0; c < 3; c++) cnt[tr[c]] += 2;
        }
    for (int i = 0; i < m->nverts; i++) {
        double l = v3_len(N[i]);
        N[i] = l > 0.0 ? v3_scale(N[i], 1.0 / l) : v3(0, 0, 1);
        vec3 c = cnt && cnt[i] > 0 ? v3_scale(O[i], 1.0 / cnt[i]) : P[i];
        vec3 d = v3_sub(c, P[i]);
        d = v3_sub(d, v3_scale(N[i], v3_dot(d, N[i]))); /* in the tangent plane: never through the surface */
        O[i] = v3_add(P[i], v3_scale(d, 0.01));
    }
    free(cnt);
}

/* Reflectance (finish diffuse times the pigment at the vertex) and emitted
 * radiance (radrules.h rule 1 times the pigment and its opacity) of mesh
 * m's elements; both sides take the texture of the vertex's first
 * triangle. */
static void mesh_rho(gi_vlinks *v, const scene *sc, const scene_object *o, const vmesh *m)
{
    const scene_mesh *sm = o->u.mesh.mesh;
    int *first = malloc(sizeof *first * (size_t)(m->nverts > 0 ? m->nverts : 1));
    int *corner = malloc(sizeof *corner * (size_t)(m->nverts > 0 ? m->nverts : 1));
    if (!first || !corner) {
        free(first);
        free(corner);
        return;
    }
    for (int i = 0; i < m->nverts; i++) first[i] = -1;
    for (int t = m->ntris - 1; t >= 0; t--)
        for (int c = 0; c < 3; c++) {
            int vi = sm->tris[t][c];
            if (vi >= 0 && vi < m->nverts) {
                first[vi] = t;
                corner[vi] = c;
            }
        }
    for (int i = 0; i < m->nverts; i++) {
        const scene_texture *tex = o->texture ? o->texture : &sc->default_texture;
        int t = first[i];
        const scene_texture *tt = t >= 0 ? scene_mesh_tri_texture(o, t) : NULL;
        if (tt) tex = tt;
        accel_hit h;
        memset(&h, 0, sizeof h);
        long g = m->vbase + i;
        h.p = v->pos[g];
        h.ng = h.ns = v->nrm[g];
        h.obj = o;
        h.texture = tex;
        h.prim = t >= 0 ? (unsigned)t : 0u;
        if (t >= 0) {
            int c = corner[i];
            h.u = c == 1 ? 1.0 : 0.0;
            h.v = c == 2 ? 1.0 : 0.0;
            if (sm->tri_uvs && sm->uvs) {
                int ui = sm->tri_uvs[t][c];
                if (ui >= 0 && ui < sm->nuvs) {
                    h.uv[0] = sm->uvs[ui][0];
                    h.uv[1] = sm->uvs[ui][1];
                }
            }
        }
        colour5 c5 = tex->pigment.colour;
        if (v->s.pigment && !v->s.pigment(sc, tex, &h, &c5)) c5 = tex->pigment.colour;
        double d = tex->finish.diffuse;
        float rgbv[3] = {(float)(c5.r * d), (float)(c5.g * d), (float)(c5.b * d)};
        radrules rr = radrules_of(sc, 1);
        rgb em = radrules_emission(&rr, sc, &tex->finish);
        double op = 1.0 - c5.f - c5.t;
        if (op < 0.0) op = 0.0;
        float lev[3] = {(float)(em.r * c5.r * op), (float)(em.g * c5.g * op), (float)(em.b * c5.b * op)};
        for (int side = 0; side < 2; side++) {
            float *r = &v->rho[(size_t)(2 * g + side) * 4];
            float *e = &v->le[(size_t)(2 * g + side) * 4];
            for (int k = 0; k < 3; k++) {
                r[k] = isfinite(rgbv[k]) && rgbv[k] > 0.0f ? rgbv[k] : 0.0f;
                e[k] = isfinite(lev[k]) && lev[k] > 0.0f ? lev[k] : 0.0f;
            }
            r[3] = e[3] = 0.0f;
        }
    }
    free(first);
    free(corner);
}

/* ---------------------------------------------------------------- links */

typedef struct {
    gi_vlinks *v;
    const scene *sc;
    const accel *a;
    const scene_leaves *lv;
    const long *todo;            /* elements to link */
    long ntodo;
    int nthreads;
    void *scene;                 /* RTCScene the link rays are traced in (accel_rtc_link_scene) */
    struct RTCRayHit **rh;       /* per thread: one element's rays */
    farhit **far;                /* per thread: one element's hits on objects without vertices */
    float **acc;                 /* per thread: weight per peer element (dense) */
    int **touched;               /* per thread: peers touched */
    atomic_long rays, other, raw;
    int oom;
} link_job;

static void link_chunk(void *ctx, int ci, int thread)
{
    link_job *J = ctx;
    gi_vlinks *v = J->v;
    if (v->s.cancel && *v->s.cancel) return;
    long i0 = (long)ci * LINK_CHUNK, i1 = i0 + LINK_CHUNK < J->ntodo ? i0 + LINK_CHUNK : J->ntodo;
    float *acc = J->acc[thread];
    int *touched = J->touched[thread];
    long rays = 0, other = 0, rawsum = 0;
    const float inv = 1.0f / (float)v->nc;
    for (long q = i0; q < i1; q++) {
        long e = J->todo[q], vx = e / 2;
        int side = (int)(e % 2);
        vec3 n = side ? v3_neg(v->nrm[vx]) : v->nrm[vx];
        vec3 t, b;
        v3_basis(n, &t, &b);
        vec3 org = v3_madd(v->org[vx], n, v->off);
        int nt = 0, raw = 0, nfar = 0;
        farhit *far = J->far[thread];
        /* the element's rays in one Embree stream, block by block (the
         * directions run 4 x 4 block after block: coherent) */
        struct RTCRayHit *rh = J->rh[thread];
        float tnear = (float)accel_epsilon(J->a, org, n);
        for (int k = 0; k < v->nc; k++) {
            vec3 l = v->dirs[k];
            vec3 dir = v3_add(v3_add(v3_scale(t, l.x), v3_scale(b, l.y)), v3_scale(n, l.z));
            const float of[3] = {(float)org.x, (float)org.y, (float)org.z};
            const float df[3] = {(float)dir.x, (float)dir.y, (float)dir.z};
            accel_rtc_rayhit_init(&rh[k], of, tnear, df);
        }
        struct RTCIntersectContext ictx;
        rtcInitIntersectContext(&ictx);
        ictx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        rtcIntersect1M((RTCScene)J->scene, &ictx, rh, (unsigned)v->nc, sizeof *rh);
        rays += v->nc;
        for (int k = 0; k < v->nc; k++) {
            vec3 l = v->dirs[k];
            vec3 dir = v3_add(v3_add(v3_scale(t, l.x), v3_scale(b, l.y)), v3_scale(n, l.z));
            size_t r = (size_t)e * v->nc + k;
            const struct RTCRayHit *q = &rh[k];
            if (q->hit.geomID == RTC_INVALID_GEOMETRY_ID) {
                v->ray_t[r] = INFINITY;
                v->ray_leaf[r] = -1;
                continue;
            }
            unsigned local = 0;
            const scene_object *hobj = accel_rtc_object_tri(J->a, q->hit.geomID, q->hit.primID, q->hit.instID[0], &local);
            accel_hit h;
            if (hobj) {
                h.obj = hobj;
                h.prim = local;
                h.u = q->hit.u;
                h.v = q->hit.v;
                h.t = q->ray.tfar;
            } else if (!accel_intersect(J->a, org, dir, 0.0, INFINITY, &h)) {
                /* the record alone does not tell (a CSG member): ask accel */
                v->ray_t[r] = INFINITY;
                v->ray_leaf[r] = -1;
                continue;
            }
            int leaf = scene_leaves_find(J->lv, h.obj);
            v->ray_t[r] = (float)h.t;
            v->ray_leaf[r] = leaf;
            int mi = leaf >= 0 ? v->leaf_mesh[leaf] : -1;
            if (mi < 0) {
                other++;
                /* the full record (point, normal, texture) for its reflectance */
                accel_hit fh;
                if (leaf >= 0 && accel_intersect(J->a, org, dir, 0.0, INFINITY, &fh) && fh.obj == h.obj) {
                    farhit *f = &far[nfar];
                    f->p = fh.p;
                    f->n = v3_dot(fh.ng, dir) < 0.0 ? fh.ng : v3_neg(fh.ng);
                    f->leaf = leaf;
                    const scene_texture *tex = fh.texture ? fh.texture : &J->sc->default_texture;
                    colour5 c5 = tex->pigment.colour;
                    accel_hit ph = fh;
                    ph.ns = ph.ng = f->n;
                    if (v->s.pigment && !v->s.pigment(J->sc, tex, &ph, &c5)) c5 = tex->pigment.colour;
                    double dd = tex->finish.diffuse;
                    float rr[3] = {(float)(c5.r * dd), (float)(c5.g * dd), (float)(c5.b * dd)};
                    int any = 0;
                    for (int c = 0; c < 3; c++) {
                        f->rho[c] = isfinite(rr[c]) && rr[c] > 0.0f ? rr[c] : 0.0f;
                        any |= f->rho[c] > 0.0f;
                    }
                    if (any) nfar++;
                }
                continue;
            }
            const vmesh *m = &v->mesh[mi];
            const scene_mesh *sm = h.obj->u.mesh.mesh;
            if (h.prim >= (unsigned)m->ntris) continue;
            const int *tr = sm->tris[h.prim];
            if (tr[0] < 0 || tr[1] < 0 || tr[2] < 0 || tr[0] >= m->nverts || tr[1] >= m->nverts || tr[2] >= m->nverts)
                continue;
            long g[3] = {m->vbase + tr[0], m->vbase + tr[1], m->vbase + tr[2]};
            vec3 f = v3_cross(v3_sub(v->pos[g[1]], v->pos[g[0]]), v3_sub(v->pos[g[2]], v->pos[g[0]]));
            int hs = v3_dot(dir, f) < 0.0 ? 0 : 1; /* the side the ray arrives at */
            /* accel_hit's barycentrics: p = (1 - u - v) v0 + u v1 + v v2 */
            double bw[3] = {1.0 - h.u - h.v, h.u, h.v};
            for (int c = 0; c < 3; c++) {
                float wv = (float)bw[c] * inv;
                if (!(wv > 0.0f)) continue;
                int p = (int)(2 * g[c] + hs);
                if (acc[p] == 0.0f) touched[nt++] = p;
                acc[p] += wv;
                raw++;
            }
        }
        elinks *L = &v->lk[e];
        free(L->peer);
        free(L->w);
        free(L->far);
        L->far = NULL;
        L->nfar = 0;
        if (nfar > 0) {
            L->far = malloc(sizeof *L->far * (size_t)nfar);
            if (!L->far) J->oom = 1;
            else {
                memcpy(L->far, far, sizeof *L->far * (size_t)nfar);
                L->nfar = nfar;
            }
        }
        L->peer = malloc(sizeof *L->peer * (size_t)(nt > 0 ? nt : 1));
        L->w = malloc(sizeof *L->w * (size_t)(nt > 0 ? nt : 1));
        if (!L->peer || !L->w) {
            J->oom = 1;
            L->n = 0;
            for (int k = 0; k < nt; k++) acc[touched[k]] = 0.0f;
            continue;
        }
        for (int k = 0; k < nt; k++) {
            L->peer[k] = touched[k];
            L->w[k] = acc[touched[k]];
            acc[touched[k]] = 0.0f;
        }
        L->n = nt;
        L->raw = raw;
        rawsum += raw;
    }
    atomic_fetch_add(&J->rays, rays);
    atomic_fetch_add(&J->other, other);
    atomic_fetch_add(&J->raw, rawsum);
}

/* ---------------------------------------------------------------- light */

typedef struct {
    gi_vlinks *v;
    const scene *sc;
    const accel *a;
    const gi_dev_light *dl;
    atomic_long rays;
} light_job;

/* Direct E/pi at point p with normal n from every light (POV-Ray's
 * attenuation, cones, fade; shadow rays from org; light groups by obj). */
static void direct_at(const light_job *J, vec3 p, vec3 n, vec3 org, const scene_object *obj, float E[3], long *rays)
{
    const scene *sc = J->sc;
    E[0] = E[1] = E[2] = 0.0f;
    for (int li = 0; li < sc->nlights; li++) {
        const scene_light *l = &sc->lights[li];
        const gi_dev_light *dl = &J->dl[li];
        float d[3];
        float depth = gi_light_ray(dl, dl->pos[0], dl->pos[1], dl->pos[2], (float)p.x, (float)p.y, (float)p.z, d);
        double ci2 = n.x * d[0] + n.y * d[1] + n.z * d[2];
        if (!(ci2 > 1e-10)) continue;
        float att = gi_light_attenuation(dl, (float)p.x, (float)p.y, (float)p.z, d, depth);
        if (!(att > 0.0f) || (obj && !scene_light_reaches(l, obj))) continue;
        if (!l->shadowless) {
            (*rays)++;
            if (accel_occluded(J->a, org, v3(d[0], d[1], d[2]), 0.0, depth)) continue;
        }
        for (int c = 0; c < 3; c++) E[c] += dl->colour[c] * att * (float)ci2;
    }
    for (int c = 0; c < 3; c++)
        if (!isfinite(E[c])) E[c] = 0.0f;
}

static void light_chunk(void *ctx, int ci, int thread)
{
    (void)thread;
    light_job *J = ctx;
    gi_vlinks *v = J->v;
    long e0 = (long)ci * LIGHT_CHUNK, e1 = e0 + LIGHT_CHUNK < v->ne ? e0 + LIGHT_CHUNK : v->ne;
    long rays = 0;
    for (long e = e0; e < e1; e++) {
        long vx = e / 2;
        int side = (int)(e % 2);
        vec3 n = side ? v3_neg(v->nrm[vx]) : v->nrm[vx];
        vec3 p = v->pos[vx];
        const vmesh *m = &v->mesh[v->vmesh_of[vx]];
        const scene_object *obj = scene_leaves_get(v->lv, m->leaf);
        float E[3];
        direct_at(J, p, n, v3_madd(v->org[vx], n, v->off), obj, E, &rays);
        for (int c = 0; c < 3; c++) v->edir[e * 4 + c] = E[c];
        v->edir[e * 4 + 3] = 0.0f;
        /* what the element's rays that end on objects without vertices
         * gather: each such object's reflected direct light (rho E/pi),
         * a share 1/n_C each */
        float F[3] = {0.0f, 0.0f, 0.0f};
        const elinks *L = &v->lk[e];
        for (int k = 0; k < L->nfar; k++) {
            const farhit *f = &L->far[k];
            float Ef[3];
            direct_at(J, f->p, f->n, v3_madd(f->p, f->n, v->off), scene_leaves_get(v->lv, f->leaf), Ef, &rays);
            for (int c = 0; c < 3; c++) F[c] += f->rho[c] * Ef[c];
        }
        for (int c = 0; c < 3; c++) {
            float fv = F[c] / (float)v->nc;
            v->efar[e * 4 + c] = isfinite(fv) ? fv : 0.0f;
        }
        v->efar[e * 4 + 3] = 0.0f;
    }
    atomic_fetch_add(&J->rays, rays);
}

/* ---------------------------------------------------------------- frame */

void gi_vlinks_default_settings(gi_vlinks_settings *s)
{
    *s = (gi_vlinks_settings){.nside = 16, .feature_deg = 30.0};
}

gi_vlinks *gi_vlinks_new(const gi_vlinks_settings *s)
{
    gi_vlinks *v = calloc(1, sizeof *v);
    if (!v) return NULL;
    v->s = *s;
    if (v->s.nside < 4) v->s.nside = 4;
    v->s.nside = (v->s.nside + 3) / 4 * 4;
    v->nc = v->s.nside * v->s.nside;
    v->dirs = make_dirs(v->s.nside);
    if (!v->dirs) {
        free(v);
        return NULL;
    }
    return v;
}

static void free_structure(gi_vlinks *v)
{
    for (long e = 0; e < v->ne && v->lk; e++) GROW_FREE_ALL(v->lk[e].peer, v->lk[e].w, v->lk[e].far);
    GROW_FREE_ALL(v->lk, v->mesh, v->leaf_mesh, v->pos, v->nrm, v->org, v->vmesh_of, v->rho, v->le, v->ray_t,
                  v->ray_leaf, v->edir, v->efar, v->b0, v->b1, v->itot, v->ism, v->off_csr, v->peer_csr, v->w_csr,
                  v->adj_off, v->adj);
    v->lk = NULL;
    v->mesh = NULL;
    v->leaf_mesh = NULL;
    v->pos = v->nrm = v->org = NULL;
    v->rho = v->le = v->ray_t = v->edir = v->efar = v->b0 = v->b1 = v->itot = v->ism = v->w_csr = NULL;
    v->vmesh_of = NULL;
    v->ray_leaf = v->off_csr = v->peer_csr = v->adj_off = v->adj = NULL;
    v->ne = v->nv = 0;
    v->nmesh = 0;
    v->have = 0;
}

void gi_vlinks_free(gi_vlinks *v)
{
    if (!v) return;
    free_structure(v);
    free(v->obj_hash);
    free(v->dirs);
    scene_leaves_free(v->lv);
    free(v);
}

void gi_vlinks_set_progress(gi_vlinks *v, progress *p) { v->s.progress = p; }

void gi_vlinks_set_cancel(gi_vlinks *v, volatile int *cancel) { v->s.cancel = cancel; }

long gi_vlinks_count(const gi_vlinks *v) { return v->ne; }

long gi_vlinks_lookups_other(const gi_vlinks *v) { return atomic_load(&((gi_vlinks *)v)->lookups_other); }

rgb gi_vlinks_element(const gi_vlinks *v, long i, vec3 *p, vec3 *nrm)
{
    rgb z = {0, 0, 0};
    if (i < 0 || i >= v->ne || !v->ism) return z;
    long vx = i / 2;
    if (p) *p = v->pos[vx];
    if (nrm) *nrm = i % 2 ? v3_neg(v->nrm[vx]) : v->nrm[vx];
    rgb r = {v->ism[i * 4], v->ism[i * 4 + 1], v->ism[i * 4 + 2]};
    return r;
}

/* The structure of sc's meshes: leaf -> mesh and vertex numbering. 0 on no
 * memory. */
static int make_structure(gi_vlinks *v, const scene *sc, const scene_leaves *lv)
{
    int nl = scene_leaves_count(lv);
    v->leaf_mesh = malloc(sizeof *v->leaf_mesh * (size_t)(nl > 0 ? nl : 1));
    v->mesh = malloc(sizeof *v->mesh * (size_t)(nl > 0 ? nl : 1));
    if (!v->leaf_mesh || !v->mesh) return 0;
    long nv = 0;
    v->nmesh = 0;
    for (int i = 0; i < nl; i++) {
        const scene_object *o = scene_leaves_get(lv, i);
        v->leaf_mesh[i] = -1;
        if (o->kind != SHAPE_MESH || !o->u.mesh.mesh || o->u.mesh.mesh->nverts <= 0) continue;
        vmesh *m = &v->mesh[v->nmesh];
        m->leaf = i;
        m->top = scene_leaves_top(lv, i);
        m->vbase = nv;
        m->nverts = o->u.mesh.mesh->nverts;
        m->ntris = o->u.mesh.mesh->ntris;
        v->leaf_mesh[i] = v->nmesh++;
        nv += m->nverts;
    }
    (void)sc;
    v->nv = nv;
    v->ne = 2 * nv;
    size_t ne = (size_t)(v->ne > 0 ? v->ne : 1);
    v->pos = malloc(sizeof *v->pos * (size_t)(nv > 0 ? nv : 1));
    v->nrm = malloc(sizeof *v->nrm * (size_t)(nv > 0 ? nv : 1));
    v->org = malloc(sizeof *v->org * (size_t)(nv > 0 ? nv : 1));
    v->vmesh_of = malloc(sizeof *v->vmesh_of * (size_t)(nv > 0 ? nv : 1));
    if (v->vmesh_of)
        for (int k = 0; k < v->nmesh; k++)
            for (int i = 0; i < v->mesh[k].nverts; i++) v->vmesh_of[v->mesh[k].vbase + i] = k;
    v->rho = calloc(ne * 4, sizeof *v->rho);
    v->le = calloc(ne * 4, sizeof *v->le);
    v->lk = calloc(ne, sizeof *v->lk);
    v->ray_t = malloc(sizeof *v->ray_t * ne * (size_t)v->nc);
    v->ray_leaf = malloc(sizeof *v->ray_leaf * ne * (size_t)v->nc);
    v->edir = calloc(ne * 4, sizeof(float));
    v->efar = calloc(ne * 4, sizeof(float));
    v->b0 = calloc(ne * 4, sizeof(float));
    v->b1 = calloc(ne * 4, sizeof(float));
    v->itot = calloc(ne * 4, sizeof(float));
    v->ism = calloc(ne * 4, sizeof(float));
    v->off_csr = calloc(ne + 1, sizeof(int));
    v->adj_off = calloc(ne + 1, sizeof(int));
    return v->pos && v->nrm && v->org && v->vmesh_of && v->rho && v->le && v->lk && v->ray_t && v->ray_leaf && v->edir && v->efar && v->b0 && v->b1 && v->itot &&
           v->ism && v->off_csr && v->adj_off;
}

/* One-ring neighbours of every element on the same side within the
 * feature angle (CSR adj_off/adj). */
static int make_adjacency(gi_vlinks *v, const scene_leaves *lv)
{
    double cf = cos(v->s.feature_deg * M_PI / 180.0);
    /* vertex adjacency: every triangle edge both ways, duplicates removed per vertex */
    long *cnt = calloc((size_t)v->nv + 1, sizeof *cnt);
    if (!cnt) return 0;
    for (int mi = 0; mi < v->nmesh; mi++) {
        const vmesh *m = &v->mesh[mi];
        const scene_mesh *sm = scene_leaves_get(lv, m->leaf)->u.mesh.mesh;
        for (int t = 0; t < m->ntris; t++)
            for (int c = 0; c < 3; c++) {
                int a = sm->tris[t][c];
                if (a >= 0 && a < m->nverts) cnt[m->vbase + a + 1] += 2;
            }
    }
    for (long i = 0; i < v->nv; i++) cnt[i + 1] += cnt[i];
    long total = cnt[v->nv];
    long *vn = malloc(sizeof *vn * (size_t)(total > 0 ? total : 1));
    long *fill = malloc(sizeof *fill * (size_t)(v->nv > 0 ? v->nv : 1));
    if (!vn || !fill) {
        free(cnt);
        free(vn);
        free(fill);
        return 0;
    }
    for (long i = 0; i < v->nv; i++) fill[i] = cnt[i];
    for (int mi = 0; mi < v->nmesh; mi++) {
        const vmesh *m = &v->mesh[mi];
        const scene_mesh *sm = scene_leaves_get(lv, m->leaf)->u.mesh.mesh;
        for (int t = 0; t < m->ntris; t++) {
            const int *tr = sm->tris[t];
            if (tr[0] < 0 || tr[1] < 0 || tr[2] < 0 || tr[0] >= m->nverts || tr[1] >= m->nverts || tr[2] >= m->nverts)
                continue;
            for (int c = 0; c < 3; c++) {
                long a = m->vbase + tr[c];
                vn[fill[a]++] = m->vbase + tr[(c + 1) % 3];
                vn[fill[a]++] = m->vbase + tr[(c + 2) % 3];
            }
        }
    }
    /* per element: its vertex's distinct neighbours within the angle */
    free(v->adj);
    v->adj = malloc(sizeof *v->adj * (size_t)(2 * total > 0 ? 2 * total : 1));
    if (!v->adj) {
        free(cnt);
        free(vn);
        free(fill);
        return 0;
    }
    long k = 0;
    for (long e = 0; e < v->ne; e++) {
        long a = e / 2;
        int side = (int)(e % 2);
        v->adj_off[e] = (int)k;
        long k0 = k;
        for (long q = cnt[a]; q < fill[a]; q++) {
            long b = vn[q];
            if (b == a || v3_dot(v->nrm[a], v->nrm[b]) <= cf) continue;
            int peer = (int)(2 * b + side), dup = 0;
            for (long z = k0; z < k && !dup; z++) dup = v->adj[z] == peer;
            if (!dup) v->adj[k++] = peer;
        }
    }
    v->adj_off[v->ne] = (int)k;
    free(cnt);
    free(vn);
    free(fill);
    return 1;
}

/* CSR of the links (off_csr/peer_csr/w_csr) from the per-element lists. */
static int make_csr(gi_vlinks *v, long *merged, long *raw)
{
    long total = 0, r = 0;
    for (long e = 0; e < v->ne; e++) {
        total += v->lk[e].n;
        r += v->lk[e].raw;
    }
    free(v->peer_csr);
    free(v->w_csr);
    v->peer_csr = malloc(sizeof *v->peer_csr * (size_t)(total > 0 ? total : 1));
    v->w_csr = malloc(sizeof *v->w_csr * (size_t)(total > 0 ? total : 1));
    if (!v->peer_csr || !v->w_csr) return 0;
    long k = 0;
    for (long e = 0; e < v->ne; e++) {
        v->off_csr[e] = (int)k;
        if (v->lk[e].n) {
            memcpy(v->peer_csr + k, v->lk[e].peer, sizeof(int) * (size_t)v->lk[e].n);
            memcpy(v->w_csr + k, v->lk[e].w, sizeof(float) * (size_t)v->lk[e].n);
        }
        k += v->lk[e].n;
    }
    v->off_csr[v->ne] = (int)k;
    *merged = total;
    *raw = r;
    return 1;
}

typedef struct {
    gi_vlinks *v;
    const accel *mob;
    int boxed;
    vec3 lo, hi;
    const unsigned char *moved_leaf;
    unsigned char *need;
} stale_job;

/* Marks the elements with a ray that ended on a moved object or that now
 * meets one. */
static void stale_chunk(void *ctx, int ci, int thread)
{
    (void)thread;
    stale_job *J = ctx;
    gi_vlinks *v = J->v;
    long e0 = (long)ci * LIGHT_CHUNK, e1 = e0 + LIGHT_CHUNK < v->ne ? e0 + LIGHT_CHUNK : v->ne;
    for (long e = e0; e < e1; e++) {
        if (J->need[e]) continue;
        long vx = e / 2;
        int side = (int)(e % 2);
        vec3 n = side ? v3_neg(v->nrm[vx]) : v->nrm[vx];
        vec3 t, b;
        v3_basis(n, &t, &b);
        vec3 org = v3_madd(v->org[vx], n, v->off);
        for (int k = 0; k < v->nc && !J->need[e]; k++) {
            size_t r = (size_t)e * v->nc + k;
            int lf = v->ray_leaf[r];
            if (lf == -2 || (lf >= 0 && J->moved_leaf[lf])) {
                J->need[e] = 1;
                break;
            }
            if (!J->mob) continue;
            vec3 l = v->dirs[k];
            vec3 dir = v3_add(v3_add(v3_scale(t, l.x), v3_scale(b, l.y)), v3_scale(n, l.z));
            double tmax = isfinite(v->ray_t[r]) ? v->ray_t[r] * (1.0 + 1e-6) : INFINITY;
            if (J->boxed && !v3_segment_meets_box(org, dir, J->lo, J->hi, tmax)) continue;
            accel_hit h;
            if (accel_intersect(J->mob, org, dir, 0.0, tmax, &h)) J->need[e] = 1;
        }
    }
}

pt_status gi_vlinks_frame(gi_vlinks *v, const scene *sc, const accel *a, int objects_may_change, gi_vlinks_stats *st,
                          diag *d)
{
    (void)d;
    memset(st, 0, sizeof *st);
    pt_status status = PT_OK;
    int nthreads = pool_default_threads();
    if (v->s.threads > 0) nthreads = v->s.threads;
    scene_leaves *lv = scene_leaves_new(sc);
    if (!lv) return PT_ERR_NOMEM;
    int nl = scene_leaves_count(lv);
    uint64_t *hash = malloc(sizeof *hash * (size_t)(sc->nobjects > 0 ? sc->nobjects : 1));
    unsigned char *moved_top = calloc((size_t)(sc->nobjects > 0 ? sc->nobjects : 1), 1);
    unsigned char *moved_leaf = calloc((size_t)(nl > 0 ? nl : 1), 1);
    unsigned char *need = NULL;
    long *todo = NULL;
    accel *mob = NULL;
    scene_object **mobobj = malloc(sizeof *mobobj * (size_t)(sc->nobjects > 0 ? sc->nobjects : 1));
    gi_dev_light *dl = NULL;
    link_job J;
    memset(&J, 0, sizeof J);
    if (!hash || !moved_top || !moved_leaf || !mobobj) {
        status = PT_ERR_NOMEM;
        goto done;
    }
    /* 1. structure and what moved */
    int full = !v->have || sc->nobjects != v->nobj || nl != v->nleaves;
    for (int i = 0; i < sc->nobjects; i++) {
        int opaque = 0;
        hash[i] = scene_object_hash(PT_FNV1A_BASIS, sc->objects[i], &opaque);
        if (!full && objects_may_change) moved_top[i] = opaque || hash[i] != v->obj_hash[i];
    }
    if (!full)
        for (int mi = 0; mi < v->nmesh && !full; mi++) {
            const scene_object *o = scene_leaves_get(lv, v->mesh[mi].leaf);
            full = o->kind != SHAPE_MESH || !o->u.mesh.mesh || o->u.mesh.mesh->nverts != v->mesh[mi].nverts ||
                   o->u.mesh.mesh->ntris != v->mesh[mi].ntris;
        }
    if (full) {
        free_structure(v);
        if (!make_structure(v, sc, lv)) {
            status = PT_ERR_NOMEM;
            free_structure(v);
            goto done;
        }
        vec3 lo, hi;
        accel_bounds(a, &lo, &hi);
        double sz = v3_len(v3_sub(hi, lo));
        v->off = 1e-6 * (sz > 0.0 && isfinite(sz) ? sz : accel_scale(a));
    }
    int nmob = 0;
    for (int i = 0; i < sc->nobjects; i++)
        if (moved_top[i]) mobobj[nmob++] = sc->objects[i];
    for (int l = 0; l < nl; l++) moved_leaf[l] = moved_top[scene_leaves_top(lv, l)];
    st->objects_moved = nmob;
    st->full = full;
    /* 2. geometry of the meshes that need it */
    for (int mi = 0; mi < v->nmesh; mi++) {
        const vmesh *m = &v->mesh[mi];
        if (!full && !moved_leaf[m->leaf]) continue;
        if (!full) st->meshes_moved++;
        const scene_object *o = scene_leaves_get(lv, m->leaf);
        mesh_geometry(v, o, m);
    }
    /* reflectance: every frame (textures are not hashed) */
    for (int mi = 0; mi < v->nmesh; mi++) mesh_rho(v, sc, scene_leaves_get(lv, v->mesh[mi].leaf), &v->mesh[mi]);
    st->vertices = v->nv;
    st->elements = v->ne;
    st->meshes = v->nmesh;
    st->other_objects = nl - v->nmesh;
    scene_leaves_free(v->lv);
    v->lv = lv;
    lv = NULL;
    v->sc = sc;

    /* 3. links */
    double t0 = timer_now();
    need = calloc((size_t)(v->ne > 0 ? v->ne : 1), 1);
    todo = malloc(sizeof *todo * (size_t)(v->ne > 0 ? v->ne : 1));
    if (!need || !todo) {
        status = PT_ERR_NOMEM;
        goto done;
    }
    if (full) {
        memset(need, 1, (size_t)v->ne);
    } else if (nmob > 0) {
        long nmoved = 0;
        for (int mi = 0; mi < v->nmesh; mi++)
            if (moved_leaf[v->mesh[mi].leaf]) {
                memset(need + 2 * v->mesh[mi].vbase, 1, (size_t)(2 * v->mesh[mi].nverts));
                nmoved += 2 * v->mesh[mi].nverts;
            }
        /* when the moved meshes hold half the elements or more, testing
         * the rest's rays against them costs about what linking them
         * again does: link everything */
        if (2 * nmoved >= v->ne) memset(need, 1, (size_t)v->ne);
        if (2 * nmoved < v->ne) {
            scene mobsc = *sc;
            mobsc.objects = mobobj;
            mobsc.nobjects = nmob;
            diag *dq = diag_new();
            pt_status ms = PT_OK;
            mob = accel_build(&mobsc, v->s.threads, dq, &ms);
            diag_free(dq);
            stale_job S = {v, mob, 1, v3(0, 0, 0), v3(0, 0, 0), moved_leaf, need};
            for (int k = 0; k < nmob; k++) S.boxed &= scene_object_finite(mobobj[k]);
            if (mob && S.boxed) {
                accel_bounds(mob, &S.lo, &S.hi);
                double g = 1e-6 * v3_len(v3_sub(S.hi, S.lo)) + v->off;
                S.lo = v3_sub(S.lo, v3(g, g, g));
                S.hi = v3_add(S.hi, v3(g, g, g));
            } else {
                S.boxed = 0;
            }
            if (!mob) memset(need, 1, (size_t)v->ne); /* no moved-objects accel: everything again */
            else pool_run(nthreads, (int)((v->ne + LIGHT_CHUNK - 1) / LIGHT_CHUNK), stale_chunk, &S);
        }
    }
    long ntodo = 0;
    for (long e = 0; e < v->ne; e++)
        if (need[e]) todo[ntodo++] = e;
    st->elements_linked = ntodo;
    if (ntodo > 0) {
        J.v = v;
        J.sc = sc;
        J.a = a;
        J.lv = v->lv;
        J.todo = todo;
        J.ntodo = ntodo;
        J.nthreads = nthreads;
        J.acc = calloc((size_t)nthreads, sizeof *J.acc);
        J.touched = calloc((size_t)nthreads, sizeof *J.touched);
        J.rh = calloc((size_t)nthreads, sizeof *J.rh);
        J.far = calloc((size_t)nthreads, sizeof *J.far);
        /* link rays tolerate a rare crack between triangles: the faster
         * scene without Embree's robust mode (accel.h) */
        J.scene = accel_rtc_link_scene(a);
        if (!J.scene) J.scene = accel_rtc_scene(a);
        if (!J.acc || !J.touched || !J.rh || !J.far) {
            status = PT_ERR_NOMEM;
            goto done;
        }
        for (int t = 0; t < nthreads; t++) {
            J.acc[t] = calloc((size_t)v->ne, sizeof(float));
            J.touched[t] = malloc(sizeof(int) * (size_t)v->nc * 3 + sizeof(int));
            J.rh[t] = malloc(sizeof(struct RTCRayHit) * (size_t)v->nc);
            J.far[t] = malloc(sizeof(farhit) * (size_t)v->nc);
            if (!J.acc[t] || !J.touched[t] || !J.rh[t] || !J.far[t]) {
                status = PT_ERR_NOMEM;
                goto done;
            }
        }
        progress_stage(v->s.progress, "links: link rays", (ntodo + LINK_CHUNK - 1) / LINK_CHUNK);
        pool_run_counted(nthreads, (int)((ntodo + LINK_CHUNK - 1) / LINK_CHUNK), link_chunk, &J, v->s.cancel,
                         v->s.progress);
        if (v->s.cancel && *v->s.cancel) {
            status = PT_CANCELLED;
            v->have = 0;
            goto done;
        }
        if (J.oom) {
            status = PT_ERR_NOMEM;
            v->have = 0;
            goto done;
        }
        st->link_rays = atomic_load(&J.rays);
        st->hits_other = atomic_load(&J.other);
    }
    if (!make_csr(v, &st->merged_links, &st->raw_links) || !make_adjacency(v, v->lv)) {
        status = PT_ERR_NOMEM;
        v->have = 0;
        goto done;
    }
    st->t_links = timer_now() - t0;

    /* 4. light links */
    t0 = timer_now();
    dl = calloc((size_t)(sc->nlights > 0 ? sc->nlights : 1), sizeof *dl);
    if (!dl) {
        status = PT_ERR_NOMEM;
        goto done;
    }
    for (int li = 0; li < sc->nlights; li++) gi_light_pack(&sc->lights[li], &dl[li]);
    light_job L = {v, sc, a, dl, 0};
    progress_stage(v->s.progress, "links: light", 0);
    pool_run(nthreads, (int)((v->ne + LIGHT_CHUNK - 1) / LIGHT_CHUNK), light_chunk, &L);
    st->light_rays = atomic_load(&L.rays);
    st->t_light = timer_now() - t0;

    /* 5. gathering sweeps, smoothing */
    t0 = timer_now();
    size_t n4 = (size_t)v->ne * 4;
    memset(v->itot, 0, sizeof(float) * n4);
    /* what each element sends into the first sweep: its reflected direct
     * light and its emission (which reaches other surfaces only by
     * gathering, radrules.h rule 1) */
    for (size_t i = 0; i < n4; i++) v->b0[i] = v->rho[i] * v->edir[i] + v->le[i];
    progress_stage(v->s.progress, "links: bounces", 0);
    /* POV-Ray's recursion_limit counts the bounces of gathered light
     * (radrules.h rule 6): one sweep each; brightness scales every one */
    radrules rr = radrules_of(sc, 1);
    int sweeps = v->s.bounces > 0 ? v->s.bounces : (rr.recursion_limit > 0 ? rr.recursion_limit : 3);
    st->sweeps = sweeps;
    if (rr.brightness != 1.0)
        for (long i = 0; i < (long)n4; i++) v->b0[i] *= (float)rr.brightness;
    for (int b = 0; b < sweeps; b++) {
        gi_c_vgather(nthreads, v->off_csr, v->peer_csr, v->w_csr, v->b0, v->rho, (int)v->ne, v->b1, v->itot);
        if (b == 0)
            /* the first bounce also gathers what objects without vertices
             * reflect of the lights */
            for (size_t i = 0; i < n4; i++) {
                float g = v->efar[i] * (float)rr.brightness;
                v->itot[i] += g;
                v->b1[i] += v->rho[i] * g;
            }
        if (rr.brightness != 1.0)
            for (long i = 0; i < (long)n4; i++) v->b1[i] *= (float)rr.brightness;
        float *tmp = v->b0;
        v->b0 = v->b1;
        v->b1 = tmp;
    }
    st->t_bounces = timer_now() - t0;
    t0 = timer_now();
    gi_c_vsmooth(nthreads, v->adj_off, v->adj, v->itot, (int)v->ne, v->ism);
    st->t_smooth = timer_now() - t0;
    free(v->obj_hash);
    v->obj_hash = hash;
    hash = NULL;
    v->nobj = sc->nobjects;
    v->nleaves = nl;
    v->have = 1;
    atomic_store(&v->lookups_other, 0);
done:
    if (J.acc)
        for (int t = 0; t < nthreads; t++) free(J.acc[t]);
    if (J.touched)
        for (int t = 0; t < nthreads; t++) free(J.touched[t]);
    if (J.rh)
        for (int t = 0; t < nthreads; t++) free(J.rh[t]);
    if (J.far)
        for (int t = 0; t < nthreads; t++) free(J.far[t]);
    free(J.far);
    free(J.acc);
    free(J.touched);
    free(J.rh);
    if (J.scene && J.scene != accel_rtc_scene(a)) accel_rtc_link_scene_free(J.scene);
    free(dl);
    accel_free(mob);
    free(mobobj);
    free(todo);
    free(need);
    free(moved_leaf);
    free(moved_top);
    free(hash);
    scene_leaves_free(lv);
    if (status != PT_OK) v->have = 0;
    return status;
}

/* What the hook reads of a solution: the instance's own arrays, or a
 * shot's copies of them. */
typedef struct {
    const scene_leaves *lv;
    const int *leaf_mesh;
    const vmesh *mesh;
    const vec3 *pos;
    const float *ism;
    atomic_long *lookups_other;
} vlook;

static rgb vlook_indirect(const vlook *L, const accel_hit *hit, vec3 n)
{
    rgb z = {0.0, 0.0, 0.0};
    int leaf = scene_leaves_find(L->lv, hit->obj);
    int mi = leaf >= 0 ? L->leaf_mesh[leaf] : -1;
    if (mi < 0) {
        atomic_fetch_add_explicit(L->lookups_other, 1, memory_order_relaxed);
        return z;
    }
    const vmesh *m = &L->mesh[mi];
    const scene_mesh *sm = hit->obj->u.mesh.mesh;
    if (hit->prim >= (unsigned)m->ntris) return z;
    const int *tr = sm->tris[hit->prim];
    if (tr[0] < 0 || tr[1] < 0 || tr[2] < 0 || tr[0] >= m->nverts || tr[1] >= m->nverts || tr[2] >= m->nverts) return z;
    long g[3] = {m->vbase + tr[0], m->vbase + tr[1], m->vbase + tr[2]};
    vec3 f = v3_cross(v3_sub(L->pos[g[1]], L->pos[g[0]]), v3_sub(L->pos[g[2]], L->pos[g[0]]));
    int side = v3_dot(n, f) >= 0.0 ? 0 : 1;
    double bw[3] = {1.0 - hit->u - hit->v, hit->u, hit->v};
    double s[3] = {0.0, 0.0, 0.0};
    for (int c = 0; c < 3; c++) {
        const float *e = &L->ism[(size_t)(2 * g[c] + side) * 4];
        for (int k = 0; k < 3; k++) s[k] += bw[c] * e[k];
    }
    rgb r = {s[0], s[1], s[2]};
    return r;
}

rgb gi_vlinks_indirect(void *ctx, const accel_hit *hit, vec3 n, int thread)
{
    (void)thread;
    gi_vlinks *v = ctx;
    rgb z = {0.0, 0.0, 0.0};
    if (!v->have || !v->lv) return z;
    vlook L = {v->lv, v->leaf_mesh, v->mesh, v->pos, v->ism, &v->lookups_other};
    return vlook_indirect(&L, hit, n);
}

/* ---------------------------------------------------------------- shots */

struct gi_vlinks_shot {
    scene_leaves *lv;  /* of the frame's scene: hits are on its objects */
    int *leaf_mesh;
    vmesh *mesh;
    vec3 *pos;
    float *ism;
    atomic_long lookups_other;
};

void gi_vlinks_shot_free(gi_vlinks_shot *s)
{
    if (!s) return;
    scene_leaves_free(s->lv);
    free(s->leaf_mesh);
    free(s->mesh);
    free(s->pos);
    free(s->ism);
    free(s);
}

gi_vlinks_shot *gi_vlinks_shot_new(const gi_vlinks *v)
{
    if (!v->have || !v->lv || !v->sc) return NULL;
    gi_vlinks_shot *s = calloc(1, sizeof *s);
    if (!s) return NULL;
    s->lv = scene_leaves_new(v->sc);
    int nl = s->lv ? scene_leaves_count(s->lv) : 0;
    s->leaf_mesh = malloc(sizeof *s->leaf_mesh * (size_t)(nl > 0 ? nl : 1));
    s->mesh = malloc(sizeof *s->mesh * (size_t)(v->nmesh > 0 ? v->nmesh : 1));
    s->pos = malloc(sizeof *s->pos * (size_t)(v->nv > 0 ? v->nv : 1));
    s->ism = malloc(sizeof(float) * 4 * (size_t)(v->ne > 0 ? v->ne : 1));
    /* the leaves are numbered as the frame's (same scene, same walk) */
    if (!s->lv || nl != v->nleaves || !s->leaf_mesh || !s->mesh || !s->pos || !s->ism) {
        gi_vlinks_shot_free(s);
        return NULL;
    }
    memcpy(s->leaf_mesh, v->leaf_mesh, sizeof *s->leaf_mesh * (size_t)nl);
    memcpy(s->mesh, v->mesh, sizeof *s->mesh * (size_t)v->nmesh);
    memcpy(s->pos, v->pos, sizeof *s->pos * (size_t)v->nv);
    memcpy(s->ism, v->ism, sizeof(float) * 4 * (size_t)v->ne);
    return s;
}

rgb gi_vlinks_shot_indirect(void *ctx, const accel_hit *hit, vec3 n, int thread)
{
    (void)thread;
    gi_vlinks_shot *s = ctx;
    vlook L = {s->lv, s->leaf_mesh, s->mesh, s->pos, s->ism, &s->lookups_other};
    return vlook_indirect(&L, hit, n);
}
