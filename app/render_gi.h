/* render_gi.h - one place that renders a parsed scene with the chosen GI mode
 * (none, particle, pmfg, path) and reports stage times and counts. Used by
 * `partray render`; the viewer and sweep go through the same choice. */
#ifndef PT_RENDER_GI_H
#define PT_RENDER_GI_H
#include <stdint.h>
#include "accel.h"
#include "caustics.h"
#include "diag.h"
#include "framebuffer.h"
#include "gi_particle.h"
#include "gi_vlinks.h"
#include "pm.h"
#include "pm_detp.h"
#include "render_vpl.h"
#include "scene.h"
#include "shade.h"
#include "shade_aov.h"
#include "stats_json.h"

typedef struct render_gi_kept render_gi_kept;

typedef struct {
    int mode;                 /* gi_mode */
    int width, height, threads;
    uint64_t seed;
    int antialias;            /* Whitted-based modes: 0 off, 1 +A adaptive, 2 fixed spp */
    double aa_threshold;
    int aa_depth;
    double aa_jitter;         /* +J amount (shade_settings.aa_jitter) */
    int quality;              /* none, particle: POV-Ray's +Q level 0..9 (shade_settings.quality) */
    int spp;                  /* path: samples per pixel; pmfg: eye samples; none/particle: fixed AA; vpl: per
                                 pixel; 0: the mode's default (1; pmfg's and vpl's own) */
    long particles;           /* particle: area particles (0 = from the scene/default) */
    double photon_scale;      /* none, particle: the caustic layer's photons times this (0 = 1) */
    int photon_roulette;      /* none, particle: the caustic layer ends photons by Russian roulette */
    double gi_quality;        /* particle: multiplies the scene's particle count (0 = 1); --particles wins */
    int bounces;              /* particle: n_b (0 = default) */
    int fg_rays;              /* pmfg: final-gather rays per pixel (0 = default 4096) */
    long photons;             /* pmfg: photon paths (0 = default) */
    int max_depth;            /* path: vertices per path (0 = unlimited) */
    const char *cl_device;    /* particle: OpenCL device choice (gi_cl.h), NULL = auto */
    size_t cl_max_bytes;      /* particle: OpenCL device memory it may use, 0 = the device's */
    volatile int *cancel;
    progress *progress;       /* stages and counts of every step (core/progress.h); NULL: none */
    diag *notes;              /* reference modes: a note each time the progressive image is written */
    const char *progressive_path; /* reference modes: write the image so far here every few seconds */
    /* particle: GI kept from an earlier frame of the same scene (its
     * geometry stage; the scene and accel it was built with are the ones
     * given). relight: the lights changed since, run the lighting stage
     * again; otherwise only the view stage runs. keep: hand the GI back in
     * render_gi_result.kept instead of freeing it. */
    gi_particle *reuse;
    int relight;
    int keep;
    /* detp, links: the mode's work kept from the previous frame
     * (render_gi_kept_new; NULL: a still, made and freed here) and what
     * changed since (links relights every frame: it reads only
     * objects_may_change, and takes every object as moved without kept) */
    render_gi_kept *kept;
    int lights_changed, objects_may_change;
    double detp_radius;       /* detp: disc radius (0 = default) */
    int detp_full;            /* detp: recompute every frame */
    /* particle: the geometry stage's file (gi_particle_save/_load), NULL:
     * none. gi_cache_load: read it (a mismatch or a bad file is the
     * render's error), else build and save it. gi_cache_key: the scene's
     * key it is checked against. */
    const char *gi_cache;
    int gi_cache_load;
    uint64_t gi_cache_key;
    const scene_camera *geometry_camera; /* particle: the camera of the geometry stage
                                 (gi_particle_settings.camera); NULL: the scene's */
    long vpls;                /* vpl: VPL count (0 = default) */
    int vpl_cut;              /* vpl: RENDER_VPL_* (render_vpl.h) */
    int vpl_adaptive;         /* vpl: 0 default (on), 1 on, 2 off */
    int window[4];            /* none/particle: render window x0,y0,x1,y1 (shade_settings.window); 0 = all */
    shade_aov *aov;           /* non-NULL: fill these AOVs after the render (shade_aov.h); the indirect
                                 AOV comes from particle GI only (0 for none, pmfg, path) */
} render_gi_opts;

typedef struct {
    double t_gi_geometry, t_gi_lighting, t_render;
    long primary_rays, shadow_rays, secondary_rays, other_rays, discarded;
    shade_stats shade;        /* Whitted pass (none, particle) */
    int has_particle;
    gi_particle_stats particle;
    int has_pm;
    pm_stats pm;
    double t_aov;             /* the AOV pass, seconds (not in t_render) */
    double c_render;          /* particle: process CPU seconds of prepare_view + the Whitted pass */
    int image_begun;          /* the pass that writes the image began: a cancelled render's
                                 framebuffer holds what it rendered (before: nothing) */
    int ran_geometry, ran_lighting; /* particle: the stages this render ran (the view stage always runs) */
    int has_vpl;
    render_vpl_stats vpl;
    int has_detp;
    pm_detp_stats detp;
    int gi_cache_loaded;      /* particle: the geometry stage came from opts.gi_cache */
    int has_links;
    gi_vlinks_stats links;
    gi_particle *kept;        /* particle with opts.keep: the GI, the caller frees it */
    /* Light the scene uses that the mode does not carry (each also warned
     * once): 1 where it is left out. path, pmfg: participating media
     * (atmospheric or in objects) and rainbows on every ray; particle: with
     * radiosity's `media on`, media, fog and rainbows along gathering rays. */
    int nm_media, nm_fog, nm_rainbow;
    /* particle: radiosity's `normal on` (POV-Ray gathers about the
     * perturbed normal; the final gather takes the unperturbed one) */
    int nm_normal;
    /* The scene's photons{}: nm_photons 1 where the mode shows no caustics
     * of POV-Ray's lights (every mode but none, particle and pmfg);
     * nm_photon_count 1 for pmfg, whose caustic map shoots --photons from
     * every light in all directions (not the scene's spacing or count) */
    int nm_photons, nm_photon_count;
    /* none, particle: the caustic layer of the scene's photons{} (its
     * layer is freed when render_gi returns; the figures stay) */
    caustics caus;
} render_gi_result;

pt_status render_gi(const scene *sc, const accel *a, const render_gi_opts *o, framebuffer *fb, render_gi_result *r,
                    diag *d);
/* The work of o->mode kept for the frames of one animation, with o's
 * settings (detp: its photon paths, from photons, radius, seed, threads,
 * full; links: its vertex links, from bounces, threads); NULL for another
 * mode or on no memory. */
render_gi_kept *render_gi_kept_new(const render_gi_opts *o);
void render_gi_kept_free(render_gi_kept *k);
/* Particle GI's settings for scene sc, a render's or a viewer session's:
 * the scene's (gi_particle_settings_from_scene) with shade/'s hooks (the
 * pigment at a particle, the sky, POV-Ray's filtered shadows). */
void render_gi_particle_settings(gi_particle_settings *gs, const scene *sc);
/* The vertex links' settings of a render or a viewer session (bounces 0:
 * the default): vertices reflect the pigment where they are. */
void render_gi_links_settings(gi_vlinks_settings *s, int threads, int bounces);
/* Adds the method-specific object ("particle": {...}, "reference": {...}). */
void render_gi_json(const render_gi_result *r, int mode, stats_json *js);

#endif
