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

/* ---- tilings 8-24: two or more tile shapes, values split among kinds ----
 * Each kind k of n takes [k/n, (k+1)/n]. Where POV-Ray 3.7 nudges a value
 * just past a kind boundary (e.g. 2.0000001 / 3) the same constant is used,
 * so a tile's edge keeps its colour as in POV-Ray's image. */

/* Shared by 3, 8, 19, 20: the equilateral triangle of unit side folded to
 * its half (0 <= x <= 0.5); `kind` flips when the point lies in the
 * neighbouring (inverted) triangle. Returns the edge distance in [0, 1]. */
static double unit_triangle(double x, double z, int *kind)
{
    if (x == 0.0 || z / x > R3) {
        z = R3_2 - z;
        x = 0.5 - x;
        *kind = !*kind;
    }
    double d1 = 1.0 - z * 2.0 * R3;
    double d2 = 1.0 - (R3 * x - z) * R3;
    return fmax(d1, d2);
}

/* Hexagon of unit side whose centre is at (1, sqrt(3)/2) in the folded
 * frame of 9, 19, 20: the hexagon is kind 2 of 3. */
static double unit_hexagon_third(double x, double z, double nudge)
{
    double d1 = 2.0 + 2.0 * (z * R3);
    double d2 = 2.0 + 2.0 * (R3 * x + z - R3_2) * R3_2;
    return fmax(5.0 - fmin(d1, d2), nudge) / 3.0;
}

/* 8: rows of unit squares separated by rows of equilateral triangles
 * (elongated triangular tiling), period 1 x (2 + sqrt(3)). Triangles take
 * [0, 2/3] (two orientations), squares (2/3, 1]. */
static double square_triangle_tiles(vec3 p)
{
    double x = p.x - floor(p.x), z = wrap(p.z, 2.0 + R3);
    int kind = 0;
    if (z > R3_2 + 1.0) { /* second row pair: shifted by half a square */
        z -= R3_2 + 1.0;
        x += x > 0.5 ? -0.5 : 0.5;
    }
    if (x > 0.5) x = 1.0 - x;
    z -= 1.0;
    if (z > 0.0) {
        double d = unit_triangle(x, z, &kind);
        return (kind + d) / 3.0;
    }
    if (z < -0.5) z = -1.0 - z;
    double d1 = fmin(2.0 + 2.0 * R3 * fabs(x), 3.0);
    double d2 = fmin(2.0 + 2.0 * R3 * fabs(z), 3.0);
    return (5.0000001 - fmin(d1, d2)) / 3.0;
}

/* 9: hexagons and triangles (trihexagonal tiling), period 2 x 2 sqrt(3). */
static double hexa_triangle_tiles(vec3 p)
{
    double x = wrap(p.x + 0.5, 2.0), z = wrap(p.z, 2.0 * R3);
    int kind = 0;
    if (z > R3) {
        z -= R3;
        x += x < 1.0 ? 1.0 : -1.0;
    }
    if (z > R3_2) {
        z = R3 - z;
        kind = 1;
    }
    if (x > 1.0) x = 2.0 - x;
    if (R3 * x + z < R3_2) { /* triangle in the lower left corner */
        double d1 = 1.0 - z * 2.0 * R3;
        double d2 = 1.0 + (R3 * x + z - R3_2) * R3;
        return (kind + fmax(d1, d2)) / 3.0;
    }
    return unit_hexagon_third(x, z, 2.0000001);
}

/* 10: unit squares, every other row shifted by half a square. */
static double square_offset_tiles(vec3 p)
{
    double z = wrap(p.z, 2.0), x = p.x;
    if (z > 1.0) {
        x += 0.5;
        z -= 1.0;
    }
    x -= floor(x);
    return fmax(2.0 * fabs(x - 0.5), 2.0 * fabs(z - 0.5));
}

/* Distance towards the edge of a unit square (along = 0, the square in
 * [0, 1]^2) or of a 2x1 rectangle whose long side runs along x or z (the
 * frame's origin at the middle of that side's length): 0 at the centre
 * line, 1 on the edge. */
static double cell_rect(double x, double z, int along)
{
    if (along == 'x') { /* long side along x */
        x = 2.0 * (fmax(fabs(x), 0.5) - 0.5);
        z = 2.0 * fabs(z - 0.5);
    } else if (along == 'z') {
        x = 2.0 * fabs(x - 0.5);
        z = 2.0 * (fmax(fabs(z), 0.5) - 0.5);
    } else {
        x = 2.0 * fabs(x - 0.5);
        z = 2.0 * fabs(z - 0.5);
    }
    return fmax(x, z);
}

/* The 3x3 pinwheel of 11 and 12: a unit square in the middle, four 2x1
 * rectangles around it. Kind 0 square, 1 rectangles along x, 2 along z. */
static double pinwheel_cell(double x, double z)
{
    /* per cell (x + 3 z): shift to the rectangle's frame and its kind */
    static const signed char cell[9][3] = {
        {0, 1, 2}, {2, 0, 1}, {2, 0, 1}, {0, 1, 2}, {1, 1, 0},
        {2, 2, 2}, {1, 2, 1}, {1, 2, 1}, {2, 2, 2},
    };
    int i = (int)x + 3 * (int)z, kind = 2;
    if (i >= 0 && i < 9) { /* a rounded-up wrap leaves the point unshifted, as POV-Ray */
        x -= cell[i][0];
        z -= cell[i][1];
        kind = cell[i][2];
    }
    return (cell_rect(x, z, kind == 1 ? 'x' : kind == 2 ? 'z' : 0) + kind) / 3.0;
}

/* 11: pinwheel of a unit square and four 2x1 rectangles, period 3. */
static double square_rectangle_tiles(vec3 p)
{
    return pinwheel_cell(wrap(p.x, 3.0), wrap(p.z, 3.0));
}

/* 12: the same pinwheel mirrored about x = 3 and z = 3 (period 6), so the
 * rectangles turn both ways. */
static double rectangle_square_tiles(vec3 p)
{
    return pinwheel_cell(fabs(wrap(p.x, 6.0) - 3.0), fabs(wrap(p.z, 6.0) - 3.0));
}

/* 13 and 14: a square of side sqrt(2) (the unit is scaled by sqrt(2)) and
 * four bent pieces around it, folded by the mirrors x = 2, z = 2 of the
 * 4 x 4 (scaled) period. 13 has 3 kinds; 14 gives each of the four pieces
 * around the square its own kind (5 in all). */
static double square_internal_tiles(vec3 p, int five)
{
    double x = wrap(p.x * R2, 4.0) - 2.0, z = wrap(p.z * R2, 4.0) - 2.0;
    int mir_x = x < 0.0 ? 1 : 0, mir_z = z < 0.0 ? 2 : 3;
    x = fabs(x);
    z = fabs(z);
    int cell = (int)x + 2 * (int)z;
    double a;
    switch (cell) {
    case 0: { /* the central square */
        double m = fmax(2.0 * fmax(x - 0.5, 0.0), 2.0 * fmax(z - 0.5, 0.0));
        return five ? (4.000001 + m) / 5.0 : m / 3.0;
    }
    case 1:
        a = 2.0 * fabs(1.5 - x);
        if (!five) {
            double v = (2.0 + a) / 3.0;
            if (z > 0.5) v = fmax(v, (3.0 - R2 * fabs(x - z)) / 3.0);
            return v;
        }
        if (z > 0.5) a = fmax(a, 1.0 - R2 * fabs(x - z));
        return (a + mir_x) / 5.0;
    case 2:
        a = 2.0 * fabs(1.5 - z);
        if (!five) {
            double v = (1.0 + a) / 3.0;
            if (x > 0.5) v = fmax(v, (2.0 - R2 * fabs(x - z)) / 3.0);
            return v;
        }
        if (x > 0.5) a = fmax(a, 1.0 - R2 * fabs(x - z));
        return (a + mir_z) / 5.0;
    case 3:
        if (x > z) {
            a = 2.0 * fabs(1.5 - x);
            if (!five) return fmax((2.0 + a) / 3.0, (3.0 - R2 * fabs(z - x)) / 3.0);
            return (fmax(a, 1.0 - R2 * fabs(z - x)) + mir_x) / 5.0;
        }
        a = 2.0 * fabs(1.5 - z);
        if (!five) return fmax((1.0 + a) / 3.0, (2.0 - R2 * fabs(x - z)) / 3.0);
        return (fmax(a, 1.0 - R2 * fabs(x - z)) + mir_z) / 5.0;
    default: /* on the period's far edge after rounding: POV-Ray gives 0 */
        return 0.0;
    }
}

/* 15: unit squares and 2x2 squares, period 5 x 5. Small squares take
 * [0, 0.5], large ones (0.5, 1]. */
static double square_double_tiles(vec3 p)
{
    /* per cell (x + 5 z): shift to the square's centre corner and whether
     * it is a small square (small ones are shifted to their lower corner) */
    static const signed char cell[25][3] = {
        {0, 0, 1}, {2, 0, 0}, {2, 0, 0}, {4, 1, 0}, {4, 1, 0},
        {1, 2, 0}, {1, 2, 0}, {2, 1, 1}, {4, 1, 0}, {4, 1, 0},
        {1, 2, 0}, {1, 2, 0}, {3, 3, 0}, {3, 3, 0}, {4, 2, 1},
        {0, 4, 0}, {1, 3, 1}, {3, 3, 0}, {3, 3, 0}, {5, 4, 0},
        {0, 4, 0}, {2, 5, 0}, {2, 5, 0}, {3, 4, 1}, {5, 4, 0},
    };
    double x = wrap(p.x, 5.0), z = wrap(p.z, 5.0);
    int i = (int)x + 5 * (int)z;
    int small = 0;
    if (i >= 0 && i < 25) {
        x -= cell[i][0];
        z -= cell[i][1];
        small = cell[i][2];
    }
    double m;
    if (!small) { /* large: centred on the shifted origin */
        m = fmax(2.0 * (fmax(fabs(x), 0.5) - 0.5), 2.0 * (fmax(fabs(z), 0.5) - 0.5));
        return fabs(m / 2.0 + 0.50000001);
    }
    m = fmax(2.0 * fabs(x - 0.5), 2.0 * fabs(z - 0.5));
    return fabs(m / 2.0);
}

/* 16 and 17: hexagons, squares and triangles (rhombitrihexagonal tiling),
 * period (3 + sqrt(3)) x 2 (1 + sqrt(3)). 16: triangles [0, 1/3], squares
 * [1/3, 2/3], hexagons (2/3, 1]. 17 (six kinds): squares 0-2 by
 * orientation, triangles 2-3, 3-4 by orientation, hexagons (5/6, 1]. */
static double hexa_square_triangle_tiles(vec3 p, int six)
{
    const double hx = R3_2 + 1.5, pz = R3 + 1.0;
    double x = wrap(p.x + 0.5, 3.0 + R3), z = wrap(p.z, 2.0 * (1.0 + R3));
    int mir_x = 0, mir_z = 0, rot = 0;
    if (x > hx) {
        x -= hx;
        z += z < pz ? R3_2 + 0.5 : -(R3_2 + 0.5);
    }
    if (z > pz) z -= pz;
    if (z > 0.5 + R3_2) {
        z = pz - z;
        mir_z = !mir_z;
    }
    if (x > 1.0 + R3_2) {
        x = R3 + 2.0 - x;
        mir_x = !mir_x;
    }
    if (R3 * x + z < R3_2 + 2.0 && x < 0.5 + R3_2) {
        /* the left part: turn it by 60 degrees about the square's corner */
        double cx = x - (1.0 + R3_2), cz = z - (0.5 + R3_2);
        double rx = cx / 2.0 - cz * R3_2;
        double rz = cz / 2.0 + cx * R3_2;
        x = rx + (1.0 + R3_2);
        z = rz + (0.5 + R3_2);
        rot = 1;
        if (z < 0) z = -z;
        if (x > 1.0 + R3_2) {
            x = R3 + 2.0 - x;
            mir_x = !mir_x;
            mir_z = !mir_z;
        }
    }
    if (!(R3 * x + z < R3_2 + 2.0) && !(z < 0.5)) { /* hexagon */
        z = fabs(z - 0.5);
        x = fabs(x - R3_2);
        double d1 = 2.0 * z * R3;
        double d2 = (R3 * x + z) * R3 - 1.5;
        if (six) return fmax(6.0 - fmin(d1, d2), 5.000001) / 6.0;
        return fmax(3.0 - fmin(d1, d2), 2.0000001) / 3.0;
    }
    if (!(z < 0.5)) return 0.0;
    if (x > R3_2 + 0.5) { /* square */
        x -= R3_2 + 0.5;
        z -= 0.5;
        double d1 = fmax(1.0 + z * 2.0 * R3, 0.0);
        double d2 = fmax(1.0 - x * 2.0 * R3, 0.0);
        if (six) return (fmax(d1, d2) + rot * (1.000001 + ((mir_x + mir_z) % 2))) / 6.0;
        return fmax(d1, d2) / 3.0;
    }
    /* triangle */
    x = fabs(x - (R3_2 + 0.5));
    double d2 = (R3 * z + x) * R3 + 0.5;
    double d1 = 2.0 - x * 2.0 * R3;
    if (six) return (((rot + mir_x) % 2 ? 2.0 : 3.0) + fmax(d1, d2)) / 6.0;
    return fmax(d1, d2) / 3.0;
}

/* 18: pairs of 2x1 rectangles (a 2x2 square split in two) in a basket
 * weave, period 4. Rectangles along z take [0.5, 1], along x [0, 0.5]. */
static double rectangle_pair_tiles(vec3 p)
{
    static const signed char cell[16][3] = {
        /* dx, dz, along z  for cell x + 4 z */
        {0, 1, 1}, {1, 1, 1}, {3, 0, 0}, {3, 0, 0},
        {0, 1, 1}, {1, 1, 1}, {3, 1, 0}, {3, 1, 0},
        {1, 2, 0}, {1, 2, 0}, {2, 3, 1}, {3, 3, 1},
        {1, 3, 0}, {1, 3, 0}, {2, 3, 1}, {3, 3, 1},
    };
    double x = wrap(p.x, 4.0), z = wrap(p.z, 4.0);
    int i = (int)x + 4 * (int)z, along_z = 1;
    if (i >= 0 && i < 16) {
        x -= cell[i][0];
        z -= cell[i][1];
        along_z = cell[i][2];
    }
    return fabs((cell_rect(x, z, along_z ? 'z' : 'x') + along_z) / 2.0);
}

/* 19 and 20: hexagons and triangles in the snub arrangement (each hexagon
 * ringed by triangles, rows offset by half a unit per three triangle rows),
 * right- and left-handed. The period along x is 7; each band of 3 rows
 * (3 sqrt(3)/2 high) shifts x by half a unit. Triangles take [0, 2/3] by
 * orientation, hexagons (2/3, 1]. */
static double hexa_tri_tiles(vec3 p, int right)
{
    double x = p.x, z = p.z;
    int band = (int)(z / R3_2);
    band /= 3;
    if (z < 0) band -= 1;
    x += right ? band / 2.0 : -band / 2.0;
    z = wrap(z, 3.0 * R3_2);
    x = wrap(x + 7.0, 7.0);
    if (right) { /* bring the three hexagons of the period onto one */
        if (x > 4.5 && z > R3) { x -= 4.5; z -= R3_2; }
        if (x > 5.0 && z < R3_2) { x -= 5.0; z += R3; }
        if (x > 2.5 && z < R3) { x -= 2.5; z += R3_2; }
    } else {
        if (x > 2.0 && z < R3_2) { x -= 2.0; z += R3; }
        if (x > 4.5 && z < R3) { x -= 4.5; z += R3_2; }
        if (x > 2.5 && z > R3) { x -= 2.5; z -= R3_2; }
    }
    int kind = 0, row = (int)(z / R3_2);
    if (row == 2) {
        row = 1;
        z = 2.0 * R3 - z;
        kind = 1;
    }
    if (!row || x > 2.0 || z + R3 * x < R3 || R3 * x - z > R3) {
        /* a triangle of the unit triangular lattice */
        x -= floor(x);
        z = wrap(z, R3);
        if (z > R3_2) {
            z = R3 - z;
            kind = !kind;
        }
        if (x > 0.5) x = 1.0 - x;
        double d = unit_triangle(x, z, &kind);
        return (kind + d) / 3.0;
    }
    z -= R3_2;
    if (x > 1.0) x = 2.0 - x;
    return unit_hexagon_third(x, z, 2.000001);
}

/* 21: squares and triangles (snub square tiling), period 1 + sqrt(3).
 * Triangles take [0, 4/6] in four orientations, squares [4/6, 1] in two. */
static double square_tri_tiles(vec3 p)
{
    const double h = 0.5 + R3_2, per = 1.0 + R3;
    double x = wrap(p.x, per), z = wrap(p.z, per);
    int delta = 0, gamma = 0, beta = 0;
    if (z > h) {
        z = per - z;
        delta = !delta;
    }
    if (x > h) {
        x = per - x;
        delta = !delta;
        beta = 1;
    }
    /* the quarter cell still holds a mirror and a quarter turn */
    int xflop = 2.0 * x + (R3 - 1.0) * 2.0 * z / (R3 + 1.0) > R3;
    int zflop = 2.0 * z * R3 + (R3 - 3.0) * 2.0 * x / (R3 + 1.0) > R3;
    double t;
    switch (xflop + 2 * zflop) {
    case 0: gamma = 2 * beta; break;
    case 1: /* turn clockwise */
        gamma = beta ? 1 + 2 * delta : 3 - 2 * delta;
        t = x;
        x = z;
        z = h - t;
        break;
    case 2: /* turn anticlockwise */
        gamma = beta ? 3 - 2 * delta : 1 + 2 * delta;
        t = z;
        z = x;
        x = h - t;
        break;
    default: /* point symmetry */
        gamma = beta ? 0 : 2;
        x = h - x;
        z = h - z;
        break;
    }
    if (x == 0.0) z = 0.0;
    double s = z * 2.0 * R3 - R3 + x * 2.0;
    if (s < 0) { /* triangle */
        double d = fmin(-1.5 / R3 * s, 2.0 * x * R3);
        return (gamma + 1.0 - d) / 6.0;
    }
    s = fmin(s * (1.5 / R3), 1.0); /* square */
    if (delta) return fmin(fmax((6.0 - s) / 6.0, 5.000001 / 6.0), 1.0);
    return fmax(fmin((5.0 - s) / 6.0, 5.0 / 6.0), 4.000001 / 6.0);
}

/* 22: dodecagons and triangles (truncated hexagonal tiling), period
 * (2 + sqrt(3)) x (3 + 2 sqrt(3)). Triangles [0, 2/3] by orientation,
 * dodecagons (2/3, 1]. */
static double dodeca_tri_tiles(vec3 p)
{
    const double hx = 1.0 + R3_2;
    double x = wrap(p.x, 2.0 + R3), z = wrap(p.z, 3.0 + 2.0 * R3);
    int toggle = 0;
    if (z > R3 + 1.5) {
        z -= R3 + 1.5;
        x += (x < hx ? 1.0 : -1.0) * hx;
    }
    if (x > hx) x = 2.0 + R3 - x;
    if (z > hx) {
        z = 2.0 + R3 - z;
        toggle = 1;
    }
    double d2 = x - R3_2 - 0.5 + z * R3;
    if (d2 < 0.0) { /* below the 60-degree mirror: reflect across it */
        double tx = x, tz = z;
        x = (1.0 + R3) / 4.0 + 0.5 * tx - R3_2 * tz;
        z = (3.0 + R3) / 4.0 - R3_2 * tx - 0.5 * tz;
        d2 = -d2;
    }
    double d1 = z * 3.0, d4 = x * 3.0;
    double d3 = (z - R3_2 - 0.5 + x * R3) * R3;
    d2 *= R3;
    if (d3 < 0.0) return (fmax(d3, -1.0) + (1 + toggle)) / 3.0;
    double m = fmin(fmin(fmin(fmin(d1, d2), d3), d4), 1.0);
    return (3.0000001 - m) / 3.0;
}

/* 23 and 24: dodecagons, hexagons and squares (truncated trihexagonal
 * tiling), period (3 + sqrt(3)) x (3 + 3 sqrt(3)). 23: hexagons [0, 1/3],
 * squares [1/3, 2/3], dodecagons (2/3, 1]; 24 (five kinds): hexagons
 * [0, 1/5], horizontal squares [1/5, 2/5], slanted squares [3/5, 4/5] and
 * [2/5, 3/5] by orientation, dodecagons (4/5, 1]. */
static double dodeca_hex_tiles(vec3 p, int five)
{
    const double hx = 1.5 + R3_2;
    double x = wrap(p.x, 3.0 + R3), z = wrap(p.z, 3.0 + 3.0 * R3);
    int mir_x = 0, mir_z = 0;
    if (z > 1.5 * R3 + 1.5) {
        z -= 1.5 * R3 + 1.5;
        x += (x < hx ? 1.0 : -1.0) * hx;
    }
    if (x > hx) {
        x = 3.0 + R3 - x;
        mir_x = 1;
    }
    if (z > 1.0 + R3) {
        z = 2.0 + 2.0 * R3 - z;
        mir_z = 1;
    }
    if (x - R3_2 - 1.5 + z * R3 < 0.0) {
        double tx = x, tz = z;
        x = (3.0 + R3) / 4.0 + 0.5 * tx - R3_2 * tz;
        z = (3.0 + 3.0 * R3) / 4.0 - R3_2 * tx - 0.5 * tz;
    }
    double d2 = x - R3_2 - 2.5 + z * R3;
    double d1 = z * 2.0 - R3;
    double d3 = z - 1.5 * R3 - 0.5 + x * R3;
    double d4 = (x - 0.5) * 2.0;
    double n = five ? 5.0 : 3.0, v;
    if (d2 >= 0.0 && d1 >= 0.0 && d3 >= 0.0 && d4 >= 0.0) { /* dodecagon */
        v = (five ? 5.000001 : 3.000001) - fmin(fmin(fmin(fmin(d1, d2), d3), d4), 1.0);
        return v / n;
    }
    double d5 = 2.0 * z - 2.0 * R3 - 1.0;
    if (d5 >= 0) { /* square on the horizontal edge */
        return (2.0 - fmin(d5, -d4)) / n;
    }
    double d6 = R3 * x - z - R3_2 + 0.5, d7 = d6 - 2.0;
    switch ((d6 >= 0 ? 0 : 1) + (d7 >= 0.0 ? 2 : 0)) {
    case 1: /* hexagon on the left */
        v = 1.0 - fmin(fmin(fmin(-d6, -d3), -d5), 1.0);
        break;
    case 2: /* hexagon below */
        v = 1.0 - fmin(fmin(d7, -d1), 1.0);
        break;
    default: /* slanted square */
        v = fmin(fmin(d6, -d2), -d7);
        v = five ? (mir_z + mir_x) % 2 + 3.0 - v : 2.0 - v;
        break;
    }
    return v / n;
}

/* ---- 25-27: Penrose tilings (aperiodic), by recursive substitution ----
 * The plane about the origin is folded by its 10-fold (5 rotations and a
 * mirror) symmetry into a 36-degree wedge, scaled down by phi^2 per
 * inflation level until it lies in the first-level tile, then descended
 * through the substitution rules (Robinson triangles) back down to the
 * tile the point lies in. The edge-distance scales (5.55, 4.46) are the
 * empirical factors POV-Ray 3.7 uses (pattern.cpp, "just an empiric
 * value"), kept so the grout width agrees. */
#define PHI 1.6180339887498948482045868343656
#define INVPHI 0.61803398874989484820458683436564
#define SQRPHI 2.6180339887498948482045868343656
#define INVSQRPHI 0.38196601125010515179541316563436
#define SIN18 0.30901699437494742410229341718282
#define SIN36 0.58778525229247312916870595463907
#define SIN54 0.80901699437494742410229341718282
#define SIN72 0.95105651629515357211643933337938
#define SIN108 SIN72
#define SIN144 SIN36
#define SIN162 SIN18
#define COS18 SIN72
#define COS36 SIN54
#define COS72 SIN18
#define COS108 (-COS72)
#define COS144 (-COS36)
#define COS162 (-COS18)
#define TAN18 0.32491969623290632615587141221513
#define TAN36 0.72654252800536088589546675748062
#define TAN54 1.3763819204711735382072095819109
#define TAN72 3.0776835371752534025702905760369
#define TAN108 (-TAN72)
#define TAN126 (-TAN54)
#define TAN144 (-TAN36)
#define TAN162 (-TAN18)
#define PEN_EPS 1e-6 /* keeps kinds apart, POV-Ray's TILING_EPSILON */

static double max3(double a, double b, double c) { return fmax(a, fmax(b, c)); }

/* rotate (x, z) by the angle with cosine c and sine s, clockwise */
static void turn(double *x, double *z, double c, double s)
{
    double rx = *x * c + *z * s, rz = *z * c - *x * s;
    *x = rx;
    *z = rz;
}

/* Fold into the wedge 0 <= angle <= 36 degrees by the pentagonal mirrors
 * (r = |(x, z)|). */
static void pentagon_fold(double *x, double *z, double r)
{
    *z = fabs(*z);
    if (*x < r * COS36) {
        if (*x < r * COS108)
            turn(x, z, COS144, SIN144);
        else
            turn(x, z, COS72, SIN72);
        *z = fabs(*z);
    }
}

static double half_dart(double x, double z, int depth, int rhombs);

/* Half kite (or, for P3, the half rhombs it is split into): kind 1 of 2
 * (darts / narrow rhombs above 0.5, kites / wide rhombs below). */
static double half_kite(double x, double z, int depth, int rhombs)
{
    z = fabs(z);
    while (depth > 0) {
        if (z < (x - INVPHI) * TAN144) return half_dart(x * PHI, z * PHI, depth - 1, rhombs);
        x -= COS36;
        z -= SIN36;
        double rx = x * COS108 - z * SIN108, rz = z * COS108 + x * SIN108;
        x = rx * PHI;
        z = fabs(rz * PHI);
        depth--;
    }
    if (rhombs) {
        if (z < (x - INVPHI) * TAN72) {
            double d1 = fabs(SIN72 * (x - INVPHI) - COS72 * z) * 5.55;
            double d2 = fabs(SIN108 * (x - 1) - COS108 * z) * 5.55;
            return max3(1.0 - d1 / 2, 1.0 - d2 / 2, 0.5 + PEN_EPS);
        }
        double d1 = fabs(z) * 5.55;
        double d2 = fabs(SIN72 * (x - INVPHI) - COS72 * z) * 5.55;
        return fmin(max3(0.5 - d1 / 2, 0.5 - d2 / 2, 0.0), 0.5 - PEN_EPS);
    }
    double d1 = fabs(SIN36 * x - COS36 * z) * 4.46;
    double d2 = fabs(SIN108 * (x - 1) - COS108 * z) * 4.46;
    return fmin(max3(0.5 - d1 / 2, 0.5 - d2 / 2, 0.0), 0.5 - PEN_EPS);
}

static double half_dart(double x, double z, int depth, int rhombs)
{
    z = fabs(z);
    while (depth > 0) {
        if (z < (x - INVPHI) * TAN108) {
            turn(&x, &z, COS36, SIN36);
            return half_kite(x * PHI, z * PHI, depth - 1, rhombs);
        }
        x -= 1;
        turn(&x, &z, COS144, SIN144);
        x *= PHI;
        z = fabs(z * PHI);
        depth--;
    }
    if (rhombs) {
        double d1 = fabs(SIN36 * x - COS36 * z) * 5.55;
        double d2 = fabs(SIN144 * (x - 1) - COS144 * z) * 5.55;
        return fmin(max3(0.5 - d1 / 2, 0.5 - d2 / 2, 0.0), 0.5 - PEN_EPS);
    }
    double d1 = fabs(z) * 4.46;
    double d2 = fabs(SIN144 * (x - 1) - COS144 * z) * 4.46;
    return max3(1.0 - d1 / 2, 1.0 - d2 / 2, 0.5 + PEN_EPS);
}

/* 26 (kite and dart, P2: five darts form a star at the origin) and 27
 * (rhombs, P3: five wide rhombs at the origin in a decagon of narrow
 * ones). */
static double penrose_tiles(vec3 p, int rhombs)
{
    double x = p.x, z = p.z, r = sqrt(x * x + z * z);
    if (r <= 1e-10) return 1.0; /* POV-Ray's EPSILON */
    pentagon_fold(&x, &z, r);
    if (rhombs) {
        x *= INVPHI;
        z *= INVPHI;
    }
    double dist = fabs(SIN108 * x - COS108 * z) / COS18;
    int depth = (int)ceil(log(dist) / log(SQRPHI));
    if (depth < 0) depth = 0;
    x *= pow(INVSQRPHI, depth);
    z *= pow(INVSQRPHI, depth);
    if (depth % 2) {
        turn(&x, &z, COS36, SIN36);
        z = fabs(z);
    }
    return half_kite(x, z, 2 * depth, rhombs);
}

/* 25: Penrose P1 (pentagons, stars, boats, diamonds); six kinds: three
 * pentagon kinds by their neighbourhood, star, boat, diamond (k/6). */
static double p1_pentagon1(double x, double z, int depth);
static double p1_pentagon2(double x, double z, int depth, int in_quad);
static double p1_pentagon3(double x, double z, int depth, int in_wedge);
static double p1_star(double x, double z, int depth);
static double p1_boat(double x, double z, int depth, int in_wedge);
static double p1_diamond(double x, double z, int depth, int side_a);

static void p1_fold(double *x, double *z) { pentagon_fold(x, z, sqrt(*x * *x + *z * *z)); }
/* distance from the pentagon's edge (inradius 0.5 / tan 36) */
static double p1_pentagon_dist(double x) { return fabs(x - 0.5 / TAN36) * 5.55 * INVPHI; }
/* the value for kind k (1-based) from an edge distance, kept inside its band */
static double p1_band(int k, double d, double lo)
{
    return fmin(fmax(k / 6.0 - d / 6, lo), k / 6.0 - PEN_EPS);
}

static double p1_pentagon1(double x, double z, int depth)
{
    z = fabs(z);
    p1_fold(&x, &z);
    if (depth > 0) {
        if (z < (x - 0.5 / TAN36) * TAN54 + 0.5)
            return p1_pentagon2((x - 0.5 / TAN36 - INVPHI * 0.5 * COS72 / SIN36) * PHI, z * PHI, depth - 1, 0);
        turn(&x, &z, COS36, SIN36);
        return p1_star(x * PHI, z * PHI, depth - 1);
    }
    return p1_band(1, p1_pentagon_dist(x), 0.0);
}

static double p1_pentagon2(double x, double z, int depth, int in_quad)
{
    z = fabs(z);
    if (depth > 0) {
        if (in_quad) {
            if (z < (x - INVSQRPHI * 0.5 / SIN36) * TAN54)
                return p1_pentagon1((x - 0.5 / SIN36) * PHI, z * PHI, depth - 1);
            if (z < (x - INVSQRPHI * 0.5 / SIN36) * TAN162)
                return p1_diamond(-x * PHI, z * PHI, depth - 1, 1);
            double rx = x * COS108 - z * SIN108 + INVPHI * 0.5 / SIN36;
            double rz = z * COS108 + x * SIN108;
            return p1_pentagon2(rx * PHI, rz * PHI, depth - 1, 1);
        }
        if (z < (x + 0.5 / SIN36) * TAN18)
            return p1_diamond((x + 0.5 / SIN36 - INVSQRPHI * 0.5 / SIN36) * PHI, z * PHI, depth - 1, 0);
        double rx = -(x * COS36 + z * SIN36) - COS72 * 0.5 / SIN36;
        double rz = (z * COS36 - x * SIN36) - SIN72 * 0.5 / SIN36;
        return p1_pentagon3(rx * PHI, rz * PHI, depth - 1, 0);
    }
    p1_fold(&x, &z);
    return p1_band(2, p1_pentagon_dist(x), 1.0 / 6 + PEN_EPS);
}

static double p1_pentagon3(double x, double z, int depth, int in_wedge)
{
    z = fabs(z);
    if (depth > 0) {
        if (in_wedge && x > INVSQRPHI * 0.5 * COS72 / SIN36)
            return p1_pentagon2(-(x - INVSQRPHI * 0.5 * COS72 / SIN36 - INVPHI * 0.5 / TAN36) * PHI, z * PHI, depth - 1, 1);
        if (!in_wedge && x < 0.5 * COS108 / SIN36) {
            double rx = x * COS144 + z * SIN144 - 0.5 / SIN36;
            double rz = z * COS144 - x * SIN144;
            return p1_pentagon2(rx * PHI, rz * PHI, depth - 1, 0);
        }
        if (!in_wedge && z > (x - INVSQRPHI * 0.5 / SIN36) * TAN126) {
            double rx = -(x * COS36 - z * SIN36) - COS72 * 0.5 / SIN36;
            double rz = (z * COS36 + x * SIN36) - SIN72 * 0.5 / SIN36;
            return p1_pentagon3(rx * PHI, rz * PHI, depth - 1, 0);
        }
        return p1_boat(x * PHI, z * PHI, depth - 1, in_wedge);
    }
    p1_fold(&x, &z);
    return p1_band(3, p1_pentagon_dist(x), 2.0 / 6 + PEN_EPS);
}

static double p1_star(double x, double z, int depth)
{
    z = fabs(z);
    if (depth > 0) {
        if (x < INVPHI * 0.5 / TAN36) return p1_pentagon1(x * PHI, z * PHI, depth - 1);
        return p1_pentagon3(-(x - INVPHI / TAN36) * PHI, z * PHI, depth - 1, 1);
    }
    double d = fabs(SIN162 * (x - PHI * 0.5 / SIN36) - COS162 * z) * 5.55 * INVPHI;
    return p1_band(4, d, 3.0 / 6 + PEN_EPS);
}

static double p1_boat(double x, double z, int depth, int in_wedge)
{
    z = fabs(z);
    if (depth > 0) {
        if (in_wedge && x > PHI * 0.5 * COS108 / SIN36) return p1_pentagon1(-x * PHI, z * PHI, depth - 1);
        double rx = x, rz = z;
        if (!in_wedge) {
            rx = x * COS72 - z * SIN72;
            rz = z * COS72 + x * SIN72;
        }
        rx += 0.5 / SIN36;
        return p1_pentagon3(rx * PHI, rz * PHI, depth - 1, 1);
    }
    double d1 = fabs(x - INVPHI * 0.5 * COS72 / SIN36) * 5.55 * INVPHI;
    x = -x;
    p1_fold(&x, &z);
    double d2 = fabs(SIN162 * (x - PHI * 0.5 / SIN36) - COS162 * z) * 5.55 * INVPHI;
    return fmin(max3(5.0 / 6 - d1 / 6, 5.0 / 6 - d2 / 6, 4.0 / 6 + PEN_EPS), 5.0 / 6 - PEN_EPS);
}

static double p1_diamond(double x, double z, int depth, int side_a)
{
    z = fabs(z);
    if (depth > 0) {
        if (side_a) return p1_pentagon1(x * PHI, z * PHI, depth - 1);
        return p1_pentagon3(x * PHI, z * PHI, depth - 1, 1);
    }
    double d = fabs(SIN18 * (x + INVPHI * 0.5 / SIN36) - COS18 * z) * 5.55 * INVPHI;
    return p1_band(6, d, 5.0 / 6 + PEN_EPS);
}

static double penrose1_tiles(vec3 p)
{
    double x = p.x, z = p.z, r = sqrt(x * x + z * z);
    if (r <= 1e-10) return 1.0;
    pentagon_fold(&x, &z, r);
    double dist = x * 2.0 * TAN36;
    int depth = (int)ceil(log(dist) / log(SQRPHI * SQRPHI));
    if (depth < 0) depth = 0;
    x *= pow(INVSQRPHI * INVSQRPHI, depth);
    z *= pow(INVSQRPHI * INVSQRPHI, depth);
    return p1_pentagon1(x, z, 4 * depth);
}


double shade_tiling_value(int n, vec3 p)
{
    /* cell indices are ints: beyond 1e9 units (and for NaN) they would
     * overflow; POV-Ray's result is undefined there, this gives 0 */
    if (!(fabs(p.x) < 1e9 && fabs(p.z) < 1e9)) return 0.0;
    switch (n) {
    case 2: return hexagon_tiles(p);
    case 3: return triangle_tiles(p);
    case 4: return lozenge_tiles(p);
    case 5: return rhombus_tiles(p);
    case 6: return rectangle_tiles(p);
    case 7: return octagon_square_tiles(p);
    case 8: return square_triangle_tiles(p);
    case 9: return hexa_triangle_tiles(p);
    case 10: return square_offset_tiles(p);
    case 11: return square_rectangle_tiles(p);
    case 12: return rectangle_square_tiles(p);
    case 13: return square_internal_tiles(p, 0);
    case 14: return square_internal_tiles(p, 1);
    case 15: return square_double_tiles(p);
    case 16: return hexa_square_triangle_tiles(p, 0);
    case 17: return hexa_square_triangle_tiles(p, 1);
    case 18: return rectangle_pair_tiles(p);
    case 19: return hexa_tri_tiles(p, 1);
    case 20: return hexa_tri_tiles(p, 0);
    case 21: return square_tri_tiles(p);
    case 22: return dodeca_tri_tiles(p);
    case 23: return dodeca_hex_tiles(p, 0);
    case 24: return dodeca_hex_tiles(p, 1);
    case 25: return penrose1_tiles(p);
    case 26: return penrose_tiles(p, 0);
    case 27: return penrose_tiles(p, 1);
    default: return square_tiles(p);
    }
}
