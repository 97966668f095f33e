/* sdl_material.h - texture, pigment, finish, normal, interior, material and
 * transformation grammar. The keyword has been read by the caller; these
 * parse from its '{'. Every function returns storage the caller owns (a
 * fresh copy in the scene arena), so declared values are never modified.
 *
 * Texture transforms: scene_texture.transform maps texture space to world
 * space (the transforms written in the texture, then those applied to the
 * object after the texture was attached, as POV-Ray does);
 * scene_pigment.transform maps pattern space to texture space. */
#ifndef PT_SDL_MATERIAL_H
#define PT_SDL_MATERIAL_H
#include "sdl_parse.h"

/* texture '{' ... '}' -> new texture (layer list) */
scene_texture *sdl_parse_texture(sdl_parser *p);
/* The inside of a texture block (a texture_map entry after its value). */
scene_texture *sdl_parse_texture_body(sdl_parser *p);
/* pigment '{' ... '}' modifying pg / as a new pigment */
void sdl_parse_pigment(sdl_parser *p, scene_pigment *pg);
scene_pigment *sdl_parse_pigment_new(sdl_parser *p);
/* finish '{' ... '}' */
void sdl_parse_finish(sdl_parser *p, scene_finish *f);
scene_finish *sdl_parse_finish_new(sdl_parser *p);
/* normal '{' ... '}' -> a new normal (grammar in sdl_pattern.c), starting
 * from the default texture's normal / from `base`. NULL after an error. */
scene_normal *sdl_parse_normal(sdl_parser *p);
scene_normal *sdl_parse_normal_from(sdl_parser *p, const scene_normal *base);
/* normal '{' ... '}' on texture t (its top layer): modifies t's normal, or
 * creates one that the transforms already applied to t do not move (POV-Ray
 * transforms only the parts of a texture that exist). */
void sdl_attach_normal(sdl_parser *p, scene_texture *t);
/* interior '{' ... '}' */
void sdl_parse_interior(sdl_parser *p, scene_interior *in);
scene_interior *sdl_parse_interior_new(sdl_parser *p);
/* material '{' ... '}' modifying m / as a new material */
void sdl_parse_material(sdl_parser *p, sdl_material *m);
sdl_material *sdl_parse_material_new(sdl_parser *p);
/* After 'transform': '{' ... '}' or a transform identifier. */
xform sdl_parse_transform(sdl_parser *p);
/* If the next token starts translate/rotate/scale/matrix/transform, parse
 * it into *out and return 1; else return 0 and consume nothing. */
int sdl_transform_item(sdl_parser *p, xform *out);

/* #declare right-hand sides of appearance statements whose keyword k was
 * just read: color_map, pigment_map, normal_map, slope_map, texture_map
 * (VAL_OPAQUE named "colour_map"... with ptr = scene_blend_map), fog and
 * sky_sphere (VAL_OPAQUE "fog"/"sky_sphere", ptr = the record). Returns 0
 * (nothing read) for other keywords. */
int sdl_parse_look_value(sdl_parser *p, sdl_kw k, sdl_value *out);

/* Deep copy of a texture layer list (NULL stays NULL). */
scene_texture *sdl_copy_texture(sdl_parser *p, const scene_texture *t);
/* A transform from outside the texture (object, material): layers with
 * uv_mapping keep theirs (POV-Ray transforms the UV_MAP_PATTERN wrapper,
 * which its evaluation ignores). */
void sdl_transform_texture_outer(scene_texture *t, const xform *x);

#endif
