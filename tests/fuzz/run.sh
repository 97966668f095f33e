#!/bin/sh
# Build the libFuzzer targets and run each one in turn.
#
#   tests/fuzz/run.sh [SECONDS_PER_TARGET] [TARGET...]
#
# SECONDS_PER_TARGET defaults to 600; TARGET is any of scan directive parse
# mesh2 image sdlimage (default: all, one after the other; fuzzers are not run in
# parallel). The build goes to $BUILD_DIR (default build-fuzz: clang,
# -DPARTRAY_FUZZ=ON, so ASan + UBSan). The corpus grows across runs in
# $BUILD_DIR/fuzz-work/corpus/; findings land in $BUILD_DIR/fuzz-work/artifacts/
# and the run stops with a non-zero status. See tests/fuzz/fuzz_one.sh.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
secs=${1:-600}
[ $# -gt 0 ] && shift
targets=${*:-scan directive parse mesh2 image sdlimage}
build=${BUILD_DIR:-$repo/build-fuzz}

if [ ! -f "$build/CMakeCache.txt" ]; then
    cmake -S "$repo" -B "$build" -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
        -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPARTRAY_FUZZ=ON >/dev/null
fi
bins=""
for t in $targets; do bins="$bins fuzz_$t"; done
# shellcheck disable=SC2086
cmake --build "$build" -j "$(nproc)" --target $bins >/dev/null

status=0
for t in $targets; do
    case "$t" in image|sdlimage) dict="$here/image.dict" ;; *) dict="$build/tests/fuzz/sdl.dict" ;; esac
    "$here/fuzz_one.sh" "$build/tests/fuzz/fuzz_$t" "$t" "$build/fuzz-work" "$secs" -dict="$dict" || status=1
done
exit $status
