// partray default scene: the Cornell box.
// Geometry from the Cornell University Program of Computer Graphics'
// published measurements (units: cm/10), light as a 4x4 area light with a
// cosine spotlight falloff so it behaves like a diffuse emitting patch.
#version 3.7;

global_settings {
  assumed_gamma 1.0
  radiosity { count 100 recursion_limit 3 error_bound 0.8 }
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
light_source {
  <27.8, 54.87, 27.95>
  color Emit * 9
  area_light 13*x, 10.5*z, 4, 4 jitter adaptive 1
  spotlight radius -90 falloff 90 tightness 1 point_at <27.8, 0, 27.95>
  fade_distance 6 fade_power 2
}

// light patch, seen by the camera but casting no shadow
box { <21.3, 54.86, 22.7>, <34.3, 54.88, 33.2> no_shadow
  pigment { rgb 1 } finish { ambient 0 emission 1 diffuse 0 } }

mesh {
  // floor
  triangle { <55.28, 0, 0>, <0, 0, 0>, <0, 0, 55.92> }
  triangle { <55.28, 0, 0>, <0, 0, 55.92>, <54.96, 0, 55.92> }
  // ceiling
  triangle { <55.60, 54.88, 0>, <55.60, 54.88, 55.92>, <0, 54.88, 55.92> }
  triangle { <55.60, 54.88, 0>, <0, 54.88, 55.92>, <0, 54.88, 0> }
  // back wall
  triangle { <0, 54.88, 55.92>, <55.60, 54.88, 55.92>, <54.96, 0, 55.92> }
  triangle { <0, 54.88, 55.92>, <54.96, 0, 55.92>, <0, 0, 55.92> }
  texture { White }
}
mesh {
  triangle { <0, 54.88, 0>, <0, 54.88, 55.92>, <0, 0, 55.92> }
  triangle { <0, 54.88, 0>, <0, 0, 55.92>, <0, 0, 0> }
  texture { Green }
}
mesh {
  triangle { <55.28, 0, 0>, <54.96, 0, 55.92>, <55.60, 54.88, 55.92> }
  triangle { <55.28, 0, 0>, <55.60, 54.88, 55.92>, <55.60, 54.88, 0> }
  texture { Red }
}

// short block
mesh2 {
  vertex_vectors { 8,
    <13.0, 0, 6.5>, <29.0, 0, 11.4>, <24.0, 0, 27.2>, <8.2, 0, 22.5>,
    <13.0, 16.5, 6.5>, <29.0, 16.5, 11.4>, <24.0, 16.5, 27.2>, <8.2, 16.5, 22.5> }
  face_indices { 10,
    <4,5,6>, <4,6,7>, <0,1,5>, <0,5,4>, <1,2,6>, <1,6,5>, <2,3,7>, <2,7,6>, <3,0,4>, <3,4,7> }
  texture { White }
}

// tall block
mesh2 {
  vertex_vectors { 8,
    <42.3, 0, 24.7>, <47.2, 0, 40.6>, <31.4, 0, 45.6>, <26.5, 0, 29.6>,
    <42.3, 33.0, 24.7>, <47.2, 33.0, 40.6>, <31.4, 33.0, 45.6>, <26.5, 33.0, 29.6> }
  face_indices { 10,
    <4,5,6>, <4,6,7>, <0,1,5>, <0,5,4>, <1,2,6>, <1,6,5>, <2,3,7>, <2,7,6>, <3,0,4>, <3,4,7> }
  texture { White }
}
