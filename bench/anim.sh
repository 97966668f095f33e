#!/bin/sh
# bench/anim.sh [BUILD_DIR] - animations in one run (docs/farm.md).
#
#  1. animations/raddem/raddem.pov (radiosity, 30 frames, its own .ini):
#     wall time of the 30 frames in one `partray render raddem.ini` run, of
#     30 separate runs (--frame N), and of POV-Ray's `povray raddem.ini`
#     (+KFF30) on the same machine in the same run, and which GI stages
#     each frame of the one-run animation ran (raddem turns an object with
#     the clock, so every frame needs every stage).
#  2. bench/scenes/cbox_fly.pov (scenes/cbox.pov with a camera moving with
#     the clock): 30 frames in one run; the geometry stage runs once; the
#     total against one frame's geometry stage plus the 30 frames' view
#     stages (prepare_view + the Whitted pass), and against the same plus
#     the 30 parses (a view frame reads the scene again for its camera).
#  3. --gi-cache on scenes/cbox.pov at FLY_SIZE with CACHE_PARTICLES
#     (default 50000, the particle mode's own default): the geometry stage run and
#     saved, then read by a second process; both processes' wall time, the
#     geometry stage's time against the read's, the file's size, and whether
#     the two images are the same bytes.
# Figures are wall seconds on whatever else the machine runs: compare the
# ratios within one run. SIZE (default 160x120) and FLY_SIZE (128x96) set
# the image sizes.
set -eu
BUILD=${1:-build}
P=$(cd "$BUILD" && pwd)/partray
SRC=$(cd "$(dirname "$0")/.." && pwd)
SIZE=${SIZE:-160x120}
FLY_SIZE=${FLY_SIZE:-128x96}
W=${SIZE%x*}
H=${SIZE#*x}
T=$(mktemp -d /tmp/partray-bench-anim-XXXXXX)
trap 'rm -rf "$T"' EXIT
cp /usr/share/doc/povray/examples/animations/raddem/raddem.ini /usr/share/doc/povray/examples/animations/raddem/raddem.pov "$T/"
cd "$T"
now() { date +%s.%N; }
secs() { echo "$2 - $1" | bc; }

echo "== raddem.pov, 30 frames at $SIZE (radiosity: partray --gi particle, POV-Ray its radiosity)"
t0=$(now)
"$P" render raddem.ini +W"$W" +H"$H" -o one.png 2>one.log
t1=$(now)
one=$(secs "$t0" "$t1")
t0=$(now)
for f in $(seq 1 30); do
    "$P" render raddem.ini +W"$W" +H"$H" --frame "$f" -q -o sep.png 2>/dev/null
done
t1=$(now)
sep=$(secs "$t0" "$t1")
t0=$(now)
povray raddem.ini +W"$W" +H"$H" -D -V +Opov.png >/dev/null 2>&1
t1=$(now)
pov=$(secs "$t0" "$t1")
n=$(ls one*.png | wc -l)
printf "partray, 30 frames in one run:     %8.2f s (%d images)\n" "$one" "$n"
printf "partray, 30 separate runs:         %8.2f s (one run / separate = %.3f)\n" "$sep" "$(echo "$one / $sep" | bc -l)"
printf "povray raddem.ini (+KFF30):        %8.2f s (%d images; partray one run / povray = %.2f)\n" "$pov" \
    "$(ls pov*.png | wc -l)" "$(echo "$one / $pov" | bc -l)"
echo "GI stages each frame ran (one run):"
grep "gi stages run" one.log | sed 's/^partray: /  /'

echo
echo "== cbox_fly.pov (scenes/cbox.pov, the camera moving), 30 frames at $FLY_SIZE in one run"
t0=$(now)
"$P" render "$SRC/bench/scenes/cbox_fly.pov" --size "$FLY_SIZE" --gi particle +KFI1 +KFF30 -o fly.png 2>fly.log
t1=$(now)
fly=$(secs "$t0" "$t1")
geo=$(grep "frame 1: gi particle: geometry" fly.log | sed 's/.*geometry \([0-9.]*\) s.*/\1/')
view=$(grep -o "render [0-9.]* s" fly.log | awk '{ s += $2 } END { print s }')
parse=$(grep -o "parse [0-9.]* s" fly.log | awk '{ s += $2 } END { print s }')
gruns=$(grep -c "gi stages run: geometry" fly.log || true)
printf "geometry stage runs:               %d of 30 frames\n" "$gruns"
printf "total, 30 frames:                  %8.2f s\n" "$fly"
printf "geometry (frame 1):                %8.2f s\n" "$geo"
printf "view stages, 30 frames:            %8.2f s\n" "$view"
printf "parses, 30 frames:                 %8.2f s\n" "$parse"
printf "total / (geometry + 30 views):     %8.3f (asked: <= 1.5)\n" "$(echo "$fly / ($geo + $view)" | bc -l)"
printf "total / (geometry + 30 views and parses): %.3f\n" "$(echo "$fly / ($geo + $view + $parse)" | bc -l)"
echo "frames by the GI stages they ran:"
grep "gi stages run" fly.log | sed 's/.*gi stages run: //' | sort | uniq -c

echo
CP=${CACHE_PARTICLES:-50000}
echo "== --gi-cache: scenes/cbox.pov at $FLY_SIZE, $CP particles, the geometry stage saved, then read by another process"
t0=$(now)
"$P" render "$SRC/scenes/cbox.pov" --size "$FLY_SIZE" --gi particle --particles "$CP" --gi-cache cbox.gic -o save.pfm 2>save.log
t1=$(now)
"$P" render "$SRC/scenes/cbox.pov" --size "$FLY_SIZE" --gi particle --particles "$CP" --gi-cache cbox.gic -o load.pfm 2>load.log
t2=$(now)
gsave=$(grep "gi particle: geometry" save.log | sed 's/.*geometry \([0-9.]*\) s.*/\1/')
gload=$(grep "gi particle: geometry" load.log | sed 's/.*geometry \([0-9.]*\) s.*/\1/')
printf "saving run:                        %8.2f s (geometry stage %.2f s)\n" "$(secs "$t0" "$t1")" "$gsave"
printf "loading run:                       %8.2f s (cache read %.2f s; read / geometry = %.3f)\n" "$(secs "$t1" "$t2")" \
    "$gload" "$(echo "$gload / $gsave" | bc -l)"
printf "cache file:                        %8.1f MiB\n" "$(echo "$(stat -c %s cbox.gic) / 1048576" | bc -l)"
if cmp -s save.pfm load.pfm; then echo "images: byte-identical"; else echo "images: DIFFER"; fi
