/* view_gi.h - the viewer's lighting modes behind one small interface. Each
 * mode is a row of a function table in view_gi.c (open, relight, render,
 * close, number of refinement levels); nothing else in the viewer knows
 * which renderer runs.
 *
 *   none      shade_render: direct light + Whitted (+ POV-Ray's ambient).
 *             Levels: 0 preview, 1 full resolution, 2 adaptive antialiasing
 *             (+A0.3 +R3). A scene with photons{} gets its caustic layer
 *             (caustics.h) in this mode and in particle, as `partray
 *             render` does: shot by the first relight (none opens stale,
 *             view_gi_stale, so that its first image does not wait for
 *             the photons; particle shoots it as it opens) and again by a
 *             relight when the lights moved.
 *   particle  gi_particle (seed 000): open = geometry + lighting stage,
 *             relight = lighting stage only, every pass = prepare_view +
 *             shade_render with the indirect hook. Levels as `none`.
 *             The lighting stage is the slow part of a light edit: the
 *             render thread first relights a preview instance with 1/8 of
 *             the particles and shows a pass with it (or, without one, the
 *             new lights' direct term over the old indirect light), then
 *             relights the full instance; a newer light edit cancels a
 *             relight in progress (its visibility pass; the old lighting
 *             stays until one finishes).
 *   path      reference previews: pm_path (path tracer) and pm_fg (photon
 *   pmfg      map + final gathering at low settings: a photon map of its own
 *             per pass, 16 gather rays per eye sample). Levels: 0 preview at
 *             1 spp, 1 full resolution at 1 spp, then passes of 1, 2, 4, ...
 *             more samples averaged in, up to view_gi_opts.ref_spp in all.
 *
 * Each open mode works on its own shallow copy of the scene (camera and
 * lights copied, objects shared), so a mode can be opened on one thread
 * while another renders with a different mode. After open, calls on one
 * instance come from one thread: edit view_gi_scene's camera and lights
 * between calls, and call relight after a light edit. */
#ifndef PT_VIEW_GI_H
#define PT_VIEW_GI_H
#include <stdint.h>
#include "accel.h"
#include "diag.h"
#include "framebuffer.h"
#include "scene.h"

typedef struct view_gi view_gi;

/* Seconds spent by the last call, by stage (0 for stages it did not run). */
typedef struct {
    double build;   /* geometry stage (open) */
    double light;   /* lighting stage (open, relight) */
    double view;    /* per-view work before the pass (particle: prepare_view) */
    double render;  /* the pass itself */
} view_gi_times;

/* Settings of every mode. */
typedef struct {
    int threads;            /* <= 0: all cores */
    int ref_spp;            /* path/pmfg: samples per pixel at the last level (<= 0: 256) */
    int ref_photons;        /* pmfg: photon paths per pass (<= 0: 50,000) */
    long particles;         /* particle: area particles (<= 0: from the scene, gi_particle.h) */
    int bounces;            /* particle: n_b (<= 0: from the scene) */
    const char *cl_device;  /* particle: OpenCL device (NULL: auto) */
    long preview_particles; /* particle: the preview instance's count (0: 1/8 of the mode's, < 0: none) */
    /* none, particle: the caustic layer of the scene's photons{}: its
     * G-buffer's size (the image's; <= 0: 160 x 120) and its jitter's seed */
    int width, height;
    uint64_t seed;
} view_gi_opts;

typedef struct {
    int width, height;      /* size of this pass (fb has it) */
    int level;              /* 0 preview, 1 first full-resolution pass, >= 2 refinements */
    int threads;            /* <= 0: all cores */
    uint64_t seed;
    volatile int *cancel;   /* non-zero: stop soon; the pass's image is then incomplete */
    int coarse;             /* set by view_gi_render: the pass uses the preview lighting */
} view_gi_pass;

int view_gi_available(int mode);
/* The mode after `mode` in the cycle. */
int view_gi_next(int mode);
const char *view_gi_name(int mode);

/* Opens a mode on a copy of the scene (read only here; the objects must
 * outlive the instance): runs whatever the mode precomputes. */
pt_status view_gi_open(view_gi **out, int mode, const scene *sc, const accel *a, const view_gi_opts *o, view_gi_times *t,
                       diag *d);
/* The instance's scene: set its camera and lights before a pass. */
scene *view_gi_scene(view_gi *g);
/* The last level of the refinement (none/particle 2, path/pmfg 1 + log2 ref_spp). */
int view_gi_last_level(const view_gi *g);
/* Say that the scene's lights were edited (positions, colours): the GI is
 * stale until view_gi_relight completes. A pass before that shows the new
 * lights' direct term over the old indirect light. */
void view_gi_lights_changed(view_gi *g);
int view_gi_stale(const view_gi *g);
/* 1 when the mode's lighting stage is slow enough that a stale pass is
 * worth showing first (particle, when its last lighting stage took more
 * than 40 ms). */
int view_gi_slow_light(const view_gi *g);
/* Preview lighting (particle: a second instance with 1/8 of the particles,
 * built at open when that is at least 500): view_gi_relight_preview relights
 * it alone, fast; until the full relight completes, passes use it
 * (view_gi_last_coarse says so). PT_ERR_UNSUPPORTED when the mode has none;
 * cancellable as view_gi_relight. */
int view_gi_has_preview_light(const view_gi *g);
pt_status view_gi_relight_preview(view_gi *g, volatile int *cancel, view_gi_times *t, diag *d);
int view_gi_last_coarse(const view_gi *g);
/* Reruns the lighting stage for the scene's current lights. While *cancel
 * (may be NULL) is non-zero it may stop early: it returns PT_OK with the old
 * lighting in place and the mode still stale. */
pt_status view_gi_relight(view_gi *g, volatile int *cancel, view_gi_times *t, diag *d);
/* One pass of the refinement into fb (p->width x p->height) with the
 * scene's current camera. */
pt_status view_gi_render(view_gi *g, const view_gi_pass *p, framebuffer *fb, view_gi_times *t, diag *d);
/* A new scene (the same file at another clock: objects deformed or moved,
 * the same lights) for a mode that can follow it (links: linked again only
 * where it changed). view_gi_reframe computes the mode's solution for nsc
 * and na with `lights` (nsc->nlights of them) on any thread while another
 * keeps rendering passes with the old scene; PT_OK when it finished (not
 * cancelled). view_gi_adopt, on the thread that renders, then makes the
 * new scene, lights and solution the instance's (the camera stays); nsc's
 * objects and na must outlive the instance or the next adopt. Modes
 * without it (view_gi_can_reframe 0) are closed and opened again on the
 * new scene. */
int view_gi_can_reframe(const view_gi *g);
pt_status view_gi_reframe(view_gi *g, const scene *nsc, const accel *na, const scene_light *lights, volatile int *cancel,
                          view_gi_times *t, diag *d);
void view_gi_adopt(view_gi *g);
/* A line of mode-specific figures (particle counts, spp) for the title bar. */
void view_gi_describe(const view_gi *g, char *buf, int n);
void view_gi_close(view_gi *g);

#endif
