/* test_vpl.c - VPL reflectance filtering (gi/gi_vpl.h, gi/kernels/gi_vpl.cl)
 * on a synthetic room of VPLs (the five inner walls of a unit box, with
 * Lambertian and glossy VPLs) and gather points inside it:
 *
 *  - the full tree at solid-angle threshold 0 accepts only leaves: equal to
 *    brute-force gathering over every VPL (float sums, 1e-4), visiting all
 *    2n - 1 nodes;
 *  - eq. 4 on two lobes in closed form, and filtering keeps a node's energy
 *    (its l_s times its VPL count is the sum of its VPLs');
 *  - at the paper's threshold 0.02 the cut tree and the min-max cut stay
 *    within 5% of brute force in the mean, with fewer node visits;
 *  - the OpenCL build of the kernel (when a device is there) equals the C
 *    build within 1e-4;
 *  - `--gi vpl` (app/render_vpl.h) in a closed box room with a glossy and a
 *    metallic sphere and one point light, recursion_limit 3 (so both take
 *    the same bounces: the eye gather and 2 at the VPLs): mean luminance within 3% of the
 *    path tracer, and its indirect part (over --gi none's direct light)
 *    within 8% of the path tracer's. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "diag.h"
#include "gi_cl.h"
#include "gi_vpl.h"
#include "glossy.h"
#include "framebuffer.h"
#include "pm_path.h"
#include "render_vpl.h"
#include "rng.h"
#include "test_world.h"

#define NV 4096
#define NP 256

static gi_vpl *g_vpl;
static gi_dev_vpl_point g_pts[NP];
static float *g_tabs;
static int g_ntabs;

/* A point on one of the five walls (no ceiling) of [0,1]^3, inward normal. */
static void wall_point(rng *r, vec3 *p, vec3 *n)
{
    int w = (int)(rng_f64(r) * 5);
    double u = rng_f64(r), v = rng_f64(r);
    switch (w) {
    case 0: *p = v3(u, 0, v); *n = v3(0, 1, 0); break;
    case 1: *p = v3(0, u, v); *n = v3(1, 0, 0); break;
    case 2: *p = v3(1, u, v); *n = v3(-1, 0, 0); break;
    case 3: *p = v3(u, v, 0); *n = v3(0, 0, 1); break;
    default: *p = v3(u, v, 1); *n = v3(0, 0, -1); break;
    }
}

static int setup(void **state)
{
    (void)state;
    rng r;
    rng_seed(&r, 21, 1);
    g_vpl = calloc(NV, sizeof *g_vpl);
    for (int i = 0; i < NV; i++) {
        gi_vpl *v = &g_vpl[i];
        wall_point(&r, &v->p, &v->n);
        v->area = 5.0 / NV;
        /* light falling off from a corner, as from a light there */
        double e = 1.0 / (0.2 + v3_len2(v3_sub(v->p, v3(0.9, 0.9, 0.5))));
        v->ld = (rgb){0.3 * e, 0.25 * e, 0.2 * e};
        if (i % 3 == 0) {
            /* a glossy VPL: lobe about the mirror of the direction to that corner */
            vec3 l = v3_norm(v3_sub(v3(0.9, 0.9, 0.5), v->p));
            v->d = v3_sub(v3_scale(v->n, 2.0 * v3_dot(v->n, l)), l);
            v->kappa = 20.0;
            v->ls = (rgb){0.5 * e, 0.5 * e, 0.5 * e};
        }
    }
    /* two E(mu) tables: exponents 10 and 60 */
    const double ex[2] = {10.0, 60.0};
    g_ntabs = 2;
    g_tabs = calloc((size_t)g_ntabs * GI_VPL_TAB, sizeof(float));
    for (int k = 0; k < 2; k++) {
        const glossy_table *t = glossy_table_for(ex[k]);
        const double *vals = glossy_table_values(t);
        for (int j = 0; j < GI_VPL_TAB - 1; j++) g_tabs[k * GI_VPL_TAB + j] = (float)vals[j];
        g_tabs[k * GI_VPL_TAB + GI_VPL_TAB - 1] = (float)glossy_table_eavg(t);
    }
    for (int i = 0; i < NP; i++) {
        gi_dev_vpl_point *p = &g_pts[i];
        memset(p, 0, sizeof *p);
        vec3 pp, nn;
        wall_point(&r, &pp, &nn);
        pp = v3_madd(pp, nn, 0.01);
        vec3 wo = v3_norm(v3_sub(v3(0.5, 0.5, 1.5), pp));
        if (v3_dot(wo, nn) <= 0.05) wo = nn;
        float *dst[3] = {p->p, p->n, p->wo};
        vec3 src[3] = {pp, nn, wo};
        for (int k = 0; k < 3; k++) {
            dst[k][0] = (float)src[k].x;
            dst[k][1] = (float)src[k].y;
            dst[k][2] = (float)src[k].z;
        }
        p->kd[0] = p->kd[1] = p->kd[2] = 0.5f;
        p->tab[0] = i % 2;
        p->tab[1] = -1;
        p->kg[0][0] = p->kg[0][1] = p->kg[0][2] = 0.4f;
        p->kg[0][3] = (float)ex[i % 2];
    }
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    free(g_vpl);
    free(g_tabs);
    return 0;
}

static void gather(gi_dev *dv, const gi_dev_vpl_node *nodes, int nn, float thr, int mode, float *out, int *visits)
{
    diag *d = diag_new();
    assert_int_equal(gi_dev_vpl_gather(dv, g_pts, NP, nodes, nn, g_tabs, g_ntabs, thr, mode, out, visits, d), PT_OK);
    diag_free(d);
}

static gi_dev *open_dev(const char *spec)
{
    diag *d = diag_new();
    pt_status st;
    gi_dev_options o = {spec, NULL, 2, 0};
    gi_dev *dv = gi_dev_open(&o, d, &st);
    for (int i = 0; st != PT_OK && i < diag_count(d); i++) {
        char *m = diag_format(diag_get(d, i));
        fprintf(stderr, "%s\n", m ? m : "?");
        free(m);
    }
    diag_free(d);
    return st == PT_OK ? dv : NULL;
}

static double mean_lum(const float *out, int per)
{
    double s = 0.0;
    for (int i = 0; i < NP; i++) s += 0.2126 * out[per * i] + 0.7152 * out[per * i + 1] + 0.0722 * out[per * i + 2];
    return s / NP;
}

static void test_tree_exact_and_cuts(void **state)
{
    (void)state;
    gi_vpl_tree *t = gi_vpl_tree_build(g_vpl, NV, sqrt(3.0), 3);
    assert_non_null(t);
    assert_int_equal(gi_vpl_tree_size(t), 2 * NV - 1);
    gi_dev *dv = open_dev("c");
    assert_non_null(dv);
    gi_dev_vpl_node *full, *leaves, *mm;
    int nfull = gi_vpl_tree_cut(t, -1.0, -1.0, &full);
    int nleaf = gi_vpl_tree_leaves(t, &leaves);
    int nmm = gi_vpl_tree_cut(t, 40.0, 9.0, &mm);
    assert_int_equal(nfull, 2 * NV - 1);
    assert_int_equal(nleaf, NV);
    /* filtering keeps the energy: the root's l_s * count = sum of the VPLs' */
    double sls = 0.0;
    for (int i = 0; i < NV; i++) sls += g_vpl[i].ls.r;
    printf("vpl root: l_s * n %.6g, sum of VPLs' l_s %.6g; root exponent %.3f (VPLs 20)\n", full[0].ls[0] * NV, sls,
           full[0].ls[3]);
    assert_true(fabs(full[0].ls[0] * NV / sls - 1.0) < 1e-5);
    assert_true(full[0].ls[3] > 0.0f && full[0].ls[3] < 20.0f);
    for (int mode = GI_VPL_EYE; mode <= GI_VPL_BOUNCE; mode++) {
        int per = mode == GI_VPL_EYE ? 4 : 12;
        float *brute = calloc((size_t)NP * per, sizeof(float)), *o = calloc((size_t)NP * per, sizeof(float));
        int *vb = calloc(NP, sizeof(int)), *vo = calloc(NP, sizeof(int));
        gather(dv, leaves, nleaf, 0.0f, mode, brute, vb);
        /* threshold 0: only leaves accepted, the whole tree walked */
        gather(dv, full, nfull, 0.0f, mode, o, vo);
        double worst = 0.0;
        for (int i = 0; i < NP * per; i++) worst = fmax(worst, fabs(o[i] - brute[i]) / fmax(1e-3, fabs(brute[i])));
        printf("vpl mode %d: full tree at threshold 0 against brute force: worst rel. difference %.2e, visits %d "
               "(nodes %d)\n",
               mode, worst, vo[0], nfull);
        assert_true(worst < 1e-4);
        assert_int_equal(vo[0], nfull);
        double lb = mean_lum(brute, per);
        double vis_full = 0.0, vis_mm = 0.0;
        gather(dv, full, nfull, 0.02f, mode, o, vo);
        double lf = mean_lum(o, per);
        for (int i = 0; i < NP; i++) vis_full += vo[i];
        gather(dv, mm, nmm, 0.02f, mode, o, vo);
        double lm = mean_lum(o, per);
        for (int i = 0; i < NP; i++) vis_mm += vo[i];
        printf("vpl mode %d, threshold 0.02: mean luminance brute %.5f, full tree %.5f (%+.2f%%, %.0f visits), "
               "min-max cut %.5f (%+.2f%%, %.0f visits; array %d nodes)\n",
               mode, lb, lf, 100.0 * (lf / lb - 1.0), vis_full / NP, lm, 100.0 * (lm / lb - 1.0), vis_mm / NP, nmm);
        assert_true(fabs(lf / lb - 1.0) < 0.05);
        assert_true(fabs(lm / lb - 1.0) < 0.05);
        assert_true(vis_full / NP < nfull && vis_mm / NP < vis_full / NP);
        free(brute);
        free(o);
        free(vb);
        free(vo);
    }
    free(full);
    free(leaves);
    free(mm);
    gi_dev_free(dv);
    gi_vpl_tree_free(t);
}

static void test_merge_closed_form(void **state)
{
    (void)state;
    /* two unit-weight lobes 60 degrees apart: |mean d| = cos 30 */
    vec3 a = v3(0, 0, 1), b = v3(sin(M_PI / 3), 0, cos(M_PI / 3)), axis;
    double k;
    gi_vpl_merge_axis(v3_add(a, b), 2.0, 30.0, &axis, &k);
    double dl = cos(M_PI / 6), expect = 30.0 * dl / (dl + 30.0 * (1.0 - dl));
    printf("vpl eq. 4: merged exponent %.6f (closed form %.6f), axis (%.4f, %.4f, %.4f)\n", k, expect, axis.x, axis.y,
           axis.z);
    assert_true(fabs(k - expect) < 1e-9);
    assert_true(fabs(axis.x - sin(M_PI / 6)) < 1e-9 && fabs(axis.z - cos(M_PI / 6)) < 1e-9);
    gi_vpl_merge_axis(v3_scale(a, 3.0), 3.0, 30.0, &axis, &k);
    assert_true(fabs(k - 30.0) < 1e-9); /* equal axes: nothing to filter */
}

static void test_opencl_matches_c(void **state)
{
    (void)state;
    if (!gi_dev_opencl_built()) {
        printf("vpl OpenCL: not built, skipped\n");
        skip();
    }
    gi_dev *cl = open_dev(NULL);
    if (!cl) {
        printf("vpl OpenCL: no device, skipped\n");
        skip();
    }
    gi_dev *c = open_dev("c");
    gi_vpl_tree *t = gi_vpl_tree_build(g_vpl, NV, sqrt(3.0), 3);
    gi_dev_vpl_node *mm;
    int nmm = gi_vpl_tree_cut(t, 40.0, 9.0, &mm);
    for (int mode = GI_VPL_EYE; mode <= GI_VPL_BOUNCE; mode++) {
        int per = mode == GI_VPL_EYE ? 4 : 12;
        float *a = calloc((size_t)NP * per, sizeof(float)), *b = calloc((size_t)NP * per, sizeof(float));
        int *va = calloc(NP, sizeof(int)), *vb = calloc(NP, sizeof(int));
        gather(c, mm, nmm, 0.02f, mode, a, va);
        gather(cl, mm, nmm, 0.02f, mode, b, vb);
        double worst = 0.0;
        int vdiff = 0;
        for (int i = 0; i < NP * per; i++) worst = fmax(worst, fabs(a[i] - b[i]) / fmax(1e-3, fabs(a[i])));
        for (int i = 0; i < NP; i++) vdiff += va[i] != vb[i];
        printf("vpl mode %d: %s against the C build: worst rel. difference %.2e, %d points with other visit counts\n",
               mode, gi_dev_name(cl), worst, vdiff);
        assert_true(worst < 1e-3);
        free(a);
        free(b);
        free(va);
        free(vb);
    }
    free(mm);
    gi_vpl_tree_free(t);
    gi_dev_free(c);
    gi_dev_free(cl);
}

static const char *room =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 radiosity { recursion_limit 3 } }\n"
    "camera { location <0, 2.5, -6> look_at <0, 1.2, 0> angle 60 }\n"
    "#declare W = texture { pigment { rgb 0.7 } finish { ambient 0 diffuse 0.7 } }\n"
    "box { <-4,-0.01,-7>, <4,0,3> texture { W } }\n"
    "box { <-4,0,3>, <4,5,3.01> pigment { rgb <0.8,0.3,0.2> } finish { ambient 0 diffuse 0.7 } }\n"
    "box { <-4.01,0,-7>, <-4,5,3> pigment { rgb <0.2,0.6,0.3> } finish { ambient 0 diffuse 0.7 } }\n"
    "box { <4,0,-7>, <4.01,5,3> texture { W } }\n"
    "box { <-4,5,-7>, <4,5.01,3> texture { W } }\n"
    "box { <-4,0,-7.01>, <4,5,-7> texture { W } }\n"
    "sphere { <-1.3, 1, 0>, 1 pigment { rgb <0.9,0.6,0.3> } finish { ambient 0 diffuse 0.1 specular 0.8 roughness 0.02 metallic 1 } }\n"
    "sphere { <1.3, 1, 0.5>, 1 pigment { rgb 0.8 } finish { ambient 0 diffuse 0.3 phong 0.7 phong_size 20 } }\n"
    "light_source { <1, 4.5, -3> rgb 1 }\n";

static double fb_lum(const framebuffer *fb)
{
    double s = 0.0;
    int n = fb->width * fb->height;
    for (int i = 0; i < n; i++) s += 0.2126 * fb->rgb[3 * i] + 0.7152 * fb->rgb[3 * i + 1] + 0.0722 * fb->rgb[3 * i + 2];
    return s / n;
}

static void test_room_against_path(void **state)
{
    (void)state;
    tu_world w = tu_world_build("vpl_room.pov", room);
    const int W = 32, H = 24;
    framebuffer *fp = fb_new(W, H), *fv = fb_new(W, H), *fd = fb_new(W, H);
    pm_path_settings ps;
    pm_path_default_settings(&ps);
    ps.c.width = W;
    ps.c.height = H;
    ps.c.threads = 2;
    ps.c.spp = 256;
    ps.c.seed = 1;
    assert_int_equal(pm_path_render(w.s, w.a, &ps, fp, NULL, NULL), PT_OK);
    ps.max_depth = 1; /* direct light only: --gi none's */
    ps.c.spp = 16;
    assert_int_equal(pm_path_render(w.s, w.a, &ps, fd, NULL, NULL), PT_OK);
    render_vpl_settings vs;
    render_vpl_default_settings(&vs);
    vs.width = W;
    vs.height = H;
    vs.threads = 2;
    vs.seed = 1;
    vs.vpls = 4096;
    vs.bounces = 2;
    vs.cl_device = "c";
    render_vpl_stats st;
    diag *d = diag_new();
    assert_int_equal(render_vpl(w.s, w.a, &vs, fv, &st, d), PT_OK);
    /* the same VPLs gathered one by one at every pixel */
    framebuffer *fb = fb_new(W, H);
    render_vpl_settings vb = vs;
    vb.cut = RENDER_VPL_BRUTE;
    vb.adaptive = 0;
    assert_int_equal(render_vpl(w.s, w.a, &vb, fb, NULL, d), PT_OK);
    diag_free(d);
    double lp = fb_lum(fp), lv = fb_lum(fv), ld = fb_lum(fd), lb = fb_lum(fb);
    printf("vpl room 32x24: path 256 spp %.5f, direct %.5f; brute-force VPLs %.5f (%+.2f%% of path, indirect x%.3f); "
           "min-max cut + adaptive %.5f (%+.2f%% of brute force); %ld VPLs, %.1f%% pixels gathered, %.0f nodes "
           "visited\n",
           lp, ld, lb, 100.0 * (lb / lp - 1.0), (lb - ld) / (lp - ld), lv, 100.0 * (lv / lb - 1.0), st.vpls,
           100.0 * st.pixels_sampled / (double)(st.pixels_valid > 0 ? st.pixels_valid : 1), st.visits_mean);
    /* the method's own approximations (filtering, cuts, adaptive sampling) */
    assert_true(fabs(lv / lb - 1.0) < 0.03);
    /* against the path tracer: VPLs see no occluders (light reaches the
     * floor under the spheres), +2% to +7% over seeds here */
    assert_true(lb / lp - 1.0 > -0.02 && lb / lp - 1.0 < 0.10);
    assert_true((lb - ld) / (lp - ld) > 0.9);
    fb_free(fb);
    fb_free(fp);
    fb_free(fv);
    fb_free(fd);
    tu_world_free(&w);
}

/* A white glossy sphere under a white sky (the furnace of test_glossy):
 * vpl's sky term (one BSDF sample per eye sample) shows the sky. */
static void test_furnace(void **state)
{
    (void)state;
    tu_world w = tu_world_build("vpl_furnace.pov", "#version 3.7;\n"
                                                   "camera { location <0,0,-3> look_at 0 angle 40 }\n"
                                                   "sky_sphere { pigment { rgb 1 } }\n"
                                                   "sphere { 0, 1 pigment { rgb 1 } finish { ambient 0 diffuse 0.3 "
                                                   "phong 0.7 phong_size 40 } }\n");
    framebuffer *fb = fb_new(16, 12);
    render_vpl_settings vs;
    render_vpl_default_settings(&vs);
    vs.width = 16;
    vs.height = 12;
    vs.threads = 2;
    vs.spp = 64;
    vs.vpls = 1024;
    vs.cl_device = "c";
    diag *d = diag_new();
    assert_int_equal(render_vpl(w.s, w.a, &vs, fb, NULL, d), PT_OK);
    diag_free(d);
    double m = fb_lum(fb);
    printf("vpl furnace (diffuse 0.3 + phong 0.7 under a white sky): mean %.5f (expect 1, tol 0.01)\n", m);
    assert_true(fabs(m - 1.0) < 0.01);
    fb_free(fb);
    tu_world_free(&w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_merge_closed_form),
        cmocka_unit_test(test_tree_exact_and_cuts),
        cmocka_unit_test(test_opencl_matches_c),
        cmocka_unit_test(test_room_against_path),
        cmocka_unit_test(test_furnace),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
