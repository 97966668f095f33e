/* gi_surface_csg.c - particles on members of CSG: only where a member's
 * surface is the result's surface. */
#include "gi_surface_internal.h"
#include <math.h>
#include "geom_shape.h"
#include "geom_hfield.h"
#include "accel_surface.h"
#include "geom_sweep.h"
#include "geom_tess.h"
#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------ CSG members
 *
 * A member of merge, intersection or difference has particles only where
 * its surface is the CSG result's surface: POV-Ray's rule (as geom_csg.h),
 * applied at every level from the member up to the root: intersection keeps
 * a point inside all siblings, merge outside all of them, difference the
 * first member's points outside all the others and a subtracted member's
 * inside the first and outside the rest; union keeps everything. Inside
 * tests are the members' own (geom_shape_inside, POV-Ray's Inside_Object:
 * union/merge any, intersection all, difference the first and none of the
 * others, inverse negating). */

static int add_cnode(gi_surface *g, const scene_object *o, int parent)
{
    if (g->ncn == g->capcn) {
        int nc = g->capcn ? 2 * g->capcn : 64;
        csg_node *nn = realloc(g->cn, (size_t)nc * sizeof *nn);
        if (!nn) return -1;
        g->cn = nn;
        g->capcn = nc;
    }
    csg_node *c = &g->cn[g->ncn];
    memset(c, 0, sizeof *c);
    c->o = o;
    c->parent = parent;
    c->first = -1;
    return g->ncn++;
}

static int is_csg_kind(shape_kind k)
{
    return k == SHAPE_UNION || k == SHAPE_MERGE || k == SHAPE_INTERSECTION || k == SHAPE_DIFFERENCE;
}

/* Kids of node `at` (a CSG object), consecutive, then their subtrees. */
static pt_status build_cnodes(gi_surface *g, int at, int depth)
{
    const scene_object *o = g->cn[at].o;
    if (depth > 512) return PT_ERR_LIMIT;
    int first = g->ncn;
    for (int i = 0; i < o->u.csg.nkids; i++)
        if (add_cnode(g, o->u.csg.kids[i], at) < 0) return PT_ERR_NOMEM;
    g->cn[at].first = first;
    g->cn[at].nkids = o->u.csg.nkids;
    for (int i = 0; i < o->u.csg.nkids; i++) {
        const scene_object *k = o->u.csg.kids[i];
        if (is_csg_kind(k->kind)) {
            pt_status st = build_cnodes(g, first + i, depth + 1);
            if (st != PT_OK) return st;
        } else {
            geom_shape *sh = malloc(sizeof *sh);
            if (!sh) return PT_ERR_NOMEM;
            if (geom_shape_init(sh, k) != 0) {
                free(sh);
                continue;
            }
            g->cn[first + i].sh = sh;
        }
    }
    return PT_OK;
}

static int csg_inside(const gi_surface *g, int node, vec3 p)
{
    const csg_node *c = &g->cn[node];
    int in = 0;
    switch (c->o->kind) {
    case SHAPE_UNION: case SHAPE_MERGE:
        for (int i = 0; i < c->nkids && !in; i++) in = csg_inside(g, c->first + i, p);
        break;
    case SHAPE_INTERSECTION:
        in = c->nkids > 0;
        for (int i = 0; i < c->nkids && in; i++) in = csg_inside(g, c->first + i, p);
        break;
    case SHAPE_DIFFERENCE:
        in = c->nkids > 0 && csg_inside(g, c->first, p);
        for (int i = 1; i < c->nkids && in; i++) in = !csg_inside(g, c->first + i, p);
        break;
    default:
        in = c->sh ? geom_shape_inside(c->sh, p) : 0;
        break;
    }
    return (c->o->flags & OBJ_INVERSE) ? !in : in;
}

/* An odd number of inversions on the node and its ancestors, a subtracted
 * member of a difference counting as one (geom_csg.c's inv_odd). */
static int csg_inv_odd(const gi_surface *g, int node)
{
    int odd = 0;
    for (int n = node; n >= 0; n = g->cn[n].parent) {
        odd ^= (g->cn[n].o->flags & OBJ_INVERSE) != 0;
        int par = g->cn[n].parent;
        if (par >= 0 && g->cn[par].o->kind == SHAPE_DIFFERENCE && n != g->cn[par].first) odd ^= 1;
    }
    return odd;
}

/* Is world point p (on the surface of member `node`) on the CSG result's surface? */
int gi_surface_csg_keep(const gi_surface *g, int node, vec3 p)
{
    for (int n = node; g->cn[n].parent >= 0; n = g->cn[n].parent) {
        const csg_node *P = &g->cn[g->cn[n].parent];
        int i = n - P->first;
        shape_kind op = P->o->kind;
        /* an inverted union is POV-Ray's intersection of inverted members
         * (De Morgan): its surfaces are a merge's, as geom_csg.c keeps them */
        if (op == SHAPE_UNION && csg_inv_odd(g, g->cn[n].parent)) op = SHAPE_MERGE;
        if (op == SHAPE_UNION) continue;
        for (int j = 0; j < P->nkids; j++) {
            if (j == i) continue;
            int in = csg_inside(g, P->first + j, p);
            int need_in = op == SHAPE_INTERSECTION || (op == SHAPE_DIFFERENCE && i > 0 && j == 0);
            if (in != need_in) return 0;
        }
    }
    return 1;
}

/* The side of member `node` that faces out of the result: 1 (its inside)
 * when it is inverse, or subtracted in a difference, or under an inverse
 * CSG an odd number of times in all. */
static int csg_flip(const gi_surface *g, int node)
{
    int flip = (g->cn[node].o->flags & OBJ_INVERSE) != 0;
    for (int n = node; g->cn[n].parent >= 0; n = g->cn[n].parent) {
        const csg_node *P = &g->cn[g->cn[n].parent];
        if (P->o->kind == SHAPE_DIFFERENCE && n - P->first > 0) flip ^= 1;
        if (P->o->flags & OBJ_INVERSE) flip ^= 1;
    }
    return flip;
}

static int keep_fn(void *ctx, vec3 p)
{
    const keep_sampler *k = ctx;
    return gi_surface_csg_keep(k->g, k->node, p);
}

/* A PIECE-kind member of CSG (cur_node): sampled by Crofton lines over its
 * own shape, keeping the crossings on the result's surface. */
pt_status gi_surface_csg_add_piece(gi_surface *g, const scene_object *o, const scene_texture *tex)
{
    const geom_shape *nsh = g->cn[g->cur_node].sh;
    if (!nsh) {
        g->skipped++;
        diag_warn_once(g->d, o->loc, "particle GI: no particles on %s objects in CSG (they get no indirect light)",
                       o->name ? o->name : "these");
        return PT_OK;
    }
    patch p;
    memset(&p, 0, sizeof p);
    p.kind = PATCH_PIECE;
    p.piece = -1;
    p.tex = tex;
    p.nsides = 2;
    p.mask = g->cur_mask;
    p.cnode = g->cur_node;
    /* a copy of the node's shape (which keeps serving the inside tests)
     * that may be clipped; its data stays the node's */
    p.sh = malloc(sizeof *p.sh);
    p.ks = malloc(sizeof *p.ks);
    if (!p.sh || !p.ks) {
        free(p.sh);
        free(p.ks);
        return PT_ERR_NOMEM;
    }
    *p.sh = *nsh;
    p.own_sh = 2;
    if (p.sh->infinite) geom_shape_clip_plane(p.sh, g->lo, g->hi);
    p.ks->g = g;
    p.ks->node = g->cur_node;
    /* accel_surface's accuracy for its own Crofton shapes: 0.1%, 65536 lines */
    double area = geom_tess_sampler_init(&p.ks->cs, p.sh, keep_fn, p.ks, 1e-3, 65536);
    if (!(area > 0.0) || !isfinite(area)) {
        /* nothing of it is on the result's surface */
        gi_surface_free_patch(&p);
        return PT_OK;
    }
    p.area = area;
    int obj = gi_surface_add_obj(g, o);
    if (obj < 0) {
        gi_surface_free_patch(&p);
        return PT_ERR_NOMEM;
    }
    p.obj = obj;
    if (gi_surface_add_patch(g, &p) < 0) {
        gi_surface_free_patch(&p);
        return PT_ERR_NOMEM;
    }
    g->o[obj].count++;
    return PT_OK;
}


static int has_mesh_member(const scene_object *o, int depth)
{
    if (!o || depth > 512) return 0;
    if (o->kind == SHAPE_MESH) return 1;
    if (!is_csg_kind(o->kind)) return 0;
    for (int i = 0; i < o->u.csg.nkids; i++)
        if (has_mesh_member(o->u.csg.kids[i], depth + 1)) return 1;
    return 0;
}

static long leaf_count(const scene_object *o, int depth)
{
    if (!o || depth > 512) return 0;
    if (!is_csg_kind(o->kind)) return 1;
    long n = 0;
    for (int i = 0; i < o->u.csg.nkids; i++) n += leaf_count(o->u.csg.kids[i], depth + 1);
    return n;
}

/* Members of a CSG tree built by build_cnodes; both: the camera or a light
 * is inside the result, so the members get both sides. */
static pt_status walk_member(gi_surface *g, int node, const scene_texture *tex, int both)
{
    const scene_object *o = g->cn[node].o;
    if (o->texture) tex = o->texture;
    if (o->flags & OBJ_NO_RADIOSITY) return PT_OK;
    if (is_csg_kind(o->kind)) {
        int first = g->cn[node].first, nk = g->cn[node].nkids;
        for (int i = 0; i < nk; i++) {
            pt_status st = walk_member(g, first + i, tex, both);
            if (st != PT_OK) return st;
        }
        return PT_OK;
    }
    g->cur_node = node;
    g->cur_mask = both ? 3 : (unsigned char)(1u << csg_flip(g, node));
    pt_status st = gi_surface_add_leaf(g, o, tex, 1);
    g->cur_node = -1;
    return st;
}

int gi_surface_csg_walk(gi_surface *g, const scene_object *o, const scene_texture *tex, pt_status *status)
{
    /* accel renders CSG with a mesh member, and merges of more than 64
     * members, as unions (accel.c) */
    if (o->kind == SHAPE_UNION || has_mesh_member(o, 0) || (o->kind == SHAPE_MERGE && leaf_count(o, 0) > 64)) return 0;
    int root = add_cnode(g, o, -1);
    *status = root < 0 ? PT_ERR_NOMEM : build_cnodes(g, root, 0);
    if (*status != PT_OK) return 1;
    const scene *s = g->sc;
    int both = s->camera_set && csg_inside(g, root, s->camera.location);
    for (int i = 0; i < s->nlights && !both; i++) both = csg_inside(g, root, s->lights[i].position);
    for (int i = 0; i < g->cn[root].nkids && *status == PT_OK; i++)
        *status = walk_member(g, g->cn[root].first + i, tex, both);
    return 1;
}
