// The long bar of glassthing.pov's glass alone (its box, 6 x 2.4 x 1.2,
// 0.01 above the floor, not on it: no coplanar tie), under glassthing's
// light, seen from straight above (bench/caustic_bar.sh).
//   View 0: the floor in the bar's shadow, lit by photons through its long
//           faces;
//   View 1: the floor beyond the bar's far end, with the bar's top and long
//           faces covered, lit by the light that enters the end facing the
//           light and leaves the other end after total reflections (a light
//           pipe); Block = 1 covers the entering end too.
// Photons: Photons = 0 removes the global block.
#version 3.7;
#ifndef (View) #declare View = 0; #end
#ifndef (Block) #declare Block = 0; #end
#ifndef (Photons) #declare Photons = 1; #end
#ifndef (Spacing) #declare Spacing = 0.05; #end
global_settings {
  assumed_gamma 1.0
  max_trace_level 25
  #if (Photons) photons { spacing Spacing autostop 0 jitter 0 } #end
}
#if (View = 0)
camera { orthographic location <-1.5, 8, -3> sky z look_at <-1.5, 0, -3> right x*2 up z*1.5 }
#else
camera { orthographic location <5, 8, -2.5> sky z look_at <5, 0, -2.5> right x*4 up z*3 }
#end
light_source {
  <-10, 7, 18> color rgb <1.3, 1.2, 1.1>
  fade_power 2 fade_distance 45
  photons { reflection on refraction on }
}
cylinder {
  0, 9 * y, 30
  texture { pigment { rgb <0.98, 0.96, 0.90> } finish { diffuse 0.7 brilliance 0.6 } }
  hollow on
}
box {
  <-3, 0.01, -0.6>, <3, 2.4, 0.6>
  material {
    texture {
      pigment { rgbf <1, 1, 1, 1> }
      finish { specular 0.6 roughness 0.002 ambient 0 diffuse 0.1 brilliance 5
               reflection { 0.1, 1.0 fresnel on } conserve_energy }
    }
    interior { ior 1.5 fade_distance 2 fade_power 1001 fade_color <0.35, 0.65, 0.85> }
  }
  photons { target reflection on refraction on collect off }
}
#if (View = 1)
union {
  box { <-3.1, 2.5, -0.8>, <3.1, 2.55, 0.8> }
  box { <-3.1, 0.02, 0.7>, <3.1, 2.55, 0.75> }
  box { <-3.1, 0.02, -0.75>, <3.1, 2.55, -0.7> }
  #if (Block) box { <-3.2, 0.02, -0.8>, <-3.05, 2.6, 0.8> } #end
  pigment { rgb 0 } finish { ambient 0 diffuse 0 }
}
#end
