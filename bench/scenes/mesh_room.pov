// The distribution's deforming spline mesh (templates/Meshes_by_meshmaker_inc/
// 40_mesh_by_4_splines.txt: a Coons surface of four splines, 51 x 51
// vertices, two of its splines turning with the clock) in a closed room of
// mesh2 walls lit by one point light: bench/motion.sh's scene for
// --gi links (every surface that takes indirect light is a mesh). Render
// with +L pointing at the template folder.
#version 3.7;
global_settings { assumed_gamma 1.0 radiosity { count 100 recursion_limit 4 } }
#declare CLOCK = clock; // the template's own default holds the clock at 0.25 in animations
camera { location <0.5, 1.6, -4.2> look_at <0, 0.1, 0> angle 60 }
light_source { <0.6, 2.3, -0.8> color rgb 1.2 fade_distance 2.5 fade_power 2 }
#declare Wall = texture { pigment { rgb <0.75, 0.74, 0.70> } finish { ambient 0 diffuse 0.8 } }
#declare Warm = texture { pigment { rgb <0.80, 0.35, 0.20> } finish { ambient 0 diffuse 0.8 } }
#declare Cool = texture { pigment { rgb <0.20, 0.40, 0.75> } finish { ambient 0 diffuse 0.8 } }
#macro Quad(A, B, C, D, N, T)
  mesh2 {
    vertex_vectors { (N + 1) * (N + 1),
      #for (J, 0, N) #for (I, 0, N)
        #local U = I / N; #local V = J / N;
        (1 - V) * ((1 - U) * A + U * B) + V * ((1 - U) * D + U * C),
      #end #end
    }
    face_indices { 2 * N * N,
      #for (J, 0, N - 1) #for (I, 0, N - 1)
        #local K = J * (N + 1) + I;
        <K, K + 1, K + N + 2>, <K, K + N + 2, K + N + 1>,
      #end #end
    }
    texture { T }
  }
#end
#declare NR = 16;
// floor, ceiling, back, left, right, front (behind the camera)
Quad(<-3, -1.2, -5>, <3, -1.2, -5>, <3, -1.2, 3>, <-3, -1.2, 3>, NR, Wall)
Quad(<-3, 2.6, -5>, <-3, 2.6, 3>, <3, 2.6, 3>, <3, 2.6, -5>, NR, Wall)
Quad(<-3, -1.2, 3>, <3, -1.2, 3>, <3, 2.6, 3>, <-3, 2.6, 3>, NR, Wall)
Quad(<-3, -1.2, -5>, <-3, -1.2, 3>, <-3, 2.6, 3>, <-3, 2.6, -5>, NR, Warm)
Quad(<3, -1.2, -5>, <3, 2.6, -5>, <3, 2.6, 3>, <3, -1.2, 3>, NR, Cool)
Quad(<-3, -1.2, -5>, <-3, 2.6, -5>, <3, 2.6, -5>, <3, -1.2, -5>, NR, Wall)
#include "40_mesh_by_4_splines.txt"
