// test_media: an absorbing box (constant absorption and a gradient density,
// method 2) in front of a checker wall, casting a tinted shadow.
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 2, -6> look_at <0, 0.3, 0> angle 50 }
light_source { <-3, 6, -4> color rgb 1.2 }
plane { y, -1.5 pigment { checker rgb 0.9, rgb 0.4 } }
plane { z, 3 pigment { checker rgb <0.9, 0.8, 0.3>, rgb 0.3 } hollow } // the camera is inside it: hollow, or no media reach the camera
box { <-1.2, -1, -0.8>, <1.2, 1, 0.8>
  pigment { rgbf 1 }
  hollow
  interior { media {
    method 2 intervals 4 samples 3
    absorption <0.3, 0.8, 1.4>
    density { gradient y color_map { [0 rgb 1] [1 rgb 0.2] } translate -y }
  } }
  rotate 20*y
}
