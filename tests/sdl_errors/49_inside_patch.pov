// expect syntax: 49_inside_patch.pov:3:21: error: inside needs a solid object; a triangle has no inside (a mesh needs inside_vector)
#declare T = triangle { <0,0,0>, <1,0,0>, <0,1,0> }
#declare I = inside(T, <0,0,0>);
