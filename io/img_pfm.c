/* img_pfm.c - Portable Float Map reading and writing.
 *
 * Format (as described by its author, Paul Debevec, and used by HDRShop and
 * netpbm's pfmtopam): a text header "PF" (3 channels) or "Pf" (1 channel),
 * whitespace, width, whitespace, height, whitespace, a scale factor whose
 * sign gives the byte order (negative = little-endian), then exactly one
 * whitespace character, then binary 32-bit IEEE floats, rows ordered from
 * the BOTTOM of the image to the top, pixels left to right. */
#include "img_pfm.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Write all of buf; 0 on success, errno value on failure. */
static int write_all(int fd, const void *buf, size_t n)
{
    const unsigned char *p = buf;
    while (n > 0) {
        ssize_t w = write(fd, p, n);
        if (w < 0) {
            if (errno == EINTR) continue;
            return errno;
        }
        if (w == 0) return EIO;
        p += w;
        n -= (size_t)w;
    }
    return 0;
}

static void put_le32(unsigned char *p, float v)
{
    uint32_t u;
    memcpy(&u, &v, 4);
    p[0] = (unsigned char)(u & 0xffu);
    p[1] = (unsigned char)((u >> 8) & 0xffu);
    p[2] = (unsigned char)((u >> 16) & 0xffu);
    p[3] = (unsigned char)((u >> 24) & 0xffu);
}

static float get32(const unsigned char *p, int little)
{
    uint32_t u;
    if (little)
        u = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
    else
        u = (uint32_t)p[3] | (uint32_t)p[2] << 8 | (uint32_t)p[1] << 16 | (uint32_t)p[0] << 24;
    float v;
    memcpy(&v, &u, 4);
    return v;
}

pt_status img_pfm_write(int fd, const char *name, const framebuffer *fb, diag *d)
{
    char header[64];
    int hn = snprintf(header, sizeof header, "PF\n%d %d\n-1.0\n", fb->width, fb->height);
    int err = write_all(fd, header, (size_t)hn);
    if (err) {
        diag_error(d, "cannot write '%s': %s", name, strerror(err));
        return PT_ERR_IO;
    }
    size_t rowbytes = (size_t)fb->width * 3u * 4u;
    unsigned char *row = malloc(rowbytes);
    if (!row) {
        diag_error(d, "cannot write '%s': out of memory", name);
        return PT_ERR_NOMEM;
    }
    for (int i = 0; i < fb->height && !err; i++) {
        int y = fb->height - 1 - i; /* bottom row first */
        const float *src = fb->rgb + (size_t)y * (size_t)fb->width * 3u;
        for (size_t k = 0; k < (size_t)fb->width * 3u; k++) {
            float v = src[k];
            put_le32(row + k * 4u, isfinite(v) ? v : 0.0f);
        }
        err = write_all(fd, row, rowbytes);
    }
    free(row);
    if (err) {
        diag_error(d, "cannot write '%s': %s", name, strerror(err));
        return PT_ERR_IO;
    }
    return PT_OK;
}

static int is_space(int c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

/* Skip whitespace, read one token into buf; *term gets the character that
 * ended it (EOF or one whitespace character, consumed). 0 on success. */
static int read_token(FILE *f, char *buf, size_t cap, int *term)
{
    int c;
    do c = getc(f); while (c != EOF && is_space(c));
    size_t n = 0;
    while (c != EOF && !is_space(c)) {
        if (n + 1 >= cap) return -1;
        buf[n++] = (char)c;
        c = getc(f);
    }
    buf[n] = '\0';
    *term = c;
    return n > 0 ? 0 : -1;
}

static int parse_dim(const char *s, int *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || *end || end == s) return -1;
    if (v <= 0 || v > 0x7fffffffL) return -1;
    *out = (int)v;
    return 0;
}

pt_status img_pfm_read(const char *path, uint64_t max_pixels, framebuffer **out, diag *d)
{
    *out = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) {
        diag_error(d, "cannot read '%s': %s", path, strerror(errno));
        return PT_ERR_IO;
    }
    pt_status st = PT_ERR_IO;
    unsigned char *row = NULL;
    framebuffer *fb = NULL;
    char tok[64];
    int term, w = 0, h = 0, ch;
    double scale;

    int c0 = getc(f), c1 = getc(f), c2 = getc(f);
    if (c0 != 'P' || (c1 != 'F' && c1 != 'f') || c2 == EOF || !is_space(c2)) {
        diag_error(d, "cannot read '%s': not a PFM file (bad magic)", path);
        goto done;
    }
    ch = c1 == 'F' ? 3 : 1;
    if (read_token(f, tok, sizeof tok, &term) || parse_dim(tok, &w) || term == EOF ||
        read_token(f, tok, sizeof tok, &term) || parse_dim(tok, &h) || term == EOF) {
        diag_error(d, "cannot read '%s': bad PFM header (width/height)", path);
        goto done;
    }
    if (read_token(f, tok, sizeof tok, &term) || term == EOF) {
        diag_error(d, "cannot read '%s': bad PFM header (scale)", path);
        goto done;
    }
    {
        char *end;
        scale = strtod(tok, &end);
        if (*end || end == tok || !isfinite(scale) || scale == 0.0) {
            diag_error(d, "cannot read '%s': bad PFM scale '%s'", path, tok);
            goto done;
        }
    }
    char why[256];
    if (imgcheck_size((uint64_t)w, (uint64_t)h, max_pixels, why, sizeof why)) {
        diag_error(d, "cannot read '%s': %s", path, why);
        goto done;
    }
    /* A header may claim far more pixels than the file holds: check the
     * data is there before allocating for it. */
    {
        struct stat sb;
        long at = ftell(f);
        uint64_t need = (uint64_t)w * (uint64_t)h * (uint64_t)ch * 4u;
        if (at >= 0 && fstat(fileno(f), &sb) == 0 && S_ISREG(sb.st_mode) && (uint64_t)(sb.st_size - at) < need) {
            diag_error(d, "cannot read '%s': truncated PFM file (%dx%d needs %llu bytes of pixels, %lld present)", path, w,
                       h, (unsigned long long)need, (long long)(sb.st_size - at));
            goto done;
        }
    }
    fb = fb_new(w, h);
    size_t rowbytes = (size_t)w * (size_t)ch * 4u;
    row = malloc(rowbytes);
    if (!fb || !row) {
        diag_error(d, "cannot read '%s': out of memory for %dx%d image", path, w, h);
        st = PT_ERR_NOMEM;
        goto done;
    }
    int little = scale < 0.0;
    for (int i = 0; i < h; i++) {
        if (fread(row, 1, rowbytes, f) != rowbytes) {
            if (ferror(f))
                diag_error(d, "cannot read '%s': %s", path, strerror(errno));
            else
                diag_error(d, "cannot read '%s': truncated PFM file (%d of %d rows present)", path, i, h);
            goto done;
        }
        float *dst = fb_px(fb, 0, h - 1 - i); /* file rows run bottom to top */
        for (int x = 0; x < w; x++) {
            if (ch == 3) {
                for (int k = 0; k < 3; k++) dst[x * 3 + k] = get32(row + ((size_t)x * 3u + (size_t)k) * 4u, little);
            } else {
                float v = get32(row + (size_t)x * 4u, little);
                dst[x * 3] = dst[x * 3 + 1] = dst[x * 3 + 2] = v;
            }
        }
    }
    st = PT_OK;
    *out = fb;
    fb = NULL;
done:
    free(row);
    fb_free(fb);
    fclose(f);
    return st;
}
