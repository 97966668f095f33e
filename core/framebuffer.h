/* framebuffer.h - float RGB image, scene-linear. */
#ifndef PT_FRAMEBUFFER_H
#define PT_FRAMEBUFFER_H
#include <stddef.h>

typedef struct {
    int width, height;
    float *rgb;       /* width*height*3, row 0 at the top */
    float *alpha;     /* optional, may be NULL */
} framebuffer;

framebuffer *fb_new(int width, int height);
void fb_free(framebuffer *fb);
static inline float *fb_px(framebuffer *fb, int x, int y) { return fb->rgb + ((size_t)y * (size_t)fb->width + (size_t)x) * 3u; }
/* Replace NaN/Inf by 0; returns how many values were fixed. Negative values
 * (POV-Ray allows negative lights) are kept. */
long fb_sanitize(framebuffer *fb);
double fb_mean(const framebuffer *fb, int channel); /* channel -1 = mean of rgb */
/* src's rgb resampled into dst (its own size) by bilinear interpolation,
 * pixel centres aligned and edge pixels held; a copy when the sizes
 * agree. Alpha is not touched. */
void fb_resample_bilinear(const framebuffer *src, framebuffer *dst);

#endif
