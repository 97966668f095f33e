/* shade_tiling.h - POV-Ray 3.7's `tiling N` pattern: periodic tilings of
 * the x-z plane (y is ignored). Each tile kind k of a tiling with n kinds
 * takes the value range [k/n, (k+1)/n]: the tile's centre at k/n rising to
 * (k+1)/n at its edges, so a colour_map can colour tiles and grout. */
#ifndef PT_SHADE_TILING_H
#define PT_SHADE_TILING_H
#include "vec.h"

/* Value of tiling n at p, in [0, 1]. */
double shade_tiling_value(int n, vec3 p);

#endif
