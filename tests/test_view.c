/* test_view.c - `partray view`.
 *
 * Headless run under Xvfb (started here on a free display with -displayfd,
 * so neither xvfb-run nor xauth is needed): a plane, two spheres and a point
 * light at 128x128; the script waits for the refinement, takes a screenshot,
 * moves the light, screenshots again, dims the light, screenshots, orbits the
 * camera and writes it out; then raw input through the window's event queue
 * (a left drag, C, the wheel, P, Escape). Asserted: the images differ where the shadows
 * moved (regions computed analytically from the scene), hardly anywhere
 * else, no NaN, not black, dimming halves the direct light, and the written
 * camera{} block parses back to the orbited camera. A second run: the
 * window saved with the overlay on and off (`window`, the O key) differs in
 * the overlay's box and nowhere else; switching to the reference previews
 * (path, pmfg) gives refined images that are not black and NaN-free. Skips
 * only when there is no Xvfb binary at all.
 *
 * Without a display: the overlay's font (pixel counts of known glyphs), the render thread (its last level equals a direct
 * shade_render, a burst of submits ends idle on the newest state), camera moves (orbit keeps the distance, +yaw goes to
 * screen right also for mirrored cameras, the camera{} block round-trips
 * through the parser) and the script grammar (order, errors with columns). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include "accel.h"
#include "gi.h"
#include "gi_vlinks.h"
#include "img_io.h"
#include "radrules.h"
#include "render_gi.h"
#include "scene.h"
#include "sdl.h"
#include "shade.h"
#include "shade_texture.h"
#include "test_util.h"
#include "timer.h"
#include "view_camera.h"
#include "view_gi.h"
#include "view_overlay.h"
#include "view_render.h"
#include "view_script.h"

#define W 128
#define H 128

static char tmpdir[256];
static char out_text[65536];
static pid_t xvfb_pid = -1;
static char display[32];

/* ------------------------------------------------------------- helpers */

static int run_capture(const char *cmd)
{
    char full[4096];
    snprintf(full, sizeof full, "%s 2>&1", cmd);
    FILE *p = popen(full, "r");
    if (!p) return -1;
    size_t n = fread(out_text, 1, sizeof out_text - 1, p);
    out_text[n] = 0;
    int rc = pclose(p);
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : 128;
}

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static int have_program(const char *name)
{
    const char *path = getenv("PATH");
    char dirs[4096];
    snprintf(dirs, sizeof dirs, "%s:/usr/bin:/usr/local/bin", path ? path : "");
    for (char *save = NULL, *d = strtok_r(dirs, ":", &save); d; d = strtok_r(NULL, ":", &save)) {
        char p[4200];
        snprintf(p, sizeof p, "%s/%s", d, name);
        if (access(p, X_OK) == 0) return 1;
    }
    return 0;
}

/* Starts Xvfb on a display it picks itself (-displayfd); 1 on success. */
static int start_xvfb(void)
{
    int fd[2];
    if (pipe(fd) != 0) return 0;
    pid_t pid = fork();
    if (pid < 0) return 0;
    if (pid == 0) {
        close(fd[0]);
        char fds[16];
        snprintf(fds, sizeof fds, "%d", fd[1]);
        int nul = open("/dev/null", O_RDWR);
        if (nul >= 0) {
            dup2(nul, 0);
            dup2(nul, 1);
            dup2(nul, 2);
        }
        execlp("Xvfb", "Xvfb", "-displayfd", fds, "-screen", "0", "640x480x24", "-nolisten", "tcp", "-noreset", (char *)NULL);
        _exit(127);
    }
    close(fd[1]);
    xvfb_pid = pid;
    char buf[32] = "";
    size_t n = 0;
    struct pollfd pf = {fd[0], POLLIN, 0};
    while (n < sizeof buf - 1 && poll(&pf, 1, 20000) > 0) {
        ssize_t r = read(fd[0], buf + n, sizeof buf - 1 - n);
        if (r <= 0) break;
        n += (size_t)r;
        buf[n] = 0;
        if (strchr(buf, '\n')) break;
    }
    close(fd[0]);
    int num;
    if (sscanf(buf, "%d", &num) != 1) return 0;
    snprintf(display, sizeof display, ":%d", num);
    return 1;
}

static void stop_xvfb(void)
{
    if (xvfb_pid > 0) {
        kill(xvfb_pid, SIGTERM);
        waitpid(xvfb_pid, NULL, 0);
        xvfb_pid = -1;
    }
}

/* ----------------------------------------------------- the scene, analytically */

static const char *two_spheres_pov =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 }\n"
    "camera { location <0, 8, -8> direction <0, -0.70710678, 0.70710678>\n"
    "         up <0, 0.70710678, 0.70710678> right <1, 0, 0> }\n"
    "light_source { <-3, 10, -1> color rgb 1 }\n"
    "plane { y, 0 pigment { rgb 0.8 } finish { ambient 0.05 diffuse 0.8 } }\n"
    "sphere { <-1.5, 1, 0>, 1 pigment { rgb <0.9, 0.2, 0.2> } finish { ambient 0.05 diffuse 0.8 } }\n"
    "sphere { <1.5, 0.7, 1.5>, 0.7 pigment { rgb <0.2, 0.3, 0.9> } finish { ambient 0.05 diffuse 0.8 } }\n"
    "background { rgb <0.1, 0.15, 0.3> }\n";

/* A room of mesh2 walls split by a mesh2 divider, and a mesh2 sheet on the
 * floor of the left half whose middle rises with the clock (its vertices
 * computed from `clock`): --gi links follows it. */
static const char *sheet_room_pov =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 radiosity { recursion_limit 2 } }\n"
    "camera { location <0.3, 1.6, -1.9> look_at <-0.2, 0.5, 1.5> angle 75 }\n"
    "light_source { <-0.8, 2.2, -0.8> color rgb 1 }\n"
    "#macro Quad(A, B, C, D, N, T)\n"
    "  mesh2 {\n"
    "    vertex_vectors { (N + 1) * (N + 1), #for (J, 0, N) #for (I, 0, N) #local U = I / N; #local V = J / N;\n"
    "      (1 - V) * ((1 - U) * A + U * B) + V * ((1 - U) * D + U * C), #end #end }\n"
    "    face_indices { 2 * N * N, #for (J, 0, N - 1) #for (I, 0, N - 1) #local K = J * (N + 1) + I;\n"
    "      <K, K + 1, K + N + 2>, <K, K + N + 2, K + N + 1>, #end #end }\n"
    "    texture { T }\n"
    "  }\n"
    "#end\n"
    "#ifndef (NR) #declare NR = 6; #end\n"
    "#ifndef (NS) #declare NS = 10; #end\n"
    "#declare Wall = texture { pigment { rgb 0.75 } finish { ambient 0 diffuse 0.8 } }\n"
    "#declare Red = texture { pigment { rgb <0.8, 0.25, 0.2> } finish { ambient 0 diffuse 0.8 } }\n"
    "Quad(<-2, 0, -2>, <2, 0, -2>, <2, 0, 2>, <-2, 0, 2>, NR, Wall)\n"
    "Quad(<-2, 2.5, -2>, <-2, 2.5, 2>, <2, 2.5, 2>, <2, 2.5, -2>, NR, Wall)\n"
    "Quad(<-2, 0, 2>, <2, 0, 2>, <2, 2.5, 2>, <-2, 2.5, 2>, NR, Wall)\n"
    "Quad(<-2, 0, -2>, <-2, 0, 2>, <-2, 2.5, 2>, <-2, 2.5, -2>, NR, Red)\n"
    "Quad(<2, 0, -2>, <2, 2.5, -2>, <2, 2.5, 2>, <2, 0, 2>, NR, Wall)\n"
    "Quad(<-2, 0, -2>, <-2, 2.5, -2>, <2, 2.5, -2>, <2, 0, -2>, NR, Wall)\n"
    "Quad(<0.4, 0, -0.2>, <0.4, 0, 2>, <0.4, 2.5, 2>, <0.4, 2.5, -0.2>, NR, Wall)\n"
    "mesh2 {\n"
    "  vertex_vectors { (NS + 1) * (NS + 1), #for (J, 0, NS) #for (I, 0, NS) #local U = I / NS; #local V = J / NS;\n"
    "    <-1.8 + 1.6 * U, 0.05 + 0.9 * clock * sin(pi * U) * sin(pi * V), 0.2 + 1.6 * V>, #end #end }\n"
    "  face_indices { 2 * NS * NS, #for (J, 0, NS - 1) #for (I, 0, NS - 1) #local K = J * (NS + 1) + I;\n"
    "    <K, K + 1, K + NS + 2>, <K, K + NS + 2, K + NS + 1>, #end #end }\n"
    "  texture { pigment { rgb <0.3, 0.5, 0.9> } finish { ambient 0 diffuse 0.8 } }\n"
    "}\n";

static const vec3 light_a = {-3, 10, -1}, light_b = {3, 10, -1}; /* the script moves it by <6, 0, 0> */
static const vec3 sph_c[2] = {{-1.5, 1, 0}, {1.5, 0.7, 1.5}};
static const double sph_r[2] = {1, 0.7};

/* First t in (0, tmax) where o + t d meets a sphere, or 0. */
static int hits_sphere(vec3 o, vec3 d, double tmax)
{
    for (int i = 0; i < 2; i++) {
        vec3 oc = v3_sub(o, sph_c[i]);
        double a = v3_dot(d, d), b = v3_dot(oc, d), c = v3_dot(oc, oc) - sph_r[i] * sph_r[i];
        double disc = b * b - a * c;
        if (disc < 0) continue;
        double s = sqrt(disc);
        double t0 = (-b - s) / a, t1 = (-b + s) / a;
        if ((t0 > 1e-6 && t0 < tmax) || (t1 > 1e-6 && t1 < tmax)) return 1;
    }
    return 0;
}

/* Pixel classes from 4x4 sub-samples: -1 mixed or not on the plane,
 * else bit 0 = shadowed from light A, bit 1 = shadowed from light B. */
static int classify(int px, int py)
{
    const vec3 loc = {0, 8, -8}, dir = {0, -0.70710678, 0.70710678}, up = {0, 0.70710678, 0.70710678}, right = {1, 0, 0};
    int cls = -2;
    for (int j = 0; j < 4; j++) {
        for (int i = 0; i < 4; i++) {
            double sx = (px + (i + 0.5) / 4) / W - 0.5, sy = 0.5 - (py + (j + 0.5) / 4) / H;
            vec3 d = v3_add(dir, v3_add(v3_scale(right, sx), v3_scale(up, sy)));
            if (d.y >= 0) return -1;
            double t = -loc.y / d.y;
            if (hits_sphere(loc, d, t)) return -1;
            vec3 p = v3_madd(loc, d, t);
            int c = (hits_sphere(p, v3_sub(light_a, p), 1.0) ? 1 : 0) | (hits_sphere(p, v3_sub(light_b, p), 1.0) ? 2 : 0);
            if (cls == -2) cls = c;
            else if (cls != c) return -1;
        }
    }
    return cls;
}

static double luma(const framebuffer *fb, int x, int y)
{
    const float *p = fb->rgb + ((size_t)y * fb->width + x) * 3;
    return (p[0] + p[1] + p[2]) / 3.0;
}

static void check_image(const framebuffer *fb, const char *name)
{
    assert_int_equal(fb->width, W);
    assert_int_equal(fb->height, H);
    long nan = 0;
    double sum = 0;
    for (size_t i = 0; i < (size_t)W * H * 3; i++) {
        if (!isfinite(fb->rgb[i])) nan++;
        else sum += fb->rgb[i];
    }
    double mean = sum / (W * H * 3.0);
    printf("%s: mean %.4f, non-finite values %ld\n", name, mean, nan);
    assert_int_equal(nan, 0);
    assert_true(mean > 0.1); /* lit plane ~0.6, background 0.18: far from black */
}

/* ------------------------------------------------------------ the viewer */

static void test_viewer_script(void **st)
{
    (void)st;
    if (!have_program("Xvfb")) {
        printf("Xvfb not found on PATH: the viewer cannot be run headless here\n");
        skip();
    }
    assert_true(start_xvfb());
    printf("Xvfb on display %s\n", display);
    char scene_path[512], script[512], cmd[4096], path[600];
    snprintf(scene_path, sizeof scene_path, "%s/two.pov", tmpdir);
    snprintf(script, sizeof script, "%s/run.txt", tmpdir);
    write_file(scene_path, two_spheres_pov);
    char text[2048];
    snprintf(text, sizeof text,
             "# screenshot, move the light, screenshot, dim it, screenshot, orbit, write the camera\n"
             "0.0 wait-idle\n"
             "0.1 screenshot %s/a\n"
             "0.2 light 1 move 6 0 0\n"
             "0.2 wait-idle\n"
             "0.3 screenshot %s/b.exr\n"
             "0.4 light 1 scale 0.5\n"
             "0.4 wait-idle\n"
             "0.5 screenshot %s/c.exr\n"
             "0.6 camera orbit 30 0\n"
             "0.6 camera write %s/cam.inc\n"
             "0.6 wait-idle\n"
             "# raw input through the event queue: a left drag of -100 px orbits +30\n"
             "# degrees more, C writes the camera, two wheel clicks zoom in, C again, P\n"
             "# takes a screenshot, Escape quits\n"
             "0.7 drag left -100 0\n"
             "0.7 key c\n"
             "0.7 wheel 2\n"
             "0.7 key c\n"
             "0.7 wait-idle\n"
             "0.8 key p\n"
             "0.9 key Escape\n",
             tmpdir, tmpdir, tmpdir, tmpdir);
    write_file(script, text);
    /* In sanitizer builds LeakSanitizer would report what SDL2 2.26 leaves
     * behind in libdbus and the X11 libraries it unloads; the viewer's own
     * memory is checked in-process by test_render_thread. */
    snprintf(cmd, sizeof cmd, "cd '%s' && ASAN_OPTIONS=detect_leaks=0 DISPLAY=%s timeout 120 '%s' view '%s' --size %dx%d --gi none --threads 2 --script '%s'",
             tmpdir, display, PARTRAY_BIN, scene_path, W, H, script);
    int rc = run_capture(cmd);
    stop_xvfb();
    printf("exit %d:\n%s", rc, out_text);
    assert_int_equal(rc, 0);
    assert_non_null(strstr(out_text, "screenshot"));

    framebuffer *a = NULL, *b = NULL, *c = NULL, *ap = NULL;
    diag *d = diag_new();
    snprintf(path, sizeof path, "%s/a.exr", tmpdir);
    assert_int_equal(img_read(path, 0, &a, d), PT_OK);
    snprintf(path, sizeof path, "%s/a.png", tmpdir);
    assert_int_equal(img_read(path, 0, &ap, d), PT_OK);
    snprintf(path, sizeof path, "%s/b.exr", tmpdir);
    assert_int_equal(img_read(path, 0, &b, d), PT_OK);
    snprintf(path, sizeof path, "%s/c.exr", tmpdir);
    assert_int_equal(img_read(path, 0, &c, d), PT_OK);
    check_image(a, "a (light at <-3,10,-1>)");
    check_image(b, "b (light moved to <3,10,-1>)");
    check_image(c, "c (light dimmed to 0.5)");

    /* The PNG is the sRGB encoding of the EXR (8-bit, half-float EXR). */
    double png_err = 0;
    for (size_t i = 0; i < (size_t)W * H * 3; i++) {
        double e = fabs(img_srgb_encode(fmin(1.0, fmax(0.0, a->rgb[i]))) - img_srgb_encode(ap->rgb[i]));
        if (e > png_err) png_err = e;
    }
    printf("PNG vs EXR: largest difference %.4f (sRGB encoded)\n", png_err);
    assert_true(png_err < 1.5 / 255);

    /* Regions: S = the shadow moved in or out (analytically), F = plane lit
     * by both lights. */
    double sum_s = 0, sum_f = 0, sum_fb = 0, sum_fc = 0;
    long n_s = 0, n_f = 0, n_s_darker_a = 0;
    for (int y = 0; y < H; y++) {
        for (int x = 0; x < W; x++) {
            int k = classify(x, y);
            if (k < 0) continue;
            double da = luma(a, x, y), db = luma(b, x, y);
            if (k == 1 || k == 2) {
                sum_s += fabs(da - db);
                n_s++;
                if ((k == 1) == (da < db)) n_s_darker_a++;
            } else if (k == 0) {
                sum_f += fabs(da - db);
                sum_fb += db;
                sum_fc += luma(c, x, y);
                n_f++;
            }
        }
    }
    double mean_s = sum_s / (n_s ? n_s : 1), mean_f = sum_f / (n_f ? n_f : 1);
    printf("shadow-change region: %ld px, mean |b-a| %.4f, %ld px darker on the shadowed side\n", n_s, mean_s, n_s_darker_a);
    printf("lit-in-both region:   %ld px, mean |b-a| %.4f (ratio %.1f)\n", n_f, mean_f, mean_f > 0 ? mean_s / mean_f : 0.0);
    assert_true(n_s > 100);
    assert_true(n_f > 2000);
    assert_true(mean_s > 0.3);
    assert_true(mean_f < 0.1);
    assert_true(mean_s > 5 * mean_f);
    assert_true(n_s_darker_a == n_s); /* every pixel is darker where it is in shadow */

    /* Dimming: plane = 0.8 * 0.05 ambient + direct, direct halves. */
    double mb = sum_fb / n_f, mc = sum_fc / n_f, amb = 0.8 * 0.05;
    printf("dimming: lit plane %.4f -> %.4f, expected %.4f\n", mb, mc, amb + 0.5 * (mb - amb));
    assert_true(fabs(mc - (amb + 0.5 * (mb - amb))) < 0.01);

    /* The camera written after `camera orbit 30 0`: look_at is where the
     * view met the plane (the origin), the location turned 30 degrees
     * towards screen right (+x) around it. */
    snprintf(path, sizeof path, "%s/cam.inc", tmpdir);
    char *block = tu_read_file(path);
    assert_non_null(block);
    char src[9000];
    snprintf(src, sizeof src, "#version 3.7;\n%s", block);
    scene *sc = NULL;
    sdl_options so;
    sdl_default_options(&so);
    assert_int_equal(sdl_parse_string("cam.inc", src, &so, &sc, d), PT_OK);
    vec3 l = sc->camera.location;
    double r = 8.0; /* horizontal radius of <0,8,-8> about the origin */
    printf("orbited camera: location <%.4f, %.4f, %.4f>, expected <%.4f, 8, %.4f>\n", l.x, l.y, l.z, r * sin(M_PI / 6),
           -r * cos(M_PI / 6));
    assert_true(fabs(l.x - r * sin(M_PI / 6)) < 1e-3);
    assert_true(fabs(l.y - 8) < 1e-3);
    assert_true(fabs(l.z + r * cos(M_PI / 6)) < 1e-3);
    vec3 dn = v3_norm(sc->camera.direction);
    vec3 to = v3_norm(v3_neg(l));
    assert_true(v3_dot(dn, to) > 1 - 1e-6);
    scene_free(sc);

    /* keys and mouse: after the drag, 60 degrees; after the wheel, 0.9^2 of
     * the distance; P saved both files under the counter name */
    for (int k = 1; k <= 2; k++) {
        snprintf(path, sizeof path, "%s/two-camera-%04d.inc", tmpdir, k);
        block = tu_read_file(path);
        assert_non_null(block);
        snprintf(src, sizeof src, "#version 3.7;\n%s", block);
        sc = NULL;
        assert_int_equal(sdl_parse_string("cam.inc", src, &so, &sc, d), PT_OK);
        l = sc->camera.location;
        double f = k == 1 ? 1.0 : 0.81;
        vec3 want = v3(f * r * sin(M_PI / 3), f * 8, -f * r * cos(M_PI / 3));
        printf("camera after drag%s: <%.4f, %.4f, %.4f>, expected <%.4f, %.4f, %.4f>\n", k == 2 ? " + wheel" : "", l.x, l.y,
               l.z, want.x, want.y, want.z);
        assert_true(v3_len(v3_sub(l, want)) < 1e-3);
        scene_free(sc);
    }
    struct stat sb;
    snprintf(path, sizeof path, "%s/two-0001.exr", tmpdir);
    assert_int_equal(stat(path, &sb), 0);
    snprintf(path, sizeof path, "%s/two-0001.png", tmpdir);
    assert_int_equal(stat(path, &sb), 0);

    fb_free(a);
    fb_free(ap);
    fb_free(b);
    fb_free(c);
    diag_free(d);
}

/* Overlay on/off and the reference previews, in one headless run. */
static void test_viewer_overlay_reference(void **st)
{
    (void)st;
    if (!have_program("Xvfb")) {
        printf("Xvfb not found on PATH: the viewer cannot be run headless here\n");
        skip();
    }
    assert_true(start_xvfb());
    char scene_path[512], script[512], cmd[4096], path[600], text[2048];
    snprintf(scene_path, sizeof scene_path, "%s/two.pov", tmpdir);
    snprintf(script, sizeof script, "%s/ov.txt", tmpdir);
    write_file(scene_path, two_spheres_pov);
    snprintf(text, sizeof text,
             "0.0 wait-idle\n"
             "0.1 window %s/on.png\n"
             "0.2 key o\n"
             "0.3 window %s/off.png\n"
             "0.4 gi path\n"
             "0.4 wait-idle\n"
             "0.5 screenshot %s/path.exr\n"
             "0.6 gi pmfg\n"
             "0.6 wait-idle\n"
             "0.7 screenshot %s/pmfg.exr\n"
             "0.8 quit\n",
             tmpdir, tmpdir, tmpdir, tmpdir);
    write_file(script, text);
    /* --ref-spp 2: the previews' last level is 2 (1 + 1 samples per pixel) */
    snprintf(cmd, sizeof cmd,
             "cd '%s' && ASAN_OPTIONS=detect_leaks=0 DISPLAY=%s timeout 120 '%s' view '%s' --size %dx%d --gi none --threads 2 "
             "--ref-spp 2 --script '%s'",
             tmpdir, display, PARTRAY_BIN, scene_path, W, H, script);
    int rc = run_capture(cmd);
    stop_xvfb();
    printf("exit %d:\n%s", rc, out_text);
    assert_int_equal(rc, 0);
    assert_non_null(strstr(out_text, "(path, level 2/2)"));
    assert_non_null(strstr(out_text, "(pmfg, level 2/2)"));

    diag *d = diag_new();
    framebuffer *on = NULL, *off = NULL;
    snprintf(path, sizeof path, "%s/on.png", tmpdir);
    assert_int_equal(img_read(path, 0, &on, d), PT_OK);
    snprintf(path, sizeof path, "%s/off.png", tmpdir);
    assert_int_equal(img_read(path, 0, &off, d), PT_OK);
    assert_int_equal(on->width, W);
    assert_int_equal(off->height, H);
    /* at most 5 lines of 9 font pixels, a 3-pixel margin: the box ends
     * above row 5 * 9 - 2 + 6 = 49 (scale 1 below 900 pixels) */
    const int box_rows = 49;
    long in_box = 0, differ_box = 0, differ_out = 0, lighter = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double a = luma(on, x, y), b = luma(off, x, y);
            int differ = fabs(a - b) > 1e-6;
            if (y < box_rows) {
                in_box++;
                differ_box += differ;
                lighter += a > b + 0.2; /* white glyph pixels */
            } else {
                differ_out += differ;
            }
        }
    /* the first line starts at the top left: its first glyph cells */
    long first_cell = 0;
    for (int y = 3; y < 10; y++)
        for (int x = 3; x < 8; x++) first_cell += fabs(luma(on, x, y) - luma(off, x, y)) > 1e-6;
    printf("overlay: %ld of %ld pixels in the box rows differ (%ld lighter: glyphs), %ld differ below the box; first glyph "
           "cell %ld px\n",
           differ_box, in_box, lighter, differ_out, first_cell);
    assert_true(differ_box > in_box / 4); /* the darkened box covers the top left */
    assert_true(lighter > 100);
    assert_true(first_cell > 5);
    assert_int_equal(differ_out, 0);

    const char *names[] = {"path", "pmfg"};
    double means[2];
    for (int k = 0; k < 2; k++) {
        framebuffer *fb = NULL;
        snprintf(path, sizeof path, "%s/%s.exr", tmpdir, names[k]);
        assert_int_equal(img_read(path, 0, &fb, d), PT_OK);
        char label[64];
        snprintf(label, sizeof label, "%s reference preview", names[k]);
        check_image(fb, label); /* NaN-free, mean > 0.1 */
        means[k] = 0;
        for (size_t i = 0; i < (size_t)W * H * 3; i++) means[k] += fb->rgb[i];
        means[k] /= W * H * 3.0;
        fb_free(fb);
    }
    /* both estimate the same light (pm_fg.h: pmfg's direct term is the path
     * tracer's NEE); at 2 spp the image means agree to noise */
    printf("reference previews: mean path %.4f, pmfg %.4f\n", means[0], means[1]);
    assert_true(fabs(means[0] - means[1]) < 0.03 * means[0]);
    fb_free(on);
    fb_free(off);
    diag_free(d);
}

/* ------------------------------------- functions at parse time, with a display */

/* The viewer opens a scene as `partray render` does (app/pipeline.h): a
 * scene whose parse calls vturbulence (POV-Ray's noise) and trace() on a
 * sor places a sphere against the sor where the traced ray met it. Asserted:
 * the viewer renders it (a parse without the evaluators stops at
 * vturbulence with an error), its last refinement level equals `partray
 * render`'s image of the same scene at the same size (mean absolute
 * difference below FN_MEAN; under 2% of the pixels, the
 * edges, differ by more than FN_EDGE; the sphere covers the same pixels to
 * 10%), and the parse limits reach the viewer (--max-tokens 20 stops this
 * scene's parse). */
#define FN_MEAN 0.004
#define FN_EDGE 0.05
static const char *functions_pov =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 }\n"
    "camera { location <0, 2.5, -6> look_at <0, 0.9, 0> }\n"
    "light_source { <-4, 8, -5> color rgb 1 }\n"
    "plane { y, 0 pigment { rgb 0.8 } finish { ambient 0 diffuse 0.8 } }\n"
    "#declare S = sor { 5, <0, -0.5>, <1, 0>, <0.7, 1.2>, <0.3, 2>, <0, 2.5>\n"
    "  pigment { rgb <0.9, 0.5, 0.2> } finish { ambient 0 diffuse 0.8 } }\n"
    "object { S }\n"
    "#declare N = <0, 0, 0>;\n"
    "#declare P = trace(S, <3, 1, 0>, <-1, 0, 0>, N);\n"
    "#declare V = vturbulence(2, 0.5, 6, <0.3, 0.2, 0.1>);\n"
    "sphere { P + 0.35 * N + <0, 0.05 * V.y, 0>, 0.35 pigment { rgb <0.2, 0.4, 0.9> } finish { ambient 0 diffuse 0.8 } }\n";

static void test_viewer_functions(void **st)
{
    (void)st;
    if (!have_program("Xvfb")) {
        printf("Xvfb not found on PATH: the viewer cannot be run headless here\n");
        skip();
    }
    enum { FW = 96, FH = 96 };
    char scene_path[512], script[512], cmd[4096], path[600], text[1024];
    snprintf(scene_path, sizeof scene_path, "%s/fn.pov", tmpdir);
    snprintf(script, sizeof script, "%s/fn.txt", tmpdir);
    write_file(scene_path, functions_pov);
    snprintf(text, sizeof text, "0.0 wait-idle\n0.1 screenshot %s/fn_view.exr\n0.2 quit\n", tmpdir);
    write_file(script, text);
    snprintf(cmd, sizeof cmd, "cd '%s' && '%s' render '%s' -o '%s/fn_render.exr' --size %dx%d --gi none --threads 2 --quiet",
             tmpdir, PARTRAY_BIN, scene_path, tmpdir, FW, FH);
    assert_int_equal(run_capture(cmd), 0);
    assert_true(start_xvfb());
    snprintf(cmd, sizeof cmd,
             "cd '%s' && ASAN_OPTIONS=detect_leaks=0 DISPLAY=%s timeout 120 '%s' view '%s' --size %dx%d --gi none --threads 2 "
             "--script '%s'",
             tmpdir, display, PARTRAY_BIN, scene_path, FW, FH, script);
    int rc = run_capture(cmd);
    printf("exit %d:\n%s", rc, out_text);
    assert_int_equal(rc, 0);
    /* the limits the command line gives reach the parse */
    snprintf(cmd, sizeof cmd,
             "cd '%s' && ASAN_OPTIONS=detect_leaks=0 DISPLAY=%s timeout 120 '%s' view '%s' --size %dx%d --gi none --threads 2 "
             "--max-tokens 20 --script '%s'",
             tmpdir, display, PARTRAY_BIN, scene_path, FW, FH, script);
    int rc_limit = run_capture(cmd);
    stop_xvfb();
    printf("with --max-tokens 20: exit %d:\n%s", rc_limit, out_text);
    assert_int_equal(rc_limit, 1);

    framebuffer *r = NULL, *v = NULL;
    diag *d = diag_new();
    snprintf(path, sizeof path, "%s/fn_render.exr", tmpdir);
    assert_int_equal(img_read(path, 0, &r, d), PT_OK);
    snprintf(path, sizeof path, "%s/fn_view.exr", tmpdir);
    assert_int_equal(img_read(path, 0, &v, d), PT_OK);
    assert_int_equal(v->width, FW);
    assert_int_equal(v->height, FH);
    /* The viewer's camera is rebuilt from the scene's (view_camera.h), so
     * its rays differ from render's in the last bits: edges and the far
     * plane at the horizon land in neighbouring pixels. Compared: the mean
     * difference, the pixels that differ by more than FN_EDGE, and the
     * sphere's pixels (blue clearly above red) in each image. */
    double sum_r = 0.0, sum_e = 0.0;
    long edge = 0, sphere_r = 0, sphere_v = 0;
    for (size_t p = 0; p < (size_t)FW * FH; p++) {
        double e = 0.0;
        for (int c = 0; c < 3; c++) {
            assert_true(isfinite(v->rgb[3 * p + c]));
            double ec = fabs((double)v->rgb[3 * p + c] - (double)r->rgb[3 * p + c]);
            e = fmax(e, ec);
            sum_e += ec;
            sum_r += r->rgb[3 * p + c];
        }
        edge += e > FN_EDGE;
        sphere_r += r->rgb[3 * p + 2] > 2.0 * r->rgb[3 * p] + 0.02;
        sphere_v += v->rgb[3 * p + 2] > 2.0 * v->rgb[3 * p] + 0.02;
    }
    double mean_e = sum_e / (FW * FH * 3.0);
    printf("view against render: mean |difference| %.5f (bound %.3f), %ld of %d pixels differ by more than %.2f; sphere "
           "pixels %ld (render) and %ld (view); image mean %.4f\n",
           mean_e, FN_MEAN, edge, FW * FH, FN_EDGE, sphere_r, sphere_v, sum_r / (FW * FH * 3.0));
    assert_true(sum_r > 0.05 * FW * FH * 3.0); /* lit, not black */
    assert_true(sphere_r > 50);                /* the traced placement put the sphere in view */
    assert_true(labs(sphere_v - sphere_r) <= sphere_r / 10);
    assert_true(mean_e < FN_MEAN);
    assert_true(edge * 50 < FW * FH); /* under 2%: edges only */
    fb_free(r);
    fb_free(v);
    diag_free(d);
}

/* `clock V` in a script, through the window: the viewer in --gi links
 * shows the sheet room (finer: walls of 12 x 12 cells, a 24 x 24 sheet,
 * about 3,000 vertices, so that the update takes a while) at clock 0 refined, is told `clock 0.6` while the
 * camera orbits back and forth, and its refined screenshot afterwards
 * matches `partray render --gi links --clock 0.6 +A0.3 +R3` (mean
 * |difference| under CLK_MEAN and mean luminance within 1%: the viewer's
 * camera is rebuilt from the scene's, so edges land in neighbouring
 * pixels), while the render at clock 0 differs from it by more than 3
 * CLK_MEAN (the bound can fail); the exit summary says one scene at a new
 * clock was taken over and images were shown while it was prepared. */
#define CLK_MEAN 0.001
static void test_viewer_clock(void **st)
{
    (void)st;
    if (!have_program("Xvfb")) {
        printf("Xvfb not found on PATH: the viewer cannot be run headless here\n");
        skip();
    }
    enum { CW = 96, CH = 72 };
    char scene_path[512], script[512], cmd[4096], path[600], text[2048];
    snprintf(scene_path, sizeof scene_path, "%s/sheet.pov", tmpdir);
    snprintf(script, sizeof script, "%s/clk.txt", tmpdir);
    write_file(scene_path, sheet_room_pov);
    int n = snprintf(text, sizeof text, "0.0 wait-idle\n0.1 clock 0.6\n");
    for (int k = 0; k < 12; k++)
        n += snprintf(text + n, sizeof text - (size_t)n, "%.2f camera orbit %d 0\n", 0.1 + 0.02 * k, k % 2 ? -3 : 3);
    snprintf(text + n, sizeof text - (size_t)n, "0.4 wait-idle\n0.5 screenshot %s/clk_view.exr\n0.6 quit\n", tmpdir);
    write_file(script, text);
    for (int k = 0; k < 2; k++) {
        snprintf(cmd, sizeof cmd,
                 "cd '%s' && '%s' render '%s' -o '%s/clk_render%d.exr' --size %dx%d --gi links --clock %s +A0.3 +R3 "
                 "--threads 2 --quiet -D NR=12 -D NS=24",
                 tmpdir, PARTRAY_BIN, scene_path, tmpdir, k, CW, CH, k ? "0.6" : "0");
        assert_int_equal(run_capture(cmd), 0);
    }
    assert_true(start_xvfb());
    snprintf(cmd, sizeof cmd,
             "cd '%s' && ASAN_OPTIONS=detect_leaks=0 DISPLAY=%s timeout 120 '%s' view '%s' --size %dx%d --gi links "
             "--threads 2 -D NR=12 -D NS=24 --script '%s'",
             tmpdir, display, PARTRAY_BIN, scene_path, CW, CH, script);
    int rc = run_capture(cmd);
    stop_xvfb();
    printf("exit %d:\n%s", rc, out_text);
    assert_int_equal(rc, 0);
    const char *sum = strstr(out_text, "view: clock ");
    double shown = -1, asked = -1, took = -1;
    long updates = -1, busy = -1;
    /* the summary line (the action's own "view: clock V" comes first) */
    while (sum && sscanf(sum, "view: clock %lf shown (%lf asked): %ld", &shown, &asked, &updates) != 3)
        sum = strstr(sum + 1, "view: clock ");
    assert_non_null(sum);
    sum = strstr(sum, "the last after ");
    assert_non_null(sum);
    assert_int_equal(sscanf(sum, "the last after %lf s; %ld", &took, &busy), 2);
    assert_true(shown == 0.6 && asked == 0.6);
    assert_int_equal(updates, 1);
    assert_true(busy >= 1);

    framebuffer *r0 = NULL, *r1 = NULL, *v = NULL;
    diag *d = diag_new();
    snprintf(path, sizeof path, "%s/clk_render0.exr", tmpdir);
    assert_int_equal(img_read(path, 0, &r0, d), PT_OK);
    snprintf(path, sizeof path, "%s/clk_render1.exr", tmpdir);
    assert_int_equal(img_read(path, 0, &r1, d), PT_OK);
    snprintf(path, sizeof path, "%s/clk_view.exr", tmpdir);
    assert_int_equal(img_read(path, 0, &v, d), PT_OK);
    assert_int_equal(v->width, CW);
    assert_int_equal(v->height, CH);
    double e1 = 0, e0 = 0, s1 = 0, sv = 0;
    for (size_t i = 0; i < (size_t)CW * CH * 3; i++) {
        assert_true(isfinite(v->rgb[i]));
        e1 += fabs(v->rgb[i] - r1->rgb[i]);
        e0 += fabs(r0->rgb[i] - r1->rgb[i]);
        s1 += r1->rgb[i];
        sv += v->rgb[i];
    }
    e1 /= CW * CH * 3.0;
    e0 /= CW * CH * 3.0;
    printf("view at clock 0.6 against render --clock 0.6: mean |difference| %.5f (bound %.3f), mean %.4f vs %.4f (%+.2f%%); "
           "render at clock 0 against 0.6: %.5f\n",
           e1, CLK_MEAN, sv / (CW * CH * 3.0), s1 / (CW * CH * 3.0), 100.0 * (sv / s1 - 1.0), e0);
    assert_true(s1 > 0.05 * CW * CH * 3.0);
    assert_true(e1 < CLK_MEAN);
    assert_true(fabs(sv / s1 - 1.0) < 0.01);
    assert_true(e0 > 3 * CLK_MEAN);
    fb_free(r0);
    fb_free(r1);
    fb_free(v);
    diag_free(d);
}

/* ------------------------------------- particle relight, no display */

static framebuffer *gi_pass(view_gi *g, int w, int h)
{
    framebuffer *fb = fb_new(w, h);
    assert_non_null(fb);
    view_gi_pass p = {w, h, 1, 2, 0, NULL};
    view_gi_times t;
    diag *d = diag_new();
    assert_int_equal(view_gi_render(g, &p, fb, &t, d), PT_OK);
    diag_free(d);
    return fb;
}

static double max_diff(const framebuffer *a, const framebuffer *b)
{
    double e = 0;
    for (size_t i = 0; i < (size_t)a->width * a->height * 3; i++) e = fmax(e, fabs(a->rgb[i] - b->rgb[i]));
    return e;
}

/* The particle mode's light edit: a cancelled relight keeps the old
 * lighting exactly (the image with the moved light's direct term and the
 * old indirect light does not change), the mode stays stale, and the relight
 * that completes gives exactly the image of a mode opened with the light
 * already there (same particles, same seed); the preview instance's lighting
 * likewise (cancelled: no change; done: the passes use it, and its image is
 * within 2% of the relit one). 1,200 particles and a preview instance of
 * 500, the C build of the kernels: about 5 s on the shared 2-core machine
 * (geometry stages 2.4 s for the first open, both instances). */
static void test_particle_relight_cancel(void **st)
{
    (void)st;
    scene *sc = NULL;
    sdl_options so;
    sdl_default_options(&so);
    diag *d = diag_new();
    assert_int_equal(sdl_parse_string("two.pov", two_spheres_pov, &so, &sc, d), PT_OK);
    pt_status ps = PT_OK;
    accel *acc = accel_build(sc, 2, d, &ps);
    assert_non_null(acc);
    const int w = 48, h = 48;
    view_gi_opts go;
    memset(&go, 0, sizeof go);
    go.threads = 2;
    go.particles = 1200;
    go.preview_particles = 500;
    go.cl_device = "c"; /* the C build of the kernels: no OpenCL program build */
    go.bounces = 3;
    view_gi_times t;
    view_gi *g = NULL;
    double t_open = timer_now();
    assert_int_equal(view_gi_open(&g, GI_PARTICLE, sc, acc, &go, &t, d), PT_OK);
    printf("opened: %.2f s (geometry stages %.2f s, lighting %.3f s)\n", timer_now() - t_open, t.build, t.light);
    assert_int_equal(view_gi_slow_light(g), t.light > 0.040); /* a stale preview first only when relighting is slow */
    framebuffer *a = gi_pass(g, w, h);

    view_gi_scene(g)->lights[0].position = light_b;
    view_gi_lights_changed(g);
    assert_true(view_gi_stale(g));
    framebuffer *q = gi_pass(g, w, h); /* new direct, old indirect */
    volatile int cancel = 1;
    assert_int_equal(view_gi_relight(g, &cancel, &t, d), PT_OK);
    assert_true(view_gi_stale(g));
    framebuffer *q2 = gi_pass(g, w, h);
    double e_cancel = max_diff(q, q2);
    assert_false(view_gi_last_coarse(g));
    /* the preview lighting: cancelled, nothing changes; done, the passes use it */
    assert_true(view_gi_has_preview_light(g));
    assert_int_equal(view_gi_relight_preview(g, &cancel, &t, d), PT_OK);
    framebuffer *q3 = gi_pass(g, w, h);
    assert_false(view_gi_last_coarse(g));
    double e_cancel_preview = max_diff(q, q3);
    cancel = 0;
    assert_int_equal(view_gi_relight_preview(g, &cancel, &t, d), PT_OK);
    assert_true(view_gi_stale(g));
    framebuffer *cq = gi_pass(g, w, h);
    assert_true(view_gi_last_coarse(g));
    assert_int_equal(view_gi_relight(g, &cancel, &t, d), PT_OK);
    assert_false(view_gi_stale(g));
    printf("relight: %.1f ms\n", t.light * 1e3);
    framebuffer *r = gi_pass(g, w, h);
    assert_false(view_gi_last_coarse(g));

    /* a mode opened with the light at B */
    scene sc_b = *sc;
    scene_light lb = sc->lights[0];
    lb.position = light_b;
    sc_b.lights = &lb;
    view_gi *gb = NULL;
    go.preview_particles = -1; /* not needed here */
    assert_int_equal(view_gi_open(&gb, GI_PARTICLE, &sc_b, acc, &go, &t, d), PT_OK);
    framebuffer *fresh = gi_pass(gb, w, h);
    double e_fresh = max_diff(r, fresh), e_stale = max_diff(q, r), e_moved = max_diff(a, q);
    /* the preview lighting's image against the relit one: mean difference
     * relative to the mean, and against the stale image's */
    double sum_r = 0, d_cq = 0, d_q = 0;
    for (size_t i = 0; i < (size_t)w * h * 3; i++) {
        sum_r += r->rgb[i];
        d_cq += fabs(cq->rgb[i] - r->rgb[i]);
        d_q += fabs(q->rgb[i] - r->rgb[i]);
    }
    printf("mean |preview-lit - relit| %.4f, |stale - relit| %.4f (relit mean %.4f); cancelled preview relight changed %.3g\n",
           d_cq / (w * h * 3.0), d_q / (w * h * 3.0), sum_r / (w * h * 3.0), e_cancel_preview);
    assert_true(e_cancel_preview == 0);
    /* 500 particles against 1,200: their noise, well inside 2% of the mean */
    assert_true(d_cq < 0.02 * sum_r);
    assert_true(max_diff(cq, q) > 0); /* relit, not the stale image */
    printf("cancelled relight changed the image by %.3g; relit vs opened at B %.3g; stale vs relit %.3g; before vs after "
           "the move %.3g\n",
           e_cancel, e_fresh, e_stale, e_moved);
    assert_true(e_cancel == 0);
    assert_true(e_fresh < 1e-5);
    assert_true(e_stale > 1e-3); /* the indirect light did change */
    assert_true(e_moved > 0.1);  /* the shadows moved */
    view_gi_close(g);
    view_gi_close(gb);
    fb_free(a);
    fb_free(q);
    fb_free(q2);
    fb_free(q3);
    fb_free(cq);
    fb_free(r);
    fb_free(fresh);
    accel_free(acc);
    scene_free(sc);
    diag_free(d);
}

/* ------------------------------------- caustic layer, no display */

/* A glass sphere over a floor under a point light, photons{} on it; the
 * camera looks straight down at the caustic (the sphere is no_image). %s:
 * the global photons block, the light's x. */
static const char *caustic_view_fmt =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 max_trace_level 10 %s radiosity { count 20 recursion_limit 2 } }\n"
    "camera { orthographic location <0, 5, 0> look_at <0, 0, 0> sky z right x*0.6 up z*0.6 }\n"
    "light_source { <%g, 10, 0> color rgb 1 }\n"
    "sphere { <0, 0.8, 0>, 0.5 pigment { rgbf 1 } finish { ambient 0 diffuse 0 } interior { ior 1.5 } no_image\n"
    "         photons { target refraction on reflection off } }\n"
    "plane { y, 0 pigment { rgb 1 } finish { ambient 0 diffuse 0.8 } }\n"
    "box { <0.4, 0, -1>, <0.5, 1, 1> pigment { rgb 1 } finish { ambient 0 diffuse 0.8 } }\n";

static void caustic_world(double lx, int photons, scene **sc, accel **a)
{
    char text[1024];
    snprintf(text, sizeof text, caustic_view_fmt, photons ? "photons { spacing 0.004 }" : "", lx);
    sdl_options so;
    sdl_default_options(&so);
    diag *d = diag_new();
    assert_int_equal(sdl_parse_string("caustic.pov", text, &so, sc, d), PT_OK);
    pt_status ps = PT_OK;
    *a = accel_build(*sc, 2, d, &ps);
    assert_non_null(*a);
    diag_free(d);
}

/* Mean green over the central c x c pixels of a w x w image. */
static double centre_green(const framebuffer *fb, int c)
{
    double s = 0;
    int w = fb->width;
    for (int y = (w - c) / 2; y < (w + c) / 2; y++)
        for (int x = (w - c) / 2; x < (w + c) / 2; x++) s += fb->rgb[((size_t)y * w + x) * 3 + 1];
    return s / (c * c);
}

/* Opens mode on sc; a mode that opens stale (none with photons: its
 * caustic layer is the first relight's) is relit at once. *opened_stale
 * (NULL: not wanted) says whether it was. */
static view_gi *caustic_mode(int mode, const scene *sc, const accel *a, int w, int *opened_stale)
{
    view_gi_opts go;
    memset(&go, 0, sizeof go);
    go.threads = 2;
    go.width = go.height = w;
    go.seed = 1;
    go.cl_device = "c";
    go.particles = 1200;
    go.preview_particles = -1;
    view_gi_times t;
    view_gi *g = NULL;
    diag *d = diag_new();
    assert_int_equal(view_gi_open(&g, mode, sc, a, &go, &t, d), PT_OK);
    int stale = view_gi_stale(g);
    if (opened_stale) *opened_stale = stale;
    if (stale) assert_int_equal(view_gi_relight(g, NULL, &t, d), PT_OK);
    assert_false(view_gi_stale(g));
    diag_free(d);
    return g;
}

/* The viewer's none and particle modes show the scene's caustics, as
 * `partray render` does: none opens stale where there are photons (its
 * first relight shoots them), and its first full-resolution pass then equals
 * render_gi's --gi none image of the same size and seed exactly (one
 * caustic layer, same G-buffer), and the caustic is there (the focus
 * region at least 3 times as bright as without photons). A light edit: a
 * cancelled relight keeps the old layer (the pass does not change), the
 * relight that completes gives exactly the image of a mode opened with the
 * light already there, in none and in particle (whose lighting stage takes
 * the new layer's photons). */
static void test_viewer_caustics(void **st)
{
    (void)st;
    const int w = 40, c = 8;
    scene *sc = NULL, *sc_b = NULL, *sc_off = NULL;
    accel *a = NULL, *a_b = NULL, *a_off = NULL;
    caustic_world(0.0, 1, &sc, &a);
    caustic_world(1.0, 1, &sc_b, &a_b);
    caustic_world(0.0, 0, &sc_off, &a_off);

    int stale_photons = 0, stale_none = 1, stale_particle = 1;
    view_gi *g = caustic_mode(GI_NONE, sc, a, w, &stale_photons);
    framebuffer *v = gi_pass(g, w, w);
    render_gi_opts o;
    memset(&o, 0, sizeof o);
    o.mode = GI_NONE;
    o.width = o.height = w;
    o.threads = 2;
    o.seed = 1;
    o.quality = 9;
    o.cl_device = "c";
    framebuffer *r = fb_new(w, w);
    render_gi_result rr;
    memset(&rr, 0, sizeof rr);
    diag *d = diag_new();
    assert_int_equal(render_gi(sc, a, &o, r, &rr, d), PT_OK);
    assert_true(rr.caus.st.stored > 1000);
    view_gi *goff = caustic_mode(GI_NONE, sc_off, a_off, w, &stale_none);
    /* none opens stale where there are photons to shoot, so that the
     * viewer's first image does not wait for them */
    assert_true(stale_photons);
    assert_false(stale_none);
    framebuffer *voff = gi_pass(goff, w, w);
    double e_render = max_diff(v, r), focus = centre_green(v, c), focus_off = centre_green(voff, c);
    char desc[256];
    view_gi_describe(g, desc, sizeof desc);
    printf("none: view against render %.3g; focus %.4f, without photons %.4f (%s)\n", e_render, focus, focus_off, desc);
    assert_true(e_render < 1e-6);
    assert_true(focus > 3.0 * focus_off);

    /* the light moves to x = 1 */
    view_gi_scene(g)->lights[0].position = sc_b->lights[0].position;
    view_gi_lights_changed(g);
    framebuffer *q = gi_pass(g, w, w); /* new direct light, old caustics */
    volatile int cancel = 1;
    view_gi_times t;
    assert_int_equal(view_gi_relight(g, &cancel, &t, d), PT_OK);
    assert_true(view_gi_stale(g));
    framebuffer *q2 = gi_pass(g, w, w);
    cancel = 0;
    assert_int_equal(view_gi_relight(g, &cancel, &t, d), PT_OK);
    assert_false(view_gi_stale(g));
    framebuffer *rl = gi_pass(g, w, w);
    view_gi *gb = caustic_mode(GI_NONE, sc_b, a_b, w, NULL);
    framebuffer *fresh = gi_pass(gb, w, w);
    double e_cancel = max_diff(q, q2), e_fresh = max_diff(rl, fresh), e_moved = max_diff(q, rl);
    printf("none: cancelled relight changed %.3g, relit vs opened there %.3g, caustic moved %.3g\n", e_cancel, e_fresh,
           e_moved);
    assert_true(e_cancel == 0);
    assert_true(e_fresh < 1e-6);
    assert_true(e_moved > 0.05);

    /* particle: the same light edit */
    view_gi *gp = caustic_mode(GI_PARTICLE, sc, a, w, &stale_particle);
    assert_false(stale_particle); /* particle shoots its layer as it opens */
    view_gi *gpoff = caustic_mode(GI_PARTICLE, sc_off, a_off, w, NULL);
    framebuffer *p0 = gi_pass(gp, w, w), *poff = gi_pass(gpoff, w, w);
    double pfocus = centre_green(p0, c), pfocus_off = centre_green(poff, c);
    view_gi_scene(gp)->lights[0].position = sc_b->lights[0].position;
    view_gi_lights_changed(gp);
    assert_int_equal(view_gi_relight(gp, &cancel, &t, d), PT_OK);
    framebuffer *prl = gi_pass(gp, w, w);
    view_gi *gpb = caustic_mode(GI_PARTICLE, sc_b, a_b, w, NULL);
    framebuffer *pfresh = gi_pass(gpb, w, w);
    double pe_fresh = max_diff(prl, pfresh), pe_moved = max_diff(p0, prl);
    view_gi_describe(gp, desc, sizeof desc);
    printf("particle: focus %.4f, without photons %.4f; relit vs opened there %.3g, moved %.3g (%s)\n", pfocus,
           pfocus_off, pe_fresh, pe_moved, desc);
    assert_true(pfocus > 3.0 * pfocus_off);
    assert_true(pe_fresh < 1e-5);
    assert_true(pe_moved > 0.05);

    framebuffer *fbs[] = {v, r, voff, q, q2, rl, fresh, p0, poff, prl, pfresh};
    for (size_t i = 0; i < sizeof fbs / sizeof fbs[0]; i++) fb_free(fbs[i]);
    view_gi *gs[] = {g, goff, gb, gp, gpoff, gpb};
    for (size_t i = 0; i < sizeof gs / sizeof gs[0]; i++) view_gi_close(gs[i]);
    accel_free(a);
    accel_free(a_b);
    accel_free(a_off);
    scene_free(sc);
    scene_free(sc_b);
    scene_free(sc_off);
    diag_free(d);
}

/* ------------------------------------------------- overlay, no display */

static void test_overlay_font(void **st)
{
    (void)st;
    /* every character the overlay prints has a glyph */
    const char *used = "0123456789 ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz.,:;/()[]<>-+=*%#|_!?'";
    for (const char *c = used; *c; c++) assert_true(view_overlay_has_glyph(*c));
    assert_false(view_overlay_has_glyph('~'));
    /* "1" has 10 set font pixels (5x7); at scale 2 each is 2x2 white */
    enum { BW = 40, BH = 30 };
    uint8_t buf[BW * BH * 4];
    memset(buf, 0, sizeof buf);
    const char *one[] = {"1"};
    view_overlay_box b = view_overlay_draw(buf, BW, BH, 2, 1, one, 1, 2, 160);
    long white = 0, dark = 0, untouched = 0;
    for (int y = 0; y < BH; y++)
        for (int x = 0; x < BW; x++) {
            const uint8_t *p = buf + (y * BW + x) * 4;
            int inside = x >= b.x && x < b.x + b.w && y >= b.y && y < b.y + b.h;
            if (p[3] == 255 && p[0] == 255) white++;
            else if (p[3] == 160 && p[0] == 0) dark += inside;
            else untouched += !inside && p[3] == 0;
        }
    printf("glyph '1' at scale 2: box %dx%d at (%d,%d), %ld white, %ld dark, %ld untouched\n", b.w, b.h, b.x, b.y, white,
           dark, untouched);
    /* box: (1 char * 6 - 1 + 2 * 3) x (1 line * 9 - 2 + 2 * 3) font pixels */
    assert_int_equal(b.w, 11 * 2);
    assert_int_equal(b.h, 13 * 2);
    assert_int_equal(white, 40);
    assert_int_equal(dark, b.w * b.h - 40);
    assert_int_equal(untouched, BW * BH - b.w * b.h);
    /* lower case draws as capitals */
    uint8_t u[BW * BH * 4], l[BW * BH * 4];
    memset(u, 0, sizeof u);
    memset(l, 0, sizeof l);
    const char *up[] = {"GI"}, *lo[] = {"gi"};
    view_overlay_draw(u, BW, BH, 0, 0, up, 1, 1, 160);
    view_overlay_draw(l, BW, BH, 0, 0, lo, 1, 1, 160);
    assert_memory_equal(u, l, sizeof u);
    /* clipped at the buffer's edge: no writes outside, box clipped */
    memset(buf, 0, sizeof buf);
    const char *wide[] = {"FRAME 123 MS: BUILD 0 LIGHT 0"};
    b = view_overlay_draw(buf, BW, BH, 30, 20, wide, 1, 1, 160);
    assert_int_equal(b.w, BW - 30);
    assert_int_equal(b.h, BH - 20);
}

/* ------------------------------------------- render thread, no display */

static int wait_idle(view_render *vr, double seconds)
{
    for (int i = 0; i < (int)(seconds * 200); i++) {
        if (view_render_idle(vr)) return 1;
        usleep(5000);
    }
    return 0;
}

/* The viewer's last refinement pass of none/particle/links on 2 threads
 * (view_gi.c whitted_settings at level 2: +A0.3 +R3), for a direct render
 * to compare with. */
static void last_pass_settings(shade_settings *ss, int w, int h)
{
    shade_default_settings(ss);
    ss->width = w;
    ss->height = h;
    ss->threads = 2;
    ss->antialias = 1;
    ss->aa_threshold = 0.3;
    ss->aa_depth = 3;
}

static void test_render_thread(void **st)
{
    (void)st;
    scene *sc = NULL;
    sdl_options so;
    sdl_default_options(&so);
    diag *d = diag_new();
    assert_int_equal(sdl_parse_string("two.pov", two_spheres_pov, &so, &sc, d), PT_OK);
    pt_status ps = PT_OK;
    accel *acc = accel_build(sc, 2, d, &ps);
    assert_non_null(acc);
    const int w = 64, h = 48;

    /* the reference: the same final pass rendered directly */
    shade_settings ss;
    last_pass_settings(&ss, w, h);
    ss.use_ambient = 1;
    framebuffer *ref = fb_new(w, h);
    assert_int_equal(shade_render(sc, acc, &ss, ref, NULL, d), PT_OK);

    view_light lights[1] = {{sc->lights[0].position, sc->lights[0].point_at, sc->lights[0].colour}};
    view_state s0 = {sc->camera, GI_NONE, lights};
    view_render_opts ro = {w, h, 2, 0, 0, 0};
    view_render *vr = NULL;
    assert_int_equal(view_render_start(&vr, sc, acc, &ro, &s0, d), PT_OK);
    assert_true(wait_idle(vr, 60));
    view_frame_info in;
    framebuffer *a = view_render_snapshot(vr, &in);
    assert_non_null(a);
    double e = 0;
    for (size_t i = 0; i < (size_t)w * h * 3; i++) e = fmax(e, fabs(a->rgb[i] - ref->rgb[i]));
    printf("final level %d/%d, %dx%d, largest difference to shade_render %.3g\n", in.level, in.last_level, in.width,
           in.height, e);
    assert_int_equal(in.level, in.last_level);
    assert_int_equal(in.width, w);
    assert_true(in.complete);
    assert_true(e == 0);

    /* a burst of camera moves and a light move: the thread ends idle on the
     * newest state, and the image shows the light moved */
    view_camera vc;
    view_camera_from_scene(&vc, &sc->camera, 11.3);
    for (int i = 0; i < 20; i++) {
        view_camera_orbit(&vc, 0.5, 0);
        view_state s = s0;
        view_camera_to_scene(&vc, &s.camera);
        view_render_submit(vr, &s, VIEW_CAUSE_CAMERA);
        usleep(2000);
    }
    view_camera_orbit(&vc, -10, 0); /* back where it started */
    lights[0].position = light_b;
    view_state s1 = s0;
    view_camera_to_scene(&vc, &s1.camera);
    view_render_submit(vr, &s1, VIEW_CAUSE_LIGHT);
    assert_false(view_render_idle(vr));
    assert_true(wait_idle(vr, 60));
    framebuffer *b = view_render_snapshot(vr, &in);
    printf("after 21 submits: generation %ld, level %d, cause %d\n", in.generation, in.level, in.cause);
    assert_int_equal(in.generation, 21);
    assert_true(in.cause & VIEW_CAUSE_LIGHT);
    double diff = 0;
    for (size_t i = 0; i < (size_t)w * h * 3; i++) diff += fabs(a->rgb[i] - b->rgb[i]);
    diff /= w * h * 3.0;
    printf("mean |b - a| after the light move: %.4f\n", diff);
    assert_true(diff > 0.005);

    /* messages: none expected */
    diag *m = diag_new();
    view_render_messages(vr, m);
    assert_int_equal(diag_count(m), 0);
    diag_free(m);
    view_render_stop(vr);
    fb_free(a);
    fb_free(b);
    fb_free(ref);
    accel_free(acc);
    scene_free(sc);
    diag_free(d);
}

/* ------------------------------------------------- the clock, no display */

static scene *sheet_scene(double clock, diag *d)
{
    sdl_options so;
    sdl_default_options(&so);
    sdl_set_still_clock(&so, clock);
    scene *sc = NULL;
    pt_status st = sdl_parse_string("sheet_room.pov", sheet_room_pov, &so, &sc, d);
    for (int i = 0; i < diag_count(d); i++) printf("%s\n", diag_get(d, i)->text);
    assert_int_equal(st, PT_OK);
    return sc;
}

/* view_render_opts.scene_at for the sheet room; counts its calls. It
 * takes at least 0.3 s (as a larger scene's parse would), so that the
 * images made meanwhile do not depend on how fast the machine is. */
static int sheet_calls;
static pt_status sheet_at(void *ctx, double clock, scene **sc, accel **a, diag *d)
{
    (void)ctx;
    sheet_calls++;
    usleep(300000);
    sdl_options so;
    sdl_default_options(&so);
    sdl_set_still_clock(&so, clock);
    *sc = NULL;
    *a = NULL;
    pt_status st = sdl_parse_string("sheet_room.pov", sheet_room_pov, &so, sc, d);
    if (st != PT_OK) return st;
    *a = accel_build(*sc, 2, d, &st);
    if (!*a) {
        scene_free(*sc);
        *sc = NULL;
        return st == PT_OK ? PT_ERR_INTERNAL : st;
    }
    return PT_OK;
}

/* The clock in --gi links, through the render thread as the viewer drives
 * it: after `clock 0.6` the scene is evaluated again and linked where it
 * deformed on the clock thread while camera moves keep producing images
 * of the old clock; the newest finished solution then takes over. Its
 * refined image equals a fresh --gi links render of the scene at clock
 * 0.6 (a new gi_vlinks instance, the same pass settings) within 1e-5 of
 * the largest value (the incremental links equal a fresh build bit for
 * bit, tests/test_motion.c), and fewer elements than all were linked. */
static void test_render_thread_clock(void **st)
{
    (void)st;
    diag *d = diag_new();
    scene *sc = sheet_scene(0.0, d);
    pt_status ps = PT_OK;
    accel *acc = accel_build(sc, 2, d, &ps);
    assert_non_null(acc);
    const int w = 64, h = 48;
    const double clock1 = 0.6;

    /* the reference: a fresh links solution at the new clock, the viewer's
     * last pass (view_gi.c: whitted_settings at level 2, links_render) */
    scene *sc1 = sheet_scene(clock1, d);
    accel *acc1 = accel_build(sc1, 2, d, &ps);
    assert_non_null(acc1);
    gi_vlinks_settings vs;
    gi_vlinks_default_settings(&vs);
    vs.threads = 2;
    vs.pigment = shade_tex_pigment_at;
    gi_vlinks *gv = gi_vlinks_new(&vs);
    gi_vlinks_stats gst;
    assert_int_equal(gi_vlinks_frame(gv, sc1, acc1, 1, &gst, d), PT_OK);
    shade_settings ss;
    last_pass_settings(&ss, w, h);
    ss.use_ambient = radrules_of(sc1, 1).ambient;
    ss.indirect = gi_vlinks_indirect;
    ss.indirect_ctx = gv;
    framebuffer *ref = fb_new(w, h);
    assert_int_equal(shade_render(sc1, acc1, &ss, ref, NULL, d), PT_OK);
    printf("fresh --gi links at clock %.1f: %ld elements, %ld links\n", clock1, gst.elements, gst.merged_links);

    view_light lights[1] = {{sc->lights[0].position, sc->lights[0].point_at, sc->lights[0].colour}};
    view_state s0 = {sc->camera, GI_LINKS, lights, 0.0};
    view_render_opts ro = {w, h, 2, 0, 0, 0};
    ro.scene_at = sheet_at;
    ro.clock = 0.0;
    view_render *vr = NULL;
    assert_int_equal(view_render_start(&vr, sc, acc, &ro, &s0, d), PT_OK);
    assert_true(wait_idle(vr, 120));
    view_frame_info in;
    framebuffer *a0 = view_render_snapshot(vr, &in);
    assert_non_null(a0);
    assert_int_equal(in.gi_mode, GI_LINKS);
    assert_true(in.clock == 0.0);

    /* the new clock, then camera moves while it is prepared */
    view_state s1 = s0;
    s1.clock = clock1;
    view_render_submit(vr, &s1, VIEW_CAUSE_CLOCK);
    view_camera vc;
    view_camera_from_scene(&vc, &sc->camera, 3.5);
    long serial = 0, busy_images = 0, images = 0;
    uint8_t *rgba = malloc((size_t)w * h * 4);
    double t0 = timer_now(), t_new = 0;
    int k = 0;
    while (timer_now() - t0 < 120) {
        if (view_render_fetch(vr, &serial, rgba, &in)) {
            images++;
            if (in.clock_busy && in.clock == 0.0) busy_images++;
            if (in.clock == clock1) {
                t_new = timer_now() - t0;
                break;
            }
        }
        view_camera_orbit(&vc, (k++ % 2) ? -1.0 : 1.0, 0);
        view_state s = s1;
        view_camera_to_scene(&vc, &s.camera);
        view_render_submit(vr, &s, VIEW_CAUSE_CAMERA);
        usleep(15000);
    }
    printf("clock %.1f shown after %.3f s (the update took %.3f s); %ld images fetched meanwhile, %ld of the old clock made "
           "while the update ran\n",
           clock1, t_new, in.clock_update, images, busy_images);
    assert_true(in.clock == clock1);
    assert_int_equal(in.clock_updates, 1);
    assert_true(busy_images >= 3); /* a 0.3 s update, camera moves every 15 ms, previews of a few ms */
    assert_int_equal(sheet_calls, 1);

    /* back to the scene's camera, refined */
    view_render_submit(vr, &s1, VIEW_CAUSE_CAMERA);
    assert_true(wait_idle(vr, 120));
    framebuffer *b = view_render_snapshot(vr, &in);
    assert_non_null(b);
    long linked = -1, elements = -1;
    const char *p = strstr(in.describe, "links (");
    if (p) p = strchr(p, ',');
    if (p) sscanf(p, ", %ld of %ld linked", &linked, &elements);
    double e = 0, mx = 0, moved = 0;
    for (size_t i = 0; i < (size_t)w * h * 3; i++) {
        e = fmax(e, fabs(b->rgb[i] - ref->rgb[i]));
        mx = fmax(mx, fabs(ref->rgb[i]));
        moved += fabs(b->rgb[i] - a0->rgb[i]);
    }
    moved /= w * h * 3.0;
    printf("refined at clock %.1f: level %d/%d, '%s'; largest difference to the fresh render %.3g (largest value %.3g); "
           "mean |difference| to clock 0: %.4f\n",
           in.clock, in.level, in.last_level, in.describe, e, mx, moved);
    assert_true(in.complete);
    assert_true(in.clock == clock1);
    assert_true(mx > 0.1);
    assert_true(e <= 1e-5 * mx);
    assert_true(moved > 0.002); /* the sheet rose: the image changed */
    assert_true(elements == gst.elements);
    assert_true(linked > 0 && linked < elements);

    diag *m = diag_new();
    view_render_messages(vr, m);
    for (int i = 0; i < diag_count(m); i++) printf("message: %s\n", diag_get(m, i)->text);
    assert_int_equal(diag_count(m), 0);
    diag_free(m);
    view_render_stop(vr);
    free(rgba);
    fb_free(a0);
    fb_free(b);
    fb_free(ref);
    gi_vlinks_free(gv);
    accel_free(acc1);
    scene_free(sc1);
    accel_free(acc);
    scene_free(sc);
    diag_free(d);
}

/* ------------------------------------------------- camera, no display */

static scene_camera parse_camera(const char *text)
{
    scene *sc = NULL;
    sdl_options so;
    sdl_default_options(&so);
    diag *d = diag_new();
    pt_status st = sdl_parse_string("cam", text, &so, &sc, d);
    for (int i = 0; i < diag_count(d); i++) printf("%s\n", diag_get(d, i)->text);
    assert_int_equal(st, PT_OK);
    scene_camera c = sc->camera;
    scene_free(sc);
    diag_free(d);
    return c;
}

static double vdiff(vec3 a, vec3 b) { return v3_len(v3_sub(a, b)); }

static void roundtrip(const char *camera_text, int mirrored)
{
    scene_camera c0 = parse_camera(camera_text);
    view_camera vc;
    view_camera_from_scene(&vc, &c0, 10.0);
    assert_int_equal(vc.mirrored, mirrored);
    /* unmoved: the scene's camera unchanged */
    scene_camera same;
    view_camera_to_scene(&vc, &same);
    assert_true(vdiff(same.direction, c0.direction) < 1e-12);

    double dist0 = v3_len(v3_sub(vc.location, vc.look_at));
    vec3 r0;
    view_camera_frame(&vc, NULL, &r0, NULL);
    vec3 loc0 = vc.location;
    view_camera_orbit(&vc, 10, 0);
    double moved_right = v3_dot(v3_sub(vc.location, loc0), r0);
    printf("orbit +10: moved %.4f along screen right, distance %.6f -> %.6f\n", moved_right, dist0,
           v3_len(v3_sub(vc.location, vc.look_at)));
    assert_true(moved_right > 0);
    assert_true(fabs(v3_len(v3_sub(vc.location, vc.look_at)) - dist0) < 1e-9 * dist0);
    view_camera_orbit(&vc, 20, 200); /* pitch clamps at 89 degrees */
    vec3 fw;
    view_camera_frame(&vc, &fw, NULL, NULL);
    assert_true(v3_dot(fw, vc.sky) < -sin(88.9 * M_PI / 180));
    view_camera_orbit(&vc, 0, -120);
    vec3 fw1, rt1;
    view_camera_frame(&vc, &fw1, &rt1, NULL);
    view_camera_look(&vc, 5, 0);
    vec3 fw2;
    view_camera_frame(&vc, &fw2, NULL, NULL);
    assert_true(v3_dot(v3_sub(fw2, fw1), rt1) > 0); /* +yaw looks towards screen right */
    view_camera_move(&vc, 1.5, -0.5, 0.25);
    view_camera_zoom(&vc, 0.8);

    scene_camera want;
    view_camera_to_scene(&vc, &want);
    char block[2048], src[2200];
    view_camera_format(&vc, block, sizeof block);
    snprintf(src, sizeof src, "#version 3.7;\n%s", block);
    scene_camera got = parse_camera(src);
    double e = fmax(fmax(vdiff(got.location, want.location), vdiff(got.direction, want.direction)),
                    fmax(vdiff(got.right, want.right), vdiff(got.up, want.up)));
    printf("camera{} round trip: largest vector difference %.3g\n", e);
    assert_true(e < 1e-6);
    /* mirrored stays mirrored */
    assert_true((v3_dot(v3_cross(got.up, got.direction), got.right) < 0) == mirrored);
}

static void test_camera_roundtrip(void **st)
{
    (void)st;
    /* cbox's mirrored camera */
    roundtrip("camera { location <27.8, 27.3, -80.0> direction <0, 0, 1> up <0, 1, 0> right <-1, 0, 0> angle 39.3 }\n", 1);
    roundtrip("camera { location <3, 4, -6> right x*1.5 up y look_at <0, 1, 0> angle 50 }\n", 0);
    roundtrip("camera { orthographic location <0, 5, -5> look_at 0 right 4*x up 3*y }\n", 0);
}

/* ------------------------------------------------- script, no display */

static void test_script_grammar(void **st)
{
    (void)st;
    diag *d = diag_new();
    view_script *vs = NULL;
    const char *text = "# comment\n"
                       "1.0 light 2 move 1 -2 3.5   # trailing comment\n"
                       "0.5 camera orbit 10 -5\n"
                       "1.0 gi next\n"
                       "\n"
                       "1.5 wait-idle\n"
                       "2.0 screenshot x.png\n"
                       "2.5 quit\n";
    assert_int_equal(view_script_parse("s", text, &vs, d), PT_OK);
    assert_int_equal(view_script_count(vs), 6);
    view_action a;
    assert_int_equal(view_script_next(vs, 100.0, 1, &a), 0); /* not started */
    view_script_start(vs, 10.0);
    assert_int_equal(view_script_next(vs, 10.4, 1, &a), 0);
    assert_int_equal(view_script_next(vs, 10.5, 1, &a), 1);
    assert_int_equal(a.kind, VIEW_ACT_CAMERA_ORBIT);
    assert_true(a.v[0] == 10 && a.v[1] == -5);
    assert_int_equal(view_script_next(vs, 11.0, 1, &a), 1);
    assert_int_equal(a.kind, VIEW_ACT_LIGHT_MOVE); /* ties keep file order */
    assert_int_equal(a.light, 2);
    assert_true(a.v[0] == 1 && a.v[1] == -2 && a.v[2] == 3.5);
    assert_int_equal(view_script_next(vs, 11.0, 1, &a), 1);
    assert_int_equal(a.kind, VIEW_ACT_GI);
    assert_int_equal(a.mode, -1);
    /* wait-idle at 1.5 holds until idle; the clock then resumes at 1.5 */
    assert_int_equal(view_script_next(vs, 11.6, 0, &a), 0);
    assert_int_equal(view_script_next(vs, 20.0, 0, &a), 0);
    assert_int_equal(view_script_next(vs, 30.0, 1, &a), 0); /* released; screenshot due at 30.5 */
    assert_int_equal(view_script_next(vs, 30.4, 1, &a), 0);
    assert_int_equal(view_script_next(vs, 30.5, 1, &a), 1);
    assert_int_equal(a.kind, VIEW_ACT_SCREENSHOT);
    assert_string_equal(a.text, "x.png");
    assert_int_equal(view_script_next(vs, 31.0, 1, &a), 1);
    assert_int_equal(a.kind, VIEW_ACT_QUIT);
    assert_true(view_script_done(vs));
    view_script_free(vs);

    struct { const char *text, *msg; int line, col; } bad[] = {
        {"0 light 0 move 1 2 3\n", "integer >= 1", 1, 9},
        {"0 quit\n1 camera spin 3 4\n", "unknown camera action 'spin'", 2, 10},
        {"x screenshot\n", "expected a time", 1, 1},
        {"1 light 1 move 1 2\n", "wrong number of values", 1, 19},
        {"1 gi photon\n", "unknown GI mode 'photon'", 1, 6},
        {"1 wait-idle now\n", "takes no arguments", 1, 13},
        {"2 camera zoom 0\n", "must be > 0", 1, 15},
        {"1 drag middle 1 2\n", "left or right", 1, 8},
        {"1 wheel 1.5\n", "whole number", 1, 9},
        {"1 key\n", "key takes NAME", 1, 6},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        diag *e = diag_new();
        vs = NULL;
        assert_int_equal(view_script_parse("bad.txt", bad[i].text, &vs, e), PT_ERR_SYNTAX);
        assert_null(vs);
        assert_true(diag_errors(e) >= 1);
        const diag_msg *m = diag_get(e, 0);
        char *f = diag_format(m);
        printf("%s\n", f);
        assert_non_null(strstr(m->text, bad[i].msg));
        assert_int_equal(m->loc.line, bad[i].line);
        assert_int_equal(m->loc.col, bad[i].col);
        free(f);
        diag_free(e);
    }
    diag_free(d);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/partray-view-XXXXXX");
    if (!mkdtemp(tmpdir)) return 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_camera_roundtrip),
        cmocka_unit_test(test_script_grammar),
        cmocka_unit_test(test_render_thread),
        cmocka_unit_test(test_render_thread_clock),
        cmocka_unit_test(test_overlay_font),
        cmocka_unit_test(test_particle_relight_cancel),
        cmocka_unit_test(test_viewer_caustics),
        cmocka_unit_test(test_viewer_script),
        cmocka_unit_test(test_viewer_overlay_reference),
        cmocka_unit_test(test_viewer_functions),
        cmocka_unit_test(test_viewer_clock),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    stop_xvfb();
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (rc == 0) run_capture(cmd);
    return rc;
}
