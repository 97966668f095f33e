/* test_caustics.c - the caustic layer (gi/gi_caustic.h, app/caustics.h):
 * its irradiance against the path tracer in a glass sphere's focus, against
 * the closed form behind a mirror, the splat against the brute-force sum of
 * the same photon volumes, OpenCL against the C build, determinism, media
 * photons in a lit box against the closed form, the
 * photon settings that are counted and warned about as not modelled, and
 * the light through glass in particle GI's bounces (the caustics' and
 * POV-Ray's filtered shadows'). */
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
#include "caustics.h"
#include "framebuffer.h"
#include "gi_cl.h"
#include "gi_cl_c.h"
#include "pm_fg.h"
#include "pm_path.h"
#include "render_gi.h"
#include "gi.h"
#include "sdl.h"
#include "test_world.h"

#define THREADS 2

/* The layer of scene `text` over a w x h G-buffer on device dev (NULL auto). */
static void layer(caustics *c, const scene *sc, const accel *a, int w, int h, const char *dev, int threads, diag *d)
{
    assert_int_equal(caustics_build(c, sc, a, w, h, threads, 1, dev, 0, 0.0, 0, NULL, d), PT_OK);
    assert_non_null(c->layer);
}

/* Mean green of the central cw x ch pixels of a w-wide image of `stride`
 * floats a pixel. */
static double centre_mean(const float *img, int stride, int w, int h, int cw, int ch)
{
    double s = 0.0;
    for (int y = (h - ch) / 2; y < (h + ch) / 2; y++)
        for (int x = (w - cw) / 2; x < (w + cw) / 2; x++) s += img[((size_t)y * w + x) * stride + 1];
    return s / (cw * ch);
}

/* Mean of channel k over the n pixels of a layer image (4 floats a pixel). */
static double channel_mean(const float *img, int n, int k)
{
    double s = 0.0;
    for (int i = 0; i < n; i++) s += img[4 * i + k];
    return s / n;
}

/* A glass sphere (radius 0.5, ior 1.5) 0.8 above a white floor under a
 * point light 10 above the floor that falls off as 1/d^2 (colour 50,
 * fade_distance 0.1, fade_power 2: 2/(1 + (d/0.1)^2) = 0.02/d^2 within
 * 1e-4). The camera looks straight down (orthographic, 0.3 x 0.3) at the
 * focus; the sphere is no_image, so the image is the floor's irradiance.
 * The path tracer cannot reach a point light through glass, so its scene
 * has an emissive sphere of radius 0.3 and radiance 1/0.3^2 in its place:
 * the same 1/d^2 intensity (E = pi L (r/d)^2 cos, E/pi units). Compared:
 * the mean irradiance over the central 0.2 x 0.2 square (the focus and the
 * inner part of its aberration halo: about 70% of the flux through the
 * sphere, by geometric optics). The layer's G-buffer is 150 x 150 (pixels
 * of 0.002, finer than the photon volumes' radius 0.0055, so that its
 * point samples integrate the focused spike); the path tracer's pixels
 * integrate their area, 15 x 15 at 4096 samples. */
static const char *focus_fmt =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 max_trace_level 10 %s }\n"
    "camera { orthographic location <0, 5, 0> look_at <0, 0, 0> sky z right x*0.3 up z*0.3 }\n"
    "%s\n"
    "sphere { <0, 0.8, 0>, 0.5 pigment { rgbf 1 } finish { ambient 0 diffuse 0 } interior { ior 1.5 } no_image %s }\n"
    "plane { y, 0 pigment { rgb 1 } finish { ambient 0 diffuse 1 } }\n";

static void test_focus_vs_path(void **state)
{
    (void)state;
    char text[2048];
    snprintf(text, sizeof text, focus_fmt, "photons { spacing 0.002 }",
             "light_source { <0, 10, 0> color rgb 50 fade_distance 0.1 fade_power 2 }",
             "photons { target refraction on reflection off }");
    tu_world w = tu_world_build("test.pov", text);
    scene *sc = w.s;
    accel *a = w.a;
    diag *d = diag_new();
    caustics c;
    layer(&c, sc, a, 150, 150, NULL, THREADS, d);
    double e_layer = centre_mean(gi_caustic_image(c.layer), 4, 150, 150, 100, 100);
    gi_caustic_stats st;
    gi_caustic_get_stats(c.layer, &st);
    caustics_free(&c);
    diag_free(d);
    tu_world_free(&w);

    snprintf(text, sizeof text, focus_fmt, "",
             "sphere { <0, 10, 0>, 0.3 pigment { rgb 1 } finish { ambient 0 diffuse 0 emission 11.111111111 } }", "");
    w = tu_world_build("test.pov", text);
    sc = w.s;
    a = w.a;
    pm_path_settings ps;
    pm_path_default_settings(&ps);
    ps.c.width = ps.c.height = 15;
    ps.c.threads = THREADS;
    ps.c.spp = getenv("PT_CAUSTIC_SPP") ? atoi(getenv("PT_CAUSTIC_SPP")) : 4096;
    ps.c.seed = 11;
    framebuffer *fb = fb_new(15, 15);
    pm_stats pst;
    assert_int_equal(pm_path_render(sc, a, &ps, fb, &pst, NULL), PT_OK);
    double e_path = centre_mean(fb->rgb, 3, 15, 15, 10, 10);
    printf("glass sphere focus, mean irradiance over 0.2 x 0.2: caustic layer %.6f (%ld photons, r_xy median %.4f, "
           "%.2f s trace, %.3f s splat), path %.6f (%d spp, %.1f s): ratio %.4f (tol 0.05)\n",
           e_layer, st.stored, st.r_median, st.t_trace, st.t_splat, e_path, ps.c.spp, pst.t_total, e_layer / e_path);
    assert_true(fabs(e_layer / e_path - 1.0) <= 0.05);
    fb_free(fb);
    tu_world_free(&w);
}

/* The mirror scenes below: a camera looking straight down at the floor's
 * 0.4 x 0.4 around the origin, a mirror wall at x = 1; %s: the global
 * photons block, the light (or emitter), the mirror's photons block and the
 * floor's finish items. */
static const char *mirror_fmt =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 %s }\n"
    "camera { orthographic location <0, 5, 0> look_at <0, 0, 0> sky z right x*0.4 up z*0.4 }\n"
    "%s\n"
    "box { <1, -1, -3>, <1.1, 3, 3> pigment { rgb 0 } finish { ambient 0 diffuse 0 reflection 1 } %s }\n"
    "plane { y, 0 pigment { rgb 1 } finish { ambient 0 diffuse 1 %s } }\n";

/* The reference for mirror caustics: --gi path sees an emissive sphere
 * (radius 1 at <-4, 5, 0>, radiance 10) in a mirror wall at x = 1; an
 * opaque no_reflection block hides the sphere's direct light from the
 * floor, so the image is the mirrored light alone: the floor sees the
 * sphere's image at <6, 5, 0>, E/pi = L sin^2(alpha) cos = L (r/d)^2 (5/d)
 * at each point, 0.10498 averaged over the 0.4 x 0.4 view (closed form
 * summed here). The light reaches the floor only along diffuse -> mirror ->
 * emitter paths, found by BSDF sampling (MIS weight 1 after a specular
 * bounce), so the estimate is heavy-tailed for small emitters (a sphere of
 * radius 0.3 at 64 samples a pixel came out 32% low, at 16384 within
 * 0.2%); tolerance 5%, about 3 standard deviations of this 8 x 8 image at
 * 16384 samples. */
static void test_path_mirror_closed_form(void **state)
{
    (void)state;
    char text[1024];
    snprintf(text, sizeof text, mirror_fmt, "",
             "sphere { <-4, 5, 0>, 1 pigment { rgb 1 } finish { ambient 0 diffuse 0 emission 10 } no_image }\n"
             "box { <-1.3, 0.8, -1>, <-0.4, 1.2, 1> pigment { rgb 0 } finish { ambient 0 diffuse 0 } no_reflection }",
             "", "");
    tu_world w = tu_world_build("test.pov", text);
    double want = 0.0;
    for (int i = 0; i < 40; i++)
        for (int j = 0; j < 40; j++) {
            double x = -0.2 + (i + 0.5) * 0.01, z = -0.2 + (j + 0.5) * 0.01;
            double d2 = (6.0 - x) * (6.0 - x) + 25.0 + z * z;
            want += 10.0 / d2 * 5.0 / sqrt(d2) / 1600.0;
        }
    pm_path_settings ps;
    pm_path_default_settings(&ps);
    ps.c.width = ps.c.height = 8;
    ps.c.threads = THREADS;
    ps.c.spp = 16384;
    ps.c.seed = 5;
    framebuffer *fb = fb_new(8, 8);
    pm_stats pst;
    assert_int_equal(pm_path_render(w.s, w.a, &ps, fb, &pst, NULL), PT_OK);
    double e = 0.0;
    for (int k = 0; k < 64; k++) e += fb->rgb[3 * k + 1] / 64.0;
    printf("path, emissive sphere in a mirror: %.5f, closed form %.5f (rel err %+.4f, tol 0.05; %d spp, %.1f s)\n", e, want,
           e / want - 1.0, ps.c.spp, pst.t_total);
    assert_true(fabs(e / want - 1.0) <= 0.05);
    fb_free(fb);
    tu_world_free(&w);
}

/* A mirror wall (x = 1, reflection 1) beside a point light of colour 1 at
 * <-2, 5, 0>: at the floor's origin the reflected light comes from the
 * mirror image <4, 5, 0>, and a POV-Ray light gives E/pi = C cos at any
 * distance, so the caustic layer must give 5 / sqrt(41) = 0.78087 (mean
 * over 0.4 x 0.4, where cos varies by under 1%). */
static void test_mirror_closed_form(void **state)
{
    (void)state;
    char text[1024];
    snprintf(text, sizeof text, mirror_fmt, "photons { spacing 0.01 }", "light_source { <-2, 5, 0> color rgb 1 }",
             "photons { target reflection on }", "");
    tu_world w = tu_world_build("test.pov", text);
    scene *sc = w.s;
    accel *a = w.a;
    diag *d = diag_new();
    caustics c;
    layer(&c, sc, a, 32, 32, NULL, THREADS, d);
    double e = centre_mean(gi_caustic_image(c.layer), 4, 32, 32, 32, 32), want = 5.0 / sqrt(41.0);
    printf("mirror: caustic layer %.5f, closed form %.5f (rel err %+.4f, tol 0.02)\n", e, want, e / want - 1.0);
    assert_true(fabs(e / want - 1.0) <= 0.02);
    caustics_free(&c);
    diag_free(d);
    tu_world_free(&w);
}

/* The two ways a photon loses what a surface does not pass on: a grey
 * mirror (diffuse 0.2, reflection 0.6) beside the light of
 * test_mirror_closed_form. POV-Ray's weights (the default) send every
 * photon on at 0.6 of its power; seed 002's Russian roulette
 * (--photon-roulette) sends on a share p = 0.6 (the specular lobe's share
 * of 0.8, under 1) at 1/p of 0.6 of its power. Both must give the closed
 * form 0.6 x 5 / sqrt(41) = 0.46852 (2%: each photon volume holds some
 * hundred photons, so the roulette's noise is a fraction of that), and the
 * attrition after the bounce map must be the rule's: every photon at its
 * target goes on under the weights, 0.6 of them under the roulette (+-0.02,
 * many standard deviations of a binomial over the 10^5 photons at the
 * mirror, far from the other rule's 1). */
static void test_mirror_roulette(void **state)
{
    (void)state;
    static const char *fmt = "#version 3.7;\n"
                             "global_settings { assumed_gamma 1.0 photons { spacing 0.01 } }\n"
                             "camera { orthographic location <0, 5, 0> look_at <0, 0, 0> sky z right x*0.4 up z*0.4 }\n"
                             "light_source { <-2, 5, 0> color rgb 1 }\n"
                             "box { <1, -1, -3>, <1.1, 3, 3> pigment { rgb 1 } finish { ambient 0 diffuse 0.2 "
                             "reflection 0.6 } photons { target reflection on } }\n"
                             "plane { y, 0 pigment { rgb 1 } finish { ambient 0 diffuse 1 } }\n";
    tu_world w = tu_world_build("test.pov", fmt);
    double want = 0.6 * 5.0 / sqrt(41.0);
    for (int rr = 0; rr <= 1; rr++) {
        diag *d = diag_new();
        caustics c;
        assert_int_equal(caustics_build(&c, w.s, w.a, 32, 32, THREADS, 1, NULL, 0, 0.0, rr, NULL, d), PT_OK);
        assert_non_null(c.layer);
        double e = centre_mean(gi_caustic_image(c.layer), 4, 32, 32, 32, 32);
        gi_caustic_stats st;
        gi_caustic_get_stats(c.layer, &st);
        double kept = st.first_hits ? (double)st.alive[1] / (double)st.first_hits : 0.0;
        printf("grey mirror, %s: caustic layer %.5f, closed form %.5f (rel err %+.4f, tol 0.02); going on after the "
               "bounce map %.4f of %ld (want %.1f)\n",
               rr ? "roulette" : "weights", e, want, e / want - 1.0, kept, st.first_hits, rr ? 0.6 : 1.0);
        assert_true(st.first_hits > 1000);
        assert_true(fabs(e / want - 1.0) <= 0.02);
        assert_true(fabs(kept - (rr ? 0.6 : 1.0)) <= 0.02);
        caustics_free(&c);
        diag_free(d);
    }
    tu_world_free(&w);
}

/* POV-Ray's gather minimum (gi_caustic.c, widen_sparse): a photon volume
 * holding fewer than `gather`'s minimum m of photon positions is widened
 * to hold m (up to 3 times its radius), spreading its power, not adding
 * to it. Under the mirror the floor's photons are an unfocused beam whose
 * volumes hold some 170 photons each: the default m = 20 widens none but
 * the odd one at the beam's edge, m = 300 nearly all. Checked by brute
 * force on every 500th photon: each holds m as it was, or its radius is
 * the distance of its m-th nearest position (m within 1.001 of it, fewer
 * within 0.999), or it holds fewer than m at 3 times the radius it had
 * (the beam's edge); at m = 300 at least 80% are at their m-th nearest,
 * at m = 20 99% hold m as they were; the irradiance keeps the closed form
 * (2%). */
static long positions_within(const gi_caus_photon *ph, long n, const gi_caus_photon *q, double r)
{
    long k = 0;
    for (long j = 0; j < n; j++) {
        const gi_caus_photon *o = &ph[j];
        if (o->n[0] * q->n[0] + o->n[1] * q->n[1] + o->n[2] * q->n[2] < 0.5f) continue;
        double dx = o->x[0] - q->x[0], dy = o->x[1] - q->x[1], dz = o->x[2] - q->x[2];
        double dn = dx * q->n[0] + dy * q->n[1] + dz * q->n[2];
        double dp2 = fmax(dx * dx + dy * dy + dz * dz - dn * dn, 0.0);
        k += sqrt(dp2 + 16.0 * dn * dn) < r;
    }
    return k;
}

static void test_gather_minimum(void **state)
{
    (void)state;
    long widened[2], stored[2];
    for (int k = 0; k < 2; k++) {
        const long m = k ? 300 : 20;
        char text[1024];
        snprintf(text, sizeof text, mirror_fmt, k ? "photons { spacing 0.01 gather 300, 400 }" : "photons { spacing 0.01 }",
                 "light_source { <-2, 5, 0> color rgb 1 }", "photons { target reflection on }", "");
        tu_world w = tu_world_build("test.pov", text);
        diag *d = diag_new();
        caustics c;
        layer(&c, w.s, w.a, 32, 32, NULL, THREADS, d);
        gi_caustic_stats st;
        gi_caustic_get_stats(c.layer, &st);
        double e = centre_mean(gi_caustic_image(c.layer), 4, 32, 32, 32, 32), want = 5.0 / sqrt(41.0);
        widened[k] = st.widened;
        stored[k] = st.stored;
        long n, checked = 0, at_mth = 0, held = 0, capped = 0;
        const gi_caus_photon *ph = gi_caustic_photons(c.layer, &n);
        assert_int_equal(n, st.stored);
        for (long i = 0; i < n; i += 500) {
            long less = positions_within(ph, n, &ph[i], 0.999 * ph[i].r_xy);
            long more = positions_within(ph, n, &ph[i], 1.001 * ph[i].r_xy);
            at_mth += less < m && more >= m; /* widened to the m-th nearest */
            held += less >= m;               /* held m already: as it was */
            capped += more < m;              /* fewer than m within 3 times its radius */
            checked++;
        }
        printf("gather minimum %ld: %ld of %ld volumes widened, median radius %.5f; of %ld checked, %ld at their "
               "m-th nearest, %ld at 3 times their radius, %ld holding m as they were; caustic layer %.5f, closed "
               "form %.5f (rel err %+.4f, tol 0.02)\n",
               m, st.widened, st.stored, st.r_median, checked, at_mth, capped, held, e, want, e / want - 1.0);
        assert_int_equal(at_mth + capped + held, checked);
        if (k) assert_true(at_mth >= checked * 8 / 10);
        else assert_true(held >= checked * 99 / 100);
        assert_true(fabs(e / want - 1.0) <= 0.02);
        caustics_free(&c);
        diag_free(d);
        tu_world_free(&w);
    }
    assert_true(widened[0] < stored[0] / 100);
    assert_true(widened[1] > stored[1] * 9 / 10);
}

/* The mirror above with a floor of finish brilliance b: POV-Ray shades
 * each photon as a light through the diffuse term cos^b after dividing by
 * the cosine (trace.cpp's ComputePhotonDiffuseLight), with the direction
 * it stored for the photon: the elevation above the floor truncated to a
 * multiple of pi/127 (photons.cpp's addSurfacePhoton keeps it in a signed
 * byte). At a floor point whose mirrored light is seen at cosine c, where
 * the stored elevation gives c_q, the layer must give c c_q^(b-1) (the
 * photons' density carries c), averaged over the view's pixel centres
 * (the elevation there spans 50 to 53 degrees, across two byte steps);
 * with the exact direction, (5 / sqrt(41))^b within 0.2% of it. Tolerance
 * 0.5%: at b = 3 the exact direction's answer is 1% off. */
static double mirror_brilliance_want(double b)
{
    double sum = 0.0;
    for (int i = 0; i < 32; i++)
        for (int j = 0; j < 32; j++) {
            double x = -0.2 + (i + 0.5) * 0.4 / 32.0, z = -0.2 + (j + 0.5) * 0.4 / 32.0;
            double dx = 4.0 - x, dz = -z, len = sqrt(dx * dx + 25.0 + dz * dz);
            double c = 5.0 / len, elev = asin(c);
            double cq = sin((double)(int)(elev * 127.0 / M_PI) * M_PI / 127.0);
            sum += c * pow(cq, b - 1.0);
        }
    return sum / (32.0 * 32.0);
}

/* The mirror scene lit by the point light <-2, 5, 0> of colour 1 shooting
 * photons at the mirror (spacing 0.01), its floor's finish items `floor`. */
static tu_world mirror_lit(const char *floor)
{
    char text[1024];
    snprintf(text, sizeof text, mirror_fmt, "photons { spacing 0.01 }", "light_source { <-2, 5, 0> color rgb 1 }",
             "photons { target reflection on }", floor);
    return tu_world_build("test.pov", text);
}

static void test_mirror_brilliance(void **state)
{
    (void)state;
    const double bs[2] = {0.5, 3.0};
    for (int i = 0; i < 2; i++) {
        char floor[64];
        snprintf(floor, sizeof floor, "brilliance %g", bs[i]);
        tu_world w = mirror_lit(floor);
        diag *d = diag_new();
        caustics c;
        layer(&c, w.s, w.a, 32, 32, NULL, THREADS, d);
        double e = centre_mean(gi_caustic_image(c.layer), 4, 32, 32, 32, 32), want = mirror_brilliance_want(bs[i]);
        printf("mirror, floor brilliance %g: caustic layer %.5f, closed form %.5f (rel err %+.4f, tol 0.005; exact "
               "direction's %.5f)\n",
               bs[i], e, want, e / want - 1.0, pow(5.0 / sqrt(41.0), bs[i]));
        assert_true(fabs(e / want - 1.0) <= 0.005);
        caustics_free(&c);
        diag_free(d);
        tu_world_free(&w);
    }
}

/* The mirror above over a floor with no Lambertian term but a specular
 * highlight (diffuse 0, specular 1, roughness 0.5: POV-Ray's exponent
 * 1 / roughness = 2), as clear glass is: the photons stored there light it
 * through the highlight alone, each as a light (trace.cpp,
 * ComputePhotonDiffuseLight). Seen straight down (eye -y, normal y), a
 * light along unit l gives the half-vector cosine^2 = (1 + l_y) / 2; the
 * photons around a point sum to the mirrored light's colour 1 (their
 * density carries the cosine c that each photon's 1 / c takes away), from
 * the mirrored light at <4, 5, 0>. So the highlight at floor point
 * (x, 0, z) is (1 + 5 / |(4 - x, 5, -z)|) / 2, about 0.89; the mean over
 * a 9 x 9 grid of the view's points must match within 2% (POV-Ray's
 * stored direction, truncated to pi/127 steps, moves it by under 1%).
 * The floor stores no photon for the splat, and a floor of specular 0
 * gets no highlight. */
static void test_highlight_photons(void **state)
{
    (void)state;
    for (int spec = 1; spec >= 0; spec--) {
        char floor[96];
        snprintf(floor, sizeof floor, "diffuse 0 specular %d roughness 0.5", spec);
        tu_world w = mirror_lit(floor);
        diag *d = diag_new();
        caustics c;
        layer(&c, w.s, w.a, 32, 32, NULL, THREADS, d);
        assert_int_equal(c.st.stored, 0);
        if (spec) assert_true(c.st.stored_highlights > 1000);
        else assert_int_equal(c.st.stored_highlights, 0);
        double got = 0.0, want = 0.0;
        for (int i = 0; i < 9; i++)
            for (int j = 0; j < 9; j++) {
                double x = -0.18 + 0.045 * i, z = -0.18 + 0.045 * j;
                accel_hit h;
                assert_true(accel_intersect(w.a, v3(x, 5, z), v3(0, -1, 0), 0.0, INFINITY, &h));
                const scene_finish *f = &h.obj->texture->finish;
                shade_light_surface s = {f, {1, 1, 1}, v3(0, 1, 0), v3(0, -1, 0), 1.0, NULL, h.p, &w.s->global};
                rgb e = caustics_highlights(&c, &h, &s, 0);
                got += e.g / 81.0;
                want += spec * 0.5 * (1.0 + 5.0 / sqrt((4.0 - x) * (4.0 - x) + 25.0 + z * z)) / 81.0;
            }
        printf("highlight-only floor, specular %d: photons' highlight %.5f, closed form %.5f (%ld photons)\n", spec, got,
               want, c.st.stored_highlights);
        if (spec) assert_true(fabs(got / want - 1.0) <= 0.02);
        else assert_true(got == 0.0);
        caustics_free(&c);
        diag_free(d);
        tu_world_free(&w);
    }
}

/* A photon is stored faded by the interior it arrives from: a box of
 * half-transparent white (rgbt 0.5, diffuse 1, ior 1) lit straight down by
 * a parallel light; each photon enters the top face (its target, not
 * stored) and meets the bottom face 1 below from inside, where it is
 * stored. POV-Ray 3.7 (photons.cpp, PhotonTrace::ComputeLightedTexture)
 * fades the photon by the hit object's interior over its way there before
 * it adds the surface photon, so with fade_distance 1, fade_power 1001 and
 * fade_color 0 the stored flux is exp(-1) of the unfaded box's (tolerance
 * 0.5%: every photon crosses the same 1 unit), with as many photons. */
static void test_stored_fade(void **state)
{
    (void)state;
    static const char *fmt =
        "#version 3.7;\n"
        "global_settings { assumed_gamma 1.0 photons { spacing 0.02 } }\n"
        "camera { orthographic location <0, 5, 0> look_at <0, 0, 0> right x*2 up z*2 }\n"
        "light_source { <0, 10, 0> color rgb 1 parallel point_at <0, 0, 0> }\n"
        "box { <-0.5, 0.5, -0.5>, <0.5, 1.5, 0.5> pigment { rgbt <1, 1, 1, 0.5> } finish { ambient 0 diffuse 1 }\n"
        "      interior { ior 1 %s } photons { target refraction on } }\n";
    double flux[2];
    long stored[2];
    for (int faded = 0; faded < 2; faded++) {
        char text[1024];
        snprintf(text, sizeof text, fmt, faded ? "fade_distance 1 fade_power 1001 fade_color rgb 0" : "");
        tu_world w = tu_world_build("test.pov", text);
        diag *d = diag_new();
        caustics c;
        layer(&c, w.s, w.a, 16, 16, NULL, THREADS, d);
        gi_caustic_stats st;
        gi_caustic_get_stats(c.layer, &st);
        flux[faded] = st.flux;
        stored[faded] = st.stored;
        caustics_free(&c);
        diag_free(d);
        tu_world_free(&w);
    }
    printf("photons stored leaving a faded box: %ld and %ld, flux %.6g faded over %.6g (ratio %.5f, exp(-1) %.5f)\n",
           stored[1], stored[0], flux[1], flux[0], flux[1] / flux[0], exp(-1.0));
    assert_true(stored[0] > 1000);
    assert_int_equal(stored[1], stored[0]);
    assert_true(fabs(flux[1] / flux[0] / exp(-1.0) - 1.0) <= 0.005);
}

/* The mirror above with a pass_through pane (rgbft <1, 0.5, 0.25, 0.6,
 * 0.2>, no ior) across the photons' way from the light to the mirror:
 * POV-Ray 3.7 (photons.cpp, built with PT_FILTER_BEFORE_TARGET) lets a
 * photon through each surface of a pass_through object before its target
 * filtered by colour x filter + transmit = <0.8, 0.5, 0.35>, at the
 * pane's two faces, so the layer must give 5 / sqrt(41) times its square
 * per channel (tolerance 2%). povray's own image of this scene (32 x 32,
 * photons on minus off) gives 0.203 and 0.099 in green and blue against
 * 0.195 and 0.096. The pane lies outside the reflected light's way and
 * the camera's view. Then the pane with an interior fading exponentially
 * to grey (fade_distance 1, fade_colour 0.5): each photon is dimmed by
 * exp(-0.5 L), L = 0.1 / c_x its way inside (c_x its direction's x
 * component, 0.61 to 0.64 here), not over its way from the light; the
 * closed form is the mean over the view's 32 x 32 points of the filter
 * squared x cos x exp(-0.5 L) (the mirrored light's cosine at the point,
 * the photon aimed at it through the mirror point). */
static void test_pass_through_filter(void **state)
{
    (void)state;
    for (int faded = 0; faded < 2; faded++) {
        char text[1200];
        snprintf(text, sizeof text, mirror_fmt, "photons { spacing 0.01 }",
                 faded ? "light_source { <-2, 5, 0> color rgb 1 }\n"
                         "box { <-1.6, 0, -3>, <-1.5, 8, 3> pigment { rgbft <1, 0.5, 0.25, 0.6, 0.2> } "
                         "interior { fade_distance 1 fade_power 1001 fade_color rgb 0.5 } photons { pass_through } }"
                       : "light_source { <-2, 5, 0> color rgb 1 }\n"
                         "box { <-1.6, 0, -3>, <-1.5, 8, 3> pigment { rgbft <1, 0.5, 0.25, 0.6, 0.2> } photons { pass_through } }",
                 "photons { target reflection on }", "");
        tu_world w = tu_world_build("test.pov", text);
        diag *d = diag_new();
        caustics c;
        layer(&c, w.s, w.a, 32, 32, NULL, THREADS, d);
        const float *img = gi_caustic_image(c.layer);
        const double f[3] = {0.8, 0.5, 0.35};
        double g = 0.0; /* mean of cos x fade over the view */
        for (int i = 0; i < 32; i++)
            for (int j = 0; j < 32; j++) {
                double x0 = -0.2 + (i + 0.5) * 0.0125, z0 = -0.2 + (j + 0.5) * 0.0125;
                double cosv = 5.0 / sqrt((4.0 - x0) * (4.0 - x0) + 25.0 + z0 * z0);
                double t = 3.0 / (4.0 - x0), dy = -5.0 * t, dz = z0 * t; /* light to the mirror point */
                double cx = 3.0 / sqrt(9.0 + dy * dy + dz * dz);
                g += cosv * (faded ? exp(-0.5 * 0.1 / cx) : 1.0) / 1024.0;
            }
        for (int k = 0; k < 3; k++) {
            double e = channel_mean(img, 32 * 32, k), want = f[k] * f[k] * g;
            printf("pass_through pane%s, channel %d: caustic layer %.5f, closed form %.5f (rel err %+.4f, tol 0.02)\n",
                   faded ? " with fade" : "", k, e, want, e / want - 1.0);
            assert_true(fabs(e / want - 1.0) <= 0.02);
        }
        caustics_free(&c);
        diag_free(d);
        tu_world_free(&w);
    }
}

/* A glass slab (glass.inc's F_Glass6: fresnel reflection with
 * conserve_energy; exponential fade to rgb <0.35, 0.65, 0.85> over 2) of
 * thickness 1 and ior 1 above a floor, a point light of colour 1 above.
 * POV-Ray 3.7's photon tracer (photons.cpp) passes a photon through each
 * surface with the filter colour times 1 - reflectivity under
 * conserve_energy; with ior 1 the fresnel term is 0, so reflectivity is
 * reflection_min = 0.1 at both faces, and the fade over the thickness is
 * a = exp(-(1 - c) / 2) per channel. A photon reflected back inside ends
 * there: POV-Ray's photon ray weight (0.9 through the top, times 0.1^2 for
 * each reflection, photons.cpp) is 0.9 x 0.01 x 0.01 when it turns down
 * again, under adc_bailout 1/255; so E = 0.81 a (tolerance 3%). povray's
 * own image under such a slab is 0.850 of its image without
 * conserve_energy, 5% above this closed form's 0.81.
 * Then a slab of constant reflection 0.25 (ior 1, no fade): E = 0.75^2;
 * the photon reflected twice inside (weight 0.75 x 0.25^2 x 0.25^2 x 0.75
 * = 0.0022 < 1/255) ends as in POV-Ray. Ending photons on their flux
 * (0.75 x 0.25 x 0.25 x 0.75 = 0.035) instead adds the series
 * 1 / (1 - 0.25^2): E = 0.600, 6.7% above (tolerance 2%).
 * Then that slab 0.002 thick inside a sphere of radius 1e6 (a sky dome):
 * the same E = 0.75^2. The photons' surface offsets follow the median
 * object size, as the shader's do; offsets of 1e-6 of the scene's extent
 * (3.5 here) carried each photon past the slab's lower face, and it never
 * left the slab (a drinking glass's wall in `balcony` so dropped its
 * caustic). */
/* slab_case's layer (16 x 16) under the box from y0 to y1 (texture and
 * interior items `box`, further objects `extra`): *c, to free with
 * caustics_free and tu_world_free(w). */
/* finish { diffuse A, B } receives photons from behind (POV-Ray's photon
 * gather shades each photon as a light, and a light behind the surface
 * lights it through diffuse_back): a glass sphere's caustic on a plane of
 * diffuse 0.6, 0.3, the camera below the plane. Every G-buffer pixel on the
 * plane has back = B / A = 0.5; its splatted value equals the sum over the
 * photons at its point with the normal turned down and back 0.5. POV-Ray
 * divides a photon from behind by 0.1 (its cosine against the normal
 * turned to the viewer is negative, and the clamp makes it 0.1), not by
 * its cosine c, so each photon weighs 0.5 x c / 0.1 from below against
 * c / c seen from above: the sum from below is 5 x the sum seen from above
 * at brilliance 2 (c^2 / c; every photon here arrives at c > 0.1),
 * relative 1e-5. Without B the underside gets none. */
static void test_diffuse_back_photons(void **state)
{
    (void)state;
    for (int k = 0; k < 2; k++) {
        char text[1024];
        snprintf(text, sizeof text, "global_settings { photons { spacing 0.02 } }\n"
                 "camera { location <0, -3, -0.5> look_at <0, 0, 0> angle 60 }\n"
                 "light_source { <0, 5, 0> rgb 1 }\n"
                 "sphere { <0, 1, 0>, 0.5 pigment { rgbf 1 } interior { ior 1.5 } photons { target refraction on } }\n"
                 "plane { y, 0 pigment { rgb 1 } finish { diffuse 0.6%s } }\n", k ? ", 0.3" : "");
        tu_world w = tu_world_build("test.pov", text);
        diag *d = diag_new();
        caustics c;
        layer(&c, w.s, w.a, 32, 32, NULL, THREADS, d);
        long n;
        const gi_caus_photon *ph = gi_caustic_photons(c.layer, &n);
        const gi_caus_pixel *gb = gi_caustic_gbuffer(c.layer);
        const float *img = gi_caustic_image(c.layer);
        int on = 0, lit = 0;
        double worst = 0.0, under = 0.0, above = 0.0;
        for (int i = 0; i < 32 * 32; i++) {
            if (!(gb[i].valid > 0.0f) || fabs(gb[i].s[1]) > 1e-4f) continue;
            on++;
            assert_true(gb[i].n[1] < 0.0f);
            assert_true(fabsf(gb[i].back - (k ? 0.5f : 0.0f)) < 1e-6f);
            float up[3] = {-gb[i].n[0], -gb[i].n[1], -gb[i].n[2]}, e[3], t[3], t2[3];
            assert_true(gb[i].brilliance == 1.0f);
            gi_c_caustic_at(ph, NULL, (int)n, gb[i].s, up, 1.0f, 0.0f, t);
            gi_c_caustic_at(ph, NULL, (int)n, gb[i].s, up, 2.0f, 0.0f, t2);
            gi_c_caustic_at(ph, NULL, (int)n, gb[i].s, gb[i].n, 1.0f, gb[i].back, e);
            lit += t[1] > 0.0f;
            for (int c3 = 0; c3 < 3; c3++) {
                double want = (k ? 5.0 : 0.0) * t2[c3];
                worst = fmax(worst, fabs(e[c3] - want) / fmax(t[c3], 1e-30));
                worst = fmax(worst, fabs(img[4 * i + c3] - e[c3]) / fmax(t[c3], 1e-30));
            }
            under += img[4 * i + 1];
            above += t[1];
        }
        printf("diffuse 0.6%s, seen from below: %d pixels on the plane, %d under the caustic; splatted %.5f, "
               "from above %.5f (ratio %.4f; worst pixel off by %.1e)\n",
               k ? ", 0.3" : "", on, lit, under, above, above > 0.0 ? under / above : 0.0, worst);
        assert_true(on > 200 && lit > 20);
        assert_true(worst < 1e-5);
        assert_int_equal(diag_count(d), 0);
        caustics_free(&c);
        diag_free(d);
        tu_world_free(&w);
    }
}

static void slab_layer(double y0, double y1, const char *extra, const char *box, tu_world *w, caustics *c)
{
    char text[1400];
    snprintf(text, sizeof text,
             "#version 3.7;\n"
             "global_settings { assumed_gamma 1.0 max_trace_level 25 photons { spacing 0.02 } }\n"
             "camera { orthographic location <0, 5, 0> look_at <0, 0, 0> sky z right x*2 up z*2 }\n"
             "light_source { <0, 10, 0> color rgb 1 photons { reflection on refraction on } }\n"
             "box { <-3, %g, -3>, <3, %g, 3> pigment { rgbf 1 } %s "
             "photons { target reflection on refraction on collect off } }\n"
             "plane { y, 0 pigment { rgb 1 } finish { ambient 0 diffuse 1 } }\n%s\n",
             y0, y1, box, extra);
    *w = tu_world_build("test.pov", text);
    diag *d = diag_new();
    layer(c, w->s, w->a, 16, 16, NULL, THREADS, d);
    diag_free(d);
}

/* The layer's mean irradiance (green) under a slab. */
static double slab_mean(double y0, double y1, const char *extra, const char *box)
{
    tu_world w;
    caustics c;
    slab_layer(y0, y1, extra, box, &w, &c);
    double e = channel_mean(gi_caustic_image(c.layer), 256, 1);
    caustics_free(&c);
    tu_world_free(&w);
    return e;
}

/* A glass slab (ior 1.5, reflection { 0.1, 1.0 fresnel on },
 * conserve_energy) lit from straight above, with and without a hollow
 * sphere around the whole scene. POV-Ray starts each photon inside the
 * objects that hold the light (photonshootingtask.cpp) and takes the
 * fresnel reflectivity's relative ior from the photon's interior list
 * (ComputeRelativeIOR): leaving the slab, the innermost of two
 * containers, the ratio is 1, the fresnel term 0 and the reflectivity
 * reflection_min, 0.1, where without the sphere it is 0.1 + 0.9 x 0.04
 * (the fresnel term of ior 1.5 at normal incidence). The light through
 * the slab's exit face so grows by 0.9 / 0.864 = 1.04167 in the room;
 * the entry face, the beam's narrowing and the faded reflections inside
 * (ended by adc_bailout, as in POV-Ray) are the same in both, so the
 * layer's ratio must be that (tolerance 0.5%; photons that start with no
 * list give 1; docs/caustics.md, Transport, compares glassthing's room
 * with povray's image). */
/* The caustics' light in particle GI's bounces (POV-Ray's radiosity rays
 * see photons). A point light above a clear slab (ior 1, transmit 1, a
 * photon target) over a white floor; a wall standing on the floor under
 * the slab faces away from the light, so it is lit only by the floor. The
 * camera sees the wall alone. The slab casts a full shadow (photons on)
 * and its photons carry the light through it, unchanged: the wall must
 * look as in the same scene without slab and photons, within 3% (the
 * photon volumes' density estimate), with particles (recursion_limit 2)
 * and with the final gather alone (recursion_limit 1). Without the
 * photons' light at the particles, or at the gather's hits, the wall is
 * black. */
static const char *caustic_bounce_fmt =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1 radiosity { recursion_limit %d } %s }\n"
    "camera { location <0, 1, 0> look_at <2, 1, 0> angle 40 }\n"
    "light_source { <3, 10, 0> color rgb 1 }\n"
    "box { <-2, -0.1, -2>, <3.5, 0, 2> pigment { rgb 1 } finish { ambient 0 diffuse 0.8 } }\n"
    "box { <2, 0, -2>, <2.1, 1.9, 2> pigment { rgb 1 } finish { ambient 0 diffuse 0.8 } }\n"
    "%s\n";

enum { GI_W = 32, GI_H = 24 };

/* Mean of partray's default particle render of w (GI_W x GI_H, the C
 * build); *caustic_photons: the caustic layer's stored photons. */
static double particle_mean_of(const tu_world *w, long *caustic_photons)
{
    render_gi_opts o;
    memset(&o, 0, sizeof o);
    o.mode = GI_PARTICLE;
    o.width = GI_W;
    o.height = GI_H;
    o.threads = THREADS;
    o.seed = 1;
    o.quality = 9;
    o.cl_device = "c";
    framebuffer *fb = fb_new(o.width, o.height);
    render_gi_result r;
    memset(&r, 0, sizeof r);
    assert_int_equal(render_gi(w->s, w->a, &o, fb, &r, w->d), PT_OK);
    *caustic_photons = r.caus.st.stored;
    double m = fb_mean(fb, -1);
    fb_free(fb);
    return m;
}

/* Mean of the path tracer's render of w (GI_W x GI_H, spp samples). */
static double path_mean_of(const tu_world *w, int spp)
{
    pm_path_settings ps;
    pm_path_default_settings(&ps);
    ps.c.width = GI_W;
    ps.c.height = GI_H;
    ps.c.threads = THREADS;
    ps.c.spp = spp;
    ps.c.seed = 3;
    framebuffer *fb = fb_new(GI_W, GI_H);
    pm_stats st;
    assert_int_equal(pm_path_render(w->s, w->a, &ps, fb, &st, NULL), PT_OK);
    double m = fb_mean(fb, -1);
    fb_free(fb);
    return m;
}

/* particle_mean_of the caustic bounce scene. */
static double particle_mean(int rl, const char *photons, const char *slab, long *caustic_photons)
{
    char text[2048];
    snprintf(text, sizeof text, caustic_bounce_fmt, rl, photons, slab);
    tu_world w = tu_world_build("test.pov", text);
    double m = particle_mean_of(&w, caustic_photons);
    tu_world_free(&w);
    return m;
}

static void test_caustic_bounce(void **state)
{
    (void)state;
    /* recursion_limit 2: the particles carry it; 1: no particles, the
     * final gather's hits take it */
    for (int rl = 2; rl >= 1; rl--) {
        long n0 = 0, n1 = 0;
        double open = particle_mean(rl, "", "", &n0);
        double slab = particle_mean(rl, "photons { count 400000 }",
                                    "box { <-2, 2, -2>, <3.5, 2.1, 2> pigment { rgbt <1, 1, 1, 1> } "
                                    "finish { ambient 0 diffuse 0 } interior { ior 1 } photons { target refraction on } }",
                                    &n1);
        printf("recursion_limit %d: wall lit by a floor that photons through a slab light: %.5f, without the slab %.5f "
               "(rel err %+.4f, tol 0.03; %ld photons stored)\n",
               rl, slab, open, slab / open - 1.0, n1);
        assert_true(n0 == 0 && n1 > 0);
        assert_true(open > 0.01);
        assert_true(fabs(slab / open - 1.0) <= 0.03);
    }
}

/* POV-Ray's filtered shadows in particle GI (its radiosity sees them): a
 * white room lit through a window closed by a transparent pane (transmit
 * 0.7, no photons), the camera inside. partray's default render within 3%
 * of the path tracer (1024 spp, which takes filtered shadows too), with
 * particles (recursion_limit 2) and with the final gather alone (1). With
 * the pane shadowing fully the room is nearly black. */
static const char *pane_fmt =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1 radiosity { recursion_limit %d } }\n"
    "camera { location <0, 1, -0.9> look_at <0, 1.2, 1> angle 90 }\n"
    "light_source { <6, 5, 0.5> color rgb 1 }\n"
    "difference { box { <-1.1, -0.1, -1.1>, <1.1, 2.1, 1.1> } box { <-1, 0, -1>, <1, 2, 1> }\n"
    "  box { <0.9, 0.5, -0.5>, <1.2, 1.5, 0.5> } pigment { rgb 0.9 } finish { ambient 0 diffuse 1 } }\n"
    "box { <1.02, 0.45, -0.55>, <1.05, 1.55, 0.55> pigment { rgbt <1, 1, 1, 0.7> }\n"
    "  finish { ambient 0 diffuse 0.1 } interior { ior 1.5 } }\n";

static void test_filtered_shadow_gi(void **state)
{
    (void)state;
    for (int rl = 2; rl >= 1; rl--) {
        char text[2048];
        snprintf(text, sizeof text, pane_fmt, rl);
        tu_world w = tu_world_build("test.pov", text);
        long nc = 0;
        double mg = particle_mean_of(&w, &nc), mp = path_mean_of(&w, 1024);
        printf("recursion_limit %d: room lit through a transparent pane: particle %.5f, path %.5f (rel err %+.4f, "
               "tol 0.03)\n",
               rl, mg, mp, mg / mp - 1.0);
        assert_true(mp > 0.0);
        assert_true(fabs(mg / mp - 1.0) <= 0.03);
        tu_world_free(&w);
    }
}

static void test_photons_in_room(void **state)
{
    (void)state;
    const char *glass = "finish { ambient 0 diffuse 0 reflection { 0.1, 1.0 fresnel on } conserve_energy } "
                        "interior { ior 1.5 }";
    double open = slab_mean(0.5, 1.5, "", glass);
    double room = slab_mean(0.5, 1.5, "sphere { 0, 100 hollow pigment { rgb 1 } finish { ambient 0 diffuse 0 } }", glass);
    double want = 0.9 / 0.864;
    printf("slab in a room: caustic layer %.5f / %.5f = %.5f, closed form %.5f (rel err %+.4f, tol 0.005)\n", room, open,
           room / open, want, room / open / want - 1.0);
    assert_true(fabs(room / open / want - 1.0) <= 0.005);
}

static void slab_case(double y0, double y1, const char *extra, const char *box, const double want[3], double tol)
{
    tu_world w;
    caustics c;
    slab_layer(y0, y1, extra, box, &w, &c);
    const float *img = gi_caustic_image(c.layer);
    for (int k = 0; k < 3; k++) {
        double e = channel_mean(img, 256, k);
        printf("slab channel %d: caustic layer %.4f, closed form %.4f (rel err %+.4f, tol %.2f)\n", k, e, want[k],
               e / want[k] - 1.0, tol);
        assert_true(fabs(e / want[k] - 1.0) <= tol);
    }
    caustics_free(&c);
    tu_world_free(&w);
}

static void test_slab_transmission(void **state)
{
    (void)state;
    const double col[3] = {0.35, 0.65, 0.85};
    double fresnel[3], flat[3] = {0.5625, 0.5625, 0.5625};
    for (int k = 0; k < 3; k++) fresnel[k] = 0.81 * exp(-(1.0 - col[k]) / 2.0);
    slab_case(0.5, 1.5, "", "finish { specular 0.6 roughness 0.002 ambient 0 diffuse 0.1 brilliance 5 "
              "reflection { 0.1, 1.0 fresnel on } conserve_energy } "
              "interior { ior 1 fade_distance 2 fade_power 1001 fade_color rgb <0.35, 0.65, 0.85> }",
              fresnel, 0.03);
    const char *flat_box = "finish { ambient 0 diffuse 0 reflection { 0.25 } conserve_energy } interior { ior 1 }";
    slab_case(0.5, 1.5, "", flat_box, flat, 0.02);
    slab_case(1.0, 1.002, "sphere { 0, 1e6 hollow pigment { rgb 1 } finish { ambient 0 diffuse 0 } }", flat_box, flat, 0.02);
}

/* pmfg's caustic map under the same rule: the pass_through pane scene
 * with the light made a spotlight at the mirror (full inside 10 degrees,
 * none beyond 12; the viewed floor lies 17 degrees off its axis), so
 * every photon crosses the pane before its first hit and the floor sees
 * only the mirrored light and its own bounces of it. With the pane its
 * image is the image without it times the pane's filter squared per
 * channel, <0.64, 0.25, 0.1225> (tolerance 3%: the images' photon noise
 * and the global map's bounces are the same in both up to that factor).
 * Passing the pane unfiltered gives 1. Without the pane the floor is the
 * mirrored light, 5 / sqrt((4 - x)^2 + 25 + z^2) averaged over the view
 * (0.7807), as POV-Ray's photons carry it: their power goes with their
 * whole path length squared (tolerance 3%; with the first hit's distance
 * instead, (4.80 / 6.40)^2 of it, 0.445). */
/* pmfg's image's mean per channel into m[3]. */
static void pmfg_mean(const char *pane, double m[3])
{
    char text[1400];
    snprintf(text, sizeof text, mirror_fmt, "photons { spacing 0.01 }", pane, "photons { target reflection on }", "");
    tu_world w = tu_world_build("test.pov", text);
    pm_fg_settings s;
    pm_fg_default_settings(&s);
    s.c.width = s.c.height = 16;
    s.c.threads = THREADS;
    s.c.spp = 1;
    s.c.seed = 7;
    s.fg_rays = 16;
    s.photons = 100000;
    framebuffer *fb = fb_new(16, 16);
    pm_stats st;
    assert_int_equal(pm_fg_render(w.s, w.a, &s, fb, &st, NULL), PT_OK);
    for (int k = 0; k < 3; k++) {
        m[k] = 0.0;
        for (int i = 0; i < 256; i++) m[k] += fb->rgb[3 * i + k] / 256.0;
    }
    fb_free(fb);
    tu_world_free(&w);
}

static void test_pmfg_pass_through_filter(void **state)
{
    (void)state;
    const char *spot = "light_source { <-2, 5, 0> color rgb 1 spotlight point_at <1, 1.25, 0> radius 10 falloff 12 }\n";
    char with[600];
    snprintf(with, sizeof with, "%s%s", spot,
             "box { <-1.6, 0, -3>, <-1.5, 8, 3> pigment { rgbft <1, 0.5, 0.25, 0.6, 0.2> } photons { pass_through } }");
    const double f[3] = {0.8, 0.5, 0.35};
    double m0[3], m1[3];
    pmfg_mean(spot, m0);
    pmfg_mean(with, m1);
    double g = 0.0;
    for (int i = 0; i < 16; i++)
        for (int j = 0; j < 16; j++) {
            double x0 = -0.2 + (i + 0.5) * 0.025, z0 = -0.2 + (j + 0.5) * 0.025;
            g += 5.0 / sqrt((4.0 - x0) * (4.0 - x0) + 25.0 + z0 * z0) / 256.0;
        }
    printf("pmfg, mirrored spotlight: %.5f, closed form %.5f (rel err %+.4f, tol 0.03)\n", m0[1], g, m0[1] / g - 1.0);
    assert_true(fabs(m0[1] / g - 1.0) <= 0.03);
    for (int k = 0; k < 3; k++) {
        double e0 = m0[k], e1 = m1[k], want = f[k] * f[k];
        printf("pmfg, pass_through pane, channel %d: %.5f / %.5f = %.5f, closed form %.5f (rel err %+.4f, tol 0.03)\n", k,
               e1, e0, e1 / e0, want, e1 / e0 / want - 1.0);
        assert_true(e0 > 0.0 && fabs(e1 / e0 / want - 1.0) <= 0.03);
    }
}

static const char *ball =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 max_trace_level 10 photons { spacing 0.01 } }\n"
    "camera { location <0, 3, -4> look_at <0, 0.3, 0> angle 40 }\n"
    "light_source { <1, 6, -1> color rgb 1 }\n"
    "sphere { <0, 0.8, 0>, 0.5 pigment { rgbf <1, 0.9, 0.8, 0.9> } finish { ambient 0 diffuse 0.05 reflection 0.1 } "
    "interior { ior 1.5 } photons { target refraction on reflection on } }\n"
    "box { <0.7, 0, 0.5>, <1.2, 1, 1> pigment { rgb 0.5 } finish { reflection 0.8 } photons { target reflection on } }\n"
    "plane { y, 0 pigment { rgb 1 } finish { ambient 0 diffuse 0.8 } }\n";

/* The splat (tiles, kernel) gives at every G-buffer pixel the sum of every
 * photon volume there, computed brute force over all photons. */
static void test_splat_equals_sum(void **state)
{
    (void)state;
    tu_world w = tu_world_build("test.pov", ball);
    scene *sc = w.s;
    accel *a = w.a;
    diag *d = diag_new();
    caustics c;
    layer(&c, sc, a, 64, 48, NULL, THREADS, d);
    long n;
    const gi_caus_photon *ph = gi_caustic_photons(c.layer, &n);
    const gi_caus_pixel *gb = gi_caustic_gbuffer(c.layer);
    const float *img = gi_caustic_image(c.layer);
    double maxe = 0.0, maxd = 0.0;
    int lit = 0;
    for (int i = 0; i < 64 * 48; i++) {
        if (!(gb[i].valid > 0.0f)) continue;
        float e[3];
        gi_c_caustic_at(ph, NULL, (int)n, gb[i].s, gb[i].n, gb[i].brilliance, gb[i].back, e);
        for (int k = 0; k < 3; k++) {
            maxe = fmax(maxe, e[k]);
            maxd = fmax(maxd, fabs(e[k] - img[4 * i + k]));
        }
        lit += e[1] > 0.0f;
    }
    printf("splat vs brute-force sum: %ld photons, %d pixels lit, largest value %.5f, largest difference %.3g\n", n, lit,
           maxe, maxd);
    assert_true(n > 1000 && lit > 50);
    assert_true(maxd <= 1e-5 * maxe + 1e-7);
    caustics_free(&c);
    diag_free(d);
    tu_world_free(&w);
}

/* OpenCL (PoCL here) and the C build of gi_k_caustic_splat, and 1 against
 * 2 threads: the same photons, the same image within float rounding. */
static void test_devices_and_threads(void **state)
{
    (void)state;
    tu_world w = tu_world_build("test.pov", ball);
    scene *sc = w.s;
    accel *a = w.a;
    diag *d = diag_new();
    caustics c1, c2;
    layer(&c1, sc, a, 64, 48, "c", 1, d);
    layer(&c2, sc, a, 64, 48, NULL, THREADS, d);
    long n1, n2;
    const gi_caus_photon *p1 = gi_caustic_photons(c1.layer, &n1), *p2 = gi_caustic_photons(c2.layer, &n2);
    assert_int_equal(n1, n2);
    assert_memory_equal(p1, p2, sizeof *p1 * (size_t)n1);
    const float *i1 = gi_caustic_image(c1.layer), *i2 = gi_caustic_image(c2.layer);
    double maxe = 0.0, maxd = 0.0;
    for (int i = 0; i < 64 * 48 * 4; i++) {
        maxe = fmax(maxe, i1[i]);
        maxd = fmax(maxd, fabs(i1[i] - i2[i]));
    }
    printf("C build, 1 thread vs %s, %d threads: %ld photons identical, image largest difference %.3g of %.4f\n",
           c2.st.device, THREADS, n1, maxd, maxe);
    assert_true(maxd <= 1e-5 * maxe);
    caustics_free(&c1);
    caustics_free(&c2);
    diag_free(d);
    tu_world_free(&w);
}


/* gi_caustic_media_visit's callback: the photons' light summed. */
static void media_sum(void *ctx, vec3 w, rgb e)
{
    (void)w;
    rgb *s = ctx;
    s->r += e.r;
    s->g += e.g;
    s->b += e.b;
}

/* Media photons through a box of scattering media (scattering 0.5 grey,
 * extinction 0, isotropic), the box a photon target lit along x by a point
 * light of colour 1 at distance 100, global photons { media 100 }. A
 * POV-Ray light does not fall off, so the box is lit by L = 1 throughout:
 *  - the media photons summed at points inside (away from the walls by
 *    more than a photon sphere's radius) give L = 1. Tolerance 4%: POV-Ray's
 *    step rule weighs a photon t along its segment by (D + t) / D (here at
 *    most +1.5%), and the integer count of steps per segment loses up to
 *    one step of the 2 units (-2.5% at spacing 0.05);
 *  - the radiance of a view ray across the box (length 4, along z, through
 *    its centre) is scattering x L x length = 2 (POV-Ray's media
 *    in-scattering, no 1/(4 pi)), the box's photon shadow keeping the
 *    light's direct part out (POV-Ray's rule for photon targets); the
 *    photons' spheres reach past the two walls the ray crosses, so within
 *    a radius of each the sum falls towards half (a loss of under a
 *    radius's worth, 0.15 of the 4 units at most): tolerance 5%. */
static const char *media_box_fmt =
    "#version 3.7;\n"
    "global_settings { %s }\n"
    "camera { location <0, 0, -10> look_at 0 }\n"
    "light_source { <-101, 0, 0> color rgb 1 }\n"
    "box { <-1, -1, -2>, <1, 1, 2> hollow pigment { rgbf 1 } "
    "interior { media { scattering { 1, rgb 0.5 extinction 0 } method 3 intervals 1 samples 4 } } "
    "photons { target refraction on } }\n";

static void test_media_photons(void **state)
{
    (void)state;
    char text[1024];
    snprintf(text, sizeof text, media_box_fmt, "photons { spacing 0.05 media 100 }");
    tu_world w = tu_world_build("test.pov", text);
    diag *d = diag_new();
    caustics c;
    layer(&c, w.s, w.a, 8, 8, NULL, THREADS, d);
    long n = 0;
    assert_non_null(gi_caustic_media_photons(c.layer, &n));
    assert_int_equal(n, c.st.stored_media);
    double sum = 0.0, lo = 1e9, hi = 0.0;
    int np = 0;
    for (int i = 0; i < 5; i++)
        for (int j = 0; j < 5; j++)
            for (int k = 0; k < 5; k++) {
                rgb e = {0, 0, 0};
                vec3 p = v3(-0.5 + 0.25 * i, -0.5 + 0.25 * j, -1.5 + 0.75 * k);
                gi_caustic_media_visit(c.layer, p, media_sum, &e);
                sum += e.g;
                lo = fmin(lo, e.g);
                hi = fmax(hi, e.g);
                np++;
            }
    double mean = sum / np;
    printf("media photons: %ld stored (sphere radius median %.4f); light at 125 inside points: mean %.5f (%.5f..%.5f), "
           "closed form 1 (rel err %+.4f, tol 0.04)\n",
           n, c.st.r_media_median, mean, lo, hi, mean - 1.0);
    assert_true(fabs(mean - 1.0) <= 0.04);

    shade_settings ss;
    shade_default_settings(&ss);
    caustics_attach(&c, &ss);
    assert_non_null(ss.media_photons);
    double ray = 0.0;
    for (int i = 0; i < 16; i++) {
        rng r;
        rng_seed(&r, 7, (uint64_t)i);
        rgb col = shade_trace(w.s, w.a, &ss, v3(0.02 * (i - 8), 0.02 * (i % 4), -10), v3(0, 0, 1), 0, &r);
        ray += col.g / 16.0;
    }
    printf("media photons: radiance across the box %.5f, closed form 2 (rel err %+.4f, tol 0.05)\n", ray, ray / 2.0 - 1.0);
    assert_true(fabs(ray / 2.0 - 1.0) <= 0.05);
    caustics_free(&c);
    diag_free(d);
    tu_world_free(&w);
}

/* Photon settings the layer does not model are counted and warned about,
 * each once; a scene without any target warns that nothing shoots. */
static void test_not_modelled(void **state)
{
    (void)state;
    tu_world w = tu_world_build("test.pov", "#version 3.7;\n"
                      "global_settings { photons { count 2000 gather 10, 50 radius 0.1 media 20 autostop 0.2 "
                      "expand_thresholds 0.1, 10 save_file \"x.ph\" } }\n"
                      "camera { location <0, 3, -4> look_at 0 }\n"
                      "light_source { <0, 5, 0> rgb 1 }\n"
                      "sphere { <0, 1, 0>, 0.5 pigment { rgbf 1 } interior { ior 1.5 dispersion 1.1 } "
                      "photons { target refraction on } }\n"
                      "plane { y, 0 pigment { rgb 1 } }\n");
    scene *sc = w.s;
    accel *a = w.a;
    diag *d = diag_new();
    caustics c;
    layer(&c, sc, a, 16, 12, NULL, THREADS, d);
    caustics_not_modelled *nm = &c.nm;
    assert_true(nm->gather && nm->radius && nm->autostop && nm->expand_thresholds && nm->save_file &&
                nm->dispersion && !nm->load_file);
    int warned = diag_count(d);
    printf("not modelled: %d warnings:\n", warned);
    for (int i = 0; i < warned; i++) {
        char *m = diag_format(diag_get(d, i));
        printf("  %s\n", m ? m : "?");
        free(m);
    }
    assert_int_equal(warned, 6); /* media 20 is modelled: no warning */
    /* count 2000: POV-Ray's estimate over the one light-target pair sets
     * the spacing, and about that many photons are shot at the target */
    printf("count 2000: spacing %.5f, %ld shot\n", c.st.spacing, c.st.emitted);
    assert_true(c.st.spacing > 0.0);
    caustics_free(&c);
    /* again: the same warnings are not repeated into the same context */
    layer(&c, sc, a, 16, 12, NULL, THREADS, d);
    assert_int_equal(diag_count(d), warned);
    caustics_free(&c);
    diag_free(d);
    tu_world_free(&w);

    /* a diffuse_back receiver seen from behind: modelled, no warning
     * (test_diffuse_back_photons) */
    w = tu_world_build("test.pov", "global_settings { photons { spacing 0.1 } }\n"
               "light_source { <0, 5, 0> rgb 1 }\n"
               "sphere { <0, 1, 0>, 0.5 pigment { rgbf 1 } interior { ior 1.5 } photons { target refraction on } }\n"
               "plane { y, 0 pigment { rgb 1 } finish { diffuse 0.6, 0.3 } }\n");
    d = diag_new();
    layer(&c, w.s, w.a, 8, 8, NULL, THREADS, d);
    assert_int_equal(diag_count(d), 0);
    caustics_free(&c);
    diag_free(d);
    tu_world_free(&w);

    w = tu_world_build("test.pov", "global_settings { photons { spacing 0.1 } }\n"
               "light_source { <0, 5, 0> rgb 1 }\n"
               "sphere { <0, 1, 0>, 0.5 pigment { rgbf 1 } interior { ior 1.5 } }\n");
    sc = w.s;
    a = w.a;
    d = diag_new();
    assert_int_equal(caustics_build(&c, sc, a, 8, 8, THREADS, 1, NULL, 0, 0.0, 0, NULL, d), PT_OK);
    assert_null(c.layer);
    assert_int_equal(diag_count(d), 1);
    caustics_free(&c);
    diag_free(d);
    tu_world_free(&w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mirror_closed_form),
        cmocka_unit_test(test_mirror_brilliance),
        cmocka_unit_test(test_diffuse_back_photons),
        cmocka_unit_test(test_mirror_roulette),
        cmocka_unit_test(test_gather_minimum),
        cmocka_unit_test(test_highlight_photons),
        cmocka_unit_test(test_photons_in_room),
        cmocka_unit_test(test_pass_through_filter),
        cmocka_unit_test(test_stored_fade),
        cmocka_unit_test(test_path_mirror_closed_form),
        cmocka_unit_test(test_slab_transmission),
        cmocka_unit_test(test_pmfg_pass_through_filter),
        cmocka_unit_test(test_splat_equals_sum),
        cmocka_unit_test(test_devices_and_threads),
        cmocka_unit_test(test_not_modelled),
        cmocka_unit_test(test_media_photons),
        cmocka_unit_test(test_focus_vs_path),
        cmocka_unit_test(test_caustic_bounce),
        cmocka_unit_test(test_filtered_shadow_gi),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
