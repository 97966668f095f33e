/* sdl_object.c - shapes, CSG, meshes, object modifiers. */
#include "sdl_object.h"
#include "grow.h"
#include "scene_leaves.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "sdl_clip.h"
#include "sdl_directive.h"
#include "sdl_expr.h"
#include "sdl_material.h"
#include "sdl_media.h"
#include "sdl_scene.h"
#include "sdl_shape.h"

/* ------------------------------------------------------------ keywords */

static int is_unsupported_shape(sdl_kw k)
{
    switch (k) {
    case KW_BICUBIC_PATCH: case KW_BLOB: case KW_CUBIC: case KW_HEIGHT_FIELD: case KW_ISOSURFACE:
    case KW_JULIA_FRACTAL: case KW_LATHE: case KW_OVUS: case KW_PARAMETRIC: case KW_POLY:
    case KW_POLYGON: case KW_POLYNOMIAL: case KW_PRISM: case KW_QUADRIC: case KW_QUARTIC:
    case KW_SOR: case KW_SPHERE_SWEEP: case KW_SUPERELLIPSOID: case KW_TEXT:
        return 1;
    default:
        return 0;
    }
}

static int is_shape_kw(sdl_kw k)
{
    switch (k) {
    case KW_SPHERE: case KW_BOX: case KW_PLANE: case KW_TRIANGLE: case KW_SMOOTH_TRIANGLE:
    case KW_MESH: case KW_MESH2: case KW_UNION: case KW_MERGE: case KW_INTERSECTION:
    case KW_DIFFERENCE: case KW_CYLINDER: case KW_CONE: case KW_DISC: case KW_TORUS:
    case KW_OBJECT: case KW_LIGHT_SOURCE: case KW_LIGHT_GROUP:
        return 1;
    default:
        return is_unsupported_shape(k);
    }
}

int sdl_starts_object(const sdl_tok *t)
{
    return t->tk.kind == TOK_KEYWORD && is_shape_kw(t->tk.kw);
}

/* ------------------------------------------------------------ nodes */

static sdl_obj *new_obj(sdl_parser *p, shape_kind kind, const char *name, src_loc loc)
{
    sdl_obj *so = sdl_alloc(p, sizeof *so);
    if (!so) return NULL;
    so->obj = scene_new_object(p->s, kind, loc);
    if (!so->obj) {
        sdl_error(p, loc, PT_ERR_NOMEM, "out of memory");
        return NULL;
    }
    so->obj->name = name;
    return so;
}

static scene_texture *own_texture(const scene_texture *t) { return (scene_texture *)t; }

/* POV-Ray 3.7's Post_Process (parse.cpp) gives a CSG member the parent's
 * UV flag when it copies the parent's texture or its interior_texture, so
 * every member without an interior_texture of its own gets it, even one
 * with its own texture (checked against povray: a textured sphere in a
 * uv-mapped union is uv-mapped). It does so only after parsing, so the
 * CSG's transforms still move such a member's own texture: members get
 * uv_mapping 2 (inherited), which node_transform does not count. */
static void set_uv_mapping(scene_object *o, int value)
{
    if (o->uv_mapping != 1) o->uv_mapping = value;
    if (scene_object_is_csg(o))
        for (int i = 0; i < o->u.csg.nkids; i++) {
            scene_object *k = o->u.csg.kids[i];
            if (!k->texture || !k->interior_texture) set_uv_mapping(k, 2);
        }
}

static void node_transform(scene_object *o, const xform *x)
{
    o->transform = xform_then(o->transform, *x);
    if (o->uv_mapping != 1) { /* uv-mapped textures stay on the surface (POV-Ray's UV_FLAG) */
        sdl_transform_texture_outer(own_texture(o->texture), x);
        sdl_transform_texture_outer(own_texture(o->interior_texture), x);
        /* and a mesh's texture_list moves with it (each object holds its
         * own copies, own_mesh_textures) */
        if (o->kind == SHAPE_MESH && o->u.mesh.mesh && o->u.mesh.textures)
            for (int i = 0; i < o->u.mesh.mesh->ntextures; i++) sdl_transform_texture_outer(own_texture(o->u.mesh.textures[i]), x);
    }
    if (scene_object_is_csg(o))
        for (int i = 0; i < o->u.csg.nkids; i++) node_transform(o->u.csg.kids[i], x);
}

static void sdl_light_transform(scene_light *l, const xform *x)
{
    l->position = xform_point(x, l->position);
    l->point_at = xform_point(x, l->point_at);
    l->axis1 = xform_vector(x, l->axis1);
    l->axis2 = xform_vector(x, l->axis2);
    if (l->looks_like) node_transform((scene_object *)l->looks_like, x);
}

void sdl_obj_transform(sdl_obj *o, const xform *x)
{
    if (!o) return;
    if (o->obj) node_transform(o->obj, x);
    for (int i = 0; i < o->nlights; i++) sdl_light_transform(&o->lights[i], x);
}

/* Object o's own copies of the n textures src (a mesh's texture_list),
 * so that its transforms move them and no other object's. */
static void own_mesh_textures(sdl_parser *p, scene_object *o, const scene_texture *const *src, int n)
{
    o->u.mesh.textures = NULL;
    if (!src || n <= 0) return;
    const scene_texture **t = sdl_alloc(p, sizeof *t * (size_t)n);
    if (!t) return;
    for (int i = 0; i < n; i++) t[i] = src[i] ? sdl_copy_texture(p, src[i]) : NULL;
    o->u.mesh.textures = t;
}

static scene_object *copy_node(sdl_parser *p, const scene_object *o)
{
    scene_object *c = sdl_dup(p, o, sizeof *c);
    if (!c) return NULL;
    c->texture = sdl_copy_texture(p, o->texture);
    c->interior_texture = sdl_copy_texture(p, o->interior_texture);
    if (o->kind == SHAPE_MESH && o->u.mesh.mesh)
        own_mesh_textures(p, c, o->u.mesh.textures, o->u.mesh.mesh->ntextures);
    if (scene_object_is_csg(o) && o->u.csg.nkids > 0) {
        c->u.csg.kids = sdl_alloc(p, sizeof(scene_object *) * (size_t)o->u.csg.nkids);
        if (!c->u.csg.kids) return NULL;
        for (int i = 0; i < o->u.csg.nkids; i++) c->u.csg.kids[i] = copy_node(p, o->u.csg.kids[i]);
    }
    return c;
}

static void copy_lights(sdl_parser *p, sdl_obj *dst, const scene_light *src, int n)
{
    dst->nlights = 0;
    dst->lights = n ? sdl_alloc(p, sizeof(scene_light) * (size_t)n) : NULL;
    if (n && !dst->lights) return;
    for (int i = 0; i < n; i++) {
        dst->lights[i] = src[i];
        if (src[i].looks_like) dst->lights[i].looks_like = copy_node(p, src[i].looks_like);
    }
    dst->nlights = n;
}

sdl_obj *sdl_copy_obj(sdl_parser *p, const sdl_obj *o)
{
    sdl_obj *c = sdl_alloc(p, sizeof *c);
    if (!c || !o) return c;
    c->obj = o->obj ? copy_node(p, o->obj) : NULL;
    copy_lights(p, c, o->lights, o->nlights);
    return c;
}

/* Append the lights of `from` to `to`. */
static void merge_lights(sdl_parser *p, sdl_obj *to, const sdl_obj *from)
{
    if (from->nlights == 0) return;
    int n = to->nlights + from->nlights;
    scene_light *l = sdl_alloc(p, sizeof *l * (size_t)n);
    if (!l) return;
    if (to->nlights) memcpy(l, to->lights, sizeof *l * (size_t)to->nlights);
    memcpy(l + to->nlights, from->lights, sizeof *l * (size_t)from->nlights);
    to->lights = l;
    to->nlights = n;
}

/* ------------------------------------------------------------ finishing */

enum { INHERITED_FLAGS = OBJ_NO_REFLECTION | OBJ_NO_RADIOSITY | OBJ_NO_IMAGE | OBJ_NO_SHADOW };

/* An object's own copy of its interior: POV-Ray gives each object its own
 * Interior (a declared material or interior is copied into every object
 * that uses it, parser.cpp), and a ray's list of the objects it is inside
 * tells them apart by it (shade_media.h). */
static void own_interior(sdl_parser *p, scene_object *o)
{
    if (!o->interior) return;
    scene_interior *in = sdl_dup(p, o->interior, sizeof *in);
    if (!in) return;
    o->interior = in;
}

/* POV-Ray's post-processing: kids take the parent's texture, interior
 * texture, interior (the same one: parser.cpp's Post_Process) and
 * visibility flags when they have none. */
static void post_process(sdl_parser *p, scene_object *o, const scene_object *parent, const scene_texture *deflt)
{
    int own = o->interior != NULL;
    if (!parent || o->interior) own_interior(p, o);
    if (parent) {
        if (!o->texture) o->texture = parent->texture;
        if (!o->interior_texture) o->interior_texture = parent->interior_texture;
        if (!o->interior) {
            o->interior = parent->interior;
            /* interior media live in the container's space: a member with
             * transforms of its own sees the parent's media through them */
            if (o->interior && o->interior->nmedia && memcmp(&o->transform, &parent->transform, sizeof o->transform) != 0) {
                scene_interior *in = sdl_alloc(p, sizeof *in);
                if (in) {
                    *in = *parent->interior;
                    in->nmedia = 0;
                    in->media = NULL;
                    xform rebase = xform_then(parent->transform, xform_inverse(o->transform));
                    for (int i = 0; i < parent->interior->nmedia; i++) {
                        scene_media *c = sdl_dup(p, parent->interior->media[i], sizeof *c);
                        if (!c) break;
                        c->transform = xform_then(c->transform, rebase);
                        sdl_media_append(p, &in->media, &in->nmedia, c);
                    }
                    o->interior = in;
                }
            }
        }
        o->flags |= parent->flags & INHERITED_FLAGS;
    }
    o->medium = own ? (const void *)o->interior : parent ? parent->medium : (const void *)o;
    if (!o->texture) o->texture = deflt;
    if (o->kind == SHAPE_MESH && o->u.mesh.mesh) ((scene_mesh *)o->u.mesh.mesh)->uses++;
    if (scene_object_is_csg(o))
        for (int i = 0; i < o->u.csg.nkids; i++) post_process(p, o->u.csg.kids[i], o, deflt);
}

void sdl_obj_add_to_scene(sdl_parser *p, sdl_obj *o)
{
    if (!o || !sdl_ok(p)) return;
    const scene_texture *deflt = NULL;
    if (p->default_texture_set) deflt = sdl_copy_texture(p, &p->s->default_texture);
    if (o->obj) {
        post_process(p, o->obj, NULL, deflt);
        if (scene_add_object(p->s, o->obj) != PT_OK) sdl_error(p, o->obj->loc, PT_ERR_NOMEM, "out of memory");
    }
    for (int i = 0; i < o->nlights; i++) {
        if (o->lights[i].looks_like) {
            post_process(p, (scene_object *)o->lights[i].looks_like, NULL, deflt);
            /* POV-Ray renders the looks_like object with the scene */
            if (scene_add_object(p->s, (scene_object *)o->lights[i].looks_like) != PT_OK)
                sdl_error(p, o->lights[i].loc, PT_ERR_NOMEM, "out of memory");
        }
        if (scene_add_light(p->s, &o->lights[i]) != PT_OK) sdl_error(p, o->lights[i].loc, PT_ERR_NOMEM, "out of memory");
    }
}

/* ------------------------------------------------------------ modifiers */

/* Put a new texture layer on top of the object's textures. */
static void link_texture(scene_object *o, scene_texture *t)
{
    if (!t) return;
    scene_texture *last = t;
    while (last->next) last = last->next;
    last->next = own_texture(o->texture);
    o->texture = t;
}

/* The top texture layer, created from the default texture if needed. */
static scene_texture *top_texture(sdl_parser *p, scene_object *o)
{
    if (!o->texture) {
        scene_texture *t = sdl_dup(p, &p->s->default_texture, sizeof *t);
        if (!t) return NULL;
        t->next = NULL;
        t->transform = xform_identity();
        t->loc = o->loc;
        o->texture = t;
    }
    return own_texture(o->texture);
}

static void set_flag(scene_object *o, unsigned flag, int on, int recurse)
{
    if (on) o->flags |= flag;
    else o->flags &= ~flag;
    if (recurse && scene_object_is_csg(o))
        for (int i = 0; i < o->u.csg.nkids; i++) set_flag(o->u.csg.kids[i], flag, on, 1);
}

/* flag_mod := ( no_image | no_reflection | no_radiosity | hollow |
 *   double_illuminate | sturm | hierarchy | split_union ) [ bool ] | no_shadow |
 *   inverse | open ; returns 0 if the keyword is not one of them. */
static int flag_mod(sdl_parser *p, scene_object *o, sdl_kw k, src_loc loc)
{
    unsigned flag = 0;
    int recurse = 0, has_arg = 1;
    switch (k) {
    case KW_NO_IMAGE: flag = OBJ_NO_IMAGE; break;
    case KW_NO_REFLECTION: flag = OBJ_NO_REFLECTION; break;
    case KW_NO_RADIOSITY: flag = OBJ_NO_RADIOSITY; break;
    case KW_HOLLOW: flag = OBJ_HOLLOW; recurse = 1; break;
    case KW_DOUBLE_ILLUMINATE: flag = OBJ_DOUBLE_ILLUMINATE; recurse = 1; break;
    case KW_STURM: flag = OBJ_STURM; break;
    case KW_NO_SHADOW: flag = OBJ_NO_SHADOW; has_arg = 0; break;
    case KW_OPEN: flag = OBJ_OPEN; has_arg = 0; break;
    case KW_INVERSE: o->flags ^= OBJ_INVERSE; return 1;
    case KW_HIERARCHY: case KW_SPLIT_UNION: sdl_allow_float(p, 1.0); return 1;
    case KW_UV_MAPPING:
        /* POV-Ray 3.7: "uv_mapping must be specified before texture" */
        if (o->texture) sdl_error(p, loc, PT_ERR_SYNTAX, "uv_mapping must be specified before texture");
        set_uv_mapping(o, 1);
        return 1;
    case KW_CUTAWAY_TEXTURES: return 1;
    default: return 0;
    }
    int on = has_arg ? sdl_allow_float(p, 1.0) > 0.0 : 1;
    set_flag(o, flag, on, recurse);
    return 1;
}

/* material_mod := texture | interior_texture | pigment | finish | normal |
 *   interior | material | ior ; returns 0 if not one of them. */
static int material_mod(sdl_parser *p, scene_object *o, sdl_kw k)
{
    switch (k) {
    case KW_TEXTURE: link_texture(o, sdl_parse_texture(p)); return 1;
    case KW_INTERIOR_TEXTURE: o->interior_texture = sdl_parse_texture(p); return 1;
    case KW_PIGMENT: {
        scene_texture *t = top_texture(p, o);
        if (t) sdl_parse_pigment(p, &t->pigment);
        return 1;
    }
    case KW_FINISH: {
        scene_texture *t = top_texture(p, o);
        if (t) sdl_parse_finish(p, &t->finish);
        return 1;
    }
    case KW_NORMAL: {
        scene_texture *t = top_texture(p, o);
        if (t) sdl_attach_normal(p, t);
        else sdl_parse_normal(p);
        return 1;
    }
    case KW_INTERIOR: {
        scene_interior *in = sdl_alloc(p, sizeof *in);
        if (!in) return 1;
        if (o->interior) *in = *o->interior;
        else scene_default_interior(in);
        sdl_parse_interior(p, in);
        sdl_media_attach(p, in, o->interior, &o->transform); /* media: transforms written so far are not theirs */
        o->interior = in;
        return 1;
    }
    case KW_MATERIAL: {
        const scene_interior *before = o->interior;
        sdl_material m = {own_texture(o->texture), own_texture(o->interior_texture), (scene_interior *)o->interior};
        sdl_parse_material(p, &m);
        o->texture = m.texture;
        o->interior_texture = m.interior_texture;
        if (m.interior && m.interior != before && m.interior->nmedia) {
            scene_interior *in = sdl_dup(p, m.interior, sizeof *in);
            if (!in) return 1;
            sdl_media_attach(p, in, before, &o->transform);
            m.interior = in;
        }
        o->interior = m.interior;
        return 1;
    }
    case KW_IOR: {
        scene_interior *in = sdl_alloc(p, sizeof *in);
        if (!in) return 1;
        if (o->interior) *in = *o->interior;
        else scene_default_interior(in);
        in->ior = sdl_float(p);
        o->interior = in;
        return 1;
    }
    default:
        return 0;
    }
}

static void photons_to_members(scene_object *o, const scene_obj_photons *ph)
{
    if (!scene_object_is_csg(o)) return;
    for (int i = 0; i < o->u.csg.nkids; i++) {
        scene_object *k = o->u.csg.kids[i];
        if (!k->photons) {
            k->photons = ph;
            photons_to_members(k, ph);
        }
    }
}

/* photons_mod := photons '{' { target [f] | reflection b | refraction b |
 *   collect [b] | pass_through [b] } '}'  (POV-Ray 3.7's object photons
 *   block; IR: scene_obj_photons with the keyword's location) */
static void photons_mod(sdl_parser *p, scene_object *o, src_loc loc)
{
    scene_obj_photons *ph = sdl_alloc(p, sizeof *ph);
    if (!ph) return;
    if (o->photons) *ph = *o->photons;
    else {
        memset(ph, 0, sizeof *ph);
        ph->spacing = 1.0;
        ph->collect = 1;
    }
    ph->loc = loc;
    if (!sdl_begin_block(p, "photons")) return;
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE)) {
        sdl_tok t = sdl_next(p);
        if (sdl_is_kw(&t, KW_TARGET)) {
            ph->spacing = sdl_allow_float(p, 1.0);
            ph->target = ph->spacing > 0.0;
        } else if (sdl_is_kw(&t, KW_REFLECTION)) {
            ph->reflection = sdl_float(p) != 0.0;
            ph->reflection_off = !ph->reflection;
        } else if (sdl_is_kw(&t, KW_REFRACTION)) {
            ph->refraction = sdl_float(p) != 0.0;
            ph->refraction_off = !ph->refraction;
        } else if (sdl_is_kw(&t, KW_COLLECT)) {
            ph->collect = sdl_allow_float(p, 1.0) != 0.0;
        } else if (sdl_is_kw(&t, KW_PASS_THROUGH)) {
            ph->pass_through = sdl_allow_float(p, 1.0) != 0.0;
        } else {
            sdl_unexpected(p, &t, "target, reflection, refraction, collect, pass_through or '}'");
            return;
        }
    }
    sdl_end_block(p);
    o->photons = ph;
    photons_to_members(o, ph);
}

/* skipped_mod := bounded_by {..} | clipped_by {..} | photons {..} |
 *   radiosity {..} | quick colour ; 0 if not one of them */
static int skipped_mod(sdl_parser *p, const sdl_tok *t)
{
    sdl_kw k = t->tk.kw;
    if (k == KW_BOUNDED_BY || k == KW_RADIOSITY) {
        if (sdl_begin_block(p, sdl_kw_text(k))) sdl_skip_block(p);
        return 1;
    }
    if (k == KW_CLIPPED_BY) {
        sdl_ignore_block(p, t->tk.loc, "clipped_by", "clipped_by is not supported yet; objects are not clipped");
        return 1;
    }
    if (sdl_starts_colour(t)) {
        sdl_unget(p, t);
        sdl_colour(p, 1);
        sdl_warn_once(p, t->tk.loc, "quick colour belongs in a texture; colour ignored");
        return 1;
    }
    return 0;
}

/* object_mods := { transform_item | flag_mod | material_mod | skipped_mod } */
void sdl_object_mods(sdl_parser *p, sdl_obj *so)
{
    while (sdl_ok(p)) {
        xform x;
        if (sdl_transform_item(p, &x)) {
            sdl_obj_transform(so, &x);
            continue;
        }
        const sdl_tok *pk = sdl_peek(p);
        if (pk->tk.kind != TOK_KEYWORD) return;
        if (!so->obj) {
            /* a bare light source: only transformations apply */
            return;
        }
        sdl_tok t = sdl_next(p);
        if (t.tk.kw == KW_CLIPPED_BY || t.tk.kw == KW_BOUNDED_BY) { /* sdl_shape.c */
            if (t.tk.kw == KW_CLIPPED_BY) sdl_clip_clipped_by(p, so);
            else sdl_clip_bounded_by(p, so);
            continue;
        }
        if (t.tk.kw == KW_PHOTONS) {
            photons_mod(p, so->obj, t.tk.loc);
            continue;
        }
        if (flag_mod(p, so->obj, t.tk.kw, t.tk.loc) || material_mod(p, so->obj, t.tk.kw) || skipped_mod(p, &t)) continue;
        sdl_unget(p, &t);
        return;
    }
}

/* ------------------------------------------------------------ shapes */

/* sphere_args := centre ',' radius */
static void sphere_args(sdl_parser *p, scene_object *o)
{
    o->u.sphere.centre = sdl_vector(p);
    sdl_accept(p, TOK_COMMA);
    o->u.sphere.radius = sdl_float(p);
}

/* box_args := corner ',' corner   (stored with c1 <= c2 per axis) */
static void box_args(sdl_parser *p, scene_object *o)
{
    vec3 a = sdl_vector(p);
    sdl_accept(p, TOK_COMMA);
    vec3 b = sdl_vector(p);
    o->u.box.c1 = v3_min(a, b);
    o->u.box.c2 = v3_max(a, b);
}

/* plane_args := normal ',' distance   (points p with n.p = d, n unit) */
static void plane_args(sdl_parser *p, scene_object *o, src_loc loc)
{
    vec3 n = sdl_vector(p);
    sdl_accept(p, TOK_COMMA);
    double d = sdl_float(p);
    double len = v3_len(n);
    if (len == 0) {
        if (sdl_ok(p)) sdl_error(p, loc, PT_ERR_SYNTAX, "plane normal has zero length");
        return;
    }
    o->u.plane.normal = v3_scale(n, 1.0 / len);
    o->u.plane.offset = d; /* POV-Ray normalises the normal but not the distance */
}

/* triangle_args := v ',' v ',' v ; smooth_triangle_args := v ',' n ',' v ',' n ',' v ',' n */
static void triangle_args(sdl_parser *p, scene_object *o, int smooth)
{
    for (int i = 0; i < 3; i++) {
        if (i) sdl_accept(p, TOK_COMMA);
        o->u.triangle.v[i] = sdl_vector(p);
        if (smooth) {
            sdl_accept(p, TOK_COMMA);
            o->u.triangle.n[i] = sdl_vector(p);
        }
    }
}

/* cylinder_args := base ',' cap ',' radius [ 'open' ] ;
 * cone_args := base ',' radius ',' cap ',' radius [ 'open' ] */
static void cone_args(sdl_parser *p, scene_object *o, int cylinder)
{
    o->u.cone.base = sdl_vector(p);
    sdl_accept(p, TOK_COMMA);
    if (!cylinder) {
        o->u.cone.base_radius = sdl_float(p);
        sdl_accept(p, TOK_COMMA);
    }
    o->u.cone.cap = sdl_vector(p);
    sdl_accept(p, TOK_COMMA);
    o->u.cone.cap_radius = sdl_float(p);
    if (cylinder) o->u.cone.base_radius = o->u.cone.cap_radius;
    if (sdl_accept_kw(p, KW_OPEN)) o->flags |= OBJ_OPEN;
}

/* disc_args := centre ',' normal ',' radius [ ',' hole_radius ] */
static void disc_args(sdl_parser *p, scene_object *o)
{
    o->u.disc.centre = sdl_vector(p);
    sdl_accept(p, TOK_COMMA);
    o->u.disc.normal = sdl_vector(p);
    sdl_accept(p, TOK_COMMA);
    o->u.disc.radius = sdl_float(p);
    if (sdl_accept(p, TOK_COMMA)) o->u.disc.hole_radius = sdl_float(p);
}

/* torus_args := major ',' minor [ 'sturm' ] */
static void torus_args(sdl_parser *p, scene_object *o)
{
    o->u.torus.major = sdl_float(p);
    sdl_accept(p, TOK_COMMA);
    o->u.torus.minor = sdl_float(p);
}

/* ------------------------------------------------------------ meshes */

typedef struct {
    float (*v)[3];
    int nv, capv;
    float (*n)[3];
    int nn, capn;
    float (*uv)[2];
    int nuv, capuv;
    int (*tri)[3];
    int (*trin)[3];
    int *trit;
    int (*triuv)[3]; /* uv indices per triangle (default: the vertex indices) */
    int nt, capt;
    int zero_uv;     /* mesh: index of a <0,0> uv for triangles without uv_vectors, -1 none yet */
    int uv_indices;  /* mesh2: uv_indices given */
    int any_uv;      /* mesh: some triangle has uv_vectors */
    const scene_texture **tex;
    int ntex, captex;
    int any_normals, any_tex;
    sdl_parser *p;   /* work memory is counted in p->build_bytes */
    size_t bytes;    /* this mesh's share of it */
} mesh_build;

/* grow_array_int() for a mesh's work arrays, within the parser's memory limit. */
static int mesh_grow(mesh_build *b, void **arr, int *cap, int need, size_t elem)
{
    if (need <= *cap) return 1;
    if (need > (1 << 28)) {
        sdl_error(b->p, b->p->last_loc, PT_ERR_LIMIT, "mesh has more than %d entries in one list", 1 << 28);
        return 0;
    }
    int old = *cap;
    size_t more = elem * grow_capacity((size_t)old, (size_t)need);
    if (!sdl_memory_ok(b->p, more, b->p->last_loc, "the mesh")) return 0;
    if (!grow_array_int(arr, cap, need, elem)) return 0;
    more = elem * (size_t)(*cap - old);
    b->bytes += more;
    b->p->build_bytes += more;
    return 1;
}

static void mesh_build_free(mesh_build *b)
{
    b->p->build_bytes -= b->bytes;
    free(b->v);
    free(b->n);
    free(b->uv);
    free(b->tri);
    free(b->trin);
    free(b->trit);
    free(b->triuv);
    free(b->tex);
}

static int add_vec(sdl_parser *p, mesh_build *b, float (**arr)[3], int *n, int *cap, vec3 v)
{
    if (!mesh_grow(b, (void **)arr, cap, *n + 1, sizeof **arr)) {
        src_loc none = {NULL, 0, 0};
        sdl_error(p, none, PT_ERR_NOMEM, "out of memory");
        return -1;
    }
    v3_store_f((*arr)[*n], v);
    return (*n)++;
}

/* Index of a texture in the mesh's texture list (added if new). */
static int mesh_texture_index(mesh_build *b, const scene_texture *t)
{
    for (int i = 0; i < b->ntex; i++)
        if (b->tex[i] == t) return i;
    if (!mesh_grow(b, (void **)&b->tex, &b->captex, b->ntex + 1, sizeof *b->tex)) return -1;
    b->tex[b->ntex] = t;
    return b->ntex++;
}

/* Room for one more triangle in the three per-triangle arrays. */
static int reserve_tri(mesh_build *b)
{
    if (b->nt < b->capt) return 1;
    int nc = b->capt ? b->capt * 2 : 64;
    size_t more = (sizeof *b->tri + sizeof *b->trin + sizeof *b->trit + sizeof *b->triuv) * (size_t)(nc - b->capt);
    if (nc > (1 << 28)) {
        sdl_error(b->p, b->p->last_loc, PT_ERR_LIMIT, "mesh has more than %d triangles", 1 << 28);
        return 0;
    }
    if (!sdl_memory_ok(b->p, more, b->p->last_loc, "the mesh")) return 0;
    int (*tri)[3] = realloc(b->tri, sizeof *tri * (size_t)nc);
    if (tri) b->tri = tri;
    int (*trin)[3] = tri ? realloc(b->trin, sizeof *trin * (size_t)nc) : NULL;
    if (trin) b->trin = trin;
    int *trit = trin ? realloc(b->trit, sizeof *trit * (size_t)nc) : NULL;
    if (trit) b->trit = trit;
    int (*triuv)[3] = trit ? realloc(b->triuv, sizeof *triuv * (size_t)nc) : NULL;
    if (triuv) b->triuv = triuv;
    if (!triuv) return 0;
    b->capt = nc;
    b->bytes += more;
    b->p->build_bytes += more;
    return 1;
}

static int add_tri(sdl_parser *p, mesh_build *b, const int v[3], const int n[3], int tex)
{
    if (!reserve_tri(b)) {
        sdl_error(p, p->last_loc, PT_ERR_NOMEM, "out of memory");
        return 0;
    }
    memcpy(b->tri[b->nt], v, sizeof b->tri[0]);
    memcpy(b->trin[b->nt], n, sizeof b->trin[0]);
    memcpy(b->triuv[b->nt], v, sizeof b->triuv[0]);
    b->trit[b->nt] = tex;
    b->nt++;
    return 1;
}

/* mesh_triangle := ('triangle' | 'smooth_triangle') '{' vertices
 *   [ 'uv_vectors' uv ',' uv ',' uv ] [ 'texture' texture ] '}' */
static void mesh_triangle(sdl_parser *p, mesh_build *b, int smooth)
{
    if (!sdl_begin_block(p, smooth ? "smooth_triangle" : "triangle")) return;
    vec3 v[3], n[3];
    for (int i = 0; i < 3; i++) {
        if (i) sdl_accept(p, TOK_COMMA);
        v[i] = sdl_vector(p);
        if (smooth) {
            sdl_accept(p, TOK_COMMA);
            n[i] = sdl_vector(p);
        }
    }
    /* uv_vectors: the corners' uv (POV-Ray's Parse_Three_UVCoords; <0,0>
     * for all three without them) */
    double uv[3][2] = {{0, 0}, {0, 0}, {0, 0}};
    int has_uv = 0;
    if (sdl_accept_kw(p, KW_UV_VECTORS)) {
        for (int i = 0; i < 3; i++) {
            if (i) sdl_accept(p, TOK_COMMA);
            sdl_vector_n(p, uv[i], 2);
        }
        has_uv = 1;
        b->any_uv = 1;
    }
    int tex = -1;
    if (sdl_accept_kw(p, KW_TEXTURE)) {
        tex = mesh_texture_index(b, sdl_parse_texture(p));
        b->any_tex = 1;
    }
    sdl_end_block(p);
    if (!sdl_ok(p)) return;
    int vi[3], ni[3];
    for (int i = 0; i < 3; i++) vi[i] = add_vec(p, b, &b->v, &b->nv, &b->capv, v[i]);
    /* a flat triangle among smooth ones keeps POV-Ray's face normal
     * (P3-P1) x (P2-P1) (Mesh::Compute_Mesh_Triangle), which trace() reports */
    if (!smooth) n[0] = n[1] = n[2] = v3_cross(v3_sub(v[2], v[0]), v3_sub(v[1], v[0]));
    for (int i = 0; i < 3; i++) ni[i] = add_vec(p, b, &b->n, &b->nn, &b->capn, n[i]);
    if (smooth) b->any_normals = 1;
    int ui[3];
    for (int i = 0; i < 3; i++) {
        if (!has_uv && b->zero_uv >= 0) {
            ui[i] = b->zero_uv;
            continue;
        }
        if (!mesh_grow(b, (void **)&b->uv, &b->capuv, b->nuv + 1, sizeof *b->uv)) return;
        b->uv[b->nuv][0] = (float)uv[i][0];
        b->uv[b->nuv][1] = (float)uv[i][1];
        ui[i] = b->nuv++;
        if (!has_uv) b->zero_uv = ui[i];
    }
    if (sdl_ok(p) && add_tri(p, b, vi, ni, tex)) memcpy(b->triuv[b->nt - 1], ui, sizeof ui);
}

static scene_mesh *finish_mesh(sdl_parser *p, mesh_build *b, src_loc loc)
{
    scene_mesh *m = scene_new_mesh(p->s);
    if (!m) {
        sdl_error(p, loc, PT_ERR_NOMEM, "out of memory");
        return NULL;
    }
    m->loc = loc;
    m->nverts = b->nv;
    m->ntris = b->nt;
    m->verts = arena_memdup(p->s->mem, b->v, sizeof *b->v * (size_t)(b->nv ? b->nv : 1));
    m->tris = arena_memdup(p->s->mem, b->tri, sizeof *b->tri * (size_t)(b->nt ? b->nt : 1));
    if (b->any_normals && b->nn) {
        m->nnormals = b->nn;
        m->normals = arena_memdup(p->s->mem, b->n, sizeof *b->n * (size_t)b->nn);
        m->tri_normals = arena_memdup(p->s->mem, b->trin, sizeof *b->trin * (size_t)(b->nt ? b->nt : 1));
    }
    if (b->nuv) {
        m->nuvs = b->nuv;
        m->uvs = arena_memdup(p->s->mem, b->uv, sizeof *b->uv * (size_t)b->nuv);
        m->tri_uvs = arena_memdup(p->s->mem, b->triuv, sizeof *b->triuv * (size_t)(b->nt ? b->nt : 1));
    }
    if (b->any_tex && b->ntex) {
        m->ntextures = b->ntex;
        m->textures = arena_memdup(p->s->mem, b->tex, sizeof *b->tex * (size_t)b->ntex);
        m->tri_texture = arena_memdup(p->s->mem, b->trit, sizeof *b->trit * (size_t)(b->nt ? b->nt : 1));
    }
    return m;
}

/* mesh_inside_vector := 'inside_vector' vector */
static void inside_vector(sdl_parser *p, scene_object *o)
{
    o->u.mesh.inside_vector = sdl_vector(p);
    o->u.mesh.inside_vector_set = 1;
}

/* mesh := '{' { mesh_triangle } [ inside_vector ] [ hierarchy [bool] ] object_mods '}' */
static void mesh_body(sdl_parser *p, sdl_obj *so, src_loc loc)
{
    mesh_build b;
    memset(&b, 0, sizeof b);
    b.p = p;
    b.zero_uv = -1;
    for (;;) {
        if (!sdl_ok(p)) break;
        if (sdl_accept_kw(p, KW_TRIANGLE)) mesh_triangle(p, &b, 0);
        else if (sdl_accept_kw(p, KW_SMOOTH_TRIANGLE)) mesh_triangle(p, &b, 1);
        else if (sdl_accept_kw(p, KW_INSIDE_VECTOR)) inside_vector(p, so->obj);
        else break;
    }
    if (sdl_ok(p) && b.nt == 0) sdl_error(p, loc, PT_ERR_SYNTAX, "mesh has no triangles");
    if (!b.any_uv) b.nuv = 0; /* every uv <0,0>: keep none */
    if (sdl_ok(p)) so->obj->u.mesh.mesh = finish_mesh(p, &b, loc);
    if (sdl_ok(p) && so->obj->u.mesh.mesh)
        own_mesh_textures(p, so->obj, so->obj->u.mesh.mesh->textures, so->obj->u.mesh.mesh->ntextures);
    mesh_build_free(&b);
}

/* The count that opens a mesh2 list: a whole number of entries that fits
 * the parser's memory limit (checked before any entry is read, so a huge
 * declared mesh fails at once with a clear message). */
static int list_count(sdl_parser *p, const char *name, size_t entry_bytes)
{
    src_loc at = sdl_peek(p)->tk.loc;
    double c = sdl_float(p);
    if (!sdl_ok(p)) return 0;
    if (!(c >= 0)) {
        sdl_error(p, at, PT_ERR_SYNTAX, "%s: count %g is not a number of entries", name, c);
        return 0;
    }
    double bytes = (c < 1e15 ? c : 1e15) * (double)entry_bytes;
    char what[96];
    snprintf(what, sizeof what, "%s with %.0f entries", name, c < 1e15 ? c : 1e15);
    if (!sdl_memory_ok(p, (size_t)bytes, at, what)) return 0;
    if (c > (1 << 28)) {
        sdl_error(p, at, PT_ERR_LIMIT, "%s: %.0f entries, more than a mesh may have (%d)", name, c, 1 << 28);
        return 0;
    }
    return (int)c;
}

/* count_list := '{' count [','] item { [','] item } '}' for vertex_vectors,
 * normal_vectors, uv_vectors: vectors with `dim` terms */
static void vector_list(sdl_parser *p, const char *name, int dim, mesh_build *b, int which)
{
    if (!sdl_begin_block(p, name)) return;
    src_loc loc = sdl_peek(p)->tk.loc;
    int count = list_count(p, name, dim == 2 ? sizeof *b->uv : sizeof *b->v);
    int got = 0;
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE)) {
        sdl_accept(p, TOK_COMMA);
        if (sdl_is(sdl_peek(p), TOK_RBRACE)) break;
        double v[3] = {0, 0, 0};
        sdl_vector_n(p, v, dim);
        if (which == 0) add_vec(p, b, &b->v, &b->nv, &b->capv, v3(v[0], v[1], v[2]));
        else if (which == 1) add_vec(p, b, &b->n, &b->nn, &b->capn, v3(v[0], v[1], v[2]));
        else if (mesh_grow(b, (void **)&b->uv, &b->capuv, b->nuv + 1, sizeof *b->uv)) {
            b->uv[b->nuv][0] = (float)v[0];
            b->uv[b->nuv][1] = (float)v[1];
            b->nuv++;
        }
        got++;
    }
    sdl_end_block(p);
    if (sdl_ok(p) && got != count) sdl_error(p, loc, PT_ERR_SYNTAX, "%s: %d entries declared but %d given", name, count, got);
}

/* texture_list := '{' count { [','] texture texture_block } '}' */
static void texture_list(sdl_parser *p, mesh_build *b)
{
    if (!sdl_begin_block(p, "texture_list")) return;
    src_loc loc = sdl_peek(p)->tk.loc;
    int count = list_count(p, "texture_list", sizeof *b->tex);
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE)) {
        sdl_accept(p, TOK_COMMA);
        if (!sdl_accept_kw(p, KW_TEXTURE)) {
            sdl_tok t = sdl_next(p);
            sdl_unexpected(p, &t, "texture");
            return;
        }
        scene_texture *t = sdl_parse_texture(p);
        if (mesh_grow(b, (void **)&b->tex, &b->captex, b->ntex + 1, sizeof *b->tex)) b->tex[b->ntex++] = t;
    }
    sdl_end_block(p);
    if (sdl_ok(p) && b->ntex != count) sdl_error(p, loc, PT_ERR_SYNTAX, "texture_list: %d entries declared but %d given", count, b->ntex);
}

static int check_index(sdl_parser *p, int i, int n, const char *what, src_loc loc)
{
    if (i >= 0 && i < n) return 1;
    if (sdl_ok(p)) sdl_error(p, loc, PT_ERR_SYNTAX, "%s index %d out of range (0..%d)", what, i, n - 1);
    return 0;
}

/* face_indices := '{' count { [','] '<' a ',' b ',' c '>' [ ',' t [ ',' t ',' t ] ] } '}' */
static void face_indices(sdl_parser *p, mesh_build *b)
{
    if (!sdl_begin_block(p, "face_indices")) return;
    src_loc loc = sdl_peek(p)->tk.loc;
    int count = list_count(p, "face_indices", sizeof *b->tri + sizeof *b->trin + sizeof *b->trit);
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE)) {
        sdl_accept(p, TOK_COMMA);
        if (sdl_is(sdl_peek(p), TOK_RBRACE)) break;
        src_loc at = sdl_peek(p)->tk.loc;
        vec3 f = sdl_vector(p);
        int v[3] = {sdl_to_int(f.x), sdl_to_int(f.y), sdl_to_int(f.z)}, tex = -1;
        if (sdl_is(sdl_peek(p), TOK_COMMA)) {
            sdl_next(p);
            if (sdl_starts_float(sdl_peek(p))) {
                tex = sdl_to_int(sdl_float(p));
                b->any_tex = 1;
                if (sdl_accept(p, TOK_COMMA) && sdl_starts_float(sdl_peek(p))) {
                    sdl_float(p);
                    sdl_accept(p, TOK_COMMA);
                    sdl_float(p);
                }
            }
        }
        for (int i = 0; i < 3; i++) check_index(p, v[i], b->nv, "vertex", at);
        if (tex >= 0) check_index(p, tex, b->ntex, "texture", at);
        if (sdl_ok(p)) add_tri(p, b, v, v, tex);
    }
    sdl_end_block(p);
    if (sdl_ok(p) && b->nt != count) sdl_error(p, loc, PT_ERR_SYNTAX, "face_indices: %d entries declared but %d given", count, b->nt);
}

/* normal_indices / uv_indices := '{' count { [','] '<' a ',' b ',' c '>' } '}' */
static void index_list(sdl_parser *p, mesh_build *b, int normals)
{
    const char *name = normals ? "normal_indices" : "uv_indices";
    if (!sdl_begin_block(p, name)) return;
    src_loc loc = sdl_peek(p)->tk.loc;
    int count = list_count(p, name, sizeof *b->trin), got = 0;
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE)) {
        sdl_accept(p, TOK_COMMA);
        if (sdl_is(sdl_peek(p), TOK_RBRACE)) break;
        src_loc at = sdl_peek(p)->tk.loc;
        vec3 f = sdl_vector(p);
        int v[3] = {sdl_to_int(f.x), sdl_to_int(f.y), sdl_to_int(f.z)};
        if (normals && got < b->nt) {
            for (int i = 0; i < 3; i++) check_index(p, v[i], b->nn, "normal", at);
            memcpy(b->trin[got], v, sizeof v);
        } else if (!normals && got < b->nt) {
            for (int i = 0; i < 3; i++) check_index(p, v[i], b->nuv, "uv", at);
            memcpy(b->triuv[got], v, sizeof v);
        }
        got++;
    }
    sdl_end_block(p);
    if (sdl_ok(p) && got != count) sdl_error(p, loc, PT_ERR_SYNTAX, "%s: %d entries declared but %d given", name, count, got);
    if (sdl_ok(p) && normals && got != b->nt) sdl_error(p, loc, PT_ERR_SYNTAX, "normal_indices must have one entry per face (%d)", b->nt);
    /* POV-Ray 3.7 (parse.cpp, Parse_Mesh2): "Number of uv indices must equal number of faces." */
    if (sdl_ok(p) && !normals && got != b->nt) sdl_error(p, loc, PT_ERR_SYNTAX, "uv_indices must have one entry per face (%d)", b->nt);
    if (normals) b->any_normals = 2;
    else b->uv_indices = 1;
}

/* mesh2 := '{' vertex_vectors [normal_vectors] [uv_vectors] [texture_list]
 *   face_indices [normal_indices] [uv_indices] [inside_vector] object_mods '}' */
static void mesh2_body(sdl_parser *p, sdl_obj *so, src_loc loc)
{
    mesh_build b;
    memset(&b, 0, sizeof b);
    b.p = p;
    while (sdl_ok(p)) {
        if (sdl_accept_kw(p, KW_VERTEX_VECTORS)) vector_list(p, "vertex_vectors", 3, &b, 0);
        else if (sdl_accept_kw(p, KW_NORMAL_VECTORS)) vector_list(p, "normal_vectors", 3, &b, 1);
        else if (sdl_accept_kw(p, KW_UV_VECTORS)) vector_list(p, "uv_vectors", 2, &b, 2);
        else if (sdl_accept_kw(p, KW_TEXTURE_LIST)) texture_list(p, &b);
        else if (sdl_accept_kw(p, KW_FACE_INDICES)) face_indices(p, &b);
        else if (sdl_accept_kw(p, KW_NORMAL_INDICES)) index_list(p, &b, 1);
        else if (sdl_accept_kw(p, KW_UV_INDICES)) index_list(p, &b, 0);
        else if (sdl_accept_kw(p, KW_INSIDE_VECTOR)) inside_vector(p, so->obj);
        else break;
    }
    if (sdl_ok(p) && b.nt == 0) sdl_error(p, loc, PT_ERR_SYNTAX, "mesh2 has no face_indices");
    /* without normal_indices, normals are indexed like the vertices */
    if (sdl_ok(p) && b.nn > 0 && b.any_normals != 2) {
        if (b.nn != b.nv) sdl_error(p, loc, PT_ERR_SYNTAX, "mesh2 normal_vectors need normal_indices unless there is one per vertex");
        b.any_normals = 1;
    }
    /* without uv_indices (POV-Ray 3.7's Parse_Mesh2): uvs are indexed like
     * the vertices when there is one per vertex, a single uv serves every
     * corner, otherwise it is an error */
    if (sdl_ok(p) && b.nuv > 0 && !b.uv_indices) {
        if (b.nuv == 1) {
            for (int i = 0; i < b.nt; i++) b.triuv[i][0] = b.triuv[i][1] = b.triuv[i][2] = 0;
        } else if (b.nuv != b.nv) {
            sdl_error(p, loc, PT_ERR_SYNTAX, "mesh2 uv_vectors need uv_indices unless there is one per vertex");
        }
    }
    if (sdl_ok(p) && b.uv_indices && b.nuv == 0) sdl_error(p, loc, PT_ERR_SYNTAX, "mesh2 uv_indices without uv_vectors");
    if (sdl_ok(p)) so->obj->u.mesh.mesh = finish_mesh(p, &b, loc);
    if (sdl_ok(p) && so->obj->u.mesh.mesh)
        own_mesh_textures(p, so->obj, so->obj->u.mesh.mesh->textures, so->obj->u.mesh.mesh->ntextures);
    mesh_build_free(&b);
}

/* ------------------------------------------------------------ CSG and object */

/* csg_body := { object_statement } object_mods */
static void csg_body(sdl_parser *p, sdl_obj *so)
{
    scene_object **kids = NULL;
    int n = 0, cap = 0;
    while (sdl_ok(p) && sdl_starts_object(sdl_peek(p))) {
        sdl_obj *k = sdl_parse_object(p);
        if (!k) break;
        merge_lights(p, so, k);
        if (!k->obj) continue;
        if (!grow_array_int((void **)&kids, &cap, n + 1, sizeof *kids)) {
            sdl_error(p, k->obj->loc, PT_ERR_NOMEM, "out of memory");
            break;
        }
        kids[n++] = k->obj;
    }
    so->obj->u.csg.nkids = n;
    so->obj->u.csg.kids = n ? arena_memdup(p->s->mem, kids, sizeof *kids * (size_t)n) : NULL;
    free(kids);
}

/* An object identifier at the start of a shape block: a copy of it. */
static sdl_obj *object_identifier(sdl_parser *p)
{
    const sdl_tok *t = sdl_peek(p);
    if (t->tk.kind != TOK_IDENT || t->val.kind != VAL_OBJECT) return NULL;
    sdl_tok id = sdl_next(p);
    return sdl_copy_obj(p, id.val.ptr);
}

/* object := 'object' '{' ( object_identifier | object_statement ) object_mods '}' */
static sdl_obj *object_body(sdl_parser *p)
{
    sdl_obj *so = object_identifier(p);
    if (so) return so;
    const sdl_tok *t = sdl_peek(p);
    if (sdl_starts_object(t)) return sdl_parse_object(p);
    sdl_tok bad = sdl_next(p);
    sdl_unexpected(p, &bad, "object identifier or object");
    return NULL;
}

sdl_obj *sdl_parse_object_body(sdl_parser *p)
{
    return object_body(p); /* no modifiers: POV-Ray's Parse_Bound_Clip takes the object as it is */
}

static shape_kind shape_of(sdl_kw k)
{
    switch (k) {
    case KW_SPHERE: return SHAPE_SPHERE;
    case KW_BOX: return SHAPE_BOX;
    case KW_PLANE: return SHAPE_PLANE;
    case KW_TRIANGLE: return SHAPE_TRIANGLE;
    case KW_SMOOTH_TRIANGLE: return SHAPE_SMOOTH_TRIANGLE;
    case KW_MESH: case KW_MESH2: return SHAPE_MESH;
    case KW_UNION: case KW_LIGHT_GROUP: return SHAPE_UNION;
    case KW_MERGE: return SHAPE_MERGE;
    case KW_INTERSECTION: return SHAPE_INTERSECTION;
    case KW_DIFFERENCE: return SHAPE_DIFFERENCE;
    case KW_CYLINDER: return SHAPE_CYLINDER;
    case KW_CONE: return SHAPE_CONE;
    case KW_DISC: return SHAPE_DISC;
    case KW_TORUS: return SHAPE_TORUS;
    default: return SHAPE_UNSUPPORTED;
    }
}

/* shape_args for the analytic shapes, meshes and CSG */
static void shape_args(sdl_parser *p, sdl_kw k, sdl_obj *so, src_loc loc)
{
    scene_object *o = so->obj;
    switch (k) {
    case KW_SPHERE: sphere_args(p, o); break;
    case KW_BOX: box_args(p, o); break;
    case KW_PLANE: plane_args(p, o, loc); break;
    case KW_TRIANGLE: triangle_args(p, o, 0); break;
    case KW_SMOOTH_TRIANGLE: triangle_args(p, o, 1); break;
    case KW_CYLINDER: cone_args(p, o, 1); break;
    case KW_CONE: cone_args(p, o, 0); break;
    case KW_DISC: disc_args(p, o); break;
    case KW_TORUS: torus_args(p, o); break;
    case KW_MESH: mesh_body(p, so, loc); break;
    case KW_MESH2: mesh2_body(p, so, loc); break;
    default:
        if (sdl_shape_handles(k)) sdl_shape_args(p, k, so, loc); /* further shapes */
        else csg_body(p, so);
        break;
    }
}

/* unsupported_shape := keyword '{' ... '}' skipped by brace matching */
static sdl_obj *unsupported_shape(sdl_parser *p, const sdl_tok *k)
{
    const char *name = sdl_kw_text(k->tk.kw);
    sdl_warn_once(p, k->tk.loc, "shape '%s' is not supported yet; it is skipped", name);
    sdl_obj *so = new_obj(p, SHAPE_UNSUPPORTED, name, k->tk.loc);
    if (sdl_begin_block(p, name)) sdl_skip_block(p);
    return so;
}

/* Objects of a light_group not already in an inner one join group id; the
 * global_lights setting of the outermost group wins for all of them, as
 * POV-Ray's Set_CSG_Children_Flag overwrites the inner groups' flags. */
static void mark_light_group(scene_object *o, int id, int no_global)
{
    if (!o->light_group) o->light_group = id;
    o->no_global_lights = no_global;
    if (scene_object_is_csg(o))
        for (int i = 0; i < o->u.csg.nkids; i++) mark_light_group(o->u.csg.kids[i], id, no_global);
}

sdl_obj *sdl_parse_object(sdl_parser *p)
{
    sdl_tok k = sdl_next(p);
    if (!sdl_starts_object(&k)) {
        sdl_unexpected(p, &k, "object");
        return NULL;
    }
    if (k.tk.kw == KW_LIGHT_SOURCE) return sdl_parse_light(p, k.tk.loc);
    if (is_unsupported_shape(k.tk.kw) && !sdl_shape_handles(k.tk.kw)) return unsupported_shape(p, &k);
    const char *name = sdl_kw_text(k.tk.kw);
    if (!sdl_begin_block(p, name)) return NULL;
    sdl_obj *so = k.tk.kw == KW_OBJECT ? object_body(p) : object_identifier(p);
    if (!so) {
        so = new_obj(p, shape_of(k.tk.kw), name, k.tk.loc);
        if (!so) return NULL;
        shape_args(p, k.tk.kw, so, k.tk.loc);
    }
    sdl_object_mods(p, so);
    /* light_group: global_lights [bool] may stand among the modifiers
     * (default off: POV-Ray 3.7's Parse_Light_Group) */
    int global_lights = 0;
    while (k.tk.kw == KW_LIGHT_GROUP && sdl_ok(p) && sdl_accept_kw(p, KW_GLOBAL_LIGHTS)) {
        global_lights = sdl_allow_float(p, 1.0) > 0.5;
        sdl_object_mods(p, so);
    }
    if (!sdl_end_block(p)) return NULL;
    if (k.tk.kw == KW_LIGHT_GROUP) {
        /* the group's own lights (not those of inner groups) light only its
         * objects; objects of inner groups keep their group's lights only
         * (POV-Ray's Promote_Local_Lights) */
        int id = ++p->nlight_groups;
        for (int i = 0; i < so->nlights; i++)
            if (so->lights[i].group == 0) so->lights[i].group = id;
        if (so->obj) mark_light_group(so->obj, id, !global_lights);
    }
    return so;
}
