// Language checks: every #debug line is compared with POV-Ray 3.7.0's output
// (tests/sdl/lang_checks.expected, made by `povray +Ilang_checks.pov +W1 +H1 -F -D`).
#version 3.7;
#include "functions.inc"
// ---- arrays
#declare A = array[2][3] {{1, 2, 3}, {4, 5, 6}}
#declare B = A;
#declare B[1][2] = 60;
#debug concat("arr ", str(A[1][2],0,3), " ", str(B[1][2],0,3), " ", str(dimensions(A),0,0), " ", str(dimension_size(A,2),0,0), " ", str(dimension_size(A,3),0,0), "\n")
#declare C = array[3]
#declare C[1] = <1,2,3>;
#debug concat("arrdef ", str(defined(C[0]),0,0), str(defined(C[1]),0,0), " ", str(C[1].y,0,3), "\n")
#declare Obj = array[2] { sphere { 0, 1 }, box { -1, 1 } }
// ---- macros: by reference, by value, recursion, locals
#macro Set(R, V) #declare R = V; #end
#macro Inc(R) #declare R = R + 1; #end
#macro Twice(R) Inc(R) Inc(R) #end
#macro Fact(N) #if (N <= 1) 1 #else N * Fact(N - 1) #end #end
#macro Loc() #local Z = 7; Z * 2 #end
#declare V = 1;
Set(V, 5)
#declare W = 10;
Twice(W)
Set(V + 0, 99)
#declare Q = Loc();
#debug concat("mac ", str(V,0,0), " ", str(W,0,0), " ", str(Fact(6),0,0), " ", str(Q,0,0), " ", str(defined(Z),0,0), "\n")
#macro Fill(X) #local i = 0; #while (i < dimension_size(X, 1)) #declare X[i] = i * i; #local i = i + 1; #end #end
#declare D = array[4]
Fill(D)
#debug concat("fill ", str(D[3],0,0), "\n")
// ---- functions
#declare F = function(a, b, c) { select(a - b, min(a, b, c), max(c, a), b * c) + sum(k, 1, 4, k * a) - prod(k, 1, 3, b + k) + atan2(a, b) * pow(c, 2) / mod(7, 3) + div(7, 2) + abs(-b) * int(2.7) }
#debug concat("fn ", str(F(1.5, 2, 0.5),0,9), " ", str(F(3, 2, -1),0,9), " ", str(F(2, 2, 2),0,9), "\n")
#declare G = function { f_sphere(x, y, z, 1) * 2 + f_r(x, y, z) }
#declare H = function(x, u) { x * 10 + y + u }
#debug concat("fn2 ", str(G(0.3, 0.4, 1.2),0,9), " ", str(H(2, 3),0,9), "\n")
// arithmetic, comparisons, min/max and math only: evaluated in post order
#declare Fpost = function(a, b) { min(a, b, 3) * 2 - max(a, 1) + atan2(a, b) + pow(b, 2) / (a + 1) + (a < b) + (a >= b) * 3 - (a != b) + abs(-a) * sqrt(abs(b)) - (a > 1 & b > 1) + (a < 0 | b < 0) * 5 }
#debug concat("fnq ", str(Fpost(1.5, 2),0,9), " ", str(Fpost(3, -2),0,9), " ", str(Fpost(-0.5, 0.25),0,9), "\n")
#declare T = function { transform { rotate <10, 20, 30> translate <1, 2, 3> scale 2 } }
#declare TV = T(1, -1, 0.5);
#debug concat("fnt ", vstr(3, TV, " ", 0, 9), " ", str(T(0, 1, 0).y,0,9), "\n")
#debug concat("int1 ", str(f_rounded_box(0.9,0.3,1.2, 0.2, 1,0.5,1),0,9), " ", str(f_superellipsoid(0.3,0.4,0.5, 0.5, 0.8),0,9), " ", str(f_helix1(1,0.5,0.2, 2,3,0.3,1,1,1,0),0,9), "\n")
#debug concat("int2 ", str(f_torus2(1,0.5,0.2, 1,2,0.5),0,9), " ", str(f_algbr_cyl2(0.4,0.3,0.2, 1,10,1,0.5,30),0,9), " ", str(f_blob(0.2,0.1,0.3, 1,1,1,1,1),0,9), "\n")
#debug concat("int3 ", str(f_spiral(0.5,0.2,0.4, 0.3,0.1,1,0,0,1),0,9), " ", str(f_hex_x(0.7,1.3,0, 0),0,9), " ", str(f_mesh1(0.3,0.1,0.7, 1,1,1,0.2,1),0,9), " ", str(f_quantum(0.3,0.4,0.5, 1),0,9), "\n")
#debug concat("int4 ", str(f_enneper(0.3,0.5,0.1, 1),0,9), " ", str(f_helical_torus(1.2,0.3,0.4, 1,2,1,0.1,0.2,0.3,1,1,1,1),0,9), " ", str(f_dupin_cyclid(0.3,0.2,0.1, 1,0.5,1,0.3,0.2,0.4),0,9), "\n")
// ---- splines
#declare S = spline { natural_spline -1, <0,0,1>, 0.5, <1,2,0>, 1, <0,3,2>, 2.5, <2,1,1>, 4, <1,0,0> }
#declare Ts = array[7] {-2, -0.5, 0.2, 0.9, 1.7, 3.3, 5}
#for (i, 0, 6)
  #debug concat("spn ", vstr(3, S(Ts[i]), " ", 0, 9), "\n")
  #debug concat("spl ", vstr(3, S(Ts[i], linear_spline), " ", 0, 9), "\n")
  #debug concat("spq ", vstr(3, S(Ts[i], quadratic_spline), " ", 0, 9), "\n")
  #debug concat("spc ", vstr(3, S(Ts[i], cubic_spline), " ", 0, 9), "\n")
#end
#declare SF = function { spline { S } }
#debug concat("spf ", str(SF(0.7).y,0,9), "\n")
// ---- trace, inside, extents
#declare N = <0,0,0>;
#declare Ob = difference { box { -1, 1 } sphere { <1,1,1>, 1.2 } rotate <5, 10, 15> }
#declare P = trace(Ob, <3,0.9,0.9>, <-1,0.05,0>, N);
#debug concat("tr1 ", vstr(3, P, " ", 0, 9), " ", vstr(3, N, " ", 0, 9), "\n")
#declare Tor = torus { 2, 0.5 rotate x*20 translate y }
#declare P = trace(Tor, <5,1.1,0.2>, <-1,0,0>, N);
#debug concat("tr2 ", vstr(3, P, " ", 0, 9), " ", vstr(3, N, " ", 0, 9), "\n")
#declare Me = mesh { triangle { <0,0,0>, <1,0,0>, <0,1,0> } smooth_triangle { <1,0,0>, <0,0,-1>, <1,1,0>, <0,1,-1>, <0,1,0>, <1,0,-1> } scale 2 }
#declare P = trace(Me, <1.2,1.6,5>, <0,0,-1>, N);
#debug concat("tr3 ", vstr(3, P, " ", 0, 9), " ", vstr(3, N, " ", 0, 9), "\n")
#declare La = lathe { cubic_spline 6, <0,-1>, <0,0>, <1,0.5>, <0.8,1.5>, <0,2>, <0,3> scale 2 }
#declare P = trace(La, <5,1.2,0.3>, <-1,0,0>, N);
#debug concat("tr4 ", vstr(3, P, " ", 0, 6), " ", vstr(3, N, " ", 0, 6), "\n")
#declare Ins = intersection { sphere { 0, 1 } cylinder { -2*x, 2*x, 0.5 } plane { y, 0.2 } }
#debug concat("ins ", str(inside(Ins, <0.5,0,0>),0,0), str(inside(Ins, <0.5,0.3,0>),0,0), str(inside(Ins, <0,0,0.7>),0,0), str(inside(Ob, <-0.5,-0.5,-0.5>),0,0), "\n")
#debug concat("ext1 ", vstr(3, min_extent(Ob), " ", 0, 6), " ", vstr(3, max_extent(Ob), " ", 0, 6), "\n")
#debug concat("ext2 ", vstr(3, min_extent(Ins), " ", 0, 6), " ", vstr(3, max_extent(Ins), " ", 0, 6), "\n")
#debug concat("ext3 ", vstr(3, min_extent(Tor), " ", 0, 6), " ", vstr(3, max_extent(Tor), " ", 0, 6), "\n")
#debug concat("ext4 ", vstr(3, min_extent(Obj[0]), " ", 0, 6), " ", vstr(3, max_extent(La), " ", 0, 6), "\n")
// ---- random numbers and strings
#declare R = seed(42);
#debug concat("rnd ", str(rand(R),0,9), " ", str(rand(R),0,9), " ", str(rand(R),0,9), "\n")
#debug concat("str ", substr("abcdef", 2, 3), strupr("xY"), str(strlen("hello"),0,0), vstr(2, <1.25,2>, ";", 0, 2), "\n")
