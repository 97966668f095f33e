/* geom_bvh.h - a bounding volume hierarchy over items given by their boxes
 * (a mesh's triangles, a blob's components): median splits on the longest
 * axis of the items' box centres, built once, then asked which items a ray
 * stretch or a point may meet. Items are numbered 0..n-1 by the caller; a
 * query reports each candidate item once, leaf by leaf, in no particular
 * order. */
#ifndef PT_GEOM_BVH_H
#define PT_GEOM_BVH_H
#include "vec.h"

typedef struct {
    vec3 lo, hi;
    int left, right;  /* children; -1 for a leaf */
    int first, count; /* leaf: its items are order[first .. first + count) */
    double pad;       /* a ray query's padding of the box (geom_bvh.c, node_meets) */
} geom_bvh_node;

typedef struct {
    geom_bvh_node *nodes; /* nodes[0] is the root */
    int nnodes, capnodes;
    int *order;
} geom_bvh;

/* Build over n items with boxes [lo[i], hi[i]], at most `leaf` items per
 * leaf (fewer where the depth cap or coincident centres stop the split).
 * 0, or -1 when memory ran out or n < 1 (*b is then empty). */
int geom_bvh_build(geom_bvh *b, int n, const vec3 *lo, const vec3 *hi, int leaf);
void geom_bvh_free(geom_bvh *b);

/* Called with each candidate item; `ctx` is the query's. */
typedef void (*geom_bvh_visit)(void *ctx, int item);

/* The items in every leaf whose box (padded by 1e-9 of its size, so that a
 * crossing on a face is not lost to rounding) the ray o + t d meets for
 * some t in [tmin, tmax]. */
void geom_bvh_ray(const geom_bvh *b, vec3 o, vec3 d, double tmin, double tmax, geom_bvh_visit fn, void *ctx);
/* The items in every leaf whose box holds q. */
void geom_bvh_point(const geom_bvh *b, vec3 q, geom_bvh_visit fn, void *ctx);

#endif
