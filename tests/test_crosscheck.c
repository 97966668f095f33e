/* test_crosscheck.c - partray --gi none against POV-Ray 3.7 itself.
 *
 * Each scene is rendered at 160x160 with +A0.3 by Debian's `povray` and by
 * partray; both sRGB PNGs are box-downsampled 4x4 (to absorb area-light and
 * antialiasing jitter) and the mean absolute difference over all channels
 * must be at most 0.01 of white (issue "Foundation"). The distribution's
 * radiosity/cornell.pov is used with its radiosity block removed, since POV-Ray
 * would otherwise add its own GI. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include "img_io.h"

#define SIZE 160
#define TOLERANCE 0.01
/* Our own regression bound: measured values are 0.0002-0.0012; the issue's
 * acceptance bound above is loose enough to miss a small missing feature. */
#define REGRESSION 0.004

static char tmpdir[256];

static int run(const char *cmd)
{
    int rc = system(cmd);
    return rc == -1 ? -1 : WEXITSTATUS(rc);
}

/* Copy `src` to `dst` without its radiosity{...} block. */
static int strip_radiosity(const char *src, const char *dst)
{
    FILE *f = fopen(src, "rb");
    if (!f) return 0;
    static char buf[1 << 20];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = 0;
    char *r = strstr(buf, "radiosity");
    if (!r) return 0;
    char *p = strchr(r, '{');
    if (!p) return 0;
    int depth = 0;
    char *end = p;
    for (; *end; end++) {
        if (*end == '{') depth++;
        if (*end == '}' && --depth == 0) break;
    }
    if (!*end) return 0;
    FILE *o = fopen(dst, "wb");
    if (!o) return 0;
    fwrite(buf, 1, (size_t)(r - buf), o);
    fputs(end + 1, o);
    fclose(o);
    return 1;
}

/* Mean absolute difference of the 4x4 box-downsampled sRGB-encoded images. */
static double downsampled_mad(const framebuffer *a, const framebuffer *b)
{
    int w = a->width / 4, h = a->height / 4;
    double sum = 0.0;
    for (int y = 0; y < h; y++) {
        for (int x = 0; x < w; x++) {
            for (int c = 0; c < 3; c++) {
                double sa = 0, sb = 0;
                for (int j = 0; j < 4; j++)
                    for (int i = 0; i < 4; i++) {
                        size_t k = ((size_t)(y * 4 + j) * (size_t)a->width + (size_t)(x * 4 + i)) * 3 + (size_t)c;
                        sa += a->rgb[k];
                        sb += b->rgb[k];
                    }
                sum += fabs(sa - sb) / 16.0;
            }
        }
    }
    return sum / (3.0 * w * h);
}

static double crosscheck(const char *scene_path, const char *name)
{
    char cmd[4096], pov_png[512], pt_png[512];
    snprintf(pov_png, sizeof pov_png, "%s/%s_pov.png", tmpdir, name);
    snprintf(pt_png, sizeof pt_png, "%s/%s_pt.png", tmpdir, name);
    /* POV-Ray restricts file writes to the working directory: run it there. */
    snprintf(cmd, sizeof cmd,
             "cd '%s' && cp '%s' '%s.pov' 2>/dev/null; povray +I%s.pov +O%s_pov.png +W%d +H%d +A0.3 +R3 -D -V -GA +WT2 +FN >povray_%s.log 2>&1",
             tmpdir, scene_path, name, name, name, SIZE, SIZE, name);
    int rc = run(cmd);
    if (rc != 0) fail_msg("povray failed (%d) on %s; see %s/povray_%s.log", rc, scene_path, tmpdir, name);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' -o '%s' +W%d +H%d +A0.3 +R3 --threads 2 --quiet", PARTRAY_BIN, scene_path,
             pt_png, SIZE, SIZE);
    rc = run(cmd);
    if (rc != 0) fail_msg("partray failed (%d) on %s", rc, scene_path);
    framebuffer *a = NULL, *b = NULL;
    assert_int_equal(img_read(pov_png, 1, &a, NULL), PT_OK);
    assert_int_equal(img_read(pt_png, 1, &b, NULL), PT_OK);
    assert_int_equal(a->width, b->width);
    assert_int_equal(a->height, b->height);
    double mad = downsampled_mad(a, b);
    printf("crosscheck %-22s mean |diff| after 4x4 downsample = %.5f (tolerance %.3f)\n", name, mad, TOLERANCE);
    fb_free(a);
    fb_free(b);
    return mad;
}

static void test_cornell_direct(void **st)
{
    (void)st;
    char path[512];
    snprintf(path, sizeof path, "%s/cornell_direct.pov", tmpdir);
    assert_true(strip_radiosity("/usr/share/povray-3.7/scenes/radiosity/cornell.pov", path));
    double mad = crosscheck(path, "cornell_direct");
    assert_true(mad <= TOLERANCE);
    assert_true(mad <= REGRESSION);
}

static void scene_test(const char *name)
{
    char path[512];
    snprintf(path, sizeof path, "%s/scenes/%s.pov", TESTS_DIR, name);
    double mad = crosscheck(path, name);
    assert_true(mad <= TOLERANCE);
    assert_true(mad <= REGRESSION);
}

static void test_point_phong(void **st) { (void)st; scene_test("xc_point_phong"); }
static void test_spot_specular(void **st) { (void)st; scene_test("xc_spot_specular"); }
static void test_parallel_reflect(void **st) { (void)st; scene_test("xc_parallel_reflect"); }
static void test_area_fade(void **st) { (void)st; scene_test("xc_area_fade"); }

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/partray-xc-XXXXXX");
    if (!mkdtemp(tmpdir)) return 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cornell_direct),
        cmocka_unit_test(test_point_phong),
        cmocka_unit_test(test_spot_specular),
        cmocka_unit_test(test_parallel_reflect),
        cmocka_unit_test(test_area_fade),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    if (rc == 0) {
        char cmd[600];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
        run(cmd);
    } else {
        printf("images kept in %s\n", tmpdir);
    }
    return rc;
}
