// expect syntax: 59_camera_angle.pov:2:8: error: viewing angle has to be smaller than 180 degrees
camera { angle 200 }
