/* sdl_map.c - POV-Ray 3.7's maps: color_map (POV-Ray's Parse_Colour_Map:
 * entries in single precision, `[a b color c1 color c2]` ranges), and
 * pigment_map, normal_map, slope_map, texture_map (Parse_Blend_Map), as
 * records of the IR (sdl_map.h; semantics studied, not copied). */
#include "sdl_map.h"
#include <stdlib.h>
#include <string.h>
#include "sdl_directive.h"
#include "sdl_expr.h"
#include "sdl_material.h"
#include "sdl_pattern.h"

scene_map_entry *sdl_map_entries(sdl_parser *p, int n)
{
    scene_map_entry *e = sdl_alloc(p, sizeof *e * (size_t)(n > 0 ? n : 1));
    return e;
}

scene_blend_map *sdl_map_make(sdl_parser *p, map_kind k, scene_map_entry *e, int n)
{
    scene_blend_map *m = sdl_alloc(p, sizeof *m);
    if (!m) return NULL;
    m->kind = k;
    m->n = n;
    m->e = e;
    return m;
}

void sdl_map_colour_into(double c[5], colour5 v)
{
    c[0] = v.r;
    c[1] = v.g;
    c[2] = v.b;
    c[3] = v.f;
    c[4] = v.t;
}

/* A declared map used as `map { Id }`. */
static const scene_blend_map *declared_map(sdl_parser *p, const char *what)
{
    sdl_tok id = sdl_next(p);
    if (id.val.kind == VAL_OPAQUE && id.val.ptr && id.val.str && strcmp(id.val.str, what) == 0) return id.val.ptr;
    sdl_warn_once(p, id.tk.loc, "declared %s '%.*s' is not available; the default map is used", what, id.tk.len, id.tk.text);
    return NULL;
}

/* The head every map shares: its block `block` opened, then either a
 * declared map of kind `kind` (*declared set, block closed: returns NULL
 * with *declared possibly NULL too) or the array of entries to fill. */
static scene_map_entry *map_begin(sdl_parser *p, const char *block, const char *kind, const scene_blend_map **declared)
{
    *declared = NULL;
    if (!sdl_begin_block(p, block)) return NULL;
    if (sdl_is(sdl_peek(p), TOK_IDENT) && sdl_peek(p)->val.kind == VAL_OPAQUE) {
        *declared = declared_map(p, kind);
        sdl_end_block(p);
        return NULL;
    }
    return sdl_map_entries(p, SDL_MAP_MAX_ENTRIES);
}

/* The next entry, '[', when n entries and `need` more fit; past the limit
 * a located error naming the map (`what`). */
static int map_next(sdl_parser *p, int n, int need, const char *what)
{
    if (!sdl_ok(p) || !sdl_accept(p, TOK_LBRACKET)) return 0;
    if (n + need <= SDL_MAP_MAX_ENTRIES) return 1;
    sdl_error(p, sdl_peek(p)->tk.loc, PT_ERR_LIMIT, "too many entries in %s (at most %d)", what, SDL_MAP_MAX_ENTRIES);
    return 0;
}

/* The block closed; 0, with POV-Ray's error `empty`, when no entry was read. */
static int map_end(sdl_parser *p, int n, const char *empty)
{
    sdl_end_block(p);
    if (n > 0) return 1;
    if (sdl_ok(p)) sdl_error(p, sdl_peek(p)->tk.loc, PT_ERR_SYNTAX, "%s", empty);
    return 0;
}

/* colour_map := '{' ( map_id | { '[' v [','] ( colour | v2 [','] colour colour ) ']' } ) '}' */
const scene_blend_map *sdl_map_colour(sdl_parser *p)
{
    const scene_blend_map *declared;
    scene_map_entry *e = map_begin(p, "color_map", "colour_map", &declared);
    if (!e) return declared;
    int n = 0;
    while (map_next(p, n, 2, "color_map")) {
        double v = sdl_map_single(sdl_float(p));
        sdl_accept(p, TOK_COMMA);
        if (!sdl_starts_colour(sdl_peek(p))) {
            /* old style [v1 v2 colour c1 colour c2] or [v <r,g,b,f,t>] */
            sdl_value ex;
            sdl_sum(p, &ex);
            if (ex.dim == 5 || ex.kind == VAL_COLOUR) {
                e[n].value = v;
                for (int i = 0; i < 5; i++) e[n].c[i] = ex.v[i];
                n++;
            } else {
                double v2 = sdl_map_single(ex.v[0]);
                sdl_accept(p, TOK_COMMA);
                e[n].value = v;
                sdl_map_colour_into(e[n].c, sdl_colour(p, 1));
                e[n + 1].value = v2;
                sdl_map_colour_into(e[n + 1].c, sdl_colour(p, 1));
                n += 2;
            }
        } else {
            e[n].value = v;
            sdl_map_colour_into(e[n].c, sdl_colour(p, 1));
            n++;
        }
        sdl_expect(p, TOK_RBRACKET, "']' closing the color_map entry");
    }
    if (!map_end(p, n, "must have at least one color in color map")) return NULL;
    /* POV-Ray drops an entry identical to the one before it. */
    int k = 0;
    for (int i = 1; i < n; i++) {
        if (memcmp(&e[k], &e[i], sizeof e[i]) == 0) continue;
        e[++k] = e[i];
    }
    return sdl_map_make(p, MAP_COLOUR, e, k + 1);
}

static const char *map_name(map_kind k)
{
    switch (k) {
    case MAP_PIGMENT: return "pigment_map";
    case MAP_NORMAL: return "normal_map";
    case MAP_TEXTURE: return "texture_map";
    case MAP_SLOPE: return "slope_map";
    default: return "colour_map";
    }
}

/* blend_map := '{' ( map_id | { '[' v [','] entry ']' } ) '}'; `average`
 * allows the value to be omitted (weight 1). */
const scene_blend_map *sdl_map_blend(sdl_parser *p, map_kind k, int average)
{
    const scene_blend_map *declared;
    scene_map_entry *e = map_begin(p, map_name(k), map_name(k), &declared);
    if (!e) return declared;
    int n = 0;
    while (map_next(p, n, 1, "map")) {
        e[n].value = sdl_map_single(average ? sdl_allow_float(p, 1.0) : sdl_float(p));
        sdl_accept(p, TOK_COMMA);
        switch (k) {
        case MAP_PIGMENT: {
            scene_pigment *pg = sdl_dup(p, &p->s->default_texture.pigment, sizeof *pg);
            if (!pg) return NULL;
            sdl_pattern_pigment_body(p, pg);
            e[n].pigment = pg;
            break;
        }
        case MAP_NORMAL:
            e[n].normal = sdl_pattern_normal_body(p, p->s->default_texture.normal);
            break;
        case MAP_TEXTURE:
            e[n].texture = sdl_parse_texture_body(p);
            break;
        case MAP_SLOPE: {
            double hs[2];
            sdl_vector_n(p, hs, 2);
            e[n].height = hs[0];
            e[n].slope = hs[1];
            break;
        }
        default:
            break;
        }
        n++;
        sdl_expect(p, TOK_RBRACKET, "']' closing the map entry");
    }
    if (!map_end(p, n, "must have at least one entry in map")) return NULL;
    return sdl_map_make(p, k, e, n);
}

const scene_blend_map *sdl_map_parse(sdl_parser *p, sdl_kw k)
{
    switch (k) {
    case KW_COLOR_MAP: case KW_COLOUR_MAP: return sdl_map_colour(p);
    case KW_PIGMENT_MAP: return sdl_map_blend(p, MAP_PIGMENT, 0);
    case KW_NORMAL_MAP: return sdl_map_blend(p, MAP_NORMAL, 0);
    case KW_SLOPE_MAP: return sdl_map_blend(p, MAP_SLOPE, 0);
    case KW_TEXTURE_MAP: return sdl_map_blend(p, MAP_TEXTURE, 0);
    default: return NULL;
    }
}

