// Cross-check: area light with jitter and adaptive sampling, fade_distance/fade_power,
// a shadowless light, a no_shadow object and a cylinder light.
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 4, -8> look_at <0, 0.5, 0> angle 45 right x up y }
light_source { <0, 5, 0> color rgb 2
  area_light <3, 0, 0>, <0, 0, 3>, 5, 5 adaptive 1 jitter
  fade_distance 4 fade_power 2 }
light_source { <4, 2, -4> color rgb 0.25 shadowless }
light_source { <-6, 1.2, 0> color rgb <1, 0.5, 0.2>
  cylinder point_at <0, 1.2, 0> radius 0.6 falloff 1.2 tightness 2 }
plane { y, 0 pigment { rgb 0.75 } finish { ambient 0 diffuse 0.8 } }
sphere { <-1, 1, 0>, 1 pigment { rgb <0.3, 0.6, 0.9> } finish { ambient 0.05 diffuse 0.7 } }
box { <0.8, 0, -0.8>, <2.2, 1.6, 0.6> pigment { rgb <0.9, 0.9, 0.3> } finish { diffuse 0.7 ambient 0.05 } }
sphere { <0, 3.5, -1.5>, 0.4 no_shadow pigment { rgb 1 } finish { ambient 0.3 diffuse 0.5 } }
