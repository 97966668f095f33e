/* test_anim.c - animations in one run, POV-Ray INI files, render windows
 * and `partray merge`, end to end through the partray command and checked
 * against POV-Ray 3.7 itself (`povray`) where it has the same option:
 * output names of every frame and the clock of every frame (POV-Ray's
 * output recorded in tests/anim), the pixels a window covers; tiles merged
 * equal the whole frame exactly (RMSE 0). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "framebuffer.h"
#include "img_exr.h"
#include "img_io.h"
#include "test_util.h"

#ifndef PT_SOURCE_DIR
#define PT_SOURCE_DIR "."
#endif

static char tmpdir[256];

/* The scene prints each frame's values (POV-Ray and partray both send
 * #debug to stderr). */
static const char *clock_scene =
    "#debug concat(\"K \", str(clock,0,6), \" fn \", str(frame_number,0,0), \" if \", str(initial_frame,0,0), "
    "\" ff \", str(final_frame,0,0), \" d \", str(clock_delta,0,6), \" on \", str(clock_on,0,0), \"\\n\")\n"
    "camera { location <0,0,-4> look_at 0 }\nbackground { rgb 1 }\n";

/* "name1 name2 ..." of the files in dir, sorted. */
static void list_dir(const char *dir, char *out, size_t n)
{
    struct dirent **ents;
    int k = scandir(dir, &ents, NULL, alphasort);
    out[0] = 0;
    for (int i = 0; i < k; i++) {
        if (ents[i]->d_name[0] != '.' && strstr(ents[i]->d_name, ".png")) {
            strncat(out, ents[i]->d_name, n - strlen(out) - 2);
            strncat(out, " ", n - strlen(out) - 1);
        }
        free(ents[i]);
    }
    free(ents);
}

/* The "K ..." lines of tu_out, in order (povray prints #debug text as it
 * is, partray as a located note "FILE:1:1: note: K ..."). */
static void k_lines(char *out, size_t n)
{
    out[0] = 0;
    for (const char *p = tu_out; *p;) {
        const char *e = strchr(p, '\n');
        size_t len = e ? (size_t)(e - p + 1) : strlen(p);
        const char *k = strncmp(p, "K ", 2) == 0 ? p : NULL;
        const char *note = strstr(p, "note: K ");
        if (!k && note && note < p + len) k = note + 6;
        if (k && strlen(out) + (size_t)(p + len - k) + 1 < n) strncat(out, k, (size_t)(p + len - k));
        p += len;
    }
}

/* POV-Ray's own output for each case of test_frames_as_povray (the
 * names of the frames it writes, the clock lines it prints), recorded in
 * tests/anim/frames_as_povray.expected: one block per case, "opts: OPTS",
 * "files: NAMES", then its K lines, ended by a blank line. Running POV-Ray
 * on each case at every test run cost most of the test's time for an
 * answer that only changes with POV-Ray. PARTRAY_RECORD_POVRAY=1 runs
 * povray and writes the file again. */
#define FRAMES_EXPECTED PT_SOURCE_DIR "/tests/anim/frames_as_povray.expected"

static void povray_frames(const char *opts, const char *dir, char *files, size_t nf, char *k, size_t nk)
{
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "cd '%s' && povray +Ik.pov +W8 +H6 -D -A -V %s +Oout.png", dir, opts);
    assert_int_equal(tu_run_capture(cmd), 0);
    k_lines(k, nk);
    list_dir(dir, files, nf);
}

/* The recorded block of opts: its file names and K lines; 0 when absent. */
static int recorded_frames(const char *text, const char *opts, char *files, size_t nf, char *k, size_t nk)
{
    char head[256];
    snprintf(head, sizeof head, "opts: %s\nfiles: ", opts);
    const char *p = strstr(text, head);
    if (!p) return 0;
    p += strlen(head);
    const char *e = strchr(p, '\n');
    if (!e) return 0;
    snprintf(files, nf, "%.*s", (int)(e - p), p);
    const char *end = strstr(e + 1, "\n\n");
    if (!end) return 0;
    snprintf(k, nk, "%.*s", (int)(end + 1 - (e + 1)), e + 1);
    return 1;
}

/* Every frame of each animation in one run: the same file names and the
 * same clock values as povray renders with the same options (its output
 * recorded, above). */
static void test_frames_as_povray(void **st)
{
    (void)st;
    const char *opts[] = {
        "+KFI1 +KFF12",               /* out01..out12 */
        "+KFI0 +KFF9 +KC",            /* cyclic: final frame 10, two digits */
        "+KFI5 +KFF8 +SF6 +EF7 +KI2 +KF4",
        "+KFI1 +KFF10 +SF0.3 +EF0.6", /* fractions of the frames */
        "+KFI1 +KFF9 +KC",
        "+KFI3 +KFF3",
    };
    const int record = getenv("PARTRAY_RECORD_POVRAY") != NULL;
    const char *text = record ? NULL : tu_read_file(FRAMES_EXPECTED);
    if (!record && !text) fail_msg("%s missing: make it with PARTRAY_RECORD_POVRAY=1 (needs povray)", FRAMES_EXPECTED);
    FILE *rec = record ? fopen(FRAMES_EXPECTED, "w") : NULL;
    if (record) assert_non_null(rec);
    for (size_t i = 0; i < sizeof opts / sizeof opts[0]; i++) {
        char pd[512], td[512], cmd[4096], want[2048], got[2048], wk[4096], gk[4096];
        snprintf(pd, sizeof pd, "%s/pov%zu", tmpdir, i);
        snprintf(td, sizeof td, "%s/pt%zu", tmpdir, i);
        snprintf(cmd, sizeof cmd, "mkdir -p '%s' '%s'", pd, td);
        assert_int_equal(tu_run(cmd), 0);
        snprintf(cmd, sizeof cmd, "%s/k.pov", pd);
        tu_write_file(cmd, clock_scene);
        if (record) {
            povray_frames(opts[i], pd, want, sizeof want, wk, sizeof wk);
            fprintf(rec, "opts: %s\nfiles: %s\n%s\n", opts[i], want, wk);
        } else if (!recorded_frames(text, opts[i], want, sizeof want, wk, sizeof wk)) {
            fail_msg("%s has no block for '%s': record it again (PARTRAY_RECORD_POVRAY=1)", FRAMES_EXPECTED, opts[i]);
        }
        snprintf(cmd, sizeof cmd, "cd '%s' && '%s' render ../pov%zu/k.pov --size 8x6 %s -o out.png", td, PARTRAY_BIN, i,
                 opts[i]);
        assert_int_equal(tu_run_capture(cmd), 0);
        k_lines(gk, sizeof gk);
        list_dir(td, got, sizeof got);
        printf("%s\n  povray:  %s\n  partray: %s\n", opts[i], want, got);
        assert_true(want[0] != 0);
        assert_string_equal(got, want);
        printf("  povray clocks:\n%s  partray clocks:\n%s", wk, gk);
        assert_true(wk[0] != 0);
        /* a single frame other than 1..1: povray divides by zero (clock
         * nan, clock_delta inf); partray gives clock = +KI, delta 0 */
        if (strstr(wk, "nan")) assert_non_null(strstr(gk, "K 0.000000 fn 3 if 3 ff 3 d 0.000000 on 1"));
        else assert_string_equal(gk, wk);
    }
    if (rec) assert_int_equal(fclose(rec), 0);
}

/* An INI file: its keys set what their switches set, sections, Declare,
 * warnings with file:line, errors with file:line:col. */
static void test_ini(void **st)
{
    (void)st;
    char ini[512], scene[512], inc[512], cmd[4096];
    snprintf(scene, sizeof scene, "%s/ini/s.pov", tmpdir);
    snprintf(inc, sizeof inc, "%s/ini/lib/v.inc", tmpdir);
    snprintf(cmd, sizeof cmd, "mkdir -p '%s/ini/lib'", tmpdir);
    assert_int_equal(tu_run(cmd), 0);
    tu_write_file(inc, "#declare V = 7;\n");
    tu_write_file(scene, "#include \"v.inc\"\n#debug concat(\"W \", str(image_width,0,0), \" H \", str(image_height,0,0), "
                         "\" V \", str(V,0,0), \" F \", str(Foo,0,2), \" S \", Bar, \" K \", str(clock,0,4), \"\\n\")\n"
                         "camera { location <0,0,-4> look_at 0 }\nbackground { rgb 1 }\n");
    snprintf(ini, sizeof ini, "%s/ini/a.ini", tmpdir);
    tu_write_file(ini, "; an animation\n"
                       "Input_File_Name=s.pov\n"
                       "Width = 12   ; pixels\n"
                       "Height=8\n"
                       "Library_Path=lib\n"
                       "Declare=Foo=2.5\n"
                       "Declare=Bar=\"str\"\n"
                       "Initial_Frame=1\nFinal_Frame=4\nInitial_Clock=0\nFinal_Clock=3\n"
                       "Subset_Start_Frame=2\nSubset_End_Frame=3\n"
                       "Antialias=on\nAntialias_Threshold=0.2\n"
                       "Output_File_Type=E\n"
                       "Output_File_Name=img\n"
                       "Verbose=off\n"
                       "Bogus_Key=1\n"
                       "// a comment as distribution files have them\n"
                       "[Big]\nWidth=20\n");
    snprintf(cmd, sizeof cmd, "cd '%s/ini' && '%s' render a.ini", tmpdir, PARTRAY_BIN);
    int rc = tu_run_capture(cmd);
    printf("%s", tu_out);
    assert_int_equal(rc, 0);
    assert_non_null(strstr(tu_out, "W 12 H 8 V 7 F 2.50 S str K 1.0000"));
    assert_non_null(strstr(tu_out, "W 12 H 8 V 7 F 2.50 S str K 2.0000"));
    assert_null(strstr(tu_out, "K 0.0000"));
    assert_non_null(strstr(tu_out, "a.ini:18:1: warning: INI option 'Verbose' is not used by partray"));
    assert_non_null(strstr(tu_out, "a.ini:19:1: warning: unknown INI key 'Bogus_Key'"));
    /* img2.exr, img3.exr: Output_File_Type=E, frame numbers of one digit */
    char p2[600], p3[600];
    snprintf(p2, sizeof p2, "%s/ini/img2.exr", tmpdir);
    snprintf(p3, sizeof p3, "%s/ini/img3.exr", tmpdir);
    assert_true(tu_exists(p2) && tu_exists(p3));
    const char *keys[] = {"partray:settings"};
    char *vals[1];
    int w, h, win[4];
    diag *d = diag_new();
    assert_int_equal(img_exr_info(p2, &w, &h, win, keys, 1, vals, d), PT_OK);
    diag_free(d);
    assert_int_equal(w, 12);
    assert_int_equal(h, 8);
    assert_non_null(vals[0]);
    assert_non_null(strstr(vals[0], "antialias adaptive threshold 0.20000000000000001"));
    free(vals[0]);
    /* the section, and a command-line INI option after it wins */
    snprintf(cmd, sizeof cmd, "cd '%s/ini' && '%s' parse 'a.ini[Big]' Height=9", tmpdir, PARTRAY_BIN);
    assert_int_equal(tu_run_capture(cmd), 0);
    assert_non_null(strstr(tu_out, "W 20 H 9 V 7"));
    /* bad values: file:line:col, exit 2 */
    tu_write_file(ini, "Width=12\nHeight = abc\n");
    snprintf(cmd, sizeof cmd, "cd '%s/ini' && '%s' parse s.pov a.ini", tmpdir, PARTRAY_BIN);
    assert_int_equal(tu_run_capture(cmd), 2);
    assert_non_null(strstr(tu_out, "a.ini:2:10: error: 'Height' wants an integer"));
    tu_write_file(ini, "Antialias=maybe\n");
    assert_int_equal(tu_run_capture(cmd), 2);
    assert_non_null(strstr(tu_out, "a.ini:1:11: error: 'Antialias' wants on/off"));
    tu_write_file(ini, "[Big\n");
    assert_int_equal(tu_run_capture(cmd), 2);
    assert_non_null(strstr(tu_out, "a.ini:1:1: error:"));
    snprintf(cmd, sizeof cmd, "cd '%s/ini' && '%s' parse s.pov missing.ini", tmpdir, PARTRAY_BIN);
    assert_int_equal(tu_run_capture(cmd), 3);
}

/* The pixels of +SC/+EC/+SR/+ER windows (fractions and pixels) are the
 * ones povray renders with the same switches (a white background: rendered
 * pixels are white, the others black). */
static void test_window_as_povray(void **st)
{
    (void)st;
    const char *wins[] = {"+SC0.25 +EC15 +SR3 +ER0.8", "+SC1 +EC1.0 +SR0.5", "+SC7 +EC7 +SR1 +ER1",
                          "+SC0.1 +EC0.9 +SR0.3 +ER0.7"};
    char scene[512], cmd[4096];
    snprintf(scene, sizeof scene, "%s/w.pov", tmpdir);
    tu_write_file(scene, "camera { location <0,0,-4> look_at 0 }\nbackground { rgb 1 }\n");
    for (size_t i = 0; i < sizeof wins / sizeof wins[0]; i++) {
        char pp[600], tp[600];
        snprintf(pp, sizeof pp, "%s/wpov%zu.png", tmpdir, i);
        snprintf(tp, sizeof tp, "%s/wpt%zu.png", tmpdir, i);
        snprintf(cmd, sizeof cmd, "cd '%s' && povray +Iw.pov +W20 +H10 -D -A -V %s '+O%s'", tmpdir, wins[i], pp);
        assert_int_equal(tu_run_capture(cmd), 0);
        snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 20x10 -q %s -o '%s'", PARTRAY_BIN, scene, wins[i], tp);
        assert_int_equal(tu_run_capture(cmd), 0);
        framebuffer *a = NULL, *b = NULL;
        diag *d = diag_new();
        assert_int_equal(img_read(pp, 0, &a, d), PT_OK);
        assert_int_equal(img_read(tp, 0, &b, d), PT_OK);
        diag_free(d);
        int diff = 0, lit = 0;
        for (int y = 0; y < 10; y++)
            for (int x = 0; x < 20; x++) {
                int pa = fb_px(a, x, y)[0] > 0.5f, pb = fb_px(b, x, y)[0] > 0.5f;
                diff += pa != pb;
                lit += pa;
            }
        printf("%s: %d pixels in povray's window, %d differ\n", wins[i], lit, diff);
        assert_true(lit > 0);
        assert_int_equal(diff, 0);
        fb_free(a);
        fb_free(b);
    }
    /* a window outside the image, or ending before it starts */
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 20x10 -q +SC21 -o '%s/x.png'", PARTRAY_BIN, scene, tmpdir);
    assert_int_equal(tu_run_capture(cmd), 2);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 20x10 -q +SC10 +EC5 -o '%s/x.png'", PARTRAY_BIN, scene, tmpdir);
    assert_int_equal(tu_run_capture(cmd), 2);
}

static double rmse(const char *a, const char *b)
{
    framebuffer *fa = NULL, *fb = NULL;
    diag *d = diag_new();
    assert_int_equal(img_read(a, 0, &fa, d), PT_OK);
    assert_int_equal(img_read(b, 0, &fb, d), PT_OK);
    diag_free(d);
    assert_int_equal(fa->width, fb->width);
    assert_int_equal(fa->height, fb->height);
    double s = 0;
    size_t n = (size_t)fa->width * fa->height * 3;
    for (size_t i = 0; i < n; i++) s += ((double)fa->rgb[i] - fb->rgb[i]) * ((double)fa->rgb[i] - fb->rgb[i]);
    fb_free(fa);
    fb_free(fb);
    return sqrt(s / n);
}

/* Tiles of a particle-GI frame with +A (an apron for the AA decisions),
 * rendered in separate processes with different thread counts, merged:
 * RMSE 0 against the frame rendered in one process. merge refuses a gap,
 * an overlap and a tile of other settings. */
static void test_tiles_merge(void **st)
{
    (void)st;
    char cmd[4096], full[600], t[3][600], m[600];
    const char *scene = PT_SOURCE_DIR "/scenes/cbox.pov";
    const char *opts = "--size 64x48 --gi particle --particles 20000 +A0.05 --float -q";
    const char *wins[3] = {"+ER0.5", "+SR0.5 +EC40", "+SR25 +SC41"};
    snprintf(full, sizeof full, "%s/full.exr", tmpdir);
    snprintf(m, sizeof m, "%s/merged.exr", tmpdir);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' %s --threads 2 -o '%s'", PARTRAY_BIN, scene, opts, full);
    assert_int_equal(tu_run_capture(cmd), 0);
    for (int i = 0; i < 3; i++) {
        snprintf(t[i], sizeof t[i], "%s/tile%d.exr", tmpdir, i);
        snprintf(cmd, sizeof cmd, "'%s' render '%s' %s --threads %d %s -o '%s'", PARTRAY_BIN, scene, opts, 1 + i % 2,
                 wins[i], t[i]);
        assert_int_equal(tu_run_capture(cmd), 0);
    }
    snprintf(cmd, sizeof cmd, "'%s' merge '%s' '%s' '%s' '%s'", PARTRAY_BIN, m, t[2], t[0], t[1]);
    assert_int_equal(tu_run_capture(cmd), 0);
    double e = rmse(full, m);
    printf("merged 3 tiles vs one process: RMSE %g\n", e);
    assert_true(e == 0.0);
    /* a gap, an overlap, another seed: refused, no output */
    remove(m);
    snprintf(cmd, sizeof cmd, "'%s' merge '%s' '%s' '%s'", PARTRAY_BIN, m, t[0], t[1]);
    assert_int_equal(tu_run_capture(cmd), 2);
    assert_non_null(strstr(tu_out, "uncovered"));
    snprintf(cmd, sizeof cmd, "'%s' merge '%s' '%s' '%s' '%s' '%s'", PARTRAY_BIN, m, t[0], t[1], t[2], t[1]);
    assert_int_equal(tu_run_capture(cmd), 2);
    assert_non_null(strstr(tu_out, "overlaps"));
    char t3[600];
    snprintf(t3, sizeof t3, "%s/tile3.exr", tmpdir);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 64x48 --gi none +A0.05 --float -q --seed 3 +SR25 +SC41 -o '%s'",
             PARTRAY_BIN, scene, t3);
    assert_int_equal(tu_run_capture(cmd), 0);
    snprintf(cmd, sizeof cmd, "'%s' merge '%s' '%s' '%s' '%s'", PARTRAY_BIN, m, t[0], t[1], t3);
    assert_int_equal(tu_run_capture(cmd), 2);
    assert_non_null(strstr(tu_out, "differ in partray:settings"));
    assert_false(tu_exists(m));
}

/* GI across an animation's frames: with only the camera moving, the
 * geometry and lighting stages run once; with a light moving, geometry
 * once and lighting every frame; with an object moving, every stage every
 * frame. Every frame is byte-identical (PFM) to the frame rendered alone. */
static void test_gi_reuse(void **st)
{
    (void)st;
    static const struct {
        const char *name, *camera, *light, *sphere, *stages2;
    } cases[] = {
        {"cam", "<0.4 * clock, 1, -3.2>", "<0, 1.8, -0.5>", "<-0.6, 0.4, -0.3>", "gi stages run: view"},
        {"light", "<0, 1, -3.2>", "<0.5 * clock, 1.8, -0.5>", "<-0.6, 0.4, -0.3>", "gi stages run: lighting, view"},
        {"object", "<0, 1, -3.2>", "<0, 1.8, -0.5>", "<-0.6 + 0.5 * clock, 0.4, -0.3>",
         "gi stages run: geometry, lighting, view"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char scene[600], text[2048], cmd[4096], out[600], one[600];
        snprintf(scene, sizeof scene, "%s/reuse_%s.pov", tmpdir, cases[i].name);
        snprintf(text, sizeof text,
                 "#version 3.7;\nglobal_settings { radiosity { count 50 } }\n"
                 "camera { location %s look_at <0, 0.8, 0> angle 60 }\n"
                 "light_source { %s rgb 1 }\n"
                 "box { <-1.5, 0, -4>, <1.5, 2, 1.5> hollow pigment { rgb 0.8 } finish { diffuse 0.8 ambient 0 } }\n"
                 "sphere { %s, 0.4 pigment { rgb <0.9, 0.3, 0.2> } finish { diffuse 0.8 ambient 0 } }\n",
                 cases[i].camera, cases[i].light, cases[i].sphere);
        tu_write_file(scene, text);
        snprintf(out, sizeof out, "%s/reuse_%s_.pfm", tmpdir, cases[i].name);
        snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 48x36 --particles 5000 +KFI1 +KFF3 -o '%s'", PARTRAY_BIN, scene,
                 out);
        assert_int_equal(tu_run_capture(cmd), 0);
        printf("%s:\n%s", cases[i].name, tu_out);
        assert_non_null(strstr(tu_out, "frame 1: gi stages run: geometry, lighting, view"));
        char want[128];
        for (int f = 2; f <= 3; f++) {
            snprintf(want, sizeof want, "frame %d: %s\n", f, cases[i].stages2);
            assert_non_null(strstr(tu_out, want));
        }
        for (int f = 2; f <= 3; f++) {
            snprintf(one, sizeof one, "%s/one_%s_.pfm", tmpdir, cases[i].name);
            snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 48x36 --particles 5000 +KFI1 +KFF3 --frame %d -q -o '%s'",
                     PARTRAY_BIN, scene, f, one);
            assert_int_equal(tu_run_capture(cmd), 0);
            snprintf(cmd, sizeof cmd, "cmp '%s/reuse_%s_%d.pfm' '%s/one_%s_%d.pfm'", tmpdir, cases[i].name, f, tmpdir,
                     cases[i].name, f);
            int rc = tu_run_capture(cmd);
            printf("frame %d in one run vs alone: %s\n", f, rc == 0 ? "identical" : tu_out);
            assert_int_equal(rc, 0);
        }
    }
}

/* An animation's geometry stage does not read the camera: a free-standing
 * wall under a sky, the camera going round it from the front to the back.
 * The back's particles are linked by no ray (nothing faces them), so a
 * still keeps them only when the camera faces them; frame 3 rendered in
 * the run that built the GI at frame 1 (camera in front) must equal frame 3
 * rendered alone (camera behind), byte for byte. With --gi-cache the
 * frames share one file (the geometry does not change from frame to
 * frame), and frame 3 rendered alone from it is the same again. */
static void test_gi_reuse_behind(void **st)
{
    (void)st;
    char scene[600], cmd[4096], cache[600];
    snprintf(scene, sizeof scene, "%s/behind.pov", tmpdir);
    snprintf(cache, sizeof cache, "%s/behind.gic", tmpdir);
    tu_write_file(scene, "#version 3.7;\nglobal_settings { radiosity { count 50 } }\n"
                         "camera { location <3 * sin(clock * pi), 1, -3 * cos(clock * pi)> look_at <0, 1, 0> angle 60 }\n"
                         "light_source { <-2, 4, -3> rgb 1 }\nsky_sphere { pigment { rgb <0.6, 0.7, 1.0> } }\n"
                         "box { <-1, 0, -0.05>, <1, 2, 0.05> pigment { rgb 0.8 } finish { diffuse 0.8 ambient 0 } }\n");
    const char *opts = "--size 48x36 --particles 5000 +KFI1 +KFF3";
    snprintf(cmd, sizeof cmd, "'%s' render '%s' %s --gi-cache '%s' -o '%s/behind_.pfm'", PARTRAY_BIN, scene, opts, cache,
             tmpdir);
    assert_int_equal(tu_run_capture(cmd), 0);
    printf("%s", tu_out);
    assert_non_null(strstr(tu_out, "frame 3: gi stages run: view\n"));
    assert_true(tu_exists(cache));
    snprintf(cmd, sizeof cmd, "'%s' render '%s' %s --frame 3 -q -o '%s/alone_.pfm'", PARTRAY_BIN, scene, opts, tmpdir);
    assert_int_equal(tu_run_capture(cmd), 0);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' %s --frame 3 --gi-cache '%s' -o '%s/cached_.pfm'", PARTRAY_BIN, scene,
             opts, cache, tmpdir);
    assert_int_equal(tu_run_capture(cmd), 0);
    assert_non_null(strstr(tu_out, "behind.gic: loaded"));
    snprintf(cmd, sizeof cmd, "cmp '%s/behind_3.pfm' '%s/alone_3.pfm' && cmp '%s/behind_3.pfm' '%s/cached_3.pfm'", tmpdir,
             tmpdir, tmpdir, tmpdir);
    int rc = tu_run_capture(cmd);
    printf("frame 3 in one run, alone, alone from the shared cache: %s\n", rc == 0 ? "identical" : tu_out);
    assert_int_equal(rc, 0);
}

/* --gi-cache: a render saves its particle GI's geometry stage; another
 * process (other thread count) loads it and gives the same image, byte for
 * byte (PFM), as does a render without the cache. A cache is refused (exit
 * 1, `FILE: error: ...`, no image written) after an edit of an #include'd
 * file, with other GI settings, of another format version, or altered. */
static void test_gi_cache(void **st)
{
    (void)st;
    char scene[600], inc[600], cache[600], a[600], b[600], c[600], x[600], cmd[4096];
    snprintf(scene, sizeof scene, "%s/cache.pov", tmpdir);
    snprintf(inc, sizeof inc, "%s/cache_room.inc", tmpdir);
    snprintf(cache, sizeof cache, "%s/cache.gic", tmpdir);
    snprintf(a, sizeof a, "%s/cache_a.pfm", tmpdir);
    snprintf(b, sizeof b, "%s/cache_b.pfm", tmpdir);
    snprintf(c, sizeof c, "%s/cache_c.pfm", tmpdir);
    snprintf(x, sizeof x, "%s/cache_x.pfm", tmpdir);
    tu_write_file(scene, "#version 3.7;\nglobal_settings { radiosity { count 50 } }\n"
                         "camera { location <0.3, 1, -3.2> look_at <0, 0.8, 0> angle 60 }\n"
                         "light_source { <0, 1.8, -0.5> rgb 1 }\n#include \"cache_room.inc\"\n"
                         "sphere { <-0.6, 0.4, -0.3>, 0.4 pigment { rgb <0.9, 0.3, 0.2> } finish { diffuse 0.8 ambient 0 } }\n"
                         /* a triangle: the final gather's rays look its
                          * particles up in lists the cache does not hold */
                         "triangle { <0.1, 0.001, -1>, <1.2, 0.001, -1>, <0.6, 0.001, 0.8> pigment { rgb <0.2, 0.5, 0.9> }"
                         " finish { diffuse 0.8 ambient 0 } }\n");
    tu_write_file(inc, "box { <-1.5, 0, -4>, <1.5, 2, 1.5> hollow pigment { rgb 0.8 } finish { diffuse 0.8 ambient 0 } }\n");
    const char *opts = "--size 48x36 --particles 5000";
    snprintf(cmd, sizeof cmd, "'%s' render '%s' %s --threads 2 --gi-cache '%s' -o '%s'", PARTRAY_BIN, scene, opts, cache, a);
    assert_int_equal(tu_run_capture(cmd), 0);
    assert_non_null(strstr(tu_out, "cache.gic: saved"));
    snprintf(cmd, sizeof cmd, "'%s' render '%s' %s --threads 1 --gi-cache '%s' -o '%s'", PARTRAY_BIN, scene, opts, cache, b);
    assert_int_equal(tu_run_capture(cmd), 0);
    assert_non_null(strstr(tu_out, "cache.gic: loaded"));
    snprintf(cmd, sizeof cmd, "'%s' render '%s' %s -q -o '%s'", PARTRAY_BIN, scene, opts, c);
    assert_int_equal(tu_run_capture(cmd), 0);
    snprintf(cmd, sizeof cmd, "cmp '%s' '%s' && cmp '%s' '%s'", a, b, a, c);
    int rc = tu_run_capture(cmd);
    printf("saved, loaded in another process, no cache: %s\n", rc == 0 ? "identical" : tu_out);
    assert_int_equal(rc, 0);

    /* refusals: exit 1, the cache's name first, no image */
    static const struct {
        const char *what, *extra, *want;
    } bad[] = {
        {"include edited", "", "made for another scene"},
        {"other settings", "--particles 6000", "another particle count"},
        {"format version", "", "format version 9"},
        {"altered", "", "checksum"},
    };
    char saved[600];
    snprintf(saved, sizeof saved, "%s/cache_saved.gic", tmpdir);
    snprintf(cmd, sizeof cmd, "cp '%s' '%s'", cache, saved);
    assert_int_equal(tu_run_capture(cmd), 0);
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        snprintf(cmd, sizeof cmd, "cp '%s' '%s'", saved, cache);
        assert_int_equal(tu_run_capture(cmd), 0);
        if (i == 0)
            tu_write_file(inc, "box { <-1.5, 0, -4>, <1.5, 2, 1.5> hollow pigment { rgb 0.7 } finish { diffuse 0.8 ambient 0 } }\n");
        else
            tu_write_file(inc, "box { <-1.5, 0, -4>, <1.5, 2, 1.5> hollow pigment { rgb 0.8 } finish { diffuse 0.8 ambient 0 } }\n");
        if (i == 2 || i == 3) {
            /* byte 17 is the version's low byte (little-endian), 100000 inside the links */
            snprintf(cmd, sizeof cmd, "printf '%s' | dd of='%s' bs=1 seek=%d conv=notrunc 2>/dev/null", i == 2 ? "\\011" : "\\125",
                     cache, i == 2 ? 17 : 100000);
            assert_int_equal(tu_run_capture(cmd), 0);
        }
        remove(x);
        snprintf(cmd, sizeof cmd, "'%s' render '%s' %s %s --gi-cache '%s' -o '%s'", PARTRAY_BIN, scene, opts, bad[i].extra,
                 cache, x);
        rc = tu_run_capture(cmd);
        printf("%s: exit %d: %s", bad[i].what, rc, tu_out);
        assert_int_equal(rc, 1);
        char want[700];
        snprintf(want, sizeof want, "%s: error: ", cache);
        assert_non_null(strstr(tu_out, want));
        assert_non_null(strstr(tu_out, bad[i].want));
        assert_false(tu_exists(x));
    }
}

int main(void)
{
    if (tu_mkdtemp(tmpdir, sizeof tmpdir, "partray-anim")) return 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_frames_as_povray),
        cmocka_unit_test(test_ini),
        cmocka_unit_test(test_window_as_povray),
        cmocka_unit_test(test_tiles_merge),
        cmocka_unit_test(test_gi_reuse),
        cmocka_unit_test(test_gi_reuse_behind),
        cmocka_unit_test(test_gi_cache),
    };
    return tu_finish(cmocka_run_group_tests(tests, NULL, NULL), tmpdir);
}
