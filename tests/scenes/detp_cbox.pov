// A reduced Cornell box (scenes/cbox.pov with coarser tessellation) whose
// short block moves with the clock: the incremental photon paths' test
// scene (tests/test_motion.c) and bench/motion.sh's.
#version 3.7;
global_settings { assumed_gamma 1.0 radiosity { count 100 recursion_limit 9 } }
#declare Matte = finish { ambient 0 diffuse 0.75 }
#declare White = texture { pigment { rgb <0.73, 0.73, 0.73> } finish { Matte } }
#declare Red   = texture { pigment { rgb <0.63, 0.065, 0.05> } finish { Matte } }
#declare Green = texture { pigment { rgb <0.14, 0.45, 0.091> } finish { Matte } }
camera {
  location  <27.8, 27.3, -80.0>
  direction <0, 0, 1> up <0, 1, 0> right <-1, 0, 0>
  angle 39.3
}
light_source {
  <27.8, 54.80, 27.95> color <1.0, 0.78, 0.45> * 9
  spotlight radius -90 falloff 90 tightness 1 point_at <27.8, 0, 27.95>
  fade_distance 6 fade_power 2
}
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
#macro Block(P0, P1, P2, P3, H, N, T)
  #local Y = <0, H, 0>;
  Quad(P0 + Y, P1 + Y, P2 + Y, P3 + Y, N, T)
  Quad(P0, P1, P1 + Y, P0 + Y, N, T)
  Quad(P1, P2, P2 + Y, P1 + Y, N, T)
  Quad(P2, P3, P3 + Y, P2 + Y, N, T)
  Quad(P3, P0, P0 + Y, P3 + Y, N, T)
#end
#declare NW = 4;
#declare NB = 2;
Quad(<55.28, 0, 0>, <0, 0, 0>, <0, 0, 55.92>, <54.96, 0, 55.92>, NW, White)
Quad(<55.60, 54.88, 0>, <55.60, 54.88, 55.92>, <0, 54.88, 55.92>, <0, 54.88, 0>, NW, White)
Quad(<0, 54.88, 55.92>, <55.60, 54.88, 55.92>, <54.96, 0, 55.92>, <0, 0, 55.92>, NW, White)
Quad(<0, 54.88, 0>, <0, 54.88, 55.92>, <0, 0, 55.92>, <0, 0, 0>, NW, Green)
Quad(<55.28, 0, 0>, <54.96, 0, 55.92>, <55.60, 54.88, 55.92>, <55.60, 54.88, 0>, NW, Red)
// the short block slides towards the red wall as the clock runs 0..1
union {
  Block(<13.0, 0, 6.5>, <29.0, 0, 11.4>, <24.0, 0, 27.2>, <8.2, 0, 22.5>, 16.5, NB, White)
  translate <10 * clock, 0, 0>
}
Block(<42.3, 0, 24.7>, <47.2, 0, 40.6>, <31.4, 0, 45.6>, <26.5, 0, 29.6>, 33.0, NB, White)
