// expect syntax: 05_missing_brace.pov:3:1: error: unterminated sphere block opened at 2:8
sphere { <0,0,0>, 1
