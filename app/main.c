/* main.c - the `partray` command: render, parse, compare, sweep, crosscheck,
 * view. Exit codes: cli.h (CLI_EXIT_*), one list for every command. */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "accel.h"
#include "cli.h"
#include "cmd_compare.h"
#include "cmd_crosscheck.h"
#include "cmd_farm.h"
#include "cmd_merge.h"
#include "cmd_sweep.h"
#include "diag.h"
#include "framebuffer.h"
#include "gi.h"
#include "hash.h"
#include "img_falsecolor.h"
#include "img_io.h"
#include "img_ocio.h"
#include "ini.h"
#include "lighting_study.h"
#include "pipeline.h"
#include "pool.h"
#include "progress.h"
#include "progress_bar.h"
#include "render_gi.h"
#include "scene.h"
#include "sdl.h"
#include "shade.h"
#include "shade_aov.h"
#include "stats_json.h"
#include "timer.h"
#include "view.h"

#ifndef PARTRAY_VERSION
#define PARTRAY_VERSION "0.0.0"
#endif

enum {
    EXIT_OK = CLI_EXIT_OK,
    EXIT_SCENE = CLI_EXIT_SCENE,
    EXIT_USAGE = CLI_EXIT_USAGE,
    EXIT_IO = CLI_EXIT_IO,
    EXIT_INTERRUPTED = CLI_EXIT_INTERRUPTED
};

static volatile int g_cancel = 0;

/* SIGINT or SIGTERM: the render stops within a tile row; g_cancel keeps
 * the signal number for the exit code (128 + signal: 130, 143). */
static void on_sigint(int sig)
{
    g_cancel = sig > 0 ? sig : SIGINT;
}

static const char *usage_text =
    "usage:\n"
    "  partray render SCENE.pov [-o OUT.exr|.png|.pfm]... [--size WxH] [--gi MODE] [--spp N]\n"
    "                 [--threads N] [--seed N] [--stats FILE.json] [-D NAME=VALUE] [-L DIR]\n"
    "                 [--float] [--exr-compression none|zip|piz] [--png16]\n"
    "                 [--display NAME] [--view NAME] [--look NAME] [--exposure STOPS]\n"
    "                 [--working-space NAME] [--ocio-config FILE] [--false-color OUT.png]\n"
    "                 [--false-color-range LO,HI] [--false-color-quantity luminance|illuminance]\n"
    "                 [--aovs direct,indirect,albedo,normal,depth,illuminance] [--units m|cm|mm|ft|METRES]\n"
    "                 [--particles N] [--nb N] [--cl-device NAME] [--cl-max-memory MIB]\n"
    "                 [--fg-rays N] [--photons N] [--max-depth N]\n"
    "                 [--max-loop N] [--max-include-depth N] [--max-macro-depth N]\n"
    "                 [--max-tokens N] [--max-memory MIB] [--max-string BYTES] [--max-array N]\n"
    "                 [--max-image-pixels N]\n"
    "                 [+W640 +H480 +A0.3 +R3 +Oout.png +Iscene.pov +Ldir ...]\n"
    "                 [--clock V | +KV] [+KFIn +KFFn +KIv +KFv +KC] [--frame N | +SFn +EFn]\n"
    "  partray parse SCENE.pov [-D NAME=VALUE] [-L DIR] [--clock V] [frame options as render]\n"
    "  partray compare REF TEST [--heatmap OUT.png] [--json]\n"
    "  partray merge OUT.exr TILE.exr...   # tiles of a frame (render windows) into one image\n"
    "  partray farm SCENE.pov|anim.ini [render options] -o OUT --dir DIR [--tiles N] [--engine parallel|slurm]\n"
    "  partray sweep SCENE.pov --ref REF.exr [--gi MODE[,MODE...]] --vary [MODE/]KEY=v1,v2,... [--out DIR]\n"
    "                [--size WxH] [--metric relmse|rmse|flip|psnr|ssim] [--time total|render|wall] [render options]\n"
    "  partray crosscheck SCENE.pov [--size WxH] [+A0.3] [--threads N] [--out DIR] [--json] [--povray PATH]\n"
    "  partray view SCENE.pov\n"
    "  partray --help | --version\n"
    "\n"
    "\n"
    "GI modes: none (direct light + Whitted), particle, pmfg, path.\n"
    "Without --gi a scene with radiosity{} asks for particle GI, otherwise none.\n"
    "`partray COMMAND --help` lists a command's options; docs/guide.md is the user guide.\n";

static int status_exit(pt_status st) { return cli_exit_status(st); }

static void fill_sdl_options(sdl_options *so, const cli_render *o, const anim_plan *plan, int frame)
{
    pipeline_sdl_options(so, o, o->width > 0 ? o->width : 320, o->height > 0 ? o->height : 240);
    cli_frame_options(o, plan, frame, so);
}

/* The image size must fit what the writers accept and the memory there is:
 * refused before parsing, so a long render is never lost at the end. The
 * framebuffer is 12 bytes a pixel; writing a PNG or converting colours
 * makes a second copy. Returns 0 and prints why when not. */
static int check_image_size(int w, int h, unsigned long long limit)
{
    if (w > IMG_MAX_SIDE || h > IMG_MAX_SIDE) {
        fprintf(stderr, "partray render: image size %dx%d: a side is larger than %d pixels\n", w, h, IMG_MAX_SIDE);
        return 0;
    }
    unsigned long long px = (unsigned long long)w * (unsigned long long)h;
    if (limit == 0 || limit > IMG_MAX_PIXELS) limit = IMG_MAX_PIXELS;
    if (px > limit) {
        fprintf(stderr, "partray render: image size %dx%d: %llu pixels, more than the %llu an image may have%s\n", w, h, px,
                limit, limit < IMG_MAX_PIXELS ? " (--max-image-pixels)" : "");
        return 0;
    }
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    double need = (double)px * 2.0 * 3.0 * sizeof(float);
    double have = pages > 0 && page > 0 ? (double)pages * (double)page : 0.0;
    if (have > 0 && need > have) {
        fprintf(stderr, "partray render: image size %dx%d needs %.1f GiB for its framebuffers, more than the %.1f GiB of memory\n",
                w, h, need / (1 << 30), have / (1 << 30));
        return 0;
    }
    return 1;
}

/* The render options after INI files are expanded (ini.h); warnings
 * printed. Returns 0, -1 when --help was asked for (help and the exit
 * codes printed), or the exit code. *ia keeps o's strings alive. */
static int read_options(const char *cmd, const char *help, int argc, char **argv, cli_render *o, ini_args **ia)
{
    if (cli_wants_help(argc, argv)) {
        fputs(help, stdout);
        fputs(cli_exit_codes, stdout);
        return -1;
    }
    diag *d = diag_new();
    pt_status st = ini_expand(argc, argv, ia, d);
    cli_print_diags(d, 0, 0);
    diag_free(d);
    if (st != PT_OK) return st == PT_ERR_IO ? EXIT_IO : EXIT_USAGE;
    char err[512];
    if (cli_parse_render(ini_argc(*ia), ini_argv(*ia), o, err, sizeof err)) {
        if (strcmp(cmd, "parse") == 0) fprintf(stderr, "partray parse: %s\n%s", err, cli_parse_help);
        else fprintf(stderr, "partray %s: %s\n(partray %s --help lists the options)\n", cmd, err, cmd);
        ini_free(*ia);
        *ia = NULL;
        return EXIT_USAGE;
    }
    return 0;
}

static int cmd_parse(int argc, char **argv)
{
    cli_render o;
    ini_args *ia = NULL;
    int rc = read_options("parse", cli_parse_help, argc, argv, &o, &ia);
    if (rc) return rc < 0 ? EXIT_OK : rc;
    anim_plan plan;
    char err[256];
    cli_frames(&o, &plan, err, sizeof err); /* checked by cli_parse_render */
    for (int f = plan.first; f <= plan.last && rc == EXIT_OK; f++) {
        sdl_options so;
        fill_sdl_options(&so, &o, &plan, f);
        pbar *bar = pbar_start(o.quiet);
        so.progress = pbar_progress(bar);
        diag *d = diag_new();
        diag_set_sink(d, pbar_diag_sink, bar); /* #debug text as the parse produces it */
        scene *sc = NULL;
        double t_parse = 0.0;
        pt_status st = pipeline_parse(o.scene, &so, &sc, d, &t_parse);
        pbar_stop(bar);
        diag_free(d);
        pbar_free(bar);
        if (st != PT_OK) {
            rc = status_exit(st);
            break;
        }
        scene_counts c = scene_count(sc);
        char frame[32] = "";
        if (plan.animated) snprintf(frame, sizeof frame, " frame %d", f);
        printf("%s%s: %ld objects (%ld CSG nodes), %ld lights, %ld triangles in %ld meshes, %ld unsupported, %d files, %.3f s\n",
               o.scene, frame, c.objects, c.csg, c.lights, c.triangles, c.meshes, c.unsupported, sc->nfiles, t_parse);
        scene_free(sc);
    }
    ini_free(ia);
    return rc;
}

/* "out.png" -> "out.partial.png" */
static char *partial_name(const char *path)
{
    size_t n = strlen(path);
    char *s = malloc(n + 16);
    if (!s) return NULL;
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash)) {
        snprintf(s, n + 16, "%s.partial", path);
    } else {
        size_t stem = (size_t)(dot - path);
        memcpy(s, path, stem);
        snprintf(s + stem, n + 16 - stem, ".partial%s", dot);
    }
    return s;
}

static char *default_output(const char *scene_path)
{
    const char *base = strrchr(scene_path, '/');
    base = base ? base + 1 : scene_path;
    size_t n = strlen(base);
    char *s = malloc(n + 8);
    if (!s) return NULL;
    memcpy(s, base, n + 1);
    char *dot = strrchr(s, '.');
    if (dot) *dot = 0;
    strcat(s, ".png");
    return s;
}

/* False-colour image of the render's luminance (Rec.709 Y of the linear
 * values) or of the illuminance AOV (log scale, legend with values):
 * cd/m^2 and lux under --units (docs/units.md), relative values otherwise. */
static int write_false_color(const cli_render *o, const framebuffer *fb, const lighting_study *ls)
{
    diag *d = diag_new();
    float *y = lighting_fc_values(ls, fb);
    framebuffer *out = NULL;
    double lo = 0, hi = 0;
    img_fc_opts fo;
    img_fc_default_opts(&fo);
    fo.lo = o->fc_lo;
    fo.hi = o->fc_hi;
    fo.unit = lighting_fc_unit(ls);
    pt_status st = y ? img_falsecolor(y, fb->width, fb->height, &fo, &out, &lo, &hi, d) : PT_ERR_NOMEM;
    if (st == PT_OK) st = img_write(o->false_color, out, NULL, d);
    if (st == PT_OK && !o->quiet) fprintf(stderr, "partray: false colour %s, %s %.4g to %.4g %s%s(log scale)\n", o->false_color,
                                          lighting_fc_name(ls), lo, hi, fo.unit ? fo.unit : "", fo.unit ? " " : "");
    cli_print_diags(d, 0, 0);
    diag_free(d);
    free(y);
    fb_free(out);
    return status_exit(st);
}

/* Particle GI kept from one frame of an animation to the next: the scene
 * and accel its geometry stage was built from, and the hashes of the
 * stages' inputs it was built with (stage_hashes). */
typedef struct {
    scene *sc;
    accel *acc;
    gi_particle *gp;
    uint64_t h_geom, h_light;
} gi_keep;

static void gi_keep_free(gi_keep *k)
{
    gi_particle_free(k->gp);
    accel_free(k->acc);
    scene_free(k->sc);
    memset(k, 0, sizeof *k);
}

#define FNV(h, field) pt_fnv1a((h), &(field), sizeof(field))

/* The hashes of the GI stages' inputs in the IR.
 *  - geometry (and everything else but the camera and the lights: objects,
 *    materials, media, global settings): the bytes of every file the parse
 *    read (scene.input_hash) and the options, which are the same in every
 *    frame of one run, and the frame
 *    number when the parser saw a per-frame value read outside camera{} and
 *    light_source{} (sdl_options.frame_dependent), when a light carries
 *    geometry (looks_like, projected_through) or the camera does (normal,
 *    mesh_camera); and the number of lights (the lighting stage edits
 *    lights in place);
 *  - lighting: every light's fields;
 *  - view: the camera, which the view stage always takes as given (an
 *    animation's geometry stage looks from its initial frame's camera
 *    whatever the frame: geometry_camera).
 * Returns 1 when h_geom holds the frame number. */
static int stage_hashes(const scene *sc, int frame_dependent, int frame, uint64_t *h_geom, uint64_t *h_light)
{
    uint64_t g = PT_FNV1A_BASIS, l = g;
    int dep = frame_dependent || sc->camera.normal || sc->camera.nmeshes > 0;
    for (int i = 0; i < sc->nlights; i++) {
        const scene_light *li = &sc->lights[i];
        if (li->looks_like || li->projected_through) dep = 1;
        l = FNV(l, li->kind);
        l = FNV(l, li->position);
        l = FNV(l, li->colour);
        l = FNV(l, li->point_at);
        l = FNV(l, li->radius);
        l = FNV(l, li->falloff);
        l = FNV(l, li->tightness);
        l = FNV(l, li->parallel);
        l = FNV(l, li->area);
        l = FNV(l, li->axis1);
        l = FNV(l, li->axis2);
        l = FNV(l, li->size1);
        l = FNV(l, li->size2);
        l = FNV(l, li->adaptive);
        l = FNV(l, li->jitter);
        l = FNV(l, li->circular);
        l = FNV(l, li->orient);
        l = FNV(l, li->area_illumination);
        l = FNV(l, li->fade_distance);
        l = FNV(l, li->fade_power);
        l = FNV(l, li->shadowless);
        l = FNV(l, li->media_interaction);
        l = FNV(l, li->media_attenuation);
        l = FNV(l, li->group);
    }
    g = FNV(g, sc->input_hash);
    g = FNV(g, sc->nlights);
    if (dep) g = FNV(g, frame);
    *h_geom = g;
    *h_light = l ^ g;
    return dep;
}

/* The key a GI cache is checked against (--gi-cache, gi_particle_save):
 * the geometry stage's inputs as stage_hashes sees them, and what one run
 * keeps the same from frame to frame but another process may not: the
 * declarations (-D, Declare=), the image size (image_width and
 * image_height are scene values), the animation values when the scene read
 * them outside the camera and lights, the camera the geometry stage looks
 * from (cam: the surfaces' sides and clip box, the particles placed by the
 * view, the pruning; its projection, not its pointers or focal blur), and
 * this partray's version. The GI settings are checked by the cache
 * itself. */
static uint64_t gi_cache_key(uint64_t h_geom, const sdl_options *so, int frame_dependent, const scene_camera *cam)
{
    uint64_t k = FNV(PT_FNV1A_BASIS, h_geom);
    for (int i = 0; i < so->ndefines; i++) k = pt_fnv1a(k, so->defines[i], strlen(so->defines[i]) + 1);
    k = FNV(k, so->image_width);
    k = FNV(k, so->image_height);
    if (frame_dependent) {
        k = FNV(k, so->clock);
        k = FNV(k, so->clock_delta);
        k = FNV(k, so->frame_number);
    }
    if (cam) {
        k = FNV(k, cam->kind);
        k = FNV(k, cam->cylinder_type);
        k = FNV(k, cam->location);
        k = FNV(k, cam->direction);
        k = FNV(k, cam->up);
        k = FNV(k, cam->right);
        k = FNV(k, cam->sky);
        k = FNV(k, cam->look_at);
        k = FNV(k, cam->angle);
        k = FNV(k, cam->v_angle);
    }
    return pt_fnv1a(k, PARTRAY_VERSION, strlen(PARTRAY_VERSION));
}

/* What stays the same from frame to frame of one `partray render`. */
typedef struct {
    cli_render *o;
    img_ocio *oc;
    lighting_study *ls;
    int win[4];             /* the render window (cli_window) */
    int tile;               /* 1: a window smaller than the image was asked for */
    double t_start;
    gi_keep keep;           /* particle GI of the previous frame */
    scene_camera geo_cam;   /* an animation's initial frame's camera, pointers cleared (geometry_camera) */
    int have_geo_cam;
    render_gi_kept *kept;   /* --gi detp, links: the work of the previous frame */
    uint64_t kept_h_geom, kept_l; /* and the stage hashes (stage_hashes) of that frame */
} render_run;

/* A copy of fb with straight alpha: colour / alpha where alpha > 0. */
static framebuffer *straight_alpha(const framebuffer *fb)
{
    framebuffer *c = fb_new(fb->width, fb->height);
    if (!c) return NULL;
    size_t n = (size_t)fb->width * (size_t)fb->height;
    c->alpha = malloc(sizeof(float) * n);
    if (!c->alpha) {
        fb_free(c);
        return NULL;
    }
    memcpy(c->alpha, fb->alpha, sizeof(float) * n);
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) c->rgb[i * 3 + k] = fb->alpha[i] > 0 ? fb->rgb[i * 3 + k] / fb->alpha[i] : fb->rgb[i * 3 + k];
    return c;
}

/* The camera an animation's particle GI geometry stage looks from in every
 * frame when its geometry is the same in all of them (stage_hashes without
 * the frame): the initial frame's (+KFI), so that a frame's GI is the same
 * whether an earlier frame of the run built it or the frame is rendered
 * alone (--frame N, a farm task). sc: this frame's scene (frame `frame`);
 * another frame parses the scene at +KFI once. Its pointers (camera
 * normal, mesh camera) are cleared: the stage's probe rays go through the
 * pixel centres of the plain projection. NULL: the scene's own camera (a
 * still, a mesh camera, or the initial frame failed to parse: an error in
 * d and *st). */
static const scene_camera *geometry_camera(render_run *run, const anim_plan *plan, int frame, const scene *sc, diag *d,
                                           pt_status *st)
{
    if (!plan->animated || sc->camera.kind == CAMERA_MESH) return NULL;
    if (!run->have_geo_cam) {
        if (frame == plan->initial_frame) {
            run->geo_cam = sc->camera;
        } else {
            sdl_options so;
            fill_sdl_options(&so, run->o, plan, plan->initial_frame);
            diag *pd = diag_new(); /* the scene's #debug text was shown by this frame's parse */
            scene *s0 = NULL;
            *st = pipeline_parse(run->o->scene, &so, &s0, pd, NULL);
            if (*st != PT_OK) {
                for (int i = 0; i < diag_count(pd); i++) {
                    const diag_msg *m = diag_get(pd, i);
                    if (m->severity == DIAG_ERROR) diag_report(d, DIAG_ERROR, m->loc, NULL, "%s", m->text);
                }
                diag_free(pd);
                return NULL;
            }
            diag_free(pd);
            run->geo_cam = s0->camera;
            scene_free(s0);
        }
        run->geo_cam.normal = NULL;
        run->geo_cam.meshes = NULL;
        run->geo_cam.nmeshes = 0;
        run->have_geo_cam = 1;
    }
    return &run->geo_cam;
}

/* Frame `frame` of the plan (a still: frame 0), written to outputs[]. */
static int render_frame(render_run *run, const anim_plan *plan, int frame, char **outputs, int noutputs)
{
    cli_render *o = run->o;
    lighting_study *ls = run->ls;
    double t_frame = timer_now();
    sdl_options so;
    fill_sdl_options(&so, o, plan, frame);
    /* Progress of every stage, drawn by its own thread; the scene's
     * messages (#debug, #warning, errors) print as they are recorded. */
    pbar *bar = pbar_start(o->quiet);
    progress *prog = pbar_progress(bar);
    so.progress = prog;
    int frame_dependent = 1;
    so.frame_dependent = &frame_dependent;
    diag *d = diag_new();
    diag_set_sink(d, pbar_diag_sink, bar);
    scene *sc = NULL;
    double t_parse = 0.0;
    pt_status st = pipeline_parse(o->scene, &so, &sc, d, &t_parse);
    if (st != PT_OK) {
        diag_free(d);
        pbar_free(bar);
        return status_exit(st);
    }
    lighting_apply_units(ls, sc, d); /* photometric lights; warns about fade */
    /* below +Q9 POV-Ray turns radiosity off (view.cpp: Q_ADVANCED_LIGHT) */
    int gi = pipeline_gi_mode(o->gi, sc, o->quality);
    if (o->quality_given && o->quality < 9) {
        src_loc none = {NULL, 0, 0};
        if (gi == GI_PATH || gi == GI_PMFG)
            diag_report(d, DIAG_WARNING, none, NULL, "+Q%d: quality levels apply to --gi none and particle; --gi %s renders everything",
                        o->quality, gi_mode_name(gi));
        else if (o->quality <= 5)
            diag_report(d, DIAG_WARNING, none, NULL, "+Q%d: quick colours (levels 0-5) are not modelled: pigments are evaluated in full",
                        o->quality);
        if (sc->global.radiosity.enabled && !o->gi)
            diag_report(d, DIAG_NOTE, none, NULL, "+Q%d: radiosity is off below +Q9, as in POV-Ray", o->quality);
    }
    const char *gi_used = gi_mode_name(gi);
    if (run->tile && (gi == GI_PATH || gi == GI_PMFG || gi == GI_DETP || gi == GI_VPL || gi == GI_LINKS)) {
        pbar_free(bar);
        fprintf(stderr, "partray render: a render window (+SC/+EC/+SR/+ER) needs --gi none or particle, not %s\n", gi_used);
        scene_free(sc);
        diag_free(d);
        return EXIT_USAGE;
    }

    int threads = o->threads > 0 ? o->threads : pool_default_threads();
    /* GI across an animation's frames: each stage runs again only when the
     * hash of its inputs changed (stage_hashes); the frame then renders the
     * kept scene with this frame's camera and lights. */
    int reuse = 0, relight = 0, keep_gi = gi == GI_PARTICLE && plan->animated && !run->tile;
    uint64_t h_geom = 0, h_light = 0, scene_hash = sc->input_hash;
    int per_frame = gi == GI_PARTICLE && stage_hashes(sc, frame_dependent, frame, &h_geom, &h_light);
    /* An animation whose geometry is the same in every frame builds it from
     * the initial frame's camera (geometry_camera), so that a frame that
     * keeps an earlier frame's GI renders what it would alone (and so would
     * a tile of it on a farm), and its frames share one cache. When the
     * geometry changes from frame to frame, every frame builds its own from
     * its own camera, with a cache each, numbered as the outputs. */
    const scene_camera *geo_cam = gi == GI_PARTICLE && !per_frame ? geometry_camera(run, plan, frame, sc, d, &st) : NULL;
    if (st != PT_OK) {
        scene_free(sc);
        diag_free(d);
        pbar_free(bar);
        return status_exit(st);
    }
    char *gi_cache_frame = gi == GI_PARTICLE && o->gi_cache && plan->animated && per_frame
                               ? anim_output_name(o->gi_cache, frame, plan->digits) : NULL;
    const char *gi_cache = gi_cache_frame ? gi_cache_frame : (gi == GI_PARTICLE ? o->gi_cache : NULL);
    uint64_t cache_key = gi_cache ? gi_cache_key(h_geom, &so, frame_dependent,
                                                 geo_cam ? geo_cam : (sc->camera_set ? &sc->camera : NULL)) : 0;
    if (o->gi_cache && !gi_cache)
        diag_warn_once(d, (src_loc){0}, "--gi-cache applies to --gi particle, not %s: ignored", gi_used);
    if (keep_gi) {
        if (run->keep.gp && h_geom == run->keep.h_geom) {
            reuse = 1;
            relight = h_light != run->keep.h_light;
            scene *ks = run->keep.sc;
            ks->camera = sc->camera; /* no pointers: a camera with any makes h_geom per frame */
            for (int i = 0; i < sc->nlights && relight; i++) {
                src_loc keep_loc = ks->lights[i].loc; /* the kept scene's file name */
                ks->lights[i] = sc->lights[i];        /* looks_like, projected_through NULL (stage_hashes) */
                ks->lights[i].loc = keep_loc;
            }
            run->keep.h_light = h_light;
            scene_free(sc);
            sc = ks;
        } else if (run->keep.gp) {
            gi_keep_free(&run->keep);
        }
    }
    if (!reuse) progress_stage(prog, "accel", 0);
    double t_accel = 0.0;
    accel *acc = reuse ? run->keep.acc : pipeline_accel(sc, threads, d, &st, &t_accel);
    if (!acc || st != PT_OK) {
        free(gi_cache_frame);
        scene_free(sc);
        diag_free(d);
        pbar_free(bar);
        return status_exit(st == PT_OK ? PT_ERR_DEVICE : st);
    }

    render_gi_opts ss = {.mode = gi, .width = o->width > 0 ? o->width : 320, .height = o->height > 0 ? o->height : 240,
                         .threads = threads, .seed = o->seed, .antialias = o->antialias ? 1 : (o->spp > 1 ? 2 : 0),
                         .aa_threshold = o->aa_threshold, .aa_depth = o->aa_depth,
                         .aa_jitter = o->aa_jitter, .quality = o->quality, .spp = o->spp,
                         .particles = o->particles, .gi_quality = o->gi_quality, .photon_scale = o->photon_scale,
                         .photon_roulette = o->photon_roulette,
                         .bounces = o->bounces, .fg_rays = o->fg_rays, .photons = o->photons, .max_depth = o->max_depth,
                         .cl_device = o->cl_device,
                         .cl_max_bytes = o->cl_max_memory_mib > 0 ? (size_t)o->cl_max_memory_mib << 20 : 0,
                         .progress = prog, .notes = d, .cancel = &g_cancel, .reuse = reuse ? run->keep.gp : NULL,
                         .relight = relight, .keep = keep_gi, .detp_radius = o->detp_radius, .detp_full = o->detp_full,
                         .vpls = o->vpls, .vpl_cut = o->vpl_cut, .vpl_adaptive = o->vpl_adaptive};
    if ((gi == GI_DETP || gi == GI_LINKS) && plan->animated) {
        /* the work kept across frames: detp traces again the pieces of its
         * paths that changed (pm_detp.h), links links again only what
         * moved (gi_vlinks.h); the IR's stage hashes say whether the
         * lights changed and whether objects may have */
        uint64_t hg, hl;
        stage_hashes(sc, frame_dependent, frame, &hg, &hl);
        int had = run->kept != NULL;
        if (!run->kept) run->kept = render_gi_kept_new(&ss);
        ss.kept = run->kept;
        ss.lights_changed = had && (hl ^ hg) != run->kept_l;
        ss.objects_may_change = !had || hg != run->kept_h_geom;
        run->kept_h_geom = hg;
        run->kept_l = hl ^ hg;
    }
    ss.gi_cache = gi_cache;
    ss.gi_cache_load = gi_cache && access(gi_cache, F_OK) == 0;
    ss.gi_cache_key = cache_key;
    ss.geometry_camera = geo_cam;
    if (run->tile) memcpy(ss.window, run->win, sizeof ss.window);
    char *progressive = NULL;
    if ((gi == GI_PATH || gi == GI_PMFG) && noutputs > 0 && img_format_from_path(outputs[0]) != IMG_FMT_UNKNOWN) {
        progressive = partial_name(outputs[0]);
        ss.progressive_path = progressive;
    }
    framebuffer *fb = fb_new(ss.width, ss.height);
    render_gi_result sst;
    memset(&sst, 0, sizeof sst);
    double t0 = timer_now();
    pt_status lst = ls->aov ? PT_OK : lighting_alloc(ls, ss.width, ss.height, d);
    ss.aov = ls->aov;
    st = fb && lst == PT_OK ? render_gi(sc, acc, &ss, fb, &sst, d) : PT_ERR_NOMEM;
    if (st == PT_OK && o->alpha && !g_cancel) {
        /* +UA: each pixel's coverage (shade_aov.h); the colour stays
         * associated (premultiplied: a clear background adds nothing) */
        fb->alpha = malloc(sizeof(float) * (size_t)ss.width * (size_t)ss.height);
        if (!fb->alpha) {
            st = PT_ERR_NOMEM;
        } else {
            shade_settings as;
            shade_default_settings(&as);
            as.width = ss.width;
            as.height = ss.height;
            as.threads = threads;
            as.antialias = ss.antialias;
            as.cancel = &g_cancel;
            shade_alpha(sc, acc, &as, fb->alpha);
        }
    }
    double t_render = sst.t_render > 0 ? sst.t_render : timer_now() - t0;
    /* the progressive image of a finished render is no longer needed */
    if (progressive && !g_cancel) remove(progressive);
    free(progressive);
    /* the bar ends with the render; what follows prints plainly */
    pbar_stop(bar);

    int rc = EXIT_OK;
    img_write_opts wo;
    img_default_write_opts(&wo);
    wo.exr_float = o->exr_float;
    if (o->exr_compression >= 0) wo.exr_compression = o->exr_compression;
    wo.png_16bit = o->png16;
    wo.ocio = run->oc;
    wo.working_space = o->working_space;
    wo.display = o->display;
    wo.view = o->view;
    wo.look = o->look;
    wo.exposure = o->exposure;
    lighting_write_opts(ls, &wo);
    char tbuf[64], timings[160], settings[320], hash[40], framestr[32], window[96];
    snprintf(tbuf, sizeof tbuf, "%.3f", t_render);
    snprintf(timings, sizeof timings, "parse %.3f s, accel %.3f s, gi_geometry %.3f s, gi_lighting %.3f s, render %.3f s",
             t_parse, t_accel, sst.t_gi_geometry, sst.t_gi_lighting, t_render);
    /* what a merged image's tiles must share (partray merge): no thread
     * count, which does not change the pixels */
    snprintf(settings, sizeof settings,
             "size %dx%d, antialias %s threshold %.17g depth %d, spp %d, seed %llu, gi %s, particles %ld, bounces %d",
             ss.width, ss.height, ss.antialias == 1 ? "adaptive" : (ss.antialias == 2 ? "fixed" : "off"), ss.aa_threshold,
             ss.aa_depth, ss.spp > 0 ? ss.spp : 1, (unsigned long long)ss.seed, gi_used, o->particles, o->bounces);
    snprintf(hash, sizeof hash, "%016llx", (unsigned long long)scene_hash);
    snprintf(framestr, sizeof framestr, "%d clock %.17g", frame, so.clock);
    snprintf(window, sizeof window, "%d %d %d %d", run->win[0], run->win[1], run->win[2], run->win[3]);
    const char *keys[] = {"partray:scene", "partray:gi", "partray:version", "partray:render_seconds", "partray:timings",
                          "partray:settings", "partray:scene_hash", "partray:frame", "partray:window",
                          "partray:units", "partray:aovs"};
    const char *vals[] = {o->scene, gi_used, PARTRAY_VERSION, tbuf, timings, settings, hash, framestr, window,
                          ls->units_text, ls->aovs_text};
    wo.meta_keys = keys;
    wo.meta_values = vals;
    wo.nmeta = ls->aovs_text[0] ? 11 : 10;
    if (run->tile) memcpy(wo.window, run->win, sizeof wo.window);
    if (g_cancel && (!sst.image_begun || (st != PT_OK && st != PT_CANCELLED))) {
        /* Interrupted before the image pass (parse, accel or a GI stage):
         * no pixel was rendered, and a black "partial" image would say
         * otherwise. A stage that failed because it was cut short (an
         * OpenCL kernel build interrupted by SIGTERM) is an interruption
         * too (130/143, which a farm runs again), not an error. */
        fprintf(stderr, "partray: interrupted before any pixel was rendered: no partial image\n");
        rc = g_cancel == SIGTERM ? 128 + SIGTERM : EXIT_INTERRUPTED;
    } else if ((st == PT_OK || st == PT_CANCELLED) && g_cancel) {
        /* Interrupted: keep what was rendered under a clearly partial name. */
        for (int i = 0; i < noutputs; i++) {
            char *pn = partial_name(outputs[i]);
            diag *wd = diag_new();
            if (pn && img_write(pn, fb, &wo, wd) == PT_OK) fprintf(stderr, "partray: interrupted; partial image in %s\n", pn);
            cli_print_diags(wd, 0, 0);
            diag_free(wd);
            free(pn);
        }
        rc = g_cancel == SIGTERM ? 128 + SIGTERM : EXIT_INTERRUPTED;
    } else if (st != PT_OK) {
        rc = status_exit(st);
    } else {
        for (int i = 0; i < noutputs && rc == EXIT_OK; i++) {
            diag *wd = diag_new();
            /* PNG's alpha is straight (PNG spec 12.8), EXR's associated */
            framebuffer *straight = fb->alpha && img_format_from_path(outputs[i]) == IMG_FMT_PNG ? straight_alpha(fb) : NULL;
            if (fb->alpha && img_format_from_path(outputs[i]) == IMG_FMT_PFM)
                diag_warn_once(wd, (src_loc){0}, "+UA: PFM has no alpha channel: %s is written without it", outputs[i]);
            pt_status ws = img_write(outputs[i], straight ? straight : fb, &wo, wd);
            fb_free(straight);
            cli_print_diags(wd, 0, 0);
            diag_free(wd);
            if (ws != PT_OK) rc = status_exit(ws);
        }
        if (rc == EXIT_OK && o->false_color) rc = write_false_color(o, fb, ls);
    }
    double t_total = timer_now() - t_frame;
    if (o->stats && rc == EXIT_OK) {
        accel_stats as = accel_get_stats(acc);
        scene_counts cnt = scene_count(sc);
        stats_json js;
        stats_begin(&js);
        stats_obj_begin(&js, "timings");
        stats_num(&js, "parse", t_parse);
        stats_num(&js, "accel", t_accel);
        stats_num(&js, "gi_geometry", sst.t_gi_geometry);
        stats_num(&js, "gi_lighting", sst.t_gi_lighting);
        stats_num(&js, "render", t_render);
        if (ls->aov) stats_num(&js, "aov", sst.t_aov);
        stats_num(&js, "total", plan->animated ? t_total : timer_now() - run->t_start);
        stats_obj_end(&js);
        if (plan->animated) stats_int(&js, "frame", frame);
        if (gi_cache) stats_str(&js, "gi_cache", sst.gi_cache_loaded ? "loaded" : "saved");
        if (keep_gi) {
            stats_int(&js, "gi_geometry_ran", sst.ran_geometry);
            stats_int(&js, "gi_lighting_ran", sst.ran_lighting);
        }
        stats_int(&js, "rays", sst.primary_rays + sst.shadow_rays + sst.secondary_rays + sst.other_rays);
        STATS_INTS(&js, &sst, primary_rays, shadow_rays, secondary_rays, other_rays);
        stats_int(&js, "discarded_samples", sst.discarded);
        stats_int(&js, "width", ss.width);
        stats_int(&js, "height", ss.height);
        stats_int(&js, "threads", threads);
        stats_str(&js, "gi", gi_used);
        stats_str(&js, "gi_requested", o->gi ? o->gi : (sc->global.radiosity.enabled ? "particle" : "none"));
        stats_str(&js, "scene", o->scene);
        stats_obj_begin(&js, "scene_counts");
        STATS_INTS(&js, &cnt, objects, lights, triangles, unsupported);
        stats_obj_end(&js);
        render_gi_json(&sst, gi, &js);
        stats_obj_begin(&js, "accel");
        STATS_INTS(&js, &as, geometries, instances, triangles, user_prims);
        stats_obj_end(&js);
        /* an animation's stats file holds its last frame's figures */
        int ok = stats_write(&js, o->stats);
        if (!ok) {
            fprintf(stderr, "partray: cannot write stats file '%s'\n", o->stats);
            rc = EXIT_IO;
        }
    }
    if (!o->quiet && rc == EXIT_OK) {
        char fr[32] = "";
        if (plan->animated) snprintf(fr, sizeof fr, "frame %d: ", frame);
        fprintf(stderr, "partray: %s%dx%d, gi %s, parse %.3f s, accel %.3f s, render %.3f s, %.2f Mrays/s\n", fr, ss.width,
                ss.height, gi_used, t_parse, t_accel, t_render,
                t_render > 0 ? (sst.primary_rays + sst.shadow_rays + sst.secondary_rays) / t_render * 1e-6 : 0.0);
        if (sst.t_gi_geometry > 0 || sst.t_gi_lighting > 0)
            fprintf(stderr, "partray: %sgi %s: geometry %.3f s, lighting %.3f s\n", fr, gi_used, sst.t_gi_geometry,
                    sst.t_gi_lighting);
        if (sst.has_links) {
            const gi_vlinks_stats *p = &sst.links;
            fprintf(stderr, "partray: %slinks: %s, %ld of %ld objects moved, %ld of %ld elements linked again, "
                    "links %ld raw, %ld merged (%.2fx), %ld link rays\n", fr, p->full ? "full" : "incremental",
                    p->objects_moved, (long)sc->nobjects, p->elements_linked, p->elements, p->raw_links,
                    p->merged_links, p->merged_links > 0 ? (double)p->raw_links / (double)p->merged_links : 0.0,
                    p->link_rays);
        }
        if (sst.has_detp) {
            const pm_detp_stats *p = &sst.detp;
            fprintf(stderr, "partray: %sdetp: %s, %ld of %ld objects moved, %ld of %ld paths re-traced (%.2f%%), "
                    "segments -%ld +%ld of %ld, %ld of %ld receivers estimated anew\n", fr,
                    p->full_frame ? p->full_reason : "incremental", p->moving_objects, p->objects, p->paths_retraced,
                    p->paths, p->paths > 0 ? 100.0 * (double)p->paths_retraced / (double)p->paths : 0.0, p->segments_old,
                    p->segments_new, p->segments, p->receivers_full, p->receivers);
        }
        if (gi_cache && (sst.ran_geometry || sst.gi_cache_loaded))
            fprintf(stderr, "partray: %sgi cache %s: %s\n", fr, gi_cache, sst.gi_cache_loaded ? "loaded" : "saved");
        if (keep_gi)
            fprintf(stderr, "partray: %sgi stages run: %s%sview\n", fr, sst.ran_geometry ? "geometry, " : "",
                    sst.ran_lighting ? "lighting, " : "");
    }
    fb_free(fb);
    free(gi_cache_frame);
    if (keep_gi && sst.kept && !reuse) {
        /* this frame's GI, scene and accel serve the next frames */
        run->keep.sc = sc;
        run->keep.acc = acc;
        run->keep.gp = sst.kept;
        run->keep.h_geom = h_geom;
        run->keep.h_light = h_light;
    } else if (!reuse) {
        accel_free(acc);
        scene_free(sc);
    }
    diag_free(d);
    pbar_free(bar);
    return rc;
}

/* The output name POV-Ray makes from +O (imageprocessing.cpp
 * GetOutputFilename): none -> the scene's stem; a directory (ending in '/')
 * -> the scene's stem in it; no known extension -> +F's (.png unless +FE). */
static char *output_base(const char *out, const char *scene, char format)
{
    const char *ext = format == 'E' ? ".exr" : ".png";
    if (out && *out && out[strlen(out) - 1] != '/') {
        if (img_format_from_path(out) != IMG_FMT_UNKNOWN) return strdup(out);
        size_t n = strlen(out) + 8;
        char *s = malloc(n);
        if (s) snprintf(s, n, "%s%s", out, ext);
        return s;
    }
    char *stem = default_output(scene); /* "scene.png" */
    if (!stem) return NULL;
    char *dot = strrchr(stem, '.');
    if (dot) *dot = 0;
    size_t n = (out ? strlen(out) : 0) + strlen(stem) + 8;
    char *s = malloc(n);
    if (s) snprintf(s, n, "%s%s%s", out ? out : "", stem, ext);
    free(stem);
    return s;
}

static int cmd_render(int argc, char **argv)
{
    double t_start = timer_now();
    cli_render o;
    ini_args *ia = NULL;
    int rc = read_options("render", cli_render_help, argc, argv, &o, &ia);
    if (rc) return rc < 0 ? EXIT_OK : rc;
    char *bases[8];
    int nbases = o.noutputs > 0 ? o.noutputs : 1;
    for (int i = 0; i < nbases; i++) bases[i] = output_base(o.noutputs > 0 ? o.outputs[i] : NULL, o.scene, o.format);
    for (int i = 0; i < nbases && rc == EXIT_OK; i++) {
        if (!bases[i]) rc = EXIT_IO;
        else if (img_format_from_path(bases[i]) == IMG_FMT_UNKNOWN) {
            fprintf(stderr, "partray render: output '%s': unknown format (use .exr, .png or .pfm)\n", bases[i]);
            rc = EXIT_USAGE;
        }
    }
    int w = o.width > 0 ? o.width : 320, h = o.height > 0 ? o.height : 240;
    if (rc == EXIT_OK && !check_image_size(w, h, (unsigned long long)o.max_image_pixels)) rc = EXIT_USAGE;
    if (rc == EXIT_OK && o.gi && gi_mode_parse(o.gi) < 0) {
        fprintf(stderr, "partray render: unknown --gi mode '%s' (none, particle, pmfg, path)\n", o.gi);
        rc = EXIT_USAGE;
    }
    render_run run;
    memset(&run, 0, sizeof run);
    run.o = &o;
    run.t_start = t_start;
    char err[256];
    if (rc == EXIT_OK && cli_window(&o, w, h, run.win, err, sizeof err)) {
        fprintf(stderr, "partray render: %s\n", err);
        rc = EXIT_USAGE;
    }
    run.tile = !(run.win[0] == 0 && run.win[1] == 0 && run.win[2] == w && run.win[3] == h);
    /* Colour management: check the names before spending time on a render. */
    img_ocio *oc = NULL;
    int want_ocio = o.display || o.view || o.look || o.working_space || o.ocio_config;
    if (rc == EXIT_OK && want_ocio) {
        diag *od = diag_new();
        pt_status os = img_ocio_open(o.ocio_config, &oc, od);
        if (os == PT_OK) os = img_ocio_check(oc, o.working_space, o.display, o.view, o.look, od);
        cli_print_diags(od, 0, 0);
        diag_free(od);
        if (os != PT_OK) rc = status_exit(os == PT_ERR_IO ? PT_ERR_IO : PT_ERR_USAGE);
    }
    /* Lighting studies: --units, --aovs, --false-color-quantity (lighting_study.h). */
    lighting_study ls;
    memset(&ls, 0, sizeof ls);
    if (rc == EXIT_OK) {
        diag *ld = diag_new();
        pt_status lst = lighting_setup(&ls, o.units, o.aovs, o.fc_quantity, ld);
        if (lst == PT_OK) lighting_check_outputs(&ls, (const char **)bases, nbases, ld);
        cli_print_diags(ld, 0, 0);
        diag_free(ld);
        if (lst != PT_OK) rc = EXIT_USAGE;
    }
    anim_plan plan;
    cli_frames(&o, &plan, err, sizeof err); /* checked by cli_parse_render */
    /* Fail fast: every file this render will write is checked before the
     * scene is read, so a long render is never lost to a typo (an
     * animation's frames go where its first frame goes). */
    char *first_names[8] = {0};
    const char *writes[12];
    int nwrites = 0;
    for (int i = 0; i < nbases && rc == EXIT_OK; i++) {
        first_names[i] = anim_output_name(bases[i], plan.first, plan.animated ? plan.digits : 0);
        writes[nwrites++] = first_names[i] ? first_names[i] : bases[i];
    }
    if (o.stats) writes[nwrites++] = o.stats;
    if (o.false_color) writes[nwrites++] = o.false_color;
    for (int i = 0; i < nwrites && rc == EXIT_OK; i++) {
        int wrc = cli_check_output(writes[i], err, sizeof err);
        if (wrc) {
            fprintf(stderr, "partray render: %s\n", err);
            rc = wrc;
        }
    }
    for (int i = 0; i < nbases; i++) free(first_names[i]);
    if (rc == EXIT_OK && !o.quiet && o.noutputs == 0)
        fprintf(stderr, "partray: no output given (-o or +O): writing %s\n", bases[0]);
    if (rc == EXIT_OK && !o.quiet && (o.width <= 0 || o.height <= 0))
        fprintf(stderr, "partray: %s (--size WxH or +W +H): %dx%d%s\n",
                o.width <= 0 && o.height <= 0 ? "no size given" : (o.width <= 0 ? "no width given" : "no height given"),
                o.width > 0 ? o.width : 320, o.height > 0 ? o.height : 240,
                o.width <= 0 && o.height <= 0 ? ", POV-Ray's default" : " (POV-Ray's default 320x240 for the side not given)");
    run.oc = oc;
    run.ls = &ls;
    signal(SIGINT, on_sigint);
    signal(SIGTERM, on_sigint); /* kill, systemd, timeout(1): stop like Ctrl-C */
    int nframes = plan.last - plan.first + 1;
    for (int f = plan.first; f <= plan.last && rc == EXIT_OK && !g_cancel; f++) {
        char *names[8];
        int ok = 1;
        for (int i = 0; i < nbases; i++) ok &= (names[i] = anim_output_name(bases[i], f, plan.animated ? plan.digits : 0)) != NULL;
        if (!o.quiet && plan.animated) {
            /* the ETA from the frames so far (the first frame builds what
             * later ones may keep, so it is an upper bound then) */
            int done = f - plan.first;
            char eta[48] = "";
            if (done > 0) snprintf(eta, sizeof eta, ", ETA %.1f s", (timer_now() - t_start) / done * (nframes - done));
            fprintf(stderr, "partray: frame %d (%d of %d%s) -> %s\n", f, done + 1, nframes, eta, names[0]);
        }
        rc = ok ? render_frame(&run, &plan, f, names, nbases) : EXIT_IO;
        for (int i = 0; i < nbases; i++) free(names[i]);
    }
    if (rc == EXIT_OK && g_cancel) rc = g_cancel == SIGTERM ? 128 + SIGTERM : EXIT_INTERRUPTED;
    if (!o.quiet && rc == EXIT_OK && plan.animated)
        fprintf(stderr, "partray: %d frames in %.3f s\n", nframes, timer_now() - t_start);
    for (int i = 0; i < nbases; i++) free(bases[i]);
    gi_keep_free(&run.keep);
    render_gi_kept_free(run.kept);
    lighting_free(&ls);
    img_ocio_close(oc);
    ini_free(ia);
    return rc;
}

int main(int argc, char **argv)
{
    /* Past a file size limit (ulimit -f) a write must fail with EFBIG and be
     * reported (exit 3, temporary file removed), not kill the process. */
    signal(SIGXFSZ, SIG_IGN);
    if (argc < 2) {
        fputs(usage_text, stderr);
        return EXIT_USAGE;
    }
    const char *cmd = argv[1];
    if (strcmp(cmd, "--help") == 0 || strcmp(cmd, "-h") == 0 || strcmp(cmd, "help") == 0) {
        fputs(usage_text, stdout);
        fputs("\n", stdout);
        fputs(cli_exit_codes, stdout);
        return EXIT_OK;
    }
    if (strcmp(cmd, "--version") == 0) {
        printf("partray %s\n", PARTRAY_VERSION);
        return EXIT_OK;
    }
    if (strcmp(cmd, "render") == 0) return cmd_render(argc - 2, argv + 2);
    if (strcmp(cmd, "parse") == 0) return cmd_parse(argc - 2, argv + 2);
    if (strcmp(cmd, "compare") == 0) return cmd_compare(argc - 2, argv + 2);
    if (strcmp(cmd, "merge") == 0) return cmd_merge(argc - 2, argv + 2);
    if (strcmp(cmd, "farm") == 0) return cmd_farm(argc - 2, argv + 2);
    if (strcmp(cmd, "sweep") == 0) return cmd_sweep(argc - 2, argv + 2);
    if (strcmp(cmd, "crosscheck") == 0) return cmd_crosscheck(argc - 2, argv + 2);
    if (strcmp(cmd, "view") == 0) return cmd_view(argc - 2, argv + 2);
    /* POV-Ray habit: `partray scene.pov +W..` means render. */
    if (strstr(cmd, ".pov") || strstr(cmd, ".ini") || cmd[0] == '+') return cmd_render(argc - 1, argv + 1);
    fprintf(stderr, "partray: unknown command '%s'\n%s", cmd, usage_text);
    return EXIT_USAGE;
}
