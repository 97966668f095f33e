/* xform.c - affine transforms. */
#include "xform.h"
#include <string.h>

static void mat_identity(double m[3][4])
{
    memset(m, 0, sizeof(double) * 12);
    m[0][0] = m[1][1] = m[2][2] = 1.0;
}

/* r = a after b, i.e. r(p) = a(b(p)) */
static void mat_mul(double r[3][4], const double a[3][4], const double b[3][4])
{
    double t[3][4];
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 4; j++) {
            double s = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
            if (j == 3) s += a[i][3];
            t[i][j] = s;
        }
    }
    memcpy(r, t, sizeof t);
}

static int mat_invert(double r[3][4], const double a[3][4])
{
    double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
               - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
               + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    if (det == 0.0 || !isfinite(det)) {
        mat_identity(r);
        return 0;
    }
    double id = 1.0 / det;
    double t[3][4];
    t[0][0] = (a[1][1] * a[2][2] - a[1][2] * a[2][1]) * id;
    t[0][1] = (a[0][2] * a[2][1] - a[0][1] * a[2][2]) * id;
    t[0][2] = (a[0][1] * a[1][2] - a[0][2] * a[1][1]) * id;
    t[1][0] = (a[1][2] * a[2][0] - a[1][0] * a[2][2]) * id;
    t[1][1] = (a[0][0] * a[2][2] - a[0][2] * a[2][0]) * id;
    t[1][2] = (a[0][2] * a[1][0] - a[0][0] * a[1][2]) * id;
    t[2][0] = (a[1][0] * a[2][1] - a[1][1] * a[2][0]) * id;
    t[2][1] = (a[0][1] * a[2][0] - a[0][0] * a[2][1]) * id;
    t[2][2] = (a[0][0] * a[1][1] - a[0][1] * a[1][0]) * id;
    for (int i = 0; i < 3; i++)
        t[i][3] = -(t[i][0] * a[0][3] + t[i][1] * a[1][3] + t[i][2] * a[2][3]);
    memcpy(r, t, sizeof t);
    return 1;
}

xform xform_identity(void)
{
    xform x;
    mat_identity(x.m);
    mat_identity(x.inv);
    return x;
}

xform xform_translate(vec3 t)
{
    xform x = xform_identity();
    x.m[0][3] = t.x; x.m[1][3] = t.y; x.m[2][3] = t.z;
    x.inv[0][3] = -t.x; x.inv[1][3] = -t.y; x.inv[2][3] = -t.z;
    return x;
}

xform xform_scale(vec3 s)
{
    xform x = xform_identity();
    x.m[0][0] = s.x; x.m[1][1] = s.y; x.m[2][2] = s.z;
    x.inv[0][0] = s.x != 0 ? 1.0 / s.x : 0;
    x.inv[1][1] = s.y != 0 ? 1.0 / s.y : 0;
    x.inv[2][2] = s.z != 0 ? 1.0 / s.z : 0;
    return x;
}

static xform rot_axis(int axis, double deg)
{
    /* POV-Ray is left-handed; rotate <0,0,a> turns +x towards +y, as its docs show
     * (left-hand rule about the axis). The matrix is the same as the usual
     * right-handed one applied to the coordinates. */
    double a = deg * (M_PI / 180.0);
    double c = cos(a), s = sin(a);
    xform x = xform_identity();
    int i = (axis + 1) % 3, j = (axis + 2) % 3;
    x.m[i][i] = c; x.m[i][j] = -s;
    x.m[j][i] = s; x.m[j][j] = c;
    x.inv[i][i] = c; x.inv[i][j] = s;
    x.inv[j][i] = -s; x.inv[j][j] = c;
    return x;
}

xform xform_rotate(vec3 deg)
{
    xform r = rot_axis(0, deg.x);
    r = xform_then(r, rot_axis(1, deg.y));
    return xform_then(r, rot_axis(2, deg.z));
}

xform xform_matrix(const double v[12])
{
    xform x;
    /* p' = p * M  =>  p'_j = sum_i p_i M[i][j] + M[3][j] */
    for (int j = 0; j < 3; j++) {
        for (int i = 0; i < 3; i++) x.m[j][i] = v[i * 3 + j];
        x.m[j][3] = v[9 + j];
    }
    mat_invert(x.inv, x.m);
    return x;
}

xform xform_then(xform a, xform b)
{
    xform r;
    mat_mul(r.m, b.m, a.m);
    mat_mul(r.inv, a.inv, b.inv);
    return r;
}

xform xform_inverse(xform a)
{
    xform r;
    memcpy(r.m, a.inv, sizeof r.m);
    memcpy(r.inv, a.m, sizeof r.inv);
    return r;
}


