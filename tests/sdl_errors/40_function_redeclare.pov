// expect syntax: 40_function_redeclare.pov:3:10: error: function 'F' cannot be redeclared (#undef it first)
#declare F = function { x }
#declare F = function { y }
