// expect syntax: 09_if_without_end.pov:4:1: error: unterminated #if opened at 2:1 (missing #end)
#if (1)
  sphere { 0, 1 }
