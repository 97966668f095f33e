// A box of scattering media (isotropic, extinction 0) that is a photon
// target, lit along x by a point light at distance 100: with Photons=1 the
// global photons block asks for media photons (media 100), and the box's
// photon shadow leaves the light inside it to them; with Photons=0 the
// light is direct. A POV-Ray light does not fall off, so a view ray across
// the box (4 long) sees Scat x 4 either way (bench/caustic_media.sh).
#version 3.7;
#ifndef (Photons) #declare Photons = 1; #end
#ifndef (Scat) #declare Scat = 0.1; #end
global_settings { assumed_gamma 1 #if (Photons) photons { spacing 0.05 media 100 } #end }
camera { location <0, 0, -10> look_at 0 angle 30 }
light_source { <-101, 0, 0> color rgb 1 }
box { <-1, -1, -2>, <1, 1, 2> hollow pigment { rgbf 1 }
    interior { media { scattering { 1, rgb Scat extinction 0 } method 3 intervals 1 samples 4 } }
    photons { target refraction on } }
