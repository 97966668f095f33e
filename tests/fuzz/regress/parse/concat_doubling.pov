// A string that doubles each round must hit the string length limit.
#declare S = "0123456789abcdef";
#for (I, 0, 40) #declare S = concat(S, S); #end
