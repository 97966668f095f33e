// Cross-check: the object pattern (1 inside, 0 outside) with
// CSG (union, difference, an inverse member), pattern transforms and a
// clipped object.
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 3, -7> look_at <0, 0.8, 0> angle 50 }
light_source { <5, 10, -5> color rgb 1 }
#declare Star = difference { sphere { 0, 1 } cylinder { -2*y, 2*y, 0.5 } box { <-2, -0.2, -2>, <2, 0.2, 2> inverse } }
plane { y, 0 pigment { object { union { sphere { <-1, 0, 0>, 0.8 } box { <0.5, -1, -0.5>, <1.5, 1, 0.5> } } color rgb <0.9, 0.2, 0.1> color rgb <0.2, 0.8, 0.3> } } }
box { <-2.5, 0, 0>, <2.5, 2.5, 0.2> pigment { object { Star rgb 0.9 rgb <0.1, 0.2, 0.9> } scale 1.1 translate <0, 1.2, 0> } }
// a clipped_by solid limits the object's inside (POV-Ray's Inside_Object)
box { <-2.4, 0, -1.6>, <-0.6, 1.2, -1.5> pigment { object { sphere { <-1.5, 0.6, -1.55>, 0.55 clipped_by { plane { x, -1.3 } } } rgb 0.9 rgb <0.9, 0.8, 0.1> } } }
