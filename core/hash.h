/* hash.h - integer and pointer hashes for open-addressing tables, and the
 * one byte-string hash (FNV-1a 64) for keys of files and settings. */
#ifndef PT_HASH_H
#define PT_HASH_H
#include <stddef.h>
#include <stdint.h>

/* 32 bits of a pointer, mixed: the first half of MurmurHash3's 64-bit
 * finalizer (fmix64: xor-shift 33, multiply by 0xff51afd7ed558ccd,
 * xor-shift 33; Appleby, MurmurHash3). Mask the low bits for a table. */
static inline unsigned pt_ptr_hash(const void *p)
{
    uint64_t v = (uint64_t)(uintptr_t)p;
    v ^= v >> 33;
    v *= 0xff51afd7ed558ccdULL;
    v ^= v >> 33;
    return (unsigned)v;
}

/* A 64-bit mix with full avalanche: SplitMix64's output function (Steele,
 * Lea and Flood, "Fast Splittable Pseudorandom Number Generators", OOPSLA
 * 2014; the shifts and multipliers of Vigna's splitmix64.c). */
static inline uint64_t pt_mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/* FNV-1a 64 (Fowler, Noll and Vo: offset basis 0xcbf29ce484222325, prime
 * 0x100000001b3) of n bytes, continuing from h (PT_FNV1A_BASIS to start). */
#define PT_FNV1A_BASIS 0xcbf29ce484222325ULL
static inline uint64_t pt_fnv1a(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++) h = (h ^ b[i]) * 0x100000001b3ULL;
    return h;
}

#endif
