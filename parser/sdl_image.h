/* sdl_image.h - images for image_map / image_pattern, read at parse time as
 * POV-Ray does: PNG, GIF, TGA, PGM/PPM, JPEG or TIFF through the one image
 * reader (sdl_imgread.h), decoded to linear RGBFT with POV-Ray 3.7's gamma
 * rules (formats without gamma information: sRGB). */
#ifndef PT_SDL_IMAGE_H
#define PT_SDL_IMAGE_H
#include <stddef.h>
#include "scene.h"

/* Fill img->width/height/pixels (in `mem`, the scene's arena) from
 * img->path, in the scene's working space: working_gamma = assumed_gamma
 * (1 = linear), or 0 when gamma handling is off (pre-3.7 scene without
 * assumed_gamma, or an image used as data): the file's codes as they are,
 * unless the scene gave the file's gamma (img->gamma), then linear values.
 * A negative working_gamma (-assumed_gamma) is a pre-3.7 scene that set
 * assumed_gamma: POV-Ray 3.7 then takes the working gamma as the default
 * gamma of files, so a file without gamma information keeps its codes
 * (its "AssumedGamma36" mode); files that state a gamma are decoded.
 * Returns 0 on success, else a reason in `why`. */
int sdl_image_load(scene_image *img, arena *mem, double working_gamma, unsigned long long max_pixels, char *why,
                   size_t whycap);
/* Set img->clear from its pixels: whether any has a filter or transmit
 * other than 0 (what transmit_texture_may asks of an image_map); again
 * after a palette entry's filter or transmit changed. */
void sdl_image_note_clear(scene_image *img);
/* The sRGB transfer function decoded to linear as POV-Ray 3.7 decodes it
 * (SRGBGammaCurve: knee at 0.04045), for images and srgb colours. */
double sdl_srgb_decode(double v);

#endif
