/* test_accel.c - Embree scene build and ray queries against closed-form
 * answers: every analytic shape, triangles, meshes and instances, grazing
 * rays, self-intersection, scale invariance, no_shadow, mesh textures.
 * Tolerances: distances 1e-9 relative for analytic shapes (double precision
 * end to end), 1e-6 relative for triangles (refined from Embree's float hit),
 * normals 1e-9 (analytic) / 1e-6 (triangles). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <embree3/rtcore.h>
#include "accel.h"
#include "geom_shape.h"
#include "diag.h"
#include "pool.h"
#include "rng.h"
#include "scene.h"

static const src_loc here = {"test.pov", 1, 1};

static void assert_near(double a, double b, double tol)
{
    if (!(fabs(a - b) <= tol)) fail_msg("got %.17g, expected %.17g (tol %g)", a, b, tol);
}

static void assert_vec(vec3 a, vec3 b, double tol)
{
    if (!(fabs(a.x - b.x) <= tol && fabs(a.y - b.y) <= tol && fabs(a.z - b.z) <= tol))
        fail_msg("got <%.12g,%.12g,%.12g>, expected <%.12g,%.12g,%.12g> (tol %g)", a.x, a.y, a.z, b.x, b.y, b.z, tol);
}

static void assert_hit_sane(const accel_hit *h)
{
    assert_true(isfinite(h->t));
    assert_true(v3_finite(h->p));
    assert_true(v3_finite(h->ng));
    assert_true(v3_finite(h->ns));
    assert_near(v3_len(h->ng), 1.0, 1e-9);
    assert_near(v3_len(h->ns), 1.0, 1e-9);
    assert_true(v3_dot(h->ng, h->ns) >= 0.0);
    assert_true(isfinite(h->u) && isfinite(h->v));
    assert_non_null(h->obj);
    assert_non_null(h->texture);
}

static scene_object *add_obj(scene *s, shape_kind k)
{
    scene_object *o = scene_new_object(s, k, here);
    assert_non_null(o);
    assert_int_equal(scene_add_object(s, o), PT_OK);
    return o;
}

static scene_object *sphere(scene *s, vec3 c, double r)
{
    scene_object *o = add_obj(s, SHAPE_SPHERE);
    o->name = "sphere";
    o->u.sphere.centre = c;
    o->u.sphere.radius = r;
    return o;
}

static scene_object *box(scene *s, vec3 a, vec3 b)
{
    scene_object *o = add_obj(s, SHAPE_BOX);
    o->name = "box";
    o->u.box.c1 = a;
    o->u.box.c2 = b;
    return o;
}

static scene_object *triangle(scene *s, vec3 a, vec3 b, vec3 c)
{
    scene_object *o = add_obj(s, SHAPE_TRIANGLE);
    o->name = "triangle";
    o->u.triangle.v[0] = a;
    o->u.triangle.v[1] = b;
    o->u.triangle.v[2] = c;
    return o;
}

static accel *build(const scene *s, diag *d)
{
    pt_status st = PT_ERR_INTERNAL;
    accel *a = accel_build(s, 2, d, &st);
    if (st != PT_OK) {
        for (int i = 0; i < diag_count(d); i++) {
            char *m = diag_format(diag_get(d, i));
            print_error("%s\n", m);
            free(m);
        }
    }
    assert_int_equal(st, PT_OK);
    assert_non_null(a);
    return a;
}

/* Hit with tolerance checks on distance and normal. */
static void expect_hit(const accel *a, vec3 org, vec3 dir, double t, vec3 n, double ttol, double ntol, accel_hit *out)
{
    accel_hit h;
    if (!accel_intersect(a, org, dir, 0.0, INFINITY, &h))
        fail_msg("expected a hit at t=%g from <%g,%g,%g>", t, org.x, org.y, org.z);
    assert_hit_sane(&h);
    assert_near(h.t, t, ttol * fmax(1.0, fabs(t)));
    assert_vec(h.ng, n, ntol);
    assert_vec(h.p, v3_madd(org, dir, h.t), 1e-12 * (1.0 + v3_len(h.p)));
    if (out) *out = h;
}

static void expect_miss(const accel *a, vec3 org, vec3 dir)
{
    accel_hit h;
    if (accel_intersect(a, org, dir, 0.0, INFINITY, &h))
        fail_msg("expected a miss from <%g,%g,%g> dir <%g,%g,%g>, got t=%g", org.x, org.y, org.z, dir.x, dir.y,
                 dir.z, h.t);
}

/* ------------------------------------------------------------ shapes */

static void test_sphere(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    scene_object *o = sphere(s, v3(0, 0, 5), 1);
    /* a second, transformed sphere: unit sphere scaled by 2 then moved to x=10 */
    scene_object *o2 = sphere(s, v3(0, 0, 0), 1);
    o2->transform = xform_then(xform_scale(v3(2, 2, 2)), xform_translate(v3(10, 0, 0)));
    accel *a = build(s, d);
    accel_hit h;
    /* from outside along the axis */
    expect_hit(a, v3(0, 0, 0), v3(0, 0, 1), 4.0, v3(0, 0, -1), 1e-12, 1e-12, &h);
    assert_ptr_equal(h.obj, o);
    assert_ptr_equal(h.texture, &s->default_texture);
    /* off axis: x = 0.6 gives z = 5 - 0.8 */
    expect_hit(a, v3(0.6, 0, 0), v3(0, 0, 1), 4.2, v3(0.6, 0, -0.8), 1e-12, 1e-12, NULL);
    /* unnormalised direction: t is the ray parameter */
    expect_hit(a, v3(0, 0, 0), v3(0, 0, 2), 2.0, v3(0, 0, -1), 1e-12, 1e-12, NULL);
    /* from inside (the centre): exit point, outward normal (not flipped) */
    expect_hit(a, v3(0, 0, 5), v3(1, 0, 0), 1.0, v3(1, 0, 0), 1e-12, 1e-12, NULL);
    expect_hit(a, v3(0, 0, 5), v3(0, -1, 0), 1.0, v3(0, -1, 0), 1e-12, 1e-12, NULL);
    /* transformed sphere: radius 2 at x=10 */
    expect_hit(a, v3(10, 0, -10), v3(0, 0, 1), 8.0, v3(0, 0, -1), 1e-12, 1e-12, &h);
    assert_ptr_equal(h.obj, o2);
    expect_hit(a, v3(10, 10, 0), v3(0, -1, 0), 8.0, v3(0, 1, 0), 1e-12, 1e-12, NULL);
    /* tmax cuts the hit off, tmin skips the first one */
    assert_false(accel_intersect(a, v3(0, 0, 0), v3(0, 0, 1), 0.0, 3.9, &h));
    assert_true(accel_intersect(a, v3(0, 0, 0), v3(0, 0, 1), 4.5, INFINITY, &h));
    assert_near(h.t, 6.0, 1e-12);
    assert_vec(h.ng, v3(0, 0, 1), 1e-12);
    expect_miss(a, v3(0, 2, 0), v3(0, 0, 1));
    accel_stats stt = accel_get_stats(a);
    assert_int_equal(stt.user_prims, 2);
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

/* One huge object beside one small one (a sky dome of radius 1e4 around a
 * 20-unit building): the ray epsilon follows the small one's size, so a
 * ray starting 0.01 from the building still hits it (1e-5 of the dome's
 * diameter would be 0.2). */
static void test_epsilon_small_beside_huge(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    sphere(s, v3(0, 0, 0), 1e4);
    scene_object *b = box(s, v3(-10, -0.1, -10), v3(10, 4, 10));
    accel *a = build(s, d);
    accel_hit h;
    expect_hit(a, v3(-10.01, 1.9, -4.5), v3(1, 0, 0), 0.01, v3(-1, 0, 0), 1e-9, 1e-12, &h);
    assert_ptr_equal(h.obj, b);
    assert_true(accel_epsilon(a, v3(-10.01, 1.9, -4.5), v3(1, 0, 0)) < 1e-3);
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

/* Shells of a planet-sized sky (advanced/mediasky.pov): spheres of radius
 * 5e4 and 5e4 + 1 about one centre, with a sun sphere of radius 7.5e4.
 * Every object is closed-form, so the rays' scale term is 1e-3 of the
 * median size and a ray leaving the inner shell meets the outer one 1 unit
 * on (1e-5 of the working scale alone would be about 1.5, past it). One
 * triangle anywhere puts the float margin back (the median size again),
 * and the same ray then skips the gap: the rule is per scene, stated in
 * accel.c. */
static void test_epsilon_closed_form_shells(void **st)
{
    (void)st;
    for (int with_triangle = 0; with_triangle < 2; with_triangle++) {
        scene *s = scene_new();
        diag *d = diag_new();
        sphere(s, v3(0, -5e4, 0), 5e4);
        scene_object *outer = sphere(s, v3(0, -5e4, 0), 5e4 + 1.0);
        sphere(s, v3(1e6, 0, 0), 7.5e4);
        if (with_triangle) triangle(s, v3(1e6, 1e6, 1e6), v3(1e6 + 1, 1e6, 1e6), v3(1e6, 1e6 + 1, 1e6));
        accel *a = build(s, d);
        /* leaving the inner shell's top (y = 0) upwards */
        double e = accel_epsilon(a, v3(0, 0, 0), v3(0, 1, 0));
        accel_hit h;
        int hit = accel_intersect(a, v3(0, 0, 0), v3(0, 1, 0), 0.0, INFINITY, &h);
        if (!with_triangle) {
            assert_true(e < 0.01); /* 1e-5 * 1e-3 * (median diagonal ~1.7e5) */
            assert_true(hit);
            assert_ptr_equal(h.obj, outer);
            assert_true(fabs(h.t - 1.0) < 1e-9);
        } else {
            assert_true(e > 1.0); /* the median diagonal's 1e-5 */
        }
        accel_free(a);
        diag_free(d);
        scene_free(s);
    }
}

static void test_box_faces(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    box(s, v3(-1, -2, -3), v3(1, 2, 3));
    accel *a = build(s, d);
    accel_hit h;
    expect_hit(a, v3(-10, 0.5, 0.5), v3(1, 0, 0), 9.0, v3(-1, 0, 0), 1e-12, 0, &h);
    assert_int_equal(h.prim, GEOM_PART_BOX_NX);
    expect_hit(a, v3(10, 0.5, 0.5), v3(-1, 0, 0), 9.0, v3(1, 0, 0), 1e-12, 0, &h);
    assert_int_equal(h.prim, GEOM_PART_BOX_PX);
    expect_hit(a, v3(0.5, -10, 0.5), v3(0, 1, 0), 8.0, v3(0, -1, 0), 1e-12, 0, NULL);
    expect_hit(a, v3(0.5, 10, 0.5), v3(0, -1, 0), 8.0, v3(0, 1, 0), 1e-12, 0, NULL);
    expect_hit(a, v3(0.5, 0.5, -10), v3(0, 0, 1), 7.0, v3(0, 0, -1), 1e-12, 0, NULL);
    expect_hit(a, v3(0.5, 0.5, 10), v3(0, 0, -1), 7.0, v3(0, 0, 1), 1e-12, 0, NULL);
    /* diagonal entry through the +y face */
    expect_hit(a, v3(0, 4, 0), v3(0.1, -1, 0.1), 2.0, v3(0, 1, 0), 1e-12, 0, NULL);
    /* from inside: the exit face */
    expect_hit(a, v3(0, 0, 0), v3(0, 0, 1), 3.0, v3(0, 0, 1), 1e-12, 0, NULL);
    expect_hit(a, v3(0, 0, 0), v3(-1, 0, 0), 1.0, v3(-1, 0, 0), 1e-12, 0, NULL);
    /* parallel to a slab, outside it: miss (no 0*inf NaN) */
    expect_miss(a, v3(-10, 5, 0), v3(1, 0, 0));
    /* rotated box: rotate 90 about z maps the x half-size 1 onto y */
    scene *s2 = scene_new();
    /* a zero-thickness box (z from 0.25 to 0.25, var_reflection.pov's
     * strips): from either side the face opposing the ray, so the hit
     * reads as entering as POV-Ray's interior list has it */
    box(s2, v3(20, -1, 0.25), v3(22, 1, 0.25));
    scene_object *o = box(s2, v3(-1, -2, -3), v3(1, 2, 3));
    o->transform = xform_rotate(v3(0, 0, 90));
    accel *a2 = build(s2, d);
    expect_hit(a2, v3(0, 10, 0), v3(0, -1, 0), 9.0, v3(0, 1, 0), 1e-12, 1e-12, NULL);
    expect_hit(a2, v3(10, 0, 0), v3(-1, 0, 0), 8.0, v3(1, 0, 0), 1e-12, 1e-12, NULL);
    expect_hit(a2, v3(21, 0, 5.25), v3(0, 0, -1), 5.0, v3(0, 0, 1), 1e-12, 1e-12, NULL);
    expect_hit(a2, v3(21, 0, -4.75), v3(0, 0, 1), 5.0, v3(0, 0, -1), 1e-12, 1e-12, NULL);
    expect_hit(a2, v3(21, -5, 5.25), v3(0, 1, -1), 5.0, v3(0, 0, 1), 1e-12, 1e-12, NULL);
    accel_free(a2);
    scene_free(s2);
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

static void test_plane(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    scene_object *p = add_obj(s, SHAPE_PLANE);
    p->u.plane.normal = v3(0, 1, 0);
    p->u.plane.offset = 1.0; /* y = 1 */
    sphere(s, v3(0, 5, 0), 0.5);
    accel *a = build(s, d);
    /* both sides: normal is the plane's, not flipped */
    expect_hit(a, v3(3, -3, 0), v3(0, 1, 0), 4.0, v3(0, 1, 0), 1e-12, 0, NULL);
    expect_hit(a, v3(3, 3, 0), v3(0, -1, 0), 2.0, v3(0, 1, 0), 1e-12, 0, NULL);
    expect_hit(a, v3(0, 3, 0), v3(1, -1, 0), 2.0, v3(0, 1, 0), 1e-12, 0, NULL);
    /* parallel: miss */
    expect_miss(a, v3(0, 3, 0), v3(1, 0, 0));
    /* a far hit, 1000 scene sizes away, at a grazing angle */
    double sc = accel_scale(a);
    vec3 dir = v3(1, -2.0 / (1000.0 * sc), 0);
    expect_hit(a, v3(0, 3, 0), dir, 1000.0 * sc, v3(0, 1, 0), 1e-9, 0, NULL);
    /* bounds exclude the plane: they are the sphere's */
    vec3 lo, hi;
    accel_bounds(a, &lo, &hi);
    assert_vec(lo, v3(-0.5, 4.5, -0.5), 1e-12);
    assert_vec(hi, v3(0.5, 5.5, 0.5), 1e-12);
    assert_near(accel_scale(a), sqrt(3.0), 1e-12);
    accel_free(a);
    /* a rotated, non-normalised plane: normal <0,2,0>, offset 2 -> y = 1, then rotate 90 about z -> x = -1 */
    scene *s2 = scene_new();
    p = add_obj(s2, SHAPE_PLANE);
    p->u.plane.normal = v3(0, 2, 0);
    p->u.plane.offset = 2.0;
    p->transform = xform_rotate(v3(0, 0, 90));
    a = build(s2, d);
    expect_hit(a, v3(5, 0.3, 0.2), v3(-1, 0, 0), 6.0, v3(-1, 0, 0), 1e-12, 1e-12, NULL);
    expect_hit(a, v3(-5, 0.3, 0.2), v3(1, 0, 0), 4.0, v3(-1, 0, 0), 1e-12, 1e-12, NULL);
    accel_free(a);
    scene_free(s2);
    diag_free(d);
    scene_free(s);
}

static void test_triangles(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    scene_object *t = triangle(s, v3(0, 0, 5), v3(1, 0, 5), v3(0, 1, 5));
    scene_object *sm = add_obj(s, SHAPE_SMOOTH_TRIANGLE);
    sm->u.triangle.v[0] = v3(10, 0, 5);
    sm->u.triangle.v[1] = v3(11, 0, 5);
    sm->u.triangle.v[2] = v3(10, 1, 5);
    sm->u.triangle.n[0] = v3(0, 0, 1);
    sm->u.triangle.n[1] = v3(1, 0, 1);
    sm->u.triangle.n[2] = v3(0, 1, 1);
    /* a transformed triangle: scaled by 2 and mirrored in x (winding follows world) */
    scene_object *tm = triangle(s, v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0));
    tm->transform = xform_then(xform_scale(v3(-2, 2, 2)), xform_translate(v3(-10, 0, 7)));
    scene_texture *tex = scene_new_texture(s);
    t->texture = tex;
    accel *a = build(s, d);
    accel_hit h;
    expect_hit(a, v3(0.25, 0.25, 0), v3(0, 0, 1), 5.0, v3(0, 0, 1), 1e-6, 1e-6, &h);
    assert_ptr_equal(h.obj, t);
    assert_ptr_equal(h.texture, tex);
    assert_near(h.u, 0.25, 1e-6);
    assert_near(h.v, 0.25, 1e-6);
    assert_vec(h.ns, h.ng, 1e-12);
    /* back side: same normal */
    expect_hit(a, v3(0.25, 0.25, 9), v3(0, 0, -1), 4.0, v3(0, 0, 1), 1e-6, 1e-6, NULL);
    /* smooth: at barycentrics (u,v) = (0.5, 0.25) normal = .25 n0 + .5 n1 + .25 n2 */
    expect_hit(a, v3(10.5, 0.25, 0), v3(0, 0, 1), 5.0, v3(0, 0, 1), 1e-6, 1e-6, &h);
    assert_ptr_equal(h.obj, sm);
    assert_vec(h.ns, v3_norm(v3(0.5, 0.25, 1.0)), 1e-6);
    /* mirrored: world vertices (-10,0,7), (-12,0,7), (-10,2,7): cross gives -z */
    expect_hit(a, v3(-10.5, 0.5, 0), v3(0, 0, 1), 7.0, v3(0, 0, -1), 1e-6, 1e-6, &h);
    assert_ptr_equal(h.obj, tm);
    expect_miss(a, v3(0.75, 0.75, 0), v3(0, 0, 1));
    accel_stats stt = accel_get_stats(a);
    assert_int_equal(stt.triangles, 3);
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

/* A unit square in the xy plane (z = 0) made of two triangles, with
 * per-vertex normals tilted and per-triangle textures. */
static scene_mesh *quad_mesh(scene *s, const scene_texture *t0, const scene_texture *t1)
{
    scene_mesh *m = scene_new_mesh(s);
    m->nverts = 4;
    m->ntris = 2;
    m->verts = arena_alloc(s->mem, sizeof(float[3]) * 4);
    m->tris = arena_alloc(s->mem, sizeof(int[3]) * 2);
    float v[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    memcpy(m->verts, v, sizeof v);
    int tr[2][3] = {{0, 1, 2}, {0, 2, 3}};
    memcpy(m->tris, tr, sizeof tr);
    if (t0) {
        m->ntextures = 2;
        m->textures = arena_alloc(s->mem, sizeof(scene_texture *) * 2);
        m->textures[0] = t0;
        m->textures[1] = t1;
        m->tri_texture = arena_alloc(s->mem, sizeof(int) * 2);
        m->tri_texture[0] = 0;
        m->tri_texture[1] = 1;
    }
    return m;
}

static scene_object *mesh_obj(scene *s, const scene_mesh *m, xform x)
{
    scene_object *o = add_obj(s, SHAPE_MESH);
    o->name = "mesh";
    o->u.mesh.mesh = m;
    o->u.mesh.textures = m->textures; /* the object's texture_list (the parser gives it copies) */
    o->transform = x;
    ((scene_mesh *)m)->uses++;
    return o;
}

static void test_mesh_instances(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    scene_mesh *m = quad_mesh(s, NULL, NULL);
    /* first instance at z = 5; second scaled by 2 at z = 10 */
    scene_object *i1 = mesh_obj(s, m, xform_translate(v3(0, 0, 5)));
    scene_object *i2 = mesh_obj(s, m, xform_then(xform_scale(v3(2, 2, 2)), xform_translate(v3(0, 0, 10))));
    /* a single-use mesh: flattened */
    scene_mesh *m2 = quad_mesh(s, NULL, NULL);
    scene_object *f = mesh_obj(s, m2, xform_then(xform_rotate(v3(90, 0, 0)), xform_translate(v3(0, 20, 0))));
    accel *a = build(s, d);
    accel_stats stt = accel_get_stats(a);
    assert_int_equal(stt.instances, 2);
    assert_int_equal(stt.triangles, 4); /* shared mesh once + flattened */
    accel_hit h;
    /* (0.25, 0.75) lies in the second triangle of the first instance */
    expect_hit(a, v3(0.25, 0.75, -1), v3(0, 0, 1), 6.0, v3(0, 0, 1), 1e-6, 1e-6, &h);
    assert_ptr_equal(h.obj, i1);
    assert_int_equal(h.prim, 1);
    assert_true(accel_intersect(a, v3(0.25, 0.75, -1), v3(0, 0, 1), 6.5, INFINITY, &h));
    assert_hit_sane(&h);
    assert_ptr_equal(h.obj, i2);
    assert_near(h.t, 11.0, 1e-6 * 11);
    assert_vec(h.ng, v3(0, 0, 1), 1e-6);
    /* only the scaled instance covers x = 1.5 */
    expect_hit(a, v3(1.5, 0.5, -1), v3(0, 0, 1), 11.0, v3(0, 0, 1), 1e-6, 1e-6, &h);
    assert_ptr_equal(h.obj, i2);
    assert_int_equal(h.prim, 0);
    /* flattened mesh: rotate 90 about x takes the xy square to xz at y = 20 (z in [0,1]); +z normal goes to -y */
    expect_hit(a, v3(0.5, 30, 0.5), v3(0, -1, 0), 10.0, v3(0, -1, 0), 1e-6, 1e-6, &h);
    assert_ptr_equal(h.obj, f);
    vec3 lo, hi;
    accel_bounds(a, &lo, &hi);
    assert_vec(lo, v3(0, 0, 0), 1e-6);
    assert_vec(hi, v3(2, 20, 10), 1e-6);
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

static void test_mesh_textures_normals(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    scene_texture *t0 = scene_new_texture(s), *t1 = scene_new_texture(s), *to = scene_new_texture(s);
    scene_mesh *m = quad_mesh(s, t0, t1);
    /* normals: one per vertex, tilted */
    m->nnormals = 4;
    m->normals = arena_alloc(s->mem, sizeof(float[3]) * 4);
    float n[4][3] = {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    memcpy(m->normals, n, sizeof n);
    m->tri_normals = arena_alloc(s->mem, sizeof(int[3]) * 2);
    int tn[2][3] = {{0, 1, 2}, {0, 2, 3}};
    memcpy(m->tri_normals, tn, sizeof tn);
    /* used twice (instanced) and once more as a separate single-use copy */
    scene_object *a1 = mesh_obj(s, m, xform_translate(v3(0, 0, 5)));
    a1->texture = to;
    mesh_obj(s, m, xform_translate(v3(5, 0, 5)));
    scene_mesh *m2 = quad_mesh(s, t0, t1);
    m2->tri_texture[1] = 7; /* out of range: falls back to the object's texture */
    scene_object *b = mesh_obj(s, m2, xform_translate(v3(10, 0, 5)));
    b->texture = to;
    accel *a = build(s, d);
    accel_hit h;
    expect_hit(a, v3(0.75, 0.25, 0), v3(0, 0, 1), 5.0, v3(0, 0, 1), 1e-6, 1e-6, &h);
    assert_ptr_equal(h.texture, t0);
    /* shading normal: barycentrics u=0.5 (v1), v=0.25 (v2): .25 n0 + .5 n1 + .25 n2 */
    assert_vec(h.ns, v3_norm(v3(0.75, 0.25, 1.0)), 1e-6);
    expect_hit(a, v3(0.25, 0.75, 0), v3(0, 0, 1), 5.0, v3(0, 0, 1), 1e-6, 1e-6, &h);
    assert_ptr_equal(h.texture, t1);
    expect_hit(a, v3(5.25, 0.75, 0), v3(0, 0, 1), 5.0, v3(0, 0, 1), 1e-6, 1e-6, &h);
    assert_ptr_equal(h.texture, t1);
    expect_hit(a, v3(10.75, 0.25, 0), v3(0, 0, 1), 5.0, v3(0, 0, 1), 1e-6, 1e-6, &h);
    assert_ptr_equal(h.texture, t0);
    expect_hit(a, v3(10.25, 0.75, 0), v3(0, 0, 1), 5.0, v3(0, 0, 1), 1e-6, 1e-6, &h);
    assert_ptr_equal(h.texture, to);
    assert_int_equal(accel_get_stats(a).instances, 2);
    /* the bare Embree hits the GI's link rays make: accel_rtc_leaf gives the
     * same per-triangle textures (instanced and single-use meshes) */
    const struct { double x, y; const scene_texture *tex; } probe[] = {
        {0.75, 0.25, t0}, {0.25, 0.75, t1}, {5.25, 0.75, t1}, {10.75, 0.25, t0}, {10.25, 0.75, to}};
    for (int i = 0; i < 5; i++) {
        struct RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        struct RTCRayHit rh;
        memset(&rh, 0, sizeof rh);
        rh.ray.org_x = (float)probe[i].x;
        rh.ray.org_y = (float)probe[i].y;
        rh.ray.dir_z = 1.0f;
        rh.ray.tfar = INFINITY;
        rh.ray.mask = 0xFFFFFFFFu;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1((RTCScene)accel_rtc_scene(a), &ctx, &rh);
        const scene_texture *lt = NULL;
        const scene_object *lo = accel_rtc_leaf(a, rh.hit.geomID, rh.hit.primID, rh.hit.instID[0], rh.hit.u, &lt);
        assert_non_null(lo);
        assert_ptr_equal(lt, probe[i].tex);
    }
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

/* accel_hit.uv against POV-Ray 3.7's UVCoord formulas worked out by hand
 * (spheres.cpp, boxes.cpp's cube net, torus.cpp, mesh.cpp; every other
 * shape the world x, y); tolerance 1e-9 (analytic) / 1e-6 (triangles). */
static void test_uv(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    scene_object *sp = sphere(s, v3(0, 0, 0), 1);
    sp->transform = xform_then(xform_rotate(v3(0, 90, 0)), xform_translate(v3(0, 0, 5)));
    sp->uv_mapping = 1; /* analytic shapes compute their UV only when asked */
    box(s, v3(9, -2, -3), v3(11, 2, 3))->uv_mapping = 1;
    scene_object *to = add_obj(s, SHAPE_TORUS);
    to->u.torus.major = 2;
    to->u.torus.minor = 0.5;
    to->transform = xform_translate(v3(0, 0, 20));
    to->uv_mapping = 1;
    scene_object *di = add_obj(s, SHAPE_DISC);
    di->u.disc.centre = v3(30, 0, 0);
    di->u.disc.normal = v3(0, 0, -1);
    di->u.disc.radius = 1;
    scene_mesh *m = quad_mesh(s, NULL, NULL);
    m->nuvs = 4;
    m->uvs = arena_alloc(s->mem, sizeof(float[2]) * 4);
    float uv[4][2] = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
    memcpy(m->uvs, uv, sizeof uv);
    m->tri_uvs = m->tris;
    mesh_obj(s, m, xform_translate(v3(0, 0, 40)));
    mesh_obj(s, m, xform_then(xform_rotate(v3(0, 0, 90)), xform_translate(v3(5, 0, 40))));
    mesh_obj(s, quad_mesh(s, NULL, NULL), xform_translate(v3(10, 0, 40)));
    triangle(s, v3(20, 0, 40), v3(21, 0, 40), v3(20, 1, 40));
    accel *a = build(s, d);
    accel_hit h;
    /* sphere turned 90 about y (POV-Ray's left-handed rotate: object <x,y,z>
     * goes to <z, y, -x>): world <1,0,5> is object <0,0,1>: u = acos(0)/2pi */
    expect_hit(a, v3(5, 0, 5), v3(-1, 0, 0), 4.0, v3(1, 0, 0), 1e-12, 1e-12, &h);
    assert_near(h.uv[0], 0.25, 1e-9);
    assert_near(h.uv[1], 0.5, 1e-9);
    /* world <-1,0,5> is object <0,0,-1>: u = (2pi - pi/2) / 2pi = 0.75 */
    expect_hit(a, v3(-5, 0, 5), v3(1, 0, 0), 4.0, v3(-1, 0, 0), 1e-12, 1e-12, &h);
    assert_near(h.uv[0], 0.75, 1e-9);
    assert_near(h.uv[1], 0.5, 1e-9);
    /* north pole: v 1, u 0 */
    expect_hit(a, v3(0, 5, 5), v3(0, -1, 0), 4.0, v3(0, 1, 0), 1e-12, 1e-12, &h);
    assert_near(h.uv[0], 0.0, 1e-9);
    assert_near(h.uv[1], 1.0, 1e-9);
    /* box, normalised point <0, .75, .75> on min x: u = z/4, v = (1 + y)/3 */
    expect_hit(a, v3(0, 1, 1.5), v3(1, 0, 0), 9.0, v3(-1, 0, 0), 1e-12, 0, &h);
    assert_near(h.uv[0], 0.1875, 1e-9);
    assert_near(h.uv[1], 1.75 / 3.0, 1e-9);
    /* <.75, .5, 1> on max z: u = 1/4 + x/4, v = (1 + y)/3 */
    expect_hit(a, v3(10.5, 0, 10), v3(0, 0, -1), 7.0, v3(0, 0, 1), 1e-12, 0, &h);
    assert_near(h.uv[0], 0.4375, 1e-9);
    assert_near(h.uv[1], 0.5, 1e-9);
    /* <.75, 0, .75> on min y: u = 1/4 + x/4, v = z/3 */
    expect_hit(a, v3(10.5, -10, 1.5), v3(0, 1, 0), 8.0, v3(0, -1, 0), 1e-12, 0, &h);
    assert_near(h.uv[0], 0.4375, 1e-9);
    assert_near(h.uv[1], 0.25, 1e-9);
    /* <.25, .25, 0> on min z: u = 1 - x/4 */
    expect_hit(a, v3(9.5, -1, -10), v3(0, 0, 1), 7.0, v3(0, 0, -1), 1e-12, 0, &h);
    assert_near(h.uv[0], 0.9375, 1e-9);
    assert_near(h.uv[1], 1.25 / 3.0, 1e-9);
    /* torus top at object <2, .5, 0>: u = 1 - (atan2(0, 2) + pi)/2pi = .5,
     * v = (atan2(.5, 0) + pi)/2pi = .75 */
    expect_hit(a, v3(2, 5, 20), v3(0, -1, 0), 4.5, v3(0, 1, 0), 1e-10, 1e-10, &h);
    assert_near(h.uv[0], 0.5, 1e-9);
    assert_near(h.uv[1], 0.75, 1e-9);
    /* disc: no UVCoord of its own, the world x and y */
    expect_hit(a, v3(30.25, 0.5, -5), v3(0, 0, 1), 5.0, v3(0, 0, -1), 1e-12, 1e-12, &h);
    assert_near(h.uv[0], 30.25, 1e-9);
    assert_near(h.uv[1], 0.5, 1e-9);
    /* without uv_mapping the sphere reports the world x, y */
    sp->uv_mapping = 0;
    accel *a2 = build(s, d);
    expect_hit(a2, v3(5, 0.25, 5), v3(-1, 0, 0), 5.0 - sqrt(1.0 - 0.0625), v3(sqrt(1.0 - 0.0625), 0.25, 0), 1e-12, 1e-12, &h);
    assert_near(h.uv[0], sqrt(1.0 - 0.0625), 1e-9);
    assert_near(h.uv[1], 0.25, 1e-9);
    accel_free(a2);
    /* mesh with uv_vectors: barycentric interpolation, also on the rotated instance */
    expect_hit(a, v3(0.75, 0.25, 30), v3(0, 0, 1), 10.0, v3(0, 0, 1), 1e-6, 1e-6, &h);
    assert_near(h.uv[0], 1.5, 1e-6);
    assert_near(h.uv[1], 0.5, 1e-6);
    expect_hit(a, v3(0.25, 0.75, 30), v3(0, 0, 1), 10.0, v3(0, 0, 1), 1e-6, 1e-6, &h);
    assert_near(h.uv[0], 0.5, 1e-6);
    assert_near(h.uv[1], 1.5, 1e-6);
    /* rotated 90 about z: world <5 - .25, .75> is local <.75, .25> */
    expect_hit(a, v3(4.75, 0.75, 30), v3(0, 0, 1), 10.0, v3(0, 0, 1), 1e-6, 1e-6, &h);
    assert_near(h.uv[0], 1.5, 1e-6);
    assert_near(h.uv[1], 0.5, 1e-6);
    /* mesh without uv_vectors: <0,0>; lone triangle: world x, y */
    expect_hit(a, v3(10.75, 0.25, 30), v3(0, 0, 1), 10.0, v3(0, 0, 1), 1e-6, 1e-6, &h);
    assert_near(h.uv[0], 0.0, 0);
    assert_near(h.uv[1], 0.0, 0);
    expect_hit(a, v3(20.25, 0.25, 30), v3(0, 0, 1), 10.0, v3(0, 0, 1), 1e-6, 1e-6, &h);
    assert_near(h.uv[0], 20.25, 1e-6);
    assert_near(h.uv[1], 0.25, 1e-6);
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

static scene_object *cone(scene *s, shape_kind k, vec3 b, double rb, vec3 c, double rc)
{
    scene_object *o = add_obj(s, k);
    o->name = k == SHAPE_CONE ? "cone" : "cylinder";
    o->u.cone.base = b;
    o->u.cone.cap = c;
    o->u.cone.base_radius = rb;
    o->u.cone.cap_radius = rc;
    return o;
}

/* Coincident surfaces of two objects (a box's bottom face on a plane, a
 * floor cylinder's cap): rays from inside the box meet both at one
 * distance, and the tie goes to each about half the time, as POV-Ray's
 * rounding splits it; a gap of 1e-8 (a liquid inside its glass) is no tie.
 * Tolerance: 2000 rays, each object's share within 0.5 +- 0.1 (about 9
 * standard deviations of a fair split). A surface the caller passes over
 * (accel_intersect_past's skip) loses every tie. */
static double floor_share(double gap, int cylinder_floor)
{
    scene *s = scene_new();
    diag *d = diag_new();
    box(s, v3(-3, 0, -0.6), v3(3, 2.4, 0.6));
    scene_object *fl;
    if (cylinder_floor) {
        fl = cone(s, SHAPE_CYLINDER, v3(0, gap, 0), 30, v3(0, 9, 0), 30);
    } else {
        fl = add_obj(s, SHAPE_PLANE);
        fl->u.plane.normal = v3(0, 1, 0);
        fl->u.plane.offset = gap;
    }
    accel *a = build(s, d);
    rng r;
    rng_seed(&r, 19, 5);
    int on_floor = 0, n = 2000;
    for (int k = 0; k < n; k++) {
        vec3 org = v3(-2.5 + 5 * rng_f64(&r), 0.2 + 2 * rng_f64(&r), -0.5 + rng_f64(&r));
        vec3 dir = v3_norm(v3(rng_f64(&r) - 0.5, -0.2 - rng_f64(&r), rng_f64(&r) - 0.5));
        /* where the ray meets y = 0 inside the box's bottom face */
        double t = -org.y / dir.y;
        vec3 p = v3_madd(org, dir, t);
        if (fabs(p.x) > 2.9 || fabs(p.z) > 0.5) {
            k--;
            continue;
        }
        accel_hit h;
        assert_true(accel_intersect(a, org, dir, 0.0, INFINITY, &h));
        assert_near(h.t, t, 1e-7 * t);
        on_floor += h.obj == fl;
    }
    accel_free(a);
    diag_free(d);
    scene_free(s);
    return (double)on_floor / n;
}

/* A box that the rays pass over (no_reflection, for reflected rays)
 * standing on a plane: accel_intersect_past goes through the box to the
 * plane at its foot on every ray, the tie at the box's bottom face going
 * to the plane. */
static void past_box_to_floor(void)
{
    scene *s = scene_new();
    diag *d = diag_new();
    scene_object *b = box(s, v3(-3, 0, -0.6), v3(3, 2.4, 0.6));
    b->flags |= OBJ_NO_REFLECTION;
    scene_object *fl = add_obj(s, SHAPE_PLANE);
    fl->u.plane.normal = v3(0, 1, 0);
    fl->u.plane.offset = 0.0;
    accel *a = build(s, d);
    rng r;
    rng_seed(&r, 23, 7);
    for (int k = 0; k < 500; k++) {
        vec3 org = v3(-2.5 + 5 * rng_f64(&r), 4 + rng_f64(&r), -0.5 + rng_f64(&r));
        vec3 dir = v3_norm(v3(0.2 * (rng_f64(&r) - 0.5), -1, 0.2 * (rng_f64(&r) - 0.5)));
        accel_hit h;
        assert_int_equal(accel_intersect_past(a, NULL, org, dir, 1e-6, OBJ_NO_REFLECTION, &h, NULL), 1);
        assert_true(h.obj == fl);
        assert_near(h.t, -org.y / dir.y, 1e-9 * h.t);
    }
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

static void test_coplanar_tie(void **st)
{
    (void)st;
    past_box_to_floor();
    assert_near(floor_share(0.0, 0), 0.5, 0.1);
    assert_near(floor_share(0.0, 1), 0.5, 0.1);
    /* the floor 1e-8 above the box's bottom: always the floor; below it: never */
    assert_near(floor_share(1e-8, 0), 1.0, 0.0);
    assert_near(floor_share(-1e-8, 0), 0.0, 0.0);
    assert_near(floor_share(1e-8, 1), 1.0, 0.0);
}

static void test_cylinder_cone(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    cone(s, SHAPE_CYLINDER, v3(0, 0, 0), 1, v3(0, 2, 0), 1);
    scene_object *op = cone(s, SHAPE_CYLINDER, v3(10, 0, 0), 1, v3(10, 2, 0), 1);
    op->flags |= OBJ_OPEN;
    cone(s, SHAPE_CONE, v3(20, 0, 0), 1, v3(20, 2, 0), 0);
    /* a truncated cone along x, radii 1 -> 2 */
    cone(s, SHAPE_CONE, v3(30, 0, 0), 1, v3(34, 0, 0), 2);
    accel *a = build(s, d);
    accel_hit h;
    expect_hit(a, v3(-5, 1, 0), v3(1, 0, 0), 4.0, v3(-1, 0, 0), 1e-12, 1e-12, &h);
    assert_int_equal(h.prim, GEOM_PART_CONE_SIDE);
    expect_hit(a, v3(0.5, 5, 0), v3(0, -1, 0), 3.0, v3(0, 1, 0), 1e-12, 1e-12, &h);
    assert_int_equal(h.prim, GEOM_PART_CONE_CAP);
    expect_hit(a, v3(0.5, -5, 0), v3(0, 1, 0), 5.0, v3(0, -1, 0), 1e-12, 1e-12, &h);
    assert_int_equal(h.prim, GEOM_PART_CONE_BASE);
    /* from inside: the side at the exit */
    expect_hit(a, v3(0, 1, 0), v3(0, 0, 1), 1.0, v3(0, 0, 1), 1e-12, 1e-12, NULL);
    /* diagonal through side and cap: from (0,1,-3) towards (0,3,1)... enters side at z=-1, y=1.5 */
    expect_hit(a, v3(0, 1, -3), v3(0, 0.25, 1), 2.0, v3(0, 0, -1), 1e-12, 1e-12, NULL);
    /* open cylinder: down the axis misses; from inside through the open end: hits nothing */
    expect_miss(a, v3(10, 5, 0), v3(0, -1, 0));
    expect_hit(a, v3(10, 1, 0), v3(1, 0, 0), 1.0, v3(1, 0, 0), 1e-12, 1e-12, NULL);
    /* cone apex up: at y = 1 the radius is 0.5; normal (-2,1,0)/sqrt5 */
    expect_hit(a, v3(15, 1, 0), v3(1, 0, 0), 4.5, v3_norm(v3(-2, 1, 0)), 1e-12, 1e-12, NULL);
    expect_hit(a, v3(20.25, -5, 0), v3(0, 1, 0), 5.0, v3(0, -1, 0), 1e-12, 1e-12, NULL);
    /* truncated cone along x: at x = 32 radius 1.5; normal (-1/4, 1, 0) normalised */
    expect_hit(a, v3(32, 5, 0), v3(0, -1, 0), 3.5, v3_norm(v3(-0.25, 1, 0)), 1e-12, 1e-12, NULL);
    expect_hit(a, v3(40, 1.5, 0), v3(-1, 0, 0), 6.0, v3(1, 0, 0), 1e-12, 1e-12, NULL);
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

static void test_disc(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    scene_object *o = add_obj(s, SHAPE_DISC);
    o->name = "disc";
    o->u.disc.centre = v3(0, 0, 3);
    o->u.disc.normal = v3(0, 0, 2);
    o->u.disc.radius = 2;
    o->u.disc.hole_radius = 0.5;
    accel *a = build(s, d);
    expect_hit(a, v3(1, 0, 0), v3(0, 0, 1), 3.0, v3(0, 0, 1), 1e-12, 1e-12, NULL);
    expect_hit(a, v3(0, -1.5, 6), v3(0, 0, -1), 3.0, v3(0, 0, 1), 1e-12, 1e-12, NULL);
    expect_miss(a, v3(0.2, 0, 0), v3(0, 0, 1)); /* hole */
    expect_miss(a, v3(2.5, 0, 0), v3(0, 0, 1)); /* outside */
    expect_miss(a, v3(0, 0, 0), v3(1, 0, 0));   /* parallel */
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

static void test_torus(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    scene_object *o = add_obj(s, SHAPE_TORUS);
    o->name = "torus";
    o->u.torus.major = 2;
    o->u.torus.minor = 0.5;
    /* a second torus, rotated to stand in the xy plane, moved to z = 10 */
    scene_object *o2 = add_obj(s, SHAPE_TORUS);
    o2->u.torus.major = 2;
    o2->u.torus.minor = 0.5;
    o2->transform = xform_then(xform_rotate(v3(90, 0, 0)), xform_translate(v3(0, 0, 10)));
    accel *a = build(s, d);
    accel_hit h;
    expect_hit(a, v3(-5, 0, 0), v3(1, 0, 0), 2.5, v3(-1, 0, 0), 1e-10, 1e-10, NULL);
    assert_true(accel_intersect(a, v3(-5, 0, 0), v3(1, 0, 0), 3.0, INFINITY, &h));
    assert_near(h.t, 3.5, 1e-10);
    assert_vec(h.ng, v3(1, 0, 0), 1e-10);
    assert_true(accel_intersect(a, v3(-5, 0, 0), v3(1, 0, 0), 4.0, INFINITY, &h));
    assert_near(h.t, 6.5, 1e-10);
    assert_true(accel_intersect(a, v3(-5, 0, 0), v3(1, 0, 0), 7.0, INFINITY, &h));
    assert_near(h.t, 7.5, 1e-10);
    assert_false(accel_intersect(a, v3(-5, 0, 0), v3(1, 0, 0), 8.0, INFINITY, &h));
    /* from above onto the tube */
    expect_hit(a, v3(2, 5, 0), v3(0, -1, 0), 4.5, v3(0, 1, 0), 1e-10, 1e-10, NULL);
    /* 45 degrees onto the tube top at x = z = sqrt2 */
    double c = sqrt(2.0);
    expect_hit(a, v3(c, 3, c), v3(0, -1, 0), 2.5, v3(0, 1, 0), 1e-10, 1e-10, NULL);
    /* through the hole: miss */
    expect_miss(a, v3(0, 5, 0), v3(0, -1, 0));
    /* rotated torus: axis along z at z = 10; ray along -z at x = 2 hits the tube top (z = 10.5) */
    expect_hit(a, v3(2, 0, 20), v3(0, 0, -1), 9.5, v3(0, 0, 1), 1e-10, 1e-10, &h);
    assert_ptr_equal(h.obj, o2);
    /* tangent rays along y = 0.5 (touching the tube top): no NaN, consistent */
    for (int i = -4; i <= 4; i++) {
        double y = 0.5 + i * 1e-9;
        int hit = accel_intersect(a, v3(-5, y, 0), v3(1, 0, 0), 0.0, INFINITY, &h);
        if (hit) assert_hit_sane(&h);
        if (i > 0) assert_false(hit);
        if (i < 0) assert_true(hit);
    }
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

static void test_poly_roots(void **st)
{
    (void)st;
    /* (x-1)(x-2)(x-3)(x-4) = x^4 - 10x^3 + 35x^2 - 50x + 24 */
    double c[5] = {24, -50, 35, -10, 1}, r[4];
    int n = geom_poly_roots(c, 4, 0.0, 5.0, r);
    assert_int_equal(n, 4);
    for (int i = 0; i < 4; i++) assert_near(r[i], i + 1.0, 1e-12);
    assert_int_equal(geom_poly_roots(c, 4, 1.5, 3.5, r), 2);
    assert_near(r[0], 2.0, 1e-12);
    /* (x^2 + 1)(x^2 + 2): no real roots */
    double c2[5] = {2, 0, 3, 0, 1};
    assert_int_equal(geom_poly_roots(c2, 4, -10, 10, r), 0);
    /* close roots 1 and 1 + 1e-6 */
    double e = 1e-6;
    double c3[3] = {1 + e, -(2 + e), 1};
    double c4[5] = {0, 0, c3[0], c3[1], c3[2]}; /* x^2 (x-1)(x-1-e) */
    n = geom_poly_roots(c4, 4, 0.5, 2.0, r);
    assert_int_equal(n, 2);
    assert_near(r[0], 1.0, 1e-9);
    assert_near(r[1], 1.0 + e, 1e-9);
}

/* ------------------------------------------------------------ robustness */

static void test_grazing_sphere(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    sphere(s, v3(0, 0, 0), 1);
    accel *a = build(s, d);
    accel_hit h;
    /* exactly tangent: a hit must be at t = 5 with a sane normal */
    if (accel_intersect(a, v3(1, 0, -5), v3(0, 0, 1), 0.0, INFINITY, &h)) {
        assert_hit_sane(&h);
        assert_near(h.t, 5.0, 1e-6);
    }
    /* offsets around the tangent: hit inside, miss outside, never NaN */
    int prev = 1;
    for (int i = -20; i <= 20; i++) {
        double x = 1.0 + i * 1e-13;
        int hit = accel_intersect(a, v3(x, 0, -5), v3(0, 0, 1), 0.0, INFINITY, &h);
        if (hit) assert_hit_sane(&h);
        if (i < -2) assert_true(hit);
        if (i > 2) assert_false(hit);
        assert_true(hit <= prev); /* monotonic: once missing, stays missing */
        prev = hit;
        assert_int_equal(accel_occluded(a, v3(x, 0, -5), v3(0, 0, 1), 0.0, INFINITY), hit);
    }
    /* degenerate rays: no hit, no crash */
    assert_false(accel_intersect(a, v3(0, 0, -5), v3(0, 0, 0), 0.0, INFINITY, &h));
    assert_false(accel_intersect(a, v3(NAN, 0, -5), v3(0, 0, 1), 0.0, INFINITY, &h));
    assert_false(accel_intersect(a, v3(0, 0, -5), v3(0, INFINITY, 1), 0.0, INFINITY, &h));
    assert_false(accel_intersect(a, v3(0, 0, -5), v3(0, 0, 1), 0.0, NAN, &h));
    assert_false(accel_occluded(a, v3(0, 0, -5), v3(0, 0, 0), 0.0, INFINITY));
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

/* For every kind: hit it, then leave the surface along directions on the
 * outer side (no self-hit), and into the solid (no hit at t ~ 0). */
static void test_no_self_hit(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    sphere(s, v3(0, 0, 0), 1);
    box(s, v3(4, -1, -1), v3(6, 1, 1));
    cone(s, SHAPE_CYLINDER, v3(10, -1, 0), 1, v3(10, 1, 0), 1);
    cone(s, SHAPE_CONE, v3(15, -1, 0), 1, v3(15, 1, 0), 0.2);
    scene_object *t = add_obj(s, SHAPE_TORUS);
    t->u.torus.major = 1;
    t->u.torus.minor = 0.4;
    t->transform = xform_then(xform_rotate(v3(90, 0, 0)), xform_translate(v3(20, 0, 0)));
    scene_object *dc = add_obj(s, SHAPE_DISC);
    dc->u.disc.centre = v3(25, 0, 0);
    dc->u.disc.normal = v3(0, 0, 1);
    dc->u.disc.radius = 1;
    triangle(s, v3(29, -1, 0), v3(31, -1, 0), v3(30, 1, 0));
    scene_mesh *m = quad_mesh(s, NULL, NULL);
    mesh_obj(s, m, xform_translate(v3(34, 0, 0)));
    mesh_obj(s, m, xform_translate(v3(38, 0, 0)));
    accel *a = build(s, d);
    double xs[] = {0, 5, 10, 15, 20.0 + 1.0, 25.3, 30, 34.5, 38.5};
    double ys[] = {0.1, 0.2, 0.3, 0.1, 0.0, 0.2, 0.0, 0.5, 0.5};
    rng r;
    rng_seed(&r, 7, 1);
    for (int k = 0; k < (int)(sizeof xs / sizeof xs[0]); k++) {
        vec3 org = v3(xs[k] + 0.05, ys[k], -10);
        accel_hit h;
        assert_true(accel_intersect(a, org, v3(0, 0.001, 1), 0.0, INFINITY, &h));
        assert_hit_sane(&h);
        vec3 n = v3_dot(h.ng, v3(0, 0.001, 1)) < 0 ? h.ng : v3_neg(h.ng); /* towards the ray origin */
        for (int j = 0; j < 200; j++) {
            vec3 t, b;
            v3_basis(n, &t, &b);
            double phi = 6.283185307179586 * rng_f64(&r);
            double ct = 0.02 + 0.98 * rng_f64(&r); /* at least ~1 degree above the tangent plane */
            double stt = sqrt(1 - ct * ct);
            vec3 dir = v3_add(v3_scale(n, ct), v3_add(v3_scale(t, stt * cos(phi)), v3_scale(b, stt * sin(phi))));
            accel_hit h2;
            if (accel_intersect(a, h.p, dir, 0.0, INFINITY, &h2)) {
                /* the only thing allowed is another part of a non-convex shape, far away */
                if (h2.obj == h.obj && h2.t < 1e-3)
                    fail_msg("self-hit on object %d at t=%g (n.d=%g)", k, h2.t, ct);
            }
            if (accel_occluded(a, h.p, dir, 0.0, 1e-3)) fail_msg("self-occlusion on object %d", k);
        }
    }
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

/* The same scene at three scales: distances scale exactly (relative error < 1e-5). */
static scene *scaled_scene(double k)
{
    scene *s = scene_new();
    sphere(s, v3(0, 0, 5 * k), 1 * k);
    box(s, v3(3 * k, -1 * k, 4 * k), v3(5 * k, 1 * k, 6 * k));
    triangle(s, v3(-4 * k, -1 * k, 5 * k), v3(-2 * k, -1 * k, 6 * k), v3(-3 * k, 1 * k, 5.5 * k));
    cone(s, SHAPE_CYLINDER, v3(8 * k, -1 * k, 5 * k), 1 * k, v3(8 * k, 1 * k, 5 * k), 1 * k);
    scene_object *t = add_obj(s, SHAPE_TORUS);
    t->u.torus.major = 1 * k;
    t->u.torus.minor = 0.25 * k;
    t->transform = xform_then(xform_rotate(v3(70, 0, 0)), xform_translate(v3(-8 * k, 0, 5 * k)));
    scene_mesh *m = quad_mesh(s, NULL, NULL);
    mesh_obj(s, m, xform_then(xform_scale(v3s(2 * k)), xform_translate(v3(11 * k, -1 * k, 6 * k))));
    mesh_obj(s, m, xform_then(xform_scale(v3s(2 * k)), xform_translate(v3(14 * k, -1 * k, 7 * k))));
    scene_object *p = add_obj(s, SHAPE_PLANE);
    p->u.plane.normal = v3(0, 0, 1);
    p->u.plane.offset = 20 * k;
    return s;
}

static void test_scales(void **st)
{
    (void)st;
    double scales[3] = {1e-4, 1.0, 1e5};
    double ref[64];
    int nref = 0;
    diag *d = diag_new();
    for (int si = 0; si < 3; si++) {
        double k = scales[si];
        scene *s = scaled_scene(k);
        accel *a = build(s, d);
        assert_near(accel_scale(a) / k, accel_scale(a) / k, 0); /* finite */
        int n = 0;
        for (int ix = 0; ix < 32; ix++) {
            double x = -9.5 + ix * (25.0 / 31.0);
            vec3 org = v3(0.1 * k, 0.13 * k, -3 * k);
            vec3 tgt = v3(x * k, 0.2 * k, 5 * k);
            vec3 dir = v3_norm(v3_sub(tgt, org));
            accel_hit h;
            int hit = accel_intersect(a, org, dir, 0.0, INFINITY, &h);
            assert_true(hit); /* everything ends on the back plane at worst */
            assert_hit_sane(&h);
            double tn = h.t / k;
            if (si == 0) {
                ref[n] = tn;
            } else if (fabs(tn - ref[n]) > 1e-5 * ref[n]) {
                fail_msg("scale %g ray %d: t/k = %.12g, at scale 1e-4: %.12g", k, ix, tn, ref[n]);
            }
            n++;
        }
        nref = n;
        accel_free(a);
        scene_free(s);
    }
    assert_int_equal(nref, 32);
    diag_free(d);
}

static void test_no_shadow(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    /* blockers between z = 0 and z = 10 at different x */
    scene_object *sp = sphere(s, v3(0, 0, 5), 1);
    sp->flags |= OBJ_NO_SHADOW;
    scene_object *tr = triangle(s, v3(2, -1, 5), v3(4, -1, 5), v3(3, 1, 5));
    tr->flags |= OBJ_NO_SHADOW;
    triangle(s, v3(5, -1, 5), v3(7, -1, 5), v3(6, 1, 5)); /* casts shadows */
    scene_mesh *m = quad_mesh(s, NULL, NULL);
    scene_object *mi = mesh_obj(s, m, xform_translate(v3(8, -0.5, 5)));
    mi->flags |= OBJ_NO_SHADOW;
    mesh_obj(s, m, xform_translate(v3(10, -0.5, 5))); /* casts shadows */
    /* a union flagged no_shadow: its child box inherits it */
    scene_object *u = add_obj(s, SHAPE_UNION);
    u->flags |= OBJ_NO_SHADOW;
    scene_object *kid = scene_new_object(s, SHAPE_BOX, here);
    kid->u.box.c1 = v3(12, -1, 4);
    kid->u.box.c2 = v3(13, 1, 6);
    u->u.csg.kids = arena_alloc(s->mem, sizeof(scene_object *));
    u->u.csg.kids[0] = kid;
    u->u.csg.nkids = 1;
    sphere(s, v3(15, 0, 5), 1); /* casts shadows */
    accel *a = build(s, d);
    double x[7] = {0, 3, 6, 8.5, 10.5, 12.5, 15};
    int occl[7] = {0, 0, 1, 0, 1, 0, 1};
    for (int i = 0; i < 7; i++) {
        vec3 org = v3(x[i], 0, 0), dir = v3(0, 0, 1);
        accel_hit h;
        assert_true(accel_intersect(a, org, dir, 0.0, 10.0, &h)); /* visible to camera rays */
        assert_int_equal((h.flags & OBJ_NO_SHADOW) != 0, !occl[i]); /* inherited flags reported */
        assert_int_equal(accel_occluded(a, org, dir, 0.0, 10.0), occl[i]);
        /* the bare Embree scene honours it too (filters live in the scene) */
    }
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

static scene_object *csg(scene *s, shape_kind k, int n, int top)
{
    scene_object *o = top ? add_obj(s, k) : scene_new_object(s, k, here);
    o->name = k == SHAPE_DIFFERENCE ? "difference" : k == SHAPE_INTERSECTION ? "intersection" : "union";
    o->u.csg.kids = arena_alloc(s->mem, (size_t)n * sizeof(scene_object *));
    o->u.csg.nkids = n;
    return o;
}

static scene_object *member(scene *s, shape_kind k)
{
    scene_object *o = scene_new_object(s, k, here);
    o->name = k == SHAPE_SPHERE ? "sphere" : k == SHAPE_BOX ? "box" : k == SHAPE_PLANE ? "plane" : "shape";
    return o;
}

static scene_object *msphere(scene *s, vec3 c, double r)
{
    scene_object *o = member(s, SHAPE_SPHERE);
    o->u.sphere.centre = c;
    o->u.sphere.radius = r;
    return o;
}

static scene_object *mplane(scene *s, vec3 n, double off)
{
    scene_object *o = member(s, SHAPE_PLANE);
    o->u.plane.normal = n;
    o->u.plane.offset = off;
    return o;
}

static void test_warnings_csg(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    for (int i = 0; i < 2; i++) {
        scene_object *o = add_obj(s, SHAPE_UNSUPPORTED);
        o->name = "lathe";
    }
    scene_object *o = add_obj(s, SHAPE_UNSUPPORTED);
    o->name = "sor";
    /* a difference whose subtracted member is unsupported: warned, the base stays whole */
    scene_texture *tx = scene_new_texture(s);
    scene_object *df = csg(s, SHAPE_DIFFERENCE, 2, 1);
    df->texture = tx;
    df->u.csg.kids[0] = msphere(s, v3(10, 0, 5), 1);
    df->u.csg.kids[1] = member(s, SHAPE_UNSUPPORTED);
    df->u.csg.kids[1]->name = "lathe";
    /* a difference with a mesh member: rendered as a union, with one warning */
    scene_mesh *m = quad_mesh(s, NULL, NULL);
    for (int i = 0; i < 2; i++) {
        scene_object *dm = csg(s, SHAPE_DIFFERENCE, 2, 1);
        dm->u.csg.kids[0] = msphere(s, v3(20 + 5 * i, 0, 5), 1);
        scene_object *mo = scene_new_object(s, SHAPE_MESH, here);
        mo->u.mesh.mesh = m;
        mo->transform = xform_translate(v3(20 + 5 * i, 0, 5));
        m->uses++;
        dm->u.csg.kids[1] = mo;
    }
    accel *a = build(s, d);
    int lathe = 0, sor = 0, csgw = 0;
    for (int i = 0; i < diag_count(d); i++) {
        const diag_msg *dm = diag_get(d, i);
        assert_int_equal(dm->severity, DIAG_WARNING);
        if (strstr(dm->text, "lathe is not rendered yet")) lathe++;
        if (strstr(dm->text, "sor is not rendered yet")) sor++;
        if (strstr(dm->text, "with a mesh member is not evaluated yet")) csgw++;
    }
    assert_int_equal(lathe, 1);
    assert_int_equal(sor, 1);
    assert_int_equal(csgw, 1);
    assert_int_equal(accel_get_stats(a).unsupported, 4);
    accel_hit h;
    /* the base sphere, whole, with the difference's texture */
    expect_hit(a, v3(10, 0, 0), v3(0, 0, 1), 4.0, v3(0, 0, -1), 1e-12, 1e-12, &h);
    assert_ptr_equal(h.texture, tx);
    /* the union fallback: the mesh quad at z = 5 in front of the sphere's back */
    expect_hit(a, v3(20.5, 0.5, 0), v3(0, 0, 1), 5.0 - sqrt(1 - 0.5), v3_norm(v3(0.5, 0.5, -sqrt(0.5))), 1e-9,
               1e-9, NULL);
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

/* accel_crossings: every crossing in order, the same from the one-traversal
 * walk (analytic shapes only) and from the per-crossing loop (a triangle in
 * the scene); closed-form distances along +z. */
typedef struct {
    double t[16];
    int n, stop_after;
} crossing_log;

static int log_crossing(void *ctx, const accel_hit *h)
{
    crossing_log *l = ctx;
    assert_hit_sane(h);
    if (l->n < 16) l->t[l->n] = h->t;
    l->n++;
    return l->stop_after <= 0 || l->n < l->stop_after;
}

static void test_crossings(void **st)
{
    (void)st;
    for (int with_tri = 0; with_tri < 2; with_tri++) {
        scene *s = scene_new();
        diag *d = diag_new();
        sphere(s, v3(0, 0, 5), 1);                 /* 4, 6 */
        box(s, v3(-1, -1, 8), v3(1, 1, 9));        /* 8, 9 */
        scene_object *ns = sphere(s, v3(0, 0, 12), 0.5); /* 11.5, 12.5; no_shadow */
        ns->flags |= OBJ_NO_SHADOW;
        /* a hollow ball (geom_csg_crossings' one search per member): 14, 14.5, 15.5, 16 */
        scene_object *hb = csg(s, SHAPE_DIFFERENCE, 2, 1);
        hb->u.csg.kids[0] = msphere(s, v3(0, 0, 15), 1);
        hb->u.csg.kids[1] = msphere(s, v3(0, 0, 15), 0.5);
        if (with_tri) triangle(s, v3(-1, -1, 7), v3(3, -1, 7), v3(-1, 3, 7)); /* 7 */
        accel *a = build(s, d);
        const double all[2][11] = {{4, 6, 8, 9, 11.5, 12.5, 14, 14.5, 15.5, 16},
                                   {4, 6, 7, 8, 9, 11.5, 12.5, 14, 14.5, 15.5, 16}};
        int n = with_tri ? 11 : 10;
        crossing_log l = {{0}, 0, 0};
        assert_int_equal(accel_crossings(a, v3(0, 0, 0), v3(0, 0, 1), 0.0, INFINITY, 1e-6, log_crossing, &l), n);
        assert_int_equal(l.n, n);
        for (int i = 0; i < n; i++) assert_near(l.t[i], all[with_tri][i], 1e-9);
        /* the interval: (5, 11.5) leaves 6 (7) 8 9 */
        l = (crossing_log){{0}, 0, 0};
        accel_crossings(a, v3(0, 0, 0), v3(0, 0, 1), 5.0, 11.5, 1e-6, log_crossing, &l);
        assert_int_equal(l.n, with_tri ? 4 : 3);
        assert_near(l.t[0], 6.0, 1e-9);
        assert_near(l.t[l.n - 1], 9.0, 1e-9);
        /* stopping: fn's 0 ends the walk */
        l = (crossing_log){{0}, 0, 2};
        assert_int_equal(accel_crossings(a, v3(0, 0, 0), v3(0, 0, 1), 0.0, INFINITY, 1e-6, log_crossing, &l), 2);
        assert_near(l.t[1], 6.0, 1e-9);
        /* a step longer than a gap passes the crossing inside it: each
         * next crossing is at least 1.5 further, so 9 (after 8), 12.5
         * (after 11.5), 14.5 and 15.5 (after 14) are passed */
        l = (crossing_log){{0}, 0, 0};
        accel_crossings(a, v3(0, 0, 0), v3(0, 0, 1), 7.5, INFINITY, 1.5, log_crossing, &l);
        assert_int_equal(l.n, 4);
        assert_near(l.t[0], 8.0, 1e-9);
        assert_near(l.t[1], 11.5, 1e-9);
        assert_near(l.t[2], 14.0, 1e-9);
        assert_near(l.t[3], 16.0, 1e-9);
        /* skipping no_shadow objects: 11.5 and 12.5 are not reported, and
         * with a step of 1.5 the crossing after 9 is 14 */
        l = (crossing_log){{0}, 0, 0};
        assert_int_equal(accel_crossings_skip(a, v3(0, 0, 0), v3(0, 0, 1), 0.0, INFINITY, 1e-6, OBJ_NO_SHADOW,
                                              log_crossing, &l), n - 2);
        for (int i = 0, j = 0; i < n; i++)
            if (all[with_tri][i] != 11.5 && all[with_tri][i] != 12.5) assert_near(l.t[j++], all[with_tri][i], 1e-9);
        l = (crossing_log){{0}, 0, 0};
        accel_crossings_skip(a, v3(0, 0, 0), v3(0, 0, 1), 8.5, INFINITY, 1.5, OBJ_NO_SHADOW, log_crossing, &l);
        assert_int_equal(l.n, 3);
        assert_near(l.t[0], 9.0, 1e-9);
        assert_near(l.t[1], 14.0, 1e-9);
        assert_near(l.t[2], 16.0, 1e-9);
        accel_free(a);
        diag_free(d);
        scene_free(s);
    }
}

static void test_csg(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    scene_texture *ta = scene_new_texture(s), *tb = scene_new_texture(s);
    /* 1. sphere minus a sphere biting its front */
    scene_object *d1 = csg(s, SHAPE_DIFFERENCE, 2, 1);
    d1->texture = ta;
    d1->u.csg.kids[0] = msphere(s, v3(0, 0, 5), 1);
    d1->u.csg.kids[1] = msphere(s, v3(0, 0, 4), 1);
    d1->u.csg.kids[1]->texture = tb;
    /* 2. box intersected with a sphere */
    scene_object *i2 = csg(s, SHAPE_INTERSECTION, 2, 1);
    i2->u.csg.kids[0] = member(s, SHAPE_BOX);
    i2->u.csg.kids[0]->u.box.c1 = v3(-1, -1, -1);
    i2->u.csg.kids[0]->u.box.c2 = v3(1, 1, 1);
    i2->u.csg.kids[1] = msphere(s, v3(0, 0, 0), 1.2);
    i2->transform = xform_translate(v3(10, 0, 5));
    for (int k = 0; k < 2; k++) i2->u.csg.kids[k]->transform = xform_translate(v3(10, 0, 5));
    /* 3. box minus the half-space y < 0 (plane): the top half */
    scene_object *d3 = csg(s, SHAPE_DIFFERENCE, 2, 1);
    d3->u.csg.kids[0] = member(s, SHAPE_BOX);
    d3->u.csg.kids[0]->u.box.c1 = v3(19, -1, 4);
    d3->u.csg.kids[0]->u.box.c2 = v3(21, 1, 6);
    d3->u.csg.kids[1] = mplane(s, v3(0, 1, 0), 0);
    /* 4. a shell: big sphere intersected with an inverse small one */
    scene_object *i4 = csg(s, SHAPE_INTERSECTION, 2, 1);
    i4->u.csg.kids[0] = msphere(s, v3(30, 0, 5), 2);
    i4->u.csg.kids[1] = msphere(s, v3(30, 0, 5), 1);
    i4->u.csg.kids[1]->flags |= OBJ_INVERSE;
    /* 5. a triangle with a hole */
    scene_object *d5 = csg(s, SHAPE_DIFFERENCE, 2, 1);
    scene_object *tri = member(s, SHAPE_TRIANGLE);
    tri->u.triangle.v[0] = v3(37, -3, 5);
    tri->u.triangle.v[1] = v3(43, -3, 5);
    tri->u.triangle.v[2] = v3(40, 3, 5);
    d5->u.csg.kids[0] = tri;
    d5->u.csg.kids[1] = msphere(s, v3(40, 0, 5), 0.5);
    /* 6. a cube from six planes, no_shadow */
    scene_object *i6 = csg(s, SHAPE_INTERSECTION, 6, 1);
    i6->flags |= OBJ_NO_SHADOW;
    for (int k = 0; k < 6; k++) {
        vec3 n = v3(k / 2 == 0 ? 1 : 0, k / 2 == 1 ? 1 : 0, k / 2 == 2 ? 1 : 0);
        if (k & 1) n = v3_neg(n);
        i6->u.csg.kids[k] = mplane(s, n, 1.0);
    }
    i6->transform = xform_translate(v3(50, 0, 5));
    for (int k = 0; k < 6; k++) i6->u.csg.kids[k]->transform = xform_translate(v3(50, 0, 5));
    /* 7. merge nested in an intersection with a big box: no internal surface */
    accel_hit h;
    scene_object *i7 = csg(s, SHAPE_INTERSECTION, 2, 1);
    scene_object *mg = csg(s, SHAPE_UNION, 2, 0);
    mg->kind = SHAPE_MERGE;
    mg->u.csg.kids[0] = msphere(s, v3(60, 0, 5), 1);
    mg->u.csg.kids[1] = msphere(s, v3(60, 0, 6), 1);
    i7->u.csg.kids[0] = mg;
    i7->u.csg.kids[1] = member(s, SHAPE_BOX);
    i7->u.csg.kids[1]->u.box.c1 = v3(50, -10, -10);
    i7->u.csg.kids[1]->u.box.c2 = v3(70, 10, 20);
    /* 8. a top-level merge: its internal surfaces are gone too */
    scene_object *m8 = csg(s, SHAPE_UNION, 2, 1);
    m8->kind = SHAPE_MERGE;
    m8->u.csg.kids[0] = msphere(s, v3(70, 0, 5), 1);
    m8->u.csg.kids[1] = msphere(s, v3(70, 0, 6), 1);
    /* 9. a merge of 300 spheres (more leaves than grenadine.pov's liquid,
     * 243) is one CSG too: along the row of centres only its first
     * member's front and its last member's back are surfaces */
    scene_object *m9 = csg(s, SHAPE_UNION, 300, 1);
    m9->kind = SHAPE_MERGE;
    for (int k = 0; k < 300; k++) m9->u.csg.kids[k] = msphere(s, v3(65, 0, 5 + 0.003 * k), 0.5);
    accel *a = build(s, d);
    assert_int_equal(diag_count(d), 0);
    assert_int_equal(accel_get_stats(a).user_prims, 9);
    expect_hit(a, v3(65, 0, 0), v3(0, 0, 1), 4.5, v3(0, 0, -1), 1e-12, 1e-12, NULL);
    assert_true(accel_intersect(a, v3(65, 0, 0), v3(0, 0, 1), 4.6, INFINITY, &h));
    assert_near(h.t, 5.0 + 0.003 * 299 + 0.5, 1e-9);
    expect_hit(a, v3(70, 0, 0), v3(0, 0, 1), 4.0, v3(0, 0, -1), 1e-12, 1e-12, NULL);
    assert_true(accel_intersect(a, v3(70, 0, 0), v3(0, 0, 1), 4.5, INFINITY, &h));
    assert_near(h.t, 7.0, 1e-12);
    /* 1: the bite's far side at z = 5, normal flipped towards the ray, the bite's texture */
    expect_hit(a, v3(0, 0, 0), v3(0, 0, 1), 5.0, v3(0, 0, -1), 1e-12, 1e-12, &h);
    assert_ptr_equal(h.texture, tb);
    assert_true(accel_intersect(a, v3(0, 0, 0), v3(0, 0, 1), 5.5, INFINITY, &h));
    assert_near(h.t, 6.0, 1e-12);
    assert_vec(h.ng, v3(0, 0, 1), 1e-12);
    assert_ptr_equal(h.texture, ta);
    /* outside the bite (x = 0.9: A at z = 5 - sqrt(.19), B's reach ends at sqrt(1-.81)) */
    expect_hit(a, v3(0.9, 0, 0), v3(0, 0, 1), 5 - sqrt(0.19), v3(0.9, 0, -sqrt(0.19)), 1e-12, 1e-12, NULL);
    /* 2: box face inside the sphere; sphere inside the box */
    expect_hit(a, v3(10, 0, 0), v3(0, 0, 1), 4.0, v3(0, 0, -1), 1e-12, 1e-12, NULL);
    double zs = sqrt(1.44 - 0.64);
    expect_hit(a, v3(10.8, 0, 0), v3(0, 0, 1), 5.0 - zs, v3(0.8 / 1.2, 0, -zs / 1.2), 1e-12, 1e-12, NULL);
    expect_miss(a, v3(10.9, 0.9, 0), v3(0, 0, 1));
    /* 3: from below, the cut face at y = 0 with the flipped plane normal; from above the box top */
    expect_hit(a, v3(20, -5, 5), v3(0, 1, 0), 5.0, v3(0, -1, 0), 1e-12, 1e-12, NULL);
    expect_hit(a, v3(20, 5, 5), v3(0, -1, 0), 4.0, v3(0, 1, 0), 1e-12, 1e-12, NULL);
    assert_false(accel_intersect(a, v3(15, -0.5, 5), v3(1, 0, 0), 0.0, 10.0, &h)); /* through the removed half */
    /* 4: from the centre of the shell: the inner wall at r = 1, normal towards the centre */
    expect_hit(a, v3(30, 0, 5), v3(1, 0, 0), 1.0, v3(-1, 0, 0), 1e-12, 1e-12, NULL);
    expect_hit(a, v3(30, 0, 0), v3(0, 0, 1), 3.0, v3(0, 0, -1), 1e-12, 1e-12, NULL);
    /* 5: triangle hole: through the hole we see the hole's edge? no: the sphere surface is kept only inside the
     * triangle, which has no inside, so the hole is empty */
    expect_miss(a, v3(40, 0, 0), v3(0, 0, 1));
    expect_hit(a, v3(40, 1, 0), v3(0, 0, 1), 5.0, v3(0, 0, 1), 1e-12, 1e-12, NULL);
    /* 6: plane cube: bounded, visible, no shadow */
    expect_hit(a, v3(50, 0, 0), v3(0, 0, 1), 4.0, v3(0, 0, -1), 1e-12, 1e-12, NULL);
    expect_hit(a, v3(50.5, -10, 5.5), v3(0, 1, 0), 9.0, v3(0, -1, 0), 1e-12, 1e-12, NULL);
    assert_false(accel_occluded(a, v3(50, 0, 0), v3(0, 0, 1), 0.0, 10.0));
    assert_true(accel_occluded(a, v3(0, 0, 0), v3(0, 0, 1), 0.0, 10.0));
    /* 7: merged spheres: the front one's back (z = 6) is inside the other: not a surface */
    expect_hit(a, v3(60, 0, 0), v3(0, 0, 1), 4.0, v3(0, 0, -1), 1e-12, 1e-12, NULL);
    assert_true(accel_intersect(a, v3(60, 0, 0), v3(0, 0, 1), 4.5, INFINITY, &h));
    assert_near(h.t, 7.0, 1e-12);
    /* bounds are finite: the plane cube is [49,51]x[-1,1]x[4,6] */
    vec3 lo, hi;
    accel_bounds(a, &lo, &hi);
    assert_true(v3_finite(lo) && v3_finite(hi));
    assert_near(hi.x, 71.0, 1e-9); /* the merge m8; i7 is bounded by its merge, not by its big box (x <= 70) */
    assert_near(lo.x, -1.0, 1e-9);
    assert_near(hi.z, 7.0, 1e-9);
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

/* An inverse union inside an intersection: POV-Ray inverts a CSG by De
 * Morgan (the union becomes an intersection of its inverted members), so a
 * member's surface inside another member is no surface. A box with a
 * cavity of two overlapping spheres (centres x = -0.5 and 0.5, radius 1):
 * from the centre along +x the first wall is the right sphere's at x = 1.5
 * (the left sphere's wall at x = 0.5 lies inside the right one); the same
 * cavity written as difference{box, union} (POV-Ray: an intersection with
 * the union inverted) gives the same. The qtvr panorama example (camera
 * inside such a box) differed by 0.059 from POV-Ray before this. */
static void test_csg_inverse_union(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    for (int k = 0; k < 2; k++) {
        double x0 = 10.0 * k;
        scene_object *i = csg(s, k == 0 ? SHAPE_INTERSECTION : SHAPE_DIFFERENCE, 2, 1);
        i->u.csg.kids[0] = member(s, SHAPE_BOX);
        i->u.csg.kids[0]->u.box.c1 = v3(x0 - 3, -3, -3);
        i->u.csg.kids[0]->u.box.c2 = v3(x0 + 3, 3, 3);
        scene_object *u = csg(s, SHAPE_UNION, 2, 0);
        u->u.csg.kids[0] = msphere(s, v3(x0 - 0.5, 0, 0), 1);
        u->u.csg.kids[1] = msphere(s, v3(x0 + 0.5, 0, 0), 1);
        if (k == 0) u->flags |= OBJ_INVERSE;
        i->u.csg.kids[1] = u;
    }
    accel *a = build(s, d);
    assert_int_equal(diag_count(d), 0);
    for (int k = 0; k < 2; k++) {
        double x0 = 10.0 * k;
        /* the wall faces the cavity: normal towards the ray's origin */
        expect_hit(a, v3(x0, 0, 0), v3(1, 0, 0), 1.5, v3(-1, 0, 0), 1e-12, 1e-12, NULL);
        expect_hit(a, v3(x0, 0, 0), v3(-1, 0, 0), 1.5, v3(1, 0, 0), 1e-12, 1e-12, NULL);
        /* from outside the box: its face */
        expect_hit(a, v3(x0, 0, -10), v3(0, 0, 1), 7.0, v3(0, 0, -1), 1e-12, 1e-12, NULL);
    }
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

/* CSG against brute force: a lens (intersection of two spheres) minus a
 * cylinder; the first change of the inside state along the ray (sampled)
 * must agree with the reported hit. */
static int lens_inside(vec3 p)
{
    double a = v3_len2(v3_sub(p, v3(0, 0, -0.5))), b = v3_len2(v3_sub(p, v3(0, 0, 0.5)));
    int lens = a < 1.0 && b < 1.0;
    int cyl = p.x * p.x + p.z * p.z < 0.09 && p.y > -2 && p.y < 2;
    return lens && !cyl;
}

static void test_csg_brute(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    scene_object *df = csg(s, SHAPE_DIFFERENCE, 2, 1);
    scene_object *in = csg(s, SHAPE_INTERSECTION, 2, 0);
    in->u.csg.kids[0] = msphere(s, v3(0, 0, -0.5), 1);
    in->u.csg.kids[1] = msphere(s, v3(0, 0, 0.5), 1);
    df->u.csg.kids[0] = in;
    scene_object *cy = member(s, SHAPE_CYLINDER);
    cy->u.cone.base = v3(0, -2, 0);
    cy->u.cone.cap = v3(0, 2, 0);
    cy->u.cone.base_radius = cy->u.cone.cap_radius = 0.3;
    df->u.csg.kids[1] = cy;
    accel *a = build(s, d);
    rng r;
    rng_seed(&r, 3, 4);
    int hits = 0;
    for (int i = 0; i < 3000; i++) {
        vec3 org = v3(4 * rng_f64(&r) - 2, 4 * rng_f64(&r) - 2, 4 * rng_f64(&r) - 2);
        vec3 tgt = v3(1.6 * rng_f64(&r) - 0.8, 1.6 * rng_f64(&r) - 0.8, 1.2 * rng_f64(&r) - 0.6);
        vec3 dir = v3_norm(v3_sub(tgt, org));
        accel_hit h;
        int hit = accel_intersect(a, org, dir, 0.0, 10.0, &h);
        double tend = hit ? h.t : 10.0;
        if (hit) {
            hits++;
            assert_hit_sane(&h);
            /* the normal points out of the solid */
            assert_false(lens_inside(v3_madd(h.p, h.ng, 1e-6)));
        }
        double t0 = 2.0 * accel_epsilon(a, org, dir); /* crossings closer than this are skipped by design */
        int s0 = lens_inside(v3_madd(org, dir, t0));
        for (double t = t0 + 1e-3; t < tend - 1e-6; t += 1e-3)
            if (lens_inside(v3_madd(org, dir, t)) != s0)
                fail_msg("ray %d: inside state changes at t~%g before the reported %s %g", i, t, hit ? "hit" : "end",
                         tend);
        if (hit) {
            int before = lens_inside(v3_madd(org, dir, h.t - 1e-7)), after = lens_inside(v3_madd(org, dir, h.t + 1e-7));
            if (before == after) fail_msg("ray %d: no state change at the hit t=%g", i, h.t);
        }
    }
    assert_true(hits > 300);
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

static void test_empty_and_errors(void **st)
{
    (void)st;
    diag *d = diag_new();
    scene *s = scene_new();
    accel *a = build(s, d);
    accel_hit h;
    assert_false(accel_intersect(a, v3(0, 0, 0), v3(0, 0, 1), 0.0, INFINITY, &h));
    assert_false(accel_occluded(a, v3(0, 0, 0), v3(0, 0, 1), 0.0, INFINITY));
    assert_near(accel_scale(a), 1.0, 0);
    accel_free(a);
    /* degenerate objects are skipped with a warning */
    sphere(s, v3(0, 0, 0), 0);
    scene_object *o = sphere(s, v3(0, 0, 0), 1);
    o->transform = xform_scale(v3(1, 0, 1));
    triangle(s, v3(0, 0, 0), v3(1, 0, 0), v3(2, 0, 0)); /* collinear: never hit */
    a = build(s, d);
    assert_false(accel_intersect(a, v3(0.5, 0, -1), v3(0, 0, 1), 0.0, INFINITY, &h));
    assert_true(diag_count(d) >= 1);
    accel_free(a);
    scene_free(s);
    pt_status stt = PT_OK;
    assert_null(accel_build(NULL, 1, d, &stt));
    assert_int_not_equal(stt, PT_OK);
    accel_free(NULL);
    diag_free(d);
}

/* Random rays through a mixed scene: hits are sane and agree with occlusion. */
static void test_random_rays(void **st)
{
    (void)st;
    scene *s = scaled_scene(1.0);
    diag *d = diag_new();
    accel *a = build(s, d);
    rng r;
    rng_seed(&r, 42, 3);
    for (int i = 0; i < 20000; i++) {
        vec3 org = v3(30 * rng_f64(&r) - 12, 6 * rng_f64(&r) - 3, 30 * rng_f64(&r) - 8);
        vec3 dir = v3(rng_f64(&r) - 0.5, rng_f64(&r) - 0.5, rng_f64(&r) - 0.5);
        accel_hit h;
        int hit = accel_intersect(a, org, dir, 0.0, INFINITY, &h);
        if (hit) {
            assert_hit_sane(&h);
            assert_true(h.t > 0.0);
            assert_true(accel_occluded(a, org, dir, 0.0, h.t * 1.001));
        }
        assert_int_equal(accel_occluded(a, org, dir, 0.0, INFINITY), hit);
    }
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

/* The shadow cache (accel_occluded_cached) answers as accel_occluded does:
 * over shadow rays from random points to a light, with the cache carried
 * from ray to ray, with every primitive number (and numbers past the last)
 * put in the cache by hand, with rays that end short of a blocker, and
 * with a no_shadow primitive cached; and it
 * learns a blocker (the cache is set once a ray was blocked). */
static void test_occluded_cached(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    sphere(s, v3(0, 4, 0), 1);
    box(s, v3(2, 3, -1), v3(4, 3.5, 1));
    scene_object *ns = sphere(s, v3(-3, 4, 0), 1); /* casts no shadow */
    ns->flags |= OBJ_NO_SHADOW;
    /* a slab with a hole: rays through the hole pass */
    scene_object *dif = csg(s, SHAPE_DIFFERENCE, 2, 1);
    dif->u.csg.kids[0] = member(s, SHAPE_BOX);
    dif->u.csg.kids[0]->u.box.c1 = v3(-2, 6, -2);
    dif->u.csg.kids[0]->u.box.c2 = v3(2, 6.5, 2);
    dif->u.csg.kids[1] = msphere(s, v3(0.5, 6.25, 0.5), 0.8);
    triangle(s, v3(-6, 5, -2), v3(-4, 5, -2), v3(-5, 5, 2));
    accel *a = build(s, d);
    const unsigned nprim = 8; /* more than the scene's user primitives */
    vec3 light = v3(0, 12, 0);
    rng r;
    rng_seed(&r, 7, 1);
    unsigned last = 0;
    int blocked = 0, learnt = 0;
    for (int i = 0; i < 4000; i++) {
        vec3 org = v3(16 * rng_f64(&r) - 8, 2 * rng_f64(&r), 8 * rng_f64(&r) - 4);
        vec3 dir = v3_sub(light, org);
        double tmax = 0.3 + 0.7 * rng_f64(&r); /* some rays end short of a blocker */
        int want = accel_occluded(a, org, dir, 0.0, tmax);
        assert_int_equal(accel_occluded_cached(a, &last, org, dir, 0.0, tmax), want);
        blocked += want;
        learnt += want && last != 0;
        for (unsigned k = 0; k <= nprim + 1; k++) {
            unsigned c = k;
            assert_int_equal(accel_occluded_cached(a, &c, org, dir, 0.0, tmax), want);
        }
    }
    assert_true(blocked > 400 && blocked < 3600); /* both answers were asked */
    assert_true(learnt > blocked / 2);
    /* straight through the no_shadow sphere only: not blocked, whatever is cached */
    for (unsigned k = 0; k <= nprim + 1; k++) {
        unsigned c = k;
        assert_false(accel_occluded_cached(a, &c, v3(-3, 0, 0), v3(0, 12, 0), 0.0, 0.999));
    }
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

/* Torus against brute force: signed distance to the tube sampled along the
 * ray; the reported hit must be on the surface and no sign change may come
 * before it. */
static double torus_sdf(vec3 p, double R, double r)
{
    double rho = sqrt(p.x * p.x + p.z * p.z) - R;
    return sqrt(rho * rho + p.y * p.y) - r;
}

static void test_torus_brute(void **st)
{
    (void)st;
    scene *s = scene_new();
    diag *d = diag_new();
    scene_object *o = add_obj(s, SHAPE_TORUS);
    o->u.torus.major = 1.0;
    o->u.torus.minor = 0.3;
    accel *a = build(s, d);
    rng r;
    rng_seed(&r, 5, 9);
    int hits = 0;
    for (int i = 0; i < 3000; i++) {
        vec3 org = v3(4 * rng_f64(&r) - 2, 2 * rng_f64(&r) - 1, 4 * rng_f64(&r) - 2);
        vec3 tgt = v3(2.6 * rng_f64(&r) - 1.3, 0.6 * rng_f64(&r) - 0.3, 2.6 * rng_f64(&r) - 1.3);
        vec3 dir = v3_norm(v3_sub(tgt, org));
        accel_hit h;
        int hit = accel_intersect(a, org, dir, 0.0, 10.0, &h);
        double tend = hit ? h.t : 10.0;
        if (hit) {
            hits++;
            assert_hit_sane(&h);
            assert_near(torus_sdf(h.p, 1.0, 0.3), 0.0, 1e-9);
            /* outward normal: moving along it increases the distance */
            assert_true(torus_sdf(v3_madd(h.p, h.ng, 1e-4), 1.0, 0.3) > 0.0);
        }
        /* no crossing before tend (steps of 1e-3, skipping the ends) */
        double eps = 1e-6;
        double f0 = torus_sdf(v3_madd(org, dir, eps), 1.0, 0.3);
        for (double t = eps + 1e-3; t < tend - 1e-6; t += 1e-3) {
            double f1 = torus_sdf(v3_madd(org, dir, t), 1.0, 0.3);
            if ((f0 < 0) != (f1 < 0) && fabs(f1) > 1e-7 && fabs(f0) > 1e-7)
                fail_msg("ray %d: surface crossed at t~%g before the reported %s %g", i, t, hit ? "hit" : "end", tend);
            f0 = f1;
        }
    }
    print_message("torus: %d of 3000 rays hit\n", hits);
    assert_true(hits > 500);
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

/* The bare Embree scene (plain context: float rays in the user callbacks)
 * agrees with accel_intersect to float precision, no_shadow included. */
static void test_bare_embree(void **st)
{
    (void)st;
    scene *s = scaled_scene(1.0);
    scene_object *ns = sphere(s, v3(0, 0, 2), 0.5);
    ns->flags |= OBJ_NO_SHADOW;
    diag *d = diag_new();
    accel *a = build(s, d);
    RTCScene rs = (RTCScene)accel_rtc_scene(a);
    assert_non_null(rs);
    rng r;
    rng_seed(&r, 11, 2);
    for (int i = 0; i < 2000; i++) {
        vec3 org = v3(0.1, 0.13, -3);
        vec3 dir = v3_norm(v3(25 * rng_f64(&r) - 12, 3 * rng_f64(&r) - 1.5, 8));
        double eps = accel_epsilon(a, org, dir);
        accel_hit h;
        int hit = accel_intersect(a, org, dir, 0.0, INFINITY, &h);
        struct RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        struct RTCRayHit rh;
        memset(&rh, 0, sizeof rh);
        rh.ray.org_x = (float)org.x; rh.ray.org_y = (float)org.y; rh.ray.org_z = (float)org.z;
        rh.ray.dir_x = (float)dir.x; rh.ray.dir_y = (float)dir.y; rh.ray.dir_z = (float)dir.z;
        rh.ray.tnear = (float)eps;
        rh.ray.tfar = INFINITY;
        rh.ray.mask = 0xFFFFFFFFu;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(rs, &ctx, &rh);
        int bare = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
        assert_int_equal(bare, hit);
        if (hit) assert_near(rh.ray.tfar, h.t, 1e-5 * h.t);
        /* occlusion: the bare query must skip the no_shadow sphere as well */
        struct RTCRay ray = rh.ray;
        ray.tfar = INFINITY;
        rtcOccluded1(rs, &ctx, &ray);
        assert_int_equal(ray.tfar == -INFINITY, accel_occluded(a, org, dir, 0.0, INFINITY));
    }
    vec3 org = v3(0, 0, 0), dir = v3(0, 0, 1);
    assert_true(accel_occluded(a, org, dir, 0.0, INFINITY)); /* the box behind */
    assert_false(accel_occluded(a, org, dir, 0.0, 3.0));     /* only the no_shadow sphere */
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

typedef struct {
    const accel *a;
    double *t;
    int n;
} par_ctx;

static void par_job(void *ctx, int i, int thread)
{
    (void)thread;
    par_ctx *c = ctx;
    rng r;
    rng_seed(&r, 99, (uint64_t)i);
    for (int k = 0; k < 100; k++) {
        vec3 org = v3(30 * rng_f64(&r) - 12, 6 * rng_f64(&r) - 3, 30 * rng_f64(&r) - 8);
        vec3 dir = v3(rng_f64(&r) - 0.5, rng_f64(&r) - 0.5, rng_f64(&r) - 0.5);
        accel_hit h;
        c->t[i * 100 + k] = accel_intersect(c->a, org, dir, 0.0, INFINITY, &h) ? h.t : -1.0;
    }
}

static void test_threads(void **st)
{
    (void)st;
    scene *s = scaled_scene(1.0);
    diag *d = diag_new();
    accel *a = build(s, d);
    int n = 200;
    double *t1 = malloc(sizeof(double) * (size_t)n * 100), *t4 = malloc(sizeof(double) * (size_t)n * 100);
    par_ctx c1 = {a, t1, n}, c4 = {a, t4, n};
    pool_run(1, n, par_job, &c1);
    pool_run(4, n, par_job, &c4);
    assert_memory_equal(t1, t4, sizeof(double) * (size_t)n * 100);
    free(t1);
    free(t4);
    accel_free(a);
    diag_free(d);
    scene_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere),
        cmocka_unit_test(test_occluded_cached),
        cmocka_unit_test(test_box_faces),
        cmocka_unit_test(test_plane),
        cmocka_unit_test(test_triangles),
        cmocka_unit_test(test_mesh_instances),
        cmocka_unit_test(test_mesh_textures_normals),
        cmocka_unit_test(test_uv),
        cmocka_unit_test(test_cylinder_cone),
        cmocka_unit_test(test_coplanar_tie),
        cmocka_unit_test(test_disc),
        cmocka_unit_test(test_torus),
        cmocka_unit_test(test_poly_roots),
        cmocka_unit_test(test_grazing_sphere),
        cmocka_unit_test(test_no_self_hit),
        cmocka_unit_test(test_scales),
        cmocka_unit_test(test_no_shadow),
        cmocka_unit_test(test_warnings_csg),
        cmocka_unit_test(test_crossings),
        cmocka_unit_test(test_csg),
        cmocka_unit_test(test_csg_inverse_union),
        cmocka_unit_test(test_csg_brute),
        cmocka_unit_test(test_empty_and_errors),
        cmocka_unit_test(test_random_rays),
        cmocka_unit_test(test_torus_brute),
        cmocka_unit_test(test_bare_embree),
        cmocka_unit_test(test_threads),
        cmocka_unit_test(test_epsilon_small_beside_huge),
        cmocka_unit_test(test_epsilon_closed_form_shells),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
