# scene_bench.sh - sourced (not run) by the bench scripts that render one
# scene of bench/scenes/ with both renderers, after they set BENCH_SCENE (the
# scene's name) and BENCH_SIZE (the default size); their own first two
# arguments are SIZE and THREADS. Sets ROOT (the repository), PARTRAY (the
# environment's, else build/partray), SCENE (bench/scenes/BENCH_SCENE.pov),
# SIZE (argument 1, else BENCH_SIZE) and its parts W and H, THREADS
# (argument 2, else 2), and TMP, a fresh directory removed on exit.
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PARTRAY=${PARTRAY:-$ROOT/build/partray}
SCENE=$ROOT/bench/scenes/$BENCH_SCENE.pov
SIZE=${1:-$BENCH_SIZE}
THREADS=${2:-2}
W=${SIZE%x*} H=${SIZE#*x}
TMP=$(mktemp -d "/tmp/$BENCH_SCENE.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
