/* shade_light.h - POV-Ray 3.7 light sources and the surface response to
 * them, shared by the Whitted integrator (shade.c) and the GI modes.
 *
 * Units. A light of colour C seen along unit direction l from a point with
 * (viewer-facing) normal n gives a surface with `diffuse d` and pigment P the
 * colour d * P * C * cos(n,l)^brilliance * attenuation (POV-Ray 3.7 manual,
 * "Finish" and "Light Source"). Read physically with brilliance 1, this is a
 * Lambertian BRDF d*P/pi under an irradiance E = pi * C * att * cos: POV-Ray
 * lights deliver that irradiance at any distance (no 1/d^2 unless
 * fade_power says so). The GI modes use exactly these functions, so their
 * direct light is POV-Ray's.
 *
 * What moved here from shade.c (behaviour unchanged): the spotlight falloff
 * curve, shade_light_attenuation, shade_light_ray, the area-light grid point layout (since
 * in core/scene.c, shared with gi/), the
 * metallic tint, the diffuse/phong/specular terms of one light and the
 * Fresnel reflectance used by `reflection { fresnel }`. New: shade_light_nee, a
 * continuous direct-light estimator for the GI modes. */
#ifndef PT_SHADE_LIGHT_H
#define PT_SHADE_LIGHT_H
#include "accel.h"
#include "diag.h"
#include "rng.h"
#include "scene.h"

/* Angle- and distance-based attenuation of `l` seen from `p` along unit `dir`
 * (towards the light) at distance `depth`: spotlight cos^tightness with the
 * cubic falloff between cos(radius) and cos(falloff), cylinder lights (radius
 * and falloff are distances from the axis), fade 2/(1+(d/fade_distance)^fade_power)
 * (or d^-fade_power with fade_distance 0). */
double shade_light_attenuation(const scene_light *l, vec3 p, vec3 dir, double depth);
/* cos(radius) and cos(falloff) of a spotlight, its angles in degrees (the
 * values cos() gives, kept per thread). */
void shade_light_spot_cosines(const scene_light *l, double *cos_radius, double *cos_falloff);
/* The light's fade at distance depth: 2 / (1 + (depth / fade_distance)^
 * fade_power), depth^-fade_power with fade_distance 0, 1 without
 * fade_power (POV-Ray 3.7's Attenuate_Light). */
double shade_light_fade(const scene_light *l, double depth);

/* Unit direction from p towards the light point `centre` (the light's
 * position or a point of its area) and the distance to it, with POV-Ray's
 * handling of cylinder and parallel lights (fixed direction, depth measured
 * along it). */
void shade_light_ray(const scene_light *l, vec3 centre, vec3 p, vec3 *dir, double *depth);

/* The grid point layout of an area light: scene_light_area_point (core/scene.h). */

/* Axes of an area light as seen from p: the light's own, or for `orient`
 * the same lengths turned to face p (POV-Ray's rule, scene_light_orient_axes). */
void shade_light_area_axes(const scene_light *l, vec3 p, vec3 *ax1, vec3 *ax2);

/* The surface a light shines on. */
typedef struct {
    const scene_finish *f;
    rgb pigment;
    vec3 n;       /* shading normal facing the viewer */
    vec3 eye;     /* incoming (viewing) ray direction, unit */
    double att;   /* opacity of the layer: 1 - grey(filter*pigment + transmit) */
    rng *r;       /* for crand */
    /* irid: the surface point and the scene's settings (irid
     * wavelengths, noise generator); NULL: POV-Ray's defaults */
    vec3 ipoint;
    const scene_global *global;
} shade_light_surface;

/* POV-Ray 3.7's iridescence factor (ComputeIridColour) of a finish with
 * irid > 0: per channel 1 + irid * cos(2 pi d (|n.l| + |n.e|) / wavelength),
 * d the film thickness varied by turbulence at ipoint; l, e unit. */
rgb shade_light_irid(const scene_finish *f, vec3 l, vec3 e, vec3 n, vec3 ipoint, const scene_global *g);

/* Diffuse + phong + specular response to a light of colour `lc` arriving
 * along unit `l` (towards the light); `backside` uses diffuse_back and no
 * highlights. */
rgb shade_light_terms(const shade_light_surface *s, vec3 l, rgb lc, int backside);

/* ------------------------------------------------------------ GI direct light */

/* Everything shade_light_nee needs besides the light. */
typedef struct {
    const accel *a;
    double eps;          /* scene distance epsilon (shade.c's: accel_scale * 1e-6) */
    long *shadow_rays;   /* incremented per shadow ray; may be NULL */
    const accel_from *from; /* the surface the shadow rays leave (accel_occluded_from); NULL: none */
    /* Filtered shadows (POV-Ray's, shade_tex_shadow_ray): sc non-NULL and
     * transparent set (shade_tex_scene_transparent) make a blocked shadow
     * ray walk the surfaces it crosses and pass their filter colours;
     * photon_shadows (the scene's photons{} is on): a photon target that
     * refracts the light's photons shadows it fully. Else every object but
     * no_shadow ones is opaque. */
    const scene *sc;
    int transparent, photon_shadows;
} shade_light_ctx;

/* Direct light from one POV-Ray light source at the surface point p (already
 * offset off the surface on the viewer's side), estimated with `nsamples`
 * shadow rays for area lights (1 for the others). Same terms and
 * attenuation as shade.c's direct light, with one difference: an area light
 * is sampled continuously (stratified, nsamples = k*k strata, uniform over
 * the parallelogram axis1 x axis2, or the ellipse inside it when `circular`)
 * instead of POV-Ray's jittered size1 x size2 grid with adaptive
 * subdivision; an axis whose size is 1 has no extent, as in the grid. The
 * intensity (spot, fade, cosine) comes from the light's centre unless
 * area_illumination is on, as in shade.c. `double_illum` is the object's
 * double_illuminate flag. Shadows: accel_occluded (no_shadow objects do not
 * block), then, where c asks for filtered shadows, POV-Ray's filter of the
 * transparent surfaces crossed, as shade.c's. Unbiased for the continuous
 * light. */
rgb shade_light_nee(const shade_light_ctx *c, const scene_light *l, const shade_light_surface *s, vec3 p, int double_illum,
              int nsamples, rng *r);

/* ------------------------------------------------------ photometric units */

/* Photometric light units for lighting studies (docs/units.md): one scene
 * unit is `metres_per_unit` metres; a light's colour C has luminance
 * I = 0.2126 R + 0.7152 G + 0.0722 B (Rec.709 weights). Point and spot lights (and area lights, whose
 * intensity is spread over their grid as POV-Ray spreads it) become
 * isotropic sources of I candela (on the axis for spotlights) with
 * inverse-square falloff, E = I cos / d^2 lux, d in metres; parallel,
 * cylinder and `parallel` lights give I lux on a surface facing them, at
 * any distance. The renderer's values then read as luminance in cd/m^2:
 * a diffuse surface of reflectance rho = pigment * diffuse under E shows
 * L = rho E / pi.
 *
 * The model is applied by rewriting the lights once, after parsing, into
 * the POV-Ray terms every integrator already evaluates: colour scaled by
 * 1/(pi m^2) with fade_distance 0 and fade_power 2 (shade_light_attenuation's
 * d^-fade_power branch, d in scene units), or colour / pi with no fade for
 * the parallel kinds. So shade.c (Whitted), gi/ (particle GI: the OpenCL
 * kernels' gi_light_attenuation in gi/kernels/gi_types.h, a copy of
 * shade_light_attenuation) and reference/ (shade_light_nee, shade_light_attenuation and the
 * photon powers of pm_photon.c) all see the same falloff.
 * A light's own fade_distance/fade_power are replaced; each such light
 * gets a warning in d. PT_ERR_USAGE when metres_per_unit is not a positive
 * finite number. Applying it twice scales twice: call it once. */
pt_status shade_light_units_apply(scene *sc, double metres_per_unit, diag *d);

#endif
