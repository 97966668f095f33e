// expect syntax: 55_plane_zero_normal.pov:2:1: error: plane normal has zero length
plane { <0,0,0>, 1 }
