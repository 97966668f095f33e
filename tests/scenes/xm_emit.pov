// test_media: an emitting sphere (interior media: emission with a spherical
// density and colour_map, method 3 defaults) over a checker plane.
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 1, -6> look_at <0, 0.5, 0> angle 45 }
light_source { <4, 8, -6> color rgb 1 }
plane { y, -1 pigment { checker rgb 0.2, rgb 0.6 } }
sphere { 0, 1
  pigment { rgbf 1 }
  hollow
  interior { media {
    emission <1.2, 0.6, 0.2>
    density { spherical color_map { [0 rgb 0] [0.5 rgb 0.6] [1 rgb 1] } }
  } }
  scale <1.5, 1, 1> translate <0, 0.6, 0>
}
