/* accel_fractal.h - julia_fractal: 4-D Julia sets (quaternion or
 * hypercomplex) cut by a 3-D slice, as POV-Ray 3.7 defines them.
 *
 * Inside = the iterates z -> f(z) + c of the sliced point stay within the
 * bailout for max_iteration steps (bailout and bounding radius as POV-Ray:
 * quaternions R = min(2, 1 + |c|), hypercomplex R = 4). A ray is marched
 * through the bounding sphere in steps of at least 1 / precision (for
 * quaternions, longer steps from POV-Ray's distance estimate outside the
 * set), and each change of the inside test is bisected to rounding; the
 * surface found is the one POV-Ray's march defines. Normals are the
 * gradient of |z_N|^2 at the crossing's inside point, by forward-mode
 * derivatives through the iteration (quaternion products; hypercomplex
 * numbers as two complex numbers, where any analytic f applies). */
#ifndef PT_ACCEL_FRACTAL_H
#define PT_ACCEL_FRACTAL_H
#include "accel_shapes.h"

int accel_fractal_init(accel_shape *sh, const scene_object *o, vec3 *lo, vec3 *hi);
void accel_fractal_free(void *data);
int accel_fractal_hits(const accel_shape *sh, vec3 o, vec3 d, double tmin, double tmax, accel_shape_hit *out, int max);
int accel_fractal_inside(const accel_shape *sh, vec3 q);
vec3 accel_fractal_normal(const accel_shape *sh, vec3 q);

#endif
