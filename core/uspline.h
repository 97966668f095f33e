/* uspline.h - POV-Ray 3.7 splines (spline { ... }): a list of (t, vector)
 * entries kept sorted by t, and their evaluation. The parser builds them;
 * anything may evaluate them (spline functions in the renderer).
 *
 * The kinds are the four of POV-Ray 3.7.0's spline statement: linear,
 * quadratic, cubic (Catmull-Rom, which needs a point before and after the
 * interpolated range) and natural (cubic with zero second derivative at both
 * ends). Outside the range of t the end value is returned (for cubic: the
 * second and next-to-last points, which are the ends of its range). */
#ifndef PT_USPLINE_H
#define PT_USPLINE_H
#include "diag.h"

typedef enum { USPLINE_LINEAR, USPLINE_QUADRATIC, USPLINE_CUBIC, USPLINE_NATURAL } uspline_kind;

typedef struct {
    double t;
    double v[5];
} uspline_point;

typedef struct user_spline {
    uspline_kind kind;
    int terms;          /* 2..5: the most terms any entry was given */
    int n;
    uspline_point *pts;  /* sorted by t, no two equal */
    double *m;          /* natural spline: second derivatives, 5 per point (NULL = not computed) */
    src_loc loc;
} user_spline;

/* Insert (t, v) keeping the order; an entry with the same t is replaced
 * (POV-Ray's rule). `pts` must have room for one more entry. */
void uspline_insert(user_spline *s, double t, const double v[5]);
/* Second derivatives of the natural spline into m (5 * n doubles). */
void uspline_natural_coeffs(const user_spline *s, double *m);
/* Value at t using `kind` (which may differ from s->kind, as in S(t, kind));
 * m: natural coefficients for kind USPLINE_NATURAL (NULL: computed on the
 * fly). All five terms are written. */
void uspline_eval(const user_spline *s, uspline_kind kind, const double *m, double t, double out[5]);

#endif
