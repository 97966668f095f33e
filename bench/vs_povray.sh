#!/bin/sh
# Wall time of partray beside POV-Ray 3.7 on the distribution's
# radiosity/cornell.pov with its radiosity block removed (direct light only),
# at the same size, antialiasing and thread count. Prints figures; not a test.
# usage: bench/vs_povray.sh [SIZE] [THREADS] [REPEATS]
set -eu
SIZE=${1:-512}
THREADS=${2:-2}
REPEATS=${3:-3}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PARTRAY=${PARTRAY:-$ROOT/build/partray}
SRC=/usr/share/povray-3.7/scenes/radiosity/cornell.pov
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
# drop the radiosity{...} block (it spans lines 15-22 of the distribution file)
awk 'BEGIN{skip=0} /radiosity *\{/ {skip=1} { if(!skip) print; else if ($0 ~ /^ *\}/) skip=0 }' "$SRC" > "$TMP/cornell_direct.pov"
cd "$TMP"
now() { date +%s.%N; }
best_pov=999999; best_pt=999999
i=0
while [ $i -lt "$REPEATS" ]; do
    t0=$(now); povray +Icornell_direct.pov +Opov.png +W$SIZE +H$SIZE +A0.3 -D -V -GA +WT$THREADS >/dev/null 2>&1; t1=$(now)
    "$PARTRAY" render cornell_direct.pov -o pt.png +W$SIZE +H$SIZE +A0.3 --threads "$THREADS" --quiet; t2=$(now)
    best_pov=$(awk -v a="$t0" -v b="$t1" -v m="$best_pov" 'BEGIN{d=b-a; print (d<m)?d:m}')
    best_pt=$(awk -v a="$t1" -v b="$t2" -v m="$best_pt" 'BEGIN{d=b-a; print (d<m)?d:m}')
    i=$((i + 1))
done
printf "cornell (no radiosity) %sx%s +A0.3, %s threads, best of %s:\n" "$SIZE" "$SIZE" "$THREADS" "$REPEATS"
printf "  povray  %.3f s\n  partray %.3f s\n  speed-up %.2fx\n" "$best_pov" "$best_pt" "$(awk -v a="$best_pov" -v b="$best_pt" 'BEGIN{print a/b}')"
