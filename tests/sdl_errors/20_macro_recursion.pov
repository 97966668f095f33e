// expect limit: 20_macro_recursion.pov:3:13: error: macro calls nested more than 256 deep
// chain:   in macro R called from 20_macro_recursion.pov:3:13
#macro R(N) R(N + 1) #end
R(0)
