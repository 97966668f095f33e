/* accel.h - Embree 3 scene built from the scene IR: triangles and meshes as
 * Embree triangle geometry, analytic shapes (sphere, box, plane, cylinder,
 * cone, disc, torus) as user geometry intersected in double precision,
 * reused meshes as instances, CSG intersection/difference/merge evaluated
 * exactly along the ray (unions are flattened). */
#ifndef PT_ACCEL_H
#define PT_ACCEL_H
#include "diag.h"
#include "scene.h"

typedef struct accel accel;

typedef struct {
    double t;                     /* ray parameter (dir need not be unit) */
    vec3 p;                       /* world hit point */
    vec3 ng;                      /* world geometric normal, unit, NOT flipped to face the ray */
    vec3 ns;                      /* world shading normal (smooth triangles/meshes), unit, same side as ng */
    double u, v;                  /* surface parameters (barycentrics for triangles) */
    const scene_object *obj;      /* the leaf object hit */
    const scene_texture *texture; /* effective texture (per-triangle mesh textures resolved) */
    unsigned prim;                /* primitive index within the object: triangle index for meshes,
                                     the part for analytic shapes (box face, cone side/base/cap:
                                     GEOM_PART_* in geom_shape.h), else 0 */
    unsigned flags;               /* effective OBJ_* flags: obj->flags plus no_shadow/no_image/
                                     no_reflection/no_radiosity inherited from CSG parents */
    double uv[2];                 /* POV-Ray 3.7's UV coordinates of the hit (ObjectBase::UVCoord and
                                     its overrides), what uv_mapping evaluates textures at: sphere,
                                     box (cube net), torus, lathe, sor, ovus in object space; mesh and
                                     mesh2 interpolate their uv_vectors (<0,0> without); bicubic_patch
                                     and parametric (tessellated) their patch/parameter uv; every
                                     other shape the world hit point's x and y. Analytic shapes
                                     compute it only when the object or its textures use
                                     uv_mapping (else the world x and y) */
    int pov_flip;                 /* 1 when POV-Ray's own surface normal (its Normal(), which picks
                                     texture or interior_texture) points against ng: triangles and
                                     meshes, whose POV-Ray normal is (P1-P2) x (P3-P2), the opposite
                                     of the winding normal (smooth ones: the interpolated normal's
                                     side); else 0 */
} accel_hit;

typedef struct {
    long geometries, instances, triangles, user_prims, unsupported;
    double build_seconds;
} accel_stats;

/* Build. Unsupported shapes are skipped with one warning per kind in `d`;
 * Embree failures give NULL, PT_ERR_DEVICE and an error in `d`. threads <= 0
 * lets Embree use every core for its builds. */
accel *accel_build(const scene *s, int threads, diag *d, pt_status *status);
void accel_free(accel *a);
/* The scene must outlive the accel: hits point into it (hit->obj, and
 * hit->texture, which is &s->default_texture for untextured objects).
 * Textures and no_shadow/no_image/no_reflection/no_radiosity are inherited
 * from CSG parents when the leaf has none of its own.
 *
 * Self-intersection rule: every query uses an effective tmin of
 * max(tmin, accel_epsilon(a, org, dir)), i.e.
 * ACCEL_EPS_REL * (s + max|org_i|) / |dir|, so a ray leaving a surface does
 * not hit it again at t ~ 0, with s = accel_eps_scale, times
 * ACCEL_EXACT_EPS_FACTOR when every shape is closed-form (reasoning in
 * accel.c). */
#define ACCEL_EPS_REL 1e-5
#define ACCEL_EXACT_EPS_FACTOR 1e-3
/* Thread-safe: any number of threads may query one accel concurrently. */

/* How a query's ray meets the surfaces whose crossings are searched for
 * along it (isosurfaces; every other shape is met at its exact crossings
 * under both rules; geom_shape.h's rules):
 * ACCEL_RAY_POV: POV-Ray 3.7's rules for its rays: the hit is placed at
 *   the far end of the halving piece shorter than `accuracy` that holds
 *   the crossing (up to accuracy beyond the surface: accel_hit_placement),
 *   and a ray that starts on the surface searches from 5 accuracy on (a
 *   shadow ray from a noise-displaced surface under a grazing light meets
 *   the next fold, as in POV-Ray's images). Every query below that does
 *   not name its rule uses it: they trace the renderer's rays (camera,
 *   reflected, refracted, shadow, photon and GI rays).
 * ACCEL_RAY_EXACT: every crossing at its root, from tmin on: queries
 *   between two points on surfaces that count or step over the crossings
 *   between them (visibility for density estimates), which a hit placed
 *   inside a surface or a search that starts 5 accuracy on would
 *   miscount. */
typedef enum { ACCEL_RAY_POV = 0, ACCEL_RAY_EXACT = 1 } accel_ray_rule;

/* Nearest hit with t in (tmin, tmax); returns 1 on hit. (no_image and
 * no_reflection are not applied here yet: callers see them in hit->obj->flags.)
 * accel_intersect is accel_intersect_rule under ACCEL_RAY_POV. */
int accel_intersect(const accel *a, vec3 org, vec3 dir, double tmin, double tmax, accel_hit *hit);
int accel_intersect_rule(const accel *a, accel_ray_rule rule, vec3 org, vec3 dir, double tmin, double tmax,
                         accel_hit *hit);
/* How far from its exact surface an ACCEL_RAY_POV hit on leaf object o may
 * lie (world length): an isosurface's accuracy, 0 for every other shape. A
 * visibility test from such a hit lifts it by more than this, so that it
 * starts on the outer side of the surface it lies on. */
double accel_hit_placement(const scene_object *o);
/* Every surface the ray crosses with t in (tmin, tmax) (tmin as for
 * accel_intersect), nearest first, each the nearest at least
 * max(step, 1e-7 t) past the one before (at most 256): fn gets each and
 * returns 0 to stop. A scene of analytic shapes and CSG alone is walked in
 * one traversal that collects every primitive's crossings (a shadow ray
 * through glass asks each primitive once, not once per surface crossed);
 * with triangles, one accel_intersect per crossing. Returns the number of
 * crossings fn got. */
typedef int (*accel_crossing_fn)(void *ctx, const accel_hit *h);
int accel_crossings(const accel *a, vec3 org, vec3 dir, double tmin, double tmax, double step, accel_crossing_fn fn,
                    void *ctx);
/* accel_crossings without the crossings of objects whose effective flags
 * carry one of `skip` (OBJ_NO_SHADOW for shadow rays: POV-Ray's shadow
 * rays do not test such objects, trace.cpp's NoShadowFlagRayObjectCondition,
 * so the next crossing's distance counts from the last one reported); in
 * the one-traversal walk such primitives are not asked at all. */
int accel_crossings_skip(const accel *a, vec3 org, vec3 dir, double tmin, double tmax, double step, unsigned skip,
                         accel_crossing_fn fn, void *ctx);
/* Whether a crossing walk's fn reads the surface of a crossing of leaf
 * object obj with effective texture tex (accel_crossings_cut). */
typedef int (*accel_surface_fn)(void *ctx, const scene_object *obj, const scene_texture *tex);
/* accel_crossings_skip for a walk that stops (fn returns 0) at the first
 * crossing of an object none of whose textures can let light through
 * (transmit_texture_may: a shadow ray's filter is 0 there): of such a
 * height field only the nearest crossing is collected, not its crossings
 * behind it (its walk over the cells along the rest of the ray).
 * The crossings fn gets are accel_crossings_skip's; where `surface` (if
 * not NULL) says fn does not read the surface of a crossing of a user
 * primitive (not of a blob, whose texture depends on the point), its
 * record has t, p, obj, texture, flags, prim and pov_flip but no
 * normals (ng and ns 0) and no uv. Returns -1 when fn
 * went on past a cut crossing (the walk's own rule passed it over), so
 * that the crossings after it may be missing: the caller walks again with
 * accel_crossings_skip. */
int accel_crossings_cut(const accel *a, vec3 org, vec3 dir, double tmin, double tmax, double step, unsigned skip,
                        accel_surface_fn surface, accel_crossing_fn fn, void *ctx);
/* Mutual visibility of two surface points for density estimates
 * (ACCEL_RAY_EXACT: it steps over crossings between the points): 1 when
 * the segment from x + lift*nx to y + lift*ny (lift = 16 eps) crosses no
 * object for which same(obj, ctx) is 0; crossings of "same" objects are
 * stepped over (at most 8); inside the self-intersection distance only
 * objects parallel to x's surface pass (contacts, see accel_intersect_from).
 * Points closer than twice the lift count as visible. Used by particle GI's estimation lists and pmfg's photon
 * gathering, so neither reaches across a wall. */
typedef int (*accel_same_fn)(const scene_object *obj, const void *ctx);
int accel_mutually_visible(const accel *a, double eps, vec3 x, vec3 nx, vec3 y, vec3 ny, accel_same_fn same,
                           const void *ctx);
/* Any hit in (tmin, tmax) by an object that casts shadows (not no_shadow). */
int accel_occluded(const accel *a, vec3 org, vec3 dir, double tmin, double tmax);
/* accel_occluded with a shadow cache (as POV-Ray 3.7's trace.cpp, which
 * keeps per light and thread the object that last blocked it,
 * lightSourceLevel1ShadowCache, and tests it first): *last (0: none)
 * names the primitive that last blocked a ray of this caller's; it is
 * asked first, and a ray it blocks is answered without the scene's
 * traversal. The answer is
 * accel_occluded's: the primitive is asked as the traversal asks it (the
 * same double ray, interval, box test and rule), and a blocked ray is
 * blocked whichever primitive blocks it. After a ray the traversal
 * answers, *last is the shape or CSG that blocked it, or 0 where nothing
 * did or a triangle did (a ray after an unblocked one is seldom blocked,
 * and the cached test would be paid for nothing). One cache per thread
 * and light: consecutive shadow rays to one light mostly meet one
 * blocker. */
int accel_occluded_cached(const accel *a, unsigned *last, vec3 org, vec3 dir, double tmin, double tmax);

/* The surface a ray leaves: the hit it starts from. */
typedef struct {
    const scene_object *obj;
    unsigned prim;
    vec3 ng;
} accel_from;
void accel_from_hit(accel_from *f, const accel_hit *h);
/* accel_intersect and accel_occluded for a ray leaving surface f (NULL:
 * the plain queries) at a point moved off it: within the self-intersection
 * distance (the rule above) other surfaces are hit too, so a point at a
 * contact (a floor point at the foot of a box standing on it) is not lit
 * through the box, nor do its rays pass into it; only the surface left and
 * surfaces parallel to it (within about 8 degrees: a float re-hit of a
 * coplanar neighbour) are passed there, as before. */
int accel_intersect_from(const accel *a, const accel_from *f, vec3 org, vec3 dir, double tmin, double tmax,
                         accel_hit *hit);
int accel_occluded_from(const accel *a, const accel_from *f, vec3 org, vec3 dir, double tmin, double tmax);
/* accel_intersect_past's `skip` bit beside the OBJ_* flags: objects whose
 * photons { pass_through } is on (photons go through them unchanged). */
#define ACCEL_SKIP_PASS_THROUGH (1u << 31)
/* The most hits one accel_intersect_past ray passes over. */
#define ACCEL_PASS_MAX 64
/* The nearest hit along a ray leaving surface f (NULL: none; as
 * accel_intersect_from) past tmin eps that carries none of the `skip`
 * flags (OBJ_* and ACCEL_SKIP_PASS_THROUGH): each passed hit moves tmin to
 * just beyond it (by max(eps, 1e-7 t)). Each intersection adds one to
 * *rays (NULL: not counted). Returns 1 with *hit the hit, 0 when the ray
 * leaves the scene, -1 when it passed ACCEL_PASS_MAX hits (*hit: the last). */
int accel_intersect_past(const accel *a, const accel_from *f, vec3 org, vec3 dir, double eps, unsigned skip,
                         accel_hit *hit, long *rays);
/* accel_occluded for n rays at once (Embree packets of 16, flagged
 * coherent: shadow rays towards one light from neighbouring points): out[k]
 * = 1 when ray k is blocked. Same effective tmin rule; analytic shapes see
 * the packet's float rays (accel_occluded passes them its double ray). */
void accel_occluded_n(const accel *a, int n, const vec3 *org, const vec3 *dir, const double *tmin,
                      const double *tmax, unsigned char *out);
/* Whether accel_intersect could find a hit for each of n rays, traced
 * together (Embree packets of 16, flagged coherent): out[k] = 0 when ray k
 * meets nothing in accel_intersect's effective interval (every object, the
 * no_shadow ones too: an intersection query runs no filter), 1 when it meets
 * something (then accel_intersect tells what). Triangles see the same float
 * ray as accel_intersect's; analytic shapes see the packet's float rays
 * where accel_intersect gives them its double ray. */
void accel_hit_any_n(const accel *a, accel_ray_rule rule, int n, const vec3 *org, const vec3 *dir,
                     const double *tmin, const double *tmax, unsigned char *out);
/* World bounds of finite geometry (infinite planes excluded) and a scene
 * scale (bounding-box diagonal) for epsilons. */
void accel_bounds(const accel *a, vec3 *lo, vec3 *hi);
double accel_scale(const accel *a);
/* Working scale of the epsilon rule: the median of the leaf objects'
 * bounding-box diagonals (at most accel_scale), so one far object does not
 * coarsen the epsilons of the rest; scales with the scene. */
double accel_eps_scale(const accel *a);
/* The distance a secondary ray's origin is moved off the surface it leaves
 * (shading offsets, photon and eye-ray tmin): 1e-6 of the rays' working
 * scale (accel_eps_scale, times ACCEL_EXACT_EPS_FACTOR in a scene of
 * closed-form shapes only; 1e-6 where that is not a positive number). One rule for the shader, the
 * caustic layer and the references, so a thin shell (a drinking glass's
 * wall in a scene with a sky sphere of radius 1e6) is crossed alike by all. */
double accel_surface_eps(const accel *a);
accel_stats accel_get_stats(const accel *a);
/* The underlying RTCScene (as void*), for benchmarks that drive Embree directly. */
void *accel_rtc_scene(const accel *a);
/* A second RTCScene over the same geometries (the same geometry ids, so
 * accel_rtc_object reads its hits too) for rays whose answers tolerate a
 * rare crack between triangles: the particle GI's link rays. It is built
 * without RTC_SCENE_FLAG_ROBUST (accel_rtc_scene keeps it), and a user
 * geometry of one primitive
 * gets a second, empty one far outside the scene so that Embree tests the
 * first one's box before calling it (a lone primitive is a BVH leaf that
 * every ray enters). Rays use a plain RTCIntersectContext. NULL on failure;
 * accel_rtc_link_scene_free releases it (before accel_free). */
void *accel_rtc_link_scene(const accel *a);
void accel_rtc_link_scene_free(void *scene);
/* Fills one Embree ray-hit record (struct RTCRayHit) for rtcIntersect1M
 * on either scene: origin o, direction d, the interval [tnear, inf), time
 * 0, every mask bit, no hit yet. */
struct RTCRayHit;
void accel_rtc_rayhit_init(struct RTCRayHit *rh, const float o[3], float tnear, const float d[3]);
/* The leaf object of a hit that rtcIntersect on accel_rtc_scene reported
 * (geomID, primID and instID[0] of its RTCHit), as accel_intersect would
 * give it; NULL when the record alone does not tell (a member of a CSG) or
 * the ids are invalid. */
const scene_object *accel_rtc_object(const accel *a, unsigned geom, unsigned prim, unsigned inst);
/* accel_rtc_object, and for a hit on a triangle the triangle's index among
 * the leaf's own (a mesh's tris[], what accel_hit.prim gives) in *local (0
 * for other hits). Embree's u, v of such a hit weight the triangle's second
 * and third vertices, as accel_hit's do. */
const scene_object *accel_rtc_object_tri(const accel *a, unsigned geom, unsigned prim, unsigned inst, unsigned *local);
/* The (u, v) of mesh o's triangle `local` (its index among the mesh's own,
 * as accel_rtc_object_tri gives it) at barycentrics bu, bv (weights of its
 * second and third vertices): Mesh::UVCoord interpolates the corners'
 * uv_vectors (mesh.cpp; <0,0> without uv_vectors). What a uv-mapped
 * texture reads where a ray hits the mesh. */
void accel_mesh_uv(const scene_object *o, unsigned local, double bu, double bv, double uv[2]);
/* The leaf object a bare Embree hit lies on (geomID, primID, instID[0]
 * and u of its RTCHit), and its effective texture (*tex; the CSG parents'
 * when the leaf has none), for every hit accel_rtc_object answers and for
 * hits on CSG results too (their record's u names the member hit); a mesh
 * triangle's own texture_list entry where it names one. NULL: invalid
 * ids. */
const scene_object *accel_rtc_leaf(const accel *a, unsigned geom, unsigned prim, unsigned inst, float u,
                                   const scene_texture **tex);
/* Every leaf accel_rtc_leaf can name: leaf i of [0, accel_leaf_count) and
 * its texture as accel_rtc_leaf gives it (*tex; NULL where the leaf and
 * its CSG parents have none; a mesh's texture_list entries are read
 * through scene_mesh_tri_texture). */
int accel_leaf_count(const accel *a);
const scene_object *accel_leaf_at(const accel *a, int i, const scene_texture **tex);
/* Embree geometry ids run over [0, accel_rtc_ngeoms). For a geometry of
 * world-space triangles (the ids rtcIntersect on accel_rtc_scene or
 * accel_rtc_link_scene reports with an invalid instID), its triangle count,
 * with *v its vertices (3 floats each) and *idx its vertex indices (3 per
 * triangle; Embree's u, v of a hit weight vertices idx[1] and idx[2]);
 * else 0 (user geometry, instances). The arrays live as long as `a`. */
unsigned accel_rtc_ngeoms(const accel *a);
long accel_rtc_triangles(const accel *a, unsigned geom, const float **v, const unsigned **idx);
/* The smallest ray parameter queries accept (see the self-intersection rule). */
double accel_epsilon(const accel *a, vec3 org, vec3 dir);

#endif
