// expect syntax: 64_area_light_size.pov:2:21: error: area light sizes must be greater than zero
light_source { 0, 1 area_light x, y, 0, 2 }
