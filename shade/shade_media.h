/* shade_media.h - participating media as POV-Ray 3.7 renders them
 * (interior media of the objects a ray is inside, atmospheric media of the
 * scene), and the bookkeeping of which objects a ray is inside.
 *
 * A ray keeps the list of containers it is inside (POV-Ray's interior list):
 * a transmitted ray toggles the object it crosses, a reflected ray keeps the
 * list. A ray is "hollow" while every container is `hollow`: only then do
 * interior media, atmospheric media and fog act on it (POV-Ray 3.7).
 *
 * shade_media_segment applies the media on one ray segment (origin to the next
 * surface) to the colour seen at its end: colour * exp(-optical depth) +
 * the light emitted and in-scattered along the segment, sampled with the
 * media's method (3: POV-Ray's adaptive sampling; 1 and 2: stratified
 * Monte Carlo samples). Shadow rays get the extinction only. */
#ifndef PT_SHADE_MEDIA_H
#define PT_SHADE_MEDIA_H
#include "accel.h"
#include "rng.h"
#include "scene.h"

#define SHADE_MEDIA_MAX_INSIDE 16

typedef struct {
    int n;
    const scene_object *obj[SHADE_MEDIA_MAX_INSIDE]; /* leaf objects (their interior, their transform) */
} shade_media_inside;

/* Any media in the scene (interior or atmospheric)? */
int shade_media_scene_has(const scene *sc);
/* Whether some media of sc (an object's interior or the atmosphere) can
 * dim light: absorption or scattering above 0 in some channel. Without,
 * a shadow ray crosses every media unchanged (POV-Ray's shadow rays take
 * their media's extinction only, never their emission). */
int shade_media_scene_attenuates(const scene *sc);
/* Is the ray hollow (every container hollow)? */
int shade_media_inside_hollow(const shade_media_inside *in);
/* Do the containers hold any media? */
int shade_media_inside_has_media(const shade_media_inside *in);
/* Where o's interior is in the list (0 = outermost), -1 if the ray is not
 * inside it. */
int shade_media_inside_find(const shade_media_inside *in, const scene_object *o);
/* The ray crosses object o's surface: leave it if inside, else enter it. */
void shade_media_inside_cross(shade_media_inside *in, const scene_object *o);
/* The objects holding point p (the camera's location), POV-Ray's
 * containing interiors (tracepixel.cpp's InitRayContainerState): every
 * object, hollow or not, as each has an interior there. */
void shade_media_inside_at(const scene *sc, vec3 p, shade_media_inside *in);

/* Light of l reaching p (attenuated, shadowed, filtered) and the unit
 * direction from p towards it; 0 when none. `in` = the sampled ray's
 * containers (the shadow ray starts inside them). collect: the sample's
 * media take photons (some has `collect` on): then, where a caustic layer
 * carries l's photons, a photon target that refracts them casts a full
 * shadow (POV-Ray 3.7's trace.cpp, ComputeShadowColour, whose
 * litObjectIgnoresPhotons media.cpp sets from the media's ignore_photons:
 * the light through the target arrives as media photons). */
typedef rgb (*shade_media_light_fn)(void *ctx, int thread, const scene_light *l, vec3 p, const shade_media_inside *in,
                                    int collect, vec3 *to_light);
/* Media photons (a caustic layer's): each photon around p as a light of
 * colour `light` arriving from the unit direction to_light, already over
 * the gather volume (gi/gi_caustic.h, gi_caustic_media_visit). */
typedef void (*shade_media_photon_fn)(void *ctx, vec3 to_light, rgb light);
typedef void (*shade_media_photons_fn)(void *ctx, vec3 p, shade_media_photon_fn each, void *each_ctx);

typedef struct {
    const scene *sc;
    void *ctx;
    int thread;
    rng *r;
    shade_media_light_fn light;   /* scattering's light (NULL: no in-scattering) */
    const scene_object *hit; /* the surface ending the segment (its light group), NULL = none */
    /* media photons: every sample of a view ray's scattering media adds
     * the photons around it, through its scattering and phase function as
     * lights, lit interval or not (POV-Ray's media.cpp, ComputeOneMediaSample
     * and ComputeMediaPhotons). NULL: none. */
    shade_media_photons_fn photons;
    void *photons_ctx;
} shade_media_env;

enum { SHADE_MEDIA_INTERIOR = 0, SHADE_MEDIA_ATMOSPHERE = 1 };

/* Colour c seen at distance depth along org + t dir (unit dir) after the
 * interior media of the containers `in` (which = SHADE_MEDIA_INTERIOR) or the
 * scene's atmosphere (SHADE_MEDIA_ATMOSPHERE). shadow: extinction only (a shadow
 * ray). The caller checks hollowness. */
rgb shade_media_segment(const shade_media_env *e, int which, const shade_media_inside *in, vec3 org, vec3 dir, double depth, rgb c,
                  int shadow);

/* Light left along a shadow ray from p (unit dir, over (tmin, tmax)) for
 * light l, starting inside `in`, as POV-Ray's TraceShadowRay with media:
 * at each surface crossed the filter colour (shade_tex_shadow_filter), the
 * interior media of the containers over the segment before it (a hollow
 * ray) and, for a light with media_interaction and media_attenuation, the
 * atmospheric media (and fog on hollow segments); after the last surface
 * the atmosphere and fog alone. no_shadow objects are passed through.
 * rest non-NULL: that last part is left out and *rest is its length (tmax
 * less the last surface crossed), for an area light's samples
 * (shade_media_shadow_rest). */
/* photon_light: NULL, or l where a caustic layer carries its photons and
 * the lit surface or media take them: a photon target that refracts them
 * casts a full shadow (shade_tex_shadow_ray's rule). */
rgb shade_media_shadow_ray(const scene *sc, const accel *a, const shade_media_env *e, const scene_light *l, vec3 p, vec3 dir,
                           double tmin, double tmax, const shade_media_inside *in, double *rest,
                           const scene_light *photon_light);
/* c after the atmosphere and fog over len along p + t dir, for light l
 * with media_interaction and media_attenuation, on a hollow ray starting
 * inside `in` (else c unchanged): the last part of a shadow ray. POV-Ray
 * 3.7 (trace.cpp, TraceShadowRay) adds it once after an area light's
 * samples are averaged, from the shaded point itself over what the last
 * sample traced left of its way after its last transparent surface: so
 * fog near the ground dims an area light twice where that sample crossed a
 * transparent object (benchmark.pov's cloud shell), once otherwise. */
rgb shade_media_shadow_rest(const scene *sc, const shade_media_env *e, const scene_light *l, const shade_media_inside *in,
                            vec3 p, vec3 dir, double len, rgb c);

#endif
