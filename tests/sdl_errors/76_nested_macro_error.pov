// expect syntax: 76_nested_macro_error.pov:5:5: error: #error: negative
// chain:   in macro Check called from 76_nested_macro_error.pov:9:1
#macro Check(V)
  #if (V < 0)
    #error "negative"
  #end
#end
Check(1)
Check(-1)
