/* mirror.h - POV-Ray 3.7's mirror reflection of a finish, in one place for
 * the Whitted pass (shade/) and the final gather's rays (gi/), which
 * follow mirror reflections as POV-Ray's radiosity rays do.
 *
 * The rules (POV-Ray 3.7 source: source/core/render/trace.cpp
 * Trace::ComputeReflectivity and Trace::ComputeMetallic; docs "Finish:
 * reflection"): with `fresnel on` the reflectivity blends reflection max
 * and min by the dielectric Fresnel reflectance at the relative ior (max
 * where it is 1, and max outright under total internal reflection); without
 * it by (1 - cos_i)^falloff (max at grazing incidence). `metallic` then
 * tints it towards the pigment, and `conserve_energy` takes it off what
 * the surface transmits (the callers apply that). */
#ifndef PT_MIRROR_H
#define PT_MIRROR_H
#include "scene.h"

/* 1 when finish f reflects at any angle (reflection min or max above 0). */
int mirror_reflects(const scene_finish *f);

/* The reflectivity of finish f at the cosine cos_i between the incoming
 * ray and the normal (both facing each other: cos_i >= 0) and the relative
 * ior rel_ior (outside over inside for a ray entering), before the metallic
 * tint; *weight (the ray's weight, adc_bailout's measure) is multiplied by
 * what the reflected ray carries: the largest channel of the result with
 * fresnel, else the largest of max's and min's. */
rgb mirror_reflectivity(const scene_finish *f, double cos_i, double rel_ior, double *weight);

/* POV-Ray's empirical metallic tint of a highlight or reflection colour
 * cs towards the pigment: F(x) = 0.014567225/(x-1.12)^2 - 0.011612903 with
 * x = angle/(pi/2), cs *= 1 + metallic (1 - F) (pigment - 1). */
void mirror_metallic_tint(rgb *cs, double metallic, rgb pigment, double cos_angle);

#endif
