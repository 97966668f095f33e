// expect syntax: 35_function_bad_call_args.pov:3:14: error: function 'F' takes 2 arguments, 1 given
#declare F = function(a, b) { a + b }
#declare V = F(1);
