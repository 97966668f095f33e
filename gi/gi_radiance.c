/* gi_radiance.c - estimation lists for the radiance particles. */
#include "gi_radiance.h"
#include "grow.h"
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include "pool.h"

#define RP_CHUNK 1024

typedef struct {
    const gi_surface *g;
    const gi_particles *ps;
    const accel *a;
    double eps;
    gi_grid *grid, *fine;
    const int *alive; /* particles per patch side */
    double r, cos_thr;
    long nrp;
    int **out;    /* per chunk: entries */
    long *outlen; /* per chunk */
    int *count;   /* per radiance particle */
    atomic_long widened, empty, dead, rays;
    atomic_int oom;
} list_job;

int gi_visible_segment(const accel *a, double eps, vec3 x, vec3 nx, vec3 y, vec3 ny, const scene_object *own,
                       gi_segment *sg)
{
    /* both ends lifted off their surfaces by more than accel's
     * self-intersection epsilon at x (accel.h), so that a segment leaving
     * x's surface downwards meets that surface where it crosses it; and by
     * more than twice how far a traced hit on `own` may lie inside it
     * (accel_hit_placement: an isosurface's hit up to accuracy past its
     * surface), so that x starts outside the surface it lies on and the
     * crossings counted below are the exact surface's */
    double lift = fmax(fmax(16.0 * eps, 2.0 * accel_epsilon(a, x, nx)), 2.0 * accel_hit_placement(own));
    vec3 p = v3_madd(x, nx, lift), q = v3_madd(y, ny, lift);
    vec3 d = v3_sub(q, p);
    double len = v3_len(d);
    if (!(len > 2.0 * lift)) return 0;
    sg->p = p;
    sg->d = v3_scale(d, 1.0 / len);
    sg->len = len;
    sg->lift = lift;
    return 1;
}

int gi_visible_along(const accel *a, double eps, const gi_segment *sg, const scene_object *own)
{
    double tmin = 0.0, len = sg->len;
    int crossings = 0;
    for (int k = 0; k < 8; k++) {
        accel_hit h;
        /* the exact crossings: their parity is the test (ACCEL_RAY_EXACT) */
        if (!accel_intersect_rule(a, ACCEL_RAY_EXACT, sg->p, sg->d, tmin, len, &h)) break;
        if (h.obj != own) return 0;
        /* not where the segment ends: a radiance particle on an edge,
         * lifted, lies in the plane of the face across the edge */
        if (h.t < len - sg->lift) crossings++;
        tmin = h.t + fmax(eps, h.t * 1e-7);
    }
    /* `own` may be crossed only an even number of times: a chord of a
     * curved surface dips under it and comes out again (2), while one
     * crossing puts y behind a sheet of `own`: the inner side of the lower
     * face of a thin closed slab (conference.pov's table tops, 0.04 thick,
     * within one list radius of the upper face: same object, same patch
     * side, same normal) lent its dark inside to the top's estimates */
    return (crossings & 1) == 0;
}

int gi_visible(const accel *a, double eps, vec3 x, vec3 nx, vec3 y, vec3 ny, const scene_object *own)
{
    gi_segment sg;
    return !gi_visible_segment(a, eps, x, nx, y, ny, own, &sg) || gi_visible_along(a, eps, &sg, own);
}

static int visible(const list_job *J, vec3 q, vec3 nq, int i, const scene_object *obj)
{
    const gi_dev_particle *pt = &J->ps->p[i];
    return gi_visible(J->a, J->eps, q, nq, v3(pt->p[0], pt->p[1], pt->p[2]), v3(pt->n[0], pt->n[1], pt->n[2]), obj);
}

/* 1 when area particle i lies on object `obj`, on side `side` (0: the
 * patches' front normal, 1: the opposite). Estimation lists hold only
 * particles of the radiance particle's own object and side: the normal test
 * alone let particles on the inside of a closed sphere or box (which exist
 * when a light or the camera is inside it) count for the outside of its
 * opposite wall, and the inner bottom of a box standing on the floor count
 * for the floor around it (test_stability, light_inside). The estimate is
 * an area-weighted mean, so fewer entries only smooth less; they bias
 * nothing. */
static int gi_same_surface(const gi_surface *g, const gi_particles *ps, int i, const scene_object *obj, int side)
{
    return gi_surface_object(g, ps->patch[i]) == obj && ps->side[i] == side;
}

/* Keeps, of the m entries just appended to buf[0, *len), those on the
 * radiance particle's own object and side (gi_same_surface); returns how
 * many are left (m < 0: out of memory, passed on). */
static long same_surface(const list_job *J, const scene_object *obj, int side, vec3 q, vec3 nq, int *buf, long *len,
                         long m, long *rays)
{
    if (m <= 0) return m;
    long w = *len - m, first = w;
    for (long i = first; i < *len; i++) {
        if (!gi_same_surface(J->g, J->ps, buf[i], obj, side)) continue;
        (*rays)++;
        if (visible(J, q, nq, buf[i], obj)) buf[w++] = buf[i];
    }
    *len = w;
    return w - first;
}

static void job(void *ctx, int chunk, int thread)
{
    (void)thread;
    list_job *J = ctx;
    long lo = (long)chunk * RP_CHUNK, hi = lo + RP_CHUNK < J->nrp ? lo + RP_CHUNK : J->nrp;
    int *buf = NULL;
    long len = 0, cap = 0, wid = 0, emp = 0, dead = 0, vrays = 0;
    for (long l = lo; l < hi; l++) {
        int pa = gi_surface_rp_patch(J->g, l);
        int side = gi_surface_rp_side(J->g, l);
        if (!J->alive[2 * (size_t)pa + side]) {
            /* its object has no particles on this side (it faces only the void): empty list */
            J->count[l] = 0;
            dead++;
            continue;
        }
        vec3 q, nq;
        gi_surface_rp(J->g, l, &q, &nq);
        const scene_object *obj = gi_surface_object(J->g, pa);
        long m = gi_grid_radius(J->grid, q, nq, J->r, J->cos_thr, &buf, &len, &cap);
        m = same_surface(J, obj, side, q, nq, buf, &len, m, &vrays);
        for (int widen = 2; m == 0 && widen <= 4; widen *= 2) {
            m = gi_grid_radius(J->grid, q, nq, J->r * widen, J->cos_thr, &buf, &len, &cap);
            m = same_surface(J, obj, side, q, nq, buf, &len, m, &vrays);
            if (m > 0) wid++;
        }
        if (m == 0) {
            /* the nearest particle facing the same way, within 4 r */
            int near = gi_grid_nearest(J->fine, q, v3_neg(nq), v3_madd(q, nq, 4.0 * J->r), 4.0 * J->r);
            if (near >= 0 && !(gi_same_surface(J->g, J->ps, near, obj, side) && visible(J, q, nq, near, obj))) near = -1;
            if (near >= 0) {
                if (!grow_array_long((void **)&buf, &cap, len + 1, sizeof *buf)) m = -1;
                if (m == 0) {
                    buf[len++] = near;
                    m = 1;
                    wid++;
                }
            } else {
                emp++;
            }
        }
        if (m < 0) {
            atomic_store(&J->oom, 1);
            break;
        }
        J->count[l] = (int)m;
    }
    J->out[chunk] = buf;
    J->outlen[chunk] = len;
    atomic_fetch_add(&J->widened, wid);
    atomic_fetch_add(&J->empty, emp);
    atomic_fetch_add(&J->dead, dead);
    atomic_fetch_add(&J->rays, vrays);
}

pt_status gi_radiance_lists(gi_lists *L, const gi_surface *g, const gi_particles *ps, const accel *a, double r,
                            double cos_thr, int threads, volatile int *cancel, progress *prog, diag *d)
{
    memset(L, 0, sizeof *L);
    L->nrp = gi_surface_nrp(g);
    list_job J = {.g = g, .ps = ps, .a = a,
                  .eps = 1e-6 * (accel_eps_scale(a) > 0.0 && isfinite(accel_eps_scale(a)) ? accel_eps_scale(a) : 1.0),
                  .r = r, .cos_thr = cos_thr, .nrp = L->nrp};
    atomic_init(&J.widened, 0);
    atomic_init(&J.empty, 0);
    atomic_init(&J.dead, 0);
    atomic_init(&J.rays, 0);
    atomic_init(&J.oom, 0);
    int chunks = (int)((L->nrp + RP_CHUNK - 1) / RP_CHUNK);
    J.grid = gi_grid_build(ps->p, ps->n, r);
    J.fine = gi_grid_build(ps->p, ps->n, ps->spacing > 0.0 ? ps->spacing : r);
    int np = gi_surface_npatches(g);
    int *alive = calloc(2 * (size_t)np + 2, sizeof *alive);
    if (alive) {
        for (int i = 0; i < ps->n; i++) alive[2 * (size_t)ps->patch[i] + ps->side[i]]++;
        /* A side is dead (it faces only the void) when its object has no
         * particles on that side, not merely its patch: a mesh's triangles
         * smaller than the particle spacing mostly get no particle of their
         * own (systematic sampling gives a patch floor(area / dA) or one
         * more), yet their radiance particles need the neighbours' lists.
         * An object's patches are consecutive (gi_surface_locate). */
        for (int a = 0; a < np;) {
            const scene_object *o = gi_surface_object(g, a);
            int b = a, n0 = 0, n1 = 0;
            while (b < np && gi_surface_object(g, b) == o) {
                n0 |= alive[2 * (size_t)b] > 0;
                n1 |= alive[2 * (size_t)b + 1] > 0;
                b++;
            }
            for (int k = a; k < b; k++) {
                alive[2 * (size_t)k] = n0;
                alive[2 * (size_t)k + 1] = n1;
            }
            a = b;
        }
    }
    J.alive = alive;
    J.out = calloc((size_t)chunks + 1, sizeof *J.out);
    J.outlen = calloc((size_t)chunks + 1, sizeof *J.outlen);
    J.count = calloc((size_t)L->nrp + 1, sizeof *J.count);
    L->off = malloc(((size_t)L->nrp + 1) * sizeof *L->off);
    pt_status st = PT_OK;
    if (!J.grid || !J.fine || !alive || !J.out || !J.outlen || !J.count || !L->off) st = PT_ERR_NOMEM;
    if (st == PT_OK && chunks > 0 && !pool_run_counted(threads, chunks, job, &J, cancel, prog)) st = PT_CANCELLED;
    if (st == PT_OK && atomic_load(&J.oom)) st = PT_ERR_NOMEM;
    long total = 0;
    if (st == PT_OK) {
        for (int c = 0; c < chunks; c++) total += J.outlen[c];
        if (total > 2147483000L) {
            diag_report(d, DIAG_ERROR, (src_loc){0}, NULL,
                        "particle GI: estimation lists too long (%ld entries); lower the list radius", total);
            st = PT_ERR_LIMIT;
        }
    }
    if (st == PT_OK) {
        L->idx = malloc((size_t)(total > 0 ? total : 1) * sizeof *L->idx);
        if (!L->idx) st = PT_ERR_NOMEM;
    }
    if (st == PT_OK) {
        long at = 0;
        for (int c = 0; c < chunks; c++) {
            if (J.outlen[c]) memcpy(L->idx + at, J.out[c], (size_t)J.outlen[c] * sizeof *L->idx);
            at += J.outlen[c];
        }
        L->off[0] = 0;
        for (long l = 0; l < L->nrp; l++) L->off[l + 1] = L->off[l] + J.count[l];
        L->widened = atomic_load(&J.widened);
        L->empty = atomic_load(&J.empty);
        L->dead = atomic_load(&J.dead);
        L->vis_rays = atomic_load(&J.rays);
    }
    for (int c = 0; c < chunks; c++) free(J.out[c]);
    free(J.out);
    free(J.outlen);
    free(J.count);
    gi_grid_free(J.grid);
    gi_grid_free(J.fine);
    free(alive);
    if (st != PT_OK) gi_lists_free(L);
    return st;
}

void gi_lists_free(gi_lists *L)
{
    if (!L) return;
    free(L->off);
    free(L->idx);
    memset(L, 0, sizeof *L);
}
