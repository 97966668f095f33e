/* sdl_geom.h - parse-time geometry for trace(), inside(), min_extent() and
 * max_extent(), evaluated on the IR objects built so far (the parser does
 * not depend on accel/).
 *
 * Exact (closed-form, double precision): sphere, box, plane, triangle,
 * smooth_triangle, mesh/mesh2 (a BVH per mesh, built on first use), cylinder,
 * cone, disc, quadric, and union/merge/intersection/difference of them with
 * POV-Ray's CSG rules (a hit of one member counts if it is inside every other
 * member of an intersection, outside every other member of a merge) and
 * clipped_by. Torus and superellipsoid hits are found by marching the ray
 * (steps of minor radius/16, resp. 1/64 of the box) and bisection: exact to
 * 1e-12 except for grazing rays that touch without crossing; lathe, prism,
 * blob and isosurface are marched the same way. sor, poly (cubic, quartic,
 * polynomial), text, julia_fractal, polygon and height_field are asked of the
 * renderer's intersector through sdl_options.geom_env (accel_query.h: the
 * code that renders them); without it, and for shapes the IR cannot draw,
 * trace/inside give a located PT_ERR_UNSUPPORTED error. sphere_sweep and
 * bicubic_patch are unions of spheres and cones, resp. meshes, in the IR.
 *
 * Extents follow POV-Ray 3.7's bounding boxes: the shape's box in its own
 * space, transformed corner by corner (spheres moved only by translation,
 * rotation and uniform scale stay tight, as in POV-Ray); cylinders, cones and
 * discs use POV-Ray's alignment frame; planes and other unbounded shapes give
 * +-1e10; an intersection is the overlap of its non-inverted members' boxes
 * (axis-aligned planes cut it); boxes longer than 1e6 become +-1e10. */
#ifndef PT_SDL_GEOM_H
#define PT_SDL_GEOM_H
#include "sdl_parse.h"

/* trace '(' object ',' start ',' direction [ ',' vector_identifier ] ')' :
 * the nearest hit (<0,0,0> if none); the identifier receives the normal. */
vec3 sdl_trace_fn(sdl_parser *p, src_loc loc);
/* inside '(' object ',' point ')' : 1 or 0 */
double sdl_inside_fn(sdl_parser *p, src_loc loc);
/* min_extent / max_extent '(' object ')' */
vec3 sdl_extent_fn(sdl_parser *p, src_loc loc, int max);
/* Release the BVHs built during the parse (called when the parse ends). */
void sdl_geom_free(sdl_parser *p);

#endif
