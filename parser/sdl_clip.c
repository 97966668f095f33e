/* sdl_clip.c - clipped_by and bounded_by (sdl_shape.h): the clipping and
 * bounding objects of an object, made relative to its space (sdl_clip.h). */
#include "sdl_clip.h"
#include "scene_leaves.h"
#include <stdlib.h>
#include <string.h>
#include "sdl_directive.h"
#include "sdl_expr.h"
#include "sdl_material.h"
#include "sdl_object.h"

/* Make every node of a clip tree relative to the host's space (see
 * scene_object.clip). */
static void relativize(scene_object *c, const xform *host_inv, int depth)
{
    if (!c || depth > 1000) return;
    c->transform = xform_then(c->transform, *host_inv);
    if (scene_object_is_csg(c))
        for (int i = 0; i < c->u.csg.nkids; i++) relativize(c->u.csg.kids[i], host_inv, depth + 1);
}

/* Add `c` (world transforms) to the host's clip: several clip objects
 * intersect, as in POV-Ray. */
static void add_clip(sdl_parser *p, scene_object *host, scene_object *c)
{
    if (!c) return;
    xform inv = xform_inverse(host->transform);
    relativize(c, &inv, 0);
    if (!host->clip) {
        host->clip = c;
        return;
    }
    scene_object *both = scene_new_object(p->s, SHAPE_INTERSECTION, c->loc);
    scene_object **k = sdl_alloc(p, 2 * sizeof *k);
    if (!both || !k) return;
    both->name = "clipped_by";
    /* identity in host space */
    k[0] = (scene_object *)host->clip;
    k[1] = c;
    both->u.csg.kids = k;
    both->u.csg.nkids = 2;
    host->clip = both;
}

/* objects := { object_statement } '}' -> one object (an intersection when
 * several) with world transforms, or NULL */
static scene_object *clip_objects(sdl_parser *p, src_loc loc)
{
    scene_object *acc = NULL;
    while (sdl_ok(p) && sdl_starts_object(sdl_peek(p))) {
        sdl_obj *k = sdl_parse_object(p);
        if (!k || !k->obj) continue;
        if (!acc) {
            acc = k->obj;
            continue;
        }
        scene_object *both = scene_new_object(p->s, SHAPE_INTERSECTION, loc);
        scene_object **kids = sdl_alloc(p, 2 * sizeof *kids);
        if (!both || !kids) return acc;
        both->name = "clipped_by";
        kids[0] = acc;
        kids[1] = k->obj;
        both->u.csg.kids = kids;
        both->u.csg.nkids = 2;
        acc = both;
    }
    return acc;
}

static scene_object *copy_tree(sdl_parser *p, const scene_object *o, int depth)
{
    if (!o || depth > 1000) return NULL;
    scene_object *c = sdl_dup(p, o, sizeof *c);
    if (!c) return NULL;
    if (scene_object_is_csg(o)) {
        c->u.csg.kids = o->u.csg.nkids ? sdl_alloc(p, sizeof *c->u.csg.kids * (size_t)o->u.csg.nkids) : NULL;
        for (int i = 0; i < o->u.csg.nkids && c->u.csg.kids; i++) c->u.csg.kids[i] = copy_tree(p, o->u.csg.kids[i], depth + 1);
    }
    return c;
}

/* The last bounded_by seen per thread (for `clipped_by { bounded_by }`). */
static _Thread_local const scene_object *last_bound_host;
static _Thread_local scene_object *last_bound;

/* clipped_by := '{' ( objects | bounded_by ) '}' */
void sdl_clip_clipped_by(sdl_parser *p, sdl_obj *so)
{
    src_loc loc = p->last_loc;
    if (!sdl_begin_block(p, "clipped_by")) return;
    scene_object *host = so ? so->obj : NULL;
    if (sdl_accept_kw(p, KW_BOUNDED_BY)) {
        if (host && last_bound_host == host && last_bound) {
            /* the bounding objects, already relative to the host */
            scene_object *c = copy_tree(p, last_bound, 0);
            xform fwd = host->transform;
            relativize(c, &fwd, 0); /* back to world, add_clip makes it relative again */
            add_clip(p, host, c);
        }
        sdl_end_block(p);
        return;
    }
    scene_object *c = clip_objects(p, loc);
    sdl_end_block(p);
    if (host && c && sdl_ok(p)) add_clip(p, host, c);
}

/* bounded_by := '{' ( objects | clipped_by ) '}'
 * POV-Ray's semantics (Ray_In_Bound): a ray sees the object only if it meets
 * every bounding object or starts inside it; the bound never cuts the
 * surface. Kept on every object (scene_object.bound); the renderer drops it
 * where POV-Ray's Link_To_Frame does. `bounded_by { clipped_by }` makes the
 * clip objects the bound. */
void sdl_clip_bounded_by(sdl_parser *p, sdl_obj *so)
{
    src_loc loc = p->last_loc;
    if (!sdl_begin_block(p, "bounded_by")) return;
    scene_object *host = so ? so->obj : NULL;
    if (sdl_accept_kw(p, KW_CLIPPED_BY)) {
        sdl_end_block(p);
        if (host && host->clip && !host->bound) {
            scene_object *list = scene_new_object(p->s, SHAPE_UNION, loc);
            scene_object **k = sdl_alloc(p, sizeof *k);
            if (!list || !k) return;
            list->name = "bounded_by";
            k[0] = copy_tree(p, host->clip, 0); /* already relative to the host */
            list->u.csg.kids = k;
            list->u.csg.nkids = k[0] ? 1 : 0;
            host->bound = list;
        }
        return;
    }
    /* each object is a bound of its own (all must be met) */
    scene_object *objs[64];
    int n = 0;
    while (sdl_ok(p) && sdl_starts_object(sdl_peek(p))) {
        sdl_obj *k = sdl_parse_object(p);
        if (k && k->obj && n < 64) objs[n++] = k->obj;
    }
    sdl_end_block(p);
    if (!host || n == 0 || !sdl_ok(p)) return;
    xform inv = xform_inverse(host->transform);
    /* clipped_by { bounded_by }: the objects intersected, relative to the host */
    scene_object *acc = NULL;
    for (int i = 0; i < n; i++) {
        scene_object *c = copy_tree(p, objs[i], 0);
        if (!c) return;
        if (!acc) {
            acc = c;
            continue;
        }
        scene_object *both = scene_new_object(p->s, SHAPE_INTERSECTION, loc);
        scene_object **kids = sdl_alloc(p, 2 * sizeof *kids);
        if (!both || !kids) return;
        both->name = "clipped_by";
        kids[0] = acc;
        kids[1] = c;
        both->u.csg.kids = kids;
        both->u.csg.nkids = 2;
        acc = both;
    }
    relativize(acc, &inv, 0);
    last_bound_host = host;
    last_bound = acc;
    scene_object *list = scene_new_object(p->s, SHAPE_UNION, loc);
    scene_object **kids = sdl_alloc(p, sizeof *kids * (size_t)n);
    if (!list || !kids) return;
    list->name = "bounded_by";
    for (int i = 0; i < n; i++) {
        kids[i] = copy_tree(p, objs[i], 0);
        if (!kids[i]) return;
        relativize(kids[i], &inv, 0);
    }
    list->u.csg.kids = kids;
    list->u.csg.nkids = n;
    host->bound = list;
}
