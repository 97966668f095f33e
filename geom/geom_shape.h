/* geom_shape.h - exact double-precision ray intersection with the analytic
 * POV-Ray shapes (sphere, box, plane, cylinder, cone, disc, torus; and, in
 * their own modules, polygon, lathe, sor, prism, text (geom_sweep.h),
 * superellipsoid, quadric, poly, blob (geom_implicit.h) and height_field
 * (geom_hfield.h)). Pure math: no Embree here; accel.c wraps these as
 * Embree user geometry.
 *
 * Every shape is intersected in its object space: the world ray is mapped by
 * the object's `inv` (direction not renormalised, so t is the same parameter
 * in both spaces) and normals go back with the inverse transpose. */
#ifndef PT_GEOM_SHAPE_H
#define PT_GEOM_SHAPE_H
#include "scene.h"

/* Parts reported in geom_shape_hit.part (and accel_hit.prim). */
enum {
    GEOM_PART_BOX_NX = 0, GEOM_PART_BOX_PX, GEOM_PART_BOX_NY,
    GEOM_PART_BOX_PY, GEOM_PART_BOX_NZ, GEOM_PART_BOX_PZ,
    GEOM_PART_CONE_SIDE = 0, GEOM_PART_CONE_BASE = 1, GEOM_PART_CONE_CAP = 2,
    GEOM_PART_OVUS_BOTTOM = 0, GEOM_PART_OVUS_TOP = 1, GEOM_PART_OVUS_LEMON = 2
};

typedef struct {
    shape_kind kind;
    int identity;      /* transform is the identity: skip the ray mapping */
    int open;          /* cone/cylinder without end caps */
    int clipped;       /* plane: hits outside [clip_lo, clip_hi] are rejected */
    xform x;           /* object -> world */
    union {
        struct { vec3 c; double r; } sphere;
        struct { vec3 lo, hi; } box;
        /* unit n, n.p = d in object space; the same plane in world space
         * is wn.p = wd (wn = M^-T n, not unit), which rays and inside
         * tests use without carrying the point to object space, as
         * POV-Ray's Plane::Transform folds the transform into the plane */
        struct { vec3 n; double d; vec3 wn; double wd; } plane;
        struct { vec3 base, u, v, w; double h, r0, r1, k; } cone; /* frame: w along the axis */
        struct { vec3 c, n; double r2, h2; } disc; /* unit n, squared radii */
        struct { double R, r; } torus;           /* in the xz plane, axis y */
        struct { vec3 v0, e1, e2, n[3]; int smooth; double wind; } tri; /* CSG members only */
        /* ovus: bottom sphere (0, rb) below y = yb, top sphere ((0, rb, 0), rt)
         * above y = yt, between them the inner ("lemon") part of the spindle
         * torus of tube radius rc around the circle of radius h at y = v
         * (centres of the generating circle on the far side of the axis) */
        struct { double rb, rt, rc, h, v, yb, yt; } ovus;
    } g;
    vec3 lo, hi;       /* world bounds (planes: the clip box) */
    vec3 clip_lo, clip_hi;
    /* sweeps, implicit shapes, height field, fractal, mesh */
    void *data;        /* derived data owned by the shape (geom_shape_release frees it) */
    int infinite;      /* unbounded surface (quadric, poly): clipped like planes */
    vec3 olo, ohi;     /* object-space bounds of the finite ones */
} geom_shape;

typedef struct {
    double t;
    int part;
} geom_shape_hit;

/* Puts the crossing (t, part) into out[0..n-1], kept ascending and at most
 * max long (when full, the farthest gives way to a nearer t; an equal or
 * farther t is dropped): returns the new count. Every shape's hits list
 * (geom_shape.c, fractal, height field, isosurface family, sweeps). */
static inline int geom_shape_hit_put(geom_shape_hit *out, int n, int max, double t, int part)
{
    if (max <= 0) return 0;
    if (n == max && !(t < out[n - 1].t)) return n;
    int i = n < max ? n++ : n - 1;
    while (i > 0 && out[i - 1].t > t) {
        out[i] = out[i - 1];
        i--;
    }
    out[i].t = t;
    out[i].part = part;
    return n;
}

/* The entry points of a shape family module FAM that geom_shape.c calls
 * for its kinds, one contract for all (geom_sweep, geom_hfield,
 * geom_fractal):
 *   geom_FAM_init   set up sh from o: object-space bounds in lo/hi, may
 *                   allocate sh->data; -1 when degenerate;
 *   geom_FAM_free   free sh->data;
 *   geom_FAM_hits   object-space ray o + t d: crossings with t in
 *                   (tmin, tmax), ascending, at most max;
 *   geom_FAM_inside whether the object-space point q is inside. */
#define GEOM_FAMILY(fam)                                                                                               \
    int geom_##fam##_init(geom_shape *sh, const scene_object *o, vec3 *lo, vec3 *hi);                                  \
    void geom_##fam##_free(void *data);                                                                                \
    int geom_##fam##_hits(const geom_shape *sh, vec3 o, vec3 d, double tmin, double tmax, geom_shape_hit *out,         \
                          int max);                                                                                    \
    int geom_##fam##_inside(const geom_shape *sh, vec3 q);

/* Fill `sh` from a leaf object of an analytic kind (triangles and smooth
 * triangles too: they are intersected here when they belong to a CSG
 * intersection/difference; otherwise Embree handles them). Returns 0 on success, -1
 * when the object is degenerate (zero radius, singular transform, non-finite
 * numbers) and should be skipped. World bounds are computed for finite shapes;
 * planes get them from geom_shape_clip_plane. */
int geom_shape_init(geom_shape *sh, const scene_object *o);
/* geom_shape_init that also takes meshes (geom_mesh.h: parse-time queries). */
int geom_shape_init_mesh(geom_shape *sh, const scene_object *o);
/* Planes are infinite: limit one to the world box [lo, hi] (see accel.c for
 * how that box is chosen) and set its bounds to the part of the box it can
 * touch. Also used for the other unbounded shapes (sh->infinite). */
void geom_shape_clip_plane(geom_shape *sh, vec3 lo, vec3 hi);
/* Free what geom_shape_init allocated (the shape may be copied before:
 * exactly one copy is released). */
void geom_shape_release(geom_shape *sh);
/* 1 when the shape's inside lies within its bounds (CSG bounding); 0 for
 * half-spaces, unbounded solids and shapes without an inside. */
int geom_shape_solid_bounded(const geom_shape *sh);
/* Blob components with their own textures: the one that dominates at the
 * world point p; NULL otherwise. */
const scene_texture *geom_shape_texture(const geom_shape *sh, vec3 p);
/* How a traced ray meets the surfaces whose crossings are searched for
 * along it (isosurfaces; every other shape's crossings are its roots under
 * either rule):
 * GEOM_RAY_POV: POV-Ray 3.7's rules for its rays (isosurface.cpp
 *   All_Intersections, Function_Find_Root_R): a crossing is placed at the
 *   far end of the halving piece shorter than `accuracy` (world length)
 *   that holds it, up to accuracy beyond the surface; a ray that starts on
 *   the surface (within 4 max_gradient accuracy of the threshold) searches
 *   from 5 accuracy on. The renderer's rays, whose images are compared with
 *   POV-Ray's: the shading of a noise-displaced surface depends on both.
 * GEOM_RAY_EXACT: every crossing at its root, searched from tmin on: for
 *   queries that count the crossings between two points on surfaces
 *   (visibility for density estimates), which a ray starting up to
 *   accuracy inside a surface or skipping the first 5 accuracies would
 *   miscount. */
typedef enum { GEOM_RAY_POV = 0, GEOM_RAY_EXACT = 1 } geom_ray_rule;

/* Nearest intersection with t in (tmin, tmax) of the world ray org + t*dir,
 * a traced ray under `rule`. Returns 1 and fills `h` on a hit. Never
 * produces NaN for finite input. */
int geom_shape_intersect(const geom_shape *sh, vec3 org, vec3 dir, double tmin, double tmax, geom_shape_hit *h,
                          geom_ray_rule rule);
/* All crossings with t in (tmin, tmax), ascending, at most `max` of them
 * (the `max` nearest; a torus has up to 4, the quadrics up to 2, swept,
 * implicit and mesh shapes any number), each at its root. */
int geom_shape_hits(const geom_shape *sh, vec3 org, vec3 dir, double tmin, double tmax, geom_shape_hit *out,
                     int max);
/* The crossings a traced ray gets (CSG members, geom_shape_intersect):
 * geom_shape_hits under the scene's per-ray limits, as POV-Ray reports
 * them: an isosurface gives at most its max_trace crossings (default 1),
 * placed by `rule`. geom_shape_hits is the geometry's full set
 * (tessellation, sampling). */
int geom_shape_ray_hits(const geom_shape *sh, vec3 org, vec3 dir, double tmin, double tmax, geom_shape_hit *out,
                         int max, geom_ray_rule rule);
/* Whether the world point p is strictly inside the solid, as POV-Ray defines
 * it for CSG: planes and discs are half-spaces (the side against the normal),
 * open cylinders and cones are their closed solids, triangles have no inside. */
int geom_shape_inside(const geom_shape *sh, vec3 p);
/* Surface data at world point p (on the shape, `part` from the hit): unit
 * outward world normal and natural surface parameters in [0,1] (triangles:
 * barycentrics, normal by world winding; `ns` gets the interpolated normal
 * of smooth triangles, else the geometric one; it may be NULL). u and v
 * may be NULL: the parameters are then not computed (they cost an atan2
 * and more per hit on round shapes, and only triangles' are read). */
void geom_shape_surface(const geom_shape *sh, vec3 p, int part, vec3 *ng, double *u, double *v);
void geom_shape_shading(const geom_shape *sh, vec3 p, vec3 ng, vec3 *ns);
/* POV-Ray's own unit normal at p (its Normal(): what trace() reports): the
 * shading normal, except that triangles give (P1 - P2) x (P3 - P2) and
 * smooth triangles and meshes their interpolated normal, none of them
 * oriented by the winding. */
vec3 geom_shape_pov_normal(const geom_shape *sh, vec3 p, int part);
/* POV-Ray 3.7's UV coordinates at world point p (accel_hit.uv): sphere,
 * box, torus, ovus, lathe and sor in object space, every other shape the
 * world x and y (ObjectBase::UVCoord). Always finite. */
void geom_shape_uv(const geom_shape *sh, vec3 p, int part, double uv[2]);

/* Parametric grid for radiance particles (DESIGN.md) on the shapes that
 * are not triangles or Embree's: object-space triangles whose vertices lie on the exact surface,
 * with the exact outward normals there, about n x n per part (polygon and
 * height_field: their own triangles; quadric, poly, blob, isosurface and
 * julia_fractal: marching tetrahedra on n cells along the longest side of
 * their bounds, geom_tess.h; the unbounded quadric and poly within their
 * clip box, so clip them first with geom_shape_clip_plane). Calls fn per
 * triangle; returns the number of triangles, 0 when the shape has no grid
 * (the original shapes, which GI parametrises itself), -1 when fn returned
 * 0 or memory ran out. */
typedef int (*geom_grid_fn)(void *ctx, const vec3 p[3], const vec3 n[3]);
int geom_shape_grid(const geom_shape *sh, int n, geom_grid_fn fn, void *ctx);

/* Real roots of c[0] + c[1] x + ... + c[n] x^n (n <= 4) inside [a, b], in
 * ascending order; returns their number. Exposed for the unit tests. */
int geom_poly_roots(const double *c, int n, double a, double b, double *roots);

#endif
