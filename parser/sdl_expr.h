/* sdl_expr.h - float/vector/colour/string expressions (POV-Ray 3.7 rules).
 *
 * Values carry 1..5 terms. A float used where more terms are wanted is
 * copied into every term; a shorter vector is padded with zeros (POV-Ray's
 * promotion). Levels, loosest first:
 *   expression := logical [ '?' expression ':' expression ]
 *   logical    := relation { ('&' | '|') relation }
 *   relation   := sum { ('<' | '<=' | '=' | '!=' | '>=' | '>') sum } | string comparison
 *   sum        := term { ('+' | '-') term }
 *   term       := factor { ('*' | '/') factor }
 *   factor     := primary [ '.' component ]
 * Like POV-Ray, plain float/vector arguments (sdl_float, sdl_vector) are read
 * at the `sum` level; parentheses and directives' conditions use `expression`. */
#ifndef PT_SDL_EXPR_H
#define PT_SDL_EXPR_H
#include "sdl_parse.h"

/* expression: result is VAL_FLOAT (1 term), VAL_VECTOR (2..4) or VAL_COLOUR (5). */
void sdl_expr(sdl_parser *p, sdl_value *out);
/* sum level, any number of terms. */
void sdl_sum(sdl_parser *p, sdl_value *out);
/* A float (error if a vector is found). */
double sdl_float(sdl_parser *p);
/* The float if an expression follows, else `def`. */
double sdl_allow_float(sdl_parser *p, double def);
/* '(' expression ')' giving a float. */
double sdl_float_param(sdl_parser *p);
/* A 3D vector (floats promote). */
vec3 sdl_vector(sdl_parser *p);
/* An n-term vector (n = 2 for uv, 4 for 4D). */
void sdl_vector_n(sdl_parser *p, double *out, int n);
/* colour: POV-Ray's colour syntax. want_ft=1: rgbft (a float fills all five
 * terms); 0: plain rgb (a float fills three). */
colour5 sdl_colour(sdl_parser *p, int want_ft);
rgb sdl_rgb(sdl_parser *p);
/* A string expression; the result lives in the scene arena. */
const char *sdl_string(sdl_parser *p);
/* A string as POV-Ray 3.7 hands it to C (messages, #write): every code point
 * above 127 becomes a space (UCS2_To_String). */
const char *sdl_c_string(sdl_parser *p, const char *s);

/* Token classes (POV-Ray's CASE_EXPRESS, CASE_FLOAT, colour and string starts). */
int sdl_starts_expr(const sdl_tok *t);
int sdl_starts_float(const sdl_tok *t);
int sdl_starts_colour(const sdl_tok *t);
int sdl_starts_string(const sdl_tok *t);
/* The member a `.NAME` after a vector or colour selects: x/u/red 0,
 * y/v/green 1, z/blue 2, t/filter 3, transmit 4, gray 5; -1 for any other
 * token. */
int sdl_component_index(const sdl_tok *t);

/* Truth of a float as POV-Ray tests it (|x| > 1e-10). */
int sdl_true(double x);

#endif
