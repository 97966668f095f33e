/* geom_tess.c - surface grids and area sampling for shapes known only
 * through their inside test and their ray crossings (geom_tess.h).
 *
 * Grid: marching tetrahedra over a lattice of cubes, each cube cut into the
 * six tetrahedra of Kuhn's (Freudenthal's) triangulation (the paths
 * 0 -> e_a -> e_a + e_b -> e_x + e_y + e_z over the permutations (a, b, c)),
 * so neighbouring cubes share their face diagonals and the surface is
 * watertight. A tetrahedron with one (three) inside corner(s) gives one
 * triangle, with two a quad (two triangles). Every crossing of a lattice edge
 * is found with the shape's exact ray query along the edge (bisection on the
 * inside test where rounding hides it), cached per edge, so vertices lie on
 * the exact surface and carry its exact normal.
 *
 * Sampling: the Cauchy-Crofton formula. For lines with the motion-invariant
 * measure dL = d(omega) dA_perp, the measure of lines meeting a surface
 * element dA is integral |omega . n| d(omega) dA = 2 pi dA; the lines
 * meeting a ball of radius R have measure 4 pi * pi R^2. So for a uniform
 * random line through the ball the expected number of crossings is
 * E[k] = A / (2 pi R^2) (Santalo, "Integral Geometry and Geometric
 * Probability", 1976, ch. 14), and taking one of a line's k crossings with
 * probability 1 / kmax (accepting the line with probability k / kmax) gives
 * a point whose density is uniform by area. */
#include "geom_tess.h"
#include "hash.h"
#include "pool.h"
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define TESS_MAX_HITS 64

/* ------------------------------------------------------------ lattice space */

typedef struct {
    const geom_shape *sh;
    int world;          /* lattice in world space (unbounded shapes), else object space */
    vec3 lo, step;
    int nx, ny, nz;
    unsigned char *in;  /* (nx+1)(ny+1)(nz+1) inside flags */
    /* edge crossing cache: key = lattice index * 8 + direction bits */
    uint64_t *keys;
    vec3 *pts, *nrm;    /* object-space point and unit outward object-space normal */
    unsigned char *ok;
    size_t cap, used;
} tess;

static vec3 to_world(const tess *t, vec3 q) { return t->world || t->sh->identity ? q : xform_point(&t->sh->x, q); }
static vec3 to_object(const tess *t, vec3 w) { return t->sh->identity ? w : xform_inv_point(&t->sh->x, w); }

/* Object-space unit normal from a world one: n_o ~ A^T n_w. */
static vec3 normal_to_object(const geom_shape *sh, vec3 nw)
{
    if (sh->identity) return nw;
    const double (*m)[4] = sh->x.m;
    vec3 n = v3(m[0][0] * nw.x + m[1][0] * nw.y + m[2][0] * nw.z, m[0][1] * nw.x + m[1][1] * nw.y + m[2][1] * nw.z,
                m[0][2] * nw.x + m[1][2] * nw.y + m[2][2] * nw.z);
    double l = v3_len(n);
    return l > 0.0 && isfinite(l) ? v3_scale(n, 1.0 / l) : nw;
}

static vec3 lattice_point(const tess *t, int i, int j, int k)
{
    return v3(t->lo.x + i * t->step.x, t->lo.y + j * t->step.y, t->lo.z + k * t->step.z);
}

static size_t lattice_index(const tess *t, int i, int j, int k)
{
    return ((size_t)k * (size_t)(t->ny + 1) + (size_t)j) * (size_t)(t->nx + 1) + (size_t)i;
}

static int cache_grow(tess *t)
{
    size_t nc = t->cap ? 2 * t->cap : 4096;
    uint64_t *keys = malloc(nc * sizeof *keys);
    vec3 *pts = malloc(nc * sizeof *pts), *nrm = malloc(nc * sizeof *nrm);
    unsigned char *ok = malloc(nc);
    if (!keys || !pts || !nrm || !ok) {
        free(keys); free(pts); free(nrm); free(ok);
        return 0;
    }
    for (size_t i = 0; i < nc; i++) keys[i] = UINT64_MAX;
    for (size_t i = 0; i < t->cap; i++) {
        if (t->keys[i] == UINT64_MAX) continue;
        size_t h = (size_t)pt_mix64(t->keys[i]) & (nc - 1);
        while (keys[h] != UINT64_MAX) h = (h + 1) & (nc - 1);
        keys[h] = t->keys[i];
        pts[h] = t->pts[i];
        nrm[h] = t->nrm[i];
        ok[h] = t->ok[i];
    }
    free(t->keys); free(t->pts); free(t->nrm); free(t->ok);
    t->keys = keys; t->pts = pts; t->nrm = nrm; t->ok = ok;
    t->cap = nc;
    return 1;
}

/* The crossing on the lattice edge from a (inside) to b (outside). */
static void find_crossing(const tess *t, vec3 a, vec3 b, int a_inside, vec3 *p, vec3 *n)
{
    const geom_shape *sh = t->sh;
    vec3 wa = to_world(t, a), wb = to_world(t, b);
    geom_shape_hit h[TESS_MAX_HITS];
    int nh = geom_shape_hits(sh, wa, v3_sub(wb, wa), 0.0, 1.0, h, TESS_MAX_HITS);
    vec3 wp;
    int part = 0;
    if (nh > 0) {
        /* the crossing nearest the middle of the edge (any odd one separates a from b) */
        int best = 0;
        for (int i = 1; i < nh; i++)
            if (fabs(h[i].t - 0.5) < fabs(h[best].t - 0.5)) best = i;
        wp = v3_madd(wa, v3_sub(wb, wa), h[best].t);
        part = h[best].part;
    } else {
        /* rounding hid the crossing from the ray query: bisect the inside test */
        double lo = 0.0, hi = 1.0;
        for (int it = 0; it < 60; it++) {
            double mid = 0.5 * (lo + hi);
            int in = geom_shape_inside(sh, v3_madd(wa, v3_sub(wb, wa), mid));
            if (in == a_inside) lo = mid;
            else hi = mid;
        }
        wp = v3_madd(wa, v3_sub(wb, wa), 0.5 * (lo + hi));
        /* part of the nearest crossing of a short probe through the point */
        vec3 d = v3_sub(wb, wa);
        int np = geom_shape_hits(sh, v3_madd(wp, d, -1e-3), d, 0.0, 2e-3, h, 1);
        part = np > 0 ? h[0].part : 0;
    }
    vec3 ng;
    geom_shape_surface(sh, wp, part, &ng, NULL, NULL);
    *p = to_object(t, wp);
    *n = normal_to_object(sh, ng);
}

/* Cached crossing of the edge from lattice corner (i,j,k) along dir bits. */
static int edge_crossing(tess *t, int i, int j, int k, int dir, vec3 *p, vec3 *n)
{
    uint64_t key = (uint64_t)lattice_index(t, i, j, k) * 8u + (uint64_t)dir;
    if (2 * (t->used + 1) > t->cap && !cache_grow(t)) return 0;
    size_t h = (size_t)pt_mix64(key) & (t->cap - 1);
    while (t->keys[h] != UINT64_MAX) {
        if (t->keys[h] == key) {
            *p = t->pts[h];
            *n = t->nrm[h];
            return 1;
        }
        h = (h + 1) & (t->cap - 1);
    }
    int i2 = i + (dir & 1), j2 = j + ((dir >> 1) & 1), k2 = k + ((dir >> 2) & 1);
    int ia = t->in[lattice_index(t, i, j, k)];
    find_crossing(t, lattice_point(t, i, j, k), lattice_point(t, i2, j2, k2), ia, p, n);
    t->keys[h] = key;
    t->pts[h] = *p;
    t->nrm[h] = *n;
    t->ok[h] = 1;
    t->used++;
    return 1;
}

/* Emit a triangle, wound so its normal points from `inside_c` to `outside_c`. */
static int emit(geom_grid_fn fn, void *ctx, vec3 a, vec3 b, vec3 c, vec3 na, vec3 nb, vec3 nc, vec3 inside_c,
                vec3 outside_c, int *count)
{
    vec3 cr = v3_cross(v3_sub(b, a), v3_sub(c, a));
    if (!(v3_len2(cr) > 0.0)) return 1;
    vec3 p[3] = {a, b, c}, n[3] = {na, nb, nc};
    if (v3_dot(cr, v3_sub(outside_c, inside_c)) < 0.0) {
        p[1] = c; p[2] = b;
        n[1] = nc; n[2] = nb;
    }
    if (!fn(ctx, p, n)) return 0;
    (*count)++;
    return 1;
}

int geom_tess_grid(const geom_shape *sh, int n, geom_grid_fn fn, void *ctx)
{
    if (n < 1) return 0;
    tess t;
    memset(&t, 0, sizeof t);
    t.sh = sh;
    vec3 lo, hi;
    if (sh->infinite) {
        if (!sh->clipped) return 0;
        t.world = 1;
        lo = sh->clip_lo;
        hi = sh->clip_hi;
    } else {
        lo = sh->olo;
        hi = sh->ohi;
    }
    vec3 ext = v3_sub(hi, lo);
    double m = v3_maxc(ext);
    if (!(m > 0.0) || !isfinite(m)) return 0;
    /* pad by a hair so surfaces lying on the bounds are inside the lattice */
    vec3 pad = v3s(1e-6 * m);
    lo = v3_sub(lo, pad);
    ext = v3_add(ext, v3_scale(pad, 2.0));
    if (n > 512) n = 512;
    t.nx = (int)fmax(1.0, ceil(n * ext.x / m));
    t.ny = (int)fmax(1.0, ceil(n * ext.y / m));
    t.nz = (int)fmax(1.0, ceil(n * ext.z / m));
    t.lo = lo;
    t.step = v3(ext.x / t.nx, ext.y / t.ny, ext.z / t.nz);
    size_t nv = (size_t)(t.nx + 1) * (size_t)(t.ny + 1) * (size_t)(t.nz + 1);
    t.in = malloc(nv);
    if (!t.in) return -1;
    for (int k = 0; k <= t.nz; k++)
        for (int j = 0; j <= t.ny; j++)
            for (int i = 0; i <= t.nx; i++)
                t.in[lattice_index(&t, i, j, k)] = (unsigned char)(geom_shape_inside(sh, to_world(&t, lattice_point(&t, i, j, k))) != 0);
    static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    int count = 0, fail = 0;
    for (int k = 0; k < t.nz && !fail; k++)
        for (int j = 0; j < t.ny && !fail; j++)
            for (int i = 0; i < t.nx && !fail; i++) {
                int cin[8], any_in = 0, any_out = 0;
                for (int c = 0; c < 8; c++) {
                    cin[c] = t.in[lattice_index(&t, i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1))];
                    if (cin[c]) any_in = 1;
                    else any_out = 1;
                }
                if (!any_in || !any_out) continue;
                for (int q = 0; q < 6 && !fail; q++) {
                    int tv[4] = {0, 1 << perm[q][0], (1 << perm[q][0]) | (1 << perm[q][1]), 7};
                    int ins[4], nin = 0, outs[4], nout = 0;
                    for (int v = 0; v < 4; v++) {
                        if (cin[tv[v]]) ins[nin++] = tv[v];
                        else outs[nout++] = tv[v];
                    }
                    if (nin == 0 || nout == 0) continue;
                    vec3 cin_c = v3s(0.0), cout_c = v3s(0.0);
                    for (int v = 0; v < nin; v++)
                        cin_c = v3_add(cin_c, lattice_point(&t, i + (ins[v] & 1), j + ((ins[v] >> 1) & 1), k + ((ins[v] >> 2) & 1)));
                    for (int v = 0; v < nout; v++)
                        cout_c = v3_add(cout_c, lattice_point(&t, i + (outs[v] & 1), j + ((outs[v] >> 1) & 1), k + ((outs[v] >> 2) & 1)));
                    cin_c = to_object(&t, to_world(&t, v3_scale(cin_c, 1.0 / nin)));
                    cout_c = to_object(&t, to_world(&t, v3_scale(cout_c, 1.0 / nout)));
                    /* crossings on the edges between inside and outside corners */
                    vec3 P[4], N[4];
                    int np = 0;
                    for (int a = 0; a < nin; a++)
                        for (int b = 0; b < nout; b++) {
                            int lo_c = ins[a] & outs[b], hi_c = ins[a] | outs[b];
                            /* corners on a Kuhn path are nested: lo_c is one of them */
                            if (!edge_crossing(&t, i + (lo_c & 1), j + ((lo_c >> 1) & 1), k + ((lo_c >> 2) & 1),
                                               lo_c ^ hi_c, &P[np], &N[np])) {
                                fail = -1;
                                break;
                            }
                            np++;
                        }
                    if (fail) break;
                    int ok;
                    if (np == 3) {
                        ok = emit(fn, ctx, P[0], P[1], P[2], N[0], N[1], N[2], cin_c, cout_c, &count);
                    } else {
                        /* two inside a0, a1 and two outside b0, b1: P holds a0b0, a0b1,
                         * a1b0, a1b1; round the quad is a0b0, a0b1, a1b1, a1b0 */
                        ok = emit(fn, ctx, P[0], P[1], P[3], N[0], N[1], N[3], cin_c, cout_c, &count) &&
                             emit(fn, ctx, P[0], P[3], P[2], N[0], N[3], N[2], cin_c, cout_c, &count);
                    }
                    if (!ok) fail = 1;
                }
            }
    free(t.in);
    free(t.keys);
    free(t.pts);
    free(t.nrm);
    free(t.ok);
    if (fail > 0) return -1;
    if (fail < 0) return -1;
    return count;
}

/* ------------------------------------------------------------ Crofton sampling */

/* Uniform random line through the ball (c, R): direction from (u1, u2),
 * offset uniform on the disc across it from (u3, u4). */
static void random_line(vec3 c, double R, double u1, double u2, double u3, double u4, vec3 *org, vec3 *dir)
{
    double z = 1.0 - 2.0 * u1, s = sqrt(fmax(0.0, 1.0 - z * z)), phi = 2.0 * M_PI * u2;
    vec3 w = v3(s * cos(phi), s * sin(phi), z), a, b;
    v3_basis(w, &a, &b);
    double rho = R * sqrt(u3), th = 2.0 * M_PI * u4;
    vec3 off = v3_add(v3_scale(a, rho * cos(th)), v3_scale(b, rho * sin(th)));
    *org = v3_add(v3_add(c, off), v3_scale(w, -1.0001 * R));
    *dir = w;
}

static int line_hits(const geom_tess_sampler *cs, vec3 org, vec3 dir, geom_shape_hit *h)
{
    int k = geom_shape_hits(cs->sh, org, dir, 0.0, 2.0002 * cs->R, h, TESS_MAX_HITS);
    if (!cs->keep) return k;
    int m = 0;
    for (int i = 0; i < k; i++)
        if (cs->keep(cs->keep_ctx, v3_madd(org, dir, h[i].t))) h[m++] = h[i];
    return m;
}

/* van der Corput radical inverse in base b */
static double radical_inverse(uint64_t i, unsigned b)
{
    double f = 1.0 / b, r = 0.0, inv = f;
    while (i) {
        r += (double)(i % b) * inv;
        i /= b;
        inv *= f;
    }
    return r;
}

/* Crofton lines are cast in batches of TESS_BATCH; a batch's crossings
 * are counted in integers, so its mean (the count over a power of two) is
 * exact whichever thread counted it. */
enum { TESS_BATCH = 1024 };

enum { TESS_SLOTS = 64 }; /* batches counted at once, at most */

typedef struct {
    const geom_tess_sampler *cs;
    int first;                 /* the first batch of this round */
    long count[TESS_SLOTS];    /* batch b's crossings in slot b % TESS_SLOTS */
    int kmax[TESS_SLOTS];      /* and the most on one of its lines */
} batch_job;

/* Batch first + j: lines TESS_BATCH b + 1 .. TESS_BATCH (b + 1) of the
 * Halton sequence (bases 2, 3, 5, 7). */
static void batch_run(void *ctx, int j, int thread)
{
    (void)thread;
    batch_job *J = ctx;
    const geom_tess_sampler *cs = J->cs;
    int b = J->first + j;
    geom_shape_hit h[TESS_MAX_HITS];
    uint64_t idx = 1 + (uint64_t)b * TESS_BATCH;
    long sum = 0;
    int kmax = 0;
    for (int i = 0; i < TESS_BATCH; i++, idx++) {
        vec3 org, dir;
        random_line(cs->c, cs->R, radical_inverse(idx, 2), radical_inverse(idx, 3), radical_inverse(idx, 5),
                    radical_inverse(idx, 7), &org, &dir);
        int k = line_hits(cs, org, dir, h);
        if (k > kmax) kmax = k;
        sum += k;
    }
    J->count[b % TESS_SLOTS] = sum;
    J->kmax[b % TESS_SLOTS] = kmax;
}

double geom_tess_sampler_init(geom_tess_sampler *cs, const geom_shape *sh, geom_tess_keep_fn keep,
                               void *keep_ctx, double rel_err, int max_lines, int threads)
{
    memset(cs, 0, sizeof *cs);
    cs->sh = sh;
    cs->keep = keep;
    cs->keep_ctx = keep_ctx;
    /* a ball holding the surface: the (clip) box's corners in world space */
    vec3 corners[8];
    if (sh->infinite) {
        if (!sh->clipped) return 0.0;
        for (int i = 0; i < 8; i++)
            corners[i] = v3(i & 1 ? sh->clip_hi.x : sh->clip_lo.x, i & 2 ? sh->clip_hi.y : sh->clip_lo.y,
                            i & 4 ? sh->clip_hi.z : sh->clip_lo.z);
    } else {
        for (int i = 0; i < 8; i++) {
            vec3 q = v3(i & 1 ? sh->ohi.x : sh->olo.x, i & 2 ? sh->ohi.y : sh->olo.y, i & 4 ? sh->ohi.z : sh->olo.z);
            corners[i] = sh->identity ? q : xform_point(&sh->x, q);
        }
    }
    vec3 c = v3s(0.0);
    for (int i = 0; i < 8; i++) c = v3_add(c, corners[i]);
    c = v3_scale(c, 1.0 / 8.0);
    double R = 0.0;
    for (int i = 0; i < 8; i++) R = fmax(R, v3_len(v3_sub(corners[i], c)));
    R *= 1.000001;
    if (!(R > 0.0) || !isfinite(R) || !v3_finite(c)) return 0.0;
    cs->c = c;
    cs->R = R;
    /* E[k] by quasi-Monte Carlo lines, in batches until the standard error
     * of the batch means is below rel_err. The stopping rule reads the
     * batches in order from the 8th on; with threads, the first 8 are
     * counted together and then `threads` at a time (a batch counted past
     * the stop is not read), so the estimate is the same for any count. */
    if (max_lines < 1024) max_lines = 1024;
    enum { FIRST = 8 };
    if (threads < 1) threads = 1;
    if (threads > TESS_SLOTS) threads = TESS_SLOTS;
    int total = (max_lines + TESS_BATCH - 1) / TESS_BATCH;
    batch_job *J = malloc(sizeof *J);
    if (!J) return 0.0;
    J->cs = cs;
    double sum = 0.0, sum2 = 0.0;
    int nb = 0, kmax = 0, done = 0;
    while (nb < total) {
        if (nb == done) {
            int n = nb < FIRST ? FIRST - nb : threads;
            if (n > total - done) n = total - done;
            J->first = done;
            if (threads > 1 && n > 1) pool_run(threads, n, batch_run, J);
            else
                for (int j = 0; j < n; j++) batch_run(J, j, 0);
            done += n;
        }
        double bs = (double)J->count[nb % TESS_SLOTS] / TESS_BATCH;
        if (J->kmax[nb % TESS_SLOTS] > kmax) kmax = J->kmax[nb % TESS_SLOTS];
        sum += bs;
        sum2 += bs * bs;
        nb++;
        if (nb >= 8) {
            double mean = sum / nb, var = fmax(0.0, sum2 / nb - mean * mean) / (nb - 1);
            if (mean > 0.0 && sqrt(var) <= rel_err * mean) break;
            if (mean == 0.0 && nb >= 16) break;
        }
    }
    free(J);
    double mean = sum / nb;
    cs->kmax = kmax;
    cs->area = 2.0 * M_PI * R * R * mean;
    return cs->area;
}

int geom_tess_sample(const geom_tess_sampler *cs, double u1, double u2, rng *r, vec3 *p, vec3 *n, unsigned *part)
{
    if (!(cs->area > 0.0) || cs->kmax < 1) return 0;
    rng local;
    if (!r) {
        uint64_t a = (uint64_t)(u1 * 9007199254740992.0), b = (uint64_t)(u2 * 9007199254740992.0);
        rng_seed(&local, pt_mix64(a ^ pt_mix64(b)), 17);
        r = &local;
    }
    geom_shape_hit h[TESS_MAX_HITS];
    for (int tries = 0; tries < 1 << 16; tries++) {
        vec3 org, dir;
        random_line(cs->c, cs->R, u1, u2, rng_f64(r), rng_f64(r), &org, &dir);
        int k = line_hits(cs, org, dir, h);
        if (k > cs->kmax) k = cs->kmax; /* lines with more crossings than the estimate saw: rare */
        if (k > 0 && rng_f64(r) * cs->kmax < k) {
            int j = (int)(rng_f64(r) * k);
            if (j >= k) j = k - 1;
            *p = v3_madd(org, dir, h[j].t);
            geom_shape_surface(cs->sh, *p, h[j].part, n, NULL, NULL);
            *part = (unsigned)h[j].part;
            return 1;
        }
        u1 = rng_f64(r);
        u2 = rng_f64(r);
    }
    return 0;
}
