// Cross-check: point light, diffuse with brilliance, phong highlights, shadows.
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 2, -6> look_at <0, 0.8, 0> angle 50 right x up y }
light_source { <-4, 6, -5> color rgb <1, 0.95, 0.9> }
light_source { <5, 3, -2> color rgb 0.4 }
plane { y, 0 pigment { rgb <0.6, 0.6, 0.55> } finish { ambient 0.05 diffuse 0.8 } }
sphere { <-1.2, 1, 0>, 1 pigment { rgb <0.8, 0.2, 0.15> } finish { ambient 0.1 diffuse 0.7 phong 0.8 phong_size 60 } }
sphere { <1.3, 0.8, 0.5>, 0.8 pigment { rgb <0.2, 0.5, 0.9> } finish { ambient 0.1 diffuse 0.6 brilliance 3 phong 0.4 phong_size 20 } }
box { <-0.4, 0, -1.6>, <0.4, 0.5, -1.0> rotate y*30 pigment { rgb <0.9, 0.85, 0.3> } finish { diffuse 0.9 ambient 0 } }
