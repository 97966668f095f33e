// expect syntax: 26_array_subscript_range.pov:3:12: error: array subscript 3 out of range (dimension 1 has size 3)
#declare A = array[3];
#declare A[3] = 1;
