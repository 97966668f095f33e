/* scene_leaves.h - the leaf objects of a scene (CSG members included) in a
 * fixed order, with a lookup from a leaf's pointer (accel_hit.obj) to its
 * index, and hashes of what decides where an object's surfaces are. Two
 * frames of one scene file whose object structure is the same number
 * their leaves alike, so GI kept across frames (reference/pm_detp.h,
 * gi/gi_vlinks.h) refers to surfaces by index. */
#ifndef PT_SCENE_LEAVES_H
#define PT_SCENE_LEAVES_H
#include <stdint.h>
#include "scene.h"

typedef struct scene_leaves scene_leaves;

/* NULL on no memory. */
scene_leaves *scene_leaves_new(const scene *sc);
void scene_leaves_free(scene_leaves *L);
int scene_leaves_count(const scene_leaves *L);
const scene_object *scene_leaves_get(const scene_leaves *L, int i);
/* The top-level object (index into sc->objects) leaf i belongs to. */
int scene_leaves_top(const scene_leaves *L, int i);
/* Index of leaf o; -1 for NULL, -2 for an object that is not a leaf of
 * the scene. Thread-safe. */
int scene_leaves_find(const scene_leaves *L, const scene_object *o);

/* FNV-1a hash (continuing from h) of an object's kind, transform, flags,
 * shape parameters (mesh vertices, triangles and normals; CSG members),
 * clip and bound: equal for an object that did not move or deform. Shapes
 * whose data it does not read (lathe, prism, blob, isosurface, ...) set
 * *opaque. Textures are not read. */
uint64_t scene_object_hash(uint64_t h, const scene_object *o, int *opaque);
/* 1 when every surface of o is finite (lies in the accel's bounds):
 * spheres, boxes, triangles, meshes, cylinders, cones, discs, tori,
 * superellipsoids, ovus and CSG of them. */
int scene_object_finite(const scene_object *o);
int scene_object_is_csg(const scene_object *o);
/* 1 when pred holds for o or for any member of it (CSG members, at any
 * depth). */
int scene_object_any(const scene_object *o, int (*pred)(const scene_object *o));

#endif
