// expect syntax: 60_mesh_camera_distribution.pov:2:27: error: unknown mesh_camera distribution 7 (0 to 3)
camera { mesh_camera { 1, 7 mesh { triangle { 0, x, y } } } }
