/* sdl_clip.h - the clipped_by and bounded_by object modifiers: their
 * objects are read, made relative to the host object's space (see
 * scene_object.clip and .bound) and attached to it. */
#ifndef PT_SDL_CLIP_H
#define PT_SDL_CLIP_H
#include "sdl_parse.h"

/* After 'clipped_by' / 'bounded_by' (the keyword read, '{' next). */
void sdl_clip_clipped_by(sdl_parser *p, sdl_obj *so);
void sdl_clip_bounded_by(sdl_parser *p, sdl_obj *so);

#endif
