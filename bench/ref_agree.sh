#!/bin/sh
# ref_agree.sh - the two reference renderers against each other, and against
# POV-Ray, on scenes lit through radiosity. Figures, never pass/fail.
#
#   bench/ref_agree.sh [SCENE...]    SCENE: a path under the distribution's
#                                    examples (default: radiosity/cornell.pov
#                                    advanced/blocks/stackerday.pov
#                                    advanced/balcony/balcony.pov)
#
# Each scene's directory is copied to OUT (scenes write files beside
# themselves) and rendered at SIZE (64x48; cornell, a square image, at
# 64x64) with THREADS (2) threads:
#   path   --gi path --spp PATH_SPP (1024)
#   pmfg   --gi pmfg with its defaults (16 eye samples, 4096 gather rays per
#          pixel, 1,000,000 photons)
#   povray its own render of the scene as written (radiosity block and all),
#          as Radiance HDR (a PNG clips at 1, and these scenes exceed it)
# Printed per scene: wall time of each; the modes' warnings about light they
# do not model; mean luminance of each and the difference of pmfg and of
# POV-Ray from path; pmfg's
# pixels darker than half of path's where path's luminance exceeds 0.1
# (speckles, leaks), with the smallest pmfg/path ratio over those pixels.
# The reference modes agree when the difference is within 2% and there is
# no dark pixel.
#
# BUILD=DIR (default build) holds partray; EXAMPLES=DIR (default
# /usr/share/doc/povray/examples); OUT=DIR (default /tmp/ref_agree) keeps
# the images and logs. POVRAY=0 skips POV-Ray.
set -eu
cd "$(dirname "$0")/.."
ROOT=$(pwd)
BUILD=${BUILD:-build}
case $BUILD in /*) ;; *) BUILD=$ROOT/$BUILD ;; esac
PARTRAY=$BUILD/partray
SIZE=${SIZE:-64x48}
THREADS=${THREADS:-2}
PATH_SPP=${PATH_SPP:-1024}
EXAMPLES=${EXAMPLES:-/usr/share/doc/povray/examples}
OUT=${OUT:-/tmp/ref_agree}
POVRAY=${POVRAY:-1}
[ $# -gt 0 ] || set -- radiosity/cornell.pov advanced/blocks/stackerday.pov advanced/balcony/balcony.pov
mkdir -p "$OUT"

now() { date +%s.%N; }

# Mean luminances (Rec. 709 weights) of path.pfm, pmfg.pfm and, when
# present, POV-Ray's povray.hdr (Radiance RGBE: POV-Ray writes no PFM, and
# its PNG clips at 1); pmfg's dark pixels against path's.
figures() {
    python3 - <<'EOF2'
import os, struct
def lum(r, g, b): return 0.2126 * r + 0.7152 * g + 0.0722 * b
def pfm(p):
    f = open(p, 'rb')
    kind = f.readline().strip()
    w, h = (int(v) for v in f.readline().split())
    scale = float(f.readline())
    ch = 3 if kind == b'PF' else 1
    n = w * h * ch
    v = struct.unpack(('<' if scale < 0 else '>') + '%df' % n, f.read(4 * n))
    # PFM rows run bottom to top
    rows = [[lum(*(v[(y * w + x) * ch + (k if ch == 3 else 0)] for k in range(3))) for x in range(w)]
            for y in range(h)]
    return [l for row in reversed(rows) for l in row]
def hdr(p):
    d = open(p, 'rb').read()
    i = d.index(b'\n\n') + 2
    j = d.index(b'\n', i)
    dims = d[i:j].split()
    h, w = int(dims[1]), int(dims[3])
    i = j + 1
    out = []
    for y in range(h):
        if d[i] == 2 and d[i + 1] == 2:          # new-style run-length scanline
            i += 4
            chans = []
            for c in range(4):
                row = []
                while len(row) < w:
                    n = d[i]; i += 1
                    if n > 128:
                        row += [d[i]] * (n - 128); i += 1
                    else:
                        row += list(d[i:i + n]); i += n
                chans.append(row)
            px = list(zip(*chans))
        else:                                    # flat RGBE
            px = [tuple(d[i + 4 * x:i + 4 * x + 4]) for x in range(w)]
            i += 4 * w
        for r, g, b, e in px:
            f = 0.0 if e == 0 else 2.0 ** (e - 136)
            out.append(lum(r * f, g * f, b * f))
    return out
a, b = pfm('path.pfm'), pfm('pmfg.pfm')
ma, mb = sum(a) / len(a), sum(b) / len(b)
print('mean luminance: path %.5f, pmfg %.5f (%+.2f%% of path)' % (ma, mb, 100.0 * (mb / ma - 1.0)), end='')
if os.path.exists('povray.hdr'):
    c = hdr('povray.hdr')
    mc = sum(c) / len(c)
    print(', POV-Ray %.5f (%+.2f%% of path)' % (mc, 100.0 * (mc / ma - 1.0)), end='')
print()
bright = [(p, q) for p, q in zip(a, b) if p > 0.1]
dark = sum(1 for p, q in bright if q < 0.5 * p)
ratio = min((q / p for p, q in bright), default=float('nan'))
print('pixels with path > 0.1: %d, pmfg below half of path: %d, smallest pmfg/path there: %.3f'
      % (len(bright), dark, ratio))
EOF2
}

for s in "$@"; do
    name=$(basename "$s" .pov)
    dir=$OUT/$name
    rm -rf "$dir"
    mkdir -p "$dir"
    cp -r "$EXAMPLES/$(dirname "$s")/." "$dir/"
    size=$SIZE
    [ "$name" = cornell ] && size=64x64
    w=${size%x*}
    h=${size#*x}
    echo "== $s at $size, $THREADS threads (load $(cut -d' ' -f1-3 /proc/loadavg))"
    cd "$dir"
    t0=$(now)
    "$PARTRAY" render "$name.pov" --gi path --spp "$PATH_SPP" --size "$size" --threads "$THREADS" --seed 1 \
        -o path.pfm --stats path.json >path.log 2>&1
    t1=$(now)
    "$PARTRAY" render "$name.pov" --gi pmfg --size "$size" --threads "$THREADS" --seed 1 \
        -o pmfg.pfm --stats pmfg.json >pmfg.log 2>&1
    t2=$(now)
    printf 'wall: path %.1f s, pmfg %.1f s' "$(awk "BEGIN{print $t1 - $t0}")" "$(awk "BEGIN{print $t2 - $t1}")"
    if [ "$POVRAY" = 1 ]; then
        povray -i"$name.pov" +W"$w" +H"$h" -D -V +FH -opovray.hdr +WT"$THREADS" >povray.log 2>&1 || true
        t3=$(now)
        printf ', povray %.1f s' "$(awk "BEGIN{print $t3 - $t2}")"
    fi
    echo
    grep -h "warning: --gi" path.log pmfg.log | sort -u | sed 's/^/  /' || true
    figures
    cd "$ROOT"
done
