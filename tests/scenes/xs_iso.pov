// Shape cross-check: isosurfaces displaced by noise, lit at a grazing angle,
// against POV-Ray 3.7 (the normal's forward difference over accuracy,
// isosurf.cpp). A coarse accuracy makes the rule show.
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 0.6, -5> look_at <0, 0, 0> angle 42 }
light_source { <-30, 6, 4> rgb 1 }
light_source { <2, 3, -6> rgb 0.15 shadowless }
#declare F = function { pigment { bozo poly_wave 2 color_map { [0 rgb 0] [1 rgb 1] }
                        warp { turbulence 0.4 lambda 2.3 omega 0.52 } scale 0.2 } }
isosurface {
  function { sqrt(x*x + z*z) - 0.7 - F(x, y, z).gray * 0.12 }
  max_gradient 2.5 accuracy 0.01
  contained_by { box { <-1, -0.8, -1>, <1, 0.8, 1> } }
  pigment { rgb <1, 0.5, 0.25> } finish { diffuse 0.7 specular 0.2 }
  translate -0.75*x
}
isosurface {
  function { sqrt(x*x + y*y + z*z) - 0.6 - F(x, y, z).gray * 0.1 }
  max_gradient 2 accuracy 0.003
  contained_by { sphere { 0, 0.8 } }
  pigment { rgb <0.5, 0.8, 1> }
  translate <0.85, 0, 0>
}
plane { y, -0.8 pigment { rgb 0.6 } }
