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

/* Members of the record *p written under their own names, in order:
 * STATS_INTS(j, p, a, b) is stats_int(j, "a", p->a) then stats_int(j, "b",
 * p->b); STATS_NUMS the same with stats_num. The _PRE forms take a prefix
 * the members carry and the keys do not: STATS_NUMS_PRE(j, p, t_, a) is
 * stats_num(j, "a", p->t_a). 1 to 16 members a call. */
#define STATS_INTS(j, p, ...) STATS_EACH_(stats_int, long long, j, p, , __VA_ARGS__)
#define STATS_NUMS(j, p, ...) STATS_EACH_(stats_num, double, j, p, , __VA_ARGS__)
#define STATS_INTS_PRE(j, p, pre, ...) STATS_EACH_(stats_int, long long, j, p, pre, __VA_ARGS__)
#define STATS_NUMS_PRE(j, p, pre, ...) STATS_EACH_(stats_num, double, j, p, pre, __VA_ARGS__)

/* The expansion: count the members, then one call per member. */
#define STATS_EACH_(f, T, j, p, pre, ...) \
    do { STATS_CAT_(STATS_E, STATS_COUNT_(__VA_ARGS__))(f, T, j, p, pre, __VA_ARGS__) } while (0)
#define STATS_COUNT_(...) STATS_16TH_(__VA_ARGS__, 16, 15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0)
#define STATS_16TH_(a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, count, ...) count
#define STATS_CAT_(a, b) STATS_CAT2_(a, b)
#define STATS_CAT2_(a, b) a##b##_
#define STATS_ONE_(f, T, j, p, pre, m) f(j, #m, (T)(p)->pre##m);
#define STATS_E1_(f, T, j, p, pre, m) STATS_ONE_(f, T, j, p, pre, m)
#define STATS_E2_(f, T, j, p, pre, m, ...) STATS_ONE_(f, T, j, p, pre, m) STATS_E1_(f, T, j, p, pre, __VA_ARGS__)
#define STATS_E3_(f, T, j, p, pre, m, ...) STATS_ONE_(f, T, j, p, pre, m) STATS_E2_(f, T, j, p, pre, __VA_ARGS__)
#define STATS_E4_(f, T, j, p, pre, m, ...) STATS_ONE_(f, T, j, p, pre, m) STATS_E3_(f, T, j, p, pre, __VA_ARGS__)
#define STATS_E5_(f, T, j, p, pre, m, ...) STATS_ONE_(f, T, j, p, pre, m) STATS_E4_(f, T, j, p, pre, __VA_ARGS__)
#define STATS_E6_(f, T, j, p, pre, m, ...) STATS_ONE_(f, T, j, p, pre, m) STATS_E5_(f, T, j, p, pre, __VA_ARGS__)
#define STATS_E7_(f, T, j, p, pre, m, ...) STATS_ONE_(f, T, j, p, pre, m) STATS_E6_(f, T, j, p, pre, __VA_ARGS__)
#define STATS_E8_(f, T, j, p, pre, m, ...) STATS_ONE_(f, T, j, p, pre, m) STATS_E7_(f, T, j, p, pre, __VA_ARGS__)
#define STATS_E9_(f, T, j, p, pre, m, ...) STATS_ONE_(f, T, j, p, pre, m) STATS_E8_(f, T, j, p, pre, __VA_ARGS__)
#define STATS_E10_(f, T, j, p, pre, m, ...) STATS_ONE_(f, T, j, p, pre, m) STATS_E9_(f, T, j, p, pre, __VA_ARGS__)
#define STATS_E11_(f, T, j, p, pre, m, ...) STATS_ONE_(f, T, j, p, pre, m) STATS_E10_(f, T, j, p, pre, __VA_ARGS__)
#define STATS_E12_(f, T, j, p, pre, m, ...) STATS_ONE_(f, T, j, p, pre, m) STATS_E11_(f, T, j, p, pre, __VA_ARGS__)
#define STATS_E13_(f, T, j, p, pre, m, ...) STATS_ONE_(f, T, j, p, pre, m) STATS_E12_(f, T, j, p, pre, __VA_ARGS__)
#define STATS_E14_(f, T, j, p, pre, m, ...) STATS_ONE_(f, T, j, p, pre, m) STATS_E13_(f, T, j, p, pre, __VA_ARGS__)
#define STATS_E15_(f, T, j, p, pre, m, ...) STATS_ONE_(f, T, j, p, pre, m) STATS_E14_(f, T, j, p, pre, __VA_ARGS__)
#define STATS_E16_(f, T, j, p, pre, m, ...) STATS_ONE_(f, T, j, p, pre, m) STATS_E15_(f, T, j, p, pre, __VA_ARGS__)

#endif
