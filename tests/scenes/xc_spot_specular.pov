// Cross-check: spotlights (radius, falloff, tightness), specular/roughness, metallic highlights.
#version 3.7;
global_settings { assumed_gamma 1.0 ambient_light rgb 0.5 }
camera { location <0, 3, -7> look_at <0, 0.5, 0> angle 45 right x up y }
light_source { <0, 6, -1> color rgb <1, 1, 0.9> * 1.5
  spotlight point_at <0, 0, 0> radius 15 falloff 30 tightness 5 }
light_source { <-5, 4, -3> color rgb <0.3, 0.4, 1.0>
  spotlight point_at <1.5, 0.7, 0.5> radius 8 falloff 12 tightness 0 }
plane { y, 0 pigment { rgb 0.7 } finish { ambient 0.1 diffuse 0.7 } }
sphere { <0, 1, 0>, 1 pigment { rgb <0.9, 0.6, 0.2> } finish { ambient 0.05 diffuse 0.5 specular 0.8 roughness 0.02 metallic 0.7 } }
sphere { <1.5, 0.7, 0.5>, 0.7 pigment { rgb <0.3, 0.8, 0.3> } finish { diffuse 0.6 specular 0.5 roughness 0.1 } }
triangle { <-3, 0, 2>, <-1, 0, 3>, <-2, 2.5, 2.5> pigment { rgb <0.8, 0.3, 0.7> } finish { diffuse 0.8 } }
