/* geom_extent.h - POV-Ray 3.7's bounding box of an IR object, what its
 * min_extent() and max_extent() report (the parser's built-ins).
 *
 * The shape's box in its own space, transformed corner by corner (spheres
 * moved only by translation, rotation and uniform scale stay tight, as in
 * POV-Ray); cylinders, cones and discs use POV-Ray's alignment frame;
 * planes and other unbounded shapes give +-1e10; an intersection is the
 * overlap of its non-inverted members' boxes (axis-aligned planes cut it);
 * boxes longer than 1e6 become +-1e10. These are POV-Ray's boxes, not the
 * tighter ones geom_shape_init computes for ray queries. */
#ifndef PT_GEOM_EXTENT_H
#define PT_GEOM_EXTENT_H
#include "scene.h"

/* 0 and the box in *lo, *hi; -1 when o holds a shape without a box, named
 * in *what. */
int geom_extent(const scene_object *o, vec3 *lo, vec3 *hi, const char **what);

#endif
