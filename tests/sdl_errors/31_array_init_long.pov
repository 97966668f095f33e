// expect syntax: 31_array_init_long.pov:2:30: error: too many values in array initialiser: dimension 1 of the array has 2
#declare A = array[2] {1, 2, 3}
