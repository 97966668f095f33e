// Cross-check: parallel light, reflection (plain and with falloff), union and object reuse, transforms.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 }
background { color rgb <0.2, 0.3, 0.5> }
camera { location <0, 2.5, -6> look_at <0, 0.7, 0> angle 55 right x up y }
light_source { <-3, 8, -4> color rgb 1 parallel point_at <0, 0, 0> }
#declare Ball = sphere { 0, 0.6 pigment { rgb <0.95, 0.95, 0.95> } finish { ambient 0 diffuse 0.2 reflection 0.7 } }
plane { y, 0 pigment { rgb <0.5, 0.5, 0.45> } finish { ambient 0.1 diffuse 0.6 reflection { 0.05, 0.6 falloff 3 } } }
object { Ball translate <-1.3, 0.6, 0> }
object { Ball scale 1.5 translate <1.2, 0.9, 1> }
union {
  box { <-0.5, 0, -0.5>, <0.5, 1, 0.5> }
  sphere { <0, 1.2, 0>, 0.35 }
  pigment { rgb <0.9, 0.3, 0.2> }
  finish { ambient 0.1 diffuse 0.8 }
  rotate y*20 translate <0, 0, -1.2>
}
// invisible to the camera but seen in reflections and casting a shadow
sphere { <-0.2, 0.4, 1.8>, 0.4 no_image pigment { rgb <0.2, 0.9, 0.3> } finish { diffuse 0.8 } }
// seen by the camera but not in reflections
box { <1.6, 0, -1.8>, <2.2, 0.6, -1.2> no_reflection pigment { rgb <0.9, 0.9, 0.2> } finish { diffuse 0.8 } }
