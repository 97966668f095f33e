/* geom_hfield.h - POV-Ray height_field intersected exactly as its
 * triangles, in double precision, by a front-to-back walk of a min/max
 * quadtree over the grid cells (each node: the cells it covers and their
 * height range).
 *
 * Geometry (POV-Ray's heightfield.cpp): heights h[z][x] over the unit
 * square, grid point (i, j) at x = i / (W-1), z = j / (H-1); each cell is
 * split along the diagonal from (i+1, j) to (i, j+1) into the triangles
 * (i,j) (i+1,j) (i,j+1) and (i+1,j+1) (i,j+1) (i+1,j); heights below
 * water_level are raised to it. Only the top surface exists (no walls); a
 * point is inside when it lies over the square and below the surface.
 * `smooth` interpolates vertex normals (central differences of the grid)
 * for shading. Part = 2 * cell + triangle. */
#ifndef PT_GEOM_HFIELD_H
#define PT_GEOM_HFIELD_H
#include "geom_shape.h"

/* geom_hfield_init, _free, _hits, _inside (geom_shape.h) */
GEOM_FAMILY(hfield)
/* Object-space geometric normal of the triangle `part` and (u, v) = (x, z). */
void geom_hfield_surface(const geom_shape *sh, vec3 q, int part, vec3 *n, double *u, double *v);
/* Object-space smooth shading normal at q (0 when the field is not smooth). */
vec3 geom_hfield_shading(const geom_shape *sh, vec3 q);

/* Triangle count (2 per cell) and triangle `part` in object space. */
int geom_hfield_ntriangles(const geom_shape *sh);
void geom_hfield_triangle(const geom_shape *sh, int part, vec3 *a, vec3 *b, vec3 *c);

/* Cells along x and z (0 when the field has no data). */
void geom_hfield_cells(const geom_shape *sh, int *nx, int *nz);
/* A coarser grid for GI's radiance particles (gi_surface): the grid points
 * every sx-th along x and sz-th along z (and the last ones), split along
 * the same diagonal as the cells; vertices on the exact surface, object
 * normals from central differences over the coarse neighbours. Strides 1
 * give the field's own triangles. Calls fn per triangle; returns their
 * number, -1 when fn returned 0. */
int geom_hfield_coarse_grid(const geom_shape *sh, int sx, int sz, geom_grid_fn fn, void *ctx);

#endif
