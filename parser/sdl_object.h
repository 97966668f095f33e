/* sdl_object.h - object statements -> scene IR nodes.
 *
 * Transforms are applied eagerly: a node's `transform` is always its
 * object -> world transform so far, and applying a transform to a CSG node
 * applies it to every kid, to every texture already attached (POV-Ray
 * moves textures with their objects) and to contained light sources.
 * Texture, interior and flag inheritance from CSG parents to kids happens
 * when a finished object is added to the scene (POV-Ray's post-processing),
 * so leaves carry their effective texture. */
#ifndef PT_SDL_OBJECT_H
#define PT_SDL_OBJECT_H
#include "sdl_parse.h"

/* Shape/CSG/object/light_source keyword (or an object identifier)? */
int sdl_starts_object(const sdl_tok *t);
/* object_statement := object_keyword '{' ... '}' ; NULL after an error. */
sdl_obj *sdl_parse_object(sdl_parser *p);
/* An identifier or an object statement (no modifiers after it), for the
 * object pattern; NULL after an error. */
sdl_obj *sdl_parse_object_body(sdl_parser *p);
/* Deep copy (textures copied, meshes shared). */
sdl_obj *sdl_copy_obj(sdl_parser *p, const sdl_obj *o);
void sdl_obj_transform(sdl_obj *o, const xform *x);
/* Resolve inheritance and add the object and its lights to the scene. */
void sdl_obj_add_to_scene(sdl_parser *p, sdl_obj *o);
/* Object modifiers up to (not including) the closing '}'. */
void sdl_object_mods(sdl_parser *p, sdl_obj *o);

#endif
