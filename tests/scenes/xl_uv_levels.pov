// Cross-check: uv_mapping in pigment, normal and texture blocks, image_map (xl_image.png, written by test_look), a texture pattern, layered textures on mesh2
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 3, -7> look_at <0, 0.6, 0> angle 50 }
light_source { <5, 10, -5> color rgb 1 }
light_source { <-6, 4, -8> color rgb 0.4 }
plane { y, -0.01 pigment { rgb 0.6 } }
// pigment-level: object transforms do not move it
sphere { 0, 0.8 pigment { uv_mapping checker rgb <1,0.2,0.1>, rgb 0.9 scale <0.125, 0.1, 1> } scale <1,1.2,1> rotate y*40 translate <-2.3, 0.95, 0.3> }
// image_map with uv_mapping on a box (cube net) and a sphere
box { -0.7, 0.7 pigment { uv_mapping image_map { png "xl_image.png" } } rotate <10,-30,0> translate <-0.4,0.75,0.6> }
sphere { 0, 0.7 texture { uv_mapping pigment { image_map { png "xl_image.png" interpolate 2 } } finish { phong 0.4 } } rotate x*-30 translate <1.2,0.7,0.8> }
// normal-level uv_mapping
torus { 0.6, 0.25 pigment { rgb <0.9,0.8,0.5> } normal { uv_mapping gradient x 0.8 scale 0.1 } rotate x*-60 translate <2.6, 0.8, -0.6> }
// texture pattern with uv_mapping
sphere { 0, 0.6 texture { uv_mapping checker texture { pigment { rgb <0.2,0.4,1> } } texture { pigment { rgb 0.95 } finish { phong 0.6 } } scale <0.1, 0.2, 1> } translate <0.5, 0.6, -1.8> }
// object-level uv_mapping with a layered texture on a mesh2 quad (uv per vertex)
mesh2 { vertex_vectors { 4, <0,0,0>, <1,0,0>, <1,1,0>, <0,1,0> }
        uv_vectors { 4, <0,0>, <1,0>, <1,1>, <0,1> }
        face_indices { 2, <0,1,2>, <0,2,3> }
        uv_mapping texture { pigment { rgb <0.3,0.8,0.3> } } texture { pigment { checker rgbt <1,1,1,0.9>, rgb <0.6,0.1,0.5> scale 0.25 } }
        rotate y*-20 translate <-1.9,0.05,-1.6> }
