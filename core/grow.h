/* grow.h - growable arrays: the one doubling rule every builder uses for
 * arrays it appends to. */
#ifndef PT_GROW_H
#define PT_GROW_H
#include <stddef.h>

/* The capacity grow_array makes for `need` elements from capacity `cap`:
 * cap (16 when 0) doubled until it holds need. */
size_t grow_capacity(size_t cap, size_t need);
/* Makes *p (of *cap elements of elem bytes; NULL with *cap 0 at first)
 * hold at least `need`: reallocated to grow_capacity(*cap, need) when it
 * is smaller. 1 on success; 0 when memory runs out (then *p and *cap are
 * as they were). */
int grow_array(void **p, size_t *cap, size_t need, size_t elem);
/* grow_array for an int capacity and count (need >= 0). */
int grow_array_int(void **p, int *cap, int need, size_t elem);

#endif
