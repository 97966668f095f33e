/* sdl_geom.c - parse-time trace(), inside(), min_extent() and max_extent()
 * on the IR objects built so far, answered by geom/: the object's CSG tree
 * (geom_csg_build, meshes included), the same shapes and inside rules that
 * render it, and POV-Ray's bounding boxes (geom_extent). */
#include "sdl_geom.h"
#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "func.h"
#include "geom_csg.h"
#include "geom_extent.h"
#include "sdl_directive.h"
#include "sdl_expr.h"

#define DEPTH_TOLERANCE 1e-6 /* POV-Ray's shapes ignore hits closer than this */
/* Unbounded shapes (planes, quadric, poly) are clipped to a cube of half
 * side QUERY_EXTENT around the origin, and a tree with one is searched in
 * windows of t that grow from QUERY_WINDOW by 4x: the quartic root finder
 * loses the near root of an unbounded poly on long intervals. Only hits at
 * t > 0 are reported then. */
#define QUERY_EXTENT 1.0e5
#define QUERY_WINDOW 100.0
#define QUERY_BUCKETS 256
#define MAX_DEPTH 512

/* One object's prepared tree, built on first use and kept for the parse
 * (declared objects do not change). */
typedef struct query {
    const scene_object *o;
    geom_csg c;
    int empty;    /* no members, or provably empty */
    int infinite; /* an unbounded member: search in windows */
    struct query *next;
} query;

/* The first shape in o that geom cannot answer for (its name), or NULL. */
static const char *unsupported_in(sdl_parser *p, const scene_object *o, int depth)
{
    if (!o || depth > MAX_DEPTH) return NULL;
    const char *why = NULL;
    switch (o->kind) {
    case SHAPE_UNION: case SHAPE_MERGE: case SHAPE_INTERSECTION: case SHAPE_DIFFERENCE:
        for (int i = 0; i < o->u.csg.nkids && !why; i++) why = unsupported_in(p, o->u.csg.kids[i], depth + 1);
        break;
    case SHAPE_SPHERE: case SHAPE_BOX: case SHAPE_PLANE: case SHAPE_TRIANGLE: case SHAPE_SMOOTH_TRIANGLE:
    case SHAPE_MESH: case SHAPE_CYLINDER: case SHAPE_CONE: case SHAPE_DISC: case SHAPE_TORUS:
    case SHAPE_POLYGON: case SHAPE_LATHE: case SHAPE_SOR: case SHAPE_PRISM: case SHAPE_SUPERELLIPSOID:
    case SHAPE_QUADRIC: case SHAPE_POLY: case SHAPE_BLOB: case SHAPE_TEXT: case SHAPE_JULIA: case SHAPE_OVUS:
        break;
    case SHAPE_HEIGHT_FIELD:
        /* kept without height data (e.g. height_field { function ... }):
         * no answer rather than a wrong one */
        if (!o->u.height_field || !o->u.height_field->heights) why = "height_field without height data";
        break;
    case SHAPE_ISOSURFACE: {
        /* its function must be one the parse can evaluate */
        const scene_isosurface *iso = o->u.isosurface;
        if (!iso || !iso->fn) break;
        double args[FUNC_MAX_SLOTS], out[5];
        memset(args, 0, sizeof args);
        const char *need = NULL;
        if (func_eval(iso->fn, args, out, p->opt.func_env, &need) != PT_OK) {
            char buf[160];
            snprintf(buf, sizeof buf, "isosurface (its function needs %s)", need ? need : "an evaluator");
            why = sdl_strndup(p, buf, strlen(buf));
        }
        break;
    }
    default:
        why = o->name ? o->name : "object";
        break;
    }
    return why ? why : unsupported_in(p, o->clip, depth + 1);
}

/* The prepared tree of o; NULL when out of memory or over the nesting
 * limit. */
static query *query_get(sdl_parser *p, const scene_object *o)
{
    query **tab = p->geom_cache;
    if (!tab) {
        tab = calloc(QUERY_BUCKETS, sizeof *tab);
        if (!tab) return NULL;
        p->geom_cache = tab;
    }
    size_t b = ((size_t)o >> 4) % QUERY_BUCKETS;
    for (query *q = tab[b]; q; q = q->next)
        if (q->o == o) return q;
    query *q = calloc(1, sizeof *q);
    if (!q) return NULL;
    q->o = o;
    geom_csg_builder bld = {NULL, NULL, 0, 1, NULL, 0};
    if (geom_csg_build(&q->c, o, NULL, 0, -1, 0, &bld) != PT_OK) {
        geom_csg_free(&q->c);
        free(q);
        return NULL;
    }
    q->empty = !geom_csg_finish(&q->c);
    for (int i = 0; i < q->c.nshapes; i++)
        if (q->c.shapes[i].infinite) q->infinite = 1;
    geom_csg_clip(&q->c, v3s(-QUERY_EXTENT), v3s(QUERY_EXTENT));
    q->next = tab[b];
    tab[b] = q;
    return q;
}

/* Nearest crossing of the world ray with t > tmin (dir unit), under
 * POV-Ray's rules for its rays (GEOM_RAY_POV): trace() answers with the
 * object's own intersection routine (POV-Ray 3.7 parser_expressions.cpp
 * Parse_Trace, through Find_Intersection), so an isosurface's point is
 * placed as its rays' are. */
static int query_hit(const query *q, vec3 org, vec3 dir, double tmin, geom_csg_hit *h)
{
    if (q->empty) return 0;
    if (!q->infinite) return geom_csg_intersect(&q->c, org, dir, tmin, INFINITY, h, GEOM_RAY_POV);
    double a = tmin > 0.0 ? tmin : 0.0, w = QUERY_WINDOW, reach = 4.0 * QUERY_EXTENT;
    while (a < reach) {
        if (geom_csg_intersect(&q->c, org, dir, a, a + w, h, GEOM_RAY_POV)) return 1;
        a += w;
        w *= 4.0;
    }
    return 0;
}

/* object_param := object identifier (a declared object, not a bare light) */
static const scene_object *object_param(sdl_parser *p, const char *fn)
{
    sdl_tok t = sdl_next(p);
    if (t.tk.kind == TOK_IDENT && t.val.kind == VAL_OBJECT && t.val.ptr && ((const sdl_obj *)t.val.ptr)->obj)
        return ((const sdl_obj *)t.val.ptr)->obj;
    char what[64];
    snprintf(what, sizeof what, "object identifier in %s", fn);
    sdl_unexpected(p, &t, what);
    return NULL;
}

static void unsupported(sdl_parser *p, src_loc loc, const char *fn, const char *what)
{
    if (!what) sdl_error(p, loc, PT_ERR_NOMEM, "out of memory");
    else sdl_error(p, loc, PT_ERR_UNSUPPORTED, "%s: shape '%s' is not supported by the parse-time geometry", fn, what);
}

vec3 sdl_trace_fn(sdl_parser *p, src_loc loc)
{
    vec3 res = v3(0, 0, 0), normal = v3(0, 0, 0);
    sdl_expect(p, TOK_LPAREN, "'('");
    const scene_object *o = object_param(p, "trace");
    sdl_accept(p, TOK_COMMA);
    vec3 org = sdl_vector(p);
    sdl_accept(p, TOK_COMMA);
    src_loc dloc = sdl_peek(p)->tk.loc;
    vec3 dir = sdl_vector(p);
    if (!sdl_ok(p) || !o) return res;
    if (v3_len2(dir) == 0) {
        sdl_error(p, dloc, PT_ERR_SYNTAX, "trace direction has zero length");
        return res;
    }
    dir = v3_norm(dir);
    const char *why = unsupported_in(p, o, 0);
    query *q = why ? NULL : query_get(p, o);
    if (!q) {
        unsupported(p, loc, "trace", why);
        return res;
    }
    geom_csg_hit h;
    if (query_hit(q, org, dir, DEPTH_TOLERANCE, &h)) {
        assert(h.shape >= 0 && h.shape < q->c.nshapes && h.t > DEPTH_TOLERANCE);
        res = v3_madd(org, dir, h.t);
        normal = geom_shape_pov_normal(&q->c.shapes[h.shape], res, h.part);
        if (h.flip) normal = v3_neg(normal);
    }
    if (sdl_accept(p, TOK_COMMA) && !sdl_is(sdl_peek(p), TOK_RPAREN)) {
        p->hold_arrays++;
        sdl_tok id = sdl_next(p);
        p->hold_arrays--;
        if (id.tk.kind != TOK_IDENT || id.val.kind != VAL_VECTOR || id.val.dim != 3) {
            sdl_error(p, id.tk.loc, PT_ERR_SYNTAX, "trace's fourth argument must be a declared vector identifier (it receives the normal)");
            return res;
        }
        sdl_value v = id.val;
        v.v[0] = normal.x;
        v.v[1] = normal.y;
        v.v[2] = normal.z;
        sdl_symtarget tg = sdl_symtab_target(p->sym, id.tk.text, (size_t)id.tk.len, 0);
        if (sdl_symtab_assign(p->sym, &tg, id.tk.text, (size_t)id.tk.len, &v) == 0) sdl_error(p, id.tk.loc, PT_ERR_NOMEM, "out of memory");
    }
    sdl_expect(p, TOK_RPAREN, "')'");
    return res;
}

/* Patch objects have no inside (POV-Ray: "Solid object identifier expected"). */
static int is_patch(const scene_object *o)
{
    return o->kind == SHAPE_TRIANGLE || o->kind == SHAPE_SMOOTH_TRIANGLE || (o->kind == SHAPE_MESH && !o->u.mesh.inside_vector_set);
}

double sdl_inside_fn(sdl_parser *p, src_loc loc)
{
    sdl_expect(p, TOK_LPAREN, "'('");
    src_loc oloc = sdl_peek(p)->tk.loc;
    const scene_object *o = object_param(p, "inside");
    sdl_accept(p, TOK_COMMA);
    vec3 pt = sdl_vector(p);
    sdl_expect(p, TOK_RPAREN, "')'");
    if (!sdl_ok(p) || !o) return 0;
    if (is_patch(o)) {
        sdl_error(p, oloc, PT_ERR_SYNTAX, "inside needs a solid object; a %s has no inside (a mesh needs inside_vector)", o->name ? o->name : "patch");
        return 0;
    }
    const char *why = unsupported_in(p, o, 0);
    query *q = why ? NULL : query_get(p, o);
    if (!q) {
        unsupported(p, loc, "inside", why);
        return 0;
    }
    return q->c.nnodes > 0 && q->c.kids && geom_csg_inside(&q->c, 0, pt);
}

vec3 sdl_extent_fn(sdl_parser *p, src_loc loc, int max)
{
    const char *fn = max ? "max_extent" : "min_extent";
    sdl_expect(p, TOK_LPAREN, "'('");
    const sdl_tok *t = sdl_peek(p);
    if (max && t->tk.kind == TOK_IDENT && t->val.kind == VAL_PIGMENT) {
        sdl_error(p, t->tk.loc, PT_ERR_UNSUPPORTED, "max_extent of an image_map pigment (the image size) is not supported at parse time");
        return v3(0, 0, 0);
    }
    const scene_object *o = object_param(p, fn);
    sdl_expect(p, TOK_RPAREN, "')'");
    if (!sdl_ok(p) || !o) return v3(0, 0, 0);
    vec3 lo, hi;
    const char *what;
    if (geom_extent(o, &lo, &hi, &what) != 0) {
        unsupported(p, loc, fn, what);
        return v3(0, 0, 0);
    }
    return max ? hi : lo;
}

void sdl_geom_free(sdl_parser *p)
{
    query **tab = p->geom_cache;
    if (!tab) return;
    for (int b = 0; b < QUERY_BUCKETS; b++) {
        query *q = tab[b];
        while (q) {
            query *n = q->next;
            geom_csg_free(&q->c);
            free(q);
            q = n;
        }
    }
    free(tab);
    p->geom_cache = NULL;
}
