/* gi_trilook.c - nearest area particle by the hit triangle (see gi_trilook.h). */
#include "gi_trilook.h"
#include <embree3/rtcore.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "geom_mesh.h"
#include "pool.h"
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

/* a cell's edge is at most CELL_FAC particle spacings (k = ceil(longest
 * edge / (CELL_FAC spacing)), at most MAX_K). Smaller cells cost more to
 * build (the 4x4 pass), larger ones longer lists to scan (the 16x16 pass);
 * 1 spacing gave the least CPU time for the two passes together on cbox
 * among 0.7, 1.0 and 1.4 (bench_gi's link pass timings). */
#define CELL_FAC 1.0
#define MAX_K 64
/* cells per edge of a block that gathers its candidates together
 * (build_block): of 1, 2, 4 and 8, 2 built cornell.pov's lists in the
 * fewest instructions (callgrind, gi_trilook_build alone), and 1 left
 * some cells without a certain particle among their candidates (those
 * lists go to the grid) */
#define BLOCK 2
/* particles whose n . N lies within AGREE_SLACK of the threshold are
 * "uncertain" (gi_links compares Embree's Ng, not this N) */
#define AGREE_SLACK 1e-3
/* relative widening of the list radius and narrowing of the certificate */
#define REL 1e-4
#define UNCERTAIN 0x80000000u

/* a particle as the scan reads it (32 bytes, two 16-byte loads; the
 * lists hold indices; one more at infinity pads the scan's last lanes) */
typedef struct {
    float x, y, z, nx, ny, nz, pad[2];
} tl_pp;

typedef struct {
    float n[3]; /* unit normal (v1 - v0) x (v2 - v0) */
    int k;      /* cells per edge; 0: not covered */
    long cell0; /* first cell (2 lists each) */
} tl_tri;

/* A list in e[]: a header word (entry count | COMPLETE: the list holds
 * every particle of the side within maxdist, so no answer means none),
 * the certificate (float bits: an answer at squared distance <= it is
 * exact), then its entries (particle | UNCERTAIN), ascending. */
#define COMPLETE 0x80000000u
/* shared headers of empty lists */
#define EMPTY_COMPLETE 0u
#define EMPTY_OPEN 2u
#define SHARED_WORDS 4u
/* during the build: an offset into the list's chunk */
#define LOCAL 0x80000000u

struct gi_trilook {
    unsigned ngeom;
    tl_tri **tri; /* per geometry (NULL: none) */
    long *ntri;
    unsigned *loff; /* per list: its offset in e; 2 per cell: side 0 (+N), side 1 (-N) */
    long ncell;     /* lists */
    unsigned *e;
    long ne;
    long entries;
    tl_pp *pp; /* the particles */
    int n;
    float start2; /* scan radius squared: maxdist (1 + REL), squared */
    float lift;   /* the centre query's origin above the surface (a spacing) */
    float *cc;    /* per cell (ncell / 2): its centre and its triangle's unit normal, 6 floats */
    int *rep;     /* per list (NULL: not made): the answer at its cell's centre (gi_trilook_centres) */
};

/* ------------------------------------------------------------------ build */

typedef struct {
    double h, inv;
    double o[3];
    long dim[3];
    int *start; /* ncells + 1 */
    int *ord;   /* particles by cell */
} bgrid;

static void bgrid_free(bgrid *g)
{
    free(g->start);
    free(g->ord);
}

static int bgrid_build(bgrid *g, const gi_dev_particle *p, int n, double h)
{
    memset(g, 0, sizeof *g);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], p[i].p[k]);
            hi[k] = fmax(hi[k], p[i].p[k]);
        }
    if (!(h > 0.0)) h = 1.0;
    for (;;) {
        double cells = 1.0;
        for (int k = 0; k < 3; k++) cells *= floor((hi[k] - lo[k]) / h) + 1.0;
        if (cells <= 4.0 * n + 4096.0) break;
        h *= 1.25;
    }
    g->h = h;
    g->inv = 1.0 / h;
    for (int k = 0; k < 3; k++) {
        g->o[k] = lo[k];
        g->dim[k] = (long)floor((hi[k] - lo[k]) / h) + 1;
    }
    long nc = g->dim[0] * g->dim[1] * g->dim[2];
    g->start = calloc((size_t)nc + 2, sizeof *g->start);
    g->ord = malloc((size_t)(n > 0 ? n : 1) * sizeof *g->ord);
    long *key = malloc((size_t)(n > 0 ? n : 1) * sizeof *key);
    if (!g->start || !g->ord || !key) {
        free(key);
        bgrid_free(g);
        return 0;
    }
    for (int i = 0; i < n; i++) {
        long c[3];
        for (int k = 0; k < 3; k++) {
            long ci = (long)((p[i].p[k] - g->o[k]) * g->inv);
            c[k] = ci < 0 ? 0 : (ci >= g->dim[k] ? g->dim[k] - 1 : ci);
        }
        key[i] = (c[2] * g->dim[1] + c[1]) * g->dim[0] + c[0];
        g->start[key[i] + 2]++;
    }
    for (long c = 0; c <= nc; c++) g->start[c + 1] += g->start[c];
    for (int i = 0; i < n; i++) g->ord[g->start[key[i] + 1]++] = i; /* ascending within a cell */
    free(key);
    return 1;
}

typedef struct {
    unsigned geom;
    const float *v;
    const unsigned *idx;
} tl_geo;

typedef struct {
    gi_trilook *t;
    const gi_dev_particle *p;
    const int *pobjid; /* object id of each particle */
    const unsigned char *buried;
    const tl_geo *geo;
    const long *gbase; /* first flattened triangle of each geometry */
    const int *tobj;   /* object id of each flattened triangle */
    unsigned ngeo;
    long ntris;
    int chunks;
    bgrid g;
    double spacing, agree, maxdist, delta;
    /* per chunk output */
    unsigned **ce;
    long *cne, *ccap;
    int *fail;
} tl_build;

/* candidates of one triangle: particles of its object with a normal on
 * either side of the agreement threshold's slack (each list is sorted by
 * index when written) */
typedef struct {
    int *ix;
    float *px; /* position, 3 each */
    double *dx, *dy, *dz; /* the same, by coordinate (centre_distances) */
    signed char *side; /* 0 (+N) or 1 (-N) */
    unsigned char *unc;
    long n, cap;
    double *cd; /* per cell: max distance to the cell's corners */
    double *pc; /* per cell: distance to the cell's centre */
} tl_scratch;

static int scratch_grow(tl_scratch *s, long need)
{
    if (need <= s->cap) return 1;
    long nc = s->cap ? s->cap : 256;
    while (nc < need) nc *= 2;
    int *ix = realloc(s->ix, (size_t)nc * sizeof *ix);
    if (!ix) return 0;
    s->ix = ix;
    float *px = realloc(s->px, (size_t)nc * 3 * sizeof *px);
    if (!px) return 0;
    s->px = px;
    double **dc[3] = {&s->dx, &s->dy, &s->dz};
    for (int k = 0; k < 3; k++) {
        double *d = realloc(*dc[k], (size_t)nc * sizeof *d);
        if (!d) return 0;
        *dc[k] = d;
    }
    signed char *sd = realloc(s->side, (size_t)nc);
    if (!sd) return 0;
    s->side = sd;
    unsigned char *u = realloc(s->unc, (size_t)nc);
    if (!u) return 0;
    s->unc = u;
    double *cd = realloc(s->cd, (size_t)nc * sizeof *cd);
    if (!cd) return 0;
    s->cd = cd;
    double *pc = realloc(s->pc, (size_t)nc * sizeof *pc);
    if (!pc) return 0;
    s->pc = pc;
    s->cap = nc;
    return 1;
}

/* particles of object oid within r of centre c */
static int gather(const tl_build *B, tl_scratch *s, int oid, const double c[3], double r, const double nrm[3])
{
    const bgrid *g = &B->g;
    long lo[3], hi[3];
    for (int k = 0; k < 3; k++) {
        double a = (c[k] - r - g->o[k]) * g->inv, b = (c[k] + r - g->o[k]) * g->inv;
        lo[k] = a < 0.0 ? 0 : (long)a;
        hi[k] = b < 0.0 ? -1 : (b >= (double)(g->dim[k] - 1) ? g->dim[k] - 1 : (long)b);
    }
    s->n = 0;
    double r2 = r * r;
    for (long z = lo[2]; z <= hi[2]; z++)
        for (long y = lo[1]; y <= hi[1]; y++) {
            long row = (z * g->dim[1] + y) * g->dim[0];
            for (int e = g->start[row + lo[0]]; e < g->start[row + hi[0] + 1]; e++) {
                int i = g->ord[e];
                if (B->pobjid[i] != oid) continue;
                const float *pp = B->p[i].p;
                double dd = 0.0;
                for (int k = 0; k < 3; k++) dd += (pp[k] - c[k]) * (pp[k] - c[k]);
                if (dd > r2) continue;
                if (!scratch_grow(s, s->n + 1)) return 0;
                s->ix[s->n++] = i;
            }
        }
    double lo_ag = B->agree - AGREE_SLACK, hi_ag = B->agree + AGREE_SLACK;
    long m = 0;
    for (long a = 0; a < s->n; a++) {
        int i = s->ix[a];
        const gi_dev_particle *p = &B->p[i];
        double ag = p->n[0] * nrm[0] + p->n[1] * nrm[1] + p->n[2] * nrm[2];
        int side = ag >= lo_ag ? 0 : (-ag >= lo_ag ? 1 : -1);
        if (side < 0) continue;
        s->ix[m] = i;
        for (int k = 0; k < 3; k++) s->px[3 * m + k] = p->p[k];
        s->dx[m] = p->p[0];
        s->dy[m] = p->p[1];
        s->dz[m] = p->p[2];
        s->side[m] = (signed char)side;
        double av = side ? -ag : ag;
        s->unc[m] = (unsigned char)(av < hi_ag || (B->buried && B->buried[i]));
        m++;
    }
    s->n = m;
    return 1;
}

/* s->pc[m]: candidate m's distance from c, for every m. The same sums in
 * the same order as one candidate at a time (the squares of x, y, z,
 * added in turn, then the root, each rounded once), two candidates per
 * SSE2 instruction: most of the lists' build time goes into these
 * distances, one per candidate and list cell. */
static void centre_distances(tl_scratch *s, const double c[3])
{
    long m = 0;
#if defined(__SSE2__)
    const __m128d c0 = _mm_set1_pd(c[0]), c1 = _mm_set1_pd(c[1]), c2 = _mm_set1_pd(c[2]);
    for (; m + 2 <= s->n; m += 2) {
        __m128d d0 = _mm_sub_pd(_mm_loadu_pd(s->dx + m), c0), d1 = _mm_sub_pd(_mm_loadu_pd(s->dy + m), c1),
                d2 = _mm_sub_pd(_mm_loadu_pd(s->dz + m), c2);
        __m128d e = _mm_add_pd(_mm_add_pd(_mm_mul_pd(d0, d0), _mm_mul_pd(d1, d1)), _mm_mul_pd(d2, d2));
        _mm_storeu_pd(s->pc + m, _mm_sqrt_pd(e));
    }
#endif
    for (; m < s->n; m++) {
        double d0 = s->dx[m] - c[0], d1 = s->dy[m] - c[1], d2 = s->dz[m] - c[2];
        s->pc[m] = sqrt(d0 * d0 + d1 * d1 + d2 * d2);
    }
}

static unsigned *chunk_words(tl_build *B, int ch, long more)
{
    if (B->cne[ch] + more > B->ccap[ch]) {
        long nc = B->ccap[ch] ? B->ccap[ch] : 256;
        while (nc < B->cne[ch] + more) nc *= 2;
        unsigned *ne = realloc(B->ce[ch], (size_t)nc * sizeof *ne);
        if (!ne) return NULL;
        B->ce[ch] = ne;
        B->ccap[ch] = nc;
    }
    return B->ce[ch] + B->cne[ch];
}

/* The lists of triangle T's cells (i, j) with bi <= i < ie, bj <= j < je
 * (v: its vertices, e1, e2 its edges from v[0], nrm its unit normal),
 * from candidates gathered around ct within rt of every point of those
 * cells; written to chunk ch. 0: out of memory. */
static int build_block(tl_build *B, tl_scratch *s, int ch, const tl_tri *T, int oid, const double v[3][3],
                       const double e1[3], const double e2[3], const double nrm[3], int bi, int ie, int bj, int je,
                       const double ct[3], double rt)
{
    gi_trilook *t = B->t;
    const int k = T->k;
    const double full = B->maxdist * (1.0 + REL) + B->delta;
    /* the candidates cover every point within rg - rt of the block;
     * gathered again wider when a cell's list needs more */
    double rg = rt + fmin(1.5 * B->spacing, full);
    long blk_start = B->cne[ch];
    for (int pass = 0; pass < 2; pass++) {
        if (!gather(B, s, oid, ct, rg, nrm)) return 0;
        double needed = 0.0;
        for (int i = bi; i < ie; i++)
            for (int j = bj; j < je && j + i < k; j++) {
                long cell = T->cell0 + (long)i * k - (long)i * (i - 1) / 2 + j;
                /* corners (i, j), (i+1, j), (i, j+1) [, (i+1, j+1)] in units of 1/k */
                double uv[4][2] = {{i, j}, {i + 1, j}, {i, j + 1}, {i + 1, j + 1}};
                int nv = i + j < k - 1 ? 4 : 3;
                double cv[4][3], c[3] = {0, 0, 0};
                for (int q = 0; q < nv; q++)
                    for (int a = 0; a < 3; a++) {
                        cv[q][a] = v[0][a] + uv[q][0] / k * e1[a] + uv[q][1] / k * e2[a];
                        c[a] += cv[q][a] / nv;
                    }
                float *cc = t->cc + 6 * cell;
                for (int a = 0; a < 3; a++) {
                    cc[a] = (float)c[a];
                    cc[3 + a] = (float)nrm[a];
                }
                vec3 cw[4]; /* the corners as vectors (geom_tri_closest) */
                for (int q = 0; q < nv; q++) cw[q] = v3(cv[q][0], cv[q][1], cv[q][2]);
                double rc = 0.0;
                for (int q = 0; q < nv; q++) {
                    double e = 0.0;
                    for (int a = 0; a < 3; a++) e += (cv[q][a] - c[a]) * (cv[q][a] - c[a]);
                    rc = fmax(rc, sqrt(e));
                }
                /* R: the least max corner distance of a certain
                 * candidate; the one nearest the centre first (its
                 * bound prunes the rest: max corner distance >= pc - rc) */
                double R[2] = {INFINITY, INFINITY}, pmin[2] = {INFINITY, INFINITY};
                long first[2] = {-1, -1};
                centre_distances(s, c);
                for (long m = 0; m < s->n; m++) {
                    int sd = s->side[m];
                    if (!s->unc[m] && s->pc[m] < pmin[sd]) {
                        pmin[sd] = s->pc[m];
                        first[sd] = m;
                    }
                }
                for (int pass2 = 0; pass2 < 2; pass2++)
                    for (long m = 0; m < s->n; m++) {
                        int sd = s->side[m];
                        if (pass2 == 0 ? m != first[sd] : (s->unc[m] || m == first[sd] || s->pc[m] - rc >= R[sd]))
                            continue;
                        const float *px = &s->px[3 * m];
                        double mx = 0.0;
                        for (int q = 0; q < nv; q++) {
                            double e2q = 0.0;
                            for (int a = 0; a < 3; a++) e2q += (px[a] - cv[q][a]) * (px[a] - cv[q][a]);
                            if (e2q > mx) mx = e2q;
                        }
                        mx = sqrt(mx);
                        if (mx < R[sd]) R[sd] = mx;
                    }
                /* a side without a certain particle near the triangle
                 * (a side facing the void, the inside of a closed
                 * mesh) is left to the grid path: its list would have
                 * to reach maxdist, and few rays hit it, so building it
                 * costs more than the grid path it saves */
                int cov[2];
                for (int sd = 0; sd < 2; sd++) {
                    cov[sd] = R[sd] < INFINITY;
                    if (R[sd] > B->maxdist) R[sd] = B->maxdist;
                }
                double rl[2] = {R[0] * (1.0 + REL) + B->delta, R[1] * (1.0 + REL) + B->delta};
                for (int sd = 0; sd < 2; sd++) {
                    if (cov[sd] && pass == 0) needed = fmax(needed, rl[sd]);
                    /* (the second pass gathered every need the first one saw) */
                    if (pass == 1 && rl[sd] > rg - rt) cov[sd] = 0;
                }
                if (pass == 0 && needed > rg - rt) continue; /* gathered again */
                for (int sd = 0; sd < 2; sd++) {
                    if (!cov[sd]) {
                        t->loff[2 * cell + sd] = EMPTY_OPEN;
                        continue;
                    }
                    double rl2 = rl[sd] * rl[sd];
                    /* membership: dist(p, cell) <= rl; the centre distance
                     * bounds it: pc - rc <= dist <= pc */
                    long cnt = 0;
                    for (long m = 0; m < s->n; m++) {
                        s->cd[m] = -1.0;
                        if (s->side[m] != sd || s->pc[m] - rc > rl[sd]) continue;
                        if (s->pc[m] > rl[sd]) {
                            vec3 px = v3(s->px[3 * m], s->px[3 * m + 1], s->px[3 * m + 2]);
                            double w[3];
                            double d2 = geom_tri_closest(px, cw[0], cw[1], cw[2], w);
                            if (nv == 4 && d2 > rl2) d2 = fmin(d2, geom_tri_closest(px, cw[1], cw[3], cw[2], w));
                            if (d2 > rl2) continue;
                        }
                        s->cd[m] = 1.0;
                        cnt++;
                    }
                    int complete = R[sd] >= B->maxdist;
                    double cert = complete ? B->maxdist * (1.0 - REL) : R[sd];
                    float cert2 = (float)(cert * cert * (1.0 - 1e-6));
                    if (cnt == 0) {
                        /* a shared header (offsets below the chunks') */
                        t->loff[2 * cell + sd] = complete ? EMPTY_COMPLETE : EMPTY_OPEN;
                        continue;
                    }
                    unsigned *w = chunk_words(B, ch, cnt + 2);
                    if (!w) return 0;
                    t->loff[2 * cell + sd] = (unsigned)B->cne[ch] | LOCAL;
                    w[0] = (unsigned)cnt | (complete ? COMPLETE : 0u);
                    memcpy(&w[1], &cert2, sizeof cert2);
                    long q = 2;
                    for (long m = 0; m < s->n; m++) {
                        if (s->cd[m] < 0.0) continue;
                        /* ascending particle index (insertion: lists are short) */
                        unsigned id = (unsigned)s->ix[m] | (s->unc[m] ? UNCERTAIN : 0u);
                        long b = q++;
                        while (b > 2 && (w[b - 1] & ~UNCERTAIN) > (id & ~UNCERTAIN)) {
                            w[b] = w[b - 1];
                            b--;
                        }
                        w[b] = id;
                    }
                    B->cne[ch] += cnt + 2;
                }
            }
        if (pass == 0 && needed <= rg - rt) break; /* every cell written */
        if (pass == 1) break;
        /* some cell needs more: drop this block's lists written so far
         * (the chunk's last words) and gather wider */
        B->cne[ch] = blk_start;
        rg = rt + needed * (1.0 + 1e-9);
    }
    return 1;
}

static void build_job(void *ctx, int ch, int thread)
{
    (void)thread;
    tl_build *B = ctx;
    gi_trilook *t = B->t;
    long t0 = B->ntris * ch / B->chunks, t1 = B->ntris * (ch + 1) / B->chunks;
    tl_scratch s = {0};
    unsigned gi = 0;
    for (long ft = t0; ft < t1; ft++) {
        while (gi + 1 < B->ngeo && B->gbase[gi + 1] <= ft) gi++;
        const tl_geo *G = &B->geo[gi];
        long prim = ft - B->gbase[gi];
        const tl_tri *T = &t->tri[G->geom][prim];
        if (T->k == 0) continue;
        int oid = B->tobj[ft], k = T->k;
        double v[3][3];
        for (int q = 0; q < 3; q++)
            for (int c = 0; c < 3; c++) v[q][c] = G->v[3 * G->idx[3 * prim + q] + c];
        double e1[3], e2[3], nrm[3] = {T->n[0], T->n[1], T->n[2]};
        for (int c = 0; c < 3; c++) {
            e1[c] = v[1][c] - v[0][c];
            e2[c] = v[2][c] - v[0][c];
        }
        /* the cells in blocks of BLOCK x BLOCK, each with candidates of its
         * own: one set for a whole large triangle made every cell measure
         * its distance to every particle on it (cornell.pov's floor: 1,378
         * cells by some 1,700 particles). A triangle of at most BLOCK cells
         * an edge is one block, about its centroid; a larger one's block
         * about the centre of the parallelogram [bi, ie] x [bj, je] (in
         * 1/k of the edges) that holds its cells. */
        for (int bi = 0; bi < k; bi += BLOCK)
            for (int bj = 0; bj + bi < k; bj += BLOCK) {
                int ie = bi + BLOCK < k ? bi + BLOCK : k, je = bj + BLOCK < k - bi ? bj + BLOCK : k - bi;
                double cb[3], rb = 0.0, pv[4][3];
                int np = k <= BLOCK ? 3 : 4;
                for (int q = 0; q < np; q++)
                    for (int c = 0; c < 3; c++)
                        pv[q][c] = np == 3 ? v[q][c]
                                           : v[0][c] + (double)(q & 1 ? ie : bi) / k * e1[c] +
                                                 (double)(q & 2 ? je : bj) / k * e2[c];
                for (int c = 0; c < 3; c++)
                    cb[c] = np == 3 ? (v[0][c] + v[1][c] + v[2][c]) / 3.0
                                    : (pv[0][c] + pv[1][c] + pv[2][c] + pv[3][c]) / 4.0;
                for (int q = 0; q < np; q++) {
                    double e = 0.0;
                    for (int c = 0; c < 3; c++) e += (pv[q][c] - cb[c]) * (pv[q][c] - cb[c]);
                    rb = fmax(rb, sqrt(e));
                }
                if (!build_block(B, &s, ch, T, oid, (const double(*)[3])v, e1, e2, nrm, bi, ie, bj, je, cb, rb)) {
                    B->fail[ch] = 1;
                    goto out;
                }
            }
    }
out:
    free(s.ix);
    free(s.px);
    free(s.dx);
    free(s.dy);
    free(s.dz);
    free(s.side);
    free(s.unc);
    free(s.cd);
    free(s.pc);
}

void gi_trilook_free(gi_trilook *t)
{
    if (!t) return;
    if (t->tri)
        for (unsigned g = 0; g < t->ngeom; g++) free(t->tri[g]);
    free(t->tri);
    free(t->ntri);
    free(t->loff);
    free(t->e);
    free(t->pp);
    free(t->cc);
    free(t->rep);
    free(t);
}

gi_trilook *gi_trilook_build(const accel *a, const gi_dev_particle *p, int n, const void *const *pobj,
                             const gi_lookup *grid, const unsigned char *buried, double spacing, double agree,
                             double maxdist, int threads, volatile int *cancel, pt_status *st)
{
    *st = PT_OK;
    if (!a || !p || !pobj || !grid || n <= 0 || !(spacing > 0.0) || !(maxdist > 0.0)) return NULL;
    if (threads <= 0) threads = pool_default_threads();
    int *pobjid = malloc((size_t)n * sizeof *pobjid);
    gi_trilook *t = calloc(1, sizeof *t);
    tl_geo *geo = NULL;
    long *gbase = NULL;
    int *tobj = NULL;
    tl_build B;
    memset(&B, 0, sizeof B);
    if (!pobjid || !t) goto nomem;
    /* object ids: the grid's (gi_lookup_set_objects) */
    for (int i = 0; i < n; i++) pobjid[i] = gi_lookup_object_id(grid, pobj[i]);
    double pmag = 0.0;
    for (int i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) pmag = fmax(pmag, fabs(p[i].p[k]));
    /* triangles */
    t->ngeom = accel_rtc_ngeoms(a);
    t->tri = calloc(t->ngeom ? t->ngeom : 1, sizeof *t->tri);
    t->ntri = calloc(t->ngeom ? t->ngeom : 1, sizeof *t->ntri);
    geo = calloc(t->ngeom ? t->ngeom : 1, sizeof *geo);
    gbase = calloc((size_t)t->ngeom + 1, sizeof *gbase);
    if (!t->tri || !t->ntri || !geo || !gbase) goto nomem;
    unsigned ngeo = 0;
    long ntris = 0;
    for (unsigned g = 0; g < t->ngeom; g++) {
        const float *v;
        const unsigned *ix;
        long nt = accel_rtc_triangles(a, g, &v, &ix);
        if (nt <= 0) continue;
        t->tri[g] = calloc((size_t)nt, sizeof **t->tri);
        if (!t->tri[g]) goto nomem;
        t->ntri[g] = nt;
        geo[ngeo] = (tl_geo){g, v, ix};
        gbase[ngeo] = ntris;
        ngeo++;
        ntris += nt;
    }
    gbase[ngeo] = ntris;
    tobj = malloc((size_t)(ntris > 0 ? ntris : 1) * sizeof *tobj);
    if (!tobj) goto nomem;
    long ncell = 0;
    double tmag = pmag;
    for (unsigned q = 0; q < ngeo; q++) {
        const tl_geo *G = &geo[q];
        for (long pr = 0; pr < t->ntri[G->geom]; pr++) {
            tl_tri *T = &t->tri[G->geom][pr];
            long ft = gbase[q] + pr;
            tobj[ft] = -1;
            const scene_object *o = accel_rtc_object(a, G->geom, (unsigned)pr, RTC_INVALID_GEOMETRY_ID);
            int oid = o ? gi_lookup_object_id(grid, o) : -1;
            if (oid < 0) continue; /* no particle on it */
            tobj[ft] = oid;
            double v[3][3];
            for (int k = 0; k < 3; k++)
                for (int c = 0; c < 3; c++) {
                    v[k][c] = G->v[3 * G->idx[3 * pr + k] + c];
                    tmag = fmax(tmag, fabs(v[k][c]));
                }
            double e1[3], e2[3], e3[3];
            for (int c = 0; c < 3; c++) {
                e1[c] = v[1][c] - v[0][c];
                e2[c] = v[2][c] - v[0][c];
                e3[c] = v[2][c] - v[1][c];
            }
            double nn[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
            double l1 = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
            double l2 = sqrt(e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]);
            double l3 = sqrt(e3[0] * e3[0] + e3[1] * e3[1] + e3[2] * e3[2]);
            double ln = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
            double le = fmax(l1, fmax(l2, l3));
            /* slivers (the normal's direction unsure) and non-finite ones stay on the grid path */
            if (!(ln > 1e-6 * le * le) || !isfinite(ln)) continue;
            double kk = ceil(le / (CELL_FAC * spacing));
            int k = kk < 1.0 ? 1 : (kk > MAX_K ? MAX_K : (int)kk);
            for (int c = 0; c < 3; c++) T->n[c] = (float)(nn[c] / ln);
            T->k = k;
            T->cell0 = ncell;
            ncell += (long)k * (k + 1) / 2;
        }
    }
    if (ncell == 0 || ncell > (1L << 29)) {
        /* nothing to cover (or too much): the grid path answers everything */
        free(pobjid);
        free(geo);
        free(gbase);
        free(tobj);
        gi_trilook_free(t);
        return NULL;
    }
    t->ncell = 2 * ncell;
    t->loff = calloc((size_t)t->ncell, sizeof *t->loff);
    t->cc = malloc((size_t)ncell * 6 * sizeof *t->cc);
    if (!t->cc) goto nomem;
    t->pp = aligned_alloc(64, (((size_t)n + 1) * sizeof *t->pp + 63) / 64 * 64); /* (a multiple of the alignment, as C11 asks) */
    if (!t->loff || !t->pp) goto nomem;
    t->n = n;
    for (int i = 0; i < n; i++)
        t->pp[i] = (tl_pp){p[i].p[0], p[i].p[1], p[i].p[2], p[i].n[0], p[i].n[1], p[i].n[2], {0, 0}};
    t->pp[n] = (tl_pp){INFINITY, INFINITY, INFINITY, 0, 0, 0, {0, 0}};
    float md = (float)(maxdist * (1.0 + REL));
    t->start2 = md * md;
    B.t = t;
    B.p = p;
    B.pobjid = pobjid;
    B.buried = buried;
    B.geo = geo;
    B.gbase = gbase;
    B.tobj = tobj;
    B.ngeo = ngeo;
    B.ntris = ntris;
    B.spacing = spacing;
    t->lift = (float)spacing;
    B.agree = agree;
    B.maxdist = maxdist;
    /* the hit point's distance to its cell: float rounding of Embree's
     * (u, v) and of org + t dir, a few ulps of the coordinates */
    B.delta = 1e-3 * spacing + 1e-5 * tmag;
    /* a chunk a triangle up to 4096 (a few large triangles, as in a
     * room of quads, are then shared out among the threads; 64 a chunk
     * left cornell.pov's 30 on one thread), then runs of them */
    B.chunks = (int)(ntris < 4096 ? ntris : 4096);
    if (B.chunks < 1) B.chunks = 1;
    B.ce = calloc((size_t)B.chunks, sizeof *B.ce);
    B.cne = calloc((size_t)B.chunks, sizeof *B.cne);
    B.ccap = calloc((size_t)B.chunks, sizeof *B.ccap);
    B.fail = calloc((size_t)B.chunks, sizeof *B.fail);
    if (!B.ce || !B.cne || !B.ccap || !B.fail || !bgrid_build(&B.g, p, n, spacing)) goto nomem;
    if (!pool_run_cancel(threads, B.chunks, build_job, &B, cancel)) {
        *st = PT_CANCELLED;
        gi_trilook_free(t);
        t = NULL;
        goto done;
    }
    long ne = SHARED_WORDS;
    long *base = malloc((size_t)B.chunks * sizeof *base);
    if (!base) goto nomem;
    for (int ch = 0; ch < B.chunks; ch++) {
        if (B.fail[ch]) {
            free(base);
            goto nomem;
        }
        base[ch] = ne;
        ne += B.cne[ch];
    }
    if (ne >= (long)LOCAL) {
        free(base);
        goto nomem;
    }
    /* (a padding line after the end: prefetches) */
    t->e = malloc((size_t)(ne + 16) * sizeof *t->e);
    if (!t->e) {
        free(base);
        goto nomem;
    }
    t->ne = ne;
    float zero = 0.0f;
    t->e[EMPTY_COMPLETE] = COMPLETE;
    memcpy(&t->e[EMPTY_COMPLETE + 1], &zero, sizeof zero);
    t->e[EMPTY_OPEN] = 0u;
    memcpy(&t->e[EMPTY_OPEN + 1], &zero, sizeof zero);
    memset(t->e + ne, 0, 16 * sizeof *t->e);
    /* concatenate the chunks' lists; a list's offset was chunk-local */
    for (int ch = 0; ch < B.chunks; ch++) {
        if (B.cne[ch]) memcpy(t->e + base[ch], B.ce[ch], (size_t)B.cne[ch] * sizeof *t->e);
        long t0 = ntris * ch / B.chunks, t1 = ntris * (ch + 1) / B.chunks;
        unsigned gi = 0;
        for (long ft = t0; ft < t1; ft++) {
            while (gi + 1 < ngeo && gbase[gi + 1] <= ft) gi++;
            const tl_tri *T = &t->tri[geo[gi].geom][ft - gbase[gi]];
            if (T->k == 0) continue;
            long nc = (long)T->k * (T->k + 1) / 2;
            for (long c = 2 * T->cell0; c < 2 * (T->cell0 + nc); c++)
                if (t->loff[c] & LOCAL) t->loff[c] = (unsigned)((t->loff[c] & ~LOCAL) + base[ch]);
        }
    }
    for (long c = 0; c < t->ncell; c++)
        if (t->loff[c] >= SHARED_WORDS) t->entries += t->e[t->loff[c]] & ~COMPLETE;
    free(base);
    goto done;
nomem:
    *st = PT_ERR_NOMEM;
    gi_trilook_free(t);
    t = NULL;
done:
    if (B.ce)
        for (int ch = 0; ch < B.chunks; ch++) free(B.ce[ch]);
    free(B.ce);
    free(B.cne);
    free(B.ccap);
    free(B.fail);
    bgrid_free(&B.g);
    free(pobjid);
    free(geo);
    free(gbase);
    free(tobj);
    return t;
}

void gi_trilook_compact(gi_trilook *t, const int *remap, const gi_dev_particle *p, int n)
{
    if (!t) return;
    long entries = 0;
    for (long c = 0; c < t->ncell; c++) {
        unsigned o = t->loff[c];
        if (o < SHARED_WORDS) continue;
        unsigned *L = t->e + o, cnt = L[0] & ~COMPLETE, w = 0;
        for (unsigned r = 0; r < cnt; r++) {
            unsigned id = L[2 + r];
            int ni = remap[id & ~UNCERTAIN];
            if (ni >= 0) L[2 + w++] = (unsigned)ni | (id & UNCERTAIN);
        }
        /* the certificate stays: the list still holds every remaining
         * particle within its radius */
        L[0] = w | (L[0] & COMPLETE);
        entries += w;
    }
    t->entries = entries;
    free(t->rep);
    t->rep = NULL;
    /* the particles, renumbered */
    if (n <= t->n) {
        for (int i = 0; i < n; i++)
            t->pp[i] = (tl_pp){p[i].p[0], p[i].p[1], p[i].p[2], p[i].n[0], p[i].n[1], p[i].n[2], {0, 0}};
        t->pp[n] = (tl_pp){INFINITY, INFINITY, INFINITY, 0, 0, 0, {0, 0}};
        t->n = n;
    }
}

size_t gi_trilook_bytes(const gi_trilook *t)
{
    if (!t) return 0;
    size_t b = sizeof *t + (size_t)t->ncell * sizeof *t->loff + (size_t)(t->ne + 16) * sizeof *t->e +
               (size_t)(t->n + 1) * sizeof *t->pp + (size_t)t->ngeom * (sizeof(tl_tri *) + sizeof(long));
    for (unsigned g = 0; g < t->ngeom; g++) b += (size_t)t->ntri[g] * sizeof(tl_tri);
    return b;
}

long gi_trilook_entries(const gi_trilook *t) { return t ? t->entries : 0; }
long gi_trilook_cells(const gi_trilook *t) { return t ? t->ncell : 0; }

/* ------------------------------------------------------------------ query */

long gi_trilook_cell(const gi_trilook *t, unsigned geom, unsigned prim, float u, float v, const float dir[3])
{
    if (geom >= t->ngeom || !t->tri[geom] || (long)prim >= t->ntri[geom]) return -1;
    const tl_tri *T = &t->tri[geom][prim];
    int k = T->k;
    if (k == 0) return -1;
    float s = T->n[0] * dir[0] + T->n[1] * dir[1] + T->n[2] * dir[2];
    /* gi_links turns Embree's Ng against the ray; a ray this close to the
     * plane might be turned the other way there */
    if (!(fabsf(s) >= 1e-4f)) return -1;
    float fu = u * (float)k, fv = v * (float)k;
    int i = fu > 0.0f ? (int)fu : 0, j = fv > 0.0f ? (int)fv : 0;
    if (i > k - 1) i = k - 1;
    if (j > k - 1) j = k - 1;
    if (i + j > k - 1) j = k - 1 - i;
    long c = T->cell0 + (long)i * k - (long)i * (i - 1) / 2 + j;
    return 2 * c + (s > 0.0f);
}

void gi_trilook_prefetch(const gi_trilook *t, long cell, int stage)
{
    if (stage == 0) {
        __builtin_prefetch(&t->loff[cell]);
    } else if (stage == 1) {
        __builtin_prefetch(t->e + t->loff[cell]);
    } else {
        const unsigned *L = t->e + t->loff[cell];
        unsigned cnt = L[0] & ~COMPLETE;
        for (unsigned r = 0; r < cnt; r++) __builtin_prefetch(&t->pp[L[2 + r] & ~UNCERTAIN]);
    }
}

int gi_trilook_nearest(const gi_trilook *t, long cell, const float q[3], const float dir[3], const float org[3])
{
    const unsigned *L = t->e + t->loff[cell];
    unsigned cnt = L[0] & ~COMPLETE;
    /* gi_lookup's filters in its float arithmetic (scan_runs4: the same
     * operations in the same order): the normal faces against the ray,
     * the origin lies in front of the particle, the hit lies near its
     * tangent plane. A tie with the best is left to the grid path, which
     * breaks ties its own way (by grid slot when its first answer stands,
     * by particle index when it searched again). */
#if defined(__SSE2__)
    /* 4 entries at a time, branch-free (the filters' outcomes are
     * unpredictable); lanes past the list read the particle at infinity */
    const __m128 zero = _mm_setzero_ps(), vnp = _mm_set1_ps(0.25f);
    const __m128 qx = _mm_set1_ps(q[0]), qy = _mm_set1_ps(q[1]), qz = _mm_set1_ps(q[2]);
    const __m128 dx = _mm_set1_ps(dir[0]), dy = _mm_set1_ps(dir[1]), dz = _mm_set1_ps(dir[2]);
    const __m128 ox = _mm_set1_ps(org[0]), oy = _mm_set1_ps(org[1]), oz = _mm_set1_ps(org[2]);
    __m128 best = _mm_set1_ps(t->start2);
    __m128i slot = _mm_set1_epi32(-1), tie = _mm_setzero_si128();
    __m128i lane = _mm_setr_epi32(0, 1, 2, 3);
    const __m128i four = _mm_set1_epi32(4);
    const tl_pp *pp = t->pp;
    for (unsigned r = 0; r < cnt; r += 4, lane = _mm_add_epi32(lane, four)) {
        unsigned i0 = L[2 + r] & ~UNCERTAIN;
        unsigned i1 = r + 1 < cnt ? L[3 + r] & ~UNCERTAIN : (unsigned)t->n;
        unsigned i2 = r + 2 < cnt ? L[4 + r] & ~UNCERTAIN : (unsigned)t->n;
        unsigned i3 = r + 3 < cnt ? L[5 + r] & ~UNCERTAIN : (unsigned)t->n;
        __m128 x = _mm_load_ps(&pp[i0].x), y = _mm_load_ps(&pp[i1].x), z = _mm_load_ps(&pp[i2].x),
               nx = _mm_load_ps(&pp[i3].x);
        _MM_TRANSPOSE4_PS(x, y, z, nx);
        __m128 ny = _mm_load_ps(&pp[i0].ny), nz = _mm_load_ps(&pp[i1].ny), c = _mm_load_ps(&pp[i2].ny),
               dd = _mm_load_ps(&pp[i3].ny);
        _MM_TRANSPOSE4_PS(ny, nz, c, dd);
        __m128 ex = _mm_sub_ps(x, qx), ey = _mm_sub_ps(y, qy), ez = _mm_sub_ps(z, qz);
        __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(ex, ex), _mm_mul_ps(ey, ey)), _mm_mul_ps(ez, ez));
        __m128 f = _mm_add_ps(_mm_add_ps(_mm_mul_ps(nx, dx), _mm_mul_ps(ny, dy)), _mm_mul_ps(nz, dz));
        __m128 hh = _mm_add_ps(_mm_add_ps(_mm_mul_ps(nx, _mm_sub_ps(ox, x)), _mm_mul_ps(ny, _mm_sub_ps(oy, y))),
                               _mm_mul_ps(nz, _mm_sub_ps(oz, z)));
        __m128 pe = _mm_add_ps(_mm_add_ps(_mm_mul_ps(nx, ex), _mm_mul_ps(ny, ey)), _mm_mul_ps(nz, ez));
        __m128 filt = _mm_and_ps(_mm_and_ps(_mm_cmplt_ps(f, zero), _mm_cmpgt_ps(hh, zero)),
                                 _mm_cmple_ps(_mm_mul_ps(pe, pe), _mm_mul_ps(vnp, d2)));
        __m128 ok = _mm_and_ps(filt, _mm_cmplt_ps(d2, best));
        __m128i oki = _mm_castps_si128(ok);
        tie = _mm_or_si128(_mm_andnot_si128(oki, tie), _mm_castps_si128(_mm_and_ps(filt, _mm_cmpeq_ps(d2, best))));
        best = _mm_or_ps(_mm_and_ps(ok, d2), _mm_andnot_ps(ok, best));
        slot = _mm_or_si128(_mm_and_si128(oki, lane), _mm_andnot_si128(oki, slot));
    }
    __m128i has = _mm_cmpgt_epi32(slot, _mm_set1_epi32(-1));
    if (!_mm_movemask_ps(_mm_castsi128_ps(has))) return (L[0] & COMPLETE) ? -1 : -2;
    /* lanes without a slot hold start2, above every lane with one */
    __m128 m = _mm_min_ps(best, _mm_shuffle_ps(best, best, _MM_SHUFFLE(1, 0, 3, 2)));
    m = _mm_min_ps(m, _mm_shuffle_ps(m, m, _MM_SHUFFLE(2, 3, 0, 1)));
    __m128 eq = _mm_and_ps(_mm_castsi128_ps(has), _mm_cmpeq_ps(best, m));
    int em = _mm_movemask_ps(eq), tm = _mm_movemask_ps(_mm_castsi128_ps(tie));
    if ((em & (em - 1)) || (em & tm)) return -2; /* a tie */
    int sl[4];
    _mm_storeu_si128((__m128i *)sl, slot);
    unsigned win = L[2 + sl[__builtin_ctz((unsigned)em)]];
    float bestd = _mm_cvtss_f32(m);
#else
    const float qx = q[0], qy = q[1], qz = q[2], dx = dir[0], dy = dir[1], dz = dir[2];
    const float ox = org[0], oy = org[1], oz = org[2];
    float bestd = t->start2;
    unsigned win = 0;
    int found = 0, tie = 0;
    for (unsigned r = 0; r < cnt; r++) {
        unsigned id = L[2 + r];
        const tl_pp *e = &t->pp[id & ~UNCERTAIN];
        float ex = e->x - qx, ey = e->y - qy, ez = e->z - qz;
        float d2 = ex * ex + ey * ey + ez * ez;
        if (d2 > bestd) continue;
        float f = e->nx * dx + e->ny * dy + e->nz * dz;
        float hh = e->nx * (ox - e->x) + e->ny * (oy - e->y) + e->nz * (oz - e->z);
        float pe = e->nx * ex + e->ny * ey + e->nz * ez;
        if (!(f < 0.0f) || !(hh > 0.0f) || !(pe * pe <= 0.25f * d2)) continue;
        if (d2 < bestd) {
            bestd = d2;
            win = id;
            found = 1;
            tie = 0;
        } else {
            tie = found; /* d2 == best */
        }
    }
    if (!found) return (L[0] & COMPLETE) ? -1 : -2;
    if (tie) return -2;
#endif
    float cert2;
    memcpy(&cert2, &L[1], sizeof cert2);
    if (bestd > cert2 || (win & UNCERTAIN)) return -2;
    return (int)win;
}

/* ------------------------------------------------------------ centres */

typedef struct {
    gi_trilook *t;
    long per;
} rep_job;

static void rep_chunk(void *ctx, int ch, int thread)
{
    (void)thread;
    rep_job *R = ctx;
    gi_trilook *t = R->t;
    long c0 = (long)ch * R->per, c1 = c0 + R->per < t->ncell ? c0 + R->per : t->ncell;
    for (long l = c0; l < c1; l++) {
        const float *cc = t->cc + 6 * (l / 2);
        /* a ray along the side's normal onto the centre, from a spacing
         * above it (the scan's filters: the particle faces the ray, the
         * origin lies in front of it, the centre near its plane) */
        float sg = (l & 1) ? -1.0f : 1.0f, q[3], dir[3], org[3];
        for (int a = 0; a < 3; a++) {
            q[a] = cc[a];
            dir[a] = -sg * cc[3 + a];
            org[a] = cc[a] + sg * cc[3 + a] * t->lift;
        }
        int r = t->loff[l] == EMPTY_OPEN ? -2 : gi_trilook_nearest(t, l, q, dir, org);
        t->rep[l] = r >= 0 ? r : -2;
    }
}

int gi_trilook_centres(gi_trilook *t, int threads)
{
    if (!t || !t->cc) return 0;
    if (t->rep) return 1;
    t->rep = malloc((size_t)t->ncell * sizeof *t->rep);
    if (!t->rep) return 0;
    rep_job R = {t, 4096};
    pool_run(threads > 0 ? threads : pool_default_threads(), (int)((t->ncell + R.per - 1) / R.per), rep_chunk, &R);
    return 1;
}

const int *gi_trilook_centre_table(const gi_trilook *t) { return t ? t->rep : NULL; }
