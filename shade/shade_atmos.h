/* shade_atmos.h - what a ray sees besides surfaces: the background colour,
 * sky_sphere pigments, and constant and ground fog along the ray (POV-Ray
 * 3.7 semantics; rainbow and atmospheric media are not modelled). */
#ifndef PT_SHADE_ATMOS_H
#define PT_SHADE_ATMOS_H
#include "scene.h"

/* Colour of a ray that hits nothing (unit direction). */
rgb shade_atmos_sky(const scene *sc, vec3 dir);
/* Colour `c` seen at distance `depth` (INFINITY: nothing hit) along the ray
 * after the scene's rainbows and fogs (in POV-Ray's order). Returns c
 * unchanged without them. */
rgb shade_atmos_fog(const scene *sc, vec3 org, vec3 dir, double depth, rgb c);
/* The fogs over a segment as an affine map of the colour behind them,
 * seen = add + att * c (shade_atmos_fog without rainbows): for integrators that
 * carry a throughput. */
void shade_atmos_fog_affine(const scene *sc, vec3 org, vec3 dir, double depth, rgb *att, rgb *add);
/* The fogs' attenuation alone over a segment (a light with
 * media_attenuation on sees its light dimmed so along shadow rays). */
rgb shade_atmos_fog_attenuation(const scene *sc, vec3 org, vec3 dir, double depth);

#endif
