#!/bin/sh
# The light under a wide slab of glassthing.pov's glass (fresnel reflection
# with conserve_energy, ior 1.5; bench/scenes/caustic_slab.pov), as a
# fraction of the unobstructed light on the same floor: partray's caustic
# layer beside POV-Ray 3.7's photons, at each light angle from the normal
# (and at 71 degrees without conserve_energy, and with a floor of
# brilliance 0.6, glassthing.pov's walls, where POV-Ray's photons are shaded
# with their stored, truncated direction). Each fraction is the mean
# luminance of the render with the slab over the one without (both linear
# EXR). Prints figures; not a test (docs/caustics.md).
# usage: bench/caustic_slab.sh [SIZE] [THREADS] [ANGLE...]   (80x60 2 0 45 71)
set -eu
BENCH_SCENE=caustic_slab BENCH_SIZE=80x60
. "$(dirname "$0")/scene_bench.sh"
[ $# -gt 2 ] && shift 2 || set -- 0 45 71
lum() { "$PARTRAY" compare "$1" "$2" | awk '/^mean luminance/ { print $6 / $4 }'; }
row() { # ANGLE CONSERVE [BRILLIANCE]
    b=${3:-1}
    for s in 0 1; do
        "$PARTRAY" render "$SCENE" -o "$TMP/pt_$s.exr" --size "$SIZE" --threads "$THREADS" --quiet \
            -D Slab=$s -D Angle=$1 -D Conserve=$2 -D Bril=$b
        povray +I"$SCENE" +O"$TMP/pov_$s.exr" +FE +W$W +H$H -A -D -V -P -GA +WT$THREADS \
            Declare=Slab=$s Declare=Angle=$1 Declare=Conserve=$2 Declare=Bril=$b >/dev/null 2>&1
    done
    pt=$(lum "$TMP/pt_0.exr" "$TMP/pt_1.exr"); pov=$(lum "$TMP/pov_0.exr" "$TMP/pov_1.exr")
    printf "%5s  %8s  %10s  %8.4f  %8.4f  %+6.1f%%\n" "$1" "$2" "$b" "$pt" "$pov" "$(awk -v a="$pt" -v b="$pov" 'BEGIN{print 100*(a/b-1)}')"
}
printf "glass slab at %s, %s threads: the floor's light through the slab over the unobstructed light\n" "$SIZE" "$THREADS"
printf "angle  conserve  brilliance   partray    povray   partray/povray\n"
for a in "$@"; do row "$a" 1; done
row 71 0
row 71 1 0.6
