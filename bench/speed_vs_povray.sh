#!/bin/sh
# Wall time of partray `--gi none` beside POV-Ray 3.7 on the distribution's
# scenes without radiosity or photons (objects/, advanced/, lights/,
# interior/, textures/), both at SIZE +A0.3 with THREADS threads, one scene
# after the other in the same run. Prints one line per scene: the ratio of
# partray's wall time over POV-Ray's, the same ratio of CPU time (user +
# system, all threads), then both programs' wall and CPU seconds; slowest
# wall ratio first (SORT=cpu: by CPU ratio); then the geometric means and
# how many scenes are slower than POV-Ray. On a machine shared with other
# work the wall times carry the waits of both programs; the CPU ratio does
# not. Prints figures; not a test.
#
# usage: bench/speed_vs_povray.sh [SIZE] [THREADS] [SCENE...]
#   SIZE default 160x120, THREADS 2. Scenes: paths relative to the examples
#   directory (advanced/chess2.pov), or bare names (chess2) looked up there;
#   default every scene of the five directories without radiosity{} or
#   photons{}. TIMEOUT (default 300 s) bounds each render: a scene POV-Ray
#   does not finish in that time is left out, one partray does not finish
#   is reported as such. PARTRAY overrides the binary; PT_ARGS adds options
#   to partray's command line (e.g. PT_ARGS=--stats); KEEP=DIR keeps both
#   images of every scene there.
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PARTRAY=${PARTRAY:-$ROOT/build/partray}
SIZE=${1:-160x120}
THREADS=${2:-2}
[ $# -gt 2 ] && shift 2 || set --
TIMEOUT=${TIMEOUT:-300}
EX=/usr/share/doc/povray/examples
W=${SIZE%x*}; H=${SIZE#*x}
if [ $# -eq 0 ]; then
    set -- $(cd "$EX" && find objects advanced lights interior textures -name '*.pov' | sort |
             while read -r f; do grep -qE 'radiosity *\{|photons *\{' "$f" || echo "$f"; done)
fi
TMP=$(mktemp -d /tmp/speed_vs_povray.XXXXXX)
trap 'rm -rf "$TMP"' EXIT
: > "$TMP/lines"
n=0
for rel in "$@"; do
    case "$rel" in
        */*) ;;
        *) rel=$(cd "$EX" && find objects advanced lights interior textures -name "${rel%.pov}.pov" | head -1) ;;
    esac
    [ -n "$rel" ] && [ -f "$EX/$rel" ] || { echo "no such scene: $rel" >&2; continue; }
    dir=$(dirname "$rel"); base=$(basename "$rel" .pov)
    work="$TMP/$n"; n=$((n + 1))
    mkdir -p "$work" && cp -r "$EX/$dir/." "$work/"
    (cd "$work" && timeout "$TIMEOUT" /usr/bin/time -f "%e %U %S" -o "$work/pov.time" \
         povray +I"$base.pov" +Opov.png +W"$W" +H"$H" +A0.3 -D -V -GA +WT"$THREADS" >/dev/null 2>&1)
    rp=$?
    (cd "$work" && timeout "$TIMEOUT" /usr/bin/time -f "%e %U %S" -o "$work/pt.time" \
         "$PARTRAY" render "$base.pov" -o pt.png --size "$SIZE" +A0.3 --gi none \
         --threads "$THREADS" --quiet ${PT_ARGS:-} >/dev/null 2>"$work/pt.err")
    rt=$?
    if [ -n "${KEEP:-}" ]; then
        mkdir -p "$KEEP" && cp "$work/pov.png" "$KEEP/$base.pov.png" 2>/dev/null; cp "$work/pt.png" "$KEEP/$base.pt.png" 2>/dev/null
    fi
    pv=$(tail -1 "$work/pov.time" 2>/dev/null); pt=$(tail -1 "$work/pt.time" 2>/dev/null)
    awk -v s="$rel" -v pv="$pv" -v pt="$pt" -v rp="$rp" -v rt="$rt" -v lim="$TIMEOUT" 'BEGIN {
        split(pv, a, " "); split(pt, b, " ")
        tp = a[1]; cp = a[2] + a[3]; tt = b[1]; ct = b[2] + b[3]
        if (rp != 0) { printf "%9s %9s %-44s povray exit %d: left out\n", "-", "-", s, rp; exit }
        if (rt == 124 || pt == "") { printf "%9s %9s %-44s %8.2f %8s %8.2f  partray > %d s\n", "inf", "inf", s, tp, "-", cp, lim; exit }
        note = (rt != 0) ? sprintf("  (partray exit %d)", rt) : ""
        printf "%9.3f %9.3f %-44s %8.2f %8.2f %8.2f %8.2f%s\n", tt / tp, (cp > 0 ? ct / cp : 0), s, tp, tt, cp, ct, note }' >> "$TMP/lines"
    tail -1 "$TMP/lines" >&2
done
printf '%9s %9s %-44s %8s %8s %8s %8s\n' wall cpu scene wall_pov wall_pt cpu_pov cpu_pt
key=1; [ "${SORT:-wall}" = cpu ] && key=2
sort -k$key,$key -g -r "$TMP/lines" | grep -v ' left out$'
grep ' left out$' "$TMP/lines"
awk '$1 != "-" && $1 != "inf" && $1 > 0 { k++; s += log($1); if ($1 > 1) slow++ }
     $2 != "-" && $2 != "inf" && $2 > 0 { kc++; sc += log($2); if ($2 > 1) slowc++ }
     $1 == "inf" { slow++; slowc++; inf++ }
     END { if (k) printf "geometric mean of partray/POV-Ray over %d scenes: wall %.3f (%d slower), cpu %.3f (%d slower)%s\n",
                  k, exp(s / k), slow, exp(sc / kc), slowc, inf ? sprintf("; %d timed out", inf) : "" }' "$TMP/lines"
