// partray default scene: the Cornell box.
// Geometry from the Cornell University Program of Computer Graphics'
// published measurements (units: cm/10), tessellated and lit as seed 000's
// CBOX benchmark: about 8,000 triangles and one point light.
#version 3.7;

global_settings {
  assumed_gamma 1.0
  // recursion_limit 9 = n_b 8, the paper's CBOX (seed 000, Table 2: n_b 8)
  radiosity { count 100 recursion_limit 9 error_bound 0.8 }
}

#declare Matte = finish { ambient 0 diffuse 0.75 }
#declare White = texture { pigment { rgb <0.73, 0.73, 0.73> } finish { Matte } }
#declare Red   = texture { pigment { rgb <0.63, 0.065, 0.05> } finish { Matte } }
#declare Green = texture { pigment { rgb <0.14, 0.45, 0.091> } finish { Matte } }

camera {
  location  <27.8, 27.3, -80.0>
  direction <0, 0, 1>
  up        <0, 1, 0>
  right     <-1, 0, 0>   // the data is right-handed: mirror to match the photographs
  angle 39.3
}

#declare Emit = <1.0, 0.78, 0.45>;
// One point light, as the paper's CBOX (seed 000, section 5): at the centre
// of the Cornell light patch, just below the ceiling, with a cosine
// (tightness 1) spotlight falloff pointing down so it lights the room the
// way the diffuse patch does. Its power is the 4x4 area light's it replaces
// (POV-Ray divides an area light's colour among its elements).
light_source {
  <27.8, 54.80, 27.95>
  color Emit * 9
  spotlight radius -90 falloff 90 tightness 1 point_at <27.8, 0, 27.95>
  fade_distance 6 fade_power 2
}

// light patch, seen by the camera but casting no shadow
box { <21.3, 54.86, 22.7>, <34.3, 54.88, 33.2> no_shadow
  pigment { rgb 1 } finish { ambient 0 emission 1 diffuse 0 } }

// Quad(A, B, C, D, N): the planar quad A-B-C-D (in order round its edge)
// as a mesh2 of N x N bilinear cells, 2 N^2 triangles, so the box is
// tessellated as the paper's CBOX is (about 8,000 triangles in all).
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

// Box(P0..P3 bottom corners, H height, N): the 4 sides and the top of a
// block, each side a Quad.
#macro Block(P0, P1, P2, P3, H, N, T)
  #local Y = <0, H, 0>;
  Quad(P0 + Y, P1 + Y, P2 + Y, P3 + Y, N, T)
  Quad(P0, P1, P1 + Y, P0 + Y, N, T)
  Quad(P1, P2, P2 + Y, P1 + Y, N, T)
  Quad(P2, P3, P3 + Y, P2 + Y, N, T)
  Quad(P3, P0, P0 + Y, P3 + Y, N, T)
#end

#declare NW = 24;   // cells per wall side: 5 walls x 1,152 triangles
#declare NB = 11;   // cells per block face: 10 faces x 242 triangles

// floor, ceiling, back wall (white), left (green), right (red)
Quad(<55.28, 0, 0>, <0, 0, 0>, <0, 0, 55.92>, <54.96, 0, 55.92>, NW, White)
Quad(<55.60, 54.88, 0>, <55.60, 54.88, 55.92>, <0, 54.88, 55.92>, <0, 54.88, 0>, NW, White)
Quad(<0, 54.88, 55.92>, <55.60, 54.88, 55.92>, <54.96, 0, 55.92>, <0, 0, 55.92>, NW, White)
Quad(<0, 54.88, 0>, <0, 54.88, 55.92>, <0, 0, 55.92>, <0, 0, 0>, NW, Green)
Quad(<55.28, 0, 0>, <54.96, 0, 55.92>, <55.60, 54.88, 55.92>, <55.60, 54.88, 0>, NW, Red)

// short block, tall block
Block(<13.0, 0, 6.5>, <29.0, 0, 11.4>, <24.0, 0, 27.2>, <8.2, 0, 22.5>, 16.5, NB, White)
Block(<42.3, 0, 24.7>, <47.2, 0, 40.6>, <31.4, 0, 45.6>, <26.5, 0, 29.6>, 33.0, NB, White)
