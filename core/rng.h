/* rng.h - PCG32 random numbers (O'Neill 2014, pcg32 XSH-RR variant). */
#ifndef PT_RNG_H
#define PT_RNG_H
#include <stdint.h>

typedef struct { uint64_t state, inc; } rng;

static inline uint32_t rng_u32(rng *r)
{
    uint64_t old = r->state;
    r->state = old * 6364136223846793005ULL + r->inc;
    uint32_t xs = (uint32_t)(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = (uint32_t)(old >> 59u);
    return (xs >> rot) | (xs << ((-rot) & 31));
}
static inline void rng_seed(rng *r, uint64_t seed, uint64_t stream)
{
    r->state = 0u;
    r->inc = (stream << 1u) | 1u;
    rng_u32(r);
    r->state += seed;
    rng_u32(r);
}
/* Uniform in [0, 1). */
static inline double rng_f64(rng *r) { return (rng_u32(r) >> 8) * (1.0 / 16777216.0); }

#endif
