// expect syntax: 51_fopen_mode.pov:2:18: error: expected read, write or append, found undeclared identifier 'readwrite'
#fopen F "x.txt" readwrite
