/* view_overlay.h - the viewer's on-screen figures: lines of text in a small
 * built-in 5x7 bitmap font (our own glyphs: digits, capitals, punctuation;
 * lower case is drawn as capitals), drawn into an RGBA buffer that the
 * window blends over the image. No SDL here, so tests can draw without a
 * display. */
#ifndef PT_VIEW_OVERLAY_H
#define PT_VIEW_OVERLAY_H
#include <stdint.h>

enum { VIEW_OVERLAY_GLYPH_W = 5, VIEW_OVERLAY_GLYPH_H = 7, VIEW_OVERLAY_PAD = 3 };

typedef struct {
    int x, y, w, h;
} view_overlay_box;

/* The box that view_overlay_draw fills for these lines at this scale
 * (font pixels of `scale` x `scale` screen pixels), with its corner at
 * (0, 0): a cell of 6 x 9 font pixels per character plus a margin. */
view_overlay_box view_overlay_measure(const char *const *lines, int nlines, int scale);

/* Draws into rgba (w x h pixels, 4 bytes each, rows of w): the box at
 * (x, y) in black at alpha `bg_alpha`, the glyphs in opaque white. Pixels
 * outside the buffer are clipped. Returns the box (clipped to the buffer). */
view_overlay_box view_overlay_draw(uint8_t *rgba, int w, int h, int x, int y, const char *const *lines, int nlines,
                                   int scale, uint8_t bg_alpha);

/* 1 when the font has a glyph for c (else '?' is drawn). */
int view_overlay_has_glyph(char c);

#endif
