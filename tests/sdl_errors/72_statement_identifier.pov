// expect syntax: 72_statement_identifier.pov:3:1: error: identifier 'S' cannot start a statement (use object { S })
#declare S = sphere { 0, 1 }
S
