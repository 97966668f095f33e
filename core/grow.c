/* grow.c - growable arrays (see grow.h). */
#include "grow.h"
#include <limits.h>
#include <stdint.h>
#include <stdlib.h>

size_t grow_capacity(size_t cap, size_t need)
{
    size_t nc = cap ? cap : 16;
    while (nc < need) nc *= 2;
    return nc;
}

int grow_array(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap) return 1;
    size_t nc = grow_capacity(*cap, need);
    if (elem > 0 && nc > SIZE_MAX / elem) return 0;
    void *n = realloc(*p, nc * elem);
    if (!n) return 0;
    *p = n;
    *cap = nc;
    return 1;
}

int grow_array_int(void **p, int *cap, int need, size_t elem)
{
    if (need <= *cap) return 1;
    size_t c = *cap > 0 ? (size_t)*cap : 0;
    if (!grow_array(p, &c, (size_t)need, elem)) return 0;
    /* a capacity past INT_MAX is recorded as INT_MAX: never more than
     * what is allocated */
    *cap = c > (size_t)INT_MAX ? INT_MAX : (int)c;
    return 1;
}
