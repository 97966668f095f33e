/* grow.h - growable arrays: the one doubling rule every builder uses for
 * arrays it appends to. The checks are inline (appends run in inner
 * loops); only a growth calls out. And the arrays a structure owns, freed
 * together (GROW_FREE_ALL). */
#ifndef PT_GROW_H
#define PT_GROW_H
#include <limits.h>
#include <stddef.h>

/* The capacity a growth makes for `need` elements from capacity `cap`:
 * cap (16 when 0) doubled until it holds need. */
size_t grow_capacity(size_t cap, size_t need);
/* Reallocates *p (of *cap elements of elem bytes; NULL with *cap 0 at
 * first) to grow_capacity(*cap, need) elements. 1 on success; 0 when
 * memory runs out (then *p and *cap are as they were). */
int grow_realloc(void **p, size_t *cap, size_t need, size_t elem);

/* Makes *p hold at least `need` elements (grow_realloc when it is
 * smaller); 1 on success, 0 when memory runs out. */
static inline int grow_array(void **p, size_t *cap, size_t need, size_t elem)
{
    return need <= *cap || grow_realloc(p, cap, need, elem);
}

/* grow_array for an int or long capacity and count (need >= 0); a
 * capacity past the type's range is recorded as its maximum, never more
 * than what is allocated. */
static inline int grow_array_int(void **p, int *cap, int need, size_t elem)
{
    if (need <= *cap) return 1;
    size_t c = *cap > 0 ? (size_t)*cap : 0;
    if (!grow_realloc(p, &c, (size_t)need, elem)) return 0;
    *cap = c > (size_t)INT_MAX ? INT_MAX : (int)c;
    return 1;
}

static inline int grow_array_long(void **p, long *cap, long need, size_t elem)
{
    if (need <= *cap) return 1;
    size_t c = *cap > 0 ? (size_t)*cap : 0;
    if (!grow_realloc(p, &c, (size_t)need, elem)) return 0;
    *cap = c > (size_t)LONG_MAX ? LONG_MAX : (long)c;
    return 1;
}

/* Frees each of the n blocks (free(NULL) does nothing): the arrays a
 * structure owns, freed in one call. */
void grow_free_all(void *const *blocks, size_t n);
/* grow_free_all over the pointers listed: GROW_FREE_ALL(s->a, s->b, ...).
 * Each is converted to void * as an initialiser (any object pointer). */
#define GROW_FREE_ALL(...) \
    grow_free_all((void *const[]){__VA_ARGS__}, sizeof((void *const[]){__VA_ARGS__}) / sizeof(void *))

#endif
