/* scene.h - the scene IR: plain records the parser fills and every renderer
 * reads. Nothing here knows about tokens or about Embree. All memory belongs
 * to the scene's arena; pointers between records stay valid for its life.
 *
 * Conventions (POV-Ray's): left-handed world, y up, colours are linear
 * (assumed_gamma 1.0 is the only working space we model; see DESIGN.md).
 *
 * The records by meaning: scene_material.h (colours, pigments, finishes,
 * interiors, media, textures), scene_shape.h (objects), scene_light.h,
 * scene_camera.h, scene_settings.h (global_settings), scene_pattern.h
 * (patterns, maps, atmosphere); this header the scene itself. */
#ifndef PT_SCENE_H
#define PT_SCENE_H
#include <stddef.h>
#include <stdint.h>
#include "arena.h"
#include "diag.h"
#include "scene_camera.h"
#include "scene_light.h"
#include "scene_material.h"
#include "scene_settings.h"
#include "scene_shape.h"

/* ---------------------------------------------------------------- the scene */
typedef struct {
    arena *mem;
    unsigned long serial;   /* unique among this process's scenes, never reused: keys caches of derived data */
    scene_global global;
    scene_camera camera;
    int camera_set;
    colour5 background;     /* default black */
    int nobjects, cap_objects;
    scene_object **objects; /* top-level objects */
    int nlights, cap_lights;
    scene_light *lights;
    scene_texture default_texture;
    int version_major, version_minor; /* from #version; 0 if absent */
    int nfiles;             /* files read (scene + includes) */
    uint64_t input_hash;    /* FNV-1a 64 (hash.h) of every file the parse read, in the order read: the
                               scene, its includes, #read data files, images, height fields and density
                               files, each as its length then its bytes (sdl_hash_input); what the GI
                               cache and a tile's header name the scene by */
    double clock;
    /* the functions whose bodies call a function that is internal(59),
     * f_ridged_mf (its weights come from one call: func_internal.h) */
    int ridged_mf_callers;
    /* atmosphere (scene_pattern.h) */
    const scene_fog *fogs;  /* linked through `next`; NULL = none */
    const scene_sky_sphere *sky_sphere; /* NULL = none */
    const scene_rainbow *rainbows;      /* linked through `next` */
    scene_image *images;    /* every image the scene references (image_map...), to load */
    int natmosphere;        /* atmospheric media { } statements in order */
    const scene_media *const *atmosphere;
} scene;

scene *scene_new(void);
void scene_free(scene *s);
/* Defaults as POV-Ray 3.7 documents them. */
void scene_default_finish(scene_finish *f);
void scene_default_pigment(scene_pigment *p);
void scene_default_camera(scene_camera *c);
void scene_default_light(scene_light *l);
void scene_default_photons(scene_photons *p);
void scene_default_interior(scene_interior *i);
scene_object *scene_new_object(scene *s, shape_kind kind, src_loc loc);
scene_texture *scene_new_texture(scene *s);
scene_mesh *scene_new_mesh(scene *s);
pt_status scene_add_object(scene *s, scene_object *o);
pt_status scene_add_light(scene *s, const scene_light *l);

/* Counting helpers for `partray parse` and stats. */
typedef struct {
    long objects;     /* leaf objects (CSG children counted) */
    long csg;         /* CSG nodes */
    long triangles;   /* triangle + mesh triangles */
    long meshes;
    long lights;
    long unsupported;
} scene_counts;
scene_counts scene_count(const scene *s);

/* Camera ray for pixel position (px, py) in [0,w)x[0,h), pixel centres at .5,
 * every camera type (core/camera.h; where a camera traces no ray, e.g.
 * outside a fisheye's circle, this gives the camera's direction: use
 * camera_ray to know). Direction is normalised. */
void scene_camera_ray(const scene_camera *c, double px, double py, int w, int h, vec3 *org, vec3 *dir);

#endif
