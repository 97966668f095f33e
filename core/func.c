/* func.c - evaluation of compiled POV-Ray functions. */
#include "func.h"
#include <math.h>
#include <string.h>
#include "func_internal.h"

#define FUNC_MAX_CALL_DEPTH 256

typedef struct {
    const func_env *env;
    const char *why;
    int depth;
    int failed;
} eval_ctx;

static int truth(double v) { return v != 0.0; }

static pt_status eval_function(const scene_function *f, const double *args, double *out, eval_ctx *c);

static double math1(func_math m, double x)
{
    switch (m) {
    case FM_SIN: return sin(x);
    case FM_COS: return cos(x);
    case FM_TAN: return tan(x);
    case FM_ASIN: return asin(x);
    case FM_ACOS: return acos(x);
    case FM_ATAN: return atan(x);
    case FM_SINH: return sinh(x);
    case FM_COSH: return cosh(x);
    case FM_TANH: return tanh(x);
    case FM_ASINH: return asinh(x);
    case FM_ACOSH: return acosh(x);
    case FM_ATANH: return atanh(x);
    case FM_ABS: return fabs(x);
    case FM_RADIANS: return x * (M_PI / 180.0);
    case FM_DEGREES: return x * (180.0 / M_PI);
    case FM_FLOOR: return floor(x);
    case FM_INT: return trunc(x);
    case FM_CEIL: return ceil(x);
    case FM_SQRT: return sqrt(x);
    case FM_EXP: return exp(x);
    case FM_LN: return log(x);
    case FM_LOG: return log10(x);
    default: return x * x; /* FM_SQR */
    }
}

static double node_value(const scene_function *f, int i, double *slots, eval_ctx *c);

/* A kid's value: constants and arguments (about half the nodes of a
 * typical body) without a call. */
static inline double kid_value(const scene_function *f, int i, double *slots, eval_ctx *c)
{
    const func_node *n = &f->nodes[i];
    if (n->op == FN_CONST) return c->failed ? 0 : n->k;
    if (n->op == FN_ARG) return c->failed ? 0 : slots[n->slot];
    return node_value(f, i, slots, c);
}

/* One node's value; slots holds the parameters and loop variables. */
static double node_value(const scene_function *f, int i, double *slots, eval_ctx *c)
{
    const func_node *n = &f->nodes[i];
    const int *k = f->kids ? f->kids + n->kid : NULL; /* no kids: no NULL + 0 */
    if (c->failed) return 0;
#define KID(j) kid_value(f, k[j], slots, c)
    switch ((func_op)n->op) {
    case FN_CONST: return n->k;
    case FN_ARG: return slots[n->slot];
    case FN_NEG: return -KID(0);
    case FN_ADD: return KID(0) + KID(1);
    case FN_SUB: return KID(0) - KID(1);
    case FN_MUL: return KID(0) * KID(1);
    case FN_DIV: return KID(0) / KID(1);
    case FN_LT: return KID(0) < KID(1);
    case FN_LE: return KID(0) <= KID(1);
    case FN_EQ: return KID(0) == KID(1);
    case FN_NE: return KID(0) != KID(1);
    case FN_GE: return KID(0) >= KID(1);
    case FN_GT: return KID(0) > KID(1);
    case FN_AND: { double a = KID(0); double b = KID(1); return truth(a) && truth(b); }
    case FN_OR: { double a = KID(0); double b = KID(1); return truth(a) || truth(b); }
    case FN_MATH: return math1((func_math)n->sub, KID(0));
    case FN_ATAN2: { double a = KID(0); return atan2(a, KID(1)); }
    case FN_POW: { double a = KID(0); return pow(a, KID(1)); }
    case FN_MOD: { double a = KID(0); return fmod(a, KID(1)); }
    case FN_IDIV: { double a = KID(0); return trunc(a / KID(1)); }
    case FN_MIN: case FN_MAX: {
        double v = KID(0);
        for (int j = 1; j < n->nkids; j++) {
            double w = KID(j);
            if (n->op == FN_MIN ? w < v : w > v) v = w;
        }
        return v;
    }
    case FN_SELECT: {
        double a = KID(0);
        if (a < 0) return KID(1);
        if (n->nkids == 3 || a == 0) return KID(2);
        return KID(3);
    }
    case FN_SUM: case FN_PROD: {
        double from = KID(0), to = KID(1), acc = n->op == FN_SUM ? 0.0 : 1.0;
        for (double v = from; v <= to && !c->failed; v += 1.0) {
            slots[n->slot] = v;
            double b = KID(2);
            acc = n->op == FN_SUM ? acc + b : acc * b;
        }
        return acc;
    }
    case FN_CALL: {
        double a[FUNC_MAX_SLOTS], r[5];
        for (int j = 0; j < n->nkids && j < FUNC_MAX_SLOTS; j++) a[j] = KID(j);
        const scene_function *g = n->fn;
        if (g->kind == FUNC_FLOAT && g->nodes[g->root].op == FN_INTERNAL && n->sub == 0) {
            /* a body that is one built-in (functions.inc's f_rounded_box and
             * the rest): the built-in reads the call's arguments directly,
             * when the call gives it all of them */
            int in = g->nodes[g->root].slot, np = func_internal_params(in);
            if (np >= 0 && np <= n->nkids && np <= g->nparams) {
                double v;
                if (func_internal_eval(in, a, c->env, &v)) return v;
                c->failed = 1;
                c->why = func_internal_name(in);
                return 0;
            }
        }
        if (eval_function(n->fn, a, r, c) != PT_OK) return 0;
        if (n->sub == 5) return 0.297 * r[0] + 0.589 * r[1] + 0.114 * r[2]; /* gray */
        return n->sub < n->fn->nterms ? r[n->sub] : 0.0;
    }
    case FN_INTERNAL: {
        double v;
        if (func_internal_eval(n->slot, slots, c->env, &v)) return v;
        c->failed = 1;
        c->why = func_internal_name(n->slot);
        return 0;
    }
    }
#undef KID
    return 0;
}

/* Whether an op can run on the value stack (no control flow, no calls,
 * cannot fail). */
static int post_op(func_op op)
{
    switch (op) {
    case FN_CONST: case FN_ARG: case FN_NEG: case FN_ADD: case FN_SUB: case FN_MUL: case FN_DIV:
    case FN_LT: case FN_LE: case FN_EQ: case FN_NE: case FN_GE: case FN_GT: case FN_AND: case FN_OR:
    case FN_MATH: case FN_ATAN2: case FN_POW: case FN_MOD: case FN_IDIV: case FN_MIN: case FN_MAX:
        return 1;
    default:
        return 0;
    }
}

/* Post order below node i into out[*n]; the stack depth it needs in *depth.
 * 0 when a node does not qualify or out is full. */
static int post_walk(const scene_function *f, int i, int *out, int max, int *n, int *depth, int level)
{
    if (level > FUNC_POST_STACK || i < 0 || i >= f->nnodes) return 0;
    const func_node *nd = &f->nodes[i];
    if (!post_op((func_op)nd->op)) return 0;
    if ((nd->op == FN_MIN || nd->op == FN_MAX) && nd->nkids < 1) return 0;
    int need = 1;
    for (int j = 0; j < nd->nkids; j++) {
        int d;
        if (!post_walk(f, f->kids[nd->kid + j], out, max, n, &d, level + 1)) return 0;
        /* kid j is computed with j values already on the stack */
        if (j + d > need) need = j + d;
    }
    if (*n >= max) return 0;
    out[(*n)++] = i;
    *depth = need;
    return 1;
}

int func_postorder(const scene_function *f, int *out, int max)
{
    if (!f || f->kind != FUNC_FLOAT || !f->nodes) return -1;
    int n = 0, depth = 0;
    if (!post_walk(f, f->root, out, max, &n, &depth, 0) || depth > FUNC_POST_STACK) return -1;
    return n;
}

/* The body of f as its post-order list (scene_function.post): the same
 * operations on the same values as node_value, so the same result. */
static double post_value(const scene_function *f, const double *slots)
{
    double st[FUNC_POST_STACK];
    int sp = 0;
    /* a binary node: its two kids' values, the first below, give one */
#define BIN(expr)                                                                                              \
    do {                                                                                                       \
        double y = st[--sp], x = st[sp - 1];                                                                   \
        st[sp - 1] = (expr);                                                                                   \
    } while (0)
    for (int i = 0; i < f->npost; i++) {
        const func_node *n = &f->nodes[f->post[i]];
        switch ((func_op)n->op) {
        case FN_CONST: st[sp++] = n->k; break;
        case FN_ARG: st[sp++] = slots[n->slot]; break;
        case FN_NEG: st[sp - 1] = -st[sp - 1]; break;
        case FN_MATH: st[sp - 1] = math1((func_math)n->sub, st[sp - 1]); break;
        case FN_ADD: BIN(x + y); break;
        case FN_SUB: BIN(x - y); break;
        case FN_MUL: BIN(x * y); break;
        case FN_DIV: BIN(x / y); break;
        case FN_LT: BIN(x < y); break;
        case FN_LE: BIN(x <= y); break;
        case FN_EQ: BIN(x == y); break;
        case FN_NE: BIN(x != y); break;
        case FN_GE: BIN(x >= y); break;
        case FN_GT: BIN(x > y); break;
        case FN_AND: BIN(truth(x) && truth(y)); break;
        case FN_OR: BIN(truth(x) || truth(y)); break;
        case FN_ATAN2: BIN(atan2(x, y)); break;
        case FN_POW: BIN(pow(x, y)); break;
        case FN_MOD: BIN(fmod(x, y)); break;
        case FN_IDIV: BIN(trunc(x / y)); break;
        case FN_MIN: case FN_MAX: {
            int k = n->nkids;
            double v = st[sp - k];
            for (int j = 1; j < k; j++) {
                double w = st[sp - k + j];
                if (n->op == FN_MIN ? w < v : w > v) v = w;
            }
            sp -= k - 1;
            st[sp - 1] = v;
            break;
        }
        default: return 0.0; /* func_postorder admits none other */
        }
    }
#undef BIN
    return st[0];
}

static pt_status eval_function(const scene_function *f, const double *args, double *out, eval_ctx *c)
{
    for (int i = 0; i < (f->nterms > 0 ? f->nterms : 1); i++) out[i] = 0;
    if (c->failed) return PT_ERR_UNSUPPORTED;
    if (c->depth >= FUNC_MAX_CALL_DEPTH) {
        c->failed = 1;
        c->why = "calls nested too deep";
        return PT_ERR_UNSUPPORTED;
    }
    c->depth++;
    switch (f->kind) {
    case FUNC_FLOAT: {
        double slots[FUNC_MAX_SLOTS];
        int np = f->nparams < FUNC_MAX_SLOTS ? f->nparams : FUNC_MAX_SLOTS;
        /* only the slots the body uses (parameters, loop variables) are
         * cleared: a call is evaluated per isosurface sample */
        int ns = f->nslots > np ? (f->nslots < FUNC_MAX_SLOTS ? f->nslots : FUNC_MAX_SLOTS) : np;
        /* loops, not memcpy/memset: a handful of slots, per evaluation */
        for (int i = 0; i < np; i++) slots[i] = args[i];
        for (int i = np; i < ns; i++) slots[i] = 0.0;
        out[0] = f->post ? post_value(f, slots) : node_value(f, f->root, slots, c);
        break;
    }
    case FUNC_TRANSFORM: {
        vec3 p = xform_point(&f->transform, v3(args[0], args[1], args[2]));
        out[0] = p.x;
        out[1] = p.y;
        out[2] = p.z;
        break;
    }
    case FUNC_SPLINE: {
        double v[5];
        uspline_eval(f->spline, f->spline->kind, f->spline->m, args[0], v);
        for (int i = 0; i < f->nterms; i++) out[i] = v[i];
        break;
    }
    case FUNC_PIGMENT: case FUNC_PATTERN: {
        double v[5] = {0, 0, 0, 0, 0};
        if (!c->env || !c->env->pigment || !c->env->pigment(c->env->user, f, v3(args[0], args[1], args[2]), v)) {
            c->failed = 1;
            c->why = f->kind == FUNC_PIGMENT ? "pigment function" : "pattern function";
            break;
        }
        for (int i = 0; i < f->nterms; i++) out[i] = v[i];
        break;
    }
    }
    c->depth--;
    return c->failed ? PT_ERR_UNSUPPORTED : PT_OK;
}

pt_status func_eval(const scene_function *f, const double *args, double *out, const func_env *env, const char **why)
{
    eval_ctx c = {env, NULL, 0, 0};
    pt_status st = eval_function(f, args, out, &c);
    if (why) *why = c.why;
    return st;
}

double func_eval_float(const scene_function *f, const double *args, const func_env *env)
{
    double out[5];
    if (func_eval(f, args, out, env, NULL) != PT_OK) return NAN;
    return out[0];
}
