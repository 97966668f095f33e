// expect syntax: 46_trace_not_object.pov:3:20: error: expected object identifier in trace, found 'A'
#declare A = 1;
#declare P = trace(A, <0,0,0>, <1,0,0>);
