// expect syntax: 18_macro_no_end.pov:4:1: error: unterminated #macro opened at 2:1 (missing #end)
#macro M()
  sphere { 0, 1 }
