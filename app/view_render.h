/* view_render.h - the viewer's render thread: progressive refinement off the
 * UI thread, cancellation, double-buffered images.
 *
 * The UI thread posts the wanted state (camera, lights, GI mode) with
 * view_render_submit and never waits for a render: the thread renders the
 * newest state in levels (view_gi.h): level 0 is a quick preview at 1/d of
 * the resolution (d adapts so a preview takes about 40 ms, 2 <= d <= 16),
 * level 1 the full resolution, higher levels refine (antialiasing, more
 * samples) while nothing changes. Each finished pass is converted to sRGB
 * 8-bit and swapped with the front buffer under a short lock; the UI copies
 * the front buffer when its serial changes (and scales it to the window), so
 * the window keeps showing the last complete image while the next one
 * computes (the asynchronous updates of seed 001).
 *
 * A submit cancels a refinement pass (level >= 1) through
 * shade_settings.cancel; a preview pass is left to finish (so continuous
 * motion still shows frames) unless the GI mode changed. Light edits rerun
 * only the GI's lighting stage (view_gi_relight; where that is slow, the
 * first pass after the edit shows the new lights' direct term over the old
 * indirect light, gi_stale, and a newer light edit cancels a relight in
 * progress: the stale job is abandoned), camera moves only the
 * per-view work and the passes. A mode that is not open yet is opened on a
 * thread of its own (its geometry and lighting stages) while the render
 * thread goes on refining with the mode on screen (at the start: `none`);
 * the new mode takes over when it is ready. Opened modes stay open, so
 * switching back is immediate. A new clock (view_state.clock, with
 * view_render_opts.scene_at) is prepared on a thread of its own too: the
 * scene evaluated at that clock, its acceleration structure, and for a
 * mode that can follow it (view_gi_reframe: links, linked again only where
 * the scene deformed) its new solution, while the render thread goes on
 * with the old scene and solution; then the new scene takes over, and the
 * other open modes are closed (opened again on the new scene when wanted).
 * No mode is opened while a clock is prepared, and no clock is prepared
 * while a mode is opened. Refinement passes start only after the input
 * has been quiet for 0.12 s (a pass that cannot be cancelled, such as the
 * particle GI's per-view stage, does not delay the next preview). */
#ifndef PT_VIEW_RENDER_H
#define PT_VIEW_RENDER_H
#include <stdint.h>
#include "accel.h"
#include "diag.h"
#include "framebuffer.h"
#include "scene.h"
#include "view_gi.h"

typedef struct view_render view_render;

/* The editable part of a light. */
typedef struct {
    vec3 position, point_at;
    rgb colour;
} view_light;

typedef struct {
    scene_camera camera;
    int gi_mode;
    const view_light *lights; /* the scene's light count of them (copied) */
    double clock;             /* the scene's clock (used only with view_render_opts.scene_at) */
} view_state;

enum { VIEW_CAUSE_CAMERA = 1, VIEW_CAUSE_LIGHT = 2, VIEW_CAUSE_MODE = 4, VIEW_CAUSE_CLOCK = 8 };

typedef struct {
    int width, height;      /* full image size */
    int threads;            /* <= 0: all cores */
    uint64_t seed;
    int preview_div;        /* 0: adaptive (start 4); else fixed */
    int ref_spp;            /* path/pmfg previews: samples per pixel at the last level (0: 256) */
    long particles;         /* particle GI: area particles (0: from the scene) */
    int bounces;            /* particle GI: n_b (0: from the scene) */
    const char *cl_device;  /* particle GI: OpenCL device (NULL: auto) */
    long preview_particles; /* particle GI: preview instance's count (0: 1/8, < 0: none) */
    /* The scene at another clock (NULL: the clock is fixed): the same file
     * evaluated again, called on a thread of its own; *sc and *a become the
     * render thread's (it frees them). */
    pt_status (*scene_at)(void *ctx, double clock, scene **sc, accel **a, diag *d);
    void *scene_ctx;
    double clock;           /* the clock of the scene view_render_start gets */
} view_render_opts;

typedef struct {
    long serial;            /* counts published images from 1 */
    long generation;        /* the submit it shows (0 = the initial state) */
    int level, last_level;
    int width, height;      /* size of the pass (previews are smaller than the full size) */
    int gi_mode;            /* the mode that made it */
    int wanted_mode;        /* the mode asked for (differs while that one is being built) */
    double frame;           /* seconds from the pass's start to its publication, GI stages included */
    view_gi_times times;    /* stages run for this pass (build/light only when they ran) */
    double frame_cpu;       /* process CPU seconds during the pass (every thread: a mode being built meanwhile too) */
    double light_cpu;       /* of which the lighting stage: / threads ~ its wall time on an idle machine */
    double latency;         /* seconds from the oldest submit its generation answers to its publication */
    int first;              /* the first image of its generation */
    double first_latency;   /* latency of its generation's first image (so a UI that missed it still knows) */
    double relit_latency;   /* latency of its generation's first image with the GI relit (preview lighting counts) */
    double relit_full_latency; /* ... with the mode's full GI relit */
    double full_latency;    /* latency of its generation's first full-resolution image; 0 before it */
    int gi_stale;           /* the indirect light is from before a light edit (the relight follows) */
    int gi_coarse;          /* the indirect light is the preview lighting's (the full relight follows) */
    int cause;              /* VIEW_CAUSE_* of the submits in its generation */
    int complete;           /* last level reached: the refinement is done */
    char describe[96];      /* view_gi_describe */
    double clock;           /* the clock of the scene it shows */
    int clock_busy;         /* made while the scene at a newer clock was being prepared */
    long clock_updates;     /* scenes at a new clock taken over so far */
    double clock_update;    /* seconds the last one took (parse, accel, the GI's reframe) */
} view_frame_info;

/* Starts the thread on the scene (read only; every mode works on its own
 * copy of the camera and lights) and the initial state. */
pt_status view_render_start(view_render **out, const scene *sc, const accel *a, const view_render_opts *o,
                            const view_state *initial, diag *d);
/* Post a new state; cause is VIEW_CAUSE_* bits (for latency figures). */
void view_render_submit(view_render *vr, const view_state *s, int cause);
/* Copies the front image into rgba (info.width * info.height * 4 bytes,
 * RGBA, sRGB; rgba must hold the full size) and its info when it is newer
 * than *serial; returns 1 then, else 0. */
int view_render_fetch(view_render *vr, long *serial, uint8_t *rgba, view_frame_info *info);
/* 1 when the newest posted state is rendered to its last level. */
int view_render_idle(view_render *vr);
/* What the thread works on: level (or -1 when waiting) and for how long. */
int view_render_busy(view_render *vr, double *seconds);
/* Copy of the front image as linear floats at the full size (a preview is
 * upsampled bilinearly; NULL before the first image); info may be NULL. */
framebuffer *view_render_snapshot(view_render *vr, view_frame_info *info);
/* Moves the thread's new messages (GI failures, warnings) into d. */
void view_render_messages(view_render *vr, diag *d);
/* Stops the thread (cancelling the pass) and frees everything but the scene. */
void view_render_stop(view_render *vr);

#endif
