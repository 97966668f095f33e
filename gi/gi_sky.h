/* gi_sky.h - the sky as particle GI sees it: radiance arriving along rays
 * that leave the scene (sky_sphere over background, core/radrules.h rule 4),
 * tabulated once per lighting so that the geometry stage's hundreds of
 * millions of escaping link rays read a table instead of evaluating
 * pigments, and the irradiance an unoccluded surface receives from it.
 * Internal to gi/. */
#ifndef PT_GI_SKY_H
#define PT_GI_SKY_H
#include "scene.h"

/* Radiance arriving from the sky along -dir for a ray that leaves the scene
 * along unit direction dir: sky_sphere pigments over the background (the
 * signature of shade_atmos.h's shade_atmos_sky, which the app passes). */
typedef rgb (*gi_sky_fn)(const scene *sc, vec3 dir);

typedef struct gi_sky gi_sky;

/* The sky of sc: fn's radiance on a latitude-longitude table about +y
 * (POV-Ray's up), or sc's background colour when fn is NULL. NULL when out
 * of memory. */
gi_sky *gi_sky_new(const scene *sc, gi_sky_fn fn);
void gi_sky_free(gi_sky *s);

/* 1 when the sky is black in every direction (nothing to gather). */
int gi_sky_black(const gi_sky *s);

/* Radiance along -d for a ray leaving along unit d (bilinear in the table). */
void gi_sky_radiance(const gi_sky *s, const float d[3], float out[3]);

/* E/pi at a surface with unit normal n that sees the whole sky hemisphere
 * about n, nothing occluding: the cosine-weighted mean of the radiance over
 * that hemisphere (tabulated over normals, bilinear). */
void gi_sky_irradiance(const gi_sky *s, vec3 n, float out[3]);

#endif
