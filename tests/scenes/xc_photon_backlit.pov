// A curtain lit from behind through glass, seen from the room (as in the
// distribution's advanced/diffuse_back.pov): photons that land on the far
// side of a surface light it through diffuse_back, each weighted as
// POV-Ray's gather weighs a photon from behind (divided by 0.1, not by its
// cosine). Left: a glass slab (its photons spread evenly); right: a glass
// rod (its caustic line). The count is high enough that the two
// renderers' density estimates differ less than POV-Ray's own image at a
// quarter of the count does.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 25 photons { count 240000 } }
camera { location <3, 1.0, 0> look_at <0, 1.0, 0> angle 60 }
light_source { vnormalize(<-500, 200, -250>) * 100000 color rgb 0.25
  photons { refraction on reflection on } }
polygon { 5, <0, 0.1, -1.4>, <0, 0.1, 1.4>, <0, 2, 1.4>, <0, 2, -1.4>, <0, 0.1, -1.4>
  pigment { rgb <1.0, 0.8, 0.6> } finish { ambient 0 diffuse 0.7, 0.2 } }
#declare M_Glass = material {
  texture { pigment { rgbt 1 }
    finish { ambient 0 diffuse 0 specular 0.6 roughness 0.005 reflection { 0.1, 1.0 fresnel on } conserve_energy } }
  interior { ior 1.5 fade_power 1001 fade_distance 9 fade_color <0.5, 0.8, 0.6> } }
box { <-0.6, 0.2, -0.2>, <-0.4, 1.8, 0.6> material { M_Glass } photons { target refraction on reflection on } }
cylinder { <-0.25, 0.2, 1.0>, <-0.25, 1.8, 1.0>, 0.15 material { M_Glass } photons { target refraction on reflection on } }
