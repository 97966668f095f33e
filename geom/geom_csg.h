/* geom_csg.h - POV-Ray CSG intersection and difference (with any unions,
 * merges and inverses nested in them) evaluated exactly along a ray, over
 * analytic shapes and triangles (geom_shape.h).
 *
 * The rule is POV-Ray's: a crossing of a member's surface belongs to the
 * result when the point passes the inside tests of that member's siblings,
 * at every level up to the root: intersection keeps it if inside all
 * siblings, difference keeps the first member's surface outside all the
 * others and a subtracted member's surface inside the first and outside the
 * rest (its normal flipped), merge keeps it outside all siblings, union
 * always. POV-Ray inverts a CSG by De Morgan (Invert_CSG_Object: members
 * inverted, union and merge become an intersection, an intersection a
 * merge; a difference is an intersection with its subtracted members
 * inverted), so a union under an odd number of inversions (its own
 * included) keeps a member's surface only outside all its siblings, as a
 * merge does; the other operations keep the same surfaces either way. The
 * result's inside test combines the members' tests the same way (inverse
 * negates it). geom_csg_build makes the tree of an IR object: accel.c turns
 * each into one user-geometry primitive, the parser's trace() and inside()
 * query it, gi keeps the CSG members' particles where it keeps their
 * surface. */
#ifndef PT_GEOM_CSG_H
#define PT_GEOM_CSG_H
#include "diag.h"
#include "geom_shape.h"

/* Deepest CSG nesting an object may have (an error beyond it). */
#define GEOM_CSG_MAX_DEPTH 512
/* A merge with more leaves is rendered as a union (accel.c, warned): a ray
 * through a CSG tries every member whose keep box it crosses, and each
 * crossing of a merge member tests the inside of its siblings, so the cost
 * per ray grows with the leaves as in POV-Ray's own CSG. Merges of a few
 * hundred leaves occur (grenadine.pov's liquid, 243: as a union its bubbles'
 * and cylinders' internal surfaces band the liquid), so the bound only
 * keeps a generated merge of many thousands from being traced leaf by leaf. */
#define GEOM_CSG_MAX_MERGE 4096
/* Members beyond which geom_csg_finish builds the keep boxes' hierarchy. */
#define GEOM_CSG_BVH_MIN 32
/* Subtracted boxes a ray is tested against before the members (geom_csg.nholes). */
#define GEOM_CSG_MAX_HOLES 4

/* o, or a member of it at any level, is a mesh (depth: o's nesting level;
 * nothing deeper than GEOM_CSG_MAX_DEPTH counts). */
int geom_csg_has_mesh(const scene_object *o, int depth);
/* The leaves of o (1 for a leaf), as far as GEOM_CSG_MAX_DEPTH. */
long geom_csg_leaf_count(const scene_object *o, int depth);

typedef enum { GEOM_CSG_LEAF, GEOM_CSG_UNION, GEOM_CSG_MERGE, GEOM_CSG_INTERSECTION, GEOM_CSG_DIFFERENCE } geom_csg_op;

typedef struct {
    geom_csg_op op;
    int inverse;      /* inside test negated */
    int parent;       /* -1 at the root */
    int first, nkids; /* members: kids[first .. first + nkids) */
    int shape;        /* GEOM_CSG_LEAF: index into shapes */
    int flip;         /* GEOM_CSG_LEAF: normal points into the result's outside when negated */
    int nosurf;       /* GEOM_CSG_LEAF: takes part in inside tests only (a clipped_by
                         solid); set by the caller after adding the leaf */
    int inv_odd;      /* an odd number of inversions on the node and its
                         ancestors, a subtracted member of a difference
                         counting as one (set by geom_csg_finish) */
} geom_csg_node;

/* A node of the members' bounding volume hierarchy (geom_csg.bvh): a leaf
 * (count > 0) holds bvh_items[first .. first + count); an inner node's
 * children are the next node and node `first`. */
typedef struct {
    vec3 lo, hi;
    int first, count;
} geom_csg_bvh;

typedef struct {
    geom_csg_node *nodes;
    int nnodes, capnodes;
    int *kids;
    int nkids, capkids;
    geom_shape *shapes;
    unsigned *shape_leaf;  /* caller's tag per shape (accel.c: its leaf record) */
    int *shape_node;
    int nshapes, capshapes;
    vec3 lo, hi;           /* world bounds of the result's surface (may be infinite before clipping) */
    /* From geom_csg_finish (NULL before): per shape, the box (lo, hi) where
     * a crossing of it can be kept (its own box within the boxes of the
     * siblings that must contain it, up to the root), and per node the box
     * of its inside; rays and inside tests skip what lies outside them. */
    vec3 *keep_box, *inside_box;
    /* From geom_csg_finish, for a CSG of more than GEOM_CSG_BVH_MIN members
     * (NULL otherwise): a hierarchy over the finite keep boxes, so that a
     * ray tries the members whose boxes it crosses, not every member; the
     * members with an unbounded keep box are tried always. */
    geom_csg_bvh *bvh;
    int *bvh_items, *unbounded;
    int nunbounded;
    /* From geom_csg_finish: the box holding every member's keep box
     * (keep_lo, keep_hi) and, where the root is a difference, the boxes of
     * its subtracted members that are untransformed boxes, shrunk by a
     * margin (nholes of them, 0 when a keep box is unbounded or a member is
     * searched from the ray's start): every crossing but a hole's own is
     * kept only outside it, so a ray whose stretch through keep_lo..keep_hi
     * runs inside one hole, or a chain of overlapping ones, has no
     * crossing, and one that starts so is searched from where the chain
     * ends. */
    vec3 keep_lo, keep_hi;
    vec3 hole_lo[GEOM_CSG_MAX_HOLES], hole_hi[GEOM_CSG_MAX_HOLES];
    int nholes;
    unsigned flags;        /* caller's tag (accel.c: effective object flags of the root) */
} geom_csg;

typedef struct {
    double t;
    int shape, part, flip;
} geom_csg_hit;

/* After all nodes are in: fixes the member lists, the normal flips and the
 * bounds (infinite where half-spaces leave it open). Returns 0 when the
 * result is provably empty or has no members. */
int geom_csg_finish(geom_csg *c);
/* Limit infinite parts (planes, unbounded quadrics and polys) to the world box [lo, hi] and clip the bounds to it. */
void geom_csg_clip(geom_csg *c, vec3 lo, vec3 hi);
/* Frees the members' shape data too (geom_shape_release). */
void geom_csg_free(geom_csg *c);

/* Per leaf object that becomes a member: the caller's tag for it (kept in
 * geom_csg.shape_leaf), or -1 when out of memory. `tex` is the effective
 * texture (o's own, else the nearest parent's; may be NULL) and `flags` o's
 * flags plus its parents' `inherit` bits. */
typedef int (*geom_csg_leaf_fn)(void *ctx, const scene_object *o, const scene_texture *tex, unsigned flags);

typedef struct {
    geom_csg_leaf_fn leaf; /* NULL: every tag 0 */
    void *ctx;
    unsigned inherit;      /* OBJ_* flags members take from their parents */
    int meshes;            /* mesh members as geom_mesh shapes; else they count as unsupported */
    diag *d;               /* warnings (degenerate and unsupported members) and errors; may be NULL */
    long unsupported;      /* out: members of kinds geom does not model */
} geom_csg_builder;

/* The tree of object o (any kind: a leaf gives a one-member tree) with its
 * clipped_by solids (an intersection with them, their surfaces not
 * counted), added under node `parent` (-1: the root) of c; `tex` and
 * `flags` are what o inherits. A degenerate member (zero size, singular
 * transform, non-finite numbers) or one geom does not model is left out of
 * an intersection and is an empty set elsewhere (a difference whose first
 * member is gone is empty, as in POV-Ray). PT_ERR_LIMIT beyond
 * GEOM_CSG_MAX_DEPTH (reported in b->d), PT_ERR_NOMEM. Call
 * geom_csg_finish afterwards. */
pt_status geom_csg_build(geom_csg *c, const scene_object *o, const scene_texture *tex, unsigned flags, int parent,
                         int depth, geom_csg_builder *b);

/* Nearest crossing of the result with t in (tmin, tmax), the members'
 * crossings placed by `rule` (geom_shape.h). */
int geom_csg_intersect(const geom_csg *c, vec3 org, vec3 dir, double tmin, double tmax, geom_csg_hit *h,
                       geom_ray_rule rule);
/* Whether some crossing of the result lies in (tmin, tmax): what
 * geom_csg_intersect finds, without searching on for the nearest (shadow
 * rays). */
int geom_csg_occludes(const geom_csg *c, vec3 org, vec3 dir, double tmin, double tmax, geom_ray_rule rule);
/* Every kept crossing in (tmin, tmax), nearest first, each the nearest at
 * least max(step, 1e-7 t) past the one before: what geom_csg_intersect
 * called again from just past each crossing gives, from one search of
 * each member over the whole interval (members whose root finders work on
 * the interval they are given may place a root an ulp apart). Returns how
 * many (at most max), or -1 when the caller must step itself: an
 * isosurface member (its max_trace counts from the search's start) or
 * more kept crossings than max. */
int geom_csg_crossings(const geom_csg *c, vec3 org, vec3 dir, double tmin, double tmax, double step, geom_csg_hit *out,
                       int max, geom_ray_rule rule);
int geom_csg_inside(const geom_csg *c, int node, vec3 p);
/* Does a point p on the surface of leaf `node` belong to the result's
 * surface (the member rules at every level up to the root)? */
int geom_csg_kept(const geom_csg *c, int node, vec3 p);

#endif
