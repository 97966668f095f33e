// mesh_camera, distribution 0 with 2 rays per pixel: ray k of a pixel
// shoots from mesh k (the same camera mesh turned 10 and 12 degrees), the
// pixel is their mean. Compared with POV-Ray 3.7 (test_cli).
#version 3.7;
global_settings { assumed_gamma 1 }
#declare W = 32;
#declare H = 24;
#declare Cam = mesh {
  #for (j, 0, H - 1)
    #for (i, 0, W - 1)
      #local X = (i + 0.5) / W * 4 - 2;
      #local Y = 1.5 - (j + 0.5) / H * 3;
      // (P3 - P1) x (P2 - P1) points to +z
      triangle { <X - 0.01, Y - 0.01, 0>, <X, Y + 0.01, 0>, <X + 0.01, Y - 0.01, 0> }
    #end
  #end
}
camera {
  mesh_camera { 2 0 mesh { Cam rotate 10 * y translate -5 * z } mesh { Cam rotate 12 * y translate -5 * z } }
  location <0, 0, 0.01>
}
light_source { <-3, 5, -8>, rgb 1 }
sphere { 0, 1.2 pigment { checker rgb <1, 0.2, 0.1> rgb <0.1, 0.3, 1> scale 0.4 } finish { ambient 0.1 diffuse 0.8 } }
plane { z, 2 pigment { rgb 0.7 } finish { ambient 0.2 diffuse 0.6 } }
