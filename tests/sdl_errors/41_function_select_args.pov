// expect syntax: 41_function_select_args.pov:2:25: error: select in a function takes 3 to 4 arguments, 2 given
#declare F = function { select(x, 1) }
