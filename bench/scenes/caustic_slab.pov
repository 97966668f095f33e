// A wide slab of glassthing.pov's glass (F_Glass6: fresnel reflection
// {0.1, 1.0} with conserve_energy; ior 1.5) over a white floor, one point
// light Angle degrees from the normal; the camera, under the slab, sees only
// floor that the light reaches through the slab. Slab=0 leaves the slab out
// (the unobstructed light). bench/caustic_slab.sh renders it.
#version 3.7;
#ifndef (Slab) #declare Slab = 1; #end
#ifndef (Conserve) #declare Conserve = 1; #end
#ifndef (Angle) #declare Angle = 71; #end
#ifndef (Bril) #declare Bril = 1; #end
global_settings {
  assumed_gamma 1.0
  max_trace_level 25
  ambient_light 0
  photons { spacing 0.05 autostop 0 jitter 0 }
}
camera { location <-14, 2.5, -5> look_at <-14, 0, -4.5> angle 60 right x*4/3 }
light_source {
  <100 * sin(radians(Angle)), 100 * cos(radians(Angle)), 0> color rgb 1
  photons { reflection on refraction on }
}
plane { y, 0 pigment { rgb 1 } finish { ambient 0 diffuse 1 brilliance Bril } }
#if (Slab)
box {
  <-30, 3, -15>, <15, 3.5, 15>
  texture {
    pigment { rgbf <1, 1, 1, 1> }
    finish {
      specular 0.6 roughness 0.002 ambient 0 diffuse 0.1 brilliance 5
      reflection { 0.1, 1.0 fresnel on }
      #if (Conserve) conserve_energy #end
    }
  }
  interior { ior 1.5 }
  photons { target reflection on refraction on collect off }
}
#end
