/* geom_bvh.c - median-split bounding volume hierarchy (geom_bvh.h). */
#include "geom_bvh.h"
#include "grow.h"
#include <assert.h>
#include <math.h>
#include <stdlib.h>

/* The depth cap keeps a query's stack within BVH_STACK: a depth-first walk
 * that pushes both children holds at most one entry per level plus one. */
#define BVH_MAX_DEPTH 60
#define BVH_STACK 128

typedef struct {
    geom_bvh *b;
    const vec3 *lo, *hi;
    vec3 *cen;
    int leaf;
} builder;

static int node_new(geom_bvh *b)
{
    if (!grow_array_int((void **)&b->nodes, &b->capnodes, b->nnodes + 1, sizeof *b->nodes)) return -1;
    return b->nnodes++;
}

static int split(builder *bd, int first, int count, int depth)
{
    geom_bvh *b = bd->b;
    int id = node_new(b);
    if (id < 0) return -1;
    vec3 lo = v3s(INFINITY), hi = v3s(-INFINITY), clo = v3s(INFINITY), chi = v3s(-INFINITY);
    for (int i = first; i < first + count; i++) {
        int it = b->order[i];
        lo = v3_min(lo, bd->lo[it]);
        hi = v3_max(hi, bd->hi[it]);
        clo = v3_min(clo, bd->cen[it]);
        chi = v3_max(chi, bd->cen[it]);
    }
    b->nodes[id].lo = lo;
    b->nodes[id].hi = hi;
    b->nodes[id].pad = 1e-9 * v3_maxc(v3_sub(hi, lo)) + 1e-300;
    b->nodes[id].left = b->nodes[id].right = -1;
    b->nodes[id].first = first;
    b->nodes[id].count = count;
    if (count <= bd->leaf || depth > BVH_MAX_DEPTH) return id;
    vec3 ext = v3_sub(chi, clo);
    int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    if (!(v3_idx(ext, axis) > 0)) return id;
    /* nth element around the median by repeated partition */
    int *ord = b->order;
    int lo_i = first, hi_i = first + count - 1, mid = first + count / 2;
    while (lo_i < hi_i) {
        double pivot = v3_idx(bd->cen[ord[(lo_i + hi_i) / 2]], axis);
        int i = lo_i, j = hi_i;
        while (i <= j) {
            while (v3_idx(bd->cen[ord[i]], axis) < pivot) i++;
            while (v3_idx(bd->cen[ord[j]], axis) > pivot) j--;
            if (i <= j) {
                int tmp = ord[i];
                ord[i] = ord[j];
                ord[j] = tmp;
                i++;
                j--;
            }
        }
        if (mid <= j) hi_i = j;
        else if (mid >= i) lo_i = i;
        else break;
    }
    int left = split(bd, first, mid - first, depth + 1);
    int right = left < 0 ? -1 : split(bd, mid, first + count - mid, depth + 1);
    if (right < 0) return -1;
    b->nodes[id].left = left;
    b->nodes[id].right = right;
    return id;
}

void geom_bvh_free(geom_bvh *b)
{
    free(b->nodes);
    free(b->order);
    *b = (geom_bvh){0};
}

int geom_bvh_build(geom_bvh *b, int n, const vec3 *lo, const vec3 *hi, int leaf)
{
    *b = (geom_bvh){0};
    if (n < 1) return -1;
    builder bd = {b, lo, hi, malloc(sizeof(vec3) * (size_t)n), leaf < 1 ? 1 : leaf};
    b->order = malloc(sizeof *b->order * (size_t)n);
    if (!bd.cen || !b->order) {
        free(bd.cen);
        geom_bvh_free(b);
        return -1;
    }
    for (int i = 0; i < n; i++) {
        bd.cen[i] = v3_scale(v3_add(lo[i], hi[i]), 0.5);
        b->order[i] = i;
    }
    int root = split(&bd, 0, n, 0);
    free(bd.cen);
    if (root < 0) {
        geom_bvh_free(b);
        return -1;
    }
    return 0;
}

/* A query: the ray o + t d over [tmin, tmax] with 1/d per axis (flat
 * axes, d = 0, flagged), or the point o when !ray. */
typedef struct {
    int ray;
    vec3 o;
    double inv[3];
    int flat[3];
    double tmin, tmax;
} bvh_query;

/* Whether the node's box meets the query: the ray stretch (the box padded
 * by 1e-9 of its size, so that a crossing on a face is not lost to
 * rounding; the padding taken once, when the node is built) or the point. */
static int node_meets(const geom_bvh_node *nd, const bvh_query *q)
{
    if (!q->ray)
        return !(q->o.x < nd->lo.x || q->o.x > nd->hi.x || q->o.y < nd->lo.y || q->o.y > nd->hi.y ||
                 q->o.z < nd->lo.z || q->o.z > nd->hi.z);
    double pad = nd->pad;
    double a = q->tmin, b = q->tmax;
    for (int k = 0; k < 3; k++) {
        double o = v3_idx(q->o, k), lo = v3_idx(nd->lo, k) - pad, hi = v3_idx(nd->hi, k) + pad;
        if (q->flat[k]) {
            if (o < lo || o > hi) return 0;
            continue;
        }
        /* the face the ray enters by, then the one it leaves by */
        double inv = q->inv[k], t0 = ((inv > 0.0 ? lo : hi) - o) * inv, t1 = ((inv > 0.0 ? hi : lo) - o) * inv;
        if (t0 > a) a = t0;
        if (t1 < b) b = t1;
        if (!(a <= b)) return 0;
    }
    return 1;
}

static void walk(const geom_bvh *b, const bvh_query *q, geom_bvh_visit fn, void *ctx)
{
    if (b->nnodes == 0) return;
    int stack[BVH_STACK], sp = 0;
    stack[sp++] = 0;
    while (sp > 0) {
        const geom_bvh_node *nd = &b->nodes[stack[--sp]];
        if (!node_meets(nd, q)) continue;
        if (nd->left < 0) {
            for (int i = nd->first; i < nd->first + nd->count; i++) fn(ctx, b->order[i]);
            continue;
        }
        assert(sp + 2 <= BVH_STACK);
        stack[sp++] = nd->left;
        stack[sp++] = nd->right;
    }
}

void geom_bvh_ray(const geom_bvh *b, vec3 o, vec3 d, double tmin, double tmax, geom_bvh_visit fn, void *ctx)
{
    bvh_query q = {1, o, {0, 0, 0}, {0, 0, 0}, tmin, tmax};
    for (int k = 0; k < 3; k++) {
        double dk = v3_idx(d, k);
        q.flat[k] = dk == 0.0;
        q.inv[k] = q.flat[k] ? 0.0 : 1.0 / dk;
    }
    walk(b, &q, fn, ctx);
}

void geom_bvh_point(const geom_bvh *b, vec3 q, geom_bvh_visit fn, void *ctx)
{
    bvh_query pq = {0, q, {0, 0, 0}, {0, 0, 0}, 0.0, 0.0};
    walk(b, &pq, fn, ctx);
}
