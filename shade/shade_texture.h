/* shade_texture.h - POV-Ray 3.7 texture evaluation at a ray hit: patterned
 * textures (texture_map and friends) blended from fully lit sub-textures,
 * layered textures (filter colour through the layers), perturbed normals,
 * per-layer reflection, refraction with total internal reflection and
 * dispersion, interior fade, all as POV-Ray's ComputeOneTextureColour /
 * ComputeLightedTexture.
 *
 * The integrator (shade.c) supplies ray tracing, direct light and the GI
 * indirect term through callbacks, so this module owns the surface model
 * and nothing about rays or lights.
 *
 * For the GI modes: shade_tex_pigment_at gives the pigment colour of a surface at a
 * hit (patterns, image maps, texture maps resolved), the colour to use as
 * albedo where pigments vary over a surface. */
#ifndef PT_SHADE_TEXTURE_H
#define PT_SHADE_TEXTURE_H
#include "accel.h"
#include "rng.h"
#include "scene.h"
#include "shade_light.h"
#include "shade_media.h"

typedef struct {
    const scene *sc;
    double eps;          /* distance the secondary origins move off the surface */
    int use_ambient;     /* add finish ambient * ambient_light */
    int max_level;
    void *ctx;           /* the integrator's, passed back to the callbacks */
    int thread;
    rng *r;
    /* Radiance along a ray (level = the new ray's level; skip = OBJ_* flags
     * of objects the ray does not see; wavelength = the ray's spectral band
     * in nm once a dispersive surface split it, 0 for a ray of all colours:
     * pass it back to shade_tex_shade for the ray's hits). */
    rgb (*trace)(void *ctx, int thread, vec3 org, vec3 dir, int level, double weight, unsigned skip, float wavelength,
                 rng *r);
    /* Direct light of every light source on the layer surface s at p. */
    rgb (*direct)(void *ctx, int thread, const shade_light_surface *s, const accel_hit *h, vec3 p, rng *r);
    /* GI indirect irradiance-like term at a diffuse layer (NULL = none). */
    rgb (*indirect)(void *ctx, int thread, const accel_hit *h, vec3 n);
    long *unsupported;   /* incremented when a hit uses something not evaluated (may be NULL) */
    int quality;         /* POV-Ray's +Q level (shade_settings.quality): 9 everything */
    /* The containers of the ray being shaded (POV-Ray's interior list: the
     * camera's, then toggled by each surface a transmitted ray crosses);
     * they set the ior ratios and whether the interior's fade applies.
     * NULL: the ray's side of the surface decides (a ray from the
     * atmosphere). */
    const shade_media_inside *inside;
    /* Highlights of directed indirect light (the caustic layer's photons)
     * on the layer surface s at every layer with specular or phong (NULL =
     * none). */
    rgb (*highlights)(void *ctx, int thread, const accel_hit *h, const shade_light_surface *s);
    /* Hits being shaded on this ray tree's stack, this one included (1 at
     * a camera ray's first hit): depth - level is the number of straight
     * rays (below) on the way here. 0: unknown, every ray counts a level. */
    int depth;
} shade_tex_env;

/* A ray that goes on unbent through a surface between equal iors (an
 * object without ior, the overlap of two objects) keeps its trace level,
 * as POV-Ray 3.7's ComputeRefraction traces it as a continued ray
 * (trace.cpp: TraceRay checks the level but does not raise it). At most
 * this many such rays in a chain keep it, so that a stack of transparent
 * surfaces cannot recurse without bound; past that each counts a level. */
#define SHADE_TEX_MAX_CONTINUED 64

/* Colour seen along unit `dir` at hit h (the ray's level and weight as in
 * POV-Ray's TraceRay; skip and wavelength as for trace). */
rgb shade_tex_shade(const shade_tex_env *e, const accel_hit *h, vec3 dir, int level, double weight, unsigned skip, float wavelength);

/* Pigment colour (r g b filter transmit) of the top layer of the texture at
 * a hit: texture transforms applied, texture maps blended. `tex` NULL = the
 * hit's effective texture. Returns 0 if no colour was found (outside an
 * image map used `once`). */
int shade_tex_pigment_at(const scene *sc, const scene_texture *tex, const accel_hit *h, colour5 *out);

/* The perturbed normal of the top layer of the hit's texture (its normal
 * pattern, warped as the Whitted pass warps it; through texture maps along
 * the entry of the larger weight), for unit n, the raw normal on the side
 * seen, into *out: POV-Ray's radiosity `normal on` gathers about it
 * (core/radrules.h rule 5). Returns 0, with *out = n, where the texture
 * has no normal pattern or the perturbed normal leaves n's side. */
int shade_tex_normal_at(const scene *sc, const accel_hit *h, vec3 n, vec3 *out);

/* Filter colour of a surface for a shadow ray crossing it at h (POV-Ray's
 * ComputeShadowTexture: rgb*filter + transmit of the layers, multiplied,
 * with the interior's faked caustics and fade; 0 for opaque surfaces).
 * h->t is taken as the distance travelled inside the object when the ray
 * leaves it. */
rgb shade_tex_shadow_filter(const scene *sc, const accel_hit *h, vec3 dir);
/* shade_tex_shadow_filter with the interior's fade over h->t taken when
 * `inside` (and not otherwise), whichever way the ray crosses. */
rgb shade_tex_shadow_filter_inside(const scene *sc, const accel_hit *h, vec3 dir, int inside);
/* POV-Ray 3.7's walk of a shadow ray over the surfaces it crosses
 * (trace.cpp, TracePointLightShadowRay): the ray's origin moves to each
 * crossing it takes, and the next one it takes is the nearest more than
 * SMALL_TOLERANCE beyond it (FindIntersection's postcondition,
 * SmallToleranceRayObjectCondition; the first also more than
 * SHADOW_TOLERANCE from the lit point; both 0.001, absolute lengths:
 * configbackend.h, trace.cpp). A crossing nearer than that is not seen: no
 * filter, and the ray's interior list is not updated (ComputeShadowMedia
 * does that for the crossings taken), so the list's fade rule
 * (ComputeShadowTexture: fade when the list holds the object's interior)
 * counts that object from the wrong side until its next crossing taken: a
 * drink 0.3 mm inside its glass casts no filtered shadow. */
typedef struct {
    double last;                /* t of the last crossing taken (0: the lit point) */
    shade_media_inside unseen;  /* interiors crossed an odd number of times unseen */
} shade_tex_walk;
#define SHADE_TEX_POV_SMALL_TOLERANCE 1.0e-3
/* 1 when the walk takes the crossing at h (not a no_shadow object's): then
 * *depth is its distance from the last one taken (from the lit point for
 * the first) and *inside whether POV-Ray's interior list holds h's object
 * there (it leaves the object, or an odd number of its crossings went
 * unseen, not both); 0 when it is not seen. */
int shade_tex_walk_take(shade_tex_walk *w, const accel_hit *h, vec3 dir, double *depth, int *inside);
/* The interior's fade over h->t for a ray along dir that leaves h's object
 * there (dir along the geometric normal); 1 for a ray entering it: the
 * Whitted pass's rule without an interior list (the object left fades
 * what came through it, shade_tex_shade). `shadow` 1: transmit_fade's
 * shadow rule, the fade shade_tex_shadow_filter applies, alone: a photon
 * reflected inside an object has crossed it as well (POV-Ray 3.7
 * photons.cpp, PhotonTrace::ComputeLightedTexture attenuates the photon
 * by the hit object's fade whenever it travelled inside that object,
 * before it is reflected or refracted); 0: a view ray's (the reference
 * renderers' paths). */
rgb shade_tex_leaving_fade(const accel_hit *h, vec3 dir, int shadow);
/* The ior ratio eta = n_incident / n_transmitted of a refraction through
 * object o's surface (entering: the ray hits its outside) by a ray whose
 * containers are `in`, POV-Ray 3.7's interior-list rule (the one the eye
 * rays follow, trace.cpp ComputeRefraction; photons.cpp
 * ComputeRefractionForPhotons has the same): nested objects refract
 * against their container, leaving an overlap does not refract. */
double shade_tex_refraction_eta(const shade_media_inside *in, const scene_object *o, int entering);
/* The relative ior of the fresnel reflectivity there (ComputeRelativeIOR,
 * ior_setup's rule): 1 when the ray leaves the innermost of two or more
 * containers (a glass in a closed room reflects only its reflection_min
 * from inside). */
double shade_tex_fresnel_ior(const shade_media_inside *in, const scene_object *o, int entering);

/* Light left along a shadow ray from p (unit dir) over (tmin, tmax): 0 when
 * an opaque surface blocks it, else the product of the filter colours of the
 * (transparent) surfaces crossed; no_shadow objects are ignored (POV-Ray's
 * TracePointLightShadowRay). photon_light: NULL, or the light when the
 * caustic layer carries its photons (POV-Ray 3.7 trace.cpp: a photon
 * target that refracts that light's photons, scene_photon_lobe, casts a
 * full shadow: the light through it arrives as photons). */
rgb shade_tex_shadow_ray(const scene *sc, const accel *a, vec3 p, vec3 dir, double tmin, double tmax,
                         const scene_light *photon_light);

/* Can any surface of the scene let light through (filter/transmit anywhere
 * in its textures, image maps with alpha or `once`)? When not, shadows are
 * plain occlusion tests. */
int shade_tex_scene_transparent(const scene *sc);

#endif
