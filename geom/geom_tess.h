/* geom_tess.h - what GI needs (DESIGN.md) from shapes known only through
 * their inside test and exact ray crossings (geom_shape_inside,
 * geom_shape_hits): quadric, poly, blob, isosurface, julia_fractal,
 * superellipsoid, ovus, and any shape under a transform the shape's own
 * parametrisation cannot sample uniformly.
 *
 * - geom_tess_grid: a parametric grid for radiance particles, as
 *   geom_shape_grid: object-space triangles whose vertices lie on the exact
 *   surface (crossings of lattice edges found by the shape's ray query), with
 *   the exact unit outward object-space normals there; n lattice cells along
 *   the longest side of the shape's bounds. Unbounded shapes (quadric, poly)
 *   are gridded inside their clip box (geom_shape_clip_plane: GI clips them
 *   to the scene's finite extent, as planes).
 * - geom_tess_sampler: points uniform by world area, exactly in
 *   distribution (Crofton: uniform random lines through a ball holding the
 *   surface, one crossing taken with probability 1 / kmax), and the world
 *   area from the same lines (quasi-Monte Carlo, to a requested standard
 *   error). Optional `keep` filter (world point -> 0/1): only crossings it
 *   keeps count, which samples a clipped part of a surface just as exactly. */
#ifndef PT_GEOM_TESS_H
#define PT_GEOM_TESS_H
#include "geom_shape.h"
#include "rng.h"

int geom_tess_grid(const geom_shape *sh, int n, geom_grid_fn fn, void *ctx);

typedef int (*geom_tess_keep_fn)(void *ctx, vec3 world_p);

typedef struct {
    const geom_shape *sh;  /* not owned; must outlive the sampler */
    geom_tess_keep_fn keep;
    void *keep_ctx;
    vec3 c;                 /* ball holding the surface (world) */
    double R;
    int kmax;               /* most crossings seen on one line */
    double area;            /* world area estimate */
} geom_tess_sampler;

/* Estimate the area with quasi-random lines, in batches of 1024 until the
 * standard error of the batch means is below rel_err (relative) or
 * max_lines were cast. Returns the area (0: no surface found). With
 * threads > 1 the batches are counted on that many threads (keep must then
 * be safe to call from several); the estimate is the same for any count. */
double geom_tess_sampler_init(geom_tess_sampler *cs, const geom_shape *sh, geom_tess_keep_fn keep,
                               void *keep_ctx, double rel_err, int max_lines, int threads);
/* A world point uniform by area with its unit outward world normal and the
 * part (as geom_shape_hit.part). (u1, u2) choose the first line's direction;
 * r supplies the rest (NULL: a generator seeded from u1, u2). 0 on failure. */
int geom_tess_sample(const geom_tess_sampler *cs, double u1, double u2, rng *r, vec3 *p, vec3 *n,
                      unsigned *part);

#endif
