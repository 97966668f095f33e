/* test_motion.c - GI that follows motion (docs/motion.md).
 *
 * Incremental photon paths and the DETP estimator (reference/pm_detp.h):
 *  - integrating sphere: the receivers' mean indirect irradiance inside a
 *    Lambertian sphere (rho 0.5) around an off-centre point light against
 *    its closed form (test_gi.c's: E_ind / pi = (1 - a^2/3) sum rho^k);
 *  - incremental = full: on tests/scenes/detp_cbox.pov (a block moving with
 *    the clock) every frame's integer sums equal those of tracing every
 *    path and estimating every receiver anew with the same streams, bit for
 *    bit, while the incremental frames re-trace a small share of the paths;
 *  - a frame where nothing moved re-traces nothing and keeps every sum.
 * Vertex links (gi/gi_vlinks.h, --gi links):
 *  - integrating sphere: inside a tessellated Lambertian sphere the
 *    elements' mean indirect E/pi after 10 sweeps against the closed form,
 *    and the merged links fewer than the raw ones;
 *  - incremental = full: on detp_cbox.pov a frame that links again only the
 *    elements the motion touches gives every element the value a fresh
 *    build of that frame gives, bit for bit. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "accel.h"
#include "diag.h"
#include "gi_vlinks.h"
#include "pm_detp.h"
#include "sdl.h"

static void print_diag(diag *d)
{
    for (int i = 0; i < diag_count(d); i++) {
        char *m = diag_format(diag_get(d, i));
        fprintf(stderr, "  diag: %s\n", m);
        free(m);
    }
}

typedef struct {
    scene *sc;
    accel *a;
    diag *d;
} frame;

static void load(frame *f, const char *path, const char *text, int fr, int nframes)
{
    f->d = diag_new();
    sdl_options o;
    sdl_default_options(&o);
    if (nframes > 1) assert_int_equal(sdl_set_frame(&o, 1, nframes, 0.0, 1.0, 0, fr), 0);
    pt_status st = text ? sdl_parse_string("test.pov", text, &o, &f->sc, f->d) : sdl_parse_file(path, &o, &f->sc, f->d);
    if (st != PT_OK) print_diag(f->d);
    assert_int_equal(st, PT_OK);
    f->a = accel_build(f->sc, 2, f->d, &st);
    assert_non_null(f->a);
}

static void unload(frame *f)
{
    accel_free(f->a);
    scene_free(f->sc);
    diag_free(f->d);
}

static pm_detp *make(long photons, int full)
{
    pm_detp_settings s;
    pm_detp_default_settings(&s);
    s.photons = photons;
    s.full = full;
    s.threads = 2;
    s.seed = 5;
    pm_detp *dp = pm_detp_new(&s);
    assert_non_null(dp);
    return dp;
}

static const char *sphere_scene =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 radiosity { recursion_limit 20 } }\n"
    "camera { location <0, 0, 0> look_at <0, 0, 1> angle 120 }\n"
    "light_source { <0.3, 0.2, 0.1> color rgb 1 }\n"
    "sphere { 0, 1 pigment { rgb 1 } finish { ambient 0 diffuse 0.5 } }\n";

static void test_detp_sphere(void **state)
{
    (void)state;
    frame f;
    load(&f, NULL, sphere_scene, 1, 1);
    pm_detp *dp = make(200000, 0);
    pm_detp_stats st;
    pm_detp_frame_info fi = {0, 0};
    assert_int_equal(pm_detp_frame(dp, f.sc, f.a, 48, 48, &fi, &st, f.d), PT_OK);
    /* E_ind / pi for C = 1 inside a unit sphere, light at a from the centre,
     * gathered 19 times at most (recursion_limit 20) */
    double a2 = 0.3 * 0.3 + 0.2 * 0.2 + 0.1 * 0.1, sum = 0.0, pk = 1.0;
    for (int k = 1; k <= 19; k++) {
        pk *= 0.5;
        sum += pk;
    }
    double expected = (1.0 - a2 / 3.0) * sum;
    long n;
    double scale;
    const int64_t *E = pm_detp_sums(dp, &n, &scale);
    double mean = 0.0, m2 = 0.0;
    long m = 0;
    for (long i = 0; i < n; i++) {
        double e = (double)E[i * 3 + 1] * scale / M_PI;
        if (e == 0.0) continue;
        mean += e;
        m2 += e * e;
        m++;
    }
    assert_true(m > n / 2);
    mean /= m;
    double rms = sqrt(fmax(0.0, m2 / m - mean * mean)) / expected;
    printf("  detp sphere: %ld paths, %ld segments, radius %.4f, %ld receivers: mean E_ind/pi %.5f, expected %.5f "
           "(%+.2f%%), per-receiver RMS %.1f%%\n",
           st.paths, st.segments, st.radius, m, mean, expected, 100.0 * (mean / expected - 1.0), 100.0 * rms);
    /* the disc in the tangent plane of a sphere of radius 1 with r = 0.07
     * misses little: 2% covers it and the noise of the mean */
    assert_true(fabs(mean / expected - 1.0) < 0.02);
    assert_true(rms < 0.2);
    pm_detp_free(dp);
    unload(&f);
}

static void test_detp_incremental(void **state)
{
    (void)state;
    const int nframes = 6, w = 64, h = 48;
    pm_detp *inc = make(30000, 0), *full = make(30000, 1);
    for (int fr = 1; fr <= nframes; fr++) {
        frame f;
        load(&f, PT_SOURCE_DIR "/tests/scenes/detp_cbox.pov", NULL, fr, nframes);
        pm_detp_frame_info fi = {0, 1};
        pm_detp_stats si, sf;
        assert_int_equal(pm_detp_frame(inc, f.sc, f.a, w, h, &fi, &si, f.d), PT_OK);
        assert_int_equal(pm_detp_frame(full, f.sc, f.a, w, h, &fi, &sf, f.d), PT_OK);
        long n1, n2;
        double s1, s2;
        const int64_t *e1 = pm_detp_sums(inc, &n1, &s1), *e2 = pm_detp_sums(full, &n2, &s2);
        assert_int_equal(n1, n2);
        assert_true(s1 == s2);
        long differ = 0, nonzero = 0;
        for (long i = 0; i < n1 * 3; i++) {
            differ += e1[i] != e2[i];
            nonzero += e1[i] != 0;
        }
        double frac = si.paths > 0 ? (double)si.paths_retraced / (double)si.paths : 0.0;
        printf("  detp cbox frame %d: %s, %ld moving, paths re-traced %ld / %ld (%.2f%%), segments -%ld +%ld, "
               "receivers anew %ld / %ld, sums differing from the full recomputation: %ld of %ld\n",
               fr, si.full_frame ? "full" : "incremental", si.moving_objects, si.paths_retraced, si.paths, 100.0 * frac,
               si.segments_old, si.segments_new, si.receivers_full, si.receivers, differ, n1 * 3);
        assert_int_equal(differ, 0);
        assert_true(pm_detp_paths_hash(inc) == pm_detp_paths_hash(full));
        assert_true(nonzero > n1);
        assert_int_equal(si.segments, sf.segments);
        assert_int_equal(sf.full_frame, 1);
        if (fr == 1) {
            assert_int_equal(si.full_frame, 1);
        } else {
            assert_int_equal(si.full_frame, 0);
            assert_int_equal(si.moving_objects, 1);
            assert_true(frac > 0.0 && frac < 0.3);
            assert_true(si.receivers_full > 0 && si.receivers_full < si.receivers / 3);
        }
        unload(&f);
    }
    pm_detp_free(inc);
    pm_detp_free(full);
}

/* raddem.pov's set-up in small: a divider turning with the clock changes
 * the scene's extent (and with it the distance rays start off surfaces):
 * the paths stay those of the full recomputation. */
static const char *turning_scene =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 radiosity { recursion_limit 4 } }\n"
    "camera { location <-1.5, 2, -29.9> direction z * 1.75 look_at <0.5, -1, 0> }\n"
    "light_source { <0, 9.5, 0> color rgb 0.45 fade_distance 15 fade_power 2 shadowless }\n"
    "box { -1, 1 scale <10, 10, 30> pigment { rgb 1 } finish { ambient 0 } inverse }\n"
    "box { -1, 1 scale <9, 8, 0.2> pigment { rgb <1, 0.2, 0.2> } finish { ambient 0 }\n"
    "      rotate y * 90 rotate y * (clock * 360) translate z * 10 }\n";

static void test_detp_turning(void **state)
{
    (void)state;
    const int nframes = 5;
    pm_detp *inc = make(20000, 0), *full = make(20000, 1);
    for (int fr = 1; fr <= nframes; fr++) {
        frame f;
        f.d = diag_new();
        sdl_options o;
        sdl_default_options(&o);
        assert_int_equal(sdl_set_frame(&o, 1, nframes, 0.0, 1.0, 1, fr), 0);
        assert_int_equal(sdl_parse_string("turn.pov", turning_scene, &o, &f.sc, f.d), PT_OK);
        pt_status st;
        f.a = accel_build(f.sc, 2, f.d, &st);
        assert_non_null(f.a);
        pm_detp_frame_info fi = {0, 1};
        pm_detp_stats si, sf;
        assert_int_equal(pm_detp_frame(inc, f.sc, f.a, 40, 30, &fi, &si, f.d), PT_OK);
        assert_int_equal(pm_detp_frame(full, f.sc, f.a, 40, 30, &fi, &sf, f.d), PT_OK);
        long n;
        double sc;
        const int64_t *e1 = pm_detp_sums(inc, &n, &sc), *e2 = pm_detp_sums(full, &n, &sc);
        int same_paths = pm_detp_paths_hash(inc) == pm_detp_paths_hash(full);
        printf("  detp turning divider frame %d: %.2f%% of paths re-traced, paths %s, sums %s\n", fr,
               100.0 * (double)si.paths_retraced / (double)si.paths, same_paths ? "equal" : "DIFFER",
               memcmp(e1, e2, sizeof *e1 * (size_t)n * 3) == 0 ? "equal" : "DIFFER");
        assert_true(same_paths);
        assert_memory_equal(e1, e2, sizeof *e1 * (size_t)n * 3);
        if (fr > 1) assert_int_equal(si.full_frame, 0);
        unload(&f);
    }
    pm_detp_free(inc);
    pm_detp_free(full);
}

static void test_detp_static_frame(void **state)
{
    (void)state;
    pm_detp *dp = make(20000, 0);
    int64_t *before = NULL;
    long n = 0;
    for (int k = 0; k < 2; k++) {
        frame f;
        load(&f, PT_SOURCE_DIR "/tests/scenes/detp_cbox.pov", NULL, 1, 1);
        pm_detp_frame_info fi = {0, 1};
        pm_detp_stats st;
        assert_int_equal(pm_detp_frame(dp, f.sc, f.a, 40, 30, &fi, &st, f.d), PT_OK);
        double scale;
        const int64_t *e = pm_detp_sums(dp, &n, &scale);
        if (k == 0) {
            before = malloc(sizeof *before * (size_t)n * 3);
            assert_non_null(before);
            memcpy(before, e, sizeof *before * (size_t)n * 3);
        } else {
            assert_int_equal(st.full_frame, 0);
            assert_int_equal(st.moving_objects, 0);
            assert_int_equal(st.paths_retraced, 0);
            assert_int_equal(st.receivers_full, 0);
            assert_memory_equal(before, e, sizeof *before * (size_t)n * 3);
        }
        unload(&f);
    }
    free(before);
    pm_detp_free(dp);
}

static gi_vlinks *make_links(int bounces)
{
    gi_vlinks_settings s;
    gi_vlinks_default_settings(&s);
    s.bounces = bounces;
    s.threads = 2;
    gi_vlinks *v = gi_vlinks_new(&s);
    assert_non_null(v);
    return v;
}

/* A unit sphere as a mesh2 of 40 x 80 latitude-longitude cells. */
static const char *mesh_sphere_scene =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 }\n"
    "camera { location <0, 0, 0> look_at <0, 0, 1> }\n"
    "light_source { <0.3, 0.2, 0.1> color rgb 1 }\n"
    "#declare NT = 40; #declare NP = 80;\n"
    "mesh2 {\n"
    "  vertex_vectors { (NT + 1) * NP,\n"
    "    #for (J, 0, NT) #for (I, 0, NP - 1)\n"
    "      #local T = pi * J / NT; #local P = 2 * pi * I / NP;\n"
    "      <sin(T) * cos(P), cos(T), sin(T) * sin(P)>,\n"
    "    #end #end }\n"
    "  face_indices { 2 * NT * NP,\n"
    "    #for (J, 0, NT - 1) #for (I, 0, NP - 1)\n"
    "      #local A = J * NP + I; #local B = J * NP + mod(I + 1, NP);\n"
    "      <A, B, B + NP>, <A, B + NP, A + NP>,\n"
    "    #end #end }\n"
    "  pigment { rgb 1 } finish { ambient 0 diffuse 0.5 }\n"
    "}\n";

static void test_links_sphere(void **state)
{
    (void)state;
    frame f;
    load(&f, NULL, mesh_sphere_scene, 1, 1);
    gi_vlinks *v = make_links(10);
    gi_vlinks_stats st;
    assert_int_equal(gi_vlinks_frame(v, f.sc, f.a, 1, &st, f.d), PT_OK);
    double a2 = 0.3 * 0.3 + 0.2 * 0.2 + 0.1 * 0.1, sum = 0.0, pk = 1.0;
    for (int k = 1; k <= 10; k++) {
        pk *= 0.5;
        sum += pk;
    }
    double expected = (1.0 - a2 / 3.0) * sum;
    /* the inner side's elements: their normal points at the centre */
    double mean = 0.0, m2 = 0.0;
    long m = 0;
    for (long i = 0; i < gi_vlinks_count(v); i++) {
        vec3 p, n;
        rgb e = gi_vlinks_element(v, i, &p, &n);
        if (v3_dot(p, n) > 0.0) continue;
        mean += e.g;
        m2 += e.g * e.g;
        m++;
    }
    assert_true(m > 3000);
    mean /= m;
    double rms = sqrt(fmax(0.0, m2 / m - mean * mean)) / expected;
    printf("  links sphere: %ld vertices, raw links %ld, merged %ld (%.2fx), %ld link rays: mean E_ind/pi %.5f, "
           "expected %.5f (%+.2f%%), spread %.2f%%\n",
           st.vertices, st.raw_links, st.merged_links, (double)st.raw_links / (double)st.merged_links, st.link_rays,
           mean, expected, 100.0 * (mean / expected - 1.0), 100.0 * rms);
    assert_true(fabs(mean / expected - 1.0) < 0.03);
    assert_true(rms < 0.1);
    assert_true(st.merged_links < st.raw_links);
    gi_vlinks_free(v);
    unload(&f);
}

static void test_links_incremental(void **state)
{
    (void)state;
    const int nframes = 4;
    gi_vlinks *inc = make_links(3);
    for (int fr = 1; fr <= nframes; fr++) {
        frame f;
        load(&f, PT_SOURCE_DIR "/tests/scenes/detp_cbox.pov", NULL, fr, nframes);
        gi_vlinks_stats si, sf;
        assert_int_equal(gi_vlinks_frame(inc, f.sc, f.a, 1, &si, f.d), PT_OK);
        gi_vlinks *fresh = make_links(3);
        assert_int_equal(gi_vlinks_frame(fresh, f.sc, f.a, 1, &sf, f.d), PT_OK);
        long n = gi_vlinks_count(inc), differ = 0;
        assert_int_equal(n, gi_vlinks_count(fresh));
        for (long i = 0; i < n; i++) {
            rgb a = gi_vlinks_element(inc, i, NULL, NULL), b = gi_vlinks_element(fresh, i, NULL, NULL);
            differ += a.r != b.r || a.g != b.g || a.b != b.b;
        }
        printf("  links cbox frame %d: %s, %ld objects moved, %ld of %ld elements linked again, "
               "elements differing from a fresh build: %ld\n",
               fr, si.full ? "full" : "incremental", si.objects_moved, si.elements_linked, si.elements, differ);
        assert_int_equal(differ, 0);
        assert_int_equal(si.merged_links, sf.merged_links);
        if (fr > 1) {
            assert_int_equal(si.full, 0);
            assert_int_equal(si.objects_moved, 1);
            assert_true(si.elements_linked > 0 && si.elements_linked < si.elements);
        }
        gi_vlinks_free(fresh);
        unload(&f);
    }
    gi_vlinks_free(inc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_detp_sphere),
        cmocka_unit_test(test_detp_incremental),
        cmocka_unit_test(test_detp_turning),
        cmocka_unit_test(test_detp_static_frame),
        cmocka_unit_test(test_links_sphere),
        cmocka_unit_test(test_links_incremental),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
