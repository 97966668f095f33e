// expect syntax: 61_mesh_camera_rays.pov:2:27: error: mesh_camera distribution 2 needs 1 ray per pixel
camera { mesh_camera { 2, 2 mesh { triangle { 0, x, y } } } }
