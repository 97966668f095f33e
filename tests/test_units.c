/* test_units.c - photometric units and AOVs (docs/units.md), end to
 * end through the partray binary: a point light of I candela at height d
 * over a white Lambertian plane gives E = I/d^2 lux at the foot (the
 * illuminance AOV, and read back from the false-colour PNG) and luminance
 * L = rho E / pi; the same scene in centimetres gives the same lux; an EXR
 * with --aovs holds every layer with the expected values; parallel lights
 * give their luminance in lux; POV-Ray's own units are unchanged without
 * --units; the path tracer agrees with Whitted under --units; POV-Ray
 * reads the layered EXR. */
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

#include <openexr.h>

#include "diag.h"
#include "framebuffer.h"
#include "img_falsecolor.h"
#include "img_io.h"
#include "lighting_study.h"

static char tmpdir[256];
static char out_text[65536];

static int run_capture(const char *cmd)
{
    char full[4096];
    snprintf(full, sizeof full, "%s 2>&1", cmd);
    FILE *p = popen(full, "r");
    if (!p) return -1;
    size_t n = fread(out_text, 1, sizeof out_text - 1, p);
    out_text[n] = 0;
    int rc = pclose(p);
    return WEXITSTATUS(rc);
}

/* The scene: camera at (0,4,-3)*S looking at the origin (distance 5 S),
 * a light of colour `light` at (0,2,0)*S, a white plane y = 0 with
 * diffuse 1 (rho = 1) and no ambient. S scales every length. */
static void write_scene(const char *name, const char *light)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "#version 3.7;\n"
               "#ifndef (S) #declare S = 1; #end\n"
               "global_settings { assumed_gamma 1.0 }\n"
               "camera { location <0, 4, -3>*S look_at <0, 0, 0> }\n"
               "%s\n"
               "plane { y, 0 pigment { rgb 1 } finish { diffuse 1 ambient 0 } }\n",
            light);
    fclose(f);
}

/* Render scene `name` to `out` (33x33, centre pixel (16,16) sees the
 * origin) with extra options; expects exit 0. */
static void render(const char *name, const char *out, const char *opts)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "'%s' render '%s/%s' -o '%s/%s' --size 33x33 --threads 2 %s", PARTRAY_BIN, tmpdir, name,
             tmpdir, out, opts);
    int rc = run_capture(cmd);
    if (rc != 0) printf("%s\n-> exit %d: %s", cmd, rc, out_text);
    assert_int_equal(rc, 0);
}

/* Channel k (of n) of the layer's pixel (x, y). */
static double layer_px(const char *file, const char *layer, const char *suffixes, int x, int y, int k)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", tmpdir, file);
    diag *d = diag_new();
    float *v = NULL;
    int w = 0, h = 0;
    pt_status st = img_read_exr_layer(path, layer, suffixes, &v, &w, &h, d);
    if (st != PT_OK) printf("reading %s layer %s: %s\n", file, layer, diag_count(d) ? diag_get(d, 0)->text : "?");
    assert_int_equal(st, PT_OK);
    assert_int_equal(w, 33);
    assert_int_equal(h, 33);
    int n = (int)strlen(suffixes);
    double r = v[((size_t)y * 33 + (size_t)x) * (size_t)n + (size_t)k];
    free(v);
    diag_free(d);
    return r;
}

static double y709(double r, double g, double b) { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }

static double layer_y(const char *file, const char *layer, int x, int y)
{
    return y709(layer_px(file, layer, "RGB", x, y, 0), layer_px(file, layer, "RGB", x, y, 1),
                layer_px(file, layer, "RGB", x, y, 2));
}

#define I_CD 100.0
#define D_M 2.0

/* Illuminance I/d^2 at the foot, luminance rho E / pi, in metres. */
static void test_point_light_metres(void **st)
{
    (void)st;
    write_scene("foot.pov", "light_source { <0, 2, 0>*S color rgb 100 }");
    char opts[1024];
    snprintf(opts, sizeof opts, "--float --units m --aovs illuminance,albedo --false-color-quantity illuminance "
             "--false-color-range 1,100 --false-color '%s/foot_fc.png'", tmpdir);
    render("foot.pov", "foot_m.exr", opts);
    const double E = I_CD / (D_M * D_M);
    double e = layer_y("foot_m.exr", "illuminance", 16, 16);
    double l = layer_y("foot_m.exr", NULL, 16, 16);
    double rho = layer_y("foot_m.exr", "albedo", 16, 16);
    printf("point light %g cd at %g m: E = %.4f lx (expected %.4f), L = %.4f cd/m2 (expected rho E/pi = %.4f)\n", I_CD,
           D_M, e, E, l, rho * E / M_PI);
    assert_float_equal(e / E, 1.0, 0.01);
    assert_float_equal(rho, 1.0, 1e-6);
    assert_float_equal(l / (rho * E / M_PI), 1.0, 0.01);
    assert_non_null(strstr(out_text, "illuminance 1 to 100 lx"));

    /* the false-colour PNG, read back through the ramp's inverse */
    char path[512];
    snprintf(path, sizeof path, "%s/foot_fc.png", tmpdir);
    diag *d = diag_new();
    framebuffer *png = NULL;
    assert_int_equal(img_read(path, 1, &png, d), PT_OK);
    assert_true(png->width > 33); /* the legend */
    double dist = 1.0;
    double t = img_fc_unramp(fb_px(png, 16, 16), &dist);
    double v = img_fc_value_at(t, 1.0, 100.0);
    printf("  false-colour PNG at the foot: %.4f lx (%+.2f%%), colour distance %.4f\n", v, 100 * (v / E - 1), dist);
    assert_true(dist < 0.01);
    assert_float_equal(v / E, 1.0, 0.01);
    /* a probe over the 3x3 neighbourhood of the AOV itself */
    float yv[9];
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++) yv[j * 3 + i] = (float)layer_y("foot_m.exr", "illuminance", 15 + i, 15 + j);
    double probe = img_fc_probe(yv, 3, 3, 1, 1, 0);
    assert_float_equal(probe / E, 1.0, 0.01);
    fb_free(png);
    diag_free(d);
}

/* The same scene in centimetres (every length x100) reads the same lux. */
static void test_point_light_centimetres(void **st)
{
    (void)st;
    write_scene("foot.pov", "light_source { <0, 2, 0>*S color rgb 100 }");
    render("foot.pov", "foot_cm.exr", "--float --units cm -D S=100 --aovs illuminance,depth");
    const double E = I_CD / (D_M * D_M);
    double e = layer_y("foot_cm.exr", "illuminance", 16, 16);
    double l = layer_y("foot_cm.exr", NULL, 16, 16);
    double z = layer_px("foot_cm.exr", "depth", "Z", 16, 16, 0);
    printf("same scene in cm: E = %.4f lx, L = %.4f cd/m2, depth %.3f scene units\n", e, l, z);
    assert_float_equal(e / E, 1.0, 0.01);
    assert_float_equal(l / (E / M_PI), 1.0, 0.01);
    assert_float_equal(z / 500.0, 1.0, 1e-4);
    /* a number of metres per unit works as well */
    render("foot.pov", "foot_num.exr", "--float --units 0.01 -D S=100 --aovs illuminance");
    assert_float_equal(layer_y("foot_num.exr", "illuminance", 16, 16) / E, 1.0, 0.01);
}

/* Every layer of --aovs, with its channels and values at the centre pixel. */
static void test_aov_layers(void **st)
{
    (void)st;
    write_scene("foot.pov", "light_source { <0, 2, 0>*S color rgb 100 }");
    render("foot.pov", "aovs.exr", "--units m --aovs direct,indirect,albedo,normal,depth,illuminance");

    /* the channel list, as OpenEXR's own API reports it */
    char path[512];
    snprintf(path, sizeof path, "%s/aovs.exr", tmpdir);
    exr_context_t ctx = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    assert_int_equal(exr_start_read(&ctx, path, &init), EXR_ERR_SUCCESS);
    const exr_attr_chlist_t *chl = NULL;
    assert_int_equal(exr_get_channels(ctx, 0, &chl), EXR_ERR_SUCCESS);
    static const char *const want[] = {"B", "G", "R", "albedo.B", "albedo.G", "albedo.R", "depth.Z", "direct.B",
                                       "direct.G", "direct.R", "illuminance.B", "illuminance.G", "illuminance.R",
                                       "indirect.B", "indirect.G", "indirect.R", "normal.X", "normal.Y", "normal.Z"};
    assert_int_equal(chl->num_channels, (int)(sizeof want / sizeof want[0]));
    for (int i = 0; i < chl->num_channels; i++) {
        assert_string_equal(chl->entries[i].name.str, want[i]);
        /* depth is float even in a half file */
        assert_int_equal(chl->entries[i].pixel_type, strcmp(want[i], "depth.Z") == 0 ? EXR_PIXEL_FLOAT : EXR_PIXEL_HALF);
    }
    float wl = 0;
    assert_int_equal(exr_attr_get_float(ctx, 0, "whiteLuminance", &wl), EXR_ERR_SUCCESS);
    assert_float_equal(wl, 1.0, 0);
    const char *units = NULL;
    assert_int_equal(exr_attr_get_string(ctx, 0, "partray:units", NULL, &units), EXR_ERR_SUCCESS);
    assert_non_null(strstr(units, "cd/m2"));
    exr_finish(&ctx);

    const double E = I_CD / (D_M * D_M);
    double depth = layer_px("aovs.exr", "depth", "Z", 16, 16, 0);
    printf("centre pixel: depth %.5f (camera distance 5)", depth);
    assert_float_equal(depth, 5.0, 1e-4);
    double n[3];
    for (int k = 0; k < 3; k++) n[k] = layer_px("aovs.exr", "normal", "XYZ", 16, 16, k);
    printf(", normal (%.4f %.4f %.4f)", n[0], n[1], n[2]);
    assert_float_equal(n[0], 0.0, 1e-3);
    assert_float_equal(n[1], 1.0, 1e-3);
    assert_float_equal(n[2], 0.0, 1e-3);
    for (int k = 0; k < 3; k++) {
        double b = layer_px("aovs.exr", NULL, "RGB", 16, 16, k);
        double dir = layer_px("aovs.exr", "direct", "RGB", 16, 16, k);
        double ind = layer_px("aovs.exr", "indirect", "RGB", 16, 16, k);
        double alb = layer_px("aovs.exr", "albedo", "RGB", 16, 16, k);
        double il = layer_px("aovs.exr", "illuminance", "RGB", 16, 16, k);
        if (k == 0) printf(", direct %.4f, indirect %.4f, albedo %.4f, illuminance %.4f, beauty %.4f\n", dir, ind, alb, il, b);
        assert_float_equal(alb, 1.0, 1e-3);
        assert_float_equal(ind, 0.0, 0.0); /* gi none */
        assert_float_equal(il / E, 1.0, 0.01);
        assert_float_equal(dir / (E / M_PI), 1.0, 0.01);
        assert_float_equal(dir / b, 1.0, 2e-3); /* no ambient: the beauty is the direct term (half precision) */
    }
    /* a corner sees the plane farther away and lit at a slant: less light, positive depth */
    assert_true(layer_px("aovs.exr", "depth", "Z", 0, 0, 0) > 5.0);
    assert_true(layer_y("aovs.exr", "illuminance", 0, 32) < E);
}

/* The direct AOV shades like the beauty behind a transparent sphere
 * (filtered shadow: 0.6 transmit, pigment <1, .5, .5>). */
static void test_filtered_shadow(void **st)
{
    (void)st;
    write_scene("tr.pov", "light_source { <0, 2, 0>*S color rgb 100 }\n"
                          "sphere { <0, 1, 0>, 0.3 pigment { rgbt <1, 0.5, 0.5, 0.6> } }");
    render("tr.pov", "tr.exr", "--float --units m --aovs direct,illuminance");
    const double E = I_CD / (D_M * D_M);
    for (int k = 0; k < 3; k++) {
        double b = layer_px("tr.exr", NULL, "RGB", 16, 16, k), dir = layer_px("tr.exr", "direct", "RGB", 16, 16, k);
        double il = layer_px("tr.exr", "illuminance", "RGB", 16, 16, k);
        printf("filtered shadow, channel %d: beauty %.4f, direct %.4f, illuminance %.4f of %.4f lx\n", k, b, dir, il, E);
        assert_float_equal(dir / b, 1.0, 1e-4);
        assert_true(il > 0.1 * E && il < 0.95 * E);
        assert_float_equal(il / (M_PI * b), 1.0, 1e-4); /* white Lambertian: E = pi L */
    }
}

/* A parallel light of luminance Y gives Y lux on a surface facing it, at any distance. */
static void test_parallel_light(void **st)
{
    (void)st;
    write_scene("par.pov", "light_source { <0, 7, 0>*S color rgb <10, 20, 5> parallel point_at <0, 0, 0> }");
    render("par.pov", "par.exr", "--float --units m --aovs illuminance");
    double Y = y709(10, 20, 5);
    double e = layer_y("par.exr", "illuminance", 16, 16);
    double l = layer_y("par.exr", NULL, 16, 16);
    printf("parallel light of Y = %.4f: E = %.4f lx, L = %.4f cd/m2\n", Y, e, l);
    assert_float_equal(e / Y, 1.0, 0.01);
    assert_float_equal(l / (Y / M_PI), 1.0, 0.01);
}

/* Without --units nothing changes: a POV-Ray light of colour C on a
 * diffuse-1 white surface shows C cos; the illuminance AOV is pi C cos.
 * fade_distance/fade_power are ignored (with a warning) under --units. */
static void test_povray_units_and_fade(void **st)
{
    (void)st;
    write_scene("pov.pov", "light_source { <0, 2, 0>*S color rgb 1 }");
    render("pov.pov", "pov.exr", "--float --aovs illuminance");
    double l = layer_y("pov.exr", NULL, 16, 16), e = layer_y("pov.exr", "illuminance", 16, 16);
    printf("POV-Ray units: L = %.5f (1), illuminance %.5f (pi)\n", l, e);
    assert_float_equal(l, 1.0, 1e-4);
    assert_float_equal(e, M_PI, 1e-3);

    write_scene("fade.pov", "light_source { <0, 2, 0>*S color rgb 100 fade_distance 1 fade_power 1 }");
    render("fade.pov", "fade.exr", "--float --units m --aovs illuminance");
    assert_non_null(strstr(out_text, "fade_power"));
    assert_non_null(strstr(out_text, "ignored"));
    assert_float_equal(layer_y("fade.exr", "illuminance", 16, 16) / (I_CD / (D_M * D_M)), 1.0, 0.01);
}

/* The reference path tracer sees the same photometric light (its shade_light_nee
 * and shade_light_attenuation): the centre pixel agrees with Whitted. */
static void test_path_agrees(void **st)
{
    (void)st;
    write_scene("foot.pov", "light_source { <0, 2, 0>*S color rgb 100 }");
    render("foot.pov", "path.exr", "--float --units m --gi path --spp 4 --quiet");
    double l = layer_y("path.exr", NULL, 16, 16);
    printf("path tracer, centre pixel: L = %.4f cd/m2 (rho E/pi = %.4f)\n", l, I_CD / (D_M * D_M) / M_PI);
    assert_float_equal(l / (I_CD / (D_M * D_M) / M_PI), 1.0, 0.02);
}

/* POV-Ray 3.7 (OpenEXR's C++ library) reads an EXR with AOV layers: an
 * image_map of it, rendered by POV-Ray to EXR with ambient 1, gives back
 * the beauty. Skipped without `povray`. */
static void test_povray_reads_layers(void **st)
{
    (void)st;
    if (system("command -v povray >/dev/null 2>&1") != 0) {
        printf("povray not found: skipped\n");
        skip();
    }
    write_scene("foot.pov", "light_source { <0, 2, 0>*S color rgb 100 }");
    render("foot.pov", "layers.exr", "--units m --aovs all");
    char path[512], cmd[2048];
    snprintf(path, sizeof path, "%s/readback.pov", tmpdir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
               "camera { orthographic location <0.5, 0.5, -1> look_at <0.5, 0.5, 0> right x up y }\n"
               "plane { z, 0 pigment { image_map { exr \"layers.exr\" } } finish { ambient 1 diffuse 0 } }\n");
    fclose(f);
    snprintf(cmd, sizeof cmd, "cd '%s' && povray +Ireadback.pov +Oreadback.exr +W33 +H33 -D -V -GA +FE -A +WT2", tmpdir);
    int rc = run_capture(cmd);
    if (rc != 0) printf("%s", out_text);
    assert_int_equal(rc, 0);
    double worst = 0;
    for (int y = 0; y < 33; y += 4)
        for (int x = 0; x < 33; x += 4) {
            double a = layer_px("layers.exr", NULL, "RGB", x, y, 1), b = layer_px("readback.exr", NULL, "RGB", x, y, 1);
            worst = fmax(worst, fabs(a - b) / fmax(a, 1e-3));
        }
    printf("POV-Ray's read of the layered EXR: worst relative difference %.2e\n", worst);
    assert_true(worst < 2e-3);
}

/* Option parsing (lighting_study.h) and usage errors from the command line. */
static void test_options(void **st)
{
    (void)st;
    double m = 0;
    assert_true(lighting_parse_units("cm", &m));
    assert_float_equal(m, 0.01, 0);
    assert_true(lighting_parse_units("ft", &m));
    assert_float_equal(m, 0.3048, 0);
    assert_true(lighting_parse_units("2.5", &m));
    assert_float_equal(m, 2.5, 0);
    assert_false(lighting_parse_units("-1", &m));
    assert_false(lighting_parse_units("parsec", &m));
    diag *d = diag_new();
    lighting_study ls;
    assert_int_equal(lighting_setup(&ls, NULL, "depth,normal", NULL, d), PT_OK);
    assert_int_equal(ls.aov_mask, (1u << AOV_DEPTH) | (1u << AOV_NORMAL));
    assert_int_equal(lighting_setup(&ls, NULL, "all", "illuminance", d), PT_OK);
    assert_int_equal(ls.aov_mask, (1u << AOV_COUNT) - 1u);
    assert_int_equal(lighting_setup(&ls, NULL, "depth,nromal", NULL, d), PT_ERR_USAGE);
    assert_int_equal(lighting_setup(&ls, "furlong", NULL, NULL, d), PT_ERR_USAGE);
    assert_int_equal(lighting_setup(&ls, NULL, NULL, "brightness", d), PT_ERR_USAGE);
    diag_free(d);
    write_scene("foot.pov", "light_source { <0, 2, 0>*S color rgb 100 }");
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "'%s' render '%s/foot.pov' -o '%s/x.exr' --aovs depth,bogus", PARTRAY_BIN, tmpdir, tmpdir);
    assert_int_equal(run_capture(cmd), 2);
    assert_non_null(strstr(out_text, "bogus"));
    snprintf(cmd, sizeof cmd, "'%s' render '%s/foot.pov' -o '%s/x.exr' --units 0", PARTRAY_BIN, tmpdir, tmpdir);
    assert_int_equal(run_capture(cmd), 2);
}

static int setup(void **st)
{
    (void)st;
    snprintf(tmpdir, sizeof tmpdir, "/tmp/pt_test_units_XXXXXX");
    return mkdtemp(tmpdir) ? 0 : -1;
}

static int teardown(void **st)
{
    (void)st;
    char cmd[512];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    return system(cmd) == 0 ? 0 : -1;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_point_light_metres),   cmocka_unit_test(test_point_light_centimetres),
        cmocka_unit_test(test_aov_layers),           cmocka_unit_test(test_parallel_light),
        cmocka_unit_test(test_filtered_shadow),
        cmocka_unit_test(test_povray_units_and_fade), cmocka_unit_test(test_path_agrees),
        cmocka_unit_test(test_povray_reads_layers),  cmocka_unit_test(test_options),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
