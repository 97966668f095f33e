/* shade_gamma.c - working gamma (see shade_gamma.h). POV-Ray 3.7 (parse.cpp,
 * imageprocessing.cpp): with assumed_gamma G an output pixel is the file's
 * encoding of decode_G(v) = v^G; a pre-3.7 scene without assumed_gamma runs
 * with gamma handling off (values written as computed). */
#include "shade_gamma.h"
#include <math.h>
#include "pool.h"

/* assumed_gamma when given; 1 for #version 3.7 scenes without it; 0 for
 * older scenes without it (POV-Ray then turns gamma handling off: computed
 * values are written to the file as they are). */
static double gamma_working(const scene *sc)
{
    if (sc->global.assumed_gamma > 0.0) return sc->global.assumed_gamma;
    double v = sc->version_major > 0 ? sc->version_major + sc->version_minor / 10.0 : 3.7;
    return v < 3.65 ? 0.0 : 1.0;
}

static float srgb_decode(float v)
{
    if (v <= 0.0f) return v;
    return v <= 0.04045f ? v / 12.92f : (float)pow((v + 0.055) / 1.055, 2.4);
}

double shade_gamma_aa_value(const scene *sc, double v)
{
    if (!(v > 0.0)) return 0.0;
    /* PowerLawGammaCurve 2.5 after the working gamma's decoding: one power */
    double g = gamma_working(sc);
    return pow(v, (g > 0.0 ? g : 1.0) / 2.5);
}

typedef struct {
    framebuffer *fb;
    double g;
} to_linear_job;

static void to_linear_row(void *ctx, int y, int thread)
{
    (void)thread;
    const to_linear_job *j = ctx;
    float *row = j->fb->rgb + (size_t)y * (size_t)j->fb->width * 3;
    for (size_t i = 0; i < (size_t)j->fb->width * 3; i++) {
        float v = row[i];
        if (!isfinite(v)) continue;
        row[i] = j->g == 0.0 ? srgb_decode(v) : (v > 0.0f ? (float)pow(v, j->g) : v);
    }
}

/* A power per channel, a row per job: on one thread it was a serial tail
 * of every render with a working gamma other than 1. */
void shade_gamma_fb_to_linear(const scene *sc, framebuffer *fb, int threads)
{
    double g = gamma_working(sc);
    if (g == 1.0) return;
    to_linear_job j = {fb, g};
    pool_run(threads > 0 ? threads : pool_default_threads(), fb->height, to_linear_row, &j);
}
