// expect syntax: 45_spline_bad_kind.pov:3:21: error: expected linear_spline, quadratic_spline, cubic_spline or natural_spline, found 'sphere_sweep'
#declare S = spline { 0, <0,0>, 1, <1,1> }
#declare V = S(0.5, sphere_sweep);
