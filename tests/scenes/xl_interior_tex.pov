// Cross-check: texture vs interior_texture on flat meshes of both windings, chosen by POV-Ray's own triangle normal (P1-P2)x(P3-P2), the opposite of the winding normal
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 0.5, -4> look_at <0, 0, 0> angle 50 }
light_source { <5, 10, -5> color rgb 1 }
background { rgb <0.4,0.5,0.6> }
mesh { triangle { <-2,-1,0>, <-0.2,-1,0>, <-0.2,1,0> } triangle { <-2,-1,0>, <-0.2,1,0>, <-2,1,0> }
  texture { pigment { rgb <1,0,0> } } interior_texture { pigment { rgb <0,0,1> } } }
mesh { triangle { <0.2,-1,0>, <2,1,0>, <2,-1,0> } triangle { <0.2,-1,0>, <0.2,1,0>, <2,1,0> }
  texture { pigment { rgb <1,0,0> } } interior_texture { pigment { rgb <0,0,1> } } }
