// expect syntax: 11_else_without_if.pov:2:1: error: #else without matching #if
#else
