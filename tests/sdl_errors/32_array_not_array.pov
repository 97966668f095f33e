// expect syntax: 32_array_not_array.pov:3:11: error: 'A' is not an array and cannot take a subscript
#declare A = 1;
#declare A[0] = 2;
