/* geom_mesh.h - a mesh or mesh2 as a geom_shape (kind SHAPE_MESH), in double
 * precision over a BVH of its triangles in object space: the parser's
 * trace() and inside() and CSG trees built with geom_csg_builder.meshes.
 * The renderer draws meshes with Embree's triangles instead (accel.c), so
 * geom_shape_init leaves meshes out; geom_shape_init_mesh takes them.
 *
 * Hits report the triangle index as their part. The surface normal is
 * POV-Ray's own (what its trace() reports): the triangle's
 * (P3 - P1) x (P2 - P1), or the interpolated normal where the mesh has
 * normals, not oriented. A mesh has an inside only with inside_vector
 * (POV-Ray's rule: an odd number of crossings along it). */
#ifndef PT_GEOM_MESH_H
#define PT_GEOM_MESH_H
#include "geom_shape.h"

/* The mesh part of sh (geom_shape_init_mesh calls it: data, olo, ohi): 0,
 * or -1 when the mesh is empty, has bad indices or memory ran out. */
int geom_mesh_init(geom_shape *sh, const scene_object *o);
void geom_mesh_free(void *data);
/* Object-space ray; crossings with t in (tmin, tmax), ascending. */
int geom_mesh_hits(const geom_shape *sh, vec3 o, vec3 d, double tmin, double tmax, geom_shape_hit *out, int max);
int geom_mesh_inside(const geom_shape *sh, vec3 q);
/* Object-space normal of triangle `part` at object-space point q. */
vec3 geom_mesh_normal(const geom_shape *sh, vec3 q, int part);
/* The point of triangle (a, b, c) closest to q, as barycentrics w (wa, wb,
 * wc; a degenerate triangle gives vertex a); returns its squared distance
 * from q. */
double geom_tri_closest(vec3 q, vec3 a, vec3 b, vec3 c, double w[3]);

#endif
