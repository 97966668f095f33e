// trace() and inside() on the shapes whose parse-time answers come from the
// renderer's own geometry (geom/): every #debug line is compared
// with POV-Ray 3.7.0's output (trace_shapes.expected, made by
// `povray +Itrace_shapes.pov +W8 +H6 -F -D -GR -GS -GW +GDtrace_shapes.expected`).
#version 3.7;
global_settings { assumed_gamma 1 }
#declare N = <0, 0, 0>;
#macro T(Name, O, P0, D, Q)
  #local P = trace(O, P0, D, N);
  #debug concat(Name, " ", vstr(3, P, " ", 0, 6), " ", vstr(3, N, " ", 0, 6), " ", str(inside(O, Q), 0, 0), "\n")
#end
#macro TT(Name, O, P0, D)
  #local P = trace(O, P0, D, N);
  #debug concat(Name, " ", vstr(3, P, " ", 0, 6), " ", vstr(3, N, " ", 0, 6), "\n")
#end
#declare Sor = sor { 4, <0, 0>, <1, 0>, <0.5, 1>, <0, 2> }
T("sor", Sor, <3, 0.4, 0.1>, -x, <0.05, 0.3, 0.02>)
T("sor2", Sor, <0.2, 5, 0.1>, -y, <0.7, 0.3, 0.02>)
T("sor3", object { Sor scale <1, 2, 0.5> rotate 30 * z translate x }, <3, 0.4, 0.1>, <-1, 0.1, 0>, <1, 0.3, 0>)
T("sorcsg", difference { object { Sor } box { <0, -1, -1>, <2, 3, 1> } }, <3, 0.4, 0.1>, -x, <0.05, 0.3, 0.02>)
T("poly", poly { 2, <1, 0, 0, 0, 1, 0, 0, 1, 0, -1> scale <1, 2, 1> }, <3, 0.4, 0.1>, -x, <0.5, 1.5, 0>)
T("quartic", quartic { <1, 0, 0, 0, 2, 0, 0, 2, 0, -2.5, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 2, 0, 0.5, 0, 0, 0, 0.5625, 0, 0, 0, 0, 0> }, <3, 0.4, 0.1>, -x, <1, 0.1, 0>)
T("cubic", cubic { <1, 0, 0, 0, 0, 0, 0, 0, 0, -1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0> }, <3, 0.4, 0.1>, -x, <0.5, 0, 0>)
T("text", text { internal 1 "H" 0.5, 0 }, <0.1, 0.3, -2>, z, <0.1, 0.3, 0.25>)
T("text2", text { internal 1 "H" 0.5, 0 rotate 30 * y }, <0.1, 0.3, -2>, z, <0.3, 0.3, 0.25>)
// (side faces: POV-Ray reports the normal as the glyph contour winds, inward
// on some; partray reports the outward one, so only front and back faces here)
T("text3", text { internal 1 "Hi" 1, <0.2, 0> scale 2 }, <2.15, 0.5, 3>, -z, <0.2, 0.5, 1>)
T("julia", julia_fractal { <-0.083, 0.0, -0.83, -0.025> quaternion sqr max_iteration 8 precision 15 }, <3, 0.1, 0.05>, -x, <0, 0, 0>)
TT("polygon", polygon { 4, <0, 0>, <1, 0>, <0, 1>, <0, 0> rotate 10 * y }, <0.2, 0.2, -2>, z)
#declare Hf = height_field { png "crater_dat.png" translate <-0.5, 0, -0.5> scale <2, 0.5, 2> }
#declare Ps = array[4] {<0.1, 3, 0.05>, <-0.7, 3, 0.33>, <0.45, 3, -0.2>, <0.2, 3, 0.6>}
#for (i, 0, 3)
  T("hf", Hf, Ps[i], -y, Ps[i] * <1, 0.01, 1>)
  T("hfr", object { Hf rotate 20 * x }, Ps[i] * 0.5, <0.1, -1, 0.2>, Ps[i] * <0.5, 0.02, 0.5>)
#end
// patches: POV-Ray's triangle normal (P3-P1) x (P2-P1), also for flat
// triangles in a mesh among smooth ones; smooth normals interpolated, also
// the vertex normals of a bicubic_patch mesh
TT("t1", triangle { <0, 0, 0>, <1, 0, 0>, <0, 0, 1> }, <0.2, -3, 0.1>, y)
TT("t2", triangle { <0, 0, 0>, <0, 0, 1>, <1, 0, 0> }, <0.2, 3, 0.1>, -y)
TT("s1", smooth_triangle { <0, 0, 0>, <0, 1, 0>, <1, 0, 0>, <1, 1, 0>, <0, 0, 1>, <0, 1, 1> }, <0.2, 3, 0.1>, -y)
#declare M = mesh {
  smooth_triangle { <0, 0, 0>, <0, 1, 0>, <1, 0, 0>, <1, 1, 0>, <0, 0, 1>, <0, 1, 1> }
  triangle { <0, 0, 1>, <1, 0, 1>, <0, 0, 2> }
  triangle { <2, 0, 0>, <2, 0, 1>, <3, 0, 0> }
  rotate 10 * x
}
TT("m1", M, <0.3, 3, 0.1>, -y)
TT("m2", M, <0.3, 3, 1.2>, -y)
TT("m3", M, <2.2, -3, 0.2>, y)
#declare B = bicubic_patch { type 1 u_steps 3 v_steps 3
  <0, 0, 0>, <1, 0, 0>, <2, 0, 0>, <3, 0, 0>, <0, 0, 1>, <1, 1, 1>, <2, 1, 1>, <3, 0, 1>,
  <0, 0, 2>, <1, 1, 2>, <2, 1, 2>, <3, 0, 2>, <0, 0, 3>, <1, 0, 3>, <2, 0, 3>, <3, 0, 3> }
TT("b1", B, <1.5, 3, 1.5>, -y)
TT("b2", B, <0.7, 3, 1.1>, -y)
T("sweep", sphere_sweep { linear_spline 2, <0, 0, 0>, 0.5, <1, 0, 0>, 0.25 }, <0.5, 3, 0.1>, -y, <0.9, 0.1, 0>)
sphere { 0, 1 }
