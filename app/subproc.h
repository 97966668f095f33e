/* subproc.h - running child programs for the measuring commands (`partray
 * sweep`, `partray crosscheck`): this binary again (render), or POV-Ray. */
#ifndef PT_SUBPROC_H
#define PT_SUBPROC_H
#include <stddef.h>
#include "diag.h"

/* Runs argv[0] (a path, or a name looked up on PATH) with the NULL-terminated
 * argv, in directory `cwd` (NULL = the current one), with stdin from
 * /dev/null and stdout + stderr appended to `log_path` (NULL = inherited),
 * and waits for it. Returns its exit status (0..255), 128 + N when killed by
 * signal N, or -1 when it could not be started (a message goes into d).
 * *seconds (may be NULL) receives the wall-clock time. */
int subproc_run(const char *const *argv, const char *cwd, const char *log_path, double *seconds, diag *d);

/* Sends `sig` to the child subproc_run is waiting for, if any (safe to
 * call from a signal handler). */
void subproc_forward_signal(int sig);

/* The path of the running executable ("/proc/self/exe" resolved), written
 * into buf; 0 when it cannot be found. */
int subproc_self_exe(char *buf, size_t n);

/* Looks `name` up on PATH (or takes it as given when it holds a '/');
 * writes the path of an executable file into buf and returns 1, else 0. */
int subproc_find_program(const char *name, char *buf, size_t n);

/* A whole file as a NUL-terminated malloc'd string (NULL if unreadable). */
char *subproc_read_text(const char *path, size_t *len);

/* Creates directory `path` and its missing parents (mode 0777 & ~umask);
 * 1 on success or when it exists. */
int subproc_mkdirs(const char *path);

#endif
