// expect syntax: 79_ln_zero.pov:2:14: error: ln of a non-positive number 0
#declare L = ln(0);
