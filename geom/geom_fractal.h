/* geom_fractal.h - julia_fractal: 4-D Julia sets (quaternion or
 * hypercomplex) cut by a 3-D slice, as POV-Ray 3.7 defines them.
 *
 * Inside = the iterates z -> f(z) + c of the sliced point stay within the
 * bailout for max_iteration steps (bailout and bounding radius as POV-Ray:
 * quaternions R = min(2, 1 + |c|), hypercomplex R = 4). A ray is marched
 * through the bounding sphere in steps of at least 1 / precision (longer
 * steps from POV-Ray's distance estimates outside the set), up to where it
 * leaves the ball beyond which every point escapes (sqr and cube), and
 * each change of the inside test is bisected to POV-Ray's tolerance, 1e-7;
 * the surface found is the one POV-Ray's march defines. Normals are the
 * gradient of |z_N|^2 at the crossing's inside point, by forward-mode
 * derivatives through the iteration (quaternion products; hypercomplex
 * numbers as two complex numbers, where any analytic f applies). */
#ifndef PT_GEOM_FRACTAL_H
#define PT_GEOM_FRACTAL_H
#include "geom_shape.h"

/* geom_fractal_init, _free, _hits, _inside (geom_shape.h) */
GEOM_FAMILY(fractal)
vec3 geom_fractal_normal(const geom_shape *sh, vec3 q);

#endif
