/* func_internal.c - POV-Ray 3.7's internal(N) functions (functions.inc).
 *
 * The formulas are the semantics of POV-Ray 3.7.0's built-in functions
 * (each "field strength" surface clamps strength * value to [-10, 10]; the
 * "_2d" variants can first turn the xy profile into a surface of revolution
 * about y: with sor switch > 0, x becomes sqrt(x^2 + z^2) - sor offset and
 * (x, y) is rotated by the sor angle in degrees). Written here from those
 * definitions. */
#include "func_internal.h"
#include <math.h>
#include <string.h>

typedef double (*internal_fn)(const double *a, const func_env *env, int *ok);

static double clamp10(double v) { return v < -10 ? -10 : (v > 10 ? 10 : v); }
static double field(double strength, double r) { return clamp10(strength * r); }
static double sq(double v) { return v * v; }
static double dmin(double a, double b) { return a < b ? a : b; }
static double dmax(double a, double b) { return a > b ? a : b; }

/* The planar profile (px, py) of a _2d function, turned into a solid of
 * revolution when sor > 0 (see the file comment). */
static void profile(const double *a, double sor, double offset, double angle, double *px, double *py)
{
    *px = a[0];
    *py = a[1];
    if (sor <= 0) return;
    double r = sqrt(a[0] * a[0] + a[2] * a[2]) - offset;
    double th = angle * M_PI / 180.0;
    if (th != 0) {
        *px = r * cos(th) - a[1] * sin(th);
        *py = r * sin(th) + a[1] * cos(th);
    } else {
        *px = r;
    }
}

/* Cross-section shape used by the helix and spiral functions: 1 circle,
 * 0 square, other values a superellipse of that exponent. */
static double section(double u, double v, double shape, int spiral)
{
    if (shape == 1) return sqrt(u * u + v * v);
    if (shape == 0) return dmax(fabs(u), fabs(v));
    double e = 2.0 / shape;
    return pow(pow(fabs(u), e) + pow(fabs(v), e), spiral ? 1.0 / e : shape * 0.5);
}

#define X a[0]
#define Y a[1]
#define Z a[2]
#define P(i) a[3 + (i)]

/* 0..3: algebraic cylinders */
static double algbr_cyl(const double *a, int which)
{
    double px, py;
    profile(a, P(2), P(3), P(4), &px, &py);
    double x2 = px * px, y2 = py * py, r;
    switch (which) {
    case 0: r = -(x2 * fabs(px) - x2 + y2); return -dmin(P(1), dmax(P(0) * r, -P(1)));
    case 1: r = -(2 * x2 * x2 - 3 * x2 * py + y2 - 2 * y2 * py + y2 * y2); break;
    case 2: r = -(x2 * x2 + x2 * y2 - 2 * x2 * py - px * y2 + y2); break;
    default: r = -(x2 * x2 + y2 * y2 + 2 * x2 * y2 + 3 * x2 * py - y2 * py); break;
    }
    return dmin(P(1), dmax(P(0) * r, -P(1)));
}
static double f_algbr_cyl1(const double *a, const func_env *e, int *ok) { (void)e; (void)ok; return algbr_cyl(a, 0); }
static double f_algbr_cyl2(const double *a, const func_env *e, int *ok) { (void)e; (void)ok; return algbr_cyl(a, 1); }
static double f_algbr_cyl3(const double *a, const func_env *e, int *ok) { (void)e; (void)ok; return algbr_cyl(a, 2); }
static double f_algbr_cyl4(const double *a, const func_env *e, int *ok) { (void)e; (void)ok; return algbr_cyl(a, 3); }

static double f_bicorn(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double s2 = P(1) * P(1), h = X * X + Z * Z;
    double q = h + 2 * P(1) * Y - s2;
    return field(P(0), Y * Y * (s2 - h) - q * q);
}

static double f_bifolia(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double h = X * X + Z * Z, r = h + Y * Y;
    return field(P(0), -(r * r - P(1) * h * Y));
}

static double f_blob(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double half = P(0) * 0.5, yz = Y * Y + Z * Z;
    double r1 = dmin(1, (sq(X + half) + yz) * P(2) * P(2));
    double r2 = dmin(1, (sq(X - half) + yz) * P(4) * P(4));
    return -(P(1) * sq(1 - r1) + P(3) * sq(1 - r2));
}

static double f_blob2(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double yz = Y * Y + Z * Z;
    double s = exp(-(X * X + yz) * P(1)) + exp(-(sq(X - P(0)) + yz) * P(1));
    return P(3) - s * P(2);
}

static double f_boy_surface(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X, y2 = Y * Y, z2 = Z * Z, w = 1 - Z, h = x2 + y2, r2 = sqrt(2.0);
    double r = P(1) * (64 * w * w * w * z2 * Z - 48 * w * w * z2 * (3 * x2 + 3 * y2 + 2 * z2) +
                       12 * w * Z * (27 * h * h - 24 * z2 * h + 36 * r2 * Y * Z * (y2 - 3 * x2) + 4 * z2 * z2) +
                       (9 * x2 + 9 * y2 - 2 * z2) * (-81 * h * h - 72 * z2 * h + 108 * r2 * X * Z * (x2 - 3 * y2) + 4 * z2 * z2));
    return field(P(0), r);
}

static double f_comma(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x = (X == 0 && Z == 0) ? 0.0001 : X, s = P(0);
    double th = atan2(Z, x);
    double r = sqrt(sq(x + s * 0.25) + Z * Z);
    double t = dmin(Z, cos(th * 0.5) * s * 0.5 - sqrt(sq(r - s * 0.75) + Y * Y));
    double b = s * 0.5 - sqrt(sq(x - s * 0.5) + Z * Z + Y * Y);
    return -dmax(t, b);
}

/* exponentials of the three axis-stretched ellipsoids of 10, 19, 32, 62 */
static void ellipsoid_terms(const double *a, double ecc, double inv, double out[3])
{
    double x2 = X * X, y2 = Y * Y, z2 = Z * Z;
    out[0] = exp(-(x2 * ecc + y2 * ecc + z2) * inv);
    out[1] = exp(-(x2 * ecc + y2 + z2 * ecc) * inv);
    out[2] = exp(-(x2 + y2 * ecc + z2 * ecc) * inv);
}

static double f_cross_ellipsoids(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double t[3];
    ellipsoid_terms(a, P(0), P(1), t);
    return P(3) - dmax(dmax(t[0], t[1]), t[2]) * P(2);
}

static double f_crossed_trough(const double *a, const func_env *e, int *ok) { (void)e; (void)ok; return field(P(0), X * X * Z * Z - Y); }
static double f_cubic_saddle(const double *a, const func_env *e, int *ok) { (void)e; (void)ok; return field(P(0), -(X * X * X - Y * Y * Y - Z)); }

/* 13 (cushion) and 43 (odd) share one polynomial */
static double cushion_poly(const double *a)
{
    double x2 = X * X, y2 = Y * Y, z2 = Z * Z;
    return z2 * x2 - z2 * z2 - 2 * Z * x2 + 2 * z2 * Z + x2 - z2 - sq(x2 - Z) - y2 * y2 - 2 * x2 * y2 - y2 * z2 + 2 * y2 * Z + y2;
}
static double f_cushion(const double *a, const func_env *e, int *ok) { (void)e; (void)ok; return field(P(0), cushion_poly(a)); }

static double f_devils_curve(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X, y2 = Y * Y, z2 = Z * Z;
    return field(P(0), -(x2 * x2 + 2 * x2 * z2 - 0.36 * x2 - y2 * y2 + 0.25 * y2 + z2 * z2));
}

static double f_devils_curve_2d(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double px, py;
    profile(a, P(3), P(4), P(5), &px, &py);
    double x2 = px * px, y2 = py * py;
    return field(P(0), -(x2 * (x2 - P(1) * P(1)) - y2 * (y2 - P(2) * P(2))));
}

static double f_dupin_cyclid(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X, y2 = Y * Y, z2 = Z * Z, d2 = P(5) * P(5);
    double b2 = P(2) * P(2), c2 = P(4) * P(4);
    double q1 = b2 - c2 - sq(P(3) + P(1)), q2 = b2 - c2 - sq(P(3) - P(1));
    double a2 = P(3) * P(3), m2 = P(1) * P(1);
    double r = -(q1 * q2 * (x2 * x2 + y2 * y2 + z2 * z2) + 2 * (q1 * q2 * (x2 * y2 + x2 * z2 + y2 * z2)) +
                 2 * d2 * ((-c2 - a2 + b2 + m2) * (2 * X * P(3) + 2 * Y * P(4) - d2) - 4 * P(4) * b2 * Y) * (x2 + y2 + z2) +
                 4 * d2 * d2 * (P(3) * X + P(4) * Y) * (-d2 + P(4) * Y + P(3) * X) + 4 * d2 * d2 * m2 * y2 + d2 * d2 * d2 * d2);
    return field(P(0), r);
}

static double f_ellipsoid(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    return sqrt(X * X * P(0) * P(0) + Y * Y * P(1) * P(1) + Z * Z * P(2) * P(2));
}

static double f_enneper(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    /* z2 is taken before z is kept away from 0 (as POV-Ray 3.7.0 does) */
    double x2 = X * X, y2 = Y * Y, z2 = Z * Z, z = fabs(Z) < 0.2 ? 0.2 : Z;
    /* POV-Ray 3.7.0 writes the constants 2/3, 1/4, 8/9, 2/9 as integer
     * divisions, which are 0; the surface is defined by that. */
    double r = (y2 - x2) / (2 * z) + 2 * z2 / 9;
    double r2 = (y2 - x2) / (4 * z);
    return field(P(0), -(r * r * r - 6 * r2 * r2));
}

static double f_flange_cover(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double t[3];
    ellipsoid_terms(a, P(0), P(1), t);
    return P(3) - (t[0] + t[1] + t[2]) * P(2);
}

static double f_folium_surface(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    return field(P(0), (Y * Y + Z * Z) * (1 + (P(2) - 4 * P(1)) * X) + X * X * (1 + P(2)));
}

static double f_folium_surface_2d(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double px, py;
    profile(a, P(3), P(4), P(5), &px, &py);
    return field(P(0), -(py * py * (1 + (P(2) - 4 * P(1)) * px) + px * px * (1 + P(2))));
}

static double f_glob(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X;
    return field(P(0), 0.5 * x2 * x2 * X + 0.5 * x2 * x2 - (Y * Y + Z * Z));
}

static double f_heart(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X, y2 = Y * Y, z2 = Z * Z, s = 2 * x2 + y2 + z2 - 1;
    return field(P(0), -(s * s * s - 0.1 * x2 * z2 * Z - y2 * z2 * Z));
}

static double f_helical_torus(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double rr = sqrt(X * X + Z * Z);
    double x = (X == 0 && Z == 0) ? 0.000001 : X;
    double ph = atan2(x, Z);
    double t = atan2(rr - P(0), Y);
    double r = sqrt(sq(rr - P(0)) + Y * Y);
    double th = fmod(ph * P(1) + t * P(2), 2 * M_PI);
    if (th < 0) th += 2 * M_PI;
    t = atan2((th - M_PI) * P(8), r - P(5));
    t = cos(t * P(7) + ph * P(9)) * P(3) + P(4);
    double outer = P(4) + P(5) - P(0) - rr;
    th -= M_PI;
    t -= dmin(sqrt(sq(r - P(5)) + th * th * P(6)), r + P(5));
    return -dmax(outer, t);
}

static double f_helix1(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double r = sqrt(X * X + Z * Z);
    double x = (X == 0 && Z == 0) ? 0.000001 : X;
    double th = fmod(atan2(Z, x) * P(0) + Y * P(1) * P(0), 2 * M_PI);
    if (th < 0) th += 2 * M_PI;
    double v = (th - M_PI) / P(4) / (P(1) * P(0));
    double u = r - P(3);
    if (P(5) != 1 && P(6) != 0) {
        double c = cos(P(6) * M_PI / 180), s = sin(P(6) * M_PI / 180);
        double nu = u * c - v * s;
        v = u * s + v * c;
        u = nu;
    }
    return -P(2) + dmin(P(3) + r, section(u, v, P(5), 0));
}

static double f_helix2(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double c = cos(Y * P(1)), s = sin(Y * P(1));
    double dx = X - P(3) * c, dz = Z - P(3) * s;
    double u = dx * c + dz * s, v = -dx * s + dz * c;
    return section(u, v, P(5), 0) - P(2);
}

/* 27, 28: distance-like hexagonal tiling fields */
static double hex_field(const double *a, int want_y)
{
    double r3 = sqrt(3.0);
    double x1 = fabs(fmod(fabs(X), r3) - r3 / 2), y1 = fabs(fmod(fabs(Y), 3) - 1.5);
    double x2 = r3 / 2 - x1, y2 = 1.5 - y1;
    if (x1 * x1 + y1 * y1 > x2 * x2 + y2 * y2) {
        x1 = x2;
        y1 = y2;
    }
    if (atan2(y1, x1) < M_PI / 6) return want_y ? y1 : x1;
    if (want_y) return fabs(-sin(M_PI / 3) * x1 + cos(M_PI / 3) * y1);
    return cos(M_PI / 3) * x1 + sin(M_PI / 3) * y1;
}
static double f_hex_x(const double *a, const func_env *e, int *ok) { (void)e; (void)ok; return hex_field(a, 0); }
static double f_hex_y(const double *a, const func_env *e, int *ok) { (void)e; (void)ok; return hex_field(a, 1); }

static double noise_at(const func_env *e, vec3 p, int gen, int *ok)
{
    if (!e || !e->noise) {
        *ok = 0;
        return 0;
    }
    return e->noise(e->user, p, gen);
}

static double f_hetero_mf(const double *a, const func_env *e, int *ok)
{
    vec3 p = v3(X, Y, Z);
    int gen = (int)P(5) & 3;
    double signal = noise_at(e, p, gen, ok) * 2 - 1 + P(3);
    p = v3_scale(p, P(1));
    double step = pow(P(1), -P(0)), weight = step;
    for (int i = 1; i < P(2) && *ok; i++) {
        double inc = (noise_at(e, p, gen, ok) * 2 - 1 + P(3)) * weight;
        for (int k = (int)P(4); k > 0; k--) inc *= signal;
        signal += inc;
        p = v3_scale(p, P(1));
        weight *= step;
    }
    double rem = P(2) - (int)P(2);
    if (rem != 0.0) signal += rem * (noise_at(e, p, gen, ok) * 2 - 1 + P(3)) * weight * signal;
    return signal;
}

static double f_hunt_surface(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X, y2 = Y * Y, z2 = Z * Z, s = x2 + y2 + z2 - 13, t = 3 * x2 + y2 - 4 * z2 - 12;
    return field(P(0), -(4 * s * s * s + 27 * t * t));
}

static double f_hyperbolic_torus(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X, y2 = Y * Y, z2 = Z * Z, m = P(1) * P(1), n = P(2) * P(2);
    return field(P(0), -(x2 * x2 + 2 * x2 * y2 - 2 * x2 * z2 - 2 * (m + n) * x2 + y2 * y2 - 2 * y2 * z2 + 2 * (m - n) * y2 + z2 * z2 +
                         2 * (m + n) * z2 + (m - n) * (m - n)));
}

static double f_isect_ellipsoids(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double t[3];
    ellipsoid_terms(a, P(0), P(1), t);
    return P(3) - dmin(dmin(t[0], t[1]), t[2]) * P(2);
}

static double f_kampyle_of_eudoxus(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X, s2 = P(2) * P(2);
    return field(P(0), -((Y * Y + Z * Z) - s2 * x2 * x2 + s2 * P(1) * P(1) * x2));
}

static double f_kampyle_of_eudoxus_2d(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double px, py;
    profile(a, P(3), P(4), P(5), &px, &py);
    double x2 = px * px, s2 = P(2) * P(2);
    /* POV-Ray 3.7.0's last term is P2^2 * P1 * P2 (not P1^2) */
    return field(P(0), -(py * py - s2 * x2 * x2 + s2 * P(1) * P(2) * x2));
}

static double f_klein_bottle(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double s = X * X + Y * Y + Z * Z, m = s - 2 * Y - 1;
    return field(P(0), -((s + 2 * Y - 1) * (m * m - 8 * Z * Z) + 16 * X * Z * m));
}

static double f_kummer_surface_v1(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X, y2 = Y * Y, z2 = Z * Z;
    return field(P(0), -(x2 * x2 + y2 * y2 + z2 * z2 - x2 - y2 - z2 - x2 * y2 - x2 * z2 - y2 * z2 + 1));
}

static double f_kummer_surface_v2(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X, y2 = Y * Y, z2 = Z * Z;
    return field(P(0), -(x2 * x2 + y2 * y2 + z2 * z2 + P(1) * (x2 + y2 + z2) + P(2) * (x2 * y2 + x2 * z2 + y2 * z2) + P(3) * X * Y * Z - 1));
}

static double f_lemniscate_of_gerono(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X;
    return field(P(0), -(x2 * x2 - x2 + Y * Y + Z * Z));
}

static double f_lemniscate_of_gerono_2d(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double px, py;
    profile(a, P(3), P(4), P(5), &px, &py);
    double x2 = px * px, s2 = P(2) * P(2);
    return field(P(0), -(py * py - s2 * P(1) * P(1) * x2 + s2 * x2 * x2));
}

/* one strand of the mesh1 weave: |wrapped distance| and the wavy height */
static double weave(double along, double period, double scale, double height)
{
    double r = fmod(along, period * 2);
    if (r < 0) r += period * 2;
    r = fabs(r - period) * scale;
    return -sqrt(height * height + r * r);
}

static double f_mesh1(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double th = M_PI / P(0), ph = M_PI / P(1);
    double t = weave(X, P(0), P(2), (Y - cos(Z * ph) * P(3)) * P(4));
    t = dmax(weave(X - P(0), P(0), P(2), (Y + cos(Z * ph) * P(3)) * P(4)), t);
    t = dmax(weave(Z, P(1), P(2), (Y + cos(X * th) * P(3)) * P(4)), t);
    return -dmax(weave(Z - P(1), P(1), P(2), (Y - cos(X * th) * P(3)) * P(4)), t);
}

static double f_mitre(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X, y2 = Y * Y, z2 = Z * Z;
    return field(P(0), -(4 * x2 * (x2 + y2 + z2) - y2 * (1 - y2 - z2)));
}

static double f_nodal_cubic(const double *a, const func_env *e, int *ok) { (void)e; (void)ok; return field(P(0), -(Y * Y * Y + Z * Z * Z - 6 * Y * Z)); }
static double f_odd(const double *a, const func_env *e, int *ok) { (void)e; (void)ok; return field(P(0), cushion_poly(a)); }

static double f_ovals_of_cassini(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X, z2 = Z * Z, s = x2 + Y * Y + z2 + P(1) * P(1);
    return field(P(0), -(s * s - P(3) * P(1) * P(1) * (x2 + z2) - P(2) * P(2)));
}

static double f_paraboloid(const double *a, const func_env *e, int *ok) { (void)e; (void)ok; return field(P(0), -(X * X - Y + Z * Z)); }

static double f_parabolic_torus(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X, y2 = Y * Y, z2 = Z * Z, m = P(1) * P(1), n = P(2) * P(2);
    return field(P(0), -(x2 * x2 + 2 * x2 * y2 - 2 * x2 * Z - (m + n) * x2 + y2 * y2 - 2 * y2 * Z + (m - n) * y2 + z2 + (m + n) * Z + (m - n) * (m - n)));
}

static double f_ph(const double *a, const func_env *e, int *ok) { (void)e; (void)ok; return atan2(sqrt(X * X + Z * Z), Y); }

static double f_pillow(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X, y2 = Y * Y, z2 = Z * Z;
    return field(P(0), x2 * x2 + y2 * y2 + z2 * z2 - (x2 + y2 + z2));
}

static double f_piriform(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X;
    return -field(P(0), -((x2 * x2 - x2 * X) + Y * Y + Z * Z));
}

static double f_piriform_2d(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double px, py;
    profile(a, P(4), P(5), P(6), &px, &py);
    double x2 = px * px, s2 = P(3) * P(3);
    return field(P(0), -(py * py - P(1) * s2 * x2 * px - P(2) * s2 * x2 * x2));
}

static double f_poly4(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double y2 = Y * Y;
    double t = P(0) + P(1) * Y + P(2) * y2 + P(3) * y2 * Y + P(4) * y2 * y2;
    if (t < -5) t = -5;
    return -t + sqrt(X * X + Z * Z);
}

static double f_polytubes(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double y2 = Y * Y, rad = P(1) + P(2) * Y + P(3) * y2 + P(4) * y2 * Y + P(5) * y2 * y2, best = -10000;
    for (int i = 0; i < (int)P(0); i++) {
        double dx = X - rad * sin(2 * M_PI / P(0) * i), dz = Z - rad * cos(2 * M_PI / P(0) * i);
        best = dmax(best, -sqrt(dx * dx + dz * dz));
    }
    return -best;
}

static double f_quantum(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x = (X == 0 && Z == 0) ? 1e-6 : X;
    double r = sqrt(x * x + Z * Z), c = cos(atan2(r, Y));
    r = sqrt(r * r + Y * Y) * 2;
    double t = r * r * exp(-r * 0.33333333) * (3 * c * c - 1);
    return (t * t - 12.0) * -0.1;
}

static double f_quartic_paraboloid(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X, z2 = Z * Z;
    return field(P(0), -(x2 * x2 + z2 * z2 - Y));
}

static double f_quartic_saddle(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X, z2 = Z * Z;
    return field(P(0), -(x2 * x2 - z2 * z2 - Y));
}

static double f_quartic_cylinder(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double h = X * X + Z * Z, s2 = P(2) * P(2);
    return field(P(0), -(h * Y * Y + s2 * h - s2 * P(1) * P(1)));
}

static double f_r(const double *a, const func_env *e, int *ok) { (void)e; (void)ok; return sqrt(X * X + Y * Y + Z * Z); }

static double f_ridge(const double *a, const func_env *e, int *ok)
{
    vec3 p = v3(X, Y, Z);
    int gen = (int)P(5) & 3, octaves = (int)P(1);
    double lambda = P(0), omega = P(2), off = P(3), ridge = P(4);
    double rscale = 1.0 / dmax(ridge, 1.0 - ridge), scale = 1.0 / dmax(off, 1.0 - off);
    double resid = P(1) - octaves, l = lambda, o = omega, total = 1.0;
    double value = fabs(noise_at(e, p, gen, ok) - ridge) * rscale - off;
    for (int i = 2; i <= octaves && *ok; i++) {
        value += o * (fabs(noise_at(e, v3_scale(p, l), gen, ok) - ridge) * rscale - off);
        total += o;
        l *= lambda;
        o *= omega;
    }
    if (resid != 0.0) {
        value += o * (fabs(noise_at(e, v3_scale(p, l), gen, ok) - ridge) * rscale - off) * resid;
        total += o * resid;
    }
    return value * scale / total;
}

enum { RIDGED_OWN, RIDGED_RECORD, RIDGED_FIXED };
static struct {
    int state;
    double h, lacunarity;
} ridged; /* func_internal.h: written by one thread between renders */

void func_ridged_mf_reset(void) { ridged.state = RIDGED_OWN; }
void func_ridged_mf_record(void) { ridged.state = RIDGED_RECORD; }

int func_ridged_mf_fixed(double *h, double *lacunarity)
{
    if (ridged.state != RIDGED_FIXED) return 0;
    if (h) *h = ridged.h;
    if (lacunarity) *lacunarity = ridged.lacunarity;
    return 1;
}

static double f_ridged_mf(const double *a, const func_env *e, int *ok)
{
    vec3 p = v3(X, Y, Z);
    int gen = (int)P(5) & 3;
    double signal = P(3) - fabs(noise_at(e, p, gen, ok) * 2 - 1);
    signal *= signal;
    /* the weights' H and lacunarity: the first call's once recorded
     * (func_internal.h); past the first call's octaves POV-Ray reads beyond
     * its array, the same sequence goes on here */
    double h = P(0), lac = P(1);
    if (ridged.state == RIDGED_RECORD) {
        ridged.h = h;
        ridged.lacunarity = lac;
        ridged.state = RIDGED_FIXED;
    } else if (ridged.state == RIDGED_FIXED) {
        h = ridged.h;
        lac = ridged.lacunarity;
    }
    /* octave i weighs freq^-H = (lacunarity^-H)^i: one pow, then a
     * product per octave */
    double result = signal, step = P(2) > 1 ? pow(lac, -h) : 1.0, w = 1.0;
    for (int i = 1; i < P(2) && *ok; i++) {
        w *= step;
        p = v3_scale(p, P(1));
        double weight = signal * P(4);
        weight = weight > 1 ? 1 : (weight < 0 ? 0 : weight);
        signal = P(3) - fabs(noise_at(e, p, gen, ok) * 2 - 1);
        signal = signal * signal * weight;
        result += signal * w;
    }
    return result;
}

static double f_rounded_box(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    /* distance outside the box shrunk by the radius P0, minus P0 */
    double d[3];
    for (int i = 0; i < 3; i++) {
        double half = P(i + 1) - P(0), v = a[i];
        d[i] = dmax(v > -half ? 0 : -half - v, v < half ? 0 : v - half);
    }
    return -P(0) + sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) - 1e-6;
}

static double f_sphere(const double *a, const func_env *e, int *ok) { (void)e; (void)ok; return -P(0) + sqrt(X * X + Y * Y + Z * Z); }

static double f_spikes(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double t[3];
    ellipsoid_terms(a, P(0), P(1), t);
    double r = exp(-(X * X + Y * Y + Z * Z) * P(3)) * P(4) - t[0] - t[1] - t[2];
    return -r * P(2);
}

static double f_spikes_2d(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    return -(P(0) * cos(P(1) * X) * cos(P(2) * Z) * exp(-P(3) * (X * X + Z * Z)) - Y);
}

static double f_spiral(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double r = sqrt(X * X + Z * Z);
    double x = (X == 0 && Z == 0) ? 0.000001 : X;
    r += P(0) * atan2(Z, x) / (2 * M_PI);
    double band = fmod(r, P(0)) - P(0) * 0.5;
    double cross = section(band, Y, P(5), 1);
    double dist = sqrt(x * x + Y * Y + Z * Z);
    return -dmin(P(2) - dist, P(1) - dmin(cross, dist));
}

static double f_steiners_roman(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X, y2 = Y * Y, z2 = Z * Z;
    return field(P(0), -(x2 * y2 + x2 * z2 + y2 * z2 + X * Y * Z));
}

static double f_strophoid(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X, s2 = P(3) * P(3);
    return field(P(0), -((P(2) - X) * (Y * Y + Z * Z) - s2 * P(1) * x2 - s2 * x2 * X));
}

static double f_strophoid_2d(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double px, py;
    profile(a, P(4), P(5), P(6), &px, &py);
    double x2 = px * px, s2 = P(3) * P(3);
    return field(P(0), -((P(2) - px) * py * py - s2 * P(1) * x2 - s2 * x2 * px));
}

static double f_superellipsoid(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double ew = 2 / P(0), n = 1 / P(1);
    return 1 - pow(pow(pow(fabs(X), ew) + pow(fabs(Y), ew), P(0) * n) + pow(fabs(Z), 2 * n), P(1) * 0.5);
}

static double f_th(const double *a, const func_env *e, int *ok) { (void)e; (void)ok; return atan2(X, Z); }

static double f_torus(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double u = sqrt(X * X + Z * Z) - P(0);
    return -P(1) + sqrt(u * u + Y * Y);
}

static double f_torus2(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X, y2 = Y * Y, z2 = Z * Z, m = P(1) * P(1), n = P(2) * P(2);
    return field(P(0), -(x2 * x2 + y2 * y2 + z2 * z2 + 2 * x2 * y2 + 2 * x2 * z2 + 2 * y2 * z2 - 2 * (m + n) * x2 + 2 * (m - n) * y2 -
                         2 * (m + n) * z2 + (m - n) * (m - n)));
}

static double f_torus_gumdrop(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double x2 = X * X, y2 = Y * Y, z2 = Z * Z;
    return field(P(0), -(4 * (x2 * x2 + sq(y2 + z2)) + 17 * x2 * (y2 + z2) - 20 * (x2 + y2 + z2) + 17));
}

static double f_umbrella(const double *a, const func_env *e, int *ok) { (void)e; (void)ok; return field(P(0), -(X * X - Y * Z * Z)); }

static double f_witch_of_agnesi(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    return field(P(0), -(P(1) * (Y - 1) + (X * X + Z * Z) * Y));
}

static double f_witch_of_agnesi_2d(const double *a, const func_env *e, int *ok)
{
    (void)e; (void)ok;
    double px, py;
    profile(a, P(3), P(4), P(5), &px, &py);
    return field(P(0), -(P(1) * P(1) * py + px * px * py - P(2)));
}

static double f_noise3d(const double *a, const func_env *e, int *ok)
{
    return noise_at(e, v3(X, Y, Z), e ? e->noise_generator : 2, ok);
}

static double f_noise_generator(const double *a, const func_env *e, int *ok)
{
    return noise_at(e, v3(X, Y, Z), (int)P(0) & 3, ok);
}

typedef struct {
    const char *name;
    int params;       /* 3 + extra parameters */
    int noise;        /* needs env->noise */
    internal_fn fn;   /* NULL: not callable by number */
} internal_entry;

static const internal_entry table[FUNC_INTERNAL_COUNT] = {
    {"f_algbr_cyl1", 8, 0, f_algbr_cyl1}, {"f_algbr_cyl2", 8, 0, f_algbr_cyl2},
    {"f_algbr_cyl3", 8, 0, f_algbr_cyl3}, {"f_algbr_cyl4", 8, 0, f_algbr_cyl4},
    {"f_bicorn", 5, 0, f_bicorn}, {"f_bifolia", 5, 0, f_bifolia},
    {"f_blob", 8, 0, f_blob}, {"f_blob2", 7, 0, f_blob2},
    {"f_boy_surface", 5, 0, f_boy_surface}, {"f_comma", 4, 0, f_comma},
    {"f_cross_ellipsoids", 7, 0, f_cross_ellipsoids}, {"f_crossed_trough", 4, 0, f_crossed_trough},
    {"f_cubic_saddle", 4, 0, f_cubic_saddle}, {"f_cushion", 4, 0, f_cushion},
    {"f_devils_curve", 4, 0, f_devils_curve}, {"f_devils_curve_2d", 9, 0, f_devils_curve_2d},
    {"f_dupin_cyclid", 9, 0, f_dupin_cyclid}, {"f_ellipsoid", 6, 0, f_ellipsoid},
    {"f_enneper", 4, 0, f_enneper}, {"f_flange_cover", 7, 0, f_flange_cover},
    {"f_folium_surface", 6, 0, f_folium_surface}, {"f_folium_surface_2d", 9, 0, f_folium_surface_2d},
    {"f_glob", 4, 0, f_glob}, {"f_heart", 4, 0, f_heart},
    {"f_helical_torus", 13, 0, f_helical_torus}, {"f_helix1", 10, 0, f_helix1},
    {"f_helix2", 10, 0, f_helix2}, {"f_hex_x", 4, 0, f_hex_x},
    {"f_hex_y", 4, 0, f_hex_y}, {"f_hetero_mf", 9, 1, f_hetero_mf},
    {"f_hunt_surface", 4, 0, f_hunt_surface}, {"f_hyperbolic_torus", 6, 0, f_hyperbolic_torus},
    {"f_isect_ellipsoids", 7, 0, f_isect_ellipsoids}, {"f_kampyle_of_eudoxus", 6, 0, f_kampyle_of_eudoxus},
    {"f_kampyle_of_eudoxus_2d", 9, 0, f_kampyle_of_eudoxus_2d}, {"f_klein_bottle", 4, 0, f_klein_bottle},
    {"f_kummer_surface_v1", 4, 0, f_kummer_surface_v1}, {"f_kummer_surface_v2", 7, 0, f_kummer_surface_v2},
    {"f_lemniscate_of_gerono", 4, 0, f_lemniscate_of_gerono}, {"f_lemniscate_of_gerono_2d", 9, 0, f_lemniscate_of_gerono_2d},
    {"f_mesh1", 8, 0, f_mesh1}, {"f_mitre", 4, 0, f_mitre},
    {"f_nodal_cubic", 4, 0, f_nodal_cubic}, {"f_odd", 4, 0, f_odd},
    {"f_ovals_of_cassini", 7, 0, f_ovals_of_cassini}, {"f_paraboloid", 4, 0, f_paraboloid},
    {"f_parabolic_torus", 6, 0, f_parabolic_torus}, {"f_ph", 3, 0, f_ph},
    {"f_pillow", 4, 0, f_pillow}, {"f_piriform", 4, 0, f_piriform},
    {"f_piriform_2d", 10, 0, f_piriform_2d}, {"f_poly4", 8, 0, f_poly4},
    {"f_polytubes", 9, 0, f_polytubes}, {"f_quantum", 4, 0, f_quantum},
    {"f_quartic_paraboloid", 4, 0, f_quartic_paraboloid}, {"f_quartic_saddle", 4, 0, f_quartic_saddle},
    {"f_quartic_cylinder", 6, 0, f_quartic_cylinder}, {"f_r", 3, 0, f_r},
    {"f_ridge", 9, 1, f_ridge}, {"f_ridged_mf", 9, 1, f_ridged_mf},
    {"f_rounded_box", 7, 0, f_rounded_box}, {"f_sphere", 4, 0, f_sphere},
    {"f_spikes", 8, 0, f_spikes}, {"f_spikes_2d", 7, 0, f_spikes_2d},
    {"f_spiral", 9, 0, f_spiral}, {"f_steiners_roman", 4, 0, f_steiners_roman},
    {"f_strophoid", 7, 0, f_strophoid}, {"f_strophoid_2d", 10, 0, f_strophoid_2d},
    {"f_superellipsoid", 5, 0, f_superellipsoid}, {"f_th", 3, 0, f_th},
    {"f_torus", 5, 0, f_torus}, {"f_torus2", 6, 0, f_torus2},
    {"f_torus_gumdrop", 4, 0, f_torus_gumdrop}, {"f_umbrella", 4, 0, f_umbrella},
    {"f_witch_of_agnesi", 5, 0, f_witch_of_agnesi}, {"f_witch_of_agnesi_2d", 9, 0, f_witch_of_agnesi_2d},
    {"f_noise3d", 3, 1, f_noise3d}, {"f_pattern", 3, 0, NULL},
    {"f_noise_generator", 4, 1, f_noise_generator},
};

int func_internal_params(int n) { return n >= 0 && n < FUNC_INTERNAL_COUNT ? table[n].params : -1; }
const char *func_internal_name(int n) { return n >= 0 && n < FUNC_INTERNAL_COUNT ? table[n].name : NULL; }

/* 1 if internal(n) is implemented here (with `noise` given for the noise ones). */
static int func_internal_available(int n, int have_noise)
{
    if (n < 0 || n >= FUNC_INTERNAL_COUNT || !table[n].fn) return 0;
    return !table[n].noise || have_noise;
}

int func_internal_eval(int n, const double *a, const func_env *env, double *out)
{
    *out = 0;
    if (!func_internal_available(n, env && env->noise)) return 0;
    int ok = 1;
    double v = table[n].fn(a, env, &ok);
    if (!ok) return 0;
    *out = v;
    return 1;
}
