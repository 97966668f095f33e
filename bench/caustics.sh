#!/bin/sh
# POV-Ray's photon scenes: partray's caustic layer (docs/caustics.md)
# against POV-Ray. For every distribution scene with a photons{} block, at
# SIZE +A0.3 with THREADS threads, partray's default render (its GI mode:
# none, or particle under radiosity{}) and POV-Ray's default render in the
# same run, both measured against POV-Ray at 4x the scene's photon count
# (its global photons block with count x4 or spacing / 2; cached). Prints:
# mean luminance of partray's render over that reference's, LDR-FLIP of
# POV-Ray's default and of partray's render against it, the sRGB mean
# absolute difference of partray's render from POV-Ray's default after a
# 4x4 box downsample, both wall times and their ratio, and whether the
# render meets the bounds (luminance within 5%, FLIP no worse than POV-Ray's
# default, time no longer); then, per scene, bench_caustics' splat-versus-
# kd-tree-gather times and photon attrition per bounce. Prints figures; not
# a test. With CAUSTICS_FLOOR=1, each row is followed by the floor without
# caustics: the scene with its global photons block removed, rendered by
# both, partray's FLIP against POV-Ray's (how much of the row's FLIP is not
# the caustics).
#
# In a scene with radiosity{} POV-Ray's default render and its 4x render
# share their radiosity solution (same samples, same positions), so their
# FLIP measures the photons alone while partray's also holds every
# difference of its GI from that unconverged solution. Such a row is
# followed by a second comparison against POV-Ray at 4x the photons and
# with converged radiosity (the 4x scene through `partray crosscheck
# --converged`: its radiosity block at 4x the count and 0.4x the
# error_bound, cached in XC_CACHE as gi_vs_povray.sh's are; a render over
# REF_TIMEOUT is not made and the line says so).
#
# usage: bench/caustics.sh [SIZE] [THREADS] [REF_TIMEOUT] [SCENE...]
#   SIZE default 160x120, THREADS 2, REF_TIMEOUT 1200 s (a 4x render that
#   takes longer is not made; the line says so and POV-Ray's default render
#   is the reference). Scenes relative to the examples directory, default
#   the 7 with photons{}. PARTRAY, BENCH_CAUSTICS, CAUSTICS_CACHE, XC_CACHE
#   override the binaries and the reference caches.
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PARTRAY=${PARTRAY:-$ROOT/build/partray}
BENCH=${BENCH_CAUSTICS:-$ROOT/build/bench/bench_caustics}
SIZE=${1:-160x120}
THREADS=${2:-2}
RTIMEOUT=${3:-1200}
[ $# -gt 3 ] && shift 3 || set --
EX=/usr/share/doc/povray/examples
CACHE=${CAUSTICS_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/partray/caustics}
XC_CACHE=${XC_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/partray/crosscheck}
W=${SIZE%x*}; H=${SIZE#*x}
if [ $# -eq 0 ]; then
    set -- lights/phot_met_glass.pov lights/glassthing.pov advanced/optics.pov advanced/grenadine/grenadine.pov \
           advanced/balcony/balcony.pov advanced/benchmark/benchmark.pov advanced/diffuse_back.pov
fi
mkdir -p "$CACHE"
TMP=$(mktemp -d /tmp/caustics_bench.XXXXXX)
trap 'rm -rf "$TMP"' EXIT
POVOPTS="+W$W +H$H +A0.3 +R3 -D -V -P +FN -UA +WT$THREADS"

# wall time of a command in seconds (its output is dropped)
wall() {
    python3 -c 'import subprocess, sys, time
t = time.time(); subprocess.call(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
print("%.3f" % (time.time() - t))' "$@"
}

# The scene with its global photons block edited. MODE 4x: at 4x the
# photons: count x4, or spacing / 2 (POV-Ray's photon count goes as
# 1 / spacing^2); a block with neither gets spacing 0.5 (the default spacing
# 1, halved). MODE off: the block removed (no photons at all).
photons_edit() {
    python3 - "$1" "$2" "$3" <<'EOF'
import re, sys
mode, src, dst = sys.argv[1], sys.argv[2], sys.argv[3]
text = open(src, encoding='latin-1').read()
out, i, done = [], 0, False
for m in re.finditer(r'\bphotons\s*\{', text):
    # the block's text up to its closing brace
    j, depth = m.end(), 1
    while j < len(text) and depth:
        depth += {'{': 1, '}': -1}.get(text[j], 0); j += 1
    body = text[m.end():j - 1]
    code = re.sub(r'//[^\n]*', lambda c: ' ' * len(c.group(0)), body)
    if not re.search(r'\b(spacing|count)\b', code) and not re.search(r'\b(autostop|jitter|gather)\b', code):
        continue  # an object's or a light's block
    def count4(c): return c.group(1) + str(4 * int(float(c.group(2))))
    def spacing2(c): return c.group(1) + repr(float(c.group(2)) / 2)
    new = code
    if mode == 'off':
        out.append(text[i:m.start()]); out.append('/* photons removed */'); i = j; done = True
        continue
    if re.search(r'\bcount\b', code):
        new = re.sub(r'(\bcount\s+)([0-9.eE+]+)', count4, code)
    elif re.search(r'\bspacing\b', code):
        new = re.sub(r'(\bspacing\s+)([0-9.eE+-]+)', spacing2, code)
    else:
        new = ' spacing 0.5 ' + code
    out.append(text[i:m.end()]); out.append(new); i = j - 1; done = True
out.append(text[i:])
open(dst, 'w', encoding='latin-1').write(''.join(out))
print('ok' if done else 'none')
EOF
}

printf '%-34s %7s %8s %8s %8s %8s %8s %6s  %s\n' scene lum_pt flip_pov flip_pt mad4_pt t_pov t_pt t_rat "bounds (lum flip time)"
for rel in "$@"; do
    dir=$(dirname "$rel"); base=$(basename "$rel"); stem=${base%.pov}
    work="$TMP/$dir"; mkdir -p "$work" && cp -r "$EX/$dir/." "$work/"
    key=$(cat "$EX/$rel" | md5sum | cut -c1-12)
    ref="$CACHE/${stem}_${key}_${W}x${H}_4x.png"
    note=""
    if [ ! -f "$ref" ] && [ ! -f "$ref.timedout" ]; then
        if [ "$(photons_edit 4x "$work/$base" "$work/${stem}_4x.pov")" = ok ]; then
            (cd "$work" && timeout "$RTIMEOUT" povray +I"${stem}_4x.pov" +O"${stem}_4x.png" $POVOPTS +L"$work" >/dev/null 2>&1)
            if [ -f "$work/${stem}_4x.png" ]; then cp "$work/${stem}_4x.png" "$ref"; else touch "$ref.timedout"; fi
        fi
    fi
    t_pov=$(cd "$work" && wall povray +I"$base" +O"${stem}_pov.png" $POVOPTS +L"$work")
    t_pt=$(cd "$work" && wall "$PARTRAY" render "$base" --size "$SIZE" +A0.3 --threads "$THREADS" -o "${stem}_pt.png" \
           --stats "${stem}.json" --quiet)
    if [ ! -f "$work/${stem}_pt.png" ] || [ ! -f "$work/${stem}_pov.png" ]; then
        printf '%-34s failed (partray or POV-Ray made no image)\n' "$rel"; continue
    fi
    if [ -f "$ref" ]; then refimg=$ref; else refimg="$work/${stem}_pov.png"; note=" [ref: POV-Ray default, 4x not made]"; fi
    fpov=$("$PARTRAY" compare "$refimg" "$work/${stem}_pov.png" --json 2>/dev/null | python3 -c 'import json,sys; print(json.load(sys.stdin)["flip"]["mean"])')
    js=$("$PARTRAY" compare "$refimg" "$work/${stem}_pt.png" --json 2>/dev/null)
    mad=$(python3 - "$ROOT/scripts" "$work/${stem}_pov.png" "$work/${stem}_pt.png" <<'EOF'
import sys
sys.path.insert(0, sys.argv[1])
from pngread import mad4, read_png
print("%.4f" % mad4(read_png(sys.argv[2]), read_png(sys.argv[3])))
EOF
)
    printf '%s\n' "$js" | python3 -c '
import json, sys
j = json.load(sys.stdin); rel, fpov, mad, tp, tt, note = sys.argv[1], float(sys.argv[2]), sys.argv[3], float(sys.argv[4]), float(sys.argv[5]), sys.argv[6]
lum = j["luminance"]["test"] / j["luminance"]["reference"] if j["luminance"]["reference"] > 0 else 0
fpt = j["flip"]["mean"]
ok = lambda b: "ok" if b else "NO"
print("%-34s %7.4f %8.4f %8.4f %8s %8.2f %8.2f %6.3f  %s %s %s%s" % (rel, lum, fpov, fpt, mad, tp, tt, tt / tp if tp > 0 else 0,
      ok(abs(lum - 1) <= 0.05), ok(fpt <= fpov) if fpov > 0 else "--", ok(tt <= tp), note))
print("RATIO %.6f" % (tt / tp if tp > 0 else 1), file=sys.stderr)
' "$rel" "$fpov" "$mad" "$t_pov" "$t_pt" "$note" 2>>"$TMP/ratios"
    if [ "${CAUSTICS_FLOOR:-0}" = 1 ] && [ "$(photons_edit off "$work/$base" "$work/${stem}_off.pov")" = ok ]; then
        (cd "$work" && povray +I"${stem}_off.pov" +O"${stem}_off_pov.png" $POVOPTS +L"$work" >/dev/null 2>&1)
        (cd "$work" && "$PARTRAY" render "${stem}_off.pov" --size "$SIZE" +A0.3 --threads "$THREADS" -o "${stem}_off_pt.png" \
             --quiet >/dev/null 2>&1)
        "$PARTRAY" compare "$work/${stem}_off_pov.png" "$work/${stem}_off_pt.png" --json 2>/dev/null | python3 -c '
import json, sys
print("  without photons (both renderers): FLIP partray vs POV-Ray %.4f" % json.load(sys.stdin)["flip"]["mean"])'
    fi
    # partray's default mode is particle GI exactly when the scene has radiosity{}
    gi=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1])).get("gi", ""))' "$work/${stem}.json" 2>/dev/null)
    if [ "$gi" = particle ] && [ "$(photons_edit 4x "$work/$base" "$work/${stem}_4x.pov")" = ok ]; then
        xj=$(cd "$work" && "$PARTRAY" crosscheck "${stem}_4x.pov" --size "$SIZE" +A0.3 --threads "$THREADS" --converged \
             --cache "$XC_CACHE" --converged-timeout "$RTIMEOUT" --json --quiet 2>/dev/null)
        conv=$(printf '%s\n' "$xj" | python3 -c 'import json, sys
try: c = json.load(sys.stdin).get("converged", {})
except Exception: c = {}
print(c.get("image", "") if c.get("made") else "")')
        if [ -n "$conv" ]; then
            fpc=$("$PARTRAY" compare "$conv" "$work/${stem}_pov.png" --json 2>/dev/null)
            ftc=$("$PARTRAY" compare "$conv" "$work/${stem}_pt.png" --json 2>/dev/null)
            python3 -c '
import json, sys
p, t = json.loads(sys.argv[1]), json.loads(sys.argv[2])
lum = lambda j: j["luminance"]["test"] / j["luminance"]["reference"] if j["luminance"]["reference"] > 0 else 0
print("  vs POV-Ray at 4x photons, converged radiosity: lum POV-Ray %.4f partray %.4f, FLIP POV-Ray %.4f partray %.4f  %s" %
      (lum(p), lum(t), p["flip"]["mean"], t["flip"]["mean"], "ok" if t["flip"]["mean"] <= p["flip"]["mean"] else "NO"))' "$fpc" "$ftc"
        else
            echo "  vs POV-Ray at 4x photons, converged radiosity: not made (over ${RTIMEOUT} s)"
        fi
    fi
    (cd "$work" && "$BENCH" "$base" --size "$SIZE" --threads "$THREADS" --reps 3 > "$TMP/${stem}.bench" 2>&1)
done
awk '/^RATIO/ { n++; s += log($2) } END { if (n) printf "geometric mean of partray/POV-Ray wall time over %d scenes: %.3f\n", n, exp(s / n) }' "$TMP/ratios"
echo
echo "splat (photon volumes) vs pmfg's kd-tree gather over the same photons; attrition per bounce:"
for f in "$TMP"/*.bench; do
    [ -f "$f" ] || continue
    echo "--- $(head -1 "$f")"
    sed -n '2,$p' "$f" | grep -v '^stages'
done
