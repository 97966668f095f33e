#!/bin/sh
# test_motion_cli.sh PARTRAY ROOT - `partray render` of an animation in one
# run with --gi detp keeps the photon paths from frame to frame (what
# app/main.c passes on: objects that may have changed, lights that did):
# every frame's image equals --detp-full's byte for byte, and the frames
# after the first re-trace only part of the paths (each frame's "detp:"
# line). Then a moving light: that frame is a full one.
set -eu
P=$1
ROOT=$2
T=$(mktemp -d /tmp/partray-test-motion-XXXXXX)
trap 'rm -rf "$T"' EXIT
cd "$T"
cp "$ROOT/tests/scenes/detp_cbox.pov" .
"$P" render detp_cbox.pov --gi detp --photons 5000 --size 32x24 --threads 2 +KFI1 +KFF3 -o inc.pfm 2>inc.log
"$P" render detp_cbox.pov --gi detp --detp-full --photons 5000 --size 32x24 --threads 2 +KFI1 +KFF3 -o full.pfm 2>full.log
for k in 1 2 3; do
    cmp "inc$k.pfm" "full$k.pfm" || { echo "frame $k differs from the full recomputation"; exit 1; }
done
grep -q "frame 1: detp: first frame" inc.log || { echo "frame 1 is not a full frame"; cat inc.log; exit 1; }
for k in 2 3; do
    line=$(grep "frame $k: detp:" inc.log)
    echo "$line"
    case "$line" in *"detp: incremental, 1 of 11 objects moved"*) ;; *) echo "frame $k: expected an incremental frame with 1 object moved"; exit 1 ;; esac
    pct=$(echo "$line" | sed 's/.*paths re-traced (\([0-9.]*\)%).*/\1/')
    awk -v p="$pct" 'BEGIN { exit !(p > 0 && p < 30) }' || { echo "frame $k re-traced $pct% of the paths"; exit 1; }
done
grep -q "frame 2: detp: full recomputation asked for" full.log || { echo "--detp-full did not recompute"; exit 1; }
# a light that moves with the clock: every frame is a full one
sed 's/^  <27.8, 54.80, 27.95> color/  <27.8 + 5 * clock, 54.80, 27.95> color/' detp_cbox.pov > moving_light.pov
grep -q "27.8 + 5 \* clock" moving_light.pov
"$P" render moving_light.pov --gi detp --photons 5000 --size 32x24 --threads 2 +KFI1 +KFF2 -o ml.pfm 2>ml.log
grep -q "frame 2: detp: a light changed" ml.log || { echo "a moving light did not make a full frame"; cat ml.log; exit 1; }
echo "ok: 3 frames equal to the full recomputation, a moving light gives a full frame"
