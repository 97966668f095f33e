/* xform.h - affine transforms (3x4 matrix plus its inverse), POV-Ray conventions. */
#ifndef PT_XFORM_H
#define PT_XFORM_H
#include "vec.h"

typedef struct {
    double m[3][4];   /* object -> world: p' = M p + t (column 3 is t) */
    double inv[3][4]; /* world -> object */
} xform;

xform xform_identity(void);
xform xform_translate(vec3 t);
xform xform_scale(vec3 s);
/* POV-Ray `rotate <x,y,z>`: degrees, about x first, then y, then z (left-handed). */
xform xform_rotate(vec3 deg);
/* POV-Ray `matrix <m00,m01,m02, m10,m11,m12, m20,m21,m22, m30,m31,m32>`:
 * row-vector convention, p' = p * M; rows 0..2 are the linear part, row 3 the translation. */
xform xform_matrix(const double v[12]);
/* Apply a, then b. */
xform xform_then(xform a, xform b);
xform xform_inverse(xform a);
int xform_is_identity(const xform *a);
vec3 xform_point(const xform *a, vec3 p);
vec3 xform_vector(const xform *a, vec3 v);
vec3 xform_normal(const xform *a, vec3 n); /* inverse-transpose, not normalised */
vec3 xform_inv_point(const xform *a, vec3 p);
vec3 xform_inv_vector(const xform *a, vec3 v);

#endif
