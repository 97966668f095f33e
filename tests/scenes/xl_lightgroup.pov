// Cross-check: light_group: a group's lights light only its
// objects (shadows cast by every object); global lights light the rest and
// a group's objects only with global_lights on; nested groups keep their own.
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 3, -7> look_at <0, 0.8, 0> angle 50 }
light_source { <5, 10, -5> color rgb 0.7 }
plane { y, 0 pigment { rgb 0.8 } finish { ambient 0.1 } }
light_group {
  light_source { <-3, 3, -3> color rgb <1, 0.3, 0.2> }
  sphere { <-2, 1, 0>, 1 pigment { rgb 1 } finish { ambient 0.05 phong 0.5 } }
}
light_group {
  light_source { <0, 4, -4> color rgb <0.2, 0.4, 1> }
  sphere { <0, 1, 0.5>, 1 pigment { rgb 1 } finish { ambient 0.05 } }
  light_group {
    light_source { <1, 1, -3> color rgb <0.2, 1, 0.2> }
    box { <-0.5, 0, -2>, <0.5, 0.5, -1.5> pigment { rgb 1 } }
  }
  global_lights on
}
sphere { <2, 1, 0>, 1 pigment { rgb <1, 0.9, 0.6> } finish { ambient 0.05 specular 0.4 } }
