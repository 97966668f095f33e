// expect syntax: 80_chr_range.pov:2:14: error: value 70000 cannot be used in chr(...)
#declare C = chr(70000);
