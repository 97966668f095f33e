/* test_media.c - participating media (shade/shade_media.c).
 *
 * Closed forms, along single rays through shade_trace (relative error
 * bound TOL below):
 *  - Beer-Lambert: a constant absorbing box (sigma_a per channel) in front
 *    of a white background transmits exp(-sigma_a L), for methods 1, 2, 3
 *    and a plain density colour (which scales sigma_a);
 *  - emission e with absorption a over L, sampled as POV-Ray 3.7's method 3
 *    does (media.cpp: S = samples / 2 + 1 sub-intervals, each emitting
 *    e L / S attenuated only by those before it): sum over k < S of
 *    e L / S exp(-a L k / S), plus bg exp(-a L);
 *  - atmospheric emission e to a black wall at distance d: e d; through a
 *    transparent sphere of diameter D in the way: e (d - D) when the sphere
 *    is not hollow (POV-Ray applies no atmosphere inside it), e d when it is;
 *  - a shadow ray through an absorbing box dims a diffuse floor by
 *    exp(-sigma_a L) of its path inside the box;
 *  - isotropic scattering s without extinction over L in front of a black
 *    background, lit by a point light of colour 1: s L; lit only by a
 *    shadowless light: 0 (POV-Ray 3.7's media.cpp lights media only with
 *    point, spot and cylinder lights; shadowless makes a fill light);
 *  - ground fog (density 1 below height h0, 1 / (1 + ((y - h0) / a)^2)
 *    above: its integral up a vertical ray is h0 - y0 + a atan((y1 - h0)
 *    / a)) dimming a light with media_attenuation straight above a floor
 *    through a clear pane: a point light by the fog over its whole way; an
 *    area light also by the fog from the floor over the way left after the
 *    pane (POV-Ray 3.7's TraceShadowRay adds that part once for the
 *    averaged samples, from the shaded point, so fog near the ground counts
 *    twice: benchmark.pov's clouds and ground fog);
 *  - POV-Ray 3.7's shadow walk (trace.cpp): a glass sphere (fade to 0.5
 *    over 1) holding a drink sphere (fade to 0 over 1) above a floor, the
 *    light straight above: with a 0.1 gap between them the floor under
 *    them gets exp(-1.8) exp(-0.5 x 0.1) (the drink's fade over its
 *    chord, the glass's over the gap before it leaves); with a 0.0005 gap
 *    (under SMALL_TOLERANCE, 0.001) the drink's entry and the glass's exit
 *    are not seen and the drink's exit is taken for an entry: no fade at
 *    all, 1 (balcony.pov's drinking glass); povray's own 16 x 16 render
 *    of the scene (assumed_gamma 1) gives 111 of 255 (0.160) and 255 at
 *    the centre. Without and with media in the scene (the two shadow
 *    walks).
 * Cross-checks against POV-Ray 3.7 (as test_look: 160x120, +A0.3, sRGB,
 * 4x4 downsample, mean |difference| <= 0.02 and a regression bound): an
 * emitting sphere with a density pattern, an absorbing box (method 2, a
 * gradient density) casting a tinted shadow, a Henyey-Greenstein scattering
 * slab lit by a spotlight with a sphere's shadow shaft and atmospheric
 * absorption with media_attenuation. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "accel.h"
#include "framebuffer.h"
#include "sdl.h"
#include "shade.h"
#include "shade_media.h"
#include "shade_texture.h"
#include "test_util.h"
#include "test_world.h"

#define W 160
#define H 120
#define TOLERANCE 0.02
/* Relative bound of the closed forms: the sampling is exact for constant
 * coefficients; the segment ends move by the ray epsilons (1e-6 of the
 * scene's size), which moves exp(-6) through 3 units by about 1e-5. */
#define TOL 3e-5

typedef tu_world world;

static world build(const char *src) { return tu_world_build("media.pov", src); }

static void done(world *w) { tu_world_free(w); }

static rgb trace(const world *w, vec3 org, vec3 dir)
{
    shade_settings ss;
    shade_default_settings(&ss);
    rng r;
    rng_seed(&r, 1, 2);
    return shade_trace(w->s, w->a, &ss, org, dir, 0, &r);
}

static void expect_rel(double got, double want, double tol, const char *what)
{
    double err = fabs(got - want) / fmax(fabs(want), 1e-300);
    printf("media %-34s got %.12f expected %.12f (rel. error %.2e)\n", what, got, want, err);
    if (!(err <= tol)) fail_msg("%s: got %.15g, expected %.15g", what, got, want);
}

/* ------------------------------------------------------------ closed forms */

static void test_beer_lambert(void **st)
{
    (void)st;
    static const char *variants[] = {"", "method 1 intervals 3 samples 2", "method 2 intervals 5 samples 4",
                                     "method 3 intervals 2 samples 7, 7"};
    for (int v = 0; v < 4; v++) {
        for (int dens = 0; dens < 2; dens++) {
            char src[1024];
            snprintf(src, sizeof src,
                     "background { rgb 1 }\n"
                     "box { <-1, -1, -1>, <1, 1, 1> pigment { rgbf 1 } finish { ambient 0 diffuse 0 } hollow\n"
                     "  interior { media { %s absorption <0.5, 1, 2> %s } } scale <1, 1, 1.5> }\n",
                     variants[v], dens ? "density { rgb 0.25 }" : "");
            world w = build(src);
            /* along z: 3 units of media (box scaled to z -1.5..1.5) */
            rgb c = trace(&w, v3(0.1, 0.2, -10), v3(0, 0, 1));
            double k = dens ? 0.25 : 1.0;
            char what[64];
            snprintf(what, sizeof what, "Beer-Lambert v%d d%d r", v, dens);
            expect_rel(c.r, exp(-0.5 * k * 3.0), TOL, what);
            what[strlen(what) - 1] = 'g';
            expect_rel(c.g, exp(-1.0 * k * 3.0), TOL, what);
            what[strlen(what) - 1] = 'b';
            expect_rel(c.b, exp(-2.0 * k * 3.0), TOL, what);
            /* an oblique ray: path length through the slab x in -1..1 */
            vec3 dir = v3_norm(v3(1, 0, 0.5));
            c = trace(&w, v3_madd(v3(0, 0, 0), dir, -10), dir);
            double len = 2.0 / dir.x;
            expect_rel(c.g, exp(-1.0 * k * len), TOL, "Beer-Lambert oblique g");
            done(&w);
        }
    }
}

static void test_emission_absorption(void **st)
{
    (void)st;
    world w = build("background { rgb <0.2, 0.4, 0.6> }\n"
                    "sphere { 0, 2 pigment { rgbf 1 } finish { ambient 0 diffuse 0 } hollow\n"
                    "  interior { media { emission <0.3, 0.1, 0.5> absorption <0.7, 0.2, 1.1> } } }\n");
    rgb c = trace(&w, v3(0, 0, -10), v3(0, 0, 1));
    double L = 4.0, e[3] = {0.3, 0.1, 0.5}, a[3] = {0.7, 0.2, 1.1}, bg[3] = {0.2, 0.4, 0.6};
    double got[3] = {c.r, c.g, c.b};
    const int S = 10 / 2 + 1; /* the default samples 10 */
    for (int i = 0; i < 3; i++) {
        double want = bg[i] * exp(-a[i] * L);
        for (int k = 0; k < S; k++) want += e[i] * L / S * exp(-a[i] * L * k / S);
        expect_rel(got[i], want, TOL, "emission + absorption");
    }
    done(&w);
}

static void test_atmosphere_hollow(void **st)
{
    (void)st;
    for (int hollow = 0; hollow < 2; hollow++) {
        char src[512];
        snprintf(src, sizeof src,
                 "media { emission 0.05 }\n"
                 "plane { z, 10 pigment { rgb 0 } finish { ambient 0 diffuse 0 } hollow }\n"
                 "sphere { <0, 0, 4>, 1.5 pigment { rgbf 1 } finish { ambient 0 diffuse 0 } hollow %s }\n",
                 hollow ? "on" : "off");
        world w = build(src);
        rgb c = trace(&w, v3(0, 0, 0), v3(0, 0, 1));
        expect_rel(c.g, 0.05 * (hollow ? 10.0 : 7.0), TOL, hollow ? "atmosphere, hollow sphere" : "atmosphere, solid sphere");
        done(&w);
    }
}

static void test_shadow_through_media(void **st)
{
    (void)st;
    /* a parallel light straight down; the box (y 0..2) absorbs 0.4 per unit */
    world w = build("light_source { <0, 100, 0> color rgb 1 parallel point_at <0, 0, 0> }\n"
                    "plane { y, -1 pigment { rgb 1 } finish { ambient 0 diffuse 1 } }\n"
                    "box { <-1, 0, -1>, <1, 2, 1> pigment { rgbf 1 } finish { ambient 0 diffuse 0 } hollow\n"
                    "  interior { media { absorption 0.4 } } }\n");
    rgb lit = trace(&w, v3(3, 5, 0), v3_norm(v3(0, -1, 0)));      /* beside the box */
    rgb shaded = trace(&w, v3(0.2, -0.5, -5), v3_norm(v3(0, -0.5, 5))); /* floor under the box, seen from below it */
    expect_rel(lit.g, 1.0, TOL, "unshadowed floor");
    expect_rel(shaded.g, exp(-0.4 * 2.0), TOL, "floor under the absorbing box");
    done(&w);
}

static void test_shadow_walk_tolerance(void **st)
{
    (void)st;
    for (int media = 0; media < 2; media++)
        for (int small = 0; small < 2; small++) {
            char src[1024];
            snprintf(src, sizeof src,
                     "light_source { <0, 100, 0> color rgb 1 parallel point_at <0, 0, 0> }\n"
                     "plane { y, -1 pigment { rgb 1 } finish { ambient 0 diffuse 1 } }\n"
                     "sphere { <0, 1, 0>, 1 pigment { rgbt 1 } finish { ambient 0 diffuse 0 }\n"
                     "  interior { fade_distance 1 fade_power 1001 fade_color rgb 0.5 } }\n"
                     "sphere { <0, 1, 0>, %s pigment { rgbt 1 } finish { ambient 0 diffuse 0 }\n"
                     "  interior { fade_distance 1 fade_power 1001 fade_color rgb 0 } }\n%s",
                     small ? "0.9995" : "0.9",
                     media ? "box { <10, -1, 10>, <11, 0, 11> pigment { rgbt 1 } hollow interior { media { absorption 0.1 } } }\n"
                           : "");
            world w = build(src);
            rgb shaded = trace(&w, v3(0, -0.5, -5), v3_norm(v3(0, -0.5, 5))); /* the floor under the spheres */
            char what[64];
            snprintf(what, sizeof what, "%s gap, %s", small ? "0.0005" : "0.1", media ? "media walk" : "plain walk");
            expect_rel(shaded.g, small ? 1.0 : exp(-1.8) * exp(-0.05), TOL, what);
            done(&w);
        }
}

static void test_shadowless_lights_no_media(void **st)
{
    (void)st;
    for (int fill = 0; fill < 2; fill++) {
        char src[512];
        snprintf(src, sizeof src,
                 "light_source { <0, 50, 0> color rgb 1 %s }\n"
                 "box { <-1, -1, -1>, <1, 1, 1> pigment { rgbf 1 } finish { ambient 0 diffuse 0 } hollow\n"
                 "  interior { media { scattering { 1, 0.3 extinction 0 } } } scale <1, 1, 1.5> }\n",
                 fill ? "shadowless" : "");
        world w = build(src);
        rgb c = trace(&w, v3(0.1, 0.2, -10), v3(0, 0, 1));
        if (fill) {
            printf("media %-34s got %.12f expected 0\n", "shadowless light scattering", c.g);
            assert_true(fabs(c.g) <= 1e-12);
        } else {
            expect_rel(c.g, 0.3 * 3.0, TOL, "point light scattering");
        }
        done(&w);
    }
}

/* Ground fog fog_offset 5, fog_alt 0.01, distance 20, colour 0; a floor at
 * 0 seen from 0.5 above; a clear hollow pane from 6 to 6.5; a light at 10
 * (an area light of 2 x 2 points 0.001 apart: the four shadow rays agree,
 * no subdivision). povray 3.7 renders this floor (File_Gamma 1) as
 * 0.758979 and 0.637125, the closed forms' 0.758977 and 0.637130. */
static void test_area_light_ground_fog(void **st)
{
    (void)st;
    const double d = 20.0, a = 0.01, h0 = 5.0;
    /* the fog's optical depth up from y0 to y1 (vertical), times d */
    #define FOG_UP(y0, y1) (fmax(0.0, fmin(h0, (y1)) - (y0)) + ((y1) > h0 ? a * (atan(((y1) - h0) / a) - atan(fmax(0.0, (y0) - h0) / a)) : 0.0))
    double eye = exp(-FOG_UP(0.0, 0.5) / d);
    double point = exp(-FOG_UP(0.0, 10.0) / d);
    double area = exp(-(FOG_UP(0.0, 6.5) + FOG_UP(0.0, 3.5)) / d);
    #undef FOG_UP
    for (int with_area = 0; with_area < 2; with_area++) {
        char src[900];
        snprintf(src, sizeof src,
                 "fog { fog_type 2 distance 20 color rgb 0 fog_offset 5 fog_alt 0.01 up y }\n"
                 "light_source { <0, 10, 0> color rgb 1 media_attenuation on %s }\n"
                 "plane { y, 0 pigment { rgb 1 } finish { ambient 0 diffuse 1 } }\n"
                 "box { <-1, 6, -1>, <1, 6.5, 1> pigment { rgbf 1 } finish { ambient 0 diffuse 0 } hollow }\n",
                 with_area ? "area_light 0.001*x, 0.001*z, 2, 2" : "");
        world w = build(src);
        rgb c = trace(&w, v3(0, 0.5, 0), v3(0, -1, 0));
        expect_rel(c.g, eye * (with_area ? area : point), 1e-4,
                   with_area ? "area light, ground fog, pane" : "point light, ground fog, pane");
        done(&w);
    }
}

/* A sample of scattering media lit by a jittered area light draws its
 * jitter from where it lies, not from the thread tracing it: the image of
 * such media seen through a penumbra is the same on 1 and 3 threads, bit
 * for bit (benchmark.pov's clouds under its jittered area light differed
 * between thread counts when the thread chose the stream). */
static void test_media_area_jitter_threads(void **st)
{
    (void)st;
    world w = build("camera { location <0, 0, -5> look_at 0 }\n"
                    "light_source { <0, 10, 0> color rgb 1 area_light 2*x, 2*z, 4, 4 jitter }\n"
                    "box { <-3, 5, -3>, <0.1, 5.1, 3> pigment { rgb 0 } }\n" /* the penumbra crosses the media */
                    "box { -1, 1 pigment { rgbt 1 } hollow\n"
                    "      interior { media { scattering { 1, 0.5 } method 3 intervals 1 samples 8 } } }\n");
    framebuffer *fb[2];
    double sum = 0.0;
    for (int k = 0; k < 2; k++) {
        shade_settings ss;
        shade_default_settings(&ss);
        ss.width = 32;
        ss.height = 24;
        ss.threads = k ? 3 : 1;
        fb[k] = fb_new(32, 24);
        assert_non_null(fb[k]);
        shade_stats sst;
        assert_int_equal(shade_render(w.s, w.a, &ss, fb[k], &sst, NULL), PT_OK);
    }
    int differ = 0;
    for (int i = 0; i < 32 * 24 * 3; i++) {
        differ += memcmp(&fb[0]->rgb[i], &fb[1]->rgb[i], sizeof(float)) != 0;
        sum += fb[0]->rgb[i];
    }
    printf("media, jittered area light: mean %.6f, %d of %d values differ between 1 and 3 threads\n",
           sum / (32 * 24 * 3), differ, 32 * 24 * 3);
    assert_true(sum / (32 * 24 * 3) > 0.01);
    assert_int_equal(differ, 0);
    fb_free(fb[0]);
    fb_free(fb[1]);
    done(&w);
}

/* The containers of a point (the camera's, shade_media_inside_at) with
 * blobs, a height field and a text, which a box test answers away from
 * them (a blob outside its components' reach, a height field above its
 * highest point or off its square, a text outside its glyphs' box): a
 * point within the field's threshold is inside, one past the reach (just
 * outside the box, and far off) is not, an inverse blob the other way
 * round, a blob within a union too (strength 1, radius 2, threshold 0.5:
 * inside within 1.08 of a lone component's centre). */
static void test_inside_at_bounds(void **st)
{
    (void)st;
    if (access("/usr/share/povray-3.7/include/timrom.ttf", R_OK) != 0) skip();
    const char *src = "blob { threshold 0.5 sphere { <0, 0, 0>, 2, 1 } sphere { <3, 0, 0>, 1, 1 } hollow }\n"
                      "blob { threshold 0.5 sphere { <0, 10, 0>, 2, 1 } inverse hollow }\n"
                      "union { blob { threshold 0.5 sphere { <0, -10, 0>, 2, 1 } translate <2, 0, 0> } sphere { 100, 1 } }\n"
                      "height_field { function 8, 8 { 0.25 + 0.5 * x } scale <4, 2, 4> translate <20, 0, 0> }\n"
                      "text { ttf \"timrom.ttf\" \"I\" 1, 0 scale 4 translate <40, 0, 0> }\n";
    diag *d = diag_new();
    scene *sc = NULL;
    assert_int_equal(sdl_parse_string("blobs.pov", src, NULL, &sc, d), PT_OK);
    static const struct { vec3 p; int n; } cases[] = {
        {{0.1, 0.2, 0.0}, 2},    /* inside the first, outside the inverse one's reach */
        {{3.5, 0.0, 0.0}, 2},    /* the first's second component */
        {{4.0001, 0.0, 0.0}, 1}, /* just past the first's reach: only the inverse one */
        {{0.0, 10.2, 0.0}, 0},   /* inside the inverse one's field */
        {{-1.0, 0.0, 0.0}, 2},   /* 1 from the first's centre on each axis: inside */
        {{0.0, 1.0, 0.0}, 2},
        {{0.0, -1.0, 0.0}, 2},
        {{0.0, 0.0, 1.0}, 2},
        {{0.0, 0.0, -1.0}, 2},
        {{3.0, -10.0, 0.0}, 2},  /* the union's blob, moved by the translate */
        {{0.5, -10.0, 0.0}, 1},  /* 1.5 from its centre: a field below the threshold */
        {{50.0, 50.0, 50.0}, 1},
        {{21.0, 0.3, 2.0}, 2},   /* under the height field's surface (0.5 to 1.5 high there) */
        {{21.0, 1.2, 2.0}, 1},   /* over it, below its highest point */
        {{21.0, 2.5, 2.0}, 1},   /* above its highest point */
        {{25.0, 0.3, 2.0}, 1},   /* past its square */
        {{21.0, -5.0, 2.0}, 2},  /* far below: still under the surface */
        {{40.6, 1.0, 2.0}, 2},   /* in the letter I's stem (40.5 to 40.75 in x, 4 deep) */
        {{40.6, 1.0, 4.5}, 1},   /* behind it */
        {{41.5, 1.0, 2.0}, 1},   /* beside it, within its box */
        {{38.0, 1.0, 2.0}, 1},   /* outside its box */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        shade_media_inside in;
        shade_media_inside_at(sc, cases[i].p, &in);
        if (in.n != cases[i].n) fail_msg("point %zu: %d containers, %d expected", i, in.n, cases[i].n);
    }
    scene_free(sc);
    diag_free(d);
}

/* Bad media are located errors (POV-Ray's messages), declared media and
 * densities are reused, defaults follow #version. */
static void test_media_parse(void **st)
{
    (void)st;
    static const struct { const char *src; const char *msg; int line, col; } bad[] = {
        {"sphere { 0, 1 interior { media { samples 0 } } }", "At least one sample per interval", 1, 34},
        {"media {\n  scattering { 1, 0.3 eccentricity 0.5 } }", "Eccentricity cannot be used", 2, 23},
        {"media { method 4 }", "Sample method choices are 1, 2, or 3.", 1, 9},
        {"media { intervals 0 }", "At least one interval is needed", 1, 9},
        {"media { samples 5, 2 }", "smaller than minimum", 1, 9},
        {"media { aa_level 0 }", "aa_level in media must be at least one", 1, 9},
        {"media { confidence 1 }", "Illegal confidence value", 1, 9},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        diag *d = diag_new();
        scene *sc = NULL;
        pt_status stt = sdl_parse_string("bad.pov", bad[i].src, NULL, &sc, d);
        assert_int_not_equal(stt, PT_OK);
        int found = 0;
        for (int k = 0; k < diag_count(d); k++) {
            char *m = diag_format(diag_get(d, k));
            char want[64];
            snprintf(want, sizeof want, "bad.pov:%d:%d: error:", bad[i].line, bad[i].col);
            if (strstr(m, want) && strstr(m, bad[i].msg)) found = 1;
            else printf("media parse: %s\n", m);
            free(m);
        }
        assert_true(found);
        scene_free(sc);
        diag_free(d);
    }
    world w = build("#version 3.1;\n#declare M = media { emission 1 }\n#version 3.7;\n"
                    "#declare D = density { spherical }\n"
                    "media { M density { D scale 2 } }\n"
                    "media { absorption 1 scattering { 5, 0.5 eccentricity 0.3 extinction 0.5 } }\n");
    assert_int_equal(w.s->natmosphere, 2);
    const scene_media *m0 = w.s->atmosphere[0], *m1 = w.s->atmosphere[1];
    /* M was written at #version 3.1: method 1, intervals 10, samples 1 */
    assert_int_equal(m0->method, 1);
    assert_int_equal(m0->intervals, 10);
    assert_int_equal(m0->min_samples, 1);
    assert_int_equal(m0->ndensity, 1);
    assert_true(m0->emission.g == 1.0);
    assert_int_equal(m1->method, 3);
    assert_int_equal(m1->intervals, 1);
    assert_int_equal(m1->min_samples, 10);
    assert_int_equal(m1->scattering_type, 5);
    assert_true(m1->eccentricity == 0.3 && m1->extinction == 0.5);
    done(&w);
}

/* ------------------------------------------------------------ POV-Ray */

static char tmpdir[256];

static void check(const char *scene, double regression)
{
    char path[512];
    snprintf(path, sizeof path, "%s/scenes/%s.pov", TESTS_DIR, scene);
    double mad = tu_crosscheck(PARTRAY_BIN, tmpdir, path, scene, W, H, NULL);
    printf("media %-18s mean |diff| after 4x4 downsample = %.5f (tolerance %.3f)\n", scene, mad, TOLERANCE);
    assert_true(mad <= TOLERANCE);
    assert_true(mad <= regression);
}

/* bounds a margin over the printed differences (deterministic renders) */
static void test_xc_emit(void **st) { (void)st; check("xm_emit", 0.008); }
static void test_xc_absorb(void **st) { (void)st; check("xm_absorb", 0.003); }
static void test_xc_scatter(void **st) { (void)st; check("xm_scatter", 0.008); }

/* What makes a render's shadow rays walk their crossings: media that can
 * dim light (absorption or scattering; emission alone never does:
 * shade_media_scene_attenuates), and surfaces that can filter them, of
 * objects that cast shadows (shade_tex_scene_transparent: a no_shadow
 * glowing bulb is neither, as in baking_demo.pov). */
static void test_shadow_media_rules(void **st)
{
    (void)st;
    const char *srcs[] = {
        "sphere { 0, 1 pigment { rgbt 1 } hollow no_shadow interior { media { emission 1 } } }\n",
        "sphere { 0, 1 pigment { rgbt 1 } hollow interior { media { emission 1 } } }\n",
        "sphere { 0, 1 pigment { rgbt 1 } hollow no_shadow interior { media { absorption 0.1 } } }\n",
        "sphere { 0, 1 pigment { rgbt 1 } hollow no_shadow interior { media { scattering { 1, 0.2 } } } }\n",
        "sphere { 0, 1 pigment { rgb 1 } }\nmedia { emission 0.1 }\n",
        "sphere { 0, 1 pigment { rgb 1 } }\nmedia { absorption 0.1 }\n",
        "union { sphere { 0, 1 pigment { rgbf 0.5 } } sphere { x, 1 } no_shadow }\n",
    };
    const int has[] = {1, 1, 1, 1, 1, 1, 0}, dims[] = {0, 0, 1, 1, 0, 1, 0}, filters[] = {0, 1, 0, 0, 0, 0, 0};
    for (int i = 0; i < (int)(sizeof srcs / sizeof srcs[0]); i++) {
        world w = build(srcs[i]);
        printf("scene %d: media %d, attenuates %d, transparent %d\n", i, shade_media_scene_has(w.s),
               shade_media_scene_attenuates(w.s), shade_tex_scene_transparent(w.s));
        assert_int_equal(shade_media_scene_has(w.s), has[i]);
        assert_int_equal(shade_media_scene_attenuates(w.s), dims[i]);
        assert_int_equal(shade_tex_scene_transparent(w.s), filters[i]);
        done(&w);
    }
}

int main(void)
{
    if (tu_mkdtemp(tmpdir, sizeof tmpdir, "partray-media") != 0) return 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_beer_lambert),
        cmocka_unit_test(test_shadow_media_rules),
        cmocka_unit_test(test_emission_absorption),
        cmocka_unit_test(test_atmosphere_hollow),
        cmocka_unit_test(test_shadow_through_media),
        cmocka_unit_test(test_shadow_walk_tolerance),
        cmocka_unit_test(test_shadowless_lights_no_media),
        cmocka_unit_test(test_area_light_ground_fog),
        cmocka_unit_test(test_media_area_jitter_threads),
        cmocka_unit_test(test_media_parse),
        cmocka_unit_test(test_inside_at_bounds),
        cmocka_unit_test(test_xc_emit),
        cmocka_unit_test(test_xc_absorb),
        cmocka_unit_test(test_xc_scatter),
    };
    return tu_finish(cmocka_run_group_tests(tests, NULL, NULL), tmpdir);
}
