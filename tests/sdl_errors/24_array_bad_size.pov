// expect syntax: 24_array_bad_size.pov:2:20: error: invalid array dimension size 0
#declare A = array[0];
