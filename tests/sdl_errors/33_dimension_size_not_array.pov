// expect syntax: 33_dimension_size_not_array.pov:3:29: error: expected array identifier, found 'A'
#declare A = 1;
#declare N = dimension_size(A, 1);
