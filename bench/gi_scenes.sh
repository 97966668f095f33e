#!/bin/sh
# gi_scenes.sh - per-scene report of the particle GI on its four
# benchmark scenes (scenes/cbox.pov, the distribution's radiosity/cornell.pov,
# scenes/maze.pov, scenes/conference.pov). Figures, never pass/fail.
#
#   bench/gi_scenes.sh [STAGE...]    STAGE: refs scenes pmfg cbox512
#                                    (default: refs scenes pmfg)
#
# refs     a converged --gi path reference of every scene at QSIZE (128)
#          with REF_SPP (1024) samples per pixel, seed 1, kept in REFDIR
#          (/tmp/gi_scenes_refs; an existing file is reused), timed.
# scenes   bench_gi on each scene at SIZE (512), THREADS (2) threads, n_b
#          NB (8), REPS (3) repetitions (median), with 50,000 particles on
#          cbox and cornell and 200,000 on maze and conference: geometry
#          stage time and breakdown (wall; CPU of all threads), memory, lighting stage time, frame
#          --gi particle against --gi none (wall and CPU); then, with the
#          same particles, a QSIZE frame with FRAME_SPP (16) stratified eye
#          samples per pixel (the reference is antialiased too) against the
#          path reference: mean HDR-FLIP, RMSE, mean luminance (bench_gi
#          --ref --ref-spp), and `partray compare` of that frame.
# pmfg     --gi pmfg with 4096 gather rays (the default --fg-rays) at PSIZE
#          (32), timed; its frame (photons, maps, irradiance, render)
#          extrapolated to SIZE by scaling the render (the final gather, per
#          pixel) by the pixel ratio and keeping the rest (the irradiance is
#          precomputed at photons, reference/README.md), over the particle
#          frame of the scenes stage (geometry stage excluded): wall time,
#          and CPU time shared out over the parts as their wall times are.
# cbox512  cbox alone at SIZE: a path reference with CBOX_REF_SPP (256)
#          samples per pixel and a particle frame with CBOX_FRAME_SPP (4).
#
# SCENES="name ..." picks scenes (default: cbox cornell maze conference).
# BUILD=DIR (default build) holds partray and bench/bench_gi; OUT=DIR
# (default /tmp/gi_scenes) gets the logs and images. The load average is
# printed before each run: wall times are only comparable under one load,
# CPU times (getrusage, all threads) less so.
set -eu
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
SIZE=${SIZE:-512}
THREADS=${THREADS:-2}
REPS=${REPS:-3}
NB=${NB:-8}
QSIZE=${QSIZE:-128}
REF_SPP=${REF_SPP:-1024}
FRAME_SPP=${FRAME_SPP:-16}
CBOX_REF_SPP=${CBOX_REF_SPP:-256}
CBOX_FRAME_SPP=${CBOX_FRAME_SPP:-4}
PSIZE=${PSIZE:-32}
REFDIR=${REFDIR:-/tmp/gi_scenes_refs}
OUT=${OUT:-/tmp/gi_scenes}
SCENES=${SCENES:-cbox cornell maze conference}
STAGES=${*:-refs scenes pmfg}
[ -x "$BUILD/partray" ] && [ -x "$BUILD/bench/bench_gi" ] || {
    echo "gi_scenes: build partray and bench_gi first ($BUILD)" >&2
    exit 2
}
mkdir -p "$REFDIR" "$OUT"

scene_file() {
    case $1 in
    cbox) echo scenes/cbox.pov ;;
    cornell) echo /usr/share/povray-3.7/scenes/radiosity/cornell.pov ;;
    maze) echo scenes/maze.pov ;;
    conference) echo scenes/conference.pov ;;
    *) echo "gi_scenes: unknown scene $1" >&2; exit 2 ;;
    esac
}
scene_count() {
    case $1 in
    maze | conference) echo 200000 ;;
    *) echo 50000 ;;
    esac
}
load() { printf '[%s] load: %s\n' "$1" "$(uptime | sed 's/.*load average: //')"; }


for stage in $STAGES; do
    for name in $SCENES; do
        f=$(scene_file "$name")
        n=$(scene_count "$name")
        case $stage in
        refs)
            ref=$REFDIR/${name}_path_${QSIZE}_$REF_SPP.exr
            if [ -s "$ref" ]; then
                echo "path reference: $ref (existing)"
                continue
            fi
            echo "== path reference: $name ($f), ${QSIZE}x$QSIZE, $REF_SPP spp, $THREADS threads"
            load "$name path reference"
            /usr/bin/time -f "path reference: %e s wall, %U s user, %S s system" \
                "$BUILD/partray" render "$f" --gi path --spp "$REF_SPP" --size "${QSIZE}x$QSIZE" \
                --threads "$THREADS" --seed 1 --float -o "$ref" --stats "${ref%.exr}.json" --quiet
            ;;
        scenes)
            ref=$REFDIR/${name}_path_${QSIZE}_$REF_SPP.exr
            echo "== $name ($f), ${SIZE}x$SIZE, $n particles, n_b $NB, $THREADS threads, $REPS reps"
            set -- "$f" --size "$SIZE" --count "$n" --nb "$NB" --threads "$THREADS" --reps "$REPS" \
                --out "$OUT/$name"
            [ -s "$ref" ] && set -- "$@" --ref "$ref" --ref-spp "$FRAME_SPP"
            load "$name"
            "$BUILD/bench/bench_gi" "$@" | tee "$OUT/${name}_scenes.log"
            if [ -s "$ref" ]; then
                "$BUILD/partray" compare "$ref" "$OUT/${name}_ref_particle.exr" \
                    --heatmap "$OUT/${name}_flip.png" | grep -E 'FLIP|RMSE|PSNR'
            fi
            ;;
        cbox512)
            [ "$name" = cbox ] || continue
            ref=$REFDIR/cbox_path_${SIZE}_$CBOX_REF_SPP.exr
            if [ ! -s "$ref" ]; then
                echo "== path reference: cbox, ${SIZE}x$SIZE, $CBOX_REF_SPP spp"
                load "cbox path reference"
                /usr/bin/time -f "path reference: %e s wall, %U s user, %S s system" \
                    "$BUILD/partray" render "$f" --gi path --spp "$CBOX_REF_SPP" --size "${SIZE}x$SIZE" \
                    --threads "$THREADS" --seed 1 --float -o "$ref" --stats "${ref%.exr}.json" --quiet
            fi
            load "cbox $SIZE quality"
            "$BUILD/bench/bench_gi" "$f" --size "$SIZE" --count "$n" --nb "$NB" --threads "$THREADS" --reps 1 \
                --spp "$CBOX_FRAME_SPP" --ref "$ref" --out "$OUT/cbox$SIZE" >"$OUT/cbox${SIZE}.log"
            grep -E '^against' "$OUT/cbox${SIZE}.log"
            "$BUILD/partray" compare "$ref" "$OUT/cbox${SIZE}_particle.exr" | grep -E 'FLIP|RMSE|PSNR'
            ;;
        pmfg)
            echo "== pmfg: $name ($f), ${PSIZE}x$PSIZE, 4096 gather rays, $THREADS threads"
            load "$name pmfg"
            js=$OUT/${name}_pmfg_$PSIZE.json
            if [ ! -s "$js" ]; then
                /usr/bin/time -o "${js%.json}.time" -f "%e %U %S" \
                    "$BUILD/partray" render "$f" --gi pmfg --fg-rays 4096 --size "${PSIZE}x$PSIZE" \
                    --threads "$THREADS" --seed 1 -o "$OUT/${name}_pmfg_$PSIZE.exr" --stats "$js" --quiet
            else
                echo "(existing $js)"
            fi
            log=$OUT/${name}_scenes.log
            python3 - "$js" "$log" "$PSIZE" "$SIZE" <<'PY'
import json, re, sys
js, log, ps, size = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
j = json.load(open(js))
t = j["pmfg"]["timings"]
wall, user, system = map(float, open(js[:-5] + ".time").read().split()[-3:])
k = (size * size) / (ps * ps)
fixed = t["lights"] + t["photons"] + t["maps"] + t["irradiance"]
parts = fixed + t["render"]
scaled = t["render"] * k
print("pmfg at %dx%d: lights %.2f s, photons %.2f s, maps %.2f s, irradiance %.2f s, render %.2f s (wall); process %.1f s wall, "
      "%.1f s CPU" % (ps, ps, t["lights"], t["photons"], t["maps"], t["irradiance"], t["render"], wall, user + system))
# CPU of the frame's parts: the process's CPU time shared out as their wall
# times are (parse and accel, a few percent, counted in)
cpu = (user + system) * (fixed + scaled) / parts
print("pmfg extrapolated to %dx%d: %.0f s wall (%.2f s + render x %.0f), ~%.0f s CPU" %
      (size, size, fixed + scaled, fixed, k, cpu))
try:
    txt = open(log).read()
    fp = float(re.search(r"frame --gi particle: ([0-9.]+) ms", txt).group(1)) / 1e3
    cp = float(re.search(r"CPU time per frame .*particle ([0-9.]+) ms", txt).group(1)) / 1e3
    print("particle frame at %dx%d (scenes stage): %.3f s wall, %.3f s CPU; pmfg / particle per frame: "
          "%.0fx wall, %.0fx CPU" % (size, size, fp, cp, (fixed + scaled) / fp, cpu / cp))
except (OSError, AttributeError):
    print("(run the scenes stage first for the per-frame ratio)")
PY
            ;;
        *)
            echo "gi_scenes: unknown stage $stage" >&2
            exit 2
            ;;
        esac
    done
done
