#!/bin/sh
# gi_modes.sh - the user guide's "which GI mode and quality" table: one
# scene rendered in every GI mode at several quality settings, each image
# compared with a converged path-traced reference (mean HDR-FLIP, relMSE,
# mean luminance against the reference) beside its total time. Figures,
# not a test; docs/guide.md shows its output.
#
#   bench/gi_modes.sh [SCENE] [SIZE] [REF_SPP]
#     SCENE    default scenes/cbox.pov; SIZE default 96 (square);
#     REF_SPP  path samples per pixel of the reference (default 1024)
#   BUILD=DIR (default build), THREADS=N (default 2), OUT=DIR (default
#   /tmp/gi_modes_SCENE_SIZE: the reference is kept there and reused),
#   TABLE_ONLY=1 prints the table of the sweep already in OUT, OPTS="..."
#   render options for every render (default +A0.3: none and particle
#   antialias as POV-Ray would; path and pmfg sample each pixel anyway).
# Uses `partray sweep` (docs/measuring.md): OUT/sweep.csv, OUT/plot.png and
# OUT/index.html hold every render.
set -eu
cd "$(dirname "$0")/.."
SCENE=${1:-scenes/cbox.pov}
SIZE=${2:-96}
REF_SPP=${3:-1024}
BUILD=${BUILD:-build}
THREADS=${THREADS:-2}
OPTS=${OPTS-+A0.3}
name=$(basename "$SCENE" .pov)
OUT=${OUT:-/tmp/gi_modes_${name}_${SIZE}}
P="$BUILD/partray"
[ -x "$P" ] || { echo "gi_modes: build partray first ($P)" >&2; exit 2; }
mkdir -p "$OUT"
REF="$OUT/ref_path_${REF_SPP}.exr"
if [ ! -s "$REF" ]; then
    echo "reference: --gi path --spp $REF_SPP at ${SIZE}x${SIZE} -> $REF" >&2
    "$P" render "$SCENE" --gi path --spp "$REF_SPP" --size "${SIZE}x${SIZE}" --threads "$THREADS" --seed 7 \
        --float -q -o "$REF"
fi
# none: POV-Ray's lighting without GI; particle: the particle count;
# path: samples per pixel; pmfg: final-gather rays per pixel
[ "${TABLE_ONLY:-0}" = 1 ] || "$P" sweep "$SCENE" --ref "$REF" --size "${SIZE}x${SIZE}" --out "$OUT/sweep" --threads "$THREADS" --quiet $OPTS \
    --gi none,particle,path,pmfg \
    --vary particle/particles=25000,50000,200000 \
    --vary path/spp=16,64,256 \
    --vary pmfg/fg-rays=64,256,1024 >/dev/null || true
csv="$OUT/sweep/sweep.csv"
[ -s "$csv" ] || { echo "gi_modes: no $csv" >&2; exit 1; }
echo "# $SCENE at ${SIZE}x${SIZE}, $THREADS threads, options '$OPTS', against --gi path --spp $REF_SPP"
echo "| mode | setting | total s | mean FLIP | relMSE | luminance vs reference |"
echo "|---|---|---|---|---|---|"
# columns by name: mode, settings, total_s, relmse, flip_mean, image, status
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
         { print $c["mode"] "\t" ($c["settings"] == "" ? "-" : $c["settings"]) "\t" $c["total_s"] "\t" $c["flip_mean"] "\t" $c["relmse"] "\t" $c["image"] "\t" $c["status"] }' "$csv" |
while IFS="$(printf '\t')" read -r mode set total flip relmse image status; do
    lum=$("$P" compare "$REF" "$OUT/sweep/$image" --json 2>/dev/null | awk '/"relative"/ { gsub(/[,]/, ""); printf "%+.2f%%", $2 * 100 }')
    [ "$status" = ok ] || set="$set ($status)"
    printf '| %s | %s | %.2f | %.4f | %.4f | %s |\n' "$mode" "$set" "$total" "$flip" "$relmse" "$lum"
done
