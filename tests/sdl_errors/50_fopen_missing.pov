// expect syntax: 50_fopen_missing.pov:2:10: error: cannot open user file "no_such_data_file.txt" for reading
#fopen F "no_such_data_file.txt" read
