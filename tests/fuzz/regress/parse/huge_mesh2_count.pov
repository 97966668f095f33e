// A declared count far beyond memory must fail before any entry is read.
mesh2 { vertex_vectors { 1e15, <0,0,0> } face_indices { 1, <0,0,0> } }
