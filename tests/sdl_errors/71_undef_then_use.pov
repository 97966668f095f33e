// expect syntax: 71_undef_then_use.pov:4:14: error: undeclared identifier 'A'
#declare A = 1;
#undef A
#declare B = A + 1;
