/* diag.h - status codes and a diagnostics context. Deep code returns a status
 * and records messages here; only the app prints. */
#ifndef PT_DIAG_H
#define PT_DIAG_H
#include <stdarg.h>

typedef enum {
    PT_OK = 0,
    PT_ERR_SYNTAX,      /* scene error: exit 1 */
    PT_ERR_LIMIT,       /* a limit (loop count, recursion, size) was hit: exit 1 */
    PT_ERR_UNSUPPORTED, /* the scene asks for something not implemented */
    PT_ERR_IO,          /* file could not be read/written: exit 3 */
    PT_ERR_NOMEM,
    PT_ERR_DEVICE,      /* Embree/OpenCL failure */
    PT_ERR_USAGE,       /* bad command line: exit 2 */
    PT_ERR_INTERNAL,
    PT_CANCELLED /* stopped by the caller's cancel flag (Ctrl-C): not an error */
} pt_status;

const char *pt_status_name(pt_status s);

/* A place in a source file. `file` points at an interned string that lives as
 * long as the scene (or the diag context). line/col are 1-based; 0 = unknown. */
typedef struct {
    const char *file;
    int line, col;
} src_loc;

typedef enum { DIAG_ERROR, DIAG_WARNING, DIAG_NOTE } diag_severity;

typedef struct {
    diag_severity severity;
    src_loc loc;
    char *text;  /* message; may hold several lines (include/macro chain) */
} diag_msg;

typedef struct diag diag;

diag *diag_new(void);
void diag_free(diag *d);
/* Record a message. `chain` (may be NULL) is appended verbatim on the following
 * lines, e.g. "  included from a.pov:3:1". */
void diag_report(diag *d, diag_severity sev, src_loc loc, const char *chain, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;
void diag_vreport(diag *d, diag_severity sev, src_loc loc, const char *chain, const char *fmt, va_list ap);
/* Report a warning only once per distinct text (e.g. "unsupported shape: lathe"). */
void diag_warn_once(diag *d, src_loc loc, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* An error with no source location (files, devices, arguments). */
void diag_error(diag *d, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* A sink sees each message as it is recorded, on the reporting thread (the
 * app prints a scene's #debug text while the parse runs); fn NULL removes
 * it. The message stays in the context as before. */
typedef void (*diag_sink_fn)(void *ctx, const diag_msg *m);
void diag_set_sink(diag *d, diag_sink_fn fn, void *ctx);
int diag_count(const diag *d);
int diag_errors(const diag *d);
const diag_msg *diag_get(const diag *d, int i);
/* Format one message as "file:line:col: error: text" into a malloc'd string. */
char *diag_format(const diag_msg *m);
/* Intern a file name so src_loc.file stays valid while the diag lives. */
const char *diag_intern(diag *d, const char *s);

#endif
