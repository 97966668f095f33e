/* geom_extent.c - POV-Ray 3.7's bounding boxes (see geom_extent.h). */
#include "geom_extent.h"
#include "scene_leaves.h"
#include <math.h>
#include <stdlib.h>
#include "geom_sweep.h"

#define BOUND_HUGE 2.0e10     /* POV-Ray 3.7's unbounded box is +-BOUND_HUGE/2 */
#define CRITICAL_LENGTH 1.0e6 /* a CSG box longer than this becomes unbounded */
#define SMALL_TOLERANCE 0.001 /* the disc's box thickness */

typedef struct {
    vec3 lo, hi;
} bbox;

typedef struct {
    const char *unsupported; /* first shape without a box */
} extent_ctx;

static vec3 mesh_vert(const scene_mesh *m, int i) { return v3(m->verts[i][0], m->verts[i][1], m->verts[i][2]); }

static bbox leaf_box_local(const scene_object *o, vec3 *lo, vec3 *hi);

static bbox box_of(vec3 lo, vec3 hi)
{
    bbox b = {lo, hi};
    return b;
}

static bbox huge_box(void) { return box_of(v3s(-BOUND_HUGE / 2), v3s(BOUND_HUGE / 2)); }

/* The box [lo, hi] of some space mapped by x, corner by corner. */
static bbox transformed_box(const xform *x, vec3 lo, vec3 hi)
{
    vec3 a = v3s(INFINITY), b = v3s(-INFINITY);
    for (int c = 0; c < 8; c++) {
        vec3 p = v3(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
        vec3 q = xform_point(x, p);
        a = v3_min(a, q);
        b = v3_max(b, q);
    }
    return box_of(a, b);
}

/* POV-Ray's frame for cylinders, cones and discs: scale (r, r, len), rotate
 * z onto the axis about z x axis, move to the origin. */
static xform axis_frame(vec3 origin, vec3 up, double radius, double length)
{
    xform x = xform_scale(v3(radius, radius, length));
    vec3 k;
    double angle;
    if (fabs(up.z) > 1.0 - 1e-10) {
        k = v3(1, 0, 0);
        angle = up.z < 0 ? M_PI : 0;
    } else {
        k = v3_norm(v3(-up.y, up.x, 0));
        angle = acos(up.z);
    }
    double c = cos(angle), s = sin(angle), m[12];
    /* rotation about unit k by angle taking z to up (Rodrigues), row-vector layout */
    double r[3][3];
    double kk[3] = {k.x, k.y, k.z};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) r[i][j] = (i == j ? c : 0) + (1 - c) * kk[i] * kk[j];
    r[0][1] -= s * kk[2]; r[0][2] += s * kk[1];
    r[1][0] += s * kk[2]; r[1][2] -= s * kk[0];
    r[2][0] -= s * kk[1]; r[2][1] += s * kk[0];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) m[i * 3 + j] = r[j][i]; /* p' = p * M: rows are the images of the axes */
    m[9] = m[10] = m[11] = 0;
    x = xform_then(x, xform_matrix(m));
    return xform_then(x, xform_translate(origin));
}

/* A transform whose linear part is a rotation times a uniform scale? */
static int is_similarity(const xform *x, double *scale)
{
    vec3 c[3];
    for (int j = 0; j < 3; j++) c[j] = v3(x->m[0][j], x->m[1][j], x->m[2][j]);
    double s = v3_len(c[0]);
    for (int j = 0; j < 3; j++)
        if (fabs(v3_len(c[j]) - s) > 1e-12 * (1 + s)) return 0;
    if (fabs(v3_dot(c[0], c[1])) > 1e-12 * (1 + s * s) || fabs(v3_dot(c[0], c[2])) > 1e-12 * (1 + s * s) ||
        fabs(v3_dot(c[1], c[2])) > 1e-12 * (1 + s * s))
        return 0;
    *scale = s;
    return 1;
}

static bbox cone_box(const scene_object *o)
{
    vec3 base = o->u.cone.base, cap = o->u.cone.cap, ax = v3_sub(cap, base);
    double len = v3_len(ax), rb = o->u.cone.base_radius, rc = o->u.cone.cap_radius, dist = 0;
    vec3 w = len > 0 ? v3_scale(ax, 1.0 / len) : v3(0, 1, 0);
    xform frame;
    if (fabs(rc - rb) < 1e-10 || len <= 0) {
        frame = axis_frame(base, w, rc, len);
    } else {
        if (rc < rb) { /* bigger end on top, as POV-Ray orders it */
            vec3 t = base;
            base = cap;
            cap = t;
            double r = rb;
            rb = rc;
            rc = r;
            w = v3_neg(w);
        }
        double lead = rb * len / (rc - rb), total = lead + len;
        dist = lead / total;
        frame = axis_frame(v3_madd(base, w, -lead), w, rc, total);
    }
    xform full = xform_then(frame, o->transform);
    return transformed_box(&full, v3(-1, -1, dist), v3(1, 1, 1));
}

static bbox points_box(const xform *x, const vec3 *pts, int n)
{
    vec3 lo = v3s(INFINITY), hi = v3s(-INFINITY);
    for (int i = 0; i < n; i++) {
        lo = v3_min(lo, pts[i]);
        hi = v3_max(hi, pts[i]);
    }
    if (n == 0) lo = hi = v3s(0);
    return transformed_box(x, lo, hi);
}

/* A plane's limits inside an intersection: an axis-aligned plane bounds one
 * side of the box (POV-Ray's Compute_Plane_Min_Max). */
static bbox plane_limits(const scene_object *o)
{
    bbox b = huge_box();
    vec3 n = v3_norm(xform_normal(&o->transform, o->u.plane.normal));
    double d = v3_dot(n, xform_point(&o->transform, v3_scale(o->u.plane.normal, o->u.plane.offset)));
    double e = 1e-10;
    if (fabs(n.y) < e && fabs(n.z) < e) { if (n.x > 0) b.hi.x = d; else b.lo.x = -d; }
    if (fabs(n.x) < e && fabs(n.z) < e) { if (n.y > 0) b.hi.y = d; else b.lo.y = -d; }
    if (fabs(n.x) < e && fabs(n.y) < e) { if (n.z > 0) b.hi.z = d; else b.lo.z = -d; }
    return b;
}

static bbox obj_box(extent_ctx *g, const scene_object *o);

static bbox csg_box(extent_ctx *g, const scene_object *o)
{
    int isect = o->kind == SHAPE_INTERSECTION || o->kind == SHAPE_DIFFERENCE;
    bbox b = isect ? box_of(v3s(-BOUND_HUGE), v3s(BOUND_HUGE)) : box_of(v3s(BOUND_HUGE), v3s(-BOUND_HUGE));
    for (int i = 0; i < o->u.csg.nkids; i++) {
        const scene_object *k = o->u.csg.kids[i];
        if (isect) {
            /* inverted members (difference's later ones) and height fields do not bound */
            int inverted = ((k->flags & OBJ_INVERSE) != 0) != (o->kind == SHAPE_DIFFERENCE && i > 0);
            if (inverted || k->kind == SHAPE_HEIGHT_FIELD) continue;
            bbox kb = k->kind == SHAPE_PLANE ? plane_limits(k) : obj_box(g, k);
            b.lo = v3_max(b.lo, kb.lo);
            b.hi = v3_min(b.hi, kb.hi);
        } else {
            bbox kb = obj_box(g, k);
            b.lo = v3_min(b.lo, kb.lo);
            b.hi = v3_max(b.hi, kb.hi);
        }
    }
    if (b.lo.x > b.hi.x || b.lo.y > b.hi.y || b.lo.z > b.hi.z) return huge_box(); /* degenerate: not used */
    vec3 len = v3_sub(b.hi, b.lo);
    if (len.x > CRITICAL_LENGTH || len.y > CRITICAL_LENGTH || len.z > CRITICAL_LENGTH) return huge_box();
    return b;
}

static bbox leaf_box(extent_ctx *g, const scene_object *o)
{
    const xform *x = &o->transform;
    switch (o->kind) {
    case SHAPE_SPHERE: {
        double s, r = o->u.sphere.radius;
        vec3 c = o->u.sphere.centre;
        if (is_similarity(x, &s)) {
            vec3 wc = xform_point(x, c);
            return box_of(v3_sub(wc, v3s(r * s)), v3_add(wc, v3s(r * s)));
        }
        return transformed_box(x, v3_sub(c, v3s(r)), v3_add(c, v3s(r)));
    }
    case SHAPE_BOX: return transformed_box(x, o->u.box.c1, o->u.box.c2);
    case SHAPE_PLANE: return huge_box();
    case SHAPE_TRIANGLE: case SHAPE_SMOOTH_TRIANGLE: {
        vec3 lo = v3s(INFINITY), hi = v3s(-INFINITY);
        for (int i = 0; i < 3; i++) {
            vec3 w = xform_point(x, o->u.triangle.v[i]);
            lo = v3_min(lo, w);
            hi = v3_max(hi, w);
        }
        return box_of(v3_sub(lo, v3s(1e-10)), v3_add(hi, v3s(1e-10)));
    }
    case SHAPE_MESH: {
        const scene_mesh *m = o->u.mesh.mesh;
        vec3 lo = v3s(INFINITY), hi = v3s(-INFINITY);
        for (int i = 0; m && i < m->nverts; i++) {
            lo = v3_min(lo, mesh_vert(m, i));
            hi = v3_max(hi, mesh_vert(m, i));
        }
        if (!m || m->nverts == 0) lo = hi = v3s(0);
        return transformed_box(x, lo, hi);
    }
    case SHAPE_CYLINDER: case SHAPE_CONE: return cone_box(o);
    case SHAPE_DISC: {
        vec3 n = v3_norm(o->u.disc.normal);
        xform f = xform_then(axis_frame(o->u.disc.centre, n, 1, 1), *x);
        double r = o->u.disc.radius;
        return transformed_box(&f, v3(-r, -r, -SMALL_TOLERANCE), v3(r, r, SMALL_TOLERANCE));
    }
    case SHAPE_TORUS: {
        double R = o->u.torus.major + o->u.torus.minor, r = o->u.torus.minor;
        return transformed_box(x, v3(-R, -r, -R), v3(R, r, R));
    }
    case SHAPE_SUPERELLIPSOID: return transformed_box(x, v3s(-1), v3s(1));
    case SHAPE_POLYGON: return o->u.polygon ? points_box(x, o->u.polygon->points, o->u.polygon->npoints) : huge_box();
    case SHAPE_LATHE: {
        vec3 lo, hi;
        leaf_box_local(o, &lo, &hi);
        return transformed_box(x, lo, hi);
    }
    case SHAPE_SOR: {
        const scene_lathe *la = o->u.lathe;
        double rmax = 0, ylo = INFINITY, yhi = -INFINITY;
        for (int i = 0; la && i < la->npoints; i++) {
            rmax = fmax(rmax, fabs(la->points[i][0]));
            ylo = fmin(ylo, la->points[i][1]);
            yhi = fmax(yhi, la->points[i][1]);
        }
        if (!la || la->npoints == 0) return huge_box();
        return transformed_box(x, v3(-rmax, ylo, -rmax), v3(rmax, yhi, rmax));
    }
    case SHAPE_PRISM: case SHAPE_BLOB: {
        int empty = o->kind == SHAPE_PRISM ? !o->u.prism || o->u.prism->npoints == 0 : !o->u.blob || o->u.blob->ncomponents == 0;
        if (empty) return huge_box();
        vec3 lo, hi;
        leaf_box_local(o, &lo, &hi);
        return transformed_box(x, lo, hi);
    }
    case SHAPE_HEIGHT_FIELD: {
        const scene_height_field *h = o->u.height_field;
        double lo = 1, hi = 0;
        for (long i = 0; h && i < (long)h->width * h->height; i++) {
            lo = fmin(lo, h->heights[i]);
            hi = fmax(hi, h->heights[i]);
        }
        if (!h || lo > hi) lo = hi = 0;
        return transformed_box(x, v3(0, lo, 0), v3(1, hi, 1));
    }
    case SHAPE_TEXT: {
        const scene_text *t = o->u.text;
        double xl = INFINITY, xh = -INFINITY, yl = INFINITY, yh = -INFINITY;
        for (int i = 0; t && i < t->nsegments; i++)
            for (int k = 0; k < 4; k++) {
                xl = fmin(xl, t->segments[i][2 * k]);
                xh = fmax(xh, t->segments[i][2 * k]);
                yl = fmin(yl, t->segments[i][2 * k + 1]);
                yh = fmax(yh, t->segments[i][2 * k + 1]);
            }
        if (!t || t->nsegments == 0) return transformed_box(x, v3s(0), v3s(0));
        return transformed_box(x, v3(xl, yl, 0), v3(xh, yh, t->depth));
    }
    case SHAPE_QUADRIC: case SHAPE_POLY: return huge_box();
    case SHAPE_ISOSURFACE: {
        const scene_isosurface *iso = o->u.isosurface;
        if (!iso) return huge_box();
        if (iso->sphere) {
            double r = iso->radius;
            return transformed_box(x, v3_sub(iso->c1, v3s(r)), v3_add(iso->c1, v3s(r)));
        }
        return transformed_box(x, iso->c1, iso->c2);
    }
    default:
        if (!g->unsupported) g->unsupported = o->name ? o->name : "object";
        return huge_box();
    }
}

static bbox obj_box(extent_ctx *g, const scene_object *o)
{
    bbox b = scene_object_is_csg(o) ? csg_box(g, o) : leaf_box(g, o);
    if (o->clip && !(o->flags & OBJ_INVERSE)) {
        /* a clipped object is bounded by its clipping solid too */
        scene_object c = *o->clip;
        c.transform = xform_then(o->clip->transform, o->transform);
        if (!scene_object_is_csg(&c)) {
            bbox cb = obj_box(g, &c);
            bbox in = {v3_max(b.lo, cb.lo), v3_min(b.hi, cb.hi)};
            if (in.lo.x <= in.hi.x && in.lo.y <= in.hi.y && in.lo.z <= in.hi.z) b = in;
        }
    }
    return b;
}

/* Boxes in the shape's own space (lathe: POV-Ray's bounding cylinder from
 * the segments' extremes). */
static bbox leaf_box_local(const scene_object *o, vec3 *lo, vec3 *hi)
{
    *lo = v3s(-1);
    *hi = v3s(1);
    if (o->kind == SHAPE_LATHE && o->u.lathe) {
        const scene_lathe *la = o->u.lathe;
        int n = la->npoints, count, step = la->spline == SPLINE_BEZIER ? 4 : 1;
        switch (la->spline) { /* linear/quadratic/cubic advance one point, bezier four */
        case SPLINE_LINEAR: count = n - 1; break;
        case SPLINE_QUADRATIC: count = n - 2; break;
        case SPLINE_CUBIC: count = n - 3; break;
        default: count = n / 4; break;
        }
        double rmax = 0, ylo = INFINITY, yhi = -INFINITY;
        for (int i = 0; i < count; i++) {
            double sa[2], sb[2], sc[2], sd[2];
            geom_sweep_coeffs(la->spline, (const double (*)[2])la->points + i * step, sa, sb, sc, sd);
            double ws[4] = {0, 1, -1, -1};
            for (int k = 0; k < 2; k++) { /* extremes where the derivative vanishes */
                double qa = 3 * sa[k], qb = 2 * sb[k], qc = sc[k];
                double cand[2];
                int nc = 0;
                if (fabs(qa) > 1e-300) {
                    double disc = qb * qb - 4 * qa * qc;
                    if (disc >= 0) {
                        cand[nc++] = (-qb - sqrt(disc)) / (2 * qa);
                        cand[nc++] = (-qb + sqrt(disc)) / (2 * qa);
                    }
                } else if (fabs(qb) > 1e-300) {
                    cand[nc++] = -qc / qb;
                }
                for (int j = 0; j < nc; j++) ws[2 + j] = cand[j];
                for (int j = 0; j < 4; j++) {
                    double w = ws[j];
                    if (w < 0 || w > 1) continue;
                    double at = ((sa[k] * w + sb[k]) * w + sc[k]) * w + sd[k];
                    if (k == 0) rmax = fmax(rmax, fabs(at));
                    else {
                        ylo = fmin(ylo, at);
                        yhi = fmax(yhi, at);
                    }
                }
                ws[2] = ws[3] = -1;
            }
        }
        if (la->spline == SPLINE_BEZIER) /* POV-Ray bounds a bezier segment by its 4 points */
            for (int i = 0; i < count * 4 && i < n; i++) {
                rmax = fmax(rmax, fabs(la->points[i][0]));
                ylo = fmin(ylo, la->points[i][1]);
                yhi = fmax(yhi, la->points[i][1]);
            }
        if (ylo > yhi) ylo = yhi = 0;
        *lo = v3(-rmax, ylo, -rmax);
        *hi = v3(rmax, yhi, rmax);
    } else if (o->kind == SHAPE_PRISM && o->u.prism) {
        const scene_prism *pr = o->u.prism;
        double xl = INFINITY, xh = -INFINITY, zl = INFINITY, zh = -INFINITY;
        for (int i = 0; i < pr->npoints; i++) {
            xl = fmin(xl, pr->points[i][0]);
            xh = fmax(xh, pr->points[i][0]);
            zl = fmin(zl, pr->points[i][1]);
            zh = fmax(zh, pr->points[i][1]);
        }
        double y0 = fmin(pr->height1, pr->height2), y1 = fmax(pr->height1, pr->height2);
        if (pr->conic) {
            double s = fmax(fabs(y0), fabs(y1));
            xl = fmin(xl * s, 0);
            xh = fmax(xh * s, 0);
            zl = fmin(zl * s, 0);
            zh = fmax(zh * s, 0);
        }
        *lo = v3(xl, y0, zl);
        *hi = v3(xh, y1, zh);
    } else if (o->kind == SHAPE_BLOB && o->u.blob) {
        *lo = v3s(INFINITY);
        *hi = v3s(-INFINITY);
        for (int i = 0; i < o->u.blob->ncomponents; i++) {
            const scene_blob_component *c = &o->u.blob->components[i];
            vec3 b2 = c->cylinder ? c->b : c->a;
            bbox cb = transformed_box(&c->transform, v3_sub(v3_min(c->a, b2), v3s(c->radius)), v3_add(v3_max(c->a, b2), v3s(c->radius)));
            *lo = v3_min(*lo, cb.lo);
            *hi = v3_max(*hi, cb.hi);
        }
        if (o->u.blob->ncomponents == 0) *lo = *hi = v3s(0);
    }
    return box_of(*lo, *hi);
}

int geom_extent(const scene_object *o, vec3 *lo, vec3 *hi, const char **what)
{
    extent_ctx g = {NULL};
    bbox b = obj_box(&g, o);
    *lo = b.lo;
    *hi = b.hi;
    *what = g.unsupported;
    return g.unsupported ? -1 : 0;
}
