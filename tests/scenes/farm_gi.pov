// A small radiosity room for the farm test (tests/test_farm.sh): the
// camera and a sphere move with the clock, so every frame differs.
#version 3.7;
global_settings { radiosity { count 50 } }
camera { location <0.3 * clock, 1, -3.2 + 0.6 * clock> look_at <0, 0.8, 0> angle 60 }
light_source { <0, 1.8, -0.5> rgb 1 }
box { <-1.5, 0, -4>, <1.5, 2, 1.5> hollow pigment { rgb 0.8 } finish { diffuse 0.8 ambient 0 } }
box { <0.4, 0, 0.2>, <1.1, 0.9, 0.9> pigment { rgb <0.2, 0.5, 0.9> } finish { diffuse 0.8 ambient 0 } }
sphere { <-0.6 + 0.8 * clock, 0.4, -0.3>, 0.4 pigment { rgb <0.9, 0.3, 0.2> } finish { diffuse 0.8 ambient 0 } }
