// xc_photon_backlit.pov under radiosity, seen from the room: the floor
// in front of the curtain is lit only by the curtain's room side, which
// shows the photons behind it through diffuse_back. POV-Ray's radiosity
// rays shade the curtain as its camera rays do (a photon from behind
// divided by 0.1, the sun behind through diffuse_back), so partray's
// particles (RL 2) and its final gather's hits (RL 1) must too.
#version 3.7;
#ifndef (RL) #declare RL = 2; #end // radiosity recursion_limit
global_settings { assumed_gamma 1.0 max_trace_level 25 photons { count 240000 }
  radiosity { count 200 error_bound 0.5 recursion_limit RL pretrace_end 0.01 nearest_count 10 } }
camera { location <3, 1.6, 2.2> look_at <0.8, 0.5, 0> angle 60 }
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
// the room: a floor and a wall facing the curtain, lit only by the curtain
box { <0.02, -0.1, -1.4>, <2.5, 0.1, 1.4> pigment { rgb 1 } finish { ambient 0 diffuse 0.8 } }
box { <2.5, 0, -1.4>, <2.6, 2, 1.4> pigment { rgb 1 } finish { ambient 0 diffuse 0.8 } }
