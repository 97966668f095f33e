/* test_reliability.c - the partray command under limits and failures:
 * every parser limit is settable and stops with a located error and exit 1;
 * image sizes beyond the writers' limits are usage errors (exit 2) found
 * before parsing; a failed write (file size limit, unwritable directory)
 * is exit 3 and leaves neither a partial file under the final name nor a
 * temporary file, and keeps an earlier output intact; SIGTERM stops a render
 * like SIGINT (partial file, exit 143); an interrupt writes every output's
 * partial file and never touches the final names. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include "img_io.h"

static char tmpdir[256];
static char out_text[65536];

/* Run a shell command, capture stdout+stderr into out_text, return exit code. */
static int run_capture(const char *cmd)
{
    char full[4096];
    snprintf(full, sizeof full, "%s 2>&1", cmd);
    FILE *p = popen(full, "r");
    if (!p) return -1;
    size_t n = fread(out_text, 1, sizeof out_text - 1, p);
    out_text[n] = 0;
    int rc = pclose(p);
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : 128 + WTERMSIG(rc);
}

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static int exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

static long file_size(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0 ? (long)sb.st_size : -1;
}

/* Number of files in dir whose name contains ".tmp-" (img_write's temporaries). */
static int temp_files_in(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d) return -1;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)))
        if (strstr(e->d_name, ".tmp-")) n++;
    closedir(d);
    return n;
}

/* Write `text` as tmpdir/NAME and `partray render` it with `args`; returns
 * the exit code, output in out_text. */
static int render(const char *name, const char *text, const char *args)
{
    char scene[512], cmd[3072];
    snprintf(scene, sizeof scene, "%s/%s", tmpdir, name);
    if (text) write_file(scene, text);
    snprintf(cmd, sizeof cmd, "cd '%s' && '%s' render '%s' --size 8x8 --quiet -o '%s/out.png' %s", tmpdir,
             PARTRAY_BIN, name, tmpdir, args);
    int rc = run_capture(cmd);
    printf("exit %d: %s", rc, out_text);
    return rc;
}

/* The render of `text` with `args` fails with `code` and `needle` in its
 * messages, and leaves no output. */
static void expect(const char *name, const char *text, const char *args, int code, const char *needle)
{
    char out[512];
    snprintf(out, sizeof out, "%s/out.png", tmpdir);
    remove(out);
    assert_int_equal(render(name, text, args), code);
    assert_non_null(strstr(out_text, needle));
    assert_false(exists(out));
    assert_int_equal(temp_files_in(tmpdir), 0);
}

static const char camera[] = "camera { location <0, 0, -5> look_at 0 }\n";

/* ------------------------------------------------------------ limits */

static void test_loop_limit(void **st)
{
    (void)st;
    char text[512];
    snprintf(text, sizeof text, "%s#declare I = 0;\n#while (I < 100)\n  #declare I = I + 1;\n#end\n", camera);
    expect("loop.pov", text, "--max-loop 10", 1, "loop.pov:3:1: error: #while loop exceeded 10 iterations");
    assert_int_equal(render("loop.pov", NULL, "--max-loop 100"), 0);
}

static void test_include_depth_limit(void **st)
{
    (void)st;
    char inc[512];
    snprintf(inc, sizeof inc, "%s/rec.inc", tmpdir);
    write_file(inc, "#include \"rec.inc\"\n");
    expect("inc.pov", "#include \"rec.inc\"\n", "--max-include-depth 3", 1,
           "rec.inc:1:1: error: includes nested more than 3 deep");
    assert_non_null(strstr(out_text, "included from "));
    assert_non_null(strstr(out_text, "inc.pov:1:1"));
}

static void test_macro_depth_limit(void **st)
{
    (void)st;
    expect("macro.pov", "#macro R(N) R(N + 1) #end\nR(0)\n", "--max-macro-depth 5", 1,
           "macro.pov:1:13: error: macro calls nested more than 5 deep");
    assert_non_null(strstr(out_text, "in macro R called from "));
}

static void test_token_limit(void **st)
{
    (void)st;
    /* 3 nested loops of 100: a million passes, far more than 5000 tokens */
    const char *text = "#declare I = 0;\n"
                       "#while (I < 100) #declare J = 0;\n"
                       "  #while (J < 100) #declare K = 0;\n"
                       "    #while (K < 100) #declare K = K + 1; #end\n"
                       "  #declare J = J + 1; #end\n"
                       "#declare I = I + 1; #end\n";
    expect("tokens.pov", text, "--max-tokens 5000", 1,
           "error: scene reads more than 5000 tokens, loop repeats and macro calls included (--max-tokens)");
    assert_non_null(strstr(out_text, "tokens.pov:4:"));
}

static void test_string_limit(void **st)
{
    (void)st;
    const char *text = "#declare S = \"0123456789\";\n"
                       "#while (1) #declare S = concat(S, S); #end\n";
    expect("string.pov", text, "--max-string 100 --max-loop 1000", 1,
           "error: concat makes a string of 160 bytes, longer than the limit of 100 (--max-string)");
    assert_non_null(strstr(out_text, "string.pov:2:"));
}

static void test_array_limit(void **st)
{
    (void)st;
    char text[512];
    snprintf(text, sizeof text, "%s#declare A = array[100][100];\n", camera);
    expect("array.pov", text, "--max-array 1000", 1, "array.pov:2:");
    assert_non_null(strstr(out_text, "error: array has more than 1000 elements (the limit, --max-array)"));
    assert_int_equal(render("array.pov", NULL, "--max-array 10000"), 0);
}

static void test_mesh_memory_limit(void **st)
{
    (void)st;
    char text[512];
    /* a million vertices: 11 MiB, more than a 4 MiB limit; refused at the count */
    snprintf(text, sizeof text,
             "%smesh2 {\n  vertex_vectors { 1000000, <0,0,0>, <1,0,0>, <0,1,0> }\n  face_indices { 1, <0,1,2> }\n}\n",
             camera);
    expect("mesh.pov", text, "--max-memory 4", 1,
           "mesh.pov:3:20: error: vertex_vectors with 1000000 entries needs 12 MiB, more than the parser's memory limit of 4 MiB (--max-memory)");
    /* far beyond any machine's memory with the default limit */
    snprintf(text, sizeof text,
             "%smesh2 {\n  vertex_vectors { 1e14, <0,0,0> }\n  face_indices { 1, <0,0,0> }\n}\n", camera);
    expect("mesh.pov", text, "", 1, "mesh.pov:3:20: error: vertex_vectors with 100000000000000 entries needs");
    assert_non_null(strstr(out_text, "more than the parser's memory limit of"));
}

static void test_image_size_limit(void **st)
{
    (void)st;
    char text[256];
    snprintf(text, sizeof text, "%ssphere { 0, 1 pigment { rgb 1 } }\n", camera);
    /* +W/+H bypass --size's own check: the side limit */
    expect("size.pov", text, "+W70000 +H2", 2, "partray render: image size 70000x2: a side is larger than 65536 pixels");
    /* sides within the limit, too many pixels for the writers */
    expect("size.pov", text, "--size 20000x20000", 2,
           "partray render: image size 20000x20000: 400000000 pixels, more than the 268435456 an image may have");
    /* refused before the scene is read: a broken scene does not matter */
    expect("size_bad.pov", "sphere {", "--size 20000x20000", 2, "400000000 pixels");
    /* --max-image-pixels lowers the limit for the image rendered ... */
    expect("size.pov", text, "--size 64x64 --max-image-pixels 4000", 2,
           "image size 64x64: 4096 pixels, more than the 4000 an image may have (--max-image-pixels)");
    assert_int_equal(render("size.pov", text, "--size 64x64 --max-image-pixels 4096"), 0);
}


/* ------------------------------------------------------------ image files */

/* A w x h framebuffer written as `name` in tmpdir (format by extension,
 * EXR uncompressed); returns the path in `path`. */
static void write_image(const char *name, int w, int h, char *path, size_t cap)
{
    snprintf(path, cap, "%s/%s", tmpdir, name);
    framebuffer *fb = fb_new(w, h);
    assert_non_null(fb);
    for (size_t i = 0; i < (size_t)w * (size_t)h * 3u; i++) fb->rgb[i] = (float)(i % 7) / 7.0f;
    img_write_opts o;
    img_default_write_opts(&o);
    o.exr_compression = 0;
    assert_int_equal(img_write(path, fb, &o, NULL), PT_OK);
    fb_free(fb);
}

static unsigned char file_bytes[1 << 20];

static size_t read_bytes(const char *path)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    size_t n = fread(file_bytes, 1, sizeof file_bytes, f);
    fclose(f);
    return n;
}

static void write_bytes(const char *path, size_t n)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(file_bytes, 1, n, f), n);
    fclose(f);
}

/* img_read's message for `path` (which must fail with PT_ERR_IO). */
static void expect_read_error(const char *path, uint64_t max_pixels, const char *needle)
{
    diag *d = diag_new();
    framebuffer *fb = NULL;
    assert_int_equal(img_read_limited(path, 0, max_pixels, &fb, d), PT_ERR_IO);
    assert_null(fb);
    assert_true(diag_errors(d) >= 1);
    char *m = diag_format(diag_get(d, 0));
    printf("  %s\n", m);
    assert_non_null(strstr(m, needle));
    free(m);
    diag_free(d);
}

/* A file that declares a huge image in a few bytes is refused before the
 * framebuffer is allocated: the checks read only the file's structure
 * (core/imgcheck.h, the EXR offset table), so the error names what is
 * missing rather than running out of memory (a 16384 x 16384 framebuffer
 * is 3 GiB). The pixel limit is settable for io/ (img_read_limited). */
static void test_image_file_limits(void **st)
{
    (void)st;
    char png[512], exr[512], path[600];
    write_image("small.png", 16, 16, png, sizeof png);
    write_image("small.exr", 64, 64, exr, sizeof exr);

    /* the settable limit: 256 pixels pass at 256, not at 255 */
    framebuffer *fb = NULL;
    assert_int_equal(img_read_limited(png, 0, 256, &fb, NULL), PT_OK);
    fb_free(fb);
    expect_read_error(png, 255, "image size 16x16 exceeds the limit (65536 per side, 255 pixels in all)");
    expect_read_error(exr, 4095, "image size 64x64 exceeds the limit (65536 per side, 4095 pixels in all)");

    /* PNG whose IHDR says 16384 x 16384 (2^28 pixels, within the hard
     * limit) over the 16 x 16 image's data */
    size_t n = read_bytes(png);
    assert_true(n > 33 && memcmp(file_bytes + 12, "IHDR", 4) == 0);
    static const unsigned char big[8] = {0, 0, 0x40, 0, 0, 0, 0x40, 0};
    memcpy(file_bytes + 16, big, 8);
    snprintf(path, sizeof path, "%s/huge.png", tmpdir);
    write_bytes(path, n);
    expect_read_error(path, 0, "declares 16384x16384 pixels (805306368 bytes of image data)");
    /* the same cut inside its image data */
    write_bytes(path, n - 20);
    expect_read_error(path, 0, "the file is truncated: chunk 'IDAT' at byte");

    /* EXR cut in half: its last scanline chunks lie beyond the end */
    n = read_bytes(exr);
    snprintf(path, sizeof path, "%s/cut.exr", tmpdir);
    write_bytes(path, n / 2);
    expect_read_error(path, 0, "the file is truncated");
    /* EXR whose data window says 16384 x 16384 */
    n = read_bytes(exr);
    unsigned char *dw = NULL;
    for (size_t i = 0; i + 17 <= n && !dw; i++)
        if (memcmp(file_bytes + i, "dataWindow\0box2i\0", 17) == 0) dw = file_bytes + i;
    assert_non_null(dw);
    static const unsigned char box[16] = {0, 0, 0, 0, 0, 0, 0, 0, 0xff, 0x3f, 0, 0, 0xff, 0x3f, 0, 0};
    memcpy(dw + 17 + 4, box, 16);
    snprintf(path, sizeof path, "%s/huge.exr", tmpdir);
    write_bytes(path, n);
    expect_read_error(path, 0, "the file is truncated or corrupt: chunk");

    /* The parser's reader (parser/sdl_imgread.c) checks PNGs the same way:
     * an image_map of the huge PNG is refused with the reason (a warning:
     * the image is transparent, as for a missing file). */
    char text[1024];
    snprintf(text, sizeof text,
             "%slight_source { <0, 5, -5> rgb 1 }\n"
             "plane { z, 1 pigment { image_map { png \"huge.png\" } } }\n", camera);
    n = read_bytes(png);
    memcpy(file_bytes + 16, big, 8);
    snprintf(path, sizeof path, "%s/huge.png", tmpdir);
    write_bytes(path, n);
    char cmd[2048];
    snprintf(path, sizeof path, "%s/imgmap.pov", tmpdir);
    write_file(path, text);
    snprintf(cmd, sizeof cmd, "cd '%s' && '%s' parse imgmap.pov", tmpdir, PARTRAY_BIN);
    assert_int_equal(run_capture(cmd), 0);
    printf("%s", out_text);
    assert_non_null(strstr(out_text, "imgmap.pov:3:"));
    assert_non_null(strstr(out_text, "the file is truncated or corrupt: it declares 16384x16384 pixels"));
}

/* --max-image-pixels also bounds the images a scene reads: a 16x16
 * PNG height_field passes at 256 pixels and is a located error at 255. */
static void test_read_image_limit(void **st)
{
    (void)st;
    char png[512], text[512];
    write_image("hf16.png", 16, 16, png, sizeof png);
    snprintf(text, sizeof text, "%slight_source { <0, 5, -5> rgb 1 }\nheight_field { png \"hf16.png\" }\n", camera);
    assert_int_equal(render("hf.pov", text, "--max-image-pixels 256"), 0);
    /* exit 1: a file the scene reads is refused, a scene error like a missing one */
    expect("hf.pov", text, "--max-image-pixels 255", 1,
           "hf.pov:3:1: error: height_field image 'hf16.png': image size 16x16 exceeds the limit (65536 per side, 255 pixels in all)");
}

static void test_limit_usage(void **st)
{
    (void)st;
    expect("u.pov", camera, "--max-tokens 0", 2, "--max-tokens wants a positive integer");
    expect("u.pov", camera, "--max-memory lots", 2, "--max-memory wants a positive integer (MiB)");
    expect("u.pov", camera, "--max-string", 2, "option '--max-string' needs a value");
    expect("u.pov", camera, "--max-array -3", 2, "--max-array wants a positive integer");
}

/* ------------------------------------------------------------ OpenCL */

/* No OpenCL platform at all (the ICD loader finds no vendor): particle GI
 * stops with a clear error naming the way out, exit 1, no output. The
 * kernel build log on a bad kernel and an unknown device are checked in
 * tests/test_gi.c. */
static void test_opencl_no_platform(void **st)
{
    (void)st;
    char text[512], args[256];
    snprintf(text, sizeof text, "%slight_source { <2, 4, -3> rgb 1 }\nplane { y, -1 pigment { rgb 0.8 } }\n"
             "sphere { 0, 1 pigment { rgb <0.8, 0.3, 0.2> } }\n", camera);
    snprintf(args, sizeof args, "--gi particle");
    setenv("OCL_ICD_VENDORS", "/nonexistent", 1);
    expect("ocl.pov", text, args, 1, "error: OpenCL: no platform found");
    unsetenv("OCL_ICD_VENDORS");
    assert_non_null(strstr(out_text, "pocl-opencl-icd"));
}

/* Out of device memory (PoCL): the particle GI's buffers beyond the
 * memory it may use (--cl-max-memory, else the device's global memory and
 * largest allocation) are a clear error before PoCL is asked, exit 1, no
 * output. */
static void test_opencl_out_of_memory(void **st)
{
    (void)st;
    char text[512];
    snprintf(text, sizeof text, "%slight_source { <2, 4, -3> rgb 1 }\nplane { y, -1 pigment { rgb 0.8 } }\n"
             "sphere { 0, 1 pigment { rgb <0.8, 0.3, 0.2> } }\n", camera);
    expect("oom.pov", text, "--gi particle --particles 20000 --cl-max-memory 1", 1,
           "error: OpenCL: out of device memory: particle GI needs");
    assert_non_null(strstr(out_text, "than the 1.0 MiB it may use (CL_DEVICE_GLOBAL_MEM_SIZE or --cl-max-memory)"));
    expect("oom.pov", text, "--gi particle --cl-max-memory 0", 2, "--cl-max-memory wants a positive integer (MiB)");
}

/* ------------------------------------------------------------ outputs */

static const char slow_scene[] =
    "camera { location <0, 3, -6> look_at 0 }\n"
    "light_source { <0, 5, 0> rgb 1 area_light 2*x, 2*z, 16, 16 jitter }\n"
    "plane { y, 0 pigment { rgb 1 } }\n"
    "sphere { <0, 1, 0>, 1 pigment { rgb 0.5 } }\n";

static void test_write_fails_file_size_limit(void **st)
{
    (void)st;
    char scene[512], out[512], cmd[2048];
    snprintf(scene, sizeof scene, "%s/fsize.pov", tmpdir);
    snprintf(out, sizeof out, "%s/fsize.pfm", tmpdir);
    write_file(scene, "camera { location -5*z look_at 0 } sphere { 0, 1 pigment { rgb 1 } } light_source { -5*z, 1 }\n");
    /* an earlier good render under the final name */
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 64x64 --quiet -o '%s'", PARTRAY_BIN, scene, out);
    assert_int_equal(run_capture(cmd), 0);
    long before = file_size(out);
    assert_int_equal(before, 64 * 64 * 12 + (long)strlen("PF\n64 64\n-1.0\n"));
    /* a PFM of 128x128 is 196 KiB; the shell allows 8 blocks (4 KiB with dash, 8 KiB with bash) */
    snprintf(cmd, sizeof cmd, "ulimit -f 8 && exec '%s' render '%s' --size 128x128 --quiet -o '%s'", PARTRAY_BIN, scene,
             out);
    int rc = run_capture(cmd);
    printf("exit %d: %s", rc, out_text);
    assert_int_equal(rc, 3);
    assert_non_null(strstr(out_text, "fsize.pfm"));
    assert_non_null(strstr(out_text, "File too large"));
    assert_int_equal(file_size(out), before); /* the earlier file is untouched */
    assert_int_equal(temp_files_in(tmpdir), 0);
}

static void test_write_fails_unwritable_dir(void **st)
{
    (void)st;
    char scene[512], dir[512], out[640], cmd[2048];
    snprintf(scene, sizeof scene, "%s/ro.pov", tmpdir);
    write_file(scene, "camera { location -5*z look_at 0 } sphere { 0, 1 pigment { rgb 1 } } light_source { -5*z, 1 }\n");
    /* a path through a regular file: cannot be created, even by root */
    snprintf(out, sizeof out, "%s/ro.pov/out.exr", tmpdir);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 16x16 --quiet -o '%s'", PARTRAY_BIN, scene, out);
    int rc = run_capture(cmd);
    printf("exit %d: %s", rc, out_text);
    assert_int_equal(rc, 3);
    assert_non_null(strstr(out_text, "cannot write"));
    /* a read-only directory (root may write anyway: then only the above counts) */
    snprintf(dir, sizeof dir, "%s/readonly", tmpdir);
    assert_int_equal(mkdir(dir, 0555), 0);
    snprintf(out, sizeof out, "%s/out.png", dir);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 16x16 --quiet -o '%s'", PARTRAY_BIN, scene, out);
    rc = run_capture(cmd);
    printf("exit %d: %s", rc, out_text);
    if (geteuid() != 0) {
        assert_int_equal(rc, 3);
        assert_non_null(strstr(out_text, "Permission denied"));
        assert_false(exists(out));
    }
    assert_int_equal(temp_files_in(dir), 0);
    chmod(dir, 0755);
}

/* Start a slow render of two outputs in the background, send `sig` once
 * the render runs, return the exit code and, in *ms, the time from the
 * signal until the render stopped: until the first partial file's
 * temporary appears (saving 4 Mpx in two formats takes longer in a
 * sanitizer build and is not part of stopping). */
static int interrupt_render(const char *sig, const char *stem, int *ms)
{
    char scene[512], cmd[3072];
    snprintf(scene, sizeof scene, "%s/%s.pov", tmpdir, stem);
    write_file(scene, slow_scene);
    snprintf(cmd, sizeof cmd,
             "cd '%s' && '%s' render '%s.pov' -o '%s.exr' -o '%s.png' --size 2000x2000 --threads 2 --quiet & pid=$!; "
             "sleep 1.5; t0=$(date +%%s%%N); kill -%s $pid; "
             "while kill -0 $pid 2>/dev/null && ! ls -a '%s' | grep -q '^\\.%s\\.partial\\.exr\\.tmp-'; do sleep 0.005; done; "
             "t1=$(date +%%s%%N); wait $pid; rc=$?; echo \"rc=$rc ms=$(( (t1 - t0) / 1000000 ))\"",
             tmpdir, PARTRAY_BIN, stem, stem, stem, sig, tmpdir, stem);
    run_capture(cmd);
    printf("%s", out_text);
    int rc = -1;
    *ms = -1;
    const char *p = strstr(out_text, "rc=");
    assert_non_null(p);
    assert_int_equal(sscanf(p, "rc=%d ms=%d", &rc, ms), 2);
    return rc;
}

static void check_partials(const char *stem)
{
    char path[512];
    const char *ext[] = {"exr", "png"};
    for (int i = 0; i < 2; i++) {
        snprintf(path, sizeof path, "%s/%s.partial.%s", tmpdir, stem, ext[i]);
        framebuffer *fb = NULL;
        assert_int_equal(img_read(path, 0, &fb, NULL), PT_OK);
        assert_int_equal(fb->width, 2000);
        assert_int_equal(fb->height, 2000);
        fb_free(fb);
        snprintf(path, sizeof path, "%s/%s.%s", tmpdir, stem, ext[i]);
        assert_false(exists(path));
    }
    assert_int_equal(temp_files_in(tmpdir), 0);
}

static void test_sigterm_partial(void **st)
{
    (void)st;
    int ms;
    int rc = interrupt_render("TERM", "term", &ms);
    assert_int_equal(rc, 143);
    assert_true(ms >= 0 && ms < 1000);
    check_partials("term");
}

static void test_sigint_two_outputs(void **st)
{
    (void)st;
    int ms;
    int rc = interrupt_render("INT", "twice", &ms);
    assert_int_equal(rc, 130);
    assert_true(ms >= 0 && ms < 1000);
    check_partials("twice");
}

/* An interrupted render never replaces a finished one of the same name. */
static void test_interrupt_keeps_earlier_output(void **st)
{
    (void)st;
    char scene[512], out[512], cmd[3072];
    snprintf(scene, sizeof scene, "%s/keep.pov", tmpdir);
    snprintf(out, sizeof out, "%s/keep.png", tmpdir);
    write_file(scene, slow_scene);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' -o '%s' --size 24x16 --quiet", PARTRAY_BIN, scene, out);
    assert_int_equal(run_capture(cmd), 0);
    snprintf(cmd, sizeof cmd,
             "'%s' render '%s' -o '%s' --size 2000x2000 --threads 2 --quiet & pid=$!; sleep 1.5; kill -INT $pid; "
             "wait $pid; echo rc=$?",
             PARTRAY_BIN, scene, out);
    run_capture(cmd);
    printf("%s", out_text);
    assert_non_null(strstr(out_text, "rc=130"));
    framebuffer *fb = NULL;
    assert_int_equal(img_read(out, 0, &fb, NULL), PT_OK);
    assert_int_equal(fb->width, 24);
    assert_int_equal(fb->height, 16);
    fb_free(fb);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/partray-rel-XXXXXX");
    if (!mkdtemp(tmpdir)) return 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_loop_limit),
        cmocka_unit_test(test_include_depth_limit),
        cmocka_unit_test(test_macro_depth_limit),
        cmocka_unit_test(test_token_limit),
        cmocka_unit_test(test_string_limit),
        cmocka_unit_test(test_array_limit),
        cmocka_unit_test(test_mesh_memory_limit),
        cmocka_unit_test(test_image_size_limit),
        cmocka_unit_test(test_read_image_limit),
        cmocka_unit_test(test_image_file_limits),
        cmocka_unit_test(test_limit_usage),
        cmocka_unit_test(test_opencl_no_platform),
        cmocka_unit_test(test_opencl_out_of_memory),
        cmocka_unit_test(test_write_fails_file_size_limit),
        cmocka_unit_test(test_write_fails_unwritable_dir),
        cmocka_unit_test(test_sigterm_partial),
        cmocka_unit_test(test_sigint_two_outputs),
        cmocka_unit_test(test_interrupt_keeps_earlier_output),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "chmod -R u+w '%s'; rm -rf '%s'", tmpdir, tmpdir);
    if (rc == 0) run_capture(cmd);
    return rc;
}
