/* sdl_shape.c - grammar of the further POV-Ray shapes (sdl_shape.h).
 *
 * Each rule follows POV-Ray 3.7's documented syntax; counts, point checks
 * and closing rules are POV-Ray's (its parser is the reference for what a
 * scene means). EPSILON below is POV-Ray's 1e-10 for "the same point". */
#include "sdl_shape.h"
#include "grow.h"
#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "pool.h"
#include "sdl_directive.h"
#include "sdl_expr.h"
#include "sdl_font.h"
#include "sdl_function.h"
#include "sdl_hfimage.h"
#include "sdl_material.h"
#include "sdl_object.h"

#define SDL_SHAPE_EPSILON 1e-10
#define SDL_DEFAULT_LIB_DIR "/usr/share/povray-3.7/include"
#define MAX_POLY_ORDER 35 /* POV-Ray's MAX_ORDER */

int sdl_shape_handles(sdl_kw k)
{
    switch (k) {
    case KW_POLYGON: case KW_LATHE: case KW_SOR: case KW_PRISM: case KW_SUPERELLIPSOID:
    case KW_QUADRIC: case KW_POLY: case KW_CUBIC: case KW_QUARTIC: case KW_POLYNOMIAL:
    case KW_BLOB: case KW_HEIGHT_FIELD: case KW_TEXT: case KW_SPHERE_SWEEP: case KW_BICUBIC_PATCH:
    case KW_ISOSURFACE: case KW_PARAMETRIC: case KW_JULIA_FRACTAL: case KW_OVUS:
        return 1;
    default:
        return 0;
    }
}

/* ------------------------------------------------------------ helpers */

static void *alloc_n(sdl_parser *p, size_t n, size_t elem)
{
    if (n == 0) n = 1;
    if (n > SIZE_MAX / elem) {
        sdl_error(p, p->last_loc, PT_ERR_LIMIT, "too many points");
        return NULL;
    }
    return sdl_alloc(p, n * elem);
}

/* count := float ; checked against [lo, hi] */
static int parse_count(sdl_parser *p, const char *what, int lo, int hi)
{
    src_loc loc = sdl_peek(p)->tk.loc;
    double n = sdl_float(p);
    if (!sdl_ok(p)) return -1;
    if (!(n >= lo) || n > hi) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "%s: %g points given, %d to %d allowed", what, n, lo, hi);
        return -1;
    }
    return (int)n;
}

/* uv_list := uv { [','] uv } ; n 2-D points */
/* n items of `elem` bytes read by `one` into a buffer that grows as they
 * arrive (a huge declared count costs nothing until its points exist), then
 * moved to the scene arena with room for `extra` more. */
static void *read_items(sdl_parser *p, int n, int extra, size_t elem, void (*one)(sdl_parser *, void *))
{
    size_t cap = 0, got = 0;
    unsigned char *buf = NULL;
    sdl_accept(p, TOK_COMMA);
    for (int i = 0; i < n && sdl_ok(p); i++) {
        if (got == cap) {
            size_t nc = cap ? 2 * cap : 64;
            unsigned char *nb = realloc(buf, nc * elem);
            if (!nb) {
                free(buf);
                sdl_error(p, p->last_loc, PT_ERR_NOMEM, "out of memory");
                return NULL;
            }
            buf = nb;
            cap = nc;
        }
        one(p, buf + got * elem);
        got++;
        sdl_accept(p, TOK_COMMA);
    }
    void *out = NULL;
    if (sdl_ok(p)) {
        out = alloc_n(p, got + (size_t)extra, elem);
        if (out && got) memcpy(out, buf, got * elem);
    }
    free(buf);
    return out;
}

static void read_uv(sdl_parser *p, void *dst) { sdl_vector_n(p, (double *)dst, 2); }
static void read_vec(sdl_parser *p, void *dst) { *(vec3 *)dst = sdl_vector(p); }

/* uv_list := uv { [','] uv } ; n 2-D points */
static double (*uv_list(sdl_parser *p, int n, int extra))[2]
{
    return read_items(p, n, extra, sizeof(double[2]), read_uv);
}

/* spline_type := linear_spline | quadratic_spline | cubic_spline | bezier_spline */
static int spline_kw(sdl_kw k, scene_spline *out)
{
    switch (k) {
    case KW_LINEAR_SPLINE: *out = SPLINE_LINEAR; return 1;
    case KW_QUADRATIC_SPLINE: *out = SPLINE_QUADRATIC; return 1;
    case KW_CUBIC_SPLINE: *out = SPLINE_CUBIC; return 1;
    case KW_BEZIER_SPLINE: *out = SPLINE_BEZIER; return 1;
    default: return 0;
    }
}

static int same2(const double *a, const double *b)
{
    return fabs(a[0] - b[0]) < SDL_SHAPE_EPSILON && fabs(a[1] - b[1]) < SDL_SHAPE_EPSILON;
}

/* A data file by POV-Ray's search: as given when absolute, else the -L
 * directories, the current file's directory, POV-Ray's include directory.
 * malloc'd path or NULL. */
static char *find_data_file(sdl_parser *p, const char *name, const char *ext)
{
    if (!name || !*name) return NULL;
    if (name[0] == '/') return access(name, R_OK) == 0 ? strdup(name) : NULL;
    if (!ext) ext = "";
    const char *dirs[64];
    int nd = 0;
    for (int i = 0; i < p->opt.nlib_paths && nd < 60; i++) dirs[nd++] = p->opt.lib_paths[i];
    char *cur = NULL;
    if (p->nframes > 0 && p->frames[p->nframes - 1].src && p->frames[p->nframes - 1].src->path) {
        const char *path = p->frames[p->nframes - 1].src->path;
        const char *slash = strrchr(path, '/');
        if (slash) {
            cur = strndup(path, (size_t)(slash - path) + (slash == path));
            if (cur) dirs[nd++] = cur;
        }
    }
    dirs[nd++] = ".";
    if (!p->opt.no_default_lib) dirs[nd++] = SDL_DEFAULT_LIB_DIR;
    char *found = NULL;
    for (int i = 0; i < nd && !found; i++)
        for (int e = 0; e < 2 && !found && ext; e++) {
            size_t n = strlen(dirs[i]) + strlen(name) + strlen(ext) + 2;
            char *f = malloc(n);
            if (!f) break;
            snprintf(f, n, "%s/%s%s", dirs[i], name, e ? ext : "");
            if (access(f, R_OK) == 0) found = f;
            else free(f);
        }
    free(cur);
    return found;
}

/* ------------------------------------------------------------ polygon */

/* polygon := n ',' point { [','] point }
 * Sub-polygons end where a point repeats their first point; an unclosed
 * last one is closed (POV-Ray warns "Polygon not closed"). */
static void polygon_args(sdl_parser *p, scene_object *o, src_loc loc)
{
    int n = parse_count(p, "polygon", 3, 1 << 24);
    if (n < 0) return;
    vec3 *pts = read_items(p, n, 1, sizeof *pts, read_vec);
    if (!pts || !sdl_ok(p)) return;
    vec3 first = pts[0];
    int closed = 0;
    for (int i = 1; i < n; i++) {
        closed = 0;
        if (fabs(first.x - pts[i].x) < SDL_SHAPE_EPSILON && fabs(first.y - pts[i].y) < SDL_SHAPE_EPSILON &&
            fabs(first.z - pts[i].z) < SDL_SHAPE_EPSILON) {
            pts[i] = first;
            i++;
            if (i < n) first = pts[i];
            closed = 1;
        }
    }
    if (!closed) {
        sdl_warn_once(p, loc, "polygon not closed; closing it");
        pts[n++] = first;
    }
    scene_polygon *pg = sdl_alloc(p, sizeof *pg);
    if (!pg) return;
    pg->npoints = n;
    pg->points = pts;
    o->kind = SHAPE_POLYGON;
    o->u.polygon = pg;
}

/* ------------------------------------------------------------ lathe, sor */

/* lathe := [ spline_type ] n ',' uv { [','] uv } [ sturm ]
 * (linear >= 2 points, quadratic >= 3, cubic >= 4, bezier 4 per segment) */
static void lathe_args(sdl_parser *p, scene_object *o)
{
    scene_spline sp = SPLINE_LINEAR;
    while (sdl_ok(p) && sdl_peek(p)->tk.kind == TOK_KEYWORD && spline_kw(sdl_peek(p)->tk.kw, &sp)) sdl_next(p);
    src_loc loc = sdl_peek(p)->tk.loc;
    int n = parse_count(p, "lathe", 2, 1 << 24);
    if (n < 0) return;
    static const int min_pts[4] = {2, 3, 4, 4};
    if (n < min_pts[sp] || (sp == SPLINE_BEZIER && (n & 3))) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "lathe with %s splines needs %s", sp == SPLINE_LINEAR ? "linear" : sp == SPLINE_QUADRATIC ? "quadratic" : sp == SPLINE_CUBIC ? "cubic" : "Bezier",
                  sp == SPLINE_LINEAR ? "at least two points" : sp == SPLINE_QUADRATIC ? "at least three points" : sp == SPLINE_CUBIC ? "at least four points" : "four points per segment");
        return;
    }
    double(*pts)[2] = uv_list(p, n, 0);
    if (!pts || !sdl_ok(p)) return;
    scene_lathe *l = sdl_alloc(p, sizeof *l);
    if (!l) return;
    l->spline = sp;
    l->npoints = n;
    l->points = pts;
    o->kind = SHAPE_LATHE;
    o->u.lathe = l;
}

/* sor := n ',' uv { [','] uv } [ open ] [ sturm ]
 * (n >= 4; radii >= 0; heights of points 1 .. n-2 strictly increasing) */
static void sor_args(sdl_parser *p, scene_object *o)
{
    src_loc loc = sdl_peek(p)->tk.loc;
    int n = parse_count(p, "sor", 4, 1 << 24);
    if (n < 0) return;
    double(*pts)[2] = uv_list(p, n, 0);
    if (!pts || !sdl_ok(p)) return;
    for (int i = 0; i < n; i++)
        if (pts[i][0] < 0.0 || (i > 1 && i < n - 1 && pts[i][1] <= pts[i - 1][1])) {
            sdl_error(p, loc, PT_ERR_SYNTAX, "incorrect point %d in surface of revolution (radius < 0 or height not increasing)", i + 1);
            return;
        }
    for (int i = 0; i + 3 < n; i++)
        if (fabs(pts[i + 2][1] - pts[i][1]) < SDL_SHAPE_EPSILON || fabs(pts[i + 3][1] - pts[i + 1][1]) < SDL_SHAPE_EPSILON) {
            sdl_error(p, loc, PT_ERR_SYNTAX, "incorrect point in surface of revolution (equal heights)");
            return;
        }
    if (sdl_accept_kw(p, KW_OPEN)) o->flags |= OBJ_OPEN;
    scene_lathe *l = sdl_alloc(p, sizeof *l);
    if (!l) return;
    l->spline = SPLINE_CUBIC;
    l->npoints = n;
    l->points = pts;
    o->kind = SHAPE_SOR;
    o->u.lathe = l;
}

/* ------------------------------------------------------------ prism */

/* prism := { spline_type | linear_sweep | conic_sweep } height1 ',' height2 ','
 *   n ',' uv { [','] uv } [ open ] [ sturm ]
 * (linear >= 3 points, quadratic >= 5, cubic >= 6, bezier 4 per segment).
 * Closing rules as POV-Ray: a sub-curve ends where a point repeats its
 * first point (quadratic/cubic: the second point, the first is a control
 * point); an unclosed linear prism is closed, any other is ignored. */
static void prism_args(sdl_parser *p, scene_object *o, src_loc oloc)
{
    scene_spline sp = SPLINE_LINEAR;
    int conic = 0;
    for (;;) {
        const sdl_tok *t = sdl_peek(p);
        if (t->tk.kind != TOK_KEYWORD) break;
        if (spline_kw(t->tk.kw, &sp)) sdl_next(p);
        else if (t->tk.kw == KW_LINEAR_SWEEP) { conic = 0; sdl_next(p); }
        else if (t->tk.kw == KW_CONIC_SWEEP) { conic = 1; sdl_next(p); }
        else break;
    }
    double h1 = sdl_float(p);
    sdl_accept(p, TOK_COMMA);
    double h2 = sdl_float(p);
    sdl_accept(p, TOK_COMMA);
    if (h1 > h2) { double t = h1; h1 = h2; h2 = t; }
    src_loc loc = sdl_peek(p)->tk.loc;
    int n = parse_count(p, "prism", 3, 1 << 24);
    if (n < 0) return;
    static const int min_pts[4] = {3, 5, 6, 4};
    if (n < min_pts[sp] || (sp == SPLINE_BEZIER && (n & 3))) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "prism with %s splines needs %s", sp == SPLINE_LINEAR ? "linear" : sp == SPLINE_QUADRATIC ? "quadratic" : sp == SPLINE_CUBIC ? "cubic" : "Bezier",
                  sp == SPLINE_LINEAR ? "at least three points" : sp == SPLINE_QUADRATIC ? "at least five points" : sp == SPLINE_CUBIC ? "at least six points" : "four points per segment");
        return;
    }
    double(*pts)[2] = uv_list(p, n, 1);
    if (!pts || !sdl_ok(p)) return;
    if (sdl_accept_kw(p, KW_OPEN)) o->flags |= OBJ_OPEN;
    int closed = 0;
    if (sp != SPLINE_BEZIER) {
        int i = sp == SPLINE_LINEAR ? 1 : 2;
        const double *first = pts[i - 1];
        for (; i < n; i++) {
            closed = 0;
            if (same2(first, pts[i])) {
                i += sp == SPLINE_LINEAR ? 1 : sp == SPLINE_QUADRATIC ? 2 : 3;
                if (i < n) first = pts[i];
                closed = 1;
            }
        }
        if (!closed && sp == SPLINE_LINEAR) {
            sdl_warn_once(p, oloc, "linear prism not closed; closing it");
            pts[n][0] = first[0];
            pts[n][1] = first[1];
            n++;
            closed = 1;
        }
    } else {
        closed = 1;
        int start = 0;
        for (int i = 4; i < n; i += 4) {
            if (!same2(pts[i], pts[i - 1])) {
                if (!same2(pts[i - 1], pts[start])) { closed = 0; break; }
                start = i;
            }
        }
        if (!same2(pts[n - 1], pts[start])) closed = 0;
    }
    scene_prism *pr = sdl_alloc(p, sizeof *pr);
    if (!pr) return;
    if (!closed) {
        sdl_warn_once(p, oloc, "prism not closed; it is ignored (as POV-Ray does)");
        n = 0;
    }
    pr->spline = sp;
    pr->conic = conic;
    pr->height1 = h1;
    pr->height2 = h2;
    pr->npoints = n;
    pr->points = pts;
    o->kind = SHAPE_PRISM;
    o->u.prism = pr;
}

/* ------------------------------------------------------------ superellipsoid, quadric */

/* superellipsoid := '<' e ',' n '>' */
static void superellipsoid_args(sdl_parser *p, scene_object *o, src_loc loc)
{
    double v[2];
    sdl_vector_n(p, v, 2);
    if (sdl_ok(p) && (!(v[0] > 0.0) || !(v[1] > 0.0)))
        sdl_error(p, loc, PT_ERR_SYNTAX, "superellipsoid exponents must be positive");
    o->kind = SHAPE_SUPERELLIPSOID;
    o->u.superellipsoid.e = v[0];
    o->u.superellipsoid.n = v[1];
}

/* quadric := '<' A ',' B ',' C '>' ',' '<' D ',' E ',' F '>' ',' '<' G ',' H ',' I '>' ',' J */
static void quadric_args(sdl_parser *p, scene_object *o)
{
    vec3 sq = sdl_vector(p);
    sdl_accept(p, TOK_COMMA);
    vec3 mx = sdl_vector(p);
    sdl_accept(p, TOK_COMMA);
    vec3 ln = sdl_vector(p);
    sdl_accept(p, TOK_COMMA);
    double j = sdl_float(p);
    double a[10] = {sq.x, sq.y, sq.z, mx.x, mx.y, mx.z, ln.x, ln.y, ln.z, j};
    o->kind = SHAPE_QUADRIC;
    memcpy(o->u.quadric.a, a, sizeof a);
}

/* ------------------------------------------------------------ poly */

static int poly_terms(int order) { return (order + 1) * (order + 2) * (order + 3) / 6; }

/* Index of x^i y^j z^k in POV-Ray's term order for `order` (x power
 * descending, then y, then z; the remaining power belongs to the constant). */
static int poly_index(int order, int i, int j, int k)
{
    int idx = 0;
    for (int a = order; a >= 0; a--)
        for (int b = order - a; b >= 0; b--)
            for (int c = order - a - b; c >= 0; c--) {
                if (a == i && b == j && c == k) return idx;
                idx++;
            }
    return -1;
}

static scene_poly *new_poly(sdl_parser *p, int order)
{
    scene_poly *pl = sdl_alloc(p, sizeof *pl);
    if (!pl) return NULL;
    pl->order = order;
    pl->ncoefs = poly_terms(order);
    pl->coefs = alloc_n(p, (size_t)pl->ncoefs, sizeof(double));
    return pl->coefs ? pl : NULL;
}

/* poly := order ',' coefs ; cubic := coefs ; quartic := coefs ;
 * coefs := '<' c { ',' c } '>' with exactly (order+1)(order+2)(order+3)/6 terms */
static void poly_args(sdl_parser *p, scene_object *o, int order)
{
    if (order == 0) {
        src_loc loc = sdl_peek(p)->tk.loc;
        double ord = sdl_float(p);
        sdl_accept(p, TOK_COMMA);
        if (!sdl_ok(p)) return;
        if (!(ord >= 2) || ord > MAX_POLY_ORDER) {
            sdl_error(p, loc, PT_ERR_SYNTAX, "order of poly is out of range (2 to %d)", MAX_POLY_ORDER);
            return;
        }
        order = (int)ord;
    }
    scene_poly *pl = new_poly(p, order);
    if (!pl) return;
    if (!sdl_expect(p, TOK_LT, "'<' starting the coefficients")) return;
    for (int i = 0; i < pl->ncoefs && sdl_ok(p); i++) {
        if (i) sdl_accept(p, TOK_COMMA); /* POV-Ray's commas are optional here too */
        pl->coefs[i] = sdl_float(p);
    }
    if (!sdl_ok(p)) return;
    sdl_tok t = sdl_next(p);
    if (t.tk.kind != TOK_GT) {
        sdl_unexpected(p, &t, "'>' after the coefficients (wrong number of coefficients?)");
        return;
    }
    o->kind = SHAPE_POLY;
    o->u.poly = pl;
}

/* polynomial := order ',' { xyz '(' i ',' j ',' k ')' ':' value [','] } */
static void polynomial_args(sdl_parser *p, scene_object *o)
{
    src_loc loc = sdl_peek(p)->tk.loc;
    double ord = sdl_float(p);
    sdl_accept(p, TOK_COMMA);
    if (!sdl_ok(p)) return;
    if (!(ord >= 2) || ord > MAX_POLY_ORDER) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "order of polynomial is out of range (2 to %d)", MAX_POLY_ORDER);
        return;
    }
    scene_poly *pl = new_poly(p, (int)ord);
    if (!pl) return;
    while (sdl_ok(p) && sdl_accept_kw(p, KW_XYZ)) {
        src_loc at = p->last_loc;
        sdl_expect(p, TOK_LPAREN, "'(' after xyz");
        double e[3];
        for (int i = 0; i < 3; i++) {
            if (i) sdl_expect(p, TOK_COMMA, "','");
            e[i] = sdl_float(p);
        }
        sdl_expect(p, TOK_RPAREN, "')'");
        sdl_expect(p, TOK_COLON, "':' after xyz(i,j,k)");
        double v = sdl_float(p);
        sdl_accept(p, TOK_COMMA);
        if (!sdl_ok(p)) return;
        int idx = (e[0] >= 0 && e[1] >= 0 && e[2] >= 0 && e[0] + e[1] + e[2] <= pl->order)
                      ? poly_index(pl->order, (int)e[0], (int)e[1], (int)e[2]) : -1;
        if (idx < 0) {
            sdl_error(p, at, PT_ERR_SYNTAX, "coefficient of polynomial is out of range");
            return;
        }
        pl->coefs[idx] = v;
    }
    o->kind = SHAPE_POLY;
    o->u.poly = pl;
}

/* ------------------------------------------------------------ blob */

typedef struct {
    scene_blob_component *c;
    int n, cap;
} comp_list;

static scene_blob_component *comp_add(sdl_parser *p, comp_list *l)
{
    if (!grow_array_int((void **)&l->c, &l->cap, l->n + 1, sizeof *l->c)) {
        sdl_error(p, p->last_loc, PT_ERR_NOMEM, "out of memory");
        return NULL;
    }
    scene_blob_component *c = &l->c[l->n++];
    memset(c, 0, sizeof *c);
    c->transform = xform_identity();
    return c;
}

/* component_mods := { translate | rotate | scale | matrix | transform |
 *   texture | pigment | finish | normal } '}' */
static void component_mods(sdl_parser *p, scene_blob_component *c)
{
    scene_texture *tex = NULL;
    while (sdl_ok(p)) {
        xform x;
        if (sdl_transform_item(p, &x)) {
            c->transform = xform_then(c->transform, x);
            if (tex) sdl_transform_texture_outer(tex, &x);
            continue;
        }
        if (sdl_accept_kw(p, KW_TEXTURE)) {
            scene_texture *t = sdl_parse_texture(p);
            if (t) {
                scene_texture *last = t;
                while (last->next) last = last->next;
                last->next = tex;
                tex = t;
            }
            continue;
        }
        const sdl_tok *pk = sdl_peek(p);
        if (pk->tk.kind == TOK_KEYWORD && (pk->tk.kw == KW_PIGMENT || pk->tk.kw == KW_FINISH || pk->tk.kw == KW_NORMAL)) {
            sdl_kw k = sdl_next(p).tk.kw;
            if (!tex) {
                tex = sdl_dup(p, &p->s->default_texture, sizeof *tex);
                if (!tex) return;
                tex->next = NULL;
                tex->transform = xform_identity();
                tex->loc = p->last_loc;
            }
            if (k == KW_PIGMENT) sdl_parse_pigment(p, &tex->pigment);
            else if (k == KW_FINISH) sdl_parse_finish(p, &tex->finish);
            else { sdl_parse_normal(p); tex->has_normal = 1; }
            continue;
        }
        break;
    }
    c->texture = tex;
    sdl_end_block(p);
}

/* blob := { threshold float | component strength ',' radius ',' centre |
 *   sphere '{' centre ',' radius ',' [strength] s component_mods |
 *   cylinder '{' end1 ',' end2 ',' radius ',' [strength] s component_mods }
 *   (threshold default 1) */
static void blob_args(sdl_parser *p, scene_object *o, src_loc loc)
{
    comp_list l = {0};
    double threshold = 1.0;
    while (sdl_ok(p)) {
        if (sdl_accept_kw(p, KW_THRESHOLD)) {
            threshold = sdl_float(p);
        } else if (sdl_accept_kw(p, KW_COMPONENT)) {
            scene_blob_component *c = comp_add(p, &l);
            if (!c) break;
            c->strength = sdl_float(p);
            sdl_accept(p, TOK_COMMA);
            c->radius = sdl_float(p);
            sdl_accept(p, TOK_COMMA);
            c->a = sdl_vector(p);
        } else if (sdl_accept_kw(p, KW_SPHERE)) {
            if (!sdl_begin_block(p, "sphere")) break;
            scene_blob_component *c = comp_add(p, &l);
            if (!c) break;
            c->a = sdl_vector(p);
            sdl_accept(p, TOK_COMMA);
            c->radius = sdl_float(p);
            sdl_accept(p, TOK_COMMA);
            sdl_accept_kw(p, KW_STRENGTH);
            c->strength = sdl_float(p);
            component_mods(p, c);
        } else if (sdl_accept_kw(p, KW_CYLINDER)) {
            if (!sdl_begin_block(p, "cylinder")) break;
            scene_blob_component *c = comp_add(p, &l);
            if (!c) break;
            src_loc at = p->last_loc;
            c->cylinder = 1;
            c->a = sdl_vector(p);
            sdl_accept(p, TOK_COMMA);
            c->b = sdl_vector(p);
            sdl_accept(p, TOK_COMMA);
            c->radius = sdl_float(p);
            sdl_accept(p, TOK_COMMA);
            sdl_accept_kw(p, KW_STRENGTH);
            c->strength = sdl_float(p);
            if (sdl_ok(p) && v3_len(v3_sub(c->b, c->a)) < 1e-10) {
                sdl_error(p, at, PT_ERR_SYNTAX, "degenerate cylindrical component in blob");
                break;
            }
            component_mods(p, c);
        } else if (sdl_accept_kw(p, KW_HIERARCHY)) {
            sdl_allow_float(p, 1.0);
        } else {
            break;
        }
    }
    if (sdl_ok(p) && l.n == 0) sdl_warn_once(p, loc, "blob without components");
    scene_blob *b = sdl_alloc(p, sizeof *b);
    if (b && sdl_ok(p)) {
        b->threshold = threshold;
        b->ncomponents = l.n;
        b->components = l.n ? arena_memdup(p->s->mem, l.c, sizeof *l.c * (size_t)l.n) : NULL;
        for (int i = 0; i < l.n; i++) b->components[i].radius = fabs(b->components[i].radius);
        o->kind = SHAPE_BLOB;
        o->u.blob = b;
    }
    free(l.c);
}

/* ------------------------------------------------------------ height_field */

/* height_field := [ file_type ] file_name { water_level float | smooth [bool] | hierarchy [bool] }
 * file_type := png | pgm | ppm | gif | tga | iff | jpeg | tiff | sys | pot | exr | hdr | bmp | function ... */
/* height_field { function W, H { ... } }: POV-Ray 3.7 (its
 * Make_Pattern_Image) evaluates the function at x = j / (W - 1),
 * y = i / (H - 1), z = 0 into row i, column j of a 16-bit grey image (a
 * pigment function: its colour's grey value), which the height field then
 * reads as it reads a file (row 0 = the top of the image). */
typedef struct {
    const scene_function *fn;
    const func_env *env;
    unsigned short *v;
    const char **why; /* per row: why it could not be evaluated, or NULL */
    int w, h;
    atomic_int failed;
} hf_rows;

/* Row i of a height field's function image (pool job: the rows are
 * independent, and the evaluators keep no state between calls). */
static void hf_row(void *ctx, int i, int thread)
{
    (void)thread;
    hf_rows *r = ctx;
    if (atomic_load_explicit(&r->failed, memory_order_relaxed)) return; /* the error is known */
    int w = r->w;
    for (int j = 0; j < w; j++) {
        double args[FUNC_MAX_PARAMS] = {0}, out[8] = {0};
        args[0] = (double)j / (w - 1);
        args[1] = (double)i / (r->h - 1);
        const char *why = NULL;
        if (func_eval(r->fn, args, out, r->env, &why) != PT_OK) {
            r->why[i] = why ? why : "the function";
            atomic_store(&r->failed, 1);
            return;
        }
        double g = r->fn->nterms >= 3 ? 0.297 * out[0] + 0.589 * out[1] + 0.114 * out[2] : out[0];
        if (!(g > 0.0)) g = 0.0; /* NaN too */
        if (g > 1.0) g = 1.0;
        r->v[(size_t)i * w + j] = (unsigned short)(g * 65535.0 + 0.5);
    }
}

static unsigned short *function_heights(sdl_parser *p, src_loc loc, int *wp, int *hp)
{
    double fw = sdl_float(p);
    sdl_accept(p, TOK_COMMA);
    double fh = sdl_float(p);
    src_loc at = sdl_peek(p)->tk.loc;
    const scene_function *fn = sdl_parse_function(p, at, NULL);
    if (!sdl_ok(p) || !fn) return NULL;
    if (!(fw >= 1.5 && fh >= 1.5 && fw < 65536.5 && fh < 65536.5) || (int)(fw + 0.5) * (double)(int)(fh + 0.5) > (double)(1 << 26)) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "height_field function size %gx%g out of range (2 to 65536 a side, 2^26 samples)", fw, fh);
        return NULL;
    }
    int w = (int)(fw + 0.5), h = (int)(fh + 0.5);
    unsigned short *v = malloc(sizeof *v * (size_t)w * (size_t)h);
    if (!v) {
        sdl_error(p, loc, PT_ERR_NOMEM, "out of memory for a %dx%d height_field function", w, h);
        return NULL;
    }
    const char **why = calloc((size_t)h, sizeof *why);
    if (!why) {
        free(v);
        sdl_error(p, loc, PT_ERR_NOMEM, "out of memory for a %dx%d height_field function", w, h);
        return NULL;
    }
    hf_rows job = {fn, p->opt.func_env, v, why, w, h, 0};
    pool_run(p->opt.threads, h, hf_row, &job);
    for (int i = 0; i < h; i++)
        if (why[i]) { /* the first row that failed (its reason is the function's) */
            sdl_error(p, loc, PT_ERR_UNSUPPORTED, "height_field function: %s cannot be evaluated at parse time", why[i]);
            free(why);
            free(v);
            return NULL;
        }
    free(why);
    *wp = w;
    *hp = h;
    return v;
}

/* height_field := [ file_type ] file_name { water_level float | smooth [bool] | hierarchy [bool] }
 *               | function W, H { function_body } { ... }
 * file_type := png | pgm | ppm | gif | tga | iff | jpeg | tiff | sys | pot | exr | hdr | bmp */
static void height_field_args(sdl_parser *p, scene_object *o, src_loc loc)
{
    const sdl_tok *t = sdl_peek(p);
    sdl_hf_image img;
    memset(&img, 0, sizeof img);
    int have = 0;
    const char *ext = NULL, *name = "function";
    if (t->tk.kind == TOK_KEYWORD && !sdl_starts_string(t)) {
        sdl_kw type = sdl_next(p).tk.kw;
        ext = type == KW_PNG ? ".png" : type == KW_PGM ? ".pgm" : type == KW_PPM ? ".ppm" : type == KW_GIF ? ".gif"
            : type == KW_POT ? ".pot" : type == KW_TGA ? ".tga" : type == KW_JPEG ? ".jpg" : type == KW_TIFF ? ".tif"
            : NULL;
        if (type == KW_FUNCTION) {
            img.values = function_heights(p, loc, &img.width, &img.height);
            if (!img.values) return;
            have = 1;
        }
    }
    if (!have) name = sdl_string(p);
    double water = 0.0;
    int smooth = 0;
    while (sdl_ok(p)) {
        if (sdl_accept_kw(p, KW_WATER_LEVEL)) water = sdl_float(p);
        else if (sdl_accept_kw(p, KW_SMOOTH)) smooth = sdl_allow_float(p, 1.0) != 0.0;
        else if (sdl_accept_kw(p, KW_HIERARCHY)) sdl_allow_float(p, 1.0);
        else break;
    }
    if (!sdl_ok(p)) {
        free(img.values);
        return;
    }
    if (!have) {
        char *path = find_data_file(p, name, ext);
        if (!path) {
            sdl_error(p, loc, PT_ERR_IO, "height_field image '%s' not found", name ? name : "");
            return;
        }
        char why[256] = "";
        int r = sdl_hf_read(path, (unsigned long long)p->opt.max_image_pixels, &img, why, sizeof why);
        sdl_hash_file(p, path);
        free(path);
        if (r == SDL_HF_UNSUPPORTED) {
            o->kind = SHAPE_UNSUPPORTED;
            o->name = "height_field";
            sdl_warn_once(p, loc, "height_field image '%s': %s; the height field is skipped", name, why);
            return;
        }
        if (r != SDL_HF_OK) {
            sdl_error(p, loc, PT_ERR_IO, "height_field image '%s': %s", name, why);
            return;
        }
    }
    if (img.width < 2 || img.height < 2) {
        free(img.values);
        sdl_error(p, loc, PT_ERR_SYNTAX, "height_field image '%s' is smaller than 2x2", name);
        return;
    }
    scene_height_field *hf = sdl_alloc(p, sizeof *hf);
    float *h = hf ? alloc_n(p, (size_t)img.width * (size_t)img.height, sizeof *h) : NULL;
    if (!h) {
        free(img.values);
        return;
    }
    /* POV-Ray: map row z is image row (height - 1 - z), heights value / 65536 */
    for (int z = 0; z < img.height; z++)
        for (int x = 0; x < img.width; x++)
            h[(size_t)z * img.width + x] = (float)(img.values[(size_t)(img.height - 1 - z) * img.width + x] / 65536.0);
    free(img.values);
    hf->width = img.width;
    hf->height = img.height;
    hf->heights = h;
    hf->smooth = smooth;
    hf->water_level = water;
    o->kind = SHAPE_HEIGHT_FIELD;
    o->u.height_field = hf;
}

/* ------------------------------------------------------------ text */

/* text := ( ttf file_name | internal n ) string thickness ',' offset
 * POV-Ray's built-in fonts are copies of the distribution's: 1 timrom.ttf,
 * 2 cyrvetic.ttf, 3 crystal.ttf, any other number povlogo.ttf (read from
 * the include path here). POV-Ray then rotates the text by
 * <0.001,0.001,0.001> degrees ("to fix cracks in text that lies along an
 * axis"); so do we. */
static void text_args(sdl_parser *p, scene_object *o, src_loc loc)
{
    const char *font = NULL;
    if (sdl_accept_kw(p, KW_INTERNAL)) {
        int id = sdl_to_int(sdl_float(p));
        font = id == 1 ? "timrom.ttf" : id == 2 ? "cyrvetic.ttf" : id == 3 ? "crystal.ttf" : "povlogo.ttf";
    } else if (!sdl_accept_kw(p, KW_TTF)) {
        sdl_tok t = sdl_next(p);
        sdl_unexpected(p, &t, "ttf or internal");
        return;
    }
    if (!font) font = sdl_string(p);
    sdl_accept(p, TOK_COMMA);
    const char *str = sdl_string(p);
    sdl_accept(p, TOK_COMMA);
    double depth = sdl_float(p);
    sdl_accept(p, TOK_COMMA);
    vec3 offset = sdl_vector(p);
    if (!sdl_ok(p)) return;
    char *path = find_data_file(p, font, ".ttf");
    if (!path) {
        sdl_error(p, loc, PT_ERR_IO, "font file '%s' not found", font ? font : "");
        return;
    }
    sdl_font_outline out;
    char why[256] = "";
    pt_status st = sdl_font_text((sdl_font_cache **)&p->fonts, path, str, offset, &out, why, sizeof why);
    free(path);
    if (st != PT_OK) {
        sdl_error(p, loc, st, "text: font '%s': %s", font, why);
        return;
    }
    scene_text *tx = sdl_alloc(p, sizeof *tx);
    if (!tx) {
        free(out.segments);
        return;
    }
    tx->nsegments = out.nsegments;
    tx->segments = out.nsegments ? arena_memdup(p->s->mem, out.segments, sizeof *out.segments * (size_t)out.nsegments) : NULL;
    tx->depth = depth;
    free(out.segments);
    o->kind = SHAPE_TEXT;
    o->u.text = tx;
    o->transform = xform_then(o->transform, xform_rotate(v3(0.001, 0.001, 0.001)));
}

/* ------------------------------------------------------------ sphere_sweep */

static scene_object *kid(sdl_parser *p, shape_kind k, const char *name, src_loc loc)
{
    scene_object *o = scene_new_object(p->s, k, loc);
    if (!o) sdl_error(p, loc, PT_ERR_NOMEM, "out of memory");
    else o->name = name;
    return o;
}

/* The sweep of one sphere to another: a truncated cone tangent to both
 * (the envelope of the linearly moving sphere), open at both ends, or
 * nothing when one sphere contains the other. */
static scene_object *tangent_cone(sdl_parser *p, vec3 c1, double r1, vec3 c2, double r2, src_loc loc)
{
    vec3 ax = v3_sub(c2, c1);
    double d = v3_len(ax);
    if (!(d > fabs(r1 - r2)) || d <= 0.0) return NULL;
    vec3 u = v3_scale(ax, 1.0 / d);
    double s = (r1 - r2) / d, c = sqrt(fmax(0.0, 1.0 - s * s));
    scene_object *o = kid(p, SHAPE_CONE, "sphere_sweep", loc);
    if (!o) return NULL;
    o->u.cone.base = v3_madd(c1, u, r1 * s);
    o->u.cone.cap = v3_madd(c2, u, r2 * s);
    o->u.cone.base_radius = r1 * c;
    o->u.cone.cap_radius = r2 * c;
    o->flags |= OBJ_OPEN;
    return o;
}

/* Point i of the sweep's spline segment: centre and radius at t in [0,1]
 * from 4 control spheres (Catmull-Rom for cubic_spline, uniform cubic
 * B-spline for b_spline). */
static void sweep_eval(int bspline, const vec3 *c, const double *r, double t, vec3 *pc, double *pr)
{
    double w[4];
    double t2 = t * t, t3 = t2 * t;
    if (bspline) {
        w[0] = (1 - t) * (1 - t) * (1 - t) / 6.0;
        w[1] = (3 * t3 - 6 * t2 + 4) / 6.0;
        w[2] = (-3 * t3 + 3 * t2 + 3 * t + 1) / 6.0;
        w[3] = t3 / 6.0;
    } else {
        w[0] = 0.5 * (-t3 + 2 * t2 - t);
        w[1] = 0.5 * (3 * t3 - 5 * t2 + 2);
        w[2] = 0.5 * (-3 * t3 + 4 * t2 + t);
        w[3] = 0.5 * (t3 - t2);
    }
    vec3 s = v3s(0.0);
    double rr = 0.0;
    for (int i = 0; i < 4; i++) {
        s = v3_madd(s, c[i], w[i]);
        rr += r[i] * w[i];
    }
    *pc = s;
    *pr = rr;
}

#define SWEEP_PIECES 16 /* linear pieces per spline segment */

/* sphere_sweep := ( linear_spline | cubic_spline | b_spline ) [','] n ','
 *   centre ',' radius { [','] centre ',' radius } [ tolerance float ]
 * -> union of spheres and tangent cones. */
static void sphere_sweep_args(sdl_parser *p, sdl_obj *so, src_loc loc)
{
    scene_object *o = so->obj;
    int kind = -1; /* 0 linear, 1 Catmull-Rom, 2 B-spline */
    if (sdl_accept_kw(p, KW_LINEAR_SPLINE)) kind = 0;
    else if (sdl_accept_kw(p, KW_CUBIC_SPLINE)) kind = 1;
    else if (sdl_accept_kw(p, KW_B_SPLINE)) kind = 2;
    else {
        sdl_tok t = sdl_next(p);
        sdl_unexpected(p, &t, "linear_spline, cubic_spline or b_spline");
        return;
    }
    sdl_accept(p, TOK_COMMA);
    int n = parse_count(p, "sphere_sweep", kind ? 4 : 2, 1 << 20);
    if (n < 0) return;
    sdl_accept(p, TOK_COMMA);
    vec3 *c = malloc(sizeof *c * (size_t)n);
    double *r = malloc(sizeof *r * (size_t)n);
    if (!c || !r) {
        free(c);
        free(r);
        sdl_error(p, loc, PT_ERR_NOMEM, "out of memory");
        return;
    }
    for (int i = 0; i < n && sdl_ok(p); i++) {
        c[i] = sdl_vector(p);
        sdl_accept(p, TOK_COMMA);
        r[i] = fabs(sdl_float(p));
        sdl_accept(p, TOK_COMMA);
    }
    if (sdl_accept_kw(p, KW_TOLERANCE)) sdl_float(p);
    /* centres and radii along the sweep */
    int npts = kind == 0 ? n : (n - 3) * SWEEP_PIECES + 1;
    vec3 *pc = malloc(sizeof *pc * (size_t)npts);
    double *pr = malloc(sizeof *pr * (size_t)npts);
    scene_object **kids = malloc(sizeof *kids * (size_t)(2 * npts));
    int nk = 0;
    if (!pc || !pr || !kids) {
        sdl_error(p, loc, PT_ERR_NOMEM, "out of memory");
        goto done;
    }
    if (!sdl_ok(p)) goto done;
    if (kind == 0) {
        memcpy(pc, c, sizeof *pc * (size_t)n);
        memcpy(pr, r, sizeof *pr * (size_t)n);
    } else {
        for (int s = 0; s < n - 3; s++)
            for (int k = 0; k < SWEEP_PIECES; k++)
                sweep_eval(kind == 2, c + s, r + s, (double)k / SWEEP_PIECES, &pc[s * SWEEP_PIECES + k], &pr[s * SWEEP_PIECES + k]);
        sweep_eval(kind == 2, c + n - 4, r + n - 4, 1.0, &pc[npts - 1], &pr[npts - 1]);
    }
    for (int i = 0; i < npts && sdl_ok(p); i++) {
        if (pr[i] > 0.0) {
            scene_object *s = kid(p, SHAPE_SPHERE, "sphere_sweep", loc);
            if (!s) break;
            s->u.sphere.centre = pc[i];
            s->u.sphere.radius = pr[i];
            kids[nk++] = s;
        }
        if (i + 1 < npts) {
            scene_object *cn = tangent_cone(p, pc[i], pr[i], pc[i + 1], pr[i + 1], loc);
            if (cn) kids[nk++] = cn;
        }
    }
    o->kind = SHAPE_UNION;
    o->u.csg.nkids = nk;
    o->u.csg.kids = nk ? arena_memdup(p->s->mem, kids, sizeof *kids * (size_t)nk) : NULL;
done:
    free(c);
    free(r);
    free(pc);
    free(pr);
    free(kids);
}

/* ------------------------------------------------------------ bicubic_patch */

static void bernstein(double t, double b[4], double db[4])
{
    double s = 1.0 - t;
    b[0] = s * s * s;
    b[1] = 3 * t * s * s;
    b[2] = 3 * t * t * s;
    b[3] = t * t * t;
    db[0] = -3 * s * s;
    db[1] = 3 * s * s - 6 * t * s;
    db[2] = 6 * t * s - 3 * t * t;
    db[3] = 3 * t * t;
}

/* bicubic_patch := { type n | flatness f | u_steps n | v_steps n | accuracy a |
 *   uv_vectors uv ',' uv ',' uv ',' uv } 16 points
 * -> a smooth mesh of 2^u_steps x 2^v_steps quads (at least 4 x 4), vertex
 * normals from the patch's derivatives. */
static void bicubic_args(sdl_parser *p, sdl_obj *so, src_loc loc)
{
    scene_object *o = so->obj;
    int us = 3, vs = 3;
    /* uv_vectors: the patch corners' uv (POV-Ray 3.7's default ST: <0,0>,
     * <1,0>, <1,1>, <0,1>, bezier.cpp) */
    double st[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    while (sdl_ok(p)) {
        if (sdl_accept_kw(p, KW_TYPE)) sdl_float(p);
        else if (sdl_accept_kw(p, KW_FLATNESS)) sdl_float(p);
        else if (sdl_accept_kw(p, KW_U_STEPS)) us = sdl_to_int(sdl_float(p));
        else if (sdl_accept_kw(p, KW_V_STEPS)) vs = sdl_to_int(sdl_float(p));
        else if (sdl_accept_kw(p, KW_ACCURACY)) sdl_float(p);
        else if (sdl_accept_kw(p, KW_UV_VECTORS)) {
            for (int i = 0; i < 4; i++) {
                if (i) sdl_accept(p, TOK_COMMA);
                sdl_vector_n(p, st[i], 2);
            }
        } else break;
    }
    sdl_accept(p, TOK_COMMA);
    vec3 cp[4][4];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            cp[i][j] = sdl_vector(p);
            sdl_accept(p, TOK_COMMA);
        }
    if (!sdl_ok(p)) return;
    us = us < 0 ? 0 : (us > 8 ? 8 : us);
    vs = vs < 0 ? 0 : (vs > 8 ? 8 : vs);
    int nu = 1 << us, nv = 1 << vs;
    if (nu < 4) nu = 4;
    if (nv < 4) nv = 4;
    scene_mesh *m = scene_new_mesh(p->s);
    int nvert = (nu + 1) * (nv + 1);
    if (!m) {
        sdl_error(p, loc, PT_ERR_NOMEM, "out of memory");
        return;
    }
    m->loc = loc;
    m->nverts = m->nnormals = nvert;
    m->ntris = 2 * nu * nv;
    m->verts = alloc_n(p, (size_t)nvert, sizeof *m->verts);
    m->normals = alloc_n(p, (size_t)nvert, sizeof *m->normals);
    m->tris = alloc_n(p, (size_t)m->ntris, sizeof *m->tris);
    m->nuvs = nvert;
    m->uvs = alloc_n(p, (size_t)nvert, sizeof *m->uvs);
    if (!m->verts || !m->normals || !m->tris || !m->uvs) return;
    for (int a = 0; a <= nv; a++) {
        double bv[4], dbv[4];
        bernstein((double)a / nv, bv, dbv);
        for (int b = 0; b <= nu; b++) {
            double bu[4], dbu[4];
            bernstein((double)b / nu, bu, dbu);
            vec3 pt = v3s(0), du = v3s(0), dv = v3s(0);
            for (int i = 0; i < 4; i++)
                for (int j = 0; j < 4; j++) {
                    pt = v3_madd(pt, cp[i][j], bv[i] * bu[j]);
                    du = v3_madd(du, cp[i][j], bv[i] * dbu[j]);
                    dv = v3_madd(dv, cp[i][j], dbv[i] * bu[j]);
                }
            /* dv x du: the side POV-Ray's patch normal points to (trace() on a
             * bicubic_patch matches povray 3.7's normals with this sign) */
            vec3 nrm = v3_cross(dv, du);
            if (!(v3_len2(nrm) > 0.0)) {
                /* degenerate edge (a collapsed row): use the neighbouring cell's diagonal */
                vec3 e1 = v3_sub(cp[3][3], cp[0][0]), e2 = v3_sub(cp[3][0], cp[0][3]);
                nrm = v3_cross(e2, e1);
            }
            int k = a * (nu + 1) + b;
            v3_store_f(m->verts[k], pt);
            vec3 un = v3_norm(nrm);
            v3_store_f(m->normals[k], un);
            /* BicubicPatch::Compute_Texture_UV of the patch point (s, t) =
             * (parameter along the second control-point index, along the
             * first): bilinear in the four ST corners */
            double ps = (double)b / nu, pt2 = (double)a / nv;
            double u1[2] = {st[0][0] + ps * (st[1][0] - st[0][0]), st[0][1] + ps * (st[1][1] - st[0][1])};
            double u2[2] = {st[3][0] + ps * (st[2][0] - st[3][0]), st[3][1] + ps * (st[2][1] - st[3][1])};
            m->uvs[k][0] = (float)(u1[0] + pt2 * (u2[0] - u1[0]));
            m->uvs[k][1] = (float)(u1[1] + pt2 * (u2[1] - u1[1]));
        }
    }
    m->tri_uvs = m->tris; /* uvs indexed like the vertices */
    int t = 0;
    for (int a = 0; a < nv; a++)
        for (int b = 0; b < nu; b++) {
            int v00 = a * (nu + 1) + b, v01 = v00 + 1, v10 = v00 + nu + 1, v11 = v10 + 1;
            m->tris[t][0] = v00; m->tris[t][1] = v01; m->tris[t][2] = v11; t++;
            m->tris[t][0] = v00; m->tris[t][1] = v11; m->tris[t][2] = v10; t++;
        }
    m->tri_normals = NULL; /* normals indexed like the vertices */
    o->kind = SHAPE_MESH;
    o->u.mesh.mesh = m;
}

/* ------------------------------------------------------------ isosurface */

/* isosurface := { function function_block | contained_by '{' ( box '{' v ',' v '}' |
 *   sphere '{' v ',' r '}' ) '}' | threshold f | accuracy f | max_gradient f |
 *   evaluate f ',' f ',' f | open | max_trace n | all_intersections }
 * (defaults as POV-Ray 3.7: box { -1, 1 }, threshold 0, accuracy 0.001,
 * max_gradient 1.1, max_trace 1) */
static void isosurface_args(sdl_parser *p, scene_object *o, src_loc loc)
{
    scene_isosurface *iso = sdl_alloc(p, sizeof *iso);
    if (!iso) return;
    iso->c1 = v3s(-1.0);
    iso->c2 = v3s(1.0);
    iso->accuracy = 0.001;
    iso->max_gradient = 1.1;
    iso->max_trace = 1;
    iso->env = p->opt.func_env;
    while (sdl_ok(p)) {
        const sdl_tok *t = sdl_peek(p);
        if (t->tk.kind != TOK_KEYWORD) break;
        sdl_kw k = t->tk.kw;
        src_loc at = t->tk.loc;
        if (k == KW_FUNCTION) {
            sdl_next(p);
            iso->fn = sdl_parse_function(p, at, NULL);
        } else if (k == KW_CONTAINED_BY) {
            sdl_next(p);
            if (!sdl_begin_block(p, "contained_by")) return;
            if (sdl_accept_kw(p, KW_BOX)) {
                if (!sdl_begin_block(p, "box")) return;
                vec3 a = sdl_vector(p);
                sdl_accept(p, TOK_COMMA);
                vec3 b = sdl_vector(p);
                sdl_end_block(p);
                iso->sphere = 0;
                iso->c1 = v3_min(a, b);
                iso->c2 = v3_max(a, b);
            } else if (sdl_accept_kw(p, KW_SPHERE)) {
                if (!sdl_begin_block(p, "sphere")) return;
                iso->c1 = sdl_vector(p);
                sdl_accept(p, TOK_COMMA);
                iso->radius = fabs(sdl_float(p));
                sdl_end_block(p);
                iso->sphere = 1;
            } else {
                sdl_tok bad = sdl_next(p);
                sdl_unexpected(p, &bad, "box or sphere");
                return;
            }
            sdl_end_block(p);
        } else if (k == KW_THRESHOLD) {
            sdl_next(p);
            iso->threshold = sdl_float(p);
        } else if (k == KW_ACCURACY) {
            sdl_next(p);
            iso->accuracy = fabs(sdl_float(p));
        } else if (k == KW_MAX_GRADIENT) {
            sdl_next(p);
            iso->max_gradient = fabs(sdl_float(p));
        } else if (k == KW_EVALUATE) {
            sdl_next(p);
            for (int i = 0; i < 3; i++) {
                if (i) sdl_accept(p, TOK_COMMA);
                sdl_float(p);
            }
        } else if (k == KW_OPEN) {
            sdl_next(p);
            o->flags |= OBJ_OPEN;
        } else if (k == KW_MAX_TRACE) {
            sdl_next(p);
            /* POV-Ray takes a count below 1 as 1 (0 here is all_intersections) */
            double v = sdl_float(p);
            iso->max_trace = v < 1.0 ? 1 : v > 1e6 ? 1000000 : (int)v;
        } else if (k == KW_ALL_INTERSECTIONS) {
            sdl_next(p);
            iso->max_trace = 0;
        } else {
            break;
        }
    }
    if (!sdl_ok(p)) return;
    if (!iso->fn) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "isosurface needs a function");
        return;
    }
    if (iso->fn->kind != FUNC_FLOAT && iso->fn->kind != FUNC_PATTERN) {
        sdl_warn_once(p, loc, "isosurface with a non-float function is not supported; it is skipped");
        o->name = "isosurface";
        return;
    }
    if (!(iso->max_gradient > 0.0)) iso->max_gradient = 1.1;
    if (!(iso->accuracy > 0.0)) iso->accuracy = 0.001;
    o->kind = SHAPE_ISOSURFACE;
    o->u.isosurface = iso;
}

/* ------------------------------------------------------------ parametric */

#define PARAM_GRID 96 /* quads per side of the parametric tessellation */

static double param_eval(const scene_function *f, double u, double v)
{
    double args[FUNC_MAX_SLOTS] = {u, v, 0.0};
    return f ? func_eval_float(f, args, NULL) : 0.0;
}

static vec3 param_point(scene_function *const fn[3], double u, double v)
{
    return v3(param_eval(fn[0], u, v), param_eval(fn[1], u, v), param_eval(fn[2], u, v));
}

/* parametric := function_block [','] function_block [','] function_block
 *   uv ',' uv { contained_by {..} | max_gradient f | accuracy f |
 *   precompute n ',' x ',' y ',' z }
 * -> a smooth mesh of PARAM_GRID x PARAM_GRID quads over [u1,u2] x [v1,v2],
 * vertex normals from central differences (tessellated: POV-Ray subdivides
 * the uv domain to `accuracy` instead; contained_by is not applied). */
static void parametric_args(sdl_parser *p, sdl_obj *so, src_loc loc)
{
    scene_object *o = so->obj;
    scene_function *fn[3] = {NULL, NULL, NULL};
    for (int i = 0; i < 3 && sdl_ok(p); i++) {
        if (i) sdl_accept(p, TOK_COMMA);
        if (!sdl_accept_kw(p, KW_FUNCTION)) {
            sdl_tok t = sdl_next(p);
            sdl_unexpected(p, &t, "function");
            return;
        }
        fn[i] = sdl_parse_function(p, p->last_loc, NULL);
    }
    sdl_accept(p, TOK_COMMA);
    double a[2], b[2];
    sdl_vector_n(p, a, 2);
    sdl_accept(p, TOK_COMMA);
    sdl_vector_n(p, b, 2);
    while (sdl_ok(p)) {
        if (sdl_accept_kw(p, KW_CONTAINED_BY)) {
            if (sdl_begin_block(p, "contained_by")) sdl_skip_block(p);
        } else if (sdl_accept_kw(p, KW_MAX_GRADIENT) || sdl_accept_kw(p, KW_ACCURACY)) {
            sdl_float(p);
        } else if (sdl_accept_kw(p, KW_PRECOMPUTE)) {
            sdl_float(p);
            while (sdl_accept(p, TOK_COMMA)) {
                if (!sdl_accept_kw(p, KW_X) && !sdl_accept_kw(p, KW_Y) && !sdl_accept_kw(p, KW_Z)) break;
            }
        } else {
            break;
        }
    }
    if (!sdl_ok(p)) return;
    for (int i = 0; i < 3; i++)
        if (!fn[i] || fn[i]->kind != FUNC_FLOAT) {
            sdl_warn_once(p, loc, "parametric with a non-float function is not supported; it is skipped");
            return;
        }
    const int N = PARAM_GRID;
    scene_mesh *m = scene_new_mesh(p->s);
    if (!m) {
        sdl_error(p, loc, PT_ERR_NOMEM, "out of memory");
        return;
    }
    m->loc = loc;
    m->nverts = m->nnormals = (N + 1) * (N + 1);
    m->ntris = 2 * N * N;
    m->verts = alloc_n(p, (size_t)m->nverts, sizeof *m->verts);
    m->normals = alloc_n(p, (size_t)m->nverts, sizeof *m->normals);
    m->tris = alloc_n(p, (size_t)m->ntris, sizeof *m->tris);
    m->nuvs = m->nverts;
    m->uvs = alloc_n(p, (size_t)m->nverts, sizeof *m->uvs);
    if (!m->verts || !m->normals || !m->tris || !m->uvs) return;
    m->tri_uvs = m->tris; /* Parametric::UVCoord: the (u, v) parameters of the hit, per vertex here */
    double du = (b[0] - a[0]) / N, dv = (b[1] - a[1]) / N, h = 1e-4;
    for (int j = 0; j <= N; j++)
        for (int i = 0; i <= N; i++) {
            double u = a[0] + du * i, v = a[1] + dv * j;
            vec3 pt = param_point(fn, u, v);
            double hu = h * fmax(fabs(du) * N, 1e-12), hv = h * fmax(fabs(dv) * N, 1e-12);
            vec3 tu = v3_sub(param_point(fn, u + hu, v), param_point(fn, u - hu, v));
            vec3 tv = v3_sub(param_point(fn, u, v + hv), param_point(fn, u, v - hv));
            vec3 nn = v3_norm(v3_cross(tu, tv));
            int k = j * (N + 1) + i;
            if (!v3_finite(pt)) pt = v3s(0.0);
            if (!v3_finite(nn)) nn = v3(0, 1, 0);
            v3_store_f(m->verts[k], pt);
            v3_store_f(m->normals[k], nn);
            m->uvs[k][0] = (float)u;
            m->uvs[k][1] = (float)v;
        }
    int t = 0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            int v00 = j * (N + 1) + i, v01 = v00 + 1, v10 = v00 + N + 1, v11 = v10 + 1;
            m->tris[t][0] = v00; m->tris[t][1] = v01; m->tris[t][2] = v11; t++;
            m->tris[t][0] = v00; m->tris[t][1] = v11; m->tris[t][2] = v10; t++;
        }
    o->kind = SHAPE_MESH;
    o->u.mesh.mesh = m;
}

/* ------------------------------------------------------------ julia_fractal */

static int julia_func_kw(sdl_kw k, scene_julia_func *f)
{
    static const struct { sdl_kw k; scene_julia_func f; } map[] = {
        {KW_SQR, JULIA_SQR}, {KW_CUBE, JULIA_CUBE}, {KW_EXP, JULIA_EXP}, {KW_LN, JULIA_LN},
        {KW_SIN, JULIA_SIN}, {KW_ASIN, JULIA_ASIN}, {KW_COS, JULIA_COS}, {KW_ACOS, JULIA_ACOS},
        {KW_TAN, JULIA_TAN}, {KW_ATAN, JULIA_ATAN}, {KW_SINH, JULIA_SINH}, {KW_ASINH, JULIA_ASINH},
        {KW_COSH, JULIA_COSH}, {KW_ACOSH, JULIA_ACOSH}, {KW_TANH, JULIA_TANH}, {KW_ATANH, JULIA_ATANH},
        {KW_RECIPROCAL, JULIA_RECIPROCAL},
    };
    for (size_t i = 0; i < sizeof map / sizeof map[0]; i++)
        if (map[i].k == k) {
            *f = map[i].f;
            return 1;
        }
    return 0;
}

/* julia_fractal := vector4 { quaternion | hypercomplex | function_kw |
 *   pwr '(' f ',' f ')' | max_iteration n | precision f | slice vector4 ',' f }
 * (POV-Ray 3.7 defaults: quaternion, sqr, max_iteration 20, precision 20,
 * slice <0,0,0,1>, 0; max_iteration >= 1, precision >= 1) */
static void julia_args(sdl_parser *p, scene_object *o, src_loc loc)
{
    scene_julia *j = sdl_alloc(p, sizeof *j);
    if (!j) return;
    sdl_vector_n(p, j->c, 4);
    j->func = JULIA_SQR;
    j->max_iteration = 20;
    j->precision = 20.0;
    j->slice[3] = 1.0;
    while (sdl_ok(p)) {
        const sdl_tok *t = sdl_peek(p);
        if (t->tk.kind != TOK_KEYWORD) break;
        sdl_kw k = t->tk.kw;
        src_loc at = t->tk.loc;
        scene_julia_func f;
        if (k == KW_QUATERNION) { sdl_next(p); j->hypercomplex = 0; }
        else if (k == KW_HYPERCOMPLEX) { sdl_next(p); j->hypercomplex = 1; }
        else if (julia_func_kw(k, &f)) { sdl_next(p); j->func = f; }
        else if (k == KW_PWR) {
            sdl_next(p);
            sdl_expect(p, TOK_LPAREN, "'(' after pwr");
            j->pwr[0] = sdl_float(p);
            sdl_accept(p, TOK_COMMA);
            j->pwr[1] = sdl_float(p);
            sdl_expect(p, TOK_RPAREN, "')'");
            j->func = JULIA_PWR;
        } else if (k == KW_MAX_ITERATION) {
            sdl_next(p);
            double n = floor(sdl_float(p));
            j->max_iteration = n < 1 ? 1 : (n > 10000 ? 10000 : (int)n);
        } else if (k == KW_PRECISION) {
            sdl_next(p);
            double pr = sdl_float(p);
            j->precision = pr < 1.0 ? 1.0 : pr;
        } else if (k == KW_SLICE) {
            sdl_next(p);
            sdl_vector_n(p, j->slice, 4);
            sdl_accept(p, TOK_COMMA);
            j->slice_dist = sdl_float(p);
            double l = sqrt(j->slice[0] * j->slice[0] + j->slice[1] * j->slice[1] + j->slice[2] * j->slice[2] +
                            j->slice[3] * j->slice[3]);
            if (sdl_ok(p) && !(l > SDL_SHAPE_EPSILON)) {
                sdl_error(p, at, PT_ERR_SYNTAX, "slice vector is zero");
                return;
            }
            for (int i = 0; i < 4; i++) j->slice[i] /= l;
            if (sdl_ok(p) && fabs(j->slice[3]) < SDL_SHAPE_EPSILON) {
                sdl_error(p, at, PT_ERR_SYNTAX, "slice t component is zero");
                return;
            }
        } else {
            break;
        }
    }
    if (!sdl_ok(p)) return;
    if (!j->hypercomplex && j->func != JULIA_SQR && j->func != JULIA_CUBE) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "quaternion julia_fractal supports only sqr and cube");
        return;
    }
    o->kind = SHAPE_JULIA;
    o->u.julia = j;
}

/* ------------------------------------------------------------ ovus */

/* ovus := bottom_radius ',' top_radius (POV-Ray 3.7's Parse_Ovus: negative
 * radii are an error; top >= 2 bottom makes the sphere of the top radius
 * centred at <0, bottom, 0>, with a warning, as POV-Ray substitutes it) */
static void ovus_args(sdl_parser *p, scene_object *o, src_loc loc)
{
    double b = sdl_float(p);
    sdl_accept(p, TOK_COMMA);
    double t = sdl_float(p);
    if (!sdl_ok(p)) return;
    if (!(b >= 0.0) || !(t >= 0.0)) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "both ovus radii must be positive");
        return;
    }
    if (!(t < 2.0 * b)) {
        sdl_warning(p, loc, "ovus top radius should be less than twice the bottom radius; a sphere replaces it, as in POV-Ray");
        o->kind = SHAPE_SPHERE;
        o->name = "ovus";
        o->u.sphere.centre = v3(0.0, b, 0.0);
        o->u.sphere.radius = t;
        return;
    }
    o->kind = SHAPE_OVUS;
    o->name = "ovus";
    o->u.ovus.bottom = b;
    o->u.ovus.top = t;
}

/* ------------------------------------------------------------ dispatch */

void sdl_shape_args(sdl_parser *p, sdl_kw k, sdl_obj *so, src_loc loc)
{
    scene_object *o = so->obj;
    switch (k) {
    case KW_POLYGON: polygon_args(p, o, loc); break;
    case KW_LATHE: lathe_args(p, o); break;
    case KW_SOR: sor_args(p, o); break;
    case KW_PRISM: prism_args(p, o, loc); break;
    case KW_SUPERELLIPSOID: superellipsoid_args(p, o, loc); break;
    case KW_QUADRIC: quadric_args(p, o); break;
    case KW_POLY: poly_args(p, o, 0); break;
    case KW_CUBIC: poly_args(p, o, 3); break;
    case KW_QUARTIC: poly_args(p, o, 4); break;
    case KW_POLYNOMIAL: polynomial_args(p, o); break;
    case KW_BLOB: blob_args(p, o, loc); break;
    case KW_HEIGHT_FIELD: height_field_args(p, o, loc); break;
    case KW_TEXT: text_args(p, o, loc); break;
    case KW_SPHERE_SWEEP: sphere_sweep_args(p, so, loc); break;
    case KW_BICUBIC_PATCH: bicubic_args(p, so, loc); break;
    case KW_ISOSURFACE: isosurface_args(p, o, loc); break;
    case KW_PARAMETRIC: parametric_args(p, so, loc); break;
    case KW_JULIA_FRACTAL: julia_args(p, o, loc); break;
    case KW_OVUS: ovus_args(p, o, loc); break;
    default: break;
    }
    /* anything that did not produce a shape stays reported as unsupported */
    if (o->kind == SHAPE_UNSUPPORTED && !o->name) o->name = sdl_kw_text(k);
}
