// Shape cross-check: bounded_by as POV-Ray 3.7 culls with it: an unbounded quartic
// cylinder seen only along rays that cross its bounding sphere (also
// outside the sphere), a union bound, a top-level sphere whose bound
// POV-Ray drops
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 3, -9> look_at <0, 0, 0> angle 50 }
light_source { <4, 8, -6> rgb 1 }
quartic { <0,0,0,0,0,0,0,0,0,0, 0,0,0,0,0,0,0,0,0,0, 0,0,0,0,0,1,0,0,0,0, 0,0,1,0,-1>
  bounded_by { sphere { 0, 2 } } pigment { rgb <1, 0.6, 0.3> } }
union { sphere { <-3,0,2>, 0.8 } sphere { <3,0,2>, 0.8 } bounded_by { box { <-4,-1,1>, <0,1,3> } } pigment { rgb <0.3,0.7,1> } }
sphere { <0,-1.5,-2>, 0.6 bounded_by { box { -0.1, 0.1 } } pigment { rgb <0.5,1,0.5> } }
plane { y, -2.2 pigment { checker rgb 1 rgb 0.5 } }
