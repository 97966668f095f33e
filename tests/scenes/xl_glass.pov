// Cross-check: interior ior (refraction, total internal
// reflection), fade_distance/fade_power/fade_colour, faked caustics,
// filtered shadows, fresnel reflection, conserve_energy.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 8 }
camera { location <0, 2, -5> look_at <0, 0.8, 0> angle 55 }
light_source { <4, 8, -4> color rgb 1 }
light_source { <-6, 5, -2> color rgb 0.4 }
background { rgb <0.2, 0.3, 0.5> }
plane { y, 0 pigment { checker rgb 1, rgb <0.2, 0.3, 0.8> } finish { ambient 0.3 } }
sphere { <-1.3, 1, 0>, 1
  pigment { rgbf <1, 0.9, 0.9, 0.95> }
  finish { ambient 0 diffuse 0 phong 0.8 reflection { 0.05, 1 fresnel on } conserve_energy }
  interior { ior 1.5 caustics 0.5 } }
sphere { <1.2, 0.8, 0.5>, 0.8
  pigment { rgbt <0.3, 1, 0.3, 0.8> }
  finish { ambient 0.1 }
  interior { ior 1.33 fade_distance 0.5 fade_power 2 fade_color rgb <0, 0.5, 0.2> } }
box { <-0.4, 0.01, -1.8>, <0.4, 0.8, -1.0> rotate y*20
  pigment { rgbf <0.4, 0.4, 1, 0.9> }
  interior { ior 2.4 fade_distance 1 fade_power 1001 } }
