// the source image of xs_hf.pov's file height fields (rendered by POV-Ray)
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { orthographic location <0.5,0.5,-1> look_at <0.5,0.5,0> right x up y }
plane { z, 0 pigment { function { 0.5 + 0.4 * sin(x * 6) * cos(y * 4) } } finish { ambient 1 diffuse 0 emission 0 } }
