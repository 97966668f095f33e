/* sdl_pattern.h - grammar of POV-Ray 3.7 patterns and what uses them:
 * pigment and normal bodies (pattern types with their arguments, listed
 * colours/pigments/normals/textures, pattern modifiers, turbulence and
 * warp{} blocks, transforms), color_map / pigment_map / normal_map /
 * slope_map / texture_map, image_map / image_pattern / bump_map, patterned
 * textures (texture_map, tiles, material_map). Builds the records of
 * core/scene_pattern.h; sdl_material.c calls in here.
 *
 * Transform rule (see scene_pattern.h): transforms accumulate in the owner's
 * outermost transform (scene_pigment.transform, scene_normal.transform,
 * scene_texture.transform); a warp{} written after transforms moves them
 * into the pattern's warp list ahead of the new warp, as POV-Ray's warp list
 * orders them. */
#ifndef PT_SDL_PATTERN_H
#define PT_SDL_PATTERN_H
#include "sdl_parse.h"

/* The inside of pigment { } (or a pigment_map entry after its value), up to
 * but not including the closing '}' or ']'. pg holds the starting pigment. */
void sdl_pattern_pigment_body(sdl_parser *p, scene_pigment *pg);
/* The inside of normal { }; base = starting normal (NULL = the default). */
scene_normal *sdl_pattern_normal_body(sdl_parser *p, const scene_normal *base);
/* A patterned texture, from its pattern keyword (or tiles/material_map) to
 * before the texture's closing '}'. */
void sdl_pattern_texture(sdl_parser *p, scene_texture *t);
/* Is k a keyword that starts a pattern type (pigment/normal/texture)? */
int sdl_pattern_is_type(sdl_kw k);
/* A rainbow's pigment: after 'colour_map' (not yet read), a gradient x
 * pigment through that map (POV-Ray's Parse_Rainbow). */
void sdl_pattern_rainbow_pigment(sdl_parser *p, scene_pigment *pg);

#endif
