/* radrules.h - POV-Ray 3.7's rules for light entering radiosity, in one
 * place for every mode: `--gi none` (shade/), particle GI (gi/), the path
 * tracer and the photon map with final gathering (reference/). A GI mode
 * is POV-Ray's radiosity switched on; `--gi none` is radiosity switched off.
 *
 * The rules (POV-Ray 3.7 source: source/core/render/trace.cpp
 * Trace::ComputeLightedTexture, Trace::ComputeSky and
 * NoSomethingFlagRayObjectCondition; source/core/lighting/radiosity.cpp
 * RadiosityFunction::ComputeAmbient and GatherLight; scenedata.h
 * EffectiveLanguageVersion; docs "Radiosity" and "Finish: ambient,
 * emission"):
 *
 * 1. Light a surface gives off, Le = pigment * opacity * E with
 *      E = emission + ambient * ambient_light   radiosity off, or #version < 3.7
 *      E = emission                             radiosity on and #version >= 3.7
 *    The same Le is what the camera sees and what gathering rays (and so
 *    particles and photons) carry to other surfaces: POV-Ray's radiosity
 *    rays shade their hits with the same code. A scene without any
 *    #version is a 3.62 scene (EffectiveLanguageVersion), so the legacy
 *    rule holds for it; `#version version` after including colors.inc and
 *    the like sets 3.7 (the `version` keyword is 3.7 until set).
 * 2. Gathered (indirect) light reaching a surface is multiplied by the
 *    radiosity block's `brightness` at every bounce (ComputeAmbient scales
 *    its result), then reflected by diffuse * pigment * opacity (and
 *    diffuse_back from the other side): Lambertian reflection of the
 *    cosine-weighted mean incoming radiance. Light from light_sources
 *    (direct light) is not scaled; emissive surfaces are not light sources
 *    and reach other surfaces only as gathered light, so their light is.
 * 3. `no_radiosity` objects are invisible to gathering rays (they still
 *    receive and reflect light and are seen by the camera).
 * 4. Gathering rays that leave the scene see the sky: sky_sphere pigments
 *    (times its emission) over the background colour, alpha ignored
 *    (GatherLight clears alphaBackground). shade/ evaluates it
 *    (shade_atmos_sky); gi/ receives it as a callback from app/.
 * 5. `media on` lets gathering rays see media, and with them fog and
 *    rainbows (default off: GetRadiosityQualityFlags drops the media
 *    quality flag, which TraceRay asks before all three); `normal on`
 *    gathers about the perturbed normal and reuses a gather only where
 *    the perturbed normals agree (ComputeAmbient's effectiveNormal;
 *    default off: the raw normal).
 * 6. `recursion_limit` is how many bounces of gathered light POV-Ray
 *    follows; `count`, `error_bound`, `pretrace_*`, `nearest_count`,
 *    `minimum_reuse`, `maximum_reuse`, `low_error_factor`,
 *    `gray_threshold`, `always_sample` (whether final-trace samples are
 *    also taken where the cache already has some), `adc_bailout` (the ray
 *    weight below which gathering rays stop recursing) and `max_sample`
 *    set the accuracy and bias of POV-Ray's irradiance cache, not the
 *    light the scene converges to; a mode that estimates without a cache
 *    has nothing to take from them.
 * 7. Trace levels (trace.cpp TraceRay; radiosity.cpp GetRecursionSettings):
 *    a ray at level >= max_trace_level returns black. A camera ray is at
 *    level 0 and each reflected or refracted ray one above its parent; the
 *    rays of the k-th gathering step (k = 1, 2, ...) start at int(1.5 k),
 *    with the limit raised to at least that + 1. This is what bounds light
 *    trapped in glass (total internal reflection adds the transmitted weight
 *    to the mirror, so a POV-Ray finish can return more than it receives).
 * 8. At the hits of gathering rays POV-Ray adds no phong or specular
 *    highlights (trace.cpp's IsRadiosityRay tests) and takes area lights as
 *    points at their centre (GetRadiosityQualityFlags clears areaLights). */
#ifndef PT_RADRULES_H
#define PT_RADRULES_H
#include "scene.h"

typedef struct {
    int gi;              /* indirect light is gathered (radiosity on) */
    int legacy;          /* the scene's effective #version is below 3.7 */
    int ambient;         /* rule 1: ambient * ambient_light is part of E */
    double brightness;   /* rule 2: 1 without a radiosity{} block */
    int recursion_limit; /* rule 6: POV-Ray's bounce count (0: no radiosity{} block) */
    int media, normal;   /* rule 5 */
} radrules;

/* The rules for scene sc rendered with (gi = 1) or without (gi = 0) global
 * illumination. */
radrules radrules_of(const scene *sc, int gi);

/* 1 when sc's effective language version is below 3.7 (no #version: 3.62). */
int radrules_legacy(const scene *sc);

/* E of rule 1 for finish f (multiply by pigment * opacity for Le). */
rgb radrules_emission(const radrules *r, const scene *sc, const scene_finish *f);

/* Rule 7: the level of the rays of gathering step k >= 1, and the level
 * limit there for a scene limit of max_trace_level. */
int radrules_gather_level(int k);
int radrules_level_limit(const scene *sc, int gather_level);

/* Rule 3: 1 when a gathering ray may hit an object with these flags. */
int radrules_gathers(unsigned obj_flags);

#endif
