// expect limit: ./75_include_depth.pov:3:1: error: includes nested more than 64 deep
// chain:   included from ./75_include_depth.pov:3:1
#include "75_include_depth.pov"
