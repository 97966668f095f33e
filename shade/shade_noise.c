/* shade_noise.c - POV-Ray 3.7 noise, reproduced (see shade_noise.h).
 *
 * What is reproduced (semantics studied in POV-Ray 3.7's texture.cpp,
 * pattern.cpp and randomsequences.cpp; this is an independent
 * implementation):
 *
 *  - The lattice hash table: 4096 entries 0..4095 shuffled from the top down
 *    with POV-Ray's linear congruential generator
 *        r = r * 1812433253 + 12345   (32-bit, seed 0),
 *        j = ((r >> 16) & 0x7FFF) % 4096, swap(t[i], t[j]) for i = 4095..0,
 *    then duplicated to 8192 entries so that hashes of (a ^ b) need no mask.
 *  - The gradient table R[0..266] of the original (DKB/POV 1.0) noise:
 *        R[i] = CRC16(three big-endian IEEE doubles, each i * 0.12345)
 *               * 2/65535 - 1,
 *    CRC-16 with the reflected polynomial 0xA001 (table-driven, init 0).
 *    POV-Ray 3.x carries these values as a literal table printed with 6
 *    significant digits; we generate them and round the same way (%g), which
 *    reproduces all 267 values exactly (checked against POV-Ray 3.7).
 *  - Noise for generators 1 and 2: trilinear blend with the cubic s-curve
 *    3t^2-2t^3 of eight lattice terms s * (R[k]/2 + R[k+1] dx + R[k+2] dy
 *    + R[k+3] dz), k = (hash(hash(ix, iy), iz) & 0xFF); cells start at
 *    -10000 (MINX) and are masked to 12 bits; negative coordinates are
 *    floored as (int)(x - (1 - 1e-10)). Generator 1 returns sum + 0.5,
 *    generator 2 (sum + 1.05242) * 0.48985582, both clamped to [0, 1]. The
 *    terms are summed in POV-Ray's order so results match to the last bit.
 *  - DNoise: the same lattice, three such sums using R[k..], R[k+4..],
 *    R[k+8..] for x, y, z, in POV-Ray's corner order.
 *  - Generator 3: Perlin's gradient noise with 2048 random unit gradients
 *    and a permutation, both drawn from the same LCG (seed 1) as POV-Ray's
 *    InitSolidNoise does (rejection of |v|^2 > 1 or < 1e-5, permutation swaps
 *    at even indices from 2048 down, tables duplicated past 2048); result
 *    0.5 * (1.59 n + 0.985) clamped.
 *  - Turbulence: value = N(p) (generator 1) or clamp(2 N(p) - 0.5)
 *    (generators 2, 3), plus omega^k * N(lambda^k p) terms for octaves 2..n
 *    (2 N - 0.5 without clamping for generators 2, 3). DTurbulence sums DNoise
 *    the same way.
 *  - PatternRands: 32768 doubles from mt19937 (default seed 5489), each
 *    x / 2^32, as boost's uniform_real(0, 1) over mt19937 gives them.
 *  - Waves: source i is DNoise(<i, 0, 0>) normalised; frequency i from the
 *    LCG seeded with -560851967: ((r >> 16) & 0x7FFF) * 0.000030518509476
 *    + 0.01 (POV-Ray's Initialize_Waves; the first number_of_waves are used). */
#include "shade_noise.h"
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#define NOISE_EPSILON 1.0e-10
#define LATTICE_MIN (-10000)
#define SOLID_N 2048
#define RANDS_N 32768
#define TWO_PI 6.283185307179586476925286766560

static unsigned short hash_table[8192];
static double rtab[267];

/* The gradient table rearranged for the lattice sums, which index it at
 * k = hash & 0xFF: ntab[k] holds R[k]/2, R[k+1], R[k+2], R[k+3] (one Noise
 * term), drow[k] the same four for R[k..], R[k+4..], R[k+8..] in lanes 0,
 * 1, 2 (the x, y, z terms of one DNoise corner; lane 3 unused). Halving is
 * exact and every lane does the scalar term's operations in its order, so
 * the sums are bit for bit the scalar ones (the compiler contracts nothing
 * into fused multiply-adds on the baseline instruction set). */
typedef double nv2 __attribute__((vector_size(16)));
static double ntab[256][4];
typedef struct {
    nv2 h, a, b, c;       /* x and y terms */
    double hz, az, bz, cz; /* z term */
} noise_drow;
static noise_drow dtab[256];
static int solid_perm[2 * (SOLID_N + 1)];
static vec3 solid_grad[2 * (SOLID_N + 1)];
static double pattern_rands[RANDS_N];
static vec3 wave_src[SHADE_NOISE_MAX_WAVES];
static double wave_freq[SHADE_NOISE_MAX_WAVES];
static pthread_once_t init_once = PTHREAD_ONCE_INIT;

/* POV-Ray's LCG step on a 32-bit int; returns the 15 bits it uses. */
static int lcg15(uint32_t *r)
{
    *r = *r * 1812433253u + 12345u;
    return (int)((*r >> 16) & 0x7FFF);
}

static void init_hash(void)
{
    for (int i = 0; i < 4096; i++) hash_table[i] = (unsigned short)i;
    uint32_t r = 0;
    for (int i = 4095; i >= 0; i--) {
        int j = lcg15(&r) % 4096;
        unsigned short t = hash_table[i];
        hash_table[i] = hash_table[j];
        hash_table[j] = t;
    }
    for (int i = 0; i < 4096; i++) hash_table[4096 + i] = hash_table[i];
}

static unsigned crc16_table(unsigned n)
{
    unsigned c = n;
    for (int k = 0; k < 8; k++) c = (c & 1) ? (c >> 1) ^ 0xA001u : c >> 1;
    return c;
}

static void init_rtable(void)
{
    unsigned tab[256];
    for (unsigned n = 0; n < 256; n++) tab[n] = crc16_table(n);
    for (int i = 0; i < 267; i++) {
        double v = i * 0.12345;
        uint64_t bits;
        memcpy(&bits, &v, sizeof bits);
        unsigned crc = 0;
        for (int rep = 0; rep < 3; rep++)
            for (int b = 7; b >= 0; b--) { /* big-endian byte order */
                unsigned byte = (unsigned)(bits >> (8 * b)) & 0xFFu;
                crc = (crc >> 8) ^ tab[(crc ^ byte) & 0xFFu];
            }
        double val = crc * (2.0 / 65535.0) - 1.0;
        char buf[64];
        snprintf(buf, sizeof buf, "%g", val); /* POV-Ray's literal table precision */
        rtab[i] = strtod(buf, NULL);
    }
    for (int k = 0; k < 256; k++) {
        ntab[k][0] = rtab[k] * 0.5;
        ntab[k][1] = rtab[k + 1];
        ntab[k][2] = rtab[k + 2];
        ntab[k][3] = rtab[k + 3];
        for (int j = 0; j < 2; j++) {
            dtab[k].h[j] = rtab[k + 4 * j] * 0.5;
            dtab[k].a[j] = rtab[k + 4 * j + 1];
            dtab[k].b[j] = rtab[k + 4 * j + 2];
            dtab[k].c[j] = rtab[k + 4 * j + 3];
        }
        dtab[k].hz = rtab[k + 8] * 0.5;
        dtab[k].az = rtab[k + 9];
        dtab[k].bz = rtab[k + 10];
        dtab[k].cz = rtab[k + 11];
    }
}

static void init_solid(void)
{
    uint32_t r = 1;
    for (int i = 0; i < SOLID_N; i++) {
        double v[3], s;
        do {
            for (int j = 0; j < 3; j++) v[j] = (double)((lcg15(&r) % (SOLID_N << 1)) - SOLID_N) / (double)SOLID_N;
            s = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        } while (s > 1.0 || s < 1.0e-5);
        s = 1.0 / sqrt(s);
        solid_grad[i] = v3(v[0] * s, v[1] * s, v[2] * s);
    }
    for (int i = 0; i < SOLID_N; i++) solid_perm[i] = i;
    for (int i = SOLID_N; i > 0; i -= 2) {
        int k = solid_perm[i];
        int j = lcg15(&r) % SOLID_N;
        solid_perm[i] = solid_perm[j];
        solid_perm[j] = k;
    }
    for (int i = 0; i < SOLID_N + 2; i++) {
        solid_perm[SOLID_N + i] = solid_perm[i];
        solid_grad[SOLID_N + i] = solid_grad[i];
    }
}

/* mt19937 (Matsumoto & Nishimura 1998), default seed 5489. */
static void init_rands(void)
{
    uint32_t mt[624];
    mt[0] = 5489u;
    for (int i = 1; i < 624; i++) mt[i] = 1812433253u * (mt[i - 1] ^ (mt[i - 1] >> 30)) + (uint32_t)i;
    int idx = 624;
    for (int n = 0; n < RANDS_N; n++) {
        if (idx >= 624) {
            for (int i = 0; i < 624; i++) {
                uint32_t y = (mt[i] & 0x80000000u) | (mt[(i + 1) % 624] & 0x7fffffffu);
                mt[i] = mt[(i + 397) % 624] ^ (y >> 1) ^ ((y & 1u) ? 0x9908b0dfu : 0u);
            }
            idx = 0;
        }
        uint32_t y = mt[idx++];
        y ^= y >> 11;
        y ^= (y << 7) & 0x9d2c5680u;
        y ^= (y << 15) & 0xefc60000u;
        y ^= y >> 18;
        pattern_rands[n] = (double)y / 4294967296.0;
    }
}

static inline vec3 dnoise(vec3 p);

static void init_waves(void)
{
    uint32_t r = (uint32_t)-560851967;
    for (int i = 0; i < SHADE_NOISE_MAX_WAVES; i++) {
        wave_src[i] = v3_norm(dnoise(v3((double)i, 0.0, 0.0)));
        wave_freq[i] = (double)lcg15(&r) * 0.000030518509476 + 0.01;
    }
}

static atomic_int tables_ready;

static void init_all(void)
{
    init_hash();
    init_rtable();
    init_solid();
    init_rands();
    init_waves();
    atomic_store_explicit(&tables_ready, 1, memory_order_release);
}

/* Build the tables (idempotent, thread-safe). Once built, one acquire load
 * answers: the lattice lookups call this per evaluation, and pthread_once
 * is a call into the C library every time. */
static inline void noise_init(void)
{
    if (!atomic_load_explicit(&tables_ready, memory_order_acquire)) pthread_once(&init_once, init_all);
}

/* ------------------------------------------------------------ lattice noise */

static inline double scurve(double a) { return a * a * (3.0 - 2.0 * a); }

#if defined(__SSE2__)
/* shade_noise_to_int's rule is what cvttsd2si does (INT_MIN for NaN and
 * out-of-range values): the instruction alone, without the two range
 * tests a portable C cast needs, in the noise's innermost step. */
static inline int trunc_int(double x) { return _mm_cvttsd_si32(_mm_set_sd(x)); }
#else
static inline int trunc_int(double x) { return shade_noise_to_int(x); }
#endif

/* Cell index (12 bits) and fraction along one axis, POV-Ray's way. */
static inline void lattice(double x, int *i, double *f)
{
    int t = trunc_int(x >= 0 ? x : x - (1 - NOISE_EPSILON));
    *i = (t - LATTICE_MIN) & 0xFFF;
    *f = x - t;
}

static inline int hash2(int a, int b) { return hash_table[hash_table[a] ^ b]; }
static inline int rindex_of(int h, int c) { return hash_table[h ^ c] & 0xFF; }

/* Two lattice terms s * (R[k]/2 + R[k+1] x + R[k+2] y + R[k+3] z), for
 * k = ka in lane 0 and kb in lane 1. */
static inline nv2 term2(int ka, int kb, nv2 s, nv2 x, nv2 y, nv2 z)
{
    const double *a = ntab[ka], *b = ntab[kb];
    nv2 h = {a[0], b[0]}, r1 = {a[1], b[1]}, r2 = {a[2], b[2]}, r3 = {a[3], b[3]};
    return s * (((h + r1 * x) + r2 * y) + r3 * z);
}

/* The x, y, z terms of one DNoise corner: x and y in the lanes of *xy, z
 * in *z; stored by the first corner, added by the rest. */
static inline void dterm(nv2 *xy, double *z, int first, int k, double s, double x, double y, double zz)
{
    const noise_drow *r = &dtab[k];
    nv2 vs = {s, s}, vx = {x, x}, vy = {y, y}, vz = {zz, zz};
    nv2 t = vs * (((r->h + r->a * vx) + r->b * vy) + r->c * vz);
    double tz = s * (((r->hz + r->az * x) + r->bz * y) + r->cz * zz);
    if (first) {
        *xy = t;
        *z = tz;
    } else {
        *xy += t;
        *z += tz;
    }
}

/* The lattice cell of p as POV-Ray's Noise and DNoise set it up: p's
 * offsets from the cell's low and high corners, the s-curve weights of the
 * eight corners (products of the per-axis weights) and the hashes of the
 * cell's four (x, y) columns. cell_at is forced inline: it runs once per
 * noise value, in the innermost loop of every turbulent pattern, and as a
 * call its results go through memory. */
typedef struct {
    int iz;
    double x0, y0, z0, x1, y1, z1, sz, tz;
    double txty, sxty, txsy, sxsy;
    int h00, h10, h01, h11;
} noise_cell;

__attribute__((always_inline)) static inline void cell_at(vec3 p, noise_cell *c)
{
    int ix, iy;
    lattice(p.x, &ix, &c->x0);
    lattice(p.y, &iy, &c->y0);
    lattice(p.z, &c->iz, &c->z0);
    c->x1 = c->x0 - 1;
    c->y1 = c->y0 - 1;
    c->z1 = c->z0 - 1;
    double sx = scurve(c->x0), sy = scurve(c->y0);
    c->sz = scurve(c->z0);
    double tx = 1 - sx, ty = 1 - sy;
    c->tz = 1 - c->sz;
    c->txty = tx * ty;
    c->sxty = sx * ty;
    c->txsy = tx * sy;
    c->sxsy = sx * sy;
    c->h00 = hash2(ix, iy);
    c->h10 = hash2(ix + 1, iy);
    c->h01 = hash2(ix, iy + 1);
    c->h11 = hash2(ix + 1, iy + 1);
}

static double solid_noise(vec3 p);

/* Generators 1 and 2 at one point; forced inline so that the octave loops
 * (shade_noise_octaves) run it without a call per octave. */
__attribute__((always_inline)) static inline double lattice_noise(vec3 p, int generator)
{
    noise_cell c;
    cell_at(p, &c);
    /* corners in POV-Ray's order, two to a vector: (000, 100), (010, 110),
     * (001, 101), (011, 111); summed one by one in that order */
    nv2 x = {c.x0, c.x1}, y0 = {c.y0, c.y0}, y1 = {c.y1, c.y1}, z0 = {c.z0, c.z0}, z1 = {c.z1, c.z1};
    nv2 sy0 = {c.txty, c.sxty}, sy1 = {c.txsy, c.sxsy}, tz = {c.tz, c.tz}, sz = {c.sz, c.sz};
    nv2 t0 = term2(rindex_of(c.h00, c.iz), rindex_of(c.h10, c.iz), sy0 * tz, x, y0, z0);
    nv2 t1 = term2(rindex_of(c.h01, c.iz), rindex_of(c.h11, c.iz), sy1 * tz, x, y1, z0);
    nv2 t2 = term2(rindex_of(c.h00, c.iz + 1), rindex_of(c.h10, c.iz + 1), sy0 * sz, x, y0, z1);
    nv2 t3 = term2(rindex_of(c.h01, c.iz + 1), rindex_of(c.h11, c.iz + 1), sy1 * sz, x, y1, z1);
    double sum = t0[0];
    sum += t0[1];
    sum += t1[0];
    sum += t1[1];
    sum += t2[0];
    sum += t2[1];
    sum += t3[0];
    sum += t3[1];
    if (generator == 2) {
        sum += 1.05242;
        sum *= 0.48985582;
    } else {
        sum = sum + 0.5;
    }
    return sum < 0.0 ? 0.0 : (sum > 1.0 ? 1.0 : sum);
}

/* The cells of two points side by side, point a in lane 0 and b in lane
 * 1 of each vector, for the two-point sums below. */
typedef struct {
    noise_cell c, d;
    nv2 x0, x1, y0, y1, z0, z1, tz, sz, txty, sxty, txsy, sxsy;
} cell_pair;

#if defined(__SSE2__)
/* lattice() along one axis for two coordinates (lanes 0 and 1): the same
 * operations lane by lane (x - 0.0 is x, -0.0 included; cvttpd2dq
 * truncates as cvttsd2si does), the cell indices back as ints. */
__attribute__((always_inline)) static inline nv2 lattice2(nv2 v, int *ia, int *ib)
{
    __m128d x = (__m128d)v;
    __m128d ge = _mm_cmpge_pd(x, _mm_setzero_pd());
    __m128i t = _mm_cvttpd_epi32(_mm_sub_pd(x, _mm_andnot_pd(ge, _mm_set1_pd(1 - NOISE_EPSILON))));
    __m128i i = _mm_and_si128(_mm_sub_epi32(t, _mm_set1_epi32(LATTICE_MIN)), _mm_set1_epi32(0xFFF));
    *ia = _mm_cvtsi128_si32(i);
    *ib = _mm_cvtsi128_si32(_mm_shuffle_epi32(i, 1));
    return (nv2)_mm_sub_pd(x, _mm_cvtepi32_pd(t));
}

/* cell_at for two points at once: the fractions, s-curves and weights in
 * the lanes (each lane cell_at's operations in its order), the hashes per
 * point; only the integer fields of q->c and q->d are set. */
__attribute__((always_inline)) static inline void cells_at(vec3 a, vec3 b, cell_pair *q)
{
    int ixa, ixb, iya, iyb;
    q->x0 = lattice2((nv2){a.x, b.x}, &ixa, &ixb);
    q->y0 = lattice2((nv2){a.y, b.y}, &iya, &iyb);
    q->z0 = lattice2((nv2){a.z, b.z}, &q->c.iz, &q->d.iz);
    nv2 one = {1.0, 1.0}, three = {3.0, 3.0}, two = {2.0, 2.0};
    q->x1 = q->x0 - one;
    q->y1 = q->y0 - one;
    q->z1 = q->z0 - one;
    nv2 sx = q->x0 * q->x0 * (three - two * q->x0), sy = q->y0 * q->y0 * (three - two * q->y0);
    q->sz = q->z0 * q->z0 * (three - two * q->z0);
    nv2 tx = one - sx, ty = one - sy;
    q->tz = one - q->sz;
    q->txty = tx * ty;
    q->sxty = sx * ty;
    q->txsy = tx * sy;
    q->sxsy = sx * sy;
    q->c.h00 = hash2(ixa, iya);
    q->c.h10 = hash2(ixa + 1, iya);
    q->c.h01 = hash2(ixa, iya + 1);
    q->c.h11 = hash2(ixa + 1, iya + 1);
    q->d.h00 = hash2(ixb, iyb);
    q->d.h10 = hash2(ixb + 1, iyb);
    q->d.h01 = hash2(ixb, iyb + 1);
    q->d.h11 = hash2(ixb + 1, iyb + 1);
}
#else
__attribute__((always_inline)) static inline void cells_at(vec3 a, vec3 b, cell_pair *q)
{
    cell_at(a, &q->c);
    cell_at(b, &q->d);
    const noise_cell *c = &q->c, *d = &q->d;
    q->x0 = (nv2){c->x0, d->x0};
    q->x1 = (nv2){c->x1, d->x1};
    q->y0 = (nv2){c->y0, d->y0};
    q->y1 = (nv2){c->y1, d->y1};
    q->z0 = (nv2){c->z0, d->z0};
    q->z1 = (nv2){c->z1, d->z1};
    q->tz = (nv2){c->tz, d->tz};
    q->sz = (nv2){c->sz, d->sz};
    q->txty = (nv2){c->txty, d->txty};
    q->sxty = (nv2){c->sxty, d->sxty};
    q->txsy = (nv2){c->txsy, d->txsy};
    q->sxsy = (nv2){c->sxsy, d->sxsy};
}
#endif

/* Generators 1 and 2 at two points at once, a and b in lanes 0 and 1: the
 * eight corners of each are summed in POV-Ray's order down the lanes, each
 * lane doing lattice_noise's operations in its order (bit for bit its
 * result), so the two sums' additions, which run one after the other in
 * a single noise value, share their instructions. */
__attribute__((always_inline)) static inline nv2 lattice_noise2(vec3 a, vec3 b, int generator)
{
    cell_pair q;
    cells_at(a, b, &q);
    const noise_cell *c = &q.c, *d = &q.d;
    nv2 x0 = q.x0, x1 = q.x1, y0 = q.y0, y1 = q.y1, z0 = q.z0, z1 = q.z1, tz = q.tz, sz = q.sz;
    nv2 txty = q.txty, sxty = q.sxty, txsy = q.txsy, sxsy = q.sxsy;
    nv2 sum = term2(rindex_of(c->h00, c->iz), rindex_of(d->h00, d->iz), txty * tz, x0, y0, z0);
    sum += term2(rindex_of(c->h10, c->iz), rindex_of(d->h10, d->iz), sxty * tz, x1, y0, z0);
    sum += term2(rindex_of(c->h01, c->iz), rindex_of(d->h01, d->iz), txsy * tz, x0, y1, z0);
    sum += term2(rindex_of(c->h11, c->iz), rindex_of(d->h11, d->iz), sxsy * tz, x1, y1, z0);
    sum += term2(rindex_of(c->h00, c->iz + 1), rindex_of(d->h00, d->iz + 1), txty * sz, x0, y0, z1);
    sum += term2(rindex_of(c->h10, c->iz + 1), rindex_of(d->h10, d->iz + 1), sxty * sz, x1, y0, z1);
    sum += term2(rindex_of(c->h01, c->iz + 1), rindex_of(d->h01, d->iz + 1), txsy * sz, x0, y1, z1);
    sum += term2(rindex_of(c->h11, c->iz + 1), rindex_of(d->h11, d->iz + 1), sxsy * sz, x1, y1, z1);
    if (generator == 2) {
        sum += (nv2){1.05242, 1.05242};
        sum *= (nv2){0.48985582, 0.48985582};
    } else {
        sum = sum + (nv2){0.5, 0.5};
    }
    /* the scalar clamp per lane (a NaN stays NaN, as there) */
    for (int k = 0; k < 2; k++) sum[k] = sum[k] < 0.0 ? 0.0 : (sum[k] > 1.0 ? 1.0 : sum[k]);
    return sum;
}

double shade_noise_value(vec3 p, int generator)
{
    noise_init();
    if (generator == 3) {
        double sum = 0.5 * (1.59 * solid_noise(p) + 0.985);
        return sum < 0.0 ? 0.0 : (sum > 1.0 ? 1.0 : sum);
    }
    return lattice_noise(p, generator);
}

void shade_noise_octaves(vec3 p, int n, double lambda, int generator, double *out)
{
    noise_init();
    double l = 1.0;
    int i = 0;
    if (generator != 3) {
        /* two octaves at a time; the scale is the running product, as
         * Turbulence forms it */
        for (; i + 1 < n; i += 2) {
            vec3 a = i ? v3_scale(p, l) : p;
            double l2 = l * lambda;
            nv2 v = lattice_noise2(a, v3_scale(p, l2), generator);
            out[i] = v[0];
            out[i + 1] = v[1];
            l = l2 * lambda;
        }
    }
    for (; i < n; i++) {
        out[i] = shade_noise_value(i ? v3_scale(p, l) : p, generator);
        l *= lambda;
    }
}

vec3 shade_noise_dvector(vec3 p)
{
    noise_init();
    return dnoise(p);
}

__attribute__((always_inline)) static inline vec3 dnoise(vec3 p)
{
    noise_cell c;
    cell_at(p, &c);
    /* The first corner initialises, the rest add (POV-Ray's corner order). */
    nv2 xy;
    double z;
    dterm(&xy, &z, 1, rindex_of(c.h00, c.iz), c.txty * c.tz, c.x0, c.y0, c.z0);
    dterm(&xy, &z, 0, rindex_of(c.h10, c.iz), c.sxty * c.tz, c.x1, c.y0, c.z0);
    dterm(&xy, &z, 0, rindex_of(c.h11, c.iz), c.sxsy * c.tz, c.x1, c.y1, c.z0);
    dterm(&xy, &z, 0, rindex_of(c.h01, c.iz), c.txsy * c.tz, c.x0, c.y1, c.z0);
    dterm(&xy, &z, 0, rindex_of(c.h01, c.iz + 1), c.txsy * c.sz, c.x0, c.y1, c.z1);
    dterm(&xy, &z, 0, rindex_of(c.h11, c.iz + 1), c.sxsy * c.sz, c.x1, c.y1, c.z1);
    dterm(&xy, &z, 0, rindex_of(c.h10, c.iz + 1), c.sxty * c.sz, c.x1, c.y0, c.z1);
    dterm(&xy, &z, 0, rindex_of(c.h00, c.iz + 1), c.txty * c.sz, c.x0, c.y0, c.z1);
    return v3(xy[0], xy[1], z);
}

/* One DNoise corner of two points c and d at once: each point's x and y
 * terms in the lanes of its own vector (as dterm), the two z terms in the
 * lanes of a third; every lane does dterm's operations in its order. */
static inline void dterm2(nv2 *xyc, nv2 *xyd, nv2 *z, int first, int kc, int kd, nv2 s, nv2 x, nv2 y, nv2 zz)
{
    const noise_drow *r = &dtab[kc], *q = &dtab[kd];
    nv2 sc = {s[0], s[0]}, sd = {s[1], s[1]};
    nv2 tc = sc * (((r->h + r->a * (nv2){x[0], x[0]}) + r->b * (nv2){y[0], y[0]}) + r->c * (nv2){zz[0], zz[0]});
    nv2 td = sd * (((q->h + q->a * (nv2){x[1], x[1]}) + q->b * (nv2){y[1], y[1]}) + q->c * (nv2){zz[1], zz[1]});
    nv2 tz = s * ((((nv2){r->hz, q->hz} + (nv2){r->az, q->az} * x) + (nv2){r->bz, q->bz} * y) + (nv2){r->cz, q->cz} * zz);
    if (first) {
        *xyc = tc;
        *xyd = td;
        *z = tz;
    } else {
        *xyc += tc;
        *xyd += td;
        *z += tz;
    }
}

/* DNoise at a and b (bit for bit dnoise's), the two interleaved. */
__attribute__((always_inline)) static inline void dnoise2(vec3 a, vec3 b, vec3 *ra, vec3 *rb)
{
    cell_pair q;
    cells_at(a, b, &q);
    const noise_cell *c = &q.c, *d = &q.d;
    nv2 x0 = q.x0, x1 = q.x1, y0 = q.y0, y1 = q.y1, z0 = q.z0, z1 = q.z1, tz = q.tz, sz = q.sz;
    nv2 txty = q.txty, sxty = q.sxty, txsy = q.txsy, sxsy = q.sxsy;
    nv2 xyc, xyd, z;
    dterm2(&xyc, &xyd, &z, 1, rindex_of(c->h00, c->iz), rindex_of(d->h00, d->iz), txty * tz, x0, y0, z0);
    dterm2(&xyc, &xyd, &z, 0, rindex_of(c->h10, c->iz), rindex_of(d->h10, d->iz), sxty * tz, x1, y0, z0);
    dterm2(&xyc, &xyd, &z, 0, rindex_of(c->h11, c->iz), rindex_of(d->h11, d->iz), sxsy * tz, x1, y1, z0);
    dterm2(&xyc, &xyd, &z, 0, rindex_of(c->h01, c->iz), rindex_of(d->h01, d->iz), txsy * tz, x0, y1, z0);
    dterm2(&xyc, &xyd, &z, 0, rindex_of(c->h01, c->iz + 1), rindex_of(d->h01, d->iz + 1), txsy * sz, x0, y1, z1);
    dterm2(&xyc, &xyd, &z, 0, rindex_of(c->h11, c->iz + 1), rindex_of(d->h11, d->iz + 1), sxsy * sz, x1, y1, z1);
    dterm2(&xyc, &xyd, &z, 0, rindex_of(c->h10, c->iz + 1), rindex_of(d->h10, d->iz + 1), sxty * sz, x1, y0, z1);
    dterm2(&xyc, &xyd, &z, 0, rindex_of(c->h00, c->iz + 1), rindex_of(d->h00, d->iz + 1), txty * sz, x0, y0, z1);
    *ra = v3(xyc[0], xyc[1], z[0]);
    *rb = v3(xyd[0], xyd[1], z[1]);
}

/* ------------------------------------------------------------ gradient noise */

#define ROLLOVER 10000000.023157213

static inline void solid_setup(double v, int *b0, int *b1, double *r0, double *r1)
{
    double t = v + ROLLOVER;
    int it = shade_noise_to_int(floor(t));
    *b0 = it & (SOLID_N - 1);
    *b1 = (*b0 + 1) & (SOLID_N - 1);
    *r0 = t - it;
    *r1 = *r0 - 1.0;
}

static inline double lerp(double t, double a, double b) { return a + t * (b - a); }
static inline double gdot(vec3 g, double x, double y, double z) { return x * g.x + y * g.y + z * g.z; }

static double solid_noise(vec3 p)
{
    int bx0, bx1, by0, by1, bz0, bz1;
    double rx0, rx1, ry0, ry1, rz0, rz1;
    solid_setup(p.x, &bx0, &bx1, &rx0, &rx1);
    solid_setup(p.y, &by0, &by1, &ry0, &ry1);
    solid_setup(p.z, &bz0, &bz1, &rz0, &rz1);
    int i = solid_perm[bx0], j = solid_perm[bx1];
    int b00 = solid_perm[i + by0], b10 = solid_perm[j + by0];
    int b01 = solid_perm[i + by1], b11 = solid_perm[j + by1];
    double sx = scurve(rx0), sy = scurve(ry0), sz = scurve(rz0);
    double u = gdot(solid_grad[b00 + bz0], rx0, ry0, rz0);
    double v = gdot(solid_grad[b10 + bz0], rx1, ry0, rz0);
    double a = lerp(sx, u, v);
    u = gdot(solid_grad[b01 + bz0], rx0, ry1, rz0);
    v = gdot(solid_grad[b11 + bz0], rx1, ry1, rz0);
    double b = lerp(sx, u, v);
    double c = lerp(sy, a, b);
    u = gdot(solid_grad[b00 + bz1], rx0, ry0, rz1);
    v = gdot(solid_grad[b10 + bz1], rx1, ry0, rz1);
    a = lerp(sx, u, v);
    u = gdot(solid_grad[b01 + bz1], rx0, ry1, rz1);
    v = gdot(solid_grad[b11 + bz1], rx1, ry1, rz1);
    b = lerp(sx, u, v);
    double d = lerp(sy, a, b);
    return lerp(sz, c, d);
}

/* ------------------------------------------------------------ fractal sums */

/* The octaves' noise values come from shade_noise_octaves / the inlined
 * DNoise loop below (the same scales, l *= lambda per octave); the sums
 * are formed in POV-Ray's order. Octaves are at most 10 in a scene (the
 * parser clamps them as POV-Ray does); more are taken in the same way, a
 * call per octave. */
#define OCTAVES_AT_ONCE 16

double shade_noise_turbulence(vec3 p, int octaves, double omega, double lambda, int generator)
{
    double v[OCTAVES_AT_ONCE];
    int n = octaves < 1 ? 1 : (octaves > OCTAVES_AT_ONCE ? OCTAVES_AT_ONCE : octaves);
    shade_noise_octaves(p, n, lambda, generator, v);
    double value;
    if (generator > 1) {
        value = 2.0 * v[0] - 0.5;
        value = fmin(fmax(value, 0.0), 1.0);
    } else {
        value = v[0];
    }
    double l = lambda, o = omega;
    for (int i = 2; i <= octaves; i++) {
        double nv = i <= n ? v[i - 1] : shade_noise_value(v3_scale(p, l), generator);
        if (generator > 1) value += o * (2.0 * nv - 0.5);
        else value += o * nv;
        if (i < octaves) {
            l *= lambda;
            o *= omega;
        }
    }
    return value;
}

void shade_noise_dvector_octaves(vec3 p, int n, double lambda, vec3 *out)
{
    noise_init();
    double l = 1.0;
    int i = 0;
    for (; i + 1 < n; i += 2) {
        double l2 = l * lambda;
        dnoise2(i ? v3_scale(p, l) : p, v3_scale(p, l2), &out[i], &out[i + 1]);
        l = l2 * lambda;
    }
    if (i < n) out[i] = dnoise(i ? v3_scale(p, l) : p);
}

vec3 shade_noise_dturbulence(vec3 p, int octaves, double omega, double lambda)
{
    /* the octaves' DNoise two at a time, then summed in POV-Ray's order */
    vec3 v[OCTAVES_AT_ONCE];
    int n = octaves < 1 ? 1 : (octaves > OCTAVES_AT_ONCE ? OCTAVES_AT_ONCE : octaves);
    shade_noise_dvector_octaves(p, n, lambda, v);
    vec3 r = v[0];
    double o = omega, l = lambda;
    for (int k = 2; k <= octaves; k++) {
        vec3 w = k <= n ? v[k - 1] : shade_noise_dvector(v3_scale(p, l));
        r.x += o * w.x;
        r.y += o * w.y;
        r.z += o * w.z;
        if (k < octaves) {
            l *= lambda;
            o *= omega;
        }
    }
    return r;
}

/* ------------------------------------------------------------ waves */

double shade_noise_cycloidal(double x)
{
    if (x >= 0.0) return sin(((x - floor(x)) * 50000.0) / 50000.0 * TWO_PI);
    return 0.0 - sin(((0.0 - (x + floor(0.0 - x))) * 50000.0) / 50000.0 * TWO_PI);
}

double shade_noise_triangle_wave(double x)
{
    double off = x >= 0.0 ? x - floor(x) : x + 1.0 + floor(fabs(x));
    return off >= 0.5 ? 2.0 * (1.0 - off) : 2.0 * off;
}

int shade_noise_hash3d(int a, int b, int c)
{
    noise_init();
    return hash_table[hash_table[hash_table[a & 0xfff] ^ (b & 0xfff)] ^ (c & 0xfff)];
}

/* Entry k of POV-Ray's 256-entry jitter table (core/math/jitter.cpp). The
 * table is a closed form: with m = (k << 1) ^ (k << 2) (ten bits) and p the
 * parity of k's bits, the entry is m/1024 - 1/2 when p is even and
 * m/1024 + 2^-15 when p is odd, wrapped into [-1/2, 1/2); POV-Ray stores
 * it printed with six decimals, so it is rounded the same way. */
static double jitter_entry(int k)
{
    int m = ((k << 1) ^ (k << 2)) & 0x3ff, p = __builtin_parity((unsigned)k);
    double v = m / 1024.0 + (p ? 1.0 / 32768.0 : -0.5);
    if (v >= 0.5) v -= 1.0;
    return round(v * 1e6) / 1e6;
}

/* Jitter2d of POV-Ray's jitter.h for real coordinates: each axis's offset
 * is the table entry at a double lattice hash of the coordinates scaled by
 * the primes 1021 and 1019 (truncated toward zero, masked to 12 bits). */
void shade_noise_jitter2d(double x, double y, double *jx, double *jy)
{
    noise_init();
    int ax = (int)(x * 1021.0), bx = (int)(y * 1019.0);
    int ay = (int)(x * 1019.0), by = (int)(y * 1021.0);
    *jx = jitter_entry(hash_table[(hash_table[ax & 0xfff] ^ bx) & 0xfff] & 0xff);
    *jy = jitter_entry(hash_table[(hash_table[ay & 0xfff] ^ by) & 0xfff] & 0xff);
}

double shade_noise_pattern_rand(unsigned long i)
{
    noise_init();
    return pattern_rands[i % RANDS_N];
}

vec3 shade_noise_wave_source(int i)
{
    noise_init();
    return wave_src[i];
}

double shade_noise_wave_frequency(int i)
{
    noise_init();
    return wave_freq[i];
}
