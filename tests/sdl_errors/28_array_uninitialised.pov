// expect syntax: 28_array_uninitialised.pov:3:14: error: array element of 'A' used before it was initialised
#declare A = array[3];
#declare B = A[1] + 1;
