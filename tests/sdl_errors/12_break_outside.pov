// expect syntax: 12_break_outside.pov:2:1: error: #break outside #switch, #while or #for
#break
