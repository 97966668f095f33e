// scenes/cbox.pov with a moving object for bench/motion.sh: a white sphere
// floats across the room in front of the blocks, from the green wall
// towards the red one, as the clock runs 0..1; the room, its light and
// everything else stay still.
#include "../../scenes/cbox.pov"
sphere { <8 + 40 * clock, 12, 1>, 4 texture { White } }
