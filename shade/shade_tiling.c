/* shade_tiling.c - POV-Ray 3.7's tiling pattern (tilings 1-7: square,
 * hexagon, triangle, lozenge, rhombus, rectangle, octagon-square).
 *
 * Semantics from POV-Ray 3.7's documentation and pattern.cpp (J. Grimbert's
 * tilings): a point of the x-z plane is folded by the tiling's symmetries
 * (periodic wrap, mirrors) into one fundamental cell, where the value is the
 * distance towards the tile's edge (0 at its centre, 1 on the edge),
 * divided among the tile kinds: kind k of n takes [k/n, (k+1)/n]. The folds
 * are done in the order POV-Ray does them, so values agree to rounding
 * (tests/test_pattern.c compares every pixel with POV-Ray's image). */
#include "shade_tiling.h"
#include <math.h>

#define R3 1.7320508075688772935274463415059     /* sqrt(3) */
#define R3_2 0.86602540378443864676372317075294  /* sqrt(3)/2 */
#define R2 1.4142135623730950488016887242097     /* sqrt(2) */
#define R2_2 0.70710678118654752440084436210485  /* sqrt(2)/2 */

static double clamp01(double v) { return v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v); }
/* v wrapped into [0, period) */
static double wrap(double v, double period) { return v - period * floor(v / period); }

/* 1: unit squares; value = Chebyshev distance from the square's centre. */
static double square_tiles(vec3 p)
{
    double x = fabs(p.x), z = fabs(p.z);
    x = 2.0 * fabs(x - floor(x) - 0.5);
    z = 2.0 * fabs(z - floor(z) - 0.5);
    return fmax(x, z);
}

/* 2: regular hexagons of unit side, in a 3 x sqrt(3) period. */
static double hexagon_tiles(vec3 p)
{
    double x = wrap(p.x + 0.5, 3.0), z = wrap(p.z, R3);
    if (z > R3_2) z = R3 - z;          /* mirror about the half-period line */
    if (x > 1.5) {                     /* second hexagon column: shift and mirror */
        x -= 1.5;
        z = R3_2 - z;
    }
    if (R3 * x + z < R3_2) {           /* corner of the neighbouring hexagon */
        x = 0.5 - x;
        z = R3_2 - z;
    }
    if (x > 1.0) x = 2.0 - x;
    double d_flat = 1.0 - z / R3_2;                   /* towards the flat edge */
    double d_slant = 1.0 - (R3 * x + z - R3_2) / R3;  /* towards the slanted edge */
    return clamp01(fmax(d_flat, d_slant));
}

/* 3: equilateral triangles of unit side; upward and downward ones are the
 * two kinds. */
static double triangle_tiles(vec3 p)
{
    double x = p.x - floor(p.x), z = wrap(p.z, R3);
    int kind = 0;
    if (z > R3_2) {
        z = R3 - z;
        kind = !kind;
    }
    if (x > 0.5) x = 1.0 - x;
    if (x == 0.0) {
        z = R3_2 - z;
        x = 0.5;
    } else if (z / x > R3) {          /* above the slanted edge: the other triangle */
        z = R3_2 - z;
        x = 0.5 - x;
        kind = !kind;
    }
    double d1 = 1.0 - z * 2.0 * R3;
    double d2 = 1.0 - (R3 * x - z) * R3;
    return kind / 2.0 + 0.5 * fmax(d1, d2);
}

/* The lozenge distance in its fundamental cell (shared by 4 and 5). */
static double lozenge_cell(double x, double z)
{
    if (2.0 * z > R3_2) {
        z = R3_2 - z;
        x = 1.5 - x;
    }
    if (x > 0.75) x -= 1.0;
    if (x != 0.0 && z / x > R3) {
        z = R3_2 - z;
        x = 0.5 - x;
    }
    double d1 = 1.0 - z * 4.0 * R3 / 3.0;
    double d2 = 1.0 - fabs(R3 * x - z) * R3 * 2.0 / 3.0;
    return fmax(d1, d2);
}

/* 4: 60-degree lozenges of unit side, all one orientation. */
static double lozenge_tiles(vec3 p)
{
    double x = p.x - floor(p.x), z = wrap(p.z, R3);
    if (z > R3_2) {
        z -= R3_2;
        x += 0.5;
    }
    return lozenge_cell(x, z);
}

/* 5: lozenges in three orientations (tumbling blocks); each orientation is
 * a kind. */
static double rhombus_tiles(vec3 p)
{
    double x = wrap(p.x + 0.5, 3.0), z = wrap(p.z, R3);
    int kind = 0;
    if (z > R3_2) {
        z = R3 - z;
        kind = 2 - kind;
    }
    if (x > 1.5) {
        x -= 1.5;
        z = R3_2 - z;
        kind = 2 - kind;
    }
    if (x < 0.5) {
        x = 1.0 - x;
        kind = 2 - kind;
    }
    x -= 0.5;
    if (x == 0.0 || z / x > R3) {
        /* the upright lozenge: rotate it by -60 degrees onto a horizontal one */
        double rx = x / 2.0 + z * R3_2;
        double rz = z / 2.0 - x * R3_2;
        x = rx;
        z = rz;
        kind = 1;
    }
    double v = lozenge_cell(x, z) / 3.0 + kind / 3.0;
    return clamp01(v);
}

/* 6: 2x1 rectangles in a basket weave of period 4 x 4; horizontal and
 * vertical rectangles are the two kinds. Each unit cell is mapped to the
 * rectangle it belongs to: (dx, dz) moves the point next to the long axis'
 * half-cell origin, `upright` tells the orientation. */
static double rectangle_tiles(vec3 p)
{
    static const signed char shift[16][3] = {
        /* dx, dz, upright  for cell index x + 4 z */
        {0, 1, 1}, {2, 0, 0}, {2, 0, 0}, {3, 0, 1},
        {0, 1, 1}, {1, 2, 1}, {3, 1, 0}, {3, 1, 0},
        {0, 2, 0}, {1, 2, 1}, {2, 3, 1}, {4, 2, 0},
        {1, 3, 0}, {1, 3, 0}, {2, 3, 1}, {3, 4, 1},
    };
    double x = wrap(p.x, 4.0), z = wrap(p.z, 4.0);
    int cell = (x >= 0.0 && x < 4.0 && z >= 0.0 && z < 4.0) ? (int)x + (int)z * 4 : -1;
    double kind = 1.0; /* NaN, or rounding onto the period's end: unshifted, as POV-Ray */
    if (cell >= 0) {
        x -= shift[cell][0];
        z -= shift[cell][1];
        kind = shift[cell][2];
    }
    if (kind == 1.0) {
        x = 2.0 * fabs(x - 0.5);
        z = 2.0 * (fmax(fabs(z), 0.5) - 0.5);
    } else {
        x = 2.0 * (fmax(fabs(x), 0.5) - 0.5);
        z = 2.0 * fabs(z - 0.5);
    }
    return fabs(fmax(x, z) / 2.0 + kind / 2.0);
}

/* 7: regular octagons and squares (truncated square tiling), period
 * 1 + sqrt(2). Squares take [0, 0.5], octagons (0.5, 1]. */
static double octagon_square_tiles(vec3 p)
{
    double x = fabs(wrap(p.x, R2 + 1.0) - (R2_2 + 0.5));
    double z = fabs(wrap(p.z, R2 + 1.0) - (R2_2 + 0.5));
    if (z > x) {
        double t = x;
        x = z;
        z = t;
    }
    if (x + z < R2_2) return (x + z) / R2;  /* the square between four octagons */
    double d1 = 1.0 - z;
    double d2 = (R2 + R2_2 - (x + z)) / R2;
    return fmax(0.500000000001, fmax(d1, d2)); /* POV-Ray keeps octagons just above 0.5 */
}

int tiling_supported(int n) { return n >= 1 && n <= 7; }

double tiling_value(int n, vec3 p)
{
    switch (n) {
    case 2: return hexagon_tiles(p);
    case 3: return triangle_tiles(p);
    case 4: return lozenge_tiles(p);
    case 5: return rhombus_tiles(p);
    case 6: return rectangle_tiles(p);
    case 7: return octagon_square_tiles(p);
    case 1: return square_tiles(p);
    default: return 0.0;
    }
}
