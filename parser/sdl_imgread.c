/* sdl_imgread.c - the scene language's image reader (sdl_imgread.h).
 *
 * Every decoder reads from memory; a path is read into memory first (regular
 * files only, at most SDL_IMG_MAX_FILE bytes). Each checks the declared
 * size with size_ok before allocating pixel memory. The libraries' own
 * error paths (libpng, libjpeg: longjmp; giflib, libtiff: return codes) end
 * in one cleanup per decoder. */
#include "sdl_imgread.h"
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <gif_lib.h>
#include <jpeglib.h>
#include <png.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <tiffio.h>
#include "imgcheck.h"

typedef struct {
    const unsigned char *b;
    size_t n, pos;
    unsigned long long max_pixels; /* the caller's limit (sdl_img_read) */
} mem_src;

static int size_ok(const mem_src *m, unsigned long long w, unsigned long long h)
{
    return w > 0 && h > 0 && w <= SDL_IMG_MAX_SIDE && h <= SDL_IMG_MAX_SIDE && w * h <= m->max_pixels;
}

static int alloc_pixels(sdl_img *out, int w, int h, int indexed)
{
    out->width = w;
    out->height = h;
    out->rgba = malloc((size_t)w * (size_t)h * 4 * sizeof *out->rgba);
    if (!out->rgba) return 0;
    if (indexed) {
        out->index = malloc((size_t)w * (size_t)h);
        if (!out->index) return 0;
    }
    return 1;
}

void sdl_img_free(sdl_img *img)
{
    if (!img) return;
    free(img->rgba);
    free(img->index);
    img->rgba = NULL;
    img->index = NULL;
}

static void set_px(sdl_img *o, size_t i, unsigned r, unsigned g, unsigned b, unsigned a)
{
    unsigned short *d = o->rgba + i * 4;
    d[0] = (unsigned short)r;
    d[1] = (unsigned short)g;
    d[2] = (unsigned short)b;
    d[3] = (unsigned short)a;
}

/* ------------------------------------------------------------ PNG */

static void png_mem_read(png_structp png, png_bytep dst, size_t len)
{
    mem_src *m = png_get_io_ptr(png);
    if (len > m->n - m->pos) png_error(png, "truncated");
    memcpy(dst, m->b + m->pos, len);
    m->pos += len;
}

/* libpng's own allocations (chunk data, zlib state, a row) never need much:
 * the pixels are allocated here. libpng 1.6 warns that a text chunk is too
 * large and then allocates it anyway (io/img_png.c, fuzz_image), so more
 * than 64 MiB at once is refused, which libpng reports as an error. */
static png_voidp png_lib_malloc(png_structp png, png_alloc_size_t n)
{
    (void)png;
    return n <= ((png_alloc_size_t)64 << 20) ? malloc(n) : NULL;
}

static void png_lib_free(png_structp png, png_voidp p)
{
    (void)png;
    free(p);
}

static void png_lib_warning(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg; /* nothing deep inside prints */
}

static int read_png(mem_src *m, sdl_img *out, char *why, size_t whycap)
{
    /* The chunk list first (core/imgcheck.h): a file whose image data cannot
     * inflate to its declared size, or that ends inside a chunk, is refused
     * before 8 bytes a pixel are allocated for it. */
    FILE *mf = fmemopen((void *)m->b, m->n, "rb");
    if (!mf) {
        snprintf(why, whycap, "out of memory");
        return SDL_IMG_ERROR;
    }
    int bad = imgcheck_png(mf, m->max_pixels, why, whycap);
    fclose(mf);
    if (bad) return SDL_IMG_ERROR;
    png_structp png =
        png_create_read_struct_2(PNG_LIBPNG_VER_STRING, NULL, NULL, png_lib_warning, NULL, png_lib_malloc, png_lib_free);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!png || !info) {
        png_destroy_read_struct(&png, &info, NULL);
        snprintf(why, whycap, "out of memory");
        return SDL_IMG_ERROR;
    }
    unsigned char *buf = NULL;
    /* set after setjmp and freed after a longjmp: volatile (C11 7.13.2.1p3) */
    png_bytep *volatile rows = NULL;
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_read_struct(&png, &info, NULL);
        free(rows);
        sdl_img_free(out); /* buf is out's */
        if (!why[0]) snprintf(why, whycap, "corrupt PNG file");
        return SDL_IMG_ERROR;
    }
    png_set_read_fn(png, m, png_mem_read);
    /* ancillary chunks (text, ICC) never need more than this */
    png_set_chunk_malloc_max(png, 8u << 20);
    png_read_info(png, info);
    png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
    int depth = png_get_bit_depth(png, info), ct = png_get_color_type(png, info);
    if (!size_ok(m, w, h)) {
        snprintf(why, whycap, "image size %lux%lu out of range (at most %d a side and %llu pixels, --max-image-pixels)", (unsigned long)w, (unsigned long)h, SDL_IMG_MAX_SIDE,
                 m->max_pixels);
        png_error(png, "size");
    }
    out->format = SDL_IMGF_PNG;
    out->depth16 = depth == 16;
    out->colour = ct == PNG_COLOR_TYPE_PALETTE ? SDL_IMG_PALETTE
                  : (ct & PNG_COLOR_MASK_COLOR) ? SDL_IMG_RGB : SDL_IMG_GREY;
    out->has_alpha = (ct & PNG_COLOR_MASK_ALPHA) || png_get_valid(png, info, PNG_INFO_tRNS);
    out->png_srgb = png_get_valid(png, info, PNG_INFO_sRGB) != 0;
    if (png_get_valid(png, info, PNG_INFO_gAMA)) {
        double g = 0.0;
        png_get_gAMA(png, info, &g);
        out->png_gamma = g > 0.0 ? g : 0.0;
    }
    int palette = ct == PNG_COLOR_TYPE_PALETTE;
    /* the palette is copied: libpng's own arrays die with png_destroy_read_struct */
    png_color plte[256];
    int nplte = 0;
    unsigned char trns[256];
    int ntrns = 0;
    if (palette) {
        png_colorp pp = NULL;
        png_bytep tp = NULL;
        if (png_get_PLTE(png, info, &pp, &nplte) && pp) {
            if (nplte > 256) nplte = 256;
            memcpy(plte, pp, sizeof plte[0] * (size_t)(nplte > 0 ? nplte : 0));
        } else {
            nplte = 0;
        }
        if (png_get_valid(png, info, PNG_INFO_tRNS) && png_get_tRNS(png, info, &tp, &ntrns, NULL) && tp) {
            if (ntrns > 256) ntrns = 256;
            memcpy(trns, tp, (size_t)(ntrns > 0 ? ntrns : 0));
        } else {
            ntrns = 0;
        }
        png_set_packing(png); /* one index per byte */
    } else {
        png_set_expand(png);
        png_set_expand_16(png);
        png_set_gray_to_rgb(png);
        png_set_add_alpha(png, 0xffff, PNG_FILLER_AFTER);
        png_set_swap(png);
    }
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
    size_t rb = png_get_rowbytes(png, info);
    if (rb != (palette ? (size_t)w : (size_t)w * 8)) png_error(png, "layout");
    if (!alloc_pixels(out, (int)w, (int)h, palette)) {
        snprintf(why, whycap, "out of memory");
        png_error(png, "memory");
    }
    buf = palette ? out->index : (unsigned char *)out->rgba;
    rows = malloc(sizeof *rows * h);
    if (!rows) {
        snprintf(why, whycap, "out of memory");
        png_error(png, "memory");
    }
    for (png_uint_32 y = 0; y < h; y++) rows[y] = buf + rb * y;
    png_read_image(png, rows);
    png_read_end(png, NULL);
    png_destroy_read_struct(&png, &info, NULL);
    free(rows);
    if (palette) {
        for (size_t i = 0; i < (size_t)w * h; i++) {
            int k = out->index[i];
            if (k < nplte)
                set_px(out, i, plte[k].red * 257u, plte[k].green * 257u, plte[k].blue * 257u,
                       k < ntrns ? trns[k] * 257u : 65535u);
            else
                set_px(out, i, 0, 0, 0, 65535u);
        }
    }
    return SDL_IMG_OK;
}

/* ------------------------------------------------------------ GIF */

static int gif_mem_read(GifFileType *g, GifByteType *dst, int len)
{
    mem_src *m = g->UserData;
    if (len < 0) return 0;
    size_t k = (size_t)len;
    if (k > m->n - m->pos) k = m->n - m->pos;
    memcpy(dst, m->b + m->pos, k);
    m->pos += k;
    return (int)k;
}

static int read_gif(mem_src *m, sdl_img *out, char *why, size_t whycap)
{
    int err = 0;
    GifFileType *g = DGifOpen(m, gif_mem_read, &err);
    if (!g) {
        snprintf(why, whycap, "corrupt GIF file (%s)", GifErrorString(err));
        return SDL_IMG_ERROR;
    }
    int transparent = -1, r = SDL_IMG_ERROR;
    GifByteType *line = NULL;
    snprintf(why, whycap, "GIF file holds no image");
    for (;;) {
        GifRecordType rt;
        if (DGifGetRecordType(g, &rt) == GIF_ERROR) {
            snprintf(why, whycap, "corrupt GIF file");
            break;
        }
        if (rt == TERMINATE_RECORD_TYPE) break;
        if (rt == EXTENSION_RECORD_TYPE) {
            int code;
            GifByteType *ext;
            if (DGifGetExtension(g, &code, &ext) == GIF_ERROR) {
                snprintf(why, whycap, "corrupt GIF file");
                break;
            }
            if (code == GRAPHICS_EXT_FUNC_CODE && ext && ext[0] >= 4) {
                GraphicsControlBlock gcb;
                if (DGifExtensionToGCB(ext[0], ext + 1, &gcb) == GIF_OK) transparent = gcb.TransparentColor;
            }
            while (ext) {
                if (DGifGetExtensionNext(g, &ext) == GIF_ERROR) {
                    ext = NULL;
                    break;
                }
            }
            continue;
        }
        if (rt != IMAGE_DESC_RECORD_TYPE) continue;
        if (DGifGetImageDesc(g) == GIF_ERROR) {
            snprintf(why, whycap, "corrupt GIF file");
            break;
        }
        int w = g->Image.Width, h = g->Image.Height;
        if (!size_ok(m, (unsigned long long)(w > 0 ? w : 0), (unsigned long long)(h > 0 ? h : 0))) {
            snprintf(why, whycap, "image size %dx%d out of range (at most %d a side and %llu pixels, --max-image-pixels)", w, h, SDL_IMG_MAX_SIDE,
                 m->max_pixels);
            break;
        }
        /* LZW codes have at least 3 bits and one gives at most 4096 pixels
         * (the longest string of a 12-bit table, GIF89a appendix F): a file
         * with fewer bytes left than that needs is cut short, refused before
         * 9 bytes a pixel are allocated (fuzz_sdlimage: 2 GiB for a 59-byte
         * file declaring 65535 x 4096) */
        size_t left = m->n > m->pos ? m->n - m->pos : 0;
        if ((unsigned long long)left * 8u / 3u * 4096u < (unsigned long long)w * (unsigned long long)h) {
            snprintf(why, whycap, "the file is truncated: %dx%d pixels cannot come from the %zu bytes left", w, h, left);
            break;
        }
        const ColorMapObject *cm = g->Image.ColorMap ? g->Image.ColorMap : g->SColorMap;
        if (!alloc_pixels(out, w, h, 1)) {
            snprintf(why, whycap, "out of memory");
            break;
        }
        /* interlaced images store rows in four passes */
        static const int start[4] = {0, 4, 2, 1}, step[4] = {8, 8, 4, 2};
        int ok = 1;
        if (g->Image.Interlace) {
            for (int pass = 0; pass < 4 && ok; pass++)
                for (int y = start[pass]; y < h && ok; y += step[pass])
                    ok = DGifGetLine(g, out->index + (size_t)y * w, w) == GIF_OK;
        } else {
            for (int y = 0; y < h && ok; y++) ok = DGifGetLine(g, out->index + (size_t)y * w, w) == GIF_OK;
        }
        if (!ok) {
            snprintf(why, whycap, "corrupt GIF image data");
            sdl_img_free(out);
            break;
        }
        out->format = SDL_IMGF_GIF;
        out->colour = SDL_IMG_PALETTE;
        out->has_alpha = transparent >= 0;
        for (size_t i = 0; i < (size_t)w * h; i++) {
            int k = out->index[i];
            if (cm && k < cm->ColorCount)
                set_px(out, i, cm->Colors[k].Red * 257u, cm->Colors[k].Green * 257u, cm->Colors[k].Blue * 257u,
                       k == transparent ? 0u : 65535u);
            else
                set_px(out, i, 0, 0, 0, k == transparent ? 0u : 65535u);
        }
        r = SDL_IMG_OK;
        why[0] = 0;
        break;
    }
    free(line);
    DGifCloseFile(g, &err);
    return r;
}

/* ------------------------------------------------------------ TGA */

static unsigned rd16(const unsigned char *p) { return p[0] | (unsigned)p[1] << 8; }

/* One pixel value of `bytes` bytes (little endian) into RGBA16. */
static void tga_colour(const unsigned char *p, int bits, int grey, unsigned *r, unsigned *g, unsigned *b, unsigned *a)
{
    *a = 65535u;
    if (grey) {
        *r = *g = *b = p[0] * 257u;
        if (bits == 16) *a = p[1] * 257u;
        return;
    }
    switch (bits) {
    case 15: case 16: {
        unsigned v = rd16(p);
        *r = ((v >> 10) & 31) * 65535u / 31;
        *g = ((v >> 5) & 31) * 65535u / 31;
        *b = (v & 31) * 65535u / 31;
        break;
    }
    case 24:
        *b = p[0] * 257u; *g = p[1] * 257u; *r = p[2] * 257u;
        break;
    default: /* 32 */
        *b = p[0] * 257u; *g = p[1] * 257u; *r = p[2] * 257u; *a = p[3] * 257u;
        break;
    }
}

static int read_tga(mem_src *m, sdl_img *out, char *why, size_t whycap)
{
    const unsigned char *h = m->b;
    if (m->n < 18) {
        snprintf(why, whycap, "TGA header cut short");
        return SDL_IMG_ERROR;
    }
    int idlen = h[0], cmtype = h[1], type = h[2];
    unsigned cmfirst = rd16(h + 3), cmlen = rd16(h + 5);
    int cmbits = h[7];
    unsigned w = rd16(h + 12), ht = rd16(h + 14);
    int bits = h[16], desc = h[17];
    int base = type & 7, rle = type & 8;
    if ((base != 1 && base != 2 && base != 3) || (type & ~11) != 0) {
        snprintf(why, whycap, "TGA image type %d not supported", type);
        return SDL_IMG_UNSUPPORTED;
    }
    int grey = base == 3, mapped = base == 1;
    if ((mapped && (bits != 8 || cmtype != 1 || (cmbits != 15 && cmbits != 16 && cmbits != 24 && cmbits != 32))) ||
        (grey && bits != 8 && bits != 16) ||
        (base == 2 && bits != 15 && bits != 16 && bits != 24 && bits != 32)) {
        snprintf(why, whycap, "TGA pixel format (%d bits, type %d) not supported", bits, type);
        return SDL_IMG_UNSUPPORTED;
    }
    if (!size_ok(m, w, ht)) {
        snprintf(why, whycap, "image size %ux%u out of range (at most %d a side and %llu pixels, --max-image-pixels)", w, ht, SDL_IMG_MAX_SIDE,
                 m->max_pixels);
        return SDL_IMG_ERROR;
    }
    size_t pos = 18 + (size_t)idlen;
    size_t cmbytes = cmtype == 1 ? (size_t)cmlen * (size_t)((cmbits + 7) / 8) : 0;
    const unsigned char *cmap = m->b + pos;
    if (pos + cmbytes > m->n) {
        snprintf(why, whycap, "TGA colour map cut short");
        return SDL_IMG_ERROR;
    }
    pos += cmbytes;
    int bpp = (bits + 7) / 8;
    size_t npx = (size_t)w * ht;
    /* uncompressed data must be there before anything is allocated; RLE
     * packets hold at most 128 pixels per 1 + bpp bytes */
    if ((!rle && (m->n - pos) / (size_t)bpp < npx) || (rle && (m->n - pos) / (size_t)(1 + bpp) < npx / 128)) {
        snprintf(why, whycap, "TGA pixel data cut short");
        return SDL_IMG_ERROR;
    }
    if (!alloc_pixels(out, (int)w, (int)ht, mapped)) {
        sdl_img_free(out);
        snprintf(why, whycap, "out of memory");
        return SDL_IMG_ERROR;
    }
    out->format = SDL_IMGF_TGA;
    out->colour = mapped ? SDL_IMG_PALETTE : grey ? SDL_IMG_GREY : SDL_IMG_RGB;
    out->has_alpha = (bits == 32) || (grey && bits == 16) || (mapped && cmbits == 32) || (desc & 15) != 0;
    int top = (desc >> 5) & 1, right = (desc >> 4) & 1;
    size_t i = 0;
    unsigned char px[4] = {0};
    int run = 0, raw = 0;
    while (i < npx) {
        if (rle && run == 0 && raw == 0) {
            if (pos >= m->n) break;
            int c = m->b[pos++];
            if (c & 0x80) {
                run = (c & 0x7f) + 1;
                if (pos + (size_t)bpp > m->n) break;
                memcpy(px, m->b + pos, (size_t)bpp);
                pos += (size_t)bpp;
            } else {
                raw = c + 1;
            }
        }
        if (!rle || raw) {
            if (pos + (size_t)bpp > m->n) break;
            memcpy(px, m->b + pos, (size_t)bpp);
            pos += (size_t)bpp;
            if (raw) raw--;
        } else {
            run--;
        }
        /* file order: rows bottom-up unless bit 5, columns left-right unless bit 4 */
        size_t fy = i / w, fx = i % w;
        size_t y = top ? fy : ht - 1 - fy, x = right ? w - 1 - fx : fx;
        size_t d = y * w + x;
        unsigned r, g, b, a;
        if (mapped) {
            out->index[d] = px[0];
            int k = (int)px[0] - (int)cmfirst;
            if (k >= 0 && (unsigned)k < cmlen) tga_colour(cmap + (size_t)k * ((cmbits + 7) / 8), cmbits, 0, &r, &g, &b, &a);
            else r = g = b = 0, a = 65535u;
        } else {
            tga_colour(px, bits, grey, &r, &g, &b, &a);
        }
        if (!(out->has_alpha)) a = 65535u;
        set_px(out, d, r, g, b, a);
        i++;
    }
    if (i < npx) {
        sdl_img_free(out);
        snprintf(why, whycap, "TGA pixel data cut short");
        return SDL_IMG_ERROR;
    }
    return SDL_IMG_OK;
}

/* ------------------------------------------------------------ PGM / PPM */

static int pnm_int(mem_src *m, long *v)
{
    int c = -1;
    while (m->pos < m->n) {
        c = m->b[m->pos++];
        if (c == '#') {
            while (m->pos < m->n && m->b[m->pos] != '\n') m->pos++;
            c = -1;
            continue;
        }
        if (c != ' ' && c != '\t' && c != '\n' && c != '\r' && c != '\v' && c != '\f') break;
        c = -1;
    }
    if (c < '0' || c > '9') return 0;
    long n = 0;
    for (;;) {
        n = n * 10 + (c - '0');
        if (n > 1L << 30) return 0;
        if (m->pos >= m->n || m->b[m->pos] < '0' || m->b[m->pos] > '9') break;
        c = m->b[m->pos++];
    }
    *v = n;
    return 1;
}

static int read_pnm(mem_src *m, int kind, sdl_img *out, char *why, size_t whycap)
{
    long w, h, maxv;
    m->pos = 2;
    if (!pnm_int(m, &w) || !pnm_int(m, &h) || !pnm_int(m, &maxv) || maxv <= 0 || maxv > 65535) {
        snprintf(why, whycap, "bad PGM/PPM header");
        return SDL_IMG_ERROR;
    }
    if (!size_ok(m, (unsigned long long)w, (unsigned long long)h)) {
        snprintf(why, whycap, "image size %ldx%ld out of range (at most %d a side and %llu pixels, --max-image-pixels)", w, h, SDL_IMG_MAX_SIDE,
                 m->max_pixels);
        return SDL_IMG_ERROR;
    }
    int colour = kind == 3 || kind == 6, binary = kind >= 5, wide = maxv > 255, ch = colour ? 3 : 1;
    size_t need = (size_t)w * (size_t)h * (size_t)ch;
    if (binary) m->pos++; /* the single whitespace after maxval */
    size_t left = m->n > m->pos ? m->n - m->pos : 0;
    /* binary: every sample's bytes; ASCII: at least a digit and a separator per sample */
    if ((binary && left / (size_t)(wide ? 2 : 1) < need) || (!binary && left / 2 + 1 < need)) {
        snprintf(why, whycap, "PGM/PPM file ends early");
        return SDL_IMG_ERROR;
    }
    if (!alloc_pixels(out, (int)w, (int)h, 0)) {
        sdl_img_free(out);
        snprintf(why, whycap, "out of memory");
        return SDL_IMG_ERROR;
    }
    out->format = SDL_IMGF_PNM;
    out->colour = colour ? SDL_IMG_RGB : SDL_IMG_GREY;
    out->depth16 = wide;
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
        long s[3] = {0, 0, 0};
        for (int c = 0; c < ch; c++) {
            if (binary) {
                if (m->pos + (size_t)(wide ? 2 : 1) > m->n) goto short_file;
                s[c] = wide ? (m->b[m->pos] << 8 | m->b[m->pos + 1]) : m->b[m->pos];
                m->pos += wide ? 2 : 1;
            } else if (!pnm_int(m, &s[c])) {
                goto short_file;
            }
            if (s[c] > maxv) s[c] = maxv;
            s[c] = (long)((double)s[c] * 65535.0 / (double)maxv + 0.5);
        }
        if (colour) set_px(out, i, (unsigned)s[0], (unsigned)s[1], (unsigned)s[2], 65535u);
        else set_px(out, i, (unsigned)s[0], (unsigned)s[0], (unsigned)s[0], 65535u);
    }
    return SDL_IMG_OK;
short_file:
    sdl_img_free(out);
    snprintf(why, whycap, "PGM/PPM file ends early");
    return SDL_IMG_ERROR;
}

/* ------------------------------------------------------------ JPEG */

typedef struct {
    struct jpeg_error_mgr pub;
    jmp_buf jb;
    char msg[JMSG_LENGTH_MAX];
} jpeg_err;

static void jpeg_fail(j_common_ptr c)
{
    jpeg_err *e = (jpeg_err *)c->err;
    e->pub.format_message(c, e->msg);
    longjmp(e->jb, 1);
}

static void jpeg_quiet(j_common_ptr c, int level) { (void)c; (void)level; }

static int read_jpeg(mem_src *m, sdl_img *out, char *why, size_t whycap)
{
    struct jpeg_decompress_struct ci;
    jpeg_err je;
    memset(&ci, 0, sizeof ci);
    ci.err = jpeg_std_error(&je.pub);
    je.pub.error_exit = jpeg_fail;
    je.pub.emit_message = jpeg_quiet;
    je.msg[0] = 0;
    unsigned char *volatile row = NULL; /* freed after a longjmp: volatile */
    if (setjmp(je.jb)) {
        jpeg_destroy_decompress(&ci);
        free(row);
        sdl_img_free(out);
        if (!why[0]) snprintf(why, whycap, "corrupt JPEG file (%s)", je.msg);
        return SDL_IMG_ERROR;
    }
    jpeg_create_decompress(&ci);
    /* bound what the library may allocate for itself (progressive files
     * keep all coefficients: 2 bytes per sample) */
    ci.mem->max_memory_to_use = 1L << 30;
    jpeg_mem_src(&ci, m->b, (unsigned long)m->n);
    jpeg_read_header(&ci, TRUE);
    if (!size_ok(m, ci.image_width, ci.image_height)) {
        snprintf(why, whycap, "image size %ux%u out of range (at most %d a side and %llu pixels, --max-image-pixels)", (unsigned)ci.image_width, (unsigned)ci.image_height, SDL_IMG_MAX_SIDE,
                 m->max_pixels);
        jpeg_fail((j_common_ptr)&ci);
    }
    int grey = ci.num_components == 1;
    if (ci.num_components != 1 && ci.num_components != 3) {
        jpeg_destroy_decompress(&ci);
        snprintf(why, whycap, "JPEG with %d components (CMYK) not supported", ci.num_components);
        return SDL_IMG_UNSUPPORTED;
    }
    ci.out_color_space = grey ? JCS_GRAYSCALE : JCS_RGB;
    jpeg_start_decompress(&ci);
    int w = (int)ci.output_width, h = (int)ci.output_height, nc = ci.output_components;
    row = malloc((size_t)w * (size_t)nc);
    if (!row || !alloc_pixels(out, w, h, 0)) {
        snprintf(why, whycap, "out of memory");
        jpeg_fail((j_common_ptr)&ci);
    }
    out->format = SDL_IMGF_JPEG;
    out->colour = grey ? SDL_IMG_GREY : SDL_IMG_RGB;
    while (ci.output_scanline < ci.output_height) {
        size_t y = ci.output_scanline;
        JSAMPROW rp = row;
        jpeg_read_scanlines(&ci, &rp, 1);
        for (int x = 0; x < w; x++) {
            const unsigned char *s = row + (size_t)x * nc;
            if (grey) set_px(out, y * w + x, s[0] * 257u, s[0] * 257u, s[0] * 257u, 65535u);
            else set_px(out, y * w + x, s[0] * 257u, s[1] * 257u, s[2] * 257u, 65535u);
        }
    }
    jpeg_finish_decompress(&ci);
    jpeg_destroy_decompress(&ci);
    free(row);
    return SDL_IMG_OK;
}

/* ------------------------------------------------------------ TIFF */

static tmsize_t tif_read(thandle_t h, void *buf, tmsize_t len)
{
    mem_src *m = (mem_src *)h;
    if (len < 0) return 0;
    size_t k = (size_t)len;
    if (m->pos > m->n) return 0;
    if (k > m->n - m->pos) k = m->n - m->pos;
    memcpy(buf, m->b + m->pos, k);
    m->pos += k;
    return (tmsize_t)k;
}
static tmsize_t tif_write(thandle_t h, void *buf, tmsize_t len) { (void)h; (void)buf; (void)len; return 0; }
static toff_t tif_seek(thandle_t h, toff_t off, int whence)
{
    mem_src *m = (mem_src *)h;
    uint64_t base = whence == SEEK_SET ? 0 : whence == SEEK_CUR ? m->pos : m->n;
    uint64_t np = base + off;
    if (np > m->n) np = m->n; /* reads past the end return nothing */
    m->pos = (size_t)np;
    return np;
}
static int tif_close(thandle_t h) { (void)h; return 0; }
static toff_t tif_size(thandle_t h) { return ((mem_src *)h)->n; }
static int tif_map(thandle_t h, void **base, toff_t *size) { (void)h; (void)base; (void)size; return 0; }
static void tif_unmap(thandle_t h, void *base, toff_t size) { (void)h; (void)base; (void)size; }

static int read_tiff(mem_src *m, sdl_img *out, char *why, size_t whycap)
{
    /* libtiff reports through global handlers: silence them (errors come back as return codes) */
    TIFFSetErrorHandler(NULL);
    TIFFSetWarningHandler(NULL);
    m->pos = 0;
    TIFF *t = TIFFClientOpen("image", "rm", (thandle_t)m, tif_read, tif_write, tif_seek, tif_close, tif_size, tif_map,
                             tif_unmap);
    if (!t) {
        snprintf(why, whycap, "corrupt TIFF file");
        return SDL_IMG_ERROR;
    }
    uint32_t w = 0, h = 0;
    uint16_t bits = 1, spp = 1, photo = PHOTOMETRIC_MINISBLACK, planar = PLANARCONFIG_CONTIG, extra = 0;
    uint16_t *extra_types = NULL;
    TIFFGetField(t, TIFFTAG_IMAGEWIDTH, &w);
    TIFFGetField(t, TIFFTAG_IMAGELENGTH, &h);
    TIFFGetFieldDefaulted(t, TIFFTAG_BITSPERSAMPLE, &bits);
    TIFFGetFieldDefaulted(t, TIFFTAG_SAMPLESPERPIXEL, &spp);
    TIFFGetFieldDefaulted(t, TIFFTAG_PLANARCONFIG, &planar);
    TIFFGetFieldDefaulted(t, TIFFTAG_EXTRASAMPLES, &extra, &extra_types);
    if (!TIFFGetField(t, TIFFTAG_PHOTOMETRIC, &photo)) photo = spp >= 3 ? PHOTOMETRIC_RGB : PHOTOMETRIC_MINISBLACK;
    if (!size_ok(m, w, h)) {
        TIFFClose(t);
        snprintf(why, whycap, "image size %ux%u out of range (at most %d a side and %llu pixels, --max-image-pixels)", (unsigned)w, (unsigned)h, SDL_IMG_MAX_SIDE,
                 m->max_pixels);
        return SDL_IMG_ERROR;
    }
    int r = SDL_IMG_ERROR;
    unsigned char *line = NULL;
    uint32_t *raster = NULL;
    int grey = photo == PHOTOMETRIC_MINISBLACK || photo == PHOTOMETRIC_MINISWHITE;
    if (grey && bits == 16 && spp == 1 && !TIFFIsTiled(t)) {
        /* 16-bit grey (elevation data): keep all bits, one scanline at a time */
        tmsize_t sl = TIFFScanlineSize(t);
        if (sl < (tmsize_t)w * 2 || !alloc_pixels(out, (int)w, (int)h, 0) || !(line = malloc((size_t)sl))) {
            snprintf(why, whycap, "out of memory or bad TIFF layout");
            goto done;
        }
        for (uint32_t y = 0; y < h; y++) {
            if (TIFFReadScanline(t, line, y, 0) < 0) {
                snprintf(why, whycap, "corrupt TIFF image data");
                goto done;
            }
            for (uint32_t x = 0; x < w; x++) {
                uint16_t v;
                memcpy(&v, line + (size_t)x * 2, 2);
                if (photo == PHOTOMETRIC_MINISWHITE) v = (uint16_t)(65535u - v);
                set_px(out, (size_t)y * w + x, v, v, v, 65535u);
            }
        }
        out->format = SDL_IMGF_TIFF;
        out->colour = SDL_IMG_GREY;
        out->depth16 = 1;
        r = SDL_IMG_OK;
        goto done;
    }
    char emsg[1024] = "";
    if (!TIFFRGBAImageOK(t, emsg)) {
        snprintf(why, whycap, "TIFF layout not supported (%s)", emsg);
        r = SDL_IMG_UNSUPPORTED;
        goto done;
    }
    raster = malloc((size_t)w * h * sizeof *raster);
    if (!raster || !alloc_pixels(out, (int)w, (int)h, 0)) {
        snprintf(why, whycap, "out of memory");
        goto done;
    }
    if (!TIFFReadRGBAImageOriented(t, w, h, raster, ORIENTATION_TOPLEFT, 0)) {
        snprintf(why, whycap, "corrupt TIFF image data");
        goto done;
    }
    for (size_t i = 0; i < (size_t)w * h; i++) {
        uint32_t p = raster[i];
        set_px(out, i, TIFFGetR(p) * 257u, TIFFGetG(p) * 257u, TIFFGetB(p) * 257u, TIFFGetA(p) * 257u);
    }
    out->format = SDL_IMGF_TIFF;
    out->colour = grey ? SDL_IMG_GREY : SDL_IMG_RGB;
    out->depth16 = bits > 8;
    out->has_alpha = extra > 0;
    r = SDL_IMG_OK;
done:
    if (r != SDL_IMG_OK) sdl_img_free(out);
    free(line);
    free(raster);
    TIFFClose(t);
    return r;
}

/* ------------------------------------------------------------ entry */

static int is_tga(const unsigned char *b, size_t n)
{
    /* no signature: a plausible header (colour map type 0/1, image type
     * 1-3 or 9-11, pixel size one TGA allows) */
    if (n < 18) return 0;
    int type = b[2], bits = b[16];
    return b[1] <= 1 && ((type >= 1 && type <= 3) || (type >= 9 && type <= 11)) &&
           (bits == 8 || bits == 15 || bits == 16 || bits == 24 || bits == 32);
}

static unsigned char *read_file(const char *path, size_t *n, char *why, size_t whycap)
{
    FILE *f = fopen(path, "rb");
    struct stat stt;
    if (!f) {
        snprintf(why, whycap, "cannot be opened");
        return NULL;
    }
    if (fstat(fileno(f), &stt) != 0 || !S_ISREG(stt.st_mode)) {
        fclose(f);
        snprintf(why, whycap, "not a regular file");
        return NULL;
    }
    if ((unsigned long long)stt.st_size > SDL_IMG_MAX_FILE) {
        fclose(f);
        snprintf(why, whycap, "file larger than %llu bytes", (unsigned long long)SDL_IMG_MAX_FILE);
        return NULL;
    }
    size_t len = (size_t)stt.st_size;
    unsigned char *b = malloc(len ? len : 1);
    if (!b) {
        fclose(f);
        snprintf(why, whycap, "out of memory");
        return NULL;
    }
    size_t got = fread(b, 1, len, f);
    fclose(f);
    *n = got;
    return b;
}

int sdl_img_read(const char *path, const unsigned char *bytes, size_t n, unsigned long long max_pixels, sdl_img *out,
                 char *why, size_t whycap)
{
    memset(out, 0, sizeof *out);
    if (whycap) why[0] = 0;
    unsigned char *owned = NULL;
    if (!bytes) {
        if (!path) {
            snprintf(why, whycap, "no image given");
            return SDL_IMG_ERROR;
        }
        owned = read_file(path, &n, why, whycap);
        if (!owned) return SDL_IMG_ERROR;
        bytes = owned;
    }
    if (max_pixels == 0 || max_pixels > SDL_IMG_MAX_PIXELS) max_pixels = SDL_IMG_MAX_PIXELS;
    mem_src m = {bytes, n, 0, max_pixels};
    int r;
    if (n >= 8 && !png_sig_cmp(bytes, 0, 8)) {
        r = read_png(&m, out, why, whycap);
    } else if (n >= 6 && memcmp(bytes, "GIF8", 4) == 0) {
        r = read_gif(&m, out, why, whycap);
    } else if (n >= 3 && bytes[0] == 0xff && bytes[1] == 0xd8 && bytes[2] == 0xff) {
        r = read_jpeg(&m, out, why, whycap);
    } else if (n >= 4 && ((bytes[0] == 'I' && bytes[1] == 'I' && (bytes[2] == 42 || bytes[2] == 43) && bytes[3] == 0) ||
                          (bytes[0] == 'M' && bytes[1] == 'M' && bytes[2] == 0 && (bytes[3] == 42 || bytes[3] == 43)))) {
        r = read_tiff(&m, out, why, whycap);
    } else if (n >= 2 && bytes[0] == 'P' && (bytes[1] == '2' || bytes[1] == '3' || bytes[1] == '5' || bytes[1] == '6')) {
        r = read_pnm(&m, bytes[1] - '0', out, why, whycap);
    } else if (is_tga(bytes, n)) {
        r = read_tga(&m, out, why, whycap);
    } else {
        snprintf(why, whycap, "image format not recognised (PNG, GIF, TGA, PGM/PPM, JPEG and TIFF are read)");
        r = SDL_IMG_UNSUPPORTED;
    }
    free(owned);
    if (r != SDL_IMG_OK) sdl_img_free(out);
    return r;
}
