// expect syntax: 37_function_not.pov:2:25: error: '!' is not allowed in a function (POV-Ray 3.7 has no logical not there)
#declare F = function { !x }
