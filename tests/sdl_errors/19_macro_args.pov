// expect syntax: 19_macro_args.pov:3:1: error: macro M expects 2 arguments, 1 given
#macro M(A, B) #end
M(1)
