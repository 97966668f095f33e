/* framebuffer.c - float RGB image. */
#include "framebuffer.h"
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
