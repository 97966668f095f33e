// expect syntax: 78_declare_no_equals.pov:2:12: error: expected '=', found number 5
#declare A 5;
