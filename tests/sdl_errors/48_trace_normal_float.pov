// expect syntax: 48_trace_normal_float.pov:4:42: error: trace's fourth argument must be a declared vector identifier (it receives the normal)
#declare S = sphere { 0, 1 }
#declare N = 0;
#declare P = trace(S, <0,0,5>, <0,0,-1>, N);
