// expect syntax: 21_macro_undeclared_ref.pov:3:5: error: undeclared identifier 'Nothing' cannot be passed to macro Set (declare it first)
#macro Set(A) #declare A = 1; #end
Set(Nothing)
