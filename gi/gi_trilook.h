/* gi_trilook.h - the link builder's nearest-particle lookup driven by the
 * hit triangle (Embree's geomID, primID, u, v) instead of a 3D grid.
 *
 * Every world-space triangle of the accel (Embree triangle geometry, not
 * instances) is cut into k x k cells of its (u, v) parameter square (k so
 * that a cell's edge is at most one particle spacing; the cells on the
 * diagonal are triangles). For each cell C and side s (particles whose
 * normal agrees with +N or -N, N the triangle's normal) the list (particle
 * indices; the positions and normals live in one packed array) holds
 * every particle of the triangle's object on that side whose distance to C
 * is at most R + delta, where R = min over the side's particles c of
 * max over C's corners of |corner - c| (capped at maxdist): for any point
 * of C one particle lies within R. A query scans only its cell's list with
 * gi_lookup's ray filters (same float arithmetic), and its answer W is
 * exact when |q - W| <= R (every particle outside the list is farther than
 * R from every point of C) and W is not "uncertain" (buried in a closed
 * solid, or with a normal within 1e-3 of gi_links' agreement threshold,
 * whose membership the grid path decides with its own arithmetic).
 * Otherwise the caller takes the grid path, as for the sides of a triangle
 * with no such particle near it. Internal to gi/. */
#ifndef PT_GI_TRILOOK_H
#define PT_GI_TRILOOK_H
#include <stddef.h>
#include "accel.h"
#include "gi_area_particles.h"
#include "kernels/gi_types.h"

typedef struct gi_trilook gi_trilook;

/* (cancel non-zero: NULL with *st PT_CANCELLED) p: n particles; pobj: the object of each (as accel_rtc_object gives it
 * for a hit on it); grid: the same particles' lookup, its object ids set
 * from pobj (gi_lookup_set_objects); buried (may be NULL): n flags,
 * particles buried in a closed solid; agree: gi_links' threshold on n . N
 * (0.3); maxdist: the lookup radius. NULL with *st set on failure (PT_OK
 * and NULL when no triangle carries particles). */
gi_trilook *gi_trilook_build(const accel *a, const gi_dev_particle *p, int n, const void *const *pobj,
                             const gi_lookup *grid, const unsigned char *buried, double spacing, double agree,
                             double maxdist, int threads, volatile int *cancel, pt_status *st);
/* The particles were renumbered: remap[i] is particle i's new index, -1
 * when it was dropped (indices keep their order); p: the n kept ones. */
void gi_trilook_compact(gi_trilook *t, const int *remap, const gi_dev_particle *p, int n);
void gi_trilook_free(gi_trilook *t);
size_t gi_trilook_bytes(const gi_trilook *t);
long gi_trilook_entries(const gi_trilook *t);
long gi_trilook_cells(const gi_trilook *t);

/* The list of a hit on triangle (geom, prim) at Embree's (u, v) by a ray
 * along dir, or -1 when the hit is not covered (not a listed triangle, or
 * a grazing ray whose side is unsure). */
long gi_trilook_cell(const gi_trilook *t, unsigned geom, unsigned prim, float u, float v, const float dir[3]);
/* Prefetch a list in stages, each after the previous one for a whole
 * batch: 0 its offset, 1 its first entries, 2 its particles. */
void gi_trilook_prefetch(const gi_trilook *t, long cell, int stage);
/* The nearest particle to hit point q (the ray from org along dir) on the
 * hit object and side, within maxdist, with gi_grid_nearest's rules:
 * >= 0 the particle, -1 none, -2 not decided here (take the grid path). */
int gi_trilook_nearest(const gi_trilook *t, long cell, const float q[3], const float dir[3], const float org[3]);

/* The answer at each list's cell centre (gi_trilook_nearest's for a ray
 * along the side's normal onto the centre): made once by
 * gi_trilook_centres (0: out of memory; undone by gi_trilook_compact);
 * gi_trilook_centre_table then gives them by list (gi_trilook_cell's
 * index), >= 0 a particle, -2 none decided (take gi_trilook_nearest), and
 * NULL before they are made. */
int gi_trilook_centres(gi_trilook *t, int threads);
const int *gi_trilook_centre_table(const gi_trilook *t);

#endif
