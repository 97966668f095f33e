/* func.c - evaluation of compiled POV-Ray functions. */
#include "func.h"
#include <limits.h>
#include <math.h>
#include <stdlib.h>
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

/* ------------------------------------------------------------ compiler */

/* A compiled body is three-address code on a register file: registers
 * 0..nslots-1 are the function's parameters and loop variables, the rest
 * temporaries, allocated as a stack (a node at depth d leaves its value in
 * temporary d; its kid j works from temporary d + j). A constant operand
 * sits in the instruction (the _K and K_ forms), a parameter is read from
 * its register: the leaves of the tree (about half its nodes) cost no
 * instruction. */
/* The maths functions, in func_math's order, as f(x). */
#define FI_MATHS(X) \
    X(SIN, sin(x)) X(COS, cos(x)) X(TAN, tan(x)) X(ASIN, asin(x)) X(ACOS, acos(x)) X(ATAN, atan(x)) \
    X(SINH, sinh(x)) X(COSH, cosh(x)) X(TANH, tanh(x)) X(ASINH, asinh(x)) X(ACOSH, acosh(x)) X(ATANH, atanh(x)) \
    X(ABS, fabs(x)) X(RADIANS, x * (M_PI / 180.0)) X(DEGREES, x * (180.0 / M_PI)) X(FLOOR, floor(x)) \
    X(INT, trunc(x)) X(CEIL, ceil(x)) X(SQRT, sqrt(x)) X(EXP, exp(x)) X(LN, log(x)) X(LOG, log10(x)) X(SQR, x * x)
/* Ops of one register operand x (register a) and the constant k. */
#define FI_UNARY(X) \
    X(NEG, -x) FI_MATHS(X) \
    X(ADD_K, x + k) X(SUB_K, x - k) X(MUL_K, x * k) X(DIV_K, x / k) \
    X(K_ADD, k + x) X(K_SUB, k - x) X(K_MUL, k * x) X(K_DIV, k / x) X(POW_K, pow(x, k))
/* Ops of two register operands x (register a) and y (register b). */
#define FI_BINARY(X) \
    X(ADD, x + y) X(SUB, x - y) X(MUL, x * y) X(DIV, x / y) \
    X(LT, x < y) X(LE, x <= y) X(EQ, x == y) X(NE, x != y) X(GE, x >= y) X(GT, x > y) \
    X(AND, truth(x) && truth(y)) X(OR, truth(x) || truth(y)) \
    X(ATAN2, atan2(x, y)) X(POW, pow(x, y)) X(MOD, fmod(x, y)) X(IDIV, trunc(x / y))
/* Each unary op has an _A form whose x is the previous instruction's
 * result, kept in a local (func_compile's last pass picks them); each
 * binary op an _A form (x is it) and a _B form (y is it). */
#define FI_ENUM_U(N, E) FI_##N, FI_##N##_A,
#define FI_ENUM_B(N, E) FI_##N, FI_##N##_A, FI_##N##_B,
enum {
    FI_MOV,      /* dst = a */
    FI_LOADK,    /* dst = k */
    FI_UNARY(FI_ENUM_U)                          /* dst = op a (and k) */
    FI_BINARY(FI_ENUM_B)                         /* dst = a op b */
    FI_MUL_ADD, FI_MUL_SUB, /* an FI_MUL and the FI_ADD_B or FI_SUB_B after
                    it (which reads its result) in one dispatch; the
                    second stays as it was, skipped */
    FI_MIN, FI_MAX, /* dst = min/max of registers a .. a + n - 1, in order */
    FI_CALL,     /* dst = fn's result term sub (5: gray) of the n
                    registers from a */
    FI_CALL_INT, /* dst = internal(b) of the n registers from a (a call of
                    a function whose body is one built-in) */
    FI_INTERNAL, /* dst = internal(b) of the function's slots, from
                    register a (0, or an inlined callee's first) */
    /* the ops above write register dst; those below are control */
    FI_JNLT,     /* unless a < 0 jump to dst (select's first test) */
    FI_SEL4,     /* a < 0: next; a == 0: jump to dst; else jump to b */
    FI_JMP,      /* jump to dst */
    FI_LOOP,     /* registers a, a+1 hold from, to; a+2 = k (the sum's or
                    product's start), a+3 = from; unless from <= to jump
                    to b (the FI_END); else slot dst = from */
    FI_NEXT,     /* registers as FI_LOOP, the body's value in a+4;
                    a+2 op= it, a+3 += 1; while a+3 <= to:
                    slot dst = a+3, jump to b (the body); sub: 1 sum */
    FI_END,      /* a = a+2 (the loop's value into its register) */
    FI_RET       /* the end: the value is in the first temporary */
};

#define FI_MATH_OP(N, E) [FM_##N] = FI_##N,
static const unsigned char math_op[] = {FI_MATHS(FI_MATH_OP)};

/* An operand: register r, or the constant k when r < 0. */
typedef struct {
    int r;
    double k;
} operand;

typedef struct {
    const scene_function *f; /* the function whose nodes are compiled */
    int base;                /* the register of its slot 0 */
    func_insn *out;
    int n, max, bad, deep, t0, top;
} compiler;

static int emit(compiler *cp, int op, int dst, int a, int b)
{
    if (cp->n >= cp->max) {
        cp->bad = 1;
        return 0;
    }
    func_insn *in = &cp->out[cp->n];
    memset(in, 0, sizeof *in);
    in->op = (unsigned char)op;
    in->dst = dst;
    in->a = a;
    in->b = b;
    return cp->n++;
}

static int node_ok(const scene_function *f, int i) { return i >= 0 && i < f->nnodes; }

/* Register `reg` made to hold operand v. */
static void place(compiler *cp, operand v, int reg)
{
    if (v.r == reg) return;
    if (v.r >= 0) {
        emit(cp, FI_MOV, reg, v.r, 0);
    } else {
        int at = emit(cp, FI_LOADK, reg, 0, 0);
        if (!cp->bad) cp->out[at].k = v.k;
    }
}

static operand compile_node(compiler *cp, int i, int depth, int level);

/* The registers before the temporaries: every slot eval_function fills. */
static int first_temp(const scene_function *f)
{
    int np = f->nparams < FUNC_MAX_SLOTS ? f->nparams : FUNC_MAX_SLOTS;
    return f->nslots > np ? (f->nslots < FUNC_MAX_SLOTS ? f->nslots : FUNC_MAX_SLOTS) : np;
}

/* FUNC_INLINE_MAX: the longest callee (in instructions) compiled into its
 * callers; each call site then adds at most that much code. */
#define FUNC_INLINE_MAX 48

/* Whether call node nd of a float function g is compiled in place: its
 * float result (not a colour's gray) with every parameter given. */
static int inline_ok(const scene_function *g, const func_node *nd)
{
    return g && g->kind == FUNC_FLOAT && g->code && g->ncode <= FUNC_INLINE_MAX && nd->sub == 0 &&
           nd->nkids == g->nparams && g->nodes;
}

/* Node i's value in temporary `depth` (copied there if it is a leaf). */
static void compile_to(compiler *cp, int i, int depth, int level)
{
    place(cp, compile_node(cp, i, depth, level), cp->t0 + depth);
}

/* Code for node i, working from temporary `depth` up; returns where its
 * value is: a parameter's register, a constant, or temporary `depth`.
 * The tree evaluates kids first to last, each op once its kids are known;
 * so does the code, with the same operations on the same values. */
static operand compile_node(compiler *cp, int i, int depth, int level)
{
    const scene_function *f = cp->f;
    operand res = {cp->t0 + depth, 0.0};
    if (!node_ok(f, i) || level > FUNC_MAX_NESTING) {
        cp->bad = 1;
        cp->deep |= level > FUNC_MAX_NESTING;
        return res;
    }
    if (depth + 1 > cp->top) cp->top = depth + 1;
    const func_node *nd = &f->nodes[i];
    const int *k = f->kids ? f->kids + nd->kid : NULL;
    int dst = cp->t0 + depth;
    switch ((func_op)nd->op) {
    case FN_CONST: return (operand){-1, nd->k};
    case FN_ARG: return (operand){cp->base + nd->slot, 0.0};
    case FN_NEG: case FN_MATH: {
        operand x = compile_node(cp, k[0], depth, level + 1);
        if (x.r < 0) place(cp, x, dst), x.r = dst;
        if (nd->op == FN_MATH && nd->sub >= sizeof math_op) break;
        emit(cp, nd->op == FN_NEG ? FI_NEG : math_op[nd->sub], dst, x.r, 0);
        return res;
    }
    case FN_ADD: case FN_SUB: case FN_MUL: case FN_DIV: {
        int o = nd->op - FN_ADD;
        operand x = compile_node(cp, k[0], depth, level + 1);
        operand y = compile_node(cp, k[1], depth + 1, level + 1);
        if (x.r < 0 && y.r < 0) place(cp, x, dst), x.r = dst;
        static const unsigned char rr[] = {FI_ADD, FI_SUB, FI_MUL, FI_DIV};
        static const unsigned char rk[] = {FI_ADD_K, FI_SUB_K, FI_MUL_K, FI_DIV_K};
        static const unsigned char kr[] = {FI_K_ADD, FI_K_SUB, FI_K_MUL, FI_K_DIV};
        /* the register operand of a k-op form is a */
        int at = x.r < 0 ? emit(cp, kr[o], dst, y.r, 0)
               : y.r < 0 ? emit(cp, rk[o], dst, x.r, 0)
                         : emit(cp, rr[o], dst, x.r, y.r);
        if (!cp->bad) cp->out[at].k = x.r < 0 ? x.k : y.k;
        return res;
    }
    case FN_LT: case FN_LE: case FN_EQ: case FN_NE: case FN_GE: case FN_GT: case FN_AND: case FN_OR:
    case FN_ATAN2: case FN_POW: case FN_MOD: case FN_IDIV: {
        static const unsigned char ops[] = {[FN_LT] = FI_LT, [FN_LE] = FI_LE, [FN_EQ] = FI_EQ, [FN_NE] = FI_NE,
                                            [FN_GE] = FI_GE, [FN_GT] = FI_GT, [FN_AND] = FI_AND, [FN_OR] = FI_OR,
                                            [FN_ATAN2] = FI_ATAN2, [FN_POW] = FI_POW, [FN_MOD] = FI_MOD,
                                            [FN_IDIV] = FI_IDIV};
        operand x = compile_node(cp, k[0], depth, level + 1);
        if (x.r < 0) place(cp, x, dst), x.r = dst;
        operand y = compile_node(cp, k[1], depth + 1, level + 1);
        if (y.r < 0 && nd->op == FN_POW) {
            /* pow(x, k): the same pow of the same values */
            int at = emit(cp, FI_POW_K, dst, x.r, 0);
            if (!cp->bad) cp->out[at].k = y.k;
            return res;
        }
        if (y.r < 0) place(cp, y, dst + 1), y.r = dst + 1;
        if (depth + 2 > cp->top) cp->top = depth + 2;
        emit(cp, ops[nd->op], dst, x.r, y.r);
        return res;
    }
    case FN_MIN: case FN_MAX: {
        if (nd->nkids < 1) break;
        for (int j = 0; j < nd->nkids; j++) compile_to(cp, k[j], depth + j, level + 1);
        if (depth + nd->nkids > cp->top) cp->top = depth + nd->nkids;
        int at = emit(cp, nd->op == FN_MIN ? FI_MIN : FI_MAX, dst, dst, 0);
        if (!cp->bad) cp->out[at].n = nd->nkids;
        return res;
    }
    case FN_SELECT: {
        /* select(a, lt, ge) or select(a, lt, eq, gt): only the branch
         * taken is evaluated, as in the tree */
        if (nd->nkids != 3 && nd->nkids != 4) break;
        operand a = compile_node(cp, k[0], depth, level + 1);
        if (a.r < 0) place(cp, a, dst), a.r = dst;
        int test = emit(cp, nd->nkids == 3 ? FI_JNLT : FI_SEL4, 0, a.r, 0), jumps[2], nj = 0;
        for (int j = 1; j < nd->nkids; j++) {
            if (j > 1 && !cp->bad) {
                if (j == 2) cp->out[test].dst = cp->n;
                else cp->out[test].b = cp->n;
            }
            compile_to(cp, k[j], depth, level + 1);
            if (j + 1 < nd->nkids) jumps[nj++] = emit(cp, FI_JMP, 0, 0, 0);
        }
        for (int j = 0; j < nj && !cp->bad; j++) cp->out[jumps[j]].dst = cp->n;
        return res;
    }
    case FN_SUM: case FN_PROD: {
        compile_to(cp, k[0], depth, level + 1);
        compile_to(cp, k[1], depth + 1, level + 1);
        if (depth + 5 > cp->top) cp->top = depth + 5;
        int loop = emit(cp, FI_LOOP, cp->base + nd->slot, dst, 0), body = cp->n;
        compile_to(cp, k[2], depth + 4, level + 1);
        int next = emit(cp, FI_NEXT, cp->base + nd->slot, dst, body);
        int end = emit(cp, FI_END, 0, dst, 0);
        if (!cp->bad) {
            cp->out[loop].k = nd->op == FN_SUM ? 0.0 : 1.0;
            cp->out[loop].b = end;
            cp->out[next].sub = nd->op == FN_SUM;
        }
        return res;
    }
    case FN_CALL: {
        const scene_function *g = nd->fn;
        for (int j = 0; j < nd->nkids; j++) compile_to(cp, k[j], depth + j, level + 1);
        if (depth + nd->nkids > cp->top) cp->top = depth + nd->nkids;
        int direct = 0, in = 0;
        if (g && g->kind == FUNC_FLOAT && g->nodes && node_ok(g, g->root) && g->nodes[g->root].op == FN_INTERNAL &&
            nd->sub == 0) {
            /* a body that is one built-in (functions.inc's f_rounded_box and
             * the rest): the built-in reads the call's arguments directly,
             * when the call gives it all of them */
            in = g->nodes[g->root].slot;
            int np = func_internal_params(in);
            direct = np >= 0 && np <= nd->nkids && np <= g->nparams;
        }
        if (!direct && inline_ok(g, nd)) {
            /* the callee's body in place: its slots are the registers of
             * the arguments (then its loop variables, cleared as
             * eval_function clears them), its temporaries above */
            int ns = first_temp(g);
            for (int j = nd->nkids; j < ns; j++) place(cp, (operand){-1, 0.0}, dst + j);
            if (depth + ns > cp->top) cp->top = depth + ns;
            const scene_function *f0 = cp->f;
            int base0 = cp->base;
            cp->f = g;
            cp->base = dst;
            operand v = compile_node(cp, g->root, depth + ns, level + 1);
            cp->f = f0;
            cp->base = base0;
            place(cp, v, dst);
            return res;
        }
        int at = emit(cp, direct ? FI_CALL_INT : FI_CALL, dst, dst, in);
        if (!cp->bad) {
            cp->out[at].n = nd->nkids;
            cp->out[at].sub = nd->sub;
            cp->out[at].fn = g;
        }
        return res;
    }
    case FN_INTERNAL: emit(cp, FI_INTERNAL, dst, cp->base, nd->slot); return res;
    }
    cp->bad = 1;
    return res;
}


int func_code_bound(const scene_function *f)
{
    if (!f || !f->nodes) return 1;
    long n = 4L * f->nnodes + 2;
    for (int i = 0; i < f->nnodes; i++) {
        const func_node *nd = &f->nodes[i];
        if (nd->op == FN_CALL && inline_ok(nd->fn, nd)) n += nd->fn->ncode + first_temp(nd->fn) + 1;
    }
    return n < INT_MAX / 2 ? (int)n : INT_MAX / 2;
}

#define FI_TO_A(N, E) [FI_##N] = FI_##N##_A,
#define FI_TO_B(N, E) [FI_##N] = FI_##N##_B,
static const unsigned char form_a[FI_RET + 1] = {FI_UNARY(FI_TO_A) FI_BINARY(FI_TO_A)};
static const unsigned char form_b[FI_RET + 1] = {FI_BINARY(FI_TO_B)};

/* The last pass: an op that reads the register the instruction before it
 * wrote takes that value from run's local instead (its _A or _B form),
 * unless something jumps to it (then the instruction before is not the
 * one that ran). Every op before FI_JNLT leaves its result in the local;
 * the register is written too, so any later reader still finds it. */
static void chain_results(func_insn *code, int n)
{
    unsigned char *target = calloc((size_t)n + 1, 1);
    if (!target) return; /* the plain forms compute the same */
    for (int i = 0; i < n; i++) {
        const func_insn *in = &code[i];
        int t1 = -1, t2 = -1;
        switch (in->op) {
        case FI_JNLT: case FI_JMP: t1 = in->dst; break;
        case FI_SEL4: t1 = in->dst, t2 = in->b; break;
        case FI_LOOP: case FI_NEXT: t1 = in->b; break;
        }
        if (t1 >= 0 && t1 <= n) target[t1] = 1;
        if (t2 >= 0 && t2 <= n) target[t2] = 1;
    }
    for (int i = 1; i < n; i++) {
        func_insn *in = &code[i];
        const func_insn *prev = &code[i - 1];
        if (target[i] || prev->op >= FI_JNLT || in->op > FI_RET) continue;
        if (form_a[in->op] && in->a == prev->dst) in->op = form_a[in->op];
        else if (form_b[in->op] && in->b == prev->dst) in->op = form_b[in->op];
    }
    /* a product added to or taken from a sum before it (x*x + y*y + z*z) */
    for (int i = 0; i + 1 < n; i++)
        if (code[i].op == FI_MUL && (code[i + 1].op == FI_ADD_B || code[i + 1].op == FI_SUB_B))
            code[i].op = code[i + 1].op == FI_ADD_B ? FI_MUL_ADD : FI_MUL_SUB;
    free(target);
}

int func_compile(const scene_function *f, func_insn *out, int max, int *stack)
{
    if (!f || f->kind != FUNC_FLOAT || !f->nodes || !out) return -1;
    compiler cp = {f, 0, out, 0, max, 0, 0, first_temp(f), 0};
    /* the result in temporary 0 (a leaf body is copied there) */
    compile_to(&cp, f->root, 0, 0);
    emit(&cp, FI_RET, 0, 0, 0);
    if (cp.bad) return cp.deep ? -2 : -1;
    if (stack) *stack = cp.top;
    chain_results(out, cp.n);
    return cp.n;
}

/* ------------------------------------------------------------ evaluation */

/* FUNC_RUN_TEMPS temporaries live on the C stack; a program that needs
 * more takes its registers from the heap for the evaluation. */
#define FUNC_RUN_TEMPS 64

/* Run f's program on registers r (its slots filled, then f->stack
 * temporaries from register t0) to its FI_RET. */
static double run(const scene_function *f, double *r, int t0, eval_ctx *c)
{
    const func_insn *code = f->code, *pc = code;
    double acc = 0.0; /* the last value op's result */
    for (;;) {
        const func_insn *in = pc++;
        switch (in->op) {
        case FI_MOV: acc = r[in->a]; break;
        case FI_LOADK: acc = in->k; break;
#define FI_RUN_U(N, E)                                                                                                 \
        case FI_##N: {                                                                                                 \
            double x = r[in->a], k = in->k;                                                                            \
            (void)k;                                                                                                   \
            acc = E;                                                                                                   \
            break;                                                                                                     \
        }                                                                                                              \
        case FI_##N##_A: {                                                                                             \
            double x = acc, k = in->k;                                                                                 \
            (void)k;                                                                                                   \
            acc = E;                                                                                                   \
            break;                                                                                                     \
        }
        FI_UNARY(FI_RUN_U)
#define FI_RUN_B(N, E)                                                                                                 \
        case FI_##N: {                                                                                                 \
            double x = r[in->a], y = r[in->b];                                                                         \
            acc = E;                                                                                                   \
            break;                                                                                                     \
        }                                                                                                              \
        case FI_##N##_A: {                                                                                             \
            double x = acc, y = r[in->b];                                                                              \
            acc = E;                                                                                                   \
            break;                                                                                                     \
        }                                                                                                              \
        case FI_##N##_B: {                                                                                             \
            double x = r[in->a], y = acc;                                                                              \
            acc = E;                                                                                                   \
            break;                                                                                                     \
        }
        FI_BINARY(FI_RUN_B)
        case FI_MUL_ADD: case FI_MUL_SUB: {
            /* the two ops as they are, each into its register */
            double y = r[in->a] * r[in->b];
            r[in->dst] = y;
            double x = r[in[1].a];
            acc = in->op == FI_MUL_ADD ? x + y : x - y;
            r[in[1].dst] = acc;
            pc = in + 2;
            continue;
        }
        case FI_MIN: case FI_MAX: {
            const double *v = r + in->a;
            double m = v[0];
            for (int j = 1; j < in->n; j++)
                if (in->op == FI_MIN ? v[j] < m : v[j] > m) m = v[j];
            acc = m;
            break;
        }
        case FI_CALL_INT: case FI_INTERNAL: {
            double v; /* not acc's address: acc stays in a register */
            if (!func_internal_eval(in->b, r + in->a, c->env, &v)) {
                c->failed = 1;
                c->why = func_internal_name(in->b);
                return 0;
            }
            acc = v;
            break;
        }
        case FI_CALL: {
            double v[5];
            if (eval_function(in->fn, r + in->a, v, c) != PT_OK) return 0;
            if (in->sub == 5) acc = 0.297 * v[0] + 0.589 * v[1] + 0.114 * v[2]; /* gray */
            else acc = in->sub < in->fn->nterms ? v[in->sub] : 0.0;
            break;
        }
        case FI_JNLT:
            if (!(r[in->a] < 0)) pc = code + in->dst;
            continue;
        case FI_SEL4: {
            double v = r[in->a];
            if (!(v < 0)) pc = code + (v == 0 ? in->dst : in->b);
            continue;
        }
        case FI_JMP: pc = code + in->dst; continue;
        case FI_LOOP: {
            double *l = r + in->a;
            l[2] = in->k;
            l[3] = l[0];
            if (l[0] <= l[1]) r[in->dst] = l[0];
            else pc = code + in->b;
            continue;
        }
        case FI_NEXT: {
            double *l = r + in->a, b = l[4];
            l[2] = in->sub ? l[2] + b : l[2] * b;
            l[3] += 1.0;
            if (l[3] <= l[1]) {
                r[in->dst] = l[3];
                pc = code + in->b;
            }
            continue;
        }
        case FI_END: r[in->a] = r[in->a + 2]; continue;
        case FI_RET: return r[t0];
        default:
            c->failed = 1;
            c->why = "bad program";
            return 0;
        }
        r[in->dst] = acc;
    }
}

/* A float function's value at args: its program on a register file
 * (slots, then temporaries). */
static double eval_float(const scene_function *f, const double *args, eval_ctx *c)
{
    if (!f->code) {
        c->failed = 1;
        c->why = "function not compiled";
        return 0;
    }
    double local[FUNC_MAX_SLOTS + FUNC_RUN_TEMPS], *r = local;
    int ns = first_temp(f), np = f->nparams < ns ? f->nparams : ns;
    if (f->stack > FUNC_RUN_TEMPS && !(r = malloc(sizeof *r * (size_t)(ns + f->stack)))) {
        c->failed = 1;
        c->why = "out of memory";
        return 0;
    }
    /* only the slots the body uses are cleared: a call is evaluated per
     * isosurface sample (loops, not memcpy/memset: a handful) */
    for (int i = 0; i < np; i++) r[i] = args[i];
    for (int i = np; i < ns; i++) r[i] = 0.0;
    double v = run(f, r, ns, c);
    if (r != local) free(r);
    return v;
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
    case FUNC_FLOAT: out[0] = eval_float(f, args, c); break;
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
    if (f->kind == FUNC_FLOAT) {
        /* eval_function's float case without its result terms (an
         * isosurface's samples come here) */
        eval_ctx c = {env, NULL, 1, 0};
        double v = eval_float(f, args, &c);
        return c.failed ? NAN : v;
    }
    double out[5];
    if (func_eval(f, args, out, env, NULL) != PT_OK) return NAN;
    return out[0];
}
