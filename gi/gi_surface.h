/* gi_surface.h - the surfaces particle GI works on, as patches with one
 * interface: area, sampling by area, radiance-particle layout, and mapping a
 * ray hit to the 3 radiance particles around it with barycentric weights.
 *
 *  - Triangle patches: triangles, smooth triangles, every mesh triangle, the
 *    faces of boxes (2 per face) and infinite planes clipped to the scene's
 *    finite bounds (a convex polygon, fanned). Radiance particles are the
 *    vertices of a regular sub-tessellation: every edge is split into k
 *    segments, k = ceil(longest edge / tess), giving (k+1)(k+2)/2 vertices
 *    (paper, section 3.2: "tessellating the three edges such that the
 *    resulting elements have sizes smaller than a user-specified threshold").
 *  - Grid patches (analytic shapes: spheres, discs): a (u,v) grid of
 *    nu x nv cells whose world size stays under tess; each cell is split
 *    into two triangles for interpolation. The parameterisations are
 *    area-preserving in object space (sphere: azimuth and height, Archimedes'
 *    hat-box theorem; disc: angle and squared radius).
 *
 * Sides. A closed solid (sphere, box) gets particles on its outside only,
 * plus its inside when the camera or a light is inside it. Open surfaces
 * (triangles, meshes, planes, discs, and anything inverse) get both sides;
 * gi_particles later drops a side whose scattering links all miss.
 * Side 0 is the patch's front normal, side 1 its opposite.
 *
 * Every other shape accel_surface samples gets area particles (sampled by
 * accel_surface, no second implementation): cylinders, cones, tori,
 * polygons and height fields (their triangles, a piece chosen by area),
 * lathe, sor, prism, text, and the implicit shapes (quadric, poly, blob,
 * isosurface, julia_fractal, ovus, superellipsoid; Crofton lines,
 * geom_tess.h). The implicit shapes get radiance particles at the
 * vertices of their grid (geom_shape_grid: marching tetrahedra, vertices
 * on the exact surface, n = ceil(world extent / tess) cells along the
 * longest side, within [2, 128]); gi_surface_locate takes the grid
 * triangle nearest the hit (a hash of cells, each triangle in those its box
 * widened by a quarter cell touches) and the barycentrics of the nearest
 * point on it. Cylinders, cones and tori get a parametric grid of their own
 * (angle x height, caps by angle x radius; the torus's two angles) with
 * the same locate. Polygons (their even-odd region's triangles), height
 * fields (their cells' triangles, or every s-th grid point where cells are
 * shorter than tess), lathe, sor, prism and text (geom_sweep_grid_cell:
 * cells of at most tess along each profile segment's arc and around or
 * along the sweep; prism/text caps as trapezoids) get grids whose
 * triangles are split at the midpoint of their longest edge until no edge
 * exceeds 1.5 tess, located the same way (a grid triangle more than 60
 * degrees off the hit's normal counts a cell farther: creases). Only a
 * surface whose grid fails (over 4M triangles, out of memory) has no
 * radiance particles: gi_particle estimates indirect light at hits on it
 * from the particles around the hit (counted: lookups_onthefly). Closed
 * ones get their outside (and inside when the camera or a light is in
 * them); polygons, height fields, lathe, sor and unbounded quadric/poly
 * both sides.
 *
 * CSG: members of union are ordinary leaves. Members of merge, intersection
 * and difference (any depth, any shape) get particles only where their
 * surface is the CSG result's: POV-Ray's rule at every level from the
 * member to the root (intersection: inside all siblings; merge: outside
 * all; difference: the first member outside the others, a subtracted one
 * inside the first and outside the rest), with the members' own inside
 * tests (geom_shape_inside). Spheres, boxes, discs, planes and triangles
 * are sampled on their whole surface and marked `probe` (gi_particles keeps
 * a particle only if a short probe ray finds the result's surface there);
 * the other shapes get their own Crofton sampler whose keep filter is that
 * rule (exact), and implicit ones the grid triangles touching the result.
 * Both sides exist; particles go on the one facing out of the result
 * (gi_surface_side_mask: a subtracted or inverse member's inside), both
 * when the camera or a light is inside the result. CSG with a mesh member
 * and merges of more than 64 members are unions here, as in accel. */
#ifndef PT_GI_SURFACE_H
#define PT_GI_SURFACE_H
#include "accel.h"
#include "diag.h"
#include "rng.h"
#include "scene.h"

typedef struct gi_surface gi_surface;

/* tess: bound on sub-triangle edges and grid cell size (world units);
 * threads: for the area estimates of shapes sampled by lines (the same
 * surfaces for any count). */
gi_surface *gi_surface_build(const scene *s, const accel *a, double tess, int threads, diag *d, pt_status *status);
void gi_surface_free(gi_surface *g);
/* Change the tessellation bound (radiance particles are laid out anew). */
void gi_surface_retess(gi_surface *g, double tess);

/* 1 when world point q is strictly inside the closed solid o (a sphere or a
 * box; 0 for every other shape). */
int gi_surface_inside_solid(const scene_object *o, vec3 q);

/* 1 when p lies in the box infinite surfaces are clipped to (every finite
 * object lies in it; an infinite surface has particles only there). */
int gi_surface_in_clip(const gi_surface *g, vec3 p);
/* The fraction of patch i in that box, from a few of its own samples
 * (exactly 1 or 0 when all or none are in). */
float gi_surface_clip_fraction(const gi_surface *g, int i, uint64_t seed);
/* The objects (records) the patches belong to: nobjs of them; patch i's is
 * gi_surface_obj_index(g, i). gi_surface_view_share: the fraction of a
 * probe of camera rays (VIEW_W x VIEW_H over the image) that hit object
 * record k first; 0 without a camera. */
int gi_surface_nobjs(const gi_surface *g);
int gi_surface_obj_index(const gi_surface *g, int patch);
double gi_surface_view_share(const gi_surface *g, int k);
int gi_surface_npatches(const gi_surface *g);
double gi_surface_area(const gi_surface *g, int patch); /* one side */
int gi_surface_sides(const gi_surface *g, int patch);
int gi_surface_probe(const gi_surface *g, int patch);
/* Sides of the patch that get particles (bit s: side s): 3, or for a member
 * of merge/intersection/difference the side facing out of the CSG result
 * (both when the camera or a light is inside the result). */
int gi_surface_side_mask(const gi_surface *g, int patch);
/* 1 for a member of merge/intersection/difference (its surface is not a
 * closed solid's: gi_particle's inside/buried rules skip it). */
int gi_surface_csg_member(const gi_surface *g, int patch);
const scene_object *gi_surface_object(const gi_surface *g, int patch);
const scene_texture *gi_surface_texture(const gi_surface *g, int patch);

/* Map (u, v) in [0,1)^2 to a point of the patch, uniformly by area; r
 * drives rejection steps (curved shapes under non-similarity transforms);
 * returns 0 when the sample is rejected. nrm: unit front normal. Analytic
 * shapes are sampled by accel_surface (shared with reference/), triangles
 * by folding the unit square. */
int gi_surface_sample(const gi_surface *g, int patch, double u, double v, rng *r, vec3 *pos, vec3 *nrm);

/* Radiance particles: gi_surface_nrp of them, in the order of the patches
 * and sides that first lay them out. Patches of one object share the ones
 * at a common point with the same facing (normals within 1 degree): a
 * mesh vertex is one radiance particle per side however many triangles
 * meet there, as are the points along an edge two triangles with the same
 * sub-tessellation share, a box face's or clipped plane's triangles'
 * common vertices, a sphere's seam and poles. gi_surface_rp_slots: the
 * count before sharing (every patch side its own). */
long gi_surface_nrp(const gi_surface *g);
long gi_surface_rp_slots(const gi_surface *g);
void gi_surface_rp(const gi_surface *g, long rp, vec3 *pos, vec3 *nrm);
/* Starts loading what gi_surface_rp(g, rp) reads first (the radiance
 * particle's slot and patch maps), for callers that look up many at once. */
void gi_surface_rp_prefetch(const gi_surface *g, long rp);
/* Patch and side (0 front, 1 back) of the first patch side that laid the
 * radiance particle out (every other one sharing it is on the same object
 * and faces the same way). */
int gi_surface_rp_patch(const gi_surface *g, long rp);
int gi_surface_rp_side(const gi_surface *g, long rp);

/* The 3 radiance particles around a hit and their barycentric weights
 * (those of the hit's own triangle or grid cell; two of them can be one
 * radiance particle at a sphere's pole).
 * n_view is the shading normal facing the viewer (shade.c's n); it picks the
 * side. Returns 1, or 0 when the hit is on a surface without particles. */
int gi_surface_locate(const gi_surface *g, const accel_hit *hit, vec3 n_view, long rp[3], double w[3]);
/* 1 when every hit on the hit's piece locates the same 3 radiance
 * particles on a side (a mesh triangle not sub-tessellated: k = 1), so a
 * hit elsewhere on that triangle, seen from the same side, marks nothing
 * new; else 0. */
int gi_surface_one_cell(const gi_surface *g, const accel_hit *hit);

/* Whether the hit object carries area particles (it may have no radiance
 * particles when its grid failed; gi_particle then estimates at the hit). */
int gi_surface_has_particles(const gi_surface *g, const accel_hit *hit);
/* Objects skipped (no particles) and a patch count per kind, for stats. */
long gi_surface_skipped(const gi_surface *g);
size_t gi_surface_bytes(const gi_surface *g);

#endif
