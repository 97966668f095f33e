/* sdl_hfimage.c - height_field image readers (sdl_hfimage.h). */
#include "sdl_hfimage.h"
#include <ctype.h>
#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define HF_MAX_SIDE 65536
#define HF_MAX_PIXELS (1ull << 28)

static int size_ok(unsigned long w, unsigned long h)
{
    return w > 0 && h > 0 && w <= HF_MAX_SIDE && h <= HF_MAX_SIDE && (unsigned long long)w * h <= HF_MAX_PIXELS;
}

static unsigned short grey16(double r, double g, double b)
{
    double v = (0.297 * r + 0.589 * g + 0.114 * b) * 65535.0;
    return (unsigned short)(v < 0 ? 0 : (v > 65535.0 ? 65535.0 : v));
}

/* ------------------------------------------------------------ PNG */

static int read_png(FILE *f, sdl_hf_image *out, char *why, size_t whycap)
{
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!png || !info) {
        png_destroy_read_struct(&png, &info, NULL);
        snprintf(why, whycap, "out of memory");
        return SDL_HF_ERROR;
    }
    unsigned char *buf = NULL;
    png_bytep *rows = NULL;
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_read_struct(&png, &info, NULL);
        free(buf);
        free(rows);
        free(out->values);
        out->values = NULL;
        snprintf(why, whycap, "corrupt PNG file");
        return SDL_HF_ERROR;
    }
    png_init_io(png, f);
    png_read_info(png, info);
    png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
    int depth = png_get_bit_depth(png, info), ct = png_get_color_type(png, info);
    if (!size_ok(w, h)) {
        png_destroy_read_struct(&png, &info, NULL);
        snprintf(why, whycap, "image size %lux%lu out of range", (unsigned long)w, (unsigned long)h);
        return SDL_HF_ERROR;
    }
    /* keep palette indices and 16-bit samples; unpack 1/2/4-bit pixels */
    if (depth < 8) png_set_packing(png);
    if (ct == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
    if (depth == 16) png_set_swap(png); /* host order (little endian assumed below via memcpy) */
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
    size_t rb = png_get_rowbytes(png, info);
    int ch = png_get_channels(png, info);
    buf = malloc(rb * h);
    rows = malloc(sizeof *rows * h);
    out->values = malloc(sizeof *out->values * (size_t)w * h);
    if (!buf || !rows || !out->values) {
        png_destroy_read_struct(&png, &info, NULL);
        free(buf);
        free(rows);
        free(out->values);
        out->values = NULL;
        snprintf(why, whycap, "out of memory");
        return SDL_HF_ERROR;
    }
    for (png_uint_32 y = 0; y < h; y++) rows[y] = buf + rb * y;
    png_read_image(png, rows);
    png_read_end(png, NULL);
    int d16 = depth == 16;
    for (png_uint_32 y = 0; y < h; y++) {
        const unsigned char *r = rows[y];
        for (png_uint_32 x = 0; x < w; x++) {
            unsigned s[4] = {0, 0, 0, 0};
            for (int c = 0; c < ch && c < 4; c++) {
                if (d16) {
                    unsigned short v;
                    memcpy(&v, r + ((size_t)x * ch + c) * 2, 2);
                    s[c] = v;
                } else {
                    s[c] = r[(size_t)x * ch + c];
                }
            }
            unsigned short hv;
            if (ct == PNG_COLOR_TYPE_PALETTE) hv = (unsigned short)(s[0] * 256u);
            else if (ct == PNG_COLOR_TYPE_GRAY || ct == PNG_COLOR_TYPE_GRAY_ALPHA)
                hv = d16 ? (unsigned short)s[0] : (unsigned short)(s[0] * 257u);
            else if (d16) hv = grey16(s[0] / 65535.0, s[1] / 65535.0, s[2] / 65535.0);
            else hv = (unsigned short)(s[0] * 256u + s[1]);
            out->values[(size_t)y * w + x] = hv;
        }
    }
    png_destroy_read_struct(&png, &info, NULL);
    free(buf);
    free(rows);
    out->width = (int)w;
    out->height = (int)h;
    return SDL_HF_OK;
}

/* ------------------------------------------------------------ GIF (and POT) */

/* First image of a GIF file as palette indices (LZW decoded, interlacing
 * undone). GIF89a: codes of 2..12 bits, clear and end codes, sub-blocks. */
static int read_gif(FILE *f, int pot, sdl_hf_image *out, char *why, size_t whycap)
{
    unsigned char hdr[13];
    if (fread(hdr, 1, 13, f) != 13 || memcmp(hdr, "GIF", 3) != 0) {
        snprintf(why, whycap, "not a GIF file");
        return SDL_HF_ERROR;
    }
    if (hdr[10] & 0x80) fseek(f, 3L * (1L << ((hdr[10] & 7) + 1)), SEEK_CUR); /* global palette */
    int c;
    for (;;) {
        c = fgetc(f);
        if (c == 0x21) { /* extension: skip its sub-blocks */
            fgetc(f);
            int n;
            while ((n = fgetc(f)) > 0) fseek(f, n, SEEK_CUR);
            if (n < 0) break;
            continue;
        }
        break;
    }
    unsigned char id[9];
    if (c != 0x2C || fread(id, 1, 9, f) != 9) {
        snprintf(why, whycap, "no image in the GIF file");
        return SDL_HF_ERROR;
    }
    unsigned w = id[4] | id[5] << 8, h = id[6] | id[7] << 8;
    int interlaced = (id[8] & 0x40) != 0;
    if (id[8] & 0x80) fseek(f, 3L * (1L << ((id[8] & 7) + 1)), SEEK_CUR); /* local palette */
    int minbits = fgetc(f);
    if (!size_ok(w, h) || minbits < 2 || minbits > 11 || (pot && (w & 1))) {
        snprintf(why, whycap, "bad GIF image header");
        return SDL_HF_ERROR;
    }
    size_t npix = (size_t)w * h;
    unsigned char *idx = calloc(npix, 1);
    unsigned short *prefix = malloc(4096 * sizeof *prefix);
    unsigned char *suffix = malloc(4096), *stack = malloc(4097);
    if (!idx || !prefix || !suffix || !stack) {
        free(idx); free(prefix); free(suffix); free(stack);
        snprintf(why, whycap, "out of memory");
        return SDL_HF_ERROR;
    }
    int clear = 1 << minbits, end = clear + 1, next = end + 1, bits = minbits + 1, old = -1;
    unsigned char first = 0;
    unsigned long acc = 0;
    int nacc = 0, blk = 0;
    size_t pos = 0;
    for (int i = 0; i < clear; i++) { prefix[i] = 0xFFFF; suffix[i] = (unsigned char)i; }
    while (pos < npix) {
        while (nacc < bits) {
            if (blk == 0) {
                blk = fgetc(f);
                if (blk <= 0) goto done;
            }
            int byte = fgetc(f);
            if (byte < 0) goto done;
            blk--;
            acc |= (unsigned long)byte << nacc;
            nacc += 8;
        }
        int code = (int)(acc & ((1UL << bits) - 1));
        acc >>= bits;
        nacc -= bits;
        if (code == clear) {
            next = end + 1;
            bits = minbits + 1;
            old = -1;
            continue;
        }
        if (code == end) break;
        int sp = 0, cur = code;
        if (old < 0) {
            if (code >= clear) break;
            first = (unsigned char)code;
            idx[pos++] = first;
            old = code;
            continue;
        }
        if (code >= next) { /* the KwKwK case */
            if (code > next) break;
            stack[sp++] = first;
            cur = old;
        }
        while (cur >= clear && sp < 4096) {
            stack[sp++] = suffix[cur];
            cur = prefix[cur];
        }
        if (cur >= clear) break;
        first = (unsigned char)cur;
        stack[sp++] = first;
        while (sp > 0 && pos < npix) idx[pos++] = stack[--sp];
        if (next < 4096) {
            prefix[next] = (unsigned short)old;
            suffix[next] = first;
            next++;
            if (next == (1 << bits) && bits < 12) bits++;
        }
        old = code;
    }
done:
    free(prefix);
    free(suffix);
    free(stack);
    if (pos < npix) {
        free(idx);
        snprintf(why, whycap, "GIF image data ends early");
        return SDL_HF_ERROR;
    }
    /* row order (interlaced: passes of every 8th from 0, 8th from 4, 4th from 2, 2nd from 1) */
    unsigned *row = malloc(sizeof *row * h);
    if (!row) { free(idx); snprintf(why, whycap, "out of memory"); return SDL_HF_ERROR; }
    if (interlaced) {
        static const unsigned start[4] = {0, 4, 2, 1}, step[4] = {8, 8, 4, 2};
        unsigned r = 0;
        for (int pass = 0; pass < 4; pass++)
            for (unsigned y = start[pass]; y < h; y += step[pass]) row[r++] = y;
    } else {
        for (unsigned y = 0; y < h; y++) row[y] = y;
    }
    unsigned ow = pot ? w / 2 : w;
    out->values = malloc(sizeof *out->values * (size_t)ow * h);
    if (!out->values) { free(idx); free(row); snprintf(why, whycap, "out of memory"); return SDL_HF_ERROR; }
    for (unsigned r = 0; r < h; r++) {
        const unsigned char *src = idx + (size_t)r * w;
        unsigned short *dst = out->values + (size_t)row[r] * ow;
        for (unsigned x = 0; x < ow; x++)
            dst[x] = pot ? (unsigned short)(src[x] << 8 | src[x + ow]) : (unsigned short)(src[x] * 256u);
    }
    free(idx);
    free(row);
    out->width = (int)ow;
    out->height = (int)h;
    return SDL_HF_OK;
}

/* ------------------------------------------------------------ PNM */

static int pnm_int(FILE *f, long *v)
{
    int c;
    for (;;) {
        c = fgetc(f);
        if (c == '#') {
            while (c != '\n' && c != EOF) c = fgetc(f);
            continue;
        }
        if (c == EOF) return 0;
        if (!isspace(c)) break;
    }
    long n = 0;
    if (!isdigit(c)) return 0;
    while (isdigit(c)) {
        n = n * 10 + (c - '0');
        if (n > 1L << 30) return 0;
        c = fgetc(f);
    }
    *v = n;
    return 1;
}

static int read_pnm(FILE *f, int kind, sdl_hf_image *out, char *why, size_t whycap)
{
    long w, h, maxv;
    if (!pnm_int(f, &w) || !pnm_int(f, &h) || !pnm_int(f, &maxv) || maxv <= 0 || maxv > 65535 || !size_ok((unsigned long)w, (unsigned long)h)) {
        snprintf(why, whycap, "bad PGM/PPM header");
        return SDL_HF_ERROR;
    }
    int colour = kind == 3 || kind == 6, binary = kind >= 5, wide = maxv > 255, ch = colour ? 3 : 1;
    out->values = malloc(sizeof *out->values * (size_t)w * (size_t)h);
    if (!out->values) {
        snprintf(why, whycap, "out of memory");
        return SDL_HF_ERROR;
    }
    for (long i = 0; i < w * h; i++) {
        long s[3] = {0, 0, 0};
        for (int c = 0; c < ch; c++) {
            if (binary) {
                int a = fgetc(f), b = wide ? fgetc(f) : 0;
                if (a == EOF || b == EOF) goto short_file;
                s[c] = wide ? (a << 8 | b) : a;
            } else if (!pnm_int(f, &s[c])) {
                goto short_file;
            }
            if (s[c] > maxv) s[c] = maxv;
        }
        unsigned short hv;
        if (!colour) hv = (unsigned short)((double)s[0] / (double)maxv * 65535.0);
        else if (maxv > 255) hv = grey16((double)s[0] / maxv, (double)s[1] / maxv, (double)s[2] / maxv);
        else hv = (unsigned short)((double)s[0] / maxv * 255.0 * 256.0 + (double)s[1] / maxv * 255.0);
        out->values[i] = hv;
    }
    out->width = (int)w;
    out->height = (int)h;
    return SDL_HF_OK;
short_file:
    free(out->values);
    out->values = NULL;
    snprintf(why, whycap, "PGM/PPM file ends early");
    return SDL_HF_ERROR;
}

int sdl_hf_read(const char *path, sdl_hf_image *out, char *why, size_t whycap)
{
    memset(out, 0, sizeof *out);
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(why, whycap, "cannot be opened");
        return SDL_HF_ERROR;
    }
    unsigned char sig[8] = {0};
    size_t n = fread(sig, 1, 8, f);
    int r;
    if (n == 8 && !png_sig_cmp(sig, 0, 8)) {
        rewind(f);
        r = read_png(f, out, why, whycap);
    } else if (n >= 6 && memcmp(sig, "GIF8", 4) == 0) {
        /* POT (Fractint continuous potential): a GIF whose right half holds
         * each pixel's low byte (POV-Ray's gif.cpp) */
        size_t len = strlen(path);
        int pot = len > 4 && (strcmp(path + len - 4, ".pot") == 0 || strcmp(path + len - 4, ".POT") == 0);
        rewind(f);
        r = read_gif(f, pot, out, why, whycap);
    } else if (n >= 2 && sig[0] == 'P' && sig[1] >= '2' && sig[1] <= '6' && sig[1] != '4') {
        fseek(f, 2, SEEK_SET);
        r = read_pnm(f, sig[1] - '0', out, why, whycap);
    } else {
        snprintf(why, whycap, "image format not supported for height fields (PNG, GIF, POT, PGM and PPM are)");
        r = SDL_HF_UNSUPPORTED;
    }
    fclose(f);
    return r;
}
