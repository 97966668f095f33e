/* img_exr.c - OpenEXR reading and writing with the OpenEXRCore C API only.
 *
 * The library is driven through its chunk interface ("Reading and Writing
 * Image Files with the C-language API", openexr.com): a context is started
 * with custom positioned read/write callbacks on a file descriptor we own,
 * then every scanline block (or tile) is encoded/decoded by an
 * exr_encode_pipeline_t / exr_decode_pipeline_t, which also converts between
 * the file's half/float/uint samples and our float buffers.
 *
 * Library error messages go to an error handler that keeps the first one in
 * a thread-local buffer (the handler may run while the context's mutex is
 * held, so it must not call back into the library, e.g. exr_get_user_data). */
#include "img_exr.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <openexr.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Largest finite half: (2 - 2^-10) * 2^15 (IEEE 754-2008 binary16). */
#define HALF_MAX 65504.0f

static _Thread_local char exr_msg[512];

static void on_error(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    (void)ctxt;
    if (exr_msg[0]) return; /* keep the first, most specific message */
    snprintf(exr_msg, sizeof exr_msg, "%s", msg ? msg : exr_get_default_error_message(code));
}

/* The reason for a failed library call: errno text for I/O failures in our
 * callbacks, otherwise the library's message (or its generic one). */
typedef struct {
    int fd;
    int err; /* errno of the first failed read/write, 0 if none */
} exr_stream;

static const char *reason(const exr_stream *s, exr_result_t rv)
{
    if (s->err) return strerror(s->err);
    if (exr_msg[0]) return exr_msg;
    return exr_get_default_error_message(rv);
}

static int64_t on_read(exr_const_context_t ctxt, void *ud, void *buf, uint64_t sz, uint64_t off,
                       exr_stream_error_func_ptr_t error_cb)
{
    exr_stream *s = ud;
    unsigned char *p = buf;
    uint64_t done = 0;
    while (done < sz) {
        ssize_t r = pread(s->fd, p + done, (size_t)(sz - done), (off_t)(off + done));
        if (r < 0) {
            if (errno == EINTR) continue;
            if (!s->err) s->err = errno;
            if (error_cb) error_cb(ctxt, EXR_ERR_READ_IO, "read failed: %s", strerror(errno));
            return -1;
        }
        if (r == 0) break; /* end of file: the library reports the short read */
        done += (uint64_t)r;
    }
    return (int64_t)done;
}

static int64_t on_size(exr_const_context_t ctxt, void *ud)
{
    (void)ctxt;
    exr_stream *s = ud;
    struct stat st;
    if (fstat(s->fd, &st) != 0) return -1;
    return (int64_t)st.st_size;
}

/* Before anything is allocated for the pixels: every chunk of part 0's
 * offset table (level 0) must lie inside the file, so a truncated file that
 * declares a huge image is refused here (0), with the reason in `why`.
 * An uncompressed chunk must hold all its bytes. */
static int chunks_inside(exr_context_t ctx, exr_storage_t storage, exr_attr_box2i_t dw, int64_t fsize, char *why,
                         size_t whycap)
{
    exr_chunk_info_t ci;
    exr_result_t rv;
    int32_t ntx = 1, nty = 0, lpc = 1;
    uint32_t tw = 0, th = 0;
    if (storage == EXR_STORAGE_SCANLINE) {
        if (exr_get_scanlines_per_chunk(ctx, 0, &lpc) != EXR_ERR_SUCCESS || lpc < 1) lpc = 1;
        nty = (int32_t)(((int64_t)dw.max.y - dw.min.y + lpc) / lpc);
    } else {
        exr_tile_level_mode_t lm;
        exr_tile_round_mode_t rm;
        int32_t lw = 0, lh = 0;
        if (exr_get_tile_descriptor(ctx, 0, &tw, &th, &lm, &rm) != EXR_ERR_SUCCESS || tw == 0 || th == 0 ||
            exr_get_level_sizes(ctx, 0, 0, 0, &lw, &lh) != EXR_ERR_SUCCESS || lw <= 0 || lh <= 0) {
            snprintf(why, whycap, "inconsistent tile description");
            return 0;
        }
        ntx = (int32_t)(((uint32_t)lw + tw - 1) / tw);
        nty = (int32_t)(((uint32_t)lh + th - 1) / th);
    }
    for (int32_t ty = 0; ty < nty; ty++)
        for (int32_t tx = 0; tx < ntx; tx++) {
            if (storage == EXR_STORAGE_SCANLINE)
                rv = exr_read_scanline_chunk_info(ctx, 0, (int)((int64_t)dw.min.y + (int64_t)ty * lpc), &ci);
            else
                rv = exr_read_tile_chunk_info(ctx, 0, tx, ty, 0, 0, &ci);
            if (rv != EXR_ERR_SUCCESS) {
                snprintf(why, whycap, "the file is truncated or corrupt: chunk %d of %d cannot be read (%s)",
                         (int)(ty * ntx + tx), (int)(ntx * nty), exr_msg[0] ? exr_msg : exr_get_default_error_message(rv));
                return 0;
            }
            if ((int64_t)ci.data_offset < 0 || ci.data_offset + ci.packed_size > (uint64_t)fsize ||
                (ci.compression == EXR_COMPRESSION_NONE && ci.packed_size < ci.unpacked_size)) {
                snprintf(why, whycap,
                         "the file is truncated: chunk %d of %d needs bytes %llu to %llu, the file has %lld",
                         (int)(ty * ntx + tx), (int)(ntx * nty), (unsigned long long)ci.data_offset,
                         (unsigned long long)(ci.data_offset + (ci.compression == EXR_COMPRESSION_NONE
                                                                    ? ci.unpacked_size : ci.packed_size)),
                         (long long)fsize);
                return 0;
            }
        }
    return 1;
}

static int64_t on_write(exr_const_context_t ctxt, void *ud, const void *buf, uint64_t sz, uint64_t off,
                        exr_stream_error_func_ptr_t error_cb)
{
    exr_stream *s = ud;
    const unsigned char *p = buf;
    uint64_t done = 0;
    while (done < sz) {
        ssize_t w = pwrite(s->fd, p + done, (size_t)(sz - done), (off_t)(off + done));
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {
            if (!s->err) s->err = w < 0 ? errno : EIO;
            if (error_cb) error_cb(ctxt, EXR_ERR_WRITE_IO, "write failed: %s", strerror(s->err));
            return -1;
        }
        done += (uint64_t)w;
    }
    return (int64_t)done;
}

/* CIE 1931 xy chromaticities of the primaries and white point.
 * Rec. ITU-R BT.709-6 item 1.4 (also the sRGB primaries, IEC 61966-2-1),
 * white D65; ACES AP1 (SMPTE ST 2065-1 / Academy S-2014-004), white ~D60;
 * ACES AP0 (SMPTE ST 2065-1), the same white. */
static const exr_attr_chromaticities_t primaries_table[] = {
    [IMG_PRIMARIES_REC709] = {0.640f, 0.330f, 0.300f, 0.600f, 0.150f, 0.060f, 0.3127f, 0.3290f},
    [IMG_PRIMARIES_ACESCG] = {0.713f, 0.293f, 0.165f, 0.830f, 0.128f, 0.044f, 0.32168f, 0.33767f},
    [IMG_PRIMARIES_ACES2065_1] = {0.7347f, 0.2653f, 0.0f, 1.0f, 0.0001f, -0.0770f, 0.32168f, 0.33767f},
};

void img_exr_primaries(img_primaries prim, float xy[8])
{
    if ((unsigned)prim >= sizeof primaries_table / sizeof primaries_table[0]) prim = IMG_PRIMARIES_REC709;
    const exr_attr_chromaticities_t *c = &primaries_table[prim];
    const float v[8] = {c->red_x, c->red_y, c->green_x, c->green_y, c->blue_x, c->blue_y, c->white_x, c->white_y};
    memcpy(xy, v, sizeof v);
}

/* OpenEXRCore 3.1's ZIP encoder keeps the zlib bytes when they come out
 * exactly as long as the packed data, but a reader takes a chunk whose
 * stored size equals its unpacked size as uncompressed: that chunk reads back
 * as garbage (OpenEXR issue #2306, fixed upstream after 3.4.7). Seen with
 * noisy float renders (a 64x64 path-traced Cornell box). Store such a chunk
 * uncompressed, as the fixed library does. */
static exr_result_t compress_checked(exr_encode_pipeline_t *e)
{
    exr_result_t (*fn)(exr_encode_pipeline_t *) = (exr_result_t(*)(exr_encode_pipeline_t *))e->encoding_user_data;
    exr_result_t rv = fn(e);
    if (rv == EXR_ERR_SUCCESS && e->compressed_buffer && e->packed_buffer && e->compressed_buffer != e->packed_buffer &&
        e->compressed_bytes == e->packed_bytes && e->compressed_alloc_size >= e->packed_bytes)
        memcpy(e->compressed_buffer, e->packed_buffer, (size_t)e->packed_bytes);
    return rv;
}

static exr_compression_t compression_of(int c)
{
    switch (c) {
    case 0: return EXR_COMPRESSION_NONE;
    case 2: return EXR_COMPRESSION_PIZ;
    default: return EXR_COMPRESSION_ZIP;
    }
}

/* One channel of the file: where its floats come from. */
typedef struct {
    char name[80];
    const float *src;  /* first pixel's value */
    int stride;        /* floats from one pixel to the next */
    int use_float;     /* 1: FLOAT in the file, 0: HALF */
} out_channel;

/* Beauty R,G,B[,A] then every layer's channels "name.X". */
static int list_channels(const framebuffer *fb, const img_write_opts *o, int use_float, out_channel **out)
{
    int n = fb->alpha ? 4 : 3;
    for (int i = 0; o && i < o->nlayers; i++) n += (int)strlen(o->layers[i].suffixes);
    out_channel *ch = calloc((size_t)n, sizeof *ch);
    if (!ch) return -1;
    static const char *const names[4] = {"R", "G", "B", "A"};
    int k = 0;
    for (int c = 0; c < (fb->alpha ? 4 : 3); c++, k++) {
        snprintf(ch[k].name, sizeof ch[k].name, "%s", names[c]);
        ch[k].src = c < 3 ? fb->rgb + c : fb->alpha;
        ch[k].stride = c < 3 ? 3 : 1;
        ch[k].use_float = use_float;
    }
    for (int i = 0; o && i < o->nlayers; i++) {
        const img_layer *l = &o->layers[i];
        int nc = (int)strlen(l->suffixes);
        for (int c = 0; c < nc; c++, k++) {
            snprintf(ch[k].name, sizeof ch[k].name, "%s.%c", l->name, l->suffixes[c]);
            ch[k].src = l->data + c;
            ch[k].stride = nc;
            ch[k].use_float = use_float || l->full_float;
        }
    }
    *out = ch;
    return n;
}

pt_status img_exr_write_xy(int fd, const char *name, const framebuffer *fb, const img_write_opts *o,
                           const float *xy, diag *d)
{
    exr_msg[0] = '\0';
    exr_stream s = {fd, 0};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = on_error;
    init.user_data = &s;
    init.write_fn = on_write;

    const int w = fb->width, h = fb->height;
    /* the data window (a tile) inside the display window (fb) */
    int wx0 = 0, wy0 = 0, wx1 = w, wy1 = h;
    if (o && o->window[2] > o->window[0] && o->window[3] > o->window[1]) {
        if (o->window[0] < 0 || o->window[1] < 0 || o->window[2] > w || o->window[3] > h) {
            diag_error(d, "cannot write '%s': data window outside the %dx%d image", name, w, h);
            return PT_ERR_INTERNAL;
        }
        wx0 = o->window[0];
        wy0 = o->window[1];
        wx1 = o->window[2];
        wy1 = o->window[3];
    }
    const int ww = wx1 - wx0;
    const int use_float = o && o->exr_float;
    out_channel *ch = NULL;
    const int nch = list_channels(fb, o, use_float, &ch);
    if (nch < 0) {
        diag_error(d, "cannot write '%s': out of memory", name);
        return PT_ERR_NOMEM;
    }

    exr_context_t ctx = NULL;
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    int enc_init = 0;
    float *buf = NULL;
    const char *what = "cannot start EXR file";
    int part = 0;
    exr_result_t rv = exr_start_write(&ctx, name, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv != EXR_ERR_SUCCESS) goto fail;

    what = "cannot set up EXR header";
    rv = exr_add_part(ctx, NULL, EXR_STORAGE_SCANLINE, &part);
    if (rv == EXR_ERR_SUCCESS) {
        exr_attr_box2i_t disp, data;
        disp.min.x = 0;
        disp.min.y = 0;
        disp.max.x = w - 1;
        disp.max.y = h - 1;
        data.min.x = wx0;
        data.min.y = wy0;
        data.max.x = wx1 - 1;
        data.max.y = wy1 - 1;
        exr_attr_v2f_t centre;
        centre.x = 0.0f;
        centre.y = 0.0f;
        rv = exr_initialize_required_attr(ctx, part, &disp, &data, 1.0f, &centre, 1.0f, EXR_LINEORDER_INCREASING_Y,
                                          compression_of(o ? o->exr_compression : 1));
    }
    /* Channel order in the file is alphabetical whatever the add order. */
    for (int c = 0; c < nch && rv == EXR_ERR_SUCCESS; c++)
        rv = exr_add_channel(ctx, part, ch[c].name, ch[c].use_float ? EXR_PIXEL_FLOAT : EXR_PIXEL_HALF,
                             EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    if (rv == EXR_ERR_SUCCESS && xy) {
        const exr_attr_chromaticities_t chr = {xy[0], xy[1], xy[2], xy[3], xy[4], xy[5], xy[6], xy[7]};
        rv = exr_attr_set_chromaticities(ctx, part, "chromaticities", &chr);
    }
    if (rv == EXR_ERR_SUCCESS && o && o->white_luminance > 0.0 && isfinite(o->white_luminance))
        rv = exr_attr_set_float(ctx, part, "whiteLuminance", (float)o->white_luminance);
    if (rv != EXR_ERR_SUCCESS) goto fail;
    for (int i = 0; o && i < o->nmeta; i++) {
        const char *k = o->meta_keys[i], *v = o->meta_values[i];
        if (!k || !*k || !v) continue;
        rv = exr_attr_set_string(ctx, part, k, v);
        if (rv != EXR_ERR_SUCCESS) {
            exr_finish(&ctx);
            free(ch);
            diag_error(d, "cannot write '%s': cannot set EXR attribute '%s': %s", name, k, reason(&s, rv));
            return PT_ERR_IO;
        }
    }
    what = "cannot write EXR header";
    rv = exr_write_header(ctx);
    if (rv != EXR_ERR_SUCCESS) goto fail;

    int32_t lpc = 1;
    what = "cannot write EXR data";
    rv = exr_get_scanlines_per_chunk(ctx, part, &lpc);
    if (rv != EXR_ERR_SUCCESS) goto fail;
    if (lpc < 1) lpc = 1;
    /* One block of sanitized floats, channel after channel (planar). */
    const size_t plane = (size_t)ww * (size_t)lpc;
    buf = malloc(sizeof(float) * plane * (size_t)nch);
    if (!buf) {
        exr_finish(&ctx);
        free(ch);
        diag_error(d, "cannot write '%s': out of memory", name);
        return PT_ERR_NOMEM;
    }
    for (int y0 = wy0; y0 < wy1; y0 += lpc) {
        exr_chunk_info_t ci;
        rv = exr_write_scanline_chunk_info(ctx, part, y0, &ci);
        if (rv != EXR_ERR_SUCCESS) goto fail;
        for (int c = 0; c < nch; c++) {
            const float lim = ch[c].use_float ? INFINITY : HALF_MAX;
            for (int y = 0; y < ci.height; y++) {
                const float *src = ch[c].src + ((size_t)(y0 + y) * (size_t)w + (size_t)wx0) * (size_t)ch[c].stride;
                float *dst = buf + (size_t)c * plane + (size_t)y * (size_t)ww;
                for (int x = 0; x < ww; x++) {
                    float v = src[(size_t)x * (size_t)ch[c].stride];
                    if (!isfinite(v)) v = 0.0f;
                    if (v > lim) v = lim;
                    if (v < -lim) v = -lim;
                    dst[x] = v;
                }
            }
        }
        rv = enc_init ? exr_encoding_update(ctx, part, &ci, &enc) : exr_encoding_initialize(ctx, part, &ci, &enc);
        if (rv != EXR_ERR_SUCCESS) goto fail;
        for (int c = 0; c < enc.channel_count; c++) {
            exr_coding_channel_info_t *ec = &enc.channels[c];
            int slot = 0;
            while (slot < nch && strcmp(ec->channel_name, ch[slot].name) != 0) slot++;
            if (slot == nch) slot = 0; /* cannot happen: we declared exactly these */
            ec->user_data_type = EXR_PIXEL_FLOAT;
            ec->user_bytes_per_element = 4;
            ec->user_pixel_stride = (int32_t)sizeof(float);
            ec->user_line_stride = (int32_t)(sizeof(float) * (size_t)ww);
            ec->encode_from_ptr = (const uint8_t *)(buf + (size_t)slot * plane);
        }
        if (!enc_init) {
            enc_init = 1;
            rv = exr_encoding_choose_default_routines(ctx, part, &enc);
            if (rv != EXR_ERR_SUCCESS) goto fail;
            if (enc.compress_fn) {
                enc.encoding_user_data = (void *)enc.compress_fn;
                enc.compress_fn = compress_checked;
            }
        }
        rv = exr_encoding_run(ctx, part, &enc);
        if (rv != EXR_ERR_SUCCESS) goto fail;
    }
    exr_encoding_destroy(ctx, &enc);
    enc_init = 0;
    free(buf);
    buf = NULL;
    free(ch);
    ch = NULL;
    what = "cannot finish EXR file";
    rv = exr_finish(&ctx);
    if (rv != EXR_ERR_SUCCESS || s.err) {
        diag_error(d, "cannot write '%s': %s: %s", name, what, reason(&s, rv));
        return PT_ERR_IO;
    }
    return PT_OK;

fail:
    if (enc_init) exr_encoding_destroy(ctx, &enc);
    free(buf);
    free(ch);
    if (ctx) exr_finish(&ctx);
    diag_error(d, "cannot write '%s': %s: %s", name, what, reason(&s, rv));
    return PT_ERR_IO;
}

/* ---- reading ---------------------------------------------------------- */

enum { SLOT_R, SLOT_G, SLOT_B, SLOT_A, SLOT_Y, NSLOTS };

/* OpenEXRCore 3.1 may choose an unpacking routine that writes through the
 * NULL decode_to_ptr of a channel that is meant to be skipped (fuzz_image:
 * a file with channels b, G, R crashed in exr_decoding_run). So a channel
 * we do not want is decoded into this scratch block, in its own type, and
 * dropped. */
typedef struct {
    uint8_t *p;
    size_t cap;
} exr_scratch;

/* Room in s for any one channel of the block dec is set up for. */
static int scratch_fit(exr_scratch *s, const exr_decode_pipeline_t *dec)
{
    size_t need = 16;
    for (int c = 0; c < dec->channel_count; c++) {
        const exr_coding_channel_info_t *dc = &dec->channels[c];
        size_t n = (size_t)(dc->width > 0 ? dc->width : 0) * (size_t)(dc->height > 0 ? dc->height : 0) *
                   (size_t)(dc->bytes_per_element > 0 ? dc->bytes_per_element : 4);
        if (n > need) need = n;
    }
    if (need <= s->cap) return 1;
    uint8_t *p = realloc(s->p, need);
    if (!p) return 0;
    s->p = p;
    s->cap = need;
    return 1;
}

static void bind_scratch(exr_coding_channel_info_t *dc, exr_scratch *s)
{
    dc->decode_to_ptr = s->p;
    dc->user_pixel_stride = dc->bytes_per_element;
    dc->user_line_stride = dc->width * dc->bytes_per_element;
    dc->user_data_type = dc->data_type;
    dc->user_bytes_per_element = dc->bytes_per_element;
}

/* Point the decoder's channels at their places in fb for the block whose
 * top-left pixel is (x0, y0) in image coordinates. */
static void bind_channels(exr_decode_pipeline_t *dec, framebuffer *fb, float *grey, int x0, int y0, int use_y,
                          exr_scratch *scratch)
{
    const size_t w = (size_t)fb->width;
    for (int c = 0; c < dec->channel_count; c++) {
        exr_coding_channel_info_t *dc = &dec->channels[c];
        const char *n = dc->channel_name;
        uint8_t *ptr = NULL;
        int32_t pstride = 0, lstride = 0;
        if (dc->x_samples == 1 && dc->y_samples == 1 && n && n[0] && !n[1]) {
            int slot = -1;
            switch (n[0]) {
            case 'R': slot = use_y ? -1 : SLOT_R; break;
            case 'G': slot = use_y ? -1 : SLOT_G; break;
            case 'B': slot = use_y ? -1 : SLOT_B; break;
            case 'A': slot = fb->alpha ? SLOT_A : -1; break;
            case 'Y': slot = use_y ? SLOT_Y : -1; break;
            default: break;
            }
            size_t pix = (size_t)y0 * w + (size_t)x0;
            if (slot >= SLOT_R && slot <= SLOT_B) {
                ptr = (uint8_t *)(fb->rgb + pix * 3u + (size_t)slot);
                pstride = (int32_t)(3 * sizeof(float));
                lstride = (int32_t)(w * 3u * sizeof(float));
            } else if (slot == SLOT_A || slot == SLOT_Y) {
                ptr = (uint8_t *)((slot == SLOT_A ? fb->alpha : grey) + pix);
                pstride = (int32_t)sizeof(float);
                lstride = (int32_t)(w * sizeof(float));
            }
        }
        if (!ptr) {
            bind_scratch(dc, scratch);
            continue;
        }
        dc->decode_to_ptr = ptr;
        dc->user_pixel_stride = pstride;
        dc->user_line_stride = lstride;
        dc->user_data_type = EXR_PIXEL_FLOAT;
        dc->user_bytes_per_element = 4;
    }
}

typedef struct {
    char names[4][80];
    int n;
    float *data; /* w*h*n */
    int w;
} layer_sink;

static void bind_layer(exr_decode_pipeline_t *dec, const layer_sink *ls, int x0, int y0, exr_scratch *scratch)
{
    for (int c = 0; c < dec->channel_count; c++) {
        exr_coding_channel_info_t *dc = &dec->channels[c];
        int slot = -1;
        for (int k = 0; k < ls->n && dc->channel_name; k++)
            if (strcmp(dc->channel_name, ls->names[k]) == 0) slot = k;
        dc->decode_to_ptr = NULL;
        dc->user_pixel_stride = 0;
        dc->user_line_stride = 0;
        if (slot >= 0 && dc->x_samples == 1 && dc->y_samples == 1) {
            size_t pix = (size_t)y0 * (size_t)ls->w + (size_t)x0;
            dc->decode_to_ptr = (uint8_t *)(ls->data + pix * (size_t)ls->n + (size_t)slot);
            dc->user_pixel_stride = (int32_t)(sizeof(float) * (size_t)ls->n);
            dc->user_line_stride = (int32_t)(sizeof(float) * (size_t)ls->n * (size_t)ls->w);
        }
        dc->user_data_type = EXR_PIXEL_FLOAT;
        dc->user_bytes_per_element = 4;
        if (!dc->decode_to_ptr) bind_scratch(dc, scratch);
    }
}

/* Where a read decodes to: the image (fb, and grey for a luminance-only
 * file) or named channels (ls), with the decoding pipeline and the scratch
 * block they share from chunk to chunk. */
typedef struct {
    exr_decode_pipeline_t dec;
    int dec_init;
    exr_scratch scratch;
    framebuffer *fb;
    float *grey;
    int use_y;
    const layer_sink *ls; /* non-NULL: named channels */
} chunk_sink;

/* Decode one chunk described by ci into the sink at (x0, y0). */
static exr_result_t decode_chunk(exr_context_t ctx, const exr_chunk_info_t *ci, chunk_sink *k, int x0, int y0)
{
    exr_result_t rv = k->dec_init ? exr_decoding_update(ctx, 0, ci, &k->dec) : exr_decoding_initialize(ctx, 0, ci, &k->dec);
    if (rv != EXR_ERR_SUCCESS) return rv;
    if (!scratch_fit(&k->scratch, &k->dec)) return EXR_ERR_OUT_OF_MEMORY;
    if (k->ls) bind_layer(&k->dec, k->ls, x0, y0, &k->scratch);
    else bind_channels(&k->dec, k->fb, k->grey, x0, y0, k->use_y, &k->scratch);
    if (!k->dec_init) {
        k->dec_init = 1;
        rv = exr_decoding_choose_default_routines(ctx, 0, &k->dec);
        if (rv != EXR_ERR_SUCCESS) return rv;
    }
    return exr_decoding_run(ctx, 0, &k->dec);
}


/* Decodes every chunk of part 0 of a w x h data window dw (scanline
 * blocks, or the tiles of level 0) into k, each checked to lie inside the
 * window. 1 when all are decoded; 0 with *rv the library's error, or with
 * *rv EXR_ERR_SUCCESS when the chunk layout is inconsistent (reported in d). */
static int decode_chunks(exr_context_t ctx, exr_storage_t storage, exr_attr_box2i_t dw, int w, int h, chunk_sink *k,
                         const char *path, exr_result_t *rv, diag *d)
{
    if (storage == EXR_STORAGE_SCANLINE) {
        int32_t lpc = 1;
        if ((*rv = exr_get_scanlines_per_chunk(ctx, 0, &lpc)) != EXR_ERR_SUCCESS) return 0;
        if (lpc < 1) lpc = 1;
        for (int64_t y = dw.min.y; y <= dw.max.y; y += lpc) {
            exr_chunk_info_t ci;
            if ((*rv = exr_read_scanline_chunk_info(ctx, 0, (int)y, &ci)) != EXR_ERR_SUCCESS) return 0;
            int row = ci.start_y - dw.min.y;
            if (row < 0 || row + ci.height > h || ci.width != w) {
                diag_error(d, "cannot read '%s': inconsistent scanline block at y=%d", path, ci.start_y);
                return 0;
            }
            if ((*rv = decode_chunk(ctx, &ci, k, 0, row)) != EXR_ERR_SUCCESS) return 0;
        }
        return 1;
    }
    uint32_t tw = 0, th = 0;
    exr_tile_level_mode_t lm;
    exr_tile_round_mode_t rm;
    if ((*rv = exr_get_tile_descriptor(ctx, 0, &tw, &th, &lm, &rm)) != EXR_ERR_SUCCESS) return 0;
    int32_t lw = 0, lh = 0;
    if ((*rv = exr_get_level_sizes(ctx, 0, 0, 0, &lw, &lh)) != EXR_ERR_SUCCESS) return 0;
    if (tw == 0 || th == 0 || lw != w || lh != h) {
        diag_error(d, "cannot read '%s': inconsistent tile description", path);
        return 0;
    }
    int ntx = (int)(((uint32_t)w + tw - 1) / tw), nty = (int)(((uint32_t)h + th - 1) / th);
    for (int ty = 0; ty < nty; ty++) {
        for (int tx = 0; tx < ntx; tx++) {
            exr_chunk_info_t ci;
            if ((*rv = exr_read_tile_chunk_info(ctx, 0, tx, ty, 0, 0, &ci)) != EXR_ERR_SUCCESS) return 0;
            int x0 = tx * (int)tw, y0 = ty * (int)th;
            if (ci.width <= 0 || ci.height <= 0 || x0 + ci.width > w || y0 + ci.height > h) {
                diag_error(d, "cannot read '%s': inconsistent tile (%d,%d)", path, tx, ty);
                return 0;
            }
            if ((*rv = decode_chunk(ctx, &ci, k, x0, y0)) != EXR_ERR_SUCCESS) return 0;
        }
    }
    return 1;
}

/* Opens path for reading into s (the caller closes s->fd when it is >= 0)
 * and starts an OpenEXR read context on it (*rv: exr_start_read's result).
 * 0, with a message, when the file cannot be opened. */
static int start_read(const char *path, exr_stream *s, exr_context_t *ctx, exr_result_t *rv, diag *d)
{
    exr_msg[0] = '\0';
    s->fd = open(path, O_RDONLY | O_CLOEXEC);
    s->err = 0;
    if (s->fd < 0) {
        diag_error(d, "cannot read '%s': %s", path, strerror(errno));
        return 0;
    }
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = on_error;
    init.user_data = s;
    init.read_fn = on_read;
    init.size_fn = on_size;
    init.max_image_width = IMG_MAX_SIDE;
    init.max_image_height = IMG_MAX_SIDE;
    /* A damaged chunk table is an error, not something to guess around. */
    init.flags = EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;
    *rv = exr_start_read(ctx, path, &init);
    return 1;
}

/* Ends what start_read began: the sink's decoder and scratch, the read
 * context, the file. */
static void finish_read(exr_stream *s, exr_context_t *ctx, chunk_sink *k)
{
    if (k->dec_init) exr_decoding_destroy(*ctx, &k->dec);
    free(k->scratch.p);
    if (*ctx) exr_finish(ctx);
    close(s->fd);
}

/* 1 when rv is success; otherwise reports "cannot read 'path': what: reason". */
static int read_ok(const exr_stream *s, exr_result_t rv, const char *path, const char *what, diag *d)
{
    if (rv == EXR_ERR_SUCCESS) return 1;
    diag_error(d, "cannot read '%s': %s: %s", path, what, reason(s, rv));
    return 0;
}

/* The first part's storage, data window and channels, after start_read
 * returned rv; 0 (reported) when the file or its header cannot be read. */
static int read_header(exr_context_t ctx, const exr_stream *s, exr_result_t rv, const char *path,
                       exr_storage_t *storage, exr_attr_box2i_t *dw, const exr_attr_chlist_t **chl, diag *d)
{
    const char *what = "cannot read EXR header";
    return read_ok(s, rv, path, "not a readable EXR file", d) &&
           read_ok(s, exr_get_storage(ctx, 0, storage), path, what, d) &&
           read_ok(s, exr_get_data_window(ctx, 0, dw), path, what, d) &&
           read_ok(s, exr_get_channels(ctx, 0, chl), path, what, d);
}

pt_status img_exr_read(const char *path, uint64_t max_pixels, framebuffer **out, diag *d)
{
    *out = NULL;
    exr_stream s = {-1, 0};
    exr_context_t ctx = NULL;
    exr_result_t rv;
    if (!start_read(path, &s, &ctx, &rv, d)) return PT_ERR_IO;

    pt_status st = PT_ERR_IO;
    chunk_sink sink = {.dec = EXR_DECODE_PIPELINE_INITIALIZER};
    framebuffer *fb = NULL;
    float *grey = NULL;
    exr_storage_t storage;
    exr_attr_box2i_t dw;
    const exr_attr_chlist_t *chl = NULL;
    if (!read_header(ctx, &s, rv, path, &storage, &dw, &chl, d)) goto done;
    if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED) {
        diag_error(d, "cannot read '%s': deep EXR images are not supported", path);
        goto done;
    }
    int64_t w64 = (int64_t)dw.max.x - dw.min.x + 1, h64 = (int64_t)dw.max.y - dw.min.y + 1;
    char why[256];
    if (w64 <= 0 || h64 <= 0 || imgcheck_size((uint64_t)w64, (uint64_t)h64, max_pixels, why, sizeof why)) {
        if (w64 <= 0 || h64 <= 0) snprintf(why, sizeof why, "image size %lldx%lld is empty", (long long)w64, (long long)h64);
        diag_error(d, "cannot read '%s': %s", path, why);
        goto done;
    }
    const int w = (int)w64, h = (int)h64;

    int have[NSLOTS] = {0};
    int chroma = 0, sub_y = 0;
    for (int i = 0; i < chl->num_channels; i++) {
        const exr_attr_chlist_entry_t *e = &chl->entries[i];
        const char *n = e->name.str;
        if (n && (strcmp(n, "RY") == 0 || strcmp(n, "BY") == 0)) chroma = 1;
        if (e->name.length != 1 || !n) continue;
        int slot = n[0] == 'R' ? SLOT_R : n[0] == 'G' ? SLOT_G : n[0] == 'B' ? SLOT_B : n[0] == 'A' ? SLOT_A
                 : n[0] == 'Y' ? SLOT_Y : -1;
        if (slot < 0) continue;
        if (e->x_sampling != 1 || e->y_sampling != 1) {
            if (slot == SLOT_Y) sub_y = 1;
            if (slot == SLOT_Y || slot == SLOT_A) continue; /* Y: reported below if it matters */
            diag_error(d, "cannot read '%s': subsampled channel '%s' is not supported", path, n);
            goto done;
        }
        have[slot] = 1;
    }
    const int use_y = !have[SLOT_R] && !have[SLOT_G] && !have[SLOT_B] && have[SLOT_Y];
    if (!have[SLOT_R] && !have[SLOT_G] && !have[SLOT_B] && !have[SLOT_Y]) {
        if (sub_y)
            diag_error(d, "cannot read '%s': subsampled luminance channel 'Y' is not supported", path);
        else
            diag_error(d, "cannot read '%s': no R, G, B or Y channel (of %d channels)", path, chl->num_channels);
        goto done;
    }
    if (use_y && chroma) {
        src_loc none = {NULL, 0, 0};
        diag_warn_once(d, none, "'%s': luminance/chroma EXR read as greyscale (RY/BY ignored)", path);
    }
    if (!chunks_inside(ctx, storage, dw, on_size(ctx, &s), why, sizeof why)) {
        diag_error(d, "cannot read '%s': %s", path, why);
        goto done;
    }
    fb = fb_new(w, h);
    if (fb && have[SLOT_A]) fb->alpha = calloc((size_t)w * (size_t)h, sizeof(float));
    if (fb && use_y) grey = calloc((size_t)w * (size_t)h, sizeof(float));
    if (!fb || (have[SLOT_A] && !fb->alpha) || (use_y && !grey)) {
        diag_error(d, "cannot read '%s': out of memory for %dx%d image", path, w, h);
        st = PT_ERR_NOMEM;
        goto done;
    }

    sink.fb = fb;
    sink.grey = grey;
    sink.use_y = use_y;
    if (!decode_chunks(ctx, storage, dw, w, h, &sink, path, &rv, d)) {
        read_ok(&s, rv, path, "cannot read EXR pixels", d);
        goto done;
    }
    if (use_y) {
        size_t n = (size_t)w * (size_t)h;
        for (size_t i = 0; i < n; i++) fb->rgb[i * 3] = fb->rgb[i * 3 + 1] = fb->rgb[i * 3 + 2] = grey[i];
    }
    st = PT_OK;
    *out = fb;
    fb = NULL;
done:
    finish_read(&s, &ctx, &sink);
    free(grey);
    fb_free(fb);
    return st;
}

/* ---- reading named channels (AOV layers) ------------------------------- */


pt_status img_read_exr_layer(const char *path, const char *layer, const char *suffixes, float **out, int *width,
                             int *height, diag *d)
{
    *out = NULL;
    layer_sink ls;
    memset(&ls, 0, sizeof ls);
    ls.n = suffixes ? (int)strlen(suffixes) : 0;
    if (ls.n < 1 || ls.n > 4) {
        diag_error(d, "cannot read '%s': 1 to 4 channel suffixes wanted", path);
        return PT_ERR_USAGE;
    }
    for (int k = 0; k < ls.n; k++) {
        if (layer && *layer) snprintf(ls.names[k], sizeof ls.names[k], "%s.%c", layer, suffixes[k]);
        else snprintf(ls.names[k], sizeof ls.names[k], "%c", suffixes[k]);
    }
    exr_stream s = {-1, 0};
    exr_context_t ctx = NULL;
    exr_result_t rv;
    if (!start_read(path, &s, &ctx, &rv, d)) return PT_ERR_IO;
    pt_status st = PT_ERR_IO;
    chunk_sink sink = {.dec = EXR_DECODE_PIPELINE_INITIALIZER, .ls = &ls};
    exr_storage_t storage;
    exr_attr_box2i_t dw;
    const exr_attr_chlist_t *chl = NULL;
    if (!read_header(ctx, &s, rv, path, &storage, &dw, &chl, d)) goto done;
    int64_t w64 = (int64_t)dw.max.x - dw.min.x + 1, h64 = (int64_t)dw.max.y - dw.min.y + 1;
    if ((storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED) || w64 <= 0 || h64 <= 0 ||
        w64 > IMG_MAX_SIDE || h64 > IMG_MAX_SIDE || (uint64_t)w64 * (uint64_t)h64 > IMG_MAX_PIXELS) {
        diag_error(d, "cannot read '%s': unsupported storage or image size", path);
        goto done;
    }
    for (int k = 0; k < ls.n; k++) {
        int found = 0;
        for (int i = 0; i < chl->num_channels; i++) {
            const exr_attr_chlist_entry_t *e = &chl->entries[i];
            if (e->name.str && strcmp(e->name.str, ls.names[k]) == 0 && e->x_sampling == 1 && e->y_sampling == 1) found = 1;
        }
        if (!found) {
            diag_error(d, "cannot read '%s': no channel '%s'", path, ls.names[k]);
            goto done;
        }
    }
    ls.w = (int)w64;
    ls.data = calloc((size_t)w64 * (size_t)h64 * (size_t)ls.n, sizeof(float));
    if (!ls.data) {
        diag_error(d, "cannot read '%s': out of memory", path);
        st = PT_ERR_NOMEM;
        goto done;
    }
    if (!decode_chunks(ctx, storage, dw, (int)w64, (int)h64, &sink, path, &rv, d)) {
        read_ok(&s, rv, path, "cannot read EXR pixels", d);
        goto done;
    }
    *out = ls.data;
    ls.data = NULL;
    *width = (int)w64;
    *height = (int)h64;
    st = PT_OK;
done:
    finish_read(&s, &ctx, &sink);
    free(ls.data);
    return st;
}

pt_status img_exr_info(const char *path, int *disp_w, int *disp_h, int win[4], const char *const *keys, int nkeys,
                       char **vals, diag *d)
{
    for (int i = 0; i < nkeys; i++) vals[i] = NULL;
    exr_stream s = {-1, 0};
    exr_context_t ctx = NULL;
    exr_attr_box2i_t dw, vw;
    exr_result_t rv;
    if (!start_read(path, &s, &ctx, &rv, d)) return PT_ERR_IO;
    if (rv == EXR_ERR_SUCCESS) rv = exr_get_data_window(ctx, 0, &dw);
    if (rv == EXR_ERR_SUCCESS) rv = exr_get_display_window(ctx, 0, &vw);
    if (rv != EXR_ERR_SUCCESS) {
        diag_error(d, "cannot read '%s': not a readable EXR header: %s", path, reason(&s, rv));
        if (ctx) exr_finish(&ctx);
        close(s.fd);
        return PT_ERR_IO;
    }
    *disp_w = vw.max.x - vw.min.x + 1;
    *disp_h = vw.max.y - vw.min.y + 1;
    win[0] = dw.min.x - vw.min.x;
    win[1] = dw.min.y - vw.min.y;
    win[2] = dw.max.x - vw.min.x + 1;
    win[3] = dw.max.y - vw.min.y + 1;
    for (int i = 0; i < nkeys; i++) {
        int32_t len = 0;
        const char *str = NULL;
        if (exr_attr_get_string(ctx, 0, keys[i], &len, &str) == EXR_ERR_SUCCESS && str && len >= 0) {
            vals[i] = malloc((size_t)len + 1);
            if (vals[i]) {
                memcpy(vals[i], str, (size_t)len);
                vals[i][len] = 0;
            }
        }
    }
    exr_finish(&ctx);
    close(s.fd);
    return PT_OK;
}
