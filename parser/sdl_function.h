/* sdl_function.h - user functions (function { ... }) and splines
 * (spline { ... }): parsed into core/func.h and core/spline.h records, and
 * called from SDL expressions.
 *
 * Function bodies use POV-Ray 3.7's function syntax: | & comparisons + - * /
 * unary + -, parentheses, numbers, parameters (x y z by default; u and v
 * stand for x and y), declared float constants (folded in), vector and
 * colour constants with a member (.x ... .gray), the built-ins abs acos
 * acosh asin asinh atan atan2 atanh ceil cos cosh degrees div exp floor int
 * ln log max min mod pow prod radians select sin sinh sqrt sum tan tanh
 * (not sqr, true or false, which 3.7 rejects there), pi and clock, and calls
 * of declared functions (vector functions with a member). `internal(N)` as
 * the whole body is POV-Ray's built-in N. */
#ifndef PT_SDL_FUNCTION_H
#define PT_SDL_FUNCTION_H
#include "func.h"
#include "sdl_parse.h"
#include "uspline.h"

/* function := 'function' [ '(' identifier { ',' identifier } ')' ]
 *             '{' ( expression | 'internal' '(' N ')' | transform | spline |
 *                   pigment | pattern ) '}'          (after 'function') */
scene_function *sdl_parse_function(sdl_parser *p, src_loc loc, const char *name);
/* spline := 'spline' '{' [ spline_identifier ] { uspline_kind } { float [','] vector [','] } '}'
 * (after 'spline') */
user_spline *sdl_parse_spline(sdl_parser *p, src_loc loc);

/* call := function_identifier '(' float { ',' float } ')' : the function's
 * result (f->nterms values) into out. The identifier has been read. */
void sdl_call_function(sdl_parser *p, const sdl_tok *id, double out[5]);
/* spline_call := spline_identifier '(' float [ ',' uspline_kind ] ')' ;
 * s->terms values into out. The identifier has been read. */
void sdl_call_spline(sdl_parser *p, const sdl_tok *id, double out[5]);

#endif
