#!/bin/sh
# A glass box standing on a floor, its bottom face in the floor's plane
# (bench/scenes/coplanar_tie.pov, glassthing.pov's contact): rays inside the
# glass meet the box's bottom and the floor at one distance. For each view
# (0: down through the box's top, 1: into its long side), both renderers at
# SIZE without antialiasing; over the pixels whose rays inside the glass
# reach the floor's plane (red: the floor under the box, with the box sunk
# 0.001 into it, POV-Ray's image), the share that shows that floor with the
# box standing on it, where the rest meet the box's bottom (then black: the
# ray left the room; or green: totally reflected). Prints figures; not a test (docs/caustics.md, Known differences).
# usage: bench/coplanar_tie.sh [SIZE] [THREADS]   (160x120 2)
set -eu
BENCH_SCENE=coplanar_tie BENCH_SIZE=160x120
. "$(dirname "$0")/scene_bench.sh"
printf "coplanar contact at %s, %s threads: share of the contact's pixels showing the floor\n" "$SIZE" "$THREADS"
printf "view    partray   povray\n"
for view in 0 1; do
    "$PARTRAY" render "$SCENE" -o "$TMP/pt_$view.png" --size "$SIZE" --threads "$THREADS" -A --quiet -D View=$view
    for lift in 0 -0.001; do
        povray +I"$SCENE" +O"$TMP/pov_${view}_$lift.png" +FN +W$W +H$H -A -D -V -P -UA +WT$THREADS \
            Declare=View=$view Declare=Lift=$lift >/dev/null 2>&1
    done
    python3 - "$TMP/pt_$view.png" "$TMP/pov_${view}_0.png" "$TMP/pov_${view}_-0.001.png" "$view" <<'PY'
import struct, sys, zlib
def read(path):
    d = open(path, 'rb').read(); i = 8; idat = b''
    while i < len(d):
        n, = struct.unpack('>I', d[i:i + 4]); t = d[i + 4:i + 8]; c = d[i + 8:i + 8 + n]; i += 12 + n
        if t == b'IHDR': w, h, bd, ct = struct.unpack('>IIBB', c[:10])
        elif t == b'IDAT': idat += c
    ch = {2: 3, 6: 4}[ct]; bpp = ch * (bd // 8); raw = zlib.decompress(idat); st = w * bpp
    prev = [0] * st; p = 0; img = []
    for y in range(h):
        f = raw[p]; row = raw[p + 1:p + 1 + st]; p += 1 + st; r = [0] * st
        for x in range(st):
            a = r[x - bpp] if x >= bpp else 0; b = prev[x]; c = prev[x - bpp] if x >= bpp else 0
            pr = 0 if f == 0 else a if f == 1 else b if f == 2 else (a + b) // 2 if f == 3 else \
                (a if abs(b - c) <= abs(a - c) and abs(b - c) <= abs(a + b - 2 * c) else b if abs(a - c) <= abs(a + b - 2 * c) else c)
            r[x] = (row[x] + pr) & 255
        prev = r
        img.append([tuple(r[x * bpp + k * (bd // 8)] for k in range(3)) for x in range(w)])
    return img
def cls(px):
    r, g, b = px
    return 'R' if r > 128 and g < 64 else 'G' if g > 128 and r < 64 else 'K' if r < 64 and g < 64 else 'M'
pt, pov, sunk, view = read(sys.argv[1]), read(sys.argv[2]), read(sys.argv[3]), sys.argv[4]
h, w = len(pt), len(pt[0])
region = [(x, y) for y in range(h) for x in range(w) if cls(sunk[y][x]) == 'R']
share = lambda im: sum(1 for x, y in region if cls(im[y][x]) == 'R') / max(1, len(region))
print("%-6s %8.3f %8.3f   (%d pixels)" % (view, share(pt), share(pov), len(region)))
PY
done
