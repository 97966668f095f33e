// Reproduces a particle-GI weakness seen on maze.pov and conference.pov
// (docs/gi.md, Known weaknesses): the front of a thin wall lit only
// indirectly is smooth as 2 triangles per face (-D N=1) and speckled with
// dark spots as 80 x 40 cells per face (default N=40, triangles smaller than
// the particle spacing). partray render scenes/gi_fine_mesh.pov [-D N=1]
#version 3.7;
global_settings { assumed_gamma 1.0 radiosity { count 40 } }
#ifndef (N) #declare N = 40; #end
camera { location <2, 1.5, -3.5> look_at <0, 0.7, 0> angle 60 }
light_source { <-1.5, 2.5, 1.5> color rgb 3 fade_distance 1 fade_power 2 }
#macro Q(A, B, C, D, NU, NV)
  mesh2 { vertex_vectors { (NU+1)*(NV+1), #for (J,0,NV) #for (I,0,NU) #local U=I/NU; #local W=J/NV; (1-W)*((1-U)*A+U*B)+W*((1-U)*D+U*C), #end #end }
    face_indices { 2*NU*NV, #for (J,0,NV-1) #for (I,0,NU-1) #local K=J*(NU+1)+I; <K,K+1,K+NU+2>, <K,K+NU+2,K+NU+1>, #end #end }
    pigment { rgb 0.7 } finish { ambient 0 diffuse 0.8 } }
#end
// floor (coarse)
Q(<-4,0,-4>,<4,0,-4>,<4,0,4>,<-4,0,4>, 8, 8)
// a wall facing the camera, in shadow of itself (light behind it): its front lit only indirectly
Q(<-1.5,0,0>,<1.5,0,0>,<1.5,1.5,0>,<-1.5,1.5,0>, 2*N, N)
Q(<-1.5,0,0.2>,<1.5,0,0.2>,<1.5,1.5,0.2>,<-1.5,1.5,0.2>, 2*N, N)
