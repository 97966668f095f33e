/* gi_cellvis.h - a lock-free cache of one verdict per interpolation cell for
 * the shading hook's light-leak guard (gi_particle_hook.c, side_value).
 *
 * A cell is the sub-triangle of 3 radiance particles that gi_surface_locate
 * returns for a hit. The hook may interpolate a radiance particle only if
 * the hit sees it (gi_visible); instead of 3 occlusion rays per hit,
 * gi_particle tests each cell once and stores here whether it is CLEAR
 * (hits inside it skip their rays) or BLOCKED (they keep the per-hit test).
 * The verdict depends on geometry only (the radiance particles' positions
 * and normals and the objects around them), so it holds across frames,
 * cameras and relighting; a new geometry stage makes a new cache.
 *
 * Keys: the 3 radiance-particle indices sorted, packed into 62 bits: the
 * smallest in b bits (b = the bits of the radiance-particle count), the
 * two others as offsets from it in (62 - b) / 2 bits each (21 bits up to 2^20
 * radiance particles: every cell fits; beyond, a cell whose indices lie
 * further apart gets key 0: not cacheable, tested per hit).
 * The key names the cell exactly (no hashing of the identity), so a
 * verdict is never applied to another cell.
 *
 * Table: open addressing, linear probing, one 64-bit word per slot holding
 * key << 2 | verdict, written once by compare-and-swap. Threads that miss
 * the same cell at the same moment both compute it and store the same
 * verdict (the test is deterministic); the first store wins. When the
 * table is 3/4 full, or a probe run is long, put does nothing and those
 * cells stay per-hit: never wrong, only slower. Internal to gi/. */
#ifndef PT_GI_CELLVIS_H
#define PT_GI_CELLVIS_H
#include <stddef.h>
#include <stdint.h>

typedef struct gi_cellvis gi_cellvis;

enum { GI_CELL_UNKNOWN = 0, GI_CELL_CLEAR = 1, GI_CELL_BLOCKED = 2 };

/* A table of at least `slots` slots (rounded up to a power of two, at least
 * 1024) for cells of radiance particles 0 .. nrp - 1. NULL when out of
 * memory (the caller then tests every hit). */
gi_cellvis *gi_cellvis_new(long slots, long nrp);
void gi_cellvis_free(gi_cellvis *c);
/* The key of the cell with radiance particles rp[0..2] (any order, may
 * repeat), or 0 when it cannot be packed (or c is NULL). */
uint64_t gi_cellvis_key(const gi_cellvis *c, const long rp[3]);
/* The stored verdict, GI_CELL_UNKNOWN when absent (or c NULL, key 0). */
int gi_cellvis_get(const gi_cellvis *c, uint64_t key);
/* Starts loading the slot where key's probe begins (a cache miss, overlapped
 * with others before their gi_cellvis_get). */
void gi_cellvis_prefetch(const gi_cellvis *c, uint64_t key);
/* Stores a verdict (GI_CELL_CLEAR or GI_CELL_BLOCKED) unless the table is
 * full; thread-safe. */
void gi_cellvis_put(gi_cellvis *c, uint64_t key, int verdict);
size_t gi_cellvis_bytes(const gi_cellvis *c);

#endif
