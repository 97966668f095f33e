/* imgcheck.c - image size checks before allocation (imgcheck.h). */
#include "imgcheck.h"
#include <string.h>

/* Deflate's largest expansion: 258 bytes from one length/distance pair that
 * takes at least 2 bits with fixed or dynamic codes (RFC 1951, 3.2.5), i.e.
 * 1032:1; a zlib stream adds 6 bytes and a few block headers. */
#define DEFLATE_MAX_RATIO 1032u

int imgcheck_size(uint64_t w, uint64_t h, uint64_t max_pixels, char *why, size_t whycap)
{
    if (max_pixels == 0 || max_pixels > IMGCHECK_MAX_PIXELS) max_pixels = IMGCHECK_MAX_PIXELS;
    if (w == 0 || h == 0) {
        snprintf(why, whycap, "image size %llux%llu is empty", (unsigned long long)w, (unsigned long long)h);
        return 1;
    }
    if (w > IMGCHECK_MAX_SIDE || h > IMGCHECK_MAX_SIDE || w * h > max_pixels) {
        snprintf(why, whycap, "image size %llux%llu exceeds the limit (%d per side, %llu pixels in all)",
                 (unsigned long long)w, (unsigned long long)h, IMGCHECK_MAX_SIDE, (unsigned long long)max_pixels);
        return 1;
    }
    return 0;
}

static uint32_t be32(const unsigned char *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

static int png_walk(FILE *f, uint64_t max_pixels, char *why, size_t whycap)
{
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    unsigned char b[8];
    if (fseek(f, 0, SEEK_SET) != 0 || fseek(f, 0, SEEK_END) != 0) {
        snprintf(why, whycap, "the file cannot be seeked");
        return 1;
    }
    long end = ftell(f);
    if (end < 0 || fseek(f, 0, SEEK_SET) != 0) {
        snprintf(why, whycap, "the file cannot be seeked");
        return 1;
    }
    if (fread(b, 1, 8, f) != 8 || memcmp(b, sig, 8) != 0) {
        snprintf(why, whycap, "not a PNG file");
        return 1;
    }
    uint64_t pos = 8, idat = 0, w = 0, h = 0, bits_pp = 0;
    int n = 0;
    for (;; n++) {
        if (pos + 8 > (uint64_t)end) {
            snprintf(why, whycap, "the file is truncated: it ends at byte %ld without an IEND chunk", end);
            return 1;
        }
        if (fseek(f, (long)pos, SEEK_SET) != 0 || fread(b, 1, 8, f) != 8) {
            snprintf(why, whycap, "the file cannot be read at byte %llu", (unsigned long long)pos);
            return 1;
        }
        uint32_t len = be32(b);
        char type[5] = {(char)b[4], (char)b[5], (char)b[6], (char)b[7], 0};
        for (int i = 0; i < 4; i++)
            if (!((type[i] >= 'A' && type[i] <= 'Z') || (type[i] >= 'a' && type[i] <= 'z'))) {
                snprintf(why, whycap, "corrupt chunk type at byte %llu", (unsigned long long)pos);
                return 1;
            }
        if (len > 0x7fffffffu) { /* PNG spec 5.3: lengths are at most 2^31 - 1 */
            snprintf(why, whycap, "chunk '%s' at byte %llu declares an invalid length %lu", type, (unsigned long long)pos,
                     (unsigned long)len);
            return 1;
        }
        if (pos + 12 + len > (uint64_t)end) {
            snprintf(why, whycap, "the file is truncated: chunk '%s' at byte %llu declares %lu bytes, %llu remain", type,
                     (unsigned long long)pos, (unsigned long)len, (unsigned long long)((uint64_t)end - pos - 8));
            return 1;
        }
        if (n == 0) {
            unsigned char ih[13];
            if (strcmp(type, "IHDR") != 0 || len != 13 || fread(ih, 1, 13, f) != 13) {
                snprintf(why, whycap, "the first chunk is not a valid IHDR");
                return 1;
            }
            w = be32(ih);
            h = be32(ih + 4);
            unsigned depth = ih[8], ct = ih[9];
            unsigned ch = ct == 0 ? 1 : ct == 2 ? 3 : ct == 3 ? 1 : ct == 4 ? 2 : ct == 6 ? 4 : 0;
            if (ch == 0 || !(depth == 1 || depth == 2 || depth == 4 || depth == 8 || depth == 16)) {
                snprintf(why, whycap, "IHDR has an invalid colour type %u or bit depth %u", ct, depth);
                return 1;
            }
            bits_pp = (uint64_t)depth * ch;
            if (imgcheck_size(w, h, max_pixels, why, whycap)) return 1;
        } else if (strcmp(type, "IDAT") == 0) {
            idat += len;
        } else if (strcmp(type, "IEND") == 0) {
            break;
        }
        pos += 12 + (uint64_t)len;
    }
    /* Unfiltered image bytes without the filter bytes: a lower bound for
     * interlaced images too (their passes hold every pixel once). */
    uint64_t need = (w * h * bits_pp) / 8;
    uint64_t most = idat * DEFLATE_MAX_RATIO + 1024;
    if (need > most) {
        snprintf(why, whycap,
                 "the file is truncated or corrupt: it declares %llux%llu pixels (%llu bytes of image data) but holds "
                 "%llu bytes of compressed image data, which inflate to at most %llu bytes",
                 (unsigned long long)w, (unsigned long long)h, (unsigned long long)need, (unsigned long long)idat,
                 (unsigned long long)most);
        return 1;
    }
    return 0;
}

int imgcheck_png(FILE *f, uint64_t max_pixels, char *why, size_t whycap)
{
    int r = png_walk(f, max_pixels, why, whycap);
    clearerr(f);
    if (fseek(f, 0, SEEK_SET) != 0 && r == 0) {
        snprintf(why, whycap, "the file cannot be seeked");
        return 1;
    }
    return r;
}
