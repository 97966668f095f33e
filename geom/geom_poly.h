/* geom_poly.h - real roots of univariate polynomials in an interval, for
 * the shapes whose ray equation is a polynomial (lathe, sor, prism, blob,
 * poly/cubic/quartic, quadric).
 *
 * Two isolation methods, both followed by safeguarded Newton steps inside a
 * sign-change bracket:
 *   - derivative brackets (default): the critical points, found
 *     recursively as roots of the derivative, split [a, b] into monotonic
 *     pieces, each holding at most one root;
 *   - Sturm sequences (`sturm`, POV-Ray's keyword): the number of distinct
 *     roots in an interval is counted from sign changes of the sequence and
 *     intervals are bisected until each holds one root.
 * Coefficients are c[0] + c[1] x + ... + c[n] x^n. */
#ifndef PT_GEOM_POLY_H
#define PT_GEOM_POLY_H

#define GEOM_POLY_MAX 35 /* POV-Ray's highest poly order */

/* Real roots in [a, b], ascending, at most n; returns their number. A
 * multiple root (even multiplicity) is found where the polynomial touches
 * zero within rounding. */
int geom_poly_solve(const double *c, int n, double a, double b, double *roots, int sturm);
/* Horner evaluation. */
double geom_poly_eval(const double *c, int n, double x);

#endif
