/* sdl_pattern.c - POV-Ray 3.7 pattern grammar (see sdl_pattern.h).
 *
 * Follows the structure of POV-Ray 3.7's Parse_Pattern, Parse_Blend_List,
 * Parse_Blend_Map, Parse_Colour_Map, Parse_Warp and Check_Turb (semantics
 * studied, not copied): a pattern type comes first (after an optional
 * identifier), then any number of modifiers; listed colours or pigments
 * (checker Red, Blue) make a map with entries at 0, 1, 2...; missing listed
 * entries come from the pattern's default map (or the default pigment /
 * texture); map values are kept in single precision as POV-Ray keeps them;
 * `mortar` is stored less 2e-10, brick/checker/hexagon/... set frequency 0;
 * marble, wood and spirals default to the triangle wave; agate always has a
 * classic turbulence record. Unknown modifiers are skipped with a warning. */
#include "sdl_pattern.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "sdl_directive.h"
#include "sdl_expr.h"
#include "sdl_df3.h"
#include "sdl_function.h"
#include "sdl_image.h"
#include "sdl_map.h"
#include "sdl_material.h"
#include "sdl_object.h"

#define PAT_EPS 1.0e-10

typedef enum { TGT_PIGMENT, TGT_NORMAL, TGT_TEXTURE } tgt_kind;

/* What a pattern block is filling in. */
typedef struct {
    tgt_kind kind;
    scene_pattern *pat;             /* mutable copy, NULL while no pattern type was given */
    const scene_blend_map **map;
    xform *outer;
    scene_pigment *pg;
    scene_normal *nm;
    scene_texture *tx;
    int uv;                         /* uv_mapping given: the pattern gets uv_mapping */
} target;

/* a number kept as POV-Ray keeps it in an unsigned char */
static int uchar_of(double v) { return (int)(unsigned char)sdl_to_int(v); }

/* ------------------------------------------------------------ records */

/* The default normal (amount 0.5, accuracy 0.02, no pattern). */
static void sdl_pattern_default_normal(scene_normal *nm)
{
    memset(nm, 0, sizeof *nm);
    nm->amount = 0.5;
    nm->delta = 0.02;
    nm->transform = xform_identity();
}

static scene_pattern *new_pattern(sdl_parser *p, const scene_pattern *from)
{
    scene_pattern *pt = sdl_alloc(p, sizeof *pt);
    if (!pt) return NULL;
    if (from) {
        *pt = *from;
    } else {
        pt->kind = PAT_PLAIN;
        pt->wave = WAVE_RAMP;
        pt->exponent = 1.0;
        pt->frequency = 1.0;
    }
    return pt;
}

/* A pattern block's target of `kind`: a mutable copy of the pattern it
 * starts from (NULL: none yet; uv_mapping set when uv), the map and the
 * transform it fills; the caller sets the pigment, normal or texture. */
static target target_new(sdl_parser *p, tgt_kind kind, const scene_pattern *pat, const scene_blend_map **map,
                         xform *outer, int uv)
{
    target tg = {.kind = kind, .pat = pat ? new_pattern(p, pat) : NULL, .map = map, .outer = outer, .uv = uv};
    if (uv && tg.pat) tg.pat->uv_mapping = 1;
    return tg;
}

static scene_warp default_turb(void)
{
    scene_warp w = {.kind = WARP_TURBULENCE, .octaves = 6, .omega = 0.5, .lambda = 2.0, .transform = xform_identity()};
    return w;
}

/* Replace the warp array by a copy with room for one more. */
static scene_warp *grow_warps(sdl_parser *p, scene_pattern *pt, int extra)
{
    scene_warp *w = sdl_alloc(p, sizeof *w * (size_t)(pt->nwarps + extra));
    if (!w) return NULL;
    if (pt->nwarps) memcpy(w, pt->warps, sizeof *w * (size_t)pt->nwarps);
    pt->warps = w;
    return w;
}

/* POV-Ray's Check_Turb: the classic turbulence record, appended if the last
 * warp is not one. Returns a mutable pointer (the array is copied). */
static scene_warp *classic_turb(sdl_parser *p, scene_pattern *pt)
{
    if (pt->nwarps > 0 && pt->warps[pt->nwarps - 1].kind == WARP_TURBULENCE && pt->warps[pt->nwarps - 1].classic) {
        scene_warp *w = grow_warps(p, pt, 0);
        return w ? &w[pt->nwarps - 1] : NULL;
    }
    scene_warp *w = grow_warps(p, pt, 1);
    if (!w) return NULL;
    w[pt->nwarps] = default_turb();
    w[pt->nwarps].classic = 1;
    return &w[pt->nwarps++];
}

/* A warp{} goes in front of the list, after the owner's pending transforms
 * (which become a transform warp right behind it). */
static void push_warp(sdl_parser *p, target *tg, const scene_warp *nw)
{
    scene_pattern *pt = tg->pat;
    int has_outer = !xform_is_identity(tg->outer);
    scene_warp *w = sdl_alloc(p, sizeof *w * (size_t)(pt->nwarps + 1 + has_outer));
    if (!w) return;
    int k = 0;
    w[k++] = *nw;
    if (has_outer) {
        scene_warp t;
        memset(&t, 0, sizeof t);
        t.kind = WARP_TRANSFORM;
        t.transform = *tg->outer;
        w[k++] = t;
        *tg->outer = xform_identity();
    }
    if (pt->nwarps) memcpy(w + k, pt->warps, sizeof *w * (size_t)pt->nwarps);
    pt->warps = w;
    pt->nwarps += k;
}

/* ------------------------------------------------------------ images */

static char *try_path(const char *dir, const char *name)
{
    size_t n = (dir ? strlen(dir) + 1 : 0) + strlen(name) + 1;
    char *f = malloc(n);
    if (!f) return NULL;
    if (dir) snprintf(f, n, "%s/%s", dir, name);
    else snprintf(f, n, "%s", name);
    if (access(f, R_OK) == 0) return f;
    free(f);
    return NULL;
}

/* POV-Ray looks for input images in the working directory and then the
 * library paths; we also look next to the file being read. */
static const char *resolve_image(sdl_parser *p, const char *name)
{
    char *found = NULL;
    if (name[0] == '/') {
        found = try_path(NULL, name);
    } else {
        found = try_path(NULL, name);
        if (!found && p->nframes > 0 && p->frames[p->nframes - 1].src && p->frames[p->nframes - 1].src->path) {
            const char *sp = p->frames[p->nframes - 1].src->path;
            const char *slash = strrchr(sp, '/');
            if (slash) {
                char *d = sdl_strndup(p, sp, (size_t)(slash - sp));
                if (d) found = try_path(d, name);
            }
        }
        for (int i = 0; i < p->opt.nlib_paths && !found; i++) found = try_path(p->opt.lib_paths[i], name);
        if (!found && !p->opt.no_default_lib) found = try_path("/usr/share/povray-3.7/include", name);
    }
    if (!found) return NULL;
    const char *r = sdl_strndup(p, found, strlen(found));
    free(found);
    return r;
}

static int is_image_type_kw(sdl_kw k)
{
    switch (k) {
    case KW_GIF: case KW_IFF: case KW_POT: case KW_SYS: case KW_TGA: case KW_PNG: case KW_PGM:
    case KW_PPM: case KW_JPEG: case KW_TIFF: case KW_BMP: case KW_EXR: case KW_HDR:
        return 1;
    default:
        return 0;
    }
}

/* image_spec := [file_type] string [gamma g | premultiplied b] | function w, h { .. } */
/* `data`: the image holds data (image_pattern, bump_map): POV-Ray reads it
 * without gamma handling unless the scene gives the file's gamma. */
static scene_image *image_spec(sdl_parser *p, int data)
{
    const sdl_tok *t = sdl_peek(p);
    src_loc loc = t->tk.loc;
    if (sdl_is_kw(t, KW_FUNCTION)) {
        sdl_next(p);
        sdl_warn_once(p, loc, "function images are not supported; the image is transparent");
        sdl_float(p);
        sdl_accept(p, TOK_COMMA);
        sdl_float(p);
        if (sdl_begin_block(p, "function")) sdl_skip_block(p);
        return NULL;
    }
    if (t->tk.kind == TOK_KEYWORD && is_image_type_kw(t->tk.kw)) sdl_next(p);
    const char *name = sdl_string(p);
    if (!sdl_ok(p) || !name) return NULL;
    scene_image *img = sdl_alloc(p, sizeof *img);
    if (!img) return NULL;
    for (;;) {
        if (sdl_accept_kw(p, KW_GAMMA)) {
            if (sdl_accept_kw(p, KW_SRGB)) img->gamma = -1.0; /* sRGB curve */
            else img->gamma = sdl_float(p);
        } else if (sdl_accept_kw(p, KW_PREMULTIPLIED)) {
            sdl_float(p);
        } else {
            break;
        }
    }
    img->path = resolve_image(p, name);
    if (!img->path && !strchr(name, '.')) {
        /* no extension: POV-Ray tries the file type's extensions */
        static const char *const ext[] = {".png", ".tga", ".jpg", ".jpeg", ".ppm", ".pgm", ".gif", ".bmp", ".tif", ".tiff",
                                          ".exr", ".hdr", ".iff"};
        for (size_t i = 0; i < sizeof ext / sizeof ext[0] && !img->path; i++) {
            char buf[1024];
            snprintf(buf, sizeof buf, "%s%s", name, ext[i]);
            img->path = resolve_image(p, buf);
        }
    }
    if (!img->path) {
        sdl_warning(p, loc, "cannot find image file '%s'; the image is transparent", name);
        return NULL;
    }
    char why[512];
    double wg = p->s->global.assumed_gamma > 0.0 ? p->s->global.assumed_gamma : (p->version < 3.65 ? 0.0 : 1.0);
    /* assumed_gamma in a pre-3.7 scene: files default to the working gamma (sdl_image.h) */
    if (p->s->global.assumed_gamma > 0.0 && p->version < 3.65) wg = -wg;
    if (data) wg = 0.0;
    sdl_hash_file(p, img->path);
    if (sdl_image_load(img, p->s->mem, wg, (unsigned long long)p->opt.max_image_pixels, why, sizeof why) != 0) {
        sdl_warning(p, loc, "%s; the image is transparent", why);
        return NULL;
    }
    img->next = p->s->images;
    p->s->images = img;
    return img;
}

/* Set channel ch (3 filter, 4 transmit) of palette entry reg (-1: every
 * entry) to v in a palette image's decoded pixels (its entries' colours are
 * what the pixels hold, POV-Ray's SetRGBFTIndexedValue). */
static void palette_set(scene_image *img, int reg, int ch, double v)
{
    size_t n = (size_t)img->width * (size_t)img->height;
    for (size_t i = 0; i < n; i++)
        if (reg < 0 || img->indices[i] == reg) img->pixels[i * 5 + (size_t)ch] = (float)v;
    sdl_image_note_clear(img);
}

/* image_map { image_spec { once | interpolate n | map_type n | use_colour |
 *   use_index | repeat uv | offset uv | filter [all] .. | transmit [all] .. } };
 * image_pattern and bump_map (kind 1, 2) the same without filter/transmit,
 * bump_map with bump_size (into *amount). */
static void image_block(sdl_parser *p, scene_image_map *im, int kind, double *amount)
{
    static const char *const names[] = {"image_map", "image_pattern", "bump_map"};
    if (!sdl_begin_block(p, names[kind])) return;
    im->image = image_spec(p, kind != 0);
    im->major_radius = 1.0;
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE)) {
        sdl_tok t = sdl_next(p);
        sdl_kw k = t.tk.kind == TOK_KEYWORD ? t.tk.kw : KW_NONE;
        switch (k) {
        case KW_ONCE: im->once = 1; break;
        case KW_INTERPOLATE:
            /* POV-Ray 3.7 accepts 2 bilinear, 3 bicubic, 4 normalised distance
             * (and 0 for bump_map and image_pattern) */
            im->interpolate = sdl_to_int(sdl_float(p));
            if (im->interpolate < 2 || im->interpolate > 4) {
                if (kind == 0 || im->interpolate != 0) sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "invalid interpolate value %d (2, 3 or 4)", im->interpolate);
            }
            break;
        case KW_MAP_TYPE:
            /* 0 planar, 1 spherical, 2 cylindrical, 5 torus (3.7 refuses the rest) */
            im->map_type = sdl_to_int(sdl_float(p));
            if (im->map_type != 0 && im->map_type != 1 && im->map_type != 2 && im->map_type != 5)
                sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "invalid map_type value %d (0, 1, 2 or 5)", im->map_type);
            break;
        case KW_USE_COLOR: case KW_USE_COLOUR: im->use_index = 0; break;
        case KW_USE_INDEX: im->use_index = kind == 2; break; /* only bump_map heights change (POV-Ray 3.7) */
        case KW_USE_ALPHA: im->use_alpha = 1; break;
        case KW_BUMP_SIZE:
            if (kind == 2 && amount) *amount = sdl_float(p);
            else sdl_unexpected(p, &t, "image modifier");
            break;
        case KW_REPEAT: case KW_OFFSET: {
            double uv[2];
            sdl_vector_n(p, uv, 2);
            if (k == KW_REPEAT) {
                if (uv[0] <= 0.0 || uv[1] <= 0.0) sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "zero or negative image repeat vector");
                im->repeat_u = uv[0];
                im->repeat_v = uv[1];
            } else if (im->image) {
                im->offset_x = -uv[0] * im->image->width;
                im->offset_y = -uv[1] * im->image->height;
            }
            break;
        }
        case KW_FILTER: case KW_TRANSMIT: case KW_ALPHA: {
            int filter = k != KW_TRANSMIT;
            scene_image *img = (scene_image *)im->image; /* this image_map's own copy */
            int indexed = img && img->indices && img->pixels;
            if (sdl_accept_kw(p, KW_ALL)) {
                double v = sdl_float(p);
                if (indexed) {
                    /* palette images: every palette entry gets the value */
                    palette_set(img, -1, filter ? 3 : 4, v);
                } else if (filter) {
                    im->filter_all = v;  /* added to each pixel's own */
                    im->filter_all_set = 1;
                } else {
                    im->transmit_all = v;
                    im->transmit_all_set = 1;
                }
            } else {
                /* filter N, v: palette entry N (POV-Ray rounds N + 0.01 down) */
                src_loc rloc = sdl_peek(p)->tk.loc;
                int reg = sdl_to_int(sdl_float(p) + 0.01);
                sdl_accept(p, TOK_COMMA);
                double v = sdl_float(p);
                if (img && !img->indices) sdl_error(p, rloc, PT_ERR_SYNTAX, "%s of one colour register needs a palette image", filter ? "filter" : "transmit");
                else if (reg < 0 || reg > 255) sdl_error(p, rloc, PT_ERR_SYNTAX, "%s colour register %d out of range", filter ? "filter" : "transmit", reg);
                else if (indexed) palette_set(img, reg, filter ? 3 : 4, v);
            }
            break;
        }
        default:
            sdl_unexpected(p, &t, "image_map modifier");
            break;
        }
    }
    sdl_end_block(p);
}

/* ------------------------------------------------------------ blend lists */

/* Default colours of the listed-pattern maps (POV-Ray's default maps). */
static colour5 list_default_colour(pattern_kind k, int i)
{
    static const double hex[3][3] = {{0, 0, 1}, {0, 1, 0}, {1, 0, 0}};
    static const double cub[6][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {0, 1, 1}, {1, 0, 1}};
    static const double brk[2][3] = {{0.5, 0.5, 0.5}, {0.6, 0.15, 0.15}};
    colour5 c = {0, 0, 0, 0, 0};
    const double *v;
    if (k == PAT_BRICK) v = brk[i % 2];
    else if (k == PAT_CHECKER || k == PAT_HEXAGON) v = hex[i % 3];
    else v = cub[i % 6];
    c.r = sdl_map_single(v[0]);
    c.g = sdl_map_single(v[1]);
    c.b = sdl_map_single(v[2]);
    return c;
}

/* blend_list := { colour [','] } | { pigment {..} [','] } | { normal {..} [','] } |
 *               { texture {..} [','] }, at most `count` items. */
static void blend_list(sdl_parser *p, target *tg, int count)
{
    scene_map_entry *e = sdl_map_entries(p, count);
    if (!e) return;
    int n = 0;
    map_kind mk = MAP_COLOUR;
    if (tg->kind == TGT_PIGMENT) {
        mk = sdl_is_kw(sdl_peek(p), KW_PIGMENT) ? MAP_PIGMENT : MAP_COLOUR;
        while (sdl_ok(p) && n < count) {
            const sdl_tok *t = sdl_peek(p);
            if (mk == MAP_PIGMENT) {
                if (!sdl_accept_kw(p, KW_PIGMENT)) break;
                scene_pigment *pg = sdl_dup(p, &p->s->default_texture.pigment, sizeof *pg);
                if (!pg) return;
                if (sdl_begin_block(p, "pigment")) {
                    sdl_pattern_pigment_body(p, pg);
                    sdl_end_block(p);
                }
                e[n].pigment = pg;
            } else {
                if (!(sdl_starts_colour(t) || sdl_starts_expr(t))) break;
                sdl_map_colour_into(e[n].c, sdl_colour(p, 1));
            }
            sdl_accept(p, TOK_COMMA);
            n++;
        }
    } else if (tg->kind == TGT_NORMAL) {
        mk = MAP_NORMAL;
        while (sdl_ok(p) && n < count && sdl_accept_kw(p, KW_NORMAL)) {
            if (sdl_begin_block(p, "normal")) {
                e[n].normal = sdl_pattern_normal_body(p, p->s->default_texture.normal);
                sdl_end_block(p);
            }
            sdl_accept(p, TOK_COMMA);
            n++;
        }
        if (n == 0) {
            *tg->map = NULL;
            return;
        }
    } else {
        mk = MAP_TEXTURE;
        while (sdl_ok(p) && n < count && sdl_accept_kw(p, KW_TEXTURE)) {
            e[n].texture = sdl_parse_texture(p);
            sdl_accept(p, TOK_COMMA);
            n++;
        }
    }
    for (int i = 0; i < count; i++) {
        e[i].value = i;
        if (i < n) continue;
        switch (mk) {
        case MAP_COLOUR: sdl_map_colour_into(e[i].c, list_default_colour(tg->pat->kind, i)); break;
        case MAP_PIGMENT: {
            scene_pigment *pg = sdl_alloc(p, sizeof *pg);
            if (pg) *pg = p->s->default_texture.pigment;
            e[i].pigment = pg;
            break;
        }
        case MAP_NORMAL: e[i].normal = p->s->default_texture.normal; break;
        case MAP_TEXTURE: {
            scene_texture *t = sdl_copy_texture(p, &p->s->default_texture);
            if (t) t->transform = xform_identity();
            e[i].texture = t;
            break;
        }
        default: break;
        }
    }
    *tg->map = sdl_map_make(p, mk, e, count);
}

/* ------------------------------------------------------------ warps */

/* warp := '{' ( turbulence v {octaves|omega|lambda} | repeat v {offset v|flip v} |
 *   black_hole v, r {strength|falloff|inverse|type|repeat v|turbulence v} |
 *   cylindrical|spherical|toroidal {orientation v|dist_exp f|major_radius f} |
 *   planar [v, f] | cubic ) '}' */
static void warp_block(sdl_parser *p, target *tg)
{
    src_loc loc = sdl_peek(p)->tk.loc;
    if (!sdl_begin_block(p, "warp")) return;
    scene_warp w = {.transform = xform_identity(), .orientation = v3(0, 0, 1), .major_radius = 1.0};
    sdl_tok t = sdl_next(p);
    sdl_kw k = t.tk.kind == TOK_KEYWORD ? t.tk.kw : KW_NONE;
    switch (k) {
    case KW_TURBULENCE:
        w = default_turb();
        w.turbulence = sdl_vector(p);
        for (;;) {
            if (sdl_accept_kw(p, KW_OCTAVES)) {
                w.octaves = sdl_to_int(sdl_float(p));
                if (w.octaves < 1) w.octaves = 1;
                if (w.octaves > 10) w.octaves = 10;
            } else if (sdl_accept_kw(p, KW_OMEGA)) {
                w.omega = sdl_float(p);
            } else if (sdl_accept_kw(p, KW_LAMBDA)) {
                w.lambda = sdl_float(p);
            } else {
                break;
            }
        }
        break;
    case KW_REPEAT: {
        w.kind = WARP_REPEAT;
        vec3 v = sdl_vector(p);
        w.axis = -1;
        double c[3] = {v.x, v.y, v.z};
        for (int i = 0; i < 3; i++) {
            if (c[i] == 0.0) continue;
            if (w.axis >= 0) sdl_error(p, loc, PT_ERR_SYNTAX, "can only repeat along 1 axis");
            w.axis = i;
        }
        if (w.axis < 0) {
            sdl_error(p, loc, PT_ERR_SYNTAX, "no axis specified in repeat");
            w.axis = 0;
        }
        w.width = c[w.axis];
        w.flip = v3(1, 1, 1);
        for (;;) {
            if (sdl_accept_kw(p, KW_OFFSET)) {
                w.offset = sdl_vector(p);
            } else if (sdl_accept_kw(p, KW_FLIP)) {
                vec3 f = sdl_vector(p);
                w.flip = v3(f.x != 0.0 ? -1.0 : 1.0, f.y != 0.0 ? -1.0 : 1.0, f.z != 0.0 ? -1.0 : 1.0);
            } else {
                break;
            }
        }
        break;
    }
    case KW_BLACK_HOLE:
        w.kind = WARP_BLACK_HOLE;
        w.centre = sdl_vector(p);
        sdl_accept(p, TOK_COMMA);
        w.radius = sdl_float(p);
        w.strength = 1.0;
        w.power = 2.0;
        for (;;) {
            if (sdl_accept_kw(p, KW_STRENGTH)) w.strength = sdl_float(p);
            else if (sdl_accept_kw(p, KW_FALLOFF)) w.power = sdl_float(p);
            else if (sdl_accept_kw(p, KW_INVERSE)) w.inverted = 1;
            else if (sdl_accept_kw(p, KW_TYPE)) w.bh_type = sdl_to_int(sdl_float(p));
            else if (sdl_accept_kw(p, KW_REPEAT)) {
                w.repeat_vec = sdl_vector(p);
                w.bh_repeat = 1;
            } else if (sdl_accept_kw(p, KW_TURBULENCE)) {
                w.uncertainty = sdl_vector(p);
                w.uncertain = 1;
            } else {
                break;
            }
        }
        break;
    case KW_CYLINDRICAL: case KW_SPHERICAL: case KW_TOROIDAL:
        w.kind = k == KW_CYLINDRICAL ? WARP_CYLINDRICAL : (k == KW_SPHERICAL ? WARP_SPHERICAL : WARP_TOROIDAL);
        for (;;) {
            if (sdl_accept_kw(p, KW_ORIENTATION)) w.orientation = v3_norm(sdl_vector(p));
            else if (sdl_accept_kw(p, KW_DIST_EXP)) w.dist_exp = sdl_float(p);
            else if (k == KW_TOROIDAL && sdl_accept_kw(p, KW_MAJOR_RADIUS)) w.major_radius = sdl_float(p);
            else break;
        }
        break;
    case KW_PLANAR:
        w.kind = WARP_PLANAR;
        if (sdl_starts_expr(sdl_peek(p))) {
            w.orientation = v3_norm(sdl_vector(p));
            sdl_accept(p, TOK_COMMA);
            w.plane_offset = sdl_float(p);
        }
        break;
    case KW_CUBIC: w.kind = WARP_CUBIC; break;
    default:
        sdl_unexpected(p, &t, "warp type");
        return;
    }
    sdl_end_block(p);
    if (sdl_ok(p) && tg->pat) push_warp(p, tg, &w);
}

/* ------------------------------------------------------------ pattern types */

static const char *kw_name(sdl_kw k) { return sdl_kw_text(k); }

int sdl_pattern_is_type(sdl_kw k)
{
    switch (k) {
    case KW_AGATE: case KW_AOI: case KW_AVERAGE: case KW_BOXED: case KW_BOZO: case KW_BRICK:
    case KW_BUMPS: case KW_CELLS: case KW_CHECKER: case KW_CRACKLE: case KW_CUBIC: case KW_CYLINDRICAL:
    case KW_DENSITY_FILE: case KW_DENTS: case KW_FACETS: case KW_FUNCTION: case KW_GRADIENT:
    case KW_GRANITE: case KW_HEXAGON: case KW_IMAGE_MAP: case KW_IMAGE_PATTERN: case KW_JULIA:
    case KW_LEOPARD: case KW_MAGNET: case KW_MANDEL: case KW_MARBLE: case KW_OBJECT: case KW_ONION:
    case KW_PAVEMENT: case KW_PIGMENT_PATTERN: case KW_PLANAR: case KW_QUILTED: case KW_RADIAL:
    case KW_RIPPLES: case KW_SLOPE: case KW_SPHERICAL: case KW_SPIRAL1: case KW_SPIRAL2: case KW_SPOTTED:
    case KW_SQUARE: case KW_TILING: case KW_TRIANGULAR: case KW_WAVES: case KW_WOOD: case KW_WRINKLES:
    case KW_BUMP_MAP: case KW_UV_MAPPING:
        return 1;
    default:
        return 0;
    }
}

/* Kinds whose value frequency does not scale (their value picks a list
 * entry, or is an image's, an object's or quilted's own): POV-Ray 3.7's
 * Parse_Pattern (parstxtr.cpp) sets their Frequency to 0 when the kind is
 * named, before any `frequency` modifier. */
static int kind_without_frequency(pattern_kind k)
{
    switch (k) {
    case PAT_QUILTED: case PAT_CHECKER: case PAT_HEXAGON: case PAT_SQUARE: case PAT_TRIANGULAR: case PAT_CUBIC:
    case PAT_BRICK: case PAT_IMAGE: case PAT_OBJECT:
        return 1;
    default:
        return 0;
    }
}

static void set_kind(target *tg, pattern_kind k, const char *name)
{
    tg->pat->kind = k;
    tg->pat->name = name;
    if (kind_without_frequency(k)) tg->pat->frequency = 0.0;
}

static void unsupported_pattern(sdl_parser *p, target *tg, const sdl_tok *t)
{
    set_kind(tg, PAT_UNSUPPORTED, kw_name(t->tk.kw));
    sdl_warn_once(p, t->tk.loc, "pattern '%s' is not supported; it evaluates to 0", kw_name(t->tk.kw));
}

/* Skip the arguments of an unsupported pattern: floats/vectors and blocks. */
static void skip_args(sdl_parser *p)
{
    for (;;) {
        const sdl_tok *t = sdl_peek(p);
        if (sdl_is(t, TOK_LBRACE)) {
            if (sdl_begin_block(p, "pattern argument")) sdl_skip_block(p);
        } else if (sdl_starts_expr(t)) {
            sdl_value v;
            sdl_sum(p, &v);
            sdl_accept(p, TOK_COMMA);
        } else {
            return;
        }
        if (!sdl_ok(p)) return;
    }
}

/* slope's and altitude's `v [, lo [, hi]]`: the vector, and in *lo and
 * *hi the range's start and width (POV-Ray: an empty range, lo == hi != 0,
 * is ignored: both 0). */
static vec3 slope_range(sdl_parser *p, double *lo, double *hi)
{
    vec3 v = sdl_vector(p);
    sdl_accept(p, TOK_COMMA);
    *lo = sdl_allow_float(p, 0.0);
    sdl_accept(p, TOK_COMMA);
    *hi = sdl_allow_float(p, 0.0);
    if (*hi != 0.0 && *hi == *lo) *lo = *hi = 0.0;
    else *hi -= *lo;
    return v;
}

/* pattern_type: the keyword is next. Returns 1 if one was parsed. */
static int pattern_type(sdl_parser *p, target *tg)
{
    const sdl_tok *pk = sdl_peek(p);
    if (pk->tk.kind != TOK_KEYWORD || !sdl_pattern_is_type(pk->tk.kw)) return 0;
    sdl_tok t = sdl_next(p);
    sdl_kw k = t.tk.kw;
    if (k == KW_UV_MAPPING) {
        /* POV-Ray 3.7 (parstxtr.cpp): UV_MAP_PATTERN holding the item that
         * follows; here the pattern that follows is marked instead */
        tg->uv = 1;
        if (tg->pat) tg->pat->uv_mapping = 1;
        pk = sdl_peek(p);
        if (pk->tk.kind != TOK_KEYWORD || !sdl_pattern_is_type(pk->tk.kw) || pk->tk.kw == KW_UV_MAPPING) return 1;
        t = sdl_next(p);
        k = t.tk.kw;
    }
    if (!tg->pat) tg->pat = new_pattern(p, NULL);
    else tg->pat = new_pattern(p, tg->pat);
    scene_pattern *pt = tg->pat;
    if (!pt) return 1;
    if (tg->uv) pt->uv_mapping = 1;
    pattern_kind old = pt->kind;
    const char *name = kw_name(k);
    switch (k) {
    case KW_AGATE:
        set_kind(tg, PAT_AGATE, name);
        classic_turb(p, pt);
        pt->agate_turb = 1.0;
        break;
    case KW_BOZO: set_kind(tg, PAT_BOZO, name); break;
    case KW_SPOTTED: set_kind(tg, PAT_SPOTTED, name); break;
    case KW_GRANITE: set_kind(tg, PAT_GRANITE, name); break;
    case KW_LEOPARD: set_kind(tg, PAT_LEOPARD, name); break;
    case KW_ONION: set_kind(tg, PAT_ONION, name); break;
    case KW_RADIAL: set_kind(tg, PAT_RADIAL, name); break;
    case KW_CELLS: set_kind(tg, PAT_CELLS, name); break;
    case KW_WAVES: set_kind(tg, PAT_WAVES, name); break;
    case KW_RIPPLES: set_kind(tg, PAT_RIPPLES, name); break;
    case KW_WRINKLES: set_kind(tg, PAT_WRINKLES, name); break;
    case KW_BUMPS: set_kind(tg, PAT_BUMPS, name); break;
    case KW_DENTS: set_kind(tg, PAT_DENTS, name); break;
    case KW_PLANAR: set_kind(tg, PAT_PLANAR, name); break;
    case KW_BOXED: set_kind(tg, PAT_BOXED, name); break;
    case KW_SPHERICAL: set_kind(tg, PAT_SPHERICAL, name); break;
    case KW_CYLINDRICAL: set_kind(tg, PAT_CYLINDRICAL, name); break;
    case KW_AVERAGE: set_kind(tg, PAT_AVERAGE, name); break;
    case KW_AOI: set_kind(tg, PAT_AOI, name); break;
    case KW_MARBLE:
        set_kind(tg, PAT_MARBLE, name);
        pt->wave = WAVE_TRIANGLE;
        break;
    case KW_WOOD:
        set_kind(tg, PAT_WOOD, name);
        pt->wave = WAVE_TRIANGLE;
        break;
    case KW_SPIRAL1: case KW_SPIRAL2:
        set_kind(tg, k == KW_SPIRAL1 ? PAT_SPIRAL1 : PAT_SPIRAL2, name);
        pt->arms = (short)sdl_float(p);
        pt->wave = WAVE_TRIANGLE;
        break;
    case KW_GRADIENT:
        set_kind(tg, PAT_GRADIENT, name);
        pt->gradient = v3_norm(sdl_vector(p));
        break;
    case KW_CRACKLE:
        set_kind(tg, PAT_CRACKLE, name);
        pt->crackle_solid = 0;
        pt->crackle_form = v3(-1, 1, 0);
        pt->crackle_metric = 2;
        pt->crackle_offset = 0;
        break;
    case KW_QUILTED:
        set_kind(tg, PAT_QUILTED, name);
        pt->control0 = 1.0;
        pt->control1 = 1.0;
        break;
    case KW_FACETS:
        set_kind(tg, PAT_FACETS, name);
        pt->facets_size = 0.1;
        pt->facets_metric = 2;
        if (tg->kind != TGT_NORMAL) sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "facets can only be used in normal");
        break;
    case KW_CHECKER: case KW_HEXAGON: case KW_SQUARE: case KW_TRIANGULAR: case KW_CUBIC: case KW_BRICK: {
        pattern_kind pk2 = k == KW_CHECKER ? PAT_CHECKER : k == KW_HEXAGON ? PAT_HEXAGON : k == KW_SQUARE ? PAT_SQUARE
                         : k == KW_TRIANGULAR ? PAT_TRIANGULAR : k == KW_CUBIC ? PAT_CUBIC : PAT_BRICK;
        int count = k == KW_CHECKER || k == KW_BRICK ? 2 : k == KW_HEXAGON ? 3 : k == KW_SQUARE ? 4 : 6;
        if (pk2 == PAT_BRICK && old != PAT_BRICK) {
            pt->brick_size = v3(8.0, 3.0, 4.5);
            pt->mortar = 0.5 - PAT_EPS * 2.0;
        }
        set_kind(tg, pk2, name);
        blend_list(p, tg, count);
        break;
    }
    case KW_IMAGE_MAP:
        set_kind(tg, PAT_IMAGE, name);
        if (tg->kind != TGT_PIGMENT) sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "image_map can only be used in pigment");
        image_block(p, &pt->image, 0, NULL);
        break;
    case KW_IMAGE_PATTERN:
        set_kind(tg, PAT_IMAGE, name);
        image_block(p, &pt->image, 1, NULL);
        break;
    case KW_BUMP_MAP:
        set_kind(tg, PAT_IMAGE, name);
        if (tg->kind != TGT_NORMAL) sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "bump_map can only be used in normal");
        image_block(p, &pt->image, 2, tg->nm ? &tg->nm->amount : NULL);
        break;
    case KW_PIGMENT_PATTERN: {
        set_kind(tg, PAT_PIGMENT, name);
        scene_pigment *sub = sdl_alloc(p, sizeof *sub);
        if (!sub) return 1;
        scene_default_pigment(sub);
        if (sdl_begin_block(p, "pigment_pattern")) {
            sdl_pattern_pigment_body(p, sub);
            sdl_end_block(p);
        }
        pt->pigment = sub;
        break;
    }
    case KW_SLOPE: {
        /* slope := v | '{' [point_at] v [, lo [, hi]] [altitude v [, lo [, hi]]] '}' */
        set_kind(tg, PAT_SLOPE, name);
        pt->slope_lo = pt->slope_hi = pt->altit_lo = pt->altit_hi = 0.0;
        pt->slope_point_at = 0;
        vec3 sv = v3(0, 0, 0), av = v3(0, 0, 0);
        if (sdl_is(sdl_peek(p), TOK_LBRACE)) {
            sdl_begin_block(p, "slope");
            pt->slope_point_at = sdl_accept_kw(p, KW_POINT_AT);
            sv = slope_range(p, &pt->slope_lo, &pt->slope_hi);
            if (sdl_accept_kw(p, KW_ALTITUDE)) {
                if (pt->slope_point_at) sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "'altitude' cannot be used with 'point_at' in slope pattern");
                av = slope_range(p, &pt->altit_lo, &pt->altit_hi);
            }
            sdl_end_block(p);
        } else {
            sv = sdl_vector(p);
        }
        if (pt->slope_point_at) {
            pt->slope_dir = sv;
            pt->slope_len = 1.0;
            pt->altit_len = 0.0;
        } else {
            pt->slope_len = v3_len(sv);
            pt->altit_len = v3_len(av);
            pt->slope_dir = pt->slope_len != 0.0 ? v3_scale(sv, 1.0 / pt->slope_len) : sv;
            pt->altit_dir = pt->altit_len != 0.0 ? v3_scale(av, 1.0 / pt->altit_len) : av;
            double tot = pt->slope_len + pt->altit_len;
            if (tot == 0.0) {
                sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "zero length for both slope and gradient");
            } else {
                pt->slope_len /= tot;
                pt->altit_len = 1.0 - pt->slope_len;
            }
        }
        break;
    }
    case KW_OBJECT: {
        /* object { object-or-identifier [list entries] }: 1 inside, 0
         * outside (POV-Ray 3.7's object pattern; the two listed entries
         * stand inside the braces) */
        set_kind(tg, PAT_OBJECT, name);
        pt->object = NULL;
        if (!sdl_begin_block(p, "object")) break;
        sdl_obj *so = sdl_parse_object_body(p);
        if (so && so->obj) {
            pt->object = so->obj;
            pt->object_serial = p->s->serial;
        }
        else if (sdl_ok(p)) sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "object or object identifier expected");
        blend_list(p, tg, 2);
        sdl_end_block(p);
        break;
    }
    case KW_FUNCTION:
        /* function { body }: a user function of x, y, z (sdl_function.c) */
        set_kind(tg, PAT_FUNCTION, name);
        pt->function = sdl_parse_function(p, t.tk.loc, NULL);
        if (!pt->function) set_kind(tg, PAT_UNSUPPORTED, name);
        break;
    case KW_DENSITY_FILE: {
        /* density_file df3 "file": read now, as POV-Ray does */
        set_kind(tg, PAT_DENSITY, name);
        pt->density = NULL;
        pt->density_interpolate = 0;
        if (!sdl_accept_kw(p, KW_DF3)) {
            sdl_error(p, sdl_peek(p)->tk.loc, PT_ERR_SYNTAX, "df3 expected after density_file");
            break;
        }
        src_loc floc = sdl_peek(p)->tk.loc;
        const char *file = sdl_string(p);
        if (!sdl_ok(p) || !file) break;
        const char *path = resolve_image(p, file);
        if (!path) {
            sdl_error(p, floc, PT_ERR_IO, "cannot find density file '%s'", file);
            break;
        }
        scene_density *d = sdl_alloc(p, sizeof *d);
        char why[512];
        sdl_hash_file(p, path);
        if (d && sdl_df3_load(d, path, p->s->mem, why, sizeof why) != 0) {
            sdl_error(p, floc, PT_ERR_IO, "%s", why);
            break;
        }
        pt->density = d;
        break;
    }
    case KW_TILING: {
        set_kind(tg, PAT_TILING, name);
        double n = sdl_float(p);
        /* POV-Ray keeps the number as an unsigned char; 0 and values past
         * 27 give the square tiling */
        pt->tiling = (int)(unsigned char)sdl_to_int(n);
        if (pt->tiling < 1 || pt->tiling > 27) pt->tiling = 1;
        break;
    }
    case KW_MANDEL: case KW_JULIA: case KW_MAGNET: {
        /* mandel N | julia <c>, N | magnet 1|2 ( mandel N | julia <c>, N ) */
        pt->magnet = 0;
        if (k == KW_MAGNET) {
            pt->magnet = sdl_to_int(sdl_float(p));
            if (pt->magnet != 1 && pt->magnet != 2) sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "invalid magnet pattern type (1 or 2)");
            if (sdl_accept_kw(p, KW_MANDEL)) {
                k = KW_MANDEL;
            } else if (sdl_accept_kw(p, KW_JULIA)) {
                k = KW_JULIA;
            } else {
                sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "invalid magnet pattern: 'mandel' or 'julia' expected");
                break;
            }
        }
        set_kind(tg, k == KW_MANDEL ? PAT_MANDEL : PAT_JULIA, name);
        if (k == KW_JULIA) {
            sdl_vector_n(p, pt->julia_c, 2);
            sdl_accept(p, TOK_COMMA);
        }
        pt->iterations = sdl_to_int(sdl_float(p));
        pt->fractal_exponent = pt->magnet ? 0 : 2;
        pt->interior_type = 0;
        pt->exterior_type = 1;
        pt->ifactor = pt->efactor = 1.0;
        break;
    }
    case KW_PAVEMENT:
        /* POV-Ray 3.7 parstxtr.cpp: triangles, one tile, pattern 1, sharp */
        set_kind(tg, PAT_PAVEMENT, name);
        pt->pave_sides = 3;
        pt->pave_tiles = 1;
        pt->pave_number = 1;
        pt->pave_exterior = pt->pave_interior = pt->pave_form = 0;
        break;
    default: /* julia, mandel, pavement, tiling */
        unsupported_pattern(p, tg, &t);
        skip_args(p);
        break;
    }
    return 1;
}

/* ------------------------------------------------------------ modifiers */

static void need_pattern(sdl_parser *p, target *tg)
{
    if (!tg->pat) tg->pat = new_pattern(p, NULL);
}

/* One pattern modifier; 0 if the next token is not one. */
static int modifier(sdl_parser *p, target *tg)
{
    xform x;
    if (sdl_transform_item(p, &x)) {
        *tg->outer = xform_then(*tg->outer, x);
        return 1;
    }
    const sdl_tok *pk = sdl_peek(p);
    if (pk->tk.kind != TOK_KEYWORD) return 0;
    sdl_kw k = pk->tk.kw;
    switch (k) {
    case KW_TURBULENCE: case KW_OCTAVES: case KW_OMEGA: case KW_LAMBDA: case KW_FREQUENCY: case KW_PHASE:
    case KW_RAMP_WAVE: case KW_TRIANGLE_WAVE: case KW_SINE_WAVE: case KW_SCALLOP_WAVE: case KW_CUBIC_WAVE:
    case KW_POLY_WAVE: case KW_NOISE_GENERATOR: case KW_WARP: case KW_AGATE_TURB: case KW_BRICK_SIZE:
    case KW_MORTAR: case KW_CONTROL0: case KW_CONTROL1: case KW_FORM: case KW_METRIC: case KW_OFFSET:
    case KW_SOLID: case KW_COORDS: case KW_SIZE:
        break;
    case KW_COLOR_MAP: case KW_COLOUR_MAP: case KW_PIGMENT_MAP: case KW_NORMAL_MAP: case KW_SLOPE_MAP:
    case KW_TEXTURE_MAP: case KW_QUICK_COLOR: case KW_QUICK_COLOUR: case KW_BUMP_SIZE: case KW_ACCURACY:
    case KW_NO_BUMP_SCALE: case KW_DENSITY_MAP: case KW_INTERPOLATE: case KW_EXTERIOR: case KW_INTERIOR:
    case KW_MAX_ITERATION: case KW_NUMBER_OF_SIDES: case KW_NUMBER_OF_TILES: case KW_PATTERN: case KW_EXPONENT:
        break;
    default:
        return 0;
    }
    sdl_tok t = sdl_next(p);
    switch (k) {
    case KW_TURBULENCE: case KW_OCTAVES: case KW_OMEGA: case KW_LAMBDA: {
        need_pattern(p, tg);
        scene_warp *w = classic_turb(p, tg->pat);
        if (!w) return 1;
        if (k == KW_TURBULENCE) {
            w->turbulence = sdl_vector(p);
        } else if (k == KW_OCTAVES) {
            w->octaves = sdl_to_int(sdl_float(p));
            if (w->octaves < 1) w->octaves = 1;
            if (w->octaves > 10) w->octaves = 10;
        } else if (k == KW_OMEGA) {
            w->omega = sdl_float(p);
        } else {
            w->lambda = sdl_float(p);
        }
        return 1;
    }
    case KW_WARP:
        need_pattern(p, tg);
        warp_block(p, tg);
        return 1;
    case KW_COLOR_MAP: case KW_COLOUR_MAP:
        *tg->map = sdl_map_colour(p);
        return 1;
    case KW_PIGMENT_MAP:
        *tg->map = sdl_map_blend(p, MAP_PIGMENT, tg->pat && tg->pat->kind == PAT_AVERAGE);
        return 1;
    case KW_NORMAL_MAP:
        *tg->map = sdl_map_blend(p, MAP_NORMAL, tg->pat && tg->pat->kind == PAT_AVERAGE);
        return 1;
    case KW_SLOPE_MAP:
        *tg->map = sdl_map_blend(p, MAP_SLOPE, 0);
        return 1;
    case KW_TEXTURE_MAP:
        *tg->map = sdl_map_blend(p, MAP_TEXTURE, tg->pat && tg->pat->kind == PAT_AVERAGE);
        return 1;
    case KW_DENSITY_MAP: /* entries are density bodies: pigment bodies (sdl_media.c) */
        *tg->map = sdl_map_blend(p, MAP_PIGMENT, tg->pat && tg->pat->kind == PAT_AVERAGE);
        return 1;
    case KW_QUICK_COLOR: case KW_QUICK_COLOUR:
        sdl_colour(p, 1);
        return 1;
    case KW_BUMP_SIZE:
        if (tg->nm) tg->nm->amount = sdl_float(p);
        else sdl_float(p);
        return 1;
    case KW_ACCURACY:
        if (tg->nm) tg->nm->delta = sdl_float(p);
        else sdl_float(p);
        return 1;
    case KW_NO_BUMP_SCALE:
        if (tg->nm) tg->nm->no_bump_scale = 1;
        return 1;
    default:
        break;
    }
    need_pattern(p, tg);
    scene_pattern *pt = tg->pat;
    if (!pt) return 1;
    switch (k) {
    case KW_FREQUENCY: pt->frequency = sdl_float(p); break;
    case KW_PHASE: pt->phase = sdl_float(p); break;
    case KW_RAMP_WAVE: pt->wave = WAVE_RAMP; break;
    case KW_TRIANGLE_WAVE: pt->wave = WAVE_TRIANGLE; break;
    case KW_SINE_WAVE: pt->wave = WAVE_SINE; break;
    case KW_SCALLOP_WAVE: pt->wave = WAVE_SCALLOP; break;
    case KW_CUBIC_WAVE: pt->wave = WAVE_CUBIC; break;
    case KW_POLY_WAVE:
        pt->wave = WAVE_POLY;
        pt->exponent = sdl_allow_float(p, pt->exponent);
        break;
    case KW_NOISE_GENERATOR: {
        int g = sdl_to_int(sdl_float(p));
        if (g < 0 || g > 3) sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "value for noise_generator must be 0, 1, 2, or 3");
        pt->noise_generator = g;
        break;
    }
    case KW_AGATE_TURB:
        pt->agate_turb = sdl_float(p);
        classic_turb(p, pt);
        break;
    case KW_BRICK_SIZE: pt->brick_size = sdl_vector(p); break;
    case KW_MORTAR: pt->mortar = sdl_float(p) - PAT_EPS * 2.0; break;
    case KW_CONTROL0: pt->control0 = sdl_float(p); break;
    case KW_CONTROL1: pt->control1 = sdl_float(p); break;
    case KW_FORM:
        if (pt->kind == PAT_CRACKLE) pt->crackle_form = sdl_vector(p);
        else if (pt->kind == PAT_PAVEMENT) pt->pave_form = uchar_of(sdl_float(p));
        else sdl_float(p);
        break;
    case KW_METRIC: {
        vec3 m = sdl_vector(p);
        if (pt->kind == PAT_FACETS) pt->facets_metric = m.x;
        else pt->crackle_metric = m.x;
        break;
    }
    case KW_OFFSET: pt->crackle_offset = sdl_float(p); break;
    case KW_SOLID: pt->crackle_solid = 1; break;
    case KW_COORDS: pt->facets_coords = sdl_float(p); break;
    case KW_SIZE: pt->facets_size = sdl_float(p); break;
    case KW_EXTERIOR: case KW_INTERIOR: {
        if (pt->kind == PAT_PAVEMENT) { /* one number for pavement */
            int v = uchar_of(sdl_float(p));
            if (k == KW_EXTERIOR) pt->pave_exterior = v;
            else pt->pave_interior = v;
            break;
        }
        int type = sdl_to_int(sdl_float(p));
        sdl_accept(p, TOK_COMMA);
        double f = sdl_float(p);
        if (pt->kind == PAT_MANDEL || pt->kind == PAT_JULIA) {
            int max = k == KW_EXTERIOR ? 8 : 6;
            if (type < 0 || type > max) sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "invalid fractal pattern %s type (0 to %d)", sdl_kw_text(k), max);
            if (k == KW_EXTERIOR) {
                pt->exterior_type = type;
                pt->efactor = f;
            } else {
                pt->interior_type = type;
                pt->ifactor = f;
            }
        }
        break;
    }
    case KW_EXPONENT: {
        int e = sdl_to_int(sdl_float(p));
        if ((pt->kind != PAT_MANDEL && pt->kind != PAT_JULIA) || pt->magnet) {
            sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "exponent can only be used with mandel or julia");
        } else if (e < 2 || e > 33) {
            sdl_warning(p, t.tk.loc, "invalid %s pattern exponent (2 to 33); using 2", pt->name);
            pt->fractal_exponent = 2;
        } else {
            pt->fractal_exponent = e;
        }
        break;
    }
    case KW_INTERPOLATE:
        if (pt->kind != PAT_DENSITY) sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "interpolate cannot be used with non-density_file");
        pt->density_interpolate = sdl_to_int(sdl_float(p));
        break;
    case KW_NUMBER_OF_SIDES: case KW_NUMBER_OF_TILES: case KW_PATTERN: {
        int v = uchar_of(sdl_float(p));
        if (pt->kind != PAT_PAVEMENT) break;
        if (k == KW_NUMBER_OF_SIDES) pt->pave_sides = v;
        else if (k == KW_NUMBER_OF_TILES) pt->pave_tiles = v;
        else pt->pave_number = v;
        break;
    }
    default: /* max_iteration */
        sdl_float(p);
        break;
    }
    return 1;
}

/* The pavings POV-Ray 3.7 defines for number_of_sides and number_of_tiles
 * (its pattern.cpp tables; the documentation's table of pavement
 * patterns): how many pattern numbers exist, 0 where the number is not
 * used (one tile; two triangles or squares; counts other than 1-6). */
static int pavement_patterns(int sides, int tiles)
{
    static const int tri[7] = {0, 0, 0, 1, 3, 4, 12};
    static const int sq[7] = {0, 0, 0, 2, 5, 12, 35};
    static const int hex[7] = {1, 1, 1, 3, 7, 22, 1};
    if (sides == 6) return tiles >= 1 && tiles <= 5 ? hex[tiles] : 1; /* others: one hexagon */
    if (tiles < 1 || tiles > 6) return 0;
    return sides == 4 ? sq[tiles] : tri[tiles];
}

/* A pattern number the paving does not have is an error (POV-Ray reads
 * past its tables there). */
static void check_pavement(sdl_parser *p, const scene_pattern *pt, src_loc loc)
{
    if (!pt || pt->kind != PAT_PAVEMENT) return;
    int n = pavement_patterns(pt->pave_sides, pt->pave_tiles);
    if (n > 0 && (pt->pave_number < 1 || pt->pave_number > n)) {
        int sides = pt->pave_sides == 4 || pt->pave_sides == 6 ? pt->pave_sides : 3;
        sdl_error(p, loc, PT_ERR_SYNTAX, "pavement with number_of_sides %d and number_of_tiles %d has patterns 1 to %d, not %d",
                  sides, pt->pave_tiles, n, pt->pave_number);
    }
}

/* Modifiers until the block's end; anything else is skipped with a warning. */
static void modifiers(sdl_parser *p, target *tg, const char *what)
{
    while (sdl_ok(p)) {
        const sdl_tok *t = sdl_peek(p);
        if (sdl_is(t, TOK_RBRACE) || sdl_is(t, TOK_RBRACKET) || sdl_is(t, TOK_EOF)) {
            check_pavement(p, tg->pat, t->tk.loc);
            return;
        }
        if (modifier(p, tg)) continue;
        sdl_tok bad = sdl_next(p);
        if (bad.tk.kind == TOK_KEYWORD) {
            sdl_warn_once(p, bad.tk.loc, "%s modifier '%s' is not supported and is ignored", what, sdl_kw_text(bad.tk.kw));
            sdl_skip_item(p);
        } else {
            sdl_unexpected(p, &bad, what);
            return;
        }
    }
}

/* ------------------------------------------------------------ pigments */

static colour5 first_colour(const scene_blend_map *m, colour5 fallback)
{
    if (!m || m->n == 0) return fallback;
    if (m->kind == MAP_COLOUR) {
        colour5 c = {m->e[0].c[0], m->e[0].c[1], m->e[0].c[2], m->e[0].c[3], m->e[0].c[4]};
        return c;
    }
    if (m->kind == MAP_PIGMENT && m->e[0].pigment) return m->e[0].pigment->colour;
    return fallback;
}

void sdl_pattern_pigment_body(sdl_parser *p, scene_pigment *pg)
{
    int uv = sdl_accept_kw(p, KW_UV_MAPPING);
    const sdl_tok *t = sdl_peek(p);
    /* a declared density (sdl_media.c) starts a density body as a pigment does */
    if (t->tk.kind == TOK_IDENT && t->val.ptr &&
        (t->val.kind == VAL_PIGMENT || (t->val.kind == VAL_OPAQUE && t->val.str && strcmp(t->val.str, "density") == 0))) {
        sdl_tok id = sdl_next(p);
        *pg = *(const scene_pigment *)id.val.ptr;
        t = sdl_peek(p);
    }
    target tg = target_new(p, TGT_PIGMENT, pg->pat, &pg->map, &pg->transform, uv);
    tg.pg = pg;
    if (sdl_starts_colour(t) || sdl_is(t, TOK_LT)) {
        pg->colour = sdl_colour(p, 1);
        pg->kind = PIGMENT_SOLID;
        pg->pattern = NULL;
        pg->pat = NULL;
        pg->map = NULL;
        tg.pat = NULL;
    } else {
        pattern_type(p, &tg);
    }
    modifiers(p, &tg, "pigment");
    if (pg->kind == PIGMENT_SOLID && (!tg.pat || tg.pat->kind == PAT_PLAIN)) {
        pg->pat = NULL;
        return;
    }
    if (tg.pat && tg.pat->kind != PAT_PLAIN) {
        pg->pat = tg.pat;
        pg->pattern = tg.pat->name;
        pg->kind = tg.pat->kind == PAT_UNSUPPORTED ? PIGMENT_OTHER : PIGMENT_PATTERN;
        if (pg->map && pg->map->kind != MAP_COLOUR && pg->map->kind != MAP_PIGMENT) pg->map = NULL;
        const scene_blend_map *m = pg->map;
        if (!m && tg.pat->kind == PAT_BRICK) {
            colour5 c = {sdl_map_single(0.5), sdl_map_single(0.5), sdl_map_single(0.5), 0, 0};
            pg->colour = c;
        } else if (m) {
            pg->colour = first_colour(m, pg->colour);
        }
    }
}

void sdl_pattern_rainbow_pigment(sdl_parser *p, scene_pigment *pg)
{
    sdl_tok k = sdl_next(p);
    scene_pattern *pt = new_pattern(p, NULL);
    if (!pt) return;
    pt->kind = PAT_GRADIENT;
    pt->name = "rainbow";
    pt->gradient = v3(1, 0, 0);
    pg->map = sdl_map_parse(p, k.tk.kw);
    pg->pat = pt;
    pg->pattern = pt->name;
    pg->kind = PIGMENT_PATTERN;
}

/* ------------------------------------------------------------ normals */

scene_normal *sdl_pattern_normal_body(sdl_parser *p, const scene_normal *base)
{
    scene_normal *nm = sdl_alloc(p, sizeof *nm);
    if (!nm) return NULL;
    if (base) *nm = *base;
    else sdl_pattern_default_normal(nm);
    int uv = sdl_accept_kw(p, KW_UV_MAPPING);
    const sdl_tok *t = sdl_peek(p);
    if (t->tk.kind == TOK_IDENT && t->val.kind == VAL_NORMAL) {
        sdl_tok id = sdl_next(p);
        if (id.val.ptr) *nm = *(const scene_normal *)id.val.ptr;
    }
    target tg = target_new(p, TGT_NORMAL, nm->pat, &nm->map, &nm->transform, uv);
    tg.nm = nm;
    if (pattern_type(p, &tg)) {
        /* POV-Ray: [','] [amount] after the pattern type */
        sdl_accept(p, TOK_COMMA);
        nm->amount = sdl_allow_float(p, nm->amount);
    }
    modifiers(p, &tg, "normal");
    nm->pat = tg.pat;
    return nm;
}

/* ------------------------------------------------------------ textures */

/* tiles := '{' texture {..} {texture {..}} tile2 texture {..} {texture {..}} '}' */
static void tiles(sdl_parser *p, scene_texture *t, src_loc loc)
{
    if (!sdl_begin_block(p, "tiles")) return;
    scene_texture *lists[2] = {NULL, NULL};
    int which = 0;
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE)) {
        if (sdl_accept_kw(p, KW_TILE2)) {
            which = 1;
        } else if (sdl_accept_kw(p, KW_TEXTURE)) {
            scene_texture *nt = sdl_parse_texture(p);
            if (!nt) break;
            scene_texture *last = nt;
            while (last->next) last = last->next;
            last->next = lists[which];
            lists[which] = nt;
        } else {
            sdl_tok bad = sdl_next(p);
            sdl_unexpected(p, &bad, "texture or tile2");
        }
    }
    sdl_end_block(p);
    if (!lists[0]) sdl_error(p, loc, PT_ERR_SYNTAX, "first texture missing from tiles");
    scene_pattern *pt = new_pattern(p, NULL);
    scene_map_entry *e = sdl_map_entries(p, 2);
    if (!pt || !e) return;
    pt->kind = PAT_CHECKER;
    pt->name = "tiles";
    pt->frequency = 0.0;
    /* The first tile is the checker's value 1 and tile2 its value 0, as in
     * POV-Ray 3.7's Parse_Tiles (parser_materials.cpp), kept from its older
     * tiles: the first tile covers the cells whose floor sum is odd. */
    e[0].value = 0;
    e[0].texture = lists[1] ? lists[1] : sdl_copy_texture(p, &p->s->default_texture);
    e[1].value = 1;
    e[1].texture = lists[0];
    t->pat = pt;
    t->map = sdl_map_make(p, MAP_TEXTURE, e, 2);
}

/* material_map := '{' image_spec { once | interpolate n | map_type n |
 *   repeat uv | offset uv } texture {..} { texture {..} } '}' : the texture
 * whose number is the image's palette index (or red * 255) at the point. */
static void material_map(sdl_parser *p, scene_texture *t)
{
    if (!sdl_begin_block(p, "material_map")) return;
    scene_pattern *pt = new_pattern(p, NULL);
    scene_map_entry *e = sdl_map_entries(p, SDL_MAP_MAX_ENTRIES);
    if (!pt || !e) return;
    pt->kind = PAT_IMAGE;
    pt->name = "material_map";
    pt->frequency = 0.0;
    pt->image.material = 1;
    pt->image.major_radius = 1.0;
    pt->image.image = image_spec(p, 1);
    int n = 0;
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE)) {
        sdl_tok k = sdl_next(p);
        switch (k.tk.kind == TOK_KEYWORD ? k.tk.kw : KW_NONE) {
        case KW_ONCE: pt->image.once = 1; break;
        case KW_INTERPOLATE: pt->image.interpolate = sdl_to_int(sdl_float(p)); break;
        case KW_MAP_TYPE: pt->image.map_type = sdl_to_int(sdl_float(p)); break;
        case KW_REPEAT: case KW_OFFSET: {
            double uv[2];
            sdl_vector_n(p, uv, 2);
            sdl_warn_once(p, k.tk.loc, "material_map %s is not supported and is ignored", sdl_kw_text(k.tk.kw));
            break;
        }
        case KW_TEXTURE:
            if (n >= SDL_MAP_MAX_ENTRIES) {
                sdl_error(p, k.tk.loc, PT_ERR_LIMIT, "too many textures in material_map (at most %d)", SDL_MAP_MAX_ENTRIES);
                break;
            }
            e[n].value = n;
            e[n].texture = sdl_parse_texture(p);
            n++;
            break;
        default:
            sdl_unexpected(p, &k, "material_map item");
            break;
        }
    }
    sdl_end_block(p);
    if (n == 0) {
        if (sdl_ok(p)) sdl_error(p, sdl_peek(p)->tk.loc, PT_ERR_SYNTAX, "material_map needs at least one texture");
        return;
    }
    t->pat = pt;
    t->map = sdl_map_make(p, MAP_TEXTURE, e, n);
}

static void fallback_look(scene_texture *t)
{
    if (!t->map || t->map->n == 0) return;
    const scene_texture *first = t->map->e[0].texture;
    if (!first) return;
    while (first->pat && first->map && first->map->n > 0 && first->map->e[0].texture) first = first->map->e[0].texture;
    t->pigment = first->pigment;
    t->finish = first->finish;
    t->normal = first->normal;
}

void sdl_pattern_texture(sdl_parser *p, scene_texture *t)
{
    const sdl_tok *pk = sdl_peek(p);
    src_loc loc = pk->tk.loc;
    t->next = NULL;
    t->pat = NULL;
    t->map = NULL;
    if (sdl_accept_kw(p, KW_TILES)) {
        tiles(p, t, loc);
    } else if (sdl_accept_kw(p, KW_MATERIAL_MAP)) {
        material_map(p, t);
    } else {
        target tg = target_new(p, TGT_TEXTURE, NULL, &t->map, &t->transform, 0);
        tg.tx = t;
        pattern_type(p, &tg);
        modifiers(p, &tg, "texture");
        t->pat = tg.pat;
        if (t->map && t->map->kind != MAP_TEXTURE) t->map = NULL;
        if (tg.pat && sdl_ok(p) && !t->map) sdl_error(p, loc, PT_ERR_SYNTAX, "patterned texture must have texture_map");
    }
    if (t->pat) {
        t->pigment.kind = t->pat->kind == PAT_UNSUPPORTED ? PIGMENT_OTHER : t->pigment.kind;
        fallback_look(t);
    }
    while (sdl_ok(p)) {
        xform x;
        if (sdl_transform_item(p, &x)) t->transform = xform_then(t->transform, x);
        else break;
    }
}
