// expect syntax: 13_case_outside_switch.pov:2:1: error: #case outside #switch
#case (1)
