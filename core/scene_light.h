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
    int adaptive;           /* adaptive level (default 100: the whole grid) */
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
    /* photons { reflection on|off refraction on|off area_light } (POV-Ray
     * 3.7): on/off flags as the object's (scene_obj_photons); area_light:
     * photons leave every point of the area grid, not only the centre */
    int ph_reflection, ph_reflection_off, ph_refraction, ph_refraction_off;
    int ph_area_light;
} scene_light;

/* POV-Ray 3.7's photon rules for light l and a target's block o (NULL:
 * none), photons.cpp and photonshootingtask.cpp:
 *  - scene_photon_shoots: whether l shoots photons at target o at all: the
 *    light's and target's flags merged, some lobe on and not off; never a
 *    `shadowless` light nor one in a light_group (photonstrategytask.cpp
 *    walks the scene's global lights and skips FILL_LIGHT_SOURCE, the type
 *    `shadowless` sets: reswords.cpp, parse.cpp; its light_group loop is
 *    left out there);
 *  - scene_photon_lobe: whether a photon of l is reflected (refract 0) or
 *    refracted (1) where it hits an object with block o: the object says
 *    on and the light not off, or the light says on and the object not off. */
static inline int scene_photon_shoots(const scene_light *l, const scene_obj_photons *o)
{
    if (!o || !o->target || l->shadowless || l->group) return 0;
    int rfr_on = l->ph_refraction || o->refraction, rfr_off = l->ph_refraction_off || o->refraction_off;
    int rfl_on = l->ph_reflection || o->reflection, rfl_off = l->ph_reflection_off || o->reflection_off;
    return (rfr_on && !rfr_off) || (rfl_on && !rfl_off);
}
static inline int scene_photon_lobe(const scene_light *l, const scene_obj_photons *o, int refract)
{
    int o_on = o ? (refract ? o->refraction : o->reflection) : 0;
    int o_off = o ? (refract ? o->refraction_off : o->reflection_off) : 0;
    int l_on = refract ? l->ph_refraction : l->ph_reflection;
    int l_off = refract ? l->ph_refraction_off : l->ph_reflection_off;
    return (o_on && !l_off) || (!o_off && l_on);
}

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
