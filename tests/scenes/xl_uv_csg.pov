// Cross-check: uv_mapping on a transformed union: members inherit it (also the sphere with its own texture, whose texture the union's transforms still move, as POV-Ray 3.7's Post_Process does)
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 3, -7> look_at <0, 0.6, 0> angle 50 }
light_source { <5, 10, -5> color rgb 1 }
plane { y, -0.01 pigment { rgb 0.6 } }
union {
  sphere { <-1.2,0.8,0>, 0.8 pigment { checker rgb <0.2,0.3,1>, rgb 0.9 scale 0.3 } }
  box { <0.4,0,-0.7>, <1.8,1.4,0.7> }
  uv_mapping pigment { checker rgb <1,0.2,0.1>, rgb 0.9 scale <0.125, 0.1, 1> }
  rotate y*20 scale 1.1
}
