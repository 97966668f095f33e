/* gi_particle_gather.c - the particle GI mode's final gather at the
 * camera's hits (gi_particle_view_gather).
 *
 * Beyond seed 000: the paper ends at the radiance particles, E/pi estimated
 * from the area particles within the list radius and interpolated over the
 * surfaces' tessellation (section 4.3.2). That estimate is as coarse as the
 * particles: where the light changes within a list radius (the sky's
 * occlusion under an eave, a thin post, the contact of an object with the
 * floor) it blurs or misses it, and where none of a hit's radiance
 * particles is visible from it there is no answer. Here every kept primary
 * hit (keep_hits) that shows diffuse light gathers as an area particle
 * does: side x side stratified cosine-weighted rays from the hit (the same
 * link rays, gi_links_build), each taking the outgoing radiance of the
 * area particle it ends on, the sky where it leaves the scene and the far
 * field where no particle answers, their mean being E/pi (the gathering
 * step, equation 5 of the paper, at the pixel). This is final gathering
 * (as pbrt's photon mapper and POV-Ray's radiosity sample rays do): one
 * bounce exact in position and visibility, the rest from the particles.
 *
 * To spend rays where the light changes, the gather points are every
 * stride-th pixel in x and y; a pixel between takes the bilinear mean of
 * those of its block's corners that lie on its object, face its way and
 * are at its depth (within DEPTH_TOL), and gathers itself when none does
 * (edges and small objects get their own gathers, as an irradiance cache
 * refines where its records do not reach).
 *
 * The links (targets and the sky's share) are kept, so a new lighting
 * (gi_particle_relight) costs one pass over them (gi_particle_view_regather). */
#include "gi_particle_internal.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "gi_cl_c.h"
#include "gi_links.h"
#include "grow.h"
#include "hash.h"
#include "pool.h"
#include "timer.h"

#define DEPTH_TOL 0.05 /* relative depth a neighbour may differ by */
#define NORMAL_COS 0.9 /* and the cosine between the two normals */

/* The normal the gather at this kept hit uses: the smooth normal turned to
 * the side the camera sees (the hook's n has that side), unless it leans
 * away from the geometric normal of that side (then the geometric one). */
static vec3 hit_normal(const accel_hit *h, int side)
{
    vec3 ng = side ? h->ng : v3_neg(h->ng);
    double l = v3_len(ng);
    if (!(l > 0.0)) return ng;
    ng = v3_scale(ng, 1.0 / l);
    vec3 ns = h->ns;
    double ls = v3_len(ns);
    if (!(ls > 0.0) || !isfinite(ls)) return ng;
    ns = v3_scale(ns, 1.0 / ls);
    if (v3_dot(ns, ng) < 0.0) ns = v3_neg(ns);
    return v3_dot(ns, ng) > 0.5 ? ns : ng;
}

/* The side of kept hit r that the gather being built takes: the one the
 * camera sees, or for the other side's gather (back) the one behind. */
static int gather_side(const gi_particle *gp, const view_rec *r) { return gp->vg->back ? !r->side : r->side; }

static vec3 view_normal(const gi_particle *gp, const view_rec *r) { return hit_normal(&r->h, gather_side(gp, r)); }

/* A kept hit that takes diffuse light from the hook: on the side seen
 * where its finish has diffuse, and for the other side's gather where it
 * also has diffuse_back (the hook adds that side's light times B / A:
 * POV-Ray gathers a surface's back side for its diffuse_back as it
 * gathers the front, trace.cpp ComputeLightedTexture's second
 * ComputeAmbient about the reversed normal). */
static const scene_finish *kept_finish(const gi_particle *gp, const view_rec *r)
{
    if (r->kind != 2 || !r->h.obj) return NULL;
    return r->h.texture ? &r->h.texture->finish : &gp->sc->default_texture.finish;
}

static int gathers(const gi_particle *gp, const view_rec *r)
{
    const scene_finish *f = kept_finish(gp, r);
    return f && f->diffuse > 0.0 && (!gp->vg->back || f->diffuse_back != 0.0);
}

/* May pixel j take pixel i's gather? (vg_nrm: their view_normal) */
static int compatible(const gi_particle *gp, size_t i, size_t j)
{
    const view_rec *a = &gp->vrec[i], *b = &gp->vrec[j];
    if (a->h.obj != b->h.obj || a->side != b->side) return 0;
    if (!(fabs(a->h.t - b->h.t) <= DEPTH_TOL * b->h.t)) return 0;
    return v3_dot(gp->vg->nrm[i], gp->vg->nrm[j]) > NORMAL_COS;
}

static void view_gather_free_side(gi_view_gather *g)
{
    GROW_FREE_ALL(g->pt, g->cpt, g->ids, g->tab, g->link, g->esky, g->val, g->pix, g->pixval, g->nrm, g->pnrm);
    gi_gatherer_free(g->gatherer);
    g->gatherer = NULL;
    gi_link_conts_free(&g->cont);
    g->pt = g->cpt = NULL;
    g->tab = NULL;
    g->nrm = g->pnrm = NULL;
    g->ids = g->link = g->pix = NULL;
    g->esky = g->val = g->pixval = NULL;
    g->levels = 0;
    g->n = g->m1 = g->rk = 0;
    g->w = g->h = 0;
}

void gi_particle_view_gather_free(gi_particle *gp)
{
    view_gather_free_side(&gp->vgs[0]);
    view_gather_free_side(&gp->vgs[1]);
}

/* The corners of pixel (x, y)'s block and their bilinear weights (fewer
 * on the last row and column). */
static int corners(int x, int y, int w, int h, int s, int cx[4], int cy[4], double cw[4])
{
    int x0 = x - x % s, y0 = y - y % s, x1 = x0 + s, y1 = y0 + s;
    double fx = (double)(x - x0) / s, fy = (double)(y - y0) / s;
    int n = 0;
    int xs[2] = {x0, x1}, ys[2] = {y0, y1};
    double wx[2] = {1.0 - fx, fx}, wy[2] = {1.0 - fy, fy};
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            if (xs[i] >= w || ys[j] >= h || !(wx[i] * wy[j] > 0.0)) continue;
            cx[n] = xs[i];
            cy[n] = ys[j];
            cw[n] = wx[i] * wy[j];
            n++;
        }
    return n;
}

/* ---- the gather points by position, for hits that are not kept (the
 * antialiasing's extra rays, a reflection of a seen surface): a point
 * answers within its radius r, stride pixels' footprint at its depth.
 * Levels of cells, level L of size c0 2^L (c0 twice the smallest radius);
 * a point lies in the one cell of the level where r <= size / 2 that holds
 * it, so a query at p finds every point within reach in the 2 x 2 x 2
 * cells of each level nearest to p (those overlapping the box p +- size/2).
 * The cells are a hash table (open addressing) of runs in vg_ids. */

#define VG_LEVELS GI_VG_LEVELS

/* A cell's key: the level, then its x, y and z indices, chained (a query
 * shares the chain's first links between the cells it looks in). */
static uint64_t hash_step(uint64_t h, int64_t i) { return pt_mix64(h ^ (uint64_t)i); }

static uint64_t cell_hash(int level, int64_t ix, int64_t iy, int64_t iz)
{
    return hash_step(hash_step(hash_step(pt_mix64((uint64_t)level), ix), iy), iz) | 1; /* 0 marks an empty slot */
}

static int point_level(const gi_particle *gp, double r)
{
    int L = 0;
    while (L < VG_LEVELS - 1 && gp->vg->c0 * (double)(1u << L) < 2.0 * r) L++;
    return L;
}

typedef struct {
    uint64_t key;
    int id;
} keyed;

static int cmp_keyed(const void *a, const void *b)
{
    const keyed *x = a, *y = b;
    return x->key < y->key ? -1 : x->key > y->key ? 1 : (x->id > y->id) - (x->id < y->id);
}

static pt_status build_index(gi_particle *gp)
{
    int m = gp->vg->n;
    double rmin = INFINITY;
    for (int k = 0; k < m; k++)
        if (gp->vg->pt[k].r > 0.0f && gp->vg->pt[k].r < rmin) rmin = gp->vg->pt[k].r;
    if (!isfinite(rmin)) return PT_OK; /* no radii: kept hits only */
    gp->vg->c0 = 2.0 * rmin;
    keyed *kk = malloc((size_t)m * sizeof *kk);
    size_t cap = 64;
    while (cap < 2 * (size_t)m) cap *= 2;
    gp->vg->ids = malloc((size_t)m * sizeof *gp->vg->ids);
    gp->vg->cpt = malloc((size_t)m * sizeof *gp->vg->cpt);
    gp->vg->tab = calloc(cap, sizeof *gp->vg->tab);
    if (!kk || !gp->vg->ids || !gp->vg->cpt || !gp->vg->tab) {
        free(kk);
        return PT_ERR_NOMEM;
    }
    gp->vg->tab_mask = cap - 1;
    unsigned used = 0;
    for (int k = 0; k < m; k++) {
        const vg_point *pt = &gp->vg->pt[k];
        int L = point_level(gp, pt->r);
        vec3 *box = gp->vg->lvl_box + 2 * L;
        box[0] = used >> L & 1u ? v3_min(box[0], pt->p) : pt->p;
        box[1] = used >> L & 1u ? v3_max(box[1], pt->p) : pt->p;
        used |= 1u << L;
        double c = gp->vg->c0 * (double)(1u << L);
        kk[k].key = cell_hash(L, (int64_t)floor(pt->p.x / c), (int64_t)floor(pt->p.y / c), (int64_t)floor(pt->p.z / c));
        kk[k].id = k;
    }
    gp->vg->levels = used;
    qsort(kk, (size_t)m, sizeof *kk, cmp_keyed);
    for (int e = 0; e < m;) {
        int f = e;
        while (f < m && kk[f].key == kk[e].key) {
            gp->vg->ids[f] = kk[f].id;
            gp->vg->cpt[f] = gp->vg->pt[kk[f].id];
            f++;
        }
        size_t slot = (size_t)kk[e].key & gp->vg->tab_mask;
        while (gp->vg->tab[slot].key) slot = (slot + 1) & gp->vg->tab_mask;
        gp->vg->tab[slot].key = kk[e].key;
        gp->vg->tab[slot].start = e;
        gp->vg->tab[slot].count = f - e;
        e = f;
    }
    free(kk);
    return PT_OK;
}

/* Whether gather point pt may answer a hit at p with normal ng (length
 * lg) that is not kept, by POV-Ray's test for reusing an irradiance cache
 * record (radiosity.cpp, Ward's error measure). Under radiosity `normal
 * on` POV-Ray files a record under the perturbed normal it gathered about
 * and compares the hit's perturbed normal (ComputeAmbient's
 * effectiveNormal): n_pt is then pt->pn and ng the hit's. With a the scene's
 * error_bound and R the point's reach, its distance d < a R and
 * d / R + 2 sqrt(1 - n . n_pt) < a, and the point does not lie in front
 * of p (the direction from it to p makes an angle of at most about 93
 * degrees with the mean of the two normals; POV-Ray's in-front limit
 * -0.05). A hit in a recess thus does not take the light of the rim
 * above it, nor a hit beside a wall the light of a point farther out. */
static int reusable(const gi_particle *gp, const vg_point *pt, vec3 p, vec3 ng, double lg)
{
    const double a = gp->set.reuse_error;
    vec3 dv = v3_sub(p, pt->p);
    double d = v3_len(dv), R = pt->reach;
    if (!(d < a * R)) return 0;
    /* toward the nearest surface its rays found, the reach shrinks to that
     * surface's distance (POV-Ray's radiosity.cpp, AverageNearBlock: ri = c
     * Nearest_Distance + (1 - c) ri, c the cosine between the offset and the
     * direction to that surface, where positive): at a contact a record
     * does not answer the hits between it and the other surface */
    double nd = sqrt((double)pt->nearest[0] * pt->nearest[0] + (double)pt->nearest[1] * pt->nearest[1] +
                     (double)pt->nearest[2] * pt->nearest[2]);
    if (d > 0.0 && nd > 0.0) {
        double cn = (dv.x * pt->nearest[0] + dv.y * pt->nearest[1] + dv.z * pt->nearest[2]) / (d * nd);
        if (cn > 0.0) R = cn * nd + (1.0 - cn) * R;
        if (!(d < a * R)) return 0;
    }
    double c = v3_dot(pt->pn, ng) / lg;
    if (!(d / R + 2.0 * sqrt(fmax(0.0, 1.0 - c)) < a)) return 0;
    vec3 half = v3_add(pt->pn, v3_scale(ng, 1.0 / lg));
    double hl = v3_len(half);
    return !(d > 0.0 && hl > 0.0) || v3_dot(dv, half) / (d * hl) > -0.05;
}

/* E/pi at a hit that is not kept, from the gather points around it on its
 * object and side that face its way: weights 1 - d/r. relaxed: any
 * object's points that face its way, within twice their radius (an
 * antialiasing ray on a part too thin for a kept pixel of its own: the
 * light of its neighbours, not the unoccluded sky). 0: none. */
static int nearby_value(const gi_particle *gp, const gi_view_gather *g, const accel_hit *hit, vec3 n, int relaxed,
                        rgb *out)
{
    if (!g->tab || !hit->obj) return 0;
    int side = v3_dot(n, hit->ng) >= 0.0;
    vec3 ng = side ? hit->ng : v3_neg(hit->ng);
    double lg = v3_len(ng), s[3] = {0.0, 0.0, 0.0}, ws = 0.0;
    /* the normal POV-Ray's cache compares: under radiosity `normal on` the
     * shading's perturbed n (core/radrules.h rule 5) */
    vec3 qn = gp->set.normal_at && v3_dot(n, ng) > 0.0 ? v3_norm(n) : v3_scale(ng, 1.0 / lg);
    for (int L = 0; L < VG_LEVELS; L++) {
        if (!(g->levels >> L & 1u)) continue;
        double c = g->c0 * (double)(1u << L);
        /* a point of this level answers within r <= c/2 (relaxed 2r <= c;
         * the last level's may be larger): none does from farther than c
         * outside the box of its points */
        const vec3 *box = g->lvl_box + 2 * L;
        if (L < VG_LEVELS - 1 &&
            (hit->p.x < box[0].x - c || hit->p.y < box[0].y - c || hit->p.z < box[0].z - c ||
             hit->p.x > box[1].x + c || hit->p.y > box[1].y + c || hit->p.z > box[1].z + c))
            continue;
        /* the 2 cells per axis overlapping p +- c/2 (relaxed: the 3 around
         * p's, which hold every point within c); cell_hash's chain over
         * the x and y indices is shared by the cells that have them */
        int64_t i0[3];
        int span = relaxed ? 3 : 2, ncell = span * span * span;
        const double sh = relaxed ? 0.0 : 0.5;
        const double pc[3] = {hit->p.x / c - sh, hit->p.y / c - sh, hit->p.z / c - sh};
        for (int a = 0; a < 3; a++) i0[a] = (int64_t)floor(pc[a]) - (relaxed ? 1 : 0);
        uint64_t hl = pt_mix64((uint64_t)L), hx[3], hxy[9];
        for (int a = 0; a < span; a++) hx[a] = hash_step(hl, i0[0] + a);
        for (int a = 0; a < span * span; a++) hxy[a] = hash_step(hx[a % span], i0[1] + a / span);
        for (int corner = 0; corner < ncell; corner++) {
            uint64_t key = hash_step(hxy[corner % (span * span)], i0[2] + corner / (span * span)) | 1;
            size_t slot = (size_t)key & g->tab_mask;
            while (g->tab[slot].key && g->tab[slot].key != key) slot = (slot + 1) & g->tab_mask;
            if (!g->tab[slot].key) continue;
            for (int e = g->tab[slot].start, end = e + g->tab[slot].count; e < end; e++) {
                const vg_point *pt = &g->cpt[e];
                if (!relaxed && (pt->obj != hit->obj || pt->side != side)) continue;
                double r = relaxed ? 2.0 * pt->r : pt->r;
                vec3 dv = v3_sub(hit->p, pt->p);
                /* most points lie out of reach: known from the squared
                 * distance (a margin far above its rounding) before the
                 * square root, whose latency the test below waited on */
                double d2 = v3_dot(dv, dv);
                if (d2 > r * r * (1.0 + 1e-9)) continue;
                double d = sqrt(d2);
                if (!(d < r) || (!relaxed && fabs(v3_dot(dv, pt->n)) > 0.25 * r)) continue;
                if (v3_dot(pt->n, ng) < NORMAL_COS * lg) continue;
                if (gp->vgs[0].gatherer && !reusable(gp, pt, hit->p, qn, 1.0)) continue;
                double w = 1.0 - d / r;
                const float *v = &g->val[4 * (size_t)g->ids[e]];
                for (int q = 0; q < 3; q++) s[q] += w * v[q];
                ws += w;
            }
        }
    }
    if (!(ws > 0.0)) return 0;
    out->r = s[0] / ws;
    out->g = s[1] / ws;
    out->b = s[2] / ws;
    return 1;
}

/* The raw E/pi of the vg_n gather points into vg_val from their links and
 * esky (the gathering kernel's C build: equation 5 at the pixels). 0: out
 * of memory. */
static int gather_values(gi_particle *gp)
{
    int *idx = malloc((size_t)gp->vg->n * sizeof *idx);
    /* the particles' reflected radiance, the sky light they reflect
     * included: their own emission was taken where each ray hit
     * (gi_links.h, first > 0) */
    float *lrefl = malloc((size_t)gp->ps.n * 4 * sizeof *lrefl);
    if (!idx || !lrefl) {
        free(idx);
        free(lrefl);
        return 0;
    }
    for (int i = 0; i < gp->vg->n; i++) idx[i] = i;
    for (int t = 0; t < gp->ps.n; t++) {
        for (int c = 0; c < 3; c++) {
            float v = gp->lout[4 * (size_t)t + c] - gi_particle_own_emission(gp, t, c);
            lrefl[4 * (size_t)t + c] = v > 0.0f ? v : 0.0f;
        }
        lrefl[4 * (size_t)t + 3] = 0.0f;
    }
    /* points [0, m1) take vg_k rays; the refinement points [m1, vg_n)
     * vg_rk, their rows packed from row m1: the kernel reads point i's
     * row at i times its k from the pointer it is given */
    int m1 = gp->vg->m1 > 0 && gp->vg->m1 < gp->vg->n && gp->vg->rk > 0 ? gp->vg->m1 : gp->vg->n;
    gi_c_gather(gp->threads, gp->vg->link, gp->vg->k, lrefl, idx, m1, gp->vg->esky, gp->vg->val);
    if (m1 < gp->vg->n)
        gi_c_gather(gp->threads, gp->vg->link + (size_t)m1 * (size_t)(gp->vg->k - gp->vg->rk), gp->vg->rk, lrefl, idx + m1,
                    gp->vg->n - m1, gp->vg->esky, gp->vg->val);
    /* the continuations that ended on particles (mirrors, glass): their
     * weight times that particle's reflected light, in the points' order */
    for (long q = 0; q < gp->vg->cont.n; q++) {
        const gi_link_cont *e = &gp->vg->cont.e[q];
        if (e->src >= gp->vg->n) continue;
        for (int c = 0; c < 3; c++) gp->vg->val[4 * (size_t)e->src + c] += e->w[c] * lrefl[4 * (size_t)e->t + c];
    }
    free(idx);
    free(lrefl);
    return 1;
}

/* Gather point k (kept pixel i) as a link source at slot cp[t], its
 * object and inside flag at cobj[t], cpin[t], and its record vg_pt[k]. */
static void put_point(gi_particle *gp, gi_dev_particle *cp, const void **cobj, unsigned char *cpin, long t, int k,
                      size_t i, int s)
{
    int w = gp->vw, h = gp->vh;
    const view_rec *r = &gp->vrec[i];
    vec3 nv = gp->vg->nrm[i];
    gi_dev_particle *q = &cp[t];
    v3_store_f(q->p, r->h.p);
    /* its rays about the texture's perturbed normal under radiosity
     * `normal on` (core/radrules.h rule 5, vg_pnrm) */
    vec3 ngat = gp->vg->pnrm[i];
    v3_store_f(q->n, ngat);
    q->area = 0.0f;
    const scene_object *o = r->h.obj;
    /* its radius: stride pixels' footprint on the surface (the distance
     * between neighbouring camera rays at its depth, over the cosine: the
     * angle between them times the depth from one eye point, the distance
     * between their origins for an orthographic camera's parallel rays) */
    size_t x = i % (size_t)w, y = i / (size_t)w;
    const view_rec *nb = &gp->vrec[x + 1 < (size_t)w ? i + 1 : (y + 1 < (size_t)h ? i + (size_t)w : i)];
    double foot = 0.0;
    if (nb != r && nb->kind) {
        vec3 d0 = v3_norm(r->dir), d1 = v3_norm(nb->dir);
        if (r->org.x == nb->org.x && r->org.y == nb->org.y && r->org.z == nb->org.z)
            foot = s * r->h.t * v3_len(v3_sub(d1, d0));
        else
            foot = s * v3_len(v3_sub(v3_madd(nb->org, d1, r->h.t), v3_madd(r->org, d0, r->h.t)));
    }
    double cs = fabs(v3_dot(v3_norm(r->dir), nv));
    vg_point *vp = &gp->vg->pt[k];
    vp->p = r->h.p;
    vp->n = nv;
    vp->pn = ngat;
    vp->obj = o;
    vp->side = gather_side(gp, r);
    vp->r = (float)(foot / (cs > 0.25 ? cs : 0.25));
    cobj[t] = o;
    /* on the inside of a closed sphere or box (as gi_particle_objects
     * marks particles): its rays end inside it */
    if ((o->kind == SHAPE_SPHERE || o->kind == SHAPE_BOX) && !(o->flags & OBJ_INVERSE)) {
        vec3 p = r->h.p;
        double lift = 1e-5 * (1.0 + fmax(fabs(p.x), fmax(fabs(p.y), fabs(p.z))));
        cpin[t] = (unsigned char)gi_surface_inside_solid(o, v3_madd(p, nv, lift));
    }
}

/* put_point for the points [k0, k1) on one row of pixels (each point
 * writes its own slots: rows may run on any thread). */
typedef struct {
    gi_particle *gp;
    gi_dev_particle *cp;
    const void **cobj;
    unsigned char *cpin;
    int n, k0, k1, s;
} put_job;

static void put_row(void *ctx, int y, int thread)
{
    (void)thread;
    put_job *P = ctx;
    gi_particle *gp = P->gp;
    size_t w = (size_t)gp->vw;
    for (size_t i = (size_t)y * w; i < (size_t)(y + 1) * w; i++) {
        int k = gp->vg->pix[i];
        if (k >= P->k0 && k < P->k1) put_point(gp, P->cp, P->cobj, P->cpin, P->n + (k - P->k0), k, i, P->s);
    }
}

/* Traces the links of gather points [k0, k1) (the pixels vg_pix names),
 * side x side rays each, into vg_link from row k0 on (rows of vg_k
 * links; a side below the rows' packs side^2 links a row from there, as
 * gather_values reads the refinement points' rows) and vg_esky: gi_links_build with the area particles
 * as targets and the points as its sources [n, n + k1 - k0). */
static pt_status trace_points(gi_particle *gp, const void **pobj, const unsigned char *pin, const gi_lookup *grid,
                              int k0, int k1, int side, int s, uint64_t seed, long *rays)
{
    int n = gp->ps.n;
    long N = (long)n + (k1 - k0);
    size_t npix = (size_t)gp->vw * (size_t)gp->vh;
    gi_dev_particle *cp = calloc((size_t)N, sizeof *cp);
    const void **cobj = calloc(2 * (size_t)N, sizeof *cobj);
    unsigned char *cpin = calloc(2 * (size_t)N, 1);
    float *reach = NULL;
    pt_status st = PT_OK;
    if (!cp || !cobj || !cpin) {
        st = PT_ERR_NOMEM;
        goto done;
    }
    if (n > 0) memcpy(cp, gp->ps.p, (size_t)n * sizeof *cp);
    for (int t = 0; t < n; t++) {
        cobj[t] = pobj[t];
        cobj[N + t] = pobj[n + t];
        cpin[t] = pin[t];
        cpin[N + t] = pin[n + t];
    }
    put_job P = {gp, cp, cobj, cpin, n, k0, k1, s};
    pool_run(gp->threads, gp->vh, put_row, &P);
    double spacing = gp->ps.spacing > 0.0 ? gp->ps.spacing : 1.0;
    gi_link_stats ls = {0};
    reach = malloc((size_t)(k1 - k0) * 4 * sizeof *reach);
    if (!reach) {
        st = PT_ERR_NOMEM;
        goto done;
    }
    long c0 = gp->vg->cont.n;
    gi_hit_light hl = gi_particle_hit_light(gp);
    st = gi_links_build(gp->a, gp->lscene, cp, cobj, cpin, (int)N, n, side, seed, grid, gp->tl, 3.0 * spacing, gp->threads,
                        gp->vg->link + (size_t)k0 * gp->vg->k, NULL, &ls, gp->set.cancel, NULL, gp->sky,
                        gp->vg->esky + 4 * (size_t)k0, gp->sc, gp->set.pigment,
                        gp->set.bounces >= 1 ? gp->set.brightness : 0.0, reach, &gp->vg->cont, &hl);
    for (long q = c0; q < gp->vg->cont.n; q++) gp->vg->cont.e[q].src += k0; /* the points' own numbers */
    *rays += ls.rays;
    /* each point's reach within POV-Ray's minimum_reuse and maximum_reuse
     * of its distance from the camera (radiosity.cpp clamps its records'
     * harmonic mean distance so) */
    for (size_t i = 0; st == PT_OK && i < npix; i++) {
        int k = gp->vg->pix[i];
        if (k < k0 || k >= k1) continue;
        double t = gp->vrec[i].h.t, R = reach[4 * (size_t)(k - k0)];
        for (int c = 0; c < 3; c++) gp->vg->pt[k].nearest[c] = reach[4 * (size_t)(k - k0) + 1 + c];
        if (gp->set.reuse_min > 0.0 && R < gp->set.reuse_min * t) R = gp->set.reuse_min * t;
        if (gp->set.reuse_max > 0.0 && R > gp->set.reuse_max * t) R = gp->set.reuse_max * t;
        gp->vg->pt[k].reach = (float)R;
    }
done:
    free(cp);
    free(cobj);
    free(cpin);
    free(reach);
    return st;
}

/* Whether kept pixel i, which takes its block's corners, should gather
 * itself instead: the corners that match it differ in luminance by more
 * than REFINE (interpolation would guess across a change of the light,
 * where an irradiance cache would place a record of its own). */
#define REFINE 0.15
/* the side of a refinement gather over the corners' side
 * (gi_particle_view_gather) */
#define REFINE_SIDE_FRAC 0.71
/* the self-gathering hits' side where their rays are occlusion tests
 * (gi_gatherer_dark) over the side otherwise: chosen so that the render's
 * CPU time is about that of nearest-hit rays at the smaller side
 * (docs/gi.md, "Gather rays that only need the sky") */
#define DARK_SIDE_GAIN (4.0 / 3.0)
static int needs_own(const gi_particle *gp, size_t i)
{
    int x = (int)(i % (size_t)gp->vw), y = (int)(i / (size_t)gp->vw);
    int cx[4], cy[4];
    double cw[4], lo = INFINITY, hi = 0.0;
    int nc = corners(x, y, gp->vw, gp->vh, gp->vg->s, cx, cy, cw), m = 0;
    for (int c = 0; c < nc; c++) {
        size_t j = (size_t)cy[c] * gp->vw + cx[c];
        int kc = gp->vg->pix[j];
        if (kc < 0 || !compatible(gp, j, i)) continue;
        /* a corner whose record POV-Ray's cache would not reuse here */
        if (gi_particle_exact_gather(&gp->set) && !reusable(gp, &gp->vg->pt[kc], gp->vrec[i].h.p, gp->vg->pnrm[i], 1.0))
            return 1;
        const float *v = &gp->vg->val[4 * (size_t)kc];
        double l = 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2];
        lo = fmin(lo, l);
        hi = fmax(hi, l);
        m++;
    }
    return m > 1 && hi > (1.0 + REFINE) * lo;
}

/* vg_nrm and vg_pnrm of one row of pixels */
static void normal_row(void *ctx, int y, int thread)
{
    (void)thread;
    gi_particle *gp = ctx;
    size_t w = (size_t)gp->vw;
    for (size_t i = (size_t)y * w; i < (size_t)(y + 1) * w; i++) {
        vec3 n = gp->vrec[i].kind == 2 ? view_normal(gp, &gp->vrec[i]) : v3s(0.0);
        gp->vg->nrm[i] = gp->vg->pnrm[i] = n;
        if (gp->set.normal_at && gathers(gp, &gp->vrec[i])) gp->set.normal_at(gp->sc, &gp->vrec[i].h, n, &gp->vg->pnrm[i]);
    }
}

/* own[i]: whether pixel i of the row, which takes its block's corners,
 * gathers itself (needs_own) */
typedef struct {
    const gi_particle *gp;
    unsigned char *own;
} own_job;

static void own_row(void *ctx, int y, int thread)
{
    (void)thread;
    own_job *O = ctx;
    const gi_particle *gp = O->gp;
    size_t w = (size_t)gp->vw;
    for (size_t i = (size_t)y * w; i < (size_t)(y + 1) * w; i++)
        O->own[i] = (unsigned char)(gp->vg->pix[i] < 0 && gathers(gp, &gp->vrec[i]) && needs_own(gp, i));
}

static void regather_side(gi_particle *gp);

/* The final gather of the side gp->vg takes (gi_particle_view_gather). */
static pt_status view_gather_side(gi_particle *gp)
{
    int side = gp->set.view_gather_side, s = gp->set.view_gather_stride > 0 ? gp->set.view_gather_stride : 2;
    if (side <= 0 || !gp->vrec || gp->vw <= 0 || gp->vh <= 0 || !gp->lout || (gp->ps.n <= 0 && !gp->final_only))
        return PT_OK;
    int w = gp->vw, h = gp->vh;
    size_t npix = (size_t)w * (size_t)h;
    pt_status st = PT_OK;
    /* vg_pix: the gather point of a pixel, -1 none (it interpolates or
     * takes the old estimate) */
    gp->vg->pix = malloc(npix * sizeof *gp->vg->pix);
    gp->vg->nrm = malloc(npix * sizeof *gp->vg->nrm);
    gp->vg->pnrm = malloc(npix * sizeof *gp->vg->pnrm);
    if (!gp->vg->pix || !gp->vg->nrm || !gp->vg->pnrm) {
        view_gather_free_side(gp->vg);
        return PT_ERR_NOMEM;
    }
    pool_run(gp->threads, h, normal_row, gp);
    int m = 0, mmax = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            gp->vg->pix[i] = -1;
            if (!gathers(gp, &gp->vrec[i])) continue;
            mmax++;
            if (x % s == 0 && y % s == 0) gp->vg->pix[i] = m++;
        }
    /* pixels no corner answers gather themselves */
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            if (gp->vg->pix[i] >= 0 || !gathers(gp, &gp->vrec[i])) continue;
            int cx[4], cy[4];
            double cw[4];
            int nc = corners(x, y, w, h, s, cx, cy, cw), ok = 0;
            for (int k = 0; k < nc && !ok; k++) {
                size_t c = (size_t)cy[k] * w + cx[k];
                ok = gp->vg->pix[c] >= 0 && compatible(gp, c, i);
            }
            if (!ok) gp->vg->pix[i] = m++;
        }
    if (m == 0) return PT_OK;
    /* room for every gathering pixel: the refinement below adds points */
    unsigned char *pin = NULL;
    const void **pobj = gi_particle_objects(gp, &gp->ps, &pin, &st);
    gp->vg->link = malloc((size_t)mmax * side * side * sizeof *gp->vg->link);
    gp->vg->esky = calloc((size_t)mmax * 4, sizeof *gp->vg->esky);
    gp->vg->val = calloc((size_t)mmax * 4, sizeof *gp->vg->val);
    gp->vg->pt = calloc((size_t)mmax, sizeof *gp->vg->pt);
    gi_lookup *grid = NULL;
    if (!pobj || !pin || !gp->vg->link || !gp->vg->esky || !gp->vg->val || !gp->vg->pt || st != PT_OK) {
        st = PT_ERR_NOMEM;
        goto done;
    }
    double spacing = gp->ps.spacing > 0.0 ? gp->ps.spacing : 1.0;
    grid = gi_lookup_build(&gp->ps, 2.0 * spacing);
    if (!grid) {
        st = PT_ERR_NOMEM;
        goto done;
    }
    st = gi_lookup_set_objects(grid, (const void *const *)pobj);
    gp->vg->k = side * side;
    gp->vg->w = w;
    gp->vg->h = h;
    gp->vg->s = s;
    long rays = 0;
    /* the triangle lists of the particles as they are now (built once for
     * the views: the geometry stage's were built before the pruning, and
     * a geometry stage read from a cache has none; so a render gives the
     * same image with and without --gi-cache). A ray that hits a triangle
     * they cover takes the particle at the centre of its cell (gi_links.h) */
    if (st == PT_OK && !gp->tl && gp->ps.n > 0)
        gp->tl = gi_trilook_build(gp->a, gp->ps.p, gp->ps.n, (const void *const *)pobj, grid, pin + gp->ps.n,
                                  spacing, GI_LINKS_AGREE, 3.0 * spacing, gp->threads, gp->set.cancel, &st);
    if (st == PT_OK && gp->tl && !gi_trilook_centres(gp->tl, gp->threads)) st = PT_ERR_NOMEM;
    if (st == PT_OK) st = trace_points(gp, pobj, pin, grid, 0, m, side, s, gp->set.seed ^ 0x7a9e7ULL, &rays);
    /* refinement (an irradiance cache's adaptive placement): pixels whose
     * matching corners disagree gather themselves, traced as a second set */
    if (st == PT_OK && s > 1) {
        gp->vg->n = m;
        gather_values(gp);
        int m1 = m;
        /* which pixels gather themselves (needs_own reads only the corner
         * points, which this pass does not change), then their numbers in
         * pixel order */
        unsigned char *own = malloc(npix);
        if (!own) {
            st = PT_ERR_NOMEM;
            goto done;
        }
        own_job O = {gp, own};
        pool_run(gp->threads, h, own_row, &O);
        for (size_t i = 0; i < npix; i++)
            if (own[i]) gp->vg->pix[i] = m++;
        free(own);
        if (m > m1) {
            /* a refinement point takes REFINE_SIDE_FRAC of the side: such
             * points sit where the light changes across a block, where
             * that change rather than the gather's noise is what shows
             * (docs/gi.md gives the trade against POV-Ray's own render).
             * Their rows are packed from row m1 on, rs^2 links each, and
             * the regather takes them so (vg_m1, vg_rk) */
            int rs = (int)lround(side * REFINE_SIDE_FRAC);
            if (rs < 4) rs = 4;
            if (rs > side) rs = side;
            st = trace_points(gp, pobj, pin, grid, m1, m, rs, s, gp->set.seed ^ 0x3c5b1ULL, &rays);
            gp->vg->m1 = m1;
            gp->vg->rk = rs * rs;
        }
    }
    /* with no bounce after the gather's hits (the exact gather, gi_links.h)
     * a hit no point may answer gathers itself, as POV-Ray's cache adds a
     * record where none can be reused */
    if (st == PT_OK && gi_particle_exact_gather(&gp->set) && !gp->vg->back) {
        /* by default a third of the side: such hits are mostly
         * antialiasing rays, each one of the (depth^2 + 1) samples a pixel
         * averages, so a pixel's 9 subsamples together still take about a
         * gather's rays (more where POV-Ray's cache reuses nearly nothing:
         * gi_particle_settings_from_scene) */
        double frac = gp->set.here_side_frac > 0.0 ? gp->set.here_side_frac : 1.0 / 3.0;
        int hs = (int)ceil(side * frac - 1e-9);
        if (hs < 4) hs = 4;
        gp->vg->gatherer = gi_gatherer_new(gp->a, gp->lscene, hs, gp->set.seed ^ 0x51d3ULL, gp->sky, gp->sc,
                                          gp->set.pigment);
        gi_hit_light hl = gi_particle_hit_light(gp);
        gi_gatherer_set_light(gp->vg->gatherer, &hl);
        /* where its rays need only occlusion tests (gi_gatherer_dark), the
         * time of hs^2 nearest-hit rays buys about DARK_SIDE_GAIN^2 times
         * as many: less noise for the same time */
        int hd = (int)ceil(hs * DARK_SIDE_GAIN - 1e-9);
        if (gp->vg->gatherer && gi_gatherer_dark(gp->vg->gatherer) && hd > hs) {
            gi_gatherer_free(gp->vg->gatherer);
            gp->vg->gatherer = gi_gatherer_new(gp->a, gp->lscene, hd, gp->set.seed ^ 0x51d3ULL, gp->sky, gp->sc,
                                              gp->set.pigment);
            gi_gatherer_set_light(gp->vg->gatherer, &hl);
        }
        if (!gp->vg->gatherer) st = PT_ERR_NOMEM;
    }
    if (st == PT_OK) {
        gp->vg->n = m;
        gp->st.view_gathers = (gp->vg->back ? gp->st.view_gathers : 0) + m;
        gp->st.view_gather_rays = (gp->vg->back ? gp->st.view_gather_rays : 0) + rays;
        regather_side(gp);
        st = build_index(gp);
    }
done:
    gi_lookup_free(grid);
    free(pobj);
    free(pin);
    if (st != PT_OK) view_gather_free_side(gp->vg);
    return st;
}

/* Whether some kept hit's finish has diffuse_back: then the other side of
 * those hits is gathered too (gathers). */
static int any_back(const gi_particle *gp)
{
    for (size_t i = 0, npix = (size_t)gp->vw * (size_t)gp->vh; i < npix; i++) {
        const scene_finish *f = kept_finish(gp, &gp->vrec[i]);
        if (f && f->diffuse > 0.0 && f->diffuse_back != 0.0) return 1;
    }
    return 0;
}

pt_status gi_particle_view_gather(gi_particle *gp, diag *d)
{
    (void)d;
    gi_particle_view_gather_free(gp);
    gp->vg = &gp->vgs[0];
    pt_status st = view_gather_side(gp);
    if (st == PT_OK && gp->vrec && any_back(gp)) {
        gp->vg = &gp->vgs[1];
        st = view_gather_side(gp);
        gp->vg = &gp->vgs[0];
    }
    if (st != PT_OK) gi_particle_view_gather_free(gp);
    return st;
}

/* E/pi at kept pixel i from the raw gathers: its own, or the bilinear
 * mean of its block's corners that match it. 0: neither. */
static int raw_value(const gi_particle *gp, size_t i, float out[3])
{
    int k = gp->vg->pix[i];
    if (k >= 0) {
        for (int c = 0; c < 3; c++) out[c] = gp->vg->val[4 * (size_t)k + c];
        return 1;
    }
    const view_rec *r = &gp->vrec[i];
    if (!gathers(gp, r)) return 0;
    int x = (int)(i % (size_t)gp->vw), y = (int)(i / (size_t)gp->vw);
    int cx[4], cy[4];
    double cw[4], s[3] = {0.0, 0.0, 0.0}, ws = 0.0;
    int nc = corners(x, y, gp->vw, gp->vh, gp->vg->s, cx, cy, cw);
    for (int c = 0; c < nc; c++) {
        size_t j = (size_t)cy[c] * gp->vw + cx[c];
        int kc = gp->vg->pix[j];
        if (kc < 0 || !compatible(gp, j, i)) continue;
        for (int q = 0; q < 3; q++) s[q] += cw[c] * gp->vg->val[4 * (size_t)kc + q];
        ws += cw[c];
    }
    if (!(ws > 0.0)) return 0;
    for (int q = 0; q < 3; q++) out[q] = (float)(s[q] / ws);
    return 1;
}

/* The edge-aware filter over the pixels' raw values: a Gaussian of
 * view_gather_filter pixels (default FILTER_SIGMA; none below 0), to 2 sigma, over the
 * pixels that lie on the same object and
 * side, face the same way and lie in the same plane (compatible, and the
 * offset along the normal within DEPTH_TOL of the depth). It averages the
 * gathers' noise over about (2 sigma / stride)^2 gathers, as an irradiance
 * cache reuses a record over its radius, and stops at edges, creases and
 * depth steps, where the light may change. */
#define FILTER_SIGMA 1.0
#define FILTER_RADIUS_MAX 8

typedef struct {
    gi_particle *gp;
    const float *raw;
    const unsigned char *ok;
} filter_job;

static void filter_row(void *ctx, int y, int thread)
{
    (void)thread;
    filter_job *F = ctx;
    gi_particle *gp = F->gp;
    int w = gp->vw, h = gp->vh;
    /* sigma from the settings (default FILTER_SIGMA), the taps to 2 sigma */
    const double sigma = gp->set.view_gather_filter != 0.0 ? gp->set.view_gather_filter : FILTER_SIGMA;
    int R = sigma > 0.0 ? (int)ceil(2.0 * sigma) : 0; /* below 0: no filter, the pixel's own value */
    if (R > FILTER_RADIUS_MAX) R = FILTER_RADIUS_MAX;
    double g[FILTER_RADIUS_MAX + 1];
    for (int d = 0; d <= R; d++) g[d] = exp(-0.5 * d * d / (sigma * sigma));
    /* under radiosity `normal on` a tap whose gather's perturbed normal
     * differs from the pixel's by more than POV-Ray's cache lets a record
     * be reused over (Ward's normal term, 2 sqrt(1 - cos) below the error
     * bound: reusable) is left out, as the bumps' light is the pixel's own */
    const double a = gp->set.normal_at && gi_particle_exact_gather(&gp->set) ? gp->set.reuse_error : 0.0;
    /* with no bounce after the gathers' hits, a tap that gathered itself
     * is left out where POV-Ray's cache would not reuse its record at the
     * pixel (reusable: near a contact its reach shrinks toward the other
     * surface, so the brighter light of the taps farther out stays there) */
    const int exact = gi_particle_exact_gather(&gp->set);
    for (int x = 0; x < w; x++) {
        size_t i = (size_t)y * w + x;
        float *o = &gp->vg->pixval[4 * i];
        o[3] = 0.0f;
        if (!F->ok[i]) continue;
        const view_rec *r = &gp->vrec[i];
        vec3 nr = gp->vg->nrm[i], pn = gp->vg->pnrm[i];
        double s[3] = {0.0, 0.0, 0.0}, ws = 0.0;
        for (int dy = -R; dy <= R; dy++) {
            int yy = y + dy;
            if (yy < 0 || yy >= h) continue;
            for (int dx = -R; dx <= R; dx++) {
                int xx = x + dx;
                if (xx < 0 || xx >= w) continue;
                size_t j = (size_t)yy * w + xx;
                if (!F->ok[j]) continue;
                const view_rec *q = &gp->vrec[j];
                if (j != i && (!compatible(gp, j, i) || fabs(v3_dot(v3_sub(q->h.p, r->h.p), nr)) > DEPTH_TOL * r->h.t))
                    continue;
                if (j != i && exact && gp->vg->pix[j] >= 0 && !reusable(gp, &gp->vg->pt[gp->vg->pix[j]], r->h.p, pn, 1.0))
                    continue;
                if (j != i && a > 0.0 && !(2.0 * sqrt(fmax(0.0, 1.0 - v3_dot(gp->vg->pnrm[j], pn))) < a)) continue;
                double wt = g[dx < 0 ? -dx : dx] * g[dy < 0 ? -dy : dy];
                for (int c = 0; c < 3; c++) s[c] += wt * F->raw[3 * j + c];
                ws += wt;
            }
        }
        for (int c = 0; c < 3; c++) o[c] = (float)(s[c] / ws);
        o[3] = 1.0f;
    }
}

/* The raw values (raw_value) of one row of pixels and whether each has one */
typedef struct {
    const gi_particle *gp;
    float *raw;
    unsigned char *ok;
} raw_job;

static void raw_row(void *ctx, int y, int thread)
{
    (void)thread;
    raw_job *R = ctx;
    size_t w = (size_t)R->gp->vw;
    for (size_t i = (size_t)y * w; i < (size_t)(y + 1) * w; i++)
        R->ok[i] = (unsigned char)raw_value(R->gp, i, &R->raw[3 * i]);
}

static void regather_side(gi_particle *gp)
{
    if (gp->vg->n <= 0 || !gp->lout) return;
    size_t npix = (size_t)gp->vw * (size_t)gp->vh;
    float *raw = malloc(npix * 3 * sizeof *raw);
    unsigned char *ok = malloc(npix);
    if (!gp->vg->pixval) gp->vg->pixval = malloc(npix * 4 * sizeof *gp->vg->pixval);
    if (!raw || !ok || !gp->vg->pixval || !gather_values(gp)) {
        free(raw);
        free(ok);
        view_gather_free_side(gp->vg);
        return;
    }
    raw_job R = {gp, raw, ok};
    pool_run(gp->threads, gp->vh, raw_row, &R);
    filter_job F = {gp, raw, ok};
    pool_run(gp->threads, gp->vh, filter_row, &F);
    /* the points answer hits that are not kept with the filtered value of
     * their pixel too */
    for (size_t i = 0; i < npix; i++) {
        int k = gp->vg->pix[i];
        if (k >= 0 && gp->vg->pixval[4 * i + 3] > 0.0f)
            for (int c = 0; c < 3; c++) gp->vg->val[4 * (size_t)k + c] = gp->vg->pixval[4 * i + c];
    }
    free(raw);
    free(ok);
}

void gi_particle_view_regather(gi_particle *gp)
{
    for (int b = 0; b < 2; b++) {
        gp->vg = &gp->vgs[b];
        regather_side(gp);
    }
    gp->vg = &gp->vgs[0];
}

/* The points of either gather near a hit that is not kept: each side's
 * points hold E/pi on the side they face, whichever gather made them. */
static int nearby_either(const gi_particle *gp, const accel_hit *hit, vec3 n, rgb *out)
{
    /* with a gatherer, a hit no point may answer gathers itself
     * (gi_particle_gather_here) instead of taking a looser neighbour */
    const int relax = !gp->vgs[0].gatherer;
    for (int relaxed = 0; relaxed <= relax; relaxed++)
        for (int b = 0; b < 2; b++) {
            const gi_view_gather *g = &gp->vgs[b];
            if (g->n > 0 && g->w == gp->vw && g->h == gp->vh && nearby_value(gp, g, hit, n, relaxed, out)) return 1;
        }
    return 0;
}

int gi_particle_view_value(const gi_particle *gp, const accel_hit *hit, const view_rec *r, vec3 n, rgb *out)
{
    if (!r) return nearby_either(gp, hit, n, out);
    /* a kept hit: its pixel's value on the side seen, or on the other side
     * (diffuse_back) from the other side's gather */
    const gi_view_gather *g = &gp->vgs[(v3_dot(n, r->h.ng) >= 0.0) != r->side];
    if (g->n <= 0 || g->w != gp->vw || g->h != gp->vh || !g->pixval) return 0;
    const float *v = &g->pixval[4 * (size_t)(r - gp->vrec)];
    if (!(v[3] > 0.0f)) return nearby_either(gp, hit, n, out);
    out->r = v[0];
    out->g = v[1];
    out->b = v[2];
    return 1;
}

int gi_particle_gather_here(gi_particle *gp, const accel_hit *hit, vec3 n, int thread, rgb *out)
{
    if (!gp->vgs[0].gatherer || !hit->obj) return 0;
    int side = v3_dot(n, hit->ng) >= 0.0;
    vec3 nv = hit_normal(hit, side);
    if (!(v3_len(nv) > 0.0)) return 0;
    /* under radiosity `normal on` about n, the shading's perturbed normal */
    if (gp->set.normal_at && v3_dot(n, nv) > 0.0) nv = v3_norm(n);
    /* its rays' random stream from where it lies, so that a render gives
     * the same image on any number of threads */
    uint64_t bits[3];
    memcpy(bits, &hit->p, sizeof bits);
    uint64_t stream = hash_step(hash_step(pt_mix64(bits[0]), (int64_t)bits[1]), (int64_t)bits[2]);
    float e[3];
    if (!gi_gatherer_point(gp->vgs[0].gatherer, thread, hit->p, nv, stream, e, NULL)) return 0;
    out->r = e[0];
    out->g = e[1];
    out->b = e[2];
    return 1;
}
