// Cross-check: glass seen from inside a closed room (the camera inside a
// hollow sphere, so every ray starts inside it: POV-Ray's interior list),
// and glass nested in glass. A fresnel glass box is seen end on (long paths
// with total internal reflection and an exponential fade); a glass ball
// holds a ball of water (ior 1.33 inside ior 1.5) and an overlapping ball.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 25 }
camera { location <14, 4.6, 7> look_at <0, 1.2, 0> angle 36 right x up y }
light_source { <-10, 7, 18> color rgb <1.3, 1.2, 1.1> fade_power 2 fade_distance 45 }
sphere { 0, 30 hollow on
  texture { pigment { checker rgb <0.98, 0.96, 0.9>, rgb <0.6, 0.7, 0.8> scale 2 } finish { diffuse 0.7 } } }
#declare Glass = material {
  texture { pigment { rgbf <0.98, 0.98, 0.98, 0.9> }
    finish { ambient 0 diffuse 0.1 specular 0.6 roughness 0.002 reflection { 0.1, 1.0 fresnel on } conserve_energy } }
  interior { ior 1.5 fade_distance 2 fade_power 1001 fade_color <0.35, 0.65, 0.85> } }
box { <-3, 0, -0.6>, <3, 2.4, 0.6> material { Glass } }
sphere { <1, 1.2, 3>, 1.2 material { Glass } }
sphere { <1, 1.2, 3>, 0.7
  material { texture { pigment { rgbf <0.9, 0.5, 0.4, 0.95> } finish { ambient 0 diffuse 0 reflection { 0, 1 fresnel on } } }
    interior { ior 1.33 } } }
sphere { <2, 1, -3>, 0.8 material { Glass } }
sphere { <2.9, 1, -3>, 0.6 material { Glass } }
