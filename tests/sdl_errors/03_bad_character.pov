// expect syntax: 03_bad_character.pov:2:17: error: unexpected character '@'
sphere { 0, 1 } @
