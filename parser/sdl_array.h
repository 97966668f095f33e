/* sdl_array.h - POV-Ray 3.7 arrays.
 *
 * An array has 1 to 5 dimensions fixed at declaration and holds values of
 * one type: the first element assigned fixes it (floats, 2-, 3- and 4-term
 * vectors and colours are distinct types, as in POV-Ray 3.7.0, which has no
 * `mixed` arrays). Elements start uninitialised. An array identifier
 * followed by '[' is turned into the element by the token stream, so an
 * element can stand wherever an identifier of its type can. Assigning an
 * array (#declare B = A) copies it; passing it to a macro passes it by
 * reference. The array value lives in the scene arena. */
#ifndef PT_SDL_ARRAY_H
#define PT_SDL_ARRAY_H
#include "sdl_parse.h"

#define SDL_ARRAY_MAX_DIMS 5

typedef struct sdl_array {
    int ndims;
    int sizes[SDL_ARRAY_MAX_DIMS];
    long total;
    sdl_val_kind kind;   /* element type, VAL_NONE until an element is set */
    int dim;             /* terms of float/vector/colour elements */
    sdl_value *elems;    /* `total` values in row-major order; VAL_NONE = unset */
    src_loc loc;
} sdl_array;

/* array := 'array' '[' size ']' { '[' size ']' } [ initialiser ]  (after 'array') */
sdl_array *sdl_parse_array(sdl_parser *p, src_loc loc);
/* The subscripts after an array identifier: '[' i ']' for each dimension.
 * Returns the element's index, -1 after an error. */
long sdl_array_subscripts(sdl_parser *p, const sdl_array *a, src_loc loc);
/* Token-stream hook: t is an identifier whose value is an array. If '['
 * follows (looked at without reading tokens), read the subscripts and make
 * t the element (error if it is uninitialised). */
void sdl_array_resolve(sdl_parser *p, sdl_tok *t);
/* Store v in element i with POV-Ray's same-type rule. */
void sdl_array_set(sdl_parser *p, sdl_array *a, long i, const sdl_value *v, src_loc loc);
/* Deep copy (nested arrays copied too). */
sdl_array *sdl_array_copy(sdl_parser *p, const sdl_array *a);
/* defined_param := '(' identifier { '[' float ']' } ')' for #ifdef, #ifndef
 * and defined(): 1 if the identifier is declared (an element: initialised). */
int sdl_defined_param(sdl_parser *p);

#endif
