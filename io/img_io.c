/* img_io.c - image file dispatch, crash-safe writing, sRGB transfer functions.
 *
 * Writing: the encoder for the format chosen by the file extension writes to
 * `<dir>/.<name>.tmp-<pid>` in the destination directory; only when every
 * byte has been written, synced and the file closed is it renamed over
 * `path` (rename(2) is atomic within one file system). On any failure the
 * temporary file is removed, so no partial file ever appears under `path`.
 *
 * Reading: the format is chosen by the file's magic bytes (EXR, PNG, PFM),
 * not by its extension.
 *
 * Values that are not finite (NaN, +-Inf) are written as 0 by every
 * encoder; callers need not sanitize first. */
#include "img_io.h"
#include "img_exr.h"
#include "img_ocio.h"
#include "img_pfm.h"
#include "img_png.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

/* IEC 61966-2-1:1999 (sRGB), section 5.2 (encoding) and 5.3 (decoding):
 *   V = 12.92 L                   for L <= 0.0031308
 *   V = 1.055 L^(1/2.4) - 0.055   otherwise
 * The standard's decoding knee is V = 0.04045; the two pieces of the curve do
 * not meet exactly with these rounded constants (the power piece at
 * L = 0.0031308 gives 0.0404499075, the linear piece 0.040449936). We decode
 * with the knee placed at 12.92 * 0.0031308 = 0.040449936, the image of the
 * encoding knee, so that encode(decode(V)) == V for every V and
 * decode(encode(L)) == L for every L outside (0.0031308, 0.0031308022], a
 * window in which the standard's own curve is not invertible. The results
 * differ from the 0.04045 knee by less than 3e-9 and only for V in
 * (0.040449936, 0.04045]. */
#define SRGB_LIN_KNEE 0.0031308
#define SRGB_ENC_KNEE (12.92 * SRGB_LIN_KNEE)

double img_srgb_encode(double linear)
{
    if (linear <= SRGB_LIN_KNEE) return 12.92 * linear;
    return 1.055 * pow(linear, 1.0 / 2.4) - 0.055;
}

double img_srgb_decode(double encoded)
{
    if (encoded <= SRGB_ENC_KNEE) return encoded / 12.92;
    return pow((encoded + 0.055) / 1.055, 2.4);
}

void img_default_write_opts(img_write_opts *o)
{
    if (!o) return;
    memset(o, 0, sizeof *o);
    o->exr_float = 0;
    o->exr_compression = 1; /* zip */
    o->png_16bit = 0;
}

img_format img_format_from_path(const char *path)
{
    if (!path) return IMG_FMT_UNKNOWN;
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    const char *dot = strrchr(base, '.');
    if (!dot || dot == base) return IMG_FMT_UNKNOWN;
    if (strcasecmp(dot, ".exr") == 0) return IMG_FMT_EXR;
    if (strcasecmp(dot, ".png") == 0) return IMG_FMT_PNG;
    if (strcasecmp(dot, ".pfm") == 0) return IMG_FMT_PFM;
    return IMG_FMT_UNKNOWN;
}

/* "<dir>/.<name>.tmp-<pid>" for `path`; malloc'd, NULL when out of memory. */
static char *temp_path_for(const char *path)
{
    const char *slash = strrchr(path, '/');
    size_t dirlen = slash ? (size_t)(slash - path) + 1 : 0;
    const char *base = path + dirlen;
    char pidbuf[32];
    snprintf(pidbuf, sizeof pidbuf, "%ld", (long)getpid());
    size_t n = dirlen + 1 + strlen(base) + 5 + strlen(pidbuf) + 1;
    char *t = malloc(n);
    if (!t) return NULL;
    memcpy(t, path, dirlen);
    snprintf(t + dirlen, n - dirlen, ".%s.tmp-%s", base, pidbuf);
    return t;
}

static int valid_fb(const framebuffer *fb)
{
    return fb && fb->rgb && fb->width > 0 && fb->height > 0 && fb->width <= IMG_MAX_SIDE &&
           fb->height <= IMG_MAX_SIDE && (uint64_t)fb->width * (uint64_t)fb->height <= IMG_MAX_PIXELS;
}

/* What colour management does to one write: the values to encode (fb, or
 * a converted copy), the EXR chromaticities, the PNG encoding and chunks. */
typedef struct {
    framebuffer *copy; /* owned RGB copy (alpha borrowed from fb), or NULL */
    float xy[8];       /* EXR chromaticities */
    int have_xy;       /* 0: write no chromaticities attribute */
    int png_display;   /* 1: copy holds display-encoded values */
    img_png_tag tag;
    img_layer *layers; /* EXR layers with the colour ones converted (NULL: o->layers as given) */
    float **owned;     /* their converted data, per layer (NULL where borrowed) */
    int nlayers;
} colour_plan;

static void plan_free(colour_plan *p)
{
    if (p->copy) p->copy->alpha = NULL; /* borrowed */
    fb_free(p->copy);
    p->copy = NULL;
    for (int i = 0; p->owned && i < p->nlayers; i++) free(p->owned[i]);
    free(p->owned);
    free(p->layers);
    p->owned = NULL;
    p->layers = NULL;
}

/* The colour layers (3 channels, `colour` set) go into the working space
 * with the beauty; data layers (normals, depth) are written as they are. */
static pt_status convert_layers(img_ocio *oc, const img_write_opts *o, int w, int h, const char *fbs, const char *ws,
                                colour_plan *p, diag *d)
{
    p->layers = calloc((size_t)o->nlayers, sizeof *p->layers);
    p->owned = calloc((size_t)o->nlayers, sizeof *p->owned);
    if (!p->layers || !p->owned) return PT_ERR_NOMEM;
    p->nlayers = o->nlayers;
    for (int i = 0; i < o->nlayers; i++) {
        p->layers[i] = o->layers[i];
        if (!o->layers[i].colour || strlen(o->layers[i].suffixes) != 3) continue;
        framebuffer *t = fb_new(w, h);
        if (!t) return PT_ERR_NOMEM;
        memcpy(t->rgb, o->layers[i].data, sizeof(float) * 3u * (size_t)w * (size_t)h);
        pt_status st = img_ocio_convert(oc, t, fbs, ws, d);
        p->owned[i] = t->rgb;
        t->rgb = NULL;
        fb_free(t);
        if (st != PT_OK) return st;
        p->layers[i].data = p->owned[i];
    }
    return PT_OK;
}

/* Layer names that make valid, distinct channel names. */
static int layers_valid(const img_write_opts *o)
{
    if (o->nlayers < 0 || (o->nlayers > 0 && !o->layers)) return 0;
    for (int i = 0; i < o->nlayers; i++) {
        const img_layer *l = &o->layers[i];
        size_t n = l->name ? strlen(l->name) : 0, ns = l->suffixes ? strlen(l->suffixes) : 0;
        if (n == 0 || n > 60 || ns < 1 || ns > 4 || !l->data) return 0;
        for (size_t k = 0; k < n; k++)
            if (!isalnum((unsigned char)l->name[k]) && l->name[k] != '_' && l->name[k] != '-') return 0;
        for (size_t k = 0; k < ns; k++)
            if (!isalpha((unsigned char)l->suffixes[k]) || strchr(l->suffixes + k + 1, l->suffixes[k])) return 0;
        for (int j = 0; j < i; j++)
            if (strcmp(o->layers[j].name, l->name) == 0) return 0;
    }
    return 1;
}

static pt_status plan_colour(const char *path, img_format fmt, const framebuffer *fb, const img_write_opts *o,
                             colour_plan *p, diag *d)
{
    memset(p, 0, sizeof *p);
    img_exr_primaries(IMG_PRIMARIES_REC709, p->xy);
    p->have_xy = 1;
    p->tag = IMG_PNG_TAG_SRGB;
    if (fmt == IMG_FMT_PNG && (!isfinite(o->exposure) || fabs(o->exposure) > 64.0)) {
        diag_error(d, "cannot write '%s': exposure %g stops is out of range (finite, at most 64 either way)", path,
               o->exposure);
        return PT_ERR_USAGE;
    }
    const int need_ocio = (fmt == IMG_FMT_EXR && (o->working_space || o->fb_space)) ||
                          (fmt == IMG_FMT_PNG && (o->display || o->view || o->look));
    const int scale = fmt == IMG_FMT_PNG && o->exposure != 0.0;
    if (!need_ocio && !scale) return PT_OK;

    const char *fbs = o->fb_space ? o->fb_space : IMG_OCIO_RENDER_SPACE;
    const char *ws = o->working_space ? o->working_space : fbs;
    img_ocio *oc = o->ocio, *owned = NULL;
    pt_status st = PT_OK;
    if (need_ocio && !oc) {
        st = img_ocio_open(o->ocio_config, &owned, d);
        if (st != PT_OK) return st;
        oc = owned;
    }
    /* Names first, so a typo fails before any pixel work. */
    if (need_ocio && fmt == IMG_FMT_EXR) st = img_ocio_check(oc, ws, NULL, NULL, NULL, d);
    if (need_ocio && st == PT_OK) st = img_ocio_check(oc, fbs, NULL, NULL, NULL, d);
    if (need_ocio && fmt == IMG_FMT_PNG && st == PT_OK)
        st = img_ocio_check(oc, NULL, o->display, o->view, o->look, d);
    const int convert = fmt == IMG_FMT_PNG || strcmp(fbs, ws) != 0;
    if (st == PT_OK && convert) {
        p->copy = fb_new(fb->width, fb->height);
        if (!p->copy) {
            diag_error(d, "cannot write '%s': out of memory", path);
            st = PT_ERR_NOMEM;
        } else {
            memcpy(p->copy->rgb, fb->rgb, sizeof(float) * 3u * (size_t)fb->width * (size_t)fb->height);
            p->copy->alpha = fb->alpha;
        }
    }
    if (st == PT_OK && !need_ocio) {
        /* Exposure alone on the plain sRGB path. */
        const float k = (float)exp2(o->exposure);
        const size_t n = 3u * (size_t)fb->width * (size_t)fb->height;
        for (size_t i = 0; i < n; i++) p->copy->rgb[i] *= k;
    } else if (st == PT_OK && fmt == IMG_FMT_EXR) {
        if (convert) st = img_ocio_convert(oc, p->copy, fbs, ws, d);
        if (convert && st == PT_OK && o->nlayers > 0) {
            st = convert_layers(oc, o, fb->width, fb->height, fbs, ws, p, d);
            if (st == PT_ERR_NOMEM) diag_error(d, "cannot write '%s': out of memory", path);
        }
        if (st == PT_OK) p->have_xy = img_ocio_chromaticities(oc, ws, p->xy, d);
    } else if (st == PT_OK) {
        st = img_ocio_apply(oc, p->copy, fbs, o->display, o->view, o->look, o->exposure, d);
        p->png_display = 1;
        switch (img_ocio_display_kind(oc, o->display, o->view)) {
        case IMG_DISPLAY_SRGB: p->tag = IMG_PNG_TAG_SRGB; break;
        case IMG_DISPLAY_REC1886: p->tag = IMG_PNG_TAG_REC1886; break;
        case IMG_DISPLAY_DATA: p->tag = IMG_PNG_TAG_NONE; break;
        default: {
            p->tag = IMG_PNG_TAG_NONE;
            src_loc none = {NULL, 0, 0};
            diag_report(d, DIAG_WARNING, none, NULL,
                        "'%s': display '%s' is neither sRGB nor Rec.1886; the PNG gets no colour chunks", path,
                        o->display ? o->display : img_ocio_default_display(oc));
            break;
        }
        }
    }
    img_ocio_close(owned);
    if (st != PT_OK) plan_free(p);
    return st;
}

pt_status img_write(const char *path, const framebuffer *fb, const img_write_opts *o, diag *d)
{
    img_write_opts defaults;
    if (!o) {
        img_default_write_opts(&defaults);
        o = &defaults;
    }
    if (!path || !*path) {
        diag_error(d, "cannot write image: empty output path");
        return PT_ERR_USAGE;
    }
    img_format fmt = img_format_from_path(path);
    if (fmt == IMG_FMT_UNKNOWN) {
        diag_error(d, "cannot write '%s': unknown image extension (expected .exr, .png or .pfm)", path);
        return PT_ERR_USAGE;
    }
    if (!valid_fb(fb)) {
        diag_error(d, "cannot write '%s': invalid framebuffer", path);
        return PT_ERR_USAGE;
    }
    if (fmt == IMG_FMT_EXR && (o->exr_compression < 0 || o->exr_compression > 2)) {
        diag_error(d, "cannot write '%s': unknown EXR compression %d (0 none, 1 zip, 2 piz)", path,
               o->exr_compression);
        return PT_ERR_USAGE;
    }
    if (o->nmeta < 0 || (o->nmeta > 0 && (!o->meta_keys || !o->meta_values))) {
        diag_error(d, "cannot write '%s': inconsistent metadata arguments", path);
        return PT_ERR_USAGE;
    }

    if (fmt == IMG_FMT_EXR && !layers_valid(o)) {
        diag_error(d, "cannot write '%s': bad EXR layer list (names: letters, digits, _ or -; 1 to 4 distinct channel letters)", path);
        return PT_ERR_USAGE;
    }

    colour_plan plan;
    pt_status cst = plan_colour(path, fmt, fb, o, &plan, d);
    if (cst != PT_OK) return cst;
    const framebuffer *out = plan.copy ? plan.copy : fb;

    char *tmp = temp_path_for(path);
    if (!tmp) {
        plan_free(&plan);
        diag_error(d, "cannot write '%s': out of memory", path);
        return PT_ERR_NOMEM;
    }
    int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno == EEXIST) {
        /* A stale temporary from an earlier process with the same pid. */
        unlink(tmp);
        fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    }
    if (fd < 0) {
        diag_error(d, "cannot write '%s': cannot create temporary file '%s': %s", path, tmp, strerror(errno));
        free(tmp);
        plan_free(&plan);
        return PT_ERR_IO;
    }

    pt_status st;
    switch (fmt) {
    case IMG_FMT_EXR: {
        img_write_opts eo = *o;
        if (plan.layers) eo.layers = plan.layers;
        st = img_exr_write_xy(fd, path, out, &eo, plan.have_xy ? plan.xy : NULL, d);
        break;
    }
    case IMG_FMT_PNG:
        st = plan.png_display ? img_png_write_display(fd, path, out, o, plan.tag, d) : img_png_write(fd, path, out, o, d);
        break;
    default: st = img_pfm_write(fd, path, fb, d); break;
    }
    plan_free(&plan);

    if (st == PT_OK && fsync(fd) != 0 && errno != EINVAL && errno != EROFS) {
        diag_error(d, "cannot write '%s': %s", path, strerror(errno));
        st = PT_ERR_IO;
    }
    if (close(fd) != 0 && st == PT_OK) {
        diag_error(d, "cannot write '%s': %s", path, strerror(errno));
        st = PT_ERR_IO;
    }
    if (st == PT_OK && rename(tmp, path) != 0) {
        diag_error(d, "cannot write '%s': cannot rename '%s' to it: %s", path, tmp, strerror(errno));
        st = PT_ERR_IO;
    }
    if (st != PT_OK) unlink(tmp);
    free(tmp);
    return st;
}

pt_status img_read(const char *path, int png_raw, framebuffer **out, diag *d)
{
    return img_read_limited(path, png_raw, 0, out, d);
}

pt_status img_read_limited(const char *path, int png_raw, uint64_t max_pixels, framebuffer **out, diag *d)
{
    if (max_pixels == 0 || max_pixels > IMG_MAX_PIXELS) max_pixels = IMG_MAX_PIXELS;
    if (!out) return PT_ERR_USAGE;
    *out = NULL;
    if (!path || !*path) {
        diag_error(d, "cannot read image: empty path");
        return PT_ERR_USAGE;
    }
    FILE *f = fopen(path, "rb");
    if (!f) {
        diag_error(d, "cannot read '%s': %s", path, strerror(errno));
        return PT_ERR_IO;
    }
    unsigned char magic[8] = {0};
    size_t n = fread(magic, 1, sizeof magic, f);
    int rerr = ferror(f);
    int saved = errno;
    fclose(f);
    if (rerr) {
        diag_error(d, "cannot read '%s': %s", path, strerror(saved));
        return PT_ERR_IO;
    }
    /* OpenEXR file layout: magic number 20000630 as a little-endian int. */
    static const unsigned char exr_magic[4] = {0x76, 0x2f, 0x31, 0x01};
    /* PNG specification, section 5.2: the 8-byte signature. */
    static const unsigned char png_magic[8] = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
    if (n >= 4 && memcmp(magic, exr_magic, 4) == 0) return img_exr_read(path, max_pixels, out, d);
    if (n >= 8 && memcmp(magic, png_magic, 8) == 0) return img_png_read(path, png_raw, max_pixels, out, d);
    if (n >= 3 && magic[0] == 'P' && (magic[1] == 'F' || magic[1] == 'f') &&
        (magic[2] == '\n' || magic[2] == '\r' || magic[2] == ' ' || magic[2] == '\t'))
        return img_pfm_read(path, max_pixels, out, d);
    if (n == 0)
        diag_error(d, "cannot read '%s': file is empty", path);
    else
        diag_error(d, "cannot read '%s': not an EXR, PNG or PFM file (unrecognized magic bytes)", path);
    return PT_ERR_IO;
}
