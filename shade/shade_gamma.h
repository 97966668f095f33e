/* shade_gamma.h - POV-Ray 3.7's working gamma (assumed_gamma): colours in
 * the scene and the arithmetic of shading live in the working space; output
 * files decode it to linear before encoding for the file. */
#ifndef PT_SHADE_GAMMA_H
#define PT_SHADE_GAMMA_H
#include "framebuffer.h"
#include "scene.h"

/* Convert a rendered framebuffer from the working space to linear values
 * (v^gamma; for gamma handling off, the sRGB decoding, so that the usual
 * sRGB encoding of a PNG writes the computed values unchanged), on
 * `threads` threads (0 or less: pool_default_threads). No-op for gamma 1. */
void shade_gamma_fb_to_linear(const scene *sc, framebuffer *fb, int threads);

/* A working-space channel value as POV-Ray 3.7's adaptive antialiasing
 * compares it (tracetask.cpp with view.cpp's Antialias_Gamma default 2.5):
 * decoded to linear (as it is with gamma handling off), then raised to
 * 1/2.5, not clipped above 1; negative values count as 0. */
double shade_gamma_aa_value(const scene *sc, double v);

#endif
