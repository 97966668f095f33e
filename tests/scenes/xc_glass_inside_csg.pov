// Cross-check: the camera inside a glass CSG intersection (the list of
// containers cannot test a CSG result, so leaving it must not count as
// entering it), looking through it at a glass ball and a checkered wall.
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 1, -2> look_at <0, 0.5, 2> angle 60 }
light_source { <3, 8, -5> rgb 1 }
plane { y, -1 pigment { checker rgb 0.2 rgb 0.9 } finish { ambient 0.1 diffuse 0.8 } }
box { <-3,-1,6>, <3,4,7> pigment { checker rgb <0.9,0.3,0.2> rgb 0.9 scale 0.5 } }
intersection { box { <-2,-0.5,-3>, <2,2.5,3> } sphere { <0,1,0>, 3.2 }
  pigment { rgbf <0.8,0.9,1,0.9> } finish { reflection { 0.05, 1 fresnel on } conserve_energy } interior { ior 1.5 } }
sphere { <0.8, 0.3, 4.5>, 0.6 pigment { rgbf <1,1,1,0.95> } interior { ior 1.3 } }
