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
    python3 - "$(dirname "$0")/../scripts" "$TMP/pt_$view.png" "$TMP/pov_${view}_0.png" "$TMP/pov_${view}_-0.001.png" "$view" <<'PY'
import sys
sys.path.insert(0, sys.argv.pop(1))
from pngread import read_png
def read(path):
    return read_png(path)[2]
def cls(px):
    r, g = px[0] * 255, px[1] * 255
    return 'R' if r > 128 and g < 64 else 'G' if g > 128 and r < 64 else 'K' if r < 64 and g < 64 else 'M'
pt, pov, sunk, view = read(sys.argv[1]), read(sys.argv[2]), read(sys.argv[3]), sys.argv[4]
h, w = len(pt), len(pt[0])
region = [(x, y) for y in range(h) for x in range(w) if cls(sunk[y][x]) == 'R']
share = lambda im: sum(1 for x, y in region if cls(im[y][x]) == 'R') / max(1, len(region))
print("%-6s %8.3f %8.3f   (%d pixels)" % (view, share(pt), share(pov), len(region)))
PY
done
