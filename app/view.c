/* view.c - `partray view`: window, input, the event loop. */
#include "view.h"
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "accel.h"
#include "cli.h"
#include "diag.h"
#include "gi.h"
#include "img_io.h"
#include "pipeline.h"
#include "pool.h"
#include "scene.h"
#include "sdl.h"
#include "timer.h"
#include "view_camera.h"
#include "view_gi.h"
#include "view_overlay.h"
#include "view_render.h"
#include "view_script.h"
#include "view_sdl.h"

enum { EXIT_OK = CLI_EXIT_OK, EXIT_SCENE = CLI_EXIT_SCENE, EXIT_USAGE = CLI_EXIT_USAGE, EXIT_IO = CLI_EXIT_IO };

#define MAX_LATENCIES 4096

static const char *view_usage =
    "usage: partray view SCENE.pov [--size WxH] [--gi none|particle|links|path|pmfg] [--threads N] [--seed N]\n"
    "                    [--script FILE] [--preview D] [--ref-spp N] [--preview-particles N] [--verbose]\n"
    "                    [--particles N] [--nb N] [--cl-device DEV] [--clock V] [-D NAME=VALUE] [-L DIR]\n"
    "keys: WASD/QE fly, right drag look, left drag orbit, wheel zoom, R reset camera,\n"
    "      1-9/Tab select light, arrows/PgUp/PgDn move it, +/- brighten/dim it,\n"
    "      G cycle GI mode, [/] clock -/+ 0.05 (the scene evaluated again), O overlay on/off,\n"
    "      F12/P screenshot, C write camera, H help, Esc quit\n";

/* Figures for the exit summary and `mark`. */
typedef struct {
    double v[MAX_LATENCIES];
    int n;
} series;

static void series_add(series *s, double x)
{
    if (s->n < MAX_LATENCIES) s->v[s->n++] = x;
}

static void series_stats(const series *s, double *mean, double *max)
{
    double sum = 0, mx = 0;
    for (int i = 0; i < s->n; i++) {
        sum += s->v[i];
        if (s->v[i] > mx) mx = s->v[i];
    }
    *mean = s->n ? sum / s->n : 0;
    *max = mx;
}

typedef struct {
    /* scene and renderer */
    const char *scene_path;
    char stem[256];
    int width, height;
    int threads;
    view_render *vr;
    view_camera cam, cam_home;
    int nlights;
    view_light *lights;
    light_kind *light_kinds;
    int selected;            /* 0-based */
    int gi_mode;
    double clock;            /* the clock asked for (the image follows when the scene at it is ready) */
    double scale;            /* scene size, for step lengths */
    int dirty;               /* VIEW_CAUSE_* bits not yet submitted */
    /* window */
    SDL_Window *win;
    SDL_Renderer *ren;
    SDL_Texture *tex;
    SDL_Texture *otex;       /* the overlay (figures), blended over the image */
    uint8_t *orgba;
    int overlay;             /* O toggles */
    const char *window_shot; /* `window PATH`: saved after the next redraw */
    uint8_t *rgba;
    long serial;
    view_frame_info info;
    int have_image;
    int need_present;        /* new image or window damage since the last present */
    int verbose;             /* print a line per image shown */
    /* keys held down, from the event queue (real and scripted presses) */
    unsigned char held[SDL_NUM_SCANCODES];
    struct { double at; SDL_Keycode key; SDL_Scancode code; } release[16];
    int nrelease;
    int raw_input;           /* a script action queued raw input this tick */
    /* script */
    view_script *script;
    int quit;
    /* figures */
    double t_start, t_first_image;
    long images;             /* images shown (fetched by the UI) */
    long published;          /* images the render thread finished (serial) */
    double recent[64];       /* times of the last images, for images/s */
    int nrecent;
    long last_gen_first;     /* generation whose first image was counted */
    long last_gen_full;
    long last_gen_relit, last_gen_relit_full;
    series lat_light_first, lat_light_relit, lat_light_relit_full, lat_light_full, lat_camera_first;
    long images_clock_busy;  /* images shown that were made while a new clock was being prepared */
    double title_time;
    diag *msgs;
} viewer;

/* ----------------------------------------------------------------- utils */

static int file_exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

static void flush_messages(viewer *v)
{
    diag *d = diag_new();
    view_render_messages(v->vr, d);
    cli_print_diags(d, 0, 0);
    diag_free(d);
}

static int status_exit(pt_status st) { return cli_exit_status(st); }

/* "dir/cbox.pov" -> "cbox" */
static void scene_stem(const char *path, char *out, size_t n)
{
    const char *b = strrchr(path, '/');
    b = b ? b + 1 : path;
    snprintf(out, n, "%s", b);
    char *dot = strrchr(out, '.');
    if (dot && dot != out) *dot = 0;
}

static view_state current_state(const viewer *v)
{
    view_state s;
    memset(&s, 0, sizeof s);
    view_camera_to_scene(&v->cam, &s.camera);
    s.gi_mode = v->gi_mode;
    s.lights = v->lights;
    s.clock = v->clock;
    return s;
}

/* Post what changed since the last submit. */
static void flush_state(viewer *v)
{
    if (!v->dirty) return;
    view_state s = current_state(v);
    view_render_submit(v->vr, &s, v->dirty);
    v->dirty = 0;
}

/* ----------------------------------------------------------- file output */

static void write_image(viewer *v, const framebuffer *fb, const view_frame_info *in, const char *path)
{
    img_write_opts wo;
    img_default_write_opts(&wo);
    char level[64], times[200];
    snprintf(level, sizeof level, "%d of %d (%dx%d pass)", in->level, in->last_level, in->width, in->height);
    snprintf(times, sizeof times, "frame %.3f s: gi build %.3f s, gi lighting %.3f s, gi view %.3f s, render %.3f s",
             in->frame, in->times.build, in->times.light, in->times.view, in->times.render);
    const char *keys[] = {"partray:scene", "partray:gi", "partray:view_level", "partray:timings"};
    const char *vals[] = {v->scene_path, view_gi_name(in->gi_mode), level, times};
    wo.meta_keys = keys;
    wo.meta_values = vals;
    wo.nmeta = 4;
    diag *d = diag_new();
    if (img_write(path, fb, &wo, d) == PT_OK)
        printf("view: screenshot %s (%s, level %d/%d)\n", path, view_gi_name(in->gi_mode), in->level, in->last_level);
    cli_print_diags(d, 0, 0);
    diag_free(d);
    fflush(stdout);
}

static void screenshot(viewer *v, const char *path)
{
    view_frame_info in;
    framebuffer *fb = view_render_snapshot(v->vr, &in);
    if (!fb) {
        fprintf(stderr, "partray view: no image to save yet\n");
        return;
    }
    char a[1100], b[1100];
    if (!path) {
        for (int i = 1; i < 100000; i++) {
            snprintf(a, sizeof a, "%s-%04d.exr", v->stem, i);
            snprintf(b, sizeof b, "%s-%04d.png", v->stem, i);
            if (!file_exists(a) && !file_exists(b)) break;
        }
        write_image(v, fb, &in, a);
        write_image(v, fb, &in, b);
    } else {
        img_format f = img_format_from_path(path);
        if (f == IMG_FMT_EXR || f == IMG_FMT_PNG) {
            write_image(v, fb, &in, path);
        } else {
            snprintf(a, sizeof a, "%s.exr", path);
            snprintf(b, sizeof b, "%s.png", path);
            write_image(v, fb, &in, a);
            write_image(v, fb, &in, b);
        }
    }
    fb_free(fb);
}

static void write_camera(viewer *v, const char *path)
{
    char block[2048], name[1100];
    view_camera_format(&v->cam, block, sizeof block);
    fputs(block, stdout);
    if (!path) {
        for (int i = 1; i < 100000; i++) {
            snprintf(name, sizeof name, "%s-camera-%04d.inc", v->stem, i);
            if (!file_exists(name)) break;
        }
        path = name;
    }
    FILE *f = fopen(path, "w");
    int ok = f && fputs(block, f) >= 0;
    if (f && fclose(f) != 0) ok = 0;
    if (ok)
        printf("view: camera written to %s\n", path);
    else
        fprintf(stderr, "partray view: cannot write '%s': %s\n", path, strerror(errno));
    fflush(stdout);
}

static void print_mark(viewer *v, const char *name)
{
    double lf, lfm, lr, lrm, lR, lRm, lF, lFm, cf, cfm;
    series_stats(&v->lat_light_first, &lf, &lfm);
    series_stats(&v->lat_light_relit, &lr, &lrm);
    series_stats(&v->lat_light_relit_full, &lR, &lRm);
    series_stats(&v->lat_light_full, &lF, &lFm);
    series_stats(&v->lat_camera_first, &cf, &cfm);
    printf("view: mark %s time=%.4f images=%ld shown=%ld light_moves=%d light_first_ms=%.2f light_first_max_ms=%.2f "
           "light_relit_ms=%.2f light_relit_max_ms=%.2f light_relit_full_ms=%.2f light_relit_full_max_ms=%.2f "
           "light_full_ms=%.2f camera_moves=%d camera_first_ms=%.2f camera_first_max_ms=%.2f\n",
           name, timer_now() - v->t_start, v->published, v->images, v->lat_light_first.n, lf * 1e3, lfm * 1e3, lr * 1e3,
           lrm * 1e3, lR * 1e3, lRm * 1e3, lF * 1e3, v->lat_camera_first.n, cf * 1e3, cfm * 1e3);
    fflush(stdout);
}

/* --------------------------------------------------------------- actions */

static int take_image(viewer *v, double now);
static void present(viewer *v);

static void light_move(viewer *v, int i, vec3 delta)
{
    view_light *l = &v->lights[i];
    l->position = v3_add(l->position, delta);
    /* a spot or cylinder light keeps pointing the same way */
    if (v->light_kinds[i] == LIGHT_SPOT || v->light_kinds[i] == LIGHT_CYLINDER) l->point_at = v3_add(l->point_at, delta);
    v->dirty |= VIEW_CAUSE_LIGHT;
}

/* Which light an action means: 1-based number or 0 = the selected one;
 * -1 when there is none. */
static int light_index(viewer *v, int number)
{
    if (v->nlights == 0) return -1;
    if (number == 0) return v->selected;
    if (number > v->nlights) {
        fprintf(stderr, "partray view: the scene has %d light%s, no light %d\n", v->nlights, v->nlights == 1 ? "" : "s", number);
        return -1;
    }
    return number - 1;
}

/* A script's input event, queued as if the user had made it. */
static void push_input(viewer *v, SDL_Event *e)
{
    SDL_PushEvent(e);
    v->raw_input = 1;
}

static void apply(viewer *v, const view_action *a)
{
    int li;
    switch (a->kind) {
    case VIEW_ACT_NONE:
    case VIEW_ACT_WAIT_IDLE:
        break;
    case VIEW_ACT_SCREENSHOT: screenshot(v, a->text); break;
    case VIEW_ACT_WINDOW_SHOT:
        /* drawn now, so the file shows the state at this event */
        take_image(v, timer_now());
        v->window_shot = a->text;
        present(v);
        break;
    case VIEW_ACT_CAMERA_WRITE: write_camera(v, a->text); break;
    case VIEW_ACT_MARK: print_mark(v, a->text); break;
    case VIEW_ACT_QUIT: v->quit = 1; break;
    case VIEW_ACT_LIGHT_SELECT:
        if (v->nlights == 0) break;
        if (a->light == 0) v->selected = (v->selected + 1) % v->nlights;
        else if ((li = light_index(v, a->light)) >= 0) v->selected = li;
        v->title_time = 0;
        break;
    case VIEW_ACT_LIGHT_MOVE:
        if ((li = light_index(v, a->light)) < 0) break;
        v->selected = li;
        light_move(v, li, v3(a->v[0], a->v[1], a->v[2]));
        break;
    case VIEW_ACT_LIGHT_SCALE:
        if ((li = light_index(v, a->light)) < 0) break;
        v->selected = li;
        v->lights[li].colour.r *= a->v[0];
        v->lights[li].colour.g *= a->v[0];
        v->lights[li].colour.b *= a->v[0];
        v->dirty |= VIEW_CAUSE_LIGHT;
        break;
    case VIEW_ACT_CAMERA_ORBIT:
        view_camera_orbit(&v->cam, a->v[0], a->v[1]);
        v->dirty |= VIEW_CAUSE_CAMERA;
        break;
    case VIEW_ACT_CAMERA_LOOK:
        view_camera_look(&v->cam, a->v[0], a->v[1]);
        v->dirty |= VIEW_CAUSE_CAMERA;
        break;
    case VIEW_ACT_CAMERA_MOVE:
        view_camera_move(&v->cam, a->v[0], a->v[1], a->v[2]);
        v->dirty |= VIEW_CAUSE_CAMERA;
        break;
    case VIEW_ACT_CAMERA_ZOOM:
        view_camera_zoom(&v->cam, a->v[0]);
        v->dirty |= VIEW_CAUSE_CAMERA;
        break;
    case VIEW_ACT_KEY: {
        char name[64];
        snprintf(name, sizeof name, "%s", a->text);
        for (char *p = name; *p; p++)
            if (*p == '_') *p = ' ';
        SDL_Keycode k = SDL_GetKeyFromName(name);
        if (k == SDLK_UNKNOWN) {
            fprintf(stderr, "partray view: unknown key '%s'\n", a->text);
            break;
        }
        SDL_Event e = {.key = {.type = SDL_KEYDOWN, .state = SDL_PRESSED,
                               .keysym = {.sym = k, .scancode = SDL_GetScancodeFromKey(k)}}};
        push_input(v, &e);
        if (v->nrelease < (int)(sizeof v->release / sizeof v->release[0])) {
            v->release[v->nrelease].at = timer_now() + a->v[0];
            v->release[v->nrelease].key = k;
            v->release[v->nrelease].code = e.key.keysym.scancode;
            v->nrelease++;
        }
        break;
    }
    case VIEW_ACT_DRAG: {
        SDL_Event e = {.motion = {.type = SDL_MOUSEMOTION, .state = a->mode == 1 ? SDL_BUTTON_LMASK : SDL_BUTTON_RMASK,
                                  .x = v->width / 2, .y = v->height / 2, .xrel = (Sint32)lround(a->v[0]),
                                  .yrel = (Sint32)lround(a->v[1])}};
        push_input(v, &e);
        break;
    }
    case VIEW_ACT_WHEEL: {
        SDL_Event e = {.wheel = {.type = SDL_MOUSEWHEEL, .y = (Sint32)lround(a->v[0]), .direction = SDL_MOUSEWHEEL_NORMAL}};
        push_input(v, &e);
        break;
    }
    case VIEW_ACT_CLOCK:
        v->clock = a->mode ? v->clock + a->v[0] : a->v[0];
        v->dirty |= VIEW_CAUSE_CLOCK;
        printf("view: clock %g\n", v->clock);
        fflush(stdout);
        break;
    case VIEW_ACT_GI: {
        int m = a->mode < 0 ? view_gi_next(v->gi_mode) : a->mode;
        if (!view_gi_available(m)) {
            fprintf(stderr, "partray view: GI mode '%s' is not available in the viewer\n", view_gi_name(m));
            break;
        }
        if (m != v->gi_mode) {
            v->gi_mode = m;
            v->dirty |= VIEW_CAUSE_MODE;
            printf("view: gi %s\n", view_gi_name(m));
            fflush(stdout);
        }
        break;
    }
    }
}

static view_action act(view_action_kind k) { view_action a = {k, 0, 0, {0, 0, 0}, NULL}; return a; }

static view_action act3(view_action_kind k, double x, double y, double z)
{
    view_action a = act(k);
    a.v[0] = x;
    a.v[1] = y;
    a.v[2] = z;
    return a;
}

/* ----------------------------------------------------------------- input */

static void on_key(viewer *v, const SDL_KeyboardEvent *k)
{
    SDL_Keycode c = k->keysym.sym;
    view_action a;
    if (c >= SDLK_1 && c <= SDLK_9) {
        a = act(VIEW_ACT_LIGHT_SELECT);
        a.light = (int)(c - SDLK_0);
        if (a.light <= v->nlights) apply(v, &a);
        return;
    }
    switch (c) {
    case SDLK_ESCAPE: a = act(VIEW_ACT_QUIT); break;
    case SDLK_TAB: a = act(VIEW_ACT_LIGHT_SELECT); break;
    case SDLK_F12:
    case SDLK_p: a = act(VIEW_ACT_SCREENSHOT); break;
    case SDLK_c: a = act(VIEW_ACT_CAMERA_WRITE); break;
    case SDLK_g: a = act(VIEW_ACT_GI); a.mode = -1; break;
    case SDLK_LEFTBRACKET: a = act3(VIEW_ACT_CLOCK, -0.05, 0, 0); a.mode = 1; break;
    case SDLK_RIGHTBRACKET: a = act3(VIEW_ACT_CLOCK, 0.05, 0, 0); a.mode = 1; break;
    case SDLK_PLUS:
    case SDLK_EQUALS:
    case SDLK_KP_PLUS: a = act3(VIEW_ACT_LIGHT_SCALE, 1.25, 0, 0); break;
    case SDLK_MINUS:
    case SDLK_KP_MINUS: a = act3(VIEW_ACT_LIGHT_SCALE, 0.8, 0, 0); break;
    case SDLK_h: fputs(view_usage, stdout); return;
    case SDLK_o:
        v->overlay = !v->overlay;
        v->need_present = 1;
        return;
    case SDLK_r:
        v->cam = v->cam_home;
        v->dirty |= VIEW_CAUSE_CAMERA;
        return;
    default: return;
    }
    apply(v, &a);
}

/* Held keys: flying and light moves, scaled by the tick's length. */
static void held_keys(viewer *v, double dt)
{
    const unsigned char *ks = v->held;
    double speed = 0.25 * v->scale * dt;
    if (ks[SDL_SCANCODE_LSHIFT] || ks[SDL_SCANCODE_RSHIFT]) speed *= 4;
    if (ks[SDL_SCANCODE_LCTRL] || ks[SDL_SCANCODE_RCTRL]) speed *= 0.25;
    double f = (ks[SDL_SCANCODE_W] ? 1 : 0) - (ks[SDL_SCANCODE_S] ? 1 : 0);
    double r = (ks[SDL_SCANCODE_D] ? 1 : 0) - (ks[SDL_SCANCODE_A] ? 1 : 0);
    double u = (ks[SDL_SCANCODE_E] ? 1 : 0) - (ks[SDL_SCANCODE_Q] ? 1 : 0);
    if (f || r || u) {
        view_action a = act3(VIEW_ACT_CAMERA_MOVE, f * speed, r * speed, u * speed);
        apply(v, &a);
    }
    double lr = (ks[SDL_SCANCODE_RIGHT] ? 1 : 0) - (ks[SDL_SCANCODE_LEFT] ? 1 : 0);
    double lf = (ks[SDL_SCANCODE_UP] ? 1 : 0) - (ks[SDL_SCANCODE_DOWN] ? 1 : 0);
    double lu = (ks[SDL_SCANCODE_PAGEUP] ? 1 : 0) - (ks[SDL_SCANCODE_PAGEDOWN] ? 1 : 0);
    if ((lr || lf || lu) && v->nlights > 0) {
        /* screen-horizontal: right and forward flattened onto the ground */
        vec3 fw, rt;
        view_camera_frame(&v->cam, &fw, &rt, NULL);
        vec3 sky = v->cam.sky;
        fw = v3_norm(v3_sub(fw, v3_scale(sky, v3_dot(fw, sky))));
        rt = v3_norm(v3_sub(rt, v3_scale(sky, v3_dot(rt, sky))));
        vec3 d = v3_add(v3_add(v3_scale(rt, lr * speed), v3_scale(fw, lf * speed)), v3_scale(sky, lu * speed));
        view_action a = act3(VIEW_ACT_LIGHT_MOVE, d.x, d.y, d.z);
        apply(v, &a);
    }
}

static void on_event(viewer *v, const SDL_Event *e)
{
    switch (e->type) {
    case SDL_QUIT: v->quit = 1; break;
    case SDL_WINDOWEVENT: v->need_present = 1; break;
    case SDL_KEYDOWN:
        if (e->key.keysym.scancode < SDL_NUM_SCANCODES) v->held[e->key.keysym.scancode] = 1;
        if (!e->key.repeat) on_key(v, &e->key);
        break;
    case SDL_KEYUP:
        if (e->key.keysym.scancode < SDL_NUM_SCANCODES) v->held[e->key.keysym.scancode] = 0;
        break;
    case SDL_MOUSEMOTION:
        if (e->motion.state & SDL_BUTTON_LMASK) {
            view_action a = act3(VIEW_ACT_CAMERA_ORBIT, -0.3 * e->motion.xrel, 0.3 * e->motion.yrel, 0);
            apply(v, &a);
        } else if (e->motion.state & SDL_BUTTON_RMASK) {
            view_action a = act3(VIEW_ACT_CAMERA_LOOK, 0.2 * e->motion.xrel, -0.2 * e->motion.yrel, 0);
            apply(v, &a);
        }
        break;
    case SDL_MOUSEWHEEL:
        if (e->wheel.y != 0) {
            view_action a = act3(VIEW_ACT_CAMERA_ZOOM, pow(0.9, e->wheel.y), 0, 0);
            apply(v, &a);
        }
        break;
    default: break;
    }
}

/* ----------------------------------------------------------------- frame */

static void update_title(viewer *v, double now)
{
    if (!v->win) return;
    double rate = 0;
    int k = 0;
    for (int i = 0; i < v->nrecent; i++)
        if (now - v->recent[i] <= 1.0) k++;
    rate = k;
    double busy_for = 0;
    int busy = view_render_busy(v->vr, &busy_for);
    const view_frame_info *in = &v->info;
    char title[512], light[96] = "no lights", work[48] = "idle";
    if (v->nlights > 0) {
        const view_light *l = &v->lights[v->selected];
        snprintf(light, sizeof light, "light %d/%d <%.3g,%.3g,%.3g> x%.3g", v->selected + 1, v->nlights, l->position.x,
                 l->position.y, l->position.z, (l->colour.r + l->colour.g + l->colour.b) / 3);
    }
    if (busy >= 0) snprintf(work, sizeof work, "L%d %.1fs", busy, busy_for);
    char mode[64];
    if (v->have_image && in->wanted_mode != in->gi_mode)
        snprintf(mode, sizeof mode, "%s (building %s)", view_gi_name(in->gi_mode), view_gi_name(in->wanted_mode));
    else if (v->have_image && (in->gi_stale || in->gi_coarse))
        snprintf(mode, sizeof mode, "%s (%s)", view_gi_name(in->gi_mode), in->gi_stale ? "relighting" : "preview GI, relighting");
    else
        snprintf(mode, sizeof mode, "%s", view_gi_name(v->have_image ? in->gi_mode : v->gi_mode));
    if (!v->have_image) {
        snprintf(title, sizeof title, "partray view: %s | %s | first image... (%s)", v->stem, mode, work);
    } else {
        snprintf(title, sizeof title,
                 "partray view: %s | %s | %dx%d L%d/%d | frame %.0f ms (build %.0f, light %.0f, view %.0f, render %.0f) "
                 "| %.0f img/s | %s | %s | %s",
                 v->stem, mode, in->width, in->height, in->level, in->last_level, in->frame * 1e3,
                 in->times.build * 1e3, in->times.light * 1e3, in->times.view * 1e3, in->times.render * 1e3, rate,
                 in->describe, light, work);
    }
    SDL_SetWindowTitle(v->win, title);
}

/* Take a new image from the render thread if there is one. */
static int take_image(viewer *v, double now)
{
    view_frame_info in;
    if (!view_render_fetch(v->vr, &v->serial, v->rgba, &in)) return 0;
    v->info = in;
    v->images++;
    v->published = in.serial;
    if (in.clock_busy) v->images_clock_busy++;
    if (v->verbose)
        printf("view: image %ld gen %ld L%d/%d %dx%d %s%s%s frame %.1f ms (build %.1f light %.1f view %.1f render %.1f) "
               "cpu %.1f ms (light %.1f) latency %.1f ms%s%s%s [%s]\n",
               in.serial, in.generation, in.level, in.last_level, in.width, in.height, view_gi_name(in.gi_mode),
               in.wanted_mode != in.gi_mode ? " building " : "", in.wanted_mode != in.gi_mode ? view_gi_name(in.wanted_mode) : "",
               in.frame * 1e3, in.times.build * 1e3, in.times.light * 1e3, in.times.view * 1e3, in.times.render * 1e3,
               in.frame_cpu * 1e3, in.light_cpu * 1e3, in.latency * 1e3, in.cause & VIEW_CAUSE_LIGHT ? " light" : "", in.cause & VIEW_CAUSE_CAMERA ? " camera" : "",
               in.gi_stale ? " gi-stale" : (in.gi_coarse ? " gi-coarse" : ""), in.describe);
    if (!v->have_image) v->t_first_image = now;
    v->have_image = 1;
    if (v->nrecent == (int)(sizeof v->recent / sizeof v->recent[0])) {
        memmove(v->recent, v->recent + 1, sizeof v->recent - sizeof v->recent[0]);
        v->nrecent--;
    }
    v->recent[v->nrecent++] = now;
    /* latencies per generation, from the render thread's figures (an
     * image the UI did not fetch in time still counts) */
    if (in.generation != v->last_gen_first && in.first_latency > 0) {
        v->last_gen_first = in.generation;
        if (in.cause & VIEW_CAUSE_LIGHT) series_add(&v->lat_light_first, in.first_latency);
        else if (in.cause & VIEW_CAUSE_CAMERA) series_add(&v->lat_camera_first, in.first_latency);
    }
    if (in.generation != v->last_gen_relit && in.relit_latency > 0) {
        v->last_gen_relit = in.generation;
        if (in.cause & VIEW_CAUSE_LIGHT) series_add(&v->lat_light_relit, in.relit_latency);
    }
    if (in.generation != v->last_gen_relit_full && in.relit_full_latency > 0) {
        v->last_gen_relit_full = in.generation;
        if (in.cause & VIEW_CAUSE_LIGHT) series_add(&v->lat_light_relit_full, in.relit_full_latency);
    }
    if (in.generation != v->last_gen_full && in.full_latency > 0) {
        v->last_gen_full = in.generation;
        if (in.cause & VIEW_CAUSE_LIGHT) series_add(&v->lat_light_full, in.full_latency);
    }
    if (v->tex) {
        SDL_Rect r = {0, 0, in.width, in.height};
        SDL_UpdateTexture(v->tex, &r, v->rgba, in.width * 4);
    }
    v->need_present = 1;
    return 1;
}

/* The overlay's lines: the same figures as the title bar. */
static int overlay_lines(viewer *v, double now, char lines[][128], int max)
{
    const view_frame_info *in = &v->info;
    int n = 0;
    double busy_for = 0;
    int busy = view_render_busy(v->vr, &busy_for);
    int k = 0;
    for (int i = 0; i < v->nrecent; i++)
        if (now - v->recent[i] <= 1.0) k++;
    char work[48] = "IDLE";
    if (busy >= 0) snprintf(work, sizeof work, "BUSY L%d %.1f S", busy, busy_for);
    if (!v->have_image) {
        snprintf(lines[n++], 128, "%s: FIRST IMAGE... (%s)", view_gi_name(v->gi_mode), work);
        return n;
    }
    if (in->wanted_mode != in->gi_mode)
        snprintf(lines[n++], 128, "%s (BUILDING %s) %dX%d L%d/%d %d IMG/S %s", view_gi_name(in->gi_mode),
                 view_gi_name(in->wanted_mode), in->width, in->height, in->level, in->last_level, k, work);
    else
        snprintf(lines[n++], 128, "%s %dX%d L%d/%d %d IMG/S %s", view_gi_name(in->gi_mode), in->width, in->height,
                 in->level, in->last_level, k, work);
    snprintf(lines[n++], 128, "FRAME %.0f MS: BUILD %.0f LIGHT %.0f VIEW %.0f RENDER %.0f", in->frame * 1e3,
             in->times.build * 1e3, in->times.light * 1e3, in->times.view * 1e3, in->times.render * 1e3);
    if (n < max && (in->clock != 0.0 || v->clock != 0.0 || in->clock_updates > 0))
        snprintf(lines[n++], 128, "CLOCK %g%s", in->clock, in->clock != v->clock ? " (PREPARING THE NEW CLOCK)" : "");
    snprintf(lines[n++], 128, "LATENCY %.0f MS%s%s", in->latency * 1e3, in->gi_stale ? ", GI STALE (RELIGHTING)" : (in->gi_coarse ? ", PREVIEW GI (RELIGHTING)" : ""),
             in->complete ? ", DONE" : "");
    if (n < max && in->describe[0]) snprintf(lines[n++], 128, "%.80s", in->describe);
    if (n < max && v->nlights > 0) {
        const view_light *l = &v->lights[v->selected];
        snprintf(lines[n++], 128, "LIGHT %d/%d <%.3g,%.3g,%.3g> X%.3g", v->selected + 1, v->nlights, l->position.x,
                 l->position.y, l->position.z, (l->colour.r + l->colour.g + l->colour.b) / 3);
    }
    return n;
}

/* `window PATH`: the window's pixels as drawn, 8-bit sRGB, into a PNG. */
static void save_window(viewer *v, const char *path)
{
    int w = 0, h = 0;
    if (SDL_GetRendererOutputSize(v->ren, &w, &h) != 0 || w < 1 || h < 1) {
        fprintf(stderr, "partray view: cannot read the window: %s\n", SDL_GetError());
        return;
    }
    uint8_t *px = malloc((size_t)w * (size_t)h * 4u);
    framebuffer *fb = fb_new(w, h);
    if (px && fb && SDL_RenderReadPixels(v->ren, NULL, SDL_PIXELFORMAT_RGBA32, px, w * 4) == 0) {
        /* decoded to linear so that the PNG writer's sRGB encoding gives the
         * same 8-bit values back */
        float lut[256];
        for (int i = 0; i < 256; i++) lut[i] = (float)img_srgb_decode(i / 255.0);
        for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
            for (int c = 0; c < 3; c++) fb->rgb[3 * i + (size_t)c] = lut[px[4 * i + (size_t)c]];
        img_write_opts wo;
        img_default_write_opts(&wo);
        diag *d = diag_new();
        if (img_write(path, fb, &wo, d) == PT_OK) printf("view: window %s (%dx%d, overlay %s)\n", path, w, h, v->overlay ? "on" : "off");
        cli_print_diags(d, 0, 0);
        diag_free(d);
        fflush(stdout);
    } else {
        fprintf(stderr, "partray view: cannot read the window: %s\n", SDL_GetError());
    }
    free(px);
    fb_free(fb);
}

static void present(viewer *v)
{
    if (!v->ren) return;
    SDL_SetRenderDrawColor(v->ren, 0, 0, 0, 255);
    SDL_RenderClear(v->ren);
    if (v->have_image) {
        /* the pass's corner of the texture, stretched over the window */
        SDL_Rect r = {0, 0, v->info.width, v->info.height};
        SDL_RenderCopy(v->ren, v->tex, &r, NULL);
    }
    if (v->overlay && v->otex) {
        char lines[7][128];
        const char *lp[7];
        int n = overlay_lines(v, timer_now(), lines, 7);
        for (int i = 0; i < n; i++) lp[i] = lines[i];
        int scale = v->width >= 900 ? 2 : 1;
        /* drawn at the top left of a cleared buffer the size of the box */
        view_overlay_box b = view_overlay_measure(lp, n, scale);
        if (b.w > v->width) b.w = v->width;
        if (b.h > v->height) b.h = v->height;
        if (b.w > 0 && b.h > 0) {
            memset(v->orgba, 0, (size_t)b.w * (size_t)b.h * 4u);
            view_overlay_draw(v->orgba, b.w, b.h, 0, 0, lp, n, scale, 160);
            SDL_Rect r = {0, 0, b.w, b.h};
            SDL_UpdateTexture(v->otex, &r, v->orgba, b.w * 4);
            SDL_RenderCopy(v->ren, v->otex, &r, &r);
        }
    }
    if (v->window_shot) {
        save_window(v, v->window_shot);
        v->window_shot = NULL;
    }
    SDL_RenderPresent(v->ren);
    v->need_present = 0;
}

static int open_window(viewer *v)
{
    char why[300];
    if (!view_sdl_load(why, sizeof why)) {
        fprintf(stderr, "partray view: cannot open a window: %s\n", why);
        return 0;
    }
    SDL_SetMainReady();
    if (SDL_Init(SDL_INIT_VIDEO) != 0) {
        fprintf(stderr, "partray view: cannot open a window: %s\n", SDL_GetError());
        return 0;
    }
    char title[300];
    snprintf(title, sizeof title, "partray view: %s", v->stem);
    v->win = SDL_CreateWindow(title, SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, v->width, v->height,
                              SDL_WINDOW_RESIZABLE);
    if (!v->win) {
        fprintf(stderr, "partray view: cannot open a window: %s\n", SDL_GetError());
        return 0;
    }
    v->ren = SDL_CreateRenderer(v->win, -1, 0);
    if (!v->ren) v->ren = SDL_CreateRenderer(v->win, -1, SDL_RENDERER_SOFTWARE);
    if (!v->ren) {
        fprintf(stderr, "partray view: cannot create a renderer: %s\n", SDL_GetError());
        return 0;
    }
    SDL_RenderSetLogicalSize(v->ren, v->width, v->height);
    v->tex = SDL_CreateTexture(v->ren, SDL_PIXELFORMAT_RGBA32, SDL_TEXTUREACCESS_STREAMING, v->width, v->height);
    if (!v->tex) {
        fprintf(stderr, "partray view: cannot create a texture: %s\n", SDL_GetError());
        return 0;
    }
    SDL_SetTextureScaleMode(v->tex, SDL_ScaleModeLinear); /* previews are stretched */
    v->otex = SDL_CreateTexture(v->ren, SDL_PIXELFORMAT_RGBA32, SDL_TEXTUREACCESS_STREAMING, v->width, v->height);
    v->orgba = calloc((size_t)v->width * (size_t)v->height, 4);
    if (!v->otex || !v->orgba) {
        fprintf(stderr, "partray view: cannot create the overlay: %s\n", SDL_GetError());
        return 0;
    }
    SDL_SetTextureBlendMode(v->otex, SDL_BLENDMODE_BLEND);
    v->need_present = 1;
    return 1;
}

static void close_window(viewer *v)
{
    if (!view_sdl_load(NULL, 0)) return; /* no window was opened */
    if (v->tex) SDL_DestroyTexture(v->tex);
    if (v->otex) SDL_DestroyTexture(v->otex);
    free(v->orgba);
    if (v->ren) SDL_DestroyRenderer(v->ren);
    if (v->win) SDL_DestroyWindow(v->win);
    SDL_Quit();
}

static void run_loop(viewer *v)
{
    double last = timer_now();
    while (!v->quit) {
        SDL_Event e;
        if (SDL_WaitEventTimeout(&e, 4)) {
            on_event(v, &e);
            while (!v->quit && SDL_PollEvent(&e)) on_event(v, &e);
        }
        double now = timer_now();
        double dt = now - last;
        last = now;
        held_keys(v, dt > 0.1 ? 0.1 : dt);
        for (int i = 0; i < v->nrelease; i++) {
            if (now < v->release[i].at) continue;
            SDL_Event up;
            memset(&up, 0, sizeof up);
            up.type = SDL_KEYUP;
            up.key.state = SDL_RELEASED;
            up.key.keysym.sym = v->release[i].key;
            up.key.keysym.scancode = v->release[i].code;
            SDL_PushEvent(&up);
            v->release[i--] = v->release[--v->nrelease];
        }
        flush_state(v);
        int fresh = take_image(v, now);
        if (v->script) {
            if (v->have_image) view_script_start(v->script, now);
            view_action a;
            /* idle is asked after every action has been posted; raw input
             * goes through the event queue first (next tick) */
            v->raw_input = 0;
            while (!v->quit && !v->raw_input && view_script_next(v->script, timer_now(), view_render_idle(v->vr), &a)) {
                apply(v, &a);
                flush_state(v);
            }
        }
        flush_messages(v);
        if (fresh || now - v->title_time > 0.25) {
            update_title(v, now);
            v->title_time = now;
            if (v->overlay) v->need_present = 1; /* the overlay's figures (busy time, img/s) */
        }
        if (v->need_present) present(v);
    }
}

/* --------------------------------------------------------------- command */

/* Takes the viewer's own options out of argv (into *script, *preview). */
static int split_args(int argc, char **argv, char **rest, int *nrest, const char **script, int *preview, int *ref_spp,
                      long *preview_particles, int *verbose, char *err, int n)
{
    *nrest = 0;
    for (int i = 0; i < argc; i++) {
        if (strcmp(argv[i], "--verbose") == 0 || strcmp(argv[i], "-v") == 0) {
            *verbose = 1;
        } else if (strcmp(argv[i], "--preview-particles") == 0) {
            char *end;
            long k = i + 1 < argc ? strtol(argv[i + 1], &end, 10) : 0;
            if (i + 1 >= argc || *end || k < -1 || k > 100000000) {
                snprintf(err, (size_t)n, "--preview-particles wants a count (0: 1/8 of --particles, -1: none)");
                return 0;
            }
            *preview_particles = k;
            i++;
        } else if (strcmp(argv[i], "--ref-spp") == 0) {
            char *end;
            long k = i + 1 < argc ? strtol(argv[i + 1], &end, 10) : 0;
            if (i + 1 >= argc || *end || k < 1 || k > 65536) {
                snprintf(err, (size_t)n, "--ref-spp wants a sample count from 1 to 65536");
                return 0;
            }
            *ref_spp = (int)k;
            i++;
        } else if (strcmp(argv[i], "--script") == 0 || strcmp(argv[i], "--preview") == 0) {
            if (i + 1 >= argc) {
                snprintf(err, (size_t)n, "option '%s' needs a value", argv[i]);
                return 0;
            }
            if (argv[i][2] == 's') {
                *script = argv[++i];
            } else {
                char *end;
                long d = strtol(argv[++i], &end, 10);
                if (*end || d < 1 || d > 64) {
                    snprintf(err, (size_t)n, "--preview wants a divisor from 1 to 64");
                    return 0;
                }
                *preview = (int)d;
            }
        } else {
            rest[(*nrest)++] = argv[i];
        }
    }
    return 1;
}

/* The scene file at another clock, opened as at the start (the render
 * thread's view_render_opts.scene_at; runs on the clock thread). */
typedef struct {
    const char *path;
    sdl_options so;
    int threads;
} scene_source;

static pt_status scene_at(void *ctx, double clock, scene **sc, accel **a, diag *d)
{
    const scene_source *src = ctx;
    sdl_options so = src->so;
    sdl_set_still_clock(&so, clock);
    *sc = NULL;
    *a = NULL;
    pt_status st = pipeline_parse(src->path, &so, sc, d, NULL);
    if (st != PT_OK) return st;
    *a = pipeline_accel(*sc, src->threads, d, &st, NULL);
    if (!*a) {
        scene_free(*sc);
        *sc = NULL;
        return st;
    }
    return PT_OK;
}

int cmd_view(int argc, char **argv)
{
    char err[512];
    for (int i = 0; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            fputs(view_usage, stdout);
            return EXIT_OK;
        }
    }
    char **rest = calloc((size_t)argc + 1, sizeof *rest);
    if (!rest) return EXIT_IO;
    int nrest = 0, preview = 0, ref_spp = 0, verbose = 0;
    long preview_particles = 0;
    const char *script_path = NULL;
    cli_render o;
    if (!split_args(argc, argv, rest, &nrest, &script_path, &preview, &ref_spp, &preview_particles, &verbose, err, sizeof err) ||
        cli_parse_render(nrest, rest, &o, err, sizeof err)) {
        fprintf(stderr, "partray view: %s\n%s", err, view_usage);
        free(rest);
        return EXIT_USAGE;
    }
    free(rest);
    int gi = -1;
    if (o.gi) {
        gi = gi_mode_parse(o.gi);
        if (gi < 0) {
            fprintf(stderr, "partray view: unknown --gi mode '%s' (none, particle, links, path, pmfg)\n", o.gi);
            return EXIT_USAGE;
        }
    }

    viewer v = {.t_start = timer_now(), .verbose = verbose, .overlay = 1, .scene_path = o.scene,
                .width = o.width > 0 ? o.width : 512, .height = o.height > 0 ? o.height : (o.width > 0 ? o.width : 512),
                .threads = o.threads > 0 ? o.threads : pool_default_threads()};
    v.last_gen_first = v.last_gen_full = v.last_gen_relit = v.last_gen_relit_full = -1;
    scene_stem(o.scene, v.stem, sizeof v.stem);

    diag *d = diag_new();
    if (script_path) {
        pt_status st = view_script_load(script_path, &v.script, d);
        cli_print_diags(d, 0, 0);
        if (st != PT_OK) {
            diag_free(d);
            return status_exit(st);
        }
    }

    /* the scene opened as `partray render` opens it (pipeline.h): the same
     * options, limits and function evaluators */
    sdl_options so;
    pipeline_sdl_options(&so, &o, v.width, v.height);
    if (o.clock_given) sdl_set_still_clock(&so, o.clock);
    v.clock = o.clock_given ? o.clock : 0.0;
    scene_source source = {o.scene, so, v.threads};
    scene *sc = NULL;
    diag *pd = diag_new();
    pt_status st = pipeline_parse(o.scene, &so, &sc, pd, NULL);
    cli_print_diags(pd, 0, 0);
    diag_free(pd);
    if (st != PT_OK) {
        view_script_free(v.script);
        diag_free(d);
        return status_exit(st);
    }
    if (gi < 0) {
        gi = pipeline_gi_mode(NULL, sc, 9);
        if (!view_gi_available(gi)) gi = GI_NONE;
    }
    if (!view_gi_available(gi)) {
        fprintf(stderr, "partray view: GI mode '%s' is not available in the viewer; using none\n", gi_mode_name(gi));
        gi = GI_NONE;
    }
    v.gi_mode = gi;

    diag *ad = diag_new();
    accel *acc = pipeline_accel(sc, v.threads, ad, &st, NULL);
    cli_print_diags(ad, 0, 0);
    diag_free(ad);
    if (!acc) {
        scene_free(sc);
        view_script_free(v.script);
        diag_free(d);
        return status_exit(st);
    }
    v.scale = accel_scale(acc);
    if (!(v.scale > 0) || !isfinite(v.scale)) v.scale = 10;

    /* camera: look_at falls back to the first surface along the view */
    double fallback = 0.5 * v.scale;
    {
        accel_hit h;
        if (accel_intersect(acc, sc->camera.location, v3_norm(sc->camera.direction), 0, INFINITY, &h)) fallback = h.t;
    }
    view_camera_from_scene(&v.cam, &sc->camera, fallback);
    v.cam_home = v.cam;

    v.nlights = sc->nlights;
    v.lights = calloc((size_t)(v.nlights > 0 ? v.nlights : 1), sizeof *v.lights);
    v.light_kinds = calloc((size_t)(v.nlights > 0 ? v.nlights : 1), sizeof *v.light_kinds);
    v.rgba = calloc((size_t)v.width * (size_t)v.height, 4);
    v.msgs = d;
    int rc = EXIT_OK;
    if (!v.lights || !v.light_kinds || !v.rgba) rc = EXIT_IO;
    for (int i = 0; rc == EXIT_OK && i < v.nlights; i++) {
        v.lights[i].position = sc->lights[i].position;
        v.lights[i].point_at = sc->lights[i].point_at;
        v.lights[i].colour = sc->lights[i].colour;
        v.light_kinds[i] = sc->lights[i].kind;
    }

    if (rc == EXIT_OK && !open_window(&v)) rc = EXIT_IO;
    for (int i = 0; rc == EXIT_OK && v.script && i < view_script_count(v.script); i++) {
        const view_action *a = view_script_action(v.script, i);
        if (a->kind != VIEW_ACT_KEY) continue;
        char name[64];
        snprintf(name, sizeof name, "%s", a->text);
        for (char *p = name; *p; p++)
            if (*p == '_') *p = ' ';
        if (SDL_GetKeyFromName(name) == SDLK_UNKNOWN) {
            fprintf(stderr, "%s: error: unknown key name '%s' (SDL key names, '_' for spaces)\n", script_path, a->text);
            rc = EXIT_SCENE;
        }
    }
    if (rc == EXIT_OK) {
        view_render_opts ro = {v.width,   v.height,          v.threads, o.seed,  preview, ref_spp, o.particles,
                               o.bounces, o.cl_device,        preview_particles, scene_at, &source, v.clock};
        view_state s0 = current_state(&v);
        diag *rd = diag_new();
        st = view_render_start(&v.vr, sc, acc, &ro, &s0, rd);
        cli_print_diags(rd, 0, 0);
        diag_free(rd);
        if (st != PT_OK) rc = status_exit(st);
    }
    if (rc == EXIT_OK) {
        printf("view: %s %dx%d, gi %s, %d threads, %d light%s%s\n", v.stem, v.width, v.height, view_gi_name(v.gi_mode),
               v.threads, v.nlights, v.nlights == 1 ? "" : "s", v.script ? ", scripted" : "");
        fflush(stdout);
        run_loop(&v);
        double now = timer_now();
        double span = now - v.t_first_image;
        double lf, lfm, lr, lrm, lR, lRm, lF, lFm, cf, cfm;
        series_stats(&v.lat_light_first, &lf, &lfm);
        series_stats(&v.lat_light_relit, &lr, &lrm);
        series_stats(&v.lat_light_relit_full, &lR, &lRm);
        series_stats(&v.lat_light_full, &lF, &lFm);
        series_stats(&v.lat_camera_first, &cf, &cfm);
        fprintf(stderr,
                "view: %ld images (%ld shown) in %.2f s (%.1f/s), first image after %.3f s; light move -> image %.1f ms mean, %.1f ms "
                "max (%d), -> relit image %.1f ms mean, %.1f ms max (%d), -> image relit by the full GI %.1f ms mean, -> full "
                "resolution %.1f ms mean; camera move -> image %.1f ms mean (%d)\n",
                v.published, v.images, span, span > 0 ? v.published / span : 0.0, v.t_first_image - v.t_start, lf * 1e3, lfm * 1e3,
                v.lat_light_first.n, lr * 1e3, lrm * 1e3, v.lat_light_relit.n, lR * 1e3, lF * 1e3, cf * 1e3, v.lat_camera_first.n);
        if (v.info.clock_updates > 0 || v.clock != v.info.clock)
            fprintf(stderr, "view: clock %g shown (%g asked): %ld scene%s at a new clock taken over, the last after %.3f s; %ld "
                            "images shown while one was prepared\n",
                    v.info.clock, v.clock, v.info.clock_updates, v.info.clock_updates == 1 ? "" : "s", v.info.clock_update,
                    v.images_clock_busy);
        view_render_stop(v.vr);
        v.vr = NULL;
    }
    close_window(&v);
    free(v.lights);
    free(v.light_kinds);
    free(v.rgba);
    view_script_free(v.script);
    accel_free(acc);
    scene_free(sc);
    diag_free(d);
    return rc;
}
