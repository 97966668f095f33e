/* ini.h - POV-Ray 3.7 INI files and INI-style options (Key=value), read
 * into the command-line switches they stand for, as POV-Ray's own front end
 * treats them (an INI option and its switch set the same thing; later ones
 * override earlier ones). Every command that takes render options expands
 * its arguments with ini_expand before parsing them (cli.h). */
#ifndef PT_INI_H
#define PT_INI_H
#include "diag.h"

typedef struct ini_args ini_args;

/* Expands argv (the arguments after the subcommand): every argument naming
 * an INI file (FILE.ini or FILE.ini[Section], any case, not starting with
 * '+' or '-') is replaced by the switches its lines stand for, in the
 * file's order; an argument KEY=VALUE whose KEY is a POV-Ray INI key is
 * read as a one-line INI file. Other arguments are kept as they are.
 * Warnings (a key POV-Ray does not know, an option partray does not use)
 * carry file:line; errors (a bad value, a missing ']') file:line:col.
 * Returns PT_OK with *out set, PT_ERR_IO (an INI file cannot be read) or
 * PT_ERR_USAGE (a bad line); *out is NULL then. */
pt_status ini_expand(int argc, char **argv, ini_args **out, diag *d);
int ini_argc(const ini_args *a);
/* The expanded arguments; they live as long as `a`. */
char **ini_argv(const ini_args *a);
/* An empty argument vector, for building a command line (ini_argv stays
 * NULL-terminated); NULL when out of memory. */
ini_args *ini_args_new(void);
/* Appends a copy of s; 0 when out of memory (a NULL a included). */
int ini_args_push(ini_args *a, const char *s);
void ini_free(ini_args *a);

#endif
