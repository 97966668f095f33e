/* test_parser.c - POV-Ray SDL parser: expressions, directives, camera,
 * lights, objects, textures, meshes, errors, and a sweep over the
 * distribution's example scenes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "scene.h"
#include "transmit.h"
#include "sdl.h"
#include "sdl_keywords.h"

#define CORNELL "/usr/share/povray-3.7/scenes/radiosity/cornell.pov"

static void assert_near(double a, double b, double tol)
{
    if (fabs(a - b) > tol) {
        print_error("%.12g != %.12g (tol %g)\n", a, b, tol);
        fail();
    }
}

static void assert_vec(vec3 a, vec3 b, double tol)
{
    assert_near(a.x, b.x, tol);
    assert_near(a.y, b.y, tol);
    assert_near(a.z, b.z, tol);
}

static void print_diag(const diag *d)
{
    for (int i = 0; i < diag_count(d); i++) {
        char *m = diag_format(diag_get(d, i));
        print_message("%s\n", m);
        free(m);
    }
}

/* Parse text that must succeed. */
static scene *parse_ok(const char *text)
{
    diag *d = diag_new();
    scene *s = NULL;
    pt_status st = sdl_parse_string("test.pov", text, NULL, &s, d);
    if (st != PT_OK) print_diag(d);
    assert_int_equal(st, PT_OK);
    assert_non_null(s);
    diag_free(d);
    return s;
}

/* Parse text that must fail with `want`; returns the first error message
 * formatted as "file:line:col: error: ..." (caller frees). */
static char *parse_err_opt(const char *text, const sdl_options *o, pt_status want)
{
    diag *d = diag_new();
    scene *s = NULL;
    pt_status st = sdl_parse_string("test.pov", text, o, &s, d);
    if (st != want) print_diag(d);
    assert_int_equal(st, want);
    assert_null(s);
    char *msg = NULL;
    for (int i = 0; i < diag_count(d) && !msg; i++)
        if (diag_get(d, i)->severity == DIAG_ERROR) msg = diag_format(diag_get(d, i));
    assert_non_null(msg);
    diag_free(d);
    return msg;
}

static char *parse_err(const char *text, pt_status want) { return parse_err_opt(text, NULL, want); }

static void assert_prefix(const char *msg, const char *prefix)
{
    if (strncmp(msg, prefix, strlen(prefix)) != 0) {
        print_error("message \"%s\" does not start with \"%s\"\n", msg, prefix);
        fail();
    }
}

/* Value of a float expression: the radius of sphere { 0, (EXPR) }. */
static double eval_float(const char *prelude, const char *expr)
{
    char buf[4096];
    snprintf(buf, sizeof buf, "%s\nsphere { 0, (%s) }\n", prelude ? prelude : "", expr);
    scene *s = parse_ok(buf);
    assert_int_equal(s->nobjects, 1);
    double r = s->objects[0]->u.sphere.radius;
    scene_free(s);
    return r;
}

/* Value of a vector expression: the centre of sphere { EXPR, 1 }. */
static vec3 eval_vec(const char *prelude, const char *expr)
{
    char buf[4096];
    snprintf(buf, sizeof buf, "%s\nsphere { %s, 1 }\n", prelude ? prelude : "", expr);
    scene *s = parse_ok(buf);
    assert_int_equal(s->nobjects, 1);
    vec3 c = s->objects[0]->u.sphere.centre;
    scene_free(s);
    return c;
}

/* ------------------------------------------------------------ keywords */

static void test_keywords_sorted(void **st)
{
    (void)st;
    for (int k = KW_NONE + 2; k < SDL_KW_LIMIT; k++)
        assert_true(strcmp(sdl_kw_text((sdl_kw)(k - 1)), sdl_kw_text((sdl_kw)k)) < 0);
    for (int k = KW_NONE + 1; k < SDL_KW_LIMIT; k++) {
        const char *t = sdl_kw_text((sdl_kw)k);
        assert_int_equal(sdl_kw_lookup(t, strlen(t)), k);
    }
    assert_int_equal(sdl_kw_lookup("spheres", 7), KW_NONE);
    assert_int_equal(sdl_kw_lookup("sphere", 6), KW_SPHERE);
}

/* ------------------------------------------------------------ expressions */

static void test_arithmetic(void **st)
{
    (void)st;
    assert_near(eval_float(NULL, "1+2*3"), 7, 1e-12);
    assert_near(eval_float(NULL, "(1+2)*3"), 9, 1e-12);
    assert_near(eval_float(NULL, "10-4-3"), 3, 1e-12);
    assert_near(eval_float(NULL, "2*3/4"), 1.5, 1e-12);
    assert_near(eval_float(NULL, "-2*-3"), 6, 1e-12);
    assert_near(eval_float(NULL, "--2"), 2, 1e-12);
    assert_near(eval_float(NULL, "1.5e1 + .5"), 15.5, 1e-12);
    assert_near(eval_float(NULL, "1 < 2"), 1, 0);
    assert_near(eval_float(NULL, "2 <= 1"), 0, 0);
    assert_near(eval_float(NULL, "1+1 = 2"), 1, 0);
    assert_near(eval_float(NULL, "3 != 3"), 0, 0);
    assert_near(eval_float(NULL, "1 < 2 & 2 < 1"), 0, 0);
    assert_near(eval_float(NULL, "1 < 2 | 2 < 1"), 1, 0);
    assert_near(eval_float(NULL, "!0"), 1, 0);
    assert_near(eval_float(NULL, "!(1 > 0)"), 0, 0);
    assert_near(eval_float(NULL, "1 > 2 ? 10 : 20"), 20, 0);
    assert_near(eval_float(NULL, "(1 < 2) ? 10 : 20"), 10, 0);
    assert_near(eval_float(NULL, "true + yes + on - false - no - off"), 3, 0);
    assert_near(eval_float(NULL, "pi"), M_PI, 1e-15);
}

static void test_functions(void **st)
{
    (void)st;
    assert_near(eval_float(NULL, "sin(pi/2) + cos(0) + tan(0)"), 2, 1e-12);
    assert_near(eval_float(NULL, "asin(1) + acos(1) + atan(1)"), M_PI / 2 + M_PI / 4, 1e-12);
    assert_near(eval_float(NULL, "atan2(1, -1)"), 3 * M_PI / 4, 1e-12);
    assert_near(eval_float(NULL, "sqrt(16) + pow(2, 10)"), 1028, 1e-9);
    assert_near(eval_float(NULL, "exp(1)"), M_E, 1e-12);
    assert_near(eval_float(NULL, "log(1000)"), 3, 1e-12); /* POV-Ray: log is base 10 */
    assert_near(eval_float(NULL, "ln(exp(2))"), 2, 1e-12);
    assert_near(eval_float(NULL, "abs(-3) + min(4, 2, 8) + max(1, 7)"), 12, 0);
    assert_near(eval_float(NULL, "floor(-1.5) + ceil(1.2) + int(-1.7)"), -2 + 2 - 1, 0);
    assert_near(eval_float(NULL, "mod(7, 3) + div(7, 2)"), 1 + 3, 0);
    assert_near(eval_float(NULL, "degrees(pi) + radians(180)"), 180 + M_PI, 1e-12);
    assert_near(eval_float(NULL, "vlength(<3,4,0>) + vdot(x, <5,6,7>)"), 10, 1e-12);
    assert_near(eval_float(NULL, "clock"), 0, 0);
    assert_near(eval_float(NULL, "select(-1, 1, 2, 3) + select(0, 1, 2, 3) + select(1, 1, 2, 3)"), 6, 0);
    assert_near(eval_float(NULL, "strlen(concat(\"ab\", str(12, 0, 0), chr(65)))"), 5, 0);
    assert_near(eval_float(NULL, "strcmp(\"a\", \"b\")"), -1, 0);
    assert_near(eval_float(NULL, "(\"abc\" = \"abc\") + (\"a\" < \"b\")"), 2, 0);
}

static void test_vectors(void **st)
{
    (void)st;
    assert_vec(eval_vec(NULL, "<1,2,3> + <4,5,6>"), v3(5, 7, 9), 1e-12);
    assert_vec(eval_vec(NULL, "<1,2,3> * 2"), v3(2, 4, 6), 1e-12);
    assert_vec(eval_vec(NULL, "2"), v3(2, 2, 2), 1e-12);               /* float promotes */
    assert_vec(eval_vec(NULL, "<1,2,3> + 1"), v3(2, 3, 4), 1e-12);
    assert_vec(eval_vec(NULL, "<47.20 33.00 40.60>"), v3(47.2, 33, 40.6), 1e-12); /* no commas */
    assert_vec(eval_vec(NULL, "<31.40, 0.0 45.60>"), v3(31.4, 0, 45.6), 1e-12);
    assert_vec(eval_vec(NULL, "-<1,2,3>"), v3(-1, -2, -3), 1e-12);
    assert_vec(eval_vec(NULL, "x + 2*y - z"), v3(1, 2, -1), 1e-12);
    assert_vec(eval_vec(NULL, "vcross(x, y)"), v3(0, 0, 1), 1e-12);
    assert_vec(eval_vec(NULL, "vnormalize(<0,3,4>)"), v3(0, 0.6, 0.8), 1e-12);
    assert_vec(eval_vec(NULL, "vrotate(x, <0,0,90>)"), v3(0, 1, 0), 1e-12);
    assert_vec(eval_vec(NULL, "vaxis_rotate(x, z, 90)"), v3(0, 1, 0), 1e-12);
    assert_vec(eval_vec(NULL, "<1,2,3> / <1,2,4>"), v3(1, 1, 0.75), 1e-12);
    assert_vec(eval_vec(NULL, "(<1,2,3> < <2,2,2>)"), v3(1, 0, 0), 0);
    assert_near(eval_float(NULL, "<1,2,3>.y + <1,2,3,4,5>.transmit"), 7, 0);
    assert_near(eval_float("#declare C = rgb <0.5, 0.25, 1>;", "C.red + C.green + C.blue"), 1.75, 1e-12);
    /* a 2-vector pads with 0 */
    assert_vec(eval_vec(NULL, "<1,2>"), v3(1, 2, 0), 0);
    assert_near(eval_float(NULL, "(u + 2*v).v"), 2, 0);
}

static void test_directives(void **st)
{
    (void)st;
    assert_near(eval_float("#declare S = 0; #declare I = 1;\n"
                           "#while (I <= 10) #declare S = S + I; #declare I = I + 1; #end",
                           "S"), 55, 0);
    assert_near(eval_float("#declare S = 0; #for (I, 1, 9, 2) #declare S = S + I; #end", "S"), 25, 0);
    assert_near(eval_float("#declare A = 3;\n#if (A > 2) #declare B = 1; #elseif (A > 1) #declare B = 2; #else #declare B = 3; #end",
                           "B"), 1, 0);
    assert_near(eval_float("#declare A = 2;\n#if (A > 2) #declare B = 1; #elseif (A > 1) #declare B = 2; #else #declare B = 3; #end",
                           "B"), 2, 0);
    assert_near(eval_float("#if (0) #if (1) #declare B = 1; #end #else #declare B = 4; #end", "B"), 4, 0);
    assert_near(eval_float("#declare A = 1; #ifdef (A) #declare B = 5; #end #ifndef (Q) #declare B = B + 1; #end", "B"), 6, 0);
    assert_near(eval_float("#declare A = 1; #undef A #ifdef (A) #declare B = 0; #else #declare B = 7; #end", "B"), 7, 0);
    assert_near(eval_float("#declare B = 0; #switch (2) #case (1) #declare B = 1; #break #case (2) #declare B = B + 2;"
                           " #case (3) #declare B = B + 3; #break #else #declare B = 99; #end",
                           "B"), 5, 0); /* 2 falls through into 3 */
    assert_near(eval_float("#switch (7) #range (1, 5) #declare B = 1; #break #else #declare B = 2; #end", "B"), 2, 0);
    assert_near(eval_float("#macro Sq(A) (A*A) #end #declare B = Sq(3) + 1;", "B"), 10, 0);
    assert_near(eval_float("#macro Add(A, B) #local C = A + B; C #end", "Add(2, 3) * 2"), 10, 0);
    /* macro parameters are by value and local */
    assert_near(eval_float("#declare A = 1; #macro Set(A) #declare A = 5; #end Set(2)", "A"), 1, 0);
    /* a directive right after a declaration runs after the assignment */
    assert_near(eval_float("#declare A = 1\n#declare B = A + 1;", "B"), 2, 0);
    assert_near(eval_float("#declare V = <1,2,3>; #declare W = V * 2;", "W.z"), 6, 0);
    assert_near(eval_float("#local L = 4;", "L"), 4, 0);
    assert_near(eval_float("#version 3.5;", "version"), 3.5, 1e-12);
    assert_near(eval_float(NULL, "image_width"), 320, 0);
}

static void test_options(void **st)
{
    (void)st;
    const char *defs[] = {"R=2.5", "S=hello"};
    sdl_options o;
    sdl_default_options(&o);
    o.defines = defs;
    o.ndefines = 2;
    o.clock = 0.25;
    o.image_width = 640;
    diag *d = diag_new();
    scene *s = NULL;
    pt_status stt = sdl_parse_string("t.pov", "#if (S = \"hello\") sphere { <clock, image_width, 0>, R } #end", &o, &s, d);
    if (stt != PT_OK) print_diag(d);
    assert_int_equal(stt, PT_OK);
    assert_int_equal(s->nobjects, 1);
    assert_near(s->objects[0]->u.sphere.radius, 2.5, 0);
    assert_vec(s->objects[0]->u.sphere.centre, v3(0.25, 640, 0), 0);
    assert_near(s->clock, 0.25, 0);
    scene_free(s);
    diag_free(d);
}

static void test_messages(void **st)
{
    (void)st;
    diag *d = diag_new();
    scene *s = NULL;
    assert_int_equal(sdl_parse_string("m.pov", "#debug \"hello\\n\"\n#warning concat(\"w\", str(3,0,0))", NULL, &s, d), PT_OK);
    assert_int_equal(diag_count(d), 2);
    assert_int_equal(diag_get(d, 0)->severity, DIAG_NOTE);
    assert_string_equal(diag_get(d, 0)->text, "hello");
    assert_int_equal(diag_get(d, 1)->severity, DIAG_WARNING);
    assert_string_equal(diag_get(d, 1)->text, "w3");
    assert_int_equal(diag_get(d, 1)->loc.line, 2);
    scene_free(s);
    diag_free(d);
    char *m = parse_err("\n  #error \"stop here\"", PT_ERR_SYNTAX);
    assert_string_equal(m, "test.pov:2:3: error: #error: stop here");
    free(m);
}

/* ------------------------------------------------------------ camera */

static scene *parse_cornell(void)
{
    diag *d = diag_new();
    scene *s = NULL;
    pt_status st = sdl_parse_file(CORNELL, NULL, &s, d);
    if (st != PT_OK) print_diag(d);
    assert_int_equal(st, PT_OK);
    diag_free(d);
    return s;
}

static void test_camera_cornell(void **st)
{
    (void)st;
    scene *s = parse_cornell();
    const scene_camera *c = &s->camera;
    assert_true(s->camera_set);
    assert_int_equal(c->kind, CAMERA_PERSPECTIVE);
    /* angle 39.5 with |right| = 1: |direction| = 0.5 / tan(19.75 deg) */
    double dl = 0.5 / tan(19.75 * M_PI / 180.0);
    assert_near(dl, 1.392615, 1e-6);
    assert_vec(c->location, v3(27.8, 27.3, -80.0), 1e-12);
    assert_vec(c->direction, v3(0, 0, dl), 1e-12);
    assert_vec(c->up, v3(0, 1, 0), 1e-12);
    assert_vec(c->right, v3(-1, 0, 0), 1e-12); /* mirrored camera kept */
    assert_near(c->angle, 39.5, 0);
    scene_free(s);
}

static void test_camera_look_at(void **st)
{
    (void)st;
    scene *s = parse_ok("camera { location <0,2,-3> right x*4/3 angle 60 look_at <1,1,2> }");
    const scene_camera *c = &s->camera;
    /* angle first: |direction| = (4/3) / tan(30 deg) / 2 = 1.1547005 */
    double dl = (4.0 / 3.0) / tan(M_PI / 6) / 2;
    assert_near(dl, 1.1547005384, 1e-9);
    /* look_at: d = (1,-1,5)/sqrt(27); right = sky x d = (d.z, 0, -d.x) normalised
     * = (5, 0, -1)/sqrt(26); up = d x right */
    double s27 = sqrt(27.0), s26 = sqrt(26.0);
    vec3 d = v3(1 / s27, -1 / s27, 5 / s27);
    vec3 r = v3(5 / s26, 0, -1 / s26);
    vec3 u = v3(d.y * r.z - d.z * r.y, d.z * r.x - d.x * r.z, d.x * r.y - d.y * r.x);
    assert_near(u.y, 26.0 / (s27 * s26), 1e-12);
    assert_vec(c->direction, v3_scale(d, dl), 1e-12);
    assert_vec(c->right, v3_scale(r, 4.0 / 3.0), 1e-12);
    assert_vec(c->up, u, 1e-12);
    assert_vec(c->location, v3(0, 2, -3), 0);
    scene_free(s);

    /* a left-handed (mirrored) right vector stays mirrored through look_at */
    s = parse_ok("camera { location <0,0,-5> right -x look_at <0,0,0> }");
    assert_vec(s->camera.right, v3(-1, 0, 0), 1e-12);
    assert_vec(s->camera.up, v3(0, 1, 0), 1e-12);
    assert_vec(s->camera.direction, v3(0, 0, 1), 1e-12);
    scene_free(s);

    /* keyword order does not matter in 3.5+: look_at before angle, then a transform */
    s = parse_ok("camera { look_at <0,0,1> angle 90 location <0,0,0> right x translate <1,2,3> }");
    assert_vec(s->camera.direction, v3(0, 0, 0.5), 1e-12);
    assert_vec(s->camera.location, v3(1, 2, 3), 1e-12);
    scene_free(s);

    /* orthographic without up/right takes the perspective image area at look_at */
    s = parse_ok("camera { orthographic location <0,0,-10> look_at <0,0,0> }");
    assert_int_equal(s->camera.kind, CAMERA_ORTHOGRAPHIC);
    assert_vec(s->camera.right, v3(13.3, 0, 0), 1e-9);
    assert_vec(s->camera.up, v3(0, 10, 0), 1e-9);
    scene_free(s);
}

/* ------------------------------------------------------------ cornell */

static void test_cornell_lights(void **st)
{
    (void)st;
    scene *s = parse_cornell();
    assert_int_equal(s->nlights, 9);
    double dx = 13.0 / 3, dz = 10.5 / 3;
    for (int i = 0; i < 9; i++) {
        const scene_light *l = &s->lights[i];
        int a = i / 3, b = i % 3; /* outer loop i, inner j */
        vec3 t = v3(a * dx - (13 - dx) / 2, 0, b * dz - (10.5 - dz) / 2);
        assert_int_equal(l->kind, LIGHT_SPOT);
        assert_true(l->area);
        assert_int_equal(l->size1, 4);
        assert_int_equal(l->size2, 4);
        assert_int_equal(l->adaptive, 0);
        assert_true(l->jitter);
        assert_near(l->radius, -90, 0);
        assert_near(l->falloff, 90, 0);
        assert_near(l->tightness, 1, 0);
        assert_near(l->fade_power, 2, 0);
        assert_near(l->fade_distance, (13.0 / 3 + 3.5) / 2, 1e-12);
        assert_near(l->colour.r, 7, 1e-12);
        assert_near(l->colour.g, 4.69, 1e-12);
        assert_near(l->colour.b, 1.47, 1e-12);
        assert_vec(l->axis1, v3(dx, 0, 0), 1e-12);
        assert_vec(l->axis2, v3(0, 0, dz), 1e-12);
        assert_vec(l->position, v3_add(v3(27.8, 54.88, 27.95), t), 1e-12);
        assert_vec(l->point_at, v3_add(v3(27.8, 0, 27.95), t), 1e-12);
    }
    assert_true(s->global.radiosity.enabled);
    assert_int_equal(s->global.radiosity.count, 200);
    assert_int_equal(s->global.radiosity.recursion_limit, 3);
    assert_int_equal(s->global.radiosity.nearest_count, 10);
    assert_near(s->global.radiosity.error_bound, 0.5, 0);
    assert_near(s->global.radiosity.pretrace_start, 0.04, 0);
    assert_near(s->global.radiosity.pretrace_end, 0.01, 0);
    assert_int_equal(s->global.radiosity.direction_pool, 1600);
    assert_near(s->global.radiosity.maximum_reuse, 0.2, 0); /* defaults */
    assert_near(s->global.radiosity.adc_bailout, 0.01, 0);
    assert_near(s->global.assumed_gamma, 1.0, 0);
    assert_int_equal(s->version_major, 3);
    assert_int_equal(s->version_minor, 7);
    scene_free(s);
}

static void test_cornell_objects(void **st)
{
    (void)st;
    scene *s = parse_cornell();
    assert_int_equal(s->nobjects, 6);
    const scene_object *box = s->objects[0];
    assert_int_equal(box->kind, SHAPE_BOX);
    assert_vec(box->u.box.c1, v3(21.3, 54.87, 22.7), 1e-12);
    assert_vec(box->u.box.c2, v3(34.3, 54.88, 33.2), 1e-12);
    assert_true(box->flags & OBJ_NO_SHADOW);
    assert_non_null(box->texture);
    assert_near(box->texture->finish.ambient.r, 0.78, 0);
    assert_near(box->texture->finish.ambient.b, 0.78, 0);
    assert_near(box->texture->finish.diffuse, 0, 0);
    assert_near(box->texture->pigment.colour.g, 1, 0);
    const int kids[5] = {6, 2, 2, 10, 10}; /* floor+ceiling+back wall, right, left, short and tall block */
    for (int i = 0; i < 5; i++) {
        const scene_object *u = s->objects[i + 1];
        assert_int_equal(u->kind, SHAPE_UNION);
        assert_int_equal(u->u.csg.nkids, kids[i]);
        for (int k = 0; k < u->u.csg.nkids; k++) {
            assert_int_equal(u->u.csg.kids[k]->kind, SHAPE_TRIANGLE);
            assert_true(u->u.csg.kids[k]->texture == u->texture);
            assert_near(u->u.csg.kids[k]->texture->finish.diffuse, 0.75, 0);
            assert_near(u->u.csg.kids[k]->texture->finish.ambient.g, 0, 0);
        }
    }
    /* the Green wall (third object) */
    const scene_texture *g = s->objects[2]->u.csg.kids[1]->texture;
    assert_near(g->pigment.colour.r, 0.025, 0);
    assert_near(g->pigment.colour.g, 0.236, 0);
    assert_near(g->pigment.colour.b, 0.025, 0);
    /* vectors without commas in the tall block */
    const scene_object *tall = s->objects[5];
    assert_vec(tall->u.csg.kids[1]->u.triangle.v[2], v3(47.2, 33, 40.6), 1e-12);
    assert_vec(tall->u.csg.kids[5]->u.triangle.v[2], v3(31.4, 0, 45.6), 1e-12);
    scene_counts c = scene_count(s);
    assert_int_equal(c.triangles, 30);
    assert_int_equal(c.csg, 5);
    assert_int_equal(c.lights, 9);
    assert_int_equal(s->nfiles, 1);
    /* every node keeps its source location */
    assert_string_equal(box->loc.file, CORNELL);
    assert_int_equal(box->loc.line, 70);
    assert_int_equal(box->loc.col, 1);
    assert_int_equal(s->objects[1]->u.csg.kids[0]->loc.line, 77);
    assert_int_equal(s->lights[0].loc.line, 40); /* the declared light it copies */
    scene_free(s);
}

/* ------------------------------------------------------------ objects */

static void test_shapes(void **st)
{
    (void)st;
    scene *s = parse_ok("plane { <0,2,0>, 4 }\n"
                        "box { <1,-1,3>, <-1,1,-3> }\n"
                        "cylinder { 0, y*2, 0.5 open }\n"
                        "cone { 0, 1, y, 0.5 }\n"
                        "disc { <1,2,3>, z, 2, 1 }\n"
                        "torus { 2, 0.5 sturm }\n"
                        "smooth_triangle { 0, y, x, y, z, y }\n"
                        "ovus { 1, 0.5 }\n"
                        "ovus { 1, 0.5 }\n");
    assert_int_equal(s->nobjects, 9);
    const scene_object *const *o = (const scene_object *const *)s->objects;
    assert_vec(o[0]->u.plane.normal, v3(0, 1, 0), 0);
    assert_near(o[0]->u.plane.offset, 4, 0); /* POV-Ray: y = 4 (the distance is not divided by |n|) */
    assert_vec(o[1]->u.box.c1, v3(-1, -1, -3), 0);
    assert_vec(o[1]->u.box.c2, v3(1, 1, 3), 0);
    assert_int_equal(o[2]->kind, SHAPE_CYLINDER);
    assert_near(o[2]->u.cone.base_radius, 0.5, 0);
    assert_near(o[2]->u.cone.cap_radius, 0.5, 0);
    assert_true(o[2]->flags & OBJ_OPEN);
    assert_near(o[3]->u.cone.base_radius, 1, 0);
    assert_vec(o[3]->u.cone.cap, v3(0, 1, 0), 0);
    assert_near(o[3]->u.cone.cap_radius, 0.5, 0);
    assert_near(o[4]->u.disc.hole_radius, 1, 0);
    assert_near(o[5]->u.torus.major, 2, 0);
    assert_true(o[5]->flags & OBJ_STURM);
    assert_int_equal(o[6]->kind, SHAPE_SMOOTH_TRIANGLE);
    assert_vec(o[6]->u.triangle.n[2], v3(0, 1, 0), 0);
    assert_int_equal(o[7]->kind, SHAPE_OVUS);
    assert_string_equal(o[7]->name, "ovus");
    assert_near(o[7]->u.ovus.bottom, 1, 0);
    assert_near(o[7]->u.ovus.top, 0.5, 0);
    scene_free(s);

    /* POV-Ray 3.7 substitutes a sphere when top >= 2 bottom, with a warning */
    diag *d = diag_new();
    assert_int_equal(sdl_parse_string("w.pov", "ovus { 0.5, 1 }", NULL, &s, d), PT_OK);
    assert_int_equal(diag_count(d), 1);
    assert_int_equal(diag_get(d, 0)->severity, DIAG_WARNING);
    assert_int_equal(s->objects[0]->kind, SHAPE_SPHERE);
    assert_vec(s->objects[0]->u.sphere.centre, v3(0, 0.5, 0), 0);
    scene_free(s);
    diag_free(d);
}

static void test_transforms(void **st)
{
    (void)st;
    scene *s = parse_ok("union { sphere { 0, 1 translate x } scale 2 rotate y*90 }\n"
                        "sphere { 0, 1 matrix <1,0,0, 0,1,0, 0,0,1, 1,2,3> }\n"
                        "#declare T = transform { scale 2 translate x }\n"
                        "sphere { 0, 1 transform T }\n"
                        "sphere { 0, 1 transform { T inverse } }\n"
                        "sphere { 0, 1 scale <2, 0, 1> }\n");
    const scene_object *kid = s->objects[0]->u.csg.kids[0];
    /* translate x, scale 2, then rotate 90 about y takes +x to -z */
    assert_vec(xform_point(&kid->transform, v3(0, 0, 0)), v3(0, 0, -2), 1e-12);
    assert_vec(xform_point(&kid->transform, v3(0, 0, 1)), v3(2, 0, -2), 1e-12);
    assert_vec(xform_point(&s->objects[0]->transform, v3(1, 0, 0)), v3(0, 0, -2), 1e-12);
    assert_vec(xform_point(&s->objects[1]->transform, v3(1, 1, 1)), v3(2, 3, 4), 1e-12);
    assert_vec(xform_point(&s->objects[2]->transform, v3(1, 1, 1)), v3(3, 2, 2), 1e-12);
    assert_vec(xform_point(&s->objects[3]->transform, v3(3, 2, 2)), v3(1, 1, 1), 1e-12);
    /* zero scale components become 1 (with a warning) */
    assert_vec(xform_point(&s->objects[4]->transform, v3(1, 1, 1)), v3(2, 1, 1), 1e-12);
    scene_free(s);
}

static void test_textures(void **st)
{
    (void)st;
    scene *s = parse_ok("#declare F = finish { diffuse 0.3 ambient 0.2 phong 0.5 }\n"
                        "#declare P = pigment { rgb <0.1, 0.2, 0.3> }\n"
                        "#declare T = texture { pigment { P } finish { F } }\n"
                        "union {\n"
                        "  sphere { 0, 1 }\n"
                        "  sphere { 0, 1 pigment { rgb x } }\n"
                        "  sphere { 0, 1 texture { T finish { diffuse 0.9 } } }\n"
                        "  pigment { color red 1 green .5 }\n"
                        "  translate y\n"
                        "}\n"
                        "sphere { 0, 1 texture { T } translate x }\n"
                        "sphere { 0, 1 translate x texture { T } }\n"
                        "sphere { 0, 1 finish { F diffuse 0.8 } }\n"
                        "sphere { 0, 1 pigment { rgbft <1, 1, 1, 0.5, 0.25> } finish { reflection { 0.1, 0.5 falloff 2 exponent 0.8 } } }\n"
                        "sphere { 0, 1 pigment { checker rgb x, rgb y } }\n"
                        "sphere { 0, 1 pigment { colour 1 } finish { ambient 0.5 specular albedo 0.5 roughness 0.1 } }\n");
    const scene_object *u = s->objects[0];
    /* the union's texture reaches the kid without one */
    assert_near(u->u.csg.kids[0]->texture->pigment.colour.r, 1, 0);
    assert_near(u->u.csg.kids[0]->texture->pigment.colour.g, 0.5, 0);
    assert_true(u->u.csg.kids[0]->texture == u->texture);
    /* kids with their own texture keep it */
    assert_near(u->u.csg.kids[1]->texture->pigment.colour.r, 1, 0);
    assert_near(u->u.csg.kids[1]->texture->pigment.colour.g, 0, 0);
    const scene_texture *t2 = u->u.csg.kids[2]->texture;
    assert_near(t2->finish.diffuse, 0.9, 0);
    assert_near(t2->finish.ambient.r, 0.2, 0);
    assert_near(t2->finish.phong, 0.5, 0);
    assert_near(t2->pigment.colour.b, 0.3, 0);
    /* the union's transform moved every kid and their textures */
    assert_vec(xform_point(&t2->transform, v3(0, 0, 0)), v3(0, 1, 0), 0);
    assert_vec(xform_point(&u->u.csg.kids[0]->transform, v3(0, 0, 0)), v3(0, 1, 0), 0);
    /* transforms after a texture move it; before, they do not */
    assert_vec(xform_point(&s->objects[1]->texture->transform, v3(0, 0, 0)), v3(1, 0, 0), 0);
    assert_vec(xform_point(&s->objects[2]->texture->transform, v3(0, 0, 0)), v3(0, 0, 0), 0);
    /* declared finish overridden after use; the declaration is unchanged */
    assert_near(s->objects[3]->texture->finish.diffuse, 0.8, 0);
    assert_near(s->objects[1]->texture->finish.diffuse, 0.3, 0);
    const scene_texture *t5 = s->objects[4]->texture;
    assert_near(t5->pigment.colour.f, 0.5, 0);
    assert_near(t5->pigment.colour.t, 0.25, 0);
    assert_near(t5->finish.reflection_min.g, 0.1, 0);
    assert_near(t5->finish.reflection_max.g, 0.5, 0);
    assert_near(t5->finish.reflection_falloff, 2, 0);
    assert_near(t5->finish.reflection_exponent, 0.8, 0); /* as written */
    const scene_texture *t6 = s->objects[5]->texture;
    assert_int_equal(t6->pigment.kind, PIGMENT_PATTERN); /* evaluated by shade_pattern */
    assert_string_equal(t6->pigment.pattern, "checker");
    assert_near(t6->pigment.colour.r, 1, 0);
    assert_near(t6->pigment.colour.g, 0, 0);
    const scene_texture *t7 = s->objects[6]->texture;
    /* "colour 1" fills all five terms, as POV-Ray's colour promotion does */
    assert_near(t7->pigment.colour.t, 1, 0);
    assert_near(t7->finish.ambient.g, 0.5, 0);
    /* specular albedo: s * (r' + 2) / (4 (2 - 2^(-r'/2))) with r' = 1/roughness */
    assert_near(t7->finish.specular, 0.5 * 12.0 / (4.0 * (2.0 - pow(2.0, -5.0))), 1e-12);
    /* objects without a texture use the default (NULL) */
    scene_free(s);
    s = parse_ok("sphere { 0, 1 }");
    assert_null(s->objects[0]->texture);
    scene_free(s);
    s = parse_ok("#default { finish { ambient 0.3 } } sphere { 0, 1 }");
    assert_non_null(s->objects[0]->texture);
    assert_near(s->objects[0]->texture->finish.ambient.r, 0.3, 0);
    scene_free(s);
}

static void test_object_copies_ok(void **st)
{
    (void)st;
    scene *s = parse_ok("#declare S = sphere { <1,0,0>, 1 pigment { rgb 1 } }\n"
                        "#declare M = mesh { triangle { 0, x, y } triangle { 0, y, z } inside_vector z }\n"
                        "object { S translate y }\n"
                        "object { S }\n"
                        "object { M }\n"
                        "object { M translate x }\n"
                        "#declare L = light_source { <0,1,0> rgb 1 }\n"
                        "#declare U = union { object { S } light_source { L translate x } }\n"
                        "object { U translate <0,0,5> }\n"
                        "light_source { L translate -y }\n");
    assert_int_equal(s->nobjects, 5);
    assert_vec(xform_point(&s->objects[0]->transform, s->objects[0]->u.sphere.centre), v3(1, 1, 0), 0);
    assert_vec(xform_point(&s->objects[1]->transform, s->objects[1]->u.sphere.centre), v3(1, 0, 0), 0);
    assert_true(s->objects[0]->texture != s->objects[1]->texture); /* deep copies */
    const scene_mesh *m = s->objects[2]->u.mesh.mesh;
    assert_non_null(m);
    assert_true(m == s->objects[3]->u.mesh.mesh);
    assert_int_equal(m->uses, 2);
    assert_int_equal(m->ntris, 2);
    assert_true(s->objects[2]->u.mesh.inside_vector_set);
    /* lights inside a union move with it and join the scene's list */
    assert_int_equal(s->nlights, 2);
    assert_vec(s->lights[0].position, v3(1, 1, 5), 0);
    assert_vec(s->lights[1].position, v3(0, 0, 0), 0);
    assert_int_equal(s->objects[4]->u.csg.nkids, 1);
    scene_free(s);
}

static void test_mesh2(void **st)
{
    (void)st;
    scene *s = parse_ok("mesh2 {\n"
                        "  vertex_vectors { 4, <0,0,0>, <1,0,0>, <1,1,0>, <0,1,0> }\n"
                        "  normal_vectors { 2, z, -z }\n"
                        "  uv_vectors { 4, <0,0>, <1,0>, <1,1>, <0,1> }\n"
                        "  texture_list { 2, texture { pigment { rgb x } } texture { pigment { rgb y } } }\n"
                        "  face_indices { 2, <0,1,2>, 0, <0,2,3>, 1 }\n"
                        "  normal_indices { 2, <0,0,0>, <1,1,1> }\n"
                        "  pigment { rgb z }\n"
                        "}\n");
    const scene_object *o = s->objects[0];
    assert_int_equal(o->kind, SHAPE_MESH);
    const scene_mesh *m = o->u.mesh.mesh;
    assert_int_equal(m->nverts, 4);
    assert_int_equal(m->nnormals, 2);
    assert_int_equal(m->nuvs, 4);
    assert_int_equal(m->ntris, 2);
    assert_int_equal(m->ntextures, 2);
    assert_int_equal(m->tris[1][2], 3);
    assert_int_equal(m->tri_normals[1][0], 1);
    assert_int_equal(m->tri_texture[1], 1);
    assert_near(m->textures[1]->pigment.colour.g, 1, 0);
    assert_near(m->verts[2][1], 1, 0);
    assert_near(o->texture->pigment.colour.b, 1, 0);
    assert_int_equal(m->uses, 1);
    scene_counts c = scene_count(s);
    assert_int_equal(c.triangles, 2);
    assert_int_equal(c.meshes, 1);
    scene_free(s);

    /* a texture_list moves with each object that uses the mesh, as
     * POV-Ray moves a mesh's textures with it: both objects show the
     * pattern at the same place on their triangles */
    s = parse_ok("#declare M = mesh2 {\n"
                 "  vertex_vectors { 3, <0,0,0>, <1,0,0>, <0,1,0> }\n"
                 "  texture_list { 1, texture { pigment { agate } } }\n"
                 "  face_indices { 1, <0,1,2>, 0 }\n"
                 "}\n"
                 "object { M scale 2 }\n"
                 "object { M translate x }\n");
    const scene_object *a = s->objects[0], *b = s->objects[1];
    assert_ptr_equal(a->u.mesh.mesh, b->u.mesh.mesh);
    assert_ptr_not_equal(a->u.mesh.textures[0], b->u.mesh.textures[0]);
    assert_ptr_equal(scene_mesh_tri_texture(a, 0), a->u.mesh.textures[0]);
    vec3 pa = xform_point(&a->u.mesh.textures[0]->transform, v3(1, 1, 1));
    vec3 pb = xform_point(&b->u.mesh.textures[0]->transform, v3(1, 1, 1));
    assert_near(pa.x, 2, 1e-12);
    assert_near(pa.y, 2, 1e-12);
    assert_near(pb.x, 2, 1e-12);
    assert_near(pb.y, 1, 1e-12);
    scene_free(s);

    char *e = parse_err("mesh2 {\n vertex_vectors { 2, 0, x }\n face_indices { 1, <0,1,2> }\n}", PT_ERR_SYNTAX);
    assert_prefix(e, "test.pov:3:20: error: vertex index 2 out of range");
    free(e);
}

/* POV-Ray 3.7's photon language into the IR: the global block's items and
 * defaults (parser.cpp), the light's block, the object's on/off flags and
 * POV-Ray's merged rules for which light shoots at which target and which
 * lobe a photon takes there. */
static void test_photons_language(void **st)
{
    (void)st;
    scene *s = parse_ok("global_settings { photons { count 20000 autostop 0 jitter 0.3 max_trace_level 7\n"
                        "  adc_bailout 0.02 expand_thresholds 0.1, 20 gather 15, 80 radius 0.5, 2, , 3\n"
                        "  media 100, 2 save_file \"a.ph\" } }\n"
                        "light_source { <0, 5, 0> rgb 1 photons { refraction on reflection off area_light } }\n"
                        "light_source { <1, 5, 0> rgb 1 }\n"
                        "sphere { 0, 1 photons { target 0.5 refraction on reflection off collect off } }\n"
                        "sphere { 0, 1 photons { target } }\n");
    const scene_photons *ph = &s->global.photons;
    assert_true(ph->enabled);
    assert_int_equal(ph->count, 20000);
    assert_near(ph->spacing, 1.0, 0);
    assert_near(ph->autostop, 0.0, 0);
    assert_near(ph->jitter, 0.3, 1e-15);
    assert_int_equal(ph->max_trace_level, 7);
    assert_near(ph->adc_bailout, 0.02, 1e-15);
    assert_near(ph->expand_tolerance, 0.1, 1e-15);
    assert_int_equal(ph->expand_min, 20);
    assert_int_equal(ph->gather_min, 15);
    assert_int_equal(ph->gather_max, 80);
    assert_near(ph->radius[0], 0.5, 0);
    assert_near(ph->radius[1], 2.0, 0);
    assert_near(ph->radius[2], -1.0, 0); /* left out: POV-Ray's default */
    assert_near(ph->radius[3], 3.0, 0);
    assert_int_equal(ph->media_steps, 100);
    assert_near(ph->media_factor, 2.0, 0);
    assert_string_equal(ph->file, "a.ph");
    assert_int_equal(ph->load, 0);
    unsigned all = SCENE_PH_COUNT | SCENE_PH_AUTOSTOP | SCENE_PH_JITTER | SCENE_PH_MAX_TRACE_LEVEL |
                   SCENE_PH_ADC_BAILOUT | SCENE_PH_EXPAND | SCENE_PH_GATHER | SCENE_PH_RADIUS | SCENE_PH_MEDIA |
                   SCENE_PH_SAVE_FILE;
    assert_int_equal(ph->given, all);
    const scene_light *l0 = &s->lights[0], *l1 = &s->lights[1];
    assert_true(l0->ph_refraction && !l0->ph_refraction_off && !l0->ph_reflection && l0->ph_reflection_off);
    assert_true(l0->ph_area_light);
    assert_true(!l1->ph_refraction && !l1->ph_refraction_off && !l1->ph_reflection && !l1->ph_reflection_off);
    const scene_obj_photons *a = s->objects[0]->photons, *b = s->objects[1]->photons;
    assert_true(a->target && a->refraction && !a->refraction_off && !a->reflection && a->reflection_off && !a->collect);
    /* merged rules: the first target refracts for both lights; the second
     * (no flags) only for the light that says refraction on */
    assert_true(scene_photon_shoots(l0, a) && scene_photon_shoots(l1, a));
    assert_true(scene_photon_shoots(l0, b) && !scene_photon_shoots(l1, b));
    assert_true(scene_photon_lobe(l0, b, 1) && !scene_photon_lobe(l0, b, 0));
    assert_true(!scene_photon_lobe(l1, b, 1) && scene_photon_lobe(l1, a, 1) && !scene_photon_lobe(l1, a, 0));
    assert_true(!scene_photon_lobe(l0, NULL, 0) && scene_photon_lobe(l0, NULL, 1));
    /* POV-Ray shoots no photons from a shadowless light nor from one in a
     * light_group (photonstrategytask.cpp); shadows keep the lobe rule */
    scene_light ls = *l0, lg = *l0;
    ls.shadowless = 1;
    lg.group = 1;
    assert_true(!scene_photon_shoots(&ls, a) && !scene_photon_shoots(&lg, a));
    assert_true(scene_photon_lobe(&ls, b, 1) && scene_photon_lobe(&lg, b, 1));
    scene_free(s);

    /* defaults of a bare block; spacing alone */
    s = parse_ok("global_settings { photons { spacing 0.02 } }\n");
    ph = &s->global.photons;
    assert_true(ph->enabled);
    assert_int_equal(ph->given, SCENE_PH_SPACING);
    assert_near(ph->spacing, 0.02, 1e-15);
    assert_int_equal(ph->count, 0);
    assert_near(ph->autostop, 0.5, 0);
    assert_near(ph->jitter, 0.4, 0);
    assert_int_equal(ph->max_trace_level, -1);
    assert_true(ph->adc_bailout < 0 && ph->gather_min == 20 && ph->gather_max == 100 && ph->expand_min == 35);
    assert_null(ph->file);
    scene_free(s);
    s = parse_ok("sphere { 0, 1 }\n");
    assert_false(s->global.photons.enabled);
    scene_free(s);

    /* errors, located */
    char *m = parse_err("global_settings { photons { gather 50, 10 } }\n", PT_ERR_SYNTAX);
    assert_non_null(strstr(m, "min gather count"));
    free(m);
    m = parse_err("global_settings {\n photons { media -1 } }\n", PT_ERR_SYNTAX);
    assert_prefix(m, "test.pov:2:");
    free(m);
    m = parse_err("global_settings { photons { bogus 1 } }\n", PT_ERR_SYNTAX);
    assert_prefix(m, "test.pov:1:");
    free(m);
    m = parse_err("sphere { 0, 1 finish {\n reflection { 0.5 exponent 0 } } }\n", PT_ERR_SYNTAX);
    assert_prefix(m, "test.pov:2:");
    assert_non_null(strstr(m, "reflection exponent"));
    free(m);
    m = parse_err("light_source { 0, 1 photons { target } }\n", PT_ERR_SYNTAX);
    assert_prefix(m, "test.pov:1:");
    free(m);
}

static void test_lights(void **st)
{
    (void)st;
    scene *s = parse_ok("light_source { <1,2,3> color rgb <1,0.5,0.25> }\n"
                        "light_source { 0, 1 spotlight point_at <0,-1,0> radius 10 falloff 20 tightness 5 translate y }\n"
                        "light_source { 0, 1 cylinder point_at y }\n"
                        "light_source { 0, 1 parallel point_at -y shadowless fade_distance 3 fade_power 1 }\n"
                        "light_source { 0, 1 area_light x*2, z*2, 3, 5 adaptive 1 circular orient rotate z*90 media_interaction off }\n"
                        "light_source { 0, 1 looks_like { sphere { 0, 0.1 } } translate x }\n");
    assert_int_equal(s->nlights, 6);
    const scene_light *l = s->lights;
    assert_int_equal(l[0].kind, LIGHT_POINT);
    assert_near(l[0].colour.g, 0.5, 0);
    assert_int_equal(l[1].kind, LIGHT_SPOT);
    assert_vec(l[1].position, v3(0, 1, 0), 0);
    assert_vec(l[1].point_at, v3(0, 0, 0), 0);
    assert_near(l[1].radius, 10, 0);
    assert_near(l[1].falloff, 20, 0);
    assert_near(l[1].tightness, 5, 0);
    assert_int_equal(l[2].kind, LIGHT_CYLINDER);
    assert_near(l[2].radius, 0.75, 0);
    assert_true(l[3].parallel);
    assert_true(l[3].shadowless);
    assert_near(l[3].fade_distance, 3, 0);
    assert_true(l[4].area);
    assert_int_equal(l[4].size1, 3);
    assert_int_equal(l[4].size2, 5);
    assert_int_equal(l[4].adaptive, 1);
    assert_true(l[4].circular && l[4].orient);
    assert_false(l[4].media_interaction);
    assert_vec(l[4].axis1, v3(0, 2, 0), 1e-12);
    assert_non_null(l[5].looks_like);
    assert_vec(xform_point(&l[5].looks_like->transform, v3(0, 0, 0)), v3(1, 0, 0), 0);
    assert_int_equal(l[0].adaptive, 100);
    scene_free(s);

    char *e = parse_err("light_source { 0, 1\n  radius 5 }", PT_ERR_SYNTAX);
    assert_prefix(e, "test.pov:2:3: error: 'radius' cannot be used with a standard light source");
    free(e);
}

static void test_global_settings(void **st)
{
    (void)st;
    scene *s = parse_ok("global_settings { assumed_gamma 2.2 ambient_light rgb <0.5,0.5,1> max_trace_level 10 adc_bailout 0.01\n"
                        "  radiosity { brightness 2 gray_threshold 0.5 low_error_factor 0.7 minimum_reuse 0.01 always_sample on normal on media off count 10, 20 nearest_count 3, 1\n"
                        "    adc_bailout 0.05 max_sample 2 maximum_reuse 0.3 subsurface on }\n"
                        "  number_of_waves 5 }\n"
                        "background { rgb <0.1, 0.2, 0.3> }\n");
    assert_near(s->global.assumed_gamma, 2.2, 0);
    assert_near(s->global.ambient_light.b, 1, 0);
    assert_int_equal(s->global.max_trace_level, 10);
    assert_near(s->global.adc_bailout, 0.01, 0);
    assert_near(s->global.radiosity.brightness, 2, 0);
    assert_near(s->global.radiosity.gray_threshold, 0.5, 0);
    assert_near(s->global.radiosity.low_error_factor, 0.7, 0);
    assert_near(s->global.radiosity.minimum_reuse, 0.01, 0);
    assert_true(s->global.radiosity.always_sample);
    assert_true(s->global.radiosity.normal);
    assert_int_equal(s->global.radiosity.count, 10);
    assert_int_equal(s->global.radiosity.nearest_count, 3);
    assert_int_equal(s->global.radiosity.direction_pool, 20);
    assert_int_equal(s->global.radiosity.nearest_count_pretrace, 1);
    assert_near(s->global.radiosity.adc_bailout, 0.05, 0);
    assert_near(s->global.radiosity.max_sample, 2, 0);
    assert_near(s->global.radiosity.maximum_reuse, 0.3, 0);
    assert_true(s->global.radiosity.subsurface);
    assert_near(s->background.g, 0.2, 0);
    assert_near(s->background.t, 0, 0);
    scene_free(s);
    char *e = parse_err("global_settings { radiosity {\n  count 0 } }", PT_ERR_SYNTAX);
    assert_string_equal(e, "test.pov:2:3: error: radiosity count must be a positive number");
    free(e);
}

/* ------------------------------------------------------------ errors */

static void test_error_unknown(void **st)
{
    (void)st;
    char *e = parse_err("sphere { 0, 1 }\n  foo", PT_ERR_SYNTAX);
    assert_string_equal(e, "test.pov:2:3: error: unknown identifier 'foo'");
    free(e);
    e = parse_err("sphere { 0, 1\n  spotlight }", PT_ERR_SYNTAX);
    assert_string_equal(e, "test.pov:2:3: error: expected '}' closing sphere, found 'spotlight'");
    free(e);
    e = parse_err("sphere { Nope, 1 }", PT_ERR_SYNTAX);
    assert_string_equal(e, "test.pov:1:10: error: undeclared identifier 'Nope'");
    free(e);
    e = parse_err("#declare A = 1;\n#bogus", PT_ERR_SYNTAX); /* a '#' without directive is ignored */
    assert_string_equal(e, "test.pov:2:2: error: unknown identifier 'bogus'");
    free(e);
    e = parse_err("#declare A = 1;\n#sphere", PT_ERR_SYNTAX);
    assert_string_equal(e, "test.pov:2:2: error: unknown directive #sphere");
    free(e);
}

static void test_error_unterminated(void **st)
{
    (void)st;
    char *e = parse_err("sphere { 0, 1", PT_ERR_SYNTAX);
    assert_string_equal(e, "test.pov:1:14: error: unterminated sphere block opened at 1:8");
    free(e);
    e = parse_err("union {\n  box { 0, 1 }\n  sphere { 0, 1\n", PT_ERR_SYNTAX);
    assert_string_equal(e, "test.pov:4:1: error: unterminated sphere block opened at 3:10");
    free(e);
    e = parse_err("#if (1)\nsphere { 0, 1 }\n", PT_ERR_SYNTAX);
    assert_string_equal(e, "test.pov:3:1: error: unterminated #if opened at 1:1 (missing #end)");
    free(e);
    e = parse_err("/* open comment\n", PT_ERR_SYNTAX);
    assert_string_equal(e, "test.pov:1:1: error: unterminated comment");
    free(e);
    e = parse_err("#declare S = \"abc\n", PT_ERR_SYNTAX);
    assert_string_equal(e, "test.pov:1:14: error: unterminated string");
    free(e);
    scene *s = parse_ok("\xEF\xBB\xBFsphere { 0, 1 }\r\n// CRLF and a byte order mark\r\n");
    assert_int_equal(s->objects[0]->loc.col, 1);
    scene_free(s);
    e = parse_err("sphere { 0, 1 }\r\n\r\n  @", PT_ERR_SYNTAX);
    assert_string_equal(e, "test.pov:3:3: error: unexpected character '@'");
    free(e);
    e = parse_err("sphere { 0, 1 } }", PT_ERR_SYNTAX);
    assert_prefix(e, "test.pov:1:17: error: expected object");
    free(e);
}

static void test_error_loop_limit(void **st)
{
    (void)st;
    sdl_options o;
    sdl_default_options(&o);
    o.max_loop_iterations = 1000;
    char *e = parse_err_opt("#declare I = 0;\n#while (1) #declare I = I + 1; #end", &o, PT_ERR_LIMIT);
    assert_string_equal(e, "test.pov:2:1: error: #while loop exceeded 1000 iterations");
    free(e);
    /* recursion without end hits the macro depth limit */
    o.max_macro_depth = 50;
    e = parse_err_opt("#macro R(N) R(N+1) #end\nR(0)", &o, PT_ERR_LIMIT);
    assert_prefix(e, "test.pov:1:13: error: macro calls nested more than 50 deep");
    free(e);
}

static char tmpdir[256];

static void write_file(const char *name, const char *text)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static int make_tmpdir(void **st)
{
    (void)st;
    snprintf(tmpdir, sizeof tmpdir, "/tmp/pt_parser_XXXXXX");
    return mkdtemp(tmpdir) ? 0 : -1;
}

static uint64_t input_hash_of(const char *name)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    diag *d = diag_new();
    scene *s = NULL;
    assert_int_equal(sdl_parse_file(path, NULL, &s, d), PT_OK);
    uint64_t h = s->input_hash;
    scene_free(s);
    diag_free(d);
    return h;
}

/* scene.input_hash covers every file the parse read: an edit of an
 * #include'd file or of a #read data file changes it (the GI cache and a
 * tile's header name the scene by it), parsing again does not, and a
 * byte moved from one file to the other does (each file is hashed with its
 * length). */
static void test_input_hash(void **st)
{
    (void)st;
    write_file("hash.inc", "#declare R = 2;\n");
    write_file("hash.dat", "3,\n");
    write_file("hash.pov", "#include \"hash.inc\"\n#fopen F \"hash.dat\" read\n#read (F, V)\n"
                           "sphere { 0, R + V }\n");
    uint64_t h0 = input_hash_of("hash.pov");
    assert_true(h0 == input_hash_of("hash.pov"));
    write_file("hash.inc", "#declare R = 3;\n");
    uint64_t h1 = input_hash_of("hash.pov");
    assert_true(h1 != h0);
    write_file("hash.dat", "4,\n");
    uint64_t h2 = input_hash_of("hash.pov");
    assert_true(h2 != h1 && h2 != h0);
    write_file("hash.inc", "#declare R = 2;\n");
    write_file("hash.dat", "3,\n");
    assert_true(input_hash_of("hash.pov") == h0);
    /* "#declare R = 2;\n" + "3,\n" against "#declare R = 2;" + "\n3,\n": same bytes in all */
    write_file("hash.inc", "#declare R = 2;");
    write_file("hash.dat", "\n3,\n");
    assert_true(input_hash_of("hash.pov") != h0);
}

static void test_error_files(void **st)
{
    (void)st;
    char path[512];
    write_file("inc.inc", "#declare R = 2;\n#macro Bad(A)\n  sphere { 0, A Oops }\n#end\n");
    write_file("bad.inc", "\n  sphere { 0, 1 foo }\n");
    write_file("main.pov", "#include \"inc.inc\"\nsphere { 0, R }\n");
    write_file("chain.pov", "#declare X = 1;\n#include \"bad.inc\"\n");
    write_file("macro.pov", "#include \"inc.inc\"\n\n    Bad(1)\n");
    write_file("missing.pov", "\n#include \"nowhere.inc\"\n");

    diag *d = diag_new();
    scene *s = NULL;
    snprintf(path, sizeof path, "%s/main.pov", tmpdir);
    assert_int_equal(sdl_parse_file(path, NULL, &s, d), PT_OK);
    assert_near(s->objects[0]->u.sphere.radius, 2, 0);
    assert_int_equal(s->nfiles, 2);
    scene_free(s);
    diag_free(d);

    /* error inside an include: location in the include, chain below */
    d = diag_new();
    snprintf(path, sizeof path, "%s/chain.pov", tmpdir);
    assert_int_equal(sdl_parse_file(path, NULL, &s, d), PT_ERR_SYNTAX);
    const diag_msg *m = diag_get(d, 0);
    assert_int_equal(m->loc.line, 2);
    assert_int_equal(m->loc.col, 17);
    char want[1024];
    snprintf(want, sizeof want, "expected '}' closing sphere, found undeclared identifier 'foo'\n  included from %s/chain.pov:2:1", tmpdir);
    assert_string_equal(m->text, want);
    diag_free(d);

    /* error inside a macro body: "in macro ... called from" */
    d = diag_new();
    snprintf(path, sizeof path, "%s/macro.pov", tmpdir);
    assert_int_equal(sdl_parse_file(path, NULL, &s, d), PT_ERR_SYNTAX);
    m = diag_get(d, 0);
    snprintf(want, sizeof want, "%s/inc.inc", tmpdir);
    assert_string_equal(m->loc.file, want);
    assert_int_equal(m->loc.line, 3);
    assert_int_equal(m->loc.col, 17);
    snprintf(want, sizeof want, "expected '}' closing sphere, found undeclared identifier 'Oops'\n  in macro Bad called from %s/macro.pov:3:5", tmpdir);
    assert_string_equal(m->text, want);
    diag_free(d);

    /* missing include file */
    d = diag_new();
    snprintf(path, sizeof path, "%s/missing.pov", tmpdir);
    assert_int_equal(sdl_parse_file(path, NULL, &s, d), PT_ERR_SYNTAX); /* a scene error: exit 1 */
    assert_null(s);
    m = diag_get(d, 0);
    assert_int_equal(m->loc.line, 2);
    assert_int_equal(m->loc.col, 1);
    assert_string_equal(m->text, "cannot find include file \"nowhere.inc\"");
    diag_free(d);

    /* missing scene file */
    d = diag_new();
    snprintf(path, sizeof path, "%s/no_such_scene.pov", tmpdir);
    assert_int_equal(sdl_parse_file(path, NULL, &s, d), PT_ERR_IO);
    assert_null(s);
    assert_int_equal(diag_errors(d), 1);
    assert_string_equal(diag_get(d, 0)->loc.file, path);
    diag_free(d);

    /* -L directories are searched */
    sdl_options o;
    sdl_default_options(&o);
    const char *dirs[] = {tmpdir};
    o.lib_paths = dirs;
    o.nlib_paths = 1;
    o.no_default_lib = 1;
    d = diag_new();
    assert_int_equal(sdl_parse_string("elsewhere/x.pov", "#include \"inc\"\nsphere { 0, R }", &o, &s, d), PT_OK);
    scene_free(s);
    diag_free(d);
    /* no default library: colors.inc is not found */
    d = diag_new();
    assert_int_equal(sdl_parse_string("x.pov", "#include \"colors.inc\"", &o, &s, d), PT_ERR_SYNTAX);
    diag_free(d);
    /* include depth limit */
    write_file("self.inc", "#include \"self.inc\"\n");
    o.max_include_depth = 10;
    d = diag_new();
    assert_int_equal(sdl_parse_string("x.pov", "#include \"self.inc\"", &o, &s, d), PT_ERR_LIMIT);
    diag_free(d);
}

/* ------------------------------------------------------------ scene sweep */

static int sweep_file(const char *path, int *ok, int *located)
{
    diag *d = diag_new();
    scene *s = NULL;
    pt_status st = sdl_parse_file(path, NULL, &s, d);
    if (st == PT_OK) {
        (*ok)++;
    } else {
        const diag_msg *m = NULL;
        for (int i = 0; i < diag_count(d) && !m; i++)
            if (diag_get(d, i)->severity == DIAG_ERROR) m = diag_get(d, i);
        if (m && m->loc.file && m->loc.line > 0) (*located)++;
        else print_message("unlocated error in %s\n", path);
        if (m) {
            char *f = diag_format(m);
            print_message("  %s\n", f);
            free(f);
        }
    }
    scene_free(s);
    diag_free(d);
    return st;
}

static int sweep_dir(const char *dir, int *n, int *ok, int *located)
{
    DIR *dd = opendir(dir);
    if (!dd) return 0;
    struct dirent *e;
    char *names[256];
    int k = 0;
    while ((e = readdir(dd)) && k < 256) {
        size_t l = strlen(e->d_name);
        if (l > 4 && strcmp(e->d_name + l - 4, ".pov") == 0) names[k++] = strdup(e->d_name);
    }
    closedir(dd);
    for (int i = 0; i < k; i++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        sweep_file(path, ok, located);
        (*n)++;
        free(names[i]);
    }
    return 1;
}

static void test_scene_sweep(void **st)
{
    (void)st;
    static const char *dirs[] = {
        "/usr/share/povray-3.7/scenes/radiosity",
        "/usr/share/povray-3.7/scenes/lights",
        "/usr/share/povray-3.7/scenes/objects",
        "/usr/share/povray-3.7/scenes/camera",
        "/usr/share/povray-3.7/scenes/interior",
        "/usr/share/povray-3.7/scenes/language",
        "/usr/share/povray-3.7/scenes/language/macros",
        "/usr/share/povray-3.7/scenes/textures/finishes",
        "/usr/share/povray-3.7/scenes/advanced",
    };
    int n = 0, ok = 0, located = 0;
    for (size_t i = 0; i < sizeof dirs / sizeof dirs[0]; i++) sweep_dir(dirs[i], &n, &ok, &located);
    if (n == 0) skip();
    print_message("scene sweep: %d of %d files parse; %d fail with a located error\n", ok, n, located);
    assert_int_equal(ok + located, n);
}

/* The object pattern records its scene's serial, which keys the
 * renderer's cache of the object's shapes where an evaluation names no
 * scene (a pigment function's). */
static void test_object_pattern_serial(void **st)
{
    (void)st;
    scene *s = parse_ok("sphere { 0, 1 pigment { object { sphere { 0, 0.5 } rgb 1 rgb 0 } } }\n");
    assert_int_equal(s->nobjects, 1);
    const scene_texture *t = s->objects[0]->texture;
    assert_non_null(t);
    assert_int_equal(t->pigment.kind, PIGMENT_PATTERN);
    assert_non_null(t->pigment.pat);
    assert_int_equal(t->pigment.pat->kind, PAT_OBJECT);
    assert_non_null(t->pigment.pat->object);
    assert_true(s->serial != 0);
    assert_true(t->pigment.pat->object_serial == s->serial);
    scene_free(s);
}

/* A layered texture lets light through only where every layer does (the
 * layers' filters multiply): one solid layer without filter or transmit
 * makes the whole texture opaque (transmit_texture_may), as stones.inc's
 * T_StoneN over pigment { color Black }; layers that all may transmit, or
 * a single transmitting one, may. */
static void test_layered_transmit(void **st)
{
    (void)st;
    scene *s = parse_ok("sphere { 0, 1 texture { pigment { color rgb 0 } } texture { pigment { rgbt <1, 1, 1, 0.5> } } }\n"
                        "sphere { 0, 1 texture { pigment { rgbt <1, 1, 1, 0.5> } } texture { pigment { color rgb 1 } } }\n"
                        "sphere { 0, 1 texture { pigment { rgbf <1, 1, 1, 0.5> } } texture { pigment { rgbt 0.5 } } }\n"
                        "sphere { 0, 1 texture { pigment { rgbt 0.5 } } }\n"
                        "sphere { 0, 1 texture { pigment { color rgb 1 } } }\n"
                        "sphere { 0, 1 texture { pigment { checker rgb 0, rgbt 1 } } texture { pigment { rgbt 0.5 } } }\n");
    assert_int_equal(s->nobjects, 6);
    int want[6] = {0, 0, 1, 1, 0, 1};
    for (int i = 0; i < 6; i++) {
        assert_non_null(s->objects[i]->texture);
        assert_int_equal(transmit_texture_may(s->objects[i]->texture), want[i]);
    }
    scene_free(s);
}

/* An image_map lets light through only where a pixel has a filter or
 * transmit above 0 (transmit_texture_may reads the image's pixels, not its
 * format): fract003.png's palette has a transparent entry (tRNS, index 0)
 * that no pixel uses, so the image stops all light; a transmit given to a
 * used entry (index 1), or to all of them, lets light through, one given
 * to the unused entry does not. */
static void test_image_map_transmit(void **st)
{
    (void)st;
    if (access("/usr/share/povray-3.7/include/fract003.png", R_OK) != 0) skip();
    scene *s = parse_ok("#declare F = \"/usr/share/povray-3.7/include/fract003.png\";\n"
                        "plane { y, 0 pigment { image_map { png F } } }\n"
                        "plane { y, 0 pigment { image_map { png F transmit 1, 0.5 } } }\n"
                        "plane { y, 0 pigment { image_map { png F transmit 0, 0.5 } } }\n"
                        "plane { y, 0 pigment { image_map { png F transmit all 0.3 } } }\n");
    assert_int_equal(s->nobjects, 4);
    int want[4] = {0, 1, 0, 1};
    for (int i = 0; i < 4; i++) {
        const scene_texture *t = s->objects[i]->texture;
        assert_non_null(t);
        assert_non_null(t->pigment.pat);
        assert_non_null(t->pigment.pat->image.image);
        assert_int_equal(t->pigment.pat->image.image->has_alpha, 1);
        assert_int_equal(transmit_texture_may(t), want[i]);
    }
    scene_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_keywords_sorted),
        cmocka_unit_test(test_arithmetic),
        cmocka_unit_test(test_functions),
        cmocka_unit_test(test_vectors),
        cmocka_unit_test(test_directives),
        cmocka_unit_test(test_options),
        cmocka_unit_test(test_messages),
        cmocka_unit_test(test_camera_cornell),
        cmocka_unit_test(test_camera_look_at),
        cmocka_unit_test(test_cornell_lights),
        cmocka_unit_test(test_cornell_objects),
        cmocka_unit_test(test_shapes),
        cmocka_unit_test(test_transforms),
        cmocka_unit_test(test_textures),
        cmocka_unit_test(test_object_copies_ok),
        cmocka_unit_test(test_mesh2),
        cmocka_unit_test(test_lights),
        cmocka_unit_test(test_global_settings),
        cmocka_unit_test(test_error_unknown),
        cmocka_unit_test(test_error_unterminated),
        cmocka_unit_test(test_error_loop_limit),
        cmocka_unit_test_setup(test_error_files, make_tmpdir),
        cmocka_unit_test(test_photons_language),
        cmocka_unit_test_setup(test_input_hash, make_tmpdir),
        cmocka_unit_test(test_scene_sweep),
        cmocka_unit_test(test_object_pattern_serial),
        cmocka_unit_test(test_layered_transmit),
        cmocka_unit_test(test_image_map_transmit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
