/* accel_surface.h - sample points uniformly by world area on the surfaces of
 * a scene: the emitters for next-event estimation (reference/), and later
 * the area particles of the particle-space GI (seed 000, section 4.1: area
 * particles "distributed uniformly over all surfaces").
 *
 * A set is built from the scene's leaf objects that a caller-supplied
 * weight function accepts. Each accepted surface becomes one or more
 * "pieces": one per triangle (triangle, smooth_triangle, each mesh
 * triangle), one per analytic leaf (sphere, box, disc, cylinder, cone,
 * torus), and one per infinite plane, clipped to the scene's finite bounds
 * (accel_bounds; DESIGN.md: "Infinite planes are clipped to the scene's
 * finite bounds for GI purposes"). Piece i is chosen with probability
 * weight_i * area_i / sum_j weight_j * area_j, then a point uniform by world
 * area on it, so the density over the set is weight_i / sum (per unit area).
 *
 * Uniform in world space under the object's transform: exact for triangles
 * and all planar parts (box faces, discs, caps, clipped planes: an affine
 * map scales area by a constant on a plane) and for curved shapes under
 * similarity transforms. Curved shapes (sphere, cylinder/cone side, torus)
 * under a non-uniform scale or shear are sampled uniformly in object space
 * and accepted with probability J/J_max, where J = |det A| |A^-T n| is the
 * local area scale of the linear part A (exact in distribution); their world
 * area is then computed by quadrature (spectrally accurate for the periodic
 * directions; relative error below 1e-9 in the tests).
 *
 * Not sampled (pdf 0, so MIS stays unbiased: a BSDF ray that finds such a
 * surface counts it with full weight): members of CSG intersection,
 * difference and merge (their visible surface is a part of the members'
 * surfaces; a later version can sample a member and reject points that the
 * CSG inside rules remove), unsupported shapes, degenerate objects and
 * objects with clipped_by. Polygons (their region cut into triangles) and
 * height fields (their cells' triangles) are sampled exactly; lathe, sor,
 * linear prism and text uniformly by area (geom_sweep_sample) under
 * similarities. Superellipsoid, quadric, poly, blob, isosurface,
 * julia_fractal, conic prisms and the sweeps under other transforms are
 * sampled by random lines (geom_tess.h: Crofton's formula, exact in
 * distribution; their area is a quasi-Monte Carlo estimate to 0.1%
 * standard error or 65536 lines, within 2^19 lines per scene); quadric and
 * poly within the scene's finite bounds, as planes.
 * Union members are sampled as separate leaves, as accel renders them. */
#ifndef PT_ACCEL_SURFACE_H
#define PT_ACCEL_SURFACE_H
#include "accel.h"
#include "rng.h"

typedef struct accel_surf accel_surf;

/* Weight per unit area of a leaf surface (>= 0; 0 leaves it out). `tex` is
 * the effective texture (inherited from CSG parents, mesh triangle textures
 * resolved, never NULL) and `flags` the effective OBJ_* flags. */
typedef double (*accel_surf_weight_fn)(void *ctx, const scene_object *leaf, const scene_texture *tex, unsigned flags);

typedef struct {
    const scene_object *obj;
    const scene_texture *texture;
    unsigned flags;
    unsigned prim;     /* mesh triangle index, else ACCEL_SURF_ANY */
    double area;       /* world area */
    double weight;     /* weight per unit area */
} accel_surf_piece;

#define ACCEL_SURF_ANY 0xffffffffu

typedef struct {
    vec3 p;            /* world point */
    vec3 n;            /* unit world geometric normal (outward for closed shapes, winding for triangles) */
    const scene_object *obj;
    const scene_texture *texture;
    unsigned flags;
    unsigned prim;     /* as accel_hit.prim: triangle of a mesh, part of a box/cone (geom_shape.h) */
    int piece;
    double pdf_area;   /* density per unit world area over the whole set */
} accel_surf_sample;

/* Build a set. `weight` NULL = every surface with weight 1. Returns NULL on
 * out-of-memory (st = PT_ERR_NOMEM); an empty set is valid. */
accel_surf *accel_surf_build(const scene *s, const accel *a, accel_surf_weight_fn weight, void *ctx, diag *d,
                             pt_status *st);
/* The same with infinite planes (and quadrics, polys) clipped to the box
 * [*lo, *hi] instead of the scene's finite bounds (lo or hi NULL: those):
 * for sets that must cover what the camera sees of a plane; the areas of
 * shapes sampled by random lines are estimated on `threads` threads
 * (accel_surf_build: 1), the same set for any count. */
accel_surf *accel_surf_build_in(const scene *s, const accel *a, const vec3 *lo, const vec3 *hi,
                                accel_surf_weight_fn weight, void *ctx, int threads, diag *d, pt_status *st);
void accel_surf_free(accel_surf *as);

int accel_surf_count(const accel_surf *as);
const accel_surf_piece *accel_surf_piece_at(const accel_surf *as, int i);
double accel_surf_total_area(const accel_surf *as);
double accel_surf_total_weight(const accel_surf *as); /* sum of weight * area */

/* Sample the set: u0 picks the piece, (u1, u2) the point (stratify them for
 * stratified sampling); `r` supplies extra numbers for the rejection steps
 * (tori, and curved shapes under non-similarity transforms). With r NULL the
 * first candidate is taken, which is uniform only for triangles, planar
 * parts and spheres/cylinders/cones under similarities. Returns 0 if the set
 * is empty. */
int accel_surf_sample_point(const accel_surf *as, double u0, double u1, double u2, rng *r, accel_surf_sample *out);
/* A point uniform on one piece (pdf_area is still the set's density). */
int accel_surf_sample_piece(const accel_surf *as, int piece, double u1, double u2, rng *r, accel_surf_sample *out);

/* The piece of (obj, prim) (prim ignored except for meshes), or -1. */
int accel_surf_find(const accel_surf *as, const scene_object *obj, unsigned prim);
/* Density per unit area with which accel_surf_sample_point produces the hit
 * point (0 when the hit is on no piece of the set, e.g. a plane outside its
 * clip box). */
double accel_surf_pdf(const accel_surf *as, const accel_hit *h);

#endif
