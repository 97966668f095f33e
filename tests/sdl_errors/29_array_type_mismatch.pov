// expect syntax: 29_array_type_mismatch.pov:4:17: error: array element type mismatch: the array holds floats, the value is a vector
#declare A = array[2];
#declare A[0] = 1;
#declare A[1] = <1, 2, 3>;
