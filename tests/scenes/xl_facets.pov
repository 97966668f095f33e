// Cross-check: the facets normal (normal snapped to random cell
// points; with coords, the point's noise gradient), three metrics, size.
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 3, -7> look_at <0, 0.8, 0> angle 50 }
light_source { <5, 10, -5> color rgb 1 }
light_source { <-6, 4, -3> color rgb 0.4 }
plane { y, 0 pigment { rgb <0.7, 0.7, 0.6> } normal { facets coords 0.6 size 0.4 scale 0.7 } finish { ambient 0.2 phong 0.4 } }
sphere { <-2, 1, 0>, 1 pigment { rgb <0.9, 0.3, 0.2> } normal { facets size 0.15 } finish { ambient 0.15 phong 0.8 phong_size 60 } }
sphere { <0, 1, 0.5>, 1 pigment { rgb <0.3, 0.8, 0.3> } normal { facets size 0.3 metric 1 } finish { ambient 0.15 specular 0.6 } }
sphere { <2, 1, 0>, 1 pigment { rgb <0.3, 0.4, 0.9> } normal { facets size 0.25 metric 3 rotate y*30 } finish { ambient 0.15 phong 0.6 } }
