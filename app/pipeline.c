/* pipeline.c - opening a scene (see pipeline.h). */
#include "pipeline.h"
#include <string.h>
#include "gi.h"
#include "shade_funcenv.h"
#include "timer.h"

void pipeline_sdl_options(sdl_options *so, const cli_render *o, int width, int height)
{
    sdl_default_options(so);
    so->image_width = width;
    so->image_height = height;
    /* pattern/pigment functions, noise, vturbulence while parsing, and the
     * isosurfaces' functions (they keep the evaluators: scene_isosurface.env) */
    so->func_env = shade_func_env();
    if (!o) return;
    so->threads = o->threads; /* as the render's */
    so->lib_paths = o->libs;
    so->nlib_paths = o->nlibs;
    so->defines = o->defines;
    so->ndefines = o->ndefines;
    if (o->max_loop > 0) so->max_loop_iterations = o->max_loop;
    if (o->max_include_depth > 0) so->max_include_depth = o->max_include_depth;
    if (o->max_macro_depth > 0) so->max_macro_depth = o->max_macro_depth;
    if (o->max_tokens > 0) so->max_tokens = o->max_tokens;
    if (o->max_memory_mib > 0) so->max_memory = o->max_memory_mib > (1LL << 40) ? (1LL << 60) : o->max_memory_mib << 20;
    if (o->max_string > 0) so->max_string_length = o->max_string;
    if (o->max_array > 0) so->max_array_elements = o->max_array;
    if (o->max_image_pixels > 0) so->max_image_pixels = o->max_image_pixels;
}

pt_status pipeline_parse(const char *path, const sdl_options *so, scene **sc, diag *d, double *seconds)
{
    double t0 = timer_now();
    *sc = NULL;
    pt_status st = sdl_parse_file(path, so, sc, d);
    if (seconds) *seconds = timer_now() - t0;
    if (st != PT_OK) return st;
    /* POV-Ray warns about a scene without objects and renders its
     * background (POV-Ray 3.7 source, parser.cpp: "No objects in scene.") */
    if (scene_count(*sc).objects == 0) {
        src_loc none = {NULL, 0, 0};
        diag_report(d, DIAG_WARNING, none, NULL, "no objects in scene: the image shows only the background");
    }
    return PT_OK;
}

accel *pipeline_accel(const scene *sc, int threads, diag *d, pt_status *st, double *seconds)
{
    double t0 = timer_now();
    *st = PT_OK;
    accel *a = accel_build(sc, threads, d, st);
    if (seconds) *seconds = timer_now() - t0;
    if (!a || *st != PT_OK) {
        accel_free(a);
        if (*st == PT_OK) *st = PT_ERR_DEVICE;
        return NULL;
    }
    return a;
}

pt_status pipeline_open(pipeline *pl, const char *path, const sdl_options *so, int threads, diag *d)
{
    memset(pl, 0, sizeof *pl);
    pt_status st = pipeline_parse(path, so, &pl->sc, d, &pl->t_parse);
    if (st != PT_OK) return st;
    pl->acc = pipeline_accel(pl->sc, threads, d, &st, &pl->t_accel);
    if (!pl->acc) {
        scene_free(pl->sc);
        memset(pl, 0, sizeof *pl);
    }
    return st;
}

void pipeline_close(pipeline *pl)
{
    accel_free(pl->acc);
    scene_free(pl->sc);
    memset(pl, 0, sizeof *pl);
}

int pipeline_gi_mode(const char *gi, const scene *sc, int quality)
{
    if (gi) return gi_mode_parse(gi);
    return sc->global.radiosity.enabled && quality >= 9 ? GI_PARTICLE : GI_NONE;
}
