/* arena.h - bump allocator; everything in a scene IR lives in one arena. */
#ifndef PT_ARENA_H
#define PT_ARENA_H
#include <stddef.h>

typedef struct arena arena;

arena *arena_new(void);
void arena_free(arena *a);
/* Zeroed, 16-byte aligned; NULL on out-of-memory. */
void *arena_alloc(arena *a, size_t n);
char *arena_strdup(arena *a, const char *s);
void *arena_memdup(arena *a, const void *p, size_t n);
size_t arena_bytes(const arena *a);

#endif
