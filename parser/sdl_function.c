/* sdl_function.c - function { } bodies -> core/func.h trees; splines; calls. */
#include "sdl_function.h"
#include "grow.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "func_internal.h"
#include "sdl_directive.h"
#include "sdl_expr.h"
#include "sdl_material.h"

/* ------------------------------------------------------------ building */

/* A function being compiled: growable node/kid arrays and the names that
 * are slots (parameters, then sum/prod loop variables in scope). */
typedef struct {
    sdl_parser *p;
    func_node *nodes;
    int nnodes, cap_nodes;
    int *kids;
    int nkids, cap_kids;
    const char *names[FUNC_MAX_SLOTS];
    int name_slot[FUNC_MAX_SLOTS];
    int nnames;          /* visible names (parameters + loop variables in scope) */
    int nparams, nslots;
    int reg[3];          /* slot of the x/u, y/v, z parameter, -1 = none (reads 0) */
} fn_build;

static int new_node(fn_build *b, func_op op)
{
    if (!grow_array_int((void **)&b->nodes, &b->cap_nodes, b->nnodes + 1, sizeof *b->nodes)) {
        sdl_error(b->p, b->p->last_loc, PT_ERR_NOMEM, "out of memory");
        return -1;
    }
    func_node *n = &b->nodes[b->nnodes];
    memset(n, 0, sizeof *n);
    n->op = (unsigned char)op;
    return b->nnodes++;
}

static int const_node(fn_build *b, double k)
{
    int i = new_node(b, FN_CONST);
    if (i >= 0) b->nodes[i].k = k;
    return i;
}

/* A node with the given kids (copied to the kid list). */
static int op_node(fn_build *b, func_op op, const int *kids, int n)
{
    for (int j = 0; j < n; j++)
        if (kids[j] < 0) return -1;
    if (!grow_array_int((void **)&b->kids, &b->cap_kids, b->nkids + n, sizeof *b->kids)) {
        sdl_error(b->p, b->p->last_loc, PT_ERR_NOMEM, "out of memory");
        return -1;
    }
    int i = new_node(b, op);
    if (i < 0) return -1;
    b->nodes[i].kid = b->nkids;
    b->nodes[i].nkids = (unsigned short)n;
    memcpy(b->kids + b->nkids, kids, sizeof(int) * (size_t)n);
    b->nkids += n;
    return i;
}

static int binary(fn_build *b, func_op op, int l, int r)
{
    int k[2] = {l, r};
    return op_node(b, op, k, 2);
}

static int slot_of(const fn_build *b, const char *s, int len)
{
    for (int i = b->nnames - 1; i >= 0; i--)
        if ((int)strlen(b->names[i]) == len && memcmp(b->names[i], s, (size_t)len) == 0) return b->name_slot[i];
    return -1;
}

/* ------------------------------------------------------------ expressions */

static int f_or(fn_build *b);

/* member := '.' ( x | y | z | u | v | t | red | green | blue | filter | transmit | gray ) */
static int member_index(sdl_parser *p)
{
    sdl_tok t = sdl_next(p);
    int i = sdl_component_index(&t);
    if (i < 0) sdl_unexpected(p, &t, "colour or vector member (x, y, z, t, red, green, blue, filter, transmit, gray)");
    return i;
}

/* args := '(' f_or { ',' f_or } ')' ; returns the count (kids in k) */
static int call_args(fn_build *b, int *k, int max, const char *what)
{
    sdl_parser *p = b->p;
    int n = 0;
    if (!sdl_expect(p, TOK_LPAREN, "'('")) return -1;
    do {
        if (n == max) {
            sdl_error(p, sdl_peek(p)->tk.loc, PT_ERR_SYNTAX, "too many arguments for %s", what);
            return -1;
        }
        k[n++] = f_or(b);
        if (!sdl_ok(p)) return -1;
    } while (sdl_accept(p, TOK_COMMA));
    if (!sdl_expect(p, TOK_RPAREN, "',' or ')'")) return -1;
    return n;
}

static int math_of(sdl_kw k)
{
    switch (k) {
    case KW_SIN: return FM_SIN; case KW_COS: return FM_COS; case KW_TAN: return FM_TAN;
    case KW_ASIN: return FM_ASIN; case KW_ACOS: return FM_ACOS; case KW_ATAN: return FM_ATAN;
    case KW_SINH: return FM_SINH; case KW_COSH: return FM_COSH; case KW_TANH: return FM_TANH;
    case KW_ASINH: return FM_ASINH; case KW_ACOSH: return FM_ACOSH; case KW_ATANH: return FM_ATANH;
    case KW_ABS: return FM_ABS; case KW_RADIANS: return FM_RADIANS; case KW_DEGREES: return FM_DEGREES;
    case KW_FLOOR: return FM_FLOOR; case KW_INT: return FM_INT; case KW_CEIL: return FM_CEIL;
    case KW_SQRT: return FM_SQRT; case KW_EXP: return FM_EXP; case KW_LN: return FM_LN;
    case KW_LOG: return FM_LOG; /* no sqr: POV-Ray 3.7's function syntax lacks it */
    default: return -1;
    }
}

/* sum '(' name ',' from ',' to ',' expression ')' (and prod): the loop
 * variable is a new slot visible in the body only. */
static int seq_op(fn_build *b, func_op op, const sdl_tok *kt)
{
    sdl_parser *p = b->p;
    if (!sdl_expect(p, TOK_LPAREN, "'('")) return -1;
    p->hold_macros++;
    sdl_tok v = sdl_next(p);
    p->hold_macros--;
    if (v.tk.kind != TOK_IDENT) {
        sdl_unexpected(p, &v, "loop variable name");
        return -1;
    }
    if (b->nslots >= FUNC_MAX_SLOTS || b->nnames >= FUNC_MAX_SLOTS) {
        sdl_error(p, v.tk.loc, PT_ERR_LIMIT, "too many local variables in function");
        return -1;
    }
    int k[3];
    sdl_expect(p, TOK_COMMA, "','");
    k[0] = f_or(b);
    sdl_expect(p, TOK_COMMA, "','");
    k[1] = f_or(b);
    sdl_expect(p, TOK_COMMA, "','");
    int slot = b->nslots++;
    b->names[b->nnames] = sdl_strndup(p, v.tk.text, (size_t)v.tk.len);
    b->name_slot[b->nnames++] = slot;
    k[2] = f_or(b);
    b->nnames--;
    if (!sdl_expect(p, TOK_RPAREN, "')'")) return -1;
    int i = op_node(b, op, k, 3);
    if (i >= 0) b->nodes[i].slot = slot;
    (void)kt;
    return i;
}

/* builtin := math1 '(' e ')' | (atan2|pow|mod|div) '(' e ',' e ')' |
 *            (min|max) '(' e ',' e { ',' e } ')' | select '(' e ',' e ',' e [',' e] ')' |
 *            (sum|prod) '(' ... ')' */
static int builtin(fn_build *b, const sdl_tok *kt)
{
    sdl_parser *p = b->p;
    sdl_kw k = kt->tk.kw;
    const char *name = sdl_kw_text(k);
    int kids[FUNC_MAX_PARAMS];
    if (k == KW_SUM || k == KW_PROD) return seq_op(b, k == KW_SUM ? FN_SUM : FN_PROD, kt);
    int n = call_args(b, kids, FUNC_MAX_PARAMS, name);
    if (n < 0) return -1;
    int m = math_of(k), want_lo = 1, want_hi = 1;
    func_op op = FN_MATH;
    switch (k) {
    case KW_ATAN2: op = FN_ATAN2; want_lo = want_hi = 2; break;
    case KW_POW: op = FN_POW; want_lo = want_hi = 2; break;
    case KW_MOD: op = FN_MOD; want_lo = want_hi = 2; break;
    case KW_DIV: op = FN_IDIV; want_lo = want_hi = 2; break;
    case KW_MIN: op = FN_MIN; want_lo = 2; want_hi = FUNC_MAX_PARAMS; break;
    case KW_MAX: op = FN_MAX; want_lo = 2; want_hi = FUNC_MAX_PARAMS; break;
    case KW_SELECT: op = FN_SELECT; want_lo = 3; want_hi = 4; break;
    default: break;
    }
    if (n < want_lo || n > want_hi) {
        if (want_lo == want_hi)
            sdl_error(p, kt->tk.loc, PT_ERR_SYNTAX, "%s in a function takes %d argument%s, %d given", name, want_lo, want_lo == 1 ? "" : "s", n);
        else
            sdl_error(p, kt->tk.loc, PT_ERR_SYNTAX, "%s in a function takes %d to %d arguments, %d given", name, want_lo,
                      want_hi > 4 ? 56 : want_hi, n);
        return -1;
    }
    int i = op_node(b, op, kids, n);
    if (i >= 0 && op == FN_MATH) b->nodes[i].sub = (unsigned char)m;
    return i;
}

/* user_call := function_identifier args [ member ] (a member is required for
 * vector functions) */
static int user_call(fn_build *b, const sdl_tok *id)
{
    sdl_parser *p = b->p;
    const scene_function *f = id->val.ptr;
    int kids[FUNC_MAX_SLOTS];
    int n = call_args(b, kids, FUNC_MAX_SLOTS, "a function call");
    if (n < 0) return -1;
    if (n != f->nparams) {
        sdl_error(p, id->tk.loc, PT_ERR_SYNTAX, "function '%.*s' takes %d argument%s, %d given", id->tk.len, id->tk.text, f->nparams,
                  f->nparams == 1 ? "" : "s", n);
        return -1;
    }
    int sub = 0;
    if (f->nterms > 1) {
        if (!sdl_accept(p, TOK_DOT)) {
            sdl_error(p, sdl_peek(p)->tk.loc, PT_ERR_SYNTAX, "vector function '%.*s' needs a member here (.x, .y, .red ...)", id->tk.len,
                      id->tk.text);
            return -1;
        }
        sub = member_index(p);
        if (sub < 0) return -1;
    }
    int i = op_node(b, FN_CALL, kids, n);
    if (i < 0) return -1;
    b->nodes[i].fn = f;
    b->nodes[i].sub = (unsigned char)sub;
    return i;
}

/* The x/y/z registers: the parameter named x (or u), y (or v), z. */
static int register_node(fn_build *b, int r)
{
    if (b->reg[r] < 0) return const_node(b, 0.0);
    int i = new_node(b, FN_ARG);
    if (i >= 0) b->nodes[i].slot = b->reg[r];
    return i;
}

/* identifier_operand := parameter | loop variable | float constant |
 *   vector/colour constant member | function call */
static int identifier_operand(fn_build *b, const sdl_tok *t)
{
    sdl_parser *p = b->p;
    int slot = slot_of(b, t->tk.text, t->tk.len);
    if (slot >= 0) {
        int i = new_node(b, FN_ARG);
        if (i >= 0) b->nodes[i].slot = slot;
        return i;
    }
    switch (t->val.kind) {
    case VAL_FLOAT: return const_node(b, t->val.v[0]);
    case VAL_VECTOR: case VAL_COLOUR: {
        if (!sdl_expect(p, TOK_DOT, "'.' and a member after a vector constant in a function")) return -1;
        int m = member_index(p);
        if (m < 0) return -1;
        if (m == 5) return const_node(b, 0.297 * t->val.v[0] + 0.589 * t->val.v[1] + 0.114 * t->val.v[2]);
        return const_node(b, m < t->val.dim ? t->val.v[m] : 0.0);
    }
    case VAL_FUNCTION: return user_call(b, t);
    case VAL_NONE:
        sdl_error(p, t->tk.loc, PT_ERR_SYNTAX, "'%.*s' is neither a parameter of the function nor a declared float", t->tk.len, t->tk.text);
        return -1;
    default:
        sdl_error(p, t->tk.loc, PT_ERR_SYNTAX, "'%.*s' (a %s) cannot be used in a function", t->tk.len, t->tk.text,
                  t->val.kind == VAL_SPLINE ? "spline; wrap it as function { spline { ... } }" : "non-numeric identifier");
        return -1;
    }
}

/* keyword_operand := x | y | z | u | v | pi | clock | true ... | builtin */
static int keyword_operand(fn_build *b, const sdl_tok *t)
{
    sdl_parser *p = b->p;
    switch (t->tk.kw) {
    case KW_X: case KW_U: return register_node(b, 0);
    case KW_Y: case KW_V: return register_node(b, 1);
    case KW_Z: return register_node(b, 2);
    case KW_PI: return const_node(b, M_PI);
    case KW_CLOCK: sdl_note_frame_value(p); return const_node(b, p->opt.clock);
    case KW_INTERNAL:
        sdl_error(p, t->tk.loc, PT_ERR_SYNTAX, "internal(N) must be the whole function body");
        return -1;
    default:
        break;
    }
    if (math_of(t->tk.kw) >= 0 || t->tk.kw == KW_ATAN2 || t->tk.kw == KW_POW || t->tk.kw == KW_MOD || t->tk.kw == KW_DIV ||
        t->tk.kw == KW_MIN || t->tk.kw == KW_MAX || t->tk.kw == KW_SELECT || t->tk.kw == KW_SUM || t->tk.kw == KW_PROD)
        return builtin(b, t);
    sdl_error(p, t->tk.loc, PT_ERR_SYNTAX, "'%s' cannot be used in a function", sdl_kw_text(t->tk.kw));
    return -1;
}

/* f_unary := ( '-' | '+' ) f_unary | number | '(' f_or ')' | identifier_operand | keyword_operand */
static int f_unary(fn_build *b)
{
    sdl_parser *p = b->p;
    if (!sdl_enter(p, p->last_loc)) return -1;
    sdl_tok t = sdl_next(p);
    int r = -1;
    switch (t.tk.kind) {
    case TOK_MINUS: {
        int k = f_unary(b);
        r = op_node(b, FN_NEG, &k, 1);
        break;
    }
    case TOK_PLUS: r = f_unary(b); break;
    case TOK_NUMBER: r = const_node(b, t.tk.num); break;
    case TOK_LPAREN:
        r = f_or(b);
        sdl_expect(p, TOK_RPAREN, "')'");
        break;
    case TOK_IDENT: r = identifier_operand(b, &t); break;
    case TOK_KEYWORD: r = keyword_operand(b, &t); break;
    case TOK_BANG:
        sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "'!' is not allowed in a function (POV-Ray 3.7 has no logical not there)");
        break;
    default:
        sdl_unexpected(p, &t, "operand");
        break;
    }
    sdl_leave(p);
    return r;
}

/* f_term := f_unary { ( '*' | '/' ) f_unary } */
static int f_term(fn_build *b)
{
    int l = f_unary(b);
    for (;;) {
        sdl_tok_kind k = sdl_peek(b->p)->tk.kind;
        if (!sdl_ok(b->p) || (k != TOK_STAR && k != TOK_SLASH)) return l;
        sdl_next(b->p);
        l = binary(b, k == TOK_STAR ? FN_MUL : FN_DIV, l, f_unary(b));
    }
}

/* f_sum := f_term { ( '+' | '-' ) f_term } */
static int f_sum(fn_build *b)
{
    int l = f_term(b);
    for (;;) {
        sdl_tok_kind k = sdl_peek(b->p)->tk.kind;
        if (!sdl_ok(b->p) || (k != TOK_PLUS && k != TOK_MINUS)) return l;
        sdl_next(b->p);
        l = binary(b, k == TOK_PLUS ? FN_ADD : FN_SUB, l, f_term(b));
    }
}

static int compare_op(sdl_tok_kind k)
{
    switch (k) {
    case TOK_LT: return FN_LT;
    case TOK_LE: return FN_LE;
    case TOK_EQ: return FN_EQ;
    case TOK_NE: return FN_NE;
    case TOK_GE: return FN_GE;
    case TOK_GT: return FN_GT;
    default: return -1;
    }
}

/* f_compare := f_sum { ( '<' | '<=' | '=' | '!=' | '>=' | '>' ) f_sum } */
static int f_compare(fn_build *b)
{
    int l = f_sum(b);
    for (;;) {
        int op = compare_op(sdl_peek(b->p)->tk.kind);
        if (!sdl_ok(b->p) || op < 0) return l;
        sdl_next(b->p);
        l = binary(b, (func_op)op, l, f_sum(b));
    }
}

/* f_and := f_compare { '&' f_compare } */
static int f_and(fn_build *b)
{
    int l = f_compare(b);
    while (sdl_ok(b->p) && sdl_accept(b->p, TOK_AMP)) l = binary(b, FN_AND, l, f_compare(b));
    return l;
}

/* f_or := f_and { '|' f_and } */
static int f_or(fn_build *b)
{
    int l = f_and(b);
    while (sdl_ok(b->p) && sdl_accept(b->p, TOK_BAR)) l = binary(b, FN_OR, l, f_and(b));
    return l;
}

/* ------------------------------------------------------------ declarations */

/* params := '(' identifier { [','] identifier } ')' ; x y z u v allowed */
static void function_params(fn_build *b)
{
    sdl_parser *p = b->p;
    p->hold_macros++;
    p->hold_arrays++;
    while (sdl_ok(p)) {
        sdl_tok t = sdl_next(p);
        int reg_kw = t.tk.kind == TOK_KEYWORD && (t.tk.kw == KW_X || t.tk.kw == KW_Y || t.tk.kw == KW_Z || t.tk.kw == KW_U || t.tk.kw == KW_V);
        if (t.tk.kind != TOK_IDENT && !reg_kw) {
            sdl_unexpected(p, &t, "parameter name");
            break;
        }
        if (b->nparams == FUNC_MAX_PARAMS) {
            sdl_error(p, t.tk.loc, PT_ERR_LIMIT, "a function has at most %d parameters", FUNC_MAX_PARAMS);
            break;
        }
        b->names[b->nnames] = sdl_strndup(p, t.tk.text, (size_t)t.tk.len);
        b->name_slot[b->nnames++] = b->nparams++;
        sdl_accept(p, TOK_COMMA);
        if (sdl_accept(p, TOK_RPAREN)) break;
    }
    p->hold_arrays--;
    p->hold_macros--;
    if (sdl_ok(p) && b->nparams == 0) sdl_error(p, p->last_loc, PT_ERR_SYNTAX, "a function parameter list needs at least one parameter");
}

/* x/u, y/v, z registers: the last parameter with that name (POV-Ray). */
static void find_registers(fn_build *b)
{
    static const char *const names[3][2] = {{"x", "u"}, {"y", "v"}, {"z", "z"}};
    for (int r = 0; r < 3; r++) {
        b->reg[r] = -1;
        for (int i = 0; i < b->nparams; i++)
            if (strcmp(b->names[i], names[r][0]) == 0 || strcmp(b->names[i], names[r][1]) == 0) b->reg[r] = i;
    }
}

static const char **copy_params(sdl_parser *p, fn_build *b)
{
    const char **pp = sdl_alloc(p, sizeof(char *) * (size_t)(b->nparams ? b->nparams : 1));
    if (pp) memcpy(pp, b->names, sizeof(char *) * (size_t)b->nparams);
    return pp;
}

/* internal_body := 'internal' '(' N ')' */
static void internal_body(fn_build *b, scene_function *f)
{
    sdl_parser *p = b->p;
    sdl_expect(p, TOK_LPAREN, "'('");
    src_loc at = sdl_peek(p)->tk.loc;
    double v = sdl_float(p);
    sdl_expect(p, TOK_RPAREN, "')'");
    if (!sdl_ok(p)) return;
    int n = sdl_to_int(v), count = func_internal_params(n);
    if (v != floor(v) || count < 0 || n == 77) {
        sdl_error(p, at, PT_ERR_SYNTAX, "unknown internal function %g (POV-Ray 3.7 has internal(0) to internal(78), 77 being reserved)", v);
        return;
    }
    if (b->nparams) sdl_warning(p, at, "a parameter list is ignored for internal(%d): it takes %d parameters", n, count);
    f->nparams = count;
    f->nslots = count;
    static const char *const xyz[3] = {"x", "y", "z"};
    const char **pp = sdl_alloc(p, sizeof(char *) * (size_t)count);
    if (!pp) return;
    for (int i = 0; i < count; i++) {
        char buf[16];
        snprintf(buf, sizeof buf, "P%d", i - 3);
        pp[i] = i < 3 ? xyz[i] : sdl_strndup(p, buf, strlen(buf));
    }
    f->params = pp;
    int i = new_node(b, FN_INTERNAL);
    if (i >= 0) b->nodes[i].slot = n;
    f->root = i;
}

/* vector_body := transform {..} | spline {..} | pigment {..} | pattern {..} */
static void special_body(fn_build *b, scene_function *f, const sdl_tok *k)
{
    sdl_parser *p = b->p;
    if (b->nparams) {
        sdl_error(p, k->tk.loc, PT_ERR_SYNTAX, "%s functions take no parameter list", sdl_kw_text(k->tk.kw));
        return;
    }
    static const char *const xyz[3] = {"x", "y", "z"};
    f->params = xyz;
    f->nparams = f->nslots = 3;
    switch (k->tk.kw) {
    case KW_TRANSFORM:
        f->kind = FUNC_TRANSFORM;
        f->nterms = 3;
        f->transform = sdl_parse_transform(p);
        break;
    case KW_SPLINE: {
        static const char *const t[1] = {"t"};
        f->kind = FUNC_SPLINE;
        f->params = t;
        f->nparams = f->nslots = 1;
        f->spline = sdl_parse_spline(p, k->tk.loc);
        f->nterms = f->spline ? f->spline->terms : 2;
        break;
    }
    default: /* pigment, pattern */
        f->kind = k->tk.kw == KW_PIGMENT ? FUNC_PIGMENT : FUNC_PATTERN;
        f->nterms = f->kind == FUNC_PIGMENT ? 5 : 1;
        f->pigment = sdl_parse_pigment_new(p);
        break;
    }
}

/* 1 when f's body calls a function whose body is internal(59), f_ridged_mf
 * (scene.ridged_mf_callers) */
static int calls_ridged_mf(const scene_function *f)
{
    for (int i = 0; i < f->nnodes; i++) {
        const scene_function *g = f->nodes[i].op == FN_CALL ? f->nodes[i].fn : NULL;
        if (g && g->kind == FUNC_FLOAT && g->nodes && g->root >= 0 && g->root < g->nnodes &&
            g->nodes[g->root].op == FN_INTERNAL && g->nodes[g->root].slot == FUNC_INTERNAL_RIDGED_MF)
            return 1;
    }
    return 0;
}

scene_function *sdl_parse_function(sdl_parser *p, src_loc loc, const char *name)
{
    fn_build b;
    memset(&b, 0, sizeof b);
    b.p = p;
    scene_function *f = sdl_alloc(p, sizeof *f);
    if (!f) return NULL;
    f->kind = FUNC_FLOAT;
    f->name = name;
    f->loc = loc;
    f->nterms = 1;
    if (sdl_accept(p, TOK_LPAREN)) function_params(&b);
    if (sdl_begin_block(p, "function")) {
        const sdl_tok *t = sdl_peek(p);
        sdl_kw k = t->tk.kind == TOK_KEYWORD ? t->tk.kw : KW_NONE;
        if (k == KW_INTERNAL) {
            sdl_next(p);
            internal_body(&b, f);
        } else if (k == KW_TRANSFORM || k == KW_SPLINE || k == KW_PIGMENT || k == KW_PATTERN) {
            sdl_tok kt = sdl_next(p);
            special_body(&b, f, &kt);
        } else if (t->tk.kind == TOK_STRING) {
            sdl_error(p, t->tk.loc, PT_ERR_UNSUPPORTED, "string functions (function { \"...\" }) are not supported");
        } else {
            if (b.nparams == 0) {
                static const char *const xyz[3] = {"x", "y", "z"};
                for (int i = 0; i < 3; i++) {
                    b.names[b.nnames] = xyz[i];
                    b.name_slot[b.nnames++] = b.nparams++;
                }
            }
            find_registers(&b);
            b.nslots = b.nparams;
            f->root = f_or(&b);
            f->nparams = b.nparams;
            f->params = copy_params(p, &b);
        }
        sdl_end_block(p);
    }
    if (f->kind == FUNC_FLOAT && f->nslots < b.nslots) f->nslots = b.nslots;
    if (sdl_ok(p) && b.nnodes) {
        f->nnodes = b.nnodes;
        f->nodes = arena_memdup(p->s->mem, b.nodes, sizeof *b.nodes * (size_t)b.nnodes);
        f->kids = b.nkids ? arena_memdup(p->s->mem, b.kids, sizeof *b.kids * (size_t)b.nkids) : NULL;
        if (f->kind == FUNC_FLOAT) {
            /* the body runs as a flat program (func.h) */
            int max = func_code_bound(f), stack = 0;
            func_insn *code = malloc(sizeof *code * (size_t)max);
            int nc = code ? func_compile(f, code, max, &stack) : -1;
            if (nc > 0) f->code = arena_memdup(p->s->mem, code, sizeof *code * (size_t)nc);
            if (nc == -2) sdl_error(p, loc, PT_ERR_LIMIT, "function body nested more than %d deep", FUNC_MAX_NESTING);
            else if (code && nc <= 0) sdl_error(p, loc, PT_ERR_INTERNAL, "function body could not be compiled");
            else if (!f->code) sdl_error(p, loc, PT_ERR_NOMEM, "out of memory compiling a function");
            free(code);
            f->ncode = nc;
            f->stack = stack;
        }
        if (calls_ridged_mf(f)) p->s->ridged_mf_callers++;
    }
    free(b.nodes);
    free(b.kids);
    return sdl_ok(p) ? f : NULL;
}

/* ------------------------------------------------------------ splines */

static int spline_kind_of(const sdl_tok *t, uspline_kind *k)
{
    if (t->tk.kind != TOK_KEYWORD) return 0;
    switch (t->tk.kw) {
    case KW_LINEAR_SPLINE: *k = USPLINE_LINEAR; return 1;
    case KW_QUADRATIC_SPLINE: *k = USPLINE_QUADRATIC; return 1;
    case KW_CUBIC_SPLINE: *k = USPLINE_CUBIC; return 1;
    case KW_NATURAL_SPLINE: *k = USPLINE_NATURAL; return 1;
    default: return 0;
    }
}

static int ensure_points(sdl_parser *p, user_spline *s, int *cap)
{
    if (s->n < *cap) return 1;
    int nc = *cap ? *cap * 2 : 16;
    uspline_point *np = sdl_alloc(p, sizeof *np * (size_t)nc);
    if (!np) return 0;
    if (s->n) memcpy(np, s->pts, sizeof *np * (size_t)s->n);
    s->pts = np;
    *cap = nc;
    return 1;
}

user_spline *sdl_parse_spline(sdl_parser *p, src_loc loc)
{
    if (!sdl_begin_block(p, "spline")) return NULL;
    user_spline *s = sdl_alloc(p, sizeof *s);
    if (!s) return NULL;
    s->kind = USPLINE_LINEAR;
    s->terms = 2;
    s->loc = loc;
    int cap = 0;
    const sdl_tok *t = sdl_peek(p);
    if (t->tk.kind == TOK_IDENT && t->val.kind == VAL_SPLINE && t->val.ptr) {
        sdl_tok id = sdl_next(p);
        const user_spline *src = id.val.ptr;
        *s = *src;
        s->loc = loc;
        s->m = NULL;
        cap = s->n;
        s->pts = sdl_alloc(p, sizeof *s->pts * (size_t)(cap ? cap : 1));
        if (!s->pts) return NULL;
        memcpy(s->pts, src->pts, sizeof *s->pts * (size_t)src->n);
    }
    uspline_kind k;
    while (sdl_ok(p) && spline_kind_of(sdl_peek(p), &k)) {
        sdl_next(p);
        s->kind = k;
    }
    if (sdl_is_kw(sdl_peek(p), KW_BEZIER_SPLINE)) {
        sdl_error(p, sdl_peek(p)->tk.loc, PT_ERR_SYNTAX,
                  "bezier_spline is not a spline{} type in POV-Ray 3.7 (linear_spline, quadratic_spline, cubic_spline or natural_spline)");
        return NULL;
    }
    while (sdl_ok(p) && sdl_starts_float(sdl_peek(p))) {
        double tv = sdl_float(p);
        sdl_accept(p, TOK_COMMA);
        src_loc at = sdl_peek(p)->tk.loc;
        sdl_value v;
        sdl_sum(p, &v);
        if (!sdl_ok(p)) return NULL;
        double vec[5] = {0, 0, 0, 0, 0};
        if (v.dim <= 1) {
            vec[0] = vec[1] = v.v[0];
        } else {
            for (int i = 0; i < v.dim && i < 5; i++) vec[i] = v.v[i];
            if (v.dim > s->terms) s->terms = v.dim;
        }
        (void)at;
        sdl_accept(p, TOK_COMMA);
        if (!ensure_points(p, s, &cap)) return NULL;
        uspline_insert(s, tv, vec);
    }
    sdl_end_block(p);
    if (!sdl_ok(p)) return NULL;
    if (s->n < 1) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "spline must have at least one entry");
        return NULL;
    }
    if (s->kind == USPLINE_NATURAL) {
        double *m = sdl_alloc(p, sizeof(double) * 5 * (size_t)s->n);
        if (m) uspline_natural_coeffs(s, m);
        s->m = m;
    }
    return s;
}

/* ------------------------------------------------------------ calls */

void sdl_call_function(sdl_parser *p, const sdl_tok *id, double out[5])
{
    const scene_function *f = id->val.ptr;
    double args[FUNC_MAX_SLOTS];
    memset(out, 0, sizeof(double) * 5);
    int n = 0;
    if (!sdl_expect(p, TOK_LPAREN, "'(' and the arguments of the function")) return;
    for (;;) {
        if (n == FUNC_MAX_SLOTS) {
            sdl_error(p, id->tk.loc, PT_ERR_SYNTAX, "too many arguments");
            return;
        }
        args[n++] = sdl_float(p);
        if (!sdl_ok(p) || !sdl_accept(p, TOK_COMMA)) break;
    }
    sdl_expect(p, TOK_RPAREN, "',' or ')'");
    if (!sdl_ok(p)) return;
    if (n != f->nparams) {
        sdl_error(p, id->tk.loc, PT_ERR_SYNTAX, "function '%.*s' takes %d argument%s, %d given", id->tk.len, id->tk.text, f->nparams,
                  f->nparams == 1 ? "" : "s", n);
        return;
    }
    const char *why = NULL;
    if (func_eval(f, args, out, p->opt.func_env, &why) != PT_OK)
        sdl_error(p, id->tk.loc, PT_ERR_UNSUPPORTED, "calling function '%.*s' at parse time needs %s, which the parser cannot evaluate",
                  id->tk.len, id->tk.text, why ? why : "an evaluator");
}

void sdl_call_spline(sdl_parser *p, const sdl_tok *id, double out[5])
{
    const user_spline *s = id->val.ptr;
    memset(out, 0, sizeof(double) * 5);
    if (!sdl_expect(p, TOK_LPAREN, "'(' after the spline")) return;
    double t = sdl_float(p);
    uspline_kind k = s->kind;
    if (sdl_accept(p, TOK_COMMA)) {
        sdl_tok kt = sdl_next(p);
        if (!spline_kind_of(&kt, &k)) {
            sdl_unexpected(p, &kt, "linear_spline, quadratic_spline, cubic_spline or natural_spline");
            return;
        }
    }
    if (!sdl_expect(p, TOK_RPAREN, "')'")) return;
    uspline_eval(s, k, k == s->kind ? s->m : NULL, t, out);
}
