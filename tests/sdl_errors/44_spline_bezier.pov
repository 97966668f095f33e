// expect syntax: 44_spline_bezier.pov:2:23: error: bezier_spline is not a spline{} type in POV-Ray 3.7 (linear_spline, quadratic_spline, cubic_spline or natural_spline)
#declare S = spline { bezier_spline 0, <0,0>, 1, <1,1> }
