// expect syntax: 15_error_directive.pov:3:1: error: #error: X is 3
#declare X = 3;
#error concat("X is ", str(X, 0, 0))
