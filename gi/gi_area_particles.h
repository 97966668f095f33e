/* gi_area_particles.h - area particles (paper section 3.1): samples distributed
 * uniformly by area over every surface patch, each standing for the same
 * area dA = A/N when sampled (gi_particle.c then sets each one's area to its
 * catchment, catchment_areas), with normal, diffuse reflectance and emission; and a
 * hashed uniform grid over them for the nearest-particle lookups of the link
 * builder and the radius queries of the estimation lists. Internal to gi/. */
#ifndef PT_GI_AREA_PARTICLES_H
#define PT_GI_AREA_PARTICLES_H
#include <stdint.h>
#include "accel.h"
#include "gi_particle.h"
#include "gi_surface.h"
#include "kernels/gi_types.h"

typedef struct {
    int n;
    gi_dev_particle *p; /* n records (device layout) */
    int *patch;         /* patch of each particle */
    unsigned char *side;
    double dA;          /* area per particle */
    double spacing;     /* sqrt(dA): typical distance between neighbours */
    long probed_out;    /* candidates a CSG probe removed */
} gi_particles;

/* Candidates: about `count` particles over every side of every patch,
 * uniformly by area (dA = A/count, A the summed area of the sides),
 * stratified per patch (low-discrepancy R2 points, Roberts 2018, with a
 * random shift per patch); both sides of a two-sided patch share positions.
 * side_frac (2 per patch, may be NULL = all 1) is the expected fraction of
 * each side's particles that will be kept (from a pilot run): the density
 * is set so that about `count` are kept, and sides of fraction 0 get none.
 * Materials:
 * rho = diffuse * pigment * opacity, le = pigment * E * opacity with E
 * POV-Ray's emission under radiosity (core/radrules.h), as shade.c's terms; the
 * pigment is `pig`'s at the particle (patterns, image maps, texture maps),
 * or with pig NULL the texture's base colour. */
pt_status gi_particles_sample(gi_particles *ps, const gi_surface *g, const accel *a, const scene *sc, long count,
                              uint64_t seed, const float *side_frac, gi_pigment_fn pig, diag *d);
/* The particle of the other side at particle i's point (its twin), -1
 * none (a one-sided surface, or that side was not sampled or was pruned). */
int gi_particles_twin(const gi_particles *ps, int i);
/* Every particle's twin field: gi_particles_twin for those with a
 * diffuse_back lobe (back > 0), -1 for the others (gi_types.h). */
void gi_particles_set_twins(gi_particles *ps);
/* Keep the particles with keep[i] != 0, in order. */
pt_status gi_particles_compact(gi_particles *ps, const unsigned char *keep);
void gi_particles_free(gi_particles *ps);

typedef struct gi_grid gi_grid;
/* Spatial hash of the particles (Teschner et al., "Optimized Spatial Hashing
 * for Collision Detection of Deformable Objects", VMV 2003) with the given
 * cell size; colliding cells share a bucket, which costs only extra distance
 * tests. */
gi_grid *gi_grid_build(const gi_dev_particle *p, int n, double cell);
void gi_grid_free(gi_grid *g);
/* Nearest particle to q, within maxdist, on the side a ray from org along
 * dir arrives at: its normal faces against dir (n.dir < 0) and org lies in
 * front of it (n.(org - p) > 0; this keeps a ray that hits near its own
 * start, in a corner, from linking to the back side of its own surface),
 * and q lies near its tangent plane (|n.(p - q)| <= |p - q| / 2).
 * -1 if none. */
int gi_grid_nearest(const gi_grid *g, vec3 q, vec3 dir, vec3 org, double maxdist);
/* Particles within r of q with n.nq > cos_thr, in increasing index order,
 * appended to *out (grown with realloc); returns how many, -1 on OOM. */
long gi_grid_radius(const gi_grid *g, vec3 q, vec3 nq, double r, double cos_thr, int **out, long *len, long *cap);

/* Nearest-particle lookup for the link builder: a dense grid of `cell`-wide
 * cells (grown when the box would need more than 8 cells per particle),
 * each particle stored once in its cell (16 bytes); a query reads the
 * 2x2x2 cells around it, which hold every particle within cell/2; answers
 * farther than cell/2 come from the 4x4x4 cells around it (within 1.5
 * cells), farther ones from a ring search in a hashed grid. */
typedef struct gi_lookup gi_lookup;
gi_lookup *gi_lookup_build(const gi_particles *ps, double cell);
void gi_lookup_free(gi_lookup *g);
/* Queries run in steps, for batches: a batch first computes every query's
 * block (gi_lookup_cell), prefetches stage 0 (the block's list heads) for
 * all, then stage 1 (the lists), then queries (gi_lookup_nearest_in2). */
long gi_lookup_cell(const gi_lookup *g, vec3 q);
/* The same first steps for a batch of n queries in one call: cell[i] =
 * gi_lookup_cell(g, q[i]) for every i with cell[i] >= -1 on entry (others
 * are left alone), then both prefetch stages. */
void gi_lookup_cells(const gi_lookup *g, int n, const vec3 *q, long *cell);
/* Object ids for the answers (pobj: the object of each particle). */
pt_status gi_lookup_set_objects(gi_lookup *g, const void *const *pobj);
/* Whether q lies in the box the particles stand in (within a cell): a
 * hit outside it is in the far field (gi_links.c). */
int gi_lookup_covers(const gi_lookup *g, vec3 q);
/* The id of an object (-1: no particle of the lookup lies on it). */
int gi_lookup_object_id(const gi_lookup *g, const void *obj);
/* Nearest particle to q by gi_grid_nearest's rules, from q's block `cell`;
 * also the answer's normal and object id (nrm, obj may be NULL), read from
 * the lookup's own copy; *obj = -2 when they are not known (the answer
 * came from the ring search, or none). */
int gi_lookup_nearest_in2(const gi_lookup *g, long cell, vec3 q, vec3 dir, vec3 org, double maxdist, float nrm[3],
                          int *obj);
/* Nearest particle to q by gi_grid_nearest's rules among the particles i
 * with pobj[i] == obj only (pobj NULL: all) whose normal n has n.agree >=
 * min_agree (agree = 0: any normal) and skip[i] == 0 (skip may be NULL): a
 * ring search, the slow path for answers on the wrong object or side. */
int gi_lookup_nearest_on(const gi_lookup *g, vec3 q, vec3 dir, vec3 org, double maxdist, const void *const *pobj,
                         const void *obj, vec3 agree, double min_agree, const unsigned char *skip);

/* A particle's reflectance and emitted radiance for texture tex (NULL:
 * sc's default) with pigment colour c (NULL: the texture's base colour),
 * as gi_particles_sample gives them. */
void gi_particles_material(const scene *sc, const scene_texture *tex, const colour5 *c, float rho[3], float le[3]);

#endif
