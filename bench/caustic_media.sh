#!/bin/sh
# Media photons against POV-Ray 3.7's: a box of scattering media that is a
# photon target, lit by a distant point light (bench/scenes/caustic_media_box.pov),
# rendered by partray (caustic layer) and povray, linear EXR, with media
# photons (Photons=1) and with the light direct (Photons=0): the mean
# luminance of each image and partray's over povray's. A view ray across
# the box sees Scat x 4 = 0.4 in both cases (the closed form of
# test_caustics' test_media_photons, there with Scat 0.5). Prints figures;
# not a test (docs/caustics.md).
# usage: bench/caustic_media.sh [SIZE] [THREADS]   (40x40 2)
set -eu
BENCH_SCENE=caustic_media_box BENCH_SIZE=40x40
. "$(dirname "$0")/scene_bench.sh"
# mean luminance of B (partray compare A B prints both images' means)
lum() { "$PARTRAY" compare "$1" "$1" | awk '/^mean luminance/ { sub(",", "", $4); print $4 }'; }
printf "media box at %s, %s threads: mean luminance (the box's centre sees 0.4)\n" "$SIZE" "$THREADS"
printf "photons   partray    povray   partray/povray\n"
for p in 1 0; do
    "$PARTRAY" render "$SCENE" -o "$TMP/pt_$p.exr" --size "$SIZE" --threads "$THREADS" --quiet -D Photons=$p
    povray +I"$SCENE" +O"$TMP/pov_$p.exr" +FE +W$W +H$H -A -D -V -P -GA +WT$THREADS Declare=Photons=$p >/dev/null 2>&1
    pt=$(lum "$TMP/pt_$p.exr"); pov=$(lum "$TMP/pov_$p.exr")
    printf "%7s  %8.4f  %8.4f  %+6.2f%%\n" "$p" "$pt" "$pov" "$(awk -v a="$pt" -v b="$pov" 'BEGIN{print 100*(a/b-1)}')"
done
