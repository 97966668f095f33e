/* test_gi_frame.c - the particle GI's frame stages (test_gi's main runs
 * these): the light-leak guard's verdicts per cell, the pre-pass's coarse
 * grid, and the render taking the pre-pass's kept hits. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "accel.h"
#include "diag.h"
#include "gi_cl.h"
#include "gi_particle.h"
#include "sdl.h"
#include "shade.h"
#include "shade_texture.h"
#include "pm_path.h"
#include "test_util.h"

#include "test_gi.h"

/* ------------------------------------------------------------------ light-leak guard per cell */

/* The hook's light-leak guard decides once per interpolation cell whether
 * every point of it sees the cell's 3 radiance particles (gi_particle_cells.c
 * cell_clear) and tests per hit only in the other cells. A block (rotated
 * 30 degrees, so no radiance particle lies on its walls) stands on a floor
 * box, a sphere rests on the floor beside it.
 *  - A light inside the block: the floor under it is lit, nothing outside
 *    is: every probe outside (floor, block top, sphere) gets exactly 0 from
 *    the hook, as the per-hit test gives, while the floor under the block
 *    gets light (so a leak would show).
 *  - A light outside: at the same probes (a 64 x 64 grid of rays down) the
 *    cache holds both clear cells and blocked ones (the floor cells the
 *    block's walls cross), and lookups in clear cells skip their rays. */
static const char *leak_scene =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 }\n"
    "camera { location <0, 3, -4> look_at 0 }\n"
    "light_source { L color rgb 1 }\n"
    "box { <-2, -0.1, -2>, <2, 0, 2> pigment { rgb 0.8 } finish { ambient 0 diffuse 0.8 } }\n"
    "box { <-0.5, 0, -0.5>, <0.5, 1, 0.5> rotate y*30 pigment { rgb 0.6 } finish { ambient 0 diffuse 0.8 } }\n"
    "sphere { <1.2, 0.4, 0.8>, 0.4 pigment { rgb 0.7 } finish { ambient 0 diffuse 0.8 } }\n";

enum { LEAK_N = 64 };

static gi_particle *build_leak(fixture *f, const char *light)
{
    char text[1024];
    const char *at = strstr(leak_scene, "L color");
    snprintf(text, sizeof text, "%.*s%s%s", (int)(at - leak_scene), leak_scene, light, at + 1);
    tg_load(f, text);
    gi_particle_settings s;
    gi_particle_default_settings(&s);
    s.count = 6000;
    s.bounces = 3;
    s.threads = 2;
    s.seed = 11;
    s.cl_device = tg_device_c;
    return tg_build_with(f, &s);
}

/* The hook's green value at the probes of a grid of rays straight down. */
static void leak_probe(fixture *f, gi_particle *gp, double *v)
{
    for (int j = 0; j < LEAK_N; j++)
        for (int i = 0; i < LEAK_N; i++) {
            vec3 org = v3(-1.95 + 3.9 * (i + 0.5) / LEAK_N, 5.0, -1.95 + 3.9 * (j + 0.5) / LEAK_N), dir = v3(0, -1, 0);
            accel_hit h;
            v[j * LEAK_N + i] = -1.0;
            if (!accel_intersect(f->a, org, dir, 0.0, INFINITY, &h)) continue;
            vec3 n = v3_dot(dir, h.ns) > 0.0 ? v3_neg(h.ns) : h.ns;
            rgb e = gi_particle_indirect(gp, &h, n, 0);
            assert_true(isfinite(e.g));
            v[j * LEAK_N + i] = e.g;
        }
}

void test_cell_cache(void **state)
{
    (void)state;
    static double a[LEAK_N * LEAK_N];
    /* light inside the block */
    fixture f;
    gi_particle *gp = build_leak(&f, "<0, 0.5, 0>");
    leak_probe(&f, gp, a);
    double outside = 0.0;
    int probes = 0;
    for (int k = 0; k < LEAK_N * LEAK_N; k++)
        if (a[k] >= 0.0) outside = fmax(outside, a[k]), probes++;
    accel_hit h;
    assert_true(accel_intersect(f.a, v3(0.05, 0.5, 0.05), v3(0, -1, 0), 0.0, INFINITY, &h));
    double under = gi_particle_indirect(gp, &h, v3(0, 1, 0), 0).g;
    const gi_particle_stats *st = gi_particle_get_stats(gp);
    printf("  light in the block: %d probes outside, largest indirect %.3g (must be 0); floor under the block %.4g; "
           "cells %ld (%ld clear)\n",
           probes, outside, under, st->cells, st->cells_clear);
    assert_true(probes > LEAK_N * LEAK_N / 2);
    assert_true(outside == 0.0);
    assert_true(under > 0.01);
    gi_particle_free(gp);
    tg_unload(&f);

    /* light outside */
    gp = build_leak(&f, "<-1.5, 2.5, -1.5>");
    leak_probe(&f, gp, a);
    st = gi_particle_get_stats(gp);
    long cells = st->cells, clear = st->cells_clear, lclear = st->lookups_clear, look = st->lookups;
    gi_particle_free(gp);
    tg_unload(&f);
    int n = 0;
    double sa = 0.0;
    for (int k = 0; k < LEAK_N * LEAK_N; k++) {
        if (a[k] < 0.0) continue;
        n++;
        sa += a[k];
    }
    printf("  light outside: %d probes, mean %.6f; cells %ld (%ld clear), %ld of %ld lookups in clear cells\n", n,
           sa / n, cells, clear, lclear, look);
    assert_true(sa > 0.0);
    assert_true(clear > 0 && clear < cells);
    assert_true(lclear > 0);
}

/* ------------------------------------------------------------------ the pre-pass's coarse grid */

/* The pre-pass traces every 2nd pixel in x and y and takes the hits of the
 * pixels between from the flat piece their coarse neighbours share
 * (gi_particle_view.c, coarse_hit). Inside the mesh cube at 64 x 64 it must mark
 * the radiance particles tracing every pixel marks (the same set, but for
 * ties on cell edges: at most 0.5% differ), with at most 40%
 * of the rays; a render after it computes no radiance particle late. */
void test_prepass_grid(void **state)
{
    (void)state;
    enum { PW = 64 };
    long found[2], rays[2], planar[2];
    for (int k = 0; k < 2; k++) {
        fixture f;
        tg_load(&f, tg_cube_scene);
        gi_particle_settings s;
        gi_particle_default_settings(&s);
        s.count = 3000;
        s.bounces = 2;
        s.threads = 2;
        s.seed = 5;
        s.cl_device = tg_device_c;
        s.prepass_stride = k == 0 ? 1 : 2;
        pt_status st;
        gi_particle *gp = gi_particle_build(f.sc, f.a, &s, NULL, f.d, &st);
        assert_non_null(gp);
        assert_int_equal(gi_particle_prepare_view(gp, &f.sc->camera, PW, PW, f.d), PT_OK);
        const gi_particle_stats *x = gi_particle_get_stats(gp);
        found[k] = x->found;
        rays[k] = x->prepass_rays;
        planar[k] = x->prepass_planar;
        if (k == 1) {
            shade_settings ss;
            shade_default_settings(&ss);
            ss.width = ss.height = PW;
            ss.threads = 2;
            ss.use_ambient = 0;
            ss.indirect = gi_particle_indirect;
            ss.indirect_ctx = gp;
            framebuffer *fb = fb_new(PW, PW);
            shade_stats sst;
            assert_int_equal(shade_render(f.sc, f.a, &ss, fb, &sst, f.d), PT_OK);
            x = gi_particle_get_stats(gp);
            printf("  pre-pass every pixel: %ld rays, %ld radiance particles found; every 2nd: %ld rays, %ld pixels on "
                   "their neighbours' plane, %ld found; render after it: %ld lookups, %ld radiance particles late\n",
                   rays[0], found[0], rays[1], planar[1], found[1], x->lookups, x->late_radiance);
            assert_true(x->lookups >= PW * PW);
            assert_int_equal(x->late_radiance, 0);
            fb_free(fb);
        }
        gi_particle_free(gp);
        tg_unload(&f);
    }
    assert_int_equal(planar[0], 0);
    assert_true(rays[1] * 10 <= 4 * PW * PW);
    assert_true(planar[1] + rays[1] >= PW * PW);
    assert_true(found[0] > 100);
    assert_true(labs(found[1] - found[0]) * 200 <= found[0]);
}

/* ------------------------------------------------------------------ kept hits */

/* keep_hits: the pre-pass keeps every pixel's first hit and its located
 * cell, the render takes them (gi_particle_primary_hit as
 * shade_settings.primary) instead of tracing its camera rays, the hook
 * takes the cell instead of locating. The image must be bit for bit the
 * one of the same pre-pass (stride 1) without them: a mesh floor, a box, a
 * mirror sphere (reflected rays are traced), a no_image sphere (those
 * pixels are traced: the render steps past it), background pixels (misses
 * kept). Then the camera moved in place without a new pre-pass (no ray
 * matches: every one traced) and a 4-spp render (no ray through a pixel
 * centre) must equal renders without the provider. */
static const char *const kept_scene =
    "camera { location <0.3, 2.2, -4> look_at <0, 0.4, 0> }\n"
    "light_source { <-1.5, 3, -2> color rgb 1 }\n"
    "mesh { triangle { <-2, 0, -2>, <2, 0, -2>, <2, 0, 2> } triangle { <-2, 0, -2>, <2, 0, 2>, <-2, 0, 2> }\n"
    "  pigment { rgb 0.8 } finish { ambient 0 diffuse 0.8 } }\n"
    "box { <-0.5, 0, -0.5>, <0.5, 1, 0.5> rotate y*30 pigment { rgb <0.7, 0.5, 0.4> } finish { ambient 0 diffuse 0.8 } }\n"
    "sphere { <1.1, 0.5, 0.6>, 0.5 pigment { rgb 0.3 } finish { ambient 0 diffuse 0.3 reflection 0.6 } }\n"
    "sphere { <-1.0, 0.5, -1.0>, 0.3 pigment { rgb 0.9 } finish { ambient 0 diffuse 0.8 } no_image }\n";

static framebuffer *kept_render(fixture *f, gi_particle *gp, int provider, int spp, shade_stats *sst)
{
    enum { KW = 48 };
    shade_settings ss;
    shade_default_settings(&ss);
    ss.width = ss.height = KW;
    ss.threads = 2;
    ss.use_ambient = 0;
    ss.indirect = gi_particle_indirect;
    ss.indirect_ctx = gp;
    if (spp > 1) {
        ss.antialias = 2;
        ss.spp = spp;
    }
    if (provider) {
        ss.primary_begin = gi_particle_primary_begin;
        ss.primary = gi_particle_primary_hit;
        ss.primary_ctx = gp;
    }
    framebuffer *fb = fb_new(KW, KW);
    assert_int_equal(shade_render(f->sc, f->a, &ss, fb, sst, f->d), PT_OK);
    return fb;
}

static int fb_same(const framebuffer *a, const framebuffer *b)
{
    return a->width == b->width && a->height == b->height &&
           !memcmp(a->rgb, b->rgb, (size_t)a->width * a->height * 3 * sizeof *a->rgb);
}

void test_kept_hits(void **state)
{
    (void)state;
    enum { KW = 48 };
    fixture f;
    tg_load(&f, kept_scene);
    gi_particle *gp[2];
    for (int k = 0; k < 2; k++) {
        gi_particle_settings s;
        gi_particle_default_settings(&s);
        s.count = 4000;
        s.bounces = 3;
        s.threads = 2;
        s.seed = 3;
        s.cl_device = tg_device_c;
        s.prepass_stride = 1;
        s.keep_hits = k;
        gp[k] = tg_build_with(&f, &s);
        assert_int_equal(gi_particle_prepare_view(gp[k], &f.sc->camera, KW, KW, f.d), PT_OK);
    }
    shade_stats s0, s1;
    framebuffer *a = kept_render(&f, gp[0], 0, 1, &s0), *b = kept_render(&f, gp[1], 1, 1, &s1);
    const gi_particle_stats *x = gi_particle_get_stats(gp[1]);
    long kept = x->prepass_kept, lk = x->lookups_kept, look = x->lookups;
    int misses = 0, noimg = 0;
    assert_true(gi_particle_primary_begin(gp[1], f.sc, f.a, KW, KW, 1e-6 * accel_eps_scale(f.a)));
    assert_false(gi_particle_primary_begin(gp[0], f.sc, f.a, KW, KW, 1e-6 * accel_eps_scale(f.a)));
    for (int y = 0; y < KW; y++)
        for (int i = 0; i < KW; i++) {
            vec3 org, dir;
            const accel_hit *h;
            if (!gi_particle_primary_hit(gp[1], i, y, &org, &dir, &h)) {
                noimg++;
                continue;
            }
            misses += h == NULL;
        }
    printf("  %d x %d: %ld hits kept (%d misses, %d pixels not kept: no_image), %ld of %ld lookups took a kept cell; "
           "primary rays %ld / %ld, mean %.6f / %.6f, identical %d\n",
           KW, KW, kept, misses, noimg, lk, look, s0.primary_rays, s1.primary_rays, fb_mean(a, -1), fb_mean(b, -1),
           fb_same(a, b));
    /* the kept pre-pass tests its cells in batches at each row's end (the
     * hook of gp[0] one by one): the same verdicts, blocked ones among them
     * (the floor cells across the box's foot), or the images would differ */
    long cells = x->cells, clear = x->cells_clear;
    printf("  cells tested in the kept pre-pass's batches: %ld (%ld clear)\n", cells, clear);
    assert_true(cells > 0 && clear < cells);
    assert_true(fb_same(a, b));
    assert_int_equal(s0.primary_rays, s1.primary_rays);
    assert_int_equal(kept + noimg, KW * KW);
    assert_true(noimg > 10 && misses > 10);
    assert_true(lk * 10 >= look * 7); /* the rest: reflected rays' hits */
    assert_true(lk < look);
    assert_int_equal(gi_particle_get_stats(gp[0])->prepass_kept, 0);
    fb_free(a);
    fb_free(b);

    /* the camera moved in place, no new pre-pass: nothing matches */
    f.sc->camera.location.x += 0.01;
    a = kept_render(&f, gp[0], 0, 1, &s0);
    b = kept_render(&f, gp[1], 1, 1, &s1);
    long lk2 = gi_particle_get_stats(gp[1])->lookups_kept;
    printf("  camera moved: identical %d, kept lookups %ld -> %ld\n", fb_same(a, b), lk, lk2);
    assert_true(fb_same(a, b));
    assert_int_equal(lk2, lk);
    fb_free(a);
    fb_free(b);
    f.sc->camera.location.x -= 0.01;
    /* 4 spp: no camera ray through a pixel centre */
    a = kept_render(&f, gp[0], 0, 4, &s0);
    b = kept_render(&f, gp[1], 1, 4, &s1);
    lk2 = gi_particle_get_stats(gp[1])->lookups_kept;
    printf("  4 spp: identical %d, kept lookups %ld -> %ld\n", fb_same(a, b), lk, lk2);
    assert_true(fb_same(a, b));
    assert_int_equal(lk2, lk);
    fb_free(a);
    fb_free(b);
    gi_particle_free(gp[0]);
    gi_particle_free(gp[1]);
    tg_unload(&f);
}
