// expect syntax: 47_trace_zero_dir.pov:3:32: error: trace direction has zero length
#declare S = sphere { 0, 1 }
#declare P = trace(S, <0,0,5>, <0,0,0>);
