/* sdl_df3.c - density_file df3 reader (see sdl_df3.h). Sizes are read as
 * POV-Ray reads them; a file whose length is not 6 + n * {1, 2, 4} for
 * n = nx*ny*nz is refused ("Invalid density file size" in POV-Ray). */
#include "sdl_df3.h"
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#define DF3_MAX_SAMPLES (256u * 1024u * 1024u) /* refuse more than 2 GiB of doubles */

int sdl_df3_load(scene_density *d, const char *path, arena *mem, char *why, size_t whycap)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(why, whycap, "cannot open density file '%s'", path);
        return -1;
    }
    unsigned char h[6];
    long len = -1;
    if (fread(h, 1, 6, f) == 6 && fseek(f, 0, SEEK_END) == 0) len = ftell(f) - 6;
    if (len < 0 || fseek(f, 6, SEEK_SET) != 0) {
        fclose(f);
        snprintf(why, whycap, "cannot read density file '%s'", path);
        return -1;
    }
    size_t nx = (size_t)(h[0] << 8 | h[1]), ny = (size_t)(h[2] << 8 | h[3]), nz = (size_t)(h[4] << 8 | h[5]);
    size_t n = nx * ny * nz; /* at most 2^48: no overflow */
    size_t width = 0;
    if (n > 0 && n <= DF3_MAX_SAMPLES) {
        if ((size_t)len == n * 4) width = 4;
        else if ((size_t)len == n * 2) width = 2;
        else if ((size_t)len == n) width = 1;
    }
    if (!width) {
        fclose(f);
        snprintf(why, whycap, "invalid density file size in '%s' (%zux%zux%zu samples, %ld bytes of data)", path, nx, ny, nz, len);
        return -1;
    }
    unsigned char *raw = malloc(n * width);
    double *v = arena_alloc(mem, n * sizeof *v);
    if (!raw || !v) {
        free(raw);
        fclose(f);
        snprintf(why, whycap, "out of memory reading density file '%s'", path);
        return -1;
    }
    size_t got = fread(raw, 1, n * width, f);
    fclose(f);
    if (got != n * width) {
        free(raw);
        snprintf(why, whycap, "cannot read density file '%s'", path);
        return -1;
    }
    /* POV-Ray divides by UCHAR_MAX, USHRT_MAX or UINT_MAX */
    for (size_t i = 0; i < n; i++) {
        const unsigned char *b = raw + i * width;
        if (width == 1) {
            v[i] = b[0] / 255.0;
        } else if (width == 2) {
            v[i] = (double)(b[0] << 8 | b[1]) / 65535.0;
        } else {
            uint32_t u = (uint32_t)b[0] << 24 | (uint32_t)b[1] << 16 | (uint32_t)b[2] << 8 | b[3];
            v[i] = (double)u / 4294967295.0;
        }
    }
    free(raw);
    d->path = path;
    d->nx = (int)nx;
    d->ny = (int)ny;
    d->nz = (int)nz;
    d->v = v;
    return 0;
}
