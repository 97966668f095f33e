/* func.h - POV-Ray user functions (function { ... }) compiled into a small
 * expression tree, and their evaluator.
 *
 * The parser builds scene_function records; isosurfaces, function patterns
 * and parse-time calls evaluate them with func_eval, without knowing the
 * parser. Float constants of the scene are folded in when the function is
 * declared; parameters are slots in the argument array.
 *
 * Kinds (POV-Ray 3.7): a float function of its parameters (x, y, z by
 * default); `function { internal(N) }` (one of POV-Ray's built-in functions,
 * func_internal.h); `function { transform {...} }` (3 parameters, a 3-term
 * result); `function { spline {...} }` (1 parameter, the spline's terms);
 * `function { pigment {...} }` (3 parameters, 5 terms: r g b f t) and
 * `function { pattern {...} }` (3 parameters, a float). Pigment and pattern
 * functions and the noise-based internals need the renderer's evaluators,
 * passed in a func_env; without them func_eval says PT_ERR_UNSUPPORTED. */
#ifndef PT_FUNC_H
#define PT_FUNC_H
#include "diag.h"
#include "uspline.h"
#include "vec.h"
#include "xform.h"

#define FUNC_MAX_PARAMS 56 /* POV-Ray 3.7's MAX_PARAMETER_LIST */
#define FUNC_MAX_SLOTS 128 /* parameters + sum/prod loop variables */

typedef enum {
    FN_CONST,    /* k */
    FN_ARG,      /* slot `slot` (a parameter or a sum/prod variable) */
    FN_NEG,      /* -kid0 */
    FN_ADD, FN_SUB, FN_MUL, FN_DIV,              /* kid0 op kid1 */
    FN_LT, FN_LE, FN_EQ, FN_NE, FN_GE, FN_GT,    /* 1 or 0 */
    FN_AND, FN_OR,                               /* on truth (x != 0) */
    FN_MATH,     /* sub: func_math, one kid */
    FN_ATAN2, FN_POW, FN_MOD, FN_IDIV,           /* two kids; idiv = div() */
    FN_MIN, FN_MAX,                              /* nkids >= 2 */
    FN_SELECT,   /* select(a, lt, eq_or_ge [, gt]): 3 or 4 kids */
    FN_SUM, FN_PROD, /* kids: from, to, body; `slot` is the loop variable */
    FN_CALL,     /* user function `fn` with nkids arguments; sub: term of a
                    vector result (5 = gray of a colour) */
    FN_INTERNAL  /* internal(slot) applied to this function's own arguments */
} func_op;

typedef enum {
    FM_SIN, FM_COS, FM_TAN, FM_ASIN, FM_ACOS, FM_ATAN, FM_SINH, FM_COSH, FM_TANH,
    FM_ASINH, FM_ACOSH, FM_ATANH, FM_ABS, FM_RADIANS, FM_DEGREES, FM_FLOOR, FM_INT,
    FM_CEIL, FM_SQRT, FM_EXP, FM_LN, FM_LOG, FM_SQR
} func_math;

typedef struct func_node {
    unsigned char op;      /* func_op */
    unsigned char sub;     /* FN_MATH: func_math; FN_CALL: result term */
    unsigned short nkids;
    int kid;               /* first kid's index in scene_function.kids */
    int slot;              /* FN_ARG, FN_SUM/FN_PROD variable; FN_INTERNAL number */
    double k;              /* FN_CONST */
    const struct scene_function *fn; /* FN_CALL */
} func_node;

typedef enum { FUNC_FLOAT, FUNC_TRANSFORM, FUNC_SPLINE, FUNC_PIGMENT, FUNC_PATTERN } func_kind;

typedef struct scene_function {
    func_kind kind;
    const char *name;          /* identifier it was declared as (may be NULL) */
    src_loc loc;
    int nparams;
    const char *const *params; /* parameter names */
    int nslots;                /* parameters + loop variables */
    int nterms;                /* result terms: 1, 3 (transform), 2..5 (spline), 5 (pigment) */
    int nnodes;
    const func_node *nodes;
    const int *kids;
    int root;                  /* FUNC_FLOAT: the body's node */
    /* FUNC_FLOAT: the body compiled to a flat program (func_compile, at
     * declaration), run in a loop on registers; a float function without
     * one cannot be evaluated (func_eval says so). */
    const struct func_insn *code;
    int ncode;
    int stack;                 /* the temporaries the program needs */
    xform transform;           /* FUNC_TRANSFORM */
    const struct user_spline *spline; /* FUNC_SPLINE */
    const void *pigment;       /* FUNC_PIGMENT / FUNC_PATTERN: the pigment IR (opaque here) */
} scene_function;

/* What the renderer can supply; any member may be NULL. */
typedef struct func_env {
    /* pigment/pattern functions: colour (5 terms) or pattern value (out[0]) at p */
    int (*pigment)(void *user, const scene_function *f, vec3 p, double out[5]);
    /* POV-Ray's Noise(p, generator) in [0, 1] (internal 29, 58, 59, 76, 78) */
    double (*noise)(void *user, vec3 p, int generator);
    /* POV-Ray's DTurbulence (the SDL's vturbulence) */
    vec3 (*dturbulence)(void *user, vec3 p, int octaves, double omega, double lambda);
    int noise_generator;       /* the scene's global_settings noise_generator (default 2) */
    void *user;
} func_env;

/* Evaluate f at args[0..f->nparams) into out[0..f->nterms). Returns PT_OK,
 * or PT_ERR_UNSUPPORTED when something needs an evaluator env lacks (then
 * *why, if not NULL, names it: "internal(76) (noise)", "pigment function"). */
pt_status func_eval(const scene_function *f, const double *args, double *out, const func_env *env, const char **why);

/* One instruction of a compiled body (func_compile): three-address code
 * on registers (the function's slots, then temporaries). Ops are FI_*
 * (func.c); dst is the register written or a jump target, a and b the
 * registers read (or a second jump target, an internal's number), k a
 * constant operand, fn a called function. */
typedef struct func_insn {
    unsigned char op;
    unsigned char sub;         /* FN_MATH: func_math; a call: result term */
    unsigned short n;          /* arguments of a call, operands of min/max */
    int dst, a, b;
    double k;
    const struct scene_function *fn;
} func_insn;

/* FUNC_MAX_NESTING bounds a compiled body's nesting (calls compiled in
 * place count with their callers). */
#define FUNC_MAX_NESTING 4096
/* f's body (FUNC_FLOAT) compiled into out (room for max instructions;
 * func_code_bound(f) suffices): the same operations on the same values in
 * the same order as the tree, so the same result to the bit. Calls of
 * short float functions are compiled in place. Returns the number of
 * instructions and sets *stack to the temporaries it needs; -2 when the
 * body is nested deeper than FUNC_MAX_NESTING, -1 when f is no float
 * function or out is too small. */
int func_compile(const scene_function *f, func_insn *out, int max, int *stack);
/* Room enough for func_compile(f). */
int func_code_bound(const scene_function *f);

/* The float result (out[0]); NaN when unsupported. */
double func_eval_float(const scene_function *f, const double *args, const func_env *env);

#endif
