/* shade_aov.h - arbitrary output variables (AOVs) for lighting studies:
 * per-pixel quantities at the first surface the camera sees, written as
 * extra EXR layers beside the beauty image (`--aovs`, app/lighting_study.c).
 *
 * Sampling: one camera ray through each pixel centre (the lens centre when
 * the camera has focal blur), in a pass of its own after the beauty render;
 * antialiasing samples are not averaged in. The first hit skips no_image
 * objects, as the camera rays of shade.c do. A pixel whose ray hits nothing
 * is 0 in every AOV (depth 0 means "no surface").
 *
 * The AOVs (channels in brackets):
 *  direct       [R G B] the Whitted direct term of the hit's top texture
 *               layer: diffuse + phong + specular of every light with its
 *               shadows, exactly shade.c's direct light (shade_direct), times
 *               the layer's opacity; no ambient, emission, reflection or
 *               refraction.
 *  indirect     [R G B] the GI term as it enters the colour:
 *               pigment * diffuse * opacity * the GI hook's E/pi (particle
 *               GI); 0 when no GI hook runs (gi none; pmfg/path, whose
 *               indirect light is not split off: see docs/units.md).
 *  albedo       [R G B] pigment * diffuse of the top layer (the Lambertian
 *               reflectance rho).
 *  normal       [X Y Z] the world-space shading normal, turned to face the
 *               viewer (normal{} perturbations are not applied).
 *  depth        [Z]     distance from the camera along the ray, scene units.
 *  illuminance  [R G B] irradiance E = pi * sum over lights of
 *               colour * attenuation * cos * visibility on the side facing
 *               the viewer (the direct term of a white diffuse-1 surface,
 *               times pi). Its Rec.709 Y is the illuminance: lux under
 *               photometric units (docs/units.md), where luminance
 *               L = rho E / pi. */
#ifndef PT_SHADE_AOV_H
#define PT_SHADE_AOV_H
#include "accel.h"
#include "diag.h"
#include "scene.h"
#include "shade.h"

typedef enum { AOV_DIRECT, AOV_INDIRECT, AOV_ALBEDO, AOV_NORMAL, AOV_DEPTH, AOV_ILLUMINANCE, AOV_COUNT } shade_aov_kind;

typedef struct {
    int width, height;
    unsigned mask;          /* bit k: AOV k is computed */
    float *buf[AOV_COUNT];  /* width*height*shade_aov_channels(k) floats, row 0 at the top; NULL unless in mask */
} shade_aov;

const char *shade_aov_name(int k);     /* "direct", ..., NULL out of range */
const char *shade_aov_suffixes(int k); /* channel name suffixes, one letter each: "RGB", "XYZ" or "Z" */
int shade_aov_is_colour(int k);        /* 1: RGB in the render's colour space (direct, indirect, albedo, illuminance) */

/* "direct,indirect,albedo,normal,depth,illuminance" (any subset, any order,
 * "all" for every one) -> bit mask. PT_ERR_USAGE with a message for an
 * unknown or empty name. */
pt_status shade_aov_parse(const char *list, unsigned *mask, diag *d);

/* Buffers for the AOVs in `mask`, zeroed; NULL when out of memory. */
shade_aov *shade_aov_new(int width, int height, unsigned mask);
void shade_aov_free(shade_aov *a);

/* Fill out's buffers for the scene as seen with settings s (size, threads,
 * seed; s->indirect is the GI hook for the indirect AOV, called with thread
 * indices below s->threads as in shade_render). */
pt_status shade_aov_render(const scene *sc, const accel *a, const shade_settings *s, shade_aov *out, diag *d);

/* +UA (POV-Ray's Output_Alpha): each pixel's opacity into alpha
 * (s->width * s->height floats), the fraction of n x n stratified camera
 * rays (n = 3 with antialiasing, else 1: the centre) that meet an object the
 * camera sees. A ray that leaves the scene counts 1 - the background's
 * transmit, as POV-Ray 3.7 composes it (parse.cpp, scene.cpp): with
 * #version 3.7 a background{} without transmit is opaque and no background
 * (the default <0,0,0,0,1>) is clear; before 3.7 (or without #version) the
 * background is clear. A sky_sphere is taken as opaque, and so are
 * transparent surfaces (POV-Ray lets a clear background show through
 * them: not modelled). */
void shade_alpha(const scene *sc, const accel *a, const shade_settings *s, float *alpha);

#endif
