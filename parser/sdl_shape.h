/* sdl_shape.h - grammar of POV-Ray's further shapes: polygon,
 * lathe, sor, prism, superellipsoid, quadric, poly/cubic/quartic/polynomial,
 * blob, height_field, text, sphere_sweep, bicubic_patch (clipped_by and
 * bounded_by: sdl_clip.h). sdl_object.c hands a shape keyword over after
 * its '{'; the functions here read the shape's own arguments (object
 * modifiers are left to sdl_object_mods) and fill the IR (core/scene.h).
 *
 * sphere_sweep becomes a union of spheres and tangent cones (exact for
 * linear_spline, the spline sampled into linear pieces otherwise) and
 * bicubic_patch a smooth mesh (2^u_steps x 2^v_steps quads): both then use
 * the existing shapes downstream. */
#ifndef PT_SDL_SHAPE_H
#define PT_SDL_SHAPE_H
#include "sdl_parse.h"

/* 1 if this module parses the shape keyword k. */
int sdl_shape_handles(sdl_kw k);
/* After `k '{'`: the shape's arguments into so->obj (kind and data set). */
void sdl_shape_args(sdl_parser *p, sdl_kw k, sdl_obj *so, src_loc loc);

#endif
