// Cross-check: object uv_mapping on spheres (POV-Ray 3.7's
// Sphere::UVCoord; the texture does not follow the object's transforms).
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 2, -6> look_at <0, 0.8, 0> angle 45 }
light_source { <5, 10, -5> color rgb 1 }
plane { y, 0 pigment { rgb 0.7 } }
sphere { 0, 1 uv_mapping pigment { checker rgb <1,0.2,0.1>, rgb 0.9 scale <0.1, 0.2, 1> } scale <1.2, 0.8, 1> rotate y*30 translate <-1.3, 0.8, 0> }
sphere { <1.3, 0.8, 0>, 0.8 uv_mapping texture { pigment { gradient x color_map { [0 rgb <0,0,1>] [0.5 rgb <1,1,0>] [1 rgb <0,0,1>] } } normal { bumps 0.4 scale 0.05 } finish { phong 0.5 } } rotate x*20 }
