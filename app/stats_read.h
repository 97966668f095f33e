/* stats_read.h - reading values back from a JSON object such as the
 * `--stats` file of `partray render` (the measuring commands use it for the
 * stage times). Keys are addressed by a dotted path: "timings.total". */
#ifndef PT_STATS_READ_H
#define PT_STATS_READ_H
#include <stddef.h>

/* The number at `path`; 1 when found (a JSON null gives NaN), 0 when the
 * path is missing, is not a number, or the text is not valid JSON. */
int stats_read_num(const char *json, const char *path, double *out);

/* The string at `path` copied (unescaped; \uXXXX outside ASCII becomes '?')
 * into buf; 1 when found. */
int stats_read_str(const char *json, const char *path, char *buf, size_t n);

#endif
