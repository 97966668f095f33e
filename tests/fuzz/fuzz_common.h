/* fuzz_common.h - what the libFuzzer targets share: a check macro, the
 * input size cap and a NUL-terminated copy of the input (fuzz_sdl.h adds the
 * parser's lowered limits).
 *
 * Each target defines LLVMFuzzerTestOneInput and must never crash, leak,
 * hang or allocate without bound on any input (run.sh sets -timeout and
 * -rss_limit_mb; fuzz_sdl.h lowers the parser limits to keep inside them). */
#ifndef PT_FUZZ_COMMON_H
#define PT_FUZZ_COMMON_H
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Inputs longer than this are ignored (run.sh passes -max_len too). */
#define FUZZ_MAX_INPUT (256 * 1024)

/* assert() that stays on in release builds (NDEBUG): a failed check is a
 * finding, reported by libFuzzer like a crash. */
#define FUZZ_CHECK(c)                                                              \
    do {                                                                           \
        if (!(c)) {                                                                \
            fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #c); \
            abort();                                                               \
        }                                                                          \
    } while (0)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* A malloc'd copy of data with `prefix` before and `suffix` after it and a
 * terminating NUL; NULL when out of memory. */
static inline char *fuzz_text(const uint8_t *data, size_t size, const char *prefix, const char *suffix)
{
    size_t lp = prefix ? strlen(prefix) : 0, ls = suffix ? strlen(suffix) : 0;
    char *t = malloc(lp + size + ls + 1);
    if (!t) return NULL;
    if (lp) memcpy(t, prefix, lp);
    if (size) memcpy(t + lp, data, size);
    if (ls) memcpy(t + lp + size, suffix, ls);
    t[lp + size + ls] = 0;
    return t;
}

#endif
