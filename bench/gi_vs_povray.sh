#!/bin/sh
# POV-Ray's radiosity scenes: partray's default render against POV-Ray's,
# both measured against POV-Ray's converged render (the scene's radiosity{}
# at 4x the count and 0.4x the error_bound, cached by `partray crosscheck
# --converged`). For every distribution scene with a radiosity{} block, at
# SIZE +A0.3 with THREADS threads, prints: mean luminance of partray's
# render over the reference's, LDR-FLIP of POV-Ray's default and of
# partray's render against the reference, both wall times (same run) and
# their ratio, and whether partray's render meets the three bounds (within
# 3% luminance, FLIP no worse than POV-Ray's, time no longer); then the
# geometric mean of the time ratios. Prints figures; not a test.
#
# usage: bench/gi_vs_povray.sh [SIZE] [THREADS] [CONVERGED_TIMEOUT] [SCENE...]
#   SIZE default 160x120, THREADS 2, CONVERGED_TIMEOUT 1800 s (a converged
#   render that takes longer is not made; POV-Ray's default render is then
#   the reference and the line says so). Scenes: relative to the examples
#   directory, default all 18 with radiosity{}. PARTRAY, XC_CACHE override
#   the binary and the reference cache.
# Where no converged render is made and partray's render uses GI, a second
# line compares both default renders with partray's path tracer, which
# follows POV-Ray's rules for radiosity light (diffuse bounces up to
# recursion_limit, mirrors and glass up to max_trace_level; no photons):
# `--gi path --spp PATH_SPP` (env, default 1024; 0 leaves the line out).
# It tells which of the two unconverged renders is nearer a converged one.
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PARTRAY=${PARTRAY:-$ROOT/build/partray}
SIZE=${1:-160x120}
THREADS=${2:-2}
CTIMEOUT=${3:-1800}
PATH_SPP=${PATH_SPP:-1024}
[ $# -gt 3 ] && shift 3 || set --
EX=/usr/share/doc/povray/examples
CACHE=${XC_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/partray/crosscheck}
if [ $# -eq 0 ]; then
    set -- $(cd "$EX" && grep -l 'radiosity *{' -r . --include='*.pov' | sed 's|^\./||' | sort)
fi
TMP=$(mktemp -d /tmp/gi_vs_povray.XXXXXX)
trap 'rm -rf "$TMP"' EXIT
printf '%-36s %7s %7s %7s %8s %8s %6s  %s\n' scene lum_pt flip_pov flip_pt t_pov t_pt t_rat "bounds (lum flip time)"
for rel in "$@"; do
    dir=$(dirname "$rel"); base=$(basename "$rel")
    mkdir -p "$TMP/$dir" && cp -r "$EX/$dir/." "$TMP/$dir/"
    js=$(cd "$TMP/$dir" && "$PARTRAY" crosscheck "$base" --size "$SIZE" +A0.3 --threads "$THREADS" \
         --converged --cache "$CACHE" --converged-timeout "$CTIMEOUT" --json --quiet --out "$TMP/xc" 2>"$TMP/err")
    if [ $? -ne 0 ] || [ -z "$js" ]; then
        printf '%-36s failed: %s\n' "$rel" "$(tail -1 "$TMP/err")"
        continue
    fi
    printf '%s\n' "$js" | python3 -c '
import json, sys
j = json.load(sys.stdin); rel = sys.argv[1]
c = j.get("converged", {}); tp = j["povray"]["seconds"]; tt = j["partray"]["seconds"]
if c.get("made"):
    lum = c["partray_luminance_ratio"]; fpov = c["povray_flip"]; fpt = c["partray_flip"]; note = ""
else:
    lum = j["luminance"]["ratio"]; fpov = 0.0; fpt = j["flip"]["mean"]; note = " [ref: POV-Ray default, converged not made]"
ok = lambda b: "ok" if b else "NO"
print("%-36s %7.4f %7.4f %7.4f %8.2f %8.2f %6.3f  %s %s %s%s" % (rel, lum, fpov, fpt, tp, tt, tt / tp if tp > 0 else 0,
      ok(abs(lum - 1) <= 0.03), ok(fpt <= fpov) if c.get("made") else "--", ok(tt <= tp), note))
print("RATIO %.6f" % (tt / tp if tp > 0 else 1), file=sys.stderr)
' "$rel" 2>>"$TMP/ratios"
    made=$(printf '%s\n' "$js" | python3 -c 'import json, sys; j = json.load(sys.stdin); print(int(bool(j.get("converged", {}).get("made")) or j["partray"].get("gi", "none") == "none"))')
    if [ "$made" = 0 ] && [ "$PATH_SPP" -gt 0 ]; then
        (cd "$TMP/$dir" && "$PARTRAY" render "$base" --size "$SIZE" --gi path --spp "$PATH_SPP" --threads "$THREADS" \
            -o "$TMP/path.png" --quiet 2>/dev/null)
        line=""
        for who in povray partray; do
            line="$line $("$PARTRAY" compare "$TMP/path.png" "$TMP/xc/$who.png" --json 2>/dev/null | python3 -c '
import json, sys
j = json.load(sys.stdin); r = j["luminance"]["reference"]
print("%s lum %+.2f%% FLIP %.4f;" % (sys.argv[1], 100 * (j["luminance"]["test"] / r - 1) if r > 0 else 0, j["flip"]["mean"]))' "$who")"
        done
        printf '  against --gi path --spp %s (POV-Ray'"'"'s radiosity rules, no photons):%s\n' "$PATH_SPP" "${line%;}"
    fi
    rm -rf "$TMP/xc" "$TMP/path.png"
done
awk '/^RATIO/ { n++; s += log($2) } END { if (n) printf "geometric mean of partray/POV-Ray wall time over %d scenes: %.3f\n", n, exp(s / n) }' "$TMP/ratios"
