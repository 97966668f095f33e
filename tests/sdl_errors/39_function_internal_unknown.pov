// expect syntax: 39_function_internal_unknown.pov:2:34: error: unknown internal function 99 (POV-Ray 3.7 has internal(0) to internal(78), 77 being reserved)
#declare F = function { internal(99) }
