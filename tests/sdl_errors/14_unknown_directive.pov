// expect syntax: 14_unknown_directive.pov:2:2: error: unknown directive #spline
#spline
