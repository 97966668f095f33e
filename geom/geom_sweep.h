/* geom_sweep.h - shapes made from 2-D spline curves, intersected exactly
 * in double precision in object space: lathe (curve revolved about y),
 * sor (POV-Ray's r^2 = cubic(y) surface of revolution), prism (curve swept
 * along y, linearly or conically), text (glyph outlines swept along z) and
 * polygon (planar, even-odd sub-polygons).
 *
 * Every curve segment is a polynomial p(t) = a t^3 + b t^2 + c t + d,
 * t in [0,1], built from the points by POV-Ray's spline rules (linear,
 * quadratic and Catmull-Rom cubic interpolation, Bezier). The ray equation
 * per segment is a polynomial in t (lathe: degree 2 x spline degree, prism:
 * spline degree) or in the ray parameter (sor: 3), solved with geom_poly
 * and polished by Newton steps on the original two-equation system, so hits
 * are exact to rounding. Insides follow POV-Ray: a point is inside a lathe,
 * prism or glyph when a ray from it in +x (+r) crosses the curve an odd
 * number of times (evaluated on monotonic pieces with the segments' exact end
 * points, so a vertex is counted once); inside a sor when r^2 <= f(y).
 *
 * Parts (geom_shape_hit.part): 0 base cap, 1 top cap, 2 + k segment k. */
#ifndef PT_GEOM_SWEEP_H
#define PT_GEOM_SWEEP_H
#include "geom_shape.h"
#include "rng.h"

/* geom_sweep_init (kinds SHAPE_LATHE, SOR, PRISM, TEXT and POLYGON;
 * allocates sh->data), _free, _hits, _inside (geom_shape.h) */
GEOM_FAMILY(sweep)
/* Object-space outward normal (not unit) and surface parameters at q. */
void geom_sweep_surface(const geom_shape *sh, vec3 q, int part, vec3 *n, double *u, double *v);
/* POV-Ray's UV coordinates (uv_mapping) of a lathe or sor at q. */
void geom_sweep_uv(const geom_shape *sh, vec3 q, int part, double uv[2]);
/* GI sampling (lathe, sor, linear-sweep prism, text): the object-space
 * surface area (0 when not supported: conic prisms, polygons), and a point
 * uniform by object-space area with its outward object-space normal and
 * part. Parts are picked by exact area (Gauss-Legendre on the polynomial
 * integrands: caps by the divergence theorem, sides with |C'| and the
 * lathe's radius), positions within a part by rejection against a bound of
 * the density taken from dense samples with a 10 % margin, caps by rejection
 * against the even-odd test. With r NULL the first candidate is taken
 * (u1 picks the part and the curve parameter, u2 the angle or height). */
double geom_sweep_area(const geom_shape *sh);
void geom_sweep_sample(const geom_shape *sh, double u1, double u2, rng *r, vec3 *p, vec3 *n, unsigned *part);

/* Grid triangles (geom_shape_grid) of a lathe, sor, prism, text or polygon. */
int geom_sweep_grid(const geom_shape *sh, int n, geom_grid_fn fn, void *ctx);
/* The same grid sized by length: cells of at most `cell` object units along
 * each profile segment (by its arc length) and around (lathe, sor: the
 * widest circle, at least 3) or along the sweep (prism, text); sor caps
 * by their radius; prism and text caps from the curves polygonised as their
 * sides (their trapezoids may be longer: GI splits them). Where the normal
 * turns faster, cells of at most `turn` radians of it: along a segment (its
 * normal's total turning / turn cells) and around a lathe or sor (at least
 * 2 pi / turn); turn <= 0 or infinite: by length alone. 0 for polygons. */
int geom_sweep_grid_cell(const geom_shape *sh, double cell, double turn, geom_grid_fn fn, void *ctx);

/* Polygon: its even-odd region as object-space triangles (trapezoids of
 * the slabs between vertex heights, two triangles each; exact for simple
 * and holed polygons). Calls emit(ctx, a, b, c) per triangle; returns the
 * number emitted, or -1 when emit failed. */
int geom_polygon_triangles(const geom_shape *sh, int (*emit)(void *ctx, vec3 a, vec3 b, vec3 c), void *ctx);

/* One curve segment of POV-Ray 3.7's lathe and prism splines from the
 * points starting at P (linear 2, quadratic 3, cubic and bezier 4):
 * (u, v)(w) = a w^3 + b w^2 + c w + d for w in [0, 1], per coordinate. */
void geom_sweep_coeffs(scene_spline type, const double (*P)[2], double a[2], double b[2], double c[2], double d[2]);

#endif
