/* sdl_df3.h - density_file df3 data read at parse time (POV-Ray 3.7's
 * Read_Density_File semantics: three big-endian 16-bit sizes, then samples
 * of 1, 2 or 4 big-endian bytes whose width follows from the file size). */
#ifndef PT_SDL_DF3_H
#define PT_SDL_DF3_H
#include <stddef.h>
#include "scene.h"

/* Read `path` into d (values in `mem`, scaled to 0..1 by the sample
 * width's maximum). Returns 0, or -1 with a reason in `why`. */
int sdl_df3_load(scene_density *d, const char *path, arena *mem, char *why, size_t whycap);

#endif
