// Particle GI against POV-Ray's radiosity where a gathering ray meets a
// mirror: a white floor beside a black vertical wall with a fresnel
// reflection (ior 1.5), under a uniform sky, no lights. POV-Ray traces
// its radiosity rays in full, so the floor gathers the sky the wall
// reflects as well as the sky it sees (test_crosscheck.c).
#version 3.7;
global_settings { assumed_gamma 1.0 radiosity { count 400 error_bound 0.3 recursion_limit 1 } }
background { rgb 0.8 }
camera { location <0, 2, -1> look_at <0.3, 0, 0.5> angle 50 }
plane { y, 0 pigment { rgb 1 } finish { ambient 0 diffuse 0.7 } }
plane { -x, -1
  pigment { rgb 0 }
  finish { ambient 0 diffuse 0 reflection { 0, 1 fresnel on } }
  interior { ior 1.5 } }
