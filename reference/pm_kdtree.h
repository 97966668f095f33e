/* pm_kdtree.h - photons and a balanced kd-tree over them (Jensen 2001,
 * "Realistic Image Synthesis Using Photon Maps", ch. 6: median splits on
 * the axis of largest extent; here stored implicitly: the node of a range
 * [lo, hi) is its middle element), built in parallel, with k-nearest and
 * nearest queries restricted to photons on a compatible surface side. */
#ifndef PT_PM_KDTREE_H
#define PT_PM_KDTREE_H
#include <stdint.h>
#include "scene.h"
#include "vec.h"

/* A stored photon (32 bytes): position, power (flux, RGB), the unit
 * normal of the surface it hit, turned towards the side it arrived from
 * (quantised to int8), and the surface key of that side (pm_surface_key).
 * The same record holds precomputed irradiance points (power = irradiance). */
typedef struct {
    float p[3];
    float power[3];
    signed char n[3];
    unsigned char axis;   /* split axis of the node (kd-tree internal) */
    uint32_t surf;        /* pm_surface_key of the object and side it was stored on */
} pm_photon;

/* Key of one side of one object: a hash of the leaf object (never 0) with
 * its low bit = `outside` (the photon or query ray arrives at the side the
 * geometric normal points to). Density estimates use only photons of the
 * query's own key: a photon on the inside of a closed sphere or box, or on
 * the other side of a thin wall, or on another object touching the surface
 * (a box standing on the floor: its inner bottom face lies in the floor's
 * plane, normals alike) is never counted outside it, whatever the search
 * radius. The price: near the border between two different objects that
 * continue one another (coplanar tiles) the estimate sees only its own
 * side's photons, the boundary bias every photon map has at a surface's
 * edge. */
uint32_t pm_surface_key(const void *object, int outside);

void pm_photon_set(pm_photon *ph, vec3 p, rgb power, vec3 n, uint32_t surf);
vec3 pm_photon_pos(const pm_photon *ph);
vec3 pm_photon_normal(const pm_photon *ph);

typedef struct pm_kdtree pm_kdtree;

/* Build over `n` photons; takes ownership of `ph` (malloc'd; reordered in
 * place). Deterministic for any thread count. NULL on out-of-memory. */
pm_kdtree *pm_kdtree_build(pm_photon *ph, long n, int threads);
void pm_kdtree_free(pm_kdtree *t);
long pm_kdtree_size(const pm_kdtree *t);
const pm_photon *pm_kdtree_photons(const pm_kdtree *t);

typedef struct {
    long idx;
    float d2;
} pm_neighbour;

/* The up to k nearest photons to p within squared radius max_r2 whose
 * normal n_ph satisfies dot(n_ph, n) >= min_dot (pass min_dot = -2 for no
 * filter) and whose key equals surf (surf = 0: any key). `out` has room for
 * k; returns the number found, as a max-heap on d2 (out[0] is the farthest). */
int pm_kdtree_knn(const pm_kdtree *t, vec3 p, vec3 n, uint32_t surf, double min_dot, int k, double max_r2,
                  pm_neighbour *out);

#endif
