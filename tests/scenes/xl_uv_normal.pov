// Cross-check: a uv-mapped texture's normal on rotated objects: the object's rotation turns the bumps with it (POV-Ray 3.7 warps the layer normal by the uv texture's outer transforms), the uv point stays
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 4, -6> look_at <0, 0, 0> angle 50 }
light_source { <6, 8, -3> color rgb 1 }
#declare Bumpy = texture { uv_mapping pigment { rgb <0.9, 0.8, 0.6> } normal { quilted 0.8 scale 0.25 } finish { ambient 0 diffuse 0.9 } }
mesh2 { vertex_vectors { 4, <-1,0,-1>, <1,0,-1>, <1,0,1>, <-1,0,1> }
        uv_vectors { 4, <0,0>, <1,0>, <1,1>, <0,1> }
        face_indices { 2, <0,1,2>, <0,2,3> }
        texture { Bumpy } rotate y*-50 translate <-1.2,0,0> }
mesh2 { vertex_vectors { 4, <-1,0,-1>, <1,0,-1>, <1,0,1>, <-1,0,1> }
        uv_vectors { 4, <0,0>, <1,0>, <1,1>, <0,1> }
        face_indices { 2, <0,1,2>, <0,2,3> }
        texture { Bumpy } rotate y*30 rotate x*-20 translate <1.2,0,0.3> }
