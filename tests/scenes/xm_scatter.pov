// test_media: a slab of scattering media (Henyey-Greenstein) lit by a
// spotlight, a sphere in the beam casting a shadow shaft through it, and
// atmospheric absorption with media_attenuation on the light.
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 1.5, -7> look_at <0, 0.5, 0> angle 50 }
light_source { <0, 20, -10> color rgb 0.3 media_interaction off shadowless }
light_source { <0.5, 4.5, 0> color rgb 3 spotlight point_at <0, 0, 0> radius 14 falloff 20
  media_attenuation on }
media { absorption 0.02 }
plane { y, -1.5 pigment { rgb 0.7 } }
sphere { <0.3, 2.2, 0>, 0.4 pigment { rgb <1, 0.3, 0.2> } }
box { <-2.5, -1, -1.5>, <2.5, 1.5, 1.5>
  pigment { rgbf 1 }
  hollow
  interior { media {
    scattering { 5, rgb 0.25 eccentricity 0.4 }
    absorption 0.05
    samples 12
  } }
}
