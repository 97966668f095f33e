// coplanar_tie.pov - glassthing.pov's contact of glass and floor: a clear
// glass box (ior 1.5, no reflection) standing on the floor of a closed room
// cylinder, its bottom face in the floor's plane. The floor (the room's
// bottom cap) is pure red, the rest of the room green, both self-lit; below
// the floor there is nothing (black). A ray inside the glass that meets the
// bottom face leaves the room (black) or, at a grazing angle, is totally
// reflected (green); one that meets the floor there shows red.
// View 0 looks down through the box's top, view 1 into its long side; Lift
// raises the box off the floor (0: standing on it; below 0, sunk into it).
#version 3.7;
#ifndef (View) #declare View = 0; #end
#ifndef (Lift) #declare Lift = 0; #end
global_settings { assumed_gamma 1.0 max_trace_level 25 }
#if (View = 0)
camera { location <1, 8, 2> look_at <0, 0, 0> angle 30 right x*image_width/image_height }
#else
camera { location <8, 2, 6> look_at <0, 0.5, 0> angle 30 right x*image_width/image_height }
#end
cylinder {
  0*y, 9*y, 30
  texture {
    // red on the floor under the box, green elsewhere
    pigment { object { box { <-3.001, -1, -0.601>, <3.001, 0.0005, 0.601> } rgb <0, 1, 0>, rgb <1, 0, 0> } }
    finish { ambient 1 diffuse 0 }
  }
  hollow on
}
box {
  <-3, 0, -0.6>, <3, 2.4, 0.6>
  pigment { rgbf <1, 1, 1, 1> }
  finish { ambient 0 diffuse 0 }
  interior { ior 1.5 }
  translate Lift*y
}
