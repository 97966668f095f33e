/* func_internal.h - POV-Ray 3.7's built-in functions internal(0..78), the
 * ones functions.inc declares as f_algbr_cyl1 ... f_noise_generator.
 *
 * Each takes x, y, z and then its extra parameters (the counts are POV-Ray's;
 * functions.inc documents them). Numbers 29 (f_hetero_mf), 58 (f_ridge),
 * 59 (f_ridged_mf), 76 (f_noise3d) and 78 (f_noise_generator) need POV-Ray's
 * noise, which the caller supplies; 77 is the pattern function's slot
 * (function { pattern {...} }), not callable by number. */
#ifndef PT_FUNC_INTERNAL_H
#define PT_FUNC_INTERNAL_H
#include "func.h"

#define FUNC_INTERNAL_COUNT 79

/* Number of parameters (3 + extras) of internal(n); -1 if n is not one. */
int func_internal_params(int n);
/* The functions.inc name ("f_sphere"), or NULL. */
const char *func_internal_name(int n);
/* Evaluate internal(n) at a[0..params). Returns 0 (and sets *out to 0) when
 * it cannot (unknown n, noise needed but env has none). */
int func_internal_eval(int n, const double *a, const func_env *env, double *out);

#endif
