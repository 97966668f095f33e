// Framed blocks under a sky, lit by radiosity alone (recursion_limit 1):
// each face is a recess 0.05 deep inside a rim, with a raised plate in it,
// as distribution scene advanced/blocks/stackerday.pov's lettered blocks.
// The antialiasing rays on the rims, plates and recesses must gather the
// sky that reaches them, not take a nearby pixel's.
#version 3.7;
global_settings {
    assumed_gamma 1.0
    radiosity { pretrace_start 1 pretrace_end 1 count 400 recursion_limit 1 nearest_count 1 error_bound 0.05 }
}
#default { finish { ambient 0 diffuse 1 } }
camera { location <0, 4.5, -7.5> look_at <0, 0.5, 1.8> angle 34 }
sky_sphere { pigment { gradient y color_map { [0 rgb 1.4] [1 rgb <0.45, 0.55, 0.8>] } } }
plane { y, 0 pigment { rgb 0.9 } }
#macro Block(C)
union {
    difference {
        box { -0.5, 0.5 }
        box { <-0.42, -0.42, -1>, <0.42, 0.42, 1> }
        box { <-1, -0.42, -0.42>, <1, 0.42, 0.42> }
        box { <-0.42, -1, -0.42>, <0.42, 1, 0.42> }
        pigment { rgb C }
    }
    box { -0.45, 0.45 pigment { rgb 1 } }
    box { <-0.22, -0.3, -0.5>, <0.22, 0.3, 0.5> pigment { rgb C } }
    box { <-0.5, -0.22, -0.3>, <0.5, 0.22, 0.3> pigment { rgb C } }
    box { <-0.3, -0.5, -0.22>, <0.3, 0.5, 0.22> pigment { rgb C } }
}
#end
#declare R = seed(7);
#for (I, 0, 4)
  #for (J, 0, 3)
    object { Block(<0.3 + 0.6 * rand(R), 0.3 + 0.6 * rand(R), 0.3 + 0.6 * rand(R)>) rotate y * 90 * rand(R)
             translate <(I - 2) * 1.3, 0.5, J * 1.3> }
  #end
#end
