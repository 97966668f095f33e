// Cross-check: patterns with colour/pigment maps, listed pigments,
// turbulence and warps, layered textures, texture_map, normals (bump
// patterns, slope-sampled patterns, normal_map, slope_map), no_bump_scale.
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 3, -7> look_at <0, 0.8, 0> angle 50 }
light_source { <5, 10, -5> color rgb 1 }
light_source { <-6, 4, -3> color rgb 0.3 }
plane { y, 0
  pigment { hexagon rgb 1, rgb 0.6, rgb <0.6, 0.1, 0.1> scale 0.5 }
  normal { dents 0.6 scale 0.3 }
  finish { ambient 0.2 diffuse 0.7 } }
sphere { <-2, 1, 0>, 1
  pigment { granite color_map { [0 rgb <0.1, 0.1, 0.4>] [0.5 rgb <0.9, 0.9, 0.3>] [1 rgb <0.5, 0.1, 0.1>] } scale 0.8 }
  normal { bumps 0.6 scale 0.2 }
  finish { ambient 0.15 phong 0.7 } }
sphere { <0, 1, 0.5>, 1
  texture { pigment { marble turbulence 0.7 color_map { [0 rgb 0.9] [0.6 rgb <0.2, 0.4, 0.2>] [1 rgb 0.9] } scale 0.6 }
            finish { phong 0.5 } }
  texture { pigment { bozo color_map { [0.5 rgbt 1] [0.7 rgbf <0.8, 0.3, 0.1, 0.5>] } scale 0.3 } } }
sphere { <2, 1, 0>, 1
  texture { checker texture { pigment { rgb <0.9, 0.2, 0.1> } finish { phong 0.6 } }
                    texture { pigment { wood turbulence 0.1 scale 0.1 } normal { wrinkles 0.7 scale 0.2 } }
            scale 0.5 } }
box { <-3.5, 0, 2>, <-2, 1.8, 2.5>
  pigment { gradient x pigment_map { [0 checker rgb 0, rgb 1 scale 0.2] [1 leopard scale 0.1] } warp { turbulence 0.3 } scale 1.5 }
  normal { crackle 1.5 scale 0.3 slope_map { [0 <0, 1>] [0.5 <1, 0>] [1 <0, -1>] } } }
box { <2, 0, 2>, <3.5, 1.8, 2.5>
  pigment { rgb <0.3, 0.6, 0.9> }
  normal { gradient y normal_map { [0 waves 0.8 frequency 3] [1 ripples 0.6 frequency 4] } scale 0.9 }
  finish { phong 0.8 } }
cylinder { <-0.5, 0, -2>, <0.5, 0, -2>, 0.4
  pigment { spiral1 4 color_map { [0 rgb <1, 1, 0>] [1 rgb <0, 0.5, 1>] } scale 0.3 }
  normal { quilted 0.8 control0 0.3 control1 0.9 scale 0.2 no_bump_scale } }
// tiles: the first tile on the cells whose checker value is 1
box { <0.9, 0, -3.3>, <2.3, 0.3, -2.1>
  texture { tiles { texture { pigment { rgb <0.9, 0.8, 0.2> } finish { phong 0.4 } }
                    tile2 texture { pigment { rgb <0.1, 0.2, 0.6> } } }
            scale 0.3 } }
