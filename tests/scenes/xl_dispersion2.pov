// Cross-check: rays split by one dispersive object stay
// monochromatic through the next (a slab of 5 bands in front of a sphere
// of 9): the sphere bends each band with its own ior and does not split
// it again, as POV-Ray 3.7's ComputeRefraction does.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 12 }
camera { location <0, 1.2, -6> look_at <0, 1.2, 0> angle 40 }
light_source { <4, 8, -6> color rgb 1 }
plane { z, 4
  pigment { gradient x color_map { [0 rgb 0] [0.4 rgb 0] [0.45 rgb 2] [0.55 rgb 2] [0.6 rgb 0] [1 rgb 0] } scale 0.6 }
  finish { ambient 1 diffuse 0 } }
box { <-2, -0.5, -1.2>, <2, 3, -1.0> rotate y*25
  pigment { rgbf 1 } finish { ambient 0 diffuse 0 }
  interior { ior 1.5 dispersion 1.2 dispersion_samples 5 } }
sphere { <0.3, 1.2, 0.8>, 1
  pigment { rgbf 1 } finish { ambient 0 diffuse 0 }
  interior { ior 1.4 dispersion 1.3 dispersion_samples 9 } }
