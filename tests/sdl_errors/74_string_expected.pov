// expect syntax: 74_string_expected.pov:2:26: error: expected string, found number 1
#declare S = concat("a", 1);
