/* sdl_atmos.h - fog { } and sky_sphere { } (POV-Ray 3.7 grammar), after
 * their keyword. The scene statement adds them to the scene; #declare keeps
 * them as values (sdl_parse_look_value). */
#ifndef PT_SDL_ATMOS_H
#define PT_SDL_ATMOS_H
#include "sdl_parse.h"

/* fog := '{' [fog_identifier] { colour | distance f | fog_type n | fog_alt f |
 *   fog_offset f | turb_depth f | up v | turbulence v | octaves n | omega f |
 *   lambda f | rotate/scale/matrix/transform (turn `up`) | translate } '}' */
scene_fog *sdl_parse_fog(sdl_parser *p);
/* sky_sphere := '{' [sky_sphere_identifier] { pigment {..} | emission c |
 *   transform_item } '}' */
scene_sky_sphere *sdl_parse_sky_sphere(sdl_parser *p);
/* rainbow := '{' [rainbow_identifier] { angle f | direction v | colour_map {..} |
 *   distance f | jitter f | width f | up v | falloff_angle f | arc_angle f } '}' */
scene_rainbow *sdl_parse_rainbow(sdl_parser *p);
/* Statement forms: add to the scene (fogs and rainbows accumulate, the last
 * sky_sphere wins). */
void sdl_atmos_statement(sdl_parser *p, sdl_kw k);

#endif
