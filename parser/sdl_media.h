/* sdl_media.h - media { } and density { } (POV-Ray 3.7 grammar), after
 * their keyword: interiors, the scene statement (atmospheric media) and
 * #declare use them. Declared values are VAL_OPAQUE named "media"
 * (ptr = scene_media) and "density" (ptr = scene_pigment, accepted wherever
 * a density body starts, density_map entries included). */
#ifndef PT_SDL_MEDIA_H
#define PT_SDL_MEDIA_H
#include "sdl_parse.h"

/* media := '{' [media_identifier] { method n | intervals n | samples n [, m] |
 *   jitter f | aa_threshold f | aa_level n | confidence f | variance f |
 *   ratio f | collect [b] | absorption c | emission c |
 *   scattering '{' type, c [eccentricity f] [extinction f] '}' |
 *   density '{' .. '}' | transform_item } '}'
 * A new record; NULL after an error. */
scene_media *sdl_parse_media(sdl_parser *p);
/* density := '{' [density_identifier] pigment-like body (density_map
 * allowed) '}' */
scene_pigment *sdl_parse_density(sdl_parser *p);
/* Append m to the array (*list, *n) (a new array: the old one may be shared). */
void sdl_media_append(sdl_parser *p, const scene_media *const **list, int *n, const scene_media *m);
/* Interior in, just parsed onto an object whose transform (object -> world)
 * is `obj`: the media records not in `before` (the interior it replaced,
 * may be NULL) are rebased so that their transform ends in the object's
 * space, as POV-Ray moves only what exists when a transform is applied. */
void sdl_media_attach(sdl_parser *p, scene_interior *in, const scene_interior *before, const xform *obj);
/* The media statement: parse and append to the scene's atmosphere. */
void sdl_media_statement(sdl_parser *p);

#endif
