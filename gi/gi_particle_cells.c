/* gi_particle_cells.c - the particle GI mode's light-leak guard: per-cell
 * visibility tests of the radiance particles' interpolation cells, alone
 * or batched for a pre-pass row. */
#include "gi_particle_internal.h"
#include "grow.h"
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "camera.h"
#include "gi_cellvis.h"
#include "gi_cl.h"
#include "gi_cl_c.h"
#include "gi_links.h"
#include "gi_area_particles.h"
#include "gi_radiance.h"
#include "gi_surface.h"
#include "pool.h"
#include "rng.h"
#include "timer.h"

/* The first frame's cell tests, batched (kept hits). The pre-pass meets
 * most cells for the first time in the first frame after a geometry stage
 * (maze: ~49,000 cells, 6 segments each, traced one by one with
 * accel_intersect). A pre-pass thread instead collects the untested cells
 * of its row here (each once: a small hash by key) with the records that
 * lie in them, and at the row's end traces the six segments of all of
 * them together as coherent packets (accel_hit_any_n: neighbouring cells'
 * short segments) that only ask whether anything lies on a segment. A
 * segment with nothing on it is visible (gi_visible traces no further);
 * one with something gets gi_visible's own test (gi_visible_along, the
 * same ray and rule as cell_clear's). So every verdict is cell_clear's; it
 * is written into the row's records, put in the table and in the thread's
 * small cache of recent verdicts (seen: the next rows meet most of these
 * cells again, and a table probe is a cache and TLB miss). A cell not in
 * that cache goes into the batch, which asks the table first (all the
 * row's probes prefetched together: cells another thread tested). Rows go
 * to the threads in bands (VIEW_BAND), so the row after a row is mostly the
 * same thread's. */
#define BATCH_HASH 512 /* slots of a row's hash of cells (a row of maze at 512 pixels meets ~100 new ones) */
#define BATCH_SEEN 4096 /* the thread's verdicts of the last rows, direct-mapped (32 KiB) */
typedef struct {
    uint64_t key;
    long rp[3];
    const scene_object *own;
    int verdict; /* tested (or the table's) */
    int known;   /* the table's verdict (another thread's test), UNKNOWN: tested here */
} batch_cell_t;

typedef struct {
    view_rec *vr;
    int cell;
} batch_pix_t;

struct cell_batch {
    batch_cell_t *cell;
    int ncell, capcell;
    batch_pix_t *pix;
    int npix, cappix;
    int slot[BATCH_HASH]; /* 1 + index in cell, 0: empty; more cells than slots/2: no hash, linear */
    uint64_t seen[BATCH_SEEN]; /* key << 2 | verdict of cells this thread tested (the next rows meet
                                  them again): no probe of the table (a cache miss each) */
    /* the segments of a test: ray k is segment sg[k] of cell owner[k] */
    gi_segment *sg;
    vec3 *org, *dir;
    double *tmin, *tmax;
    unsigned char *hit;
    int *owner;
    int capray;
};


/* gi_particle_kept_verdict's answer for a cell in the row's batch (never stored in a
 * record or the table: the batch writes the verdict at the row's end) */
#define CELL_PENDING 3

static int cell_clear(gi_particle *gp, const long rp[3], const scene_object *own, thread_count *tc);
static int batch_cell(struct cell_batch *b, uint64_t key, const long rp[3], const scene_object *own);
static unsigned batch_seen_slot(uint64_t key) { return (unsigned)((key * 0x9e3779b97f4a7c15ULL) >> 52); }
static int batch_pixel(struct cell_batch *b, view_rec *vr, int cell);

/* The memo of a pre-pass row; with kept hits and the table, the thread's
 * batch of cell tests (NULL when out of memory: tested when met). */
view_memo gi_particle_row_memo(gi_particle *gp, const view_rec *rec, int thread)
{
    view_memo m = {&gp->tc[thread < GI_MAX_THREADS ? thread : 0], 0, GI_CELL_UNKNOWN, NULL, -1};
    if (rec && gp->cells) {
        if (!m.tc->cb) m.tc->cb = calloc(1, sizeof *m.tc->cb);
        m.b = m.tc->cb;
    }
    return m;
}

/* The light-leak guard's verdict on cell rp (key: gi_cellvis_key) of a hit
 * on `own`: the table's, else tested now (cell_clear) and put in the table;
 * GI_CELL_UNKNOWN without a key (no table: the caller tests per hit). */
int gi_particle_cell_verdict(gi_particle *gp, uint64_t key, const long rp[3], const scene_object *own, thread_count *tc)
{
    int verdict = gi_cellvis_get(gp->cells, key);
    if (verdict == GI_CELL_UNKNOWN && key) {
        verdict = cell_clear(gp, rp, own, tc) ? GI_CELL_CLEAR : GI_CELL_BLOCKED;
        gi_cellvis_put(gp->cells, key, verdict);
    }
    return verdict;
}

/* The verdict side_value would take for the cell rp of a hit on `own`
 * (tested now when the table has none): the same test, moved to the
 * pre-pass. Before the table (a cache miss a probe), the previous pixel's
 * cell and what this pixel's record held from an earlier frame (rp and
 * verdict are written together, a verdict depends on the cell alone). */
int gi_particle_kept_verdict(gi_particle *gp, const long rp[3], const scene_object *own, view_memo *m, view_rec *old)
{
    uint64_t key = gi_cellvis_key(gp->cells, rp);
    if (!key) return GI_CELL_UNKNOWN;
    if (key == m->key) {
        /* a cell waiting in the batch: this record gets its verdict too */
        if (m->verdict == CELL_PENDING)
            return batch_pixel(m->b, old, m->pend) ? GI_CELL_UNKNOWN : gi_particle_cell_verdict(gp, key, rp, own, m->tc);
        return m->verdict;
    }
    if (old->verdict != GI_CELL_UNKNOWN && old->rp[0] == rp[0] && old->rp[1] == rp[1] && old->rp[2] == rp[2]) {
        m->key = key;
        m->verdict = old->verdict;
        return old->verdict;
    }
    int verdict = GI_CELL_UNKNOWN;
    if (m->b) {
        uint64_t v = m->b->seen[batch_seen_slot(key)];
        if (v >> 2 == key) verdict = (int)(v & 3u);
    }
    if (verdict == GI_CELL_UNKNOWN && m->b) {
        /* not tested by this thread lately: into the row's batch
         * (cell_batch), which asks the table first; the record's verdict
         * is written when the batch is done */
        int i = batch_cell(m->b, key, rp, own);
        if (i >= 0 && batch_pixel(m->b, old, i)) {
            m->key = key;
            m->verdict = CELL_PENDING;
            m->pend = i;
            return GI_CELL_UNKNOWN;
        }
    }
    if (verdict == GI_CELL_UNKNOWN) verdict = gi_particle_cell_verdict(gp, key, rp, own, m->tc);
    m->key = key;
    m->verdict = verdict;
    return verdict;
}

/* Whether every point of the cell (the sub-triangle of radiance particles
 * rp, on object own) sees its three vertices, as side_value's per-hit test
 * (gi_visible, the same eps and object rule) would find: tested once per
 * cell on six segments, the three edges and the three from the centroid
 * (normal: the mean of the vertices') to each vertex. An object that cuts
 * the (lifted) cell anywhere crosses an edge, or encloses the centroid and
 * so crosses a spoke (a box standing on the floor, a wall across a cell).
 * What this gives up: an occluder whose cross-section at the lifted cell
 * lies entirely inside it and misses the three spokes (a thin post standing
 * inside one floor cell; on a curved cell, something touching the surface
 * between the chords, e.g. the floor under a sphere resting on it, within
 * the one cell around the contact point). Hits there interpolate all three
 * vertices where the per-hit test dropped some: light from a vertex on the
 * far side of the post, never from inside a closed solid the cell's
 * vertices are outside of.
 * The segments run between the vertices moved 1e-3 of the way to the
 * centroid (CELL_SHRINK): a wall standing on the cell's edge (a floor cell
 * along the foot of a wall, the wall's cells along the floor) touches the
 * exact edge and its grazing rays, and made 5.7% of cbox's cells blocked
 * (0.7% with the margin: the cells its two blocks stand across; maze 6.1% ->
 * 2.7%); the per-hit test there had kept all three vertices but at the odd
 * hit (cbox's mean luminance -0.02%). Given up with it: an occluder within
 * that margin of the edge, parallel to it. */
#define CELL_SHRINK 1e-3

/* The ends of cell rp's six segments: its vertices q (moved CELL_SHRINK of
 * the way to the centroid) with their normals nq, the centroid c with the
 * vertices' mean normal nc. Segment 2k is the edge q[k] -> q[k+1 mod 3],
 * 2k+1 the spoke c -> q[k]. */
static void cell_ends(const gi_particle *gp, const long rp[3], vec3 q[3], vec3 nq[3], vec3 *cp, vec3 *ncp)
{
    vec3 c = v3(0, 0, 0), nc = v3(0, 0, 0);
    for (int k = 0; k < 3; k++) {
        gi_surface_rp(gp->surf, rp[k], &q[k], &nq[k]);
        c = v3_madd(c, q[k], 1.0 / 3.0);
        nc = v3_add(nc, nq[k]);
    }
    nc = v3_len2(nc) > 0.0 ? v3_norm(nc) : nq[0];
    for (int k = 0; k < 3; k++) q[k] = v3_madd(q[k], v3_sub(c, q[k]), CELL_SHRINK);
    *cp = c;
    *ncp = nc;
}

static int cell_clear(gi_particle *gp, const long rp[3], const scene_object *own, thread_count *tc)
{
    vec3 q[3], nq[3], c, nc;
    cell_ends(gp, rp, q, nq, &c, &nc);
    tc->cells++;
    for (int k = 0; k < 3; k++) {
        int j = k + 1 < 3 ? k + 1 : 0;
        tc->vis_rays++;
        if (!gi_visible(gp->a, gp->vis_eps, q[k], nq[k], q[j], nq[j], own)) return 0;
        tc->vis_rays++;
        if (!gi_visible(gp->a, gp->vis_eps, c, nc, q[k], nq[k], own)) return 0;
    }
    tc->cells_clear++;
    return 1;
}

void gi_particle_cell_batch_free(struct cell_batch *b)
{
    if (!b) return;
    free(b->cell);
    free(b->pix);
    free(b->sg);
    free(b->org);
    free(b->dir);
    free(b->tmin);
    free(b->tmax);
    free(b->hit);
    free(b->owner);
    free(b);
}

/* The batch's index of cell key (added when new), -1 out of memory. */
static int batch_cell(struct cell_batch *b, uint64_t key, const long rp[3], const scene_object *own)
{
    unsigned h = (unsigned)((key * 0x9e3779b97f4a7c15ULL) >> 55) & (BATCH_HASH - 1);
    int hashed = b->ncell < BATCH_HASH / 2;
    if (hashed) {
        for (unsigned k = h;; k = (k + 1) & (BATCH_HASH - 1)) {
            int i = b->slot[k] - 1;
            if (i < 0) break;
            if (b->cell[i].key == key) return i;
        }
    } else {
        for (int i = b->ncell - 1; i >= 0; i--)
            if (b->cell[i].key == key) return i;
    }
    if (!grow_array_int((void **)&b->cell, &b->capcell, b->ncell + 1, sizeof *b->cell)) return -1;
    int i = b->ncell++;
    b->cell[i].key = key;
    for (int k = 0; k < 3; k++) b->cell[i].rp[k] = rp[k];
    b->cell[i].own = own;
    b->cell[i].verdict = GI_CELL_CLEAR;
    b->cell[i].known = GI_CELL_UNKNOWN;
    if (hashed) {
        unsigned k = h;
        while (b->slot[k]) k = (k + 1) & (BATCH_HASH - 1);
        b->slot[k] = i + 1;
    }
    return i;
}

/* Record vr lies in the batch's cell: 1, or 0 out of memory. */
static int batch_pixel(struct cell_batch *b, view_rec *vr, int cell)
{
    if (!grow_array_int((void **)&b->pix, &b->cappix, b->npix + 1, sizeof *b->pix)) return 0;
    b->pix[b->npix].vr = vr;
    b->pix[b->npix].cell = cell;
    b->npix++;
    return 1;
}

/* Tests the batch's cells (the verdicts cell_clear gives), stores them in
 * the table and the waiting records; empties the batch. */
void gi_particle_batch_test(gi_particle *gp, struct cell_batch *b, thread_count *tc)
{
    if (!b || b->ncell == 0) return;
    int nr = 0, ok = 1;
    int need = 6 * b->ncell;
    if (need > b->capray) {
        int cap = b->capray;
        ok = grow_array_int((void **)&b->sg, &cap, need, sizeof *b->sg);
        cap = b->capray;
        ok = ok && grow_array_int((void **)&b->org, &cap, need, sizeof *b->org);
        cap = b->capray;
        ok = ok && grow_array_int((void **)&b->dir, &cap, need, sizeof *b->dir);
        cap = b->capray;
        ok = ok && grow_array_int((void **)&b->tmin, &cap, need, sizeof *b->tmin);
        cap = b->capray;
        ok = ok && grow_array_int((void **)&b->tmax, &cap, need, sizeof *b->tmax);
        cap = b->capray;
        ok = ok && grow_array_int((void **)&b->hit, &cap, need, sizeof *b->hit);
        cap = b->capray;
        ok = ok && grow_array_int((void **)&b->owner, &cap, need, sizeof *b->owner);
        if (ok) b->capray = cap;
    }
    if (ok) {
        /* the table's verdicts first (cells another thread tested): all the
         * probes' cache misses at once, as are the radiance particles' */
        for (int c = 0; c < b->ncell; c++) {
            gi_cellvis_prefetch(gp->cells, b->cell[c].key);
            for (int k = 0; k < 3; k++) gi_surface_rp_prefetch(gp->surf, b->cell[c].rp[k]);
        }
        for (int c = 0; c < b->ncell; c++) {
            b->cell[c].known = gi_cellvis_get(gp->cells, b->cell[c].key);
            if (b->cell[c].known != GI_CELL_UNKNOWN) b->cell[c].verdict = b->cell[c].known;
        }
        for (int c = 0; c < b->ncell; c++) {
            if (b->cell[c].known != GI_CELL_UNKNOWN) continue;
            vec3 q[3], nq[3], ctr, nc;
            cell_ends(gp, b->cell[c].rp, q, nq, &ctr, &nc);
            for (int k = 0; k < 3; k++) {
                int j = k + 1 < 3 ? k + 1 : 0;
                /* cell_clear's order: the edge from q[k], the spoke to q[k] */
                const scene_object *own = b->cell[c].own;
                if (gi_visible_segment(gp->a, gp->vis_eps, q[k], nq[k], q[j], nq[j], own, &b->sg[nr])) b->owner[nr++] = c;
                if (gi_visible_segment(gp->a, gp->vis_eps, ctr, nc, q[k], nq[k], own, &b->sg[nr])) b->owner[nr++] = c;
            }
        }
        for (int r = 0; r < nr; r++) {
            b->org[r] = b->sg[r].p;
            b->dir[r] = b->sg[r].d;
            b->tmin[r] = 0.0;
            b->tmax[r] = b->sg[r].len;
        }
        /* gi_visible's exact crossings (ACCEL_RAY_EXACT): a segment along
         * an isosurface cell must see the surface where it dips under it */
        accel_hit_any_n(gp->a, ACCEL_RAY_EXACT, nr, b->org, b->dir, b->tmin, b->tmax, b->hit);
        for (int r = 0; r < nr; r++) {
            batch_cell_t *bc = &b->cell[b->owner[r]];
            if (!b->hit[r] || bc->verdict != GI_CELL_CLEAR) continue;
            if (!gi_visible_along(gp->a, gp->vis_eps, &b->sg[r], bc->own)) bc->verdict = GI_CELL_BLOCKED;
        }
        tc->vis_rays += nr;
        for (int c = 0; c < b->ncell; c++) {
            if (b->cell[c].known != GI_CELL_UNKNOWN) continue;
            tc->cells++;
            tc->cells_clear += b->cell[c].verdict == GI_CELL_CLEAR;
            gi_cellvis_put(gp->cells, b->cell[c].key, b->cell[c].verdict);
        }
        for (int c = 0; c < b->ncell; c++)
            b->seen[batch_seen_slot(b->cell[c].key)] = b->cell[c].key << 2 | (uint64_t)b->cell[c].verdict;
    } else {
        /* no memory for the rays: one cell at a time */
        for (int c = 0; c < b->ncell; c++)
            b->cell[c].verdict = gi_particle_cell_verdict(gp, b->cell[c].key, b->cell[c].rp, b->cell[c].own, tc);
    }
    for (int k = 0; k < b->npix; k++) b->pix[k].vr->verdict = (unsigned char)b->cell[b->pix[k].cell].verdict;
    b->ncell = 0;
    b->npix = 0;
    memset(b->slot, 0, sizeof b->slot);
}
