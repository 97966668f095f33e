#!/bin/sh
# glossy.sh - glossy interreflection: `--gi vpl` (seed 003's VPL reflectance
# filtering) and `--gi particle` (diffuse only) against the path tracer,
# which carries the glossy lobe of phong/specular (core/glossy.h), and the
# paper's hardware-independent figures. Figures, never pass/fail.
#
#   bench/glossy.sh [NAME=SCENE ...]   SCENE: a path under the distribution's
#                                      examples (default: the four below)
#
#   metals   incdemo/metals/golds.pov (metals.inc: metallic, specular, reflection)
#   metrefl  textures/finishes/metallicreflection.pov
#   teapot   advanced/teapot/teapot.pov
#   chess2   advanced/chess2.pov (specular pieces; rendered at CHESS_SIZE)
#
# Each scene's directory is copied to OUT (scenes write files beside
# themselves) and rendered at SIZE (80x60; chess2 at CHESS_SIZE, 48x36, its
# cloud sky makes every ray slow) with THREADS (2) threads:
#   path      --gi path --spp PATH_SPP (1024): the reference
#   vpl       --gi vpl (16384 VPLs, 1 bounce at the VPLs, min-max cuts,
#             adaptive image sampling; 16 eye samples)
#   particle  --gi particle (the scene's radiosity{} or the defaults)
# Printed per scene (done-when 2): wall time of each; HDR-FLIP (mean) and the
# mean luminance of vpl and particle against path, and vpl's FLIP as a
# fraction of particle's.
# Then (done-when 3), from vpl's stats (--stats JSON, "vpl"): the fraction
# of pixels (with a surface) whose indirect light was gathered (paper:
# 1.2-4.8% at 1024x768; a small image has far fewer pixels per 16x16
# block, so the fraction is larger); nodes visited per gathered pixel with
# the min-max cut and with the full tree (--vpl-cut full; paper: 685-906
# against 3,107-6,379); the eye gather's kernel time with min-max cuts
# against brute force over every VPL (--vpl-cut brute), both at every pixel
# (--vpl-adaptive off), and with adaptive sampling on as well (paper: ~20x
# for the cuts alone). Times are from one run on a shared machine: take the
# ratios, not the seconds.
#
# BUILD=DIR (default build) holds partray; EXAMPLES=DIR (default
# /usr/share/doc/povray/examples); OUT=DIR (default /tmp/glossy_bench)
# keeps the images, stats and logs. PARTICLE=0 skips particle GI; PMFG=1
# also renders --gi pmfg (defaults; minutes a scene) and prints it against
# path: the two references, glossy lobe and all, should agree;
# KEEP_PATH=1 reuses path images already in OUT (chess2's takes minutes).
set -eu
cd "$(dirname "$0")/.."
ROOT=$(pwd)
BUILD=${BUILD:-build}
case $BUILD in /*) ;; *) BUILD=$ROOT/$BUILD ;; esac
PARTRAY=$BUILD/partray
SIZE=${SIZE:-80x60}
CHESS_SIZE=${CHESS_SIZE:-48x36}
THREADS=${THREADS:-2}
PATH_SPP=${PATH_SPP:-1024}
EXAMPLES=${EXAMPLES:-/usr/share/doc/povray/examples}
OUT=${OUT:-/tmp/glossy_bench}
PARTICLE=${PARTICLE:-1}
KEEP_PATH=${KEEP_PATH:-0}
PMFG=${PMFG:-0}
[ $# -gt 0 ] || set -- metals=incdemo/metals/golds.pov metrefl=textures/finishes/metallicreflection.pov \
    teapot=advanced/teapot/teapot.pov chess2=advanced/chess2.pov
mkdir -p "$OUT"

now() { date +%s.%N; }

# json FILE KEY...: a number from a JSON file (nested keys)
json() {
    python3 -c 'import json, sys
v = json.load(open(sys.argv[1]))
for k in sys.argv[2:]: v = v[k]
print(v)' "$@"
}

# render NAME MODE SIZE ARGS...: one render in the scene's copy, wall time into $OUT/NAME.MODE.time
render() {
    name=$1 mode=$2 size=$3
    shift 3
    t0=$(now)
    (cd "$OUT/$name" && "$PARTRAY" render "$SCENE" --size "$size" --threads "$THREADS" \
        -o "$OUT/$name.$mode.exr" --stats "$OUT/$name.$mode.json" "$@" >"$OUT/$name.$mode.log" 2>&1) ||
        echo "  $name $mode: render failed (see $OUT/$name.$mode.log)"
    t1=$(now)
    awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f\n", b - a }' >"$OUT/$name.$mode.time"
}

compare() {
    "$PARTRAY" compare "$OUT/$1.path.exr" "$OUT/$1.$2.exr" --json >"$OUT/$1.$2.cmp.json" 2>/dev/null
}

printf '%-8s %-6s %9s %10s %10s %9s\n' scene mode wall_s hdr_flip mean_lum vs_path
for arg in "$@"; do
    name=${arg%%=*}
    path=${arg#*=}
    SCENE=$(basename "$path")
    size=$SIZE
    [ "$name" = chess2 ] && size=$CHESS_SIZE
    rm -rf "${OUT:?}/$name"
    cp -r "$EXAMPLES/$(dirname "$path")" "$OUT/$name"
    if [ "$KEEP_PATH" != 1 ] || [ ! -f "$OUT/$name.path.exr" ]; then
        render "$name" path "$size" --gi path --spp "$PATH_SPP"
    fi
    render "$name" vpl "$size" --gi vpl
    render "$name" vplfull "$size" --gi vpl --vpl-cut full
    render "$name" vplmm1 "$size" --gi vpl --vpl-adaptive off
    render "$name" vplbrute "$size" --gi vpl --vpl-cut brute --vpl-adaptive off
    [ "$PARTICLE" = 1 ] && render "$name" particle "$size" --gi particle
    [ "$PMFG" = 1 ] && render "$name" pmfg "$size" --gi pmfg
    for mode in vpl particle pmfg; do [ -f "$OUT/$name.$mode.exr" ] && compare "$name" "$mode"; done
    printf '%-8s %-6s %9.1f %10s %10.5f %9s\n' "$name" path "$(cat "$OUT/$name.path.time")" - \
        "$(json "$OUT/$name.vpl.cmp.json" luminance reference)" -
    for mode in vpl particle pmfg; do
        [ -f "$OUT/$name.$mode.cmp.json" ] || continue
        printf '%-8s %-6s %9.1f %10.4f %10.5f %+8.2f%%\n' "$name" "$mode" "$(cat "$OUT/$name.$mode.time")" \
            "$(json "$OUT/$name.$mode.cmp.json" flip mean)" "$(json "$OUT/$name.$mode.cmp.json" luminance test)" \
            "$(awk -v r="$(json "$OUT/$name.$mode.cmp.json" luminance relative)" 'BEGIN { print 100 * r }')"
    done
    if [ -f "$OUT/$name.particle.cmp.json" ]; then
        echo "$name: vpl FLIP / particle FLIP = $(awk -v a="$(json "$OUT/$name.vpl.cmp.json" flip mean)" \
            -v b="$(json "$OUT/$name.particle.cmp.json" flip mean)" 'BEGIN { printf "%.3f", a / b }') (done-when 2: at most 0.5)"
    fi
done

echo
echo "paper's figures (done-when 3): vpl stats"
printf '%-8s %8s %7s %9s %9s %11s %11s %9s %9s %9s %9s\n' scene vpls cutnod sampled% visit_mm visit_full \
    gather_mm_s brute_s speedup adapt_s speedup2
for arg in "$@"; do
    name=${arg%%=*}
    j=$OUT/$name
    [ -f "$j.vpl.json" ] || continue
    v() { json "$1" vpl "$2"; }
    tmm=$(json "$j.vplmm1.json" vpl timings gather_pixels)
    tbr=$(json "$j.vplbrute.json" vpl timings gather_pixels)
    tad=$(json "$j.vpl.json" vpl timings gather_pixels)
    printf '%-8s %8s %7s %9.2f %9.0f %11.0f %11.3f %9.3f %9.1f %9.3f %9.1f\n' "$name" "$(v "$j.vpl.json" vpls)" \
        "$(v "$j.vpl.json" cut_nodes)" "$(awk -v f="$(v "$j.vpl.json" fraction_sampled)" 'BEGIN { print 100 * f }')" \
        "$(v "$j.vplmm1.json" visits_mean)" "$(v "$j.vplfull.json" visits_mean)" "$tmm" "$tbr" \
        "$(awk -v a="$tbr" -v b="$tmm" 'BEGIN { print a / b }')" "$tad" "$(awk -v a="$tbr" -v b="$tad" 'BEGIN { print a / b }')"
done
echo "(sampled%: pixels gathered by the adaptive scheme; visit_mm/visit_full: nodes per gathered pixel with the"
echo " min-max cut / the full tree; gather_mm_s, brute_s: kernel seconds gathering at every pixel centre with"
echo " min-max cuts / over every VPL; speedup = brute / min-max; adapt_s, speedup2: min-max cuts with adaptive"
echo " sampling, all its levels; mirror and refraction hits are gathered apart and not counted here)"
