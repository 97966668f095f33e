// expect syntax: 83_macro_elem_uninit.pov:5:5: error: array element of 'U' used before it was initialised
#macro Set(A) #declare A = 1; #end
// POV-Ray 3.7: "Attempt to access uninitialized array element."
#declare U = array[3]
Set(U[1])
