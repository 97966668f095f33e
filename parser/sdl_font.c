/* sdl_font.c - text outlines through FreeType (sdl_font.h). */
#include "sdl_font.h"
#include "grow.h"
#include <ft2build.h>
#include FT_FREETYPE_H
#include FT_OUTLINE_H
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    double (*seg)[8];
    int n, cap;
    double scale, ox, oy;   /* font units -> text space */
    double sx, sy;          /* contour start */
    double cx, cy;          /* current point */
    int open;               /* a contour is being drawn */
    int oom;
} outline_sink;

static void sink_add(outline_sink *s, double x0, double y0, double x1, double y1, double x2, double y2, double x3,
                     double y3)
{
    if (s->oom) return;
    if (x0 == x3 && y0 == y3 && x1 == x0 && y1 == y0 && x2 == x0 && y2 == y0) return; /* empty */
    if (!grow_array_int((void **)&s->seg, &s->cap, s->n + 1, sizeof *s->seg)) {
        s->oom = 1;
        return;
    }
    double *d = s->seg[s->n++];
    d[0] = x0; d[1] = y0; d[2] = x1; d[3] = y1; d[4] = x2; d[5] = y2; d[6] = x3; d[7] = y3;
}

static void sink_line(outline_sink *s, double x, double y)
{
    double x0 = s->cx, y0 = s->cy;
    sink_add(s, x0, y0, x0 + (x - x0) / 3.0, y0 + (y - y0) / 3.0, x0 + 2.0 * (x - x0) / 3.0, y0 + 2.0 * (y - y0) / 3.0,
             x, y);
    s->cx = x;
    s->cy = y;
}

static void sink_close(outline_sink *s)
{
    if (s->open && (s->cx != s->sx || s->cy != s->sy)) sink_line(s, s->sx, s->sy);
    s->open = 0;
}

static double tx(const outline_sink *s, const FT_Vector *v) { return s->ox + s->scale * (double)v->x; }
static double ty(const outline_sink *s, const FT_Vector *v) { return s->oy + s->scale * (double)v->y; }

static int cb_move(const FT_Vector *to, void *user)
{
    outline_sink *s = user;
    sink_close(s);
    s->sx = s->cx = tx(s, to);
    s->sy = s->cy = ty(s, to);
    s->open = 1;
    return 0;
}

static int cb_line(const FT_Vector *to, void *user)
{
    outline_sink *s = user;
    sink_line(s, tx(s, to), ty(s, to));
    return 0;
}

/* quadratic Bezier (P0, Q, P2) elevated to the cubic (P0, P0 + 2/3 (Q - P0), P2 + 2/3 (Q - P2), P2) */
static int cb_conic(const FT_Vector *ctl, const FT_Vector *to, void *user)
{
    outline_sink *s = user;
    double qx = tx(s, ctl), qy = ty(s, ctl), x = tx(s, to), y = ty(s, to);
    sink_add(s, s->cx, s->cy, s->cx + 2.0 / 3.0 * (qx - s->cx), s->cy + 2.0 / 3.0 * (qy - s->cy),
             x + 2.0 / 3.0 * (qx - x), y + 2.0 / 3.0 * (qy - y), x, y);
    s->cx = x;
    s->cy = y;
    return 0;
}

static int cb_cubic(const FT_Vector *c1, const FT_Vector *c2, const FT_Vector *to, void *user)
{
    outline_sink *s = user;
    double x = tx(s, to), y = ty(s, to);
    sink_add(s, s->cx, s->cy, tx(s, c1), ty(s, c1), tx(s, c2), ty(s, c2), x, y);
    s->cx = x;
    s->cy = y;
    return 0;
}

/* Next code point of a UTF-8 string (invalid bytes are taken as Latin-1). */
static unsigned long utf8_next(const unsigned char **ps)
{
    const unsigned char *s = *ps;
    unsigned long c = s[0];
    int n = 0;
    if (c >= 0xF0 && c < 0xF8) { c &= 0x07; n = 3; }
    else if (c >= 0xE0) { c &= 0x0F; n = 2; }
    else if (c >= 0xC0) { c &= 0x1F; n = 1; }
    if (c >= 0x80 && n == 0) { *ps = s + 1; return s[0]; }
    for (int i = 1; i <= n; i++) {
        if ((s[i] & 0xC0) != 0x80) { *ps = s + 1; return s[0]; }
        c = (c << 6) | (s[i] & 0x3F);
    }
    *ps = s + 1 + n;
    return c;
}

static FT_UInt glyph_for(FT_Face face, unsigned long c)
{
    FT_UInt g = FT_Get_Char_Index(face, c);
    /* symbol fonts map their characters at 0xF000 + code */
    if (g == 0 && face->charmap && face->charmap->encoding == FT_ENCODING_MS_SYMBOL) g = FT_Get_Char_Index(face, 0xF000 + c);
    return g;
}

typedef struct font_entry {
    char *path;
    FT_Face face;
    struct font_entry *next;
} font_entry;

struct sdl_font_cache {
    FT_Library lib;
    font_entry *fonts;
};

void sdl_font_cache_free(sdl_font_cache *cache)
{
    if (!cache) return;
    font_entry *f = cache->fonts;
    while (f) {
        font_entry *n = f->next;
        FT_Done_Face(f->face);
        free(f->path);
        free(f);
        f = n;
    }
    if (cache->lib) FT_Done_FreeType(cache->lib);
    free(cache);
}

/* The face of `path` in the cache into *face, opened (and its Unicode
 * charmap chosen) on first use. */
static pt_status cache_face(sdl_font_cache *cache, const char *path, FT_Face *face, char *why, size_t whycap)
{
    for (font_entry *f = cache->fonts; f; f = f->next)
        if (strcmp(f->path, path) == 0) {
            *face = f->face;
            return PT_OK;
        }
    font_entry *f = calloc(1, sizeof *f);
    if (f) f->path = strdup(path);
    if (!f || !f->path) {
        free(f);
        snprintf(why, whycap, "out of memory");
        return PT_ERR_NOMEM;
    }
    if (FT_New_Face(cache->lib, path, 0, &f->face)) {
        free(f->path);
        free(f);
        snprintf(why, whycap, "not a font FreeType can read");
        return PT_ERR_IO;
    }
    FT_Face fc = f->face;
    if (!fc->charmap && fc->num_charmaps > 0) FT_Set_Charmap(fc, fc->charmaps[0]);
    if (fc->charmap && fc->charmap->encoding != FT_ENCODING_UNICODE) {
        for (int i = 0; i < fc->num_charmaps; i++)
            if (fc->charmaps[i]->encoding == FT_ENCODING_UNICODE) FT_Set_Charmap(fc, fc->charmaps[i]);
    }
    f->next = cache->fonts;
    cache->fonts = f;
    *face = fc;
    return PT_OK;
}

static pt_status outline_text(FT_Face face, const char *text, vec3 offset, sdl_font_outline *out, char *why,
                              size_t whycap);

pt_status sdl_font_text(sdl_font_cache **cache, const char *path, const char *text, vec3 offset,
                        sdl_font_outline *out, char *why, size_t whycap)
{
    memset(out, 0, sizeof *out);
    if (!*cache) {
        sdl_font_cache *c = calloc(1, sizeof *c);
        if (!c) {
            snprintf(why, whycap, "out of memory");
            return PT_ERR_NOMEM;
        }
        if (FT_Init_FreeType(&c->lib)) {
            free(c);
            snprintf(why, whycap, "FreeType could not be initialised");
            return PT_ERR_IO;
        }
        *cache = c;
    }
    FT_Face face;
    pt_status st = cache_face(*cache, path, &face, why, whycap);
    return st == PT_OK ? outline_text(face, text, offset, out, why, whycap) : st;
}

static pt_status outline_text(FT_Face face, const char *text, vec3 offset, sdl_font_outline *out, char *why,
                              size_t whycap)
{
    double units = face->units_per_EM > 0 ? face->units_per_EM : 1000.0;
    outline_sink s;
    memset(&s, 0, sizeof s);
    s.scale = 1.0 / units;
    FT_Outline_Funcs funcs = {cb_move, cb_line, cb_conic, cb_cubic, 0, 0};
    double pen_x = 0.0, pen_y = 0.0;
    FT_UInt last = 0;
    int first = 1;
    pt_status st = PT_OK;
    const unsigned char *u = (const unsigned char *)(text ? text : "");
    while (*u && st == PT_OK) {
        unsigned long c = utf8_next(&u);
        FT_UInt g = glyph_for(face, c);
        if (FT_Load_Glyph(face, g, FT_LOAD_NO_SCALE | FT_LOAD_NO_HINTING | FT_LOAD_NO_BITMAP)) {
            snprintf(why, whycap, "glyph for U+%04lX could not be loaded", c);
            st = PT_ERR_IO;
            break;
        }
        FT_GlyphSlot gs = face->glyph;
        double adv = (double)gs->metrics.horiAdvance;
        double xmin = 0.0;
        if (gs->format == FT_GLYPH_FORMAT_OUTLINE && gs->outline.n_points > 0) {
            FT_BBox cb;
            FT_Outline_Get_CBox(&gs->outline, &cb);
            xmin = (double)cb.xMin;
        }
        double lsb = (double)gs->metrics.horiBearingX;
        double gx;
        if (first) {
            /* the first glyph's left edge at the origin; the pen after it
             * is its advance less its left side bearing */
            gx = -xmin * s.scale;
            pen_x = (adv - lsb) * s.scale;
        } else {
            double kern = 0.0;
            if (FT_HAS_KERNING(face)) {
                FT_Vector k;
                if (!FT_Get_Kerning(face, last, g, FT_KERNING_UNSCALED, &k)) kern = (double)k.x;
                if (kern < -units) kern = -units;
            }
            gx = pen_x + (lsb - xmin + kern) * s.scale;
            pen_x += (adv + kern) * s.scale;
        }
        if (gs->format == FT_GLYPH_FORMAT_OUTLINE && gs->outline.n_points > 0) {
            s.ox = gx;
            s.oy = pen_y;
            s.open = 0;
            if (FT_Outline_Decompose(&gs->outline, &funcs, &s)) {
                snprintf(why, whycap, "outline of U+%04lX could not be read", c);
                st = PT_ERR_IO;
            }
            sink_close(&s);
        }
        pen_x += offset.x;
        pen_y += offset.y;
        out->z_offset += offset.z;
        last = g;
        first = 0;
    }
    if (s.oom && st == PT_OK) {
        snprintf(why, whycap, "out of memory");
        st = PT_ERR_NOMEM;
    }
    if (st != PT_OK) {
        free(s.seg);
        return st;
    }
    out->segments = s.seg;
    out->nsegments = s.n;
    return PT_OK;
}
