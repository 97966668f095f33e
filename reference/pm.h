/* pm.h - what the two reference renderers (pm_path.h: path tracer,
 * pm_fg.h: photon map + final gathering) share: statistics, the options of
 * the image loop, progress and progressive-output callbacks, and the image
 * loop itself (passes of samples over tiles on core/pool).
 *
 * The light-transport model both converge to is shade_material.h's (see
 * reference/README.md). Determinism: sample s of pixel (x, y) draws from its
 * own PCG32 stream keyed by (seed, s, x, y), and pixel sums are formed in
 * sample order, so an image depends on the seed only, not on the thread
 * count or on how samples are split into passes. */
#ifndef PT_PM_H
#define PT_PM_H
#include <stdint.h>
#include "diag.h"
#include "framebuffer.h"
#include "progress.h"
#include "radrules.h"
#include "rng.h"
#include "scene.h"

typedef struct {
    /* stage times in seconds */
    double t_lights;        /* light set: emitter surfaces, photon sources */
    double t_photons;       /* photon tracing */
    double t_maps;          /* kd-tree builds (global, caustic, irradiance points) */
    double t_irradiance;    /* precomputed irradiance at photon positions */
    double t_render;        /* eye pass */
    double t_total;
    /* rays */
    long camera_rays;       /* primary rays */
    long bsdf_rays;         /* path continuations, specular eye rays, rays of specular gather chains */
    long gather_rays;       /* final-gather rays (pmfg) */
    long shadow_rays;       /* next-event estimation (lights and emitters); pmfg: also the visibility
                               tests of its density estimates (pm_fg.c vis_ok) */
    long photon_rays;       /* photon path segments */
    /* photons */
    long photons_emitted;
    long photons_global;    /* stored in the global map */
    long photons_caustic;   /* stored in the caustic map */
    long photons_dropped;   /* not stored: the memory cap on stored photons was reached */
    long irradiance_points;
    int caustic_map;        /* 1 if a caustic map was built */
    const char *caustic_reason; /* why (not): a static string */
    long gather_points;     /* eye vertices that final-gathered */
    long emitter_pieces;    /* emissive surface pieces sampled for NEE */
    /* samples */
    long samples;           /* pixel samples traced */
    long discarded_samples; /* NaN/Inf samples replaced by 0 */
    long unsupported;       /* hits on pigments the shader cannot evaluate */
    int spp, passes, threads;
} pm_stats;

/* Progressive output: called between passes from the thread that called the
 * render function, with the image so far (the framebuffer being rendered,
 * already normalised). The caller writes it, e.g. atomically with img_write. */
typedef void (*pm_image_fn)(void *ctx, const framebuffer *fb, int spp_done, int spp_total);
/* Progress in [0, 1]: called from worker threads, never concurrently, at most
 * about 10 times a second, and once with 1.0 at the end. */
typedef void (*pm_progress_fn)(void *ctx, double fraction);

/* Options of the image loop (both renderers). */
typedef struct {
    int width, height;
    int threads;            /* <= 0: all cores */
    uint64_t seed;
    int spp;                /* pixel samples (path: samples per pixel; pmfg: eye samples, default 1) */
    int jitter;             /* 1 (default): stratified positions in the pixel (scrambled Sobol (0,2)
                               sequence, box filter); 0: every sample through the pixel centre */
    volatile int *cancel;   /* non-zero stops at the next tile (the image so far is kept) */
    pm_image_fn on_image;
    void *image_ctx;
    double image_interval;  /* seconds between on_image calls (default 10) */
    pm_progress_fn on_progress;
    void *progress_ctx;
    progress *progress;     /* the render's stages (pmfg: photons, irradiance; both: "render", the image
                               loop's samples) with their counts (core/progress.h); NULL: none */
} pm_common;

void pm_common_defaults(pm_common *c);

/* ------------------------------------------------------------ image loop (for pm_path.c, pm_fg.c) */

/* Per-thread counters, padded. */
typedef struct {
    long camera, bsdf, gather, shadow, gather_points, discarded, unsupported, samples;
    char pad[64];
} pm_counts;

/* One pixel sample: radiance arriving through image position (px, py) in
 * pixel units. `r` is the sample's own stream. */
typedef rgb (*pm_sample_fn)(void *ctx, double px, double py, int thread, rng *r, pm_counts *cnt);

/* Renders c->spp samples per pixel in passes (1, 1, 2, 4, ... up to
 * `max_pass` samples per pixel each), calling on_image between passes and
 * on_progress as tiles finish. Fills fb (width x height), adds to st's
 * counters, samples, passes, threads. NaN/Inf samples are replaced by 0 and
 * counted. */
pt_status pm_image_render(const scene *sc, const pm_common *c, int max_pass, framebuffer *fb, pm_sample_fn fn,
                          void *ctx, pm_stats *st);

/* Helpers shared by the renderers. */
uint64_t pm_mix64(uint64_t z);
int pm_threads(int requested);
/* How many diffuse (gathering) bounces a reference path may take: the
 * radiosity recursion_limit (radrules.h rule 6), unbounded without a
 * radiosity{} block (a converged reference). */
int pm_gathers(const radrules *rr);

#endif
