// Benchmark scene CONFERENCE (as seed 000's CONFERENCE): a
// conference room of four tables and 24 chairs, 187,808 triangles,
// lit by four point lights, with radiosity{} so that partray's default is
// --gi particle.
//
// Every table and chair is one mesh2 built by macros (blocks for tops,
// seats and backs as grids of cells about S units on a side; legs as
// tessellated tubes), so the triangle count is real geometry.
#version 3.7;

global_settings {
  assumed_gamma 1.0
  // recursion_limit 4 = n_b 3, the paper's CONF (seed 000, Table 2: n_b 3)
  radiosity { count 400 recursion_limit 4 error_bound 0.8 }  // 200,000 particles
}

#ifndef (S) #declare S = 0.022; #end  // cell edge of the furniture grids
#declare SR = 0.2;                    // cell edge of the room's walls

// ---------------------------------------------------------------- mesh kit
// Vertices are placed at MB_Pos + <MB_Dir x, y, MB_Dir z>: a piece built
// facing -z turned half round when MB_Dir = -1. MB_Quad appends the planar
// quad A-B-C-D (in order round its edge) as NU x NV bilinear cells; MB_Tube
// a vertical tube; MB_Emit writes the built mesh as one mesh2.
#declare MB_V = array[20000];
#declare MB_F = array[36000];
#declare MB_NV = 0;
#declare MB_NF = 0;
#declare MB_Pos = <0, 0, 0>;
#declare MB_Dir = 1;
#declare Triangles = 0;

#macro MB_Put(P)
  #declare MB_V[MB_NV] = MB_Pos + <MB_Dir * P.x, P.y, MB_Dir * P.z>;
  #declare MB_NV = MB_NV + 1;
#end

#macro MB_Quad(A, B, C, D, NU, NV)
  #local Base = MB_NV;
  #for (J, 0, NV) #for (I, 0, NU)
    #local U = I / NU; #local W = J / NV;
    MB_Put((1 - W) * ((1 - U) * A + U * B) + W * ((1 - U) * D + U * C))
  #end #end
  #for (J, 0, NV - 1) #for (I, 0, NU - 1)
    #local K = Base + J * (NU + 1) + I;
    #declare MB_F[MB_NF] = <K, K + 1, K + NU + 2>;
    #declare MB_F[MB_NF + 1] = <K, K + NU + 2, K + NU + 1>;
    #declare MB_NF = MB_NF + 2;
  #end #end
#end

// MB_Tube(P, R, Hh, NS, NH): the side of the vertical cylinder of radius R
// from P up to P + Hh y, NS segments round and NH along (its ends are
// against the floor and a seat or top, so they are left open).
#macro MB_Tube(P, R, Hh, NS, NH)
  #local Base = MB_NV;
  #for (J, 0, NH) #for (I, 0, NS - 1)
    #local A = 2 * pi * I / NS;
    MB_Put(P + <R * cos(A), Hh * J / NH, R * sin(A)>)
  #end #end
  #for (J, 0, NH - 1) #for (I, 0, NS - 1)
    #local K = Base + J * NS + I;
    #local K1 = Base + J * NS + mod(I + 1, NS);
    #declare MB_F[MB_NF] = <K, K1, K1 + NS>;
    #declare MB_F[MB_NF + 1] = <K, K1 + NS, K + NS>;
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

#macro Cells(L, E) max(1, ceil(L / E - 1e-6)) #end

// MB_Block(P0, P1, E): the six faces of the box [P0, P1] as grids of cells
// about E on a side.
#macro MB_Block(P0, P1, E)
  #local NX = Cells(P1.x - P0.x, E); #local NY = Cells(P1.y - P0.y, E); #local NZ = Cells(P1.z - P0.z, E);
  #local A = <P0.x, P0.y, P0.z>; #local B = <P1.x, P0.y, P0.z>; #local C = <P1.x, P0.y, P1.z>; #local D = <P0.x, P0.y, P1.z>;
  #local Y = <0, P1.y - P0.y, 0>;
  MB_Quad(A, B, C, D, NX, NZ)
  MB_Quad(A + Y, B + Y, C + Y, D + Y, NX, NZ)
  MB_Quad(A, B, B + Y, A + Y, NX, NY)
  MB_Quad(B, C, C + Y, B + Y, NZ, NY)
  MB_Quad(C, D, D + Y, C + Y, NX, NY)
  MB_Quad(D, A, A + Y, D + Y, NZ, NY)
#end

// ---------------------------------------------------------------- materials
#macro Matte(Col) texture { pigment { rgb Col } finish { ambient 0 diffuse 0.8 } } #end
#declare Wood   = Matte(<0.50, 0.32, 0.18>)
#declare Steel  = Matte(<0.55, 0.56, 0.58>)
#declare Fabric = array[2];
#declare Fabric[0] = Matte(<0.15, 0.25, 0.55>)
#declare Fabric[1] = Matte(<0.60, 0.15, 0.12>)
#declare Wall   = Matte(<0.78, 0.76, 0.72>)
#declare Accent = Matte(<0.35, 0.55, 0.40>)
#declare Carpet = Matte(<0.35, 0.33, 0.32>)
#declare Ceil   = Matte(<0.85, 0.85, 0.85>)

// ---------------------------------------------------------------- furniture
// Chair at P facing -z (Dir 1) or +z (Dir -1): seat 0.46 x 0.05 x 0.46 at
// 0.45, a back 0.46 x 0.45 x 0.04 on two rear posts, four tube legs.
#macro Chair(P, Dir, Tx)
  #declare MB_Pos = P;
  #declare MB_Dir = Dir;
  MB_Block(<-0.23, 0.45, -0.23>, <0.23, 0.50, 0.23>, S)
  MB_Block(<-0.23, 0.58, 0.19>, <0.23, 0.98, 0.23>, S)
  #for (I, 0, 1)
    #local X = 0.19 * (2 * I - 1);
    MB_Tube(<X, 0, -0.19>, 0.018, 0.45, 14, 12)   // front legs
    MB_Tube(<X, 0, 0.21>, 0.018, 0.58, 14, 14)    // rear legs, up to the back
  #end
  MB_Emit(Tx)
#end

// Table centred at P: a top 2.4 x 0.04 x 1.0 at 0.72, four tube legs.
#macro Table(P)
  #declare MB_Pos = P;
  #declare MB_Dir = 1;
  MB_Block(<-1.2, 0.72, -0.5>, <1.2, 0.76, 0.5>, 2 * S)
  #for (I, 0, 1) #for (J, 0, 1)
    MB_Tube(<1.05 * (2 * I - 1), 0, 0.38 * (2 * J - 1)>, 0.035, 0.72, 20, 24)
  #end #end
  MB_Emit(Wood)
#end

// ---------------------------------------------------------------- the room
// 12 x 8 x 3, its floor, ceiling and walls as grids of SR cells.
#declare RW = 12; #declare RD = 8; #declare RH = 3;
#declare MB_Pos = <0, 0, 0>;
#declare MB_Dir = 1;
MB_Quad(<0, 0, 0>, <RW, 0, 0>, <RW, 0, RD>, <0, 0, RD>, Cells(RW, SR), Cells(RD, SR))
MB_Emit(Carpet)
MB_Quad(<0, RH, 0>, <RW, RH, 0>, <RW, RH, RD>, <0, RH, RD>, Cells(RW, SR), Cells(RD, SR))
MB_Emit(Ceil)
MB_Quad(<0, 0, RD>, <RW, 0, RD>, <RW, RH, RD>, <0, RH, RD>, Cells(RW, SR), Cells(RH, SR))
MB_Quad(<0, 0, 0>, <RW, 0, 0>, <RW, RH, 0>, <0, RH, 0>, Cells(RW, SR), Cells(RH, SR))
MB_Quad(<RW, 0, 0>, <RW, 0, RD>, <RW, RH, RD>, <RW, RH, 0>, Cells(RD, SR), Cells(RH, SR))
MB_Emit(Wall)
MB_Quad(<0, 0, 0>, <0, 0, RD>, <0, RH, RD>, <0, RH, 0>, Cells(RD, SR), Cells(RH, SR))
MB_Emit(Accent)

// four tables in two rows, three chairs along each long side
#for (TI, 0, 1) #for (TJ, 0, 1)
  #declare TP = <3.5 + 5 * TI, 0, 2.7 + 2.6 * TJ>;
  Table(TP)
  #for (K, -1, 1)
    Chair(TP + <0.8 * K, 0, -0.78>, -1, Fabric[TI])
    Chair(TP + <0.8 * K, 0, 0.78>, 1, Fabric[TI])
  #end
#end #end

#debug concat("conference.pov: ", str(Triangles, 0, 0), " triangles\n")

// four point lights just below the ceiling, one over each table, each a
// cosine (tightness 1) spotlight pointing down as ceiling lamps light a room
// (the way scenes/cbox.pov's light is made), falling off with the square of
// the distance
#for (TI, 0, 1) #for (TJ, 0, 1)
  #declare LP = <3.5 + 5 * TI, 2.9, 2.7 + 2.6 * TJ>;
  light_source { LP color rgb <1.0, 0.92, 0.8> * 4
    spotlight radius -90 falloff 90 tightness 1 point_at LP - y
    fade_distance 1 fade_power 2 }
#end #end

camera {
  location <11.3, 1.75, 0.5>
  look_at <4.5, 0.6, 5.0>
  angle 70
}
