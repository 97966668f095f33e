// Cross-check: interior dispersion as POV-Ray 3.7 renders it.
// A glass prism (default 7 dispersion_samples) and a sphere
// (dispersion_samples 12) in front of white bars on black: the bars
// seen through them split into colour fringes.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 10 }
camera { location <0, 1.2, -6> look_at <0, 1.2, 0> angle 50 }
light_source { <4, 8, -6> color rgb 1 }
plane { z, 3
  pigment { gradient x color_map { [0 rgb 0] [0.35 rgb 0] [0.45 rgb 2] [0.55 rgb 2] [0.65 rgb 0] [1 rgb 0] } scale 0.8 }
  finish { ambient 1 diffuse 0 } }
plane { y, -0.5 pigment { checker rgb 0.1, rgb 0.6 } finish { ambient 0.3 } }
// triangular prism, apex up, axis along z
prism { linear_sweep linear_spline -0.6, 0.6, 4, <-1, 0>, <1, 0>, <0, 1.6>, <-1, 0>
  rotate -90*x translate <-1.3, 0.4, 0>
  pigment { rgbf 1 } finish { ambient 0 diffuse 0 }
  interior { ior 1.5 dispersion 1.3 } }
sphere { <1.4, 1.2, 0>, 1
  pigment { rgbf 1 } finish { ambient 0 diffuse 0 }
  interior { ior 1.45 dispersion 1.25 dispersion_samples 12 } }
