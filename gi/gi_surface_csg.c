/* gi_surface_csg.c - particles on members of CSG: only where a member's
 * surface is the result's surface. */
#include "gi_surface_internal.h"
#include <assert.h>
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
#include "pool.h"

/* ------------------------------------------------------------ CSG members
 *
 * A member of merge, intersection or difference has particles only where
 * its surface is the CSG result's surface: the renderer's tree of the
 * object (geom_csg_build, clipped_by solids included) and its member rule
 * (geom_csg_kept: POV-Ray's, at every level from the member up to the
 * root). */

int gi_surface_csg_keep(const gi_surface *g, int node, vec3 p)
{
    assert(node >= 0 && node < g->ncm);
    const csg_member *m = &g->cm[node];
    return geom_csg_kept(&g->ct[m->tree], m->node, p);
}

void gi_surface_csg_free(gi_surface *g)
{
    for (int i = 0; i < g->nct; i++) geom_csg_free(&g->ct[i]);
    free(g->ct);
    free(g->cm);
    g->ct = NULL;
    g->cm = NULL;
    g->nct = g->capct = g->ncm = g->capcm = 0;
}

static int keep_fn(void *ctx, vec3 p)
{
    const keep_sampler *k = ctx;
    return gi_surface_csg_keep(k->g, k->node, p);
}

/* A PIECE-kind member of CSG (cur_node): sampled by Crofton lines over its
 * own shape, keeping the crossings on the result's surface. Its sampler
 * and area are made later, for all such members at once
 * (gi_surface_csg_finish): the patch and its object record stand with the
 * area PENDING until then. */
#define PENDING (-1.0)
pt_status gi_surface_csg_add_piece(gi_surface *g, const scene_object *o, const scene_texture *tex)
{
    assert(g->cur_node >= 0 && g->cur_node < g->ncm);
    const csg_member *m = &g->cm[g->cur_node];
    const geom_shape *nsh = &g->ct[m->tree].shapes[m->shape];
    patch p = {.kind = PATCH_PIECE, .piece = -1, .tex = tex, .nsides = 2, .mask = g->cur_mask, .cnode = g->cur_node};
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
    p.area = PENDING;
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

typedef struct {
    gi_surface *g;
    const int *patch; /* the pending patches */
    int inner;        /* threads each estimate counts its lines on (fewer patches than threads) */
} piece_job;

static void piece_area(void *ctx, int k, int thread)
{
    (void)thread;
    piece_job *J = ctx;
    patch *p = &J->g->p[J->patch[k]];
    /* The area only shares the particles out among the patches (each
     * particle stands for the same dA whatever its patch's area), so 1%
     * does: at accel_surface's 0.1% (65536 lines) a scene of a few hundred
     * CSG members (patio-radio's arcades) spent most of its geometry stage
     * here. The estimate depends on the member alone (a fixed
     * quasi-random set of lines), so the members are estimated in
     * parallel, the same for any thread count. */
    p->area = geom_tess_sampler_init(&p->ks->cs, p->sh, keep_fn, p->ks, 1e-2, 8192, J->inner);
}

pt_status gi_surface_csg_finish(gi_surface *g, int threads)
{
    int *pend = malloc(((size_t)g->np + 1) * sizeof *pend);
    int *newo = malloc(((size_t)g->no + 1) * sizeof *newo);
    if (!pend || !newo) {
        free(pend);
        free(newo);
        return PT_ERR_NOMEM;
    }
    int m = 0;
    for (int i = 0; i < g->np; i++)
        if (g->p[i].kind == PATCH_PIECE && g->p[i].cnode >= 0 && g->p[i].area == PENDING) pend[m++] = i;
    if (threads <= 0) threads = 1;
    piece_job J = {g, pend, m > 0 && m < threads ? threads / m : 1};
    pool_run(threads, m, piece_area, &J);
    /* a member with nothing of it on the result's surface has no patch and
     * no object record (each member's record is its own, of one patch):
     * both go, and the records after them move up */
    int removed = 0;
    for (int k = 0; k < m; k++) {
        patch *p = &g->p[pend[k]];
        if (p->area > 0.0 && isfinite(p->area)) continue;
        g->o[p->obj].count = -1; /* marks the record for removal */
        gi_surface_free_patch(p);
        p->obj = -1;
        removed++;
    }
    if (removed) {
        int no = 0;
        for (int j = 0; j < g->no; j++) newo[j] = g->o[j].count < 0 ? -1 : no++;
        /* a record's first patch: the patches kept before its old first */
        int np = 0, jo = 0;
        for (int i = 0; i <= g->np; i++) {
            for (; jo < g->no && g->o[jo].first <= i; jo++)
                if (newo[jo] >= 0) g->o[jo].first = np;
            if (i == g->np || g->p[i].obj < 0) continue;
            g->p[i].obj = newo[g->p[i].obj];
            g->p[np++] = g->p[i];
        }
        for (int j = 0; j < g->no; j++)
            if (newo[j] >= 0) g->o[newo[j]] = g->o[j];
        g->np = np;
        g->no = no;
    }
    free(pend);
    free(newo);
    return PT_OK;
}

/* geom_csg_build's leaf callback: the members in the order they are added. */
typedef struct {
    const scene_object *o;
    const scene_texture *tex;
    unsigned flags;
} leaf_rec;

typedef struct {
    leaf_rec *l;
    int n, cap;
} leaf_list;

static int list_leaf(void *ctx, const scene_object *o, const scene_texture *tex, unsigned flags)
{
    leaf_list *ll = ctx;
    if (ll->n == ll->cap) {
        int nc = ll->cap ? 2 * ll->cap : 16;
        leaf_rec *nl = realloc(ll->l, (size_t)nc * sizeof *nl);
        if (!nl) return -1;
        ll->l = nl;
        ll->cap = nc;
    }
    ll->l[ll->n].o = o;
    ll->l[ll->n].tex = tex;
    ll->l[ll->n].flags = flags;
    return ll->n++;
}

/* The tree of CSG object o (the renderer's: geom_csg_build, clipped_by
 * solids included), then particles on each member with a surface: on the
 * side facing out of the result (the member's flip), or on both when the
 * camera or a light is inside the result. */
static pt_status walk_tree(gi_surface *g, const scene_object *o, const scene_texture *tex)
{
    if (g->nct == g->capct) {
        int nc = g->capct ? 2 * g->capct : 8;
        geom_csg *nt = realloc(g->ct, (size_t)nc * sizeof *nt);
        if (!nt) return PT_ERR_NOMEM;
        g->ct = nt;
        g->capct = nc;
    }
    int tree = g->nct++;
    geom_csg *c = &g->ct[tree];
    memset(c, 0, sizeof *c);
    leaf_list ll = {NULL, 0, 0};
    geom_csg_builder b = {list_leaf, &ll, OBJ_NO_RADIOSITY, 0, NULL, 0};
    pt_status st = geom_csg_build(c, o, tex, 0, -1, 0, &b);
    if (st != PT_OK || !geom_csg_finish(c)) {
        free(ll.l);
        return st; /* an empty result has no particles */
    }
    const scene *s = g->sc;
    int both = s->camera_set && geom_csg_inside(c, 0, s->camera.location);
    for (int i = 0; i < s->nlights && !both; i++) both = geom_csg_inside(c, 0, s->lights[i].position);
    for (int k = 0; k < c->nshapes && st == PT_OK; k++) {
        int node = c->shape_node[k];
        assert(c->shape_leaf[k] < (unsigned)ll.n);
        const leaf_rec *lr = &ll.l[c->shape_leaf[k]];
        if (c->nodes[node].nosurf) continue; /* a clipped_by solid */
        if (lr->flags & OBJ_NO_RADIOSITY) continue;
        if (g->ncm == g->capcm) {
            int nc = g->capcm ? 2 * g->capcm : 64;
            csg_member *nm = realloc(g->cm, (size_t)nc * sizeof *nm);
            if (!nm) {
                st = PT_ERR_NOMEM;
                break;
            }
            g->cm = nm;
            g->capcm = nc;
        }
        g->cm[g->ncm].tree = tree;
        g->cm[g->ncm].node = node;
        g->cm[g->ncm].shape = k;
        g->cur_node = g->ncm++;
        /* sheets (polygons, discs, open cylinders and cones; triangles
         * and meshes, member_sides) show both sides where the result keeps
         * them: a clipped open cylinder is seen from within */
        shape_kind k = lr->o->kind;
        int sheet = k == SHAPE_POLYGON || k == SHAPE_DISC || (lr->o->flags & OBJ_OPEN);
        g->cur_mask = both || sheet ? 3 : (unsigned char)(1u << c->nodes[node].flip);
        st = gi_surface_add_leaf(g, lr->o, lr->tex, 1);
        g->cur_node = -1;
    }
    free(ll.l);
    return st;
}

int gi_surface_csg_walk(gi_surface *g, const scene_object *o, const scene_texture *tex, pt_status *status)
{
    /* clipped_by (any shape, a union too): one CSG tree whose clipping
     * solids have no surface, as accel renders it, unless meshes are
     * involved (then accel renders it unclipped: so do the particles) */
    int clipped = o->clip && o->kind != SHAPE_UNSUPPORTED && !geom_csg_has_mesh(o, 0) && !geom_csg_has_mesh(o->clip, 0);
    /* accel renders CSG with a mesh member, and merges of more than
     * GEOM_CSG_MAX_MERGE leaves, as unions (accel.c) */
    if (!clipped && (o->kind == SHAPE_UNION || geom_csg_has_mesh(o, 0) ||
                     (o->kind == SHAPE_MERGE && geom_csg_leaf_count(o, 0) > GEOM_CSG_MAX_MERGE)))
        return 0;
    *status = walk_tree(g, o, tex);
    return 1;
}
