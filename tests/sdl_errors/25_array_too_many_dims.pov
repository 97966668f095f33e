// expect syntax: 25_array_too_many_dims.pov:2:34: error: arrays have at most 5 dimensions
#declare A = array[1][1][1][1][1][1];
