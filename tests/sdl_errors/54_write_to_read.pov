// expect syntax: 54_write_to_read.pov:3:9: error: cannot write file "54_write_to_read.pov": it is open for reading
#fopen F "54_write_to_read.pov" read
#write (F, "x")
