#!/bin/sh
# bench_view.sh - the interactive viewer's figures (issue 10): images per
# second while the camera orbits, and the time from a light move to the
# relit image, per GI mode. Figures, not a pass/fail test.
#
#   bench/bench_view.sh [BUILD_DIR] [SCENE] [SIZE] [MODES]
#     BUILD_DIR  where `partray` is (default: build)
#     SCENE      default scenes/cbox.pov;  SIZE default 512x512
#     MODES      default "none particle"
#   THREADS=N (default 2, the CI machine's cores), ORBIT_S=5, MOVES=4,
#   PREVIEW=D fixes the preview at 1/D of the size (default: adaptive).
#
# Runs `partray view --script` under Xvfb (started here on a free display
# when DISPLAY is not set). The script waits until the mode is built and the
# image refined, orbits the camera 1.5 degrees per event at 30 events/s for
# ORBIT_S seconds, waits until refined, then moves the light MOVES times
# (waiting for the full refinement after each). Reported:
#   orbit img/s     images the render thread finished while orbiting / time
#   preview px      mean width of those images (the preview adapts its size)
#   cam->img ms     input to the first image showing it, mean
#   light->img ms   light move to the first relit image (a preview), mean/max
#   light->full ms  light move to the relit full-resolution image, mean
#   relight ms      the GI's lighting stage inside that, mean
#   build s         the mode's geometry + lighting stages at start
set -eu
cd "$(dirname "$0")/.."
BUILD=${1:-build}
SCENE=${2:-scenes/cbox.pov}
SIZE=${3:-512x512}
MODES=${4:-none particle}
THREADS=${THREADS:-2}
ORBIT_S=${ORBIT_S:-5}
MOVES=${MOVES:-4}
PREVIEW_OPT=
[ -n "${PREVIEW:-}" ] && PREVIEW_OPT="--preview $PREVIEW"
BIN=$BUILD/partray
[ -x "$BIN" ] || { echo "bench_view: no $BIN (build the partray target first)" >&2; exit 2; }

TMP=$(mktemp -d /tmp/bench_view.XXXXXX)
XPID=
cleanup() {
    [ -n "$XPID" ] && kill "$XPID" 2>/dev/null && wait "$XPID" 2>/dev/null
    rm -rf "$TMP"
}
trap cleanup EXIT INT TERM

if [ -z "${DISPLAY:-}" ]; then
    command -v Xvfb >/dev/null || { echo "bench_view: needs a display or Xvfb" >&2; exit 2; }
    Xvfb -displayfd 3 -screen 0 1024x768x24 -nolisten tcp -noreset 3>"$TMP/display" >/dev/null 2>&1 &
    XPID=$!
    i=0
    while [ ! -s "$TMP/display" ] && [ $i -lt 100 ]; do sleep 0.1; i=$((i + 1)); done
    DISPLAY=:$(head -n1 "$TMP/display")
    export DISPLAY
fi

# the script
{
    echo "0 wait-idle"
    echo "0 mark ready"
    awk -v n=$((ORBIT_S * 30)) 'BEGIN { for (i = 0; i < n; i++) printf "%.4f camera orbit 1.5 0\n", 0.05 + i / 30.0 }'
    t=$(awk -v s="$ORBIT_S" 'BEGIN { printf "%.3f", s + 0.1 }')
    echo "$t mark orbited"
    echo "$t wait-idle"
    echo "$t mark settled"
    k=0
    while [ $k -lt "$MOVES" ]; do
        k=$((k + 1))
        t=$(awk -v s="$t" 'BEGIN { printf "%.3f", s + 0.2 }')
        if [ $((k % 2)) -eq 1 ]; then dx=4; else dx=-4; fi
        echo "$t light 1 move $dx 0 0"
        echo "$t wait-idle"
    done
    echo "$t mark lit"
    echo "$t quit"
} >"$TMP/script.txt"

printf '%s %s, %s threads, preview %s, %s, load %s\n' "$SCENE" "$SIZE" "$THREADS" "${PREVIEW:-adaptive}" "$(uname -m)" \
    "$(cut -d' ' -f1 /proc/loadavg)"
printf '%-9s %10s %11s %10s %14s %15s %11s %9s\n' mode "orbit img/s" "preview px" "cam->img ms" "light->img ms" "light->full ms" "relight ms" "build s"
for mode in $MODES; do
    LOG=$TMP/$mode.log
    if ! timeout 900 "$BIN" view "$SCENE" --size "$SIZE" --gi "$mode" --threads "$THREADS" --script "$TMP/script.txt" \
        $PREVIEW_OPT --verbose >"$LOG" 2>&1; then
        echo "$mode: the viewer failed:"; tail -5 "$LOG"; continue
    fi
    awk -v mode="$mode" '
        function kv(key,   i, a) { for (i = 1; i <= NF; i++) { split($i, a, "="); if (a[1] == key) return a[2] } return "" }
        /^view: image / {
            if (phase == 1) { n++; w += substr($7, 1, index($7, "x") - 1) }
            if (phase == 3 && $0 ~ / L0\//) {
                match($0, /light [0-9.]+/); rl += substr($0, RSTART + 6, RLENGTH - 6); nrl++
            }
            if (build == "" && $0 ~ /build [0-9.]+/) { match($0, /build [0-9.]+/); b = substr($0, RSTART + 6, RLENGTH - 6) + 0; if (b > 0) build = b / 1000 }
        }
        /^view: mark ready/   { t0 = kv("time"); i0 = kv("images"); phase = 1 }
        /^view: mark orbited/ { t1 = kv("time"); i1 = kv("images"); cam = kv("camera_first_ms"); phase = 2 }
        /^view: mark settled/ { phase = 3 }
        /^view: mark lit/     { lf = kv("light_first_ms"); lfm = kv("light_first_max_ms"); lF = kv("light_full_ms"); phase = 4 }
        END {
            fps = (t1 > t0) ? (i1 - i0) / (t1 - t0) : 0
            printf "%-9s %10.1f %11.0f %10.1f %8.1f/%-5.0f %15.1f %11.1f %9.2f\n", mode, fps, n ? w / n : 0, cam, lf, lfm, lF,
                   nrl ? rl / nrl : 0, build + 0
        }' "$LOG"
done
