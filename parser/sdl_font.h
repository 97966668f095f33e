/* sdl_font.h - TrueType glyph outlines for the text shape, through FreeType.
 *
 * Layout follows POV-Ray 3.7 (its truetype.cpp): font units scaled by
 * 1/units_per_EM, the first glyph moved so its left edge is at x = 0, each
 * later glyph placed at the pen position plus kerning (the font's `kern`
 * table, as POV-Ray reads it), the pen advanced by the advance width plus
 * kerning and then by the `offset` vector. Outlines (lines, TrueType
 * quadratic and CFF cubic Beziers) become cubic Bezier segments, exactly
 * (quadratics are degree-elevated). */
#ifndef PT_SDL_FONT_H
#define PT_SDL_FONT_H
#include <stddef.h>
#include "diag.h"
#include "vec.h"

typedef struct {
    int nsegments;
    double (*segments)[8]; /* malloc'd: x0 y0 x1 y1 x2 y2 x3 y3 per segment */
    double z_offset;       /* offset.z summed over the string (ignored: POV-Ray moves glyphs in z, rarely used) */
} sdl_font_outline;

/* Outline of the UTF-8 string `text` in the font file at `path`. On error
 * returns PT_ERR_IO or PT_ERR_NOMEM with a reason in `why`. */
pt_status sdl_font_text(const char *path, const char *text, vec3 offset, sdl_font_outline *out, char *why, size_t whycap);

#endif
