/* sdl_material.c - textures, pigments, finishes, interiors, transforms. */
#include "sdl_material.h"
#include <math.h>
#include <string.h>
#include "sdl_directive.h"
#include "sdl_atmos.h"
#include "sdl_expr.h"
#include "sdl_media.h"
#include "sdl_map.h"
#include "sdl_pattern.h"

/* ------------------------------------------------------------ transforms */

/* scale_vector: a vector or float; zero components become 1 with a
 * warning, as POV-Ray does. */
static vec3 scale_vector(sdl_parser *p)
{
    src_loc loc = sdl_peek(p)->tk.loc;
    vec3 s = sdl_vector(p);
    double *c[3] = {&s.x, &s.y, &s.z};
    for (int i = 0; i < 3; i++) {
        if (*c[i] != 0.0) continue;
        sdl_warning(p, loc, "scale %c component is zero; changed to 1", "xyz"[i]);
        *c[i] = 1.0;
    }
    return s;
}

/* matrix := 'matrix' '<' float x12 '>' (commas optional) */
static xform matrix_value(sdl_parser *p)
{
    double m[12];
    sdl_expect(p, TOK_LT, "'<' after matrix");
    for (int i = 0; i < 12 && sdl_ok(p); i++) {
        m[i] = sdl_float(p);
        if (i < 11) sdl_accept(p, TOK_COMMA);
    }
    sdl_expect(p, TOK_GT, "'>' closing the matrix");
    if (!sdl_ok(p)) return xform_identity();
    return xform_matrix(m);
}

int sdl_transform_item(sdl_parser *p, xform *out)
{
    const sdl_tok *t = sdl_peek(p);
    if (t->tk.kind != TOK_KEYWORD) return 0;
    switch (t->tk.kw) {
    case KW_TRANSLATE: sdl_next(p); *out = xform_translate(sdl_vector(p)); return 1;
    case KW_ROTATE: sdl_next(p); *out = xform_rotate(sdl_vector(p)); return 1;
    case KW_SCALE: sdl_next(p); *out = xform_scale(scale_vector(p)); return 1;
    case KW_MATRIX: sdl_next(p); *out = matrix_value(p); return 1;
    case KW_TRANSFORM: sdl_next(p); *out = sdl_parse_transform(p); return 1;
    default: return 0;
    }
}

/* transform_block := '{' { transform_identifier | transform_item | 'inverse' } '}' */
static xform transform_block(sdl_parser *p)
{
    xform x = xform_identity(), item;
    int inverse = 0;
    if (!sdl_begin_block(p, "transform")) return x;
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE)) {
        const sdl_tok *t = sdl_peek(p);
        if (t->tk.kind == TOK_IDENT && t->val.kind == VAL_TRANSFORM) {
            sdl_tok id = sdl_next(p);
            x = xform_then(x, *(const xform *)id.val.ptr);
        } else if (sdl_accept_kw(p, KW_INVERSE)) {
            inverse = 1; /* inverts the whole block, wherever it is written */
        } else if (sdl_transform_item(p, &item)) {
            x = xform_then(x, item);
        } else {
            sdl_tok bad = sdl_next(p);
            sdl_unexpected(p, &bad, "transformation");
        }
    }
    sdl_end_block(p);
    return inverse ? xform_inverse(x) : x;
}

/* transform := 'transform' ( transform_block | transform_identifier ) */
xform sdl_parse_transform(sdl_parser *p)
{
    const sdl_tok *t = sdl_peek(p);
    if (t->tk.kind == TOK_IDENT && t->val.kind == VAL_TRANSFORM) {
        sdl_tok id = sdl_next(p);
        return *(const xform *)id.val.ptr;
    }
    return transform_block(p);
}

/* ------------------------------------------------------------ copies */

scene_texture *sdl_copy_texture(sdl_parser *p, const scene_texture *t)
{
    scene_texture *head = NULL, **tail = &head;
    for (; t; t = t->next) {
        scene_texture *c = sdl_dup(p, t, sizeof *c);
        if (!c) return head;
        c->next = NULL;
        *tail = c;
        tail = &c->next;
    }
    return head;
}

/* Apply x after a texture's current transform, every layer. */
static void sdl_transform_texture(scene_texture *t, const xform *x)
{
    for (; t; t = t->next) t->transform = xform_then(t->transform, *x);
}

void sdl_transform_texture_outer(scene_texture *t, const xform *x)
{
    for (; t; t = t->next) {
        if (!t->uv_mapping && !(t->pat && t->pat->uv_mapping)) {
            t->transform = xform_then(t->transform, *x);
        } else {
            t->uv_warp = t->uv_warped ? xform_then(t->uv_warp, *x) : *x;
            t->uv_warped = 1;
        }
    }
}

/* ------------------------------------------------------------ pigments */

/* pigment := '{' pigment body '}' (grammar in sdl_pattern.c) */
void sdl_parse_pigment(sdl_parser *p, scene_pigment *pg)
{
    if (!sdl_begin_block(p, "pigment")) return;
    sdl_pattern_pigment_body(p, pg);
    sdl_end_block(p);
}

scene_pigment *sdl_parse_pigment_new(sdl_parser *p)
{
    scene_pigment *pg = sdl_dup(p, &p->s->default_texture.pigment, sizeof *pg);
    if (!pg) return NULL;
    sdl_parse_pigment(p, pg);
    return pg;
}

/* ------------------------------------------------------------ finishes */

/* reflection := 'reflection' ( colour | '{' colour [','] [colour]
 *               { fresnel [bool] | falloff f | exponent f | metallic [f] } '}' ) */
/* reflection's exponent e (in the block or as reflection_exponent), as
 * written; shading raises the reflected colour to 1 / e, which POV-Ray 3.7
 * divides by without a check (parstxtr.cpp, Reflect_Exp), so 0 is an error. */
static double reflection_exponent(sdl_parser *p)
{
    src_loc loc = sdl_peek(p)->tk.loc;
    double v = sdl_float(p);
    if (v == 0.0) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "reflection exponent must not be 0");
        return 1.0;
    }
    return v;
}

static void reflection(sdl_parser *p, scene_finish *f)
{
    if (!sdl_is(sdl_peek(p), TOK_LBRACE)) {
        f->reflection_max = sdl_rgb(p);
        f->reflection_min = f->reflection_max;
        f->reflection_falloff = 1;
        f->fresnel = 0;
        return;
    }
    int second = 0;
    sdl_begin_block(p, "reflection");
    f->reflection_min = sdl_rgb(p);
    sdl_accept(p, TOK_COMMA);
    if (sdl_starts_expr(sdl_peek(p))) {
        f->reflection_max = sdl_rgb(p);
        second = 1;
    } else {
        f->reflection_max = f->reflection_min;
    }
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE)) {
        sdl_tok t = sdl_next(p);
        if (sdl_is_kw(&t, KW_FRESNEL)) {
            f->fresnel = sdl_true(sdl_allow_float(p, 1.0));
            if (!second && f->fresnel) f->reflection_min = (rgb){0, 0, 0};
        } else if (sdl_is_kw(&t, KW_FALLOFF)) {
            f->reflection_falloff = sdl_float(p);
        } else if (sdl_is_kw(&t, KW_EXPONENT)) {
            f->reflection_exponent = reflection_exponent(p);
        } else if (sdl_is_kw(&t, KW_METALLIC)) {
            f->reflection_metallic = sdl_allow_float(p, 1.0);
        } else {
            sdl_unexpected(p, &t, "reflection modifier");
        }
    }
    sdl_end_block(p);
}

/* irid { amount [thickness f] [turbulence v] } (POV-Ray 3.7's finish irid:
 * turbulence takes a vector of which x is used; values kept in single
 * precision). */
static void irid(sdl_parser *p, scene_finish *f)
{
    if (!sdl_begin_block(p, "irid")) return;
    f->irid = (float)sdl_float(p);
    for (;;) {
        if (sdl_accept_kw(p, KW_THICKNESS)) {
            f->irid_thickness = (float)sdl_float(p);
        } else if (sdl_accept_kw(p, KW_TURBULENCE)) {
            vec3 v = sdl_vector(p);
            f->irid_turb = (float)v.x;
        } else {
            break;
        }
    }
    sdl_end_block(p);
}

/* Skip a '{...}' finish sub-block (subsurface) with a warning. */
static void skip_sub_block(sdl_parser *p, const sdl_tok *k)
{
    const char *name = sdl_kw_text(k->tk.kw);
    sdl_ignore_block(p, k->tk.loc, name, "finish '%s' is not supported yet and is ignored", name);
}

typedef struct { int diffuse, phong, specular; } albedo_flags;

/* albedo-adjustable values: 'diffuse' ['albedo'] f [',' f], phong, specular */
static void albedo_value(sdl_parser *p, sdl_kw k, scene_finish *f, albedo_flags *a)
{
    int albedo = sdl_accept_kw(p, KW_ALBEDO);
    if (k == KW_DIFFUSE) {
        a->diffuse = albedo;
        f->diffuse = sdl_float(p);
        sdl_accept(p, TOK_COMMA);
        f->diffuse_back = sdl_allow_float(p, 0.0);
    } else if (k == KW_PHONG) {
        a->phong = albedo;
        f->phong = sdl_float(p);
    } else {
        a->specular = albedo;
        f->specular = sdl_float(p);
    }
}

/* finish_item := ambient c | emission c | brilliance f | diffuse .. | phong .. |
 *   phong_size f | specular .. | roughness f | metallic [f] | crand f |
 *   reflection .. | reflection_exponent f | conserve_energy | irid {..} |
 *   subsurface {..} | ior f | caustics f | refraction f */
static void finish_item(sdl_parser *p, scene_finish *f, albedo_flags *a)
{
    sdl_tok t = sdl_next(p);
    sdl_kw k = t.tk.kind == TOK_KEYWORD ? t.tk.kw : KW_NONE;
    switch (k) {
    case KW_AMBIENT: f->ambient = sdl_rgb(p); break;
    case KW_EMISSION: f->emission = sdl_rgb(p); break;
    case KW_BRILLIANCE: f->brilliance = sdl_float(p); break;
    case KW_DIFFUSE: case KW_PHONG: case KW_SPECULAR: albedo_value(p, k, f, a); break;
    case KW_PHONG_SIZE: f->phong_size = sdl_float(p); break;
    case KW_ROUGHNESS:
        f->roughness = sdl_float(p);
        if (f->roughness == 0) sdl_warning(p, t.tk.loc, "zero roughness used");
        break;
    case KW_METALLIC: f->metallic = sdl_starts_float(sdl_peek(p)) ? sdl_float(p) : 1.0; break;
    case KW_CRAND: f->crand = sdl_float(p); break;
    case KW_REFLECTION: reflection(p, f); break;
    case KW_REFLECTION_EXPONENT: f->reflection_exponent = reflection_exponent(p); break;
    case KW_CONSERVE_ENERGY: f->conserve_energy = 1; break;
    case KW_IRID: irid(p, f); break;
    case KW_SUBSURFACE: skip_sub_block(p, &t); break;
    case KW_IOR: case KW_CAUSTICS: case KW_REFRACTION:
        sdl_warn_once(p, t.tk.loc, "finish '%s' belongs in interior{} and is ignored", sdl_kw_text(k));
        sdl_float(p);
        break;
    default: sdl_unexpected(p, &t, "finish item"); break;
    }
}

/* POV-Ray 3.7's 'albedo' adjustments, applied after the whole block. */
static void apply_albedo(scene_finish *f, const albedo_flags *a)
{
    if (a->diffuse) {
        f->diffuse *= (f->brilliance + 1.0) / 2.0;
        f->diffuse_back *= (f->brilliance + 1.0) / 2.0;
    }
    if (a->phong) f->phong *= (f->phong_size + 1.0) / 2.0;
    if (a->specular && f->roughness != 0) {
        double r = 1.0 / f->roughness; /* POV-Ray keeps 1/roughness internally */
        f->specular *= (r + 2.0) / (4.0 * (2.0 - pow(2.0, -r / 2.0)));
    }
}

/* finish := '{' [ finish_identifier ] { finish_item } '}' */
void sdl_parse_finish(sdl_parser *p, scene_finish *f)
{
    albedo_flags a = {0, 0, 0};
    if (!sdl_begin_block(p, "finish")) return;
    const sdl_tok *t = sdl_peek(p);
    if (t->tk.kind == TOK_IDENT && t->val.kind == VAL_FINISH) {
        sdl_tok id = sdl_next(p);
        *f = *(const scene_finish *)id.val.ptr;
    }
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE) && !sdl_is(sdl_peek(p), TOK_EOF)) finish_item(p, f, &a);
    sdl_end_block(p);
    apply_albedo(f, &a);
}

scene_finish *sdl_parse_finish_new(sdl_parser *p)
{
    scene_finish *f = sdl_dup(p, &p->s->default_texture.finish, sizeof *f);
    if (!f) return NULL;
    sdl_parse_finish(p, f);
    return f;
}

scene_normal *sdl_parse_normal_from(sdl_parser *p, const scene_normal *base)
{
    if (!sdl_begin_block(p, "normal")) return NULL;
    scene_normal *nm = sdl_pattern_normal_body(p, base);
    sdl_end_block(p);
    return nm;
}

scene_normal *sdl_parse_normal(sdl_parser *p) { return sdl_parse_normal_from(p, p->s->default_texture.normal); }

void sdl_attach_normal(sdl_parser *p, scene_texture *t)
{
    int fresh = t->normal == NULL;
    scene_normal *nm = sdl_parse_normal_from(p, t->normal);
    t->has_normal = 1;
    if (!nm) return;
    /* transforms already applied to t moved its pigment, not this new normal */
    if (fresh && !xform_is_identity(&t->transform)) nm->transform = xform_then(nm->transform, xform_inverse(t->transform));
    t->normal = nm;
}

/* ------------------------------------------------------------ interiors */

/* interior_item := ior f | dispersion f | dispersion_samples n | caustics f |
 *   fade_distance f | fade_power f | fade_colour c | media {..} */
static void interior_item(sdl_parser *p, scene_interior *in)
{
    sdl_tok t = sdl_next(p);
    sdl_kw k = t.tk.kind == TOK_KEYWORD ? t.tk.kw : KW_NONE;
    switch (k) {
    case KW_IOR: in->ior = sdl_float(p); break;
    case KW_DISPERSION: in->dispersion = sdl_float(p); break;
    case KW_DISPERSION_SAMPLES: {
        /* POV-Ray 3.7 (parstxtr.cpp) truncates to int and rejects fewer than
         * 2; the upper bound here only keeps a typo from running for ever */
        double v = sdl_float(p);
        if (!(v >= 2.0 && v <= 1.0e5)) {
            sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "dispersion_samples must be between 2 and 100000 (got %g)", v);
            break;
        }
        in->dispersion_samples = (int)v;
        break;
    }
    case KW_CAUSTICS: in->caustics = sdl_float(p) * 45.0; in->caustics_set = 1; break;
    case KW_FADE_DISTANCE: in->fade_distance = sdl_float(p); break;
    case KW_FADE_POWER: in->fade_power = sdl_float(p); break;
    case KW_FADE_COLOR: case KW_FADE_COLOUR: in->fade_colour = sdl_rgb(p); break;
    case KW_MEDIA: sdl_media_append(p, &in->media, &in->nmedia, sdl_parse_media(p)); break;
    default: sdl_unexpected(p, &t, "interior item"); break;
    }
}

/* interior := '{' [ interior_identifier ] { interior_item } '}' */
void sdl_parse_interior(sdl_parser *p, scene_interior *in)
{
    if (!sdl_begin_block(p, "interior")) return;
    const sdl_tok *t = sdl_peek(p);
    if (t->tk.kind == TOK_IDENT && t->val.kind == VAL_INTERIOR) {
        sdl_tok id = sdl_next(p);
        *in = *(const scene_interior *)id.val.ptr;
    }
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE) && !sdl_is(sdl_peek(p), TOK_EOF)) interior_item(p, in);
    sdl_end_block(p);
}

scene_interior *sdl_parse_interior_new(sdl_parser *p)
{
    scene_interior *in = sdl_alloc(p, sizeof *in);
    if (!in) return NULL;
    scene_default_interior(in);
    sdl_parse_interior(p, in);
    return in;
}

/* ------------------------------------------------------------ textures */

static scene_texture *new_texture(sdl_parser *p)
{
    scene_texture *t = sdl_dup(p, &p->s->default_texture, sizeof *t);
    if (!t) return NULL;
    t->next = NULL;
    t->transform = xform_identity();
    return t;
}

/* texture_item := pigment_identifier | finish_identifier | normal_identifier |
 *   'pigment' pigment | 'finish' finish | 'normal' normal | transform_item |
 *   no_bump_scale | uv_mapping */
static int texture_item(sdl_parser *p, scene_texture *t)
{
    const sdl_tok *pk = sdl_peek(p);
    xform x;
    if (pk->tk.kind == TOK_IDENT && (pk->val.kind == VAL_PIGMENT || pk->val.kind == VAL_FINISH || pk->val.kind == VAL_NORMAL)) {
        sdl_tok id = sdl_next(p);
        if (id.val.kind == VAL_PIGMENT) t->pigment = *(const scene_pigment *)id.val.ptr;
        else if (id.val.kind == VAL_FINISH) t->finish = *(const scene_finish *)id.val.ptr;
        else {
            t->has_normal = 1;
            if (id.val.ptr) t->normal = id.val.ptr;
        }
        return 1;
    }
    if (sdl_transform_item(p, &x)) {
        sdl_transform_texture(t, &x); /* every layer (POV-Ray's Transform_Textures) */
        return 1;
    }
    if (sdl_accept_kw(p, KW_PIGMENT)) {
        sdl_parse_pigment(p, &t->pigment);
        return 1;
    }
    if (sdl_accept_kw(p, KW_FINISH)) {
        sdl_parse_finish(p, &t->finish);
        return 1;
    }
    if (sdl_accept_kw(p, KW_NORMAL)) {
        sdl_attach_normal(p, t);
        return 1;
    }
    if (sdl_accept_kw(p, KW_UV_MAPPING)) {
        t->uv_mapping = 1;
        return 1;
    }
    return sdl_accept_kw(p, KW_NO_BUMP_SCALE);
}

/* texture := '{' texture_body '}' */
scene_texture *sdl_parse_texture(sdl_parser *p)
{
    if (!sdl_begin_block(p, "texture")) return NULL;
    scene_texture *t = sdl_parse_texture_body(p);
    sdl_end_block(p);
    return t;
}

/* texture_body := [ texture_identifier ] { texture_item } | texture_pattern ...
 * (patterned textures: sdl_pattern.c) */
scene_texture *sdl_parse_texture_body(sdl_parser *p)
{
    src_loc loc = sdl_peek(p)->tk.loc;
    scene_texture *t = NULL;
    int modified = 0;
    /* texture { uv_mapping ... }: POV-Ray 3.7's UV_MAP_PATTERN around the
     * texture that follows (parstxtr.cpp), patterned or not */
    int uv = sdl_accept_kw(p, KW_UV_MAPPING);
    const sdl_tok *pk = sdl_peek(p);
    if (pk->tk.kind == TOK_IDENT && pk->val.kind == VAL_TEXTURE) {
        sdl_tok id = sdl_next(p);
        t = sdl_copy_texture(p, id.val.ptr);
        modified = 1;
    } else {
        t = new_texture(p);
    }
    if (!t) return NULL;
    t->loc = loc;
    if (uv) t->uv_mapping = 1;
    while (sdl_ok(p) && texture_item(p, t)) modified = 1;
    const sdl_tok *rest = sdl_peek(p);
    if (!modified && rest->tk.kind == TOK_KEYWORD &&
        (sdl_pattern_is_type(rest->tk.kw) || rest->tk.kw == KW_TILES || rest->tk.kw == KW_MATERIAL_MAP))
        sdl_pattern_texture(p, t);
    return t;
}

int sdl_parse_look_value(sdl_parser *p, sdl_kw k, sdl_value *out)
{
    const char *name;
    switch (k) {
    case KW_COLOR_MAP: case KW_COLOUR_MAP: name = "colour_map"; break;
    case KW_PIGMENT_MAP: name = "pigment_map"; break;
    case KW_NORMAL_MAP: name = "normal_map"; break;
    case KW_SLOPE_MAP: name = "slope_map"; break;
    case KW_TEXTURE_MAP: name = "texture_map"; break;
    case KW_MEDIA: case KW_DENSITY: /* sdl_media.c */
        memset(out, 0, sizeof *out);
        out->kind = VAL_OPAQUE;
        out->str = k == KW_MEDIA ? "media" : "density";
        out->ptr = k == KW_MEDIA ? (void *)sdl_parse_media(p) : (void *)sdl_parse_density(p);
        return 1;
    case KW_FOG: case KW_SKY_SPHERE: case KW_RAINBOW:
        memset(out, 0, sizeof *out);
        out->kind = VAL_OPAQUE;
        out->str = k == KW_FOG ? "fog" : k == KW_RAINBOW ? "rainbow" : "sky_sphere";
        out->ptr = k == KW_FOG ? (void *)sdl_parse_fog(p) : k == KW_RAINBOW ? (void *)sdl_parse_rainbow(p) : (void *)sdl_parse_sky_sphere(p);
        return 1;
    default: return 0;
    }
    memset(out, 0, sizeof *out);
    out->kind = VAL_OPAQUE;
    out->str = name;
    out->ptr = (void *)sdl_map_parse(p, k);
    return 1;
}

/* ------------------------------------------------------------ materials */

/* material := '{' [ material_identifier ] { texture | interior_texture | interior | transform_item } '}' */
void sdl_parse_material(sdl_parser *p, sdl_material *m)
{
    if (!sdl_begin_block(p, "material")) return;
    const sdl_tok *pk = sdl_peek(p);
    if (pk->tk.kind == TOK_IDENT && pk->val.kind == VAL_MATERIAL) {
        sdl_tok id = sdl_next(p);
        const sdl_material *src = id.val.ptr;
        m->texture = sdl_copy_texture(p, src->texture);
        m->interior_texture = sdl_copy_texture(p, src->interior_texture);
        m->interior = src->interior;
    }
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE)) {
        sdl_tok t = sdl_next(p);
        xform x;
        if (sdl_is_kw(&t, KW_TEXTURE)) {
            scene_texture *nt = sdl_parse_texture(p);
            if (nt) {
                scene_texture *last = nt;
                while (last->next) last = last->next;
                last->next = m->texture;
                m->texture = nt;
            }
        } else if (sdl_is_kw(&t, KW_INTERIOR_TEXTURE)) {
            m->interior_texture = sdl_parse_texture(p);
        } else if (sdl_is_kw(&t, KW_INTERIOR)) {
            scene_interior *in = sdl_alloc(p, sizeof *in);
            if (!in) return;
            if (m->interior) *in = *m->interior;
            else scene_default_interior(in);
            sdl_parse_interior(p, in);
            m->interior = in;
        } else {
            sdl_unget(p, &t);
            if (!sdl_transform_item(p, &x)) {
                sdl_next(p);
                sdl_unexpected(p, &t, "texture, interior or transformation");
                return;
            }
            sdl_transform_texture_outer(m->texture, &x);
            sdl_transform_texture_outer(m->interior_texture, &x);
        }
    }
    sdl_end_block(p);
}

sdl_material *sdl_parse_material_new(sdl_parser *p)
{
    sdl_material *m = sdl_alloc(p, sizeof *m);
    if (!m) return NULL;
    sdl_parse_material(p, m);
    return m;
}
