// expect syntax: 63_radiosity_range.pov:2:31: error: radiosity recursion_limit must be from 1 to 20
global_settings { radiosity { recursion_limit 30 } }
