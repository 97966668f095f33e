#!/bin/sh
# Run one libFuzzer target.
#
#   fuzz_one.sh BIN NAME WORKDIR SECONDS [libFuzzer options...]
#       fuzz for SECONDS from the seeds: this directory's seeds/NAME and
#       regress/NAME (ours, committed) and WORKDIR/dist/NAME, generated here
#       at run time from the POV-Ray distribution's scenes and includes and
#       the repository's scenes (never committed). New inputs go to
#       WORKDIR/corpus/NAME, findings to WORKDIR/artifacts/, the log to
#       WORKDIR/logs/NAME.log. Ends with a one-line summary.
#   fuzz_one.sh --replay BIN NAME WORKDIR
#       run every committed seed and reproducer of NAME once.
#
# NAME is scan, directive, parse, mesh2, image or sdlimage. Exit status: libFuzzer's
# (0 = nothing found).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
dist=/usr/share/povray-3.7

replay=0
if [ "${1:-}" = "--replay" ]; then replay=1; shift; fi
bin=$1; name=$2; work=$3
mkdir -p "$work"

# Options shared by both modes: limits per input, leaks on. The timeout is
# wall-clock time: 30 s, since on a shared 2-core machine an input that takes
# 0.5 s of CPU (tests/fuzz/regress/parse/nested_loops.pov under ASan) took
# over 10 s at nice 10; a real hang still runs into it.
case "$name" in
    image|sdlimage) maxlen=131072 ;;
    *) maxlen=65536 ;;
esac
common="-timeout=30 -rss_limit_mb=2048 -malloc_limit_mb=1024 -max_len=$maxlen -detect_leaks=1"

if [ "$replay" = 1 ]; then
    files=$(find "$here/seeds/$name" "$here/regress/$name" -type f 2>/dev/null | sort)
    if [ -z "$files" ]; then echo "fuzz $name: no committed inputs"; exit 0; fi
    n=$(echo "$files" | wc -l)
    # shellcheck disable=SC2086
    "$bin" $common -runs=1 $files >"$work/replay-$name.log" 2>&1 || {
        cat "$work/replay-$name.log"; echo "fuzz $name: a committed input fails"; exit 1; }
    echo "fuzz $name: $n committed inputs replayed, no finding"
    exit 0
fi

secs=$4
shift 4

# Seed corpus from the distribution, generated once per work dir.
seeds="$work/dist/$name"
if [ ! -f "$seeds/.done" ]; then
    rm -rf "$seeds"
    mkdir -p "$seeds"
    copy() { # copy files under a flat, unique name
        while IFS= read -r f; do
            b=$(echo "$f" | sed 's|^/||; s|/|_|g')
            cp "$f" "$seeds/$b" 2>/dev/null || true
        done
    }
    scenes() {
        find -L "$dist/scenes" -name '*.pov' -size -64k 2>/dev/null
        find "$repo/scenes" "$repo/tests/scenes" -name '*.pov' 2>/dev/null
    }
    case "$name" in
        scan) { scenes; find -L "$dist/include" "$dist/scenes" -name '*.inc' -size -64k 2>/dev/null; } | copy ;;
        parse) scenes | copy ;;
        directive)
            { find -L "$dist/include" -name '*.inc' -size -64k 2>/dev/null
              scenes | xargs grep -l -E '#(macro|while|for|switch)' 2>/dev/null; } | copy ;;
        mesh2)
            # The bodies of every mesh2 { } (and, marked with a leading M,
            # mesh { }) written in the distribution's files.
            find -L "$dist/scenes" "$dist/include" -type f \( -name '*.pov' -o -name '*.inc' -o -name '*.txt' \) \
                -size -256k 2>/dev/null | xargs grep -l -E 'mesh2? *\{?' 2>/dev/null | while IFS= read -r f; do
                b=$(echo "$f" | sed 's|^/||; s|/|_|g')
                awk -v out="$seeds/$b" '
                    { text = text $0 "\n" }
                    END {
                        n = 0; i = 1; L = length(text)
                        while (i <= L) {
                            rest = substr(text, i)
                            if (match(rest, /mesh2?[ \t\r\n]*\{/) == 0) break
                            kw = substr(rest, RSTART, RLENGTH)
                            start = i + RSTART + RLENGTH - 1
                            depth = 1; j = start
                            while (j <= L && depth > 0) {
                                c = substr(text, j, 1)
                                if (c == "{") depth++; else if (c == "}") depth--
                                j++
                            }
                            if (depth == 0 && j - start < 65000) {
                                body = substr(text, start, j - 1 - start)
                                n++
                                f = out "." n
                                printf "%s%s", (kw ~ /mesh2/ ? "" : "M"), body > f
                                close(f)
                            }
                            i = start
                        }
                    }' "$f"
            done ;;
        image) find -L "$dist" -type f \( -name '*.png' -o -name '*.exr' -o -name '*.pfm' \) -size -128k 2>/dev/null | copy ;;
        sdlimage)
            find -L "$dist" "$repo/scenes" "$repo/tests" -type f \( -name '*.png' -o -name '*.gif' -o -name '*.pot' \
                -o -name '*.pgm' -o -name '*.ppm' -o -name '*.jpg' -o -name '*.jpeg' -o -name '*.tga' -o -name '*.tif' \
                -o -name '*.tiff' \) -size -128k 2>/dev/null | copy ;;
        *) echo "fuzz_one.sh: unknown target '$name'" >&2; exit 2 ;;
    esac
    touch "$seeds/.done"
fi

corpus="$work/corpus/$name"
mkdir -p "$corpus" "$work/artifacts" "$work/logs"
log="$work/logs/$name.log"
dirs="$corpus $seeds"
for d in "$here/seeds/$name" "$here/regress/$name"; do
    if [ -d "$d" ]; then dirs="$dirs $d"; fi
done
echo "=== $(date -u +%FT%TZ) $name ${secs}s" >>"$log"
rc=0
# shellcheck disable=SC2086
"$bin" $common -max_total_time="$secs" -print_final_stats=1 -artifact_prefix="$work/artifacts/$name-" \
    "$@" $dirs >"$log.run" 2>&1 || rc=$?
cat "$log.run" >>"$log"
execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log.run" | tail -n 1)
last=$(grep -E '^#[0-9]+' "$log.run" | tail -n 1)
cov=$(echo "$last" | sed -n 's/.*cov: \([0-9]*\).*/\1/p')
ft=$(echo "$last" | sed -n 's/.*ft: \([0-9]*\).*/\1/p')
corp=$(echo "$last" | sed -n 's/.*corp: \([0-9]*\).*/\1/p')
if [ "$rc" != 0 ]; then
    grep -E 'ERROR|SUMMARY|check failed|Test unit written|runtime error' "$log.run" | head -n 20 >&2 || true
fi
echo "fuzz $name: ${execs:-?} execs in ${secs}s, cov ${cov:-?}, ft ${ft:-?}, corpus ${corp:-?}, exit $rc (log $log)"
exit "$rc"
