// A glass merge whose members share a surface: a cylinder standing on a
// shorter cylinder of the same radius (as shapes.inc's
// Round_Cylinder_Merge inside a cylinder of its radius), so for 0 < y < 1
// the two walls coincide. Each wall's crossing there must stay a surface.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 10 }
camera { location <0, 1.2, -4> look_at <0, 1, 0> angle 45 }
light_source { <3, 6, -4> rgb 1 }
background { rgb <0.5, 0.6, 0.9> }
plane { y, -1 pigment { checker rgb 1 rgb 0.2 scale 0.25 } }
merge {
  cylinder { <0, 0, 0>, <0, 2.5, 0>, 1 }
  cylinder { <0, -1, 0>, <0, 1, 0>, 1 }
  pigment { rgbt 1 }
  finish { ambient 0 diffuse 0 reflection { 0, 1 fresnel on } }
  interior { ior 1.3 fade_distance 0.5 fade_power 1001 fade_color <0.8, 0.3, 0.4> }
}
