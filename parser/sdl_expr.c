/* sdl_expr.c - expressions. See sdl_expr.h for the grammar. */
#include "sdl_expr.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <limits.h>
#include "sdl_array.h"
#include "sdl_directive.h"
#include "sdl_function.h"
#include "sdl_geom.h"
#include "sdl_image.h"

#define SDL_EPSILON 1e-10 /* POV-Ray's truth threshold for floats */

typedef struct {
    int n;
    double v[5];
} ex_val;

static void primary(sdl_parser *p, ex_val *out);
static void factor(sdl_parser *p, ex_val *out);
static void expression(sdl_parser *p, ex_val *out);
static void sum(sdl_parser *p, ex_val *out);
static const char *string_expr(sdl_parser *p);
static unsigned utf8_at(const char **ps);
static long utf8_len(const char *s);

int sdl_true(double x) { return fabs(x) > SDL_EPSILON; }

/* A built-in function's next argument after its ',' (the comma optional,
 * as everywhere in POV-Ray's argument lists): an integer / a string. */
static int next_int_arg(sdl_parser *p)
{
    sdl_accept(p, TOK_COMMA);
    return sdl_to_int(sdl_float(p));
}

static const char *next_string_arg(sdl_parser *p)
{
    sdl_accept(p, TOK_COMMA);
    return string_expr(p);
}

static void ex_float(ex_val *e, double x)
{
    memset(e, 0, sizeof *e);
    e->n = 1;
    e->v[0] = x;
}

/* POV-Ray promotion: a float fills every term, a vector is padded with 0. */
static void promote(ex_val *e, int n)
{
    if (e->n >= n) return;
    for (int i = e->n; i < n; i++) e->v[i] = e->n == 1 ? e->v[0] : 0.0;
    e->n = n;
}

/* Bring two operands to the same number of terms. */
static void balance(ex_val *a, ex_val *b)
{
    if (b->n > a->n) promote(a, b->n);
    else promote(b, a->n);
}

static void to_value(const ex_val *e, sdl_value *out)
{
    memset(out, 0, sizeof *out);
    out->dim = e->n;
    out->kind = e->n == 1 ? VAL_FLOAT : (e->n == 5 ? VAL_COLOUR : VAL_VECTOR);
    memcpy(out->v, e->v, sizeof e->v);
}

/* ------------------------------------------------------------ token classes */

static int kw_is_float_fn(sdl_kw k)
{
    switch (k) {
    case KW_ABS: case KW_ACOS: case KW_ACOSH: case KW_ASC: case KW_ASIN: case KW_ASINH:
    case KW_ATAN: case KW_ATAN2: case KW_ATANH: case KW_BITWISE_AND: case KW_BITWISE_OR:
    case KW_BITWISE_XOR: case KW_CEIL: case KW_CLOCK: case KW_CLOCK_ON: case KW_COS:
    case KW_COSH: case KW_DEFINED: case KW_DEGREES: case KW_DIMENSION_SIZE: case KW_DIMENSIONS:
    case KW_DIV: case KW_EXP: case KW_FILE_EXISTS: case KW_FLOOR: case KW_INSIDE: case KW_INT:
    case KW_LN: case KW_LOG: case KW_MAX: case KW_MIN: case KW_MOD: case KW_NOW: case KW_PI:
    case KW_POW: case KW_RADIANS: case KW_RAND: case KW_SEED: case KW_SELECT: case KW_SIN:
    case KW_SINH: case KW_SQR: case KW_SQRT: case KW_STRCMP: case KW_STRLEN: case KW_TAN:
    case KW_TANH: case KW_VAL: case KW_VDOT: case KW_VLENGTH: case KW_VERSION: case KW_TRUE:
    case KW_FALSE: case KW_YES: case KW_NO: case KW_ON: case KW_OFF:
        return 1;
    default:
        return 0;
    }
}

static int kw_is_vector_fn(sdl_kw k)
{
    switch (k) {
    case KW_VAXIS_ROTATE: case KW_VCROSS: case KW_VNORMALIZE: case KW_VROTATE:
    case KW_VTURBULENCE: case KW_X: case KW_Y: case KW_Z: case KW_TRACE:
    case KW_MIN_EXTENT: case KW_MAX_EXTENT:
        return 1;
    default:
        return 0;
    }
}

static int kw_is_colour_key(sdl_kw k)
{
    switch (k) {
    case KW_ALPHA: case KW_BLUE: case KW_FILTER: case KW_GREEN: case KW_RED: case KW_RGB:
    case KW_RGBF: case KW_RGBFT: case KW_RGBT: case KW_SRGB: case KW_SRGBF: case KW_SRGBFT:
    case KW_SRGBT: case KW_TRANSMIT:
        return 1;
    default:
        return 0;
    }
}

static int ident_kind(const sdl_tok *t, sdl_val_kind k) { return t->tk.kind == TOK_IDENT && t->val.kind == k; }

int sdl_starts_float(const sdl_tok *t)
{
    switch (t->tk.kind) {
    case TOK_NUMBER: case TOK_LPAREN: case TOK_PLUS: case TOK_MINUS: case TOK_BANG:
        return 1;
    case TOK_KEYWORD:
        return kw_is_float_fn(t->tk.kw);
    case TOK_IDENT:
        return t->val.kind == VAL_FLOAT || t->val.kind == VAL_FUNCTION;
    default:
        return 0;
    }
}

int sdl_starts_colour(const sdl_tok *t)
{
    if (t->tk.kind == TOK_KEYWORD)
        return t->tk.kw == KW_COLOR || t->tk.kw == KW_COLOUR || kw_is_colour_key(t->tk.kw);
    return ident_kind(t, VAL_COLOUR);
}

int sdl_starts_expr(const sdl_tok *t)
{
    if (sdl_starts_float(t) || sdl_starts_colour(t)) return 1;
    if (t->tk.kind == TOK_LT) return 1;
    if (t->tk.kind == TOK_KEYWORD)
        return kw_is_vector_fn(t->tk.kw) || t->tk.kw == KW_U || t->tk.kw == KW_V || t->tk.kw == KW_T;
    return ident_kind(t, VAL_VECTOR) || ident_kind(t, VAL_FUNCTION) || ident_kind(t, VAL_SPLINE);
}

int sdl_starts_string(const sdl_tok *t)
{
    if (t->tk.kind == TOK_STRING) return 1;
    if (t->tk.kind == TOK_IDENT) return t->val.kind == VAL_STRING;
    if (t->tk.kind != TOK_KEYWORD) return 0;
    switch (t->tk.kw) {
    case KW_CONCAT: case KW_STR: case KW_CHR: case KW_SUBSTR: case KW_STRUPR: case KW_STRLWR:
    case KW_VSTR: case KW_DATETIME:
        return 1;
    default:
        return 0;
    }
}

/* ------------------------------------------------------------ helpers */

/* Expect a float result from e. */
static double want_float(sdl_parser *p, const ex_val *e, src_loc loc)
{
    if (e->n != 1 && sdl_ok(p)) sdl_error(p, loc, PT_ERR_SYNTAX, "float expected but vector or colour expression found");
    return e->v[0];
}

/* '(' expression ')' as a float */
double sdl_float_param(sdl_parser *p)
{
    ex_val e;
    sdl_expect(p, TOK_LPAREN, "'('");
    src_loc loc = sdl_peek(p)->tk.loc;
    expression(p, &e);
    sdl_expect(p, TOK_RPAREN, "')'");
    return want_float(p, &e, loc);
}

/* '(' float ',' float ')' */
static void float_param2(sdl_parser *p, double *a, double *b)
{
    sdl_expect(p, TOK_LPAREN, "'('");
    *a = sdl_float(p);
    sdl_accept(p, TOK_COMMA);
    *b = sdl_float(p);
    sdl_expect(p, TOK_RPAREN, "')'");
}

/* '(' vector [',' vector] ')' */
static void vector_param(sdl_parser *p, vec3 *a, vec3 *b)
{
    sdl_expect(p, TOK_LPAREN, "'('");
    *a = sdl_vector(p);
    if (b) {
        sdl_accept(p, TOK_COMMA);
        *b = sdl_vector(p);
    }
    sdl_expect(p, TOK_RPAREN, "')'");
}

/* '(' float { ',' float } ')' folded with op: min, max, bitwise ops */
static double float_list_param(sdl_parser *p, sdl_kw op)
{
    sdl_expect(p, TOK_LPAREN, "'('");
    double v = sdl_float(p);
    while (sdl_ok(p) && sdl_accept(p, TOK_COMMA)) {
        double w = sdl_float(p);
        switch (op) {
        case KW_MIN: v = fmin(v, w); break;
        case KW_MAX: v = fmax(v, w); break;
        case KW_BITWISE_AND: v = (double)((long)v & (long)w); break;
        case KW_BITWISE_OR: v = (double)((long)v | (long)w); break;
        default: v = (double)((long)v ^ (long)w); break;
        }
    }
    sdl_expect(p, TOK_RPAREN, "')'");
    return v;
}

/* select '(' f ',' less ',' equal [',' greater] ')' */
static double select_fn(sdl_parser *p)
{
    sdl_expect(p, TOK_LPAREN, "'('");
    double v = sdl_float(p);
    sdl_accept(p, TOK_COMMA);
    double lt = sdl_float(p);
    sdl_accept(p, TOK_COMMA);
    double eq = sdl_float(p);
    double gt = eq;
    int four = sdl_accept(p, TOK_COMMA);
    if (four) gt = sdl_float(p);
    sdl_expect(p, TOK_RPAREN, "')'");
    if (v < 0) return lt;
    if (!four || v == 0) return eq;
    return gt;
}

/* array_param: an array identifier (or an element that is an array) */
static const sdl_array *array_param(sdl_parser *p)
{
    sdl_tok t = sdl_next(p);
    if (t.tk.kind == TOK_IDENT && t.val.kind == VAL_ARRAY && t.val.ptr) return t.val.ptr;
    sdl_unexpected(p, &t, "array identifier");
    return NULL;
}

/* dimensions '(' array ')' | dimension_size '(' array ',' float ')' ;
 * a dimension outside 1..dimensions gives 0 (POV-Ray 3.7). */
static double dimension_fn(sdl_parser *p, sdl_kw k)
{
    sdl_expect(p, TOK_LPAREN, "'('");
    const sdl_array *a = array_param(p);
    double v = 0;
    if (k == KW_DIMENSION_SIZE) {
        int d = next_int_arg(p) - 1;
        if (a && d >= 0 && d < a->ndims) v = a->sizes[d];
    } else if (a) {
        v = a->ndims;
    }
    sdl_expect(p, TOK_RPAREN, "')'");
    return v;
}

/* POV-Ray 3.7's random streams: a 32-bit LCG (x = x*1812433253 + 12345),
 * value x / (2^32-1). seed(n) opens a stream, rand(s) draws from it. */
static double rand_fn(sdl_parser *p, src_loc loc);
static double seed_fn(sdl_parser *p);

typedef struct {
    unsigned *state;
    int n;
} rand_streams;

static rand_streams *streams_of(sdl_parser *p);

static double seed_fn(sdl_parser *p)
{
    double s = sdl_float_param(p);
    rand_streams *r = streams_of(p);
    if (!r) return 0;
    unsigned *ns = sdl_alloc(p, sizeof(unsigned) * (size_t)(r->n + 1));
    if (!ns) return 0;
    if (r->n) memcpy(ns, r->state, sizeof(unsigned) * (size_t)r->n);
    ns[r->n] = (unsigned)(long)s;
    r->state = ns;
    return r->n++;
}

static double rand_fn(sdl_parser *p, src_loc loc)
{
    int i = sdl_to_int(sdl_float_param(p));
    rand_streams *r = streams_of(p);
    if (!r || i < 0 || i >= r->n) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "illegal random number generator");
        return 0;
    }
    r->state[i] = r->state[i] * 1812433253u + 12345u;
    return (double)r->state[i] / 4294967295.0;
}

/* The streams live in a symbol the user cannot spell. */
static rand_streams *streams_of(sdl_parser *p)
{
    static const char key[] = " rand streams";
    const sdl_value *v = sdl_symtab_find(p->sym, key, sizeof key - 1);
    if (v) return v->ptr;
    sdl_value nv = {.kind = VAL_OPAQUE, .str = "rand", .ptr = sdl_alloc(p, sizeof(rand_streams))};
    if (!nv.ptr) return NULL;
    /* global scope, whatever the current depth */
    sdl_symtab_declare(p->sym, key, sizeof key - 1, &nv);
    return nv.ptr;
}

/* strcmp/strlen/val/asc/file_exists: string functions with a float result */
static double string_float_fn(sdl_parser *p, sdl_kw k)
{
    sdl_expect(p, TOK_LPAREN, "'('");
    const char *a = string_expr(p);
    double v = 0;
    if (k == KW_STRCMP) {
        const char *b = next_string_arg(p);
        /* POV-Ray's UCS2_strcmp: the difference of the first differing codes */
        unsigned ca, cb;
        do {
            ca = utf8_at(&a);
            cb = utf8_at(&b);
        } while (ca == cb && ca != 0);
        v = (double)ca - (double)cb;
    } else if (k == KW_STRLEN) {
        v = (double)utf8_len(a);
    } else if (k == KW_VAL) {
        v = atof(a);
    } else if (k == KW_ASC) {
        v = utf8_at(&a);
    } else {
        v = sdl_file_exists(p, a);
    }
    sdl_expect(p, TOK_RPAREN, "')'");
    return v;
}

/* One-argument math functions. Returns 1 if k is one of them. */
static int math1(sdl_parser *p, sdl_kw k, src_loc loc, double *out)
{
    double x;
    switch (k) {
    case KW_ABS: case KW_ACOS: case KW_ACOSH: case KW_ASIN: case KW_ASINH: case KW_ATAN:
    case KW_ATANH: case KW_CEIL: case KW_COS: case KW_COSH: case KW_DEGREES: case KW_EXP:
    case KW_FLOOR: case KW_INT: case KW_LN: case KW_LOG: case KW_RADIANS: case KW_SIN:
    case KW_SINH: case KW_SQR: case KW_SQRT: case KW_TAN: case KW_TANH:
        x = sdl_float_param(p);
        break;
    default:
        return 0;
    }
    switch (k) {
    case KW_ABS: *out = fabs(x); break;
    case KW_ACOS: case KW_ASIN:
        if (x > 1 || x < -1) {
            sdl_warning(p, loc, "domain error in %s", sdl_kw_text(k));
            x = x > 1 ? 1 : -1;
        }
        *out = k == KW_ACOS ? acos(x) : asin(x);
        break;
    case KW_ACOSH: *out = acosh(x); break;
    case KW_ASINH: *out = asinh(x); break;
    case KW_ATAN: *out = atan(x); break;
    case KW_ATANH: *out = atanh(x); break;
    case KW_CEIL: *out = ceil(x); break;
    case KW_COS: *out = cos(x); break;
    case KW_COSH: *out = cosh(x); break;
    case KW_DEGREES: *out = x * (180.0 / M_PI); break;
    case KW_EXP: *out = exp(x); break;
    case KW_FLOOR: *out = floor(x); break;
    case KW_INT: *out = trunc(x); break;
    case KW_LN: case KW_LOG:
        if (x <= 0) sdl_error(p, loc, PT_ERR_SYNTAX, "%s of a non-positive number %g", sdl_kw_text(k), x);
        *out = x > 0 ? (k == KW_LN ? log(x) : log10(x)) : 0; /* POV-Ray: log is base 10 */
        break;
    case KW_RADIANS: *out = x * (M_PI / 180.0); break;
    case KW_SIN: *out = sin(x); break;
    case KW_SINH: *out = sinh(x); break;
    case KW_SQR: *out = x * x; break;
    case KW_SQRT:
        if (x < 0) sdl_error(p, loc, PT_ERR_SYNTAX, "sqrt of a negative number %g", x);
        *out = x >= 0 ? sqrt(x) : 0;
        break;
    case KW_TAN: *out = tan(x); break;
    default: *out = tanh(x); break;
    }
    return 1;
}

/* Two-argument math functions: atan2 div mod pow. */
static int math2(sdl_parser *p, sdl_kw k, src_loc loc, double *out)
{
    double a, b;
    if (k != KW_ATAN2 && k != KW_DIV && k != KW_MOD && k != KW_POW) return 0;
    float_param2(p, &a, &b);
    if (k == KW_ATAN2) {
        if (!sdl_true(a) && !sdl_true(b)) sdl_error(p, loc, PT_ERR_SYNTAX, "domain error in atan2");
        *out = atan2(a, b);
    } else if (k == KW_DIV) {
        if (b == 0) sdl_error(p, loc, PT_ERR_SYNTAX, "division by zero in div");
        *out = b != 0 ? trunc(a / b) : 0;
    } else if (k == KW_MOD) {
        *out = fmod(a, b);
    } else {
        if (a == 0 && b == 0) sdl_error(p, loc, PT_ERR_SYNTAX, "domain error in pow(0, 0)");
        *out = pow(a, b);
    }
    return 1;
}

/* float_function: the keyword k has been read. */
static double float_function(sdl_parser *p, sdl_kw k, src_loc loc)
{
    double v = 0;
    if (math1(p, k, loc, &v) || math2(p, k, loc, &v)) return v;
    switch (k) {
    case KW_PI: return M_PI;
    case KW_TRUE: case KW_YES: case KW_ON: return 1;
    case KW_FALSE: case KW_NO: case KW_OFF: return 0;
    case KW_CLOCK: sdl_note_frame_value(p); return p->opt.clock;
    case KW_CLOCK_ON: return p->opt.clock_on;
    case KW_VERSION: return p->version;
    case KW_NOW: {
        p->frame_dependent = 1; /* the time of day, anywhere */
        /* days since 2000-01-01 00:00 UTC, to the microsecond (POV-Ray 3.7).
         * CLOCK_REALTIME, the clock time() and the rest of the program read,
         * so a scene and its log agree on the date; time() if it fails. */
        struct timespec ts = { 0, 0 };
        if (clock_gettime(CLOCK_REALTIME, &ts) != 0) ts.tv_sec = time(NULL);
        return ((double)ts.tv_sec - 946684800.0 + (double)(ts.tv_nsec / 1000) * 1e-6) / 86400.0;
    }
    case KW_MIN: case KW_MAX: case KW_BITWISE_AND: case KW_BITWISE_OR: case KW_BITWISE_XOR:
        return float_list_param(p, k);
    case KW_SELECT: return select_fn(p);
    case KW_DIMENSIONS: case KW_DIMENSION_SIZE: return dimension_fn(p, k);
    case KW_DEFINED: return sdl_defined_param(p);
    case KW_SEED: return seed_fn(p);
    case KW_RAND: return rand_fn(p, loc);
    case KW_STRCMP: case KW_STRLEN: case KW_VAL: case KW_ASC: case KW_FILE_EXISTS:
        return string_float_fn(p, k);
    case KW_VDOT: {
        vec3 a, b;
        vector_param(p, &a, &b);
        return v3_dot(a, b);
    }
    case KW_VLENGTH: {
        vec3 a;
        vector_param(p, &a, NULL);
        return v3_len(a);
    }
    case KW_INSIDE: return sdl_inside_fn(p, loc);
    default:
        sdl_error(p, loc, PT_ERR_UNSUPPORTED, "'%s' is not supported yet", sdl_kw_text(k));
        return 0;
    }
}

/* vaxis_rotate '(' point ',' axis ',' degrees ')': rotate about an axis through the origin */
static vec3 vaxis_rotate_fn(sdl_parser *p)
{
    sdl_expect(p, TOK_LPAREN, "'('");
    vec3 pt = sdl_vector(p);
    sdl_accept(p, TOK_COMMA);
    vec3 ax = v3_norm(sdl_vector(p));
    sdl_accept(p, TOK_COMMA);
    double a = sdl_float(p) * (M_PI / 180.0);
    sdl_expect(p, TOK_RPAREN, "')'");
    /* Rodrigues' formula with POV-Ray's (left-handed) sense: the same matrix
     * as xform_rotate uses for the coordinate axes. */
    double c = cos(a), s = sin(a);
    return v3_add(v3_add(v3_scale(pt, c), v3_scale(v3_cross(ax, pt), s)), v3_scale(ax, v3_dot(ax, pt) * (1 - c)));
}

/* vturbulence '(' lambda ',' omega ',' octaves ',' point ')' : POV-Ray's
 * DTurbulence, from the evaluators the app supplies (sdl_options.func_env). */
static vec3 vturbulence_fn(sdl_parser *p, src_loc loc)
{
    sdl_expect(p, TOK_LPAREN, "'('");
    double lambda = sdl_float(p);
    sdl_accept(p, TOK_COMMA);
    double omega = sdl_float(p);
    int octaves = next_int_arg(p);
    sdl_accept(p, TOK_COMMA);
    vec3 v = sdl_vector(p);
    sdl_accept(p, TOK_COMMA);
    sdl_expect(p, TOK_RPAREN, "')'");
    if (!sdl_ok(p)) return v3(0, 0, 0);
    octaves = octaves < 1 ? 1 : (octaves > 10 ? 10 : octaves); /* POV-Ray's clamp */
    const func_env *env = p->opt.func_env;
    if (!env || !env->dturbulence) {
        sdl_error(p, loc, PT_ERR_UNSUPPORTED, "vturbulence needs POV-Ray's noise, which this parse was given no evaluator for");
        return v3(0, 0, 0);
    }
    return env->dturbulence(env->user, v, octaves, omega, lambda);
}

/* vector_function: the keyword k has been read. */
static vec3 vector_function(sdl_parser *p, sdl_kw k, src_loc loc)
{
    vec3 a, b;
    switch (k) {
    case KW_X: return v3(1, 0, 0);
    case KW_Y: return v3(0, 1, 0);
    case KW_Z: return v3(0, 0, 1);
    case KW_VCROSS:
        vector_param(p, &a, &b);
        return v3_cross(a, b);
    case KW_VNORMALIZE:
        vector_param(p, &a, NULL);
        if (v3_len2(a) == 0) {
            sdl_warning(p, loc, "normalizing a zero-length vector");
            return v3(0, 0, 0);
        }
        return v3_norm(a);
    case KW_VROTATE: {
        vector_param(p, &a, &b);
        xform r = xform_rotate(b);
        return xform_point(&r, a);
    }
    case KW_VAXIS_ROTATE:
        return vaxis_rotate_fn(p);
    case KW_TRACE: return sdl_trace_fn(p, loc);
    case KW_MIN_EXTENT: case KW_MAX_EXTENT: return sdl_extent_fn(p, loc, k == KW_MAX_EXTENT);
    default: return vturbulence_fn(p, loc);
    }
}

/* vector_literal: '<' sum [','] sum [ [','] sum [ [','] sum [ [','] sum ] ] ] '>'
 * Commas are optional, as POV-Ray accepts <1 2 3>. */
static void vector_literal(sdl_parser *p, ex_val *out)
{
    memset(out, 0, sizeof *out);
    out->n = 0;
    while (sdl_ok(p) && out->n < 5) {
        if (out->n >= 2 && !sdl_starts_expr(sdl_peek(p))) break;
        out->v[out->n++] = sdl_float(p);
        sdl_accept(p, TOK_COMMA);
    }
    sdl_expect(p, TOK_GT, "'>' closing the vector");
}

/* identifier_value: a float/vector/colour identifier */
static void identifier_value(sdl_parser *p, const sdl_tok *t, ex_val *out)
{
    memset(out, 0, sizeof *out);
    out->n = 1;
    switch (t->val.kind) {
    case VAL_FLOAT: case VAL_VECTOR: case VAL_COLOUR:
        out->n = t->val.dim;
        memcpy(out->v, t->val.v, sizeof out->v);
        return;
    case VAL_NONE:
        sdl_error(p, t->tk.loc, PT_ERR_SYNTAX, "undeclared identifier '%.*s'", t->tk.len, t->tk.text);
        return;
    case VAL_FUNCTION: case VAL_SPLINE: {
        /* a float function's value fills every term it is promoted to;
         * vector, colour and spline results keep their terms */
        if (t->val.kind == VAL_FUNCTION) sdl_call_function(p, t, out->v);
        else sdl_call_spline(p, t, out->v);
        out->n = t->val.kind == VAL_FUNCTION ? ((const scene_function *)t->val.ptr)->nterms : ((const user_spline *)t->val.ptr)->terms;
        return;
    }
    default:
        break;
    }
    sdl_error(p, t->tk.loc, PT_ERR_SYNTAX, "numeric expression expected but '%.*s' is not a float, vector or colour", t->tk.len, t->tk.text);
}

/* keyword_primary: float functions, vector functions, u v t */
static void keyword_primary(sdl_parser *p, const sdl_tok *t, ex_val *out)
{
    sdl_kw k = t->tk.kw;
    memset(out, 0, sizeof *out);
    if (kw_is_float_fn(k)) {
        ex_float(out, float_function(p, k, t->tk.loc));
    } else if (kw_is_vector_fn(k)) {
        vec3 v = vector_function(p, k, t->tk.loc);
        out->n = 3;
        out->v[0] = v.x; out->v[1] = v.y; out->v[2] = v.z;
    } else if (k == KW_U || k == KW_V) {
        out->n = 2;
        out->v[k == KW_U ? 0 : 1] = 1;
    } else if (k == KW_T) {
        out->n = 4;
        out->v[3] = 1;
    } else if (sdl_starts_colour(t)) {
        /* A colour written inside an expression: accepted as POV-Ray
         * accepts it in a #declare (rgb <..> etc.). */
        sdl_unget(p, t);
        colour5 c = sdl_colour(p, 1);
        out->n = 5;
        out->v[0] = c.r; out->v[1] = c.g; out->v[2] = c.b; out->v[3] = c.f; out->v[4] = c.t;
    } else {
        sdl_unexpected(p, t, "numeric expression");
    }
}

/* primary := number | identifier | function | '<' vector '>' | '(' expression ')'
 *          | ('-' | '+' | '!') factor */
static void primary_inner(sdl_parser *p, ex_val *out)
{
    sdl_tok t = sdl_next(p);
    ex_float(out, 0);
    switch (t.tk.kind) {
    case TOK_NUMBER: ex_float(out, t.tk.num); return;
    case TOK_IDENT: identifier_value(p, &t, out); return;
    case TOK_KEYWORD: keyword_primary(p, &t, out); return;
    case TOK_LT: vector_literal(p, out); return;
    case TOK_LPAREN:
        expression(p, out);
        sdl_expect(p, TOK_RPAREN, "')'");
        return;
    case TOK_PLUS: factor(p, out); return;
    case TOK_MINUS:
        factor(p, out);
        for (int i = 0; i < out->n; i++) out->v[i] = -out->v[i];
        return;
    case TOK_BANG:
        factor(p, out);
        for (int i = 0; i < out->n; i++) out->v[i] = sdl_true(out->v[i]) ? 0.0 : 1.0;
        return;
    default:
        sdl_unexpected(p, &t, "numeric expression");
        return;
    }
}

/* Inside a primary, directives and macros run even while a declaration's
 * look-ahead defers them or a condition holds macros (POV-Ray: Ok_To_Declare
 * is set within Parse_Num_Factor, so `#while (Macro(A))` calls the macro). */
static void primary(sdl_parser *p, ex_val *out)
{
    ex_float(out, 0);
    if (!sdl_enter(p, p->last_loc)) return;
    int saved = p->defer, held = p->hold_macros;
    p->defer = 0;
    p->hold_macros = 0;
    primary_inner(p, out);
    p->defer = saved;
    p->hold_macros = held;
    sdl_leave(p);
}

/* component := x | y | z | u | v | t | red | green | blue | filter | transmit | gray */
int sdl_component_index(const sdl_tok *t)
{
    if (t->tk.kind != TOK_KEYWORD) return -1;
    switch (t->tk.kw) {
    case KW_X: case KW_U: case KW_RED: return 0;
    case KW_Y: case KW_V: case KW_GREEN: return 1;
    case KW_Z: case KW_BLUE: return 2;
    case KW_T: case KW_FILTER: return 3;
    case KW_TRANSMIT: return 4;
    case KW_GRAY: return 5;
    default: return -1;
    }
}

/* factor := primary [ '.' component ] */
static void factor(sdl_parser *p, ex_val *out)
{
    primary(p, out);
    if (!sdl_ok(p) || !sdl_accept(p, TOK_DOT)) return;
    sdl_tok c = sdl_next(p);
    int i = sdl_component_index(&c);
    if (i < 0) {
        sdl_unexpected(p, &c, "x, y, z or colour component");
        return;
    }
    if (i == 5) { /* gray: POV-Ray's luminance weights */
        promote(out, 3);
        ex_float(out, 0.297 * out->v[0] + 0.589 * out->v[1] + 0.114 * out->v[2]);
        return;
    }
    if (i >= out->n) {
        sdl_error(p, c.tk.loc, PT_ERR_SYNTAX, "bad operand for '.': the value has only %d terms", out->n);
        return;
    }
    ex_float(out, out->v[i]);
}

/* term := factor { ('*' | '/') factor } */
static void term(sdl_parser *p, ex_val *out)
{
    factor(p, out);
    while (sdl_ok(p)) {
        const sdl_tok *t = sdl_peek(p);
        int mul = t->tk.kind == TOK_STAR;
        if (!mul && t->tk.kind != TOK_SLASH) return;
        src_loc loc = t->tk.loc;
        sdl_next(p);
        ex_val r;
        factor(p, &r);
        balance(out, &r);
        for (int i = 0; i < out->n; i++) {
            if (mul) {
                out->v[i] *= r.v[i];
            } else if (r.v[i] == 0.0) {
                sdl_warning(p, loc, "divide by zero");
                out->v[i] = HUGE_VAL;
            } else {
                out->v[i] /= r.v[i];
            }
        }
    }
}

/* sum := term { ('+' | '-') term } */
static void sum(sdl_parser *p, ex_val *out)
{
    term(p, out);
    while (sdl_ok(p)) {
        const sdl_tok *t = sdl_peek(p);
        int add = t->tk.kind == TOK_PLUS;
        if (!add && t->tk.kind != TOK_MINUS) return;
        sdl_next(p);
        ex_val r;
        term(p, &r);
        balance(out, &r);
        for (int i = 0; i < out->n; i++) out->v[i] += add ? r.v[i] : -r.v[i];
    }
}

static int is_compare(sdl_tok_kind k)
{
    return k == TOK_LT || k == TOK_LE || k == TOK_EQ || k == TOK_NE || k == TOK_GE || k == TOK_GT;
}

static double compare(sdl_tok_kind op, double a, double b)
{
    switch (op) {
    case TOK_LT: return a < b;
    case TOK_LE: return a <= b || !sdl_true(a - b);
    case TOK_EQ: return !sdl_true(a - b);
    case TOK_NE: return sdl_true(a - b);
    case TOK_GE: return a >= b || !sdl_true(a - b);
    default: return a > b;
    }
}

/* string_relation := string ( '<' | '<=' | '=' | '!=' | '>=' | '>' ) string */
static void string_relation(sdl_parser *p, ex_val *out)
{
    const char *a = string_expr(p);
    sdl_tok op = sdl_next(p);
    if (!is_compare(op.tk.kind)) {
        sdl_unexpected(p, &op, "string comparison operator");
        ex_float(out, 0);
        return;
    }
    const char *b = string_expr(p);
    int c = strcmp(a, b);
    ex_float(out, compare(op.tk.kind, c, 0));
}

/* relation := sum { compare sum } | string_relation */
static void relation(sdl_parser *p, ex_val *out)
{
    if (sdl_starts_string(sdl_peek(p))) {
        string_relation(p, out);
        return;
    }
    sum(p, out);
    while (sdl_ok(p) && is_compare(sdl_peek(p)->tk.kind)) {
        sdl_tok op = sdl_next(p);
        ex_val r;
        sum(p, &r);
        promote(out, r.n);
        promote(&r, out->n);
        for (int i = 0; i < out->n; i++) out->v[i] = compare(op.tk.kind, out->v[i], r.v[i]);
    }
}

/* logical := relation { ('&' | '|') relation } */
static void logical(sdl_parser *p, ex_val *out)
{
    relation(p, out);
    while (sdl_ok(p)) {
        sdl_tok_kind k = sdl_peek(p)->tk.kind;
        if (k != TOK_AMP && k != TOK_BAR) return;
        sdl_next(p);
        ex_val r;
        relation(p, &r);
        promote(out, r.n);
        promote(&r, out->n);
        for (int i = 0; i < out->n; i++) {
            int a = sdl_true(out->v[i]), b = sdl_true(r.v[i]);
            out->v[i] = k == TOK_AMP ? (a && b) : (a || b);
        }
    }
}

/* expression := logical [ '?' expression ':' expression ] */
static void expression(sdl_parser *p, ex_val *out)
{
    src_loc loc = sdl_peek(p)->tk.loc;
    logical(p, out);
    if (!sdl_ok(p) || !sdl_accept(p, TOK_QUESTION)) return;
    double c = want_float(p, out, loc);
    ex_val a, b;
    if (!sdl_enter(p, loc)) return;
    expression(p, &a);
    sdl_expect(p, TOK_COLON, "':'");
    expression(p, &b);
    sdl_leave(p);
    *out = sdl_true(c) ? a : b;
}

void sdl_expr(sdl_parser *p, sdl_value *out)
{
    ex_val e;
    expression(p, &e);
    to_value(&e, out);
}

void sdl_sum(sdl_parser *p, sdl_value *out)
{
    ex_val e;
    sum(p, &e);
    to_value(&e, out);
}

double sdl_float(sdl_parser *p)
{
    ex_val e;
    src_loc loc = sdl_peek(p)->tk.loc;
    sum(p, &e);
    return want_float(p, &e, loc);
}

double sdl_allow_float(sdl_parser *p, double def)
{
    if (!sdl_starts_expr(sdl_peek(p))) return def;
    return sdl_float(p);
}

void sdl_vector_n(sdl_parser *p, double *out, int n)
{
    ex_val e;
    src_loc loc = sdl_peek(p)->tk.loc;
    sum(p, &e);
    if (e.n > n && sdl_ok(p)) sdl_error(p, loc, PT_ERR_SYNTAX, "%d-term vector expected but %d terms found", n, e.n);
    promote(&e, n);
    for (int i = 0; i < n; i++) out[i] = e.v[i];
}

vec3 sdl_vector(sdl_parser *p)
{
    double v[3];
    sdl_vector_n(p, v, 3);
    return v3(v[0], v[1], v[2]);
}

/* ------------------------------------------------------------ colours */

/* colour_vector: the expression after rgb/rgbf/rgbt/rgbft/srgb..., into c */
static void colour_vector(sdl_parser *p, sdl_kw k, double c[5])
{
    int want = (k == KW_RGB || k == KW_SRGB) ? 3 : ((k == KW_RGBFT || k == KW_SRGBFT) ? 5 : 4);
    ex_val e;
    src_loc loc = sdl_peek(p)->tk.loc;
    expression(p, &e);
    if (e.n < want) promote(&e, want);
    else if (e.n > want) sdl_warning(p, loc, "suspicious expression after %s", sdl_kw_text(k));
    for (int i = 0; i < want; i++) c[i] = e.v[i];
    if (k == KW_RGBT || k == KW_SRGBT) { /* 4th term is transmit */
        c[4] = c[3];
        c[3] = 0;
    }
    if (k == KW_SRGB || k == KW_SRGBF || k == KW_SRGBT || k == KW_SRGBFT)
        for (int i = 0; i < 3; i++) c[i] = sdl_srgb_decode(c[i]);
}

/* colour_body := { colour_key_item } where the first item may be a whole
 * colour/vector expression; see POV-Ray 3.7's Parse_Colour. */
static void colour_body(sdl_parser *p, int want_ft, double c[5])
{
    int started = 0;
    while (sdl_ok(p)) {
        const sdl_tok *t = sdl_peek(p);
        sdl_kw k = t->tk.kind == TOK_KEYWORD ? t->tk.kw : KW_NONE;
        if (k == KW_RED || k == KW_GREEN || k == KW_BLUE || k == KW_FILTER || k == KW_ALPHA || k == KW_TRANSMIT) {
            sdl_next(p);
            int i = k == KW_RED ? 0 : k == KW_GREEN ? 1 : k == KW_BLUE ? 2 : k == KW_TRANSMIT ? 4 : 3;
            c[i] = sdl_float(p);
        } else if (kw_is_colour_key(k)) {
            if (started) return;
            sdl_next(p);
            colour_vector(p, k, c);
        } else if (!started && sdl_starts_expr(t)) {
            ex_val e;
            expression(p, &e);
            promote(&e, want_ft ? 5 : 3);
            for (int i = 0; i < 5; i++) c[i] = i < e.n ? e.v[i] : 0;
        } else {
            return;
        }
        started = 1;
    }
}

/* colour := [ 'color' | 'colour' ] colour_body */
colour5 sdl_colour(sdl_parser *p, int want_ft)
{
    double c[5] = {0, 0, 0, 0, 0};
    if (!sdl_accept_kw(p, KW_COLOR)) sdl_accept_kw(p, KW_COLOUR);
    const sdl_tok *t = sdl_peek(p);
    if (sdl_starts_expr(t))
        colour_body(p, want_ft, c);
    else
        sdl_unexpected(p, t, "colour");
    colour5 r = {c[0], c[1], c[2], c[3], c[4]};
    return r;
}

rgb sdl_rgb(sdl_parser *p)
{
    colour5 c = sdl_colour(p, 0);
    rgb r = {c.r, c.g, c.b};
    return r;
}

/* ------------------------------------------------------------ strings */

static char *concat2(sdl_parser *p, const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    if (la + lb > (size_t)p->opt.max_string_length) {
        sdl_error(p, p->last_loc, PT_ERR_LIMIT, "concat makes a string of %zu bytes, longer than the limit of %ld (--max-string)",
                  la + lb, p->opt.max_string_length);
        return (char *)"";
    }
    char *s = sdl_alloc(p, la + lb + 1);
    if (!s) return (char *)"";
    memcpy(s, a, la);
    memcpy(s + la, b, lb + 1);
    return s;
}

/* POV-Ray 3.7's number formatting for str() and vstr() (Parse_Str): width
 * w > 0 gives "%wf", w < 0 "%0|w|f" (zero padded), w = 0 no width;
 * precision d >= 0 gives ".d", d < 0 printf's default (6). A value whose %f
 * text does not fit POV-Ray's 256-byte buffer is written with %g instead. */
static void pov_number(char *out, size_t cap, double v, int w, int d)
{
    /* A width past the buffer never fits, as %f or %g: say so without
     * asking printf to count 2^31 padding characters first (str(1, 1e300,
     * 0) ran for minutes: tests/fuzz/regress/parse/int_casts.pov). A
     * precision past the buffer cannot fit as %f either; %g drops trailing
     * zeros and a double has at most 767 significant decimal digits, so
     * 800 gives the same text as any larger precision. */
    if (w > 254 || w < -254) {
        snprintf(out, cap, "<invalid>");
        return;
    }
    int fixed_fits = d <= 254;
    if (d > 800) d = 800;
    char fmt[64];
    int o = 0;
    fmt[o++] = '%';
    if (w > 0) o += snprintf(fmt + o, sizeof fmt - (size_t)o, "%d", w);
    else if (w < 0) o += snprintf(fmt + o, sizeof fmt - (size_t)o, "0%d", w == INT_MIN ? INT_MAX : -w);
    if (d >= 0) o += snprintf(fmt + o, sizeof fmt - (size_t)o, ".%d", d);
    fmt[o] = 'f';
    fmt[o + 1] = 0;
    char buf[256];
    int n = fixed_fits ? snprintf(buf, sizeof buf - 1, fmt, v) : -1;
    if (n < 0 || n >= (int)sizeof buf - 1) {
        fmt[o] = 'g';
        n = snprintf(buf, sizeof buf - 1, fmt, v);
        if (n < 0 || n >= (int)sizeof buf - 1) snprintf(buf, sizeof buf, "<invalid>");
    }
    snprintf(out, cap, "%s", buf);
}

/* str '(' float ',' width ',' precision ')' */
static const char *str_fn(sdl_parser *p)
{
    sdl_expect(p, TOK_LPAREN, "'('");
    double v = sdl_float(p);
    int w = next_int_arg(p);
    int prec = next_int_arg(p);
    sdl_expect(p, TOK_RPAREN, "')'");
    char buf[256];
    pov_number(buf, sizeof buf, v, w, prec);
    return sdl_strndup(p, buf, strlen(buf));
}

/* vstr '(' dims ',' vector ',' separator ',' width ',' precision ')'.
 * The vector is read as POV-Ray's Parse_Unknown_Vector reads it (a sum, no
 * promotion): a float fills the first term only, missing terms are 0. */
static const char *vstr_fn(sdl_parser *p)
{
    sdl_expect(p, TOK_LPAREN, "'('");
    int n = sdl_to_int(sdl_float(p));
    sdl_accept(p, TOK_COMMA);
    if (n < 2) n = 2;
    if (n > 5) n = 5;
    ex_val e;
    sum(p, &e);
    const char *sep = next_string_arg(p);
    int w = next_int_arg(p);
    int prec = next_int_arg(p);
    sdl_expect(p, TOK_RPAREN, "')'");
    if (!sdl_ok(p)) return "";
    const char *out = "";
    for (int i = 0; i < n; i++) {
        char buf[256];
        pov_number(buf, sizeof buf, i < e.n ? e.v[i] : 0.0, w, prec);
        if (i) out = concat2(p, out, sep);
        out = concat2(p, out, buf);
    }
    return out;
}

/* Strings are UTF-8 inside the parser; POV-Ray's are UCS-2, so lengths,
 * positions and character codes count code points. */
static unsigned utf8_at(const char **ps)
{
    const unsigned char *s = (const unsigned char *)*ps;
    unsigned c = s[0];
    int n = c >= 0xF0 ? 3 : c >= 0xE0 ? 2 : c >= 0xC0 ? 1 : 0;
    for (int i = 1; i <= n; i++)
        if ((s[i] & 0xC0) != 0x80) n = 0;
    if (n == 0) {
        *ps += c ? 1 : 0;
        return c;
    }
    c &= 0x3Fu >> n;
    for (int i = 1; i <= n; i++) c = (c << 6) | (s[i] & 0x3Fu);
    *ps += n + 1;
    return c;
}

static long utf8_len(const char *s)
{
    long n = 0;
    while (*s) {
        utf8_at(&s);
        n++;
    }
    return n;
}

/* substr '(' string ',' start ',' length ')'  (start is 1-based; POV-Ray's
 * check: start + length - 1 <= strlen, start >= 0, length >= 0) */
static const char *substr_fn(sdl_parser *p, src_loc loc)
{
    sdl_expect(p, TOK_LPAREN, "'('");
    const char *s = string_expr(p);
    int start = next_int_arg(p);
    int len = next_int_arg(p);
    sdl_expect(p, TOK_RPAREN, "')'");
    if (!sdl_ok(p)) return "";
    long n = utf8_len(s);
    if (start < 1 || len < 0 || (long)start - 1 + len > n) {
        /* POV-Ray lets start 0 through and reads before the string */
        sdl_error(p, loc, PT_ERR_SYNTAX, "illegal parameters in substr");
        return "";
    }
    const char *a = s;
    for (int i = 1; i < start; i++) utf8_at(&a);
    const char *b = a;
    for (int i = 0; i < len; i++) utf8_at(&b);
    return sdl_strndup(p, a, (size_t)(b - a));
}

/* chr '(' float ')': code 0..65535 (POV-Ray's UCS-2 range), kept as UTF-8 */
static const char *chr_fn(sdl_parser *p, src_loc loc)
{
    int c = sdl_to_int(sdl_float_param(p));
    if (!sdl_ok(p)) return "";
    if (c < 0 || c > 65535) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "value %d cannot be used in chr(...)", c);
        return "";
    }
    char b[4];
    size_t n;
    if (c < 0x80) {
        b[0] = (char)c;
        n = 1;
    } else if (c < 0x800) {
        b[0] = (char)(0xC0 | (c >> 6));
        b[1] = (char)(0x80 | (c & 0x3F));
        n = 2;
    } else {
        b[0] = (char)(0xE0 | (c >> 12));
        b[1] = (char)(0x80 | ((c >> 6) & 0x3F));
        b[2] = (char)(0x80 | (c & 0x3F));
        n = 3;
    }
    return sdl_strndup(p, b, n);
}

/* datetime '(' days [',' format] ')': days since 2000-01-01 00:00 UTC,
 * rounded to the second, formatted by strftime in UTC (POV-Ray 3.7's
 * Parse_Datetime: default format "%Y-%m-%d %H:%M:%SZ", at most 200 bytes,
 * an empty format or an empty result is an error). */
static const char *datetime_fn(sdl_parser *p, src_loc loc)
{
    sdl_expect(p, TOK_LPAREN, "'('");
    double days = sdl_float(p);
    sdl_accept(p, TOK_COMMA);
    const char *fmt = "%Y-%m-%d %H:%M:%SZ";
    if (!sdl_is(sdl_peek(p), TOK_RPAREN)) {
        fmt = string_expr(p);
        if (sdl_ok(p) && fmt[0] == 0) sdl_error(p, loc, PT_ERR_SYNTAX, "empty format string in datetime");
        if (sdl_ok(p) && strlen(fmt) > 200) sdl_error(p, loc, PT_ERR_SYNTAX, "format string of datetime too long (more than 200 characters)");
    }
    sdl_expect(p, TOK_RPAREN, "')'");
    if (!sdl_ok(p)) return "";
    /* 10957 days from 1970-01-01 to 2000-01-01 (365*30+7 in POV-Ray) */
    double secs = floor((days + 10957.0) * 86400.0 + 0.5);
    if (!(fabs(secs) < 1e15)) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "date out of range in datetime");
        return "";
    }
    time_t ts = (time_t)secs;
    struct tm tm;
    char buf[201];
    size_t n = 0;
    if (gmtime_r(&ts, &tm)) n = strftime(buf, 200, fmt, &tm);
    if (n == 0 || n >= 200) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "invalid formatting code in datetime's format string, or the result is too long");
        return "";
    }
    return sdl_strndup(p, buf, n);
}

/* string_function: concat chr str substr strupr strlwr vstr */
static const char *string_function(sdl_parser *p, const sdl_tok *t)
{
    switch (t->tk.kw) {
    case KW_CONCAT: {
        sdl_expect(p, TOK_LPAREN, "'('");
        const char *s = string_expr(p);
        while (sdl_ok(p) && sdl_accept(p, TOK_COMMA)) s = concat2(p, s, string_expr(p));
        sdl_expect(p, TOK_RPAREN, "')'");
        return s;
    }
    case KW_CHR: return chr_fn(p, t->tk.loc);
    case KW_DATETIME: return datetime_fn(p, t->tk.loc);
    case KW_STR: return str_fn(p);
    case KW_VSTR: return vstr_fn(p);
    case KW_SUBSTR: return substr_fn(p, t->tk.loc);
    case KW_STRUPR: case KW_STRLWR: {
        sdl_expect(p, TOK_LPAREN, "'('");
        const char *s = string_expr(p);
        sdl_expect(p, TOK_RPAREN, "')'");
        char *r = sdl_strndup(p, s, strlen(s));
        for (char *c = r; *c; c++)
            *c = (char)(t->tk.kw == KW_STRUPR ? (*c >= 'a' && *c <= 'z' ? *c - 32 : *c) : (*c >= 'A' && *c <= 'Z' ? *c + 32 : *c));
        return r;
    }
    default:
        sdl_error(p, t->tk.loc, PT_ERR_UNSUPPORTED, "'%s' is not supported yet", sdl_kw_text(t->tk.kw));
        return "";
    }
}

/* string := string_literal | string_identifier | string_function */
static const char *string_expr(sdl_parser *p)
{
    sdl_tok t = sdl_next(p);
    if (t.tk.kind == TOK_STRING) {
        char *s = sdl_alloc(p, (size_t)t.tk.len * 3 + 1);
        if (!s) return "";
        sdl_token lit = t.tk;
        char *ascii = NULL;
        if (p->charset == 0 && p->version >= 3.5) {
            /* POV-Ray 3.7's String_To_UCS2 with charset ascii (the default):
             * each byte above 127 of the literal becomes a space (escapes
             * such as \u00e9 are read afterwards and keep their code) */
            for (int i = 0; i < lit.len && !ascii; i++)
                if ((unsigned char)lit.text[i] > 127) ascii = sdl_alloc(p, (size_t)lit.len + 1);
            if (ascii) {
                for (int i = 0; i < lit.len; i++) ascii[i] = (unsigned char)lit.text[i] > 127 ? ' ' : lit.text[i];
                lit.text = ascii;
                sdl_warn_once(p, t.tk.loc, "non-ASCII characters in a string are replaced by spaces (global_settings { charset utf8 } keeps them), as POV-Ray 3.7 does");
            }
        }
        sdl_scan_unescape(&lit, s, (size_t)t.tk.len * 3 + 1);
        return s;
    }
    if (t.tk.kind == TOK_IDENT && t.val.kind == VAL_STRING) return t.val.str;
    if (t.tk.kind == TOK_KEYWORD && sdl_starts_string(&t)) return string_function(p, &t);
    if (t.tk.kind == TOK_IDENT && t.val.kind == VAL_NONE)
        sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "undeclared identifier '%.*s'", t.tk.len, t.tk.text);
    else
        sdl_unexpected(p, &t, "string");
    return "";
}

const char *sdl_string(sdl_parser *p) { return string_expr(p); }

const char *sdl_c_string(sdl_parser *p, const char *s)
{
    const char *a = s;
    int wide = 0;
    for (; *a; a++) wide |= (unsigned char)*a > 127;
    if (!wide) return s;
    char *r = sdl_alloc(p, strlen(s) + 1), *o = r;
    if (!r) return s;
    for (a = s; *a;) {
        unsigned c = utf8_at(&a);
        *o++ = c > 127 ? ' ' : (char)c;
    }
    *o = 0;
    return r;
}
