// expect syntax: 73_colour_expected.pov:2:31: error: expected colour, found '}'
sphere { 0, 1 pigment { color } }
