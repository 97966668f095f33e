/* test_shapes_hfield.c - height_field end to end (test_shapes runs these):
 * heights read from image files (PGM, PNG, GIF, TGA, TIFF, JPEG, PPM)
 * and from functions, checked at known points against the values given. */
#include "test_shapes.h"

/* ------------------------------------------------------------ height_field */

void test_height_field(void **st)
{
    (void)st;
    /* a 3x3 ramp rising with x: heights 0, 127, 254 (/255 * 65535/65536) */
    char path[] = "/tmp/test_shapes_hfXXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    unsigned char v[9] = {0, 127, 254, 0, 127, 254, 0, 127, 254};
    write_pgm(path, 3, 3, v);
    char src[512];
    snprintf(src, sizeof src, "height_field { pgm \"%s\" }", path);
    world w = build(src);
    const scene_object *o = w.s->objects[0];
    assert_int_equal(o->kind, SHAPE_HEIGHT_FIELD);
    assert_int_equal(o->u.height_field->width, 3);
    double top = 254 * 257 / 65536.0; /* 8-bit grey -> value * 257 */
    assert_near(o->u.height_field->heights[2], top, 1e-6);
    /* the surface is the plane y = x * top; normal (-top, 1, 0) */
    for (int i = 1; i < 10; i++) {
        double x = i / 10.0, z = 0.37;
        expect_hit(&w, v3(x, 5, z), v3(0, -1, 0), 5 - x * top, v3(-top, 1, 0), 1e-6, 1e-6);
    }
    /* a slanted ray */
    vec3 d = v3_norm(v3(1, -1, 0.1));
    accel_hit h;
    assert_true(hit(&w, v3(-0.5, 1.0, 0.2), d, &h));
    assert_near(h.p.y, h.p.x * top, 1e-6);
    geom_shape sh = shape_of(&w);
    assert_true(geom_shape_inside(&sh, v3(0.5, 0.1, 0.5)));
    assert_true(geom_shape_inside(&sh, v3(0.5, -10, 0.5)));
    assert_false(geom_shape_inside(&sh, v3(0.5, 0.9, 0.5)));
    assert_false(geom_shape_inside(&sh, v3(1.5, 0.1, 0.5)));
    geom_shape_release(&sh);
    done(&w);
    /* water_level raises the low part */
    snprintf(src, sizeof src, "height_field { pgm \"%s\" water_level 0.5 smooth }", path);
    w = build(src);
    expect_hit(&w, v3(0.2, 5, 0.5), v3(0, -1, 0), 4.5, v3(0, 1, 0), 1e-6, 1e-6);
    done(&w);
    unlink(path);
}

/* accel_crossings_cut: an opaque height field (a ridge along z, rising
 * from x = 0 to 0.5 and falling to x = 1, heights 0, 254/255, 0) gives
 * only its nearest crossing. A ray along +x at height 0.5 crosses it at
 * x = 0.25 and 0.75, then a glass sphere at 2.5 and 3.5: a walk that
 * stops on the height field gets what accel_crossings_skip gives it; one
 * that goes on past it is told to walk again (-1), and the full walk has
 * all four crossings. A walk whose `surface` says it reads no surface gets
 * the crossings without normals. */
typedef struct {
    double t[8];
    int n;
    int stop_at_field; /* stop on the height field's crossing */
} cut_log;

static int log_cut(void *ctx, const accel_hit *h)
{
    cut_log *l = ctx;
    if (l->n < 8) l->t[l->n] = h->t;
    l->n++;
    return !(l->stop_at_field && h->obj && h->obj->kind == SHAPE_HEIGHT_FIELD);
}

typedef struct {
    double t[8], len[8];
    int n, go_on;
} surface_log;

static int no_surface(void *ctx, const scene_object *obj, const scene_texture *tex)
{
    (void)ctx;
    (void)tex;
    assert_non_null(obj);
    return 0;
}

static int log_surface(void *ctx, const accel_hit *h)
{
    surface_log *l = ctx;
    if (l->n < 8) {
        l->t[l->n] = h->t;
        l->len[l->n] = v3_len(h->ng);
    }
    l->n++;
    return l->go_on;
}

void test_height_field_cut(void **st)
{
    (void)st;
    char path[] = "/tmp/test_shapes_hfcutXXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    unsigned char v[9] = {0, 254, 0, 0, 254, 0, 0, 254, 0};
    write_pgm(path, 3, 3, v);
    char src[768];
    snprintf(src, sizeof src,
             "height_field { pgm \"%s\" pigment { rgb 1 } }\n"
             "sphere { <3, 0.5, 0.5>, 0.5 pigment { rgbt <1, 1, 1, 0.5> } }\n",
             path);
    world w = build(src);
    double top = 254 * 257 / 65536.0, x0 = 0.5 * 0.5 / top;
    const double all[4] = {1 + x0, 2 - x0, 3.5, 4.5}; /* from x = -1 */
    vec3 o = v3(-1, 0.5, 0.5), d = v3(1, 0, 0);
    cut_log l = {{0}, 0, 1}, m = {{0}, 0, 1};
    assert_int_equal(accel_crossings_cut(w.a, o, d, 0.0, INFINITY, 1e-6, OBJ_NO_SHADOW, NULL, log_cut, &l), 1);
    assert_int_equal(accel_crossings_skip(w.a, o, d, 0.0, INFINITY, 1e-6, OBJ_NO_SHADOW, log_cut, &m), 1);
    assert_near(l.t[0], m.t[0], 0.0);
    assert_near(l.t[0], all[0], 1e-6);
    l = (cut_log){{0}, 0, 0};
    assert_int_equal(accel_crossings_cut(w.a, o, d, 0.0, INFINITY, 1e-6, OBJ_NO_SHADOW, NULL, log_cut, &l), -1);
    m = (cut_log){{0}, 0, 0};
    assert_int_equal(accel_crossings_skip(w.a, o, d, 0.0, INFINITY, 1e-6, OBJ_NO_SHADOW, log_cut, &m), 4);
    for (int i = 0; i < 4; i++) assert_near(m.t[i], all[i], 1e-6);
    /* a walk that does not read the surfaces gets the same crossings
     * without their normals; one that does gets unit normals */
    surface_log sl = {{0}, {0}, 0, 0};
    assert_int_equal(accel_crossings_cut(w.a, o, d, 0.0, INFINITY, 1e-6, OBJ_NO_SHADOW, no_surface, log_surface, &sl), 1);
    assert_near(sl.t[0], all[0], 1e-6);
    assert_near(sl.len[0], 0.0, 0.0);
    sl = (surface_log){{0}, {0}, 0, 1};
    o = v3(2, 0.5, 0.5);
    assert_int_equal(accel_crossings_cut(w.a, o, d, 0.0, INFINITY, 1e-6, OBJ_NO_SHADOW, no_surface, log_surface, &sl), 2);
    assert_near(sl.t[0], 0.5, 1e-9);
    assert_near(sl.t[1], 1.5, 1e-9);
    assert_near(sl.len[0], 0.0, 0.0);
    assert_near(sl.len[1], 0.0, 0.0);
    sl = (surface_log){{0}, {0}, 0, 1};
    assert_int_equal(accel_crossings_cut(w.a, o, d, 0.0, INFINITY, 1e-6, OBJ_NO_SHADOW, NULL, log_surface, &sl), 2);
    assert_near(sl.len[0], 1.0, 1e-12);
    assert_near(sl.len[1], 1.0, 1e-12);
    done(&w);
    unlink(path);
}

/* The crossing-by-crossing walk (a scene with an isosurface, whose
 * crossings are not collected in one traversal) honours `surface` too: an
 * isosurface sphere of radius 0.5 at the origin and a sphere of radius
 * 0.5 at x = 5, crossed along +x from x = -2 at 1.5, 2.5 (within the
 * isosurface's accuracy), 6.5 and 7.5. */
void test_crossings_walk_surface(void **st)
{
    (void)st;
    world w = build("isosurface { function { sqrt(x*x + y*y + z*z) - 0.5 } contained_by { box { -1, 1 } } "
                    "accuracy 1e-6 pigment { rgbf 0.5 } }\n"
                    "sphere { <5, 0, 0>, 0.5 pigment { rgbt <1, 1, 1, 0.5> } }\n");
    const double all[4] = {1.5, 2.5, 6.5, 7.5};
    vec3 o = v3(-2, 0, 0), d = v3(1, 0, 0);
    surface_log sl = {{0}, {0}, 0, 1};
    assert_int_equal(accel_crossings_cut(w.a, o, d, 0.0, INFINITY, 1e-6, OBJ_NO_SHADOW, no_surface, log_surface, &sl), 4);
    for (int i = 0; i < 4; i++) {
        assert_near(sl.t[i], all[i], 1e-5);
        assert_near(sl.len[i], 0.0, 0.0);
    }
    surface_log full = {{0}, {0}, 0, 1};
    assert_int_equal(accel_crossings_cut(w.a, o, d, 0.0, INFINITY, 1e-6, OBJ_NO_SHADOW, NULL, log_surface, &full), 4);
    for (int i = 0; i < 4; i++) {
        assert_near(full.t[i], sl.t[i], 0.0);
        assert_near(full.len[i], 1.0, 1e-12);
    }
    done(&w);
}

/* A minimal GIF (no palette, 8-bit LZW codes written as literals of 9 bits). */
static void write_gif(const char *path, int w, int h, const unsigned char *px)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    unsigned char hdr[13] = {'G', 'I', 'F', '8', '9', 'a', (unsigned char)w, 0, (unsigned char)h, 0, 0x07, 0, 0};
    fwrite(hdr, 1, 13, f);
    unsigned char id[10] = {0x2C, 0, 0, 0, 0, (unsigned char)w, 0, (unsigned char)h, 0, 0};
    fwrite(id, 1, 10, f);
    fputc(8, f);
    unsigned char data[256];
    int nd = 0, nbits = 0;
    unsigned long acc = 0;
    int ncodes = w * h + 2;
    for (int i = 0; i < ncodes; i++) {
        int code = i == 0 ? 256 : (i == ncodes - 1 ? 257 : px[i - 1]);
        acc |= (unsigned long)code << nbits;
        nbits += 9;
        while (nbits >= 8) {
            data[nd++] = (unsigned char)(acc & 255);
            acc >>= 8;
            nbits -= 8;
        }
    }
    if (nbits > 0) data[nd++] = (unsigned char)acc;
    fputc(nd, f);
    fwrite(data, 1, (size_t)nd, f);
    fputc(0, f);
    fputc(0x3B, f);
    fclose(f);
}

void test_height_field_gif(void **st)
{
    (void)st;
    unsigned char px[8] = {0, 1, 2, 3, 4, 5, 6, 7};
    /* a directory of its own: concurrent runs (ctest -j, two checkouts) must
     * not share the files */
    char dir[] = "/tmp/test_shapes_gifXXXXXX";
    assert_non_null(mkdtemp(dir));
    char gif[64], pot[64];
    snprintf(gif, sizeof gif, "%s/hf.gif", dir);
    snprintf(pot, sizeof pot, "%s/hf.pot", dir);
    write_gif(gif, 4, 2, px);
    write_gif(pot, 4, 2, px);
    char src[256];
    snprintf(src, sizeof src, "height_field { gif \"%s\" }", gif);
    world w = build(src);
    const scene_height_field *hf = w.s->objects[0]->u.height_field;
    assert_int_equal(hf->width, 4);
    assert_int_equal(hf->height, 2);
    /* map row 0 is the image's bottom row */
    for (int x = 0; x < 4; x++) {
        assert_near(hf->heights[x] * 65536.0, (4 + x) * 256.0, 1e-3);
        assert_near(hf->heights[4 + x] * 65536.0, x * 256.0, 1e-3);
    }
    done(&w);
    snprintf(src, sizeof src, "height_field { pot \"%s\" }", pot);
    w = build(src);
    hf = w.s->objects[0]->u.height_field;
    assert_int_equal(hf->width, 2);
    assert_near(hf->heights[0] * 65536.0, 4 * 256 + 6, 1e-3);
    assert_near(hf->heights[1] * 65536.0, 5 * 256 + 7, 1e-3);
    assert_near(hf->heights[2] * 65536.0, 0 * 256 + 2, 1e-3);
    assert_near(hf->heights[3] * 65536.0, 1 * 256 + 3, 1e-3);
    done(&w);
    unlink(gif);
    unlink(pot);
    rmdir(dir);
}

/* the distribution's plasma3.png is a palette image: heights = index * 256 */
void test_height_field_png(void **st)
{
    (void)st;
    if (access("/usr/share/povray-3.7/include/plasma3.png", R_OK) != 0) skip();
    world w = build("height_field { png \"plasma3.png\" smooth }");
    const scene_height_field *hf = w.s->objects[0]->u.height_field;
    assert_int_equal(hf->width, 100);
    assert_int_equal(hf->height, 100);
    for (int i = 0; i < 100 * 100; i++) {
        double v = hf->heights[i] * 65536.0;
        assert_near(v, 256.0 * floor(v / 256.0 + 0.5), 1e-3);
    }
    /* vertical rays hit where the grid interpolates */
    for (int i = 0; i < 20; i++) {
        double x = (i + 0.5) / 20.0, z = 0.5;
        accel_hit h;
        assert_true(hit(&w, v3(x, 5, z), v3(0, -1, 0), &h));
        assert_true(h.p.y >= 0.0 && h.p.y <= 1.0);
        assert_true(h.ns.y > 0.0);
    }
    done(&w);
}

/* ------------------------------------------------------------ image formats */

/* A 4x3 image (not square: catches transposed rows) of 16-bit heights, the
 * same data in every format. */
enum { FW = 4, FH = 3 };
static const unsigned char fmt_grey[FH][FW] = {{0, 40, 80, 120}, {160, 200, 240, 255}, {17, 33, 99, 201}};

static void write_bytes(const char *path, const void *b, size_t n)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(b, 1, n, f), n);
    fclose(f);
}

/* TGA: 8-bit grey (type 3, or 11 = RLE) or 24-bit BGR (type 2) with red =
 * grey, green = 255 - grey; rows bottom-up unless `top` */
static size_t make_tga(unsigned char *b, int type, int top)
{
    int bits = (type & 7) == 2 ? 24 : 8, bpp = bits / 8;
    memset(b, 0, 18);
    b[2] = (unsigned char)type;
    b[12] = FW; b[14] = FH; b[16] = (unsigned char)bits; b[17] = top ? 0x20 : 0;
    size_t n = 18;
    for (int r = 0; r < FH; r++) {
        int y = top ? r : FH - 1 - r;
        if (type & 8) {
            /* a run packet of one pixel, then a raw packet of three */
            b[n++] = 0x80;
            b[n++] = fmt_grey[y][0];
            b[n++] = 2;
            for (int x = 1; x < FW; x++) b[n++] = fmt_grey[y][x];
            continue;
        }
        for (int x = 0; x < FW; x++) {
            unsigned char g = fmt_grey[y][x];
            if (bpp == 1) {
                b[n++] = g;
            } else {
                b[n++] = 7; /* blue */
                b[n++] = (unsigned char)(255 - g);
                b[n++] = g;
            }
        }
    }
    return n;
}

static void write_tiff(const char *path, int bits, int spp)
{
    TIFF *t = TIFFOpen(path, "w");
    assert_non_null(t);
    TIFFSetField(t, TIFFTAG_IMAGEWIDTH, FW);
    TIFFSetField(t, TIFFTAG_IMAGELENGTH, FH);
    TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, bits);
    TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, spp);
    TIFFSetField(t, TIFFTAG_PHOTOMETRIC, spp == 1 ? PHOTOMETRIC_MINISBLACK : PHOTOMETRIC_RGB);
    TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
    TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, 1);
    for (int y = 0; y < FH; y++) {
        unsigned short row16[FW];
        unsigned char row8[FW * 3];
        for (int x = 0; x < FW; x++) {
            row16[x] = (unsigned short)(fmt_grey[y][x] * 257 + (x == 1 ? 3 : 0)); /* a value 8 bits cannot hold */
            row8[x * spp] = fmt_grey[y][x];
            if (spp == 3) {
                row8[x * 3 + 1] = (unsigned char)(255 - fmt_grey[y][x]);
                row8[x * 3 + 2] = 7;
            }
        }
        assert_true(TIFFWriteScanline(t, bits == 16 ? (void *)row16 : (void *)row8, (uint32_t)y, 0) >= 0);
    }
    TIFFClose(t);
}

static void write_jpeg(const char *path)
{
    /* an 8x8 block per height (quality 100): each block's flat grey survives */
    enum { S = 8 };
    unsigned char img[FH * S][FW * S];
    for (int y = 0; y < FH * S; y++)
        for (int x = 0; x < FW * S; x++) img[y][x] = fmt_grey[y / S][x / S];
    struct jpeg_compress_struct c;
    struct jpeg_error_mgr e;
    c.err = jpeg_std_error(&e);
    jpeg_create_compress(&c);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    jpeg_stdio_dest(&c, f);
    c.image_width = FW * S;
    c.image_height = FH * S;
    c.input_components = 1;
    c.in_color_space = JCS_GRAYSCALE;
    jpeg_set_defaults(&c);
    jpeg_set_quality(&c, 100, TRUE);
    jpeg_start_compress(&c, TRUE);
    while (c.next_scanline < c.image_height) {
        JSAMPROW r = img[c.next_scanline];
        jpeg_write_scanlines(&c, &r, 1);
    }
    jpeg_finish_compress(&c);
    jpeg_destroy_compress(&c);
    fclose(f);
}

/* expected 16-bit height of pixel (x, y): grey * 257, or POV-Ray's 8-bit
 * colour rule red * 256 + green */
static void check_hf_values(const char *path, int colour, int tol, int scale)
{
    sdl_hf_image im;
    char why[256];
    int r = sdl_hf_read(path, 0, &im, why, sizeof why);
    if (r != SDL_HF_OK) fail_msg("%s: %s", path, why);
    assert_int_equal(im.width, FW * scale);
    assert_int_equal(im.height, FH * scale);
    for (int y = 0; y < FH; y++)
        for (int x = 0; x < FW; x++) {
            int g = fmt_grey[y][x];
            int want = colour ? g * 256 + (255 - g) : g * 257;
            int got = im.values[(size_t)(y * scale + scale / 2) * im.width + (size_t)(x * scale + scale / 2)];
            if (abs(got - want) > tol) fail_msg("%s: (%d,%d) height %d, expected %d", path, x, y, got, want);
        }
    free(im.values);
}

void test_height_field_formats(void **st)
{
    (void)st;
    char dir[] = "/tmp/test_shapes_fmtXXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[512];
    unsigned char b[4096];
    size_t n;
    /* TGA: grey, grey RLE, 24-bit colour, top-down and bottom-up */
    snprintf(path, sizeof path, "%s/g.tga", dir);
    n = make_tga(b, 3, 0);
    write_bytes(path, b, n);
    check_hf_values(path, 0, 0, 1);
    n = make_tga(b, 3, 1);
    write_bytes(path, b, n);
    check_hf_values(path, 0, 0, 1);
    n = make_tga(b, 11, 0);
    write_bytes(path, b, n);
    check_hf_values(path, 0, 0, 1);
    n = make_tga(b, 2, 1);
    write_bytes(path, b, n);
    check_hf_values(path, 1, 0, 1);
    /* PPM (binary colour) */
    snprintf(path, sizeof path, "%s/c.ppm", dir);
    n = (size_t)sprintf((char *)b, "P6\n%d %d\n255\n", FW, FH);
    for (int y = 0; y < FH; y++)
        for (int x = 0; x < FW; x++) {
            b[n++] = fmt_grey[y][x];
            b[n++] = (unsigned char)(255 - fmt_grey[y][x]);
            b[n++] = 7;
        }
    write_bytes(path, b, n);
    check_hf_values(path, 1, 0, 1);
    /* TIFF: 8-bit grey, 8-bit RGB, 16-bit grey (all 16 bits kept) */
    snprintf(path, sizeof path, "%s/g8.tif", dir);
    write_tiff(path, 8, 1);
    check_hf_values(path, 0, 0, 1);
    snprintf(path, sizeof path, "%s/c8.tif", dir);
    write_tiff(path, 8, 3);
    check_hf_values(path, 1, 0, 1);
    snprintf(path, sizeof path, "%s/g16.tif", dir);
    write_tiff(path, 16, 1);
    sdl_hf_image im;
    char why[256];
    assert_int_equal(sdl_hf_read(path, 0, &im, why, sizeof why), SDL_HF_OK);
    assert_int_equal(im.values[1], fmt_grey[0][1] * 257 + 3);
    free(im.values);
    /* JPEG: lossy; flat 8x8 blocks at quality 100 come back within 1 code */
    snprintf(path, sizeof path, "%s/g.jpg", dir);
    write_jpeg(path);
    check_hf_values(path, 0, 257, 8);
    /* huge declared sizes are refused before allocating: a TGA of 65535^2
     * pixels in 18 bytes, a PGM of 16000^2 in a few */
    snprintf(path, sizeof path, "%s/huge.tga", dir);
    unsigned char hdr[18] = {0, 0, 3, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xff, 0xff, 0xff, 0xff, 8, 0};
    write_bytes(path, hdr, sizeof hdr);
    assert_int_equal(sdl_hf_read(path, 0, &im, why, sizeof why), SDL_HF_ERROR);
    assert_null(im.values);
    snprintf(path, sizeof path, "%s/huge.pgm", dir);
    write_bytes(path, "P5 16000 16000 255\n\x01\x02", 21);
    assert_int_equal(sdl_hf_read(path, 0, &im, why, sizeof why), SDL_HF_ERROR);
    assert_non_null(strstr(why, "ends early"));
    /* the one reader takes bytes too */
    sdl_img raw;
    n = make_tga(b, 2, 0);
    assert_int_equal(sdl_img_read(NULL, b, n, 0, &raw, why, sizeof why), SDL_IMG_OK);
    assert_int_equal(raw.width, FW);
    assert_int_equal(raw.rgba[(size_t)(2 * FW + 3) * 4], fmt_grey[2][3] * 257);
    sdl_img_free(&raw);
    assert_int_equal(sdl_img_read(NULL, b, 17, 0, &raw, why, sizeof why), SDL_IMG_UNSUPPORTED);
    const char *names[] = {"g.tga", "c.ppm", "g8.tif", "c8.tif", "g16.tif", "g.jpg", "huge.tga", "huge.pgm"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        unlink(path);
    }
    rmdir(dir);
}

/* height_field { function W, H { f } }: f at x = j / (W - 1), y = i / (H - 1)
 * into image row i (row 0 the top, i.e. the far edge z = 1), 16-bit
 * (POV-Ray's Make_Pattern_Image); checked against POV-Ray's image by
 * `partray crosscheck` (docs/shapes.md) */
void test_height_field_function(void **st)
{
    (void)st;
    world w = build("height_field { function 5, 3 { 0.1 + 0.5 * x * x + 0.3 * y } }");
    assert_int_equal(w.s->objects[0]->kind, SHAPE_HEIGHT_FIELD);
    const scene_height_field *hf = w.s->objects[0]->u.height_field;
    assert_int_equal(hf->width, 5);
    assert_int_equal(hf->height, 3);
    for (int z = 0; z < 3; z++)
        for (int x = 0; x < 5; x++) {
            double fx = x / 4.0, fy = (2 - z) / 2.0;
            double want = (int)((0.1 + 0.5 * fx * fx + 0.3 * fy) * 65535.0 + 0.5) / 65536.0;
            assert_near(hf->heights[z * 5 + x], want, 1e-6);
        }
    /* a hit from above on the unit-square height field 1e-5 from corner
     * (x=1, z=0), where it is f(1, 1); slope there ~1 */
    accel_hit h;
    assert_true(hit(&w, v3(1 - 1e-5, 5, 1e-5), v3(0, -1, 0), &h));
    assert_near(5 - h.t, (int)(0.9 * 65535.0 + 0.5) / 65536.0, 3e-5);
    done(&w);
}

