// expect syntax: 38_function_vector_member.pov:3:36: error: vector function 'T' needs a member here (.x, .y, .red ...)
#declare T = function { transform { scale 2 } }
#declare F = function { T(x, y, z) + 1 }
