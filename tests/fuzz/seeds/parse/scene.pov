#version 3.7;
global_settings { assumed_gamma 1.0 radiosity { count 35 error_bound 1.8 } }
camera { perspective location <0, 2, -5> look_at <0, 1, 0> angle 50 right x*image_width/image_height }
light_source { <2, 4, -3> color rgb 1 area_light x, z, 4, 4 jitter adaptive 1 fade_distance 3 fade_power 2 }
light_source { <0, 5, 0> rgb <1, 0.9, 0.8> spotlight point_at 0 radius 10 falloff 20 tightness 5 }
background { rgb 0.1 }
plane { y, 0 pigment { checker rgb 1 rgb 0 } finish { diffuse 0.8 reflection { 0.1, 0.5 fresnel } } }
sphere { <0, 1, 0>, 1 texture { pigment { rgbf <1, 1, 1, 0.9> } finish { phong 0.5 specular 0.3 roughness 0.01 } } interior { ior 1.5 } }
box { -1, 1 scale 0.5 rotate y*30 translate <2, 0.5, 0> pigment { rgb <0.2, 0.4, 0.8> } }
difference { cylinder { 0, y, 0.5 } cone { 0, 0.4, y, 0.1 } translate <-2, 0, 0> }
union { sphere { 0, 0.2 } torus { 0.5, 0.1 } no_shadow translate <0, 2, 2> }
triangle { <0,0,0>, <1,0,0>, <0,1,0> pigment { rgb x } }
