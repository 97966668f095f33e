// expect syntax: 84_macro_elem_type.pov:3:28: error: array element type mismatch: the array holds floats, the value is a vector
// chain:   in macro Set called from 84_macro_elem_type.pov:7:1
#macro Set(A) #declare A = <1, 2, 3>; #end
// an element passed to a macro keeps its array's type (3.7 retypes the whole
// array and then reads the other elements wrongly)
#declare Arr = array[2] {1, 2}
Set(Arr[1])
