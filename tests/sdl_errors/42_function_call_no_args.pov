// expect syntax: 42_function_call_no_args.pov:3:16: error: expected object, light_source, camera or other scene statement, found '+'
#declare F = function { x }
#declare V = F + 1;
