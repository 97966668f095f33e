#!/bin/sh
# bench_view.sh - the interactive viewer's figures: images per
# second while the camera orbits, and the time from a light move to the
# relit image, per GI mode. Figures, not a pass/fail test.
#
#   bench/bench_view.sh [BUILD_DIR] [SCENE] [SIZE] [MODES]
#     BUILD_DIR  where `partray` is (default: build)
#     SCENE      default scenes/cbox.pov;  SIZE default 512x512
#     MODES      default "none particle"
#   THREADS=N (default 2, the CI machine's cores), ORBIT_S=5, MOVES=4, DRAG_S=2,
#   PREVIEW=D fixes the preview at 1/D of the size (default: adaptive),
#   EXTRA="--particles N ..." more viewer options, KEEP_LOG=PREFIX keeps the
#   verbose logs as PREFIX.MODE.log.
#
# Runs `partray view --script` under Xvfb (started here on a free display
# when DISPLAY is not set). The script waits until the mode is built and the
# image refined, orbits the camera 1.5 degrees per event at 30 events/s for
# ORBIT_S seconds, waits until refined, then moves the light MOVES times
# (waiting for the full refinement after each). Reported:
#   orbit img/s     images the render thread finished while orbiting / time
#   preview px      mean width of those images (the preview adapts its size)
#   cam->img ms     input to the first image showing it, mean
#   light->img ms   light move to the first image showing it, mean/max (for
#                   particle: relit by the preview instance, 1/8 of the
#                   particles, "gi-coarse"; without one the new direct light
#                   over the old indirect light, "gi-stale")
#   prev.light ms   the preview instance's lighting stage in that pass
#   light->relit ms light move to the first image relit by the mode's full
#                   GI (a preview), mean/max, and what that image's pass spent:
#     lighting ms   the GI's lighting stage (gi_particle_relight)
#     regather ms   the per-view stage after it (gathering, estimation)
#     render ms     the preview pass itself
#     lighting cpu  the lighting stage's process CPU time / THREADS: about
#                   its wall time on an idle machine (this one is shared)
#   light->full ms  light move to the relit full-resolution image, mean
#   build s         the mode's geometry + lighting stages at start
#   drag img/s      images per second while a light is dragged (an arrow key
#                   held DRAG_S seconds), and their mean latency (drag ms)
set -eu
cd "$(dirname "$0")/.."
BUILD=${1:-build}
SCENE=${2:-scenes/cbox.pov}
SIZE=${3:-512x512}
MODES=${4:-none particle}
THREADS=${THREADS:-2}
ORBIT_S=${ORBIT_S:-5}
MOVES=${MOVES:-4}
DRAG_S=${DRAG_S:-2}
PREVIEW_OPT=
[ -n "${PREVIEW:-}" ] && PREVIEW_OPT="--preview $PREVIEW"
EXTRA=${EXTRA:-}
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
    # drag the light: the Right arrow held DRAG_S seconds (moves the selected
    # light screen-right continuously, as a user would)
    t=$(awk -v s="$t" 'BEGIN { printf "%.3f", s + 0.2 }')
    echo "$t key Right $DRAG_S"
    echo "$t mark drag"
    t=$(awk -v s="$t" -v d="$DRAG_S" 'BEGIN { printf "%.3f", s + d }')
    echo "$t mark dragged"
    echo "$t wait-idle"
    echo "$t quit"
} >"$TMP/script.txt"

printf '%s %s, %s threads, preview %s, %s, load %s\n' "$SCENE" "$SIZE" "$THREADS" "${PREVIEW:-adaptive}" "$(uname -m)" \
    "$(cut -d' ' -f1 /proc/loadavg)"
printf '%-9s %10s %10s %10s %13s %13s %15s %11s %12s %11s %9s %14s %8s %10s %8s\n' mode "orbit img/s" "preview px" "cam->img ms" \
    "light->img ms" "prev.light ms" "light->relit ms" "lighting ms" "lighting cpu" "regather ms" "render ms" "light->full ms" \
    "build s" "drag img/s" "drag ms"
for mode in $MODES; do
    LOG=$TMP/$mode.log
    if ! timeout 900 "$BIN" view "$SCENE" --size "$SIZE" --gi "$mode" --threads "$THREADS" --script "$TMP/script.txt" \
        $PREVIEW_OPT $EXTRA --verbose >"$LOG" 2>&1; then
        echo "$mode: the viewer failed:"; tail -5 "$LOG"; continue
    fi
    [ -n "${KEEP_LOG:-}" ] && cp "$LOG" "$KEEP_LOG.$mode.log"
    awk -v mode="$mode" -v threads="$THREADS" '
        function kv(key,   i, a) { for (i = 1; i <= NF; i++) { split($i, a, "="); if (a[1] == key) return a[2] } return "" }
        function stage(name,   r) { if (match($0, "[(]?" name " [0-9.]+")) { r = substr($0, RSTART, RLENGTH); sub(/.* /, "", r); return r + 0 } return 0 }
        /^view: image / {
            if (phase == 1) { n++; w += substr($7, 1, index($7, "x") - 1) }
            # the relit preview after each light move (its pass ran the lighting stage)
            if (phase == 3 && $0 ~ /gi-coarse/ && stage("light") > 0) { ql += stage("light"); nql++ }
            if (phase == 3 && $0 ~ / L0\// && $0 ~ /latency [0-9.]+ ms light/ && $0 !~ /gi-stale|gi-coarse/ && stage("light") > 0) {
                rl += stage("light"); rv += stage("view"); rr += stage("render"); nrl++
                if (match($0, /[(]light [0-9.]+[)]/)) { c = substr($0, RSTART + 7, RLENGTH - 8); rc += c / threads }
            }
            if (build == "" && $0 ~ /build [0-9.]+/) { b = stage("build"); if (b > 0) build = b / 1000 }
        }
        /^view: mark ready/   { t0 = kv("time"); i0 = kv("images"); phase = 1 }
        /^view: mark orbited/ { t1 = kv("time"); i1 = kv("images"); cam = kv("camera_first_ms"); phase = 2 }
        /^view: mark settled/ { phase = 3 }
        /^view: mark lit/     { lf = kv("light_first_ms"); lfm = kv("light_first_max_ms"); lr = kv("light_relit_full_ms");
                                lrm = kv("light_relit_full_max_ms"); lF = kv("light_full_ms"); phase = 4 }
        /^view: mark drag /   { d0 = kv("time"); j0 = kv("images"); phase = 5 }
        /^view: mark dragged/ { d1 = kv("time"); j1 = kv("images"); phase = 6 }
        /^view: image / && phase == 5 { if (match($0, /latency [0-9.]+/)) { dl += substr($0, RSTART + 8, RLENGTH - 8); ndl++ } }
        END {
            fps = (t1 > t0) ? (i1 - i0) / (t1 - t0) : 0
            dfps = (d1 > d0) ? (j1 - j0) / (d1 - d0) : 0
            printf "%-9s %10.1f %10.0f %10.1f %7.1f/%-5.0f %13.1f %8.1f/%-6.0f %11.1f %12.1f %11.1f %9.1f %14.1f %8.2f %10.1f %8.1f\n",
                   mode, fps, n ? w / n : 0, cam, lf, lfm, nql ? ql / nql : 0, lr, lrm, nrl ? rl / nrl : 0, nrl ? rc / nrl : 0,
                   nrl ? rv / nrl : 0, nrl ? rr / nrl : 0, lF, build + 0, dfps, ndl ? dl / ndl : 0
        }' "$LOG"
done
