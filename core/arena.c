/* arena.c - bump allocator built from a list of blocks. */
#include "arena.h"
#include <stdlib.h>
#include <string.h>

typedef struct block {
    struct block *next;
    size_t used, cap;
    _Alignas(16) unsigned char data[];
} block;

struct arena {
    block *head;
    size_t total;
};

arena *arena_new(void) { return calloc(1, sizeof(arena)); }

void arena_free(arena *a)
{
    if (!a) return;
    block *b = a->head;
    while (b) {
        block *n = b->next;
        free(b);
        b = n;
    }
    free(a);
}

void *arena_alloc(arena *a, size_t n)
{
    n = (n + 15u) & ~(size_t)15u;
    if (n == 0) n = 16;
    block *b = a->head;
    if (!b || b->cap - b->used < n) {
        size_t cap = n > (size_t)(1u << 20) ? n : (size_t)(1u << 20);
        b = malloc(sizeof(block) + cap);
        if (!b) return NULL;
        b->used = 0;
        b->cap = cap;
        b->next = a->head;
        a->head = b;
        a->total += cap;
    }
    void *p = b->data + b->used;
    b->used += n;
    memset(p, 0, n);
    return p;
}

char *arena_strdup(arena *a, const char *s)
{
    if (!s) return NULL;
    return arena_memdup(a, s, strlen(s) + 1);
}

void *arena_memdup(arena *a, const void *p, size_t n)
{
    void *q = arena_alloc(a, n);
    if (q && n) memcpy(q, p, n);
    return q;
}

size_t arena_bytes(const arena *a) { return a ? a->total : 0; }
