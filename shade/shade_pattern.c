/* shade_pattern.c - POV-Ray 3.7 patterns, warps, blend maps, pigments.
 *
 * Reproduced semantics (studied in POV-Ray 3.7's pattern.cpp, warps.cpp,
 * pigment.cpp and imageutil.cpp; independent implementation):
 *  - Warp_EPoint: warps in list order; classic turbulence is skipped for
 *    marble and wood (they use it inside the pattern); coordinates are
 *    clamped to +-1e17 afterwards.
 *  - Evaluate_TPat: value = pattern(p); with frequency f != 0,
 *    value = fmod(value * f + phase, 1.00001); negative values wrap by
 *    value -= floor(value); then the wave: ramp, sine (1+cycloidal)/2,
 *    triangle, scallop |cycloidal(v/2)|, cubic 3v^2-2v^3, poly v^exponent.
 *  - Each pattern function as POV-Ray defines it (the formulas are in the
 *    functions below, with the constants POV-Ray uses: EPSILON 1e-10 offsets
 *    in checker/cells/brick/crackle, 1.00001 modulus, hexagon's 6x6 block
 *    tiling, brick's mortar layers, crackle's 81 neighbouring cubes, the
 *    4x-scaled 6-octave granite, 10-octave wrinkles, ...).
 *  - Search_Blend_Map and Compute_Pigment: linear blend between the entries
 *    around the value (entries' values are single-precision as in POV-Ray);
 *    pigment_map entries are evaluated at the parent's warped point.
 *  - The default colour maps of Post_Pigment (bozo, wood, radial, marble,
 *    agate, brick, hexagon, checker, square, triangular, cubic; grey ramp
 *    for the rest). */
#include "shade_pattern.h"
#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <threads.h>
#include "func.h"
#include "shade_funcenv.h"
#include "shade_noise.h"
#include "shade_tiling.h"
#include "shade_pavement.h"
#include "geom_shape.h"

#define PAT_EPSILON 1.0e-10
#define COORD_LIMIT 1.0e17
#define TWO_PI 6.283185307179586476925286766560
#define HALF_PI 1.57079632679489661923
#define PI_ 3.1415926535897932384626
/* POV-Ray's greyscale weights. */
#define GREY(r, g, b) (0.297 * (r) + 0.589 * (g) + 0.114 * (b))

static int pattern_image_colour(const scene_image_map *im, vec3 tp, colour5 *out);

static inline double pov_floor(double x) { return x >= 0.0 ? floor(x) : (0.0 - floor(0.0 - x) - 1.0); }

shade_pattern_ctx shade_pattern_ctx_plain(const scene *sc)
{
    shade_pattern_ctx c;
    memset(&c, 0, sizeof c);
    int g = sc ? sc->global.noise_generator : 2;
    /* POV-Ray defaults to the original noise for #version < 3.5 scenes */
    if (sc && g == 2 && sc->version_major > 0 && sc->version_major + sc->version_minor / 10.0 < 3.45) g = 1;
    c.noise_generator = g >= 1 && g <= 3 ? g : 2;
    int nw = sc ? sc->global.number_of_waves : 0;
    c.nwaves = nw <= 0 ? SHADE_NOISE_WAVES : (nw > SHADE_NOISE_MAX_WAVES ? SHADE_NOISE_MAX_WAVES : nw);
    c.scene_serial = sc ? sc->serial : 0;
    return c;
}

vec3 shade_pattern_normal_to_pattern(const xform *x, vec3 n)
{
    /* m^T n: the forward matrix transposed (POV-Ray's row-vector matrix times n). */
    return v3(x->m[0][0] * n.x + x->m[1][0] * n.y + x->m[2][0] * n.z,
              x->m[0][1] * n.x + x->m[1][1] * n.y + x->m[2][1] * n.z,
              x->m[0][2] * n.x + x->m[1][2] * n.y + x->m[2][2] * n.z);
}

/* ------------------------------------------------------------ warps */

/* Orientation remap shared by the mapping warps (POV-Ray's rule for a
 * non-default orientation vector o). */
static vec3 orient(vec3 o, double x, double y, double z)
{
    if (o.x == 0.0 && o.y == 0.0 && o.z == 1.0) return v3(x, y, z);
    return v3(o.x * z + o.y * x + o.z * x, o.x * y + o.y * -z + o.z * y, o.x * -x + o.y * y + o.z * z);
}

/* Angle of (x, z) from +x in the x-z plane, 0..2pi (acos-based, as POV-Ray). */
static double xz_angle(double x, double z, double len)
{
    if (z == 0.0) return x > 0 ? 0.0 : PI_;
    double t = acos(x / len);
    return z < 0.0 ? TWO_PI - t : t;
}

static vec3 warp_cylindrical(const scene_warp *w, vec3 p)
{
    double len = sqrt(p.x * p.x + p.z * p.z);
    if (len == 0.0) return p;
    double theta = xz_angle(p.x, p.z, len) / TWO_PI;
    if (w->dist_exp == 1.0) theta *= len;
    else if (w->dist_exp != 0.0) theta *= pow(len, w->dist_exp);
    return orient(w->orientation, theta, p.y, len);
}

static vec3 warp_spherical(const scene_warp *w, vec3 p)
{
    double dist = sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
    if (dist == 0.0) return p;
    double x = p.x / dist, y = p.y / dist, z = p.z / dist;
    double phi = 0.5 + asin(y) / PI_;
    double len = sqrt(x * x + z * z);
    double theta = len == 0.0 ? 0.0 : xz_angle(x, z, len) / TWO_PI;
    if (w->dist_exp == 1.0) {
        theta *= dist;
        phi *= dist;
    } else if (w->dist_exp != 0.0) {
        theta *= pow(dist, w->dist_exp);
        phi *= pow(dist, w->dist_exp);
    }
    return orient(w->orientation, theta, phi, dist);
}

static vec3 warp_toroidal(const scene_warp *w, vec3 p)
{
    double len = sqrt(p.x * p.x + p.z * p.z);
    if (len == 0.0) return p;
    double theta = 0.0 - xz_angle(p.x, p.z, len);
    double x = len - w->major_radius, y = p.y;
    len = sqrt(x * x + y * y);
    double phi = acos(-x / len);
    if (y > 0.0) phi = TWO_PI - phi;
    theta /= -TWO_PI;
    phi /= TWO_PI;
    if (w->dist_exp == 1.0) {
        theta *= len;
        phi *= len;
    } else if (w->dist_exp != 0.0) {
        theta *= pow(len, w->dist_exp);
        phi *= pow(len, w->dist_exp);
    }
    return orient(w->orientation, theta, phi, len);
}

static vec3 warp_planar(const scene_warp *w, vec3 p) { return orient(w->orientation, p.x, p.y, w->plane_offset); }

static vec3 warp_cubic(vec3 p)
{
    double x = p.x, y = p.y, z = p.z, ax = fabs(x), ay = fabs(y), az = fabs(z);
    if (x >= 0 && x >= ay && x >= az) return v3(0.75 - 0.25 * (z / x + 1.0) / 2.0, 1.0 / 3.0 + (1.0 / 3.0) * (y / x + 1.0) / 2.0, x);
    if (y >= 0 && y >= ax && y >= az) return v3(0.25 + 0.25 * (x / y + 1.0) / 2.0, 1.0 - (1.0 / 3.0) * (z / y + 1.0) / 2.0, y);
    if (z >= 0 && z >= ax && z >= ay) return v3(0.25 + 0.25 * (x / z + 1.0) / 2.0, 1.0 / 3.0 + (1.0 / 3.0) * (y / z + 1.0) / 2.0, z);
    if (x < 0 && x <= -ay && x <= -az) {
        x = -x;
        return v3(0.25 * (z / x + 1.0) / 2.0, 1.0 / 3.0 + (1.0 / 3.0) * (y / x + 1.0) / 2.0, x);
    }
    if (y < 0 && y <= -ax && y <= -az) {
        y = -y;
        return v3(0.25 + 0.25 * (x / y + 1.0) / 2.0, (1.0 / 3.0) * (z / y + 1.0) / 2.0, y);
    }
    z = -z;
    return v3(1.0 - 0.25 * (x / z + 1.0) / 2.0, 1.0 / 3.0 + (1.0 / 3.0) * (y / z + 1.0) / 2.0, z);
}

static vec3 warp_repeat(const scene_warp *w, vec3 p)
{
    double c[3] = {p.x, p.y, p.z};
    double r[3] = {p.x, p.y, p.z};
    int a = w->axis;
    float blk = (float)floor(c[a] / w->width); /* POV-Ray keeps the block number as SNGL */
    r[a] = c[a] - blk * w->width;
    if (shade_noise_to_int(blk) & 1) {
        r[0] *= w->flip.x;
        r[1] *= w->flip.y;
        r[2] *= w->flip.z;
        if (v3_idx(w->flip, a) < 0) r[a] = w->width + r[a];
    }
    return v3(r[0] + blk * w->offset.x, r[1] + blk * w->offset.y, r[2] + blk * w->offset.z);
}

static vec3 warp_black_hole(const scene_warp *w, vec3 p)
{
    vec3 centre = w->centre;
    if (w->bh_repeat) {
        int bx = 0, by = 0, bz = 0;
        if (w->repeat_vec.x >= PAT_EPSILON) bx = shade_noise_to_int(floor(p.x / w->repeat_vec.x));
        if (w->repeat_vec.y >= PAT_EPSILON) by = shade_noise_to_int(floor(p.y / w->repeat_vec.y));
        if (w->repeat_vec.z >= PAT_EPSILON) bz = shade_noise_to_int(floor(p.z / w->repeat_vec.z));
        if (w->uncertain) {
            int seed = shade_noise_hash3d(bx, by, bz);
            centre.x += shade_noise_pattern_rand((unsigned long)seed) * w->uncertainty.x;
            centre.y += shade_noise_pattern_rand((unsigned long)seed + 1) * w->uncertainty.y;
            centre.z += shade_noise_pattern_rand((unsigned long)seed + 2) * w->uncertainty.z;
        }
        centre.x += w->repeat_vec.x * bx;
        centre.y += w->repeat_vec.y * by;
        centre.z += w->repeat_vec.z * bz;
    }
    vec3 d = v3_sub(p, centre);
    double len = v3_len(d);
    if (len >= w->radius || w->bh_type != 0) return p;
    len = (w->radius - len) / w->radius;
    double s = pow(len, w->power) * w->strength;
    if (s > 1.0) s = 1.0;
    return v3_add(p, v3_scale(d, w->inverted ? -s : s));
}

/* shade_pattern_warp's last step, the coordinates held within COORD_LIMIT */
static inline vec3 coord_clamp(vec3 p)
{
    p.x = fmin_inline(fmax_inline(p.x, -COORD_LIMIT), COORD_LIMIT);
    p.y = fmin_inline(fmax_inline(p.y, -COORD_LIMIT), COORD_LIMIT);
    p.z = fmin_inline(fmax_inline(p.z, -COORD_LIMIT), COORD_LIMIT);
    return p;
}

vec3 shade_pattern_warp(const scene_pattern *pat, vec3 p)
{
    for (int i = 0; i < pat->nwarps; i++) {
        const scene_warp *w = &pat->warps[i];
        switch (w->kind) {
        case WARP_TURBULENCE:
            if (w->classic && (pat->kind == PAT_MARBLE || pat->kind == PAT_WOOD || pat->kind == PAT_PLAIN)) break;
            {
                vec3 t = shade_noise_dturbulence(p, w->octaves, w->omega, w->lambda);
                p.x += t.x * w->turbulence.x;
                p.y += t.y * w->turbulence.y;
                p.z += t.z * w->turbulence.z;
            }
            break;
        case WARP_TRANSFORM: p = xform_inv_point(&w->transform, p); break;
        case WARP_REPEAT: p = warp_repeat(w, p); break;
        case WARP_BLACK_HOLE: p = warp_black_hole(w, p); break;
        case WARP_CYLINDRICAL: p = warp_cylindrical(w, p); break;
        case WARP_SPHERICAL: p = warp_spherical(w, p); break;
        case WARP_TOROIDAL: p = warp_toroidal(w, p); break;
        case WARP_PLANAR: p = warp_planar(w, p); break;
        case WARP_CUBIC: p = warp_cubic(p); break;
        }
    }
    return coord_clamp(p);
}

/* The classic turbulence warp of a pattern (the last warp), or NULL. */
static const scene_warp *pattern_classic_turb(const scene_pattern *pat)
{
    if (pat->nwarps == 0) return NULL;
    const scene_warp *w = &pat->warps[pat->nwarps - 1];
    return w->kind == WARP_TURBULENCE && w->classic ? w : NULL;
}

/* ------------------------------------------------------------ patterns */

static double turb_scalar(const scene_pattern *pat, vec3 p, int gen)
{
    const scene_warp *t = pattern_classic_turb(pat);
    return t ? t->turbulence.x * shade_noise_turbulence(p, t->octaves, t->omega, t->lambda, gen) : 0.0;
}

static double agate(const scene_pattern *pat, vec3 p, int gen)
{
    const scene_warp *t = pattern_classic_turb(pat);
    /* agate always has a classic turbulence record (octaves etc.), default turbulence 0 */
    double tv = pat->agate_turb * (t ? shade_noise_turbulence(p, t->octaves, t->omega, t->lambda, gen)
                                     : shade_noise_turbulence(p, 6, 0.5, 2.0, gen));
    double n = 0.5 * (shade_noise_cycloidal(1.3 * tv + 1.1 * p.z) + 1.0);
    if (n < 0.0) return 0.0;
    n = fmin_inline(1.0, n);
    return pow(n, 0.77);
}

/* POV-Ray's CLIP_DENSITY: 1 - v inside [0, 1], 1 below, 0 above. */
static double clip_density(double v) { return v < 0.0 ? 1.0 : (v > 1.0 ? 0.0 : 1.0 - v); }

static double brick(const scene_pattern *pat, vec3 p)
{
    double fudge = PAT_EPSILON + pat->mortar;
    double x = p.x + fudge, y = p.y + fudge, z = p.z + fudge;
    double bw = pat->brick_size.x, bh = pat->brick_size.y, bd = pat->brick_size.z;
    double mw = pat->mortar / bw, mh = pat->mortar / bh, md = pat->mortar / bd;
    double by = y / bh;
    by -= (double)shade_noise_to_int(by);
    if (by < 0.0) by += 1.0;
    if (by <= mh) return 0.0;
    by = (y / bh) * 0.5;
    by -= (double)shade_noise_to_int(by);
    if (by < 0.0) by += 1.0;
    double bx = x / bw;
    bx -= (double)shade_noise_to_int(bx);
    if (bx < 0.0) bx += 1.0;
    if (bx <= mw && by <= 0.5) return 0.0;
    bx = (x / bw) + 0.5;
    bx -= (double)shade_noise_to_int(bx);
    if (bx < 0.0) bx += 1.0;
    if (bx <= mw && by > 0.5) return 0.0;
    double bz = z / bd;
    bz -= (double)shade_noise_to_int(bz);
    if (bz < 0.0) bz += 1.0;
    if (bz <= md && by > 0.5) return 0.0;
    bz = (z / bd) + 0.5;
    bz -= (double)shade_noise_to_int(bz);
    if (bz < 0.0) bz += 1.0;
    if (bz <= md && by <= 0.5) return 0.0;
    return 1.0;
}

static double cells(vec3 p)
{
    int h = shade_noise_hash3d(shade_noise_to_int(floor(p.x + PAT_EPSILON)), shade_noise_to_int(floor(p.y + PAT_EPSILON)),
                         shade_noise_to_int(floor(p.z + PAT_EPSILON)));
    return fmin_inline(shade_noise_pattern_rand((unsigned long)h), 1.0);
}

static double checker(vec3 p)
{
    int v = shade_noise_to_int(floor(p.x + PAT_EPSILON) + floor(p.y + PAT_EPSILON) + floor(p.z + PAT_EPSILON));
    return (v & 1) ? 1.0 : 0.0;
}

/* One random point in the unit cube at integer corner (x, y, z). */
static vec3 cube_point(int x, int y, int z)
{
    unsigned long seed = (unsigned long)shade_noise_hash3d(x & 0xFFF, y & 0xFFF, z & 0xFFF);
    return v3(x + shade_noise_pattern_rand(seed), y + shade_noise_pattern_rand(seed + 1), z + shade_noise_pattern_rand(seed + 2));
}

static double metric_sum(vec3 d, double metric)
{
    if (metric == 2) return d.x * d.x + d.y * d.y + d.z * d.z;
    if (metric == 1) return fabs(d.x) + fabs(d.y) + fabs(d.z);
    if (metric == 3) {
        double x = fabs(d.x), y = fabs(d.y), z = fabs(d.z);
        return x * x * x + y * y * y + z * z * z;
    }
    return pow(fabs(d.x), metric) + pow(fabs(d.y), metric) + pow(fabs(d.z), metric);
}

/* Crackle's candidate points (CRACKLE_N, in table order): the indices of
 * the cube's own point and its six face neighbours', whose third-nearest
 * distance bounds the full scan's. */
static const int near7[7] = {40, 19, 61, 35, 45, 39, 41};

/* a <= b <= u: the three smallest of the values given so far, without
 * branches (a sorted insertion mispredicts at every new minimum). */
static inline void keep3(double v, double *a, double *b, double *u)
{
    double ab = *a > v ? *a : v, bb = *b > v ? *b : v;
    *u = *u < bb ? *u : bb;
    *b = *b < ab ? *b : ab;
    *a = *a < v ? *a : v;
}

/* x^(k/2) for a whole k in [1, 64], by products and at most one root: a
 * cheap stand-in for pow(x, k / 2.0) within a few units of rounding (at
 * most about a dozen roundings), used only to rule points out */
static inline double pow_half(double x, int k)
{
    double r = 1.0, b = x;
    for (int n = k >> 1; n > 0; n >>= 1) {
        if (n & 1) r *= b;
        b *= b;
    }
    return (k & 1) ? r * sqrt(x) : r;
}

/* s (< m3) among the three smallest m1 <= m2 <= m3; mi: point of m1 */
static inline void nearest3_put(double s, int i, double *m1, double *m2, double *m3, int *mi)
{
    if (s < *m1) {
        *m3 = *m2;
        *m2 = *m1;
        *m1 = s;
        *mi = i;
    } else if (s < *m2) {
        *m3 = *m2;
        *m2 = s;
    } else {
        *m3 = s;
    }
}

/* nearest3_put where the points come in any order: a tie with the
 * smallest goes to the lower index i (the table order's first) */
static inline void nearest3_put_first(double s, int i, double *m1, double *m2, double *m3, int *mi)
{
    if (s < *m1 || (s == *m1 && i < *mi)) {
        *m3 = *m2;
        *m2 = *m1;
        *m1 = s;
        *mi = i;
    } else if (s < *m2) {
        *m3 = *m2;
        *m2 = s;
    } else {
        *m3 = s;
    }
}

#define CRACKLE_SLOTS 64u /* per thread, 81 points each: about 122 KiB */
#define CRACKLE_N 81      /* the points */
static double crackle(const scene_pattern *pat, vec3 p, int gen)
{
    int fx = shade_noise_to_int(floor(p.x - PAT_EPSILON)), fy = shade_noise_to_int(floor(p.y - PAT_EPSILON)),
        fz = shade_noise_to_int(floor(p.z - PAT_EPSILON));
    double metric = pat->crackle_metric;
    /* The 81 cubes within a "3D knight move" (offsets -2..2 with at most one
     * coordinate of magnitude 2), in POV-Ray's table order; kept per thread
     * for the last few cubes visited (they depend on the cube alone), as
     * POV-Ray's crackle cache does: a ray marching an isosurface or a
     * pixel's neighbours stay in one cube for many evaluations. The points
     * are kept by coordinate (x[], y[], z[]). */
    static _Thread_local struct {
        int valid, fx, fy, fz;
        double x[CRACKLE_N];
        double y[CRACKLE_N];
        double z[CRACKLE_N];
    } cache[CRACKLE_SLOTS];
    unsigned slot = ((unsigned)fx * 73856093u ^ (unsigned)fy * 19349663u ^ (unsigned)fz * 83492791u) % CRACKLE_SLOTS;
    const double *X = cache[slot].x, *Y = cache[slot].y, *Z = cache[slot].z;
    if (!cache[slot].valid || cache[slot].fx != fx || cache[slot].fy != fy || cache[slot].fz != fz) {
        int n = 0;
        for (int ax = -2; ax <= 2; ax++)
            for (int ay = -2; ay <= 2; ay++)
                for (int az = -2; az <= 2; az++)
                    if ((abs(ax) == 2) + (abs(ay) == 2) + (abs(az) == 2) <= 1) {
                        vec3 q = cube_point(fx + ax, fy + ay, fz + az);
                        cache[slot].x[n] = q.x;
                        cache[slot].y[n] = q.y;
                        cache[slot].z[n] = q.z;
                        n++;
                    }
        cache[slot].valid = 1;
        cache[slot].fx = fx;
        cache[slot].fy = fy;
        cache[slot].fz = fz;
    }
    double m1, m2, m3, t;
    int mi = 0;
    if (metric == 2) {
        /* the common metric 2 (the default) */
        /* The cube's own point and its six face neighbours (table
         * indices) are taken first, without branches (an insertion at
         * every new minimum mispredicts): their three smallest squares
         * start m1 <= m2 <= m3 and mi. The other 20 points of the 27
         * cubes around p's follow, each compared with m3 only (few are
         * within it, so the branch stays predictable). The 54 points of
         * the cubes two away along an axis (nine per side: x -2, +2,
         * y -2, +2, z -2, +2) lie beyond that cube's near face, whose
         * distance g from p bounds their coordinate difference; the
         * rounded differences, squares and sums are monotone, so each such
         * point's square is at least the rounded g^2 (a cube's point lies
         * in [c, c + 1]: pattern_rands are in [0, 1)). A side whose g^2
         * exceeds m3 has no point that could enter the three: its squares
         * are not taken. The three values do not depend on the order the
         * points are taken in; mi is kept as the table's first index of
         * the smallest (a tie goes to the lower index), so the result is
         * the full scan's in table order. */
        m1 = m2 = m3 = INFINITY;
        mi = CRACKLE_N;
        if (pat->crackle_solid) {
            for (int k = 0; k < 7; k++) {
                int i = near7[k];
                double dx = X[i] - p.x, dy = Y[i] - p.y, dz = Z[i] - p.z;
                double sq = dx * dx + dy * dy + dz * dz;
                int first = (sq < m1) | ((sq == m1) & (i < mi));
                mi = first ? i : mi;
                keep3(sq, &m1, &m2, &m3);
            }
        } else {
            /* mi is read by `solid` alone */
            for (int k = 0; k < 7; k++) {
                int i = near7[k];
                double dx = X[i] - p.x, dy = Y[i] - p.y, dz = Z[i] - p.z;
                keep3(dx * dx + dy * dy + dz * dz, &m1, &m2, &m3);
            }
        }
        static const unsigned char around[20] = {13, 14, 15, 18, 20, 23, 24, 25, 34, 36,
                                                 44, 46, 55, 56, 57, 60, 62, 65, 66, 67};
        for (int k = 0; k < 20; k++) {
            int i = around[k];
            double dx = X[i] - p.x, dy = Y[i] - p.y, dz = Z[i] - p.z;
            double sq = dx * dx + dy * dy + dz * dz;
            if (sq < m3) nearest3_put_first(sq, i, &m1, &m2, &m3, &mi);
        }
        static const unsigned char sides[6][9] = {
            {0, 1, 2, 3, 4, 5, 6, 7, 8},           {72, 73, 74, 75, 76, 77, 78, 79, 80},
            {9, 10, 11, 30, 31, 32, 51, 52, 53},   {27, 28, 29, 48, 49, 50, 69, 70, 71},
            {12, 17, 22, 33, 38, 43, 54, 59, 64},  {16, 21, 26, 37, 42, 47, 58, 63, 68}};
        double g[6] = {p.x - (double)(fx - 1), (double)(fx + 2) - p.x, p.y - (double)(fy - 1),
                       (double)(fy + 2) - p.y, p.z - (double)(fz - 1), (double)(fz + 2) - p.z};
        for (int sd = 0; sd < 6; sd++) {
            if (g[sd] * g[sd] > m3) continue;
            for (int k = 0; k < 9; k++) {
                int i = sides[sd][k];
                double dx = X[i] - p.x, dy = Y[i] - p.y, dz = Z[i] - p.z;
                double sq = dx * dx + dy * dy + dz * dz;
                if (sq < m3) nearest3_put_first(sq, i, &m1, &m2, &m3, &mi);
            }
        }
    } else if (metric > 0.0 && metric <= 32.0 && metric != 1 && metric != 3 && 2.0 * metric == floor(2.0 * metric)) {
        /* A metric of halves (2.5, 4, 6): each point's sum is first taken
         * with pow_half, whose relative error is far below 1e-12. The
         * cube's own point and its six face neighbours bound the third
         * smallest exact sum from above (their cheap sums plus the margin,
         * third smallest: u); a point whose cheap sum, less the margin,
         * exceeds u has an exact sum (pow's) above the third smallest and is
         * passed over. The few left are summed with pow and kept as the
         * full scan keeps them (the three smallest values, the first index
         * of the smallest); the 1e-300 covers subnormal terms. */
        int k = (int)(2.0 * metric);
        double a = INFINITY, b = INFINITY, u = INFINITY;
        for (int j = 0; j < 7; j++) {
            int i = near7[j];
            double v = (pow_half(fabs(X[i] - p.x), k) + pow_half(fabs(Y[i] - p.y), k) + pow_half(fabs(Z[i] - p.z), k)) *
                           (1.0 + 1e-12) + 1e-300;
            keep3(v, &a, &b, &u);
        }
        /* a coordinate beyond u^(1/metric) alone puts a point past u */
        double cu = pow(u, 1.0 / metric) * (1.0 + 1e-12);
        m1 = m2 = m3 = INFINITY;
        for (int i = 0; i < CRACKLE_N; i++) {
            double ax = fabs(X[i] - p.x), ay = fabs(Y[i] - p.y), az = fabs(Z[i] - p.z);
            if (fmax_inline(ax, fmax_inline(ay, az)) > cu) continue;
            double sa = pow_half(ax, k) + pow_half(ay, k) + pow_half(az, k);
            if (sa * (1.0 - 1e-12) - 1e-300 > u) continue;
            double s = metric_sum(v3(X[i] - p.x, Y[i] - p.y, Z[i] - p.z), metric);
            if (s < m3) nearest3_put(s, i, &m1, &m2, &m3, &mi);
        }
    } else {
        m1 = metric_sum(v3(X[0] - p.x, Y[0] - p.y, Z[0] - p.z), metric);
        m2 = metric_sum(v3(X[1] - p.x, Y[1] - p.y, Z[1] - p.z), metric);
        m3 = metric_sum(v3(X[2] - p.x, Y[2] - p.y, Z[2] - p.z), metric);
        if (m2 < m1) { t = m1; m1 = m2; m2 = t; mi = 1; }
        if (m3 < m1) { t = m1; m1 = m3; m3 = t; mi = 2; }
        if (m3 < m2) { t = m2; m2 = m3; m3 = t; }
        /* other metrics: each term is at least the largest coordinate's, so
         * a point whose largest |coordinate| exceeds m3^(1/metric) cannot be
         * among the three nearest; that bound skips most of the pow()s */
        int general = metric > 0.0 && metric != 1;
        double bound = general ? pow(m3, 1.0 / metric) * (1.0 + 1e-12) : INFINITY;
        for (int i = 3; i < CRACKLE_N; i++) {
            vec3 d = v3(X[i] - p.x, Y[i] - p.y, Z[i] - p.z);
            if (general && fmax_inline(fabs(d.x), fmax_inline(fabs(d.y), fabs(d.z))) > bound) continue;
            double s = metric_sum(d, metric);
            if (s < m3) {
                nearest3_put(s, i, &m1, &m2, &m3, &mi);
                if (general) bound = pow(m3, 1.0 / metric) * (1.0 + 1e-12);
            }
        }
    }
    double off = pat->crackle_offset;
    if (off != 0.0) {
        double a = metric == 2 ? off * off : (metric == 1 ? off : pow(off, metric));
        m1 += a;
        m2 += a;
        m3 += a;
    }
    vec3 f = pat->crackle_form;
    if (pat->crackle_solid) t = shade_noise_value(v3(X[mi], Y[mi], Z[mi]), gen);
    else if (metric == 2) t = f.x * sqrt(m1) + f.y * sqrt(m2) + f.z * sqrt(m3);
    else if (metric == 1) t = f.x * m1 + f.y * m2 + f.z * m3;
    else {
        /* a form weight of 0 (the default form's third) adds exactly 0:
         * its root is not taken */
        double r = 1.0 / metric;
        t = (f.x != 0.0 ? f.x * pow(m1, r) : 0.0) + (f.y != 0.0 ? f.y * pow(m2, r) : 0.0) +
            (f.z != 0.0 ? f.z * pow(m3, r) : 0.0);
    }
    return fmax_inline(fmin_inline(t, 1.0), 0.0);
}

static double granite(vec3 p, int gen)
{
    /* the noise at 4 p scaled by 1, 2, 4, ... 32 */
    double noise = 0.0, freq = 1.0, n[6];
    shade_noise_octaves(v3_scale(p, 4.0), 6, 2.0, gen, n);
    for (int i = 0; i < 6; freq *= 2.0, i++) {
        double t;
        if (gen == 1) {
            t = fabs(0.5 - n[i]);
        } else {
            t = fabs(1.0 - 2.0 * n[i]);
            if (t > 0.5) t = 0.5;
        }
        noise += t / freq;
    }
    return noise;
}

static double hexagon(vec3 p)
{
    const double xf = 0.5, zf = 0.866025404;
    double x = fabs(p.x), z = p.z;
    z = z < 0.0 ? 5.196152424 - fabs(z) : z;
    double xs = x / xf, zs = z / zf;
    xs -= floor(xs / 6.0) * 6.0;
    zs -= floor(zs / 6.0) * 6.0;
    int xm = shade_noise_to_int(pov_floor(xs)) % 6, zm = shade_noise_to_int(pov_floor(zs)) % 6;
    double v = 0.0;
    switch (xm) {
    case 0: case 5:
        v = (zm == 0 || zm == 5) ? 0 : (zm == 1 || zm == 2) ? 1 : 2;
        break;
    case 2: case 3:
        v = (zm == 0 || zm == 1) ? 2 : (zm == 2 || zm == 3) ? 0 : 1;
        break;
    case 1: case 4: {
        double xl = xs - xm, zl = zs - zm;
        if (((xm + zm) % 2) == 1) xl = 1.0 - xl;
        if (xl == 0.0) xl = 0.0001;
        if ((zl / xl) < 1.0) v = (zm == 0 || zm == 3) ? 0 : (zm == 2 || zm == 5) ? 1 : 2;
        else v = (zm == 0 || zm == 3) ? 2 : (zm == 2 || zm == 5) ? 0 : 1;
        break;
    }
    }
    return fmod(v, 3.0);
}

static double square_pat(vec3 p)
{
    int vx = shade_noise_to_int(floor(p.x)), vz = shade_noise_to_int(floor(p.z));
    if (vx & 1) return (vz & 1) ? 2.0 : 3.0;
    return (vz & 1) ? 1.0 : 0.0;
}

static double triangular(vec3 p)
{
    const double sqrt3 = 1.7320508075688772935274463415059, sqrt3_2 = 0.86602540378443864676372317075294;
    double xs = p.x - 3.0 * floor(p.x / 3.0), zs = p.z - sqrt3 * floor(p.z / sqrt3);
    int a = shade_noise_to_int(floor(xs));
    xs -= a;
    int b = zs < sqrt3_2 ? 0 : 1;
    if (b) zs = sqrt3 - zs;
    double k = 1.0 - xs, ans = 1.0;
    if (xs != 0.0 && k != 0.0) {
        double s1 = zs / xs, s2 = zs / k;
        switch ((s1 < sqrt3 ? 1 : 0) + (s2 < sqrt3 ? 2 : 0)) {
        case 3: ans = 0.0; break;
        case 2: ans = 1.0; break;
        case 1: ans = 3.0; break;
        default: ans = 0.0; break; /* unreachable in POV-Ray (value left unset there) */
        }
    }
    int mask = (int)ans;
    ans = (mask & 1) ? fmod(ans + 2.0 * a, 6.0) : fmod(6.0 + ans - 2.0 * a, 6.0);
    if (b) ans = 5.0 - ans;
    return ans;
}

static double cubic_pat(vec3 p)
{
    double x = p.x, y = p.y, z = p.z, ax = fabs(x), ay = fabs(y), az = fabs(z);
    if (x >= 0 && x >= ay && x >= az) return 0.0;
    if (y >= 0 && y >= ax && y >= az) return 1.0;
    if (z >= 0 && z >= ax && z >= ay) return 2.0;
    if (x < 0 && x <= -ay && x <= -az) return 3.0;
    if (y < 0 && y <= -ax && y <= -az) return 4.0;
    return 5.0;
}

static double quilt_cubic(double t, double p1, double p2)
{
    double it = 1 - t, itsq = it * it, tsq = t * t, tcube = t * tsq;
    return (tcube + 3.0 * t * itsq * p1 + 3.0 * tsq * it * p2) * 1.154700538;
}

static double quilted(const scene_pattern *pat, vec3 p)
{
    vec3 v = v3(p.x - pov_floor(p.x) - 0.5, p.y - pov_floor(p.y) - 0.5, p.z - pov_floor(p.z) - 0.5);
    double t = sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    t = quilt_cubic(t, pat->control0, pat->control1);
    return (fabs(v.x * t) + fabs(v.y * t) + fabs(v.z * t)) / 3.0;
}

static double radial(vec3 p)
{
    if (fabs(p.x) < 0.001 && fabs(p.z) < 0.001) return 0.25;
    return 0.25 + (atan2(p.x, p.z) + PI_) / TWO_PI;
}

static double ripples(const scene_pattern *pat, vec3 p, int nw)
{
    double s = 0.0;
    for (int i = 0; i < nw; i++) {
        double len = v3_len(v3_sub(p, shade_noise_wave_source(i)));
        if (len == 0.0) len = 1.0;
        s += shade_noise_cycloidal(len * pat->frequency + pat->phase);
    }
    return 0.5 * (1.0 + (s / (double)nw));
}

static double waves(const scene_pattern *pat, vec3 p, int nw)
{
    double s = 0.0;
    for (int i = 0; i < nw; i++) {
        double len = v3_len(v3_sub(p, shade_noise_wave_source(i)));
        if (len == 0.0) len = 1.0;
        double f = shade_noise_wave_frequency(i);
        s += shade_noise_cycloidal(len * pat->frequency * f + pat->phase) / f;
    }
    return 0.2 * (2.5 + (s / (double)nw));
}

static double spiral_phi(double x, double y, double rad)
{
    if (rad == 0.0) return 0.0;
    return x < 0.0 ? 3.0 * HALF_PI - asin(y / rad) : HALF_PI + asin(y / rad);
}

static double spiral1(const scene_pattern *pat, vec3 p, int gen)
{
    double tv = turb_scalar(pat, p, gen);
    double rad = sqrt(p.x * p.x + p.y * p.y);
    double phi = spiral_phi(p.x, p.y, rad);
    return p.z + rad + (double)pat->arms * phi / TWO_PI + tv;
}

static double spiral2(const scene_pattern *pat, vec3 p, int gen)
{
    double tv = turb_scalar(pat, p, gen);
    double rad = sqrt(p.x * p.x + p.y * p.y);
    double phi = spiral_phi(p.x, p.y, rad);
    tv = shade_noise_triangle_wave(p.z + rad + (double)pat->arms * phi / TWO_PI + tv);
    return shade_noise_triangle_wave(rad) + tv;
}

static double wood(const scene_pattern *pat, vec3 p)
{
    const scene_warp *t = pattern_classic_turb(pat);
    double px = 0.0, py = 0.0;
    if (t) {
        vec3 wt = shade_noise_dturbulence(p, t->octaves, t->omega, t->lambda);
        px = shade_noise_cycloidal((p.x + wt.x) * t->turbulence.x);
        py = shade_noise_cycloidal((p.y + wt.y) * t->turbulence.y);
    }
    px += p.x;
    py += p.y;
    return sqrt(px * px + py * py);
}

static double wrinkles(vec3 p, int gen)
{
    /* the noise at p scaled by 1, 2, 4, ... 512 */
    double n[10], omega = 0.5, value;
    shade_noise_octaves(p, 10, 2.0, gen, n);
    if (gen > 1) value = fmin_inline(fmax_inline(n[0] * 2.0 - 0.5, 0.0), 1.0);
    else value = n[0];
    for (int i = 1; i < 10; i++) {
        if (gen > 1) value += omega * fmin_inline(fmax_inline(n[i] * 2.0 - 0.5, 0.0), 1.0);
        else value += omega * n[i];
        omega *= 0.5;
    }
    return value / 2.0;
}

/* POV-Ray's slope_pattern: the angle of the (perturbed, world) normal to
 * the slope direction (or the direction to the point_at point) mapped to
 * [0, 1], optionally mixed with the altitude along a direction (at the
 * pattern-space point). */
/* ------------------------------------------------------------ fractals
 * POV-Ray's mandel/julia (exponents 2, 3, 4 in closed form, 5..33 through
 * binomial sums), magnet 1/2 (mandel and julia forms), escape at |z|^2 > 4
 * (magnet: > 10000 or within 1/100 of 1), and the exterior/interior colour
 * rules (iterations fraction, a, b, a^2, b^2, |z|, modulo counts; smallest
 * |z| seen, ...). */

static double fractal_exterior(const scene_pattern *pat, int iters, double a, double b)
{
    double f = pat->efactor;
    switch (pat->exterior_type) {
    case 0: return f;
    case 1: return (double)iters / (double)pat->iterations;
    case 2: return a * f;
    case 3: return b * f;
    case 4: return a * a * f;
    case 5: return b * b * f;
    case 6: return sqrt(a * a + b * b) * f;
    case 7: {
        unsigned m = (unsigned)f;
        return m ? (double)(iters % m) / f : 0.0;
    }
    case 8: return (double)(iters % (unsigned)(1 + f)) / f;
    default: return 0.0;
    }
}

static double fractal_interior(const scene_pattern *pat, double a, double b, double mindist2)
{
    double f = pat->ifactor;
    switch (pat->interior_type) {
    case 0: return f;
    case 1: return sqrt(mindist2) * f;
    case 2: return a * f;
    case 3: return b * f;
    case 4: return a * a * f;
    case 5: return b * b * f;
    case 6: return a * a + b * b * f; /* as POV-Ray writes it */
    default: return 0.0;
    }
}

static double binomial(int n, int k)
{
    double r = 1.0;
    for (int i = 1; i <= k; i++) r = r * (n - k + i) / i;
    return floor(r + 0.5);
}

static double mandel_julia(const scene_pattern *pat, vec3 p)
{
    int julia = pat->kind == PAT_JULIA, n = pat->fractal_exponent, it_max = pat->iterations, col;
    double cr = julia ? pat->julia_c[0] : p.x, ci = julia ? pat->julia_c[1] : p.y;
    double a = p.x, b = p.y, a2 = a * a, b2 = b * b, mindist2 = a2 + b2, dist2;
    for (col = 0; col < it_max; col++) {
        if (n == 2) {
            b = 2.0 * a * b + ci;
            a = a2 - b2 + cr;
        } else if (n == 3) {
            b = 3.0 * a2 * b - b2 * b + ci;
            a = a2 * a - 3.0 * a * b2 + cr;
        } else if (n == 4) {
            b = 4.0 * (a2 * a * b - a * b2 * b) + ci;
            a = a2 * a2 - 6.0 * a2 * b2 + b2 * b2 + cr;
        } else {
            double na = pow(a, n), nb = 0.0;
            for (int k = 2; k <= n; k += 2) na += ((k & 2) ? -1.0 : 1.0) * binomial(n, k) * pow(a, n - k) * pow(b, k);
            for (int l = 1; l <= n; l += 2) nb += ((l & 2) ? -1.0 : 1.0) * binomial(n, l) * pow(a, n - l) * pow(b, l);
            a = na + cr;
            b = nb + ci;
        }
        a2 = a * a;
        b2 = b * b;
        dist2 = a2 + b2;
        if (dist2 < mindist2) mindist2 = dist2;
        if (dist2 > 4.0) return fractal_exterior(pat, col, a, b);
    }
    return fractal_interior(pat, a, b, mindist2);
}

static double magnet(const scene_pattern *pat, vec3 p)
{
    int julia = pat->kind == PAT_JULIA, it_max = pat->iterations, col;
    double cr = julia ? pat->julia_c[0] : p.x, ci = julia ? pat->julia_c[1] : p.y;
    double a, b, a2, b2, mindist2, dist2, t, t1r, t1i, t2r, t2i;
    if (julia) {
        a = p.x;
        b = p.y;
        a2 = a * a;
        b2 = b * b;
        mindist2 = a2 + b2;
    } else {
        a = a2 = b = b2 = 0.0;
        mindist2 = 10000;
    }
    double c1r = cr - 1, c2r = cr - 2, c1c2r = c1r * c2r - ci * ci, c1c2i = (c1r + c2r) * ci;
    for (col = 0; col < it_max; col++) {
        if (pat->magnet == 1) {
            t1r = a2 - b2 + cr - 1;
            t1i = 2 * a * b + ci;
            t2r = 2 * a + cr - 2;
            t2i = 2 * b + ci;
        } else {
            t1r = a2 * a - 3 * a * b2 + 3 * (a * c1r - b * ci) + c1c2r;
            t1i = 3 * a2 * b - b2 * b + 3 * (a * ci + b * c1r) + c1c2i;
            t2r = 3 * (a2 - b2) + 3 * (a * c2r - b * ci) + c1c2r + 1;
            t2i = 6 * a * b + 3 * (a * ci + b * c2r) + c1c2i;
        }
        t = t2r * t2r + t2i * t2i;
        a = (t1r * t2r + t1i * t2i) / t;
        b = (t1i * t2r - t1r * t2i) / t;
        b2 = b * b;
        b = 2 * a * b;
        a = a * a - b2;
        a2 = a * a;
        b2 = b * b;
        dist2 = a2 + b2;
        if (dist2 < mindist2) mindist2 = dist2;
        t1r = a - 1;
        if (dist2 > 10000.0 || t1r * t1r + b2 < 1 / 10000.0) return fractal_exterior(pat, col, a, b);
    }
    return fractal_interior(pat, a, b, mindist2);
}

static double slope(const scene_pattern *pat, vec3 p, const shade_pattern_ctx *c)
{
    if (!c->has_hit) return 0.0;
    double v;
    if (pat->slope_point_at) v = v3_dot(c->normal, v3_norm(v3_sub(pat->slope_dir, c->ipoint)));
    else v = v3_dot(c->normal, pat->slope_dir);
    if (v > 1.0) v = 1.0;
    else if (v < -1.0) v = -1.0;
    v = asin(v) / PI_ * 2;
    v = (v + 1.0) * 0.5;
    if (pat->slope_hi != 0.0) v = (v - pat->slope_lo) / pat->slope_hi;
    if (pat->altit_len == 0.0) {
        if (v == 1.0) return v - PAT_EPSILON;
        return v < 0.0 ? 1.0 + fmod(v, 1.0) : fmod(v, 1.0);
    }
    double a = v3_dot(p, pat->altit_dir);
    if (pat->altit_hi != 0.0) a = (a - pat->altit_lo) / pat->altit_hi;
    double value = pat->slope_len * v + pat->altit_len * a;
    if (value - 1.0 < PAT_EPSILON && value >= 1.0) return value - PAT_EPSILON;
    return value < 0.0 ? 1.0 + fmod(value, 1.0) : fmod(value, 1.0);
}

static double aoi(const shade_pattern_ctx *c)
{
    if (!c->has_hit) return 0.0;
    double ca = v3_dot(v3_norm(c->normal), v3_norm(c->dir));
    ca = fmin_inline(1.0, fmax_inline(-1.0, ca));
    return acos(ca) / PI_;
}

/* density_file: the df3 samples over the unit cube [0,1)^3, 0 outside
 * (POV-Ray 3.7's density_pattern). Interpolation 0: the sample of the
 * cell; 1: trilinear; 2 (and others): tricubic through four samples per
 * axis, indices wrapping around the grid as POV-Ray's unsigned arithmetic
 * wraps them (index -1 becomes SIZE_MAX modulo the size). */
static double df3_at(const scene_density *d, size_t x, size_t y, size_t z)
{
    return d->v[(z * (size_t)d->ny + y) * (size_t)d->nx + x];
}

/* Cubic through fa..fd at t between fb and fc, with slopes from the
 * neighbours (central differences), in POV-Ray's single precision. */
static float df3_cubic(float t, float fa, float fb, float fc, float fd)
{
    float b = (float)((fc - fa) * 0.5);
    float d = (float)((fd - fb) * 0.5);
    float e = (float)(2.0 * (fb - fc) + b + d);
    float f = (float)(-3.0 * (fb - fc) - 2.0 * b - d);
    return (float)(((e * t + f) * t + b) * t + fb);
}

static double density(const scene_pattern *pat, vec3 p)
{
    const scene_density *d = pat->density;
    if (!d || !d->v || d->nx <= 0 || d->ny <= 0 || d->nz <= 0) return 0.0;
    if (!(p.x >= 0.0 && p.x < 1.0 && p.y >= 0.0 && p.y < 1.0 && p.z >= 0.0 && p.z < 1.0)) return 0.0;
    size_t nx = (size_t)d->nx, ny = (size_t)d->ny, nz = (size_t)d->nz;
    double xx = p.x * (double)nx, yy = p.y * (double)ny, zz = p.z * (double)nz;
    size_t x1 = (size_t)xx, y1 = (size_t)yy, z1 = (size_t)zz;
    double v;
    int mode = pat->density_interpolate % 10;
    if (mode == 0) {
        if (x1 >= nx || y1 >= ny || z1 >= nz) return 0.0;
        v = df3_at(d, x1, y1, z1);
    } else if (mode == 1) {
        if (x1 >= nx || y1 >= ny || z1 >= nz) return 0.0;
        size_t x2 = (x1 + 1) % nx, y2 = (y1 + 1) % ny, z2 = (z1 + 1) % nz;
        xx -= floor(xx);
        yy -= floor(yy);
        zz -= floor(zz);
        double xi = 1.0 - xx, yi = 1.0 - yy;
        double lo = (df3_at(d, x1, y1, z1) * xi + df3_at(d, x2, y1, z1) * xx) * yi +
                    (df3_at(d, x1, y2, z1) * xi + df3_at(d, x2, y2, z1) * xx) * yy;
        double hi = (df3_at(d, x1, y1, z2) * xi + df3_at(d, x2, y1, z2) * xx) * yi +
                    (df3_at(d, x1, y2, z2) * xi + df3_at(d, x2, y2, z2) * xx) * yy;
        v = lo * (1.0 - zz) + hi * zz;
    } else {
        xx -= floor(xx);
        yy -= floor(yy);
        zz -= floor(zz);
        size_t k[4];
        for (int i = 0; i < 4; i++) k[i] = (z1 + (size_t)i - 1) % nz;
        float col[4][4]; /* [x][y], each interpolated along z */
        for (int i = 0; i < 4; i++) {
            size_t ii = (x1 + (size_t)i - 1) % nx;
            for (int j = 0; j < 4; j++) {
                size_t jj = (y1 + (size_t)j - 1) % ny;
                col[i][j] = df3_cubic((float)zz, (float)df3_at(d, ii, jj, k[0]), (float)df3_at(d, ii, jj, k[1]),
                                      (float)df3_at(d, ii, jj, k[2]), (float)df3_at(d, ii, jj, k[3]));
            }
        }
        float row[4];
        for (int i = 0; i < 4; i++) row[i] = df3_cubic((float)yy, col[i][0], col[i][1], col[i][2], col[i][3]);
        v = df3_cubic((float)xx, row[0], row[1], row[2], row[3]);
    }
    return v < 0.0 ? 0.0 : v;
}

/* Shapes of object patterns, built once per thread and scene: building a
 * shape (a text's outline and its index, say) costs far more than one inside
 * test, and the pattern asks for every shading point. Slots are keyed by the
 * scene's serial, which is never reused, so a freed scene's slots never
 * match; they are replaced round-robin and freed when the thread ends. */
#define SHAPE_SLOTS 16
typedef struct {
    unsigned long serial;
    const scene_object *o;
    geom_shape sh;
    int ok;
} shape_slot;
typedef struct {
    shape_slot slot[SHAPE_SLOTS];
    int next;
} shape_slots;

static tss_t slots_key;
static int slots_key_ok;
static once_flag slots_once = ONCE_FLAG_INIT;

static void slots_free(void *p)
{
    shape_slots *c = p;
    if (!c) return;
    for (int i = 0; i < SHAPE_SLOTS; i++)
        if (c->slot[i].serial) geom_shape_release(&c->slot[i].sh);
    free(c);
}

static void slots_init(void) { slots_key_ok = tss_create(&slots_key, slots_free) == thrd_success; }

/* The shape of leaf o, or NULL when none is cached (no serial, no memory). */
static const geom_shape *cached_shape(const scene_object *o, unsigned long serial, int *ok)
{
    if (!serial) return NULL;
    call_once(&slots_once, slots_init);
    if (!slots_key_ok) return NULL;
    shape_slots *c = tss_get(slots_key);
    if (!c) {
        c = calloc(1, sizeof *c);
        if (!c || tss_set(slots_key, c) != thrd_success) {
            free(c);
            return NULL;
        }
    }
    for (int i = 0; i < SHAPE_SLOTS; i++)
        if (c->slot[i].serial == serial && c->slot[i].o == o) {
            *ok = c->slot[i].ok;
            return &c->slot[i].sh;
        }
    shape_slot *s = &c->slot[c->next];
    c->next = (c->next + 1) % SHAPE_SLOTS;
    if (s->serial) geom_shape_release(&s->sh);
    memset(s, 0, sizeof *s);
    s->serial = serial;
    s->o = o;
    s->ok = geom_shape_init(&s->sh, o) == 0;
    *ok = s->ok;
    return &s->sh;
}

/* The object pattern's inside test (POV-Ray's Inside_Object): CSG as
 * union/merge any, intersection all, difference the first and none of the
 * others, each node's `inverse` negating it; leaves by accel's shape test
 * (a shape accel cannot build, or a patch without inside, is outside).
 * A clipped_by solid must contain the point too, whatever the object's
 * `inverse` (POV-Ray 3.7's Inside_Object tests the clip list first); its
 * transform is relative to the object's space. */
static int object_inside(const scene_object *o, vec3 p, unsigned long serial, int depth)
{
    int in = 0;
    if (depth > 64) return 0;
    if (o->clip && !object_inside(o->clip, xform_inv_point(&o->transform, p), serial, depth + 1)) return 0;
    switch (o->kind) {
    case SHAPE_UNION: case SHAPE_MERGE:
        for (int i = 0; i < o->u.csg.nkids && !in; i++) in = object_inside(o->u.csg.kids[i], p, serial, depth + 1);
        break;
    case SHAPE_INTERSECTION:
        in = o->u.csg.nkids > 0;
        for (int i = 0; i < o->u.csg.nkids && in; i++) in = object_inside(o->u.csg.kids[i], p, serial, depth + 1);
        break;
    case SHAPE_DIFFERENCE:
        in = o->u.csg.nkids > 0 && object_inside(o->u.csg.kids[0], p, serial, depth + 1);
        for (int i = 1; i < o->u.csg.nkids && in; i++) in = !object_inside(o->u.csg.kids[i], p, serial, depth + 1);
        break;
    default: {
        int ok = 0;
        const geom_shape *csh = cached_shape(o, serial, &ok);
        if (csh) {
            in = ok && geom_shape_inside(csh, p);
        } else {
            geom_shape sh;
            if (geom_shape_init(&sh, o) == 0) in = geom_shape_inside(&sh, p);
            geom_shape_release(&sh);
        }
        break;
    }
    }
    return (o->flags & OBJ_INVERSE) ? !in : in;
}

static double raw_value(const scene_pattern *pat, vec3 p, const shade_pattern_ctx *c)
{
    int gen = pat->noise_generator ? pat->noise_generator : c->noise_generator;
    switch (pat->kind) {
    case PAT_AGATE: return agate(pat, p, gen);
    case PAT_BOZO: case PAT_SPOTTED: case PAT_BUMPS: return shade_noise_value(p, gen);
    case PAT_BRICK: return brick(pat, p);
    case PAT_CELLS: return cells(p);
    case PAT_CHECKER: return checker(p);
    case PAT_CRACKLE: return crackle(pat, p, gen);
    case PAT_GRADIENT: {
        double r = v3_dot(p, pat->gradient);
        return r > 1.0 ? fmod(r, 1.0) : r;
    }
    case PAT_GRANITE: return granite(p, gen);
    case PAT_HEXAGON: return hexagon(p);
    case PAT_SQUARE: return square_pat(p);
    case PAT_TRIANGULAR: return triangular(p);
    case PAT_CUBIC: return cubic_pat(p);
    case PAT_LEOPARD: {
        double s = (sin(p.x) + sin(p.y) + sin(p.z)) / 3.0;
        return s * s;
    }
    case PAT_MARBLE: return p.x + turb_scalar(pat, p, gen);
    case PAT_ONION: return fmod(sqrt(p.x * p.x + p.y * p.y + p.z * p.z), 1.0);
    case PAT_RADIAL: return radial(p);
    case PAT_SPIRAL1: return spiral1(pat, p, gen);
    case PAT_SPIRAL2: return spiral2(pat, p, gen);
    case PAT_WOOD: return wood(pat, p);
    case PAT_WAVES: return waves(pat, p, c->nwaves > 0 ? c->nwaves : SHADE_NOISE_WAVES);
    case PAT_RIPPLES: return ripples(pat, p, c->nwaves > 0 ? c->nwaves : SHADE_NOISE_WAVES);
    case PAT_WRINKLES: return wrinkles(p, gen);
    case PAT_DENTS: {
        double n = shade_noise_value(p, gen);
        return n * n * n;
    }
    case PAT_QUILTED: return quilted(pat, p);
    case PAT_PLANAR: return clip_density(fabs(p.y));
    case PAT_BOXED: return clip_density(fmax_inline(fabs(p.x), fmax_inline(fabs(p.y), fabs(p.z))));
    case PAT_SPHERICAL: return clip_density(v3_len(p));
    case PAT_CYLINDRICAL: return clip_density(sqrt(p.x * p.x + p.z * p.z));
    case PAT_PIGMENT: {
        colour5 col;
        if (!pat->pigment || !shade_pigment_eval(pat->pigment, p, c, &col)) return 0.0;
        return GREY(col.r, col.g, col.b);
    }
    case PAT_IMAGE: {
        /* image_pattern: the greyscale (or alpha with use_alpha) of the image */
        colour5 col;
        if (!pattern_image_colour(&pat->image, p, &col)) return 0.0;
        if (pat->image.use_alpha) return 1.0 - col.t;
        return GREY(col.r, col.g, col.b);
    }
    case PAT_FUNCTION: {
        /* POV-Ray's function_pattern: f(x, y, z), values above 1 taken mod 1 */
        if (!pat->function) return 0.0;
        double args[3] = {p.x, p.y, p.z};
        double v = func_eval_float(pat->function, args, shade_func_env());
        if (!isfinite(v)) return 0.0;
        return v > 1.0 ? fmod(v, 1.0) : v;
    }
    case PAT_SLOPE: return slope(pat, p, c);
    case PAT_MANDEL: case PAT_JULIA: return pat->magnet ? magnet(pat, p) : mandel_julia(pat, p);
    case PAT_AOI: return aoi(c);
    case PAT_TILING: return shade_tiling_value(pat->tiling, p);
    case PAT_PAVEMENT: {
        shade_pavement_params pv = {pat->pave_sides, pat->pave_tiles, pat->pave_number,
                              pat->pave_exterior, pat->pave_interior, pat->pave_form};
        return shade_pavement_value(&pv, p);
    }
    case PAT_DENSITY: return density(pat, p);
    case PAT_OBJECT:
        /* a pigment function's context names no scene: the pattern's own
         * (without a cached shape, each test would build the shapes anew:
         * a text or lathe integrates its surface area when built) */
        return pat->object && object_inside(pat->object, p, c->scene_serial ? c->scene_serial : pat->object_serial, 0)
                   ? 1.0
                   : 0.0;
    default: return 0.0;
    }
}

double shade_pattern_value(const scene_pattern *pat, vec3 tp, const shade_pattern_ctx *c)
{
    double v = raw_value(pat, tp, c);
    if (pat->frequency != 0.0) {
        /* fmod is exact, so a value already in [0, 1.00001) is its own
         * remainder (most are: raw values lie in [0, 1] and the default
         * frequency is 1, phase 0); the call only for the others */
        double x = v * pat->frequency + pat->phase;
        v = x >= 0.0 && x < 1.00001 ? x : fmod(x, 1.00001);
    }
    if (v < 0.0) v -= floor(v);
    switch (pat->wave) {
    case WAVE_RAMP: break;
    case WAVE_SINE: v = (1.0 + shade_noise_cycloidal(v)) * 0.5; break;
    case WAVE_TRIANGLE: v = shade_noise_triangle_wave(v); break;
    case WAVE_SCALLOP: v = fabs(shade_noise_cycloidal(v * 0.5)); break;
    case WAVE_CUBIC: v = v * v * ((-2.0 * v) + 3.0); break;
    case WAVE_POLY: v = pow(v, pat->exponent); break;
    }
    return v;
}

/* ------------------------------------------------------------ blend maps */

#define F(x) ((double)(float)(x))
#define E(v, r, g, b) {F(v), {F(r), F(g), F(b), 0, 0}, NULL, NULL, NULL, 0, 0}
static const scene_map_entry grey_e[] = {E(0.0, 0, 0, 0), E(1.0, 1, 1, 1)};
static const scene_map_entry bozo_e[] = {E(0.4, 1, 1, 1), E(0.4, 0, 1, 0), E(0.6, 0, 1, 0),
                                         E(0.6, 0, 0, 1), E(0.8, 0, 0, 1), E(0.8, 1, 0, 0)};
static const scene_map_entry wood_e[] = {E(0.6, 0.666, 0.312, 0.2), E(0.6, 0.4, 0.1333, 0.066)};
static const scene_map_entry agate_e[] = {E(0.0, 1.0, 1.0, 1.0), E(0.5, 0.95, 0.75, 0.5), E(0.5, 0.9, 0.7, 0.5),
                                          E(0.6, 0.9, 0.7, 0.4), E(0.6, 1.0, 0.7, 0.4), E(1.0, 0.6, 0.3, 0.0)};
static const scene_map_entry radial_e[] = {E(0.0, 0, 1, 1), E(0.333, 1, 1, 0), E(0.666, 1, 0, 1), E(1.0, 0, 1, 1)};
static const scene_map_entry marble_e[] = {E(0.0, 0.9, 0.8, 0.8), E(0.9, 0.9, 0.08, 0.08), E(0.9, 0, 0, 0)};
static const scene_map_entry brick_e[] = {E(0.0, 0.5, 0.5, 0.5), E(1.0, 0.6, 0.15, 0.15)};
static const scene_map_entry hex_e[] = {E(0.0, 0, 0, 1), E(1.0, 0, 1, 0), E(2.0, 1, 0, 0)};
static const scene_map_entry mandel_e[] = {E(0.001, 0, 0, 0), E(0.001, 0, 1, 1), E(0.012, 1, 1, 0), E(0.015, 1, 0, 1),
                                           E(0.1, 0, 1, 1)};
static const scene_map_entry cubic_e[] = {E(0.0, 1, 0, 0), E(1.0, 0, 1, 0), E(1.0, 0, 0, 1),
                                          E(1.0, 1, 1, 0), E(1.0, 0, 1, 1), E(2.0, 1, 0, 1)};
#undef E
static const scene_blend_map grey_map = {MAP_COLOUR, 2, grey_e};
static const scene_blend_map bozo_map = {MAP_COLOUR, 6, bozo_e};
static const scene_blend_map wood_map = {MAP_COLOUR, 2, wood_e};
static const scene_blend_map agate_map = {MAP_COLOUR, 6, agate_e};
static const scene_blend_map radial_map = {MAP_COLOUR, 4, radial_e};
static const scene_blend_map marble_map = {MAP_COLOUR, 3, marble_e};
static const scene_blend_map brick_map = {MAP_COLOUR, 2, brick_e};
static const scene_blend_map hex_map = {MAP_COLOUR, 3, hex_e};
static const scene_blend_map check_map = {MAP_COLOUR, 2, hex_e};      /* POV-Ray uses the hexagon entries */
static const scene_blend_map cubic_map = {MAP_COLOUR, 6, cubic_e};
static const scene_blend_map mandel_map = {MAP_COLOUR, 5, mandel_e};
static const scene_blend_map square_map = {MAP_COLOUR, 4, cubic_e};   /* likewise the cubic entries */

/* POV-Ray's default colour map for a pattern kind (bozo, wood, radial...). */
static const scene_blend_map *pattern_default_map(pattern_kind k)
{
    switch (k) {
    case PAT_BOZO: return &bozo_map;
    case PAT_BRICK: return &brick_map;
    case PAT_WOOD: return &wood_map;
    case PAT_RADIAL: return &radial_map;
    case PAT_AGATE: return &agate_map;
    case PAT_MARBLE: return &marble_map;
    case PAT_HEXAGON: return &hex_map;
    case PAT_SQUARE: return &square_map;
    case PAT_TRIANGULAR: case PAT_CUBIC: return &cubic_map;
    case PAT_CHECKER: return &check_map;
    case PAT_MANDEL: return &mandel_map; /* POV-Ray: mandel (not julia, magnet) */
    default: return &grey_map;
    }
}

void shade_blend_map_search(const scene_blend_map *m, double v, int *prev, int *cur)
{
    /* a map has at least one entry (the parser refuses an empty one) */
    assert(m->n >= 1 && m->e);
    int last = m->n - 1, p, c;
    if (v >= m->e[last].value) {
        p = c = last;
    } else {
        p = c = 0;
        while (v > m->e[c].value) p = c++;
    }
    if (v == m->e[c].value) p = c;
    assert(0 <= p && p <= c && c <= last);
    *prev = p;
    *cur = c;
}

/* ------------------------------------------------------------ pigments */

static colour5 c5_lerp(colour5 a, colour5 b, double f)
{
    /* POV-Ray: Temp + fraction * (colour - Temp) */
    colour5 r = {a.r + f * (b.r - a.r), a.g + f * (b.g - a.g), a.b + f * (b.b - a.b), a.f + f * (b.f - a.f), a.t + f * (b.t - a.t)};
    return r;
}

static colour5 entry_colour(const scene_map_entry *e)
{
    colour5 c = {e->c[0], e->c[1], e->c[2], e->c[3], e->c[4]};
    return c;
}

int shade_pigment_eval(const scene_pigment *pg, vec3 p, const shade_pattern_ctx *c, colour5 *out)
{
    if (pg->kind != PIGMENT_PATTERN || !pg->pat) {
        *out = pg->colour;
        return 1;
    }
    const scene_pattern *pat = pg->pat;
    /* pigment { uv_mapping ... }: POV-Ray's UV_MAP_PATTERN evaluates the
     * pigment at the hit's <u, v, 0> (pigment.cpp), its own transforms only */
    if (pat->uv_mapping && c && c->has_uv) p = v3(c->uv[0], c->uv[1], 0.0);
    vec3 q = xform_is_identity(&pg->transform) ? p : xform_inv_point(&pg->transform, p);
    /* without warps, shade_pattern_warp is the clamp alone (no call) */
    vec3 tp = pat->nwarps ? shade_pattern_warp(pat, q) : coord_clamp(q);
    if (pat->kind == PAT_IMAGE && !pg->map) return pattern_image_colour(&pat->image, tp, out);
    const scene_blend_map *m = pg->map ? pg->map : pattern_default_map(pat->kind);
    if (!pg->map && pat->kind == PAT_MANDEL && (pat->magnet || pat->fractal_exponent != 2)) m = &grey_map;
    if (pat->kind == PAT_AVERAGE) {
        colour5 acc = {0, 0, 0, 0, 0};
        double total = 0.0;
        for (int i = 0; i < m->n; i++) {
            colour5 lc = {0, 0, 0, 0, 0};
            float w = (float)m->e[i].value;
            if (m->kind == MAP_PIGMENT && m->e[i].pigment) shade_pigment_eval(m->e[i].pigment, tp, c, &lc);
            else lc = entry_colour(&m->e[i]);
            acc.r += lc.r * w; acc.g += lc.g * w; acc.b += lc.b * w; acc.f += lc.f * w; acc.t += lc.t * w;
            total += w;
        }
        if (total != 0.0) {
            acc.r /= total; acc.g /= total; acc.b /= total; acc.f /= total; acc.t /= total;
        }
        *out = acc;
        return 1;
    }
    double v = shade_pattern_value(pat, tp, c);
    int ip, ic;
    shade_blend_map_search(m, v, &ip, &ic);
    int found = 0;
    colour5 col = {0, 0, 0, 0, 0}, prev = {0, 0, 0, 0, 0};
    if (m->kind == MAP_PIGMENT) {
        if (m->e[ic].pigment && shade_pigment_eval(m->e[ic].pigment, tp, c, &col)) found = 1;
    } else {
        col = entry_colour(&m->e[ic]);
        found = 1;
    }
    if (ip != ic) {
        if (m->kind == MAP_PIGMENT) {
            if (m->e[ip].pigment && shade_pigment_eval(m->e[ip].pigment, tp, c, &prev)) found = 1;
        } else {
            prev = entry_colour(&m->e[ip]);
        }
        /* between two entries of one colour the blend is that colour (a
         * finite fraction times a zero difference): no division there */
        if (prev.r != col.r || prev.g != col.g || prev.b != col.b || prev.f != col.f || prev.t != col.t) {
            double f = (v - m->e[ip].value) / (m->e[ic].value - m->e[ip].value);
            col = c5_lerp(prev, col, f);
        }
    }
    *out = col;
    return found;
}

/* ------------------------------------------------------------ image maps */

static double wrap_to(double v, double n)
{
    double t = fmod(v, n);
    if (t < 0.0) t += n;
    if (t >= n) t = 0.0;
    return t;
}

static int image_uv(const scene_image_map *im, vec3 p, double *u, double *v)
{
    const scene_image *img = im->image;
    /* the mapped size: the image's, times `repeat` (POV-Ray's width/height
     * beside iwidth/iheight) */
    double w = img->width * (im->repeat_u > 0.0 ? im->repeat_u : 1.0);
    double h = img->height * (im->repeat_v > 0.0 ? im->repeat_v : 1.0);
    double x = p.x, y = p.y, z = p.z;
    switch (im->map_type) {
    case 1: { /* spherical */
        double len = sqrt(x * x + y * y + z * z);
        if (len == 0.0) return 0;
        x /= len; y /= len; z /= len;
        double phi = 0.5 + asin(y) / PI_;
        double l2 = sqrt(x * x + z * z);
        double theta = l2 == 0.0 ? 0.0 : xz_angle(x, z, l2) / TWO_PI;
        *u = theta * w;
        *v = phi * h;
        return 1;
    }
    case 2: { /* cylindrical */
        if (im->once && (y < 0.0 || y > 1.0)) return 0;
        *v = fmod(y * h, h);
        double len = sqrt(x * x + y * y + z * z);
        if (len == 0.0) return 0;
        x /= len; z /= len;
        double l2 = sqrt(x * x + z * z);
        if (l2 == 0.0) return 0;
        *u = xz_angle(x, z, l2) / TWO_PI * w;
        return 1;
    }
    case 5: { /* torus */
        double len = sqrt(x * x + z * z);
        if (len == 0.0) return 0;
        double theta = 0.0 - xz_angle(x, z, len);
        x = len - im->major_radius;
        len = sqrt(x * x + y * y);
        double phi = acos(-x / len);
        if (y > 0.0) phi = TWO_PI - phi;
        *u = -(theta / TWO_PI) * w;
        *v = (phi / TWO_PI) * h;
        return 1;
    }
    default: /* planar: gradient <1,-1,0>: u from x, v from y */
        if (im->once && (x < 0.0 || x > 1.0)) return 0;
        *u = fmod(x * w, w);
        if (im->once && (y < 0.0 || y > 1.0)) return 0;
        *v = fmod(y * h, h);
        return 1;
    }
}

static colour5 pixel(const scene_image_map *im, double xc, double yc)
{
    const scene_image *img = im->image;
    int ix, iy;
    if (im->once) {
        ix = xc < 0.0 ? 0 : (xc >= img->width ? img->width - 1 : shade_noise_to_int(xc));
        iy = yc < 0.0 ? 0 : (yc >= img->height ? img->height - 1 : shade_noise_to_int(yc));
    } else {
        ix = shade_noise_to_int(wrap_to(xc, img->width));
        iy = shade_noise_to_int(wrap_to(yc, img->height));
    }
    if (ix < 0 || ix >= img->width) ix = 0; /* NaN coordinates */
    if (iy < 0 || iy >= img->height) iy = 0;
    const float *px = img->pixels + ((size_t)iy * img->width + ix) * 5;
    colour5 c = {px[0], px[1], px[2], px[3], px[4]};
    if (im->transmit_all_set) c.t += im->transmit_all;
    if (im->filter_all_set) c.f += im->filter_all;
    return c;
}

int shade_pattern_image_index(const scene_image_map *im, double xc, double yc)
{
    const scene_image *img = im->image;
    if (!img || !img->indices) return -1;
    int ix = shade_noise_to_int(wrap_to(xc, img->width)), iy = shade_noise_to_int(wrap_to(yc, img->height));
    if (ix < 0 || ix >= img->width) ix = 0;
    if (iy < 0 || iy >= img->height) iy = 0;
    return img->indices[(size_t)iy * img->width + ix];
}

int shade_pattern_image_pos(const scene_image_map *im, vec3 tp, double *x, double *y)
{
    if (!im->image || !im->image->pixels) return 0;
    double xc = 0.0, yc = 0.0;
    if (!image_uv(im, tp, &xc, &yc)) return 0;
    double w = im->image->width, h = im->image->height;
    xc += im->offset_x + PAT_EPSILON;
    yc += im->offset_y + PAT_EPSILON;
    if (im->once && (xc >= w || yc >= h || xc < 0.0 || yc < 0.0)) return 0;
    *x = wrap_to(xc, w);
    *y = wrap_to(-yc, h); /* image rows run top-down */
    return 1;
}

/* Image-map colour at a warped point (POV-Ray's image_map); 0 outside a
 * `once` image (then *out is clear: transmit 1). */
static int pattern_image_colour(const scene_image_map *im, vec3 tp, colour5 *out)
{
    colour5 clear = {1, 1, 1, 0, 1};
    double xc, yc;
    if (!shade_pattern_image_pos(im, tp, &xc, &yc)) {
        *out = clear;
        return 0;
    }
    *out = shade_pattern_image_at(im, xc, yc);
    return 1;
}

/* Catmull-Rom weights of the four samples around x (POV-Ray 3.7's bicubic
 * image interpolation, after Hagan, C Programmer's Journal 9(8)). */
static void cubic_weights(double x, double f[4])
{
    double p = x - (int)x, q = 1.0 - p;
    f[0] = -0.5 * p * q * q;
    f[1] = 0.5 * q * (q * (3.0 * p + 1.0) + 1.0);
    f[2] = 0.5 * p * (p * (3.0 * q + 1.0) + 1.0);
    f[3] = -0.5 * q * p * p;
}

colour5 shade_pattern_image_at(const scene_image_map *im, double xc, double yc)
{
    if (im->interpolate == 3) {
        xc += 0.5;
        yc += 0.5;
        int ix = shade_noise_to_int(xc), iy = shade_noise_to_int(yc);
        double fx[4], fy[4];
        cubic_weights(xc, fx);
        cubic_weights(yc, fy);
        colour5 r = {0, 0, 0, 0, 0};
        for (int i = 0; i < 4; i++)
            for (int j = 0; j < 4; j++) {
                colour5 c = pixel(im, (double)ix + i - 2, (double)iy + j - 2);
                double f = fx[i] * fy[j];
                r.r += c.r * f; r.g += c.g * f; r.b += c.b * f; r.f += c.f * f; r.t += c.t * f;
            }
        /* POV-Ray sums in double and keeps the colour in single precision */
        colour5 out = {(float)r.r, (float)r.g, (float)r.b, (float)r.f, (float)r.t};
        return out;
    }
    if (im->interpolate != 2 && im->interpolate != 4) return pixel(im, xc, yc);
    xc += 0.5;
    yc += 0.5;
    int ix = shade_noise_to_int(xc), iy = shade_noise_to_int(yc);
    colour5 cc[4] = {pixel(im, ix, iy), pixel(im, ix - 1.0, iy), pixel(im, ix, iy - 1.0), pixel(im, ix - 1.0, iy - 1.0)};
    double pp = xc - ix, q = yc - iy, f[4];
    if (im->interpolate == 2) {
        f[0] = pp * q;
        f[1] = (1 - pp) * q;
        f[2] = pp * (1 - q);
        f[3] = (1 - pp) * (1 - q);
    } else {
        double wt[4] = {1.0 / ((1 - pp) * (1 - pp) + (1 - q) * (1 - q)), 1.0 / (pp * pp + (1 - q) * (1 - q)),
                        1.0 / ((1 - pp) * (1 - pp) + q * q), 1.0 / (pp * pp + q * q)};
        double s = wt[0] + wt[1] + wt[2] + wt[3];
        for (int i = 0; i < 4; i++) f[i] = wt[i] / s;
    }
    colour5 r = {0, 0, 0, 0, 0};
    for (int i = 0; i < 4; i++) {
        r.r += cc[i].r * f[i]; r.g += cc[i].g * f[i]; r.b += cc[i].b * f[i];
        r.f += cc[i].f * f[i]; r.t += cc[i].t * f[i];
    }
    return r;
}
