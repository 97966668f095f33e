// expect syntax: 56_mesh2_bad_index.pov:4:21: error: vertex index 3 out of range (0..2)
mesh2 {
  vertex_vectors { 3, <0,0,0>, <1,0,0>, <0,1,0> }
  face_indices { 1, <0,1,3> }
}
