// Cross-check: finish irid (thin-film tint of each light's
// diffuse + highlights and of the reflected ray), with and without
// turbulence, default and scene irid_wavelength.
#version 3.7;
global_settings { assumed_gamma 1.0 irid_wavelength rgb <0.65, 0.5, 0.4> }
camera { location <0, 2, -6> look_at <0, 0.7, 0> angle 45 }
light_source { <5, 10, -5> color rgb 1 }
light_source { <-6, 4, -3> color rgb 0.4 }
plane { y, 0 pigment { checker rgb 0.8, rgb 0.2 } finish { ambient 0.2 } }
sphere { <-1.6, 0.8, 0>, 0.8 pigment { rgb 0.9 } finish { ambient 0.1 diffuse 0.6 phong 0.6 irid { 0.6 thickness 0.4 } } }
sphere { <0, 0.8, 0.3>, 0.8 pigment { rgb <0.8, 0.8, 0.6> } finish { diffuse 0.4 specular 0.5 irid { 0.4 thickness 1.2 turbulence 0.6 } } }
sphere { <1.6, 0.8, 0>, 0.8 pigment { rgb 0.2 } finish { diffuse 0.3 reflection 0.5 irid { 0.7 thickness 0.7 } } }
