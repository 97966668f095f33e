// Each call makes two: 2^24 calls within the depth limit, stopped by the token budget.
#macro R(N) #if (N > 0) R(N - 1) R(N - 1) #end #end
R(24)
