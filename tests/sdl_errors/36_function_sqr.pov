// expect syntax: 36_function_sqr.pov:2:25: error: 'sqr' cannot be used in a function
#declare F = function { sqr(x) }
