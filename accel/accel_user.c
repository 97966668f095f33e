/* accel_user.c - bounded_by (the bounding objects a ray must enter) and the
 * Embree callbacks of the user geometry over geom/ (bounds, intersect,
 * occluded, the no_shadow filters); see accel.c for the layout of the
 * Embree scene and the epsilon rule. */
#include <stdint.h>
#include <string.h>
#include <math.h>
#include "accel_internal.h"
#include "scene_leaves.h"
#include "grow.h"
#include "transmit.h"

/* ------------------------------------------------------------ bounded_by */

/* POV-Ray 3.7's Link_To_Frame drops the bound of a top-level object that is
 * cheap to intersect (remove_bounds, on by default): it keeps those of
 * unions, intersections/differences, merges, polys, text and quadrics
 * without automatic (finite) bounds. Bounds below a CSG object stay. But
 * its Parse_Object_Mods has already given the object the bounding objects'
 * box when that is smaller than its own, and rays missing that box skip the
 * object; so a dropped bound still culls by its box. */
int accel_keeps_bound(const scene_object *o, int top)
{
    if (!top) return 1;
    switch (o->kind) {
    case SHAPE_UNION: case SHAPE_MERGE: case SHAPE_INTERSECTION: case SHAPE_DIFFERENCE:
    case SHAPE_POLY: case SHAPE_TEXT:
        return 1;
    case SHAPE_QUADRIC: {
        geom_shape sh;
        if (geom_shape_init(&sh, o) != 0) return 0;
        int inf = sh.infinite;
        geom_shape_release(&sh);
        return inf;
    }
    default:
        return 0;
    }
}

static int push_bshape(accel *a)
{
    if (a->nbshapes < a->capbshapes) return 1;
    size_t cap = (size_t)a->capbshapes;
    if (!grow_array((void **)&a->bshapes, &cap, (size_t)a->nbshapes + 1, sizeof(geom_shape))) return 0;
    a->capbshapes = (int)cap;
    return 1;
}

static double box_volume(vec3 lo, vec3 hi)
{
    vec3 e = v3_sub(hi, lo);
    return e.x > 0 && e.y > 0 && e.z > 0 ? e.x * e.y * e.z : 0.0;
}

/* The bounding objects of `host` as shapes in a->bshapes; with `box_only`,
 * one box: the intersection of their (non-inverted) world boxes, kept only
 * when smaller than the host's own box (POV-Ray's rule). */
static int add_bound_objects(accel *a, diag *d, const scene_object *host, int box_only)
{
    const scene_object *list = host->bound;
    vec3 blo = v3s(-INFINITY), bhi = v3s(INFINITY);
    for (int i = 0; list && i < list->u.csg.nkids; i++) {
        const scene_object *k = list->u.csg.kids[i];
        if (!k) continue;
        if (scene_object_is_csg(k) || k->clip) {
            diag_warn_once(d, k->loc, "a CSG bounding object is not evaluated: the bound is ignored");
            continue;
        }
        scene_object moved = *k;
        moved.transform = xform_then(k->transform, host->transform);
        if (!push_bshape(a)) return 0;
        if (moved.kind == SHAPE_MESH || moved.kind == SHAPE_UNSUPPORTED ||
            geom_shape_init(&a->bshapes[a->nbshapes], &moved) != 0) {
            diag_warn_once(d, k->loc, "this bounding object is not evaluated: the bound is ignored");
            continue;
        }
        geom_shape *b = &a->bshapes[a->nbshapes];
        if (box_only) {
            if (!b->infinite && b->kind != SHAPE_PLANE && !(k->flags & OBJ_INVERSE)) {
                blo = v3_max(blo, b->lo);
                bhi = v3_min(bhi, b->hi);
            }
            geom_shape_release(b);
            continue;
        }
        if (b->infinite) geom_shape_clip_plane(b, v3s(-INFINITY), v3s(INFINITY));
        a->nbshapes++;
    }
    if (box_only && v3_finite(blo) && v3_finite(bhi)) {
        geom_shape own;
        if (geom_shape_init(&own, host) != 0) return 1;
        double vo = own.infinite || own.kind == SHAPE_PLANE ? INFINITY : box_volume(own.lo, own.hi);
        geom_shape_release(&own);
        if (!(box_volume(blo, bhi) < vo)) return 1;
        scene_object box;
        memset(&box, 0, sizeof box);
        box.kind = SHAPE_BOX;
        box.transform = xform_identity();
        box.u.box.c1 = blo;
        box.u.box.c2 = v3_max(blo, bhi);
        if (!push_bshape(a)) return 0;
        if (geom_shape_init(&a->bshapes[a->nbshapes], &box) == 0) a->nbshapes++;
    }
    return 1;
}

/* The bounds applying to object o (whose own bound counts in full if `own`,
 * else by its box), as a range of a->bshapes. 0 on out-of-memory. */
int accel_collect_bounds(accel *a, diag *d, const scene_object *o, int own, int *b0, int *bn)
{
    *b0 = a->nbshapes;
    for (const bound_chain *c = a->cur_chain; c; c = c->up)
        if (!add_bound_objects(a, d, c->host, 0)) return 0;
    if (o->bound && !add_bound_objects(a, d, o, !own)) return 0;
    *bn = a->nbshapes - *b0;
    return 1;
}

/* POV-Ray's Ray_In_Bound: the ray meets every bound ahead of its origin or
 * starts inside it. */
static int ray_in_bound(const accel *a, int b0, int bn, vec3 o, vec3 d, double tmin, geom_ray_rule rule)
{
    for (int i = 0; i < bn; i++) {
        const geom_shape *b = &a->bshapes[b0 + i];
        geom_shape_hit h;
        if (geom_shape_inside(b, o)) continue;
        if (!geom_shape_intersect(b, o, d, tmin, INFINITY, &h, rule)) return 0;
    }
    return 1;
}


/* ------------------------------------------------------------ callbacks */

/* The box of user primitive prim (lower xyz, upper xyz), padded outwards. */
void accel_user_box(const accel *a, unsigned prim, float out[6])
{
    vec3 lo, hi;
    int b0, bn;
    if (prim < (unsigned)a->nshapes) {
        lo = a->shapes[prim].lo;
        hi = a->shapes[prim].hi;
        const accel_leaf *l = &a->leaves[a->shape_leaf[prim]];
        b0 = l->b0;
        bn = l->bn;
    } else {
        lo = a->csgs[prim - (unsigned)a->nshapes].lo;
        hi = a->csgs[prim - (unsigned)a->nshapes].hi;
        b0 = a->csg_b0[prim - (unsigned)a->nshapes];
        bn = a->csg_bn[prim - (unsigned)a->nshapes];
    }
    /* A ray that hits the primitive crosses its own box, and (ray_in_bound)
     * starts inside or meets every bounding object: a bounding solid whose
     * inside lies within its box is crossed too. The smallest of these
     * boxes culls the same rays as the test it stands for (POV-Ray gives a
     * bounded object its bound's box when that is smaller), so an
     * unbounded poly inside a bounded union is only asked by the rays that
     * cross the bound. */
    double vol = box_volume(lo, hi);
    if (!(vol > 0.0) || !isfinite(vol)) vol = INFINITY;
    for (int i = 0; i < bn; i++) {
        const geom_shape *b = &a->bshapes[b0 + i];
        if (b->infinite || b->kind == SHAPE_PLANE || !geom_shape_solid_bounded(b)) continue;
        double v = box_volume(b->lo, b->hi);
        if (v > 0.0 && v < vol) {
            vol = v;
            lo = b->lo;
            hi = b->hi;
        }
    }
    double ext = v3_maxc(v3_sub(hi, lo));
    for (int i = 0; i < 3; i++) {
        double l = v3_idx(lo, i), h = v3_idx(hi, i);
        double pad = 1e-6 * (fabs(l) + fabs(h) + ext);
        out[i] = nextafterf((float)(l - pad), -INFINITY);
        out[3 + i] = nextafterf((float)(h + pad), INFINITY);
    }
}

void accel_user_bounds(const struct RTCBoundsFunctionArguments *args)
{
    const accel *a = args->geometryUserPtr;
    float out[6];
    accel_user_box(a, args->primID, out);
    struct RTCBounds *b = args->bounds_o;
    b->lower_x = out[0]; b->lower_y = out[1]; b->lower_z = out[2];
    b->upper_x = out[3]; b->upper_y = out[4]; b->upper_z = out[5];
}

/* The link scene's user geometry (accel_rtc_link_scene): the primitives
 * as accel_user_bounds gives them, then one empty primitive, a box of 1e-6 of
 * the scene's size placed 4 scene sizes beyond the upper corner of the
 * scene's bounds (the user boxes included), where no link ray starts and
 * hardly any passes; accel_user_intersect answers it with no hit. */
void accel_user_bounds_link(const struct RTCBoundsFunctionArguments *args)
{
    const accel *a = args->geometryUserPtr;
    float out[6];
    unsigned np = (unsigned)(a->nshapes + a->ncsgs);
    if (args->primID < np) {
        accel_user_box(a, args->primID, out);
    } else {
        float hi[3] = {(float)a->hi.x, (float)a->hi.y, (float)a->hi.z}, ext = (float)(a->scale > 0.0 ? a->scale : 1.0);
        for (unsigned p = 0; p < np; p++)
            for (int k = 0; k < 3; k++) hi[k] = fmaxf(hi[k], a->ubox[6 * (size_t)p + 3 + k]);
        for (int k = 0; k < 3; k++) {
            out[k] = hi[k] + 4.0f * ext;
            out[3 + k] = out[k] + 1e-6f * ext;
        }
    }
    struct RTCBounds *b = args->bounds_o;
    b->lower_x = out[0]; b->lower_y = out[1]; b->lower_z = out[2];
    b->upper_x = out[3]; b->upper_y = out[4]; b->upper_z = out[5];
}

/* Whether the callbacks test a ray against user primitive prim's box
 * (ubox) before intersecting it, of np primitives. Embree's BVH over the
 * user geometry has one primitive per leaf (Embree 3's device setting
 * object_accel_max_leaf_size defaults to 1, kernels/common/state.cpp), and
 * a ray reaches a leaf only through the test of that leaf's box in the node
 * above: the test here turns away only the rays whose nearest hit moved
 * closer since (few: docs/gi.md, "Where the time goes"), at the cost of a
 * slab test in float on every call. It pays where the intersection costs
 * far more: a CSG's search over its members, a bounded_by's tests, the
 * shapes without a closed-form solution (quartics, sweeps, isosurfaces);
 * and where no node lies above the leaf: a user geometry of one primitive
 * is a lone leaf whose box Embree never tests (cbox's light patch, asked
 * by every link ray). The other shapes' own tests are a few products and a
 * root, about the slab test's cost. */
int accel_user_box_test(const accel *a, unsigned prim, unsigned np)
{
    if (np <= 1 || prim >= (unsigned)a->nshapes) return 1;
    if (a->leaves[a->shape_leaf[prim]].bn) return 1;
    switch (a->shapes[prim].kind) {
    case SHAPE_SPHERE: case SHAPE_BOX: case SHAPE_PLANE: case SHAPE_DISC: case SHAPE_CYLINDER: case SHAPE_CONE:
    case SHAPE_TRIANGLE: case SHAPE_SMOOTH_TRIANGLE:
        return 0;
    default:
        return 1;
    }
}

/* Whether a shadow ray's filter is 0 at every surface of leaf l: its
 * texture and interior texture cannot let light through
 * (transmit_texture_may), and it is not a blob, whose components carry
 * textures of their own. */
static int leaf_opaque(const accel_leaf *l)
{
    const scene_object *o = l->obj;
    if (!o || o->kind == SHAPE_BLOB || !l->texture || transmit_texture_may(l->texture)) return 0;
    return !(o->interior_texture && transmit_texture_may(o->interior_texture));
}

int accel_user_cut(const accel *a, unsigned prim)
{
    /* a height field's crossings come from a walk over its cells along the
     * ray, which its nearest crossing ends; the other closed-form shapes
     * give all theirs from one solve, at the cost of the nearest */
    if (prim >= (unsigned)a->nshapes || a->shapes[prim].kind != SHAPE_HEIGHT_FIELD) return 0;
    return leaf_opaque(&a->leaves[a->shape_leaf[prim]]);
}

/* Does lane i of an SOA ray miss user primitive prim's box within its
 * [tnear, tfar]? (Asked where accel_user_box_test says so.) Conservative: a NaN slab (a zero direction component starting on a
 * face) constrains nothing, and the interval must be empty by more than
 * float rounding. */
__attribute__((always_inline)) static inline int user_box_missed(const accel *a, unsigned prim, void *ray,
                                                                  unsigned N, unsigned i)
{
    const float *b = a->ubox + 6 * (size_t)prim;
    float tn = SOA_F(ray, N, i, 3), tf = SOA_F(ray, N, i, 8);
    for (int k = 0; k < 3; k++) {
        float o = SOA_F(ray, N, i, k), inv = 1.0f / SOA_F(ray, N, i, 4 + k);
        float t0 = (b[k] - o) * inv, t1 = (b[3 + k] - o) * inv;
        if (t0 > t1) {
            float t = t0;
            t0 = t1;
            t1 = t;
        }
        if (t0 > tn) tn = t0;
        if (t1 < tf) tf = t1;
    }
    return tn > tf + 1e-5f * fabsf(tf) + 1e-30f;
}

/* user_box_missed with the single ray's offsets folded (N = 1: a query's
 * ray, by far the most common) or for lane i of a packet. */
static int box_missed(const accel *a, unsigned prim, void *ray, unsigned N, unsigned i)
{
    return N == 1 ? user_box_missed(a, prim, ray, 1, 0) : user_box_missed(a, prim, ray, N, i);
}

/* One user primitive against a ray: an analytic shape or a CSG tree. */
int accel_prim_hit(const accel *a, unsigned prim, vec3 o, vec3 d, double tmin, double tmax, geom_csg_hit *h,
                   geom_ray_rule rule)
{
    assert(prim < (unsigned)(a->nshapes + a->ncsgs));
    if (prim < (unsigned)a->nshapes) {
        /* the bound first: it is the cheaper test, and both must pass */
        assert(a->shape_leaf[prim] < (unsigned)a->nleaves);
        const accel_leaf *l = &a->leaves[a->shape_leaf[prim]];
        if (l->bn && !ray_in_bound(a, l->b0, l->bn, o, d, tmin, rule)) return 0;
        geom_shape_hit sh;
        if (!geom_shape_intersect(&a->shapes[prim], o, d, tmin, tmax, &sh, rule)) return 0;
        assert(sh.t > tmin && sh.t < tmax);
        h->t = sh.t;
        h->part = sh.part;
        h->shape = 0;
        h->flip = 0;
        return 1;
    }
    unsigned ci = prim - (unsigned)a->nshapes;
    if (a->csg_bn[ci] && !ray_in_bound(a, a->csg_b0[ci], a->csg_bn[ci], o, d, tmin, rule)) return 0;
    if (!geom_csg_intersect(&a->csgs[ci], o, d, tmin, tmax, h, rule)) return 0;
    assert(h->t > tmin && h->t < tmax && h->shape >= 0 && h->shape < a->csgs[ci].nshapes);
    return 1;
}

/* Whether prim has a crossing in (tmin, tmax): accel_prim_hit's answer
 * without the search for the nearest crossing of a CSG (shadow rays). */
static int prim_occludes(const accel *a, unsigned prim, vec3 o, vec3 d, double tmin, double tmax, geom_ray_rule rule)
{
    if (prim < (unsigned)a->nshapes) {
        geom_csg_hit h;
        return accel_prim_hit(a, prim, o, d, tmin, tmax, &h, rule);
    }
    unsigned ci = prim - (unsigned)a->nshapes;
    if (a->csg_bn[ci] && !ray_in_bound(a, a->csg_b0[ci], a->csg_bn[ci], o, d, tmin, rule)) return 0;
    return geom_csg_occludes(&a->csgs[ci], o, d, tmin, tmax, rule);
}

const geom_shape *accel_prim_shape(const accel *a, unsigned prim, int member)
{
    assert(prim < (unsigned)(a->nshapes + a->ncsgs));
    assert(prim < (unsigned)a->nshapes || (member >= 0 && member < a->csgs[prim - (unsigned)a->nshapes].nshapes));
    return prim < (unsigned)a->nshapes ? &a->shapes[prim] : &a->csgs[prim - (unsigned)a->nshapes].shapes[member];
}

static unsigned prim_flags(const accel *a, unsigned prim)
{
    return prim < (unsigned)a->nshapes ? a->leaves[a->shape_leaf[prim]].flags
                                       : a->csgs[prim - (unsigned)a->nshapes].flags;
}

/* The rule a query's rays meet searched-for surfaces by (accel_ray_rule):
 * its own, or for a ray traced without our context (a benchmark's bare
 * Embree calls, the particle GI's link rays, which carry light between
 * surfaces as the renderer's rays do) POV-Ray's. */
static inline geom_ray_rule query_rule(const accel_query *q)
{
    return q ? q->rule : GEOM_RAY_POV;
}

/* Ray i of an Embree packet of N (SoA) as the user callbacks read it: the
 * exact double-precision ray of q when the query is a single exact one (q
 * not NULL), else the packet's floats. */
static inline void user_ray(const accel_query *q, const void *ray, unsigned N, unsigned i, vec3 *o, vec3 *d,
                            double *tmin)
{
    if (q) {
        *o = q->org;
        *d = q->dir;
        *tmin = q->tmin;
    } else {
        *o = v3(SOA_F(ray, N, i, 0), SOA_F(ray, N, i, 1), SOA_F(ray, N, i, 2));
        *d = v3(SOA_F(ray, N, i, 4), SOA_F(ray, N, i, 5), SOA_F(ray, N, i, 6));
        *tmin = SOA_F(ray, N, i, 3);
    }
}

/* A crossing query (accel_crossings) on a leaf whose crossings are the
 * closed-form roots of its surface filtered by the interval (sphere, box,
 * cylinder, cone, disc, plane, triangle, polygon, and a height field's
 * triangles, whose distances its walk takes from the ray's origin
 * wherever the walk starts; no bounded_by, whose test takes the
 * interval's start): all of them from one solve, stepped over by the rule
 * of the loop in accel_user_intersect, which asks the shape again from
 * just past each crossing and so gets the same roots; on a CSG without
 * bounded_by, geom_csg_crossings. 0 when the loop must do it (other
 * shapes, isosurface members, more crossings than the buffer holds). */
__attribute__((always_inline)) static inline int cross_leaf_once(const accel *a, unsigned prim, vec3 o, vec3 d,
                                                            double tmin, accel_query *q)
{
    if (prim >= (unsigned)a->nshapes) {
        /* a CSG: geom_csg_crossings searches each member once over the
         * whole interval (not once per crossing) */
        unsigned ci = prim - (unsigned)a->nshapes;
        if (a->csg_bn[ci]) return 0;
        enum { MAX_CSG_CROSSINGS = 32 };
        geom_csg_hit hs[MAX_CSG_CROSSINGS];
        int k = geom_csg_crossings(&a->csgs[ci], o, d, tmin, q->ctmax, q->cstep, hs, MAX_CSG_CROSSINGS, q->rule);
        if (k < 0) return 0;
        for (int j = 0; j < k; j++) {
            if (q->ncross == q->maxcross) {
                q->overflow = 1;
                break;
            }
            q->cross[q->ncross++] = (accel_crossing){hs[j].t, prim, hs[j].part, hs[j].shape, hs[j].flip, 0};
        }
        return 1;
    }
    if (a->leaves[a->shape_leaf[prim]].bn) return 0;
    const geom_shape *sh = &a->shapes[prim];
    switch (sh->kind) {
    case SHAPE_SPHERE: case SHAPE_BOX: case SHAPE_CYLINDER: case SHAPE_CONE: case SHAPE_DISC: case SHAPE_PLANE:
    case SHAPE_TRIANGLE: case SHAPE_SMOOTH_TRIANGLE: case SHAPE_HEIGHT_FIELD: case SHAPE_POLYGON:
        break;
    default:
        return 0;
    }
    enum { MAX_LEAF_CROSSINGS = 8 };
    geom_shape_hit hs[MAX_LEAF_CROSSINGS];
    /* a cut primitive's nearest crossing is its first one here (the roots
     * do not depend on how many are asked for) */
    int cut = q->ccut && a->ucut[prim];
    int k = geom_shape_ray_hits(sh, o, d, tmin, q->ctmax, hs, cut ? 1 : MAX_LEAF_CROSSINGS, q->rule);
    if (cut ? k == 1 && !(hs[0].t > tmin) : k == MAX_LEAF_CROSSINGS) return 0;
    double from = tmin;
    for (int j = 0; j < k; j++) {
        if (!(hs[j].t > from)) continue;
        if (q->ncross == q->maxcross) {
            q->overflow = 1;
            break;
        }
        q->cross[q->ncross++] = (accel_crossing){hs[j].t, prim, hs[j].part, 0, 0, cut};
        from = hs[j].t + fmax_inline(q->cstep, hs[j].t * 1e-7);
    }
    return 1;
}

/* Two crossings of different primitives closer than this at distance t
 * are a tie. POV-Ray 3.7 computes each shape's distance in its own frame
 * (a cylinder's cap through its axis transform, a box's face directly), so
 * where two surfaces coincide, such as a glass box's bottom on a floor, the
 * rounding picks the nearer one ray by ray and either wins about half the
 * time (its image of the contact speckles). A fixed order would show one of
 * them everywhere. The window is far below any modelled gap (a liquid 1e-8
 * inside its glass, 1e-9 of the distance) and above the rounding of a
 * double-precision distance (1e-15 of it, a few times over). */
#define TIE_REL 1e-12
static inline double tie_window(double t) { return fabs(t) * TIE_REL; }

/* Whether primitive `cand` takes a tie from `cur` for the query's ray: a
 * hash of the ray's origin, direction and the two primitives, symmetric in
 * the order the traversal meets them, so the choice does not depend on it
 * and is the same for the same ray. */
static int tie_first(const accel_query *q, unsigned cand, unsigned cur)
{
    double v[6] = {q->org.x, q->org.y, q->org.z, q->dir.x, q->dir.y, q->dir.z};
    uint64_t h = 0x9e3779b97f4a7c15ULL;
    for (int k = 0; k < 6; k++) {
        uint64_t b;
        memcpy(&b, &v[k], sizeof b);
        h = (h ^ b) * 0xbf58476d1ce4e5b9ULL;
        h ^= h >> 31;
    }
    uint64_t ka = (h ^ ((uint64_t)cand * 0x94d049bb133111ebULL)) * 0x9e3779b97f4a7c15ULL;
    uint64_t kb = (h ^ ((uint64_t)cur * 0x94d049bb133111ebULL)) * 0x9e3779b97f4a7c15ULL;
    ka ^= ka >> 29;
    kb ^= kb >> 29;
    return ka < kb;
}

/* Whether primitive `cand` takes a tie from the query's hit: never from
 * itself; a primitive the caller passes over (q->tie_skip) loses to one it
 * does not; otherwise tie_first. */
static int tie_takes(const accel *a, const accel_query *q, unsigned cand)
{
    if (cand == q->uprim) return 0;
    int cs = (prim_flags(a, cand) & q->tie_skip) != 0, us = (prim_flags(a, q->uprim) & q->tie_skip) != 0;
    if (cs != us) return us;
    return tie_first(q, cand, q->uprim);
}

/* A crossing query's collection on primitive prim: every crossing of it
 * in (tmin, q->ctmax), each the nearest just past the one before. */
__attribute__((always_inline)) static inline void cross_prim(const accel *a, accel_query *q, unsigned prim, vec3 o,
                                                            vec3 d, double tmin)
{
    if (q->cskip && (prim_flags(a, prim) & q->cskip)) return;
    if (cross_leaf_once(a, prim, o, d, tmin, q)) return;
    for (double from = tmin; from < q->ctmax;) {
        geom_csg_hit h;
        if (!accel_prim_hit(a, prim, o, d, from, q->ctmax, &h, q->rule)) break;
        if (q->ncross == q->maxcross) {
            q->overflow = 1;
            break;
        }
        q->cross[q->ncross++] = (accel_crossing){h.t, prim, h.part, h.shape, h.flip, 0};
        from = h.t + fmax_inline(q->cstep, h.t * 1e-7);
    }
}

/* accel_user_intersect on a query's single exact ray (N = 1, the query
 * its context): its crossings (q->cross) or its nearest hit in q. */
__attribute__((always_inline)) static inline void intersect_one(const struct RTCIntersectFunctionNArguments *args,
                                                               const accel *a, accel_query *q)
{
    unsigned prim = args->primID;
    if (prim >= (unsigned)(a->nshapes + a->ncsgs) || args->valid[0] != -1) return;
    float *ray = (float *)args->rayhit, *hit = ray + 12;
    if (a->ubox && a->ubox_test[prim] && user_box_missed(a, prim, ray, 1, 0)) return;
    if (q->cross) {
        cross_prim(a, q, prim, q->org, q->dir, q->tmin);
        return;
    }
    /* the nearest hit so far is the exact one of the query: a float tfar
     * rounded up past a second surface within an ulp (a liquid 1e-8 inside
     * its glass) would let that farther surface win, and which one did
     * would depend on the traversal order */
    double tmax = (double)ray[8];
    double tie = q->uhit ? tie_window(q->ut) : 0.0;
    if (q->uhit && q->ut + tie < tmax) tmax = q->ut + tie;
    geom_csg_hit h;
    if (!accel_prim_hit(a, prim, q->org, q->dir, q->tmin, tmax, &h, q->rule)) return;
    /* two surfaces of different primitives at one distance within the
     * rounding of their intersections (a box standing on a plane, seen
     * through its bottom): the tie goes to one of them by the ray's hash,
     * either about as often (tie_first) */
    if (q->uhit && h.t >= q->ut - tie && !tie_takes(a, q, prim)) return;
    /* rounded up: a nearer candidate within the ulp is still tried */
    ray[8] = nextafterf((float)h.t, INFINITY);
    q->ut = h.t;
    q->upart = h.part;
    q->ushape = h.shape;
    q->uflip = h.flip;
    q->uprim = prim;
    q->uhit = 1;
    /* the record as intersect_lanes writes it; the query's reader takes
     * the hit from q */
    hit[0] = hit[1] = hit[2] = 0.0f;
    hit[3] = prim < (unsigned)a->nshapes ? 0.0f : (float)h.shape;
    hit[4] = 0.0f;
    ((unsigned *)hit)[5] = prim;
    ((unsigned *)hit)[6] = args->geomID;
    ((unsigned *)hit)[7] = args->context->instID[0];
}

/* accel_user_intersect on a packet or stream of N rays, or a ray traced
 * without our query (a benchmark's bare Embree calls, the particle GI's
 * link rays): the rays' floats. */
static __attribute__((noinline)) void intersect_lanes(const struct RTCIntersectFunctionNArguments *args)
{
    const accel *a = args->geometryUserPtr;
    accel_query *q = accel_tls_query;
    unsigned N = args->N;
    int ours = q && (void *)q == (void *)args->context;
    geom_ray_rule rule = query_rule(ours ? q : NULL);
    void *ray = args->rayhit;
    float *hit = (float *)args->rayhit + 12 * (size_t)N;
    if (args->primID >= (unsigned)(a->nshapes + a->ncsgs)) return; /* the link scene's empty primitive */
    const int box_test = a->ubox && a->ubox_test[args->primID];
    for (unsigned i = 0; i < N; i++) {
        if (args->valid[i] != -1 || (box_test && box_missed(a, args->primID, ray, N, i))) continue;
        vec3 o, d;
        double tmin;
        user_ray(NULL, ray, N, i, &o, &d, &tmin);
        geom_csg_hit h;
        if (!accel_prim_hit(a, args->primID, o, d, tmin, (double)SOA_F(ray, N, i, 8), &h, rule)) continue;
        SOA_F(ray, N, i, 8) = (float)h.t;
        /* the normal only: the surface's (u, v) (a sphere's two inverse
         * trigonometric calls) has no reader in a packet's or stream's
         * record, where u and v hold Embree's barycentrics for triangles
         * only */
        vec3 ng;
        geom_shape_surface(accel_prim_shape(a, args->primID, h.shape), v3_madd(o, d, h.t), h.part, &ng, NULL, NULL);
        if (h.flip) ng = v3_neg(ng);
        SOA_F(hit, N, i, 0) = (float)ng.x;
        SOA_F(hit, N, i, 1) = (float)ng.y;
        SOA_F(hit, N, i, 2) = (float)ng.z;
        /* a CSG result's record carries the member hit in u (exact in a
         * float: members are counted in ints far below 2^24), which
         * accel_rtc_leaf reads instead of intersecting the CSG again */
        SOA_F(hit, N, i, 3) = args->primID < (unsigned)a->nshapes ? 0.0f : (float)h.shape;
        SOA_F(hit, N, i, 4) = 0.0f;
        SOA_U(hit, N, i, 5) = args->primID;
        SOA_U(hit, N, i, 6) = args->geomID;
        SOA_U(hit, N, i, 7) = args->context->instID[0];
    }
}

void accel_user_intersect(const struct RTCIntersectFunctionNArguments *args)
{
    const accel *a = args->geometryUserPtr;
    accel_query *q = accel_tls_query;
    /* a query's single ray (every traced ray's nearest hit, every
     * filtered shadow ray's walk) */
    if (args->N == 1 && q && (void *)q == (void *)args->context && !q->packet) {
        intersect_one(args, a, q);
        return;
    }
    intersect_lanes(args);
}

/* Whether the ray from org with reciprocal direction inv misses box b (6
 * floats) within [tn, tf]: user_box_missed's test where no slab end is
 * NaN (every reciprocal finite), so that plain minima and maxima do. */
static inline int box_missed_finite(const float *b, const float org[3], const float inv[3], float tn, float tf)
{
    float x0 = (b[0] - org[0]) * inv[0], x1 = (b[3] - org[0]) * inv[0];
    float y0 = (b[1] - org[1]) * inv[1], y1 = (b[4] - org[1]) * inv[1];
    float z0 = (b[2] - org[2]) * inv[2], z1 = (b[5] - org[2]) * inv[2];
    float xl = x0 < x1 ? x0 : x1, xh = x0 < x1 ? x1 : x0;
    float yl = y0 < y1 ? y0 : y1, yh = y0 < y1 ? y1 : y0;
    float zl = z0 < z1 ? z0 : z1, zh = z0 < z1 ? z1 : z0;
    tn = xl > tn ? xl : tn;
    tn = yl > tn ? yl : tn;
    tn = zl > tn ? zl : tn;
    tf = xh < tf ? xh : tf;
    tf = yh < tf ? yh : tf;
    tf = zh < tf ? zh : tf;
    return tn > tf + 1e-5f * fabsf(tf) + 1e-30f;
}

/* A crossing query (q->cross set, ray r its Embree ray) on a scene whose
 * only geometry is the user geometry, without Embree's traversal: each
 * primitive whose box the ray's interval meets is asked as the traversal's
 * leaf would ask it (accel_user_intersect, which in collect mode reports
 * no hit, so the traversal visits every such leaf and prunes nothing by
 * distance). The crossings are the same whatever the order; the caller
 * sorts them. For a handful of primitives the loop costs less than the
 * traversal's set-up and node tests. */
void accel_user_cross_all(const accel *a, accel_query *q, const struct RTCRay *r)
{
    unsigned np = (unsigned)(a->nshapes + a->ncsgs);
    /* the reciprocals taken once; a ray along which one is not finite
     * takes user_box_missed itself */
    float org[3] = {r->org_x, r->org_y, r->org_z};
    float inv[3] = {1.0f / r->dir_x, 1.0f / r->dir_y, 1.0f / r->dir_z};
    int finite = fabsf(inv[0]) < INFINITY && fabsf(inv[1]) < INFINITY && fabsf(inv[2]) < INFINITY;
    for (unsigned p = 0; p < np && !q->overflow; p++) {
        if (a->ubox && (finite ? box_missed_finite(a->ubox + 6 * (size_t)p, org, inv, r->tnear, r->tfar)
                               : user_box_missed(a, p, (void *)r, 1, 0)))
            continue;
        cross_prim(a, q, p, q->org, q->dir, q->tmin);
    }
}

void accel_user_occluded(const struct RTCOccludedFunctionNArguments *args)
{
    const accel *a = args->geometryUserPtr;
    if (args->primID >= (unsigned)(a->nshapes + a->ncsgs)) return; /* the link scene's empty primitive */
    if (prim_flags(a, args->primID) & OBJ_NO_SHADOW) return;
    accel_query *q = accel_tls_query;
    unsigned N = args->N;
    int ours = q && (void *)q == (void *)args->context;
    int exact = ours && !q->packet && N == 1;
    geom_ray_rule rule = query_rule(ours ? q : NULL);
    void *ray = args->ray;
    const int box_test = a->ubox && a->ubox_test[args->primID];
    for (unsigned i = 0; i < N; i++) {
        if (args->valid[i] != -1 || (box_test && box_missed(a, args->primID, ray, N, i))) continue;
        vec3 o, d;
        double tmin;
        user_ray(exact ? q : NULL, ray, N, i, &o, &d, &tmin);
        if (prim_occludes(a, args->primID, o, d, tmin, (double)SOA_F(ray, N, i, 8), rule)) {
            SOA_F(ray, N, i, 8) = -INFINITY;
            if (exact && args->context->instID[0] == RTC_INVALID_GEOMETRY_ID) q->oprim = args->primID + 1u;
        }
    }
}

int accel_user_blocks(const accel *a, const accel_query *q, const struct RTCRay *r, unsigned prim)
{
    if (prim >= (unsigned)(a->nshapes + a->ncsgs) || (prim_flags(a, prim) & OBJ_NO_SHADOW)) return 0;
    if (a->ubox && a->ubox_test[prim] && box_missed(a, prim, (void *)r, 1, 0)) return 0;
    return prim_occludes(a, prim, q->org, q->dir, q->tmin, (double)r->tfar, q->rule);
}

/* Occlusion filter of the no_shadow triangle geometry: nothing there occludes. */
void accel_filter_reject_all(const struct RTCFilterFunctionNArguments *args)
{
    for (unsigned i = 0; i < args->N; i++) args->valid[i] = 0;
}

/* Occlusion filter of a shared mesh with some no_shadow instances. */
void accel_filter_instance_no_shadow(const struct RTCFilterFunctionNArguments *args)
{
    const accel *a = args->geometryUserPtr;
    unsigned N = args->N;
    for (unsigned i = 0; i < N; i++) {
        if (args->valid[i] == 0) continue;
        unsigned inst = SOA_U(args->hit, N, i, 7);
        if (inst < a->nginfo && a->ginfo[inst].kind == GEOM_INSTANCE &&
            (a->leaves[a->ginfo[inst].idx].flags & OBJ_NO_SHADOW))
            args->valid[i] = 0;
    }
}
