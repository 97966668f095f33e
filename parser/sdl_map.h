/* sdl_map.h - POV-Ray 3.7's maps (color_map, pigment_map, normal_map,
 * slope_map, texture_map) read into scene_blend_map records; the pattern
 * grammar (sdl_pattern.c) and the map declarations use them. Map values are
 * kept in single precision, as POV-Ray keeps them. */
#ifndef PT_SDL_MAP_H
#define PT_SDL_MAP_H
#include "sdl_parse.h"

/* Entries a map may have. */
#define SDL_MAP_MAX_ENTRIES 256

/* v rounded to single precision (POV-Ray's SNGL map values). */
static inline double sdl_map_single(double v) { return (double)(float)v; }

/* n entries (at least one) in the parse's arena. */
scene_map_entry *sdl_map_entries(sdl_parser *p, int n);
/* A map of kind k over entries e[0..n). */
scene_blend_map *sdl_map_make(sdl_parser *p, map_kind k, scene_map_entry *e, int n);
/* A colour into an entry's c[5] (r, g, b, filter, transmit). */
void sdl_map_colour_into(double c[5], colour5 v);
/* After color_map: its block. */
const scene_blend_map *sdl_map_colour(sdl_parser *p);
/* After pigment_map, normal_map, slope_map or texture_map: its block as a
 * map of kind k; average: the entries' values may be left out (average's
 * pigment list). */
const scene_blend_map *sdl_map_blend(sdl_parser *p, map_kind k, int average);
/* After a map keyword (color_map, pigment_map, normal_map, slope_map,
 * texture_map): its block as a map (#declare right-hand sides). */
const scene_blend_map *sdl_map_parse(sdl_parser *p, sdl_kw k);

#endif
