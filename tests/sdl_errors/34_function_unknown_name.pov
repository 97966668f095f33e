// expect syntax: 34_function_unknown_name.pov:2:29: error: 'q' is neither a parameter of the function nor a declared float
#declare F = function { x + q }
