// expect syntax: 30_array_init_short.pov:2:28: error: array initialiser has 2 values, dimension 1 of the array has 3
#declare A = array[3] {1, 2}
