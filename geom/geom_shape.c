/* geom_shape.c - double-precision intersection of analytic shapes.
 *
 * Quadratics are solved in the cancellation-free form (roots q/a and c/q with
 * q = -(b + sign(b) sqrt(disc)), Press et al., Numerical Recipes 5.6). For the
 * sphere the discriminant is formed from the ray's perpendicular offset from
 * the centre, which keeps it accurate for distant origins (Haines et al.,
 * "Precision Improvements for Ray/Sphere Intersection", Ray Tracing Gems 2019).
 * The torus quartic is solved by isolating roots between the roots of its
 * derivatives, each bracket holding at most one root of a monotonic function
 * (the approach of Yuksel, "High-Performance Polynomial Root Finding for
 * Graphics", HPG 2022), after moving the ray origin to the torus' bounding
 * box and scaling the torus to unit size, so coefficients stay O(1). */
#include "geom_shape.h"
#include <float.h>
#include <math.h>
#include <string.h>
#include "geom_fractal.h"
#include "geom_hfield.h"
#include "geom_implicit.h"
#include "geom_mesh.h"
#include "geom_poly.h"
#include "geom_sweep.h"
#include "geom_tess.h"

#define TWO_PI 6.283185307179586476925

/* ------------------------------------------------------------ polynomials */

/* Real roots in [a, b], ascending: geom_poly.c's derivative-bracket solver
 * (one root finder for every shape). */
int geom_poly_roots(const double *c, int n, double a, double b, double *roots)
{
    return geom_poly_solve(c, n, a, b, roots, 0);
}

/* Real roots of a t^2 + 2 b t + c = 0 (note the half b), ascending. */
static int quad_half(double a, double b, double c, double *t0, double *t1)
{
    if (a == 0.0) {
        if (b == 0.0) return 0;
        *t0 = *t1 = -c / (2.0 * b);
        return 1;
    }
    double disc = b * b - a * c;
    if (disc < 0.0) return 0;
    double q = -(b + copysign(sqrt(disc), b));
    double r0 = q / a, r1 = (q != 0.0) ? c / q : r0;
    if (r0 > r1) { double t = r0; r0 = r1; r1 = t; }
    *t0 = r0;
    *t1 = r1;
    return 2;
}

/* ------------------------------------------------------------ setup */

static double det3(const double m[3][4])
{
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
         - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
         + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

static void world_bounds(geom_shape *sh, vec3 lo, vec3 hi)
{
    vec3 wl = v3s(INFINITY), wh = v3s(-INFINITY);
    for (int i = 0; i < 8; i++) {
        vec3 p = v3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
        vec3 q = sh->identity ? p : xform_point(&sh->x, p);
        wl = v3_min(wl, q);
        wh = v3_max(wh, q);
    }
    sh->lo = wl;
    sh->hi = wh;
}

/* Half extents of a disc of radius r with unit axis n, per coordinate. */
static vec3 disc_extent(vec3 n, double r)
{
    return v3(r * sqrt(fmax_inline(0.0, 1.0 - n.x * n.x)), r * sqrt(fmax_inline(0.0, 1.0 - n.y * n.y)),
              r * sqrt(fmax_inline(0.0, 1.0 - n.z * n.z)));
}

static int finite_d(double x) { return isfinite(x); }

static int init_shape(geom_shape *sh, const scene_object *o, int meshes)
{
    memset(sh, 0, sizeof *sh);
    sh->kind = o->kind;
    sh->x = o->transform;
    double det = det3(o->transform.m);
    if (!isfinite(det) || det == 0.0) return -1;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++)
            if (!isfinite(o->transform.m[i][j]) || !isfinite(o->transform.inv[i][j])) return -1;
    sh->identity = xform_is_identity(&o->transform);
    sh->open = (o->flags & OBJ_OPEN) != 0;
    vec3 lo, hi;
    switch (o->kind) {
    case SHAPE_SPHERE: {
        double r = fabs(o->u.sphere.radius);
        vec3 c = o->u.sphere.centre;
        if (!(r > 0.0) || !finite_d(r) || !v3_finite(c)) return -1;
        sh->g.sphere.c = c;
        sh->g.sphere.r = r;
        lo = v3_sub(c, v3s(r));
        hi = v3_add(c, v3s(r));
        break;
    }
    case SHAPE_BOX: {
        vec3 a = o->u.box.c1, b = o->u.box.c2;
        if (!v3_finite(a) || !v3_finite(b)) return -1;
        lo = sh->g.box.lo = v3_min(a, b);
        hi = sh->g.box.hi = v3_max(a, b);
        break;
    }
    case SHAPE_PLANE: {
        vec3 n = o->u.plane.normal;
        double l = v3_len(n);
        if (!(l > 0.0) || !finite_d(l) || !finite_d(o->u.plane.offset)) return -1;
        sh->g.plane.n = v3_scale(n, 1.0 / l);
        sh->g.plane.d = o->u.plane.offset / l;
        /* object q = inv (p) + inv_t: n.q = (M^-T n).p + n.inv_t */
        vec3 on = sh->g.plane.n;
        sh->g.plane.wn = sh->identity ? on : xform_normal(&sh->x, on);
        sh->g.plane.wd = sh->identity ? sh->g.plane.d
                                      : sh->g.plane.d - (on.x * sh->x.inv[0][3] + on.y * sh->x.inv[1][3] +
                                                         on.z * sh->x.inv[2][3]);
        if (!(v3_len2(sh->g.plane.wn) > 0.0) || !v3_finite(sh->g.plane.wn) || !finite_d(sh->g.plane.wd)) return -1;
        /* bounds come from geom_shape_clip_plane */
        sh->lo = v3s(-1.0);
        sh->hi = v3s(1.0);
        return 0;
    }
    case SHAPE_CYLINDER:
    case SHAPE_CONE: {
        vec3 b = o->u.cone.base, c = o->u.cone.cap;
        double r0 = fabs(o->u.cone.base_radius);
        double r1 = fabs(o->u.cone.cap_radius);
        if (o->kind == SHAPE_CYLINDER) { /* the IR gives equal radii; take whichever is set */
            r0 = r0 > 0.0 ? r0 : r1;
            r1 = r0;
        }
        vec3 ax = v3_sub(c, b);
        double h = v3_len(ax);
        if (!v3_finite(b) || !v3_finite(c) || !(h > 0.0) || !finite_d(h) || !finite_d(r0) || !finite_d(r1) ||
            (r0 == 0.0 && r1 == 0.0))
            return -1;
        vec3 w = v3_scale(ax, 1.0 / h), u, v;
        v3_basis(w, &u, &v);
        sh->g.cone.base = b;
        sh->g.cone.u = u;
        sh->g.cone.v = v;
        sh->g.cone.w = w;
        sh->g.cone.h = h;
        sh->g.cone.r0 = r0;
        sh->g.cone.r1 = r1;
        sh->g.cone.k = (r1 - r0) / h;
        vec3 e0 = disc_extent(w, r0), e1 = disc_extent(w, r1);
        lo = v3_min(v3_sub(b, e0), v3_sub(c, e1));
        hi = v3_max(v3_add(b, e0), v3_add(c, e1));
        break;
    }
    case SHAPE_DISC: {
        vec3 c = o->u.disc.centre, n = o->u.disc.normal;
        double l = v3_len(n), r = fabs(o->u.disc.radius), hr = fabs(o->u.disc.hole_radius);
        if (!v3_finite(c) || !(l > 0.0) || !finite_d(l) || !(r > 0.0) || !finite_d(r) || !finite_d(hr))
            return -1;
        n = v3_scale(n, 1.0 / l);
        sh->g.disc.c = c;
        sh->g.disc.n = n;
        sh->g.disc.r2 = r * r;
        sh->g.disc.h2 = hr * hr;
        vec3 e = disc_extent(n, r);
        lo = v3_sub(c, e);
        hi = v3_add(c, e);
        break;
    }
    case SHAPE_TRIANGLE:
    case SHAPE_SMOOTH_TRIANGLE: {
        const vec3 *v = o->u.triangle.v;
        if (!v3_finite(v[0]) || !v3_finite(v[1]) || !v3_finite(v[2])) return -1;
        sh->g.tri.v0 = v[0];
        sh->g.tri.e1 = v3_sub(v[1], v[0]);
        sh->g.tri.e2 = v3_sub(v[2], v[0]);
        if (!(v3_len2(v3_cross(sh->g.tri.e1, sh->g.tri.e2)) > 0.0)) return -1;
        sh->g.tri.smooth = o->kind == SHAPE_SMOOTH_TRIANGLE;
        for (int k = 0; k < 3; k++) sh->g.tri.n[k] = o->u.triangle.n[k];
        sh->g.tri.wind = det < 0.0 ? -1.0 : 1.0;
        lo = v3_min(v[0], v3_min(v[1], v[2]));
        hi = v3_max(v[0], v3_max(v[1], v[2]));
        break;
    }
    case SHAPE_TORUS: {
        double R = fabs(o->u.torus.major), r = fabs(o->u.torus.minor);
        if (!(R > 0.0) || !(r > 0.0) || !finite_d(R) || !finite_d(r)) return -1;
        sh->g.torus.R = R;
        sh->g.torus.r = r;
        lo = v3(-(R + r), -r, -(R + r));
        hi = v3(R + r, r, R + r);
        break;
    }
    case SHAPE_OVUS: {
        /* POV-Ray 3.7's Parse_Ovus: the tube radius is twice the larger
         * radius; its circle is tangent (inside) to both spheres, which fixes
         * v and h: h^2 + v^2 = (rc - rb)^2, h^2 + (v - rb)^2 = (rc - rt)^2;
         * the tangent points are at yb and yt */
        double rb = o->u.ovus.bottom, rt = o->u.ovus.top;
        if (!(rb > 0.0) || !(rt > 0.0) || !(rt < 2.0 * rb) || !finite_d(rb) || !finite_d(rt)) return -1;
        double rc = 2.0 * fmax_inline(rb, rt);
        double v = (rb * rb + (rc - rb) * (rc - rb) - (rc - rt) * (rc - rt)) / (2.0 * rb);
        double h2 = (rc - rb) * (rc - rb) - v * v;
        if (!(h2 > 0.0)) return -1;
        sh->g.ovus.rb = rb;
        sh->g.ovus.rt = rt;
        sh->g.ovus.rc = rc;
        sh->g.ovus.h = sqrt(h2);
        sh->g.ovus.v = v;
        sh->g.ovus.yb = -v * rb / (rc - rb);
        sh->g.ovus.yt = (rc * rb - v * rt) / (rc - rt);
        double wide = fmax_inline(rc - sh->g.ovus.h, fmax_inline(rb, rt));
        lo = v3(-wide, -rb, -wide);
        hi = v3(wide, rb + rt, wide);
        break;
    }
    case SHAPE_POLYGON: case SHAPE_LATHE: case SHAPE_SOR: case SHAPE_PRISM: case SHAPE_TEXT:
        if (geom_sweep_init(sh, o, &lo, &hi) != 0) return -1;
        break;
    case SHAPE_SUPERELLIPSOID: case SHAPE_QUADRIC: case SHAPE_POLY: case SHAPE_BLOB: case SHAPE_ISOSURFACE:
        if (geom_implicit_init(sh, o, &lo, &hi) != 0) return -1;
        if (sh->infinite) {
            /* bounds come from geom_shape_clip_plane, as for planes */
            sh->lo = v3s(-1.0);
            sh->hi = v3s(1.0);
            return 0;
        }
        break;
    case SHAPE_HEIGHT_FIELD:
        if (geom_hfield_init(sh, o, &lo, &hi) != 0) return -1;
        break;
    case SHAPE_JULIA:
        if (geom_fractal_init(sh, o, &lo, &hi) != 0) return -1;
        break;
    case SHAPE_MESH:
        if (!meshes || geom_mesh_init(sh, o) != 0) return -1;
        lo = sh->olo;
        hi = sh->ohi;
        break;
    default:
        return -1;
    }
    sh->olo = lo;
    sh->ohi = hi;
    world_bounds(sh, lo, hi);
    if (!v3_finite(sh->lo) || !v3_finite(sh->hi)) {
        geom_shape_release(sh);
        return -1;
    }
    return 0;
}

int geom_shape_init(geom_shape *sh, const scene_object *o) { return init_shape(sh, o, 0); }

int geom_shape_init_mesh(geom_shape *sh, const scene_object *o) { return init_shape(sh, o, 1); }

void geom_shape_release(geom_shape *sh)
{
    if (!sh || !sh->data) return;
    switch (sh->kind) {
    case SHAPE_POLYGON: case SHAPE_LATHE: case SHAPE_SOR: case SHAPE_PRISM: case SHAPE_TEXT:
        geom_sweep_free(sh->data);
        break;
    case SHAPE_SUPERELLIPSOID: case SHAPE_QUADRIC: case SHAPE_POLY: case SHAPE_BLOB: case SHAPE_ISOSURFACE:
        geom_implicit_free(sh->data);
        break;
    case SHAPE_HEIGHT_FIELD:
        geom_hfield_free(sh->data);
        break;
    case SHAPE_JULIA:
        geom_fractal_free(sh->data);
        break;
    case SHAPE_MESH:
        geom_mesh_free(sh->data);
        break;
    default:
        break;
    }
    sh->data = NULL;
}

int geom_shape_solid_bounded(const geom_shape *sh)
{
    switch (sh->kind) {
    case SHAPE_SPHERE: case SHAPE_BOX: case SHAPE_CYLINDER: case SHAPE_CONE: case SHAPE_TORUS:
    case SHAPE_LATHE: case SHAPE_SOR: case SHAPE_PRISM: case SHAPE_TEXT: case SHAPE_JULIA: case SHAPE_OVUS:
        return 1;
    case SHAPE_SUPERELLIPSOID: case SHAPE_QUADRIC: case SHAPE_POLY: case SHAPE_BLOB: case SHAPE_ISOSURFACE:
        return !sh->infinite && geom_implicit_solid_bounded(sh);
    default:
        return 0;
    }
}

const scene_texture *geom_shape_texture(const geom_shape *sh, vec3 p)
{
    if (sh->kind != SHAPE_BLOB) return NULL;
    return geom_blob_texture(sh, sh->identity ? p : xform_inv_point(&sh->x, p));
}

void geom_shape_clip_plane(geom_shape *sh, vec3 lo, vec3 hi)
{
    sh->clipped = 1;
    sh->clip_lo = lo;
    sh->clip_hi = hi;
    sh->lo = lo;
    sh->hi = hi;
    if (sh->kind != SHAPE_PLANE) return;
    /* An axis-aligned plane touches only a slice of the box. */
    vec3 nw = v3_norm(sh->identity ? sh->g.plane.n : xform_normal(&sh->x, sh->g.plane.n));
    vec3 p0 = v3_scale(sh->g.plane.n, sh->g.plane.d);
    if (!sh->identity) p0 = xform_point(&sh->x, p0);
    double a[3] = {fabs(nw.x), fabs(nw.y), fabs(nw.z)};
    for (int i = 0; i < 3; i++) {
        if (a[i] > 1.0 - 1e-15 && a[(i + 1) % 3] < 1e-15 && a[(i + 2) % 3] < 1e-15) {
            double c = v3_idx(p0, i);
            if (i == 0) sh->lo.x = sh->hi.x = c;
            if (i == 1) sh->lo.y = sh->hi.y = c;
            if (i == 2) sh->lo.z = sh->hi.z = c;
        }
    }
}

/* ------------------------------------------------------------ intersection */

static int in_range(double t, double tmin, double tmax) { return t > tmin && t < tmax; }

/* Each hits_* function writes up to `max` crossings with t in (tmin, tmax),
 * in ascending order, and returns how many. */

static int hits_sphere(const geom_shape *sh, vec3 o, vec3 d, double tmin, double tmax, geom_shape_hit *out, int max)
{
    vec3 oc = v3_sub(o, sh->g.sphere.c);
    double r = sh->g.sphere.r;
    double a = v3_dot(d, d);
    double b = v3_dot(oc, d);
    vec3 l = v3_madd(oc, d, -b / a); /* offset of the closest approach */
    double disc = a * (r * r - v3_dot(l, l));
    if (disc < 0.0) return 0;
    double c = v3_dot(oc, oc) - r * r;
    double q = -(b + copysign(sqrt(disc), b));
    double t0 = q / a, t1 = (q != 0.0) ? c / q : t0;
    if (t0 > t1) { double t = t0; t0 = t1; t1 = t; }
    int n = 0;
    if (in_range(t0, tmin, tmax)) n = geom_shape_hit_put(out, n, max, t0, 0);
    if (in_range(t1, tmin, tmax) && t1 > t0) n = geom_shape_hit_put(out, n, max, t1, 0);
    return n;
}

/* One axis of slabs: the interval [*t0, *t1] and the faces it is
 * bounded by (*f0, *f1) narrowed to slab i, [l, u]; 0 when the ray runs
 * parallel to it outside it. */
static inline int slab_face(int i, double oi, double di, double l, double u, double *t0, int *f0, double *t1, int *f1)
{
    double inv = 1.0 / di;
    if (di == 0.0 || !isfinite(inv)) return !(oi < l || oi > u);
    double ta = (l - oi) * inv, tb = (u - oi) * inv;
    int fa = 2 * i, fb = 2 * i + 1;
    /* a zero-thickness slab (l == u) is entered through the face that
     * opposes the ray, so that the hit reads as entering: POV-Ray reports
     * the other face of such a box (Box::Intersect's Side2 at the same
     * depth, the last pushed and first popped in Find_Intersection) but
     * refracts by the ray's interior list, which a ray from outside
     * always enters (textures/finishes/var_reflection.pov) */
    if (ta > tb || (ta == tb && di < 0.0)) {
        double t = ta; ta = tb; tb = t;
        int f = fa; fa = fb; fb = f;
    }
    if (ta > *t0) { *t0 = ta; *f0 = fa; }
    if (tb < *t1) { *t1 = tb; *f1 = fb; }
    return 1;
}

/* Slab test; entry/exit with the face each happens on (the axes written
 * out: a loop over v3_idx is not unrolled). */
static int slabs(vec3 o, vec3 d, vec3 lo, vec3 hi, double *tn, int *fn, double *tf, int *ff)
{
    double t0 = -INFINITY, t1 = INFINITY;
    int f0 = -1, f1 = -1;
    if (!slab_face(0, o.x, d.x, lo.x, hi.x, &t0, &f0, &t1, &f1) || !slab_face(1, o.y, d.y, lo.y, hi.y, &t0, &f0, &t1, &f1) ||
        !slab_face(2, o.z, d.z, lo.z, hi.z, &t0, &f0, &t1, &f1))
        return 0;
    if (!(t0 <= t1) || f0 < 0) return 0;
    *tn = t0; *fn = f0; *tf = t1; *ff = f1;
    return 1;
}

static int hits_box(const geom_shape *sh, vec3 o, vec3 d, double tmin, double tmax, geom_shape_hit *out, int max)
{
    double t0, t1;
    int f0, f1, n = 0;
    if (!slabs(o, d, sh->g.box.lo, sh->g.box.hi, &t0, &f0, &t1, &f1)) return 0;
    if (in_range(t0, tmin, tmax)) n = geom_shape_hit_put(out, n, max, t0, f0);
    if (in_range(t1, tmin, tmax) && t1 > t0) n = geom_shape_hit_put(out, n, max, t1, f1);
    return n;
}

static int in_box(vec3 p, vec3 lo, vec3 hi)
{
    return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
}

/* In world space (the ray's parameter is the same in object space). */
static int hits_plane(const geom_shape *sh, vec3 worg, vec3 wdir, double tmin, double tmax, geom_shape_hit *out,
                      int max)
{
    double den = v3_dot(sh->g.plane.wn, wdir);
    if (den == 0.0) return 0;
    double t = (sh->g.plane.wd - v3_dot(sh->g.plane.wn, worg)) / den;
    if (!in_range(t, tmin, tmax)) return 0;
    if (sh->clipped && !in_box(v3_madd(worg, wdir, t), sh->clip_lo, sh->clip_hi)) return 0;
    return geom_shape_hit_put(out, 0, max, t, 0);
}

static int hits_cone(const geom_shape *sh, vec3 o, vec3 d, double tmin, double tmax, geom_shape_hit *out, int max)
{
    vec3 rel = v3_sub(o, sh->g.cone.base);
    double ox = v3_dot(rel, sh->g.cone.u), oy = v3_dot(rel, sh->g.cone.v), oz = v3_dot(rel, sh->g.cone.w);
    double dx = v3_dot(d, sh->g.cone.u), dy = v3_dot(d, sh->g.cone.v), dz = v3_dot(d, sh->g.cone.w);
    double H = sh->g.cone.h, k = sh->g.cone.k, r0 = sh->g.cone.r0;
    int n = 0;
    /* side: x^2 + y^2 = (r0 + k z)^2 for z in [0, H] */
    double Ro = r0 + k * oz;
    double a = dx * dx + dy * dy - k * k * dz * dz;
    double b = ox * dx + oy * dy - k * Ro * dz;
    double c = ox * ox + oy * oy - Ro * Ro;
    double ts[2];
    int nq = quad_half(a, b, c, &ts[0], &ts[1]);
    for (int i = 0; i < nq; i++) {
        double t = ts[i];
        if (!in_range(t, tmin, tmax) || (i == 1 && t == ts[0])) continue;
        double z = oz + t * dz;
        if (z < 0.0 || z > H) continue;
        n = geom_shape_hit_put(out, n, max, t, GEOM_PART_CONE_SIDE);
    }
    if (!sh->open && dz != 0.0) {
        for (int e = 0; e < 2; e++) {
            double zc = e ? H : 0.0, rc = e ? sh->g.cone.r1 : r0;
            if (rc <= 0.0) continue;
            double t = (zc - oz) / dz;
            if (!in_range(t, tmin, tmax)) continue;
            double x = ox + t * dx, y = oy + t * dy;
            if (x * x + y * y > rc * rc) continue;
            n = geom_shape_hit_put(out, n, max, t, e ? GEOM_PART_CONE_CAP : GEOM_PART_CONE_BASE);
        }
    }
    return n;
}

static int hits_disc(const geom_shape *sh, vec3 o, vec3 d, double tmin, double tmax, geom_shape_hit *out, int max)
{
    double den = v3_dot(sh->g.disc.n, d);
    if (den == 0.0) return 0;
    double t = v3_dot(sh->g.disc.n, v3_sub(sh->g.disc.c, o)) / den;
    if (!in_range(t, tmin, tmax)) return 0;
    double r2 = v3_len2(v3_sub(v3_madd(o, d, t), sh->g.disc.c));
    if (r2 > sh->g.disc.r2 || r2 < sh->g.disc.h2) return 0;
    return geom_shape_hit_put(out, 0, max, t, 0);
}

/* Double-precision Moller-Trumbore (Moller & Trumbore 1997). */
static int hits_triangle(const geom_shape *sh, vec3 o, vec3 d, double tmin, double tmax, geom_shape_hit *out,
                         int max)
{
    vec3 e1 = sh->g.tri.e1, e2 = sh->g.tri.e2;
    vec3 pv = v3_cross(d, e2);
    double det = v3_dot(e1, pv);
    if (det == 0.0 || !isfinite(det)) return 0;
    double inv = 1.0 / det;
    vec3 tv = v3_sub(o, sh->g.tri.v0);
    double u = v3_dot(tv, pv) * inv;
    if (u < 0.0 || u > 1.0) return 0;
    vec3 qv = v3_cross(tv, e1);
    double v = v3_dot(d, qv) * inv;
    if (v < 0.0 || u + v > 1.0) return 0;
    double t = v3_dot(e2, qv) * inv;
    if (!in_range(t, tmin, tmax)) return 0;
    return geom_shape_hit_put(out, 0, max, t, 0);
}

/* The torus (|p|^2 + R^2 - r^2)^2 = 4 R^2 (x^2 + z^2) along q + tau e (e
 * unit): c[0] + c[1] tau + ... + c[4] tau^4 (the torus and the ovus's
 * lemon, a spindle torus). */
static void torus_quartic(vec3 q, vec3 e, double R, double r, double c[5])
{
    double G = v3_dot(q, q) + R * R - r * r, f = v3_dot(q, e);
    double A = e.x * e.x + e.z * e.z, B = q.x * e.x + q.z * e.z, C = q.x * q.x + q.z * q.z;
    c[4] = 1.0;
    c[3] = 4.0 * f;
    c[2] = 4.0 * f * f + 2.0 * G - 4.0 * R * R * A;
    c[1] = 4.0 * f * G - 8.0 * R * R * B;
    c[0] = G * G - 4.0 * R * R * C;
}

__attribute__((noinline)) static int hits_torus(const geom_shape *sh, vec3 o, vec3 d, double tmin, double tmax, geom_shape_hit *out, int max)
{
    double s = v3_len(d);
    if (!(s > 0.0) || !isfinite(s)) return 0;
    double R = sh->g.torus.R, r = sh->g.torus.r;
    double k = 1.0 / (R + r);
    double sk = s * k;               /* tau = t * sk: distance in unit-torus space */
    vec3 e = v3_scale(d, 1.0 / s);
    vec3 o1 = v3_scale(o, k);
    double R1 = R * k, r1 = r * k;   /* R1 + r1 = 1 */
    double ta = tmin * sk, tb = tmax * sk;
    double b0, b1;
    int f0, f1;
    /* The box is padded so that no root sits exactly on a bracket end (the
     * tube touches the tight box, and a root at sigma = 0 could be lost to
     * rounding in the sign test). */
    const double pad = 0.01;
    if (!slabs(o1, e, v3(-1.0 - pad, -r1 - pad, -1.0 - pad), v3(1.0 + pad, r1 + pad, 1.0 + pad), &b0, &f0, &b1, &f1))
        return 0;
    double lo = fmax_inline(ta, b0), hi = fmin_inline(tb, b1);
    if (!(lo < hi)) return 0;
    vec3 q = v3_madd(o1, e, lo);
    /* The tube lies at distances rho from the axis within [R1 - r1,
     * R1 + r1]: a stretch of the ray (within the padded box, so within
     * the slab around the ring's plane) whose rho stays a quarter of the
     * tube's radius inside that annulus's hole or outside it has no root,
     * and the quartic is not solved (a thin ring's box holds mostly its
     * hole: patio-radio's arches). rho^2 along the stretch is a convex
     * parabola in tau: its largest value at an end, its least at the
     * vertex or an end. */
    {
        double A = e.x * e.x + e.z * e.z, B = q.x * e.x + q.z * e.z, C = q.x * q.x + q.z * q.z, L = hi - lo;
        double at_end = (A * L + 2.0 * B) * L + C, v = A > 0.0 ? -B / A : 0.0;
        v = v < 0.0 ? 0.0 : (v > L ? L : v);
        double most = fmax_inline(C, at_end), least = (A * v + 2.0 * B) * v + C;
        double m = 0.25 * r1 + 1e-9, inner = R1 - r1 - m, outer = R1 + r1 + m;
        if ((inner > 0.0 && most < inner * inner) || least > outer * outer) return 0;
    }
    double c[5];
    torus_quartic(q, e, R1, r1, c);
    double roots[4];
    int nr = geom_poly_roots(c, 4, 0.0, hi - lo, roots), n = 0;
    for (int i = 0; i < nr && n < max; i++) {
        double tau = lo + roots[i];
        if (!(tau > ta && tau < tb)) continue;
        double t = tau / sk;
        if (in_range(t, tmin, tmax)) n = geom_shape_hit_put(out, n, max, t, 0);
    }
    return n;
}

/* Ovus: the ray in units of the ovus' height (rb + rt), moved to its
 * padded box; each sphere's roots where that sphere is the surface, the
 * spindle torus' quartic (the torus equation with major radius h, tube rc,
 * centred at y = v) where the lemon is, on the lemon's branch. */
__attribute__((noinline)) static int hits_ovus(const geom_shape *sh, vec3 o, vec3 d, double tmin, double tmax, geom_shape_hit *out, int max)
{
    double s = v3_len(d);
    if (!(s > 0.0) || !isfinite(s)) return 0;
    double k = 1.0 / (sh->g.ovus.rb + sh->g.ovus.rt), sk = s * k;
    double rb = sh->g.ovus.rb * k, rt = sh->g.ovus.rt * k, rc = sh->g.ovus.rc * k, H = sh->g.ovus.h * k;
    double V = sh->g.ovus.v * k, yb = sh->g.ovus.yb * k, yt = sh->g.ovus.yt * k;
    vec3 e = v3_scale(d, 1.0 / s), o1 = v3_scale(o, k);
    double wide = fmax_inline(rc - H, fmax_inline(rb, rt)) + 0.01;
    double b0, b1;
    int f0, f1;
    if (!slabs(o1, e, v3(-wide, -rb - 0.01, -wide), v3(wide, 1.01, wide), &b0, &f0, &b1, &f1)) return 0;
    double ta = tmin * sk, tb = tmax * sk;
    double lo = fmax_inline(ta, b0), hi = fmin_inline(tb, b1);
    if (!(lo < hi)) return 0;
    vec3 q = v3_madd(o1, e, lo);
    double cand[8];
    int part[8], nc = 0;
    /* spheres (unit direction: a = 1) */
    for (int sp = 0; sp < 2; sp++) {
        vec3 c = v3(0.0, sp ? rb : 0.0, 0.0);
        double r = sp ? rt : rb;
        vec3 oc = v3_sub(q, c);
        double b = v3_dot(oc, e);
        vec3 l = v3_madd(oc, e, -b);
        double disc = r * r - v3_dot(l, l);
        if (disc < 0.0) continue;
        double cc = v3_dot(oc, oc) - r * r, qq = -(b + copysign(sqrt(disc), b));
        double r0 = qq, r1 = qq != 0.0 ? cc / qq : qq;
        double rr[2] = {r0, r1};
        for (int i = 0; i < 2; i++) {
            double y = q.y + e.y * rr[i];
            if (sp ? y > yt : y < yb) {
                cand[nc] = rr[i];
                part[nc++] = sp ? GEOM_PART_OVUS_TOP : GEOM_PART_OVUS_BOTTOM;
            }
        }
    }
    /* lemon: ((x^2+z^2) + (y-V)^2 + H^2 - rc^2)^2 = 4 H^2 (x^2+z^2) */
    vec3 qt = v3(q.x, q.y - V, q.z);
    double c[5];
    torus_quartic(qt, e, H, rc, c);
    double roots[4];
    int nr = geom_poly_roots(c, 4, 0.0, hi - lo, roots);
    for (int i = 0; i < nr; i++) {
        vec3 p = v3_madd(q, e, roots[i]);
        if (!(p.y > yb && p.y < yt)) continue;
        double hh = sqrt(p.x * p.x + p.z * p.z), dy = p.y - V;
        double inner = (hh + H) * (hh + H) + dy * dy - rc * rc, outer = (hh - H) * (hh - H) + dy * dy - rc * rc;
        if (fabs(inner) <= fabs(outer)) {
            cand[nc] = roots[i];
            part[nc++] = GEOM_PART_OVUS_LEMON;
        }
    }
    int n = 0;
    for (int i = 0; i < nc; i++) {
        double tau = lo + cand[i];
        if (!(tau > ta && tau < tb)) continue;
        double t = tau / sk;
        if (in_range(t, tmin, tmax)) n = geom_shape_hit_put(out, n, max, t, part[i]);
    }
    return n;
}

/* The shapes searched within their bounds (shape_hits' other kinds; o, d:
 * the ray in object space, org, dir: in world space). Apart from
 * shape_hits, as are the torus and ovus solves: their scratch would
 * otherwise make every sphere's or box's test set up their stack frame. */
__attribute__((noinline)) static int hits_bounded(const geom_shape *sh, vec3 org, vec3 dir, vec3 o, vec3 d, double tmin,
                                                  double tmax, geom_shape_hit *out, int max, int traced,
                                                  geom_ray_rule rule)
{
    /* the other shapes: the interval narrowed to the clip box (unbounded
     * shapes: hits outside it are rejected, as for planes) or to the
     * object-space bounds, padded */
    double a = tmin, b = tmax, t0, t1;
    if (sh->infinite) {
        if (!sh->clipped || !v3_slab(org, dir, sh->clip_lo, sh->clip_hi, &t0, &t1)) return 0;
    } else {
        vec3 pad = v3s(1e-7 * v3_maxc(v3_sub(sh->ohi, sh->olo)) + 1e-300);
        if (!v3_slab(o, d, v3_sub(sh->olo, pad), v3_add(sh->ohi, pad), &t0, &t1)) return 0;
    }
    if (t0 > a) a = t0;
    if (t1 < b) b = t1;
    if (!(a < b)) return 0;
    int n;
    switch (sh->kind) {
    case SHAPE_POLYGON: case SHAPE_LATHE: case SHAPE_SOR: case SHAPE_PRISM: case SHAPE_TEXT:
        n = geom_sweep_hits(sh, o, d, a, b, out, max);
        break;
    case SHAPE_SUPERELLIPSOID: case SHAPE_QUADRIC: case SHAPE_POLY: case SHAPE_BLOB: case SHAPE_ISOSURFACE:
        n = geom_implicit_hits(sh, o, d, v3_len(dir), a, b, out, max, traced, rule);
        break;
    case SHAPE_HEIGHT_FIELD:
        n = geom_hfield_hits(sh, o, d, a, b, out, max);
        break;
    case SHAPE_JULIA:
        n = geom_fractal_hits(sh, o, d, a, b, out, max);
        break;
    case SHAPE_MESH:
        n = geom_mesh_hits(sh, o, d, a, b, out, max);
        break;
    default:
        return 0;
    }
    /* keep the caller's open interval exactly */
    int k = 0;
    for (int i = 0; i < n; i++)
        if (out[i].t > tmin && out[i].t < tmax && isfinite(out[i].t)) out[k++] = out[i];
    return k;
}

/* Parameter interval of a ray inside a box. */
static int shape_hits(const geom_shape *sh, vec3 org, vec3 dir, double tmin, double tmax, geom_shape_hit *out,
                      int max, int traced, geom_ray_rule rule)
{
    if (max <= 0) return 0;
    if (sh->kind == SHAPE_PLANE) return v3_len2(dir) == 0.0 ? 0 : hits_plane(sh, org, dir, tmin, tmax, out, max);
    vec3 o = org, d = dir;
    if (!sh->identity) {
        o = xform_inv_point(&sh->x, org);
        d = xform_inv_vector(&sh->x, dir);
    }
    if (v3_len2(d) == 0.0) return 0;
    switch (sh->kind) {
    case SHAPE_SPHERE: return hits_sphere(sh, o, d, tmin, tmax, out, max);
    case SHAPE_BOX: return hits_box(sh, o, d, tmin, tmax, out, max);
    case SHAPE_CYLINDER:
    case SHAPE_CONE: return hits_cone(sh, o, d, tmin, tmax, out, max);
    case SHAPE_DISC: return hits_disc(sh, o, d, tmin, tmax, out, max);
    case SHAPE_TORUS: return hits_torus(sh, o, d, tmin, tmax, out, max);
    case SHAPE_OVUS: return hits_ovus(sh, o, d, tmin, tmax, out, max);
    case SHAPE_TRIANGLE:
    case SHAPE_SMOOTH_TRIANGLE: return hits_triangle(sh, o, d, tmin, tmax, out, max);
    default: return hits_bounded(sh, org, dir, o, d, tmin, tmax, out, max, traced, rule);
    }
}

int geom_shape_hits(const geom_shape *sh, vec3 org, vec3 dir, double tmin, double tmax, geom_shape_hit *out,
                     int max)
{
    return shape_hits(sh, org, dir, tmin, tmax, out, max, 0, GEOM_RAY_EXACT);
}

int geom_shape_ray_hits(const geom_shape *sh, vec3 org, vec3 dir, double tmin, double tmax, geom_shape_hit *out,
                         int max, geom_ray_rule rule)
{
    return shape_hits(sh, org, dir, tmin, tmax, out, max, 1, rule);
}

typedef struct {
    geom_grid_fn fn;
    void *ctx;
    const geom_shape *sh;
} grid_poly;

static int grid_poly_tri(void *ctx, vec3 a, vec3 b, vec3 c)
{
    grid_poly *g = ctx;
    vec3 p[3] = {a, b, c}, nn;
    double u, v;
    geom_sweep_surface(g->sh, a, 2, &nn, &u, &v);
    vec3 n[3] = {nn, nn, nn};
    return g->fn(g->ctx, p, n);
}

int geom_shape_grid(const geom_shape *sh, int n, geom_grid_fn fn, void *ctx)
{
    if (sh->kind == SHAPE_OVUS) return geom_tess_grid(sh, n, fn, ctx);
    if (!sh->data || n < 1) return 0;
    switch (sh->kind) {
    case SHAPE_LATHE: case SHAPE_SOR: case SHAPE_PRISM: case SHAPE_TEXT:
        return geom_sweep_grid(sh, n, fn, ctx);
    case SHAPE_POLYGON: {
        grid_poly g = {fn, ctx, sh};
        return geom_polygon_triangles(sh, grid_poly_tri, &g);
    }
    case SHAPE_SUPERELLIPSOID:
        return geom_implicit_grid(sh, n, fn, ctx);
    case SHAPE_QUADRIC: case SHAPE_POLY: case SHAPE_BLOB: case SHAPE_ISOSURFACE: case SHAPE_JULIA: case SHAPE_OVUS:
        /* no parametrisation of their own: marching tetrahedra (geom_tess.h) */
        return geom_tess_grid(sh, n, fn, ctx);
    case SHAPE_HEIGHT_FIELD: {
        int nt = geom_hfield_ntriangles(sh), count = 0;
        for (int i = 0; i < nt; i++) {
            vec3 p[3], nn[3], g;
            double u, v;
            geom_hfield_triangle(sh, i, &p[0], &p[1], &p[2]);
            geom_hfield_surface(sh, p[0], i, &g, &u, &v);
            for (int k = 0; k < 3; k++) {
                vec3 s = geom_hfield_shading(sh, p[k]);
                nn[k] = v3_len2(s) > 0.0 ? s : g;
            }
            if (!fn(ctx, p, nn)) return -1;
            count++;
        }
        return count;
    }
    default:
        return 0;
    }
}

int geom_shape_intersect(const geom_shape *sh, vec3 org, vec3 dir, double tmin, double tmax, geom_shape_hit *h,
                          geom_ray_rule rule)
{
    return geom_shape_ray_hits(sh, org, dir, tmin, tmax, h, 1, rule);
}

int geom_shape_inside(const geom_shape *sh, vec3 p)
{
    if (sh->kind == SHAPE_PLANE) return v3_dot(sh->g.plane.wn, p) < sh->g.plane.wd;
    vec3 q = sh->identity ? p : xform_inv_point(&sh->x, p);
    switch (sh->kind) {
    case SHAPE_SPHERE:
        return v3_len2(v3_sub(q, sh->g.sphere.c)) < sh->g.sphere.r * sh->g.sphere.r;
    case SHAPE_BOX:
        return q.x > sh->g.box.lo.x && q.x < sh->g.box.hi.x && q.y > sh->g.box.lo.y && q.y < sh->g.box.hi.y &&
               q.z > sh->g.box.lo.z && q.z < sh->g.box.hi.z;
    case SHAPE_CYLINDER:
    case SHAPE_CONE: {
        /* the closed solid, also for `open` ones, less a skin of 1e-10 of
         * its size (POV-Ray's cone.cpp Inside: EPSILON in the unit
         * cylinder's space): a point on the surface is outside, so where
         * a merge's members share a surface (shapes.inc's
         * Round_Cylinder_Merge inside a cylinder of its radius) each
         * member's crossing there is kept, not dropped by rounding */
        const double skin = 1e-10;
        vec3 rel = v3_sub(q, sh->g.cone.base);
        double x = v3_dot(rel, sh->g.cone.u), y = v3_dot(rel, sh->g.cone.v), z = v3_dot(rel, sh->g.cone.w);
        if (!(z > skin * sh->g.cone.h && z < (1.0 - skin) * sh->g.cone.h)) return 0;
        double rz = sh->g.cone.r0 + sh->g.cone.k * z;
        return x * x + y * y < (1.0 - skin) * rz * rz;
    }
    case SHAPE_DISC:
        /* POV-Ray: the half-space behind the disc (against its normal) */
        return v3_dot(sh->g.disc.n, v3_sub(q, sh->g.disc.c)) < 0.0;
    case SHAPE_TORUS: {
        double rho = sqrt(q.x * q.x + q.z * q.z) - sh->g.torus.R;
        return rho * rho + q.y * q.y < sh->g.torus.r * sh->g.torus.r;
    }
    case SHAPE_OVUS: {
        /* POV-Ray's Inside: either sphere, or the lemon between yb and yt */
        double rb = sh->g.ovus.rb, rt = sh->g.ovus.rt;
        if (v3_len2(q) < rb * rb) return 1;
        vec3 qt = v3(q.x, q.y - rb, q.z);
        if (v3_len2(qt) < rt * rt) return 1;
        if (!(q.y > sh->g.ovus.yb && q.y < sh->g.ovus.yt)) return 0;
        double hh = sqrt(q.x * q.x + q.z * q.z) + sh->g.ovus.h, dy = q.y - sh->g.ovus.v;
        return hh * hh + dy * dy < sh->g.ovus.rc * sh->g.ovus.rc;
    }
    case SHAPE_LATHE: case SHAPE_SOR: case SHAPE_PRISM: case SHAPE_TEXT:
        return geom_sweep_inside(sh, q);
    case SHAPE_SUPERELLIPSOID: case SHAPE_QUADRIC: case SHAPE_POLY: case SHAPE_BLOB: case SHAPE_ISOSURFACE:
        return geom_implicit_inside(sh, q);
    case SHAPE_HEIGHT_FIELD:
        return geom_hfield_inside(sh, q);
    case SHAPE_JULIA:
        return geom_fractal_inside(sh, q);
    case SHAPE_MESH:
        return geom_mesh_inside(sh, q);
    default:
        return 0; /* triangles and polygons have no inside */
    }
}

/* ------------------------------------------------------------ surface data */

static double wrap01(double a)
{
    double u = a / TWO_PI;
    if (u < 0.0) u += 1.0;
    return (u >= 1.0 || !isfinite(u)) ? 0.0 : u;
}

static double clamp01(double x) { return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : (isfinite(x) ? x : 0.0)); }

/* Barycentrics (weights of v1 and v2) of an object-space point in the triangle's plane. */
static void tri_bary(const geom_shape *sh, vec3 po, double *u, double *v)
{
    vec3 e1 = sh->g.tri.e1, e2 = sh->g.tri.e2, w = v3_sub(po, sh->g.tri.v0);
    double d11 = v3_dot(e1, e1), d12 = v3_dot(e1, e2), d22 = v3_dot(e2, e2);
    double w1 = v3_dot(w, e1), w2 = v3_dot(w, e2);
    double den = d11 * d22 - d12 * d12;
    *u = den != 0.0 ? clamp01((d22 * w1 - d12 * w2) / den) : 0.0;
    *v = den != 0.0 ? clamp01((d11 * w2 - d12 * w1) / den) : 0.0;
}

/* A smooth triangle's interpolated world normal at p, unit, as given (not
 * oriented); 0 where it vanishes. */
static int smooth_normal(const geom_shape *sh, vec3 p, vec3 *out)
{
    double u, v;
    tri_bary(sh, sh->identity ? p : xform_inv_point(&sh->x, p), &u, &v);
    vec3 n = v3_add(v3_add(v3_scale(sh->g.tri.n[0], 1.0 - u - v), v3_scale(sh->g.tri.n[1], u)),
                    v3_scale(sh->g.tri.n[2], v));
    if (!sh->identity) n = xform_normal(&sh->x, n);
    double l = v3_len(n);
    if (!(l > 0.0) || !isfinite(l)) return 0;
    *out = v3_scale(n, 1.0 / l);
    return 1;
}

void geom_shape_shading(const geom_shape *sh, vec3 p, vec3 ng, vec3 *ns)
{
    *ns = ng;
    if (sh->kind == SHAPE_HEIGHT_FIELD) {
        vec3 n = geom_hfield_shading(sh, sh->identity ? p : xform_inv_point(&sh->x, p));
        if (!(v3_len2(n) > 0.0)) return;
        if (!sh->identity) n = xform_normal(&sh->x, n);
        double l = v3_len(n);
        if (!(l > 0.0) || !isfinite(l)) return;
        n = v3_scale(n, 1.0 / l);
        *ns = v3_dot(n, ng) < 0.0 ? v3_neg(n) : n;
        return;
    }
    if ((sh->kind != SHAPE_SMOOTH_TRIANGLE) || !sh->g.tri.smooth) return;
    vec3 n;
    if (!smooth_normal(sh, p, &n)) return;
    *ns = v3_dot(n, ng) < 0.0 ? v3_neg(n) : n;
}

vec3 geom_shape_pov_normal(const geom_shape *sh, vec3 p, int part)
{
    vec3 ng, ns;
    geom_shape_surface(sh, p, part, &ng, NULL, NULL);
    if (sh->kind == SHAPE_TRIANGLE || sh->kind == SHAPE_SMOOTH_TRIANGLE) {
        /* POV-Ray's (P1 - P2) x (P3 - P2) is against the winding normal
         * (accel.c's pov_flip) */
        if (sh->g.tri.smooth) {
            /* POV-Ray interpolates its unit vertex normals (each placed by
             * the transform and normalised) */
            double u1, u2;
            tri_bary(sh, sh->identity ? p : xform_inv_point(&sh->x, p), &u1, &u2);
            double w[3] = {1.0 - u1 - u2, u1, u2};
            vec3 n = v3(0, 0, 0);
            for (int k = 0; k < 3; k++) {
                vec3 nk = sh->identity ? sh->g.tri.n[k] : xform_normal(&sh->x, sh->g.tri.n[k]);
                double l = v3_len(nk);
                if (l > 0.0 && isfinite(l)) n = v3_madd(n, nk, w[k] / l);
            }
            double l = v3_len(n);
            if (l > 0.0 && isfinite(l)) return v3_scale(n, 1.0 / l);
        }
        return sh->g.tri.wind > 0.0 ? v3_neg(ng) : ng;
    }
    geom_shape_shading(sh, p, ng, &ns);
    return ns;
}

void geom_shape_surface(const geom_shape *sh, vec3 p, int part, vec3 *ng, double *u, double *v)
{
    int uv = u && v;
    /* the point in the shape's frame; a box's, plane's, disc's or
     * triangle's normal does not depend on it (a box's is its face's), only
     * their (u, v) */
    int flat = sh->kind == SHAPE_BOX || sh->kind == SHAPE_PLANE || sh->kind == SHAPE_DISC ||
               sh->kind == SHAPE_TRIANGLE || sh->kind == SHAPE_SMOOTH_TRIANGLE;
    vec3 po = sh->identity || (flat && !uv) ? p : xform_inv_point(&sh->x, p);
    vec3 n = v3(0, 1, 0);
    double su = 0.0, sv = 0.0;
    switch (sh->kind) {
    case SHAPE_SPHERE: {
        n = v3_sub(po, sh->g.sphere.c);
        if (uv) {
            vec3 un = v3_norm(n);
            su = wrap01(atan2(un.z, un.x));
            sv = clamp01(1.0 - acos(fmax_inline(-1.0, fmin_inline(1.0, un.y))) / (TWO_PI * 0.5));
        }
        break;
    }
    case SHAPE_BOX: {
        int axis = part / 2;
        double s = (part & 1) ? 1.0 : -1.0;
        n = v3(axis == 0 ? s : 0.0, axis == 1 ? s : 0.0, axis == 2 ? s : 0.0);
        if (uv) {
            vec3 ext = v3_sub(sh->g.box.hi, sh->g.box.lo);
            vec3 f = v3_sub(po, sh->g.box.lo);
            double fx = ext.x > 0 ? f.x / ext.x : 0, fy = ext.y > 0 ? f.y / ext.y : 0, fz = ext.z > 0 ? f.z / ext.z : 0;
            su = clamp01(axis == 0 ? fz : fx);
            sv = clamp01(axis == 1 ? fz : fy);
        }
        break;
    }
    case SHAPE_PLANE:
        n = sh->g.plane.n;
        break;
    case SHAPE_CYLINDER:
    case SHAPE_CONE: {
        vec3 rel = v3_sub(po, sh->g.cone.base);
        double x = v3_dot(rel, sh->g.cone.u), y = v3_dot(rel, sh->g.cone.v), z = v3_dot(rel, sh->g.cone.w);
        if (uv) su = wrap01(atan2(y, x));
        if (part == GEOM_PART_CONE_BASE) {
            n = v3_neg(sh->g.cone.w);
            if (uv) sv = sh->g.cone.r0 > 0 ? clamp01(sqrt(x * x + y * y) / sh->g.cone.r0) : 0.0;
        } else if (part == GEOM_PART_CONE_CAP) {
            n = sh->g.cone.w;
            if (uv) sv = sh->g.cone.r1 > 0 ? clamp01(sqrt(x * x + y * y) / sh->g.cone.r1) : 0.0;
        } else {
            double k = sh->g.cone.k, rz = sh->g.cone.r0 + k * z;
            n = v3_add(v3_add(v3_scale(sh->g.cone.u, x), v3_scale(sh->g.cone.v, y)), v3_scale(sh->g.cone.w, -k * rz));
            if (!(v3_len2(n) > 0.0)) n = v3_scale(sh->g.cone.w, k <= 0.0 ? 1.0 : -1.0); /* apex */
            sv = clamp01(z / sh->g.cone.h);
        }
        break;
    }
    case SHAPE_DISC: {
        n = sh->g.disc.n;
        if (uv) {
            vec3 t, b, rel = v3_sub(po, sh->g.disc.c);
            v3_basis(n, &t, &b);
            su = wrap01(atan2(v3_dot(rel, b), v3_dot(rel, t)));
            sv = clamp01(sqrt(v3_len2(rel) / sh->g.disc.r2));
        }
        break;
    }
    case SHAPE_TORUS: {
        double R = sh->g.torus.R;
        double rho = sqrt(po.x * po.x + po.z * po.z);
        if (rho > 0.0) {
            vec3 core = v3(po.x * R / rho, 0.0, po.z * R / rho);
            n = v3_sub(po, core);
        } else {
            n = v3(0.0, po.y >= 0.0 ? 1.0 : -1.0, 0.0);
        }
        if (uv) {
            su = wrap01(atan2(po.z, po.x));
            sv = wrap01(atan2(po.y, rho - R));
        }
        break;
    }
    case SHAPE_TRIANGLE:
    case SHAPE_SMOOTH_TRIANGLE:
        n = v3_scale(v3_cross(sh->g.tri.e1, sh->g.tri.e2), sh->g.tri.wind);
        if (uv) tri_bary(sh, po, &su, &sv);
        break;
    case SHAPE_OVUS: {
        if (part == GEOM_PART_OVUS_BOTTOM) {
            n = po;
        } else if (part == GEOM_PART_OVUS_TOP) {
            n = v3(po.x, po.y - sh->g.ovus.rb, po.z);
        } else {
            /* away from the generating circle's centre on the far side of the axis */
            double hh = sqrt(po.x * po.x + po.z * po.z);
            double f = hh > 0.0 ? 1.0 + sh->g.ovus.h / hh : 1.0;
            n = hh > 0.0 ? v3(po.x * f, po.y - sh->g.ovus.v, po.z * f) : v3(0.0, po.y > sh->g.ovus.v ? 1.0 : -1.0, 0.0);
        }
        if (uv) {
            su = wrap01(atan2(po.z, po.x));
            sv = clamp01((po.y + sh->g.ovus.rb) / (sh->g.ovus.rb + sh->g.ovus.rt));
        }
        break;
    }
    case SHAPE_POLYGON: case SHAPE_LATHE: case SHAPE_SOR: case SHAPE_PRISM: case SHAPE_TEXT:
        geom_sweep_surface(sh, po, part, &n, &su, &sv);
        break;
    case SHAPE_SUPERELLIPSOID: case SHAPE_QUADRIC: case SHAPE_POLY: case SHAPE_BLOB: case SHAPE_ISOSURFACE:
        n = geom_implicit_normal(sh, po, part);
        break;
    case SHAPE_HEIGHT_FIELD:
        geom_hfield_surface(sh, po, part, &n, &su, &sv);
        break;
    case SHAPE_JULIA:
        n = geom_fractal_normal(sh, po);
        break;
    case SHAPE_MESH:
        n = geom_mesh_normal(sh, po, part);
        break;
    default:
        break;
    }
    vec3 nw = sh->identity ? n : xform_normal(&sh->x, n);
    double l = v3_len(nw);
    if (l > 0.0 && isfinite(l)) nw = v3_scale(nw, 1.0 / l);
    else nw = v3(0.0, 1.0, 0.0);
    *ng = nw;
    if (uv) {
        *u = su;
        *v = sv;
    }
}

/* POV-Ray 3.7's angle of (x, z) from +x around y over 2 pi, 0..1, and 0 at
 * the poles (Sphere::UVCoord, Lathe::UVCoord, Ovus::CalcUV). */
static double pov_theta(double x, double z)
{
    double len = x * x + z * z;
    if (!(len > 1.0e-10)) return 0.0;
    len = sqrt(len);
    double th;
    if (z == 0.0) th = x > 0.0 ? 0.0 : M_PI;
    else {
        th = acos(fmax_inline(-1.0, fmin_inline(1.0, x / len)));
        if (z < 0.0) th = TWO_PI - th;
    }
    return th / TWO_PI;
}

/* Sphere-like uv of a direction d (Sphere::UVCoord): u = pov_theta, v from
 * the south pole (0) to the north pole (1). Returns 0 for d = 0 (POV-Ray
 * then leaves the uv as it was; we give <0, 0>). */
static int pov_sphere_uv(vec3 d, double uv[2])
{
    double len = v3_len(d);
    if (!(len > 0.0) || !isfinite(len)) return 0;
    d = v3_scale(d, 1.0 / len);
    uv[1] = 0.5 + asin(fmax_inline(-1.0, fmin_inline(1.0, d.y))) / M_PI;
    uv[0] = pov_theta(d.x, d.z);
    return 1;
}

void geom_shape_uv(const geom_shape *sh, vec3 p, int part, double uv[2])
{
    /* ObjectBase::UVCoord, for every shape without its own: world x and y */
    uv[0] = p.x;
    uv[1] = p.y;
    vec3 po = sh->identity ? p : xform_inv_point(&sh->x, p);
    switch (sh->kind) {
    case SHAPE_SPHERE:
        if (!pov_sphere_uv(v3_sub(po, sh->g.sphere.c), uv)) uv[0] = uv[1] = 0.0;
        break;
    case SHAPE_BOX: {
        /* Box::UVCoord: the cube net of boxes.cpp's comment, faces at
         * u in quarters and v in thirds, the box normalised to <0,0,0>..<1,1,1> */
        vec3 ext = v3_sub(sh->g.box.hi, sh->g.box.lo), f = v3_sub(po, sh->g.box.lo);
        double x = ext.x != 0.0 ? f.x / ext.x : 0.0, y = ext.y != 0.0 ? f.y / ext.y : 0.0,
               z = ext.z != 0.0 ? f.z / ext.z : 0.0;
        switch (part) {
        case GEOM_PART_BOX_NX: uv[0] = z / 4.0; uv[1] = (1.0 + y) / 3.0; break;
        case GEOM_PART_BOX_PX: uv[0] = 0.75 - z / 4.0; uv[1] = (1.0 + y) / 3.0; break;
        case GEOM_PART_BOX_NY: uv[0] = 0.25 + x / 4.0; uv[1] = z / 3.0; break;
        case GEOM_PART_BOX_PY: uv[0] = 0.25 + x / 4.0; uv[1] = 1.0 - z / 3.0; break;
        case GEOM_PART_BOX_NZ: uv[0] = 1.0 - x / 4.0; uv[1] = (1.0 + y) / 3.0; break;
        default: uv[0] = 0.25 + x / 4.0; uv[1] = (1.0 + y) / 3.0; break;
        }
        break;
    }
    case SHAPE_TORUS: {
        /* Torus::CalcUV: u = 1 - (atan2(z, x) + pi) / 2pi, v = (atan2(y, rho - R) + pi) / 2pi */
        double rho = sqrt(po.x * po.x + po.z * po.z);
        uv[0] = 1.0 - (atan2(po.z, po.x) + M_PI) / TWO_PI;
        uv[1] = (atan2(po.y, rho - sh->g.torus.R) + M_PI) / TWO_PI;
        break;
    }
    case SHAPE_OVUS:
        /* Ovus::CalcUV: a sphere's uv about <0, top radius / 2, 0> */
        if (!pov_sphere_uv(v3(po.x, po.y - sh->g.ovus.rt / 2.0, po.z), uv)) uv[0] = uv[1] = 0.0;
        break;
    case SHAPE_LATHE: case SHAPE_SOR:
        geom_sweep_uv(sh, po, part, uv);
        break;
    default:
        break;
    }
    if (!isfinite(uv[0]) || !isfinite(uv[1])) uv[0] = uv[1] = 0.0;
}
