/* view_render.c - the render thread of the viewer. */
#include "view_render.h"
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

struct view_render {
    /* fixed after start */
    scene *sc;
    const accel *a;
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
    int busy_level;            /* -1 waiting */
    long busy_gen;
    double busy_since;
    long idle_gen;             /* newest generation rendered to its last level */
    framebuffer *front;        /* full size, linear */
    uint8_t *front8;           /* full size, RGBA sRGB */
    view_frame_info front_info;
    long serial;
    diag *msgs;                /* messages for the UI */

    volatile int cancel;       /* written by both threads, read by the workers */

    /* render thread only */
    framebuffer *back;
    uint8_t *back8;
    view_gi *gi;
    int failed_modes;          /* bit per gi_mode that failed to open */
    view_light *applied_lights;
    int preview_div;
};

static uint8_t srgb_lut[SRGB_LUT + 1];
static pthread_once_t lut_once = PTHREAD_ONCE_INIT;

static void lut_init(void)
{
    for (int i = 0; i <= SRGB_LUT; i++) {
        double l = (double)i / SRGB_LUT;
        double e = l <= 0.0031308 ? 12.92 * l : 1.055 * pow(l, 1.0 / 2.4) - 0.055;
        int v = (int)floor(e * 255.0 + 0.5);
        srgb_lut[i] = (uint8_t)(v < 0 ? 0 : (v > 255 ? 255 : v));
    }
}

uint8_t view_render_srgb8(float v)
{
    pthread_once(&lut_once, lut_init);
    if (!(v > 0.0f)) return 0; /* also NaN */
    if (v >= 1.0f) return 255;
    return srgb_lut[(int)(v * SRGB_LUT + 0.5f)];
}

/* Upsample src (w x h) into dst (W x H) bilinearly (pixel centres aligned);
 * a copy when the sizes agree. */
static void upsample(const framebuffer *src, framebuffer *dst)
{
    int w = src->width, h = src->height, W = dst->width, H = dst->height;
    if (w == W && h == H) {
        memcpy(dst->rgb, src->rgb, (size_t)W * (size_t)H * 3u * sizeof(float));
        return;
    }
    for (int y = 0; y < H; y++) {
        double sy = (y + 0.5) * h / H - 0.5;
        int y0 = (int)floor(sy);
        double fy = sy - y0;
        int ya = y0 < 0 ? 0 : (y0 >= h ? h - 1 : y0);
        int yb = y0 + 1 < 0 ? 0 : (y0 + 1 >= h ? h - 1 : y0 + 1);
        for (int x = 0; x < W; x++) {
            double sx = (x + 0.5) * w / W - 0.5;
            int x0 = (int)floor(sx);
            double fx = sx - x0;
            int xa = x0 < 0 ? 0 : (x0 >= w ? w - 1 : x0);
            int xb = x0 + 1 < 0 ? 0 : (x0 + 1 >= w ? w - 1 : x0 + 1);
            const float *p00 = src->rgb + ((size_t)ya * w + xa) * 3u, *p01 = src->rgb + ((size_t)ya * w + xb) * 3u;
            const float *p10 = src->rgb + ((size_t)yb * w + xa) * 3u, *p11 = src->rgb + ((size_t)yb * w + xb) * 3u;
            float *o = dst->rgb + ((size_t)y * W + x) * 3u;
            for (int c = 0; c < 3; c++)
                o[c] = (float)((p00[c] * (1 - fx) + p01[c] * fx) * (1 - fy) + (p10[c] * (1 - fx) + p11[c] * fx) * fy);
        }
    }
}

static void to_rgba8(const framebuffer *fb, uint8_t *out)
{
    size_t n = (size_t)fb->width * (size_t)fb->height;
    for (size_t i = 0; i < n; i++) {
        out[4 * i + 0] = view_render_srgb8(fb->rgb[3 * i + 0]);
        out[4 * i + 1] = view_render_srgb8(fb->rgb[3 * i + 1]);
        out[4 * i + 2] = view_render_srgb8(fb->rgb[3 * i + 2]);
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

static int lights_equal(const view_light *a, const view_light *b, int n)
{
    for (int i = 0; i < n; i++) {
        if (memcmp(&a[i].position, &b[i].position, sizeof(vec3)) || memcmp(&a[i].point_at, &b[i].point_at, sizeof(vec3)) ||
            memcmp(&a[i].colour, &b[i].colour, sizeof(rgb)))
            return 0;
    }
    return 1;
}

/* Make sure the wanted mode is open; falls back to `none` (once per mode)
 * when it cannot be opened. Returns 1 when it opened a mode (stage times in
 * t), 0 when the mode was open already. */
static int ensure_mode(view_render *vr, int mode, view_gi_times *t, diag *d)
{
    if (vr->failed_modes & (1 << mode)) mode = GI_NONE;
    if (vr->gi && view_gi_mode(vr->gi) == mode) return 0;
    view_gi_close(vr->gi);
    vr->gi = NULL;
    pt_status st = view_gi_open(&vr->gi, mode, vr->sc, vr->a, vr->o.threads, t, d);
    if (st != PT_OK && mode != GI_NONE) {
        vr->failed_modes |= 1 << mode;
        diag_report(d, DIAG_WARNING, (src_loc){0}, NULL, "GI mode '%s' failed (%s); showing --gi none",
                    view_gi_name(mode), pt_status_name(st));
        view_gi_times t2;
        st = view_gi_open(&vr->gi, GI_NONE, vr->sc, vr->a, vr->o.threads, &t2, d);
    }
    if (st != PT_OK) vr->gi = NULL;
    return 1;
}

static void *render_main(void *arg)
{
    view_render *vr = arg;
    view_state cur;
    memset(&cur, 0, sizeof cur);
    view_light *cur_lights = calloc((size_t)(vr->nlights > 0 ? vr->nlights : 1), sizeof *cur_lights);
    long work_gen = -1;
    int level = 0, last_level = 0, cause = 0;
    double submit_time = 0, first_latency = 0, full_latency = 0;
    int lights_ok = 0; /* applied_lights holds what the scene has */
    framebuffer *pass = NULL;

    pthread_mutex_lock(&vr->mu);
    for (;;) {
        while (!vr->stop && vr->posted_gen == work_gen && level > last_level) {
            vr->busy_level = -1;
            pthread_cond_wait(&vr->cv, &vr->mu);
        }
        if (vr->stop) break;
        if (vr->posted_gen != work_gen) {
            work_gen = vr->posted_gen;
            cur = vr->posted;
            memcpy(cur_lights, vr->posted_lights, (size_t)vr->nlights * sizeof *cur_lights);
            cur.lights = cur_lights;
            cause = vr->posted_cause;
            submit_time = vr->posted_time;
            vr->posted_cause = 0;
            vr->posted_time = 0;
            level = 0;
            first_latency = full_latency = 0;
        }
        vr->cancel = 0;
        vr->busy_level = level;
        vr->busy_gen = work_gen;
        vr->busy_since = timer_now();
        pthread_mutex_unlock(&vr->mu);

        /* ---- one pass, no lock held */
        double t0 = timer_now();
        diag *d = diag_new();
        view_gi_times acc, t;
        memset(&acc, 0, sizeof acc);
        int lights_changed = !lights_ok || !lights_equal(cur.lights, vr->applied_lights, vr->nlights);
        if (lights_changed) {
            for (int i = 0; i < vr->nlights; i++) {
                scene_light *l = &vr->sc->lights[i];
                l->position = cur.lights[i].position;
                l->point_at = cur.lights[i].point_at;
                l->colour = cur.lights[i].colour;
            }
            memcpy(vr->applied_lights, cur.lights, (size_t)vr->nlights * sizeof *cur_lights);
        }
        vr->sc->camera = cur.camera;
        int opened = ensure_mode(vr, cur.gi_mode, &acc, d);
        pt_status st = vr->gi ? PT_OK : PT_ERR_INTERNAL;
        /* a mode just opened has lit the scene as it is now */
        if (st == PT_OK && lights_changed && lights_ok && !opened) {
            st = view_gi_relight(vr->gi, &t, d);
            acc.light += t.light;
        }
        lights_ok = 1;
        last_level = vr->gi ? view_gi_last_level(vr->gi) : 0;
        int div = level == 0 ? vr->preview_div : 1;
        int pw = vr->o.width / div, ph = vr->o.height / div;
        if (pw < 1) pw = 1;
        if (ph < 1) ph = 1;
        if (st == PT_OK && (!pass || pass->width != pw || pass->height != ph)) {
            fb_free(pass);
            pass = fb_new(pw, ph);
            if (!pass) st = PT_ERR_NOMEM;
        }
        if (st == PT_OK) {
            view_gi_pass p = {pw, ph, level, vr->o.threads, vr->o.seed, &vr->cancel};
            st = view_gi_render(vr->gi, &p, pass, &t, d);
            acc.view += t.view;
            acc.render += t.render;
        }
        int cancelled = vr->cancel != 0;
        if (st == PT_OK && !cancelled) {
            if (level == 0 && vr->o.preview_div <= 0) {
                double tp = acc.view + acc.render;
                if (tp > 1.5 * PREVIEW_TARGET && vr->preview_div < PREVIEW_DIV_MAX) vr->preview_div++;
                else if (tp < 0.4 * PREVIEW_TARGET && vr->preview_div > PREVIEW_DIV_MIN) vr->preview_div--;
            }
            upsample(pass, vr->back);
            to_rgba8(vr->back, vr->back8);
        }
        char desc[96] = "";
        if (vr->gi) view_gi_describe(vr->gi, desc, sizeof desc);

        pthread_mutex_lock(&vr->mu);
        copy_messages(vr->msgs, d);
        diag_free(d);
        if (st != PT_OK && !cancelled) {
            /* nothing sensible to show for this state: wait for the next */
            level = last_level + 1;
            vr->idle_gen = work_gen;
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
        in->gi_mode = vr->gi ? view_gi_mode(vr->gi) : GI_NONE;
        in->times = acc;
        double now = timer_now();
        in->frame = now - t0;
        in->latency = now - submit_time;
        in->first = level == 0;
        if (level == 0) first_latency = in->latency;
        if (level == 1) full_latency = in->latency;
        in->first_latency = first_latency;
        in->full_latency = full_latency;
        in->cause = cause;
        in->complete = level >= last_level;
        memcpy(in->describe, desc, sizeof desc);
        if (level >= last_level) vr->idle_gen = work_gen;
        level++;
    }
    vr->busy_level = -1;
    pthread_mutex_unlock(&vr->mu);
    fb_free(pass);
    free(cur_lights);
    return NULL;
}

pt_status view_render_start(view_render **out, scene *sc, const accel *a, const view_render_opts *o,
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
    vr->nlights = sc->nlights;
    vr->preview_div = o->preview_div > 0 ? o->preview_div : 4;
    vr->idle_gen = -1;
    vr->busy_level = -1;
    size_t nl = (size_t)(vr->nlights > 0 ? vr->nlights : 1);
    size_t npx = (size_t)o->width * (size_t)o->height;
    vr->posted_lights = calloc(nl, sizeof *vr->posted_lights);
    vr->applied_lights = calloc(nl, sizeof *vr->applied_lights);
    vr->front = fb_new(o->width, o->height);
    vr->back = fb_new(o->width, o->height);
    vr->front8 = calloc(npx, 4);
    vr->back8 = calloc(npx, 4);
    vr->msgs = diag_new();
    if (!vr->posted_lights || !vr->applied_lights || !vr->front || !vr->back || !vr->front8 || !vr->back8 || !vr->msgs) {
        view_render_stop(vr);
        return PT_ERR_NOMEM;
    }
    vr->posted = *initial;
    memcpy(vr->posted_lights, initial->lights, (size_t)vr->nlights * sizeof *vr->posted_lights);
    vr->posted.lights = vr->posted_lights;
    vr->posted_gen = 0;
    vr->posted_time = timer_now();
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
        free(vr->applied_lights);
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
    vr->posted = *s;
    memcpy(vr->posted_lights, s->lights, (size_t)vr->nlights * sizeof *vr->posted_lights);
    vr->posted.lights = vr->posted_lights;
    vr->posted_gen++;
    vr->posted_cause |= cause | (mode_changed ? VIEW_CAUSE_MODE : 0);
    if (vr->posted_time == 0) vr->posted_time = timer_now();
    /* refinements give way at once; a preview finishes (continuous motion
     * keeps showing frames) unless the mode changed */
    if (vr->busy_level >= 1 || (vr->busy_level == 0 && mode_changed)) vr->cancel = 1;
    pthread_cond_signal(&vr->cv);
    pthread_mutex_unlock(&vr->mu);
}

int view_render_fetch(view_render *vr, long *serial, uint8_t *rgba, view_frame_info *info)
{
    int got = 0;
    pthread_mutex_lock(&vr->mu);
    if (vr->serial != *serial && vr->serial > 0) {
        memcpy(rgba, vr->front8, (size_t)vr->o.width * (size_t)vr->o.height * 4u);
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
        if (fb) memcpy(fb->rgb, vr->front->rgb, (size_t)vr->o.width * (size_t)vr->o.height * 3u * sizeof(float));
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
    view_gi_close(vr->gi);
    fb_free(vr->front);
    fb_free(vr->back);
    free(vr->front8);
    free(vr->back8);
    free(vr->posted_lights);
    free(vr->applied_lights);
    diag_free(vr->msgs);
    free(vr);
}
