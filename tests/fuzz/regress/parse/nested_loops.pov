// Nested loops multiply: the token budget (max_tokens) must stop them.
#declare I = 0;
#while (I < 1000)
  #declare J = 0;
  #while (J < 1000)
    #declare K = 0;
    #while (K < 1000) #declare K = K + 1; #end
    #declare J = J + 1;
  #end
  #declare I = I + 1;
#end
