// Numbers far outside the int range where the parser wants an int.
#declare S = str(1, 1e300, -1e300);
#declare V = vstr(1e300, <1, 2, 3>, ",", 1e300, 2);
#declare U = substr("abc", 1e300, -1e300);
#declare C = chr(1e300);
global_settings { max_trace_level 1e300 noise_generator -1e300 photons { count 1e300 } }
camera { focal_point 0 blur_samples 1e300 aperture 0.1 }
light_source { 0, 1 area_light x, z, 1e300, -1e300 adaptive 1e300 }
mesh2 { vertex_vectors { 3, 0, x, y } face_indices { 1, <1e300, -1e300, 0> } }
