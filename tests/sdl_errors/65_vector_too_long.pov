// expect syntax: 65_vector_too_long.pov:3:21: error: expected '>' closing the vector, found number 6
#declare V = <1,2,3>;
box { V, <1,2,3,4,5,6> }
