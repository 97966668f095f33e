/* stats_json.h - a tiny JSON object writer for --stats and --json output. */
#ifndef PT_STATS_JSON_H
#define PT_STATS_JSON_H
#include <stdio.h>

typedef struct {
    char *buf;
    size_t len, cap;
    int depth;
    int first[16];
} stats_json;

void stats_begin(stats_json *j);
void stats_obj_begin(stats_json *j, const char *key);
void stats_obj_end(stats_json *j);
void stats_num(stats_json *j, const char *key, double v); /* non-finite -> null */
void stats_int(stats_json *j, const char *key, long long v);
void stats_str(stats_json *j, const char *key, const char *v);
/* Closes the object; returns the text (owned by j; freed by stats_free). */
const char *stats_end(stats_json *j);
/* stats_end + write to path through a temporary file; 1 on success. */
int stats_write(stats_json *j, const char *path);
void stats_free(stats_json *j);

#endif
