/* sdl_atmos.c - fog and sky_sphere grammar (POV-Ray 3.7 Parse_Fog and
 * Parse_Skysphere semantics: fog transforms only turn its `up` vector, which
 * is normalised at the end; a translate warns; sky_sphere pigments start
 * from a clear pigment, not the default texture's). */
#include "sdl_atmos.h"
#include <math.h>
#include <string.h>
#include "sdl_directive.h"
#include "sdl_expr.h"
#include "sdl_material.h"
#include "sdl_pattern.h"

static void fog_defaults(scene_fog *f)
{
    memset(f, 0, sizeof *f);
    f->type = 1;
    f->up = v3(0, 1, 0);
    f->turb_depth = 0.5;
    f->octaves = 6;
    f->omega = 0.5;
    f->lambda = 2.0;
}

scene_fog *sdl_parse_fog(sdl_parser *p)
{
    scene_fog *f = sdl_alloc(p, sizeof *f);
    if (!f) return NULL;
    fog_defaults(f);
    if (!sdl_begin_block(p, "fog")) return NULL;
    const sdl_tok *t = sdl_peek(p);
    if (t->tk.kind == TOK_IDENT && t->val.kind == VAL_OPAQUE && t->val.str && strcmp(t->val.str, "fog") == 0 && t->val.ptr) {
        sdl_next(p);
        *f = *(const scene_fog *)t->val.ptr;
        f->next = NULL;
    }
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE)) {
        t = sdl_peek(p);
        if (sdl_starts_colour(t)) {
            colour5 c = sdl_colour(p, 1);
            f->colour[0] = c.r;
            f->colour[1] = c.g;
            f->colour[2] = c.b;
            f->colour[3] = c.f;
            f->colour[4] = c.t;
            continue;
        }
        if (sdl_starts_float(t)) {
            sdl_warn_once(p, t->tk.loc, "should use distance keyword in fog");
            f->distance = sdl_float(p);
            continue;
        }
        xform x;
        sdl_tok k = *t;
        if (sdl_is_kw(&k, KW_TRANSLATE)) {
            sdl_next(p);
            sdl_vector(p);
            sdl_warning(p, k.tk.loc, "a fog's up vector can't be translated");
            continue;
        }
        if (sdl_transform_item(p, &x)) {
            f->up = xform_vector(&x, f->up);
            continue;
        }
        sdl_tok n = sdl_next(p);
        switch (n.tk.kind == TOK_KEYWORD ? n.tk.kw : KW_NONE) {
        case KW_DISTANCE: f->distance = sdl_float(p); break;
        case KW_FOG_TYPE:
            f->type = sdl_to_int(sdl_float(p));
            if (f->type < 1 || f->type > 2) sdl_warning(p, n.tk.loc, "unknown fog type");
            break;
        case KW_FOG_ALT: f->alt = sdl_float(p); break;
        case KW_FOG_OFFSET: f->offset = sdl_float(p); break;
        case KW_TURB_DEPTH: f->turb_depth = sdl_float(p); break;
        case KW_UP: f->up = sdl_vector(p); break;
        case KW_TURBULENCE: f->turbulence = sdl_vector(p); f->has_turb = 1; break;
        case KW_OCTAVES:
            f->octaves = sdl_to_int(sdl_float(p));
            if (f->octaves < 1) f->octaves = 1;
            if (f->octaves > 10) f->octaves = 10;
            f->has_turb = 1;
            break;
        case KW_OMEGA: f->omega = sdl_float(p); f->has_turb = 1; break;
        case KW_LAMBDA: f->lambda = sdl_float(p); f->has_turb = 1; break;
        default: sdl_unexpected(p, &n, "fog item"); break;
        }
    }
    sdl_end_block(p);
    f->up = v3_norm(f->up);
    return f;
}

scene_sky_sphere *sdl_parse_sky_sphere(sdl_parser *p)
{
    scene_sky_sphere *s = sdl_alloc(p, sizeof *s);
    if (!s) return NULL;
    s->transform = xform_identity();
    s->emission[0] = s->emission[1] = s->emission[2] = 1.0;
    src_loc loc = sdl_peek(p)->tk.loc;
    if (!sdl_begin_block(p, "sky_sphere")) return NULL;
    const sdl_tok *t = sdl_peek(p);
    if (t->tk.kind == TOK_IDENT && t->val.kind == VAL_OPAQUE && t->val.str && strcmp(t->val.str, "sky_sphere") == 0 &&
        t->val.ptr) {
        sdl_next(p);
        *s = *(const scene_sky_sphere *)t->val.ptr;
    }
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE)) {
        xform x;
        if (sdl_transform_item(p, &x)) {
            s->transform = xform_then(s->transform, x);
            continue;
        }
        sdl_tok n = sdl_next(p);
        if (sdl_is_kw(&n, KW_PIGMENT)) {
            scene_pigment *pg = sdl_alloc(p, sizeof *pg);
            const scene_pigment **list = sdl_alloc(p, sizeof *list * (size_t)(s->npigments + 1));
            if (!pg || !list) return NULL;
            scene_default_pigment(pg);
            sdl_parse_pigment(p, pg);
            if (s->npigments) memcpy(list, s->pigments, sizeof *list * (size_t)s->npigments);
            list[s->npigments++] = pg;
            s->pigments = list;
        } else if (sdl_is_kw(&n, KW_EMISSION)) {
            rgb e = sdl_rgb(p);
            s->emission[0] = e.r;
            s->emission[1] = e.g;
            s->emission[2] = e.b;
        } else {
            sdl_unexpected(p, &n, "sky_sphere item");
        }
    }
    sdl_end_block(p);
    if (sdl_ok(p) && s->npigments == 0) sdl_error(p, loc, PT_ERR_SYNTAX, "empty sky_sphere statement");
    return s;
}

scene_rainbow *sdl_parse_rainbow(sdl_parser *p)
{
    scene_rainbow *r = sdl_alloc(p, sizeof *r);
    if (!r) return NULL;
    src_loc loc = sdl_peek(p)->tk.loc;
    if (!sdl_begin_block(p, "rainbow")) return NULL;
    /* POV-Ray's defaults: distance 1e7, arc and falloff angles 180 (kept as given) */
    r->distance = 1.0e7;
    r->arc_angle = r->falloff_angle = 180.0;
    r->up = v3(0, 1, 0);
    const sdl_tok *t = sdl_peek(p);
    int have_arc = 0, have_falloff = 0;
    if (t->tk.kind == TOK_IDENT && t->val.kind == VAL_OPAQUE && t->val.str && strcmp(t->val.str, "rainbow") == 0 && t->val.ptr) {
        sdl_next(p);
        *r = *(const scene_rainbow *)t->val.ptr;
        r->next = NULL;
        /* back to what was given, as POV-Ray copies the parsed record */
    }
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE)) {
        sdl_tok n = sdl_next(p);
        switch (n.tk.kind == TOK_KEYWORD ? n.tk.kw : KW_NONE) {
        case KW_ANGLE: r->angle = sdl_float(p); break;
        case KW_DIRECTION: r->antisolar = sdl_vector(p); break;
        case KW_COLOR_MAP: case KW_COLOUR_MAP: {
            sdl_unget(p, &n);
            scene_pigment *pg = sdl_alloc(p, sizeof *pg);
            if (!pg) return NULL;
            scene_default_pigment(pg);
            /* a gradient x pigment through the map (POV-Ray's rainbow pigment) */
            sdl_pattern_rainbow_pigment(p, pg);
            r->pigment = pg;
            break;
        }
        case KW_DISTANCE: r->distance = sdl_float(p); break;
        case KW_JITTER: r->jitter = sdl_float(p); break;
        case KW_WIDTH: r->width = sdl_float(p); break;
        case KW_UP: r->up = sdl_vector(p); break;
        case KW_FALLOFF_ANGLE:
            have_falloff = 1;
            r->falloff_angle = sdl_float(p);
            if (r->falloff_angle < 0.0 || r->falloff_angle > 360.0)
                sdl_error(p, n.tk.loc, PT_ERR_SYNTAX, "illegal falloff angle in rainbow (use 0 to 360 degrees)");
            r->falloff_angle *= 0.00872664625997164788; /* pi/360 */
            break;
        case KW_ARC_ANGLE:
            have_arc = 1;
            r->arc_angle = sdl_float(p);
            if (r->arc_angle < 0.0 || r->arc_angle > 360.0)
                sdl_error(p, n.tk.loc, PT_ERR_SYNTAX, "illegal arc angle in rainbow (use 0 to 360 degrees)");
            r->arc_angle *= 0.00872664625997164788;
            break;
        default: sdl_unexpected(p, &n, "rainbow item"); break;
        }
    }
    sdl_end_block(p);
    if (!sdl_ok(p)) return NULL;
    if (have_arc && !have_falloff) r->falloff_angle = r->arc_angle;
    if (r->arc_angle < r->falloff_angle) sdl_error(p, loc, PT_ERR_SYNTAX, "arc angle is smaller than falloff angle in rainbow");
    r->falloff_width = r->arc_angle - r->falloff_angle;
    if (v3_len2(r->antisolar) < 1e-10) sdl_error(p, loc, PT_ERR_SYNTAX, "rainbow's direction vector is zero");
    if (v3_len2(r->up) < 1e-10) sdl_error(p, loc, PT_ERR_SYNTAX, "rainbow's up vector is zero");
    if (!sdl_ok(p)) return NULL;
    r->antisolar = v3_norm(r->antisolar);
    r->up = v3_norm(r->up);
    if (fabs(1.0 - fabs(v3_dot(r->up, r->antisolar))) < 1e-10)
        sdl_error(p, loc, PT_ERR_SYNTAX, "rainbow's up and direction vector are co-linear");
    r->right = v3_norm(v3_cross(r->up, r->antisolar));
    r->up = v3_norm(v3_cross(r->antisolar, r->right));
    r->angle -= 0.5 * r->width;
    r->angle *= 0.01745329251994329576; /* pi/180 */
    r->width *= 0.01745329251994329576;
    return r;
}

void sdl_atmos_statement(sdl_parser *p, sdl_kw k)
{
    if (k == KW_FOG) {
        scene_fog *f = sdl_parse_fog(p);
        if (f && sdl_ok(p)) {
            f->next = (scene_fog *)p->s->fogs;
            p->s->fogs = f;
        }
    } else if (k == KW_RAINBOW) {
        scene_rainbow *r = sdl_parse_rainbow(p);
        if (r && sdl_ok(p)) {
            r->next = (scene_rainbow *)p->s->rainbows;
            p->s->rainbows = r;
        }
    } else if (k == KW_SKY_SPHERE) {
        scene_sky_sphere *s = sdl_parse_sky_sphere(p);
        if (s && sdl_ok(p)) p->s->sky_sphere = s;
    }
}
