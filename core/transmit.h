/* transmit.h - POV-Ray 3.7's transmission through a surface, in one place
 * for the Whitted pass (shade/) and the final gather's rays (gi/), which
 * follow it as POV-Ray's radiosity rays do.
 *
 * The rules (POV-Ray 3.7 source: source/core/render/trace.cpp
 * ComputeLightedTexture, ComputeRefraction, TraceRefractionRay; docs
 * "Interior: fade_distance and fade_power"): each texture layer passes on
 * its pigment's filter times colour plus transmit, times 1 - the layer's
 * reflectivity under conserve_energy; the transmitted ray is traced while
 * the grey of that filter passes adc_bailout, with the ray weight times its
 * largest channel; it refracts by Heckbert's method at the ior ratio (total
 * internal reflection: the reflected ray instead, unfiltered); a ray that
 * leaves an interior takes its fade over the distance it travelled
 * inside. */
#ifndef PT_TRANSMIT_H
#define PT_TRANSMIT_H
#include "scene.h"

/* POV-Ray's greyscale of a colour (the filter's weight, trans) */
static inline double transmit_grey(rgb c) { return 0.297 * c.r + 0.589 * c.g + 0.114 * c.b; }

/* The filter colour after one layer: filcol times the layer's pigment c
 * filtered and transmitted (c.f * colour + c.t per channel), then, under
 * f's conserve_energy, times 1 - reflec (at most 1) per channel. */
rgb transmit_layer_filter(rgb filcol, const colour5 *c, const scene_finish *f, rgb reflec);

/* The refracted direction of unit d through a surface with unit normal
 * `local` facing the incoming ray, cos_n = |d . local|, at the ior ratio
 * eta (incoming side over far side's reciprocal: 1/ior entering, ior
 * leaving); returns 1 on total internal reflection (*out untouched). */
int transmit_refract(vec3 d, vec3 local, double cos_n, double eta, vec3 *out);

/* The interior's fade of a ray segment of length d inside it: exp(-(1 -
 * fade_colour) d / fade_distance) for fade_power >= 1000, else fade_colour
 * + (1 - fade_colour) / (1 + (d / fade_distance)^fade_power); 1 without a
 * fade_distance, and for a shadow ray (`shadow`) also without a
 * fade_power above 0 (POV-Ray tests it for shadows only). */
rgb transmit_fade(const scene_interior *in, double d, int shadow);
/* Whether transmit_fade(in, d, shadow) is 1 in every channel whatever d. */
int transmit_fade_none(const scene_interior *in, int shadow);

/* 1 when texture t (its layers, maps and image maps) can let light
 * through somewhere: a filter or transmit above 0 in some colour, a
 * transparent image. */
int transmit_texture_may(const scene_texture *t);

#endif
