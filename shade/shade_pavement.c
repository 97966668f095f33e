/* shade_pavement.c - POV-Ray 3.7's `pavement` pattern: the plane x-z paved
 * with polyforms (polyiamonds, polyominoes, polyhexes) of 1 to 6 cells,
 * the grout between tiles at value 1, the tiles' inside at 0.
 *
 * Semantics from POV-Ray 3.7's documentation (pavement: number_of_sides 3,
 * 4 or 6, number_of_tiles, pattern, exterior, interior, form; all default
 * to the triangle, 1 tile, pattern 1, 0, 0, 0) and pattern.cpp (J.
 * Grimbert's pavement, functions trigonal/tetragonal/hexagonal): the plane
 * is cut into lattice cells (unit squares; equilateral triangles of unit
 * side, a hexagon being six of them around a vertex), each cell's integer
 * position is folded onto one period of the chosen paving, and a per-cell
 * code says which of the cell's edges are tile borders and which corners
 * need rounding or cutting. The value is the distance towards the nearest
 * border edge (1 on it, 0 half a cell away), adjusted at corners by
 * `interior` (concave corners: 0 sharp, 1 cut, 2 round), `exterior`
 * (convex corners, squares and triangles only: 0 sharp, 1 cut, 2 round) and
 * `form` (cells where a one-cell-wide tile turns: 0 sharp, 1 cut, 2 round;
 * 3 none).
 *
 * Which polyform and which arrangement `pattern N` names is POV-Ray's own
 * numbering, a fact we must match: the per-cell codes (shade/pavement_cells.txt,
 * one row per pattern number, made into C tables at build time by
 * shade/pavement_tables.cmake) are measured from
 * POV-Ray 3.7.0's renders of every paving by scripts/gen_pavement.py
 * (borders and corners read off 16-bit renders at several interior /
 * exterior / form settings, each code checked against the renders through
 * a copy of the cell functions below); rerun it to remake the data file.
 * Code bits, squares: 1 top, 2 right, 4 bottom, 8 left edge is a border;
 * 0x10 top-left, 0x20 top-right, 0x40 bottom-right, 0x80 bottom-left
 * concave corner. Triangles (folded to point up, vertices L (0,0),
 * R (1,0), T (1/2, sqrt(3)/2)): 1 edge L-T, 2 edge R-T, 4 edge L-R are
 * borders; 0x80 keeps all three corners from being concave;
 * 0x10/0x20/0x40 with 0x100/0x200/0x400 mark the turning cells `form`
 * bends; for hexagons 0x1000/0x2000/0x4000 force the concave corner at
 * R/L/T. */
#include "shade_pavement.h"
#include <math.h>

/* the measured cell codes: sq_monomino .. sq_hexomino, tri_moniamond ..
 * tri_hexiamond, hex_monohex .. hex_pentahex */
#include "shade_pavement_tables.h"

#define R3 1.7320508075688772935274463415059    /* sqrt(3) */
#define R3_2 0.86602540378443864676372317075294 /* sqrt(3)/2 */

/* a mod n in [0, n) */
static long pmod(long a, long n)
{
    long r = a % n;
    return r < 0 ? r + n : r;
}

/* ---------------------------------------------------------------- squares */

/* Fold the cell (xv, zv) of the square lattice onto the paving's period
 * and return its code; -1 where the pattern number does not exist. Each
 * period is a table row of `w` cells per line (w = 0: one line, the rows
 * being sheared copies of each other). */
static int square_code(int tiles, int num, long xv, long zv)
{
    int n = num - 1, w = 0;
    switch (tiles) {
    case 2: return sq_domino[0][pmod(zv, 2)];
    case 3:
        if (n < 0 || n >= 2) return -1;
        return sq_tromino[n][pmod(xv, 3) + 3 * pmod(zv, 2)];
    case 4:
        if (n < 0 || n >= 5) return -1;
        return sq_tetromino[n][pmod(xv, 4) + 4 * pmod(zv, 4)];
    case 5:
        if (n < 0 || n >= 12) return -1;
        switch (n) {
        case 0: case 1: xv = pmod(xv, 5); zv = pmod(zv, 2); break;
        case 2: case 9: case 10:
            zv = pmod(zv, 10);
            xv = pmod(xv + (n == 10 ? 4 : 3) * (zv / 2), 5);
            zv = pmod(zv, 2);
            break;
        case 3: case 4: zv = pmod(zv, 5); xv = pmod(xv + 2 * zv, 5); zv = 0; break;
        case 5: case 6: case 8: zv = pmod(zv, 10); xv = pmod(xv + zv, 10); zv = 0; break;
        case 7: zv = pmod(zv, 10); xv = pmod(xv + 3 * zv, 10); zv = 0; break;
        default: zv = pmod(zv, 10); xv = pmod(xv + 8 * zv, 10); zv = 0; break; /* 11 */
        }
        return sq_pentomino[n][xv + zv * 5];
    case 6:
        if (n < 0 || n >= 35) return -1;
        switch (n) {
        case 0: case 1: case 2: case 3: case 5: case 6: case 8: case 9:
            xv = pmod(xv, 6); zv = pmod(zv, 2); w = 6; break;
        case 4: case 7: case 19: case 20:
            zv = pmod(zv, 6); xv = pmod(xv + 5 * zv, 6); break;
        case 11: case 18: case 27:
            zv = pmod(zv, 6); xv = pmod(xv + zv, 6); break;
        case 10: case 12: case 21: case 22: case 24: case 25: case 26:
            xv = pmod(xv, 4); zv = pmod(zv, 3); w = 4; break;
        case 13: case 32:
            zv = pmod(zv, 4); xv = pmod(xv, 3); w = 3; break;
        case 14:
            zv = pmod(zv, 6); xv = pmod(xv + 2 * (zv / 2), 3); zv = pmod(zv, 2); w = 3; break;
        case 15:
            xv = pmod(xv, 6); zv = pmod(zv + xv / 2, 3); xv = pmod(xv, 2); w = 2; break;
        case 16: case 17:
            zv = pmod(zv, 12); xv = pmod(xv + zv / 2, 6); zv = pmod(zv, 2); w = 6; break;
        case 23: case 28:
            zv = pmod(zv, 12); xv = pmod(xv + 4 * (zv / 2), 6); zv = pmod(zv, 2); w = 6; break;
        case 29: case 30:
            zv = pmod(zv, 4); xv = pmod(xv + 3 * (zv / 2), 6); zv = pmod(zv, 2); w = 6; break;
        case 31:
            zv = pmod(zv, 3); xv = pmod(xv + 4 * zv, 6); break;
        case 33:
            zv = pmod(zv, 12); xv = pmod(xv + 7 * zv, 12); break;
        default: /* 34 */
            zv = pmod(zv, 6); xv = pmod(xv + 2 * (zv / 3), 4); zv = pmod(zv, 3); w = 4; break;
        }
        return sq_hexomino[n][xv + zv * w];
    default: /* one tile (POV-Ray: also any other count) */
        return sq_monomino[0][0];
    }
}

/* The four corners of a square cell: position and code bit. */
static const struct { double x, y; int bit; } sq_corner[4] = {
    {0, 1, 0x10}, {1, 1, 0x20}, {1, 0, 0x40}, {0, 0, 0x80},
};

/* Value inside a square cell from its code; (x, y) in [0, 1)^2. */
static double square_cell(int how, double x, double y, const shade_pavement_params *pv)
{
    /* `form`: a cell with two adjacent border edges and the opposite
     * corner concave is where a one-cell-wide tile turns; its value is
     * measured from that opposite corner (the masks are the two edges plus
     * that corner's bit) */
    static const int turn_mask[4] = {0x16, 0x2C, 0x49, 0x83}; /* corners TL, TR, BR, BL */
    if (pv->form >= 0 && pv->form <= 2) {
        for (int c = 0; c < 4; c++) {
            if ((how & turn_mask[c]) != turn_mask[c]) continue;
            double u = 2.0 * fabs(x - sq_corner[c].x), v = 2.0 * fabs(y - sq_corner[c].y);
            if (pv->form == 2) return fmin(fabs(sqrt(u * u + v * v) - 1.0), 1.0);
            if (pv->form == 1) return fmin(fabs(u + v - 1.0), 1.0);
            return fmax(fmax(u - 1.0, v - 1.0), fmin(1.0 - u, 1.0 - v));
        }
    }
    double r = 0.0;
    if (how & 0x01) r = fmax(r, 2.0 * y - 1.0);
    if (how & 0x02) r = fmax(r, 2.0 * x - 1.0);
    if (how & 0x04) r = fmax(r, 1.0 - 2.0 * y);
    if (how & 0x08) r = fmax(r, 1.0 - 2.0 * x);
    /* concave corners (`interior`; any value but 1 and 2 is sharp) */
    for (int c = 0; c < 4; c++) {
        if (!(how & sq_corner[c].bit)) continue;
        double u = 2.0 * fabs(x - sq_corner[c].x), v = 2.0 * fabs(y - sq_corner[c].y);
        if (pv->interior == 2) r = fmax(r, 1.0 - sqrt(u * u + v * v));
        else if (pv->interior == 1) r = fmax(r, 1.0 - (u + v));
        else r = fmax(r, fmin(1.0 - u, 1.0 - v));
    }
    /* convex corners (`exterior`): where two border edges meet, in the
     * quarter of the cell at that corner */
    static const struct { int mask; double x, y; } convex[4] = {
        {0x06, 1, 0}, {0x0C, 0, 0}, {0x09, 0, 1}, {0x03, 1, 1},
    };
    if (pv->exterior == 1 || pv->exterior == 2) {
        for (int c = 0; c < 4; c++) {
            if ((how & convex[c].mask) != convex[c].mask) continue;
            if (pv->exterior == 1) {
                double u = 2.0 * fabs(x - convex[c].x), v = 2.0 * fabs(y - convex[c].y);
                r = fmax(r, fmin(2.0 - (u + v), 1.0));
            } else {
                double a = 2.0 * x - 1.0, b = 2.0 * y - 1.0;
                int in_x = convex[c].x ? a >= 0.0 : a <= 0.0, in_y = convex[c].y ? b >= 0.0 : b <= 0.0;
                if (in_x && in_y) {
                    r = fmax(r, fmin(sqrt(a * a + b * b), 1.0));
                    break; /* one quarter */
                }
            }
        }
    }
    return r;
}

/* -------------------------------------------------------------- triangles */

/* Fold a point onto the upward unit triangle of the triangular lattice:
 * (x, z) becomes its position in that triangle, (xv, zv) the cell (twice
 * the lattice row/column, odd for the half-shifted rows and the downward
 * triangles, which are turned by 180 degrees onto the upward one). */
static void tri_fold(double *px, double *pz, long *pxv, long *pzv)
{
    double x = *px, z = *pz;
    long xv = (long)floor(x), zv = (long)floor(z / R3);
    x -= xv;
    z -= R3 * zv;
    zv *= 2;
    xv *= 2;
    if (z > R3_2) {
        z -= R3_2;
        if (x > 0.5) {
            x -= 0.5;
            xv++;
        } else {
            x += 0.5;
            xv--;
        }
        zv++;
    }
    if (x == 0.0 || z / x > R3) { /* the downward triangle on the left */
        z = R3_2 - z;
        x = 0.5 - x;
        xv--;
    }
    if (x == 1.0 || z / (1.0 - x) > R3) { /* ... on the right */
        z = R3_2 - z;
        x = 1.5 - x;
        xv++;
    }
    *px = x;
    *pz = z;
    *pxv = xv;
    *pzv = zv;
}

static int triangle_code(int tiles, int num, long xv, long zv)
{
    int n = num - 1, w = 0;
    switch (tiles) {
    case 6:
        if (n < 0 || n >= 12) return -1;
        switch (n) {
        case 0: case 1: case 9: xv = pmod(xv + 5 * zv, 6); break;
        case 2: case 10: case 11: zv = pmod(zv, 2); xv = pmod(xv + 3 * zv, 6); break;
        case 3: xv = pmod(xv + 14 * (pmod(zv, 6) / 2), 6); zv = pmod(zv, 2); w = 6; break;
        case 4: case 8: xv = pmod(xv + 8 * (pmod(zv, 6) / 2), 6); zv = pmod(zv, 2); w = 6; break;
        case 5: xv = pmod(xv, 6); zv = pmod(zv, 2); w = 6; break;
        default: /* 6, 7 */
            xv = pmod(xv - pmod(zv, 12) / 3, 4); zv = pmod(zv, 3); w = 4; break;
        }
        return tri_hexiamond[n][xv + zv * w];
    case 5:
        if (n < 0 || n >= 4) return -1;
        if (n < 3) {
            zv = pmod(zv, 2);
            xv = pmod(xv + 5 * zv, 10);
        } else {
            zv = pmod(zv, 10);
            xv = pmod(xv + 3 * zv, 10);
        }
        return tri_pentiamond[n][xv];
    case 4:
        if (n < 0 || n >= 3) return -1;
        zv = pmod(zv, 4);
        xv = pmod(xv + zv, 4);
        return tri_tetriamond[n][xv + 4 * pmod(zv, 2)];
    case 3:
        if (n != 0) return -1;
        zv = pmod(zv, 2);
        return tri_triamond[0][pmod(xv + 3 * zv, 6)];
    case 2: return tri_diamond[0][0];
    default: return tri_moniamond[0][0];
    }
}

static int hexagon_code(int tiles, int num, long xv, long zv)
{
    int n = num - 1;
    switch (tiles) {
    case 5: {
        if (n < 0 || n >= 22) return -1;
        long shift; /* rows shift by `shift` per 6 columns (period 30) */
        switch (n) {
        case 1: case 4: case 9: shift = -2; break;
        case 8: case 10: case 13: case 14: case 15: case 17: case 20: case 21: shift = 2; break;
        case 11: case 16: shift = -6; break;
        case 12: case 18: shift = 6; break;
        case 7: shift = 0; break;
        default: shift = 0; break; /* 0 2 3 5 6 19: a plain 6 x 10 period */
        }
        if (n == 7) { /* 3 columns, 20 rows, shifted by 7 per 3 columns (period 60) */
            zv = pmod(zv - 7 * (pmod(xv, 60) / 3), 20);
            return hex_pentahex[n][pmod(xv, 3) + 3 * zv];
        }
        zv = pmod(zv + shift * (pmod(xv, 30) / 6), 10);
        return hex_pentahex[n][pmod(xv, 6) + 6 * zv];
    }
    case 4:
        if (n < 0 || n >= 7) return -1;
        switch (n) {
        case 0: zv = pmod(zv, 8); break;
        case 1: zv = pmod(zv + 2 * (pmod(xv, 12) / 6), 8); break;
        case 2: return hex_tetrahex[n][pmod(xv, 12) + 12 * pmod(zv, 2)];
        case 6: return hex_tetrahex[n][pmod(xv, 12) + 12 * pmod(zv, 4)];
        default: zv = pmod(zv - 2 * (pmod(xv, 24) / 6), 8); break; /* 3 4 5 */
        }
        return hex_tetrahex[n][pmod(xv, 6) + 6 * zv];
    case 3:
        if (n < 0 || n >= 3) return -1;
        if (n == 2) return hex_trihex[n][pmod(xv, 18) + 18 * pmod(zv, 2)];
        if (n == 1) zv += 2 * (pmod(xv, 18) / 6);
        return hex_trihex[n][pmod(xv, 6) + 6 * pmod(zv, 6)];
    case 2:
        if (n != 0) return -1;
        return hex_dihex[0][pmod(xv, 6) + 6 * pmod(zv, 2)];
    default: /* one tile (POV-Ray: also any other count) */
        if (n != 0) return -1;
        zv = pmod(zv, 2);
        return hex_monohex[0][pmod(xv + 3 * zv, 6)];
    }
}

/* Value inside the folded triangle from its code. `hex` enables the
 * polyhex corner bits and disables `exterior` (POV-Ray's polyhexes have
 * none). */
static double triangle_cell(int how, double x, double z, const shade_pavement_params *pv, int hex)
{
    double r = 0.0;
    if (how & 0x01) r = fmax(r, 1.0 - fabs(R3 * x - z) * R3);
    if (how & 0x02) r = fmax(r, 1.0 - fabs(R3 * (1.0 - x) - z) * R3);
    if (how & 0x04) r = fmax(r, 1.0 - z * 2.0 * R3);
    /* the medians cut the triangle into three kites, one per vertex:
     * m1 < 0 && m2 < 0 near T, m1 > 0 && m3 > 0 near L, m3 < 0 && m2 > 0
     * near R */
    double m1 = 1.0 - fabs(R3 * z + x), m2 = 1.0 - fabs(R3 * z - x + 1.0), m3 = 1.0 - x * 2.0;
    /* concave corners at T, L, R: no border edge at that vertex (and for
     * T no 0x80), or the polyhex's forcing bit */
    int at_t = (how & 0x83) == 0 || (hex && (how & 0x4000));
    int at_l = (how & 0x85) == 0 || (hex && (how & 0x2000));
    int at_r = (how & 0x86) == 0 || (hex && (how & 0x1000));
    switch (pv->interior) {
    case 1: /* cut */
        if (at_t && m1 < 0 && m2 < 0)
            r = fmax(r, fmin(3.0 / 2.0 * fabs(R3 * z + x) - 2.0, 3.0 / 2.0 * fabs(R3 * z - x + 1.0) - 2.0));
        if (at_l && m1 > 0 && m3 > 0)
            r = fmax(r, fmin(1.0 - 3.0 / 2.0 * fabs(R3 * z + x), 1.0 - x * 3.0));
        if (at_r && m3 < 0 && m2 > 0)
            r = fmax(r, fmin(1.0 - 3.0 / 2.0 * fabs(R3 * z - x + 1.0), x * 3.0 - 2.0));
        break;
    case 2: { /* round: a third of the edge length around the vertex */
        double dx = x - 0.5, dz = z - R3_2;
        if (at_t) r = fmax(r, 1.0 - sqrt(dx * dx + dz * dz) * 3.0);
        if (at_l) r = fmax(r, 1.0 - sqrt(x * x + z * z) * 3.0);
        dx = x - 1.0;
        if (at_r) r = fmax(r, 1.0 - sqrt(dx * dx + z * z) * 3.0);
        break;
    }
    case 0: /* sharp: the grout of the two edges meeting there */
        if (at_t) r = fmax(r, 1.0 - (R3_2 - z) * 2.0 * R3);
        if (at_l) r = fmax(r, 1.0 - fabs(R3 * x + z) * R3);
        if (at_r) r = fmax(r, 1.0 - fabs(R3 * (x - 1.0) - z) * R3);
        break;
    default: /* POV-Ray: no concave corner treatment */
        break;
    }
    /* convex corners (two border edges meet): the value there replaces
     * the edge distance, measured from the triangle's centre */
    if (!hex && pv->exterior == 2) {
        if (((how & 0x03) == 0x03 && m1 <= 0.0 && m2 <= 0.0) || ((how & 0x06) == 0x06 && m2 >= 0.0 && m3 <= 0.0) ||
            ((how & 0x05) == 0x05 && m1 >= 0.0 && m3 >= 0.0)) {
            double a = x - 0.5, b = z - R3_2 / 3.0;
            r = fmin(1.0, 2 * R3 * sqrt(a * a + b * b));
        }
    } else if (!hex && pv->exterior == 1) {
        double e1 = 1.0 - fabs(R3 * x - z) * R3, e2 = 1.0 - fabs(R3 * (1.0 - x) - z) * R3, e3 = 1.0 - z * 2.0 * R3;
        double a = x - 0.5, b = z - R3_2 / 3.0;
        if ((how & 0x03) == 0x03 && e1 >= 0.0 && e2 >= 0.0) r = fmin(1.0, fabs(b * 2.0 * R3));
        if ((how & 0x06) == 0x06 && e2 >= 0.0 && e3 >= 0.0) r = fmin(1.0, fabs(R3 * a - b) * R3);
        if ((how & 0x05) == 0x05 && e1 >= 0.0 && e3 >= 0.0) r = fmin(1.0, fabs(R3 * a + b) * R3);
    }
    /* `form`: cells where a tile turns, measured from a vertex (first
     * match wins) */
    static const struct { int mask, region; double cx, cz; } bend[6] = {
        {0x120, 0, 0.0, 0.0}, {0x140, 1, 0.5, R3_2}, {0x210, 0, 1.0, 0.0},
        {0x240, 2, 0.5, R3_2}, {0x410, 1, 1.0, 0.0}, {0x420, 2, 0.0, 0.0},
    };
    if (pv->form == 1 || pv->form == 2) {
        for (int i = 0; i < 6; i++) {
            if ((how & bend[i].mask) != bend[i].mask) continue;
            int in = bend[i].region == 0 ? (m1 < 0 && m2 < 0) : bend[i].region == 1 ? (m1 > 0 && m3 > 0) : (m3 < 0 && m2 > 0);
            if (!in) continue;
            if (pv->form == 2) {
                double a = x - bend[i].cx, b = z - bend[i].cz;
                double v = 2.0 * R3 * (sqrt(a * a + b * b) - R3 / 3.0);
                return fmin(fmax(v, 0.0), 1.0);
            }
            /* cut: twice the median distance of that kite */
            static const int sign[6] = {-1, 1, -1, 1, 1, -1};
            double m = i < 2 ? m1 : i < 4 ? m2 : m3;
            return fmin(sign[i] * m * 2, 1.0);
        }
    }
    return r;
}

/* ------------------------------------------------------------------ entry */

double shade_pavement_value(const shade_pavement_params *pv, vec3 p)
{
    /* lattice indices are longs: beyond 1e9 units (and for NaN) they would
     * overflow; POV-Ray's result is undefined there, this gives 0 */
    if (!(fabs(p.x) < 1e9 && fabs(p.z) < 1e9)) return 0.0;
    if (pv->sides == 4) {
        double x = p.x, y = p.z;
        long xv = (long)floor(x), zv = (long)floor(y);
        int how = square_code(pv->tiles, pv->number, xv, zv);
        if (how < 0) return 0.0;
        return square_cell(how, x - floor(x), y - floor(y), pv);
    }
    double x = p.x, z = p.z;
    long xv, zv;
    tri_fold(&x, &z, &xv, &zv);
    int hex = pv->sides == 6;
    int how = hex ? hexagon_code(pv->tiles, pv->number, xv, zv) : triangle_code(pv->tiles, pv->number, xv, zv);
    if (how < 0) return 0.0;
    return triangle_cell(how, x, z, pv, hex);
}
