// expect syntax: 62_light_bad_item.pov:2:32: error: 'radius' cannot be used with a standard light source
light_source { <0,10,0>, rgb 1 radius 5 }
