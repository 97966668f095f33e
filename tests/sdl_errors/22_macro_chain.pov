// expect syntax: 22_macro_chain.pov:4:27: error: expected numeric expression, found '}'
// chain:   in macro Inner called from 22_macro_chain.pov:5:16
// chain:   in macro Outer called from 22_macro_chain.pov:6:1
#macro Inner() sphere { 0 } #end
#macro Outer() Inner() #end
Outer()
