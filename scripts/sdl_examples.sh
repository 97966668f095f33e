#!/usr/bin/env bash
# sdl_examples.sh - the parser's coverage: `partray parse` on every
# distribution example scene (Debian povray-examples), each run from a copy
# of its own directory (scenes read and write files beside themselves, as
# in POV-Ray). A scene with a .ini of the same name that sets up an
# animation (Initial_Frame, Final_Frame, Initial_Clock, Final_Clock,
# Cyclic_Animation) is parsed at its first frame with those settings
# (+KFI +KFF +KI +KF +KC), as POV-Ray renders it from the .ini.
#
#   scripts/sdl_examples.sh [--povray] [--stills] [PARTRAY] [EXAMPLES_DIR]
#
# --stills ignores the .ini files (every scene parsed as a still, clock 0).
# Prints one line per failure (scene, then partray's first error line; with
# --povray also POV-Ray 3.7's verdict on the same scene with the same
# frame options), then the count. Each parse has a 120 s limit.
set -u
check_povray=0; stills=0
while [ $# -gt 0 ]; do
    case $1 in
    --povray) check_povray=1; shift ;;
    --stills) stills=1; shift ;;
    *) break ;;
    esac
done
here=$(cd "$(dirname "$0")/.." && pwd)
partray=$(realpath "${1:-$here/build/partray}")
src=${2:-/usr/share/doc/povray/examples}
work=$(mktemp -d /tmp/partray_examples.XXXXXX)
trap 'rm -rf "$work"' EXIT
cp -r "$src/." "$work/"

# .ini animation keys -> POV-Ray switches (first frame)
ini_opts() {
    local ini=$1
    [ $stills -eq 0 ] && [ -f "$ini" ] || return 0
    tr -d '\r' < "$ini" | awk -F= '
        { k = tolower($1); gsub(/[ \t]/, "", k); v = $2; sub(/^[ \t]+/, "", v); sub(/[ \t;].*/, "", v) }
        v == "" { next }
        k == "initial_frame" { printf "+KFI%s ", v }
        k == "final_frame" { printf "+KFF%s ", v }
        k == "initial_clock" { printf "+KI%s ", v }
        k == "final_clock" { printf "+KF%s ", v }
        k == "cyclic_animation" && (tolower(v) == "on" || v == "1" || tolower(v) == "true") { printf "+KC " }'
}

n=0; ok=0
while IFS= read -r -d '' scene; do
    n=$((n + 1))
    dir=$(dirname "$scene"); base=$(basename "$scene" .pov)
    opts=$(ini_opts "$dir/$base.ini")
    out=$(cd "$dir" && timeout 120 "$partray" parse "$base.pov" $opts 2>&1)
    rc=$?
    if [ $rc -eq 0 ]; then ok=$((ok + 1)); continue; fi
    rel=${scene#$work/}
    first=$(printf '%s\n' "$out" | grep -m1 -E 'error|rror:' || printf '%s\n' "$out" | head -1)
    [ $rc -eq 124 ] && first="timed out after 120 s"
    line="FAIL $rel ${opts:+[$opts] }: $first"
    if [ $check_povray -eq 1 ]; then
        pov=$(cd "$dir" && timeout 300 povray "+I$base.pov" -F -D +W16 +H12 -GA $opts +SF1 +EF1 2>&1)
        prc=$?
        if printf '%s\n' "$pov" | grep -q "Parse Error\|Fatal error\|Possible Parse Error.*Can't\|Cannot open"; then
            verdict="POV-Ray fails too: $(printf '%s\n' "$pov" | grep -m1 -E 'Parse Error|Error|error' | tr -s ' ')"
        elif [ $prc -eq 124 ]; then
            verdict="POV-Ray: timed out"
        else
            verdict="POV-Ray parses it"
        fi
        line="$line | $verdict"
    fi
    printf '%s\n' "$line"
done < <(find "$work" -name '*.pov' -print0 | sort -z)
echo "example scenes: $ok of $n parse ($(awk -v a=$ok -v b=$n 'BEGIN { printf "%.1f", 100 * a / b }')%)"
