#!/usr/bin/env python3
"""gen_pavement.py - measure the cell codes of POV-Ray 3.7's `pavement`
pattern from POV-Ray's own renders and write shade/pavement_cells.txt (the
build makes it into C tables: shade/pavement_tables.cmake).

Usage: python3 scripts/gen_pavement.py [-o shade/pavement_cells.txt]
                                        [-j JOBS] [--keep DIR [--reuse]]

Needs `povray` 3.7 on PATH and nothing but the Python standard library.

How it works. shade/shade_pavement.c folds every lattice cell (unit squares;
unit equilateral triangles, a hexagon being six of them) onto one period of
the chosen paving and looks up a per-cell code in a table (one row per
pattern number). The folding (which cell of the plane lands on which table
entry) is this repository's own code, mirrored below in square_index(),
triangle_index() and hexagon_index(); this script finds the code of every
table entry by looking at POV-Ray:

 * For each paving (number_of_sides 3, 4, 6 x number_of_tiles 1-6 x each
   pattern number: 112, one table row each), POV-Ray renders a window of the x-z plane big enough
   that every table entry occurs at least twice (where the window cap
   allows), seen from above by an orthographic camera, 24 pixels per unit,
   no anti-aliasing, 16-bit binary PPM, File_Gamma 1 (pixel = pattern value
   through a 0..1 grey colour_map). The image holds four panels of the same
   window, each with other corner settings:
     A  interior 0 exterior 0 form 3   (decoding: borders, concave corners)
     B  interior 0 exterior 0 form 2   (decoding: the cells `form` bends)
     C  interior 2 exterior 1 form 1   (check only)
     D  interior 1 exterior 2 form 0   (check only)
 * In panel A the value at a point 0.08 (squares: 0.07) inside a cell edge's
   midpoint is about 0.8 when that edge is a tile border and 0 otherwise;
   the value near a cell vertex is about 0.8 when an edge at that vertex is
   a border or the vertex is a concave corner of a tile (interior 0 gives
   the corner a sharp grout). This gives the edge bits and the corner bits.
 * In panel B (form 2, round) a triangle cell where a tile turns has, in the
   kite of one vertex (the three kites the medians cut), the value
   2 sqrt(3) (|p - c| - sqrt(3)/3) clamped to [0, 1], c being one of the two
   other vertices; each kite's samples are matched against "no bend" (panel
   A's value there), "centred at c1" and "centred at c2" and the bend bits
   are the fewest that give that result.
 * Every decoded code is then evaluated by a Python copy of
   shade_pavement.c's cell functions at the sample pixels of every
   occurrence of the cell in all four panels and compared with POV-Ray's
   pixel (tolerance 2e-3); any disagreement, any table entry decoded two ways
   by two occurrences, and any sample that cannot be classified is reported
   and makes the script exit 1 without writing the header.

Bits a render cannot show are written as 0: a square's concave-corner bit
where the corner already has a border edge; the triangle flag 0x80 when
every vertex has a border edge; a hexagon's corner-forcing bit at a vertex
with a border edge; `form` bits that complete no bend (of the several bit
sets giving the bends seen, the one with the fewest bits is written). None
of these changes any value shade_pavement.c computes. Table entries the fold
never reaches are 0 too.

It reads neither POV-Ray's sources nor the tables it replaces.
"""
import argparse
import array
import math
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

R3 = math.sqrt(3.0)
R3_2 = R3 / 2.0
RES = 24          # pixels per unit
GAP = 1           # units between panels (a whole number of pixels)
MAXW = 36         # window cap, units
REUSE = False     # --reuse: take the renders already in --keep's folder
TOL = 2e-3        # value tolerance of the final check (16-bit PNG/PPM, float colours)
PANELS = [(0, 0, 3), (0, 0, 2), (2, 1, 1), (1, 2, 0)]  # (interior, exterior, form)

# --------------------------------------------------------------- the tables
# name, sides, tiles, rows (pattern numbers), entries per row: the layout of
# shade_pavement.c's tables (the fold below indexes them)
TABLES = [
    ("sq_monomino", 4, 1, 1, 1), ("sq_domino", 4, 2, 1, 2), ("sq_tromino", 4, 3, 2, 6),
    ("sq_tetromino", 4, 4, 5, 16), ("sq_pentomino", 4, 5, 12, 10), ("sq_hexomino", 4, 6, 35, 12),
    ("tri_moniamond", 3, 1, 1, 1), ("tri_diamond", 3, 2, 1, 1), ("tri_triamond", 3, 3, 1, 6),
    ("tri_tetriamond", 3, 4, 3, 8), ("tri_pentiamond", 3, 5, 4, 10), ("tri_hexiamond", 3, 6, 12, 12),
    ("hex_monohex", 6, 1, 1, 6), ("hex_dihex", 6, 2, 1, 12), ("hex_trihex", 6, 3, 3, 36),
    ("hex_tetrahex", 6, 4, 7, 48), ("hex_pentahex", 6, 5, 22, 60),
]


def pmod(a, n):
    return a % n  # Python's % is already in [0, n) for n > 0


# Mirrors of shade_pavement.c's square_code / triangle_code / hexagon_code:
# the table entry (index in the row of pattern n = num - 1) of cell (xv, zv).
def square_index(tiles, n, xv, zv):
    w = 0
    if tiles == 2:
        return pmod(zv, 2)
    if tiles == 3:
        return pmod(xv, 3) + 3 * pmod(zv, 2)
    if tiles == 4:
        return pmod(xv, 4) + 4 * pmod(zv, 4)
    if tiles == 5:
        if n in (0, 1):
            xv, zv = pmod(xv, 5), pmod(zv, 2)
        elif n in (2, 9, 10):
            zv = pmod(zv, 10)
            xv = pmod(xv + (4 if n == 10 else 3) * (zv // 2), 5)
            zv = pmod(zv, 2)
        elif n in (3, 4):
            zv = pmod(zv, 5); xv = pmod(xv + 2 * zv, 5); zv = 0
        elif n in (5, 6, 8):
            zv = pmod(zv, 10); xv = pmod(xv + zv, 10); zv = 0
        elif n == 7:
            zv = pmod(zv, 10); xv = pmod(xv + 3 * zv, 10); zv = 0
        else:
            zv = pmod(zv, 10); xv = pmod(xv + 8 * zv, 10); zv = 0
        return xv + zv * 5
    if tiles == 6:
        if n in (0, 1, 2, 3, 5, 6, 8, 9):
            xv = pmod(xv, 6); zv = pmod(zv, 2); w = 6
        elif n in (4, 7, 19, 20):
            zv = pmod(zv, 6); xv = pmod(xv + 5 * zv, 6)
        elif n in (11, 18, 27):
            zv = pmod(zv, 6); xv = pmod(xv + zv, 6)
        elif n in (10, 12, 21, 22, 24, 25, 26):
            xv = pmod(xv, 4); zv = pmod(zv, 3); w = 4
        elif n in (13, 32):
            zv = pmod(zv, 4); xv = pmod(xv, 3); w = 3
        elif n == 14:
            zv = pmod(zv, 6); xv = pmod(xv + 2 * (zv // 2), 3); zv = pmod(zv, 2); w = 3
        elif n == 15:
            xv = pmod(xv, 6); zv = pmod(zv + xv // 2, 3); xv = pmod(xv, 2); w = 2
        elif n in (16, 17):
            zv = pmod(zv, 12); xv = pmod(xv + zv // 2, 6); zv = pmod(zv, 2); w = 6
        elif n in (23, 28):
            zv = pmod(zv, 12); xv = pmod(xv + 4 * (zv // 2), 6); zv = pmod(zv, 2); w = 6
        elif n in (29, 30):
            zv = pmod(zv, 4); xv = pmod(xv + 3 * (zv // 2), 6); zv = pmod(zv, 2); w = 6
        elif n == 31:
            zv = pmod(zv, 3); xv = pmod(xv + 4 * zv, 6)
        elif n == 33:
            zv = pmod(zv, 12); xv = pmod(xv + 7 * zv, 12)
        else:
            zv = pmod(zv, 6); xv = pmod(xv + 2 * (zv // 3), 4); zv = pmod(zv, 3); w = 4
        return xv + zv * w
    return 0


def triangle_index(tiles, n, xv, zv):
    w = 0
    if tiles == 6:
        if n in (0, 1, 9):
            xv = pmod(xv + 5 * zv, 6)
        elif n in (2, 10, 11):
            zv = pmod(zv, 2); xv = pmod(xv + 3 * zv, 6)
        elif n == 3:
            xv = pmod(xv + 14 * (pmod(zv, 6) // 2), 6); zv = pmod(zv, 2); w = 6
        elif n in (4, 8):
            xv = pmod(xv + 8 * (pmod(zv, 6) // 2), 6); zv = pmod(zv, 2); w = 6
        elif n == 5:
            xv = pmod(xv, 6); zv = pmod(zv, 2); w = 6
        else:
            xv = pmod(xv - pmod(zv, 12) // 3, 4); zv = pmod(zv, 3); w = 4
        return xv + zv * w
    if tiles == 5:
        if n < 3:
            zv = pmod(zv, 2); xv = pmod(xv + 5 * zv, 10)
        else:
            zv = pmod(zv, 10); xv = pmod(xv + 3 * zv, 10)
        return xv
    if tiles == 4:
        zv = pmod(zv, 4); xv = pmod(xv + zv, 4)
        return xv + 4 * pmod(zv, 2)
    if tiles == 3:
        zv = pmod(zv, 2)
        return pmod(xv + 3 * zv, 6)
    return 0


def hexagon_index(tiles, n, xv, zv):
    if tiles == 5:
        shift = {1: -2, 4: -2, 9: -2, 8: 2, 10: 2, 13: 2, 14: 2, 15: 2, 17: 2, 20: 2, 21: 2,
                 11: -6, 16: -6, 12: 6, 18: 6}.get(n, 0)
        if n == 7:
            zv = pmod(zv - 7 * (pmod(xv, 60) // 3), 20)
            return pmod(xv, 3) + 3 * zv
        zv = pmod(zv + shift * (pmod(xv, 30) // 6), 10)
        return pmod(xv, 6) + 6 * zv
    if tiles == 4:
        if n == 0:
            zv = pmod(zv, 8)
        elif n == 1:
            zv = pmod(zv + 2 * (pmod(xv, 12) // 6), 8)
        elif n == 2:
            return pmod(xv, 12) + 12 * pmod(zv, 2)
        elif n == 6:
            return pmod(xv, 12) + 12 * pmod(zv, 4)
        else:
            zv = pmod(zv - 2 * (pmod(xv, 24) // 6), 8)
        return pmod(xv, 6) + 6 * zv
    if tiles == 3:
        if n == 2:
            return pmod(xv, 18) + 18 * pmod(zv, 2)
        if n == 1:
            zv += 2 * (pmod(xv, 18) // 6)
        return pmod(xv, 6) + 6 * pmod(zv, 6)
    if tiles == 2:
        return pmod(xv, 6) + 6 * pmod(zv, 2)
    zv = pmod(zv, 2)
    return pmod(xv + 3 * zv, 6)


def cell_index(sides, tiles, n, xv, zv):
    if sides == 4:
        return square_index(tiles, n, xv, zv)
    if sides == 6:
        return hexagon_index(tiles, n, xv, zv)
    return triangle_index(tiles, n, xv, zv)


def tri_fold(x, z):
    """shade_pavement.c's tri_fold: (local x, local z, xv, zv)."""
    xv = math.floor(x)
    zv = math.floor(z / R3)
    x -= xv
    z -= R3 * zv
    zv *= 2
    xv *= 2
    if z > R3_2:
        z -= R3_2
        if x > 0.5:
            x -= 0.5
            xv += 1
        else:
            x += 0.5
            xv -= 1
        zv += 1
    if x == 0.0 or z / x > R3:
        z = R3_2 - z
        x = 0.5 - x
        xv -= 1
    if x == 1.0 or z / (1.0 - x) > R3:
        z = R3_2 - z
        x = 1.5 - x
        xv += 1
    return x, z, xv, zv


def fold(sides, X, Z):
    if sides == 4:
        xv, zv = math.floor(X), math.floor(Z)
        return X - xv, Z - zv, xv, zv
    return tri_fold(X, Z)


def unfold(sides, xv, zv, lx, lz):
    """World point of local (lx, lz) in cell (xv, zv)."""
    if sides == 4:
        return xv + lx, zv + lz
    if (xv + zv) % 2 == 0:  # upward triangle
        return xv / 2.0 + lx, R3_2 * zv + lz
    return xv / 2.0 + 1.0 - lx, R3_2 * zv + R3_2 - lz


def window_cells(sides, wx, wz):
    """Cells lying wholly inside [0, wx] x [0, wz]."""
    if sides == 4:
        return [(xv, zv) for zv in range(wz) for xv in range(wx)]
    rows = int(wz / R3_2)
    return [(xv, zv) for zv in range(rows) for xv in range(2 * wx - 1)]


# --------------------------------------------- the cell model (shade_pavement.c)
def square_cell(how, x, y, interior, exterior, form):
    corners = [(0, 1, 0x10), (1, 1, 0x20), (1, 0, 0x40), (0, 0, 0x80)]
    turn = [0x16, 0x2C, 0x49, 0x83]
    if 0 <= form <= 2:
        for c in range(4):
            if how & turn[c] != turn[c]:
                continue
            u, v = 2 * abs(x - corners[c][0]), 2 * abs(y - corners[c][1])
            if form == 2:
                return min(abs(math.hypot(u, v) - 1.0), 1.0)
            if form == 1:
                return min(abs(u + v - 1.0), 1.0)
            return max(max(u - 1.0, v - 1.0), min(1.0 - u, 1.0 - v))
    r = 0.0
    if how & 1: r = max(r, 2 * y - 1)
    if how & 2: r = max(r, 2 * x - 1)
    if how & 4: r = max(r, 1 - 2 * y)
    if how & 8: r = max(r, 1 - 2 * x)
    for cx, cy, bit in corners:
        if not how & bit:
            continue
        u, v = 2 * abs(x - cx), 2 * abs(y - cy)
        if interior == 2: r = max(r, 1 - math.hypot(u, v))
        elif interior == 1: r = max(r, 1 - (u + v))
        else: r = max(r, min(1 - u, 1 - v))
    if exterior in (1, 2):
        for mask, cx, cy in ((0x06, 1, 0), (0x0C, 0, 0), (0x09, 0, 1), (0x03, 1, 1)):
            if how & mask != mask:
                continue
            if exterior == 1:
                u, v = 2 * abs(x - cx), 2 * abs(y - cy)
                r = max(r, min(2 - (u + v), 1.0))
            else:
                a, b = 2 * x - 1, 2 * y - 1
                in_x = a >= 0 if cx else a <= 0
                in_y = b >= 0 if cy else b <= 0
                if in_x and in_y:
                    r = max(r, min(math.hypot(a, b), 1.0))
                    break
    return r


BENDS = [(0x120, 0, 0.0, 0.0), (0x140, 1, 0.5, R3_2), (0x210, 0, 1.0, 0.0),
         (0x240, 2, 0.5, R3_2), (0x410, 1, 1.0, 0.0), (0x420, 2, 0.0, 0.0)]


def kite_of(x, z):
    m1 = 1 - abs(R3 * z + x)
    m2 = 1 - abs(R3 * z - x + 1)
    m3 = 1 - 2 * x
    if m1 < 0 and m2 < 0: return 0  # at T
    if m1 > 0 and m3 > 0: return 1  # at L
    if m3 < 0 and m2 > 0: return 2  # at R
    return -1


def triangle_cell(how, x, z, interior, exterior, form, hexa):
    r = 0.0
    if how & 1: r = max(r, 1 - abs(R3 * x - z) * R3)
    if how & 2: r = max(r, 1 - abs(R3 * (1 - x) - z) * R3)
    if how & 4: r = max(r, 1 - z * 2 * R3)
    m1 = 1 - abs(R3 * z + x)
    m2 = 1 - abs(R3 * z - x + 1)
    m3 = 1 - 2 * x
    at_t = (how & 0x83) == 0 or (hexa and how & 0x4000)
    at_l = (how & 0x85) == 0 or (hexa and how & 0x2000)
    at_r = (how & 0x86) == 0 or (hexa and how & 0x1000)
    if interior == 1:
        if at_t and m1 < 0 and m2 < 0:
            r = max(r, min(1.5 * abs(R3 * z + x) - 2, 1.5 * abs(R3 * z - x + 1) - 2))
        if at_l and m1 > 0 and m3 > 0:
            r = max(r, min(1 - 1.5 * abs(R3 * z + x), 1 - 3 * x))
        if at_r and m3 < 0 and m2 > 0:
            r = max(r, min(1 - 1.5 * abs(R3 * z - x + 1), 3 * x - 2))
    elif interior == 2:
        if at_t: r = max(r, 1 - math.hypot(x - 0.5, z - R3_2) * 3)
        if at_l: r = max(r, 1 - math.hypot(x, z) * 3)
        if at_r: r = max(r, 1 - math.hypot(x - 1, z) * 3)
    elif interior == 0:
        if at_t: r = max(r, 1 - (R3_2 - z) * 2 * R3)
        if at_l: r = max(r, 1 - abs(R3 * x + z) * R3)
        if at_r: r = max(r, 1 - abs(R3 * (x - 1) - z) * R3)
    if not hexa and exterior == 2:
        if ((how & 3) == 3 and m1 <= 0 and m2 <= 0) or ((how & 6) == 6 and m2 >= 0 and m3 <= 0) or \
           ((how & 5) == 5 and m1 >= 0 and m3 >= 0):
            r = min(1.0, 2 * R3 * math.hypot(x - 0.5, z - R3_2 / 3))
    elif not hexa and exterior == 1:
        e1 = 1 - abs(R3 * x - z) * R3
        e2 = 1 - abs(R3 * (1 - x) - z) * R3
        e3 = 1 - z * 2 * R3
        a, b = x - 0.5, z - R3_2 / 3
        if (how & 3) == 3 and e1 >= 0 and e2 >= 0: r = min(1.0, abs(b * 2 * R3))
        if (how & 6) == 6 and e2 >= 0 and e3 >= 0: r = min(1.0, abs(R3 * a - b) * R3)
        if (how & 5) == 5 and e1 >= 0 and e3 >= 0: r = min(1.0, abs(R3 * a + b) * R3)
    if form in (1, 2):
        sign = [-1, 1, -1, 1, 1, -1]
        for i, (mask, region, cx, cz) in enumerate(BENDS):
            if how & mask != mask:
                continue
            if region == 0: inside = m1 < 0 and m2 < 0
            elif region == 1: inside = m1 > 0 and m3 > 0
            else: inside = m3 < 0 and m2 > 0
            if not inside:
                continue
            if form == 2:
                v = 2 * R3 * (math.hypot(x - cx, z - cz) - R3 / 3)
                return min(max(v, 0.0), 1.0)
            m = m1 if i < 2 else (m2 if i < 4 else m3)
            return min(sign[i] * m * 2, 1.0)
    return r


def model(sides, how, x, z, panel):
    interior, exterior, form = PANELS[panel]
    if sides == 4:
        return square_cell(how, x, z, interior, exterior, form)
    return triangle_cell(how, x, z, interior, exterior, form, sides == 6)


# ------------------------------------------------------------ sample points
G = (0.5, R3_2 / 3)  # the triangle's centroid


def toward_g(p, d):
    dx, dz = G[0] - p[0], G[1] - p[1]
    k = d / math.hypot(dx, dz)
    return (p[0] + dx * k, p[1] + dz * k)


SQ_EDGE = {1: (0.5, 0.93), 2: (0.93, 0.5), 4: (0.5, 0.07), 8: (0.07, 0.5)}
SQ_CORNER = {0x10: (0.07, 0.93, 1 | 8), 0x20: (0.93, 0.93, 1 | 2), 0x40: (0.93, 0.07, 2 | 4),
             0x80: (0.07, 0.07, 4 | 8)}
SQ_EXTRA = [(0.5, 0.5), (0.3, 0.7), (0.7, 0.3), (0.25, 0.25), (0.75, 0.75), (0.2, 0.6), (0.6, 0.85)]
TV = {"T": (0.5, R3_2), "L": (0.0, 0.0), "R": (1.0, 0.0)}
TRI_EDGE = {1: toward_g((0.25, R3_2 / 2), 0.08), 2: toward_g((0.75, R3_2 / 2), 0.08),
            4: toward_g((0.5, 0.0), 0.08)}
# vertex samples: the bits of the edges at that vertex, the hex forcing bit
TRI_VERT = {"T": (toward_g(TV["T"], 0.08), 1 | 2, 0x4000), "L": (toward_g(TV["L"], 0.08), 1 | 4, 0x2000),
            "R": (toward_g(TV["R"], 0.08), 2 | 4, 0x1000)}


def kite_points():
    """A few points inside each vertex's kite, spread to tell the bends apart."""
    pts = {0: [], 1: [], 2: []}
    for name, k in (("T", 0), ("L", 1), ("R", 2)):
        v = TV[name]
        for t in (0.35, 0.55, 0.75, 0.9):
            for s in (-0.12, 0.0, 0.12):
                px = v[0] + t * (G[0] - v[0])
                pz = v[1] + t * (G[1] - v[1])
                # perpendicular to the median
                dx, dz = G[0] - v[0], G[1] - v[1]
                ln = math.hypot(dx, dz)
                px += -dz / ln * s
                pz += dx / ln * s
                if kite_of(px, pz) == k:
                    pts[k].append((px, pz))
    return pts


KITE_PTS = kite_points()
TRI_EXTRA = [G, (0.3, 0.1), (0.7, 0.1), (0.5, 0.5), (0.4, 0.3), (0.6, 0.3)]


# ------------------------------------------------------------------ POV-Ray
def read_ppm16(path):
    d = open(path, "rb").read()
    toks, i = [], 0
    while len(toks) < 4:
        while d[i:i + 1].isspace():
            i += 1
        if d[i:i + 1] == b"#":
            while d[i:i + 1] != b"\n":
                i += 1
            continue
        j = i
        while not d[j:j + 1].isspace():
            j += 1
        toks.append(d[i:j])
        i = j
    i += 1
    if toks[0] != b"P6" or toks[3] != b"65535":
        raise RuntimeError("%s: not a 16-bit binary PPM" % path)
    w, h = int(toks[1]), int(toks[2])
    a = array.array("H")
    a.frombytes(d[i:i + w * h * 6])
    if sys.byteorder == "little":
        a.byteswap()
    return w, h, a


class Paving:
    def __init__(self, table, sides, tiles, n, width):
        self.table, self.sides, self.tiles, self.n, self.width = table, sides, tiles, n, width

    def pigment(self, interior, exterior, form):
        return ("pavement number_of_sides %d number_of_tiles %d pattern %d interior %d exterior %d form %d"
                % (self.sides, self.tiles, self.n + 1, interior, exterior, form))

    def choose_window(self):
        # every entry the fold reaches (periods are below 60 cells)
        self.reach = {cell_index(self.sides, self.tiles, self.n, xv, zv) for xv in range(130) for zv in range(60)}
        wx = wz = 2
        while True:
            cnt = {}
            for xv, zv in window_cells(self.sides, wx, wz):
                k = cell_index(self.sides, self.tiles, self.n, xv, zv)
                cnt[k] = cnt.get(k, 0) + 1
            if all(cnt.get(k, 0) >= 2 for k in self.reach) or (wx >= MAXW and wz >= MAXW):
                break
            if wx <= wz:
                wx += 1
            else:
                wz += 1
        self.wx, self.wz = wx, wz
        self.min_seen = min(cnt.get(k, 0) for k in self.reach)

    def render(self, tmp):
        npan = len(PANELS)
        tw = npan * self.wx + (npan - 1) * GAP
        self.W, self.H = tw * RES, self.wz * RES
        src = ["#version 3.7;", "global_settings { assumed_gamma 1.0 }",
               "camera { orthographic location <%g, 10, %g> direction -y right x*%g up z*%g }"
               % (tw / 2.0, self.wz / 2.0, tw, self.wz)]
        for p, (i, e, f) in enumerate(PANELS):
            x0 = p * (self.wx + GAP)
            src.append("polygon { 4, <%d, 0, 0>, <%d, 0, 0>, <%d, 0, %d>, <%d, 0, %d> "
                       "pigment { %s color_map { [0 rgb 0] [1 rgb 1] } translate <%d, 0, 0> } "
                       "finish { ambient 1 diffuse 0 } }"
                       % (x0, x0 + self.wx, x0 + self.wx, self.wz, x0, self.wz, self.pigment(i, e, f), x0))
        base = os.path.join(tmp, "%s_%d" % (self.table, self.n + 1))
        with open(base + ".pov", "w") as fh:
            fh.write("\n".join(src) + "\n")
        cmd = ["povray", "+I" + base + ".pov", "+O" + base + ".ppm", "+W%d" % self.W, "+H%d" % self.H,
               "-A", "-D", "-V", "-GA", "+FP16", "File_Gamma=1.0"]
        if REUSE and os.path.exists(base + ".ppm"):
            res = None
        else:
            res = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        if res is not None and res.returncode != 0:
            raise RuntimeError("povray failed on %s:\n%s" % (base, res.stdout.decode(errors="replace")[-2000:]))
        w, h, self.img = read_ppm16(base + ".ppm")
        assert (w, h) == (self.W, self.H)

    def value(self, panel, i, j):
        k = 3 * (j * self.W + i + panel * (self.wx + GAP) * RES)
        return self.img[k] / 65535.0

    def sample(self, xv, zv, target):
        """The pixel nearest the local point `target` of cell (xv, zv) whose
        centre lies in that cell: (i, j, local x, local z) or None."""
        X, Z = unfold(self.sides, xv, zv, target[0], target[1])
        i0, j0 = int(math.floor(X * RES)), int(math.floor((self.wz - Z) * RES))
        best = None
        for j in range(j0 - 1, j0 + 2):
            for i in range(i0 - 1, i0 + 2):
                if not (0 <= i < self.wx * RES and 0 <= j < self.H):
                    continue
                px, pz = (i + 0.5) / RES, self.wz - (j + 0.5) / RES
                lx, lz, cx, cz = fold(self.sides, px, pz)
                if (cx, cz) != (xv, zv):
                    continue
                d = math.hypot(lx - target[0], lz - target[1])
                if best is None or d < best[0]:
                    best = (d, i, j, lx, lz)
        return None if best is None else best[1:]


def decode_square(pv, xv, zv, problems):
    how = 0
    for bit, t in SQ_EDGE.items():
        s = pv.sample(xv, zv, t)
        if pv.value(0, s[0], s[1]) > 0.5:
            how |= bit
    for bit, (x, y, adj) in SQ_CORNER.items():
        s = pv.sample(xv, zv, (x, y))
        if pv.value(0, s[0], s[1]) > 0.5 and not how & adj:
            how |= bit
    return how


# bend bits: for each 6-bit choice, the centre each kite bends around
def bend_behaviour(bits):
    out = []
    for k in range(3):
        c = None
        for mask, region, cx, cz in BENDS:
            if region == k and bits & mask == mask:
                c = (cx, cz)
                break
        out.append(c)
    return tuple(out)


BEND_CHOICES = {}
for _b in range(64):
    _bits = (_b & 7) << 4 | (_b >> 3) << 8
    BEND_CHOICES.setdefault(bend_behaviour(_bits), []).append(_bits)
for _k in BEND_CHOICES:
    BEND_CHOICES[_k].sort(key=lambda b: (bin(b).count("1"), b))


def decode_triangle(pv, xv, zv, problems, where):
    hexa = pv.sides == 6
    how = 0
    for bit, t in TRI_EDGE.items():
        s = pv.sample(xv, zv, t)
        if s is None:
            problems.append("%s: no pixel for an edge sample" % where)
            continue
        if pv.value(0, s[0], s[1]) > 0.4:
            how |= bit
    concave = {}
    for name, (t, edges, force) in TRI_VERT.items():
        s = pv.sample(xv, zv, t)
        if s is None:
            problems.append("%s: no pixel for a vertex sample" % where)
            continue
        if not how & edges:  # observable only where no border edge meets the vertex
            concave[name] = pv.value(0, s[0], s[1]) > 0.4
    if hexa:
        how |= 0x80
        for name, (t, edges, force) in TRI_VERT.items():
            if concave.get(name):
                how |= force
    else:
        vals = set(concave.values())
        if len(vals) > 1:
            problems.append("%s: vertices without border disagree on concavity %s" % (where, concave))
        if vals == {False}:
            how |= 0x80
    # bends, panel B (form 2) against panel A (no bend)
    centres = []
    for k in range(3):
        cands = [None] + [(cx, cz) for mask, region, cx, cz in BENDS if region == k]
        err = {c: 0.0 for c in cands}
        for t in KITE_PTS[k]:
            s = pv.sample(xv, zv, t)
            if s is None:
                continue
            i, j, lx, lz = s
            if kite_of(lx, lz) != k:
                continue
            vb = pv.value(1, i, j)
            for c in cands:
                if c is None:
                    pred = pv.value(0, i, j)
                else:
                    pred = min(max(2 * R3 * (math.hypot(lx - c[0], lz - c[1]) - R3 / 3), 0.0), 1.0)
                err[c] = max(err[c], abs(pred - vb))
        ranked = sorted(cands, key=lambda c: err[c])
        if err[ranked[0]] > 5e-3 or err[ranked[1]] < 0.05:
            problems.append("%s: kite %d bend unclear (errors %s)" % (where, k, err))
        centres.append(ranked[0])
    choice = BEND_CHOICES.get(tuple(centres))
    if choice is None:
        problems.append("%s: no bend bits give kites %s" % (where, centres))
    else:
        how |= choice[0]
    return how


def check(pv, xv, zv, how):
    """Model vs POV-Ray at the cell's sample pixels in every panel: (n, bad, worst)."""
    if pv.sides == 4:
        pts = list(SQ_EDGE.values()) + [(c[0], c[1]) for c in SQ_CORNER.values()] + SQ_EXTRA
    else:
        pts = list(TRI_EDGE.values()) + [v[0] for v in TRI_VERT.values()] + TRI_EXTRA + \
            KITE_PTS[0] + KITE_PTS[1] + KITE_PTS[2]
    n = bad = 0
    worst = 0.0
    for t in pts:
        s = pv.sample(xv, zv, t)
        if s is None:
            continue
        i, j, lx, lz = s
        for p in range(len(PANELS)):
            d = abs(model(pv.sides, how, lx, lz, p) - pv.value(p, i, j))
            n += 1
            worst = max(worst, d)
            if d > TOL:
                bad += 1
    return n, bad, worst


def measure(pv, tmp):
    pv.choose_window()
    pv.render(tmp)
    problems = []
    codes = {}
    npts = nbad = 0
    worst = 0.0
    for xv, zv in window_cells(pv.sides, pv.wx, pv.wz):
        k = cell_index(pv.sides, pv.tiles, pv.n, xv, zv)
        where = "%s pattern %d cell (%d, %d) entry %d" % (pv.table, pv.n + 1, xv, zv, k)
        if pv.sides == 4:
            how = decode_square(pv, xv, zv, problems)
        else:
            how = decode_triangle(pv, xv, zv, problems, where)
        if k in codes and codes[k] != how:
            problems.append("%s: decoded 0x%X, another cell of the entry 0x%X" % (where, how, codes[k]))
        codes.setdefault(k, how)
        n, bad, w = check(pv, xv, zv, how)
        npts += n
        nbad += bad
        worst = max(worst, w)
        if bad:
            problems.append("%s: code 0x%X disagrees with POV-Ray at %d of %d samples (worst %.4f)"
                            % (where, how, bad, n, w))
    missing = pv.reach - set(codes)
    if missing:
        problems.append("%s pattern %d: entries %s not in the window" % (pv.table, pv.n + 1, sorted(missing)))
    pv.codes = [codes.get(k, 0) for k in range(pv.width)]
    pv.stats = (npts, nbad, worst)
    return problems


def povray_version():
    res = subprocess.run(["povray", "--version"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    for line in res.stdout.decode(errors="replace").splitlines():
        if line.startswith("POV-Ray "):
            return line.strip()
    return "POV-Ray (version not reported)"


def emit(out, pavings, cmdline, version, stats):
    by_table = {}
    for pv in pavings:
        by_table.setdefault(pv.table, []).append(pv)
    lines = [
        "# pavement_cells.txt - GENERATED by scripts/gen_pavement.py; do not edit.",
        "# Remake: %s" % cmdline,
        "#",
        "# The cell codes of POV-Ray 3.7's `pavement` pavings, measured from POV-Ray",
        "# 3.7.0's 16-bit renders of each paving (borders and concave corners at",
        "# interior 0 exterior 0 form 3, the cells `form` bends at form 2) and checked",
        "# against renders at other interior/exterior/form settings through a copy of",
        "# shade_pavement.c's cell functions: %s." % stats,
        "# Measured with %s." % version,
        "#",
        "# A line `NAME ROWS WIDTH` opens a table; each of the ROWS lines after it is",
        "# one pattern number's row (pattern 1 first): WIDTH codes in hexadecimal.",
        "# Entry k of a row is the cell that shade_pavement.c's fold sends to k;",
        "# entries the fold never reaches are 0, and so are bits no render can show",
        "# (see the script). Bits as described in shade_pavement.c. At build time",
        "# shade/pavement_tables.cmake turns this file into the C tables",
        "# (unsigned char for the square pavings, unsigned short for the others).",
    ]
    for name, sides, tiles, rows, width in TABLES:
        lines.append("%s %d %d" % (name, rows, width))
        for pv in by_table[name]:
            lines.append(" ".join("%X" % c for c in pv.codes))
    with open(out, "w") as fh:
        fh.write("\n".join(lines) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("-o", "--output", default=os.path.join(here, "..", "shade", "pavement_cells.txt"))
    ap.add_argument("-j", "--jobs", type=int, default=2)
    ap.add_argument("--keep", help="keep the scenes and renders in this folder")
    ap.add_argument("--reuse", action="store_true", help="with --keep: reuse the renders found there")
    args = ap.parse_args()
    global REUSE
    REUSE = args.reuse and args.keep is not None
    t0 = time.time()
    pavings = [Paving(name, s, t, n, w) for name, s, t, rows, w in TABLES for n in range(rows)]
    tmp = args.keep or tempfile.mkdtemp(prefix="gen_pavement.")
    os.makedirs(tmp, exist_ok=True)
    with ThreadPoolExecutor(max_workers=args.jobs) as ex:
        results = list(ex.map(lambda pv: measure(pv, tmp), pavings))
    problems = [p for r in results for p in r]
    npts = sum(pv.stats[0] for pv in pavings)
    nbad = sum(pv.stats[1] for pv in pavings)
    worst = max(pv.stats[2] for pv in pavings)
    entries = sum(len(pv.reach) for pv in pavings)
    thin = [("%s/%d" % (pv.table, pv.n + 1), pv.min_seen) for pv in pavings if pv.min_seen < 2]
    print("gen_pavement: %d table rows, %d reached entries, %d sample values checked in 4 panels, "
          "%d disagree (worst %.5f), %.1f s" % (len(pavings), entries, npts, nbad, worst, time.time() - t0))
    if thin:
        print("gen_pavement: rows whose window shows some entry only once: %s" % thin)
    if problems:
        for p in problems[:50]:
            print("gen_pavement: " + p, file=sys.stderr)
        print("gen_pavement: %d problems; %s not written" % (len(problems), args.output), file=sys.stderr)
        return 1
    emit(args.output, pavings, "python3 scripts/gen_pavement.py", povray_version(),
         "%d sample values, none off by more\n# than %g" % (npts, TOL))
    print("gen_pavement: wrote %s" % os.path.normpath(args.output))
    return 0


if __name__ == "__main__":
    sys.exit(main())
