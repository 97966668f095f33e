// Shape cross-check: a height field from a function against POV-Ray 3.7; with
// HF_FILE declared, the scene around a height field from an image file
// that the including scene adds (test_shapes_xc: TGA, JPEG, PPM written by
// POV-Ray first)
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0.5, 2.6, -1.3> look_at <0.5, 0, 0.5> angle 50 }
light_source { <2, 5, -3> rgb 1 }
#ifndef (HF_FILE)
height_field { function 64, 64 { 0.2 + 0.6 * x * x * (1 - y) } smooth
  pigment { gradient y color_map { [0 rgb <1,0,0>] [1 rgb <0,0,1>] } } }
#end
plane { y, 0 pigment { checker rgb 1 rgb 0.5 scale 0.25 } }
