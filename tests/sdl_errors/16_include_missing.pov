// expect syntax: 16_include_missing.pov:2:1: error: cannot find include file "no_such_file_here.inc"
#include "no_such_file_here.inc"
