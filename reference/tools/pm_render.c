/* pm_render.c - standalone driver for the reference renderers,
 * until `partray render --gi path|pmfg` is wired: parse a scene, build the
 * Embree scene, render with the path tracer or photon map + final gather,
 * write the image (progressively during long renders, atomically through
 * img_write), print stage times and counts as JSON.
 *
 *   pm_render SCENE.pov -o OUT.exr [--gi path|pmfg] [--size WxH] [--spp N]
 *             [--fg-rays N] [--photons N] [--max-depth N] [--caustics on|off]
 *             [--threads N] [--seed N] [--interval S] [--stats FILE.json]
 *             [-D NAME=VALUE] [-L DIR] [--quiet]
 *
 * This is an application-level tool (it links the parser and io), not part
 * of pt_reference. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "accel.h"
#include "img_io.h"
#include "pm.h"
#include "pm_fg.h"
#include "pm_path.h"
#include "sdl.h"
#include "timer.h"

typedef struct {
    const char *out;
    int quiet;
} out_ctx;

static void on_image(void *ctx, const framebuffer *fb, int done, int total)
{
    out_ctx *o = ctx;
    img_write_opts wo;
    img_default_write_opts(&wo);
    diag *d = diag_new();
    if (img_write(o->out, fb, &wo, d) == PT_OK && !o->quiet)
        fprintf(stderr, "\rpm_render: %d/%d samples written to %s\n", done, total, o->out);
    diag_free(d);
}

static void on_progress(void *ctx, double f)
{
    (void)ctx;
    int w = 40, n = (int)(f * w + 0.5);
    fprintf(stderr, "\r[");
    for (int i = 0; i < w; i++) fputc(i < n ? '#' : '.', stderr);
    fprintf(stderr, "] %5.1f%%", 100.0 * f);
    if (f >= 1.0) fputc('\n', stderr);
    fflush(stderr);
}

static void usage(void)
{
    fprintf(stderr, "usage: pm_render SCENE.pov -o OUT.exr [--gi path|pmfg] [--size WxH] [--spp N] [--fg-rays N]\n"
                    "                 [--photons N] [--max-depth N] [--caustics on|off] [--threads N] [--seed N]\n"
                    "                 [--interval S] [--stats FILE.json] [-D NAME=VALUE] [-L DIR] [--quiet]\n");
}

static void print_stats(FILE *f, const char *gi, const pm_stats *st, double t_parse, double t_accel, int w, int h)
{
    fprintf(f,
            "{\"gi\": \"%s\", \"width\": %d, \"height\": %d, \"spp\": %d, \"threads\": %d,\n"
            " \"timings\": {\"parse\": %.4f, \"accel\": %.4f, \"lights\": %.4f, \"photons\": %.4f, \"maps\": %.4f,"
            " \"irradiance\": %.4f, \"render\": %.4f, \"total\": %.4f},\n"
            " \"rays\": %ld, \"camera_rays\": %ld, \"bsdf_rays\": %ld, \"gather_rays\": %ld, \"shadow_rays\": %ld,"
            " \"photon_rays\": %ld,\n"
            " \"photons_emitted\": %ld, \"photons_global\": %ld, \"photons_caustic\": %ld, \"irradiance_points\": %ld,"
            " \"caustic_map\": %d, \"caustic_reason\": \"%s\",\n"
            " \"gather_points\": %ld, \"emitter_pieces\": %ld, \"samples\": %ld, \"discarded_samples\": %ld,"
            " \"unsupported\": %ld, \"passes\": %d}\n",
            gi, w, h, st->spp, st->threads, t_parse, t_accel, st->t_lights, st->t_photons, st->t_maps, st->t_irradiance,
            st->t_render, st->t_total,
            st->camera_rays + st->bsdf_rays + st->gather_rays + st->shadow_rays + st->photon_rays, st->camera_rays,
            st->bsdf_rays, st->gather_rays, st->shadow_rays, st->photon_rays, st->photons_emitted, st->photons_global,
            st->photons_caustic, st->irradiance_points, st->caustic_map, st->caustic_reason ? st->caustic_reason : "",
            st->gather_points, st->emitter_pieces, st->samples, st->discarded_samples, st->unsupported, st->passes);
}

int main(int argc, char **argv)
{
    const char *scene_path = NULL, *out = NULL, *gi = "path", *stats = NULL;
    int w = 320, h = 240, spp = -1, fg = -1, threads = 0, max_depth = -1, caustics = -1, quiet = 0;
    long photons = -1;
    unsigned long long seed = 0;
    double interval = 10.0;
    const char *defs[64], *libs[64];
    int ndefs = 0, nlibs = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "-o") && v) out = argv[++i];
        else if (!strcmp(a, "--gi") && v) gi = argv[++i];
        else if (!strcmp(a, "--size") && v) { if (sscanf(argv[++i], "%dx%d", &w, &h) != 2) { usage(); return 2; } }
        else if (!strcmp(a, "--spp") && v) spp = atoi(argv[++i]);
        else if (!strcmp(a, "--fg-rays") && v) fg = atoi(argv[++i]);
        else if (!strcmp(a, "--photons") && v) photons = atol(argv[++i]);
        else if (!strcmp(a, "--max-depth") && v) max_depth = atoi(argv[++i]);
        else if (!strcmp(a, "--caustics") && v) caustics = !strcmp(argv[++i], "on");
        else if (!strcmp(a, "--threads") && v) threads = atoi(argv[++i]);
        else if (!strcmp(a, "--seed") && v) seed = strtoull(argv[++i], NULL, 10);
        else if (!strcmp(a, "--interval") && v) interval = atof(argv[++i]);
        else if (!strcmp(a, "--stats") && v) stats = argv[++i];
        else if (!strcmp(a, "-D") && v && ndefs < 64) defs[ndefs++] = argv[++i];
        else if (!strcmp(a, "-L") && v && nlibs < 64) libs[nlibs++] = argv[++i];
        else if (!strcmp(a, "--quiet")) quiet = 1;
        else if (a[0] != '-' && !scene_path) scene_path = a;
        else { usage(); return 2; }
    }
    if (!scene_path || !out || w <= 0 || h <= 0 || (strcmp(gi, "path") && strcmp(gi, "pmfg"))) {
        usage();
        return 2;
    }
    if (img_format_from_path(out) == IMG_FMT_UNKNOWN) {
        fprintf(stderr, "pm_render: unknown output format '%s'\n", out);
        return 2;
    }
    sdl_options so;
    sdl_default_options(&so);
    so.defines = defs;
    so.ndefines = ndefs;
    so.lib_paths = libs;
    so.nlib_paths = nlibs;
    so.image_width = w;
    so.image_height = h;
    diag *d = diag_new();
    scene *sc = NULL;
    double t0 = timer_now();
    pt_status st = sdl_parse_file(scene_path, &so, &sc, d);
    double t_parse = timer_now() - t0;
    int rc = 0;
    accel *acc = NULL;
    framebuffer *fb = NULL;
    pm_stats ps;
    memset(&ps, 0, sizeof ps);
    double t_accel = 0.0;
    if (st == PT_OK) {
        t0 = timer_now();
        acc = accel_build(sc, threads, d, &st);
        t_accel = timer_now() - t0;
    }
    if (st == PT_OK && acc) {
        fb = fb_new(w, h);
        out_ctx oc = {out, quiet};
        pm_common common;
        pm_common_defaults(&common);
        common.width = w;
        common.height = h;
        common.threads = threads;
        common.seed = seed;
        common.on_image = on_image;
        common.image_ctx = &oc;
        common.image_interval = interval;
        if (!quiet && isatty(2)) common.on_progress = on_progress;
        if (!strcmp(gi, "path")) {
            pm_path_settings s;
            pm_path_default_settings(&s);
            common.spp = spp > 0 ? spp : s.c.spp;
            s.c = common;
            if (max_depth >= 0) s.max_depth = max_depth;
            st = fb ? pm_path_render(sc, acc, &s, fb, &ps, d) : PT_ERR_NOMEM;
        } else {
            pm_fg_settings s;
            pm_fg_default_settings(&s);
            common.spp = spp > 0 ? spp : s.c.spp;
            s.c = common;
            if (fg > 0) s.fg_rays = fg;
            if (photons >= 0) s.photons = photons;
            if (caustics >= 0) s.caustics = caustics;
            st = fb ? pm_fg_render(sc, acc, &s, fb, &ps, d) : PT_ERR_NOMEM;
        }
    }
    for (int i = 0; i < diag_count(d); i++) {
        char *m = diag_format(diag_get(d, i));
        if (m && (!quiet || diag_get(d, i)->severity == DIAG_ERROR)) fprintf(stderr, "%s\n", m);
        free(m);
    }
    if (st != PT_OK) {
        fprintf(stderr, "pm_render: %s\n", pt_status_name(st));
        rc = st == PT_ERR_IO ? 3 : 1;
    } else {
        img_write_opts wo;
        img_default_write_opts(&wo);
        if (img_write(out, fb, &wo, d) != PT_OK) {
            fprintf(stderr, "pm_render: cannot write %s\n", out);
            rc = 3;
        }
        if (stats) {
            FILE *f = !strcmp(stats, "-") ? stdout : fopen(stats, "w");
            if (f) {
                print_stats(f, gi, &ps, t_parse, t_accel, w, h);
                if (f != stdout) fclose(f);
            }
        }
        if (!quiet) print_stats(stderr, gi, &ps, t_parse, t_accel, w, h);
    }
    fb_free(fb);
    accel_free(acc);
    scene_free(sc);
    diag_free(d);
    return rc;
}
