#!/bin/sh
# Set up, build and run every test through ctest.
set -eu
cd "$(dirname "$0")/.."
./scripts/build.sh
cd build
ctest --output-on-failure --timeout 900 "$@"
