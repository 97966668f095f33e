/* pm_detp.c - incremental photon paths and the DETP estimator (see pm_detp.h).
 *
 * Per frame:
 *  1. leaves: every leaf object (CSG members included) gets an index, the
 *     same in every frame of one scene file while the object structure
 *     does not change; each top-level object a hash of its geometry and
 *     transform; "moving" = hash differs from the previous frame's.
 *  2. receivers: the camera ray through every pixel centre; a pixel whose
 *     hit has the same leaf, point and normal (bitwise) on an object that
 *     did not move keeps its sum, every other one is estimated anew.
 *  3. paths (seed 004, Fig 2.2): a path's segments are walked in order; a
 *     segment is invalid when its stored hit is on a moving object or when
 *     it now meets one (a query against an accel of the moving objects
 *     only, up to the stored hit). The first invalid segment and the rest
 *     of the path are old (their shares leave the kept receivers' sums);
 *     the path is traced on from that segment's launch (pm_photon_walk) and
 *     the new segments' shares enter the sums.
 *  4. the receivers estimated anew take the shares of all segments.
 *
 * A segment's share at a receiver (x, n) is Phi / (pi r^2) per channel when
 * it arrives at the front of n, crosses the tangent plane within its length
 * (up to the stored hit, which lies on the receiver's surface for the
 * segments that end there) and within r of x (seed 004 section 1.5; the
 * paper's border correction is not applied). The share is quantised to an
 * integer once (qscale), so sums are exact and independent of order.
 *
 * Segments and receivers meet through a uniform grid of the receivers'
 * discs (seed 004 section 1.7, disc indexing): a segment walks the cells it
 * crosses (Amanatides and Woo) and tests each receiver there once. The
 * grid only proposes candidates: the test itself is the same whatever grid
 * proposed them, which the exactness above needs. */
#include "pm_detp.h"
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include "camera.h"
#include "hash.h"
#include "pm_nee.h"
#include "pm_photon.h"
#include "scene_leaves.h"
#include "pool.h"
#include "radrules.h"
#include "shade_material.h"
#include "timer.h"

#define PATH_CHUNK 256
#define MAX_CELLS (1 << 21)
/* How far past its hit (in disc radii) a segment goes on for receivers on
 * the object it hit: the same in share() and in the walk that proposes
 * them, so that what a receiver takes does not depend on the grid */
#define SAME_OBJECT_RUN 4.0
/* How far (in disc radii) the hook looks for the receiver nearest a hit
 * that is not a pixel centre's (antialiasing samples, reflections): where
 * the camera sees a surface at a grazing angle its receivers lie further
 * apart than one radius */
#define LOOKUP_RUN 3.0

/* One stored segment of a photon path. */
typedef struct {
    pm_photon_launch l;
    double t;          /* distance to its hit; INFINITY: it left the scene */
    rgb carried;       /* the power receivers it crosses take */
    int hit_leaf;      /* leaf index of the hit, -1 none, -2 a leaf not enumerated */
    int from_leaf;     /* leaf index of l.from.obj, -1 none, -2 not enumerated */
} seg;

typedef struct {
    seg *v;
    int n;
} path;

typedef struct {
    vec3 p, n;         /* hit point and the normal facing the camera */
    int leaf;          /* -1: no hit (no receiver) */
} receiver;

/* Receivers' discs in a uniform grid (CSR cell lists). */
typedef struct {
    vec3 lo;
    double cell;
    int nx, ny, nz;
    int *off, *idx;
} rgrid;

struct pm_detp {
    pm_detp_settings s;
    int have;                  /* a previous frame is kept */
    int init;                  /* bounds, radius and the share scale are set (first frame) */
    vec3 bounds[2];            /* first frame's: the photon sources' allocation */
    double radius, qscale, eps;
    double ray_eps;            /* first frame's pm_lights_eps: where photon rays start off surfaces */
    /* the previous frame's objects */
    uint64_t *obj_hash;
    int nobj;
    int nleaves;
    /* paths: each its own array of segments (a frame rewrites only the
     * paths it re-traces) */
    long npaths;
    path *paths;
    /* receivers, one per pixel, and their sums */
    int w, h;
    receiver *rec;
    _Atomic int64_t *E;
    rgrid look;                /* all receivers: the hook's lookup */
    atomic_long lookups, lookups_none;
    const scene *sc;
};

/* ------------------------------------------------------------ objects */

/* Whether an object (or a member) emits light: it is then a light source
 * of the photons, and moving it moves a light. */
static int obj_emits(const scene *sc, const scene_object *o)
{
    if (scene_object_is_csg(o)) {
        for (int i = 0; i < o->u.csg.nkids; i++)
            if (obj_emits(sc, o->u.csg.kids[i])) return 1;
        return 0;
    }
    const scene_texture *t = o->texture ? o->texture : &sc->default_texture;
    rgb e = shade_mat_texture_emission(sc, t);
    if (e.r > 0.0 || e.g > 0.0 || e.b > 0.0) return 1;
    if (o->kind == SHAPE_MESH && o->u.mesh.mesh && o->u.mesh.textures)
        for (int i = 0; i < o->u.mesh.mesh->ntextures; i++) {
            rgb m = shade_mat_texture_emission(sc, o->u.mesh.textures[i]);
            if (m.r > 0.0 || m.g > 0.0 || m.b > 0.0) return 1;
        }
    return 0;
}

/* ------------------------------------------------------------ receivers' grid */

static void rgrid_free(rgrid *g)
{
    free(g->off);
    free(g->idx);
    memset(g, 0, sizeof *g);
}

static int clampi(double v, int n)
{
    if (!(v > 0.0)) return 0;
    if (v >= (double)(n - 1)) return n - 1;
    return (int)v;
}

/* The receivers with pick[i] set (pick NULL: all with a hit) in the cells
 * that their discs (radius r, tight: the disc's own box, grown by a
 * hundredth of a cell so that a walk that rounds at a cell face still
 * finds them) or their spheres of radius LOOKUP_RUN r (not tight: the
 * hook's lookup of points near a curved surface) meet. 0 on failure (no memory). */
static int rgrid_build(rgrid *g, const receiver *rec, long n, const unsigned char *pick, double r, int tight)
{
    memset(g, 0, sizeof *g);
    vec3 lo = v3(INFINITY, INFINITY, INFINITY), hi = v3(-INFINITY, -INFINITY, -INFINITY);
    long cnt = 0;
    for (long i = 0; i < n; i++) {
        if (rec[i].leaf < 0 || (pick && !pick[i])) continue;
        lo = v3_min(lo, rec[i].p);
        hi = v3_max(hi, rec[i].p);
        cnt++;
    }
    if (cnt == 0) return 1;
    double cell = 2.0 * r;
    vec3 ext = v3_sub(hi, lo);
    for (;;) {
        double cells = (floor(ext.x / cell) + 3.0) * (floor(ext.y / cell) + 3.0) * (floor(ext.z / cell) + 3.0);
        if (cells <= MAX_CELLS) break;
        cell *= 1.25;
    }
    double m = (tight ? r : LOOKUP_RUN * r) + 0.01 * cell;
    g->cell = cell;
    g->lo = v3_sub(lo, v3(m, m, m));
    g->nx = (int)floor((ext.x + 2.0 * m) / cell) + 1;
    g->ny = (int)floor((ext.y + 2.0 * m) / cell) + 1;
    g->nz = (int)floor((ext.z + 2.0 * m) / cell) + 1;
    size_t nc = (size_t)g->nx * g->ny * g->nz;
    g->off = calloc(nc + 1, sizeof *g->off);
    if (!g->off) return 0;
    for (int pass = 0; pass < 2; pass++) {
        for (long i = 0; i < n; i++) {
            if (rec[i].leaf < 0 || (pick && !pick[i])) continue;
            vec3 p = rec[i].p, nn = rec[i].n;
            /* a disc of normal n spans r sqrt(1 - n_k^2) along axis k */
            double ex = tight ? r * sqrt(fmax(0.0, 1.0 - nn.x * nn.x)) + 0.01 * cell : m;
            double ey = tight ? r * sqrt(fmax(0.0, 1.0 - nn.y * nn.y)) + 0.01 * cell : m;
            double ez = tight ? r * sqrt(fmax(0.0, 1.0 - nn.z * nn.z)) + 0.01 * cell : m;
            int x0 = clampi((p.x - ex - g->lo.x) / cell, g->nx), x1 = clampi((p.x + ex - g->lo.x) / cell, g->nx);
            int y0 = clampi((p.y - ey - g->lo.y) / cell, g->ny), y1 = clampi((p.y + ey - g->lo.y) / cell, g->ny);
            int z0 = clampi((p.z - ez - g->lo.z) / cell, g->nz), z1 = clampi((p.z + ez - g->lo.z) / cell, g->nz);
            for (int z = z0; z <= z1; z++)
                for (int y = y0; y <= y1; y++)
                    for (int x = x0; x <= x1; x++) {
                        size_t c = ((size_t)z * g->ny + y) * g->nx + x;
                        if (pass == 0) g->off[c + 1]++;
                        else g->idx[g->off[c]++] = (int)i;
                    }
        }
        if (pass == 0) {
            for (size_t c = 0; c < nc; c++) g->off[c + 1] += g->off[c];
            g->idx = malloc(sizeof *g->idx * (size_t)(g->off[nc] > 0 ? g->off[nc] : 1));
            if (!g->idx) return 0;
        } else {
            for (size_t c = nc; c > 0; c--) g->off[c] = g->off[c - 1];
            g->off[0] = 0;
        }
    }
    return 1;
}

/* ------------------------------------------------------------ shares */

typedef struct {
    const pm_detp *dp;
    int sign;
    unsigned *stamp;   /* per receiver: the last segment that tested it (this thread's) */
    unsigned stamp_id;
} applier;

/* The share of segment s at receiver r, quantised; 0 when s does not cross
 * r's disc. A function of the two alone. */
static int share(const pm_detp *dp, const seg *s, const receiver *r, int64_t q[3])
{
    double dn = v3_dot(s->l.w, r->n);
    if (!(dn < 0.0)) return 0;
    double t = v3_dot(v3_sub(r->p, s->l.o), r->n) / dn;
    /* a segment that ends on the receiver's own object goes on through it
     * (seed 004 section 1.5, artifact control on concave surfaces: inside
     * a curved surface the tangent plane lies beyond the surface) */
    double tmax = s->t * (1.0 + 1e-6) + dp->eps + (s->hit_leaf == r->leaf ? SAME_OBJECT_RUN * dp->radius : 0.0);
    if (!(t > 0.0) || !(t <= tmax)) return 0;
    vec3 d = v3_sub(v3_madd(s->l.o, s->l.w, t), r->p);
    if (!(v3_dot(d, d) < dp->radius * dp->radius)) return 0;
    double k = dp->qscale / (M_PI * dp->radius * dp->radius);
    q[0] = (int64_t)llround(s->carried.r * k);
    q[1] = (int64_t)llround(s->carried.g * k);
    q[2] = (int64_t)llround(s->carried.b * k);
    return 1;
}

/* Adds sign * the share of s to every receiver of grid g it crosses. */
static void apply_seg(applier *ap, const rgrid *g, const seg *s)
{
    const pm_detp *dp = ap->dp;
    if (!g->off || !(s->carried.r > 0.0 || s->carried.g > 0.0 || s->carried.b > 0.0)) return;
    if (++ap->stamp_id == 0) {
        memset(ap->stamp, 0, sizeof *ap->stamp * (size_t)dp->w * dp->h);
        ap->stamp_id = 1;
    }
    /* clip to the grid's box */
    vec3 o = s->l.o, w = s->l.w;
    double t1 = s->t * (1.0 + 1e-6) + dp->eps;
    if (s->hit_leaf >= 0) t1 += SAME_OBJECT_RUN * dp->radius;
    vec3 ghi = v3_add(g->lo, v3(g->nx * g->cell, g->ny * g->cell, g->nz * g->cell));
    double b0, b1;
    if (!v3_slab(o, w, g->lo, ghi, &b0, &b1)) return;
    double t0 = fmax(0.0, b0);
    t1 = fmin(t1, b1);
    if (!(t0 <= t1)) return;
    double lo[3] = {g->lo.x, g->lo.y, g->lo.z}, oo[3] = {o.x, o.y, o.z}, ww[3] = {w.x, w.y, w.z};
    int n[3] = {g->nx, g->ny, g->nz}, c[3], step[3];
    double tnext[3], tdelta[3];
    for (int k = 0; k < 3; k++) {
        double p = oo[k] + ww[k] * t0;
        c[k] = clampi((p - lo[k]) / g->cell, n[k]);
        if (ww[k] > 0.0) {
            step[k] = 1;
            tnext[k] = (lo[k] + (c[k] + 1) * g->cell - oo[k]) / ww[k];
            tdelta[k] = g->cell / ww[k];
        } else if (ww[k] < 0.0) {
            step[k] = -1;
            tnext[k] = (lo[k] + c[k] * g->cell - oo[k]) / ww[k];
            tdelta[k] = -g->cell / ww[k];
        } else {
            step[k] = 0;
            tnext[k] = INFINITY;
            tdelta[k] = INFINITY;
        }
    }
    for (;;) {
        size_t ci = ((size_t)c[2] * g->ny + c[1]) * g->nx + c[0];
        for (int q = g->off[ci]; q < g->off[ci + 1]; q++) {
            int ri = g->idx[q];
            if (ap->stamp[ri] == ap->stamp_id) continue;
            ap->stamp[ri] = ap->stamp_id;
            int64_t v[3];
            if (!share(dp, s, &dp->rec[ri], v)) continue;
            for (int k = 0; k < 3; k++) atomic_fetch_add_explicit(&dp->E[(size_t)ri * 3 + k], ap->sign * v[k], memory_order_relaxed);
        }
        int k = tnext[0] < tnext[1] ? (tnext[0] < tnext[2] ? 0 : 2) : (tnext[1] < tnext[2] ? 1 : 2);
        if (tnext[k] > t1) break;
        c[k] += step[k];
        if (c[k] < 0 || c[k] >= n[k]) break;
        tnext[k] += tdelta[k];
    }
}

/* ------------------------------------------------------------ frame */

typedef struct {
    seg *v;
    long n, cap;
    int oom;
} segvec;

static void segvec_push(segvec *sv, const seg *s)
{
    if (sv->oom) return;
    if (sv->n == sv->cap) {
        long nc = sv->cap ? 2 * sv->cap : 64;
        seg *nv = realloc(sv->v, sizeof *nv * (size_t)nc);
        if (!nv) {
            sv->oom = 1;
            return;
        }
        sv->v = nv;
        sv->cap = nc;
    }
    sv->v[sv->n++] = *s;
}

typedef struct {
    pm_detp *dp;
    const scene *sc;
    const accel *a;
    const accel *mob;             /* moving objects only (NULL: none) */
    int mob_boxed;                /* 1: the moving objects' surfaces lie in mob_lo..mob_hi */
    vec3 mob_lo, mob_hi;
    const pm_photon_walker *wk;
    const scene_leaves *lv;
    const unsigned char *moving;  /* per leaf */
    int incremental;              /* 0: a full frame (every path traced from its source) */
    const rgrid *ginc;            /* receivers that keep their sums */
    int nthreads;
    applier *ap_minus, *ap_plus;  /* per thread */
    segvec *scratch;              /* per thread: the path being traced */
    long chunks;
    _Atomic long retraced, nold, nnew, rays, nsegs;
    atomic_int oom;
    /* filled while walking one path */
} frame_ctx;

typedef struct {
    frame_ctx *fc;
    segvec *out;
    applier *plus;
    long count;
} walk_sink;

static void on_seg(void *ctx, long index, const pm_photon_launch *l, const accel_hit *h, rgb carried)
{
    (void)index;
    walk_sink *ws = ctx;
    seg s = {.l = *l, .t = h ? h->t : INFINITY, .carried = carried,
             .hit_leaf = h ? scene_leaves_find(ws->fc->lv, h->obj) : -1,
             .from_leaf = l->from.obj ? scene_leaves_find(ws->fc->lv, l->from.obj) : -1};
    segvec_push(ws->out, &s);
    ws->count++;
    if (ws->plus) apply_seg(ws->plus, ws->fc->ginc, &s);
}

/* Whether stored segment s is still what tracing it now gives. */
static int seg_valid(const frame_ctx *fc, const seg *s, long *rays)
{
    if (s->hit_leaf == -2 || s->from_leaf == -2) return 0;
    if (s->hit_leaf >= 0 && fc->moving[s->hit_leaf]) return 0;
    if (!fc->mob) return 1;
    accel_hit h;
    /* up to a little past the stored hit: a tie is taken as a change */
    double tmax = isfinite(s->t) ? s->t * (1.0 + 1e-7) + fc->dp->eps : INFINITY;
    if (fc->mob_boxed && !v3_segment_meets_box(s->l.o, s->l.w, fc->mob_lo, fc->mob_hi, tmax)) return 1;
    (*rays)++;
    if (s->l.from.obj && s->from_leaf >= 0) {
        accel_from f = s->l.from;
        f.obj = scene_leaves_get(fc->lv, s->from_leaf);
        return !accel_intersect_from(fc->mob, &f, s->l.o, s->l.w, 0.0, tmax, &h);
    }
    return !accel_intersect(fc->mob, s->l.o, s->l.w, 0.0, tmax, &h);
}

/* Path i's new array: its first k old segments, then what out holds. */
static int path_store(path *p, const seg *old, long k, const segvec *out)
{
    long n = k + out->n;
    seg *v = malloc(sizeof *v * (size_t)(n > 0 ? n : 1));
    if (!v || out->oom) {
        free(v);
        return 0;
    }
    if (k) memcpy(v, old, sizeof *v * (size_t)k);
    if (out->n) memcpy(v + k, out->v, sizeof *v * (size_t)out->n);
    free(p->v);
    p->v = v;
    p->n = (int)n;
    return 1;
}

static void path_job(void *ctx, int ci, int thread)
{
    frame_ctx *fc = ctx;
    if (fc->dp->s.cancel && *fc->dp->s.cancel) return;
    long i0 = (long)ci * PATH_CHUNK, i1 = i0 + PATH_CHUNK < fc->dp->npaths ? i0 + PATH_CHUNK : fc->dp->npaths;
    segvec *out = &fc->scratch[thread];
    long rays = 0, retraced = 0, nold = 0, nnew = 0, nsegs = 0;
    for (long i = i0; i < i1; i++) {
        path *p = &fc->dp->paths[i];
        out->n = 0;
        walk_sink ws = {fc, out, NULL, 0};
        if (!fc->incremental) {
            pm_photon_walk(fc->wk, i, NULL, on_seg, &ws, &rays);
            if (!path_store(p, NULL, 0, out)) atomic_store(&fc->oom, 1);
            retraced++;
            nsegs += p->n;
            continue;
        }
        const seg *ps = p->v;
        long n = p->n, k = 0;
        while (k < n && seg_valid(fc, &ps[k], &rays)) k++;
        if (k < n) {
            pm_photon_launch l = ps[k].l;
            /* resumed at segment k, or traced again from the source (when
             * k is 0, or its surface is not known in this frame); kept
             * segments' `from` pointers are the frame's they were traced
             * in: only a resumed launch's is read, set here */
            int resume = k > 0 && l.bounce > 0 && (!l.from.obj || ps[k].from_leaf >= 0);
            if (!resume) k = 0;
            if (l.from.obj && ps[k].from_leaf >= 0) l.from.obj = scene_leaves_get(fc->lv, ps[k].from_leaf);
            for (long j = k; j < n; j++) apply_seg(&fc->ap_minus[thread], fc->ginc, &ps[j]);
            nold += n - k;
            retraced++;
            ws.plus = &fc->ap_plus[thread];
            pm_photon_walk(fc->wk, i, resume ? &l : NULL, on_seg, &ws, &rays);
            nnew += ws.count;
            if (!path_store(p, ps, k, out)) atomic_store(&fc->oom, 1);
        }
        nsegs += p->n;
    }
    atomic_fetch_add(&fc->rays, rays);
    atomic_fetch_add(&fc->retraced, retraced);
    atomic_fetch_add(&fc->nold, nold);
    atomic_fetch_add(&fc->nnew, nnew);
    atomic_fetch_add(&fc->nsegs, nsegs);
}

typedef struct {
    pm_detp *dp;
    const rgrid *g;
    applier *ap;
} full_ctx;

static void full_job(void *ctx, int ci, int thread)
{
    full_ctx *f = ctx;
    long i0 = (long)ci * PATH_CHUNK, i1 = i0 + PATH_CHUNK < f->dp->npaths ? i0 + PATH_CHUNK : f->dp->npaths;
    for (long i = i0; i < i1; i++)
        for (int k = 0; k < f->dp->paths[i].n; k++) apply_seg(&f->ap[thread], f->g, &f->dp->paths[i].v[k]);
}

typedef struct {
    const scene *sc;
    const accel *a;
    const scene_leaves *lv;
    receiver *rec;
    int w, h;
    double eps;
    _Atomic long rays;
} cam_ctx;

static void cam_job(void *ctx, int y, int thread)
{
    (void)thread;
    cam_ctx *c = ctx;
    long rays = 0;
    for (int x = 0; x < c->w; x++) {
        receiver *r = &c->rec[(size_t)y * c->w + x];
        r->leaf = -1;
        vec3 org, dir;
        if (!camera_ray(&c->sc->camera, x + 0.5, y + 0.5, c->w, c->h, 0.0, 0.0, &org, &dir)) continue;
        accel_hit h;
        rays++;
        if (!accel_intersect(c->a, org, dir, c->eps, INFINITY, &h)) continue;
        int leaf = scene_leaves_find(c->lv, h.obj);
        if (leaf < 0) continue;
        r->p = h.p;
        r->n = v3_dot(h.ng, dir) < 0.0 ? h.ng : v3_neg(h.ng);
        r->leaf = leaf;
    }
    atomic_fetch_add(&c->rays, rays);
}

void pm_detp_default_settings(pm_detp_settings *s)
{
    *s = (pm_detp_settings){.photons = PM_DETP_PHOTONS, .max_bounces = 256, .seed = 1};
}

pm_detp *pm_detp_new(const pm_detp_settings *s)
{
    pm_detp *dp = calloc(1, sizeof *dp);
    if (dp) dp->s = *s;
    return dp;
}

static void drop_frame(pm_detp *dp)
{
    for (long i = 0; i < dp->npaths && dp->paths; i++) free(dp->paths[i].v);
    free(dp->paths);
    dp->paths = NULL;
    dp->npaths = 0;
    dp->have = 0;
}

void pm_detp_free(pm_detp *dp)
{
    if (!dp) return;
    drop_frame(dp);
    free(dp->obj_hash);
    free(dp->rec);
    free((void *)dp->E);
    rgrid_free(&dp->look);
    free(dp);
}

void pm_detp_set_progress(pm_detp *dp, progress *p) { dp->s.progress = p; }

void pm_detp_lookups(const pm_detp *dp, long *lookups, long *none)
{
    pm_detp *m = (pm_detp *)dp; /* counters only */
    *lookups = atomic_load(&m->lookups);
    *none = atomic_load(&m->lookups_none);
}

uint64_t pm_detp_paths_hash(const pm_detp *dp)
{
    uint64_t h = PT_FNV1A_BASIS;
    if (!dp->paths) return h;
    for (long i = 0; i < dp->npaths; i++) {
        h = pt_fnv1a(h, &i, sizeof i);
        for (int k = 0; k < dp->paths[i].n; k++) {
            const seg *s = &dp->paths[i].v[k];
            h = pt_fnv1a(h, &s->l.o, sizeof s->l.o);
            h = pt_fnv1a(h, &s->l.w, sizeof s->l.w);
            h = pt_fnv1a(h, &s->t, sizeof s->t);
            h = pt_fnv1a(h, &s->hit_leaf, sizeof s->hit_leaf);
            h = pt_fnv1a(h, &s->carried, sizeof s->carried);
        }
    }
    return h;
}

const int64_t *pm_detp_sums(const pm_detp *dp, long *npixels, double *scale)
{
    *npixels = (long)dp->w * dp->h;
    *scale = dp->qscale > 0.0 ? 1.0 / dp->qscale : 0.0;
    return (const int64_t *)dp->E;
}

rgb pm_detp_indirect(void *ctx, const accel_hit *hit, vec3 n, int thread)
{
    (void)thread;
    pm_detp *dp = ctx;
    atomic_fetch_add_explicit(&dp->lookups, 1, memory_order_relaxed);
    rgb z = {0.0, 0.0, 0.0};
    const rgrid *g = &dp->look;
    if (!g->off || !(dp->qscale > 0.0)) {
        atomic_fetch_add_explicit(&dp->lookups_none, 1, memory_order_relaxed);
        return z;
    }
    vec3 p = hit->p;
    double fx = (p.x - g->lo.x) / g->cell, fy = (p.y - g->lo.y) / g->cell, fz = (p.z - g->lo.z) / g->cell;
    if (!(fx >= 0.0 && fy >= 0.0 && fz >= 0.0) || fx >= g->nx || fy >= g->ny || fz >= g->nz) {
        atomic_fetch_add_explicit(&dp->lookups_none, 1, memory_order_relaxed);
        return z;
    }
    size_t ci = ((size_t)(int)fz * g->ny + (int)fy) * g->nx + (int)fx;
    int best = -1;
    double bd = LOOKUP_RUN * LOOKUP_RUN * dp->radius * dp->radius;
    for (int q = g->off[ci]; q < g->off[ci + 1]; q++) {
        const receiver *r = &dp->rec[g->idx[q]];
        if (v3_dot(r->n, n) < 0.9) continue;
        vec3 d = v3_sub(r->p, p);
        double dd = v3_dot(d, d);
        if (dd < bd || (dd == 0.0 && best < 0)) {
            bd = dd;
            best = g->idx[q];
        }
    }
    if (best < 0) {
        atomic_fetch_add_explicit(&dp->lookups_none, 1, memory_order_relaxed);
        return z;
    }
    double k = 1.0 / (dp->qscale * M_PI);
    const _Atomic int64_t *e = &dp->E[(size_t)best * 3];
    rgb v = {(double)atomic_load_explicit(&e[0], memory_order_relaxed) * k,
             (double)atomic_load_explicit(&e[1], memory_order_relaxed) * k,
             (double)atomic_load_explicit(&e[2], memory_order_relaxed) * k};
    return v;
}

pt_status pm_detp_frame(pm_detp *dp, const scene *sc, const accel *a, int width, int height,
                        const pm_detp_frame_info *fi, pm_detp_stats *st, diag *d)
{
    memset(st, 0, sizeof *st);
    pt_status status = PT_OK;
    int nthreads = pm_threads(dp->s.threads);
    scene_leaves *lv = NULL;
    pm_lights *L = NULL;
    pm_photon_walker *wk = NULL;
    accel *mob = NULL;
    unsigned char *moving = NULL, *pick = NULL;
    uint64_t *hashes = NULL;
    receiver *rec = NULL;
    segvec *scratch = NULL;
    applier *aps = NULL;
    unsigned *stamps = NULL;
    rgrid ginc, gfull;
    memset(&ginc, 0, sizeof ginc);
    memset(&gfull, 0, sizeof gfull);
    scene mobsc;
    scene_object **mobobj = NULL;
    int mob_boxed = 0;
    vec3 mob_lo = v3(0, 0, 0), mob_hi = v3(0, 0, 0);
    double t0 = timer_now();
    lv = scene_leaves_new(sc);
    if (!lv) return PT_ERR_NOMEM;
    int nlv = scene_leaves_count(lv);
    st->objects = sc->nobjects;
    /* 1. what moved */
    const char *full = NULL;
    if (!dp->have) full = "first frame";
    else if (dp->s.full) full = "full recomputation asked for";
    else if (fi && fi->lights_changed) full = "a light changed";
    else if (sc->nobjects != dp->nobj || nlv != dp->nleaves) full = "the objects changed in number";
    hashes = malloc(sizeof *hashes * (size_t)(sc->nobjects > 0 ? sc->nobjects : 1));
    moving = calloc((size_t)(nlv > 0 ? nlv : 1), 1);
    mobobj = malloc(sizeof *mobobj * (size_t)(sc->nobjects > 0 ? sc->nobjects : 1));
    if (!hashes || !moving || !mobobj) {
        status = PT_ERR_NOMEM;
        goto done;
    }
    int nmob = 0;
    for (int i = 0; i < sc->nobjects; i++) {
        int opaque = 0;
        hashes[i] = scene_object_hash(PT_FNV1A_BASIS, sc->objects[i], &opaque);
        int mv = 0;
        if (!full && fi && fi->objects_may_change) mv = opaque || hashes[i] != dp->obj_hash[i];
        if (mv) {
            mobobj[nmob++] = sc->objects[i];
            if (obj_emits(sc, sc->objects[i])) full = "an emissive object moved";
        }
    }
    for (int l = 0; l < nlv; l++)
        for (int k = 0; k < nmob; k++)
            if (sc->objects[scene_leaves_top(lv, l)] == mobobj[k]) moving[l] = 1;
    st->moving_objects = nmob;
    if (!full && nmob > 0) {
        mobsc = *sc;
        mobsc.objects = mobobj;
        mobsc.nobjects = nmob;
        diag *dq = diag_new();
        pt_status ms = PT_OK;
        mob = accel_build(&mobsc, dp->s.threads, dq, &ms);
        diag_free(dq);
        if (!mob) {
            status = ms != PT_OK ? ms : PT_ERR_DEVICE;
            goto done;
        }
        /* a box around them, grown by a scene epsilon, answers most
         * segments before Embree is asked */
        mob_boxed = 1;
        for (int k = 0; k < nmob; k++) mob_boxed &= scene_object_finite(mobobj[k]);
        if (mob_boxed) {
            accel_bounds(mob, &mob_lo, &mob_hi);
            double g = 1e-6 * v3_len(v3_sub(mob_hi, mob_lo)) + 1e-9;
            mob_lo = v3_sub(mob_lo, v3(g, g, g));
            mob_hi = v3_add(mob_hi, v3(g, g, g));
            mob_boxed = mob_lo.x <= mob_hi.x && isfinite(mob_lo.x) && isfinite(mob_hi.x);
        }
    }
    if (full) drop_frame(dp);
    st->full_frame = full != NULL;
    st->full_reason = full;

    /* sources */
    L = pm_lights_new(sc, a, d, &status);
    if (!L) goto done;
    if (!dp->init) {
        dp->init = 1;
        accel_bounds(a, &dp->bounds[0], &dp->bounds[1]);
        double diag_len = v3_len(v3_sub(dp->bounds[1], dp->bounds[0]));
        if (!(diag_len > 0.0) || !isfinite(diag_len)) diag_len = accel_scale(a);
        dp->radius = dp->s.radius > 0.0 ? dp->s.radius : PM_DETP_RADIUS * diag_len;
        dp->eps = 1e-7 * diag_len;
        dp->ray_eps = pm_lights_eps(L);
    }
    st->radius = dp->radius;
    pm_photon_settings ps = {dp->s.photons, 0, dp->s.max_bounces > 0 ? dp->s.max_bounces : 256, dp->s.seed, dp->s.threads,
                             dp->s.cancel, NULL, 1};
    long npaths = 0;
    wk = pm_photon_walker_new(sc, a, L, &ps, dp->bounds, dp->ray_eps, &npaths, &status);
    if (!wk) goto done;
    if (dp->have && npaths != dp->npaths) {
        full = "the photon sources changed";
        st->full_frame = 1;
        st->full_reason = full;
        drop_frame(dp);
    }

    /* 2. receivers */
    long np = (long)width * height;
    rec = malloc(sizeof *rec * (size_t)(np > 0 ? np : 1));
    pick = calloc((size_t)(np > 0 ? np : 1), 1);
    if (!rec || !pick) {
        status = PT_ERR_NOMEM;
        goto done;
    }
    cam_ctx cc = {sc, a, lv, rec, width, height, dp->ray_eps, 0};
    pool_run(nthreads, height, cam_job, &cc);
    st->rays += atomic_load(&cc.rays);
    int same_image = dp->have && dp->w == width && dp->h == height && dp->E;
    if (!same_image) {
        free((void *)dp->E);
        dp->E = calloc((size_t)(np > 0 ? np : 1) * 3, sizeof *dp->E);
        if (!dp->E) {
            status = PT_ERR_NOMEM;
            goto done;
        }
    }
    long nfull = 0, nrec = 0;
    for (long i = 0; i < np; i++) {
        receiver *r = &rec[i];
        if (r->leaf < 0) {
            for (int k = 0; k < 3; k++) atomic_store(&dp->E[i * 3 + k], 0);
            continue;
        }
        nrec++;
        int keep = same_image && dp->have && dp->rec[i].leaf == r->leaf && !moving[r->leaf] &&
                   memcmp(&dp->rec[i].p, &r->p, sizeof r->p) == 0 && memcmp(&dp->rec[i].n, &r->n, sizeof r->n) == 0;
        if (!keep) {
            pick[i] = 1;
            nfull++;
            for (int k = 0; k < 3; k++) atomic_store(&dp->E[i * 3 + k], 0);
        }
    }
    st->receivers = nrec;
    st->receivers_full = nfull;
    free(dp->rec);
    dp->rec = rec;
    rec = NULL;
    dp->w = width;
    dp->h = height;
    if (dp->have) {
        unsigned char *inc = malloc((size_t)(np > 0 ? np : 1));
        if (!inc) {
            status = PT_ERR_NOMEM;
            goto done;
        }
        for (long i = 0; i < np; i++) inc[i] = !pick[i];
        int ok = rgrid_build(&ginc, dp->rec, np, inc, dp->radius, 1);
        free(inc);
        if (!ok) {
            status = PT_ERR_NOMEM;
            goto done;
        }
    }
    if (nfull > 0 && !rgrid_build(&gfull, dp->rec, np, pick, dp->radius, 1)) {
        status = PT_ERR_NOMEM;
        goto done;
    }

    /* 3. paths */
    aps = calloc((size_t)nthreads * 3, sizeof *aps);
    stamps = calloc((size_t)nthreads * 3 * (size_t)(np > 0 ? np : 1), sizeof *stamps);
    long nchunks = (npaths + PATH_CHUNK - 1) / PATH_CHUNK;
    scratch = calloc((size_t)nthreads, sizeof *scratch);
    if (!dp->have) {
        drop_frame(dp);
        dp->paths = calloc((size_t)(npaths > 0 ? npaths : 1), sizeof *dp->paths);
    }
    if (!aps || !stamps || !scratch || !dp->paths) {
        status = PT_ERR_NOMEM;
        goto done;
    }
    for (int t = 0; t < nthreads * 3; t++) {
        aps[t].dp = dp;
        aps[t].sign = t < nthreads ? -1 : 1;
        aps[t].stamp = stamps + (size_t)t * (size_t)(np > 0 ? np : 1);
    }
    frame_ctx fc = {.dp = dp, .sc = sc, .a = a, .mob = mob, .mob_boxed = mob_boxed, .mob_lo = mob_lo, .mob_hi = mob_hi,
                    .wk = wk, .lv = lv, .moving = moving, .incremental = dp->have, .ginc = &ginc,
                    .nthreads = nthreads, .ap_minus = aps, .ap_plus = aps + nthreads, .scratch = scratch};
    dp->npaths = npaths;
    progress_stage(dp->s.progress, "detp: photon paths", nchunks);
    pool_run_counted(nthreads, (int)nchunks, path_job, &fc, dp->s.cancel, dp->s.progress);
    if (dp->s.cancel && *dp->s.cancel) {
        status = PT_CANCELLED;
        drop_frame(dp);
        goto done;
    }
    if (atomic_load(&fc.oom)) {
        status = PT_ERR_NOMEM;
        drop_frame(dp);
        goto done;
    }
    long total = atomic_load(&fc.nsegs);
    st->paths = npaths;
    st->segments = total;
    st->paths_retraced = atomic_load(&fc.retraced);
    st->segments_old = atomic_load(&fc.nold);
    st->segments_new = atomic_load(&fc.nnew);
    st->rays += atomic_load(&fc.rays);
    st->t_trace = timer_now() - t0;

    /* the share scale, fixed by the first frame's largest share */
    if (!(dp->qscale > 0.0)) {
        double mx = 0.0;
        for (long i = 0; i < npaths; i++)
            for (int k = 0; k < dp->paths[i].n; k++) {
                rgb c = dp->paths[i].v[k].carried;
                mx = fmax(mx, fmax(c.r, fmax(c.g, c.b)));
            }
        double smax = mx / (M_PI * dp->radius * dp->radius);
        dp->qscale = smax > 0.0 && isfinite(smax) ? ldexp(1.0, 32) / smax : 1.0;
    }

    /* 4. receivers estimated from all segments */
    double t1 = timer_now();
    if (nfull > 0) {
        full_ctx fx = {dp, &gfull, aps + 2 * nthreads};
        for (int t = 0; t < nthreads; t++) aps[2 * nthreads + t].sign = 1;
        progress_stage(dp->s.progress, "detp: estimate", nchunks);
        pool_run_counted(nthreads, (int)nchunks, full_job, &fx, dp->s.cancel, dp->s.progress);
    }
    st->t_estimate = timer_now() - t1;
    rgrid_free(&dp->look);
    if (!rgrid_build(&dp->look, dp->rec, np, NULL, dp->radius, 0)) {
        status = PT_ERR_NOMEM;
        drop_frame(dp);
        goto done;
    }
    free(dp->obj_hash);
    dp->obj_hash = hashes;
    hashes = NULL;
    dp->nobj = sc->nobjects;
    dp->nleaves = nlv;
    dp->sc = sc;
    dp->have = 1;
    atomic_store(&dp->lookups, 0);
    atomic_store(&dp->lookups_none, 0);
done:
    if (scratch)
        for (int t = 0; t < nthreads; t++) free(scratch[t].v);
    free(scratch);
    free(aps);
    free(stamps);
    rgrid_free(&ginc);
    rgrid_free(&gfull);
    free(pick);
    free(rec);
    free(hashes);
    free(moving);
    free(mobobj);
    pm_photon_walker_free(wk);
    pm_lights_free(L);
    accel_free(mob);
    scene_leaves_free(lv);
    return status;
}
