// expect syntax: 77_object_expected.pov:2:43: error: expected '}' closing union, found number 42
union { sphere { 0, 1 } pigment { rgb 1 } 42 }
