#!/bin/sh
# sweep_gi.sh - particle sweep: particle counts 50K/100K/200K/400K
# x n_b 1/3/6/9 on a scene, each frame's error against a converged --gi path
# reference (mean FLIP, RMSE, mean luminance) beside its lighting and frame
# times, as one table (bench_gi --sweep --ref). Figures, not a test.
#
#   bench/sweep_gi.sh [BUILD_DIR] [SCENE] [SIZE] [REF_SPP]
#     BUILD_DIR  where partray and bench/bench_gi are (default: build)
#     SCENE      default scenes/cbox.pov; SIZE default 128 (square)
#     REF_SPP    path samples per pixel of the reference (default 2048)
#   THREADS=N (default 2), FRAME_SPP=N samples per pixel of the particle
#   frames (default 16: the reference is antialiased), REF=FILE.exr uses an
#   existing reference instead of rendering one (kept in /tmp otherwise).
set -eu
cd "$(dirname "$0")/.."
BUILD=${1:-build}
SCENE=${2:-scenes/cbox.pov}
SIZE=${3:-128}
REF_SPP=${4:-2048}
THREADS=${THREADS:-2}
FRAME_SPP=${FRAME_SPP:-16}
[ -x "$BUILD/partray" ] && [ -x "$BUILD/bench/bench_gi" ] || {
    echo "sweep_gi: build partray and bench_gi first" >&2
    exit 2
}
if [ -z "${REF:-}" ]; then
    REF=/tmp/sweep_gi_ref_$(basename "$SCENE" .pov)_${SIZE}_${REF_SPP}.exr
    if [ ! -s "$REF" ]; then
        echo "rendering the path reference ($SIZE x $SIZE, $REF_SPP spp) to $REF"
        "$BUILD/partray" render "$SCENE" --gi path --spp "$REF_SPP" --size "${SIZE}x${SIZE}" --threads "$THREADS" \
            -o "$REF"
    fi
fi
printf 'load %s\n' "$(cut -d' ' -f1 /proc/loadavg)"
"$BUILD/bench/bench_gi" "$SCENE" --threads "$THREADS" --size "$SIZE" --spp "$FRAME_SPP" --reps 1 --ref "$REF" --sweep
