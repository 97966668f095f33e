#!/bin/sh
# unused_exports.sh - lists every function or object a production library
# exports (a global symbol of build/{core,parser,accel,geom,shade,gi,
# reference,io,app}/libpt_*.a) that no other object file of the build
# references: not another module, not a command, test or bench tool. Such a
# symbol should be static to its file, or deleted.
#
#   scripts/unused_exports.sh [BUILD_DIR [SOURCE_DIR]]   (default: build .)
#
# Run after a full build (every test and bench target built: their objects
# count as users). The libFuzzer targets (tests/fuzz/) are built only with
# clang, so a name their sources use counts as used in any build. Names the
# compiler or a sanitizer makes (starting with "_" or holding a ".") are
# not the code's and are passed over. Exit status 0 when there is none, 1 when some are listed
# (one line each: library, object, symbol), 2 on a usage error. ctest runs it
# as `unused_exports`.
set -eu
BUILD=${1:-build}
SRC=${2:-.}
[ -d "$BUILD" ] || { echo "unused_exports.sh: no build directory $BUILD" >&2; exit 2; }
tmp=$(mktemp -d /tmp/unused_exports.XXXXXX)
trap 'rm -rf "$tmp"' EXIT

libs=""
for m in core parser accel geom shade gi reference io app; do
    for a in "$BUILD/$m"/libpt_*.a; do
        [ -f "$a" ] && libs="$libs $a"
    done
done
[ -n "$libs" ] || { echo "unused_exports.sh: no libraries under $BUILD (build first)" >&2; exit 2; }

# definitions: "library:object symbol" of each global text, data, bss or
# read-only symbol
for a in $libs; do
    nm -A --defined-only "$a" |
        awk '$2 ~ /^[TDBR]$/ && $3 ~ /^[A-Za-z][A-Za-z0-9_]*$/ { sub(/:[0-9a-f]+$/, "", $1); print $1, $3 }'
done | sort -k2 > "$tmp/defs"

# references: every undefined symbol of every object of the build (each
# library's members, test and bench libraries included, and each
# executable's own objects)
{
    for a in $(find "$BUILD" -name 'libpt_*.a'); do nm --undefined-only "$a"; done
    find "$BUILD" -name '*.o' -path '*/CMakeFiles/*' -exec nm --undefined-only {} +
} 2>/dev/null | awk '$1 == "U" { print $2 }' > "$tmp/uses.all"
cat "$SRC"/tests/fuzz/*.c 2>/dev/null | grep -o '[A-Za-z_][A-Za-z0-9_]*' >> "$tmp/uses.all" || true
sort -u "$tmp/uses.all" > "$tmp/uses"

join -1 2 -2 1 -v 1 "$tmp/defs" "$tmp/uses" | awk '{ print $2, $1 }' | sort > "$tmp/unused"
n=$(wc -l < "$tmp/unused")
if [ "$n" -eq 0 ]; then
    echo "unused_exports.sh: every exported symbol of $(echo $libs | wc -w) libraries is used outside its file"
    exit 0
fi
cat "$tmp/unused"
echo "unused_exports.sh: $n exported symbols are used by no other object file: make them static or delete them" >&2
exit 1
