/* scene_light.h - the scene IR's light sources (scene.h). */
#ifndef PT_SCENE_LIGHT_H
#define PT_SCENE_LIGHT_H
#include "rng.h"
#include "scene_shape.h"

/* ---------------------------------------------------------------- lights */
typedef enum { LIGHT_POINT, LIGHT_SPOT, LIGHT_CYLINDER, LIGHT_PARALLEL } light_kind;

typedef struct {
    light_kind kind;
    src_loc loc;
    vec3 position;
    rgb colour;
    vec3 point_at;          /* spot, cylinder, parallel; default <0,0,1> */
    double radius, falloff, tightness; /* degrees for spot; defaults 30, 45, 0 (3.7 docs) */
    int parallel;           /* `parallel` keyword on a point/spot light */
    /* area light */
    int area;
    vec3 axis1, axis2;
    int size1, size2;
    int adaptive;           /* adaptive level, -1 if not given */
    int jitter, circular, orient;
    int area_illumination;
    /* attenuation */
    double fade_distance;   /* 0 = no fading */
    double fade_power;
    int shadowless;
    int media_interaction, media_attenuation;
    const scene_object *looks_like;
    const scene_object *projected_through; /* light only through it (shade_project.c) */
    int group;              /* light_group id (lights only its objects), 0 = global */
} scene_light;

/* Whether light l lights object o (POV-Ray 3.7's light groups: a group's
 * lights light only its objects; global lights light everything else, and
 * a group's objects only with global_lights on). */
static inline int scene_light_reaches(const scene_light *l, const scene_object *o)
{
    if (!o) return l->group == 0;
    return l->group ? o->light_group == l->group : !o->no_global_lights;
}

/* Offset of grid point (u, v) of area light l from its position (POV-Ray's
 * layout: points span -axis/2 .. +axis/2, an axis with size 1 contributes
 * nothing; `jitter` moves each by up to half a cell; `circular` maps the
 * square onto a disc). Uses r only when the light jitters. The Whitted
 * pass's area lights (shade_light.c) and the particle GI's (gi_particle_light.c). */
vec3 scene_light_area_point(const scene_light *l, vec3 ax1, vec3 ax2, int u, int v, rng *r);

/* The axes of an `orient` area light l seen along unit dir (from the lit
 * point towards the light): axis1's length on both, turned to face dir
 * (POV-Ray's rule). */
void scene_light_orient_axes(const scene_light *l, vec3 dir, vec3 *ax1, vec3 *ax2);

#endif
