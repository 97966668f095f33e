// expect syntax: 58_camera_look_at.pov:2:8: error: camera location and look_at point must be different
camera { location <0,0,0> look_at <0,0,0> }
