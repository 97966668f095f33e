// Hard edges everywhere: a receding checker floor, thin cylinders and
// spheres against a dark sky, so +A supersamples about half the pixels.
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 2.2, -6> look_at <0, 0.6, 0> angle 55 }
light_source { <-4, 8, -5> rgb 1 }
background { rgb <0.05, 0.07, 0.12> }
plane { y, 0 pigment { checker rgb 0.9 rgb <0.1, 0.15, 0.3> scale 0.25 } finish { diffuse 0.8 } }
#declare I = 0;
#while (I < 9)
  cylinder { <-2 + I * 0.5, 0, 1.5>, <-2 + I * 0.5, 2.5, 1.5>, 0.03 pigment { rgb <1, 0.6, 0.2> } }
  sphere { <-2 + I * 0.5, 0.2 + mod(I, 3) * 0.35, 0>, 0.18 pigment { rgb <0.2, 0.8, 0.4> } finish { phong 0.6 } }
  #declare I = I + 1;
#end
