/* sdl_array.c - arrays: declaration, initialisers, subscripts, elements. */
#include "sdl_array.h"
#include <assert.h>
#include <string.h>
#include "sdl_directive.h"
#include "sdl_expr.h"

/* POV-Ray truncates sizes and subscripts after adding this epsilon. */
#define SUBSCRIPT_EPSILON 1e-10

/* Human name of a value's type for messages ("float", "vector", "object"...). */
static const char *sdl_value_type_name(sdl_val_kind k, int dim)
{
    switch (k) {
    case VAL_NONE: return "uninitialised value";
    case VAL_FLOAT: return "float";
    case VAL_VECTOR: return dim == 2 ? "2-D vector" : (dim == 4 ? "4-D vector" : "vector");
    case VAL_COLOUR: return "colour";
    case VAL_STRING: return "string";
    case VAL_TEXTURE: return "texture";
    case VAL_PIGMENT: return "pigment";
    case VAL_FINISH: return "finish";
    case VAL_NORMAL: return "normal";
    case VAL_INTERIOR: return "interior";
    case VAL_MATERIAL: return "material";
    case VAL_OBJECT: return "object";
    case VAL_CAMERA: return "camera";
    case VAL_TRANSFORM: return "transform";
    case VAL_MACRO: return "macro";
    case VAL_ARRAY: return "array";
    case VAL_FUNCTION: return "function";
    case VAL_SPLINE: return "spline";
    case VAL_FILE: return "file";
    default: return "value";
    }
}

/* Stride of dimension d (row-major: the last subscript varies fastest). */
static long stride(const sdl_array *a, int d)
{
    long m = 1;
    for (int i = d + 1; i < a->ndims; i++) m *= a->sizes[i];
    return m;
}

static int numeric(sdl_val_kind k) { return k == VAL_FLOAT || k == VAL_VECTOR || k == VAL_COLOUR; }

/* A copy of v fit to live in an array (arrays are copied by value). */
static sdl_value stored_value(sdl_parser *p, const sdl_value *v)
{
    sdl_value s = *v;
    if (s.kind == VAL_ARRAY && s.ptr) s.ptr = sdl_array_copy(p, s.ptr);
    return s;
}

void sdl_array_set(sdl_parser *p, sdl_array *a, long i, const sdl_value *v, src_loc loc)
{
    if (!sdl_ok(p) || i < 0 || i >= a->total) return;
    if (v->kind == VAL_NONE) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "cannot store an uninitialised value in an array");
        return;
    }
    assert(a->elems && a->total > 0);
    int dim = numeric(v->kind) ? v->dim : 0;
    if (a->kind == VAL_NONE) {
        a->kind = v->kind;
        a->dim = dim;
    } else if (a->kind != v->kind || a->dim != dim) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "array element type mismatch: the array holds %ss, the value is a %s",
                  sdl_value_type_name(a->kind, a->dim), sdl_value_type_name(v->kind, v->dim));
        return;
    }
    a->elems[i] = stored_value(p, v);
}

sdl_array *sdl_array_copy(sdl_parser *p, const sdl_array *a)
{
    sdl_array *c = sdl_dup(p, a, sizeof *c);
    if (!c) return NULL;
    c->elems = sdl_alloc(p, sizeof(sdl_value) * (size_t)a->total);
    if (!c->elems) return NULL;
    for (long i = 0; i < a->total; i++) c->elems[i] = stored_value(p, &a->elems[i]);
    return c;
}

/* Is the next token k (consumed if `take`)? A directive met by this
 * look-ahead runs after the array is stored (POV-Ray: no declarations while
 * an array is being declared). */
static int next_is(sdl_parser *p, sdl_tok_kind k, int take)
{
    p->defer++;
    int is = sdl_is(sdl_peek(p), k);
    p->defer--;
    if (is && take) sdl_next(p);
    return is;
}

/* initialiser := '{' ( initialiser { [','] initialiser } | rvalue { [','] rvalue } ) '}' [','] */
static void initialiser(sdl_parser *p, sdl_array *a, int d, long base)
{
    if (!sdl_enter(p, sdl_peek(p)->tk.loc)) return;
    if (sdl_begin_block(p, "array initialiser")) {
        for (int i = 0; i < a->sizes[d] && sdl_ok(p); i++) {
            const sdl_tok *t = sdl_peek(p);
            if (t->tk.kind == TOK_RBRACE) {
                sdl_error(p, t->tk.loc, PT_ERR_SYNTAX, "array initialiser has %d value%s, dimension %d of the array has %d",
                          i, i == 1 ? "" : "s", d + 1, a->sizes[d]);
                break;
            }
            if (d + 1 < a->ndims) {
                initialiser(p, a, d + 1, base + i * stride(a, d));
                continue;
            }
            src_loc at = t->tk.loc;
            sdl_value v;
            sdl_rvalue(p, &v);
            assert(base + i < a->total);
            sdl_array_set(p, a, base + i, &v, at);
            sdl_accept(p, TOK_COMMA);
        }
        const sdl_tok *t = sdl_peek(p);
        if (sdl_ok(p) && t->tk.kind != TOK_RBRACE)
            sdl_error(p, t->tk.loc, PT_ERR_SYNTAX, "too many values in array initialiser: dimension %d of the array has %d",
                      d + 1, a->sizes[d]);
        sdl_end_block(p);
        next_is(p, TOK_COMMA, 1);
    }
    sdl_leave(p);
}

/* array_size := '[' float ']' ; the size, or -1 after an error */
static int array_size(sdl_parser *p, sdl_array *a, src_loc loc)
{
    src_loc at = sdl_peek(p)->tk.loc;
    double v = sdl_float(p);
    sdl_expect(p, TOK_RBRACKET, "']'");
    if (!sdl_ok(p)) return -1;
    long n = (long)(v + SUBSCRIPT_EPSILON);
    if (n <= 0 || v > 2147483647.0) {
        sdl_error(p, at, PT_ERR_SYNTAX, "invalid array dimension size %g", v);
        return -1;
    }
    if (a->total > p->opt.max_array_elements / n) {
        sdl_error(p, loc, PT_ERR_LIMIT, "array has more than %lld elements (the limit, --max-array)", p->opt.max_array_elements);
        return -1;
    }
    return (int)n;
}

sdl_array *sdl_parse_array(sdl_parser *p, src_loc loc)
{
    sdl_array *a = sdl_alloc(p, sizeof *a);
    if (!a) return NULL;
    a->loc = loc;
    a->total = 1;
    while (sdl_ok(p) && next_is(p, TOK_LBRACKET, 0)) {
        sdl_tok lb = sdl_next(p);
        if (a->ndims == SDL_ARRAY_MAX_DIMS) {
            sdl_error(p, lb.tk.loc, PT_ERR_SYNTAX, "arrays have at most %d dimensions", SDL_ARRAY_MAX_DIMS);
            return NULL;
        }
        int n = array_size(p, a, loc);
        if (n < 0) return NULL;
        a->sizes[a->ndims++] = n;
        a->total *= n;
    }
    if (!sdl_ok(p)) return NULL;
    if (a->ndims == 0) {
        sdl_tok t = sdl_next(p);
        sdl_unexpected(p, &t, "'[' with the array size after 'array'");
        return NULL;
    }
    a->elems = sdl_alloc(p, sizeof(sdl_value) * (size_t)a->total);
    if (!a->elems) return NULL;
    if (next_is(p, TOK_LBRACE, 0)) initialiser(p, a, 0, 0);
    return sdl_ok(p) ? a : NULL;
}

long sdl_array_subscripts(sdl_parser *p, const sdl_array *a, src_loc loc)
{
    long index = 0;
    for (int d = 0; d < a->ndims && sdl_ok(p); d++) {
        if (!sdl_expect(p, TOK_LBRACKET, "'[' (the array has more dimensions)")) return -1;
        src_loc at = sdl_peek(p)->tk.loc;
        double v = sdl_float(p);
        if (!sdl_expect(p, TOK_RBRACKET, "']'")) return -1;
        long k = (long)(v + SUBSCRIPT_EPSILON);
        if (v < -SUBSCRIPT_EPSILON || k < 0) {
            sdl_error(p, at, PT_ERR_SYNTAX, "negative array subscript %g", v);
            return -1;
        }
        if (k >= a->sizes[d]) {
            sdl_error(p, at, PT_ERR_SYNTAX, "array subscript %ld out of range (dimension %d has size %d)", k, d + 1, a->sizes[d]);
            return -1;
        }
        index += k * stride(a, d);
    }
    /* every subscript checked against its dimension: in the array */
    assert(!sdl_ok(p) || (index >= 0 && index < a->total));
    (void)loc;
    return sdl_ok(p) ? index : -1;
}

void sdl_array_resolve(sdl_parser *p, sdl_tok *t)
{
    while (sdl_ok(p) && t->val.kind == VAL_ARRAY && t->val.ptr && sdl_raw_next_is(p, TOK_LBRACKET)) {
        const sdl_array *a = t->val.ptr;
        long i = sdl_array_subscripts(p, a, t->tk.loc);
        if (i < 0) return;
        if (a->elems[i].kind == VAL_NONE) {
            sdl_error(p, t->tk.loc, PT_ERR_SYNTAX, "array element of '%.*s' used before it was initialised", t->tk.len, t->tk.text);
            return;
        }
        t->val = a->elems[i];
        t->elem = 1;
        t->elem_arr = (sdl_array *)a;
        t->elem_idx = i;
    }
}

int sdl_defined_param(sdl_parser *p)
{
    sdl_expect(p, TOK_LPAREN, "'('");
    p->hold_macros++;
    p->hold_arrays++;
    sdl_tok t = sdl_next(p);
    p->hold_arrays--;
    p->hold_macros--;
    int defined = 0;
    if (t.tk.kind == TOK_IDENT) {
        defined = t.val.kind != VAL_NONE;
        /* an element: defined when initialised (subscripts must be in range) */
        while (defined && t.val.kind == VAL_ARRAY && t.val.ptr && sdl_is(sdl_peek(p), TOK_LBRACKET)) {
            const sdl_array *a = t.val.ptr;
            long i = sdl_array_subscripts(p, a, t.tk.loc);
            if (i < 0) return 0;
            t.val = a->elems[i];
            defined = t.val.kind != VAL_NONE;
        }
    } else if (t.tk.kind != TOK_KEYWORD) {
        sdl_unexpected(p, &t, "identifier");
    }
    sdl_expect(p, TOK_RPAREN, "')'");
    return defined;
}
