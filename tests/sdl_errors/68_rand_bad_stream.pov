// expect syntax: 68_rand_bad_stream.pov:2:14: error: illegal random number generator
#declare R = rand(7);
