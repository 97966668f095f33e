/* sdl_scene.h - top-level scene statements: camera, light_source,
 * global_settings, background, atmospheric effects, objects. */
#ifndef PT_SDL_SCENE_H
#define PT_SDL_SCENE_H
#include "sdl_parse.h"

/* scene := { statement } end-of-file */
void sdl_parse_scene(sdl_parser *p);
/* After 'light_source': '{' ... '}' -> an sdl_obj holding one light. */
sdl_obj *sdl_parse_light(sdl_parser *p, src_loc loc);
/* After 'default' / '#default': '{' { texture | pigment | finish | normal } '}' */
void sdl_parse_default(sdl_parser *p);
/* After 'camera': '{' ... '}' -> a new camera with its final vectors. */
scene_camera *sdl_parse_camera_new(sdl_parser *p);

#endif
