/* sdl_file.h - user files: #fopen, #fclose, #read, #write (POV-Ray 3.7).
 *
 * Names are relative to the scene file's directory (POV-Ray reads and
 * writes relative to its working directory, which is the scene's when it
 * renders a scene). Files are read from there, then the include path.
 * Writing is confined like POV-Ray's default I/O restriction: the file must
 * lie in the scene's directory or the current directory (or below), else a
 * located error; sdl_options.write_dir redirects every written file into
 * one directory (tests, sweeps over read-only example trees), which is then
 * also searched first for files to read.
 *
 * #read declares new identifiers globally and stops at the end of the file:
 * the identifiers not yet read keep their values and the file identifier
 * becomes undefined, so `#while (defined(F))` loops end. #write writes
 * strings as they are, floats with %g, vectors as <a,b,c> followed by a
 * space, and the binary forms sint8 ... uint16le. */
#ifndef PT_SDL_FILE_H
#define PT_SDL_FILE_H
#include "sdl_parse.h"

/* fopen := '#fopen' identifier string ( 'read' | 'write' | 'append' ) */
void sdl_fopen_directive(sdl_parser *p, src_loc loc);
/* fclose := '#fclose' identifier */
void sdl_fclose_directive(sdl_parser *p, src_loc loc);
/* read := '#read' '(' file_identifier { ',' identifier } ')' */
void sdl_read_directive(sdl_parser *p, src_loc loc);
/* write := '#write' '(' file_identifier { ',' write_item } ')' */
void sdl_write_directive(sdl_parser *p, src_loc loc);
/* Close every file still open (end of the parse). */
void sdl_files_close(sdl_parser *p);

#endif
