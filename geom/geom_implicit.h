/* geom_implicit.h - shapes given by a function f(p) whose sign is the
 * inside test, intersected in double precision in object space:
 *   superellipsoid  ((|x|^(2/e) + |y|^(2/e))^(e/n) + |z|^(2/n))^(n/2) - 1
 *                   (POV-Ray's function raised to the power n/2, which
 *                   keeps its zero set and sign and makes it homogeneous of
 *                   degree 1, so its slope along a ray is O(1))
 *   quadric         A x2 + B y2 + C z2 + D xy + E xz + F yz + G x + H y + I z + J
 *   poly            sum of the POV-Ray terms (orders 2..35)
 *   blob            threshold - sum of strength (1 - (d/r)^2)^2 over the
 *                   components within reach (d: distance to a sphere's
 *                   centre or a cylinder's axis segment, in the component's
 *                   own space)
 *   isosurface      function(x, y, z) - threshold (core/func.h), inside its
 *                   container; marched with steps bounded by max_gradient
 *                   (POV-Ray's rule), sign changes bisected to rounding; the
 *                   container's surface shows where it is inside (not `open`)
 * Quadric, poly and blob are polynomials along a ray (degree 2, order, and 4
 * between consecutive component boundaries), solved with geom_poly
 * (`sturm` honoured); the superellipsoid is convex for e, n <= 2, where its
 * two crossings are bracketed around the minimum along the ray, and sampled
 * finely otherwise. Inside means f < 0. */
#ifndef PT_GEOM_IMPLICIT_H
#define PT_GEOM_IMPLICIT_H
#include "geom_shape.h"

/* Set up sh from o (kinds SHAPE_SUPERELLIPSOID, QUADRIC, POLY, BLOB, ISOSURFACE);
 * object-space bounds in lo/hi, infinite components for unbounded
 * surfaces. May allocate sh->data. -1 when degenerate. */
int geom_implicit_init(geom_shape *sh, const scene_object *o, vec3 *lo, vec3 *hi);
void geom_implicit_free(void *data);
/* Object-space ray o + t d, crossings with t in (tmin, tmax), ascending;
 * `traced`: under POV-Ray's per-ray limits (an isosurface's max_trace) and
 * `rule` (geom_ray_rule), else all of them at their roots. wl: the length
 * of the world ray's direction (what one unit of t is in world length). */
int geom_implicit_hits(const geom_shape *sh, vec3 o, vec3 d, double wl, double tmin, double tmax,
                        geom_shape_hit *out, int max, int traced, geom_ray_rule rule);
int geom_implicit_inside(const geom_shape *sh, vec3 q);
/* Object-space gradient (outward normal, not unit); part 1 of an
 * isosurface is its container's surface. */
vec3 geom_implicit_normal(const geom_shape *sh, vec3 q, int part);
/* 1 when the inside is bounded by the shape's own box. */
int geom_implicit_solid_bounded(const geom_shape *sh);
/* Quadric: the box of its inside (f < 0) within the box [clo, chi]
 * (components may be infinite), in world coordinates, or with `local` in
 * the quadric's own object space, when the quadric has no mixed terms in
 * those coordinates; padded outwards. 1 with the box, 0 when it cannot say
 * (mixed terms, another shape, or no inside found within the box). POV-Ray
 * bounds a quadric inside a CSG intersection by the other members' box
 * the same way (csg.cpp CSG::Compute_BBox, quadric.cpp Compute_BBox). */
int geom_quadric_solid_box(const geom_shape *sh, int local, vec3 clo, vec3 chi, vec3 *lo, vec3 *hi);
/* Blob: the texture of the component contributing most at q (object
 * space), NULL when the blob's own texture applies. */
const scene_texture *geom_blob_texture(const geom_shape *sh, vec3 q);

/* Grid triangles (geom_shape_grid) of a superellipsoid; 0 for the others. */
int geom_implicit_grid(const geom_shape *sh, int n, geom_grid_fn fn, void *ctx);

#endif
