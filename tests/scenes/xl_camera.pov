// Cross-check: a non-perspective camera (declared by the test:
// CAM = 1 fisheye, 2 panoramic, 3 spherical, 4 cylinder 1, 5 ultra_wide_angle).
#version 3.7;
global_settings { assumed_gamma 1.0 }
#ifndef (CAM) #declare CAM = 1; #end
camera {
  #switch (CAM)
    #case (1) fisheye angle 180 #break
    #case (2) panoramic #break
    #case (3) spherical angle 200, 100 #break
    #case (4) cylinder 1 angle 140 #break
    #else ultra_wide_angle angle 150
  #end
  location <0, 1.5, -4> look_at <0, 1, 0> }
light_source { <5, 10, -5> color rgb 1 }
plane { y, 0 pigment { checker rgb 1, rgb <0.2, 0.3, 0.8> } finish { ambient 0.3 } }
sphere { <-1.2, 1, 0>, 1 pigment { rgb <1, 0.3, 0.2> } finish { ambient 0.2 phong 0.5 } }
sphere { <1.2, 1, 1>, 1 pigment { gradient y color_map { [0 rgb <0, 1, 0>] [1 rgb <1, 1, 0>] } } }
box { <-6, 0, 6>, <6, 4, 7> pigment { bozo scale 0.5 } }
box { <-6, 0, -8>, <6, 4, -7> pigment { rgb <0.6, 0.2, 0.6> } }
box { <-8, 0, -8>, <-7, 4, 7> pigment { rgb <0.2, 0.6, 0.6> } }
box { <7, 0, -8>, <8, 4, 7> pigment { rgb <0.6, 0.6, 0.2> } }
