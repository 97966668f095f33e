// Cross-check: uv_mapping on lathe, sor, mesh/mesh2 uv_vectors + uv_indices, bicubic_patch uv_vectors; cylinder and disc use world x, y
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 3, -7> look_at <0, 0.6, 0> angle 55 }
light_source { <5, 10, -5> color rgb 1 }
light_source { <-6, 4, -8> color rgb 0.4 }
plane { y, -0.01 pigment { rgb 0.6 } }
#declare Chk = pigment { checker rgb <1,0.2,0.1>, rgb <0.9,0.9,0.6> scale <0.125, 0.1, 1> }
lathe { linear_spline 4, <0.2,0>, <0.8,0.5>, <0.5,1.2>, <0.7,1.6> uv_mapping pigment { Chk } rotate y*20 translate <-2.6,0,0.5> }
sor { 5, <0,0>, <0.6,0>, <0.4,0.8>, <0.7,1.4>, <0.5,1.8> uv_mapping pigment { Chk } translate <-1.0,0,1> }
mesh { triangle { <0,0,0>, <1.2,0,0>, <1.2,1.2,0> uv_vectors <0,0>, <1,0>, <1,1> }
       triangle { <0,0,0>, <1.2,1.2,0>, <0,1.2,0> uv_vectors <0,0>, <1,1>, <0,1> }
       uv_mapping pigment { Chk } rotate y*-20 translate <0.2,0.1,0> }
mesh2 { vertex_vectors { 4, <0,0,0>, <1,0,0>, <1,1,0>, <0,1,0> }
        uv_vectors { 3, <0,0>, <2,0.5>, <0.5,2> }
        face_indices { 2, <0,1,2>, <0,2,3> }
        uv_indices { 2, <0,1,2>, <0,2,1> }
        uv_mapping pigment { Chk } rotate y*25 translate <1.8,0.1,0.4> }
bicubic_patch { type 1 u_steps 4 v_steps 4 uv_vectors <0,0>, <2,0>, <2,1>, <0,1>
  <0,0,0>, <0.4,0.3,0>, <0.8,0.3,0>, <1.2,0,0>,
  <0,0.4,-0.3>, <0.4,0.6,-0.3>, <0.8,0.6,-0.3>, <1.2,0.4,-0.3>,
  <0,0.8,-0.6>, <0.4,1,-0.6>, <0.8,1,-0.6>, <1.2,0.8,-0.6>,
  <0,1.2,-0.9>, <0.4,1.4,-0.9>, <0.8,1.4,-0.9>, <1.2,1.2,-0.9>
  uv_mapping pigment { Chk } translate <-0.6,0.1,-2.2> }
cylinder { <0,0,0>, <0,1,0>, 0.35 uv_mapping pigment { checker rgb <0.2,0.3,1>, rgb 0.9 scale 0.2 } translate <1.2,0,-2.4> }
disc { <0,0,0>, <0,0,-1>, 0.4 uv_mapping pigment { checker rgb <0.2,0.8,0.3>, rgb 0.9 scale 0.15 } translate <2.3,0.6,-2.4> }
