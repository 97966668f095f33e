// expect syntax: 04_unknown_identifier.pov:3:10: error: undeclared identifier 'B'
#declare A = 1;
sphere { B, 1 }
