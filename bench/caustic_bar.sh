#!/bin/sh
# glassthing.pov's long glass bar alone (bench/scenes/caustic_bar.pov),
# partray's caustic layer beside POV-Ray 3.7's photons, both at photon
# spacing 0.025 (glassthing's 4x), linear EXR, from straight above:
#   shadow  the floor in the bar's shadow (lit by photons through its long
#           faces and ambient light): mean luminance of each, and their ratio;
#   pipe    the floor beyond the bar's far end, the bar's top and long faces
#           covered: the light that enters one end and leaves the other after
#           total reflections inside, as the mean luminance with the entering
#           end open less that with it covered, for each, and their ratio.
# Prints figures; not a test (docs/caustics.md).
# usage: bench/caustic_bar.sh [SIZE] [THREADS]   (80x60 2)
set -eu
BENCH_SCENE=caustic_bar BENCH_SIZE=80x60
. "$(dirname "$0")/scene_bench.sh"
# render NAME VIEW BLOCK: both renderers into $TMP/pt_NAME.exr, $TMP/pov_NAME.exr
render() {
    "$PARTRAY" render "$SCENE" -o "$TMP/pt_$1.exr" --size "$SIZE" --threads "$THREADS" --quiet \
        -D View=$2 -D Block=$3 -D Spacing=0.025
    povray +I"$SCENE" +O"$TMP/pov_$1.exr" +FE +W$W +H$H -A -D -V -P -GA +WT$THREADS \
        Declare=View=$2 Declare=Block=$3 Declare=Spacing=0.025 >/dev/null 2>&1
}
# the mean luminance of an EXR (compared with itself)
lum() { "$PARTRAY" compare "$1" "$1" | awk '/^mean luminance/ { print $4 }' | tr -d ,; }
render shadow 0 0
render open 1 0
render blocked 1 1
printf "glassthing's glass bar at %s, %s threads, photon spacing 0.025 on both sides\n" "$SIZE" "$THREADS"
printf "view      partray    povray   partray/povray\n"
a=$(lum "$TMP/pt_shadow.exr"); b=$(lum "$TMP/pov_shadow.exr")
printf "shadow   %8.4f  %8.4f  %8.4f\n" "$a" "$b" "$(awk -v a="$a" -v b="$b" 'BEGIN{print a/b}')"
a=$(awk -v o="$(lum "$TMP/pt_open.exr")" -v c="$(lum "$TMP/pt_blocked.exr")" 'BEGIN{print o-c}')
b=$(awk -v o="$(lum "$TMP/pov_open.exr")" -v c="$(lum "$TMP/pov_blocked.exr")" 'BEGIN{print o-c}')
printf "pipe     %8.4f  %8.4f  %8.4f\n" "$a" "$b" "$(awk -v a="$a" -v b="$b" 'BEGIN{print a/b}')"
