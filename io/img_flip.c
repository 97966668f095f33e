/* img_flip.c - LDR-FLIP and HDR-FLIP, written from the papers:
 *  [L] Andersson et al., "FLIP: A Difference Evaluator for Alternating
 *      Images", HPG 2020 (PACMCGIT 3(2), 15:1-15:23);
 *  [H] Andersson et al., "Visualizing Errors in Rendered High Dynamic Range
 *      Images", Eurographics 2021 short paper.
 * Where the papers leave a detail open (kernel radii and normalisation, edge
 * handling, the median used for the exposure range, the weighted median),
 * we follow the authors' published tool, so that our numbers match its
 * output; ../shared/flip/README.md lists the values we reproduce.
 *
 * LDR-FLIP for a reference R and a test T, both linear RGB in [0,1]:
 *  Colour pipeline [L]:
 *   1. linear RGB -> XYZ -> YyCxCz, the opponent space of Johnson and
 *      Fairchild (a "linearised" CIELAB: Y' = 116 Y/Yn - 16,
 *      Cx = 500 (X/Xn - Y/Yn), Cz = 200 (Y/Yn - Z/Zn)).
 *   2. Each channel is filtered with the spatial form of its contrast
 *      sensitivity function, a sum of Gaussians
 *        h(x) = a1 sqrt(pi/b1) exp(-pi^2 x^2/b1) + a2 sqrt(pi/b2) exp(-pi^2 x^2/b2)
 *      with x in degrees of visual angle (pixels / ppd); the 2-D kernel uses
 *      x^2 -> x^2 + y^2 and is normalised to unit sum. Constants
 *      (achromatic, red-green, blue-yellow):
 *        a1 = 1, 1, 34.1   b1 = 0.0047, 0.0053, 0.04
 *        a2 = 0, 0, 13.5   b2 = 1e-5,  1e-5,   0.025
 *      Kernel radius: ceil(3 sigma_max ppd), sigma = sqrt(b / (2 pi^2)).
 *   3. Back to linear RGB, clamped to [0,1]; then CIELAB and the Hunt
 *      adjustment a' = 0.01 L a, b' = 0.01 L b.
 *   4. HyAB distance |dL| + sqrt(da^2 + db^2), raised to qc = 0.7 and
 *      remapped to [0,1] with pc = 0.4, pt = 0.95; cmax is the distance (^qc)
 *      between Hunt-adjusted pure green and pure blue.
 *  Feature pipeline [L]:
 *   5. On the achromatic channel normalised to [0,1], edges and points are
 *      found with the first and second derivatives of a Gaussian of standard
 *      deviation sigma = 0.5 w ppd pixels, w = 0.082 degrees, radius
 *      ceil(3 sigma). The Gaussian is normalised to unit sum, the positive
 *      and negative lobes of each derivative to +1 and -1. Edge and point
 *      strengths are the lengths of the (x, y) response vectors.
 *   6. Feature difference dF = (max(|dEdge|, |dPoint|) / sqrt(2))^qf, qf = 0.5.
 *  7. FLIP = dC^(1 - dF).
 * Borders repeat the edge pixel. All kernels are applied as products of 1-D
 * kernels (the blue-yellow one as a sum of two separable Gaussians), which
 * gives the same result as the 2-D kernels.
 *
 * HDR-FLIP [H]: the linear inputs are scaled by 2^c for exposures c from the
 * start to the stop exposure in n equal steps, tone mapped with the ACES
 * filmic curve (Narkowicz's fit with the 0.6 pre-exposure folded in) and
 * clamped; LDR-FLIP is evaluated for each exposure, and the per-pixel
 * maximum is the HDR-FLIP value. */
#include "img_flip.h"
#include "img_io.h"
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "pool.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* [L] constants. */
#define FLIP_QC 0.7
#define FLIP_PC 0.4
#define FLIP_PT 0.95
#define FLIP_W 0.082
#define FLIP_QF 0.5

/* CSF sum-of-Gaussians constants [L]: index 0 achromatic,
 * 1 red-green, 2 blue-yellow. */
static const double csf_a1[3] = {1.0, 1.0, 34.1};
static const double csf_b1[3] = {0.0047, 0.0053, 0.04};
static const double csf_a2[3] = {0.0, 0.0, 13.5};
static const double csf_b2[3] = {1e-5, 1e-5, 0.025};

/* ACES filmic fit t(x) = (c0 x^2 + c1 x) / (c3 x^2 + c4 x + c5), with the
 * usual 0.6 pre-exposure multiplied into the coefficients [H]. */
static const double aces_c[6] = {0.6 * 0.6 * 2.51, 0.6 * 0.03, 0.0,
                                 0.6 * 0.6 * 2.43, 0.6 * 0.59, 0.14};

/* Linear sRGB (D65) -> XYZ, in the exact rational form derived from the sRGB
 * primaries (image-engineering.de technote 958). The reference white is the
 * image of RGB (1,1,1), i.e. the row sums, so white maps to L* = 100, a* = b* = 0. */
static const double rgb2xyz[3][3] = {
    {10135552.0 / 24577794.0, 8788810.0 / 24577794.0, 4435075.0 / 24577794.0},
    {2613072.0 / 12288897.0, 8788810.0 / 12288897.0, 887015.0 / 12288897.0},
    {1425312.0 / 73733382.0, 8788810.0 / 73733382.0, 70074185.0 / 73733382.0},
};

typedef struct {
    double xyz2rgb[3][3];
    double white[3];
    double cmax, pccmax;  /* colour-difference remapping [L] */
} flip_consts;

static void lab_from_linear(const flip_consts *k, const double rgb[3], double lab[3])
{
    const double delta = 6.0 / 29.0;
    const double d3 = delta * delta * delta;
    double f[3];
    for (int i = 0; i < 3; i++) {
        double t = (rgb2xyz[i][0] * rgb[0] + rgb2xyz[i][1] * rgb[1] + rgb2xyz[i][2] * rgb[2]) / k->white[i];
        f[i] = t > d3 ? cbrt(t) : t / (3.0 * delta * delta) + 4.0 / 29.0;
    }
    lab[0] = 116.0 * f[1] - 16.0;
    lab[1] = 500.0 * (f[0] - f[1]);
    lab[2] = 200.0 * (f[1] - f[2]);
}

/* Hunt adjustment [L]: chroma scaled by 0.01 L. */
static void hunt(double lab[3])
{
    lab[1] *= 0.01 * lab[0];
    lab[2] *= 0.01 * lab[0];
}

/* HyAB distance [L]: city-block in L, Euclidean in (a, b). */
static double hyab(const double p[3], const double q[3])
{
    double da = p[1] - q[1], db = p[2] - q[2];
    return fabs(p[0] - q[0]) + sqrt(da * da + db * db);
}

static void invert3(const double m[3][3], double r[3][3])
{
    double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                 m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                 m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    r[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) / det;
    r[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / det;
    r[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / det;
    r[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) / det;
    r[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det;
    r[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / det;
    r[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) / det;
    r[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / det;
    r[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / det;
}

static void consts_init(flip_consts *k)
{
    invert3(rgb2xyz, k->xyz2rgb);
    for (int i = 0; i < 3; i++) k->white[i] = rgb2xyz[i][0] + rgb2xyz[i][1] + rgb2xyz[i][2];
    double g[3] = {0, 1, 0}, b[3] = {0, 0, 1}, lg[3], lb[3];
    lab_from_linear(k, g, lg);
    lab_from_linear(k, b, lb);
    hunt(lg);
    hunt(lb);
    k->cmax = pow(hyab(lg, lb), FLIP_QC);
    k->pccmax = FLIP_PC * k->cmax;
}

double img_flip_ppd(double dist_m, double res_x, double width_m)
{
    return dist_m * (res_x / width_m) * (M_PI / 180.0);
}

void img_flip_default_params(img_flip_params *p)
{
    p->ppd = IMG_FLIP_DEFAULT_PPD;
    p->exp_start = NAN;
    p->exp_stop = NAN;
    p->nexposures = 0;
}

/* ---- separable filtering with edge clamping, rows in parallel ---- */

#define ROWS_PER_JOB 16

typedef struct {
    int w, h, nthreads, padw;
    double *acc; /* nthreads * w */
    float *pad;  /* nthreads * padw */
} conv_ctx;

typedef struct {
    const conv_ctx *c;
    const float *src;
    float *dst;
    const double *k;
    int r, dir;
} conv_job;

/* Rows [16 index, 16 index + 16) of a 1-D pass along x (dir 0) or y (dir 1).
 * Both directions run tap by tap over a whole row (the inner loop is a plain
 * multiply-add over x), the x pass on a copy of the row padded with its edge
 * values. */
static void conv_rows(void *ctx, int index, int thread)
{
    const conv_job *j = ctx;
    int w = j->c->w, h = j->c->h, r = j->r;
    double *acc = j->c->acc + (size_t)thread * (size_t)w;
    float *pad = j->c->pad + (size_t)thread * (size_t)j->c->padw;
    int y1 = (index + 1) * ROWS_PER_JOB;
    if (y1 > h) y1 = h;
    for (int y = index * ROWS_PER_JOB; y < y1; y++) {
        for (int x = 0; x < w; x++) acc[x] = 0.0;
        if (j->dir == 0) {
            const float *row = j->src + (size_t)y * (size_t)w;
            for (int i = 0; i < r; i++) {
                pad[i] = row[0];
                pad[r + w + i] = row[w - 1];
            }
            memcpy(pad + r, row, (size_t)w * sizeof *pad);
            for (int i = 0; i <= 2 * r; i++) {
                double kv = j->k[i];
                const float *p = pad + i;
                for (int x = 0; x < w; x++) acc[x] += kv * p[x];
            }
        } else {
            for (int i = -r; i <= r; i++) {
                int yy = y + i;
                yy = yy < 0 ? 0 : (yy >= h ? h - 1 : yy);
                const float *row = j->src + (size_t)yy * (size_t)w;
                double kv = j->k[i + r];
                for (int x = 0; x < w; x++) acc[x] += kv * row[x];
            }
        }
        float *out = j->dst + (size_t)y * (size_t)w;
        for (int x = 0; x < w; x++) out[x] = (float)acc[x];
    }
}

/* One 1-D pass of kernel k (2r + 1 taps) over src (w*h) into dst. */
static void conv1d(const conv_ctx *c, const float *src, float *dst, const double *k, int r, int dir)
{
    conv_job j = {c, src, dst, k, r, dir};
    pool_run(c->nthreads, (c->h + ROWS_PER_JOB - 1) / ROWS_PER_JOB, conv_rows, &j);
}

/* 2-D separable convolution: kx along x into tmp, then ky along y. */
static void conv2d(const conv_ctx *c, const float *src, float *dst, float *tmp,
                   const double *kx, const double *ky, int r)
{
    conv1d(c, src, tmp, kx, r, 0);
    conv1d(c, tmp, dst, ky, r, 1);
}

/* The colour difference of the filtered images and the final FLIP value,
 * for a block of rows. */
typedef struct {
    const flip_consts *k;
    float *(*P)[3];
    const float *fdiff;
    float *err;
    int w, h;
} color_job;

static void color_rows(void *ctx, int index, int thread)
{
    const color_job *j = ctx;
    const flip_consts *k = j->k;
    int y1 = (index + 1) * ROWS_PER_JOB;
    if (y1 > j->h) y1 = j->h;
    size_t i0 = (size_t)index * ROWS_PER_JOB * (size_t)j->w, i1 = (size_t)y1 * (size_t)j->w;
    for (size_t i = i0; i < i1; i++) {
        double lab[2][3];
        for (int im = 0; im < 2; im++) {
            double yy = ((double)j->P[im][0][i] + 16.0) / 116.0;
            double xyz[3] = {(yy + j->P[im][1][i] / 500.0) * k->white[0], yy * k->white[1],
                             (yy - j->P[im][2][i] / 200.0) * k->white[2]};
            double rgb[3];
            for (int r = 0; r < 3; r++) {
                double v = k->xyz2rgb[r][0] * xyz[0] + k->xyz2rgb[r][1] * xyz[1] + k->xyz2rgb[r][2] * xyz[2];
                rgb[r] = v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v);
            }
            lab_from_linear(k, rgb, lab[im]);
            hunt(lab[im]);
        }
        double dc = pow(hyab(lab[0], lab[1]), FLIP_QC);
        if (dc < k->pccmax)
            dc *= FLIP_PT / k->pccmax;
        else
            dc = FLIP_PT + (dc - k->pccmax) / (k->cmax - k->pccmax) * (1.0 - FLIP_PT);
        j->err[i] = (float)pow(dc, 1.0 - (double)j->fdiff[i]);
    }
}

/* How input values become linear RGB in [0,1] for LDR-FLIP. */
typedef enum {
    FLIP_IN_SRGB,  /* display-encoded: clamp, then the sRGB decoding */
    FLIP_IN_TONED  /* scene-linear: scale by 2^c, ACES tone curve, clamp */
} flip_input_mode;

typedef struct {
    flip_input_mode mode;
    double scale; /* 2^c for FLIP_IN_TONED */
} flip_input;

static double input_linear(const flip_input *in, float v)
{
    if (in->mode == FLIP_IN_SRGB) {
        double e = !isfinite(v) ? 0.0 : (v < 0.0f ? 0.0 : (v > 1.0f ? 1.0 : (double)v));
        /* sRGB transfer function, IEC 61966-2-1. */
        return img_srgb_decode(e);
    }
    /* Negative values count as 0: the rational tone curve is meant for
     * x >= 0 (it would turn x = -1 into 1.34). */
    double x = isfinite(v) && v > 0.0f ? (double)v * in->scale : 0.0;
    double y = (aces_c[0] * x * x + aces_c[1] * x + aces_c[2]) /
               (aces_c[3] * x * x + aces_c[4] * x + aces_c[5]);
    if (!isfinite(y)) y = 1.0; /* overflow of a huge value */
    return y < 0.0 ? 0.0 : (y > 1.0 ? 1.0 : y);
}

/* Input -> linear RGB (float, as the pipeline stores it) -> YyCxCz planes,
 * for a block of rows of both images. */
typedef struct {
    const flip_consts *k;
    const flip_input *in;
    const float *src[2];
    float *(*P)[3];
    int w, h;
} ycc_job;

static void ycc_rows(void *ctx, int index, int thread)
{
    const ycc_job *j = ctx;
    int y1 = (index + 1) * ROWS_PER_JOB;
    if (y1 > j->h) y1 = j->h;
    size_t i0 = (size_t)index * ROWS_PER_JOB * (size_t)j->w, i1 = (size_t)y1 * (size_t)j->w;
    for (int im = 0; im < 2; im++)
        for (size_t i = i0; i < i1; i++) {
            double rgb[3], xyz[3];
            for (int c = 0; c < 3; c++) rgb[c] = (float)input_linear(j->in, j->src[im][i * 3 + (size_t)c]);
            for (int r = 0; r < 3; r++)
                xyz[r] = (rgb2xyz[r][0] * rgb[0] + rgb2xyz[r][1] * rgb[1] + rgb2xyz[r][2] * rgb[2]) / j->k->white[r];
            j->P[im][0][i] = (float)(116.0 * xyz[1] - 16.0);
            j->P[im][1][i] = (float)(500.0 * (xyz[0] - xyz[1]));
            j->P[im][2][i] = (float)(200.0 * (xyz[1] - xyz[2]));
        }
}

/* ---- LDR-FLIP (inputs mapped to linear RGB in [0,1] by `in`) ---- */

static pt_status flip_ldr_linear(const float *ref, const float *test, int w, int h,
                                 const flip_input *in, double ppd, float *err, diag *d)
{
    flip_consts k;
    consts_init(&k);
    size_t n = (size_t)w * (size_t)h;

    /* Spatial CSF kernels [L]. */
    double bmax = 0.0;
    for (int c = 0; c < 3; c++) {
        if (csf_b1[c] > bmax) bmax = csf_b1[c];
        if (csf_b2[c] > bmax) bmax = csf_b2[c];
    }
    int rs = (int)ceil(3.0 * sqrt(bmax / (2.0 * M_PI * M_PI)) * ppd);
    int ns = 2 * rs + 1;
    /* Feature kernels [L]. */
    double sd = 0.5 * FLIP_W * ppd;
    int rf = (int)ceil(3.0 * sd);
    int nf = 2 * rf + 1;

    double *ks = calloc((size_t)(4 * ns + 3 * nf), sizeof(double));
    /* 12 planes of w*h floats: YCxCz of both images (6), two results (F1,
     * F2), the between-passes plane T, and E, Q, S (see below). */
    float *buf = malloc(n * 12 * sizeof(float));
    conv_ctx cc;
    cc.w = w;
    cc.h = h;
    cc.nthreads = pool_default_threads();
    cc.padw = w + 2 * (rs > rf ? rs : rf);
    cc.acc = malloc((size_t)cc.nthreads * (size_t)w * sizeof(double));
    cc.pad = malloc((size_t)cc.nthreads * (size_t)cc.padw * sizeof(float));
    if (!ks || !buf || !cc.acc || !cc.pad) {
        free(ks);
        free(buf);
        free(cc.acc);
        free(cc.pad);
        diag_report(d, DIAG_ERROR, (src_loc){0}, NULL, "FLIP: out of memory for a %dx%d image", w, h);
        return PT_ERR_NOMEM;
    }

    double *kY = ks, *kCx = ks + ns, *kCz1 = ks + 2 * ns, *kCz2 = ks + 3 * ns;
    double *kg = ks + 4 * ns, *kdg = kg + nf, *kddg = kdg + nf;
    {
        double sY = 0, sCx = 0, s1 = 0, s2 = 0;
        for (int i = 0; i < ns; i++) {
            double x = (double)(i - rs) / ppd, x2 = x * x;
            /* 1-D factors of the 2-D kernels. A single Gaussian is normalised
             * on its own, so its amplitude drops out; for the blue-yellow sum
             * each factor of a sqrt(pi/b) exp(-pi^2 (x^2 + y^2)/b) carries the
             * square root of the amplitude, keeping the two terms' ratio. */
            kY[i] = csf_a1[0] * sqrt(M_PI / csf_b1[0]) * exp(-M_PI * M_PI * x2 / csf_b1[0]);
            kCx[i] = csf_a1[1] * sqrt(M_PI / csf_b1[1]) * exp(-M_PI * M_PI * x2 / csf_b1[1]);
            kCz1[i] = sqrt(csf_a1[2] * sqrt(M_PI / csf_b1[2])) * exp(-M_PI * M_PI * x2 / csf_b1[2]);
            kCz2[i] = sqrt(csf_a2[2] * sqrt(M_PI / csf_b2[2])) * exp(-M_PI * M_PI * x2 / csf_b2[2]);
            sY += kY[i];
            sCx += kCx[i];
            s1 += kCz1[i];
            s2 += kCz2[i];
        }
        /* Unit sum in 2-D: for the blue-yellow pair the 2-D sum is s1^2 + s2^2. */
        double nz = 1.0 / sqrt(s1 * s1 + s2 * s2);
        for (int i = 0; i < ns; i++) {
            kY[i] /= sY;
            kCx[i] /= sCx;
            kCz1[i] *= nz;
            kCz2[i] *= nz;
        }
        double sg = 0, sdp = 0, sdn = 0, sddp = 0, sddn = 0;
        for (int i = 0; i < nf; i++) {
            double x = (double)(i - rf);
            double g = exp(-(x * x) / (2.0 * sd * sd));
            kg[i] = g;
            kdg[i] = -x * g;
            kddg[i] = (x * x / (sd * sd) - 1.0) * g;
            sg += g;
            if (kdg[i] > 0) sdp += kdg[i]; else sdn -= kdg[i];
            if (kddg[i] > 0) sddp += kddg[i]; else sddn -= kddg[i];
        }
        for (int i = 0; i < nf; i++) {
            kg[i] /= sg;
            kdg[i] /= kdg[i] > 0 ? sdp : sdn;
            kddg[i] /= kddg[i] > 0 ? sddp : sddn;
        }
    }

    /* Plane layout: E and Q end up holding the feature difference and a
     * reference feature response, S the normalised achromatic channel. */
    float *P[2][3];
    for (int im = 0; im < 2; im++)
        for (int c = 0; c < 3; c++) P[im][c] = buf + (size_t)(im * 3 + c) * n;
    float *F1 = buf + 6 * n, *F2 = buf + 7 * n, *T = buf + 8 * n;
    float *E = buf + 9 * n, *Q = buf + 10 * n, *S = buf + 11 * n;

    /* 1. input -> linear RGB -> YCxCz. */
    ycc_job yj = {&k, in, {ref, test}, P, w, h};
    pool_run(cc.nthreads, (h + ROWS_PER_JOB - 1) / ROWS_PER_JOB, ycc_rows, &yj);

    /* 5-6. Feature pipeline first (it reads the unfiltered achromatic channel).
     * Achromatic channel normalised to [0,1]: (Y' + 16) / 116 = Y / Yn. For
     * each image: edge = |(dg_x g_y, g_x dg_y) * Yn|, point likewise with ddg.
     * Results: edge in E (ref) / F1 (test), point in Q (ref) / F2 (test). */
    for (int im = 0; im < 2; im++) {
        float *yn = S;
        for (size_t i = 0; i < n; i++) yn[i] = (float)(((double)P[im][0][i] + 16.0) / 116.0);
        float *edge = im ? F1 : E, *point = im ? F2 : Q;
        /* x-derivative responses */
        conv2d(&cc, yn, edge, T, kdg, kg, rf); /* derivative along x, Gaussian along y */
        conv2d(&cc, yn, point, T, kddg, kg, rf);
        /* y-derivative responses: Gaussian along x into T, then each
         * derivative along y, using `err` (not yet written) as scratch. */
        float *dy = err;
        conv1d(&cc, yn, T, kg, rf, 0); /* Gaussian along x */
        conv1d(&cc, T, dy, kdg, rf, 1); /* derivative along y */
        for (size_t i = 0; i < n; i++) edge[i] = sqrtf(edge[i] * edge[i] + dy[i] * dy[i]);
        conv1d(&cc, T, dy, kddg, rf, 1);
        for (size_t i = 0; i < n; i++) point[i] = sqrtf(point[i] * point[i] + dy[i] * dy[i]);
    }
    /* Feature difference into E. */
    for (size_t i = 0; i < n; i++) {
        double de = fabs((double)E[i] - F1[i]);
        double dp = fabs((double)Q[i] - F2[i]);
        double m = de > dp ? de : dp;
        E[i] = (float)pow(m / sqrt(2.0), FLIP_QF); /* qf = 0.5 */
    }

    /* 2. Spatial filtering of YCxCz, in place per plane. */
    for (int im = 0; im < 2; im++) {
        conv2d(&cc, P[im][0], F1, T, kY, kY, rs);
        memcpy(P[im][0], F1, n * sizeof(float));
        conv2d(&cc, P[im][1], F1, T, kCx, kCx, rs);
        memcpy(P[im][1], F1, n * sizeof(float));
        conv2d(&cc, P[im][2], F1, T, kCz1, kCz1, rs);
        conv2d(&cc, P[im][2], F2, T, kCz2, kCz2, rs);
        for (size_t i = 0; i < n; i++) P[im][2][i] = F1[i] + F2[i];
    }

    /* 3-4, 7. Colour difference and final error. */
    color_job cj = {&k, P, E, err, w, h};
    pool_run(cc.nthreads, (h + ROWS_PER_JOB - 1) / ROWS_PER_JOB, color_rows, &cj);

    free(ks);
    free(buf);
    free(cc.acc);
    free(cc.pad);
    return PT_OK;
}

static pt_status check_pair(const framebuffer *ref, const framebuffer *test, const float *err, diag *d)
{
    if (!ref || !test || !err || !ref->rgb || !test->rgb) {
        diag_report(d, DIAG_ERROR, (src_loc){0}, NULL, "FLIP: missing image");
        return PT_ERR_USAGE;
    }
    if (ref->width != test->width || ref->height != test->height) {
        diag_report(d, DIAG_ERROR, (src_loc){0}, NULL,
                    "FLIP: image sizes differ: reference %dx%d, test %dx%d",
                    ref->width, ref->height, test->width, test->height);
        return PT_ERR_USAGE;
    }
    if (ref->width <= 0 || ref->height <= 0) {
        diag_report(d, DIAG_ERROR, (src_loc){0}, NULL, "FLIP: empty image");
        return PT_ERR_USAGE;
    }
    return PT_OK;
}

pt_status img_flip_ldr(const framebuffer *ref, const framebuffer *test,
                       const img_flip_params *p, float *err, diag *d)
{
    pt_status st = check_pair(ref, test, err, d);
    if (st != PT_OK) return st;
    flip_input in = {FLIP_IN_SRGB, 1.0};
    double ppd = (p && p->ppd > 0.0) ? p->ppd : IMG_FLIP_DEFAULT_PPD;
    return flip_ldr_linear(ref->rgb, test->rgb, ref->width, ref->height, &in, ppd, err, d);
}

static double luminance(const float *rgb)
{
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

pt_status img_flip_exposures(const framebuffer *ref, double *start, double *stop, int *nexp, diag *d)
{
    if (!ref || !ref->rgb || ref->width <= 0 || ref->height <= 0) {
        diag_report(d, DIAG_ERROR, (src_loc){0}, NULL, "FLIP: empty reference image");
        return PT_ERR_USAGE;
    }
    size_t n = (size_t)ref->width * (size_t)ref->height;
    double *lum = malloc(n * sizeof *lum);
    if (!lum) {
        diag_report(d, DIAG_ERROR, (src_loc){0}, NULL, "FLIP: out of memory");
        return PT_ERR_NOMEM;
    }
    double ymax = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        const float *px = ref->rgb + 3 * i;
        float c[3] = {isfinite(px[0]) ? px[0] : 0.0f, isfinite(px[1]) ? px[1] : 0.0f,
                      isfinite(px[2]) ? px[2] : 0.0f};
        double y = luminance(c);
        lum[i] = y;
        if (y > ymax) ymax = y;
    }
    qsort(lum, n, sizeof *lum, cmp_double);
    /* The tool takes the element at index n/2 of the sorted luminances. */
    double ymed = lum[n / 2];
    if (ymed <= 0.0) {
        /* Degenerate (mostly black) reference: use the median of the
         * positive luminances instead (our choice; the tool would divide by 0). */
        size_t first = 0;
        while (first < n && lum[first] <= 0.0) first++;
        ymed = first < n ? lum[first + (n - first) / 2] : 0.0;
    }
    free(lum);

    /* x85: t(x85) = 0.85, the larger root of
     * (c0 - t c3) x^2 + (c1 - t c4) x + (c2 - t c5) = 0. */
    const double t = 0.85;
    double qa = aces_c[0] - t * aces_c[3], qb = aces_c[1] - t * aces_c[4], qc = aces_c[2] - t * aces_c[5];
    double x85;
    if (qa == 0.0) {
        x85 = -qc / qb;
    } else {
        double d1 = -0.5 * qb / qa;
        x85 = d1 + sqrt(d1 * d1 - qc / qa);
    }
    if (!(ymax > 0.0)) {
        diag_report(d, DIAG_WARNING, (src_loc){0}, NULL,
                    "HDR-FLIP: the reference is black; using exposures 0 to 1");
        *start = 0.0;
        *stop = 1.0;
    } else {
        *start = log2(x85 / ymax);
        *stop = ymed > 0.0 ? log2(x85 / ymed) : *start;
    }
    double span = ceil(*stop - *start);
    *nexp = (int)(span > 2.0 ? span : 2.0);
    return PT_OK;
}

pt_status img_flip_hdr(const framebuffer *ref, const framebuffer *test,
                       img_flip_params *p, float *err, diag *d)
{
    pt_status st = check_pair(ref, test, err, d);
    if (st != PT_OK) return st;
    img_flip_params def;
    if (!p) {
        img_flip_default_params(&def);
        p = &def;
    }
    double ppd = p->ppd > 0.0 ? p->ppd : IMG_FLIP_DEFAULT_PPD;
    if (isnan(p->exp_start) || isnan(p->exp_stop)) {
        double s, e;
        int ne;
        st = img_flip_exposures(ref, &s, &e, &ne, d);
        if (st != PT_OK) return st;
        if (isnan(p->exp_start)) p->exp_start = s;
        if (isnan(p->exp_stop)) p->exp_stop = e;
    }
    if (p->exp_start > p->exp_stop) {
        diag_report(d, DIAG_ERROR, (src_loc){0}, NULL,
                    "HDR-FLIP: start exposure %g is above stop exposure %g", p->exp_start, p->exp_stop);
        return PT_ERR_USAGE;
    }
    if (p->nexposures <= 0) {
        double span = ceil(p->exp_stop - p->exp_start);
        p->nexposures = (int)(span > 2.0 ? span : 2.0);
    }
    int ne = p->nexposures;
    if (ne > 64) {
        diag_report(d, DIAG_ERROR, (src_loc){0}, NULL, "HDR-FLIP: %d exposures is too many (limit 64)", ne);
        return PT_ERR_LIMIT;
    }

    int w = ref->width, h = ref->height;
    size_t n = (size_t)w * (size_t)h;
    float *e1 = malloc(n * sizeof(float));
    if (!e1) {
        diag_report(d, DIAG_ERROR, (src_loc){0}, NULL, "HDR-FLIP: out of memory");
        return PT_ERR_NOMEM;
    }
    for (size_t i = 0; i < n; i++) err[i] = 0.0f;
    double step = ne > 1 ? (p->exp_stop - p->exp_start) / (ne - 1) : 0.0;
    for (int k = 0; k < ne; k++) {
        flip_input in = {FLIP_IN_TONED, pow(2.0, p->exp_start + k * step)};
        st = flip_ldr_linear(ref->rgb, test->rgb, w, h, &in, ppd, e1, d);
        if (st != PT_OK) break;
        for (size_t i = 0; i < n; i++)
            if (e1[i] > err[i]) err[i] = e1[i];
    }
    free(e1);
    return st;
}

/* ---- pooling ---- */

double img_flip_mean(const float *err, size_t n)
{
    if (!n) return 0.0;
    double s = 0.0;
    for (size_t i = 0; i < n; i++) s += err[i];
    return s / (double)n;
}

/* Order-preserving map of a float onto an unsigned key. */
static uint32_t float_key(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}

static float key_float(uint32_t u)
{
    u = (u & 0x80000000u) ? (u & 0x7fffffffu) : ~u;
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

/* Sorts n floats ascending (non-finite values count as 0): two 16-bit LSD
 * radix passes over the keys. Returns a malloc'd array or NULL. */
static float *sorted_copy(const float *v, size_t n)
{
    uint32_t *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b);
    size_t *cnt = malloc(65536 * sizeof *cnt);
    if (!a || !b || !cnt) {
        free(a);
        free(b);
        free(cnt);
        return NULL;
    }
    for (size_t i = 0; i < n; i++) a[i] = float_key(isfinite(v[i]) ? v[i] : 0.0f);
    for (int pass = 0; pass < 2; pass++) {
        int sh = 16 * pass;
        memset(cnt, 0, 65536 * sizeof *cnt);
        for (size_t i = 0; i < n; i++) cnt[(a[i] >> sh) & 0xffffu]++;
        size_t sum = 0;
        for (size_t j = 0; j < 65536; j++) {
            size_t c = cnt[j];
            cnt[j] = sum;
            sum += c;
        }
        for (size_t i = 0; i < n; i++) b[cnt[(a[i] >> sh) & 0xffffu]++] = a[i];
        uint32_t *t = a;
        a = b;
        b = t;
    }
    free(cnt);
    free(b);
    /* Convert in place (same size); memcpy keeps this free of type punning. */
    for (size_t i = 0; i < n; i++) {
        float f = key_float(a[i]);
        memcpy(&a[i], &f, sizeof f);
    }
    return (float *)(void *)a;
}

double img_flip_weighted_percentile(const float *err, size_t n, double q)
{
    if (!n) return 0.0;
    float *v = sorted_copy(err, n);
    if (!v) return NAN;
    double total = 0.0;
    for (size_t i = 0; i < n; i++) total += v[i];
    double run = 0.0, res = 0.0;
    for (size_t i = 0; i < n; i++) {
        run += v[i];
        if (run > q * total) {
            res = v[i];
            break;
        }
    }
    free(v);
    return res;
}

double img_flip_hist_weighted_percentile(const float *err, size_t n, double q)
{
    enum { NB = 100 };
    double cnt[NB] = {0};
    const double bw = 1.0 / NB;
    for (size_t i = 0; i < n; i++) {
        double v = err[i];
        if (!(v >= 0.0 && v <= 1.0)) continue;
        int b = (int)(v / bw);
        if (b >= NB) b = NB - 1;
        cnt[b] += 1.0;
    }
    double total = 0.0;
    for (int b = 0; b < NB; b++) total += cnt[b] * (b + 0.5) * bw;
    if (total <= 0.0) return 0.0;
    double run = 0.0;
    int b = 0;
    for (; b < NB; b++) {
        double wv = cnt[b] * (b + 0.5) * bw;
        if (run + wv > q * total) break;
        run += wv;
    }
    if (b >= NB) b = NB - 1;
    double wv = cnt[b] * (b + 0.5) * bw;
    double frac = wv > 0.0 ? (q * total - run) / wv : 0.0;
    return (b + frac) * bw;
}
