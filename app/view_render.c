/* view_render.c - the render thread of the viewer. */
#include "view_render.h"
#include "img_io.h"
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include "gi.h"
#include "timer.h"

#define PREVIEW_TARGET 0.040 /* seconds per preview pass */
#define PREVIEW_DIV_MIN 2
#define PREVIEW_DIV_MAX 16
#define SRGB_LUT 4096

#define GI_MODES 8
/* A light edit cancels a relight in progress (the newer lights win) only
 * when the last full lighting stage was slow (view_gi_slow_light) and only
 * while the GI has been out of date with the lights for less than this;
 * past it the relight finishes, so dragging a light without pause still
 * updates the GI about every RELIGHT_MAX_STALE + one lighting stage. */
#define RELIGHT_MAX_STALE 0.5

struct view_render {
    /* the scene shown: changed only by the render thread, when no opener
     * or clock thread runs */
    const scene *sc;           /* read only: every mode works on its own copy (view_gi.h) */
    const accel *a;
    scene *own_sc;             /* sc and a when they came from scene_at (freed at the next clock and stop) */
    accel *own_a;
    double clock;              /* of sc */
    /* fixed after start */
    view_render_opts o;
    int nlights;
    pthread_t thread;
    int started;

    pthread_mutex_t mu;
    pthread_cond_t cv;
    /* guarded by mu */
    int stop;
    long posted_gen;           /* generation of `posted` */
    view_state posted;
    view_light *posted_lights;
    int posted_cause;          /* causes since the thread last took a state */
    double posted_time;        /* time of the oldest submit not yet taken */
    double last_submit;        /* time of the newest submit */
    int busy_level;            /* -1 waiting */
    double busy_since;
    long idle_gen;             /* newest generation rendered to its last level in the wanted mode */
    framebuffer *front;        /* the last pass, linear (storage for the full size) */
    uint8_t *front8;           /* the same, RGBA sRGB */
    view_frame_info front_info;
    long serial;
    diag *msgs;                /* messages for the UI */
    /* the opener thread: builds a mode while the render thread goes on
     * with the modes it has (seed 001's asynchronous updates) */
    int opening;               /* mode being opened, -1 none */
    int open_done;             /* the opener has finished: join it */
    pthread_t opener;
    scene *open_scene;         /* the copy handed to the opener (lights at that time) */
    view_gi *open_result;
    pt_status open_status;
    view_gi_times open_times;
    /* the clock thread: the scene at a new clock and the solution of the
     * mode that follows it, while the render thread goes on */
    int geo_running, geo_done;
    pthread_t geo;
    double geo_clock;
    int geo_mode;              /* the mode it reframes (-1: none) */
    view_light *geo_edits;     /* the viewer's light edits when it started */
    scene *geo_sc;             /* its result (NULL on failure) */
    accel *geo_a;
    pt_status geo_status;
    double geo_t0, geo_secs;
    volatile int geo_cancel;
    int geo_failed;            /* failed_clock failed: not tried again until another clock is asked */
    double failed_clock;
    long clock_updates;
    double clock_update;

    volatile int cancel;       /* written by both threads, read by the workers */
    int relighting;            /* the render thread runs a lighting stage (guarded by mu) */
    int relight_short;         /* that stage took under a preview pass last time: not cancelled */
    double stale_since;        /* first light edit the GI does not show yet (0: none) */
    double edit_in_relight;    /* first light edit posted while the relight runs (0: none) */

    /* render thread only */
    framebuffer *back;         /* the pass being rendered (storage for the full size) */
    uint8_t *back8;
    view_gi *opened[GI_MODES]; /* every mode opened so far, kept for quick switching */
    int failed_modes;          /* bit per gi_mode that failed to open */
    int shown_mode;            /* the mode of the last pass */
    int preview_div;
};

static uint8_t srgb_lut[SRGB_LUT + 1];
static pthread_once_t lut_once = PTHREAD_ONCE_INIT;

static void lut_init(void)
{
    for (int i = 0; i <= SRGB_LUT; i++) {
        double l = (double)i / SRGB_LUT;
        double e = img_srgb_encode(l);
        int v = (int)floor(e * 255.0 + 0.5);
        srgb_lut[i] = (uint8_t)(v < 0 ? 0 : (v > 255 ? 255 : v));
    }
}


static inline uint8_t srgb8(float v)
{
    if (!(v > 0.0f)) return 0; /* also NaN */
    if (v >= 1.0f) return 255;
    return srgb_lut[(int)(v * SRGB_LUT + 0.5f)];
}

static void to_rgba8(const framebuffer *fb, uint8_t *out)
{
    size_t n = (size_t)fb->width * (size_t)fb->height;
    for (size_t i = 0; i < n; i++) {
        out[4 * i + 0] = srgb8(fb->rgb[3 * i + 0]);
        out[4 * i + 1] = srgb8(fb->rgb[3 * i + 1]);
        out[4 * i + 2] = srgb8(fb->rgb[3 * i + 2]);
        out[4 * i + 3] = 255;
    }
}

/* Copy messages from src into dst (keeps severity and location). */
static void copy_messages(diag *dst, const diag *src)
{
    for (int i = 0; i < diag_count(src); i++) {
        const diag_msg *m = diag_get(src, i);
        diag_report(dst, m->severity, m->loc, NULL, "%s", m->text);
    }
}

static view_gi_opts gi_opts(const view_render *vr)
{
    view_gi_opts go = {.preview_particles = vr->o.preview_particles, .threads = vr->o.threads, .ref_spp = vr->o.ref_spp,
                       .particles = vr->o.particles, .bounces = vr->o.bounces, .cl_device = vr->o.cl_device,
                       .width = vr->o.width, .height = vr->o.height, .seed = vr->o.seed};
    return go;
}

static void *opener_main(void *arg)
{
    view_render *vr = arg;
    diag *d = diag_new();
    view_gi *g = NULL;
    view_gi_times t;
    memset(&t, 0, sizeof t);
    view_gi_opts go = gi_opts(vr);
    pt_status st = view_gi_open(&g, vr->opening, vr->open_scene, vr->a, &go, &t, d);
    pthread_mutex_lock(&vr->mu);
    copy_messages(vr->msgs, d);
    vr->open_result = g;
    vr->open_status = st;
    vr->open_times = t;
    vr->open_done = 1;
    pthread_cond_signal(&vr->cv);
    pthread_mutex_unlock(&vr->mu);
    diag_free(d);
    return NULL;
}

/* Called with mu held: collect a finished open (joined: the opener thread
 * is joined already). Returns the mode it opened (or that failed), -1 when
 * none finished. */
static int collect_open(view_render *vr, view_gi_times *t, int joined)
{
    if (!vr->open_done) return -1;
    if (!joined) pthread_join(vr->opener, NULL);
    int mode = vr->opening;
    if (vr->open_status == PT_OK && vr->open_result) {
        vr->opened[mode] = vr->open_result;
        *t = vr->open_times;
    } else {
        vr->failed_modes |= 1 << mode;
        diag_report(vr->msgs, DIAG_WARNING, (src_loc){0}, NULL, "GI mode '%s' failed (%s); showing --gi %s",
                    view_gi_name(mode), pt_status_name(vr->open_status), view_gi_name(vr->shown_mode));
    }
    free(vr->open_scene->lights);
    free(vr->open_scene);
    vr->open_scene = NULL;
    vr->open_result = NULL;
    vr->opening = -1;
    vr->open_done = 0;
    return mode;
}

/* Called with mu held: start opening `mode` on the lights of `cur`. */
static void start_open(view_render *vr, int mode, const view_state *cur)
{
    scene *s = malloc(sizeof *s);
    scene_light *ls = malloc((size_t)(vr->nlights > 0 ? vr->nlights : 1) * sizeof *ls);
    if (!s || !ls) {
        free(s);
        free(ls);
        vr->failed_modes |= 1 << mode;
        return;
    }
    *s = *vr->sc;
    if (vr->nlights > 0) memcpy(ls, vr->sc->lights, (size_t)vr->nlights * sizeof *ls);
    for (int i = 0; i < vr->nlights; i++) {
        ls[i].position = cur->lights[i].position;
        ls[i].point_at = cur->lights[i].point_at;
        ls[i].colour = cur->lights[i].colour;
    }
    s->lights = ls;
    s->camera = cur->camera;
    vr->open_scene = s;
    vr->opening = mode;
    vr->open_done = 0;
    if (pthread_create(&vr->opener, NULL, opener_main, vr) != 0) {
        free(ls);
        free(s);
        vr->open_scene = NULL;
        vr->opening = -1;
        vr->failed_modes |= 1 << mode;
    }
}

/* The wanted mode, or `none` when it failed. */
static int wanted_mode(const view_render *vr, int mode)
{
    if (mode < 0 || mode >= GI_MODES || (vr->failed_modes & (1 << mode))) return GI_NONE;
    return mode;
}

/* Light edits into a mode's scene; returns 1 when something changed. */
static int apply_lights(view_render *vr, scene *gs, const view_light *l)
{
    int changed = 0;
    for (int i = 0; i < vr->nlights; i++) {
        scene_light *s = &gs->lights[i];
        if (memcmp(&s->position, &l[i].position, sizeof(vec3)) || memcmp(&s->point_at, &l[i].point_at, sizeof(vec3)) ||
            memcmp(&s->colour, &l[i].colour, sizeof(rgb))) {
            s->position = l[i].position;
            s->point_at = l[i].point_at;
            s->colour = l[i].colour;
            changed = 1;
        }
    }
    return changed;
}

/* Process CPU seconds (every thread): with the machine shared, CPU time
 * over the thread count estimates the wall time on an idle machine. */
static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Runs a lighting stage (the full one, or the preview one) on the render
 * thread. The full one is cancelled by a newer light edit
 * (view_render_submit); the preview one (tens of ms) is not: while a light
 * is dragged each new edit would cancel it and nothing would be shown. Both
 * stop on a mode change or stop. */
static pt_status relight_step(view_render *vr, view_gi *g, int preview, view_gi_times *acc, double *cpu, diag *d)
{
    view_gi_times t;
    memset(&t, 0, sizeof t);
    pt_status st = PT_OK;
    pthread_mutex_lock(&vr->mu);
    int run = !vr->cancel;
    vr->relighting = run && !preview;
    vr->relight_short = !view_gi_slow_light(g);
    vr->edit_in_relight = 0;
    pthread_mutex_unlock(&vr->mu);
    double c0 = cpu_now();
    if (run) st = preview ? view_gi_relight_preview(g, &vr->cancel, &t, d) : view_gi_relight(g, &vr->cancel, &t, d);
    *cpu += cpu_now() - c0;
    pthread_mutex_lock(&vr->mu);
    vr->relighting = 0;
    /* the full GI is up to date with the lights of this pass: stale again
     * only from an edit posted meanwhile */
    if (!preview && st == PT_OK && !view_gi_stale(g)) vr->stale_since = vr->edit_in_relight;
    pthread_mutex_unlock(&vr->mu);
    acc->light += t.light;
    return st;
}

/* ------------------------------------------------------------ the clock */

static void *geo_main(void *arg)
{
    view_render *vr = arg;
    diag *d = diag_new();
    scene *ns = NULL;
    accel *na = NULL;
    pt_status st = vr->o.scene_at(vr->o.scene_ctx, vr->geo_clock, &ns, &na, d);
    if (st == PT_OK && ns->nlights != vr->nlights) {
        diag_error(d, "view: at clock %g the scene has %d light%s, not %d: the viewer keeps clock %g", vr->geo_clock,
                   ns->nlights, ns->nlights == 1 ? "" : "s", vr->nlights, vr->clock);
        st = PT_ERR_UNSUPPORTED;
    }
    if (st == PT_OK && vr->geo_mode >= 0) {
        /* the new scene's lights with the viewer's edits, as start_open */
        scene_light *ls = malloc((size_t)(vr->nlights > 0 ? vr->nlights : 1) * sizeof *ls);
        if (!ls) st = PT_ERR_NOMEM;
        for (int i = 0; ls && i < vr->nlights; i++) {
            ls[i] = ns->lights[i];
            ls[i].position = vr->geo_edits[i].position;
            ls[i].point_at = vr->geo_edits[i].point_at;
            ls[i].colour = vr->geo_edits[i].colour;
        }
        view_gi_times t;
        if (ls) st = view_gi_reframe(vr->opened[vr->geo_mode], ns, na, ls, &vr->geo_cancel, &t, d);
        free(ls);
    }
    if (st != PT_OK) {
        accel_free(na);
        scene_free(ns);
        ns = NULL;
        na = NULL;
    }
    pthread_mutex_lock(&vr->mu);
    copy_messages(vr->msgs, d);
    vr->geo_sc = ns;
    vr->geo_a = na;
    vr->geo_status = st;
    vr->geo_secs = timer_now() - vr->geo_t0;
    vr->geo_done = 1;
    pthread_cond_signal(&vr->cv);
    pthread_mutex_unlock(&vr->mu);
    diag_free(d);
    return NULL;
}

/* Called with mu held: the posted clock differs from the scene's and can
 * be prepared now. */
static int clock_wanted(const view_render *vr, double clock)
{
    return vr->o.scene_at && clock != vr->clock && !(vr->geo_failed && clock == vr->failed_clock);
}

/* Called with mu held: start preparing the scene at cur->clock. */
static void start_geo(view_render *vr, const view_state *cur)
{
    vr->geo_mode = -1;
    /* the mode on screen follows the clock when it can, else another open
     * one that can (the rest are closed when the new scene takes over) */
    if (vr->opened[vr->shown_mode] && view_gi_can_reframe(vr->opened[vr->shown_mode])) vr->geo_mode = vr->shown_mode;
    for (int m = 0; m < GI_MODES && vr->geo_mode < 0; m++)
        if (vr->opened[m] && view_gi_can_reframe(vr->opened[m])) vr->geo_mode = m;
    memcpy(vr->geo_edits, cur->lights, (size_t)vr->nlights * sizeof *vr->geo_edits);
    vr->geo_clock = cur->clock;
    vr->geo_cancel = 0;
    vr->geo_done = 0;
    vr->geo_t0 = timer_now();
    vr->geo_running = pthread_create(&vr->geo, NULL, geo_main, vr) == 0;
    if (!vr->geo_running) {
        vr->geo_failed = 1;
        vr->failed_clock = cur->clock;
        diag_report(vr->msgs, DIAG_WARNING, (src_loc){0}, NULL, "view: cannot start the clock thread; keeping clock %g",
                    vr->clock);
    }
}

/* Called with mu held: take over a finished clock (joined: the thread is
 * joined already). Returns 1 when one finished. */
static int collect_geo(view_render *vr, int joined)
{
    if (!vr->geo_done) return 0;
    if (!joined) pthread_join(vr->geo, NULL);
    vr->geo_running = vr->geo_done = 0;
    if (vr->geo_status == PT_OK && vr->geo_sc && vr->geo_a) {
        for (int m = 0; m < GI_MODES; m++) {
            if (!vr->opened[m]) continue;
            if (m == vr->geo_mode) {
                view_gi_adopt(vr->opened[m]);
            } else {
                view_gi_close(vr->opened[m]);
                vr->opened[m] = NULL;
            }
        }
        /* nothing refers to the old scene now: no mode is open on it, and
         * neither an opener nor the clock thread runs */
        accel_free(vr->own_a);
        scene_free(vr->own_sc);
        vr->own_sc = vr->geo_sc;
        vr->own_a = vr->geo_a;
        vr->sc = vr->geo_sc;
        vr->a = vr->geo_a;
        vr->clock = vr->geo_clock;
        vr->clock_updates++;
        vr->clock_update = vr->geo_secs;
        vr->geo_failed = 0;
        if (!vr->opened[vr->shown_mode]) vr->shown_mode = GI_NONE;
    } else {
        accel_free(vr->geo_a);
        scene_free(vr->geo_sc);
        if (vr->geo_status != PT_CANCELLED) {
            vr->geo_failed = 1;
            vr->failed_clock = vr->geo_clock;
            diag_report(vr->msgs, DIAG_WARNING, (src_loc){0}, NULL, "view: the scene at clock %g failed (%s); showing clock %g",
                        vr->geo_clock, pt_status_name(vr->geo_status), vr->clock);
        }
    }
    vr->geo_sc = NULL;
    vr->geo_a = NULL;
    return 1;
}

#define QUIET 0.12 /* seconds without a submit before refinement passes start */

static void *render_main(void *arg)
{
    view_render *vr = arg;
    view_state cur;
    memset(&cur, 0, sizeof cur);
    view_light *cur_lights = calloc((size_t)(vr->nlights > 0 ? vr->nlights : 1), sizeof *cur_lights);
    long work_gen = -1;
    int level = 0, last_level = 0, cause = 0;
    double submit_time = 0, first_latency = 0, full_latency = 0, relit_latency = 0, relit_full_latency = 0;
    int quick_pending = 0; /* lights changed: show them over the old GI before relighting */
    int published = 1; /* an image of work_gen was published */
    view_gi_times opened_times;
    memset(&opened_times, 0, sizeof opened_times);

    pthread_mutex_lock(&vr->mu);
    for (;;) {
        while (!vr->stop && vr->posted_gen == work_gen && level > last_level && !vr->open_done && !vr->geo_done) {
            vr->busy_level = -1;
            pthread_cond_wait(&vr->cv, &vr->mu);
        }
        if (vr->stop) break;
        /* a finished open (or failure) restarts the refinement */
        if (collect_open(vr, &opened_times, 0) >= 0) level = 0;
        /* a finished clock: the new scene's passes from the preview on */
        if (collect_geo(vr, 0)) level = 0;
        if (vr->posted_gen != work_gen) {
            work_gen = vr->posted_gen;
            cur = vr->posted;
            memcpy(cur_lights, vr->posted_lights, (size_t)vr->nlights * sizeof *cur_lights);
            cur.lights = cur_lights;
            if (published) {
                cause = vr->posted_cause;
                submit_time = vr->posted_time;
            } else {
                /* the last generation never made it to the screen: this
                 * image answers its inputs too */
                cause |= vr->posted_cause;
                if (submit_time == 0 || (vr->posted_time > 0 && vr->posted_time < submit_time)) submit_time = vr->posted_time;
            }
            published = 0;
            vr->posted_cause = 0;
            vr->posted_time = 0;
            level = 0;
            first_latency = full_latency = relit_latency = relit_full_latency = 0;
        }
        if (clock_wanted(vr, cur.clock) && !vr->geo_running && vr->opening < 0) start_geo(vr, &cur);
        if (level > last_level) continue; /* an open finished for a mode not wanted now */
        /* refinement waits until the input has been quiet a moment */
        if (level >= 1) {
            double quiet = timer_now() - vr->last_submit;
            if (quiet < QUIET) {
                vr->busy_level = -1;
                struct timespec ts;
                clock_gettime(CLOCK_REALTIME, &ts);
                double until = ts.tv_sec + ts.tv_nsec * 1e-9 + (QUIET - quiet);
                ts.tv_sec = (time_t)until;
                ts.tv_nsec = (long)((until - (double)ts.tv_sec) * 1e9);
                pthread_cond_timedwait(&vr->cv, &vr->mu, &ts);
                continue;
            }
        }
        /* the mode: the wanted one when it is open, else open it in the
         * background and go on with the one on screen */
        int want = wanted_mode(vr, cur.gi_mode);
        if (!vr->opened[want] && vr->opening < 0 && !vr->geo_running && want != GI_NONE) start_open(vr, want, &cur);
        want = wanted_mode(vr, cur.gi_mode); /* start_open may have failed */
        int use = vr->opened[want] ? want : vr->shown_mode;
        int waiting_for_mode = use != want;
        /* the mode the clock thread reframes is not relit meanwhile (it
         * works on the same instance); its passes read the old solution */
        int reframing = vr->geo_running ? vr->geo_mode : -1;
        int clock_pending = clock_wanted(vr, cur.clock);
        vr->cancel = 0;
        vr->relighting = 0;
        vr->busy_level = level;
        vr->busy_since = timer_now();
        pthread_mutex_unlock(&vr->mu);

        /* ---- one pass, no lock held */
        double t0 = timer_now();
        diag *d = diag_new();
        view_gi_times acc = opened_times, t;
        memset(&opened_times, 0, sizeof opened_times);
        pt_status st = PT_OK;
        if (!vr->opened[use]) {
            /* `none` opens at once, on this thread */
            view_gi_opts go = gi_opts(vr);
            st = view_gi_open(&vr->opened[use], use, vr->sc, vr->a, &go, &t, d);
            acc.build += t.build;
            /* opened stale (the caustic layer not shot yet): a preview
             * without it first, the lighting stage in the next pass */
            if (st == PT_OK && view_gi_stale(vr->opened[use])) quick_pending = 1;
        }
        view_gi *g = vr->opened[use];
        int quick = 0, stale = 0, coarse = 0;
        double light_cpu = 0, pass_cpu0 = cpu_now();
        if (st == PT_OK && g) {
            vr->shown_mode = use;
            scene *gs = view_gi_scene(g);
            gs->camera = cur.camera;
            if (apply_lights(vr, gs, cur.lights)) {
                view_gi_lights_changed(g);
                quick_pending = view_gi_slow_light(g);
            }
            if (view_gi_stale(g) && use != reframing) {
                if (quick_pending && level == 0) {
                    /* at once: the preview lighting relit (fast), or else
                     * the new lights' direct term over the old indirect
                     * light; the full relight follows in the next pass */
                    quick = 1;
                    if (view_gi_has_preview_light(g)) st = relight_step(vr, g, 1, &acc, &light_cpu, d);
                } else {
                    st = relight_step(vr, g, 0, &acc, &light_cpu, d);
                }
            }
            quick_pending = 0;
        }
        last_level = g ? view_gi_last_level(g) : 0;
        int div = level == 0 ? vr->preview_div : 1;
        int pw = vr->o.width / div, ph = vr->o.height / div;
        if (pw < 1) pw = 1;
        if (ph < 1) ph = 1;
        vr->back->width = pw;
        vr->back->height = ph;
        if (st == PT_OK && g && !vr->cancel) {
            view_gi_pass p = {pw, ph, level, vr->o.threads, vr->o.seed, &vr->cancel};
            st = view_gi_render(g, &p, vr->back, &t, d);
            acc.light += t.light;
            acc.view += t.view;
            acc.render += t.render;
            coarse = view_gi_last_coarse(g);
            stale = view_gi_stale(g) && !coarse;
        } else if (st == PT_OK && !g) {
            st = PT_ERR_INTERNAL;
        }
        int cancelled = vr->cancel != 0;
        if (st == PT_OK && !cancelled) {
            if (level == 0 && !quick && vr->o.preview_div <= 0) {
                double tp = acc.view + acc.render;
                if (tp > 1.5 * PREVIEW_TARGET && vr->preview_div < PREVIEW_DIV_MAX) vr->preview_div++;
                else if (tp < 0.4 * PREVIEW_TARGET && vr->preview_div > PREVIEW_DIV_MIN) vr->preview_div--;
            }
            to_rgba8(vr->back, vr->back8);
        }
        char desc[96] = "";
        if (g) view_gi_describe(g, desc, sizeof desc);

        pthread_mutex_lock(&vr->mu);
        copy_messages(vr->msgs, d);
        diag_free(d);
        if (st != PT_OK && !cancelled) {
            /* nothing sensible to show for this state: wait for the next */
            diag_report(vr->msgs, DIAG_ERROR, (src_loc){0}, NULL, "view: the %s pass failed (%s)", view_gi_name(use),
                        pt_status_name(st));
            level = last_level + 1;
            if (!waiting_for_mode) vr->idle_gen = work_gen;
            continue;
        }
        if (cancelled) continue; /* a newer state (or stop) is posted */
        framebuffer *f = vr->front;
        vr->front = vr->back;
        vr->back = f;
        uint8_t *f8 = vr->front8;
        vr->front8 = vr->back8;
        vr->back8 = f8;
        view_frame_info *in = &vr->front_info;
        memset(in, 0, sizeof *in);
        in->serial = ++vr->serial;
        in->generation = work_gen;
        in->level = level;
        in->last_level = last_level;
        in->width = pw;
        in->height = ph;
        in->gi_mode = use;
        in->wanted_mode = want;
        in->times = acc;
        double now = timer_now();
        in->frame = now - t0;
        in->frame_cpu = cpu_now() - pass_cpu0;
        in->light_cpu = light_cpu;
        in->latency = now - submit_time;
        in->first = level == 0;
        if (level == 0 && first_latency == 0) first_latency = in->latency;
        if (!stale && relit_latency == 0) relit_latency = in->latency;
        if (!stale && !coarse && relit_full_latency == 0) relit_full_latency = in->latency;
        if (level == 1 && full_latency == 0) full_latency = in->latency;
        in->first_latency = first_latency;
        in->relit_latency = relit_latency;
        in->relit_full_latency = relit_full_latency;
        in->gi_coarse = coarse;
        in->full_latency = full_latency;
        in->gi_stale = stale;
        in->cause = cause;
        in->complete = level >= last_level && !waiting_for_mode && !stale && !coarse;
        memcpy(in->describe, desc, sizeof desc);
        in->clock = vr->clock;
        in->clock_busy = vr->geo_running;
        in->clock_updates = vr->clock_updates;
        in->clock_update = vr->clock_update;
        if (clock_pending) in->complete = 0;
        if (in->complete) vr->idle_gen = work_gen;
        published = 1;
        if (!quick) level++; /* after a stale preview: the relit preview */
    }
    vr->busy_level = -1;
    if (vr->opening >= 0) {
        /* an open cannot be cancelled: wait for it, then drop it */
        pthread_mutex_unlock(&vr->mu);
        pthread_join(vr->opener, NULL);
        pthread_mutex_lock(&vr->mu);
        vr->open_done = 1;
        view_gi_times t;
        collect_open(vr, &t, 1);
    }
    if (vr->geo_running) {
        /* the clock thread stops at its next chunk of link rays */
        vr->geo_cancel = 1;
        pthread_mutex_unlock(&vr->mu);
        pthread_join(vr->geo, NULL);
        pthread_mutex_lock(&vr->mu);
        vr->geo_done = 1;
        collect_geo(vr, 1);
    }
    pthread_mutex_unlock(&vr->mu);
    free(cur_lights);
    return NULL;
}

pt_status view_render_start(view_render **out, const scene *sc, const accel *a, const view_render_opts *o,
                            const view_state *initial, diag *d)
{
    *out = NULL;
    pthread_once(&lut_once, lut_init);
    if (o->width < 1 || o->height < 1) {
        diag_error(d, "view: bad image size %dx%d", o->width, o->height);
        return PT_ERR_USAGE;
    }
    view_render *vr = calloc(1, sizeof *vr);
    if (!vr) return PT_ERR_NOMEM;
    vr->sc = sc;
    vr->a = a;
    vr->o = *o;
    vr->clock = o->clock;
    vr->nlights = sc->nlights;
    vr->preview_div = o->preview_div > 0 ? o->preview_div : 4;
    vr->idle_gen = -1;
    vr->opening = -1;
    vr->shown_mode = GI_NONE;
    vr->busy_level = -1;
    size_t nl = (size_t)(vr->nlights > 0 ? vr->nlights : 1);
    size_t npx = (size_t)o->width * (size_t)o->height;
    vr->posted_lights = calloc(nl, sizeof *vr->posted_lights);
    vr->geo_edits = calloc(nl, sizeof *vr->geo_edits);
    vr->front = fb_new(o->width, o->height);
    vr->back = fb_new(o->width, o->height);
    vr->front8 = calloc(npx, 4);
    vr->back8 = calloc(npx, 4);
    vr->msgs = diag_new();
    if (!vr->posted_lights || !vr->geo_edits || !vr->front || !vr->back || !vr->front8 || !vr->back8 || !vr->msgs) {
        view_render_stop(vr);
        return PT_ERR_NOMEM;
    }
    vr->posted = *initial;
    memcpy(vr->posted_lights, initial->lights, (size_t)vr->nlights * sizeof *vr->posted_lights);
    vr->posted.lights = vr->posted_lights;
    vr->posted_gen = 0;
    vr->posted_time = timer_now();
    vr->last_submit = 0;
    vr->posted_cause = 0;
    pthread_mutex_init(&vr->mu, NULL);
    pthread_cond_init(&vr->cv, NULL);
    if (pthread_create(&vr->thread, NULL, render_main, vr) != 0) {
        diag_error(d, "view: cannot start the render thread");
        pthread_mutex_destroy(&vr->mu);
        pthread_cond_destroy(&vr->cv);
        fb_free(vr->front);
        fb_free(vr->back);
        free(vr->front8);
        free(vr->back8);
        free(vr->posted_lights);
        free(vr->geo_edits);
        diag_free(vr->msgs);
        free(vr);
        return PT_ERR_INTERNAL;
    }
    vr->started = 1;
    *out = vr;
    return PT_OK;
}

void view_render_submit(view_render *vr, const view_state *s, int cause)
{
    pthread_mutex_lock(&vr->mu);
    int mode_changed = s->gi_mode != vr->posted.gi_mode;
    int lights_changed = memcmp(vr->posted_lights, s->lights, (size_t)vr->nlights * sizeof *vr->posted_lights) != 0;
    vr->posted = *s;
    memcpy(vr->posted_lights, s->lights, (size_t)vr->nlights * sizeof *vr->posted_lights);
    vr->posted.lights = vr->posted_lights;
    vr->posted_gen++;
    vr->posted_cause |= cause | (mode_changed ? VIEW_CAUSE_MODE : 0);
    double now = timer_now();
    if (vr->posted_time == 0) vr->posted_time = now;
    vr->last_submit = now;
    /* refinements give way at once; a preview finishes (continuous motion
     * keeps showing frames) unless the mode changed; a relight gives way to
     * newer lights (superseded) while the GI on screen is recent enough */
    if (vr->busy_level >= 1 || (vr->busy_level == 0 && mode_changed)) vr->cancel = 1;
    if (lights_changed) {
        if (vr->stale_since == 0) vr->stale_since = now;
        if (vr->relighting && vr->edit_in_relight == 0) vr->edit_in_relight = now;
        /* a short stage (under a preview pass, e.g. cbox's) finishes: redoing
         * it for every edit of a dragged light would show nothing */
        if (vr->relighting && !vr->relight_short && now - vr->stale_since < RELIGHT_MAX_STALE) vr->cancel = 1;
    }
    pthread_cond_signal(&vr->cv);
    pthread_mutex_unlock(&vr->mu);
}

int view_render_fetch(view_render *vr, long *serial, uint8_t *rgba, view_frame_info *info)
{
    int got = 0;
    pthread_mutex_lock(&vr->mu);
    if (vr->serial != *serial && vr->serial > 0) {
        memcpy(rgba, vr->front8, (size_t)vr->front->width * (size_t)vr->front->height * 4u);
        if (info) *info = vr->front_info;
        *serial = vr->serial;
        got = 1;
    }
    pthread_mutex_unlock(&vr->mu);
    return got;
}

int view_render_idle(view_render *vr)
{
    pthread_mutex_lock(&vr->mu);
    int idle = vr->idle_gen == vr->posted_gen;
    pthread_mutex_unlock(&vr->mu);
    return idle;
}

int view_render_busy(view_render *vr, double *seconds)
{
    pthread_mutex_lock(&vr->mu);
    int level = vr->busy_level;
    if (seconds) *seconds = level >= 0 ? timer_now() - vr->busy_since : 0.0;
    pthread_mutex_unlock(&vr->mu);
    return level;
}

framebuffer *view_render_snapshot(view_render *vr, view_frame_info *info)
{
    framebuffer *fb = NULL;
    pthread_mutex_lock(&vr->mu);
    if (vr->serial > 0) {
        fb = fb_new(vr->o.width, vr->o.height);
        if (fb) fb_resample_bilinear(vr->front, fb);
        if (info) *info = vr->front_info;
    }
    pthread_mutex_unlock(&vr->mu);
    return fb;
}

void view_render_messages(view_render *vr, diag *d)
{
    pthread_mutex_lock(&vr->mu);
    if (diag_count(vr->msgs) > 0) {
        copy_messages(d, vr->msgs);
        diag_free(vr->msgs);
        vr->msgs = diag_new();
    }
    pthread_mutex_unlock(&vr->mu);
}

void view_render_stop(view_render *vr)
{
    if (!vr) return;
    if (vr->started) {
        pthread_mutex_lock(&vr->mu);
        vr->stop = 1;
        vr->cancel = 1;
        pthread_cond_signal(&vr->cv);
        pthread_mutex_unlock(&vr->mu);
        pthread_join(vr->thread, NULL);
        pthread_mutex_destroy(&vr->mu);
        pthread_cond_destroy(&vr->cv);
    }
    for (int i = 0; i < GI_MODES; i++) view_gi_close(vr->opened[i]);
    accel_free(vr->own_a);
    scene_free(vr->own_sc);
    free(vr->geo_edits);
    fb_free(vr->front);
    fb_free(vr->back);
    free(vr->front8);
    free(vr->back8);
    free(vr->posted_lights);
    diag_free(vr->msgs);
    free(vr);
}
