/* test_gi.c - particle-space GI (gi/gi_particle.h, seed 000).
 *
 *  - energy: one scattering bounce in a closed box moves exactly rho times
 *    the flux that left the lit particles (relative 1e-5, float sums); with
 *    uniform rho every later bounce carries rho times the one before (1e-4);
 *    the same for the FULL scattering mode over 1..3 bounces.
 *  - integrating sphere (a furnace with a closed form): inside a Lambertian
 *    sphere the indirect irradiance is the same everywhere, whatever lights
 *    it, E_ind = F_d / A * sum_{k=1}^{n_b+1} rho^k (form factor dA/A between
 *    any two points of a sphere), with the direct flux of a POV-Ray point
 *    light of colour C at distance a from the centre (no distance falloff)
 *    F_d = pi C (4 pi R^2 - 4 pi a^2 / 3) (Gauss: the flux of the unit radial
 *    field through the sphere is the integral of 2/r over the ball). The
 *    RMS relative error of the hook's value over 200 points is printed for
 *    1K, 4K, 16K particles: mean within 0.5% and RMS below 1% at each.
 *  - a cylinder and a prism (radiance particles on their grids) get
 *    indirect light close to the floor's.
 *  - a sphere written as a one-component blob or an isosurface gets its
 *    particles from accel_surface's Crofton lines: their total area is
 *    4 pi r^2 within 1%, the GI render's mean that of the sphere within 2%.
 *  - direct light of the particles equals shade.c's Whitted direct term at
 *    the same point (spotlight with fade; relative 1e-3 plus 1e-6: the
 *    kernels work in float and the falloff tail cancels digits).
 *  - determinism: two builds with the same seed give bit-identical particle
 *    radiance and hook values; the OpenCL device and the C build of the
 *    kernels agree within 1e-4 relative.
 *  - cancellation: a cancelled relight (colour change: before the kernels;
 *    moved light: in the visibility pass) leaves the particles' radiance
 *    bit-identical; the next relight equals a fresh build with the new light.
 *  - OpenCL errors: a kernel source that does not compile gives
 *    PT_ERR_DEVICE with the build log in the diagnostics; an unknown device
 *    name gives PT_ERR_DEVICE too. (Skipped when no OpenCL platform exists.)
 *  - fine mesh: a wall lit only indirectly, as 80 x 40 cells a face
 *    (triangles smaller than the particle spacing), renders like the same
 *    wall as 2 triangles a face: mean within 5%, every pixel >= 50% of the
 *    coarse one (radiance particles on triangles without particles of
 *    their own must still get lists, or the fine wall shows dark spots).
 *  - light in a ceiling's plane (cornell.pov's): every particle on a block
 *    top below gets E/pi = cos(theta) of the point light within 1e-3
 *    (the ceiling the light sits in must not occlude its shadow rays).
 *  - shared radiance particles: an L-shaped mesh of two grids gets one
 *    radiance particle per grid vertex and side (and per cell-edge midpoint
 *    at k = 2), two along the right-angle crease; the two triangles on
 *    either side of a shared edge give the same value at its midpoint.
 *  - thin slab: the top of a closed mesh2 slab thinner than the list radius
 *    gets the indirect light of the top alone within 10% (its lists must
 *    not take the bottom face's dark inside).
 *  - no NaN/Inf from the hook, stats consistent. */
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
#include "test_gi.h"
#include "test_util.h"

void tg_load(fixture *f, const char *text)
{
    f->d = diag_new();
    sdl_options o;
    sdl_default_options(&o);
    pt_status st = sdl_parse_string("test.pov", text, &o, &f->sc, f->d);
    if (st != PT_OK) {
        for (int i = 0; i < diag_count(f->d); i++) {
            char *m = diag_format(diag_get(f->d, i));
            fprintf(stderr, "%s\n", m);
            free(m);
        }
    }
    assert_int_equal(st, PT_OK);
    f->a = accel_build(f->sc, 2, f->d, &st);
    assert_non_null(f->a);
}

void tg_unload(fixture *f)
{
    accel_free(f->a);
    scene_free(f->sc);
    diag_free(f->d);
}

static void print_diag(diag *d)
{
    for (int i = 0; i < diag_count(d); i++) {
        char *m = diag_format(diag_get(d, i));
        fprintf(stderr, "  diag: %s\n", m);
        free(m);
    }
}

/* Is an OpenCL device there at all? */
static int have_opencl(void)
{
    if (!gi_dev_opencl_built()) return 0;
    diag *d = diag_new();
    pt_status st;
    gi_dev_options o = {NULL, NULL, 1};
    gi_dev *dv = gi_dev_open(&o, d, &st);
    gi_dev_free(dv);
    diag_free(d);
    return st == PT_OK;
}

const char *const tg_device_c = "c";
/* The first OpenCL device: "auto" takes the C build below
 * GI_CL_AUTO_MIN_PARTICLES, which these scenes are. */
static const char *const tg_device_cl = "0:0";

static int g_scatter = GI_PARTICLE_SCATTER_WALK;

/* Build the particles of f's scene with settings s and light them. */
gi_particle *tg_build_with(fixture *f, const gi_particle_settings *s)
{
    pt_status st;
    gi_particle *gp = gi_particle_build(f->sc, f->a, s, NULL, f->d, &st);
    if (!gp) print_diag(f->d);
    assert_non_null(gp);
    assert_int_equal(gi_particle_light(gp, f->d), PT_OK);
    return gp;
}

static gi_particle *build(fixture *f, long count, int nb, const char *device, uint64_t seed)
{
    gi_particle_settings s;
    gi_particle_default_settings(&s);
    s.scatter = g_scatter;
    s.count = count;
    s.bounces = nb;
    s.threads = 2;
    s.seed = seed;
    s.cl_device = device;
    return tg_build_with(f, &s);
}

/* A closed cube (mesh, 12 triangles) of uniform reflectance with a point
 * light inside. */
const char *const tg_cube_scene =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 }\n"
    "camera { location <0.5, 0.5, 0.1> look_at <0.5, 0.5, 1> angle 90 }\n"
    "light_source { <0.3, 0.7, 0.4> color rgb <1, 0.8, 0.6> }\n"
    "mesh {\n"
    "  triangle { <0,0,0>, <1,0,0>, <1,1,0> } triangle { <0,0,0>, <1,1,0>, <0,1,0> }\n"
    "  triangle { <0,0,1>, <1,0,1>, <1,1,1> } triangle { <0,0,1>, <1,1,1>, <0,1,1> }\n"
    "  triangle { <0,0,0>, <0,1,0>, <0,1,1> } triangle { <0,0,0>, <0,1,1>, <0,0,1> }\n"
    "  triangle { <1,0,0>, <1,1,0>, <1,1,1> } triangle { <1,0,0>, <1,1,1>, <1,0,1> }\n"
    "  triangle { <0,0,0>, <1,0,0>, <1,0,1> } triangle { <0,0,0>, <1,0,1>, <0,0,1> }\n"
    "  triangle { <0,1,0>, <1,1,0>, <1,1,1> } triangle { <0,1,0>, <1,1,1>, <0,1,1> }\n"
    "  pigment { rgb 1 } finish { ambient 0 diffuse 0.6 }\n"
    "}\n";

static void energy_check(const char *device)
{
    fixture f;
    tg_load(&f, tg_cube_scene);
    /* one bounce: received scattered flux == rho * flux that left */
    gi_particle *gp = build(&f, 4000, 1, device, 1);
    const gi_particle_stats *st = gi_particle_get_stats(gp);
    assert_int_equal(st->link_unresolved, 0);
    /* the outside of the cube faces the void: no particle there, and the
     * count asked for lands inside (within 5%) */
    const float *edir, *phi, *lout;
    int n = gi_particle_debug(gp, &edir, &phi, &lout, NULL, NULL);
    printf("  [%s] %d particles for 4000 asked (%ld candidates, %ld pruned)\n", device ? device : "auto", n,
           st->candidates, st->pruned);
    assert_true(abs(n - 4000) <= 200);
    for (int i = 0; i < n; i++) {
        vec3 p, nrm;
        gi_particle_debug_particle(gp, i, NULL, NULL, &p, &nrm);
        assert_true(v3_dot(nrm, v3_sub(v3(0.5, 0.5, 0.5), p)) > 0.0);
    }
    double before = 0.0, after = 0.0;
    for (int i = 0; i < n; i++) {
        double area, rho[3];
        gi_particle_debug_particle(gp, i, &area, rho, NULL, NULL);
        for (int c = 0; c < 3; c++) {
            double fd = M_PI * edir[4 * i + c] * area;
            before += rho[c] * fd;
            after += phi[4 * i + c] - fd;
        }
    }
    printf("  [%s] one bounce: flux leaving lit particles %.9g, received %.9g (rel %.2e)\n", device ? device : "auto",
           before, after, fabs(after - before) / before);
    assert_true(before > 0.0);
    assert_true(fabs(after - before) <= 1e-5 * before);
    gi_particle_free(gp);

    /* several bounces: each carries rho = 0.6 times the one before */
    gp = build(&f, 4000, 6, device, 1);
    const double *bf;
    int nbf;
    gi_particle_debug(gp, NULL, NULL, NULL, &bf, &nbf);
    assert_int_equal(nbf, 6);
    for (int b = 1; b < nbf; b++) {
        double ratio = bf[b] / bf[b - 1];
        printf("  [%s] bounce %d / bounce %d = %.7f\n", device ? device : "auto", b + 1, b, ratio);
        assert_true(fabs(ratio - 0.6) <= 1e-4);
    }
    gi_particle_free(gp);
    tg_unload(&f);
}

static void test_energy_c(void **state)
{
    (void)state;
    energy_check(tg_device_c);
}

/* FULL scattering: n_b bounces along all links move exactly
 * (rho + rho^2 + ... + rho^n_b) / rho times the flux leaving the lit
 * particles in a closed box of uniform rho (float sums, 1e-5). */
static void full_check(const char *device)
{
    fixture f;
    tg_load(&f, tg_cube_scene);
    g_scatter = GI_PARTICLE_SCATTER_FULL;
    for (int nb = 1; nb <= 3; nb++) {
        gi_particle *gp = build(&f, 4000, nb, device, 1);
        const float *edir, *phi;
        int n = gi_particle_debug(gp, &edir, &phi, NULL, NULL, NULL);
        double before = 0.0, after = 0.0;
        for (int i = 0; i < n; i++) {
            double area, rho[3];
            gi_particle_debug_particle(gp, i, &area, rho, NULL, NULL);
            for (int c = 0; c < 3; c++) {
                double fd = M_PI * edir[4 * i + c] * area;
                before += rho[c] * fd;
                after += phi[4 * i + c] - fd;
            }
        }
        double want = before * (nb == 1 ? 1.0 : nb == 2 ? 1.6 : 1.96);
        printf("  [%s] full scattering, %d bounces: received %.9g, expected %.9g (rel %.2e)\n",
               device ? device : "auto", nb, after, want, fabs(after - want) / want);
        assert_true(fabs(after - want) <= 1e-5 * want);
        gi_particle_free(gp);
    }
    g_scatter = GI_PARTICLE_SCATTER_WALK;
    tg_unload(&f);
}

static void test_full_scatter(void **state)
{
    (void)state;
    full_check(tg_device_c);
    if (have_opencl()) full_check(tg_device_cl);
}

static void test_energy_opencl(void **state)
{
    (void)state;
    if (!have_opencl()) skip();
    energy_check(tg_device_cl);
}

/* ------------------------------------------------------------------ sphere */

static const char *sphere_scene =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 }\n"
    "camera { location <0, 0, 0> look_at <0, 0, 1> }\n"
    "light_source { <0.3, 0.2, 0.1> color rgb 1 }\n"
    "sphere { 0, 1 pigment { rgb 1 } finish { ambient 0 diffuse 0.5 } }\n";

static double g_bias;

/* Indirect light (the hook's E/pi, green) at the pixels of a pw x pw view
 * of f's camera: on[i] is 1 where the primary ray hits a shape other than
 * the mesh room, and only there is ind[i] written. */
static void view_indirect(fixture *f, gi_particle *gp, int pw, unsigned char *on, double *ind)
{
    for (int y = 0; y < pw; y++)
        for (int x = 0; x < pw; x++) {
            vec3 org, dir;
            scene_camera_ray(&f->sc->camera, x + 0.5, y + 0.5, pw, pw, &org, &dir);
            accel_hit h;
            int i = y * pw + x;
            on[i] = accel_intersect(f->a, org, dir, 0.0, INFINITY, &h) && h.obj->kind != SHAPE_MESH;
            if (!on[i]) continue;
            vec3 n = v3_dot(dir, h.ns) > 0.0 ? v3_neg(h.ns) : h.ns;
            ind[i] = gi_particle_indirect(gp, &h, n, 0).g;
        }
}

static double sphere_error(fixture *f, long count, int nb, const char *device, double *expected)
{
    gi_particle *gp = build(f, count, nb, device, 7);
    double rho = 0.5, sum = 0.0, pk = 1.0;
    for (int k = 1; k <= nb + 1; k++) {
        pk *= rho;
        sum += pk;
    }
    double a2 = 0.3 * 0.3 + 0.2 * 0.2 + 0.1 * 0.1;
    *expected = (1.0 - a2 / 3.0) * sum; /* E_ind / pi for C = 1, R = 1 */
    /* probe points: a spiral of directions from the light */
    double err2 = 0.0, bias = 0.0;
    int m = 0;
    const int probes = 200;
    for (int i = 0; i < probes; i++) {
        double z = 1.0 - 2.0 * (i + 0.5) / probes, r = sqrt(fmax(0.0, 1.0 - z * z));
        double ph = i * 2.39996322972865332;
        vec3 dir = v3(r * cos(ph), r * sin(ph), z);
        accel_hit h;
        if (!accel_intersect(f->a, v3(0.3, 0.2, 0.1), dir, 0.0, INFINITY, &h)) continue;
        vec3 n = v3_dot(dir, h.ns) > 0.0 ? v3_neg(h.ns) : h.ns;
        rgb e = gi_particle_indirect(gp, &h, n, 0);
        assert_true(isfinite(e.r) && isfinite(e.g) && isfinite(e.b));
        double rel = (e.g - *expected) / *expected;
        err2 += rel * rel;
        bias += rel;
        m++;
    }
    assert_true(m > probes / 2);
    const gi_particle_stats *st = gi_particle_get_stats(gp);
    assert_int_equal(st->discarded, 0);
    assert_true(st->lookups_late > 0); /* no prepare_view: computed on demand */
    /* the particles' areas (nominal or catchment) add up to the sphere's */
    int np = gi_particle_debug(gp, NULL, NULL, NULL, NULL, NULL);
    double asum = 0.0;
    for (int i = 0; i < np; i++) {
        double ar;
        gi_particle_debug_particle(gp, i, &ar, NULL, NULL, NULL);
        asum += ar;
    }
    printf("  integrating sphere, %6ld particles: %d kept, summed area / 4 pi = %.5f\n", count, np,
           asum / (4.0 * M_PI));
    assert_true(fabs(asum / (4.0 * M_PI) - 1.0) < 0.01);
    gi_particle_free(gp);
    g_bias = bias / m;
    return sqrt(err2 / m);
}

static void test_integrating_sphere(void **state)
{
    (void)state;
    fixture f;
    tg_load(&f, sphere_scene);
    static const long counts[] = {1000, 4000, 16000};
    double err[3], bias[3], expected = 0.0;
    for (int i = 0; i < 3; i++) {
        err[i] = sphere_error(&f, counts[i], 10, tg_device_c, &expected);
        bias[i] = g_bias;
        printf("  integrating sphere, %6ld particles: expected E/pi %.6f, RMS relative error %.4f (mean %+.4f)\n",
               counts[i], expected, err[i], g_bias);
    }
    for (int i = 0; i < 3; i++) {
        assert_true(fabs(bias[i]) < 0.005);
        assert_true(err[i] < 0.01);
    }
    tg_unload(&f);
}

/* ------------------------------------------------------------------ direct */

static const char *floor_scene =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 }\n"
    "camera { location <0, 5, -5> look_at <0, 0, 0> }\n"
    "light_source { <0.5, 3, 0.2> color rgb <2, 1.5, 1>\n"
    "  spotlight radius 20 falloff 40 tightness 2 point_at <0, 0, 0>\n"
    "  fade_distance 2 fade_power 2 }\n"
    "mesh { triangle { <-4,0,-4>, <4,0,-4>, <4,0,4> } triangle { <-4,0,-4>, <4,0,4>, <-4,0,4> }\n"
    "  pigment { rgb <0.8, 0.7, 0.6> } finish { ambient 0 diffuse 0.9 } }\n"
    "// a ceiling, so that the floor's upper side is seen by other particles\n"
    "mesh { triangle { <-4,6,-4>, <4,6,-4>, <4,6,4> } triangle { <-4,6,-4>, <4,6,4>, <-4,6,4> } }\n";

static void test_direct_matches_whitted(void **state)
{
    (void)state;
    fixture f;
    tg_load(&f, floor_scene);
    gi_particle *gp = build(&f, 3000, 1, tg_device_c, 3);
    const float *edir;
    int n = gi_particle_debug(gp, &edir, NULL, NULL, NULL, NULL);
    shade_settings ss;
    shade_default_settings(&ss);
    ss.use_ambient = 0;
    int checked = 0;
    double worst = 0.0;
    for (int i = 0; i < n && checked < 40; i += 37) {
        vec3 p, nrm;
        double rho[3];
        gi_particle_debug_particle(gp, i, NULL, rho, &p, &nrm);
        if (nrm.y < 0.5) continue; /* the lit (upper) side */
        vec3 org = v3_add(p, v3(0.0, 1.0, 0.0));
        rng r;
        rng_seed(&r, 1, 1);
        rgb w = shade_trace(f.sc, f.a, &ss, org, v3(0, -1, 0), 0, &r);
        double want[3] = {w.r / rho[0], w.g / rho[1], w.b / rho[2]};
        for (int c = 0; c < 3; c++) {
            double got = edir[4 * i + c];
            /* float kernels: the spotlight's falloff tail cancels digits */
            double tol = 1e-3 * fabs(want[c]) + 1e-6;
            if (!(fabs(got - want[c]) <= tol))
                fail_msg("particle %d channel %d: E/pi %.9g, Whitted %.9g", i, c, got, want[c]);
            if (want[c] > 1e-3) worst = fmax(worst, fabs(got - want[c]) / want[c]);
        }
        checked++;
    }
    printf("  direct light of %d particles vs shade.c: worst relative difference %.2e\n", checked, worst);
    assert_true(checked >= 10);
    gi_particle_free(gp);
    tg_unload(&f);
}

/* ------------------------------------------------------------------ determinism */

static void hook_values(fixture *f, gi_particle *gp, double *out, int nout)
{
    for (int i = 0; i < nout; i++) {
        double x = 0.05 + 0.9 * ((i * 0.618034) - floor(i * 0.618034));
        double y = 0.05 + 0.9 * ((i * 0.754878) - floor(i * 0.754878));
        accel_hit h;
        vec3 dir = v3_norm(v3(x - 0.5, y - 0.5, 0.9));
        assert_true(accel_intersect(f->a, v3(0.5, 0.5, 0.1), dir, 0.0, INFINITY, &h));
        vec3 n = v3_dot(dir, h.ns) > 0.0 ? v3_neg(h.ns) : h.ns;
        rgb e = gi_particle_indirect(gp, &h, n, 0);
        out[3 * i] = e.r;
        out[3 * i + 1] = e.g;
        out[3 * i + 2] = e.b;
    }
}

static void test_determinism(void **state)
{
    (void)state;
    fixture f;
    tg_load(&f, tg_cube_scene);
    int use_cl = have_opencl();
    const char *devs[2] = {tg_device_c, NULL};
    double *vals[2] = {NULL, NULL};
    const int nv = 64;
    for (int k = 0; k < (use_cl ? 2 : 1); k++) {
        gi_particle *g1 = build(&f, 3000, 6, devs[k], 11);
        gi_particle *g2 = build(&f, 3000, 6, devs[k], 11);
        assert_int_equal(gi_particle_prepare_view(g1, &f.sc->camera, 32, 32, f.d), PT_OK);
        assert_int_equal(gi_particle_prepare_view(g2, &f.sc->camera, 32, 32, f.d), PT_OK);
        const float *l1, *l2;
        int n1 = gi_particle_debug(g1, NULL, NULL, &l1, NULL, NULL);
        int n2 = gi_particle_debug(g2, NULL, NULL, &l2, NULL, NULL);
        assert_int_equal(n1, n2);
        assert_memory_equal(l1, l2, (size_t)n1 * 4 * sizeof(float));
        double a[3 * 64], b[3 * 64];
        hook_values(&f, g1, a, nv);
        hook_values(&f, g2, b, nv);
        assert_memory_equal(a, b, sizeof a);
        vals[k] = malloc(sizeof a);
        memcpy(vals[k], a, sizeof a);
        /* a different seed moves the particles: values change a little */
        gi_particle *g3 = build(&f, 3000, 6, devs[k], 12);
        double c3[3 * 64];
        hook_values(&f, g3, c3, nv);
        assert_true(memcmp(a, c3, sizeof a) != 0);
        gi_particle_free(g1);
        gi_particle_free(g2);
        gi_particle_free(g3);
    }
    if (use_cl) {
        double worst = 0.0;
        for (int i = 0; i < 3 * nv; i++) {
            double rel = fabs(vals[0][i] - vals[1][i]) / fmax(1e-6, fabs(vals[0][i]));
            worst = fmax(worst, rel);
        }
        printf("  OpenCL vs C build of the kernels: worst relative difference %.2e\n", worst);
        assert_true(worst <= 1e-4);
    }
    free(vals[0]);
    free(vals[1]);
    tg_unload(&f);
}

/* ------------------------------------------------------------------ errors */

static void test_opencl_errors(void **state)
{
    (void)state;
    if (!have_opencl()) skip();
    fixture f;
    tg_load(&f, tg_cube_scene);
    gi_particle_settings s;
    gi_particle_default_settings(&s);
    s.count = 500;
    s.cl_source = "__kernel void broken(__global float *x) { this is not OpenCL C; }\n";
    pt_status st = PT_OK;
    diag *d = diag_new();
    gi_particle *gp = gi_particle_build(f.sc, f.a, &s, NULL, d, &st);
    assert_null(gp);
    assert_int_equal(st, PT_ERR_DEVICE);
    assert_true(diag_errors(d) >= 1);
    char *m = diag_format(diag_get(d, diag_count(d) - 1));
    printf("  %.200s...\n", m);
    assert_non_null(strstr(m, "build log"));
    assert_non_null(strstr(m, "error"));
    free(m);
    diag_free(d);

    d = diag_new();
    s.cl_source = NULL;
    s.cl_device = "no-such-device-anywhere";
    gp = gi_particle_build(f.sc, f.a, &s, NULL, d, &st);
    assert_null(gp);
    assert_int_equal(st, PT_ERR_DEVICE);
    m = diag_format(diag_get(d, 0));
    assert_non_null(strstr(m, "no-such-device-anywhere"));
    free(m);
    diag_free(d);

    /* Out of device memory: a budget of 64 KiB (gi_dev_options.max_bytes,
     * --cl-max-memory) cannot hold 500 particles' buffers (about 100 bytes
     * each, plus links): a clear PT_ERR_NOMEM error naming the sizes, the
     * device and the way out, before anything is requested from PoCL. */
    d = diag_new();
    s.cl_device = NULL;
    s.cl_max_bytes = 64 << 10;
    gp = gi_particle_build(f.sc, f.a, &s, NULL, d, &st);
    if (gp) st = gi_particle_light(gp, d);
    gi_particle_free(gp);
    assert_int_equal(st, PT_ERR_NOMEM);
    assert_true(diag_errors(d) >= 1);
    m = diag_format(diag_get(d, 0));
    printf("  %s\n", m);
    assert_non_null(strstr(m, "OpenCL: out of device memory"));
    assert_non_null(strstr(m, "than the 0.1 MiB it may use"));
    assert_non_null(strstr(m, "--cl-device c"));
    free(m);
    diag_free(d);
    tg_unload(&f);
}

/* ------------------------------------------------------------------ view */

static void test_view_and_render(void **state)
{
    (void)state;
    fixture f;
    tg_load(&f, tg_cube_scene);
    gi_particle *gp = build(&f, 3000, 4, tg_device_c, 5);
    assert_int_equal(gi_particle_prepare_view(gp, &f.sc->camera, 24, 24, f.d), PT_OK);
    const gi_particle_stats *st = gi_particle_get_stats(gp);
    assert_true(st->found > 0);
    assert_true(st->used > 0);
    assert_true(st->used <= st->particles);
    /* render through the hook: the pre-pass found (almost) everything */
    shade_settings ss;
    shade_default_settings(&ss);
    ss.width = ss.height = 24;
    ss.threads = 2;
    ss.use_ambient = 0;
    ss.indirect = gi_particle_indirect;
    ss.indirect_ctx = gp;
    framebuffer *fb = fb_new(24, 24);
    shade_stats sst;
    assert_int_equal(shade_render(f.sc, f.a, &ss, fb, &sst, f.d), PT_OK);
    st = gi_particle_get_stats(gp);
    printf("  hook lookups %ld, computed late %ld, without particles %ld\n", st->lookups, st->lookups_late,
           st->lookups_none);
    assert_true(st->lookups >= 24 * 24);
    assert_int_equal(st->lookups_none, 0);
    assert_true(st->lookups_late * 50 <= st->lookups);
    assert_int_equal(sst.discarded_samples, 0);
    /* indirect light makes the box brighter than direct light alone */
    framebuffer *fb0 = fb_new(24, 24);
    ss.indirect = NULL;
    assert_int_equal(shade_render(f.sc, f.a, &ss, fb0, &sst, f.d), PT_OK);
    assert_true(fb_mean(fb, -1) > 1.2 * fb_mean(fb0, -1));
    /* relighting: a brighter light, same particles, twice the light */
    double before = fb_mean(fb, -1);
    f.sc->lights[0].colour.r *= 2.0;
    f.sc->lights[0].colour.g *= 2.0;
    f.sc->lights[0].colour.b *= 2.0;
    assert_int_equal(gi_particle_relight(gp, f.d), PT_OK);
    assert_int_equal(gi_particle_prepare_view(gp, &f.sc->camera, 24, 24, f.d), PT_OK);
    ss.indirect = gi_particle_indirect;
    assert_int_equal(shade_render(f.sc, f.a, &ss, fb, &sst, f.d), PT_OK);
    double after = fb_mean(fb, -1);
    printf("  relight x2: mean %.6f -> %.6f (ratio %.6f)\n", before, after, after / before);
    assert_true(fabs(after / before - 2.0) < 1e-4);
    fb_free(fb);
    fb_free(fb0);
    gi_particle_free(gp);
    tg_unload(&f);
}

/* Cancellation of the lighting stage (gi_particle_set_cancel): with the
 * flag set, a relight after a colour change (stopped before its first
 * kernel) and one after a move (stopped in the visibility pass) leave
 * every particle's radiance bit for bit as it was; cleared, the relight
 * after the move gives bit for bit what a fresh build with the moved light
 * gives. Both devices. */
static void cancel_check(const char *device)
{
    fixture f;
    tg_load(&f, tg_cube_scene);
    gi_particle *gp = build(&f, 2000, 4, device, 9);
    const float *lout;
    int n = gi_particle_debug(gp, NULL, NULL, &lout, NULL, NULL);
    float *before = malloc((size_t)n * 4 * sizeof *before);
    assert_non_null(before);
    memcpy(before, lout, (size_t)n * 4 * sizeof *before);
    volatile int cancel = 1;
    gi_particle_set_cancel(gp, &cancel);
    f.sc->lights[0].colour.r *= 3.0;
    assert_int_equal(gi_particle_relight(gp, f.d), PT_OK);
    gi_particle_debug(gp, NULL, NULL, &lout, NULL, NULL);
    assert_memory_equal(before, lout, (size_t)n * 4 * sizeof *before);
    f.sc->lights[0].colour.r /= 3.0;
    f.sc->lights[0].position.x += 0.2;
    assert_int_equal(gi_particle_relight(gp, f.d), PT_OK);
    gi_particle_debug(gp, NULL, NULL, &lout, NULL, NULL);
    assert_memory_equal(before, lout, (size_t)n * 4 * sizeof *before);
    cancel = 0;
    assert_int_equal(gi_particle_relight(gp, f.d), PT_OK);
    gi_particle_set_cancel(gp, NULL);
    gi_particle *fresh = build(&f, 2000, 4, device, 9);
    const float *lf;
    assert_int_equal(gi_particle_debug(fresh, NULL, NULL, &lf, NULL, NULL), n);
    gi_particle_debug(gp, NULL, NULL, &lout, NULL, NULL);
    int changed = 0;
    for (int i = 0; i < 4 * n; i++) changed += lout[i] != before[i];
    printf("  [%s] cancelled relights kept all %d particles; the relight after them changed %d values and equals a "
           "fresh build\n", device ? device : "auto", n, changed);
    assert_true(changed > n);
    assert_memory_equal(lf, lout, (size_t)n * 4 * sizeof *lf);
    free(before);
    gi_particle_free(fresh);
    gi_particle_free(gp);
    tg_unload(&f);
}

static void test_cancel(void **state)
{
    (void)state;
    cancel_check(tg_device_c);
    if (have_opencl()) cancel_check(NULL);
    /* the geometry stage (Ctrl-C in partray render): a set flag stops it
     * with PT_CANCELLED, no particles, no diagnostic */
    fixture f;
    tg_load(&f, tg_cube_scene);
    gi_particle_settings s;
    gi_particle_default_settings(&s);
    s.count = 2000;
    s.threads = 2;
    s.cl_device = tg_device_c;
    volatile int cancel = 1;
    s.cancel = &cancel;
    gi_particle_stats stats;
    pt_status st = PT_OK;
    gi_particle *gp = gi_particle_build(f.sc, f.a, &s, &stats, f.d, &st);
    assert_null(gp);
    assert_int_equal(st, PT_CANCELLED);
    assert_int_equal(diag_errors(f.d), 0);
    tg_unload(&f);
}

/* A cylinder and a prism: their indirect light must be close to that of
 * the floor next to them (all see the same room). Both have radiance
 * particles (the cylinder a parametric grid, the prism its sweep grid,
 * gi_surface_mesh.c split_grid) and are interpolated, none estimated at the hit
 * (the fallback for surfaces without grids: test_gi_grids). */
static void test_cylinder_prism(void **state)
{
    (void)state;
    char text[4096];
    snprintf(text, sizeof text, "%s%s", tg_cube_scene,
             "cylinder { <0.7, 0, 0.7>, <0.7, 0.5, 0.7>, 0.1 pigment { rgb 1 } finish { ambient 0 diffuse 0.6 } }\n"
             "prism { linear_sweep 0, 0.3, 4, <0.15, 0.6>, <0.3, 0.6>, <0.3, 0.8>, <0.15, 0.8> pigment { rgb 1 } "
             "finish { ambient 0 diffuse 0.6 } }\n");
    fixture f;
    tg_load(&f, text);
    gi_particle *gp = build(&f, 4000, 6, tg_device_c, 2);
    accel_hit h;
    vec3 dir = v3_norm(v3(0.2, -0.15, 0.6));
    vec3 org = v3(0.5, 0.4, 0.1);
    assert_true(accel_intersect(f.a, org, dir, 0.0, INFINITY, &h));
    assert_int_equal(h.obj->kind, SHAPE_CYLINDER);
    vec3 n = v3_dot(dir, h.ns) > 0.0 ? v3_neg(h.ns) : h.ns;
    rgb e = gi_particle_indirect(gp, &h, n, 0);
    const gi_particle_stats *st = gi_particle_get_stats(gp);
    assert_int_equal(st->lookups_onthefly, 0);
    assert_int_equal(st->lookups_none, 0);
    accel_hit hp;
    vec3 dp = v3_norm(v3(-0.3, -0.3, 0.6));
    assert_true(accel_intersect(f.a, org, dp, 0.0, INFINITY, &hp));
    assert_int_equal(hp.obj->kind, SHAPE_PRISM);
    vec3 np = v3_dot(dp, hp.ns) > 0.0 ? v3_neg(hp.ns) : hp.ns;
    rgb ep = gi_particle_indirect(gp, &hp, np, 0);
    st = gi_particle_get_stats(gp);
    assert_int_equal(st->lookups_onthefly, 0);
    assert_int_equal(st->lookups_none, 0);
    /* the floor right under the viewer's side of the cylinder */
    accel_hit h2;
    assert_true(accel_intersect(f.a, v3(0.55, 0.3, 0.55), v3(0, -1, 0), 0.0, INFINITY, &h2));
    rgb e2 = gi_particle_indirect(gp, &h2, v3(0, 1, 0), 0);
    printf("  cylinder E/pi %.4f, prism %.4f (both radiance particles), floor nearby %.4f\n", e.g, ep.g, e2.g);
    assert_true(e.g > 0.3 * e2.g && e.g < 3.0 * e2.g);
    assert_true(ep.g > 0.3 * e2.g && ep.g < 3.0 * e2.g);
    gi_particle_free(gp);
    tg_unload(&f);
}

/* Implicit shapes get particles (accel_surface's Crofton sampling): a
 * sphere of radius 0.2 in the closed cube, written as a sphere, as a
 * one-component blob (field s (1 - d^2/R^2)^2 = t at d = R sqrt(1 -
 * sqrt(t/s)), POV-Ray's blob density) and as an isosurface. The particles
 * on each carry 4 pi r^2 within 1% (Crofton estimate plus one particle of
 * rounding), and the GI render (32x32, 6000 particles, n_b 4) of the three
 * scenes has the same mean within 2% (printed). The shape's own
 * indirect light, pixel by pixel (24x24, the pixels whose primary ray hits
 * it): every hit interpolates radiance particles (on the blob and the
 * isosurface: the vertices of their marching-tetrahedra grids; none
 * estimated at the hit), mean within 1% and every pixel within 4% of the
 * sphere's. */
static double shape_particle_area(gi_particle *gp, vec3 c, double r, long *n)
{
    const gi_particle_stats *st = gi_particle_get_stats(gp);
    double sum = 0.0;
    *n = 0;
    for (long i = 0; i < st->particles; i++) {
        double a, rho[3];
        vec3 p, nn;
        gi_particle_debug_particle(gp, (int)i, &a, rho, &p, &nn);
        if (fabs(v3_len(v3_sub(p, c)) - r) < 1e-3 * r) {
            sum += a;
            (*n)++;
        }
    }
    return sum;
}

#define IMPLICIT_MEAN_TOL 0.01 /* the printed means are well inside it */
#define IMPLICIT_PIXEL_TOL 0.04 /* the grids' interpolation error, per pixel */
static void test_implicit_sphere(void **state)
{
    (void)state;
    const double r = 0.2, t = 0.5, sgt = 1.0;
    const double R = r / sqrt(1.0 - sqrt(t / sgt));
    const vec3 c = v3(0.5, 0.25, 0.6);
    char shapes[3][512];
    snprintf(shapes[0], sizeof shapes[0], "sphere { <0.5, 0.25, 0.6>, %.17g pigment { rgb <0.9, 0.5, 0.3> } "
             "finish { ambient 0 diffuse 0.7 } }\n", r);
    snprintf(shapes[1], sizeof shapes[1], "blob { threshold %.17g sphere { <0.5, 0.25, 0.6>, %.17g, %.17g } "
             "pigment { rgb <0.9, 0.5, 0.3> } finish { ambient 0 diffuse 0.7 } }\n", t, R, sgt);
    snprintf(shapes[2], sizeof shapes[2], "isosurface { function { sqrt(x*x + y*y + z*z) - %.17g } "
             "contained_by { box { -0.25, 0.25 } } max_gradient 1.1 translate <0.5, 0.25, 0.6> "
             "pigment { rgb <0.9, 0.5, 0.3> } finish { ambient 0 diffuse 0.7 } }\n", r);
    const char *names[3] = {"sphere", "blob", "isosurface"};
    double mean[3];
    /* indirect light (the hook's E/pi, green) at the pixels of a 24x24 view
     * whose primary ray hits the shape, the same pixels in all three */
    enum { PW = 24 };
    static double ind[3][PW * PW];
    static unsigned char on[3][PW * PW];
    for (int k = 0; k < 3; k++) {
        char text[4096];
        snprintf(text, sizeof text, "%s%s", tg_cube_scene, shapes[k]);
        fixture f;
        tg_load(&f, text);
        gi_particle *gp = build(&f, 6000, 4, tg_device_c, 3);
        const gi_particle_stats *st = gi_particle_get_stats(gp);
        assert_int_equal(st->skipped_objects, 0);
        long n;
        double area = shape_particle_area(gp, c, r, &n);
        double exact = 4.0 * M_PI * r * r;
        assert_int_equal(gi_particle_prepare_view(gp, &f.sc->camera, 32, 32, f.d), PT_OK);
        long otf0 = gi_particle_get_stats(gp)->lookups_onthefly;
        view_indirect(&f, gp, PW, on[k], ind[k]);
        long otf = gi_particle_get_stats(gp)->lookups_onthefly - otf0;
        shade_settings ss;
        shade_default_settings(&ss);
        ss.width = ss.height = 32;
        ss.threads = 2;
        ss.use_ambient = 0;
        ss.indirect = gi_particle_indirect;
        ss.indirect_ctx = gp;
        framebuffer *fb = fb_new(32, 32);
        shade_stats sst;
        assert_int_equal(shade_render(f.sc, f.a, &ss, fb, &sst, f.d), PT_OK);
        mean[k] = fb_mean(fb, -1);
        st = gi_particle_get_stats(gp);
        printf("  %-10s: %ld particles on it, area %.5f / 4 pi r^2 = %.5f; GI mean %.6f (%+.3f%% vs sphere); "
               "lookups without particles %ld\n",
               names[k], n, area, area / exact, mean[k], 100.0 * (mean[k] / mean[0] - 1.0), st->lookups_none);
        assert_true(n > 100);
        assert_true(fabs(area / exact - 1.0) < 0.01);
        assert_int_equal(st->lookups_none, 0);
        assert_true(fabs(mean[k] / mean[0] - 1.0) < 0.02);
        /* every hit on the shape interpolates radiance particles (none is
         * estimated at the hit), and its indirect light matches the
         * sphere's pixel by pixel */
        assert_int_equal(otf, 0);
        int npix = 0;
        double worst = 0.0, sum = 0.0, ref = 0.0;
        for (int i = 0; i < PW * PW; i++) {
            if (!on[k][i] || !on[0][i]) continue;
            double rel = fabs(ind[k][i] / ind[0][i] - 1.0);
            worst = fmax(worst, rel);
            sum += ind[k][i];
            ref += ind[0][i];
            npix++;
        }
        printf("  %-10s: %d pixels on the shape, indirect E/pi mean %.5f (%+.2f%% vs sphere), worst pixel %.2f%%\n",
               names[k], npix, sum / (npix > 0 ? npix : 1), 100.0 * (sum / ref - 1.0), 100.0 * worst);
        assert_true(npix > 20);
        assert_true(fabs(sum / ref - 1.0) < IMPLICIT_MEAN_TOL);
        assert_true(worst < IMPLICIT_PIXEL_TOL);
        fb_free(fb);
        gi_particle_free(gp);
        tg_unload(&f);
    }
}

/* Analytic shapes without a grid of accel's get a parametric one (torus:
 * its two angles): a torus (R 0.2, r 0.07) in the closed cube and the same
 * torus as an isosurface (marching-tetrahedra grid) give the same indirect
 * light pixel by pixel (24x24 view, the pixels on the shape in both, every
 * hit interpolated: none estimated at the hit): mean within 1%, each pixel
 * within TORUS_PIXEL_TOL. */
#define TORUS_PIXEL_TOL 0.05
static void test_torus_grid(void **state)
{
    (void)state;
    const char *shapes[2] = {
        "torus { 0.2, 0.07 rotate <20, 0, 10> translate <0.5, 0.3, 0.6> pigment { rgb <0.9, 0.5, 0.3> } "
        "finish { ambient 0 diffuse 0.7 } }\n",
        "isosurface { function { sqrt(pow(sqrt(x*x + z*z) - 0.2, 2) + y*y) - 0.07 } "
        "contained_by { box { <-0.28, -0.08, -0.28>, <0.28, 0.08, 0.28> } } max_gradient 1.1 "
        "rotate <20, 0, 10> translate <0.5, 0.3, 0.6> pigment { rgb <0.9, 0.5, 0.3> } "
        "finish { ambient 0 diffuse 0.7 } }\n"};
    enum { PW = 24 };
    static double ind[2][PW * PW];
    static unsigned char on[2][PW * PW];
    for (int k = 0; k < 2; k++) {
        char text[4096];
        snprintf(text, sizeof text, "%s%s", tg_cube_scene, shapes[k]);
        fixture f;
        tg_load(&f, text);
        gi_particle *gp = build(&f, 6000, 4, tg_device_c, 3);
        assert_int_equal(gi_particle_prepare_view(gp, &f.sc->camera, PW, PW, f.d), PT_OK);
        view_indirect(&f, gp, PW, on[k], ind[k]);
        const gi_particle_stats *st = gi_particle_get_stats(gp);
        assert_int_equal(st->lookups_onthefly, 0);
        assert_int_equal(st->lookups_none, 0);
        gi_particle_free(gp);
        tg_unload(&f);
    }
    int npix = 0;
    double worst = 0.0, a = 0.0, b = 0.0;
    for (int i = 0; i < PW * PW; i++) {
        if (!on[0][i] || !on[1][i]) continue;
        worst = fmax(worst, fabs(ind[1][i] / ind[0][i] - 1.0));
        a += ind[0][i];
        b += ind[1][i];
        npix++;
    }
    printf("  torus vs isosurface torus: %d pixels, indirect E/pi mean %.5f vs %.5f (%+.2f%%), worst pixel %.2f%%\n",
           npix, a / npix, b / npix, 100.0 * (b / a - 1.0), 100.0 * worst);
    assert_true(npix > 20);
    assert_true(fabs(b / a - 1.0) < 0.01);
    assert_true(worst < TORUS_PIXEL_TOL);
}

/* CSG members get particles only where their surface is the result's (the
 * CSG inside rules), on the side facing out of it: a room with a
 * difference of a box, a sphere and a one-component blob (an implicit
 * shape: its own Crofton sampler keeps the crossings on the result, radiance
 * particles on the kept part of its grid). The subtracted members' visible
 * sides are their insides. Particle GI (8000 particles, n_b 8) against the
 * path tracer (64 spp): mean luminance of the whole 24x24 image and of the
 * pixels on the CSG within CSG_TOL. */
#define CSG_TOL 0.04
static void test_csg_members(void **state)
{
    (void)state;
    fixture f;
    tg_load(&f, "#version 3.7;\n"
             "global_settings { assumed_gamma 1.0 }\n"
             "camera { location <0.5, 0.5, 0.05> look_at <0.5, 0.4, 1> angle 90 }\n"
             "light_source { <0.3, 0.8, 0.3> color rgb 1 }\n"
             "box { <0,0,0>, <1,1,1> inverse pigment { rgb 0.8 } finish { ambient 0 diffuse 0.7 } }\n"
             "difference {\n"
             "  box { <0.3, 0.0, 0.45>, <0.75, 0.45, 0.9> }\n"
             "  sphere { <0.75, 0.45, 0.45>, 0.3 }\n"
             "  blob { threshold 0.5 sphere { <0.42, 0.2, 0.45>, 0.3, 1 } }\n"
             "  pigment { rgb <0.9, 0.6, 0.3> } finish { ambient 0 diffuse 0.8 }\n"
             "}\n");
    enum { W = 24 };
    gi_particle *gp = build(&f, 8000, 8, tg_device_c, 5);
    const gi_particle_stats *st = gi_particle_get_stats(gp);
    assert_int_equal(st->skipped_objects, 0);
    assert_int_equal(gi_particle_prepare_view(gp, &f.sc->camera, W, W, f.d), PT_OK);
    shade_settings ss;
    shade_default_settings(&ss);
    ss.width = ss.height = W;
    ss.threads = 2;
    ss.use_ambient = 0;
    ss.indirect = gi_particle_indirect;
    ss.indirect_ctx = gp;
    framebuffer *fp = fb_new(W, W), *fr = fb_new(W, W);
    shade_stats sst;
    assert_int_equal(shade_render(f.sc, f.a, &ss, fp, &sst, f.d), PT_OK);
    st = gi_particle_get_stats(gp);
    long none = st->lookups_none, otf = st->lookups_onthefly;
    pm_path_settings ps;
    pm_path_default_settings(&ps);
    ps.c.width = ps.c.height = W;
    ps.c.threads = 2;
    ps.c.spp = 64;
    ps.c.seed = 3;
    pm_stats pst;
    assert_int_equal(pm_path_render(f.sc, f.a, &ps, fr, &pst, NULL), PT_OK);
    unsigned char on[W * W];
    int non = 0, nblob = 0, nsphere = 0;
    for (int y = 0; y < W; y++)
        for (int x = 0; x < W; x++) {
            vec3 org, dir;
            scene_camera_ray(&f.sc->camera, x + 0.5, y + 0.5, W, W, &org, &dir);
            accel_hit h;
            on[y * W + x] = accel_intersect(f.a, org, dir, 0.0, INFINITY, &h) && !(h.obj->flags & OBJ_INVERSE);
            non += on[y * W + x];
            nblob += on[y * W + x] && h.obj->kind == SHAPE_BLOB;
            nsphere += on[y * W + x] && h.obj->kind == SHAPE_SPHERE;
        }
    double lp = tu_luminance_mean(fp, NULL), lr = tu_luminance_mean(fr, NULL);
    double cp = tu_luminance_mean(fp, on), cr = tu_luminance_mean(fr, on);
    printf("  CSG: %ld particles (%ld probed out), lookups without particles %ld, estimated at the hit %ld; "
           "mean luminance particle %.5f vs path %.5f (%+.2f%%), on the CSG (%d pixels, %d on the sphere, %d on "
           "the blob) %.5f vs %.5f (%+.2f%%)\n",
           st->particles, st->probed_out, none, otf, lp, lr, 100.0 * (lp / lr - 1.0), non, nsphere, nblob, cp, cr,
           100.0 * (cp / cr - 1.0));
    assert_true(non > 50 && nblob > 5 && nsphere > 5);
    assert_int_equal(none, 0);
    assert_int_equal(otf, 0);
    assert_true(fabs(lp / lr - 1.0) < CSG_TOL);
    assert_true(fabs(cp / cr - 1.0) < CSG_TOL);
    fb_free(fp);
    fb_free(fr);
    gi_particle_free(gp);
    tg_unload(&f);
}

/* light_group in the particle GI (POV-Ray 3.7: a group's lights light only
 * its members; global lights the rest, and the members only with
 * global_lights on), as shade.c's direct light: the same room and sphere
 * (in a light_group) with and without the group's own light, same
 * particles. The particles' direct light (E/pi) on the walls is the same to
 * float rounding (the group light does not reach them); on the sphere it is
 * 0 without the group light (global_lights off keeps the global light from
 * it) and > 0 with it; with global_lights on the global light reaches the
 * sphere too. */
static void test_light_group(void **state)
{
    (void)state;
    const char *fmt = "#version 3.7;\n"
                      "global_settings { assumed_gamma 1.0 }\n"
                      "camera { location <0.5, 0.5, 0.05> look_at <0.5, 0.45, 1> angle 90 }\n"
                      "light_source { <0.3, 0.8, 0.3> color rgb 1 }\n"
                      "box { <0,0,0>, <1,1,1> inverse pigment { rgb 0.8 } finish { ambient 0 diffuse 0.7 } }\n"
                      "light_group { %s\n"
                      "  sphere { <0.5, 0.35, 0.6>, 0.15 pigment { rgb 0.9 } finish { ambient 0 diffuse 0.7 } } %s }\n";
    const vec3 c = v3(0.5, 0.35, 0.6);
    const double r = 0.15;
    const char *light = "light_source { <0.75, 0.3, 0.45> color rgb <2, 1, 0.5> }";
    double wall_diff = 0.0, sphere[3] = {0, 0, 0}, wall[3] = {0, 0, 0};
    long nsph = 0, n0 = -1;
    float *e0 = NULL;
    for (int k = 0; k < 3; k++) {
        char text[2048];
        snprintf(text, sizeof text, fmt, k == 1 ? light : "", k == 2 ? "global_lights on" : "");
        fixture f;
        tg_load(&f, text);
        gi_particle *gp = build(&f, 6000, 2, tg_device_c, 9);
        const float *edir;
        int n = gi_particle_debug(gp, &edir, NULL, NULL, NULL, NULL);
        if (k == 0) {
            n0 = n;
            e0 = malloc((size_t)n * 4 * sizeof *e0);
            memcpy(e0, edir, (size_t)n * 4 * sizeof *e0);
        }
        assert_int_equal(n, n0); /* lights do not move particles here */
        long ns = 0;
        for (int i = 0; i < n; i++) {
            double a, rho[3];
            vec3 p, nn;
            gi_particle_debug_particle(gp, i, &a, rho, &p, &nn);
            int on = fabs(v3_len(v3_sub(p, c)) - r) < 1e-3 * r;
            double e = edir[4 * i] + edir[4 * i + 1] + edir[4 * i + 2];
            if (on) {
                sphere[k] += e;
                ns++;
            } else {
                wall[k] += e;
                if (k == 1) {
                    double e0s = e0[4 * i] + e0[4 * i + 1] + e0[4 * i + 2];
                    wall_diff = fmax(wall_diff, fabs(e - e0s) / fmax(1e-6, e0s));
                }
            }
        }
        if (k == 0) nsph = ns;
        gi_particle_free(gp);
        tg_unload(&f);
    }
    free(e0);
    printf("  light_group: %ld particles on the sphere; its direct E/pi summed: %.4f without the group light, %.4f with "
           "it, %.4f with global_lights on; walls %.4f / %.4f / %.4f (worst particle %.1e)\n",
           nsph, sphere[0], sphere[1], sphere[2], wall[0], wall[1], wall[2], wall_diff);
    assert_true(nsph > 50);
    assert_true(sphere[0] == 0.0);
    assert_true(sphere[1] > 1.0);
    assert_true(sphere[2] > 1.0);
    assert_true(wall_diff < 1e-6);
    assert_true(fabs(wall[1] / wall[0] - 1.0) < 1e-6 && fabs(wall[2] / wall[0] - 1.0) < 1e-6);
}

/* finish { diffuse A, B } in the particles' transport (gi_types.h): a
 * two-sided sheet across the closed cube, lit on its lower side (z < 0.7,
 * the light is at z 0.4) and dark on its upper side, one bounce, C build.
 *  - Each upper particle i with its twin t (the lower particle at the same
 *    point) reflects L_i = rho phi_i / (pi dA_i) + (B/A) rho phi_t / (pi dA_t)
 *    (gi_k_back), to float rounding (1e-5).
 *  - Every link resolves inside the cube, so the first bounce receives all
 *    that leaves: sum of rho pi (E_i/pi) dA_i over the particles plus
 *    (B/A) rho pi (E_t/pi) dA_i over the sheet's particles with a twin
 *    (gi_k_emit), within 1e-4 (float sums over 4000 particles).
 *  - The back lobe's share of that is more than 1% (the sheet carries light
 *    through), and without B every upper particle's L lacks it. */
static void test_diffuse_back(void **state)
{
    (void)state;
    double share = 0.0;
    for (int k = 0; k < 2; k++) {
        char text[4096];
        snprintf(text, sizeof text, "%s"
                 "triangle { <0.2, 0.2, 0.7>, <0.9, 0.2, 0.7>, <0.2, 0.9, 0.7> pigment { rgb 0.9 } "
                 "finish { ambient 0 diffuse 0.6%s } }\n",
                 tg_cube_scene, k ? ", 0.3" : "");
        fixture f;
        tg_load(&f, text);
        gi_particle *gp = build(&f, 4000, 1, tg_device_c, 4);
        assert_int_equal(gi_particle_get_stats(gp)->link_unresolved, 0);
        const float *edir, *phi, *lout;
        int n = gi_particle_debug(gp, &edir, &phi, &lout, NULL, NULL);
        double before = 0.0, after = 0.0, through = 0.0, worst = 0.0, sum_own = 0.0, sum_back = 0.0;
        int upper = 0, twins = 0;
        for (int i = 0; i < n; i++) {
            double area, rho[3];
            vec3 p, nrm;
            gi_particle_debug_particle(gp, i, &area, rho, &p, &nrm);
            for (int c = 0; c < 3; c++) {
                double fd = M_PI * edir[4 * i + c] * area;
                before += rho[c] * fd;
                after += phi[4 * i + c] - fd;
            }
            int sheet = fabs(p.z - 0.7) < 1e-6 && p.x > 0.19 && p.y > 0.19 && p.x + p.y < 1.11;
            if (!sheet) continue;
            /* the twin: the neighbour at the same point, facing the other way */
            int t = -1;
            for (int j = i - 1; j <= i + 1; j += 2) {
                if (j < 0 || j >= n) continue;
                vec3 q, nq;
                gi_particle_debug_particle(gp, j, NULL, NULL, &q, &nq);
                if (v3_len2(v3_sub(p, q)) == 0.0 && v3_dot(nrm, nq) < 0.0) t = j;
            }
            if (t < 0) continue;
            twins++;
            double at;
            gi_particle_debug_particle(gp, t, &at, NULL, NULL, NULL);
            for (int c = 0; c < 3; c++) {
                double b = k ? 0.5 * rho[c] * M_PI * edir[4 * t + c] * area : 0.0;
                before += b;
                through += b;
            }
            if (nrm.z < 0.0) continue;
            upper++;
            for (int c = 0; c < 3; c++) {
                double own = rho[c] * phi[4 * i + c] / (M_PI * area);
                double expect = own + (k ? 0.5 * rho[c] * phi[4 * t + c] / (M_PI * at) : 0.0);
                double e = fabs(lout[4 * i + c] - expect) / expect;
                worst = e > worst ? e : worst;
                if (c == 1) {
                    sum_own += own;
                    sum_back += expect - own;
                }
            }
        }
        printf("  diffuse 0.6%s: %d sheet particles with a twin, %d on the dark side (L within %.1e); one bounce "
               "receives %.9g of %.9g leaving (rel %.2e), %.9g of it through the sheet; dark side's L (green) "
               "%.4f own + %.4f the lit side's\n",
               k ? ", 0.3" : "", twins, upper, worst, after, before, fabs(after - before) / before, through,
               sum_own / upper, sum_back / upper);
        assert_true(upper > 50 && twins >= 2 * upper - 10);
        assert_true(worst < 1e-5);
        assert_true(fabs(after - before) <= 1e-4 * before);
        if (k) {
            share = through / before;
            assert_true(sum_back > 0.5 * sum_own); /* the lit side shows through */
        }
        gi_particle_free(gp);
        tg_unload(&f);
    }
    assert_true(share > 0.01);
}

/* diffuse_back across bounces: the sheet of test_diffuse_back in the closed
 * cube, four bounces. FULL sends each bounce's back-lobe share on
 * (gi_k_back_send); WALK's paths take the twin's way with probability
 * back / (1 + back), weighted to the same expectation
 * (gi_particle_build_walk): the scattered flux (received minus direct) of
 * the two within 1% (WALK's noise; well below the back lobes' share of the
 * later bounces), and the OpenCL build's FULL within 1e-4 of the C build's
 * (float sums in another order). */
static double scattered_flux(gi_particle *gp)
{
    const float *edir, *phi;
    int n = gi_particle_debug(gp, &edir, &phi, NULL, NULL, NULL);
    double s = 0.0;
    for (int i = 0; i < n; i++) {
        double area;
        gi_particle_debug_particle(gp, i, &area, NULL, NULL, NULL);
        for (int c = 0; c < 3; c++) s += phi[4 * i + c] - M_PI * edir[4 * i + c] * area;
    }
    return s;
}

static void test_diffuse_back_bounces(void **state)
{
    (void)state;
    char text[4096];
    snprintf(text, sizeof text, "%s"
             "triangle { <0.2, 0.2, 0.7>, <0.9, 0.2, 0.7>, <0.2, 0.9, 0.7> pigment { rgb 0.9 } "
             "finish { ambient 0 diffuse 0.6, 0.3 } }\n", tg_cube_scene);
    fixture f;
    tg_load(&f, text);
    g_scatter = GI_PARTICLE_SCATTER_FULL;
    gi_particle *gp = build(&f, 4000, 4, tg_device_c, 4);
    double full = scattered_flux(gp);
    gi_particle_free(gp);
    double cl = full;
    if (have_opencl()) {
        gp = build(&f, 4000, 4, tg_device_cl, 4);
        cl = scattered_flux(gp);
        gi_particle_free(gp);
    }
    g_scatter = GI_PARTICLE_SCATTER_WALK;
    gp = build(&f, 4000, 4, tg_device_c, 4);
    double walk = scattered_flux(gp);
    gi_particle_free(gp);
    printf("  diffuse 0.6, 0.3, 4 bounces: scattered flux FULL %.6f (OpenCL %.6f, rel %.1e), WALK %.6f (%+.2f%%)\n",
           full, cl, fabs(cl / full - 1.0), walk, 100.0 * (walk / full - 1.0));
    assert_true(fabs(cl / full - 1.0) < 1e-4);
    assert_true(fabs(walk / full - 1.0) < 0.01);
    tg_unload(&f);
}

/* clipped_by: particles on the part of the surface that stays, as the
 * renderer's CSG keeps it (accel.c: a clipped object is one CSG tree). An
 * open cylinder of radius 0.3 about the room's vertical axis, clipped to
 * x < 0.5: particles on it (distance 0.3 from the axis), none on the
 * clipped half (x > 0.5 beyond the probe's tolerance), no object skipped;
 * the open half cylinder's both sides get particles. */
static void test_clipped_by(void **state)
{
    (void)state;
    fixture f;
    tg_load(&f, "#version 3.7;\n"
             "global_settings { assumed_gamma 1.0 }\n"
             "camera { location <0.9, 0.5, 0.1> look_at <0.4, 0.4, 0.6> angle 90 }\n"
             "light_source { <0.8, 0.9, 0.2> color rgb 1 }\n"
             "box { <0,0,0>, <1,1,1> inverse pigment { rgb 0.8 } finish { ambient 0 diffuse 0.7 } }\n"
             "cylinder { <0.5, 0, 0.5>, <0.5, 0.8, 0.5>, 0.3 open clipped_by { plane { x, 0.5 } }\n"
             "  pigment { rgb 0.9 } finish { ambient 0 diffuse 0.8 } }\n");
    gi_particle *gp = build(&f, 8000, 2, tg_device_c, 5);
    const gi_particle_stats *st = gi_particle_get_stats(gp);
    int n = gi_particle_debug(gp, NULL, NULL, NULL, NULL, NULL);
    int on = 0, cut = 0, inner = 0;
    for (int i = 0; i < n; i++) {
        vec3 p, nrm;
        gi_particle_debug_particle(gp, i, NULL, NULL, &p, &nrm);
        double r = hypot(p.x - 0.5, p.z - 0.5);
        if (fabs(r - 0.3) > 1e-3 || p.y < 1e-3 || p.y > 0.8 - 1e-3) continue;
        on++;
        cut += p.x > 0.5 + 1e-3;
        inner += nrm.x * (p.x - 0.5) + nrm.z * (p.z - 0.5) < 0.0;
    }
    printf("  clipped_by: %d of %d particles on the half cylinder (%d facing its axis), %d on the clipped half, "
           "%ld objects skipped\n", on, n, inner, cut, st->skipped_objects);
    assert_int_equal(st->skipped_objects, 0);
    assert_true(on > 100 && inner > 20 && on - inner > 20);
    assert_int_equal(cut, 0);
    gi_particle_free(gp);
    tg_unload(&f);
}

/* Particles take the pigment where they lie (settings.pigment =
 * shade_tex_pigment_at): a room whose walls are a checker of two colours
 * (scale 0.25, walls at -0.1 and 1.1 so no wall lies on a check boundary).
 * Every particle's reflectance is diffuse * the check's colour at its
 * position (float rounding: 1e-6); the averages over each colour's
 * particles match diffuse * colour; without the callback every particle
 * has the same reflectance (the texture's base colour). */
static void test_checker_particles(void **state)
{
    (void)state;
    fixture f;
    tg_load(&f, "#version 3.7;\n"
             "global_settings { assumed_gamma 1.0 }\n"
             "camera { location <0.5, 0.5, 0.1> look_at <0.5, 0.4, 1> angle 90 }\n"
             "light_source { <0.3, 0.7, 0.4> color rgb 1 }\n"
             "box { <-0.1, -0.1, -0.1>, <1.1, 1.1, 1.1> inverse\n"
             "  pigment { checker rgb <0.9, 0.8, 0.7>, rgb <0.1, 0.3, 0.5> scale 0.25 }\n"
             "  finish { ambient 0 diffuse 0.7 } }\n");
    const double col[2][3] = {{0.9, 0.8, 0.7}, {0.1, 0.3, 0.5}}, kd = 0.7;
    for (int with = 1; with >= 0; with--) {
        gi_particle_settings s;
        gi_particle_default_settings(&s);
        s.count = 4000;
        s.bounces = 2;
        s.threads = 2;
        s.cl_device = tg_device_c;
        s.pigment = with ? shade_tex_pigment_at : NULL;
        pt_status st;
        gi_particle *gp = gi_particle_build(f.sc, f.a, &s, NULL, f.d, &st);
        assert_non_null(gp);
        const gi_particle_stats *gs = gi_particle_get_stats(gp);
        double sum[2][3] = {{0}}, worst = 0.0;
        long cnt[2] = {0, 0}, skipped = 0;
        double first[3] = {0}, spread = 0.0;
        for (long i = 0; i < gs->particles; i++) {
            double a, rho[3];
            vec3 p, nn;
            gi_particle_debug_particle(gp, (int)i, &a, rho, &p, &nn);
            double q[3] = {p.x / 0.25, p.y / 0.25, p.z / 0.25};
            long par = 0;
            int near = 0;
            for (int k = 0; k < 3; k++) {
                par += (long)floor(q[k]);
                if (fabs(q[k] - floor(q[k] + 0.5)) < 1e-4) near = 1;
            }
            if (i == 0)
                for (int c = 0; c < 3; c++) first[c] = rho[c];
            for (int c = 0; c < 3; c++) spread = fmax(spread, fabs(rho[c] - first[c]));
            if (near) {
                skipped++;
                continue;
            }
            int k = (int)(par & 1);
            cnt[k]++;
            for (int c = 0; c < 3; c++) {
                sum[k][c] += rho[c];
                if (with) worst = fmax(worst, fabs(rho[c] - kd * col[k][c]));
            }
        }
        if (with) {
            printf("  checker walls: %ld + %ld particles (%ld near a check edge left out); mean rho <%.6f %.6f %.6f> "
                   "and <%.6f %.6f %.6f> (expect <%.2f %.2f %.2f>, <%.2f %.2f %.2f>); worst particle %.2e\n",
                   cnt[0], cnt[1], skipped, sum[0][0] / cnt[0], sum[0][1] / cnt[0], sum[0][2] / cnt[0],
                   sum[1][0] / cnt[1], sum[1][1] / cnt[1], sum[1][2] / cnt[1], kd * col[0][0], kd * col[0][1],
                   kd * col[0][2], kd * col[1][0], kd * col[1][1], kd * col[1][2], worst);
            assert_true(cnt[0] > 500 && cnt[1] > 500);
            for (int k = 0; k < 2; k++)
                for (int c = 0; c < 3; c++) assert_true(fabs(sum[k][c] / cnt[k] - kd * col[k][c]) < 1e-6);
            assert_true(worst < 1e-6);
        } else {
            printf("  checker walls without the pigment callback: one reflectance <%.3f %.3f %.3f> (spread %.1e)\n",
                   first[0], first[1], first[2], spread);
            assert_true(spread < 1e-9);
        }
        gi_particle_free(gp);
    }
    tg_unload(&f);
}

/* A finely tessellated mesh (gi_fine_mesh.pov): a thin wall whose front is
 * lit only indirectly, as 2 triangles a face (N = 1) and as 80 x 40 cells a
 * face (N = 40, triangles smaller than the particle spacing, so most get no
 * particle of their own). The fine wall must render like the coarse one: the
 * mean over the wall's front within FINE_MEAN_TOL, and no pixel there below
 * FINE_PIXEL_MIN of the coarse image's pixel (radiance particles on
 * triangles without particles of their own must still get lists, or the
 * fine wall shows dark spots). */
#define FINE_MEAN_TOL 0.05
#define FINE_PIXEL_MIN 0.5
static double fine_wall(int n, int w, int h, float *out, unsigned char *on)
{
    char text[2048];
    snprintf(text, sizeof text,
             "#version 3.7;\n"
             "global_settings { assumed_gamma 1.0 }\n"
             "camera { location <2, 1.5, -3.5> look_at <0, 0.7, 0> angle 60 }\n"
             "light_source { <-1.5, 2.5, 1.5> color rgb 3 fade_distance 1 fade_power 2 }\n"
             "#macro Q(A, B, C, D, NU, NV)\n"
             "  mesh2 { vertex_vectors { (NU+1)*(NV+1), #for (J,0,NV) #for (I,0,NU) #local U=I/NU; #local W=J/NV;"
             " (1-W)*((1-U)*A+U*B)+W*((1-U)*D+U*C), #end #end }\n"
             "    face_indices { 2*NU*NV, #for (J,0,NV-1) #for (I,0,NU-1) #local K=J*(NU+1)+I; <K,K+1,K+NU+2>,"
             " <K,K+NU+2,K+NU+1>, #end #end }\n"
             "    pigment { rgb 0.7 } finish { ambient 0 diffuse 0.8 } }\n"
             "#end\n"
             "Q(<-4,0,-4>,<4,0,-4>,<4,0,4>,<-4,0,4>, 8, 8)\n"
             "Q(<-1.5,0,0>,<1.5,0,0>,<1.5,1.5,0>,<-1.5,1.5,0>, %d, %d)\n"
             "Q(<-1.5,0,0.2>,<1.5,0,0.2>,<1.5,1.5,0.2>,<-1.5,1.5,0.2>, %d, %d)\n",
             2 * n, n, 2 * n, n);
    fixture f;
    tg_load(&f, text);
    gi_particle *gp = build(&f, 20000, 8, tg_device_c, 7);
    assert_int_equal(gi_particle_prepare_view(gp, &f.sc->camera, w, h, f.d), PT_OK);
    shade_settings ss;
    shade_default_settings(&ss);
    ss.width = w;
    ss.height = h;
    ss.threads = 2;
    ss.use_ambient = 0;
    ss.indirect = gi_particle_indirect;
    ss.indirect_ctx = gp;
    framebuffer *fb = fb_new(w, h);
    shade_stats sst;
    assert_int_equal(shade_render(f.sc, f.a, &ss, fb, &sst, f.d), PT_OK);
    /* the wall's front (z = 0, seen from -z), away from its edges */
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            vec3 org, dir;
            scene_camera_ray(&f.sc->camera, x + 0.5, y + 0.5, w, h, &org, &dir);
            accel_hit hh;
            int i = y * w + x;
            on[i] = accel_intersect(f.a, org, dir, 0.0, INFINITY, &hh) && fabs(hh.p.z) < 1e-6 &&
                    fabs(hh.p.x) < 1.4 && hh.p.y > 0.1 && hh.p.y < 1.4;
            const float *p = fb->rgb + 3 * (size_t)i;
            out[i] = (float)(0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]);
        }
    double m = tu_luminance_mean(fb, on);
    fb_free(fb);
    gi_particle_free(gp);
    tg_unload(&f);
    return m;
}

static void test_fine_mesh(void **state)
{
    (void)state;
    enum { W = 48, H = 36 };
    float lc[W * H], lf[W * H];
    unsigned char onc[W * H], onf[W * H];
    double mc = fine_wall(1, W, H, lc, onc), mf = fine_wall(40, W, H, lf, onf);
    int non = 0, bad = 0;
    double worst = INFINITY;
    for (int i = 0; i < W * H; i++) {
        if (!onc[i] || !onf[i]) continue;
        non++;
        double r = lf[i] / fmax(lc[i], 1e-12);
        worst = fmin(worst, r);
        bad += r < FINE_PIXEL_MIN;
    }
    printf("  fine mesh: wall front (%d pixels) mean luminance coarse %.5f fine %.5f (%+.2f%%), worst pixel ratio "
           "%.3f, %d below %.2f\n",
           non, mc, mf, 100.0 * (mf / mc - 1.0), worst, bad, FINE_PIXEL_MIN);
    assert_true(non > 250);
    assert_true(mc > 0.0);
    assert_true(fabs(mf / mc - 1.0) < FINE_MEAN_TOL);
    assert_int_equal(bad, 0);
}

/* A thin closed slab (a mesh2 box, 0.05 thick: less than the estimation
 * list radius, about 0.19 here) under a lit ceiling: the indirect light the
 * hook returns on its top must be what the top alone (one quad, no slab
 * under it) gets. The slab is one mesh2 whose top and bottom faces are
 * wound alike (as conference.pov's table tops and seats), so the bottom
 * face's inner side is on the same object and patch side as the top's
 * outer side, with the same normal, 0.05 below it; it receives no light. Before the fix
 * (gi_visible ignored the own object, and its lift lay inside accel's
 * self-intersection epsilon) the top's lists took those dark particles:
 * conference.pov's table tops got half their indirect light. Mean of the
 * hook's E/pi (green) at 25 points on the top, away from its edges; the two
 * scenes' particles differ (the slab's sides and bottom take some), so
 * within SLAB_TOL. */
#define SLAB_TOL 0.10
static double slab_top(int closed)
{
    char text[2048];
    snprintf(text, sizeof text,
             "#version 3.7;\n"
             "global_settings { assumed_gamma 1.0 }\n"
             "camera { location <0, 3, -4> look_at <0, 0.5, 0> }\n"
             "light_source { <0, 1.5, 0> color rgb 2 }\n"
             "#macro Q(A, B, C, D)\n"
             "  mesh2 { vertex_vectors { 4, A, B, C, D } face_indices { 2, <0, 1, 2>, <0, 2, 3> }\n"
             "    pigment { rgb 0.7 } finish { ambient 0 diffuse 0.8 } }\n"
             "#end\n"
             "Q(<-3,0,-3>,<3,0,-3>,<3,0,3>,<-3,0,3>)\n"
             "Q(<-3,2,-3>,<3,2,-3>,<3,2,3>,<-3,2,3>)\n"
             "mesh2 { vertex_vectors { 8, <-1,0.5,-1>, <1,0.5,-1>, <1,0.5,1>, <-1,0.5,1>,\n"
             "    <-1,0.55,-1>, <1,0.55,-1>, <1,0.55,1>, <-1,0.55,1> }\n"
             "  face_indices { %s }\n"
             "  pigment { rgb 0.7 } finish { ambient 0 diffuse 0.8 } }\n",
             closed ? "12, <4,5,6>, <4,6,7>, <0,1,2>, <0,2,3>, <0,1,5>, <0,5,4>, <1,2,6>, <1,6,5>, <2,3,7>, <2,7,6>, "
                      "<3,0,4>, <3,4,7>"
                    : "2, <4,5,6>, <4,6,7>");
    fixture f;
    tg_load(&f, text);
    gi_particle *gp = build(&f, 20000, 2, tg_device_c, 3);
    double sum = 0.0;
    int n = 0;
    for (int i = 0; i < 5; i++)
        for (int j = 0; j < 5; j++) {
            accel_hit h;
            vec3 o = v3(-0.6 + 0.3 * i, 1.0, -0.6 + 0.3 * j);
            assert_true(accel_intersect(f.a, o, v3(0, -1, 0), 0.0, INFINITY, &h));
            assert_true(fabs(h.p.y - 0.55) < 1e-6);
            rgb e = gi_particle_indirect(gp, &h, v3(0, 1, 0), 0);
            sum += e.g;
            n++;
        }
    gi_particle_free(gp);
    tg_unload(&f);
    return sum / n;
}

static void test_thin_slab(void **state)
{
    (void)state;
    double open = slab_top(0), closed = slab_top(1);
    printf("  thin slab: indirect E/pi on the top, top alone %.5f, closed slab %.5f (%+.2f%%)\n", open, closed,
           100.0 * (closed / open - 1.0));
    assert_true(open > 0.0);
    assert_true(fabs(closed / open - 1.0) < SLAB_TOL);
}

static void test_settings_from_radiosity(void **state)
{
    (void)state;
    fixture f;
    tg_load(&f, "#version 3.7;\n"
             "global_settings { radiosity { count 100 recursion_limit 3 error_bound 0.8 brightness 1.5 } }\n"
             "camera { location <0,0,-3> look_at 0 }\n"
             "sphere { 0, 1 }\n");
    gi_particle_settings s;
    gi_particle_settings_from_scene(&s, f.sc);
    assert_int_equal(s.count, 50 * 100); /* GI_PARTICLES_PER_COUNT x count */
    assert_int_equal(s.bounces, 2);
    gi_particle_scale_quality(&s, 2.0);
    assert_int_equal(s.count, 10000);
    gi_particle_scale_quality(&s, 0.0); /* out of range: unchanged */
    assert_int_equal(s.count, 10000);
    assert_true(fabs(s.radius_factor - 2.0) < 1e-12);
    assert_true(fabs(s.brightness - 1.5) < 1e-12);
    tg_unload(&f);
    /* the final gather's side: sqrt(count x nearest_count / 2.5) within
     * [6, 20] without further bounces; below error_bound 0.1 every pixel
     * gathers unfiltered at 1.8 times that side, at most GI_DENSE_SIDE_MAX
     * (stackerday.pov's block: count 400, nearest_count 1, 0.05; count 100 with
     * nearest_count 5: 14 -> 25); under `normal on` every pixel gathers at
     * GI_NORMAL_ON_SIDE_GAIN times the side (balcony.pov's block: count 130,
     * nearest_count 5, error_bound 0.3: 16 -> 23) */
    static const struct { double eb; int nc, side, stride, normal_on, count; } want[] = {
        {0.1, 1, 20, 2, 0, 400}, {0.05, 1, 36, 1, 0, 400}, {0.05, 5, 25, 1, 0, 100},
        {0.5, 5, 20, 2, 0, 400}, {0.3, 5, 23, 1, 1, 130}, {0.3, 5, 16, 2, 0, 130}};
    for (size_t k = 0; k < sizeof want / sizeof want[0]; k++) {
        char text[512];
        snprintf(text, sizeof text,
                 "#version 3.7;\nglobal_settings { radiosity { count %d recursion_limit 1 nearest_count %d "
                 "error_bound %g %s } }\ncamera { location <0,0,-3> look_at 0 }\nsphere { 0, 1 }\n",
                 want[k].count, want[k].nc, want[k].eb, want[k].normal_on ? "normal on" : "");
        tg_load(&f, text);
        gi_particle_settings_from_scene(&s, f.sc);
        printf("  error_bound %g, nearest_count %d: gather side %d (want %d), stride %d\n", want[k].eb, want[k].nc,
               s.view_gather_side, want[k].side, s.view_gather_stride);
        assert_int_equal(s.view_gather_side, want[k].side);
        assert_int_equal(s.view_gather_stride, want[k].stride);
        gi_particle_scale_quality(&s, 4.0); /* the quality knob still raises a dense side */
        assert_true(s.view_gather_side >= want[k].side);
        tg_unload(&f);
    }
}

/* ------------------------------------------------------------------ shared radiance particles */

/* One radiance particle per distinct (point, object, facing): an L of two
 * grids in one mesh, a floor of 6 x 4 cells and a wall of 6 x 3 (cells 0.5
 * on a side, two triangles each) meeting at a right angle along their
 * common edge. With every triangle's sub-tessellation k = 1 (tess 1 >= the
 * cells' diagonal 0.707) the radiance particles are the grid vertices, 7 x
 * 5 + 7 x 4 on each of the two sides: the 7 on the crease stay two (the
 * faces' normals differ by 90 degrees). With k = 2 (tess 0.5) the cells'
 * edge midpoints join them: 13 x 9 + 13 x 7 a side. One particle per
 * triangle corner (before sharing) would be 84 x 3 x 2 = 504 and 84 x 6 x 2
 * = 1008. Every hit still interpolates its own triangle's three: the hook
 * is checked for NaN and for agreement across a shared edge. */
static void test_shared_rps(void **state)
{
    (void)state;
    fixture f;
    tg_load(&f, "#version 3.7;\n"
             "global_settings { assumed_gamma 1.0 }\n"
             "camera { location <1.5, 1.2, -2.5> look_at <1.5, 0.5, 0.5> }\n"
             "light_source { <1, 1.2, -1> color rgb 1 }\n"
             "mesh {\n"
             "  #for (J, 0, 3) #for (I, 0, 5)\n"
             "    triangle { <I, 0, J> * 0.5, <I + 1, 0, J> * 0.5, <I + 1, 0, J + 1> * 0.5 }\n"
             "    triangle { <I, 0, J> * 0.5, <I + 1, 0, J + 1> * 0.5, <I, 0, J + 1> * 0.5 }\n"
             "  #end #end\n"
             "  #for (J, 0, 2) #for (I, 0, 5)\n"
             "    triangle { <I, J, 4> * 0.5, <I + 1, J, 4> * 0.5, <I + 1, J + 1, 4> * 0.5 }\n"
             "    triangle { <I, J, 4> * 0.5, <I + 1, J + 1, 4> * 0.5, <I, J + 1, 4> * 0.5 }\n"
             "  #end #end\n"
             "  pigment { rgb 0.8 } finish { ambient 0 diffuse 0.8 }\n"
             "}\n");
    const double tess[2] = {1.0, 0.5};
    const long want[2] = {2 * (7 * 5 + 7 * 4), 2 * (13 * 9 + 13 * 7)};
    for (int t = 0; t < 2; t++) {
        gi_particle_settings s;
        gi_particle_default_settings(&s);
        s.count = 4000;
        s.bounces = 2;
        s.threads = 2;
        s.seed = 3;
        s.cl_device = tg_device_c;
        s.tess = tess[t];
        gi_particle_stats st;
        pt_status ps;
        gi_particle *gp = gi_particle_build(f.sc, f.a, &s, &st, f.d, &ps);
        if (!gp) print_diag(f.d);
        assert_non_null(gp);
        assert_int_equal(gi_particle_light(gp, f.d), PT_OK);
        /* the floor's two triangles of cell (2, 1) (mesh triangles 16 and
         * 17) share its diagonal from (1, 0, 0.5) to (1.5, 0, 1): the hook at
         * its midpoint, as a hit on either */
        vec3 mid = v3(1.25, 0.0, 0.75), n = v3(0, 1, 0);
        accel_hit h[2];
        double v[2];
        assert_true(accel_intersect(f.a, v3(1.2, 1.0, 0.7), v3(0, -1, 0), 0.0, INFINITY, &h[0]));
        h[0].p = mid;
        h[1] = h[0];
        h[0].prim = 16;
        h[1].prim = 17;
        for (int k = 0; k < 2; k++) {
            v[k] = gi_particle_indirect(gp, &h[k], n, 0).g;
            assert_true(isfinite(v[k]) && v[k] > 0.0);
        }
        printf("  shared radiance particles (tess %.1f): %ld (expect %ld; one per triangle corner %ld), "
               "diagonal midpoint E/pi %.6f from triangle %u, %.6f from triangle %u\n",
               tess[t], st.radiance_particles, want[t], 84L * (t ? 6 : 3) * 2, v[0], h[0].prim, v[1], h[1].prim);
        assert_int_equal(st.radiance_particles, want[t]);
        assert_true(fabs(v[0] - v[1]) <= 1e-6 * v[0]);
        gi_particle_free(gp);
    }
    tg_unload(&f);
}

/* ------------------------------------------------------------------ light on a surface */

/* A light lying exactly in the plane of a ceiling (cornell.pov's nine
 * spotlights sit at y = 54.88, the ceiling's height): the shadow ray from a
 * particle must stop short of the ceiling by more than Embree's float
 * error there. With a margin of 1e-6 x depth the ceiling triangle was hit
 * (its t carries ~2e-6 relative error) and the whole top of cornell's tall
 * block got no direct light (0 instead of 402 flux units: 10% of the
 * image's mean luminance). The geometry is cornell.pov's ceiling and tall
 * block top; the light is its first sub-patch centre as a plain point
 * light (colour 1), so E/pi = cos(theta) (POV-Ray: diffuse x colour x cos,
 * no distance falloff) at every particle on the top's upper side. */
static void test_light_on_ceiling(void **state)
{
    (void)state;
    fixture f;
    tg_load(&f, "#version 3.7;\n"
             "global_settings { assumed_gamma 1.0 }\n"
             "camera { location <27.8, 27.3, -80.0> look_at <27.8, 27.3, 0> }\n"
             "light_source { <23.4667, 54.88, 24.45> color rgb 1 }\n"
             "union {\n"
             "  triangle { <55.60, 54.88, 0.0>, <55.60, 54.88, 55.92>, <0.0, 54.88, 55.92> }\n"
             "  triangle { <55.60, 54.88, 0.0>, <0.0, 54.88, 55.92>, <0.0, 54.88, 0.0> }\n"
             "  triangle { <42.30, 33.00, 24.70>, <26.50, 33.00, 29.60>, <31.40, 33.00, 45.60> }\n"
             "  triangle { <42.30, 33.00, 24.70>, <31.40, 33.00, 45.60>, <47.20, 33.00, 40.60> }\n"
             "  pigment { rgb 1 } finish { ambient 0 diffuse 0.75 }\n"
             "}\n");
    gi_particle *gp = build(&f, 4000, 1, tg_device_c, 5);
    const float *edir;
    int n = gi_particle_debug(gp, &edir, NULL, NULL, NULL, NULL);
    vec3 lp = v3(23.4667, 54.88, 24.45);
    int checked = 0, dark = 0;
    double worst = 0.0;
    for (int i = 0; i < n; i++) {
        vec3 p, nrm;
        gi_particle_debug_particle(gp, i, NULL, NULL, &p, &nrm);
        if (!(fabs(p.y - 33.0) < 1e-3 && nrm.y > 0.9)) continue; /* the block top's upper side */
        vec3 l = v3_sub(lp, p);
        double want = v3_dot(nrm, l) / v3_len(l);
        double got = edir[4 * i + 1];
        if (got < 0.5 * want) dark++;
        worst = fmax(worst, fabs(got - want) / want);
        checked++;
    }
    printf("  light in the ceiling plane: %d top particles, %d dark, worst relative error %.2e\n", checked, dark,
           worst);
    assert_true(checked >= 20);
    assert_int_equal(dark, 0);
    assert_true(worst < 1e-3);
    gi_particle_free(gp);
    tg_unload(&f);
}


int main(int argc, char **argv)
{
    /* test_gi NAME runs the tests matching NAME (cmocka's filter) */
    if (argc > 1) cmocka_set_test_filter(argv[1]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_energy_c),
        cmocka_unit_test(test_energy_opencl),
        cmocka_unit_test(test_full_scatter),
        cmocka_unit_test(test_integrating_sphere),
        cmocka_unit_test(test_sky_furnace),
        cmocka_unit_test(test_sky_final_gather),
        cmocka_unit_test(test_normal_on_gather),
        cmocka_unit_test(test_csg_emitter_gather),
        cmocka_unit_test(test_mirror_gather),
        cmocka_unit_test(test_transmit_gather),
        cmocka_unit_test(test_closed_room_gather),
        cmocka_unit_test(test_diffuse_back_gather),
        cmocka_unit_test(test_dark_gather),
        cmocka_unit_test(test_sky_second_bounce),
        cmocka_unit_test(test_direct_matches_whitted),
        cmocka_unit_test(test_determinism),
        cmocka_unit_test(test_opencl_errors),
        cmocka_unit_test(test_view_and_render),
        cmocka_unit_test(test_cancel),
        cmocka_unit_test(test_cylinder_prism),
        cmocka_unit_test(test_implicit_sphere),
        cmocka_unit_test(test_torus_grid),
        cmocka_unit_test(test_csg_members),
        cmocka_unit_test(test_checker_particles),
        cmocka_unit_test(test_light_group),
        cmocka_unit_test(test_diffuse_back),
        cmocka_unit_test(test_diffuse_back_bounces),
        cmocka_unit_test(test_clipped_by),
        cmocka_unit_test(test_settings_from_radiosity),
        cmocka_unit_test(test_fine_mesh),
        cmocka_unit_test(test_light_on_ceiling),
        cmocka_unit_test(test_shared_rps),
        cmocka_unit_test(test_thin_slab),
        cmocka_unit_test(test_cell_cache),
        cmocka_unit_test(test_prepass_grid),
        cmocka_unit_test(test_kept_hits),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
