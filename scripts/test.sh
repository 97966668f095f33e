#!/bin/sh
# Set up, build and run every test through ctest, in two stages:
#   build/           the normal build (includes valgrind memcheck on a small
#                    render);
#   build-sanitize/  clang with AddressSanitizer + UndefinedBehaviorSanitizer
#                    and the libFuzzer targets (-DPARTRAY_FUZZ=ON): the whole
#                    suite again, every committed fuzz input, and each fuzz
#                    target for PARTRAY_FUZZ_SECONDS (20) seconds.
# Measured from a clean clone on 2 cores: 1m45s + 9m30s, about 11 minutes of
# the 20-minute CI budget. PARTRAY_SANITIZE_STAGE=0 runs only the first
# stage. Arguments go to both ctest runs (e.g. -R test_cli).
set -eu
cd "$(dirname "$0")/.."
./scripts/build.sh
(cd build && ctest --output-on-failure --timeout 900 "$@")
if [ "${PARTRAY_SANITIZE_STAGE:-1}" = 0 ]; then exit 0; fi
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DPARTRAY_FUZZ=ON \
    -DPARTRAY_FUZZ_SECONDS="${PARTRAY_FUZZ_SECONDS:-20}" >/dev/null
cmake --build build-sanitize -j "$(nproc)"
cd build-sanitize
ctest --output-on-failure --timeout 900 "$@"
