/* gi_surface_layout.c - radiance particles shared between patches (the
 * layout of their slots) and locating a hit among them. */
#include "gi_surface_internal.h"
#include <math.h>
#include "geom_shape.h"
#include "geom_hfield.h"
#include "accel_surface.h"
#include "geom_sweep.h"
#include "geom_tess.h"
#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------ layout: shared radiance particles
 *
 * Every side of every patch lays out rp_count slots (its sub-tessellation's
 * or grid's vertices), slot_first + side * rp_count + local. Slots at one
 * point of one object with the same facing are one radiance particle: a
 * mesh vertex shared by n triangles (and, where neighbouring triangles have
 * the same k, the vertices along their shared edge), the two triangles of a
 * box face or the fan of a clipped plane, a sphere's seam and poles. They
 * would get identical estimation lists (same point, normal, object and side:
 * gi_radiance), so one list and one value serve all of them; each hit still
 * interpolates over its own triangle's three (gi_surface_locate maps slots
 * to radiance particles). Only slots on a patch's boundary can coincide with
 * another patch's (a triangle's edges, a grid's first and last rows and
 * columns), so only those are looked up. Implicit shapes' grids share their
 * vertices already (mesh_vertex). */

/* Same point: within SHARE_TOL of the scene's largest coordinate on each
 * axis (the same vertex reached through different triangles' v0 + e1 a/k +
 * e2 b/k, or a sphere's seam at u = 0 and 1, differ by a few ulps). Same
 * facing: oriented normals within 1 degree, far inside the lists' normal
 * test (n . n' > 0.9, 25.8 degrees), so a list is the one each slot would
 * have had up to that test's edge; creases (a box's edges, a tube's
 * segments) keep a radiance particle per face. */
#define SHARE_TOL 1e-9
#define SHARE_COS 0.99984769515639127 /* cos(1 degree) */

/* The patch holding slot `slot`: the last one whose slots start at or
 * before it (patches without slots start where the next one does). */
static int slot_patch(const gi_surface *g, long slot)
{
    int lo = 0, hi = g->np - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (g->p[mid].slot_first <= slot) lo = mid;
        else hi = mid - 1;
    }
    return lo;
}

static long rp_first_slot(const gi_surface *g, long rp) { return g->rp_slot ? g->rp_slot[rp] : rp; }
/* slot_patch of radiance particle rp's first slot `slot`, from the map when
 * there is one (a binary search over the 392-byte patch records is a cache
 * miss a step: ~18 on maze's 242,160 triangles) */
static int rp_patch(const gi_surface *g, long rp, long slot)
{
    return g->rp_patch ? g->rp_patch[rp] : slot_patch(g, slot);
}
static long slot_rp(const gi_surface *g, long slot) { return g->slot_rp ? g->slot_rp[slot] : slot; }

static vec3 tri_point(const patch *p, int a, long b)
{
    return v3_add(p->v0, v3_add(v3_scale(p->e1, (double)a / p->k), v3_scale(p->e2, (double)b / p->k)));
}

/* Point and front normal of slot `local` (side 0) of patch p. */
static void slot_point(const gi_surface *g, const patch *p, long local, vec3 *pos, vec3 *nrm)
{
    if (p->kind == PATCH_PIECE) {
        *pos = g->mv[p->vfirst + local];
        *nrm = g->mn[p->vfirst + local];
    } else if (p->kind == PATCH_TRI) {
        /* row a holds vertices (a, 0..k-a); row start a(k+1) - a(a-1)/2 */
        int k = p->k, a = 0;
        while (a < k && (long)(a + 1) * (k + 1) - (long)(a + 1) * a / 2 <= local) a++;
        long b = local - ((long)a * (k + 1) - (long)a * (a - 1) / 2);
        *pos = tri_point(p, a, b);
        *nrm = p->nrm;
    } else {
        int i = (int)(local % (p->nu + 1)), j = (int)(local / (p->nu + 1));
        gi_surface_grid_eval(g, p, (double)i / p->nu, (double)j / p->nv, pos, nrm);
    }
}

/* Radiance particles on patch boundaries, in a hash of cells 4 SHARE_TOL
 * wide keyed by (object, cell); an entry is one cache line. */
typedef struct {
    vec3 pos;
    float n[3];
    int obj, rp, next;
} share_entry;

typedef struct {
    double tol, cell;
    int *head; /* bucket -> first entry, -1 empty */
    size_t mask;
    share_entry *e;
    long n, cap;
} rp_share;

static size_t share_bucket(const rp_share *S, int obj, const int64_t c[3])
{
    uint64_t h = (uint64_t)(unsigned)obj * 0x9e3779b97f4a7c15ULL;
    for (int a = 0; a < 3; a++) {
        h ^= (uint64_t)c[a] + 0x632be59bd9b4e019ULL + (h << 6) + (h >> 2);
        h *= 0xbf58476d1ce4e5b9ULL;
    }
    h ^= h >> 31;
    return (size_t)h & S->mask;
}

/* The radiance particle of object obj at p facing n; -1 if none, -2 if p
 * is too far out to hash (home: p's cell, for share_add). A point within
 * tol of p on every axis lies in p's cell or, where p is within a quarter
 * cell (tol) of a cell face, in the cell across it. */
static int share_find(const rp_share *S, int obj, vec3 p, vec3 n, int64_t home[3])
{
    double v[3] = {p.x, p.y, p.z};
    int64_t c[3][2];
    int nc[3];
    for (int a = 0; a < 3; a++) {
        double f = v[a] / S->cell;
        if (!(fabs(f) < 1e15)) return -2; /* not hashable: a radiance particle of its own */
        double fl = floor(f), fr = f - fl;
        c[a][0] = home[a] = (int64_t)fl;
        nc[a] = 1;
        if (fr < 0.3) c[a][nc[a]++] = c[a][0] - 1;
        else if (fr > 0.7) c[a][nc[a]++] = c[a][0] + 1;
    }
    for (int x = 0; x < nc[0]; x++)
        for (int y = 0; y < nc[1]; y++)
            for (int z = 0; z < nc[2]; z++) {
                int64_t q[3] = {c[0][x], c[1][y], c[2][z]};
                for (int i = S->head[share_bucket(S, obj, q)]; i >= 0; i = S->e[i].next) {
                    const share_entry *e = &S->e[i];
                    if (e->obj != obj || fabs(e->pos.x - p.x) > S->tol || fabs(e->pos.y - p.y) > S->tol ||
                        fabs(e->pos.z - p.z) > S->tol || e->n[0] * n.x + e->n[1] * n.y + e->n[2] * n.z < SHARE_COS)
                        continue;
                    return e->rp;
                }
            }
    return -1;
}

static int share_add(rp_share *S, int obj, vec3 p, vec3 n, const int64_t home[3], int rp)
{
    if (S->n == S->cap) {
        long nc = S->cap ? 2 * S->cap : 4096;
        share_entry *ne = realloc(S->e, (size_t)nc * sizeof *ne);
        if (!ne) return 0;
        S->e = ne;
        S->cap = nc;
    }
    size_t b = share_bucket(S, obj, home);
    share_entry *e = &S->e[S->n];
    e->pos = p;
    v3_store_f(e->n, n);
    e->obj = obj;
    e->rp = rp;
    e->next = S->head[b];
    S->head[b] = (int)S->n++;
    return 1;
}

/* Slot `slot` (oriented normal n at q) joins the radiance particle of an
 * earlier slot there, or starts one; only boundary slots (edge) are looked
 * up and remembered. */
static int share_slot(gi_surface *g, rp_share *S, int obj, long slot, int edge, vec3 q, vec3 n, long *nrp)
{
    int64_t home[3];
    int r = edge ? share_find(S, obj, q, n, home) : -2;
    if (r >= 0) {
        g->slot_rp[slot] = r;
        return 1;
    }
    int id = (int)(*nrp)++;
    g->rp_slot[id] = (int)slot;
    g->slot_rp[slot] = id;
    return r == -1 ? share_add(S, obj, q, n, home, id) : 1;
}

/* Fills slot_rp / rp_slot and nrp; returns 0 when out of memory. */
static int share_rps(gi_surface *g)
{
    long ns = g->nslot, nb = 0;
    for (int i = 0; i < g->np; i++) {
        const patch *p = &g->p[i];
        if (p->rp_count == 0) continue;
        if (p->kind == PATCH_TRI) nb += 3L * p->k * p->nsides;
        else if (p->kind != PATCH_PIECE) nb += (2L * (p->nu + 1) + 2L * (p->nv + 1)) * p->nsides;
    }
    rp_share S;
    memset(&S, 0, sizeof S);
    double sc = fmax(fmax(fmax(fabs(g->lo.x), fabs(g->lo.y)), fabs(g->lo.z)),
                     fmax(fmax(fabs(g->hi.x), fabs(g->hi.y)), fabs(g->hi.z)));
    S.tol = SHARE_TOL * (sc > 0.0 && isfinite(sc) ? sc : 1.0);
    S.cell = 4.0 * S.tol;
    size_t nbk = 1024;
    while (nbk < (size_t)nb) nbk *= 2;
    S.mask = nbk - 1;
    S.head = malloc(nbk * sizeof *S.head);
    g->slot_rp = malloc((size_t)ns * sizeof *g->slot_rp);
    g->rp_slot = malloc((size_t)ns * sizeof *g->rp_slot);
    int ok = S.head && g->slot_rp && g->rp_slot;
    if (ok)
        for (size_t b = 0; b < nbk; b++) S.head[b] = -1;
    long nrp = 0;
    for (int i = 0; i < g->np && ok; i++) {
        const patch *p = &g->p[i];
        for (int side = 0; side < p->nsides && ok; side++) {
            long slot = p->slot_first + side * p->rp_count;
            double sg = side ? -1.0 : 1.0;
            if (p->kind == PATCH_TRI) {
                /* slots row by row (tri_index); edges: a = 0, b = 0, a + b = k */
                int k = p->k;
                vec3 n = v3_scale(p->nrm, sg);
                for (int a = 0; a <= k && ok; a++)
                    for (int b = 0; b <= k - a && ok; b++, slot++) {
                        int edge = a == 0 || b == 0 || a + b == k;
                        ok = share_slot(g, &S, p->obj, slot, edge, edge ? tri_point(p, a, b) : n, n, &nrp);
                    }
            } else if (p->kind == PATCH_PIECE) {
                for (long l = 0; l < p->rp_count && ok; l++, slot++)
                    ok = share_slot(g, &S, p->obj, slot, 0, p->nrm, p->nrm, &nrp);
            } else {
                for (int j = 0; j <= p->nv && ok; j++)
                    for (int u = 0; u <= p->nu && ok; u++, slot++) {
                        int edge = u == 0 || u == p->nu || j == 0 || j == p->nv;
                        vec3 q = p->nrm, n = p->nrm;
                        if (edge) {
                            gi_surface_grid_eval(g, p, (double)u / p->nu, (double)j / p->nv, &q, &n);
                            n = v3_scale(n, sg);
                        }
                        ok = share_slot(g, &S, p->obj, slot, edge, q, n, &nrp);
                    }
            }
        }
    }
    free(S.head);
    free(S.e);
    if (!ok) return 0;
    int *shrunk = realloc(g->rp_slot, (size_t)(nrp > 0 ? nrp : 1) * sizeof *shrunk);
    if (shrunk) g->rp_slot = shrunk;
    g->nrp = nrp;
    return 1;
}

/* rp_patch: slot_patch of every radiance particle's first slot, in one walk
 * (first slots rise with the radiance particle: share_slot numbers them in
 * slot order); left NULL when out of memory (or if they did not rise). */
static void map_rp_patches(gi_surface *g)
{
    free(g->rp_patch);
    g->rp_patch = NULL;
    if (g->nrp <= 0 || g->np <= 0) return;
    int *m = malloc((size_t)g->nrp * sizeof *m);
    if (!m) return;
    int i = 0;
    long prev = -1;
    for (long r = 0; r < g->nrp; r++) {
        long slot = rp_first_slot(g, r);
        if (slot < prev) {
            free(m);
            return;
        }
        prev = slot;
        while (i + 1 < g->np && g->p[i + 1].slot_first <= slot) i++;
        m[r] = i;
    }
    g->rp_patch = m;
}

static void tri_loc_fill(tri_loc *t, const patch *p)
{
    t->v0 = p->v0;
    t->e1 = p->e1;
    t->e2 = p->e2;
    t->nrm = p->nrm;
    t->rs = sqrt(p->area) + 1e-300;
    t->slot_first = p->slot_first;
    t->k = p->k;
    t->rp_count = p->rp_count <= INT_MAX ? (int)p->rp_count : INT_MAX;
    t->kind = p->kind;
    t->nsides = p->nsides;
}

void gi_surface_layout(gi_surface *g)
{
    gi_surface_build_meshes(g);
    /* A triangle or grid patch wholly outside the clip box gets no area
     * particles, and the hook answers on it from the far field: the
     * coarsest resolution (a sky dome of radius 1e6 would otherwise take
     * millions of radiance particles that are never read). */
    for (int i = 0; i < g->np; i++) {
        patch *p = &g->p[i];
        if (p->kind == PATCH_PIECE || (p->kind == PATCH_TRI && p->nsides == 0)) continue;
        if (gi_surface_clip_fraction(g, i, 0) > 0.0f) continue;
        if (p->kind == PATCH_TRI) {
            p->k = 1;
            p->rp_count = 3;
        } else {
            p->nu = 3;
            p->nv = 1;
            p->rp_count = (long)(p->nu + 1) * (p->nv + 1);
        }
    }
    long ns = 0;
    for (int i = 0; i < g->np; i++) {
        g->p[i].slot_first = ns;
        ns += g->p[i].rp_count * g->p[i].nsides;
    }
    free(g->tl);
    g->tl = NULL;
    if (g->np > 0) {
        /* triangle sub-tessellations have at most 2049 * 2050 / 2 slots a side */
        g->tl = aligned_alloc(64, (size_t)g->np * sizeof *g->tl);
        if (g->tl)
            for (int i = 0; i < g->np; i++) tri_loc_fill(&g->tl[i], &g->p[i]);
    }
    g->nslot = g->nrp = ns;
    free(g->slot_rp);
    free(g->rp_slot);
    free(g->rp_patch);
    g->slot_rp = g->rp_slot = g->rp_patch = NULL;
    if (ns == 0 || ns >= INT_MAX) return;
    if (!share_rps(g)) {
        /* out of memory: one radiance particle per slot, as before sharing */
        free(g->slot_rp);
        free(g->rp_slot);
        g->slot_rp = g->rp_slot = NULL;
        g->nrp = ns;
    }
    map_rp_patches(g);
}

void gi_surface_retess(gi_surface *g, double tess)
{
    g->tess = tess > 0.0 ? tess : g->tess;
    for (int i = 0; i < g->np; i++) gi_surface_set_resolution(g, &g->p[i]);
    gi_surface_layout(g);
}


int gi_surface_rp_patch(const gi_surface *g, long rp) { return rp_patch(g, rp, rp_first_slot(g, rp)); }

int gi_surface_rp_side(const gi_surface *g, long rp)
{
    long slot = rp_first_slot(g, rp);
    const patch *p = &g->p[rp_patch(g, rp, slot)];
    return slot - p->slot_first >= p->rp_count;
}

void gi_surface_rp_prefetch(const gi_surface *g, long rp)
{
    if (g->rp_slot) __builtin_prefetch(&g->rp_slot[rp]);
    if (g->rp_patch) __builtin_prefetch(&g->rp_patch[rp]);
}

void gi_surface_rp(const gi_surface *g, long rp, vec3 *pos, vec3 *nrm)
{
    long slot = rp_first_slot(g, rp);
    int pi = rp_patch(g, rp, slot);
    if (g->tl && g->tl[pi].kind == PATCH_TRI) {
        /* slot_point's triangle rows from the packed copy (tri_loc: the
         * same values, two cache lines instead of the patch's 392 bytes) */
        const tri_loc *t = &g->tl[pi];
        long local = slot - t->slot_first;
        int side = local >= t->rp_count;
        if (side) local -= t->rp_count;
        int k = t->k, a = 0;
        while (a < k && (long)(a + 1) * (k + 1) - (long)(a + 1) * a / 2 <= local) a++;
        long b = local - ((long)a * (k + 1) - (long)a * (a - 1) / 2);
        *pos = v3_add(t->v0, v3_add(v3_scale(t->e1, (double)a / k), v3_scale(t->e2, (double)b / k)));
        *nrm = side ? v3_neg(t->nrm) : t->nrm;
        return;
    }
    const patch *p = &g->p[pi];
    long local = slot - p->slot_first;
    int side = local >= p->rp_count;
    if (side) local -= p->rp_count;
    slot_point(g, p, local, pos, nrm);
    if (side) *nrm = v3_neg(*nrm);
}

static long tri_index(int k, int a, int b) { return (long)a * (k + 1) - (long)a * (a - 1) / 2 + b; }

/* fmax(0, x), fmin(1, fmax(0, x)) and (int)floor(x) for x >= 0 or NaN, as
 * the calls compute them (NaN gives 0; a zero's sign aside) but inline:
 * without -ffinite-math-only GCC calls libm for fmax/fmin, and floor
 * without SSE4.1, and locate runs them for every lookup. On x86-64
 * (int) of a NaN or of anything past INT_MAX is INT_MIN either way. */
static inline double max0(double x) { return x > 0.0 ? x : 0.0; }
static inline double clamp01(double x) { return x > 0.0 ? (x < 1.0 ? x : 1.0) : 0.0; }
static inline int floor_nonneg(double x) { return (int)x; }

/* The end of every locate: the cell's slots to radiance particles, its
 * weights clamped into [0, 1] (tiny negatives from rounding) and
 * normalised. */
static void cell_finish(const gi_surface *g, long rp[3], double w[3])
{
    double sum = 0.0;
    for (int q = 0; q < 3; q++) {
        rp[q] = slot_rp(g, rp[q]);
        w[q] = clamp01(w[q]);
        sum += w[q];
    }
    if (sum > 0.0)
        for (int q = 0; q < 3; q++) w[q] /= sum;
}

/* gi_surface_locate on triangle patches first .. first + count - 1 (a mesh
 * triangle, a triangle, a box's or clipped plane's triangles): the one
 * the point lies in (or nearest to), its side and sub-triangle. Reads the
 * tri_loc records (the patches' values: the same arithmetic). */
static int locate_tri(const gi_surface *g, int first, int count, const accel_hit *hit, vec3 n_view, long rp[3],
                      double w[3])
{
    tri_loc own;
    int bi = -1;
    double u = 0.0, v = 0.0, best = INFINITY;
    for (int i = first; i < first + count; i++) {
        const tri_loc *c = g->tl ? &g->tl[i] : (tri_loc_fill(&own, &g->p[i]), &own);
        if (c->nsides == 0) continue;
        /* boxes and clipped planes have several triangles: take the one
         * the point lies in (or nearest to, off a plane's clipped part);
         * the barycentrics of e1, e2 */
        vec3 r = v3_sub(hit->p, c->v0);
        double d00 = v3_dot(c->e1, c->e1), d01 = v3_dot(c->e1, c->e2), d11 = v3_dot(c->e2, c->e2);
        double d20 = v3_dot(r, c->e1), d21 = v3_dot(r, c->e2);
        double den = d00 * d11 - d01 * d01, cu = 0.0, cv = 0.0;
        if (fabs(den) > 0.0) {
            cu = (d11 * d20 - d01 * d21) / den;
            cv = (d00 * d21 - d01 * d20) / den;
        }
        double out = max0(-cu) + max0(-cv) + max0(cu + cv - 1.0) + fabs(v3_dot(r, c->nrm)) / c->rs;
        if (out < best) {
            best = out;
            u = cu;
            v = cv;
            bi = i;
        }
    }
    if (bi < 0) return 0;
    const tri_loc *p = g->tl ? &g->tl[bi] : (tri_loc_fill(&own, &g->p[bi]), &own);
    /* side: the geometric normal on the viewer's side, against the front normal */
    vec3 ng = v3_dot(n_view, hit->ng) >= 0.0 ? hit->ng : v3_neg(hit->ng);
    int side = v3_dot(ng, p->nrm) < 0.0;
    if (side >= p->nsides) return 0;
    long base = p->slot_first + side * (long)p->rp_count;
    /* clamp into the triangle, then find the sub-triangle */
    u = max0(u);
    v = max0(v);
    if (u + v > 1.0) {
        double s = u + v;
        u /= s;
        v /= s;
    }
    int k = p->k;
    double fa = u * k, fb = v * k;
    int a = floor_nonneg(fa), b = floor_nonneg(fb);
    if (a > k - 1) a = k - 1;
    if (b > k - 1) b = k - 1;
    if (a < 0) a = 0;
    if (b < 0) b = 0;
    if (a + b > k - 1) {
        /* on the far edge: step back into the last row */
        if (a >= b) a = k - 1 - b;
        else b = k - 1 - a;
    }
    double x = fa - a, y = fb - b;
    if (x + y <= 1.0 || a + b + 2 > k) {
        rp[0] = base + tri_index(k, a, b);
        rp[1] = base + tri_index(k, a + 1, b);
        rp[2] = base + tri_index(k, a, b + 1);
        w[0] = 1.0 - x - y;
        w[1] = x;
        w[2] = y;
    } else {
        rp[0] = base + tri_index(k, a + 1, b + 1);
        rp[1] = base + tri_index(k, a + 1, b);
        rp[2] = base + tri_index(k, a, b + 1);
        w[0] = x + y - 1.0;
        w[1] = 1.0 - y;
        w[2] = 1.0 - x;
    }
    cell_finish(g, rp, w);
    return 1;
}

int gi_surface_one_cell(const gi_surface *g, const accel_hit *hit)
{
    if (!hit || !hit->obj) return 0;
    const obj_rec *o = gi_surface_find_obj(g, hit->obj);
    if (!o || o->kind != SHAPE_MESH || hit->prim >= (unsigned)o->count) return 0;
    int i = o->first + (int)hit->prim;
    /* a mesh triangle is one patch (count 1 in locate): k = 1 puts a = b = 0 */
    return g->p[i].kind == PATCH_TRI && (g->tl ? g->tl[i].k : g->p[i].k) == 1;
}

int gi_surface_locate(const gi_surface *g, const accel_hit *hit, vec3 n_view, long rp[3], double w[3])
{
    if (!hit || !hit->obj) return 0;
    const obj_rec *o = gi_surface_find_obj(g, hit->obj);
    if (!o || o->count == 0) return 0;
    int first = o->first, count = o->count;
    if (o->kind == SHAPE_MESH) {
        if (hit->prim >= (unsigned)count) return 0;
        first += (int)hit->prim;
        count = 1;
    }
    const patch *p = NULL;
    double u = 0.0, v = 0.0;
    if (g->p[first].kind == PATCH_TRI) return locate_tri(g, first, count, hit, n_view, rp, w);
    if (g->p[first].kind == PATCH_PIECE) {
        /* a grid: the triangle nearest the hit, barycentrics of the nearest point on it */
        const patch *pp = &g->p[first];
        double tw[3];
        long t = pp->nsides ? gi_surface_mesh_locate(g, first, hit->p, hit->ng, tw) : -1;
        if (t < 0) return 0;
        const vec3 *vv = g->mv + pp->vfirst, *vn = g->mn + pp->vfirst;
        const int *tv = g->mt[t];
        vec3 fn = v3_cross(v3_sub(vv[tv[1]], vv[tv[0]]), v3_sub(vv[tv[2]], vv[tv[0]]));
        vec3 ns = v3_add(v3_add(vn[tv[0]], vn[tv[1]]), vn[tv[2]]);
        if (v3_dot(fn, ns) < 0.0) fn = v3_neg(fn);
        if (!(v3_len2(fn) > 0.0)) fn = ns;
        vec3 ngv = v3_dot(n_view, hit->ng) >= 0.0 ? hit->ng : v3_neg(hit->ng);
        int side = v3_dot(ngv, fn) < 0.0;
        if (side >= pp->nsides) return 0;
        long base = pp->slot_first + side * pp->rp_count;
        double sum = 0.0;
        for (int k = 0; k < 3; k++) {
            rp[k] = slot_rp(g, base + tv[k]);
            w[k] = fmin(1.0, fmax(0.0, tw[k]));
            sum += w[k];
        }
        if (!(sum > 0.0)) return 0;
        for (int k = 0; k < 3; k++) w[k] /= sum;
        return 1;
    } else {
        p = &g->p[first];
        vec3 q = xform_inv_point(&hit->obj->transform, hit->p);
        vec3 d = v3_sub(q, p->c);
        if (p->kind == PATCH_SPHERE) {
            u = atan2(d.z, d.x) / (2.0 * M_PI);
            v = 0.5 * (d.y / p->r0 + 1.0);
        } else {
            u = atan2(v3_dot(d, p->gb), v3_dot(d, p->ga)) / (2.0 * M_PI);
            double r2 = v3_len2(v3_sub(d, v3_scale(p->gn, v3_dot(d, p->gn))));
            v = (r2 - p->r0 * p->r0) / (p->r1 * p->r1 - p->r0 * p->r0);
        }
        if (u < 0.0) u += 1.0;
    }
    if (!p || p->nsides == 0) return 0;
    /* side: the geometric normal on the viewer's side, against the front normal */
    vec3 ng = v3_dot(n_view, hit->ng) >= 0.0 ? hit->ng : v3_neg(hit->ng);
    vec3 front;
    gi_surface_grid_eval(g, p, fmin(fmax(u, 0.0), 1.0), fmin(fmax(v, 0.0), 1.0), NULL, &front);
    int side = v3_dot(ng, front) < 0.0;
    if (side >= p->nsides) return 0;
    long base = p->slot_first + side * p->rp_count;
    {
        u = fmin(fmax(u, 0.0), 1.0);
        v = fmin(fmax(v, 0.0), 1.0);
        double fu = u * p->nu, fv = v * p->nv;
        int i = (int)floor(fu), j = (int)floor(fv);
        if (i > p->nu - 1) i = p->nu - 1;
        if (j > p->nv - 1) j = p->nv - 1;
        double x = fu - i, y = fv - j;
        long row = p->nu + 1;
        if (x + y <= 1.0) {
            rp[0] = base + (long)j * row + i;
            rp[1] = base + (long)j * row + i + 1;
            rp[2] = base + (long)(j + 1) * row + i;
            w[0] = 1.0 - x - y;
            w[1] = x;
            w[2] = y;
        } else {
            rp[0] = base + (long)(j + 1) * row + i + 1;
            rp[1] = base + (long)j * row + i + 1;
            rp[2] = base + (long)(j + 1) * row + i;
            w[0] = x + y - 1.0;
            w[1] = 1.0 - y;
            w[2] = 1.0 - x;
        }
    }
    cell_finish(g, rp, w);
    return 1;
}
