// expect syntax: 57_mesh_empty.pov:2:1: error: mesh has no triangles
mesh { }
