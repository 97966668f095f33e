// Cross-check: assumed_gamma 2.2 (working gamma), a pre-3.7 scene
// with noise_generator 1 by default, image_map from a PNG the test writes
// (xl_image.png, planar/spherical/cylindrical maps, once, interpolate).
#version 3.1;
global_settings { assumed_gamma 2.2 }
camera { location <0, 1.5, -5> look_at <0, 1, 0> angle 60 }
light_source { <5, 10, -5> color rgb 1 }
background { rgb <0.2, 0.3, 0.5> }
plane { y, 0 pigment { image_map { png "xl_image.png" interpolate 2 } rotate x*90 scale 2 } finish { ambient 0.3 } }
sphere { <-1.5, 1, 0>, 1 pigment { bozo scale 0.3 color_map { [0 rgb <1, 0.2, 0.1>] [1 rgb <1, 1, 0.3>] } } }
sphere { <1.5, 1, 0>, 1 pigment { image_map { png "xl_image.png" map_type 1 } } finish { ambient 0.4 } }
cylinder { <0, 0, -1.5>, <0, 1.2, -1.5>, 0.4 pigment { image_map { png "xl_image.png" map_type 2 once } } }
