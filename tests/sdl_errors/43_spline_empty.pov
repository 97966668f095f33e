// expect syntax: 43_spline_empty.pov:2:14: error: spline must have at least one entry
#declare S = spline { linear_spline }
