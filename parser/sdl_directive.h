/* sdl_directive.h - the token stream the grammar reads.
 *
 * Tokens come from a stack of inputs (the scene file, included files, macro
 * bodies). '#' directives run here as they are met: #version, #declare,
 * #local, #undef, #if/#ifdef/#ifndef/#elseif/#else/#end, #while, #for,
 * #switch/#case/#range/#break, #include, #macro (and macro calls),
 * #debug/#warning/#error, #default. Skipped branches never reach the grammar. */
#ifndef PT_SDL_DIRECTIVE_H
#define PT_SDL_DIRECTIVE_H
#include "sdl_parse.h"

/* Next token (end-of-file forever once an error was recorded). */
sdl_tok sdl_next(sdl_parser *p);
/* The token sdl_next would return, without consuming it. */
const sdl_tok *sdl_peek(sdl_parser *p);
/* Push a token back (at most 4 deep). */
void sdl_unget(sdl_parser *p, const sdl_tok *t);
/* Is the next token of kind k? Looked at in the raw text (or the pushed-back
 * tokens), so no directive or macro runs: POV-Ray's check for '[' after an
 * array identifier. */
int sdl_raw_next_is(sdl_parser *p, sdl_tok_kind k);

/* Start reading a file (path as given) or a string (text != NULL). */
pt_status sdl_open_main(sdl_parser *p, const char *path, const char *text);
/* Release inputs (sources, frames, conditionals). */
void sdl_close_inputs(sdl_parser *p);
/* After the last token: report conditionals left open. */
void sdl_check_closed(sdl_parser *p);

/* rvalue := expression | string | colour | texture/pigment/finish/normal/
 *           interior/material/camera/light_source/transform/object statement |
 *           identifier ; used by #declare, #local and macro arguments. */
void sdl_rvalue(sdl_parser *p, sdl_value *out);

/* The include/macro chain for messages ("  included from a.pov:3:1\n..."),
 * malloc'd; NULL when reading the main file. */
char *sdl_chain(const sdl_parser *p);

/* 1 if an include-style search finds the file. */
int sdl_file_exists(sdl_parser *p, const char *name);

#endif
