/* gi_cellvis.c - lock-free cell verdict cache (see gi_cellvis.h). */
#include "gi_cellvis.h"
#include "hash.h"
#include <stdatomic.h>
#include <stdlib.h>

#define CELLVIS_PROBES 32 /* longest probe run before giving up (get and put) */

struct gi_cellvis {
    _Atomic uint64_t *slot;
    uint64_t mask;
    long limit;       /* put stops storing past this count (3/4 of the slots) */
    int base_bits, off_bits; /* key layout (gi_cellvis.h) */
    atomic_long count;
};

gi_cellvis *gi_cellvis_new(long slots, long nrp)
{
    int b = 1;
    while (b < 60 && (1L << b) < nrp) b++;
    uint64_t n = 1024;
    while ((long)n < slots && n < ((uint64_t)1 << 40)) n <<= 1;
    gi_cellvis *c = malloc(sizeof *c);
    if (!c) return NULL;
    c->slot = calloc((size_t)n, sizeof *c->slot);
    if (!c->slot) {
        free(c);
        return NULL;
    }
    for (uint64_t i = 0; i < n; i++) atomic_init(&c->slot[i], 0);
    c->mask = n - 1;
    c->limit = (long)(n / 4 * 3);
    c->base_bits = b;
    c->off_bits = (62 - b) / 2;
    atomic_init(&c->count, 0);
    return c;
}

void gi_cellvis_free(gi_cellvis *c)
{
    if (!c) return;
    free((void *)c->slot);
    free(c);
}

uint64_t gi_cellvis_key(const gi_cellvis *c, const long rp[3])
{
    if (!c) return 0;
    long a = rp[0], b = rp[1], d = rp[2], t;
    if (a > b) t = a, a = b, b = t;
    if (b > d) t = b, b = d, d = t;
    if (a > b) t = a, a = b, b = t;
    int ob = c->off_bits;
    if (a < 0 || a >= (1L << c->base_bits) || b - a >= (1L << ob) || d - a >= (1L << ob)) return 0;
    /* 0 only for the degenerate cell (0, 0, 0): not cached */
    return (uint64_t)a << (2 * ob) | (uint64_t)(b - a) << ob | (uint64_t)(d - a);
}

int gi_cellvis_get(const gi_cellvis *c, uint64_t key)
{
    if (!c || !key) return GI_CELL_UNKNOWN;
    uint64_t h = pt_mix64(key);
    for (int k = 0; k < CELLVIS_PROBES; k++) {
        uint64_t v = atomic_load_explicit(&c->slot[(h + (uint64_t)k) & c->mask], memory_order_relaxed);
        if (v == 0) return GI_CELL_UNKNOWN;
        if (v >> 2 == key) return (int)(v & 3u);
    }
    return GI_CELL_UNKNOWN;
}

void gi_cellvis_prefetch(const gi_cellvis *c, uint64_t key)
{
    if (c && key) __builtin_prefetch((const void *)&c->slot[pt_mix64(key) & c->mask]);
}

void gi_cellvis_put(gi_cellvis *c, uint64_t key, int verdict)
{
    if (!c || !key || (verdict != GI_CELL_CLEAR && verdict != GI_CELL_BLOCKED)) return;
    if (atomic_load_explicit(&c->count, memory_order_relaxed) >= c->limit) return;
    uint64_t h = pt_mix64(key), want = key << 2 | (uint64_t)verdict;
    for (int k = 0; k < CELLVIS_PROBES; k++) {
        _Atomic uint64_t *s = &c->slot[(h + (uint64_t)k) & c->mask];
        uint64_t v = atomic_load_explicit(s, memory_order_relaxed);
        if (v == 0) {
            if (atomic_compare_exchange_strong_explicit(s, &v, want, memory_order_relaxed, memory_order_relaxed)) {
                atomic_fetch_add_explicit(&c->count, 1, memory_order_relaxed);
                return;
            }
            /* v now holds what another thread stored there */
        }
        if (v >> 2 == key) return; /* stored already (the same verdict: the test is deterministic) */
    }
}

size_t gi_cellvis_bytes(const gi_cellvis *c) { return c ? sizeof *c + (size_t)(c->mask + 1) * sizeof(uint64_t) : 0; }
