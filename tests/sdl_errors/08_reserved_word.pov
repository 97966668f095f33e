// expect syntax: 08_reserved_word.pov:2:10: error: 'sphere' is a reserved word and cannot be used as an identifier
#declare sphere = 1;
