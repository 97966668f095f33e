/* pipeline.h - opening a scene, the one way every command (render, parse,
 * view, crosscheck; sweep renders through `partray render`) and bench tool
 * does it: the parser's options from the command line's (library paths,
 * -D, image size, every --max-* limit, and the evaluators that pattern and
 * pigment functions, noise, vturbulence and isosurfaces call, from shade/),
 * the parse into a diagnostics context, the empty-scene warning, the
 * acceleration structure, and the GI mode the options and the scene ask
 * for. Nothing here prints: the caller reports the diagnostics. */
#ifndef PT_PIPELINE_H
#define PT_PIPELINE_H
#include "accel.h"
#include "cli.h"
#include "diag.h"
#include "scene.h"
#include "sdl.h"

/* The parser's options for a width x height image from the render/view
 * options o (NULL: the parser's defaults and no paths or -D), with the
 * function evaluators always set. Animation frames are cli_frame_options'. */
void pipeline_sdl_options(sdl_options *so, const cli_render *o, int width, int height);

/* Parses `path` into *sc (NULL on failure); warns into d about a scene
 * without objects, as POV-Ray does. *seconds (may be NULL): the parse time. */
pt_status pipeline_parse(const char *path, const sdl_options *so, scene **sc, diag *d, double *seconds);

/* The acceleration structure of sc on `threads` threads (<= 0: all cores);
 * NULL with *st set on failure (PT_ERR_DEVICE when the device gave no
 * reason). *seconds (may be NULL): the build time. */
accel *pipeline_accel(const scene *sc, int threads, diag *d, pt_status *st, double *seconds);

typedef struct {
    scene *sc;
    accel *acc;
    double t_parse, t_accel; /* seconds */
} pipeline;

/* Parse and accel together; on failure nothing is kept (pl zeroed). */
pt_status pipeline_open(pipeline *pl, const char *path, const sdl_options *so, int threads, diag *d);
void pipeline_close(pipeline *pl);

/* The GI mode (gi.h) for --gi `gi` (NULL: the scene's: particle when it has
 * radiosity{} and quality >= 9, as POV-Ray turns radiosity off below +Q9,
 * else none); -1 for an unknown name. */
int pipeline_gi_mode(const char *gi, const scene *sc, int quality);

#endif
