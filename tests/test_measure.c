/* test_measure.c - the measuring commands end to end:
 * `partray sweep` (CSV rows, plot picture, HTML page and the files it links)
 * and `partray crosscheck` (POV-Ray 3.7 against partray: metrics, exit codes). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include "img_io.h"
#include "img_plot.h"
#include "stats_read.h"
#include "test_util.h"

static char tmpdir[256];
static int exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0 && sb.st_size > 0;
}

/* A small direct-light scene: an area light with jitter, so more samples
 * per pixel bring the image closer to a many-sample reference. */
static const char *scene_text =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 }\n"
    "#ifndef (Power) #declare Power = 1; #end\n"
    "camera { location <0, 1.5, -4> look_at <0, 0.7, 0> angle 45 }\n"
    "light_source { <-3, 5, -4> color rgb Power area_light 1.5*x, 1.5*z, 4, 4 jitter }\n"
    "plane { y, 0 pigment { rgb 0.7 } finish { diffuse 0.8 ambient 0.05 } }\n"
    "sphere { <0, 0.8, 0>, 0.8 pigment { rgb <0.9, 0.3, 0.2> } finish { phong 0.6 phong_size 40 } }\n"
    "box { <-1.8, 0, -0.5>, <-1.1, 0.6, 0.2> pigment { rgb <0.2, 0.5, 0.9> } }\n";

/* Splits one CSV line (no quoted commas in these tests) into fields. */
static int csv_fields(char *line, char **f, int max)
{
    int n = 0;
    for (char *p = line; n < max;) {
        f[n++] = p;
        char *c = strchr(p, ',');
        if (!c) break;
        *c = 0;
        p = c + 1;
    }
    return n;
}

static int column(char **head, int n, const char *name)
{
    for (int i = 0; i < n; i++)
        if (strcmp(head[i], name) == 0) return i;
    fail_msg("sweep.csv lacks column %s", name);
    return -1;
}

/* Every src="..." and href="..." in the page names an existing file. */
static int check_links(const char *dir, const char *html)
{
    int n = 0;
    for (const char *p = html; (p = strstr(p, "=\"")) != NULL; p += 2) {
        int is_link = (p >= html + 3 && strncmp(p - 3, "src", 3) == 0) || (p >= html + 4 && strncmp(p - 4, "href", 4) == 0);
        if (!is_link) continue;
        const char *e = strchr(p + 2, '"');
        assert_non_null(e);
        char rel[512], path[1024];
        snprintf(rel, sizeof rel, "%.*s", (int)(e - p - 2), p + 2);
        snprintf(path, sizeof path, "%s/%s", dir, rel);
        if (!exists(path)) fail_msg("index.html links to %s, which is missing", rel);
        n++;
    }
    return n;
}

static void test_sweep_spp(void **st)
{
    (void)st;
    char scene[512], ref[512], dir[512], cmd[4096], path[1024];
    snprintf(scene, sizeof scene, "%s/sweep.pov", tmpdir);
    snprintf(ref, sizeof ref, "%s/ref.exr", tmpdir);
    snprintf(dir, sizeof dir, "%s/sweep_spp", tmpdir);
    tu_write_file(scene, scene_text);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' -o '%s' --float --size 64x64 --spp 32 --threads 2 --quiet", PARTRAY_BIN,
             scene, ref);
    assert_int_equal(tu_run_capture(cmd), 0);
    snprintf(cmd, sizeof cmd, "'%s' sweep '%s' --gi none --vary spp=1,8 --ref '%s' --out '%s' --threads 2", PARTRAY_BIN,
             scene, ref, dir);
    int rc = tu_run_capture(cmd);
    printf("%s", tu_out);
    assert_int_equal(rc, 0);

    /* CSV: a header and one row per setting, in order. */
    snprintf(path, sizeof path, "%s/sweep.csv", dir);
    char *csv = tu_read_file(path);
    assert_non_null(csv);
    printf("%s", csv ? csv : "");
    char *lines[8];
    int nl = 0;
    for (char *p = csv; *p && nl < 8;) {
        lines[nl++] = p;
        char *e = strchr(p, '\n');
        if (!e) break;
        *e = 0;
        p = e + 1;
    }
    assert_int_equal(nl, 3);
    char *head[32], *row[2][32];
    int nh = csv_fields(lines[0], head, 32);
    for (int i = 0; i < 2; i++) assert_int_equal(csv_fields(lines[i + 1], row[i], 32), nh);
    int c_mode = column(head, nh, "mode"), c_set = column(head, nh, "settings"), c_rs = column(head, nh, "render_s"),
        c_ts = column(head, nh, "total_s"), c_rel = column(head, nh, "relmse"), c_rmse = column(head, nh, "rmse"),
        c_psnr = column(head, nh, "psnr"), c_ssim = column(head, nh, "ssim"), c_flip = column(head, nh, "flip_mean"),
        c_status = column(head, nh, "status"), c_img = column(head, nh, "image");
    (void)c_psnr;
    const char *want[2] = {"spp=1", "spp=8"};
    double rel[2], flip[2];
    for (int i = 0; i < 2; i++) {
        assert_string_equal(row[i][c_mode], "none");
        assert_string_equal(row[i][c_set], want[i]);
        assert_string_equal(row[i][c_status], "ok");
        double rs = atof(row[i][c_rs]), ts = atof(row[i][c_ts]);
        rel[i] = atof(row[i][c_rel]);
        flip[i] = atof(row[i][c_flip]);
        double ssim = atof(row[i][c_ssim]), rmse = atof(row[i][c_rmse]);
        printf("row %d: %s render %.4f s total %.4f s rmse %.5f relmse %.6f ssim %.4f flip %.4f\n", i, want[i], rs, ts, rmse,
               rel[i], ssim, flip[i]);
        assert_true(rs > 0.0 && ts >= rs);
        assert_true(rel[i] > 0.0 && rmse > 0.0);
        assert_true(ssim > 0.5 && ssim <= 1.0);
        assert_true(flip[i] > 0.0 && flip[i] < 1.0);
        snprintf(path, sizeof path, "%s/%s", dir, row[i][c_img]);
        assert_true(exists(path));
    }
    /* More samples, closer to the reference. */
    assert_true(rel[1] < rel[0]);
    assert_true(flip[1] < flip[0]);

    /* The plot: the documented default size, a white background, black axes
     * and the first series colour on the curve. */
    snprintf(path, sizeof path, "%s/plot.png", dir);
    framebuffer *fb = NULL;
    assert_int_equal(img_read(path, 1, &fb, NULL), PT_OK);
    assert_int_equal(fb->width, 720);
    assert_int_equal(fb->height, 480);
    float c0[3];
    img_plot_color(0, c0);
    long white = 0, black = 0, curve = 0, n = (long)fb->width * fb->height;
    for (long i = 0; i < n; i++) {
        const float *p = fb->rgb + 3 * i;
        if (p[0] > 0.99f && p[1] > 0.99f && p[2] > 0.99f) white++;
        if (p[0] < 0.01f && p[1] < 0.01f && p[2] < 0.01f) black++;
        if (fabsf(p[0] - c0[0]) < 0.01f && fabsf(p[1] - c0[1]) < 0.01f && fabsf(p[2] - c0[2]) < 0.01f) curve++;
    }
    printf("plot.png %dx%d: white %ld, black %ld, curve-coloured %ld of %ld pixels\n", fb->width, fb->height, white, black,
           curve, n);
    assert_true(white > n / 2);
    assert_true(black > 1000);
    assert_true(curve > 100);
    fb_free(fb);

    /* The page and everything it links to. */
    snprintf(path, sizeof path, "%s/index.html", dir);
    char *html = tu_read_file(path);
    assert_non_null(html);
    assert_non_null(strstr(html, "plot.png"));
    assert_non_null(strstr(html, "_flip.png"));
    assert_non_null(strstr(html, "ref.png"));
    int links = check_links(dir, html);
    printf("index.html: %d links, all present\n", links);
    assert_true(links >= 2 + 2 * 3); /* plot, reference, csv, 2 x (exr, png, heat map) */
}

/* A sweep over image size (renders resampled to the reference's size) with a
 * GI-mode-scoped key and a scene #declare; the usage errors. */
static void test_sweep_size_and_usage(void **st)
{
    (void)st;
    char scene[512], ref[512], dir[512], cmd[4096], path[1024];
    snprintf(scene, sizeof scene, "%s/sweep2.pov", tmpdir);
    snprintf(ref, sizeof ref, "%s/ref2.exr", tmpdir);
    snprintf(dir, sizeof dir, "%s/sweep_size", tmpdir);
    tu_write_file(scene, scene_text);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' -o '%s' --float --size 64x64 --threads 2 --quiet", PARTRAY_BIN, scene, ref);
    assert_int_equal(tu_run_capture(cmd), 0);
    snprintf(cmd, sizeof cmd,
             "'%s' sweep '%s' --gi none --vary none/size=32x32,64x64 --vary D:Power=1 --ref '%s' --out '%s' "
             "--metric flip --time render --plot-size 400x300 --threads 2 --quiet",
             PARTRAY_BIN, scene, ref, dir);
    int rc = tu_run_capture(cmd);
    printf("%s", tu_out);
    assert_int_equal(rc, 0);
    snprintf(path, sizeof path, "%s/sweep.csv", dir);
    char *csv = tu_read_file(path);
    assert_non_null(csv);
    printf("%s", csv ? csv : "");
    assert_non_null(strstr(csv, "none,size=32x32;D:Power=1,"));
    assert_non_null(strstr(csv, "none,size=64x64;D:Power=1,"));
    assert_non_null(strstr(csv, ",32,32,ok,"));
    assert_non_null(strstr(csv, ",64,64,ok,"));
    /* The 64x64 render has the reference's settings (and seed): identical. */
    char *row64 = strstr(csv, "none,size=64x64;D:Power=1,");
    char *f[32];
    assert_true(csv_fields(row64, f, 32) > 5);
    printf("size 64x64 against its own settings' reference: rmse %s, relmse %s\n", f[4], f[5]);
    assert_true(atof(f[4]) == 0.0 && atof(f[5]) == 0.0);
    framebuffer *fb = NULL;
    snprintf(path, sizeof path, "%s/plot.png", dir);
    assert_int_equal(img_read(path, 1, &fb, NULL), PT_OK);
    assert_int_equal(fb->width, 400);
    assert_int_equal(fb->height, 300);
    fb_free(fb);

    /* Usage: no --ref; a --vary without values; a mode-scoped key for a mode
     * not in --gi; an option the sweep sets itself. */
    const char *bad[] = {"--vary spp=1,2", "--ref x.exr --vary spp", "--ref x.exr --gi none --vary path/spp=1",
                         "--ref x.exr --vary spp=1 -o y.exr"};
    for (int i = 0; i < 4; i++) {
        snprintf(cmd, sizeof cmd, "'%s' sweep '%s' %s --out '%s/bad'", PARTRAY_BIN, scene, bad[i], tmpdir);
        rc = tu_run_capture(cmd);
        printf("sweep %s -> exit %d: %s", bad[i], rc, tu_out);
        assert_int_equal(rc, 2);
    }
    /* A missing reference is an I/O error. */
    snprintf(cmd, sizeof cmd, "'%s' sweep '%s' --ref '%s/none.exr' --vary spp=1 --out '%s/bad'", PARTRAY_BIN, scene, tmpdir,
             tmpdir);
    rc = tu_run_capture(cmd);
    printf("missing reference -> exit %d\n", rc);
    assert_int_equal(rc, 3);
}

static int have_povray(void) { return system("command -v povray >/dev/null 2>&1") == 0; }

/* Direct light only: partray --gi none and POV-Ray agree closely. */
static void test_crosscheck_direct(void **st)
{
    (void)st;
    if (!have_povray()) {
        printf("povray not installed; skipping\n");
        skip();
    }
    char scene[512], dir[512], cmd[4096], path[1024];
    snprintf(scene, sizeof scene, "%s/xc.pov", tmpdir);
    snprintf(dir, sizeof dir, "%s/xc", tmpdir);
    tu_write_file(scene,
               "#version 3.7;\n"
               "global_settings { assumed_gamma 1.0 }\n"
               "camera { location <0, 2, -5> look_at <0, 0.6, 0> angle 50 }\n"
               "light_source { <-4, 6, -5> color rgb 1 }\n"
               "plane { y, 0 pigment { rgb 0.6 } finish { ambient 0.05 diffuse 0.8 } }\n"
               "sphere { <0, 1, 0>, 1 pigment { rgb <0.8, 0.2, 0.15> } finish { ambient 0.1 diffuse 0.7 phong 0.8 phong_size 60 } }\n");
    snprintf(cmd, sizeof cmd, "'%s' crosscheck '%s' --size 64x64 +A0.3 --threads 2 --json --out '%s'", PARTRAY_BIN, scene, dir);
    int rc = tu_run_stdout(cmd);
    printf("%s", tu_out);
    assert_int_equal(rc, 0);
    double mad = -1, mad4 = -1, rmse = -1, flip = -1, ratio = -1, rad = -1, w = 0;
    assert_true(stats_read_num(tu_out, "mean_abs_diff", &mad));
    assert_true(stats_read_num(tu_out, "mean_abs_diff_4x4", &mad4));
    assert_true(stats_read_num(tu_out, "rmse", &rmse));
    assert_true(stats_read_num(tu_out, "flip.mean", &flip));
    assert_true(stats_read_num(tu_out, "luminance.ratio", &ratio));
    assert_true(stats_read_num(tu_out, "radiosity", &rad));
    assert_true(stats_read_num(tu_out, "width", &w));
    printf("crosscheck direct: mean |diff| %.5f (4x4 %.5f, bound 0.01), rmse %.5f, flip %.5f, luminance ratio %.5f\n", mad,
           mad4, rmse, flip, ratio);
    assert_true(w == 64);
    assert_true(rad == 0);
    assert_true(mad4 >= 0 && mad4 <= 0.01);
    assert_true(mad >= 0 && mad <= 0.02);
    assert_true(fabs(ratio - 1.0) <= 0.02);
    const char *files[] = {"povray.png", "partray.png", "flip.png", "partray.json", "povray.log"};
    for (int i = 0; i < 5; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, files[i]);
        if (!exists(path)) fail_msg("crosscheck --out lacks %s", files[i]);
    }
    /* The text report names the metrics. */
    snprintf(cmd, sizeof cmd, "'%s' crosscheck '%s' --size 32x32 --threads 2", PARTRAY_BIN, scene);
    rc = tu_run_capture(cmd);
    printf("%s", tu_out);
    assert_int_equal(rc, 0);
    assert_non_null(strstr(tu_out, "FLIP"));
    assert_non_null(strstr(tu_out, "luminance"));
}

/* A scene with radiosity{}: reported with the luminance ratio; POV-Ray
 * missing: exit 3. */
static void test_crosscheck_radiosity_and_missing(void **st)
{
    (void)st;
    char scene[512], cmd[4096];
    snprintf(scene, sizeof scene, "%s/xc_rad.pov", tmpdir);
    tu_write_file(scene,
               "#version 3.7;\n"
               "global_settings { assumed_gamma 1.0 radiosity { count 20 recursion_limit 1 } }\n"
               "camera { location <0, 1, -2.5> look_at <0, 1, 0> angle 60 }\n"
               "light_source { <0, 1.8, -0.5> color rgb 1 }\n"
               "box { <-1, 0, -3>, <1, 2, 1> pigment { rgb 0.7 } finish { ambient 0 diffuse 0.8 } hollow }\n");
    snprintf(cmd, sizeof cmd, "'%s' crosscheck '%s' --povray /nonexistent/povray", PARTRAY_BIN, scene);
    int rc = tu_run_capture(cmd);
    printf("missing povray -> exit %d: %s", rc, tu_out);
    assert_int_equal(rc, 3);
    if (!have_povray()) {
        printf("povray not installed; skipping the radiosity render\n");
        skip();
    }
    snprintf(cmd, sizeof cmd, "'%s' crosscheck '%s' --size 32x32 --threads 2 --json", PARTRAY_BIN, scene);
    rc = tu_run_stdout(cmd);
    printf("%s", tu_out);
    assert_int_equal(rc, 0);
    double rad = -1, ratio = -1, lp = -1;
    assert_true(stats_read_num(tu_out, "radiosity", &rad));
    assert_true(stats_read_num(tu_out, "luminance.ratio", &ratio));
    assert_true(stats_read_num(tu_out, "luminance.povray", &lp));
    printf("crosscheck radiosity: luminance ratio partray/POV-Ray %.4f (POV-Ray mean %.4f)\n", ratio, lp);
    assert_true(rad == 1);
    assert_true(lp > 0 && isfinite(ratio) && ratio > 0);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/partray-measure-XXXXXX");
    if (!mkdtemp(tmpdir)) return 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sweep_spp),
        cmocka_unit_test(test_sweep_size_and_usage),
        cmocka_unit_test(test_crosscheck_direct),
        cmocka_unit_test(test_crosscheck_radiosity_and_missing),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    char cmd[600];
    if (rc == 0) {
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
        tu_run_capture(cmd);
    } else {
        printf("files kept in %s\n", tmpdir);
    }
    return rc;
}
