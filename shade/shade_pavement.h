/* shade_pavement.h - POV-Ray 3.7's `pavement` pattern: the x-z plane
 * paved with polyiamonds, polyominoes or polyhexes (y is ignored); 0 inside
 * a tile rising to 1 at the grout between tiles. */
#ifndef PT_SHADE_PAVEMENT_H
#define PT_SHADE_PAVEMENT_H
#include "vec.h"

typedef struct {
    int sides;    /* number_of_sides: 4 squares, 6 hexagons, else triangles */
    int tiles;    /* number_of_tiles: cells per tile, 1..6 (5 for hexagons) */
    int number;   /* pattern: which paving, from 1 */
    int exterior; /* convex corners: 0 sharp, 1 cut, 2 rounded */
    int interior; /* concave corners: 0 sharp, 1 cut, 2 rounded */
    int form;     /* turning cells: 0 sharp, 1 cut, 2 rounded, 3 none */
} shade_pavement_params;

/* Value of the pavement at p, in [0, 1]; 0 for a pattern number that does
 * not exist for the sides and tiles given (the parser reports those). */
double shade_pavement_value(const shade_pavement_params *pv, vec3 p);

#endif
