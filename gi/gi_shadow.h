/* gi_shadow.h - the hook through which the GI takes POV-Ray's filtered
 * shadows from shade/ (gi/ does not shade surfaces itself). */
#ifndef PT_GI_SHADOW_H
#define PT_GI_SHADOW_H
#include "accel.h"
#include "scene.h"

/* The light left along a shadow ray over (tmin, tmax) that an opaque test
 * found blocked: POV-Ray's filtered shadow, the filter colours of the
 * transparent surfaces crossed, 0 past an opaque one (the signature of
 * shade_texture.h's shade_tex_shadow_ray; photon_light: the light when the
 * scene's photons carry it, so a target refracting them shadows fully). */
typedef rgb (*gi_shadow_fn)(const scene *sc, const accel *a, vec3 p, vec3 dir, double tmin, double tmax,
                            const scene_light *photon_light);

#endif
