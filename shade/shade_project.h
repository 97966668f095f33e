/* shade_project.h - light_source { projected_through { object } }: light
 * reaches a point only through the object (POV-Ray 3.7's
 * TracePointLightShadowRay): the object is intersected on its own along the
 * shadow ray, and shadows are then tested only up to it. */
#ifndef PT_SHADE_PROJECT_H
#define PT_SHADE_PROJECT_H
#include "diag.h"
#include "scene.h"

typedef struct shade_light_projection shade_light_projection;

/* One Embree scene per projected_through object of the scene's lights;
 * NULL when no light has one (or on failure, with a warning in d). */
shade_light_projection *shade_projection_build(const scene *sc, diag *d);
void shade_projection_free(shade_light_projection *lp);

/* Light `light` seen from p along unit dir, the light at distance depth:
 * returns 0 when the projected object is not crossed before the light (no
 * light arrives), else 1 with *shadow_depth the distance shadows are tested
 * over (the first crossing for a projected light, depth for the others). */
int shade_projection_pass(const shade_light_projection *lp, int light, vec3 p, vec3 dir, double depth, double *shadow_depth);

#endif
