/* sdl_geom.h - parse-time trace(), inside(), min_extent() and max_extent(),
 * evaluated on the IR objects built so far with geom/ (docs/parser.md): the
 * object's CSG tree (geom_csg.h) for rays and inside tests, POV-Ray 3.7's
 * bounding boxes (geom_extent.h) for the extents. */
#ifndef PT_SDL_GEOM_H
#define PT_SDL_GEOM_H
#include "sdl_parse.h"

/* trace '(' object ',' start ',' direction [ ',' vector_identifier ] ')' :
 * the nearest hit (<0,0,0> if none); the identifier receives the normal. */
vec3 sdl_trace_fn(sdl_parser *p, src_loc loc);
/* inside '(' object ',' point ')' : 1 or 0 */
double sdl_inside_fn(sdl_parser *p, src_loc loc);
/* min_extent / max_extent '(' object ')' */
vec3 sdl_extent_fn(sdl_parser *p, src_loc loc, int max);
/* Release the trees prepared during the parse (called when the parse ends). */
void sdl_geom_free(sdl_parser *p);

#endif
