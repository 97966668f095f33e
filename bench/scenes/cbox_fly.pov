// A camera fly-through of scenes/cbox.pov for bench/anim.sh: the room, its
// light and its GI are the same in every frame, only the camera moves (the
// later camera{} replaces cbox.pov's, as in POV-Ray), so an animation in one
// run builds the GI geometry stage once.
#include "../../scenes/cbox.pov"
camera {
  location  <27.8 + 10 * sin(clock * 2 * pi), 27.3 + 4 * clock, -80.0 + 20 * clock>
  direction <0, 0, 1>
  up        <0, 1, 0>
  right     <-1, 0, 0>
  look_at   <27.8, 25, 28>
  angle 39.3
}
