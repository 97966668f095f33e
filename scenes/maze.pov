// Benchmark scene MAZE (as seed 000's MAZE): a procedural maze of
// 242,160 triangles (121 mesh2) lit by two point lights, with radiosity{}
// so that partray's default is --gi particle.
//
// The maze is a perfect maze on a 16 x 16 grid of cells carved by a
// recursive backtracker driven by a seeded rand() stream (so it is the same
// in every run and in both partray and POV-Ray). Every wall run is a thin
// block whose faces are mesh2 grids of cells about S units on a side, so
// the triangle count is real geometry, not instancing.
#version 3.7;

global_settings {
  assumed_gamma 1.0
  // recursion_limit 14 = n_b 13, the paper's MAZE (seed 000, Table 2: n_b 13)
  radiosity { count 400 recursion_limit 14 error_bound 0.8 }  // 200,000 particles
}

#declare N = 16;      // cells per maze side
#declare C = 2.0;     // cell size
#declare H = 1.5;     // wall height
#declare T = 0.2;     // wall thickness
#ifndef (S) #declare S = 0.145; #end  // tessellation: cell edge of the wall grids

// ---------------------------------------------------------------- mesh kit
// MB_Quad appends the planar quad A-B-C-D (in order round its edge) as NU x NV
// bilinear cells (2 NU NV triangles) to the mesh being built; MB_Emit writes
// the built mesh as one mesh2 with texture Tx and starts a new one.
#declare MB_V = array[60000];
#declare MB_F = array[110000];
#declare MB_NV = 0;
#declare MB_NF = 0;
#declare Triangles = 0;

#macro MB_Quad(A, B, C_, D, NU, NV)
  #local Base = MB_NV;
  #for (J, 0, NV) #for (I, 0, NU)
    #local U = I / NU; #local W = J / NV;
    #declare MB_V[MB_NV] = (1 - W) * ((1 - U) * A + U * B) + W * ((1 - U) * D + U * C_);
    #declare MB_NV = MB_NV + 1;
  #end #end
  #for (J, 0, NV - 1) #for (I, 0, NU - 1)
    #local K = Base + J * (NU + 1) + I;
    #declare MB_F[MB_NF] = <K, K + 1, K + NU + 2>;
    #declare MB_F[MB_NF + 1] = <K, K + NU + 2, K + NU + 1>;
    #declare MB_NF = MB_NF + 2;
  #end #end
#end

#macro MB_Emit(Tx)
  mesh2 {
    vertex_vectors { MB_NV, #for (I, 0, MB_NV - 1) MB_V[I], #end }
    face_indices { MB_NF, #for (I, 0, MB_NF - 1) MB_F[I], #end }
    texture { Tx }
  }
  #declare Triangles = Triangles + MB_NF;
  #declare MB_NV = 0;
  #declare MB_NF = 0;
#end

#macro Cells(L) max(1, ceil(L / S - 1e-6)) #end

// Wall(P0, P1, Cap0, Cap1): the block of thickness T and height H over the
// box [P0, P1] in x and z (P0, P1 as <x, z>); both long faces and the top
// always, an end face only where it is not against another wall.
#macro Wall(P0, P1, Cap0, Cap1, Tx)
  #local X0 = P0.u; #local Z0 = P0.v; #local X1 = P1.u; #local Z1 = P1.v;
  #local A = <X0, 0, Z0>; #local B = <X1, 0, Z0>; #local Cc = <X1, 0, Z1>; #local D = <X0, 0, Z1>;
  #local Y = <0, H, 0>;
  #local NX = Cells(X1 - X0); #local NZ = Cells(Z1 - Z0); #local NY = Cells(H);
  MB_Quad(A + Y, B + Y, Cc + Y, D + Y, NX, NZ)        // top
  #if (X1 - X0 > Z1 - Z0)                             // along x: long faces at z0, z1
    MB_Quad(A, B, B + Y, A + Y, NX, NY)
    MB_Quad(Cc, D, D + Y, Cc + Y, NX, NY)
    #if (Cap0) MB_Quad(D, A, A + Y, D + Y, NZ, NY) #end
    #if (Cap1) MB_Quad(B, Cc, Cc + Y, B + Y, NZ, NY) #end
  #else                                               // along z: long faces at x0, x1
    MB_Quad(D, A, A + Y, D + Y, NZ, NY)
    MB_Quad(B, Cc, Cc + Y, B + Y, NZ, NY)
    #if (Cap0) MB_Quad(A, B, B + Y, A + Y, NX, NY) #end
    #if (Cap1) MB_Quad(Cc, D, D + Y, Cc + Y, NX, NY) #end
  #end
  MB_Emit(Tx)
#end

// ---------------------------------------------------------------- the maze
// HW[j * N + i]: wall along x at z = j C over cell column i (j = 0..N);
// VW[i * N + j]: wall along z at x = i C over cell row j (i = 0..N).
#declare HW = array[(N + 1) * N];
#declare VW = array[(N + 1) * N];
#for (K, 0, (N + 1) * N - 1) #declare HW[K] = 1; #declare VW[K] = 1; #end
#declare Visited = array[N * N];
#for (K, 0, N * N - 1) #declare Visited[K] = 0; #end
#declare Stack = array[N * N];
#declare R = seed(2026);
#declare Visited[0] = 1;
#declare Stack[0] = 0;
#declare SP = 1;
#declare Nb = array[4];
#while (SP > 0)
  #declare Cur = Stack[SP - 1];
  #declare CI = mod(Cur, N);
  #declare CJ = div(Cur, N);
  #declare NN = 0;
  #if (CI > 0)     #if (!Visited[Cur - 1]) #declare Nb[NN] = Cur - 1; #declare NN = NN + 1; #end #end
  #if (CI < N - 1) #if (!Visited[Cur + 1]) #declare Nb[NN] = Cur + 1; #declare NN = NN + 1; #end #end
  #if (CJ > 0)     #if (!Visited[Cur - N]) #declare Nb[NN] = Cur - N; #declare NN = NN + 1; #end #end
  #if (CJ < N - 1) #if (!Visited[Cur + N]) #declare Nb[NN] = Cur + N; #declare NN = NN + 1; #end #end
  #if (NN = 0)
    #declare SP = SP - 1;
  #else
    #declare Next = Nb[min(NN - 1, floor(rand(R) * NN))];
    #switch (Next - Cur)
      #case (1)  #declare VW[(CI + 1) * N + CJ] = 0; #break
      #case (-1) #declare VW[CI * N + CJ] = 0; #break
      #case (N)  #declare HW[(CJ + 1) * N + CI] = 0; #break
      #else      #declare HW[CJ * N + CI] = 0;
    #end
    #declare Visited[Next] = 1;
    #declare Stack[SP] = Next;
    #declare SP = SP + 1;
  #end
#end
// an entrance at the near corner and an exit at the far one
#declare HW[0] = 0;
#declare HW[N * N + N - 1] = 0;

// is there a wall along x touching the grid point (i, j)?
#macro HAt(I, J)
  ((I > 0 & HW[J * N + max(I - 1, 0)]) | (I < N & HW[J * N + min(I, N - 1)]))
#end

#declare Wall_T = array[3] {
  texture { pigment { rgb <0.75, 0.74, 0.70> } finish { ambient 0 diffuse 0.8 } },
  texture { pigment { rgb <0.70, 0.30, 0.22> } finish { ambient 0 diffuse 0.8 } },
  texture { pigment { rgb <0.25, 0.45, 0.65> } finish { ambient 0 diffuse 0.8 } }
}
#declare RC = seed(7);
// most walls pale, a fifth terracotta, a fifth blue (colour bleeding to see)
#macro Pick() #local Q = rand(RC); Wall_T[select(Q - 0.6, 0, select(Q - 0.8, 1, 2))] #end

// runs of walls along x: they own the wall posts at the grid points
#for (J, 0, N)
  #declare I = 0;
  #while (I < N)
    #if (HW[J * N + I])
      #declare I0 = I;
      #while (I < N & HW[J * N + min(I, N - 1)]) #declare I = I + 1; #end
      Wall(<I0 * C - T / 2, J * C - T / 2>, <I * C + T / 2, J * C + T / 2>, 1, 1, Pick())
    #else
      #declare I = I + 1;
    #end
  #end
#end
// runs of walls along z: they end against a wall along x, or at a post of
// their own where none touches the grid point
#for (I, 0, N)
  #declare J = 0;
  #while (J < N)
    #if (VW[I * N + J])
      #declare J0 = J;
      #while (J < N & VW[I * N + min(J, N - 1)]) #declare J = J + 1; #end
      #declare H0 = HAt(I, J0);
      #declare H1 = HAt(I, J);
      Wall(<I * C - T / 2, J0 * C + (H0 ? T / 2 : -T / 2)>, <I * C + T / 2, J * C + (H1 ? -T / 2 : T / 2)>,
           !H0, !H1, Pick())
    #else
      #declare J = J + 1;
    #end
  #end
#end

// the floor: a grid of 0.25-unit cells reaching 2 units past the maze
#declare FL = -2;
#declare FH = N * C + 2;
MB_Quad(<FL, 0, FL>, <FH, 0, FL>, <FH, 0, FH>, <FL, 0, FH>, 144, 144)
MB_Emit(texture { pigment { rgb <0.60, 0.55, 0.45> } finish { ambient 0 diffuse 0.8 } })

#debug concat("maze.pov: ", str(Triangles, 0, 0), " triangles\n")

// two point lights over the maze, falling off with the square of distance
light_source { <9, 7, 7> color rgb <1.0, 0.85, 0.65> * 40 fade_distance 1 fade_power 2 }
light_source { <25, 6, 24> color rgb <0.65, 0.8, 1.0> * 30 fade_distance 1 fade_power 2 }

camera {
  location <0, 9, -5>
  look_at <15, 0, 14>
  angle 64
}
