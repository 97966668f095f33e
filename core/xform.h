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
/* inline and unrolled: shading asks it of every texture layer at every hit */
static inline int xform_is_identity(const xform *a)
{
    return a->m[0][0] == 1.0 && a->m[1][1] == 1.0 && a->m[2][2] == 1.0 && a->m[0][1] == 0.0 && a->m[0][2] == 0.0 &&
           a->m[0][3] == 0.0 && a->m[1][0] == 0.0 && a->m[1][2] == 0.0 && a->m[1][3] == 0.0 && a->m[2][0] == 0.0 &&
           a->m[2][1] == 0.0 && a->m[2][3] == 0.0;
}
/* inline: they run per ray and per inside test of every transformed shape.
 * M's 3x3 part times v, and with column 3 added (the sums in the same order,
 * so either form rounds as one written-out expression would). */
static inline vec3 xform_mat3(const double M[3][4], vec3 v)
{
    return v3(M[0][0] * v.x + M[0][1] * v.y + M[0][2] * v.z, M[1][0] * v.x + M[1][1] * v.y + M[1][2] * v.z,
              M[2][0] * v.x + M[2][1] * v.y + M[2][2] * v.z);
}
static inline vec3 xform_mat34(const double M[3][4], vec3 p)
{
    vec3 l = xform_mat3(M, p);
    return v3(l.x + M[0][3], l.y + M[1][3], l.z + M[2][3]);
}
static inline vec3 xform_point(const xform *a, vec3 p) { return xform_mat34(a->m, p); }
static inline vec3 xform_vector(const xform *a, vec3 v) { return xform_mat3(a->m, v); }
/* inverse-transpose, not normalised */
static inline vec3 xform_normal(const xform *a, vec3 n)
{
    /* (M^-1)^T n */
    return v3(a->inv[0][0] * n.x + a->inv[1][0] * n.y + a->inv[2][0] * n.z,
              a->inv[0][1] * n.x + a->inv[1][1] * n.y + a->inv[2][1] * n.z,
              a->inv[0][2] * n.x + a->inv[1][2] * n.y + a->inv[2][2] * n.z);
}
static inline vec3 xform_inv_point(const xform *a, vec3 p) { return xform_mat34(a->inv, p); }
static inline vec3 xform_inv_vector(const xform *a, vec3 v) { return xform_mat3(a->inv, v); }

#endif
