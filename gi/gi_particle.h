/* gi_particle.h - particle-space global illumination (`--gi particle`), after
 * Chang, Park and Ihm, "Diffuse Global Illumination in Particle Spaces",
 * Multimedia Tools and Applications 74(13), 2015 (seed 000). Rays are traced
 * by Embree on the host; the particle work (emission, scattering, gathering,
 * radiance estimation) runs as OpenCL kernels (gi/kernels), or as the same
 * kernels compiled as C.
 *
 * Stages, and when to run them:
 *   gi_particle_build         geometry stage: area particles, 4x4 scattering
 *                             and 16x16 gathering links, radiance particles,
 *                             estimation lists; the OpenCL device. Once per
 *                             geometry.
 *   gi_particle_light         lighting stage: emission from every light and
 *                             emissive surface, n_b scattering bounces. After
 *                             build, and again whenever a light changes
 *                             (gi_particle_relight: same stage, nothing else).
 *   gi_particle_prepare_view  ray-tracing stage, first half: preliminary rays
 *                             mark the radiance particles the view needs;
 *                             gathering at their area particles; radiance
 *                             estimation. Once per camera/frame.
 *   gi_particle_indirect      the shade_settings.indirect hook, during the
 *                             Whitted pass: barycentric interpolation of the
 *                             3 radiance particles around each hit.
 *
 * Units (see gi/kernels/gi_types.h): the hook returns E/pi, the indirect
 * irradiance divided by pi. shade.c multiplies it by diffuse*pigment, which
 * gives the reflected radiance rho*E/pi of a Lambertian surface in the same
 * units as its direct term (diffuse*pigment*colour*cos), so a path tracer
 * with the BRDF rho/pi and a light delivering E = pi*colour*cos converges
 * to the same image.
 *
 * Reflectance of a particle: diffuse * pigment * opacity (gi_area_particles.h),
 * the pigment evaluated at the particle's position when settings.pigment is
 * set (the app passes shade's shade_tex_pigment_at: checkers, image maps and
 * texture maps reflect their own colours), else the texture's base colour.
 * finish { diffuse A, B } (3.7's backside diffuse): the hook adds the other
 * side's E/pi times B / A (shade.c multiplies the hook by A), where the
 * surface has particles on both sides; the particles themselves reflect
 * with A only (no light crosses a surface inside the lighting stage).
 *
 * light_group: a light gives direct light only to particles on objects it
 * reaches (scene_light_reaches, as shade.c); what they scatter is indirect
 * light and reaches everything.
 *
 * What counts as emitted light: light_sources (every kind, with shade.c's
 * attenuation and shadow rays) and finish emission, with finish ambient *
 * ambient_light only in scenes below #version 3.7 (POV-Ray's rules under
 * radiosity, core/radrules.h). Rays that leave the scene see the sky
 * (settings.sky: sky_sphere over background; gi_sky.h), which lights the
 * particles; surfaces beyond what the camera sees are the far field
 * (docs/gi.md "Open and sky-lit scenes"). Only diffuse interreflection is
 * simulated (as in the paper): no caustics; reflective and refractive
 * surfaces take part through the Whitted pass only.
 *
 * radiosity{} -> settings (gi_particle_settings_from_scene):
 *   count            -> particle count = 50 * count, within [5000, 200000]
 *                       (the default count 35 gives 5,000, cornell.pov's 200
 *                       10,000: POV-Ray's default accuracy at 160x120, see
 *                       bench/gi_vs_povray.sh; --gi-quality scales it)
 *   recursion_limit  -> bounces n_b = recursion_limit - 1, at least 0
 *                       (POV-Ray counts diffuse bounces; here the gathering
 *                       step adds one to the n_b scattering bounces)
 *   error_bound      -> estimation list radius factor 3 * error_bound / 1.8,
 *                       within [2, 5] (smaller error_bound: sharper, noisier)
 *   nearest_count    -> not used (lists replace the nearest-sample search)
 *   brightness       -> multiplies the indirect term returned by the hook
 *   always other fields are ignored.
 */
#ifndef PT_GI_PARTICLE_H
#define PT_GI_PARTICLE_H
#include <stddef.h>
#include <stdint.h>
#include "accel.h"
#include "diag.h"
#include "progress.h"
#include "gi_shadow.h"
#include "gi_sky.h"
#include "scene.h"

typedef struct gi_particle gi_particle;

/* Pigment colour of texture `tex` at a surface point h (h->p, h->ng = h->ns,
 * h->obj, h->texture): the signature of shade_texture.h's shade_tex_pigment_at,
 * which the app passes (gi does not link shade/). Returns 0 when no colour
 * was found. */
typedef int (*gi_pigment_fn)(const scene *sc, const scene_texture *tex, const accel_hit *h, colour5 *out);

/* The perturbed normal of the hit's texture for unit n, its raw normal on
 * the side seen (the signature of shade_texture.h's shade_tex_normal_at):
 * returns 0, *out = n, where it has none. */
typedef int (*gi_normal_fn)(const scene *sc, const accel_hit *h, vec3 n, vec3 *out);

/* gi_sky_fn (gi_sky.h): the sky's radiance for rays that leave the scene. */

/* How flux is scattered after emission (gi_lighting.cl; every bounce a
 * gather, no atomics, deterministic):
 *  WALK  the paper's (section 4.2.2, Fig. 5): the first bounce along all
 *        n_s x n_s links (gi_k_bounce), then n_b - 1 bounces along one
 *        random link of each particle, drawn once per particle and bounce
 *        at geometry time (the same expected flux as the paper's
 *        per-packet choice), all run at once over the paths those draws
 *        fix (gi_k_walk; at most 16 bytes per particle and bounce for the
 *        path table);
 *  FULL  every bounce along all links: no random-walk noise, the same
 *        expected flux, about n_s^2 times the gathers of a WALK bounce. */
typedef enum { GI_PARTICLE_SCATTER_WALK = 0, GI_PARTICLE_SCATTER_FULL = 1 } gi_particle_scatter;

typedef struct {
    long count;          /* area particles per one-sided scene area (default 50,000) */
    int scatter_side;    /* n_s: n_s x n_s scattering links (default 4) */
    int gather_side;     /* gathering links gather_side^2 (default 16: the paper's 256) */
    int bounces;         /* n_b: scattering bounces, the first full fan-out included (default 8) */
    int scatter;         /* gi_particle_scatter (default WALK) */
    double tess;         /* sub-triangle edge / grid cell bound; <= 0: tess_factor * spacing */
    double tess_factor;  /* default 3 (spacing = sqrt(area per particle)) */
    double radius;       /* estimation list radius; <= 0: radius_factor * spacing */
    double radius_factor;/* default 3 */
    double normal_cos;   /* list normal threshold: n_m . n_q > normal_cos (default 0.9, 25.8 degrees) */
    int area_samples;    /* shadow rays per particle per area light; 0: the whole grid (default 0) */
    double brightness;   /* multiplies the returned indirect light (default 1) */
    int max_trace_level; /* pre-pass depth; 0: the scene's */
    int prepass_stride;  /* the pre-pass traces every Nth pixel in x and y; the pixels between take
                            their hit from the flat piece their coarse neighbours all hit, or are
                            traced (gi_particle_view.c, coarse_hit). 0: the default (2); 1: every pixel */
    int view_gather_side; /* > 0: the kept hits (keep_hits) gather side x side rays themselves
                            (final gathering, gi_particle_gather.c) instead of interpolating the
                            radiance particles; 0: they interpolate (the paper's estimate) */
    int view_gather_stride; /* gathers at every Nth pixel in x and y, and where the pixels between
                              find no matching one (default 2) */
    double view_gather_filter; /* the edge-aware filter's Gaussian sigma over the gathers, in
                                  pixels (0: the default, 1; below 0: no filter) */
    double here_side_frac; /* a hit that gathers itself (reuse_error) takes this fraction of
                            view_gather_side a side, at least 4 (0: the default, a third: such
                            hits are mostly antialiasing samples, which a pixel averages) */
    double reuse_error;  /* > 0: with no bounce after the final gather's hits, a hit that is not a
                            kept pixel takes a gathered point's value only where POV-Ray's
                            irradiance cache would reuse it (its error_bound; gi_particle_gather.c),
                            and gathers itself elsewhere. 0 (default): the nearest points answer */
    double reuse_min, reuse_max; /* a point's reach (harmonic mean distance of its rays) is kept
                            within these fractions of its distance from the camera (POV-Ray's
                            minimum_reuse and maximum_reuse) */
    int keep_hits;       /* 1: the pre-pass keeps each traced pixel's first hit, and the radiance
                            particles it located there, for the render: gi_particle_primary_begin
                            and _hit as shade_settings.primary_begin and .primary give the render
                            those rays and hits instead of its own camera rays, and the hook
                            takes their cell and the light-leak guard's verdict from the record
                            (same values: the same image). Then stride 0 means 1 (every pixel
                            traced once, by the pre-pass). Only for renders whose camera rays go through pixel centres
                            (no fixed supersampling); beyond 256 MiB of records (248 bytes a pixel) or
                            without the memory none are kept and the coarse pre-pass runs. 0
                            (default): nothing kept */
    const scene_camera *camera; /* the camera the geometry stage looks from: the surfaces' sides,
                             bounds and clip box, the particles placed by what it shows, the pruning
                             of particles that face away from it (trace_and_prune). NULL (default):
                             the scene's. An animation gives every frame its initial frame's, so
                             that a frame's geometry is the same in one run and rendered alone */
    uint64_t seed;
    int threads;         /* <= 0: all cores */
    const char *cl_device; /* NULL/"auto", "c", "P:D" or part of a name (gi_cl.h) */
    const char *cl_source; /* NULL: the built-in kernels; tests pass broken text here */
    size_t cl_max_bytes;   /* OpenCL device memory the GI may hold; 0 = the device's (gi_dev_options.max_bytes) */
    volatile int *cancel;  /* non-zero stops the geometry stage at its next chunk of work (link rays of a few
                              particles, lists of a chunk of radiance particles): gi_particle_build then returns
                              NULL with PT_CANCELLED. NULL (the default): never. */
    gi_pigment_fn pigment; /* particles' pigment at their position; NULL: each texture's base colour */
    gi_normal_fn normal_at; /* radiosity `normal on` (core/radrules.h rule 5): the final gather (keep_hits) and
                               the gatherer gather about the texture's perturbed normal, and the reuse test and
                               the filter compare perturbed normals; NULL: the raw one */
    gi_sky_fn sky;         /* radiance of rays leaving the scene; NULL: the background colour */
    gi_shadow_fn shadow;   /* filtered shadows at the particles (the scene has transparent surfaces); NULL:
                              every surface shadows fully */
    int photon_shadows;    /* the scene's photons{} is on: gi_shadow_fn's photon_light is the light */
    progress *progress;    /* names each step of the geometry, lighting and view stages (NULL: none) */
} gi_particle_settings;

typedef struct {
    /* times, seconds */
    double t_geometry;      /* whole geometry stage (kernel build excluded) */
    double t_surfaces, t_sampling, t_prune, t_scatter_links, t_gather_links, t_lists, t_upload;
    /* process CPU seconds (all threads) of the same stages: on a shared
     * machine they say more than wall time */
    double c_geometry, c_prune, c_scatter_links, c_gather_links, c_lists;
    double t_kernel_build;  /* OpenCL program build (PoCL caches it) */
    double t_lighting;      /* whole lighting stage */
    double t_visibility, t_emit, t_scatter;
    double t_view;          /* whole last prepare_view */
    double t_prepass, t_gather, t_estimate;
    double t_view_gather;   /* last prepare_view: the final gather's links and values */
    long view_gathers, view_gather_rays; /* its gather points and rays */
    double c_prepass;       /* process CPU seconds of the last pre-pass */
    /* counts */
    long candidates, particles, pruned, probed_out;
    long radiance_particles, list_entries, lists_widened, lists_empty;
    long radiance_slots;    /* radiance particles before patches shared them (gi_surface_rp_slots) */
    long link_rays, link_misses, link_unresolved;
    long link_tri, link_tri_fallback; /* link hits answered by the hit triangle's list, and those it left to the grid */
    long trilook_lists, trilook_entries; /* its lists (2 per triangle cell) and their particles (4x4 pass; fewer after pruning) */
    size_t bytes_trilook;   /* its memory (freed after the link passes, not in bytes_total) */
    long sources;           /* particles that emit or reflect direct light */
    long shadow_rays;
    long prepass_rays, found, used;  /* last prepare_view: new radiance / area particles */
    long prepass_planar;    /* last prepare_view: pixels whose hit was found on their coarse
                               neighbours' flat piece, without a ray (prepass_stride) */
    long prepass_missed;    /* last prepare_view: pixels not traced because their coarse
                               neighbours all left the scene */
    long lookups, lookups_late, lookups_none, discarded;
    long lookups_onthefly;  /* hits on surfaces without radiance particles (no grid): estimated at the hit */
    long visibility_rays;   /* gi_visible tests: estimation list entries, radiance particles at hits, cells */
    long late_radiance, late_area; /* radiance particles estimated in the hook (the pre-pass missed
                                      them) and area particles gathered there (C build, on the CPU) */
    long cells, cells_clear; /* interpolation cells tested by the light-leak guard, of them clear */
    long lookups_clear;     /* hook lookups in clear cells (no visibility rays) */
    long prepass_kept;      /* last prepare_view: pixels whose first hit was kept (keep_hits) */
    long lookups_kept;      /* hook lookups that took their cell from a kept hit (no locate) */
    long lookups_gathered;  /* lookups the final gather at the kept hits answered */
    long lookups_gathered_here; /* of them, hits no gathered point could answer (antialiasing rays,
                                   reflections) that gathered themselves (reuse_error) */
    size_t bytes_view;      /* keep_hits: the kept hits' records (not in bytes_total) */
    long skipped_objects;
    double flux_direct, flux_emitted, flux_scattered; /* sums over particles (grey) */
    double flux_caustic;    /* of flux_direct, what the caustic photons brought (gi_particle_set_caustic) */
    /* memory, bytes */
    size_t bytes_particles, bytes_links, bytes_lists, bytes_surfaces, bytes_device, bytes_cells, bytes_total;
    double spacing, tess, radius;
    int bounces;
    char device[256];
} gi_particle_stats;

void gi_particle_default_settings(gi_particle_settings *s);
/* Defaults, then the radiosity{} mapping above when the scene has one. */
#define GI_PARTICLES_PER_COUNT 50L
#define GI_PARTICLES_MIN 5000L
#define GI_PARTICLES_MAX 200000L
/* the final gather's side under an error_bound below 0.1 (gi_particle.c) */
#define GI_DENSE_SIDE_MAX 36
/* the final gather's side gain under radiosity's `normal on` (gi_particle.c) */
#define GI_NORMAL_ON_SIDE_GAIN 1.45
/* --cl-device auto below this many particles: the C build of the kernels */
#define GI_CL_AUTO_MIN_PARTICLES 20000L
void gi_particle_settings_from_scene(gi_particle_settings *s, const scene *sc);

/* The quality knob (--gi-quality): q times the particle count (q > 0;
 * within [500, 4,000,000]); other values leave s as it is. */
void gi_particle_scale_quality(gi_particle_settings *s, double q);

/* Geometry stage. The scene and accel must outlive the result. `stats` may
 * be NULL; it is filled at the end (and again by the later stages, see
 * gi_particle_get_stats). */
gi_particle *gi_particle_build(const scene *sc, const accel *a, const gi_particle_settings *s,
                               gi_particle_stats *stats, diag *d, pt_status *status);
/* Lighting stage from the scene's current lights (sc->lights may have been
 * edited in place since build: positions, colours, kinds). */
pt_status gi_particle_light(gi_particle *gp, diag *d);
/* A light moved or changed: rerun the lighting stage and forget the view's
 * gathered values (the next prepare_view recomputes them). */
pt_status gi_particle_relight(gi_particle *gp, diag *d);
/* Cancellation of the lighting stage (the interactive viewer's relight):
 * while *cancel is non-zero, gi_particle_light/relight stop at the next
 * chunk of the visibility pass (its shadow rays) or before the next kernel
 * (emission, each bounce, radiance) and return PT_OK without touching what
 * the view reads: the previous lighting stays in place and consistent, and
 * the next call redoes what changed (lights whose visibility pass was cut
 * stay marked). Once the radiance kernel has started the stage runs to its
 * end. The caller tells a cancelled stage by its own flag. NULL (the
 * default): never cancelled. */
void gi_particle_set_cancel(gi_particle *gp, volatile int *cancel);
/* Where the later stages (lighting, view) report their steps from now on
 * (settings.progress is the build's); NULL: nowhere. A GI kept across an
 * animation's frames reports to each frame's own. */
void gi_particle_set_progress(gi_particle *gp, progress *p);
/* The caustic layer whose photons the next lighting stages take as light
 * arriving at the particles (NULL: none): POV-Ray's radiosity rays see the
 * photons at every hit (trace.cpp, ComputeLightedTexture), so a caustic's
 * light is bounced on as direct light is. It must outlive those stages. */
struct gi_caustic;
void gi_particle_set_caustic(gi_particle *gp, const struct gi_caustic *layer);
/* Change n_b and the scattering mode; takes effect at the next
 * gi_particle_relight (no geometry work). */
void gi_particle_set_scattering(gi_particle *gp, int bounces, int scatter);
/* Ray-tracing stage for a w x h image from camera c (after light). */
pt_status gi_particle_prepare_view(gi_particle *gp, const scene_camera *c, int w, int h, diag *d);
/* The shade_settings.indirect hook (signature of shade_indirect_fn): ctx is
 * the gi_particle. Thread-safe; `thread` < 256. Radiance particles the
 * pre-pass missed are computed on the spot with the C build of the kernels. */
rgb gi_particle_indirect(void *ctx, const accel_hit *hit, vec3 n, int thread);
/* The shade_settings.primary_begin and .primary providers (signatures of
 * shade_primary_begin_fn and shade_primary_fn): ctx is the gi_particle.
 * With settings.keep_hits, begin says whether the last prepare_view's
 * camera (compared whole), size, accel and tmin are the render's; then
 * primary gives pixel (x, y)'s camera ray (camera_ray through its centre)
 * and first hit, or 0 where none was kept (a no_image surface first, no
 * camera ray there). The hits stay valid until the next prepare_view or
 * free. */
int gi_particle_primary_begin(void *ctx, const scene *sc, const accel *a, int w, int h, double tmin);
int gi_particle_primary_hit(void *ctx, int x, int y, vec3 *org, vec3 *dir, const accel_hit **hit);
const gi_particle_stats *gi_particle_get_stats(gi_particle *gp);
void gi_particle_free(gi_particle *gp);

/* The geometry stage in a file (--gi-cache; gi_particle_cache.c has the
 * layout): save writes gp's geometry stage (lighting and view are not
 * stored) under scene_key, the caller's hash of everything the stage read
 * of the scene; written whole or not at all (a temporary name, then
 * rename). load is gi_particle_build with the particles, links and lists
 * read from the file: the same bits, so the same image. It refuses (NULL,
 * a located error `PATH: error: ...` in d, *status PT_ERR_SYNTAX) a file
 * that is not a cache, of another format version or byte order, truncated
 * or altered (checksum), made under another scene_key or with other
 * geometry settings (count, links, bounces, seed, radii), or whose
 * particles do not fit this scene's surfaces; an unreadable file is
 * PT_ERR_IO. */
#define GI_PARTICLE_CACHE_VERSION 8
pt_status gi_particle_save(gi_particle *gp, const char *path, uint64_t scene_key, diag *d);
gi_particle *gi_particle_load(const scene *sc, const accel *a, const gi_particle_settings *s, const char *path,
                              uint64_t scene_key, gi_particle_stats *stats, diag *d, pt_status *status);

/* For tests and tools: the particles' state after the lighting stage.
 * Returns the count; arrays are owned by gp (n*4 floats: E/pi direct,
 * received flux phi, reflected radiance L), and the per-bounce tally of the
 * last scattering (grey sums, fixed point converted to flux). */
int gi_particle_debug(const gi_particle *gp, const float **edir, const float **phi, const float **lout,
                      const double **bounce_flux, int *nbounces);
/* Area, reflectance and position of particle i (tests). */
void gi_particle_debug_particle(const gi_particle *gp, int i, double *area, double rho[3], vec3 *pos, vec3 *nrm);

#endif
