// expect syntax: 82_substr_range.pov:2:14: error: illegal parameters in substr
#declare S = substr("abc", 2, 3);
