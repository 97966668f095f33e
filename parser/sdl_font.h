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

/* The font files one parse has opened, each kept open until the parse ends
 * (a scene may set thousands of texts in one font). Starts as NULL. */
typedef struct sdl_font_cache sdl_font_cache;

/* Outline of the UTF-8 string `text` in the font file at `path`, opened
 * through `*cache` (created on first use). The outline depends only on the
 * file and the arguments, not on what the face was used for before (each
 * glyph is loaded anew, the charmap is chosen once at opening). On error
 * returns PT_ERR_IO or PT_ERR_NOMEM with a reason in `why`. */
pt_status sdl_font_text(sdl_font_cache **cache, const char *path, const char *text, vec3 offset,
                        sdl_font_outline *out, char *why, size_t whycap);

/* Closes every font of the cache and frees it (NULL is a no-op). */
void sdl_font_cache_free(sdl_font_cache *cache);

#endif
