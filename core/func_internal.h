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
#define FUNC_INTERNAL_RIDGED_MF 59

/* f_ridged_mf's octave weights, (lacunarity^i)^-H. POV-Ray 3.7
 * (fnintern.cpp, f_ridged_mf) computes them at a function's first
 * evaluation, from that call's H and lacunarity, keeps them in the function
 * (its private data) and reuses them for every later call of the same
 * function whatever H and lacunarity it passes; the lacunarity that scales
 * the point stays each call's own. Which call is first is the render's
 * order (shade_ridged_mf_first). One record for the process: set only while
 * one thread renders (func_ridged_mf_record, then the first call), read by
 * every later call until func_ridged_mf_reset.
 *   reset:  every call takes its own H and lacunarity (as POV-Ray where a
 *           scene passes one set)
 *   record: the next call's H and lacunarity become every later call's
 *   fixed:  1 when recorded (its H and lacunarity into *h, *lacunarity) */
void func_ridged_mf_reset(void);
void func_ridged_mf_record(void);
int func_ridged_mf_fixed(double *h, double *lacunarity);

/* Number of parameters (3 + extras) of internal(n); -1 if n is not one. */
int func_internal_params(int n);
/* The functions.inc name ("f_sphere"), or NULL. */
const char *func_internal_name(int n);
/* Evaluate internal(n) at a[0..params). Returns 0 (and sets *out to 0) when
 * it cannot (unknown n, noise needed but env has none). */
int func_internal_eval(int n, const double *a, const func_env *env, double *out);

#endif
