#macro Fact(N) #if (N <= 1) 1 #else N * Fact(N - 1) #end #end
#declare X = Fact(5);
#local I = 0;
#while (I < 10) #declare I = I + 1; #end
#for (J, 0, 9, 2) #declare K = J; #end
#switch (X) #case (120) #declare Y = 1; #break #range (0, 10) #declare Y = 2; #break #else #declare Y = 3; #end
#ifdef (Y) #undef Y #end
#ifndef (Y) #declare Y = "u"; #end
#version 3.7;
#debug concat("x", str(X, 0, 2), "\n")
#warning "w"
#include "colors.inc"
#default { finish { ambient 0.1 } }
