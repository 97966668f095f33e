// expect syntax: 70_for_zero_step.pov:2:1: error: #for step must not be 0
#for (I, 0, 10, 0)
#end
