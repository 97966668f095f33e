// expect syntax: 27_array_negative_subscript.pov:3:16: error: negative array subscript -1
#declare A = array[3] {1, 2, 3}
#declare B = A[-1];
