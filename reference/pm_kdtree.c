/* pm_kdtree.c - implicit balanced kd-tree over photons (see pm_kdtree.h).
 *
 * Layout: the range [lo, hi) has its node at m = lo + (hi - lo) / 2, the
 * photon that is the median along ph[m].axis; [lo, m) and [m+1, hi) are the
 * children. Building partitions each range with a deterministic quickselect;
 * the top levels run one after another, then the 2^L subtrees in parallel on
 * core/pool, so the result does not depend on the thread count. */
#include "pm_kdtree.h"
#include "hash.h"
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include "pool.h"

struct pm_kdtree {
    pm_photon *ph;
    long n;
};

static signed char q8(double v)
{
    double s = v * 127.0;
    s = s > 127.0 ? 127.0 : (s < -127.0 ? -127.0 : s);
    return (signed char)lrint(s);
}

uint32_t pm_surface_key(const void *object, int outside)
{
    /* splitmix64 finaliser of the address: distinct objects, distinct keys
     * (a collision would only merge two objects' photons, as before keys) */
    uint64_t z = pt_mix64((uint64_t)(uintptr_t)object + 0x9e3779b97f4a7c15ULL);
    uint32_t k = (uint32_t)(z ^ (z >> 32)) & ~1u;
    if (k == 0) k = 2;
    return k | (outside ? 1u : 0u);
}

void pm_photon_set(pm_photon *ph, vec3 p, rgb power, vec3 n, uint32_t surf)
{
    v3_store_f(ph->p, p);
    ph->power[0] = (float)power.r;
    ph->power[1] = (float)power.g;
    ph->power[2] = (float)power.b;
    ph->n[0] = q8(n.x);
    ph->n[1] = q8(n.y);
    ph->n[2] = q8(n.z);
    ph->axis = 0;
    ph->surf = surf;
}

vec3 pm_photon_pos(const pm_photon *ph) { return v3(ph->p[0], ph->p[1], ph->p[2]); }
vec3 pm_photon_normal(const pm_photon *ph) { return v3(ph->n[0] / 127.0, ph->n[1] / 127.0, ph->n[2] / 127.0); }

/* ------------------------------------------------------------ build */

static void swap_ph(pm_photon *a, pm_photon *b)
{
    pm_photon t = *a;
    *a = *b;
    *b = t;
}

/* Partition ph[lo, hi) so that ph[k] is the k-th smallest along axis. */
static void select_k(pm_photon *ph, long lo, long hi, long k, int axis)
{
    hi--;
    while (hi > lo) {
        long mid = lo + (hi - lo) / 2;
        /* median of three as pivot, moved to hi */
        float a = ph[lo].p[axis], b = ph[mid].p[axis], c = ph[hi].p[axis];
        long piv = (a < b) ? ((b < c) ? mid : ((a < c) ? hi : lo)) : ((a < c) ? lo : ((b < c) ? hi : mid));
        swap_ph(&ph[piv], &ph[hi]);
        float pv = ph[hi].p[axis];
        long store = lo;
        for (long i = lo; i < hi; i++)
            if (ph[i].p[axis] < pv) swap_ph(&ph[i], &ph[store++]);
        /* equal keys: spread them so ranges shrink */
        long eq = store;
        for (long i = store; i < hi; i++)
            if (ph[i].p[axis] == pv) swap_ph(&ph[i], &ph[eq++]);
        swap_ph(&ph[eq], &ph[hi]);
        if (k < store) hi = store - 1;
        else if (k > eq) lo = eq + 1;
        else return;
    }
}

static void split(pm_photon *ph, long lo, long hi)
{
    float mn[3] = {FLT_MAX, FLT_MAX, FLT_MAX}, mx[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
    for (long i = lo; i < hi; i++)
        for (int k = 0; k < 3; k++) {
            if (ph[i].p[k] < mn[k]) mn[k] = ph[i].p[k];
            if (ph[i].p[k] > mx[k]) mx[k] = ph[i].p[k];
        }
    int axis = 0;
    if (mx[1] - mn[1] > mx[axis] - mn[axis]) axis = 1;
    if (mx[2] - mn[2] > mx[axis] - mn[axis]) axis = 2;
    long m = lo + (hi - lo) / 2;
    select_k(ph, lo, hi, m, axis);
    ph[m].axis = (unsigned char)axis;
}

static void build_rec(pm_photon *ph, long lo, long hi)
{
    while (hi - lo > 1) {
        split(ph, lo, hi);
        long m = lo + (hi - lo) / 2;
        build_rec(ph, lo, m);
        lo = m + 1;
    }
    if (hi - lo == 1) ph[lo].axis = 0;
}

typedef struct {
    pm_photon *ph;
    long *lo, *hi;
} sub_job;

static void sub_build(void *ctx, int i, int thread)
{
    (void)thread;
    sub_job *j = ctx;
    build_rec(j->ph, j->lo[i], j->hi[i]);
}

pm_kdtree *pm_kdtree_build(pm_photon *ph, long n, int threads)
{
    pm_kdtree *t = malloc(sizeof *t);
    if (!t) {
        free(ph);
        return NULL;
    }
    t->ph = ph;
    t->n = n;
    if (n <= 0) return t;
    /* top levels serially until there are enough subtrees for the pool */
    int levels = 0;
    int want = threads > 1 ? threads * 8 : 1;
    while ((1 << levels) < want && levels < 12 && (n >> levels) > 4096) levels++;
    long nsub = 1L << levels;
    long *lo = malloc(sizeof(long) * (size_t)nsub * 2), *hi = malloc(sizeof(long) * (size_t)nsub * 2);
    if (!lo || !hi) {
        free(lo);
        free(hi);
        build_rec(ph, 0, n);
        return t;
    }
    long cnt = 1;
    lo[0] = 0;
    hi[0] = n;
    for (int l = 0; l < levels; l++) {
        long nc = 0;
        long *nlo = lo + nsub, *nhi = hi + nsub;
        for (long i = 0; i < cnt; i++) {
            if (hi[i] - lo[i] > 1) {
                split(ph, lo[i], hi[i]);
                long m = lo[i] + (hi[i] - lo[i]) / 2;
                nlo[nc] = lo[i];
                nhi[nc++] = m;
                nlo[nc] = m + 1;
                nhi[nc++] = hi[i];
            } else if (hi[i] - lo[i] == 1) {
                ph[lo[i]].axis = 0;
            }
        }
        for (long i = 0; i < nc; i++) {
            lo[i] = nlo[i];
            hi[i] = nhi[i];
        }
        cnt = nc;
    }
    sub_job j = {ph, lo, hi};
    pool_run(threads, (int)cnt, sub_build, &j);
    free(lo);
    free(hi);
    return t;
}

void pm_kdtree_free(pm_kdtree *t)
{
    if (!t) return;
    free(t->ph);
    free(t);
}

long pm_kdtree_size(const pm_kdtree *t) { return t ? t->n : 0; }
const pm_photon *pm_kdtree_photons(const pm_kdtree *t) { return t ? t->ph : NULL; }

/* ------------------------------------------------------------ queries */

typedef struct {
    const pm_photon *ph;
    float q[3];
    float nq[3];
    float min_dot;
    uint32_t surf;
    int k, count;
    float max_d2;     /* current search radius^2 */
    pm_neighbour *heap;
} knn_state;

static int compatible(const knn_state *s, const pm_photon *p)
{
    if (s->surf != 0 && p->surf != s->surf) return 0;
    if (s->min_dot < -1.5f) return 1;
    float d = (p->n[0] * s->nq[0] + p->n[1] * s->nq[1] + p->n[2] * s->nq[2]) * (1.0f / 127.0f);
    return d >= s->min_dot;
}

static void heap_push(knn_state *s, long idx, float d2)
{
    pm_neighbour *h = s->heap;
    if (s->count < s->k) {
        int i = s->count++;
        while (i > 0) {
            int par = (i - 1) / 2;
            if (h[par].d2 >= d2) break;
            h[i] = h[par];
            i = par;
        }
        h[i].idx = idx;
        h[i].d2 = d2;
        if (s->count == s->k) s->max_d2 = h[0].d2;
        return;
    }
    /* replace the root (farthest) and sift down */
    int i = 0;
    for (;;) {
        int c = 2 * i + 1;
        if (c >= s->count) break;
        if (c + 1 < s->count && h[c + 1].d2 > h[c].d2) c++;
        if (h[c].d2 <= d2) break;
        h[i] = h[c];
        i = c;
    }
    h[i].idx = idx;
    h[i].d2 = d2;
    s->max_d2 = h[0].d2;
}

static void knn_rec(knn_state *s, long lo, long hi)
{
    while (hi > lo) {
        long m = lo + (hi - lo) / 2;
        const pm_photon *p = &s->ph[m];
        int ax = p->axis;
        float dd = s->q[ax] - p->p[ax];
        float dx = s->q[0] - p->p[0], dy = s->q[1] - p->p[1], dz = s->q[2] - p->p[2];
        float d2 = dx * dx + dy * dy + dz * dz;
        if (d2 < s->max_d2 && compatible(s, p)) heap_push(s, m, d2);
        if (hi - lo == 1) return;
        long nlo, nhi, flo, fhi;
        if (dd < 0.0f) {
            nlo = lo; nhi = m; flo = m + 1; fhi = hi;
        } else {
            nlo = m + 1; nhi = hi; flo = lo; fhi = m;
        }
        knn_rec(s, nlo, nhi);
        if (dd * dd >= s->max_d2) return;
        lo = flo;
        hi = fhi;
    }
}

int pm_kdtree_knn(const pm_kdtree *t, vec3 p, vec3 n, uint32_t surf, double min_dot, int k, double max_r2,
                  pm_neighbour *out)
{
    if (!t || t->n <= 0 || k < 1) return 0;
    knn_state s;
    s.ph = t->ph;
    v3_store_f(s.q, p);
    v3_store_f(s.nq, n);
    s.min_dot = (float)min_dot;
    s.surf = surf;
    s.k = k;
    s.count = 0;
    s.max_d2 = (float)max_r2;
    s.heap = out;
    knn_rec(&s, 0, t->n);
    return s.count;
}

