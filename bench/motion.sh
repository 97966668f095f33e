#!/bin/sh
# bench/motion.sh [BUILD_DIR] - GI that follows motion (docs/motion.md).
#
#  1. --gi links (seed 001) on bench/scenes/mesh_room.pov (the
#     distribution's deforming spline mesh of templates/
#     Meshes_by_meshmaker_inc/ in a mesh2 room): raw and merged link counts
#     and their ratio, link rays per second and link time per vertex, the
#     first full solution's time, GI updates per second over LINK_FRAMES
#     frames of the deforming mesh (cyclic, +KC: the template's splines
#     turn a whole turn over the clock 0..1, so clock 1 is clock 0 again),
#     the merge ratio against the room's tessellation, `partray view`
#     taking a new clock (the time until the deformed mesh's links are
#     shown, and the images shown meanwhile while the camera orbits;
#     needs a display or Xvfb),
#     and quality against --gi path
#     (PATH_SPP samples, HDR-FLIP and mean luminance) beside --gi particle
#     on the first and last frame at QSIZE.
#  2. --gi detp (seed 004) on animations/raddem/raddem.pov (30 frames, a
#     turning divider), bench/scenes/cbox_move.pov (scenes/cbox.pov with a
#     sphere rolling across the floor, CBOX_FRAMES frames) and
#     tests/scenes/detp_cbox.pov (the Cornell box, coarser, its short block
#     sliding) at SIZE: the fraction of paths
#     re-traced per frame, whether each frame's image equals --detp-full's
#     (every path traced and every receiver estimated anew with the same
#     random streams) byte for byte, and the GI time per frame (the stages
#     before the Whitted pass) and the whole frame against --detp-full and
#     --gi particle; and the first frame of cbox_move.pov against --gi path
#     (PATH_SPP samples) for detp, particle and links (links lights the
#     room's meshes only: the sphere gets direct light).
#  3. Flicker: the mean absolute difference of consecutive frames (linear
#     RGB) over the top third of the image (ceiling and upper walls, which
#     the moving block does not cross) of detp_cbox.pov for particle, links
#     and detp.
# Figures are seconds on whatever else the machine runs: compare ratios
# within one run. SIZE (80x60), QSIZE (80x60), PATH_SPP (256), LINK_FRAMES
# (4), CBOX_FRAMES (12), RADDEM_FRAMES (30) and PHOTONS (100000) set the
# work; PARTS (default "1 2 3") which parts run (3 needs 2's cbox frames).
set -eu
BUILD=${1:-build}
P=$(cd "$BUILD" && pwd)/partray
SRC=$(cd "$(dirname "$0")/.." && pwd)
SIZE=${SIZE:-80x60}
QSIZE=${QSIZE:-80x60}
PATH_SPP=${PATH_SPP:-256}
LINK_FRAMES=${LINK_FRAMES:-4}
CBOX_FRAMES=${CBOX_FRAMES:-12}
RADDEM_FRAMES=${RADDEM_FRAMES:-30}
PHOTONS=${PHOTONS:-100000}
PARTS=${PARTS:-1 2 3}
part() { case " $PARTS " in *" $1 "*) return 0 ;; esac; return 1; }
TPL=/usr/share/doc/povray/examples/templates/Meshes_by_meshmaker_inc
T=$(mktemp -d /tmp/partray-bench-motion-XXXXXX)
trap 'rm -rf "$T"' EXIT
cp /usr/share/doc/povray/examples/animations/raddem/raddem.pov "$T/"
cp "$SRC/tests/scenes/detp_cbox.pov" "$SRC/bench/scenes/mesh_room.pov" "$T/"
mkdir -p "$T/bench/scenes" "$T/scenes"
cp "$SRC/bench/scenes/cbox_move.pov" "$T/bench/scenes/"
cp "$SRC/scenes/cbox.pov" "$T/scenes/"
cd "$T"

# log parser: per frame, the seconds of parse, accel, GI stages and render,
# and the detp / links line's figures (partray render's stderr)
cat > parse.py <<'EOF'
import re, sys, json
frames = {}
for line in open(sys.argv[1]):
    m = re.match(r'partray: (?:frame (\d+): )?(\d+)x(\d+), gi \w+, parse ([\d.]+) s, accel ([\d.]+) s, render ([\d.]+) s', line)
    if m:
        f = frames.setdefault(int(m.group(1) or 0), {})
        f['parse'], f['accel'], f['render'] = float(m.group(4)), float(m.group(5)), float(m.group(6))
    m = re.match(r'partray: (?:frame (\d+): )?gi \w+: geometry ([\d.]+) s, lighting ([\d.]+) s', line)
    if m:
        f = frames.setdefault(int(m.group(1) or 0), {})
        f['gi'] = float(m.group(2)) + float(m.group(3))
    m = re.match(r'partray: (?:frame (\d+): )?detp: (.*?), .* (\d+) of (\d+) paths re-traced', line)
    if m:
        f = frames.setdefault(int(m.group(1) or 0), {})
        f['retraced'] = int(m.group(3)) / max(1, int(m.group(4)))
        f['how'] = m.group(2)
    m = re.match(r'partray: (?:frame (\d+): )?links: (\w+), .* (\d+) of (\d+) elements linked again, links (\d+) raw, (\d+) merged', line)
    if m:
        f = frames.setdefault(int(m.group(1) or 0), {})
        f['linked'] = int(m.group(3)) / max(1, int(m.group(4)))
for f in frames.values():
    f.setdefault('gi', 0.0)
    f['total'] = f.get('parse', 0) + f.get('accel', 0) + f['gi'] + f.get('render', 0)
json.dump(frames, sys.stdout)
EOF
# mean absolute difference of consecutive PFM frames over the top third
cat > flicker.py <<'EOF'
import struct, sys
def pfm(path):
    with open(path, 'rb') as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        n = w * h * (3 if kind == b'PF' else 1)
        data = struct.unpack(('<' if scale < 0 else '>') + 'f' * n, f.read(4 * n))
    return w, h, data
prev = None
mads = []
for p in sys.argv[1:]:
    w, h, d = pfm(p)
    # PFM rows run bottom to top: the top third is the last h/3 rows
    rows = range(h - h // 3, h)
    cur = [d[(y * w + x) * 3 + c] for y in rows for x in range(w) for c in range(3)]
    if prev is not None:
        mads.append(sum(abs(a - b) for a, b in zip(cur, prev)) / len(cur))
    prev = cur
mean = sum(cur) / len(cur)
print("%.6f %.6f %.3f" % (sum(mads) / len(mads), max(mads), 100.0 * (sum(mads) / len(mads)) / mean if mean > 0 else 0.0))
EOF
field() { python3 -c "import json,sys; j=json.load(open('$1')); print($2)"; }

if part 1; then
echo "== 1. --gi links (seed 001): bench/scenes/mesh_room.pov at $SIZE"
"$P" render mesh_room.pov +L"$TPL" --gi links --size "$SIZE" -o still.pfm --stats still.json 2>still.log
field still.json "'vertices %d (elements %d, two sides), meshes %d' % (j['links']['vertices'], j['links']['elements'], j['links']['meshes'])"
field still.json "'links raw %d, merged %d: ratio %.2f (paper Table 1: 3-5x)' % (j['links']['raw_links'], j['links']['merged_links'], j['links']['raw_links'] / max(1, j['links']['merged_links']))"
field still.json "'link rays %d in %.3f s: %.2f M rays/s, %.1f us per vertex (both sides)' % (j['links']['link_rays'], j['links']['timings']['links'], j['links']['link_rays'] / max(1e-9, j['links']['timings']['links']) * 1e-6, j['links']['timings']['links'] / max(1, j['links']['vertices']) * 1e6)"
field still.json "'link rays ending on objects that are not meshes (one bounce of light from them): %d of %d (%.1f%%), %d such objects' % (j['links']['hits_other'], j['links']['link_rays'], 100.0 * j['links']['hits_other'] / max(1, j['links']['link_rays']), j['links']['other_objects'])"
field still.json "'first full solution %.3f s (links %.3f, light %.3f, %d sweeps %.3f, smoothing %.3f)' % (sum(j['links']['timings'].values()), j['links']['timings']['links'], j['links']['timings']['light'], j['links']['sweeps'], j['links']['timings']['bounces'], j['links']['timings']['smooth'])"
field still.json "'per element: %.0f raw links, %.0f merged (paper Table 1: TEAROOM 563 and 168 per vertex, TORSO 479 and 113)' % (j['links']['raw_links'] / max(1, j['links']['elements']), j['links']['merged_links'] / max(1, j['links']['elements']))"
# merging against the room's tessellation (NR cells a wall side; the
# spline mesh stays 51 x 51): fewer, larger triangles take more of a
# vertex's rays each, so more of its raw links share a peer
for nr in 2 4 8 16; do
    sed "s/^#declare NR = 16;/#declare NR = $nr;/" mesh_room.pov > mesh_room_nr.pov
    "$P" render mesh_room_nr.pov +L"$TPL" --gi links --size 16x12 -o nr.pfm --stats nr.json 2>/dev/null
    field nr.json "'  walls of $nr x $nr cells: %d vertices, links raw %d, merged %d: ratio %.2f, %.0f merged per element' % (j['links']['vertices'], j['links']['raw_links'], j['links']['merged_links'], j['links']['raw_links'] / max(1, j['links']['merged_links']), j['links']['merged_links'] / max(1, j['links']['elements']))"
done
rm -f mesh_room_nr.pov nr.pfm nr.json
"$P" render scenes/cbox.pov --gi links --size "$SIZE" -o cbox_still.pfm --stats cbox_still.json 2>/dev/null
field cbox_still.json "'scenes/cbox.pov: %d vertices, links raw %d, merged %d: ratio %.2f; %.2f M link rays/s' % (j['links']['vertices'], j['links']['raw_links'], j['links']['merged_links'], j['links']['raw_links'] / max(1, j['links']['merged_links']), j['links']['link_rays'] / max(1e-9, j['links']['timings']['links']) * 1e-6)"
"$P" render mesh_room.pov +L"$TPL" --gi links --size "$SIZE" +KFI1 +KFF"$LINK_FRAMES" +KC -o la.pfm 2>la.log
python3 parse.py la.log > la.json
python3 - <<EOF
import json
f = json.load(open('la.json'))
ks = sorted(int(k) for k in f)
for k in ks:
    x = f[str(k)]
    print('  frame %2d: GI %.3f s, elements linked again %5.1f%%' % (k, x['gi'], 100 * x.get('linked', 0)))
inc = [f[str(k)]['gi'] for k in ks[1:]]
if inc:
    m = sum(inc) / len(inc)
    print('deforming mesh: %.2f GI updates/s over frames %d-%d (first frame %.3f s)' % (1 / m if m > 0 else 0, ks[1], ks[-1], f[str(ks[0])]['gi']))
EOF
# the viewer: `clock` in a script re-evaluates the scene and links it again
# on a thread of its own while the camera keeps orbiting (under Xvfb when
# there is no display)
XPID=
if [ -z "${DISPLAY:-}" ] && command -v Xvfb >/dev/null 2>&1; then
    Xvfb -displayfd 3 -screen 0 1024x768x24 -nolisten tcp -noreset 3>xdisplay >/dev/null 2>&1 &
    XPID=$!
    i=0
    while [ ! -s xdisplay ] && [ $i -lt 100 ]; do sleep 0.1; i=$((i + 1)); done
    DISPLAY=:$(head -n1 xdisplay)
    export DISPLAY
fi
if [ -n "${DISPLAY:-}" ]; then
    python3 -c "
print('0 wait-idle')
print('0.1 mark before')
print('0.2 clock 0.1')
for k in range(80):
    print('%.2f camera orbit %d 0' % (0.2 + 0.05 * k, 2 if k % 2 == 0 else -2))
print('4.3 wait-idle')
print('4.4 mark after')
print('4.5 quit')" > clock.txt
    "$P" view mesh_room.pov +L"$TPL" --gi links --size "${VIEW_SIZE:-320x240}" --script clock.txt >view.out 2>view.err || true
    python3 - <<'EOF'
import re
err = open('view.err').read()
m = re.search(r'view: clock (\S+) shown \((\S+) asked\): (\d+) scenes? at a new clock taken over, the last after ([0-9.]+) s; (\d+) images', err)
if m:
    t, n = float(m.group(4)), int(m.group(5))
    print('view --gi links, clock 0 -> %s (the mesh deformed: parse, accel and links again on the clock thread): taken over after %.2f s; %d images shown meanwhile (%.1f/s) while the camera orbited' % (m.group(1), t, n, n / t if t > 0 else 0))
else:
    print('view: no clock summary (%s)' % err.strip().splitlines()[-1:])
m = re.search(r'view: (\d+) images \((\d+) shown\) in ([0-9.]+) s \(([0-9.]+)/s\)', err)
if m:
    print('  whole run: %s images in %s s (%s/s)' % (m.group(1), m.group(3), m.group(4)))
EOF
fi
if [ -n "$XPID" ]; then kill "$XPID" 2>/dev/null || true; unset DISPLAY; fi
echo "quality at $QSIZE against --gi path $PATH_SPP spp (HDR-FLIP mean, mean luminance):"
for fr in 1 "$LINK_FRAMES"; do
    "$P" render mesh_room.pov +L"$TPL" --gi path --spp "$PATH_SPP" --size "$QSIZE" +KFI1 +KFF"$LINK_FRAMES" +KC --frame "$fr" -o "q_path.pfm" -q 2>/dev/null
    for m in links particle; do
        "$P" render mesh_room.pov +L"$TPL" --gi "$m" --size "$QSIZE" +KFI1 +KFF"$LINK_FRAMES" +KC --frame "$fr" -o "q_$m.pfm" -q 2>/dev/null
    done
    qp=$(ls q_path*.pfm | head -1)
    for m in links particle; do
        qm=$(ls q_"$m"*.pfm | head -1)
        "$P" compare "$qp" "$qm" --hdr --json > "q_$m.json" 2>/dev/null
        field "q_$m.json" "'  frame %s %-8s FLIP %.4f, mean luminance %+.2f%%' % ('$fr', '$m', j['flip']['mean'], 100 * j['luminance']['relative'])"
    done
    rm -f q_*.pfm
done
# the reference's own direct light against the Whitted pass's (POV-Ray's):
# --max-depth 1 is the camera's hit alone (2 would add one bounce of
# indirect light); the template's textures keep POV-Ray's default ambient
# 0.1, which --gi none adds and every GI mode drops (radiosity on,
# core/radrules.h rule 1), so both render a copy with ambient 0
sed 's|^#include "40_mesh_by_4_splines.txt"|#default { finish { ambient 0 } }\n&|' mesh_room.pov > mesh_room_a0.pov
"$P" render mesh_room_a0.pov +L"$TPL" --gi path --spp "$PATH_SPP" --max-depth 1 --size "$QSIZE" -o d_path.pfm -q 2>/dev/null
"$P" render mesh_room_a0.pov +L"$TPL" --gi none --size "$QSIZE" -o d_none.pfm -q 2>/dev/null
"$P" compare d_path.pfm d_none.pfm --hdr --json > d.json 2>/dev/null
W=${QSIZE%x*}; H=${QSIZE#*x}
if command -v povray >/dev/null 2>&1; then
    povray +Imesh_room.pov +L"$TPL" +W"$W" +H"$H" +Q8 -D -GA +Od_pov.png >/dev/null 2>&1 || true
    "$P" render mesh_room.pov +L"$TPL" --gi none --size "$QSIZE" -o d_none.png -q 2>/dev/null
    if [ -f d_pov.png ]; then
        "$P" compare d_pov.png d_none.png --json > dp.json 2>/dev/null
        field dp.json "'direct light only: --gi none against POV-Ray +Q8 (radiosity off), PNG: mean luminance %+.2f%%' % (100 * j['luminance']['relative'])"
    fi
    # POV-Ray's own radiosity (the scene's radiosity{}) as a second reference
    povray +Imesh_room.pov +L"$TPL" +W"$W" +H"$H" +Q9 -D -GA +Or_pov.png >/dev/null 2>&1 || true
    if [ -f r_pov.png ]; then
        for m in links particle; do
            "$P" render mesh_room.pov +L"$TPL" --gi "$m" --size "$QSIZE" -o "r_$m.png" -q 2>/dev/null
            "$P" compare r_pov.png "r_$m.png" --json > "r_$m.json" 2>/dev/null
            field "r_$m.json" "'  against POV-Ray radiosity (PNG) %-8s FLIP %.4f, mean luminance %+.2f%%' % ('$m', j['flip']['mean'], 100 * j['luminance']['relative'])"
        done
    fi
fi
field d.json "'direct light only (ambient 0): --gi none (the lighting of POV-Ray) against --gi path --max-depth 1: mean luminance %+.2f%%, HDR-FLIP %.4f' % (100 * j['luminance']['relative'], j['flip']['mean'])"
rm -f mesh_room_a0.pov
fi

detp_scene() {
    name=$1; scene=$2; frames=$3
    echo "== 2. --gi detp (seed 004): $name, $frames frames at $SIZE, $PHOTONS photon paths"
    "$P" render "$scene" --gi detp --photons "$PHOTONS" --size "$SIZE" +KFI1 +KFF"$frames" -o "${name}_i.pfm" 2>"${name}_i.log"
    "$P" render "$scene" --gi detp --detp-full --photons "$PHOTONS" --size "$SIZE" +KFI1 +KFF"$frames" -o "${name}_f.pfm" 2>"${name}_f.log"
    "$P" render "$scene" --gi particle --size "$SIZE" +KFI1 +KFF"$frames" -o "${name}_p.pfm" 2>"${name}_p.log"
    same=0; n=0
    for a in "${name}"_i*.pfm; do
        b=$(echo "$a" | sed "s/${name}_i/${name}_f/")
        n=$((n + 1))
        if cmp -s "$a" "$b"; then same=$((same + 1)); fi
    done
    echo "frames byte-identical to the full recomputation (same random streams): $same of $n"
    python3 parse.py "${name}_i.log" > i.json
    python3 parse.py "${name}_f.log" > f.json
    python3 parse.py "${name}_p.log" > p.json
    python3 - <<EOF
import json
i, f, p = (json.load(open(x)) for x in ('i.json', 'f.json', 'p.json'))
ks = sorted(int(k) for k in i)
print('frame  re-traced   GI s: detp  full  particle   frame s: detp  full  particle')
for k in ks:
    a, b, c = i[str(k)], f.get(str(k), {}), p.get(str(k), {})
    print('%5d  %8.2f%%   %10.3f %5.3f %8.3f   %13.3f %5.3f %8.3f' % (k, 100 * a.get('retraced', 0), a['gi'], b.get('gi', 0), c.get('gi', 0), a['total'], b.get('total', 0), c.get('total', 0)))
inc = ks[1:]
if inc:
    def mean(d, key): return sum(d[str(k)].get(key, 0) for k in inc) / len(inc)
    fr = mean(i, 'retraced')
    print('frames %d-%d: mean %.2f%% of paths re-traced; GI per frame detp %.3f s, full %.3f s (%.2fx), particle %.3f s (%.2fx); whole frame detp %.3f s, full %.3f s, particle %.3f s' % (
        inc[0], inc[-1], 100 * fr, mean(i, 'gi'), mean(f, 'gi'), mean(f, 'gi') / max(1e-9, mean(i, 'gi')), mean(p, 'gi'), mean(p, 'gi') / max(1e-9, mean(i, 'gi')),
        mean(i, 'total'), mean(f, 'total'), mean(p, 'total')))
EOF
}
if part 2; then
detp_scene raddem raddem.pov "$RADDEM_FRAMES"
detp_scene cboxmove bench/scenes/cbox_move.pov "$CBOX_FRAMES"
detp_scene cbox detp_cbox.pov "$CBOX_FRAMES"
echo "quality of bench/scenes/cbox_move.pov's first frame at $QSIZE against --gi path $PATH_SPP spp (HDR-FLIP mean, mean luminance):"
"$P" render bench/scenes/cbox_move.pov --gi path --spp "$PATH_SPP" --size "$QSIZE" +KFI1 +KFF"$CBOX_FRAMES" --frame 1 -o cq_path.pfm -q 2>/dev/null
for m in detp particle links; do
    "$P" render bench/scenes/cbox_move.pov --gi "$m" --size "$QSIZE" +KFI1 +KFF"$CBOX_FRAMES" --frame 1 -o "cq_$m.pfm" -q 2>/dev/null
    "$P" compare "$(ls cq_path*.pfm | head -1)" "$(ls cq_"$m"*.pfm | head -1)" --hdr --json > "cq_$m.json" 2>/dev/null
    field "cq_$m.json" "'  %-8s FLIP %.4f, mean luminance %+.2f%%' % ('$m', j['flip']['mean'], 100 * j['luminance']['relative'])"
done
fi

part 3 || exit 0
echo "== 3. flicker: detp_cbox.pov, $CBOX_FRAMES frames at $SIZE, top third (mean |frame k - frame k-1|, max, % of the region's mean)"
"$P" render detp_cbox.pov --gi links --size "$SIZE" +KFI1 +KFF"$CBOX_FRAMES" -o cbox_l.pfm -q 2>/dev/null
for m in particle:cbox_p links:cbox_l detp:cbox_i; do
    printf '  %-9s %s\n' "${m%%:*}" "$(python3 flicker.py $(ls "${m#*:}"*.pfm | sort))"
done
