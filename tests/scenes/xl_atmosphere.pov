// Cross-check: sky_sphere (layered pigments), ground and
// constant fog with turbulence, a light dimmed by fog (media_attenuation).
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 1.5, -5> look_at <0, 1.2, 0> angle 70 }
light_source { <5, 10, -5> color rgb 1 media_attenuation on }
sky_sphere {
  pigment { gradient y color_map { [0 rgb <0.8, 0.9, 1>] [1 rgb <0.1, 0.2, 0.7>] } }
  pigment { bozo turbulence 0.4 scale <0.3, 0.1, 0.3> color_map { [0.5 rgbt 1] [0.7 rgb 1] } } }
fog { fog_type 2 distance 4 fog_offset 0.4 fog_alt 0.6 color rgbf <0.9, 0.9, 0.9, 0.2> turbulence 0.5 }
fog { distance 40 color rgbt <1, 0.8, 0.6, 0.3> }
plane { y, 0 pigment { checker rgb 1, rgb <0.2, 0.3, 0.8> } finish { ambient 0.3 } }
sphere { <-1.2, 1, 0>, 1 pigment { rgb <1, 0.3, 0.2> } finish { ambient 0.2 phong 0.5 } }
sphere { <1.5, 1, 6>, 1 pigment { rgb <0.2, 1, 0.2> } }
