#!/bin/sh
# identical.sh - renders a fixed scene set to PFM files and compares two such
# sets byte for byte: the check that a refactor changed no pixel.
#
#   bench/identical.sh render PARTRAY OUTDIR    render the set with PARTRAY
#   bench/identical.sh compare DIR_A DIR_B      byte-compare two rendered sets
#   bench/identical.sh BASE_PARTRAY NEW_PARTRAY render with both, then compare
#                                               (into /tmp/identical.XXXXXX)
#
# A base binary comes from a build of the base commit, e.g.
#   git worktree add /tmp/base main && cmake -S /tmp/base -B /tmp/base/build \
#     -DCMAKE_BUILD_TYPE=RelWithDebInfo && cmake --build /tmp/base/build --target partray
#   bench/identical.sh /tmp/base/build/partray build/partray
# or render the base set once and compare each step's set against it.
#
# The set (THREADS threads, default 2; each run's wall time is printed):
#   xc_*            the scenes tests/test_crosscheck.c renders (its four
#                   tests/scenes/xc_*.pov and the distribution's
#                   radiosity/cornell.pov without its radiosity block), at its
#                   160x160 +A0.3 +R3, --gi none
#   cbox_particle   scenes/cbox.pov  128x128 --gi particle
#   maze_particle   scenes/maze.pov  128x128 --gi particle
#   cbox_path       scenes/cbox.pov  48x48 --gi path --spp 4
#   cbox_pmfg       scenes/cbox.pov  32x32 --gi pmfg --fg-rays 64 --photons 20000
#   cbox_vpl        scenes/cbox.pov  48x48 --gi vpl
#   cbox_links      scenes/cbox.pov  48x48 --gi links
#   photons_none    the distribution's lights/phot_met_glass.pov 64x48 --gi
#                   none (its photons{} block: the caustic layer)
#   photons_pmfg    the same, 32x24 --gi pmfg --fg-rays 64 --photons 20000
#                   (the photon map's caustic photons)
# Every render uses --seed 1. Scenes are copied to OUTDIR first (scenes may
# write files beside themselves). Exit status of compare (and of the two-binary
# form): 0 when every file is identical, 1 otherwise (each differing or
# missing file is named).
set -eu
cd "$(dirname "$0")/.."
ROOT=$(pwd)
THREADS=${THREADS:-2}
RADIOSITY_CORNELL=/usr/share/povray-3.7/scenes/radiosity/cornell.pov
PHOTONS=/usr/share/doc/povray/examples/lights/phot_met_glass.pov

# Copy $1 to $2 without its first radiosity{...} block, as test_crosscheck.c's
# strip_radiosity does: from the keyword to the brace that closes its first {.
strip_radiosity() {
    awk 'BEGIN { RS = "^$" } {
        r = index($0, "radiosity")
        rest = substr($0, r); p = index(rest, "{")
        depth = 0
        for (e = p; e <= length(rest); e++) {
            c = substr(rest, e, 1)
            if (c == "{") depth++
            if (c == "}" && --depth == 0) break
        }
        printf "%s%s", substr($0, 1, r - 1), substr(rest, e + 1)
    }' "$1" > "$2"
}

render_one() { # BIN DIR NAME SCENE ARGS...
    bin=$1 dir=$2 name=$3 scene=$4
    shift 4
    t0=$(date +%s.%N)
    if ! (cd "$dir" && "$bin" render "$scene" -o "$name.pfm" --seed 1 --threads "$THREADS" --quiet "$@" \
            > "$name.log" 2>&1); then
        echo "identical.sh: $name failed; see $dir/$name.log" >&2
        return 1
    fi
    t1=$(date +%s.%N)
    printf '  %-22s %6.2f s\n' "$name" "$(echo "$t1 - $t0" | bc)"
}

render_set() { # BIN DIR
    bin=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
    dir=$2
    mkdir -p "$dir"
    dir=$(cd "$dir" && pwd)
    for s in xc_point_phong xc_spot_specular xc_parallel_reflect xc_area_fade; do
        cp "$ROOT/tests/scenes/$s.pov" "$dir/"
    done
    strip_radiosity "$RADIOSITY_CORNELL" "$dir/xc_cornell_direct.pov"
    cp "$ROOT/scenes/cbox.pov" "$ROOT/scenes/maze.pov" "$PHOTONS" "$dir/"
    echo "rendering with $bin into $dir"
    for s in xc_cornell_direct xc_point_phong xc_spot_specular xc_parallel_reflect xc_area_fade; do
        render_one "$bin" "$dir" "$s" "$s.pov" +W160 +H160 +A0.3 +R3 --gi none
    done
    render_one "$bin" "$dir" cbox_particle cbox.pov --size 128x128 --gi particle
    render_one "$bin" "$dir" maze_particle maze.pov --size 128x128 --gi particle
    render_one "$bin" "$dir" cbox_path cbox.pov --size 48x48 --gi path --spp 4
    render_one "$bin" "$dir" cbox_pmfg cbox.pov --size 32x32 --gi pmfg --fg-rays 64 --photons 20000
    render_one "$bin" "$dir" cbox_vpl cbox.pov --size 48x48 --gi vpl
    render_one "$bin" "$dir" cbox_links cbox.pov --size 48x48 --gi links
    render_one "$bin" "$dir" photons_none phot_met_glass.pov --size 64x48 --gi none
    render_one "$bin" "$dir" photons_pmfg phot_met_glass.pov --size 32x24 --gi pmfg --fg-rays 64 --photons 20000
}

compare_sets() { # DIR_A DIR_B
    status=0 n=0
    for a in "$1"/*.pfm; do
        name=$(basename "$a")
        n=$((n + 1))
        if [ ! -f "$2/$name" ]; then
            echo "  $name: missing in $2"; status=1
        elif cmp -s "$a" "$2/$name"; then
            echo "  $name: identical"
        else
            echo "  $name: DIFFERS"; status=1
        fi
    done
    for b in "$2"/*.pfm; do
        [ -f "$1/$(basename "$b")" ] || { echo "  $(basename "$b"): missing in $1"; status=1; }
    done
    if [ "$n" -eq 0 ]; then echo "identical.sh: no PFM files in $1" >&2; return 1; fi
    if [ $status -eq 0 ]; then echo "all $n renders byte-identical"; else echo "renders differ"; fi
    return $status
}

case "${1:-}" in
render) [ $# -eq 3 ] || { echo "usage: $0 render PARTRAY OUTDIR" >&2; exit 2; }
        render_set "$2" "$3" ;;
compare) [ $# -eq 3 ] || { echo "usage: $0 compare DIR_A DIR_B" >&2; exit 2; }
         compare_sets "$2" "$3" ;;
""|-h|--help) sed -n '2,8p' "$0"; exit 2 ;;
*) [ $# -eq 2 ] || { echo "usage: $0 BASE_PARTRAY NEW_PARTRAY" >&2; exit 2; }
   tmp=$(mktemp -d /tmp/identical.XXXXXX)
   render_set "$1" "$tmp/base"
   render_set "$2" "$tmp/new"
   compare_sets "$tmp/base" "$tmp/new" ;;
esac
