// Particle GI against POV-Ray's radiosity where a gathering ray meets
// glass: a white floor under a clear slab (transmit 0.7, ior 1.5, an
// interior fade) under a uniform sky, no lights, the camera between them.
// POV-Ray traces its radiosity rays in full, so the floor gathers the sky
// through the slab, filtered by each face and faded on the way inside
// (test_crosscheck.c).
#version 3.7;
global_settings { assumed_gamma 1.0 radiosity { count 400 error_bound 0.3 recursion_limit 1 } }
background { rgb 0.8 }
camera { location <0, 0.9, -1> look_at <0, 0, 0.3> angle 50 }
plane { y, 0 pigment { rgb 1 } finish { ambient 0 diffuse 0.7 } }
box { <-100, 1, -100>, <100, 1.2, 100>
  pigment { rgbt <1, 1, 1, 0.7> }
  finish { ambient 0 diffuse 0 }
  interior { ior 1.5 fade_distance 0.5 fade_power 1001 fade_color rgb 0.2 } }
