// expect syntax: 53_read_not_file.pov:3:8: error: expected file identifier (from #fopen), found 'F'
#declare F = 1;
#read (F, V)
