// expect syntax: 66_float_expected.pov:3:18: error: float expected but vector or colour expression found
#declare V = <1,2,3>;
#declare F = sin(V);
