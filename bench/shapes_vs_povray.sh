#!/bin/sh
# Shapes benchmark: ray throughput of partray on (a) 10,000 spheres and
# (b) a CSG-heavy scene (differences and intersections of analytic shapes and
# swept and implicit ones: lathes, prisms, superellipsoids, blobs), beside POV-Ray
# 3.7's wall time for the same scene and size. Prints figures; not a test.
# usage: bench/shapes_vs_povray.sh [SIZE] [THREADS]
set -eu
SIZE=${1:-320}
THREADS=${2:-2}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PARTRAY=${PARTRAY:-$ROOT/build/partray}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
cd "$TMP"

cat > spheres.pov <<'EOF'
#version 3.7;
global_settings { assumed_gamma 1 }
camera { location <0, 0, -30> look_at 0 angle 60 }
light_source { <20, 30, -40> rgb 1 }
#declare R = seed(4);
#declare I = 0;
#while (I < 10000)
  sphere { <rand(R) * 40 - 20, rand(R) * 30 - 15, rand(R) * 40>, 0.15 + 0.25 * rand(R)
           pigment { rgb <rand(R), rand(R), rand(R)> } }
  #declare I = I + 1;
#end
EOF

cat > csg.pov <<'EOF'
#version 3.7;
global_settings { assumed_gamma 1 }
camera { location <0, 8, -22> look_at <0, 0, 0> angle 60 }
light_source { <20, 30, -40> rgb 1 }
plane { y, -1.2 pigment { rgb 0.6 } }
#declare P0 = difference { box { -1, 1 } sphere { 0, 1.3 } cylinder { -2*x, 2*x, 0.5 } }
#declare P1 = intersection { lathe { cubic_spline 6, <0,-1.2>, <0,-1>, <1,-0.5>, <0.6,0.4>, <0.9,1>, <0,1.2> } box { <-1,-0.8,-1>, <0,1,1> } }
#declare P2 = difference { superellipsoid { <0.3, 0.6> } prism { linear_sweep cubic_spline -2, 2, 7, <0,-0.6>, <0.6,0>, <0,0.6>, <-0.6,0>, <0,-0.6>, <0.6,0>, <0,0.6> rotate 90*x } }
#declare P3 = intersection { blob { threshold 0.5 sphere { <-0.4,0,0>, 1, 1 } sphere { <0.4,0.3,0>, 1, 1 } cylinder { <0,-0.8,0>, <0,0.8,0>, 0.5, 1 } } sphere { 0, 1.1 } }
#declare R = seed(7);
#declare I = 0;
#while (I < 20)
  #declare J = 0;
  #while (J < 10)
    #switch (mod(I + J, 4))
      #case (0) #declare P = P0; #break
      #case (1) #declare P = P1; #break
      #case (2) #declare P = P2; #break
      #else #declare P = P3;
    #end
    object { P rotate <rand(R)*360, rand(R)*360, 0> translate <I*2.2-21, 0, J*2.2-6> pigment { rgb <rand(R), rand(R), rand(R)> } }
    #declare J = J + 1;
  #end
  #declare I = I + 1;
#end
EOF

now() { date +%s.%N; }
for scene in spheres csg; do
    t0=$(now)
    povray +I$scene.pov +Opov_$scene.png +W$SIZE +H$SIZE -D -V -GA +WT$THREADS >/dev/null 2>&1 || echo "povray failed on $scene"
    t1=$(now)
    "$PARTRAY" render $scene.pov -o pt_$scene.png --size ${SIZE}x$SIZE --threads "$THREADS" --stats $scene.json --quiet
    t2=$(now)
    rays=$(sed -n 's/.*"rays": *\([0-9]*\).*/\1/p' $scene.json | head -1)
    render=$(sed -n 's/.*"render": *\([0-9.e+-]*\).*/\1/p' $scene.json | head -1)
    printf "%s %sx%s, %s threads:\n" "$scene" "$SIZE" "$SIZE" "$THREADS"
    printf "  povray  %.3f s wall\n" "$(awk -v a="$t0" -v b="$t1" 'BEGIN{print b-a}')"
    printf "  partray %.3f s wall, render %s s, %s rays, %.2f Mrays/s\n" "$(awk -v a="$t1" -v b="$t2" 'BEGIN{print b-a}')" \
        "$render" "$rays" "$(awk -v r="$rays" -v t="$render" 'BEGIN{print (t > 0) ? r / t / 1e6 : 0}')"
done
