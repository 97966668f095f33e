// expect syntax: 07_extra_brace.pov:2:17: error: expected object, light_source, camera or other scene statement, found '}'
sphere { 0, 1 } }
