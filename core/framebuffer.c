/* framebuffer.c - float RGB image. */
#include "framebuffer.h"
#include <string.h>
#include <math.h>
#include <stdlib.h>

framebuffer *fb_new(int width, int height)
{
    if (width <= 0 || height <= 0 || width > 65536 || height > 65536) return NULL;
    framebuffer *fb = calloc(1, sizeof *fb);
    if (!fb) return NULL;
    fb->width = width;
    fb->height = height;
    fb->rgb = calloc((size_t)width * (size_t)height * 3u, sizeof(float));
    if (!fb->rgb) { free(fb); return NULL; }
    return fb;
}

void fb_free(framebuffer *fb)
{
    if (!fb) return;
    free(fb->rgb);
    free(fb->alpha);
    free(fb);
}

long fb_sanitize(framebuffer *fb)
{
    long n = 0;
    size_t total = (size_t)fb->width * (size_t)fb->height * 3u;
    for (size_t i = 0; i < total; i++) {
        float v = fb->rgb[i];
        if (!isfinite(v)) { fb->rgb[i] = 0.0f; n++; }
    }
    return n;
}

double fb_mean(const framebuffer *fb, int channel)
{
    size_t npx = (size_t)fb->width * (size_t)fb->height;
    double s = 0.0;
    for (size_t i = 0; i < npx; i++) {
        if (channel < 0)
            s += (fb->rgb[i * 3] + fb->rgb[i * 3 + 1] + fb->rgb[i * 3 + 2]) / 3.0;
        else
            s += fb->rgb[i * 3 + (size_t)channel];
    }
    return npx ? s / (double)npx : 0.0;
}

/* Output pixel i of n along an axis of m source pixels: the two source
 * pixels it lies between (held at the edges) and the weight of the second. */
static void taps(int i, int n, int m, int *a, int *b, double *f)
{
    double s = (i + 0.5) * m / n - 0.5;
    int i0 = (int)floor(s);
    *f = s - i0;
    *a = i0 < 0 ? 0 : (i0 >= m ? m - 1 : i0);
    *b = i0 + 1 < 0 ? 0 : (i0 + 1 >= m ? m - 1 : i0 + 1);
}

void fb_resample_bilinear(const framebuffer *src, framebuffer *dst)
{
    int w = src->width, h = src->height, W = dst->width, H = dst->height;
    if (w == W && h == H) {
        memcpy(dst->rgb, src->rgb, (size_t)W * (size_t)H * 3u * sizeof(float));
        return;
    }
    for (int y = 0; y < H; y++) {
        int ya, yb;
        double fy;
        taps(y, H, h, &ya, &yb, &fy);
        for (int x = 0; x < W; x++) {
            int xa, xb;
            double fx;
            taps(x, W, w, &xa, &xb, &fx);
            const float *p00 = src->rgb + ((size_t)ya * w + xa) * 3u, *p01 = src->rgb + ((size_t)ya * w + xb) * 3u;
            const float *p10 = src->rgb + ((size_t)yb * w + xa) * 3u, *p11 = src->rgb + ((size_t)yb * w + xb) * 3u;
            float *o = dst->rgb + ((size_t)y * W + x) * 3u;
            for (int c = 0; c < 3; c++)
                o[c] = (float)((p00[c] * (1 - fx) + p01[c] * fx) * (1 - fy) + (p10[c] * (1 - fx) + p11[c] * fx) * fy);
        }
    }
}
