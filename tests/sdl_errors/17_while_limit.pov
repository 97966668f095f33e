// expect limit: 17_while_limit.pov:3:1: error: #while loop exceeded 1000 iterations
#declare I = 0;
#while (1)
  #declare I = I + 1;
#end
