// expect syntax: 23_array_no_size.pov:2:19: error: expected '[' with the array size after 'array', found ';'
#declare A = array;
