// Shape cross-check: ovus against POV-Ray 3.7 (bottom > top, top > bottom, in CSG)
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 1.2, -5> look_at <0, 0.6, 0> angle 40 }
light_source { <3, 5, -4> rgb 1 }
ovus { 1, 0.65 pigment { rgb <1, 0.8, 0.4> } finish { phong 0.5 } rotate 25*z translate -1.3*x }
ovus { 0.6, 1.0 pigment { rgb <0.4, 0.8, 1> } translate 1.2*x }
difference { ovus { 0.8, 0.5 } box { <0,-1,-2>, <2,3,0> } pigment { rgb <0.6,1,0.6> } translate <0,-0.5,1> scale 0.8 }
plane { y, -1 pigment { checker rgb 1 rgb 0.5 } }
