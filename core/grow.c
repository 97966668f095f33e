/* grow.c - growable arrays (see grow.h). */
#include "grow.h"
#include <stdint.h>
#include <stdlib.h>

size_t grow_capacity(size_t cap, size_t need)
{
    size_t nc = cap ? cap : 16;
    while (nc < need) nc *= 2;
    return nc;
}

void grow_free_all(void *const *blocks, size_t n)
{
    for (size_t i = 0; i < n; i++) free(blocks[i]);
}

int grow_realloc(void **p, size_t *cap, size_t need, size_t elem)
{
    size_t nc = grow_capacity(*cap, need);
    if (elem > 0 && nc > SIZE_MAX / elem) return 0;
    void *n = realloc(*p, nc * elem);
    if (!n) return 0;
    *p = n;
    *cap = nc;
    return 1;
}
