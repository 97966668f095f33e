// expect syntax: 67_sqrt_negative.pov:2:14: error: sqrt of a negative number -4
#declare F = sqrt(-4);
