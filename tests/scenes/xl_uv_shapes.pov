// Cross-check: object uv_mapping on sphere, box (cube net), torus, ovus (POV-Ray 3.7 UVCoord)
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 3, -7> look_at <0, 0.6, 0> angle 50 }
light_source { <5, 10, -5> color rgb 1 }
light_source { <-6, 4, -8> color rgb 0.4 }
plane { y, -0.01 pigment { rgb 0.6 } }
#declare Chk = pigment { checker rgb <1,0.2,0.1>, rgb <0.9,0.9,0.6> scale <0.125, 0.1, 1> }
box { <-0.8,0,-0.8>, <0.8,1.6,0.8> uv_mapping pigment { Chk } rotate y*35 translate <-2.2,0,0> }
torus { 0.8, 0.3 uv_mapping pigment { Chk } rotate x*-50 translate <0.2, 0.9, 0> }
sphere { 0, 0.8 uv_mapping pigment { Chk } rotate <20,30,0> translate <2.3, 0.8, 0.5> }
ovus { 0.6, 0.4 uv_mapping pigment { Chk } rotate z*20 translate <0.5, 0.1, -2> }
