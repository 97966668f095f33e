// expect syntax: 10_end_without_if.pov:3:1: error: #end without matching #if, #while, #for, #switch or #macro
sphere { 0, 1 }
#end
