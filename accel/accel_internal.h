/* accel_internal.h - the Embree scene's records, shared by accel.c (the
 * build: leaves, CSG primitives, triangles, instances; the public queries)
 * and accel_user.c (bounded_by and the Embree callbacks of the user
 * geometry). Not for use outside accel/. */
#ifndef PT_ACCEL_INTERNAL_H
#define PT_ACCEL_INTERNAL_H
#include "accel.h"
#include <assert.h>
#include <embree3/rtcore.h>
#include <float.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "geom_csg.h"
#include "geom_shape.h"
#include "timer.h"

#define PLANE_EXTENT_FACTOR 1e4

enum { GEOM_NONE = 0, GEOM_TRI, GEOM_USER, GEOM_INSTANCE };
enum { INHERITED_FLAGS = OBJ_NO_SHADOW | OBJ_NO_IMAGE | OBJ_NO_REFLECTION | OBJ_NO_RADIOSITY };

typedef struct {
    const scene_object *obj;
    const scene_texture *texture; /* effective, never NULL */
    unsigned flags;               /* effective: CSG parents' no_* flags included */
    double wind;                  /* -1 when the transform mirrors, else 1 */
    int identity;                 /* transform is the identity */
    int in_csg;                   /* member of a CSG primitive, built there */
    int group;                    /* shared-mesh group, -1 if none */
    int b0, bn;                   /* bounded_by: a->bshapes[b0 .. b0+bn) (analytic leaves) */
    int want_uv;                  /* uv_mapping on the object or in its textures: analytic hits
                                     compute POV-Ray's UV (else hit.uv is the world x, y) */
} accel_leaf;

/* bounded_by of the objects above a leaf (unions are flattened into their
 * members, which keep the union's bound, as POV-Ray's CSG union checks it
 * before its children). Lives on the stack during collect(). */
typedef struct bound_chain {
    const scene_object *host;
    const struct bound_chain *up;
} bound_chain;

typedef struct { unsigned leaf, local; } tri_ref;

typedef struct {
    float *v;       /* xyz per vertex (build time only) */
    size_t nv, capv;
    unsigned *idx;  /* 3 per triangle (build time only) */
    tri_ref *refs;  /* per triangle (kept) */
    size_t nt, capi, capr;
} tri_batch;

typedef struct { int kind; unsigned idx; } geom_info;

typedef struct {
    const scene_mesh *mesh;
    RTCScene scene;
    int any_no_shadow;
} mesh_group;

struct accel {
    RTCDevice dev;
    RTCScene root;
    const scene *s;
    accel_leaf *leaves;
    int nleaves, capleaves;
    tri_batch tri[2]; /* 0: casts shadows, 1: no_shadow */
    geom_shape *shapes;
    unsigned *shape_leaf;
    int nshapes, capshapes;
    mesh_group *groups;
    int ngroups;
    geom_csg *csgs;              /* user primitives nshapes .. nshapes + ncsgs - 1 */
    int ncsgs, capcsgs;
    float *ubox;                  /* 6 floats per user primitive: its box as accel_user_bounds gives it */
    unsigned char *ubox_test;     /* per user primitive: whether the callbacks test a ray against ubox
                                     before intersecting it (accel_user_box_test) */
    unsigned char *ucut;          /* per user primitive: accel_user_cut */
    int has_ucut;                 /* some primitive's ucut is set */
    geom_info *ginfo;
    unsigned nginfo;
    int has_tri_geoms; /* a geometry of triangles or instances: accel_crossings walks crossing by crossing */
    int has_costly_crossings; /* an isosurface or julia_fractal (CSG members too), whose crossings are
                                 found by searching the interval: collecting all of them along a
                                 shadow ray costs more than the walk, which stops at the first opaque
                                 one, so accel_crossings walks crossing by crossing */
    vec3 lo, hi;
    double scale;
    double eps_scale;  /* working scale of the epsilon rule (see the top) */
    double ray_eps_scale; /* the scale the rays' rule takes: eps_scale, times
                             ACCEL_EXACT_EPS_FACTOR when every leaf is closed-form */
    int inexact_leaves;   /* leaves whose hits are not closed-form in double */
    double *diags;     /* leaf bounding-box diagonals, during the build */
    int ndiags, capdiags;
    geom_shape *bshapes;         /* bounding objects (bounded_by), world space */
    int nbshapes, capbshapes;
    int *csg_b0, *csg_bn;         /* per CSG primitive, as accel_leaf.b0/bn */
    const bound_chain *cur_chain; /* during collect(): the bounds above the current object */
    accel_stats stats;
    atomic_int err;
    char errmsg[512];
};

/* One crossing found in collect mode; `cut`: its primitive's crossings
 * past this one were not collected (accel_crossings_cut). */
typedef struct {
    double t;
    unsigned prim;
    int part, shape;
    unsigned char flip, cut;
} accel_crossing;

/* Our intersect context: Embree passes the context pointer unchanged to the
 * user-geometry callbacks (documented for RTCIntersectContext), which lets
 * them use the caller's double ray. The callbacks recognise it by comparing
 * with a thread-local pointer, so a plain context (bare Embree use, as in the
 * benchmark) falls back to the float ray safely. */
typedef struct {
    struct RTCIntersectContext rtc; /* first member */
    vec3 org, dir;
    double tmin;
    double ut;               /* last accepted user-geometry hit */
    int upart, ushape, uflip; /* ushape, uflip: CSG member */
    unsigned uprim;
    int uhit;
    /* collect mode (accel_crossings): the user-geometry callback records
     * every crossing of each primitive it is asked about, stepping past
     * each by max(cstep, 1e-7 t), and reports none, so the traversal
     * visits every primitive the ray's interval meets */
    accel_crossing *cross;
    int ncross, maxcross, overflow;
    double ctmax, cstep;
    unsigned cskip; /* primitives whose effective flags carry one of these are not asked */
    int ccut;       /* a primitive whose ucut is set gives only its nearest crossing */
    geom_ray_rule rule; /* how searched-for surfaces are met (accel_ray_rule) */
    int packet;         /* a packet query's context: no double ray (org, dir, tmin unset) */
    /* an exact occlusion query: the top-level user primitive found to
     * block it, plus 1 (0: none or not asked; accel_occluded_cached) */
    unsigned oprim;
    unsigned tie_skip; /* nearest mode: primitives whose effective flags carry one of these lose ties */
} accel_query;

/* The query of this thread (the callbacks tell our context from a plain
 * one by it). */
extern _Thread_local accel_query *accel_tls_query;

/* Embree's SoA ray/hit packets (rtcore_ray.h: RTCRayN/RTCHitN layout; the
 * accessors there are C++ only). Ray fields: org 0-2, tnear 3, dir 4-6, time
 * 7, tfar 8, mask 9, id 10, flags 11; hit fields: Ng 0-2, u 3, v 4, primID 5,
 * geomID 6, instID 7. A RTCRayHitN holds the ray then the hit at 12*N. */
#define SOA_F(p, N, i, k) (((float *)(p))[(size_t)(k) * (N) + (i)])
#define SOA_U(p, N, i, k) (((unsigned *)(p))[(size_t)(k) * (N) + (i)])

/* bounded_by (accel_user.c). */
/* Whether o's bounded_by is kept (POV-Ray 3.7's remove_bounds rule; top: o
 * is a top-level object). */
int accel_keeps_bound(const scene_object *o, int top);
/* The bounds applying to object o (whose own bound counts in full if `own`,
 * else by its box), as a range of a->bshapes; 0 when out of memory. */
int accel_collect_bounds(accel *a, diag *d, const scene_object *o, int own, int *b0, int *bn);

/* The user geometry's primitives and Embree callbacks (accel_user.c). */
void accel_user_box(const accel *a, unsigned prim, float out[6]);
int accel_user_box_test(const accel *a, unsigned prim, unsigned np);
/* Whether a walk that stops at opaque surfaces (accel_crossings_cut) takes
 * only the nearest crossing of user primitive prim: a height field whose
 * every surface stops a shadow ray's light (its filter there is 0: no
 * texture of it can let light through). */
int accel_user_cut(const accel *a, unsigned prim);
void accel_user_bounds(const struct RTCBoundsFunctionArguments *args);
void accel_user_bounds_link(const struct RTCBoundsFunctionArguments *args);
/* Primitive prim's nearest hit in (tmin, tmax) of the double ray o + t d,
 * placed by `rule`. */
int accel_prim_hit(const accel *a, unsigned prim, vec3 o, vec3 d, double tmin, double tmax, geom_csg_hit *h,
                   geom_ray_rule rule);
/* The shape of primitive prim (member: its CSG member, else -1). */
const geom_shape *accel_prim_shape(const accel *a, unsigned prim, int member);
void accel_user_intersect(const struct RTCIntersectFunctionNArguments *args);
void accel_user_occluded(const struct RTCOccludedFunctionNArguments *args);
/* A crossing query's collection over every user primitive whose box the
 * ray meets, without Embree (scenes of user geometry only). */
void accel_user_cross_all(const accel *a, accel_query *q, const struct RTCRay *r);
/* Whether user primitive prim blocks the exact occlusion query q, whose
 * Embree ray is r, as accel_user_occluded answers when the traversal asks
 * it (accel_occluded_cached). */
int accel_user_blocks(const accel *a, const accel_query *q, const struct RTCRay *r, unsigned prim);
/* Occlusion filters of no_shadow geometry. */
void accel_filter_reject_all(const struct RTCFilterFunctionNArguments *args);
void accel_filter_instance_no_shadow(const struct RTCFilterFunctionNArguments *args);
#endif
