/* render_vpl.h - `--gi vpl`: seed 003's VPL reflectance filtering (Maletz,
 * Bowers and Wang) with partray's light model (docs/gi.md, "VPL
 * reflectance filtering"). The VPL tree, its filtering, cuts and the
 * gather kernel are gi/gi_vpl.h and gi/kernels/gi_vpl.cl; this module
 * makes the VPLs from the scene (shade/ and reference/ give the materials
 * and the direct light), gathers 1-2 bounces at them, and renders the image
 * with adaptive image-space sampling and bilateral reconstruction. */
#ifndef PT_RENDER_VPL_H
#define PT_RENDER_VPL_H
#include <stddef.h>
#include <stdint.h>
#include "accel.h"
#include "diag.h"
#include "framebuffer.h"
#include "scene.h"

enum { RENDER_VPL_MINMAX = 0, RENDER_VPL_FULL = 1, RENDER_VPL_BRUTE = 2 };

typedef struct {
    int width, height, threads;
    uint64_t seed;
    int spp;             /* eye samples per pixel (direct light, mirrors, refraction); default 16 */
    long vpls;           /* default 16384 (the paper's) */
    int bounces;         /* bounces gathered at the VPLs, default 1 (at most recursion_limit - 1) */
    double threshold;    /* a node's solid angle below which it is taken whole (0.02) */
    int cut;             /* RENDER_VPL_MINMAX (default), _FULL (whole tree), _BRUTE (every VPL) */
    double min_cut, max_cut; /* min-max band (gi_vpl.h's spread units): 40, 9 */
    int adaptive;        /* 1 (default): adaptive image sampling and bilateral reconstruction; 0: every pixel */
    double epsilon, lambda; /* coherence threshold (0.3) and colour weight (16) */
    const char *cl_device;  /* gi_cl.h's device choice; NULL = auto */
    size_t cl_max_bytes;
    volatile int *cancel;
} render_vpl_settings;

typedef struct {
    char device[160];
    long vpls, tree_nodes, cut_nodes, bounces;
    long pixels, pixels_valid, pixels_sampled; /* pixel-centre gather points: all, on a surface, gathered */
    long secondary_points;                     /* gathers at mirror/refraction hits */
    double visits_mean;                        /* nodes visited per gathered pixel */
    long visits_min, visits_max;
    long shadow_rays, camera_rays, secondary_rays;
    double t_vpls, t_tree, t_bounce, t_trace, t_gather, t_total; /* seconds; t_gather: the eye kernels */
    double t_gather_pixels;   /* the part of t_gather at pixel centres (the rest: mirror and refraction hits) */
} render_vpl_stats;

void render_vpl_default_settings(render_vpl_settings *s);
pt_status render_vpl(const scene *sc, const accel *a, const render_vpl_settings *s, framebuffer *fb,
                     render_vpl_stats *st, diag *d);

#endif
