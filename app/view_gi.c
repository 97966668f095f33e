/* view_gi.c - the function table of the viewer's lighting modes. */
#include "view_gi.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "gi.h"
#include "shade.h"
#include "shade_atmos.h"
#include "shade_texture.h"
#include "timer.h"
#include "gi_particle.h"
#include "gi_vlinks.h"
#include "pm_fg.h"
#include "radrules.h"
#include "pm_path.h"
#include "render_gi.h"
#include "caustics.h"

/* A mode's state (ctx) is ctx_size bytes that view_gi_open allocates
 * zeroed and view_gi_close frees: open fills it (and may leave it half
 * filled when it fails), close (NULL: nothing to do) frees what it holds. */
typedef struct {
    int mode;
    /* the lighting stage can be slow (none: the caustic layer's photons;
     * particle: its lighting stage): a pass with the new lights and the
     * old GI first, when the last stage took longer than a preview */
    int slow_light;
    size_t ctx_size;
    int (*last_level)(const view_gi_opts *o);
    pt_status (*open)(void *ctx, const scene *sc, const accel *a, const view_gi_opts *o, view_gi_times *t, diag *d);
    pt_status (*relight)(void *ctx, volatile int *cancel, view_gi_times *t, diag *d);
    int (*has_preview)(void *ctx); /* NULL: no preview lighting */
    pt_status (*relight_preview)(void *ctx, volatile int *cancel, view_gi_times *t, diag *d);
    pt_status (*render)(void *ctx, const view_gi_pass *p, framebuffer *fb, view_gi_times *t, diag *d);
    void (*describe)(void *ctx, char *buf, int n);
    void (*close)(void *ctx);
    /* NULL: the mode cannot follow a new scene (view_gi_reframe) */
    pt_status (*reframe)(void *ctx, const scene *sc, const accel *a, volatile int *cancel, view_gi_times *t, diag *d);
    void (*adopt)(void *ctx);
    /* NULL or 0: open ran the lighting stage; 1: open left it to the
     * first relight (the mode opens stale) */
    int (*pending)(void *ctx);
} gi_backend;

struct view_gi {
    const gi_backend *b;
    void *ctx;
    view_gi_opts o;
    int last_level;
    int stale;            /* lights changed since the last complete lighting stage */
    double t_light;       /* seconds of the last complete lighting stage */
    int preview_fresh;    /* the preview lighting is up to date with the lights */
    int last_coarse;      /* the last pass used the preview lighting */
    scene sc;             /* shallow copy: own camera and lights, shared objects */
    scene_light *lights;
    /* the scene a reframe computed for, until view_gi_adopt */
    scene next_sc;
    scene_light *next_lights;
    int reframed;
};

/* --------------------------------------------------------- caustic layer */
/* The scene's photons{} in the none and particle modes, as `partray
 * render` has them (caustics.h): shot when particle opens and by none's
 * first relight (none opens stale), and again by a relight when the
 * lights differ from those the layer was shot from. A
 * camera move needs nothing: the layer's G-buffer is the opening camera's,
 * and a lookup away from it is answered from the photons themselves
 * (gi_caustic_at). A new layer is built in the free slot and takes over
 * only when complete, so a cancelled relight keeps the old one; a slot is
 * its layer's hook context, so slots never move. */
typedef struct {
    caustics slot[2];
    int cur;
    scene_light *lights;   /* the lights the current layer was shot from */
    int nlights;
} view_caus;

static caustics *caus_cur(view_caus *v) { return v->slot[v->cur].layer ? &v->slot[v->cur] : NULL; }

/* The lights differ from the current layer's (or there is none yet). */
static int caus_stale(const view_caus *v, const scene *sc)
{
    if (!sc->global.photons.enabled) return 0;
    return !v->lights || v->nlights != sc->nlights ||
           (sc->nlights > 0 && memcmp(v->lights, sc->lights, (size_t)sc->nlights * sizeof *sc->lights) != 0);
}

/* Shoots the layer for the scene's lights unless it is up to date. The
 * scene's photon warnings go to d when the mode opens (first), not again
 * at each relight. */
static pt_status caus_update(view_caus *v, const scene *sc, const accel *a, const view_gi_opts *o,
                             volatile int *cancel, diag *d)
{
    if (!caus_stale(v, sc)) return PT_OK;
    int first = v->lights == NULL, nxt = 1 - v->cur;
    diag *dl = first ? d : diag_new();
    if (!dl) return PT_ERR_NOMEM;
    int w = o->width > 0 ? o->width : 160, h = o->height > 0 ? o->height : 120;
    pt_status st = caustics_build(&v->slot[nxt], sc, a, w, h, o->threads, o->seed, o->cl_device, 0, 0.0, 0, cancel, dl);
    if (!first) {
        if (st != PT_OK) diag_error(d, "caustic layer: %s", pt_status_name(st));
        diag_free(dl);
    }
    if (st != PT_OK || (cancel && *cancel)) {
        caustics_free(&v->slot[nxt]);
        return st;
    }
    scene_light *l = malloc((size_t)(sc->nlights > 0 ? sc->nlights : 1) * sizeof *l);
    if (!l) {
        caustics_free(&v->slot[nxt]);
        return PT_ERR_NOMEM;
    }
    if (sc->nlights > 0) memcpy(l, sc->lights, (size_t)sc->nlights * sizeof *l);
    caustics_free(&v->slot[v->cur]);
    v->cur = nxt;
    free(v->lights);
    v->lights = l;
    v->nlights = sc->nlights;
    return PT_OK;
}

static void caus_free(view_caus *v)
{
    caustics_free(&v->slot[0]);
    caustics_free(&v->slot[1]);
    free(v->lights);
    v->lights = NULL;
}

/* ------------------------------------------------------------------ none */

typedef struct {
    const scene *sc;
    const accel *a;
    view_gi_opts o;
    view_caus caus;
    long rays;
} none_ctx;

/* Shade settings for a pass of the Whitted renderer (none and particle). */
static void whitted_settings(shade_settings *ss, const view_gi_pass *p)
{
    shade_default_settings(ss);
    ss->width = p->width;
    ss->height = p->height;
    ss->threads = p->threads;
    ss->seed = p->seed;
    ss->antialias = p->level >= 2 ? 1 : 0;
    ss->aa_threshold = 0.3;
    ss->aa_depth = 3;
    ss->use_ambient = 1;
    ss->cancel = p->cancel;
}

/* A Whitted pass of the scene (shade_render, timed into t->render); for a
 * GI method's pass (gi) the ambient follows the radiosity rules as in
 * render_gi.c and fn, when given, answers the indirect light. */
static pt_status whitted_render(const scene *sc, const accel *a, const view_gi_pass *p, int gi, shade_indirect_fn fn,
                                void *fn_ctx, caustics *caus, framebuffer *fb, shade_stats *st, view_gi_times *t,
                                diag *d)
{
    shade_settings ss;
    whitted_settings(&ss, p);
    if (gi) ss.use_ambient = radrules_of(sc, 1).ambient;
    ss.indirect = fn;
    ss.indirect_ctx = fn_ctx;
    if (caus) caustics_attach(caus, &ss); /* after the mode's hook, which it keeps */
    double t0 = timer_now();
    pt_status s = shade_render(sc, a, &ss, fb, st, d);
    t->render = timer_now() - t0;
    return s;
}

static int whitted_last_level(const view_gi_opts *o) { (void)o; return 2; }

static pt_status none_open(void *ctx, const scene *sc, const accel *a, const view_gi_opts *o, view_gi_times *t, diag *d)
{
    none_ctx *c = ctx;
    c->sc = sc;
    c->a = a;
    c->o = *o;
    /* the caustic layer is left to the first relight: `none` opens on the
     * render thread, whose first image should not wait for the photons */
    return PT_OK;
}

static int none_pending(void *ctx)
{
    none_ctx *c = ctx;
    return caus_stale(&c->caus, c->sc);
}

static pt_status none_relight(void *ctx, volatile int *cancel, view_gi_times *t, diag *d)
{
    none_ctx *c = ctx;
    double t0 = timer_now();
    pt_status st = caus_update(&c->caus, c->sc, c->a, &c->o, cancel, d);
    t->light = timer_now() - t0;
    return st;
}

static pt_status none_render(void *ctx, const view_gi_pass *p, framebuffer *fb, view_gi_times *t, diag *d)
{
    none_ctx *c = ctx;
    shade_stats st;
    pt_status s = whitted_render(c->sc, c->a, p, 0, NULL, NULL, caus_cur(&c->caus), fb, &st, t, d);
    c->rays = st.primary_rays + st.shadow_rays + st.secondary_rays;
    return s;
}

static void none_describe(void *ctx, char *buf, int n)
{
    none_ctx *c = ctx;
    caustics *k = caus_cur(&c->caus);
    if (k)
        snprintf(buf, (size_t)n, "%.2f Mrays, %ld caustic photons", c->rays * 1e-6, k->st.stored);
    else
        snprintf(buf, (size_t)n, "%.2f Mrays", c->rays * 1e-6);
}

static void none_close(void *ctx) { caus_free(&((none_ctx *)ctx)->caus); }

/* -------------------------------------------------------------- particle */
/* Two instances on the same scene copy: the mode's own (the scene's or
 * --particles count) and a preview one with 1/8 of the particles and at
 * most 4 shadow rays per particle per area light, whose lighting stage is
 * about 1/8 to 1/30 as long: after a light edit it is relit first and
 * renders the first relit preview (view_gi_relight_preview), while the
 * full instance is relit in the next pass. */
typedef struct {
    const scene *sc;
    const accel *a;
    gi_particle *gp;
    gi_particle *gpq;      /* preview instance, NULL when the count is too small for one */
    gi_particle_stats stats, statsq;
    double t_light_q;      /* its last lighting stage */
    view_gi_opts o;
    view_caus caus;        /* both instances' caustic photons (their light, and the passes') */
} particle_ctx;

/* The caustic layer for the lights of the scene, given to both instances:
 * their lighting stages take its photons as light (POV-Ray's radiosity
 * sees photons), as render_gi.c's particle mode does. */
static pt_status particle_caustics(particle_ctx *c, volatile int *cancel, diag *d)
{
    pt_status st = caus_update(&c->caus, c->sc, c->a, &c->o, cancel, d);
    caustics *k = caus_cur(&c->caus);
    if (c->gp) gi_particle_set_caustic(c->gp, k ? k->layer : NULL);
    if (c->gpq) gi_particle_set_caustic(c->gpq, k ? k->layer : NULL);
    return st;
}

static pt_status particle_open(void *ctx, const scene *sc, const accel *a, const view_gi_opts *o, view_gi_times *t, diag *d)
{
    particle_ctx *c = ctx;
    c->sc = sc;
    c->a = a;
    c->o = *o;
    gi_particle_settings s;
    render_gi_particle_settings(&s, sc);
    s.threads = o->threads;
    if (o->particles > 0) s.count = o->particles;
    if (o->bounces > 0) s.bounces = o->bounces;
    if (o->cl_device) s.cl_device = o->cl_device;
    pt_status st = PT_OK;
    c->gp = gi_particle_build(sc, a, &s, &c->stats, d, &st);
    if (!c->gp || st != PT_OK) return st != PT_OK ? st : PT_ERR_INTERNAL;
    double t0 = timer_now();
    if ((st = particle_caustics(c, NULL, d)) != PT_OK) return st;
    double t_caus = timer_now() - t0;
    st = gi_particle_light(c->gp, d);
    const gi_particle_stats *gs = gi_particle_get_stats(c->gp);
    t->build = gs->t_geometry;
    t->light = gs->t_lighting + t_caus;
    if (st != PT_OK) return st;
    long nq = o->preview_particles > 0 ? o->preview_particles : s.count / 8;
    if (o->preview_particles >= 0 && nq >= 500 && nq <= s.count / 2) {
        gi_particle_settings sq = s;
        sq.count = nq;
        if (sq.area_samples <= 0 || sq.area_samples > 4) sq.area_samples = 4;
        pt_status stq = PT_OK;
        diag *dq = diag_new();
        c->gpq = gi_particle_build(sc, a, &sq, &c->statsq, dq, &stq);
        caustics *k = caus_cur(&c->caus);
        if (c->gpq && k) gi_particle_set_caustic(c->gpq, k->layer);
        if (c->gpq && stq == PT_OK) stq = gi_particle_light(c->gpq, dq);
        if (!c->gpq || stq != PT_OK) {
            /* the mode works without it: its messages are dropped */
            gi_particle_free(c->gpq);
            c->gpq = NULL;
        } else {
            const gi_particle_stats *q = gi_particle_get_stats(c->gpq);
            t->build += q->t_geometry;
            c->t_light_q = q->t_lighting;
        }
        diag_free(dq);
    }
    return PT_OK;
}

/* The caustic layer for the new lights first (whichever instance is relit
 * first shoots it; a cancelled shot keeps the old layer and the old
 * lighting), then the instance's lighting stage. */
static pt_status relight_one(particle_ctx *c, gi_particle *gp, volatile int *cancel, double *seconds, diag *d)
{
    double t0 = timer_now();
    pt_status st = particle_caustics(c, cancel, d);
    if (st != PT_OK || (cancel && *cancel)) {
        *seconds = timer_now() - t0;
        return st;
    }
    gi_particle_set_cancel(gp, cancel); /* stops in the visibility pass, old lighting kept */
    st = gi_particle_relight(gp, d);
    gi_particle_set_cancel(gp, NULL);
    *seconds = timer_now() - t0;
    return st;
}

static pt_status particle_relight(void *ctx, volatile int *cancel, view_gi_times *t, diag *d)
{
    particle_ctx *c = ctx;
    return relight_one(c, c->gp, cancel, &t->light, d);
}

static int particle_has_preview(void *ctx) { return ((particle_ctx *)ctx)->gpq != NULL; }

static pt_status particle_relight_preview(void *ctx, volatile int *cancel, view_gi_times *t, diag *d)
{
    particle_ctx *c = ctx;
    if (!c->gpq) return PT_ERR_UNSUPPORTED;
    pt_status st = relight_one(c, c->gpq, cancel, &t->light, d);
    if (st == PT_OK && !(cancel && *cancel)) c->t_light_q = t->light;
    return st;
}

static pt_status particle_render(void *ctx, const view_gi_pass *p, framebuffer *fb, view_gi_times *t, diag *d)
{
    particle_ctx *c = ctx;
    gi_particle *gp = p->coarse && c->gpq ? c->gpq : c->gp;
    pt_status st = gi_particle_prepare_view(gp, &c->sc->camera, p->width, p->height, d);
    t->view = gi_particle_get_stats(gp)->t_view;
    if (st != PT_OK) return st;
    return whitted_render(c->sc, c->a, p, 1, gi_particle_indirect, gp, caus_cur(&c->caus), fb, NULL, t, d);
}

static void particle_describe(void *ctx, char *buf, int n)
{
    particle_ctx *c = ctx;
    const gi_particle_stats *s = gi_particle_get_stats(c->gp);
    char q[48] = "";
    if (c->gpq)
        snprintf(q, sizeof q, " (preview %ld, %.0f ms)", gi_particle_get_stats(c->gpq)->particles, c->t_light_q * 1e3);
    caustics *k = caus_cur(&c->caus);
    char cp[48] = "";
    if (k) snprintf(cp, sizeof cp, ", %ld caustic photons", k->st.stored);
    snprintf(buf, (size_t)n, "%ld particles%s, %d bounces, lighting %.0f ms (visibility %.0f, emit %.0f, scatter %.0f)%s",
             s->particles, q, s->bounces, s->t_lighting * 1e3, s->t_visibility * 1e3, s->t_emit * 1e3,
             s->t_scatter * 1e3, cp);
}

static void particle_close(void *ctx)
{
    particle_ctx *c = ctx;
    gi_particle_free(c->gp);
    gi_particle_free(c->gpq);
    caus_free(&c->caus);
}

/* ----------------------------------------------------------------- links */
/* Vertex links (gi_vlinks.h): open links every mesh vertex and gathers;
 * a light edit (relight) keeps the links and runs the light links and the
 * sweeps again on the render thread, while the window stays live. Passes
 * read a shot of the last finished solution (gi_vlinks_shot), never the
 * instance: a new scene (the clock changed, view_gi_reframe) is linked
 * again on another thread, only where it deformed, while passes go on with
 * the old scene and its shot; view_gi_adopt then swaps both in. */
typedef struct {
    const scene *sc;
    const accel *a;
    gi_vlinks *v;
    gi_vlinks_shot *shot;      /* what passes read */
    gi_vlinks_stats st;
    /* a reframe's result until adopted */
    gi_vlinks_shot *next_shot;
    const accel *next_a;
    gi_vlinks_stats next_st;
} links_ctx;

/* One gi_vlinks frame on (sc, a); on success *shot is its solution. */
static pt_status links_frame(links_ctx *c, const scene *sc, const accel *a, int objects_may_change, volatile int *cancel,
                             view_gi_times *t, gi_vlinks_stats *out, gi_vlinks_shot **shot, diag *d)
{
    double t0 = timer_now();
    gi_vlinks_set_cancel(c->v, cancel);
    gi_vlinks_stats st;
    pt_status s = gi_vlinks_frame(c->v, sc, a, objects_may_change, &st, d);
    gi_vlinks_set_cancel(c->v, NULL);
    if (s == PT_OK) {
        gi_vlinks_shot *n = gi_vlinks_shot_new(c->v);
        if (!n) return PT_ERR_NOMEM;
        gi_vlinks_shot_free(*shot);
        *shot = n;
        *out = st;
    }
    t->build = st.t_links;
    t->light = timer_now() - t0 - st.t_links;
    return s;
}

static pt_status links_run(links_ctx *c, int objects_may_change, volatile int *cancel, view_gi_times *t, diag *d)
{
    pt_status s = links_frame(c, c->sc, c->a, objects_may_change, cancel, t, &c->st, &c->shot, d);
    return s == PT_CANCELLED ? PT_OK : s;
}

static pt_status links_open(void *ctx, const scene *sc, const accel *a, const view_gi_opts *o, view_gi_times *t, diag *d)
{
    links_ctx *c = ctx;
    c->sc = sc;
    c->a = a;
    gi_vlinks_settings s;
    render_gi_links_settings(&s, o->threads, o->bounces);
    c->v = gi_vlinks_new(&s);
    if (!c->v) return PT_ERR_NOMEM;
    return links_run(c, 1, NULL, t, d);
}

static pt_status links_relight(void *ctx, volatile int *cancel, view_gi_times *t, diag *d)
{
    return links_run(ctx, 0, cancel, t, d);
}

static pt_status links_reframe(void *ctx, const scene *sc, const accel *a, volatile int *cancel, view_gi_times *t, diag *d)
{
    links_ctx *c = ctx;
    gi_vlinks_shot_free(c->next_shot);
    c->next_shot = NULL;
    pt_status s = links_frame(c, sc, a, 1, cancel, t, &c->next_st, &c->next_shot, d);
    if (s == PT_OK) c->next_a = a;
    return s;
}

static void links_adopt(void *ctx)
{
    links_ctx *c = ctx;
    if (!c->next_shot) return;
    gi_vlinks_shot_free(c->shot);
    c->shot = c->next_shot;
    c->next_shot = NULL;
    c->a = c->next_a;
    c->st = c->next_st;
}

static pt_status links_render(void *ctx, const view_gi_pass *p, framebuffer *fb, view_gi_times *t, diag *d)
{
    links_ctx *c = ctx;
    return whitted_render(c->sc, c->a, p, 1, c->shot ? gi_vlinks_shot_indirect : NULL, c->shot, NULL, fb, NULL, t, d);
}

static void links_describe(void *ctx, char *buf, int n)
{
    links_ctx *c = ctx;
    const gi_vlinks_stats *s = &c->st;
    snprintf(buf, (size_t)n, "%ld vertices, %ld links (%ld raw), %ld of %ld linked, light %.0f ms, sweeps %.0f ms",
             s->vertices, s->merged_links, s->raw_links, s->elements_linked, s->elements, s->t_light * 1e3,
             s->t_bounces * 1e3);
}

static void links_close(void *ctx)
{
    links_ctx *c = ctx;
    gi_vlinks_shot_free(c->shot);
    gi_vlinks_shot_free(c->next_shot);
    gi_vlinks_free(c->v);
}

/* ------------------------------------------------- reference previews */
/* path and pmfg: each pass its own samples (its own seed), averaged at full
 * resolution: level 0 a preview at 1 sample per pixel, level 1 the full
 * resolution at 1, then 1, 2, 4, ... more: 2^(L-1) samples after level L,
 * up to o->ref_spp (rounded up to a power of 2). */

typedef struct {
    const scene *sc;
    const accel *a;
    int mode;
    int photons;       /* pmfg: photon paths per pass */
    framebuffer *sum;  /* running sum at full resolution */
    int spp;           /* samples in sum */
    double t_photons;  /* pmfg: photon maps of the last pass */
} ref_ctx;

static int ref_spp(const view_gi_opts *o) { return o->ref_spp > 0 ? o->ref_spp : 256; }

static int ref_last_level(const view_gi_opts *o)
{
    int L = 1;
    while ((1 << (L - 1)) < ref_spp(o)) L++;
    return L;
}

static pt_status ref_open(void *ctx, const scene *sc, const accel *a, int mode, const view_gi_opts *o)
{
    ref_ctx *c = ctx;
    c->sc = sc;
    c->a = a;
    c->mode = mode;
    c->photons = o->ref_photons > 0 ? o->ref_photons : 50000;
    return PT_OK;
}

static pt_status path_open(void *ctx, const scene *sc, const accel *a, const view_gi_opts *o, view_gi_times *t, diag *d)
{
    return ref_open(ctx, sc, a, GI_PATH, o);
}

static pt_status pmfg_open(void *ctx, const scene *sc, const accel *a, const view_gi_opts *o, view_gi_times *t, diag *d)
{
    return ref_open(ctx, sc, a, GI_PMFG, o);
}

static pt_status ref_relight(void *ctx, volatile int *cancel, view_gi_times *t, diag *d) { return PT_OK; }

/* The image-loop options of one preview pass (either reference mode). */
static void pass_settings(pm_common *c, const view_gi_pass *p, uint64_t seed, int spp)
{
    c->width = p->width;
    c->height = p->height;
    c->threads = p->threads;
    c->seed = seed;
    c->spp = spp;
    c->cancel = p->cancel;
    c->image_interval = 1e9;
}

static pt_status ref_render(void *ctx, const view_gi_pass *p, framebuffer *fb, view_gi_times *t, diag *d)
{
    ref_ctx *c = ctx;
    int spp = p->level <= 1 ? 1 : 1 << (p->level - 2);
    /* each pass its own samples: the seed says which */
    uint64_t seed = p->seed + 0x9e3779b97f4a7c15ULL * (uint64_t)(p->level + 1);
    pm_stats st;
    memset(&st, 0, sizeof st);
    double t0 = timer_now();
    pt_status r;
    if (c->mode == GI_PMFG) {
        /* low settings (the offline defaults are 1M photons and 4096 gather
         * rays per pixel, pm_fg.h): a photon map of its own per pass, 16
         * gather rays and 4 light samples per eye sample */
        pm_fg_settings s;
        pm_fg_default_settings(&s);
        pass_settings(&s.c, p, seed, spp);
        s.photons = c->photons;
        s.fg_rays = 16 * spp;
        s.area_samples = 4;
        s.emitter_samples = 4;
        r = pm_fg_render(c->sc, c->a, &s, fb, &st, d);
        c->t_photons = st.t_lights + st.t_photons + st.t_maps + st.t_irradiance;
        t->light = c->t_photons;
    } else {
        pm_path_settings s;
        pm_path_default_settings(&s);
        pass_settings(&s.c, p, seed, spp);
        r = pm_path_render(c->sc, c->a, &s, fb, &st, d);
    }
    t->render = timer_now() - t0 - t->light;
    if (r != PT_OK || (p->cancel && *p->cancel)) return r;
    if (p->level == 0) return PT_OK;
    size_t n = (size_t)p->width * (size_t)p->height * 3u;
    if (p->level == 1 || !c->sum || c->sum->width != p->width || c->sum->height != p->height) {
        fb_free(c->sum);
        c->sum = fb_new(p->width, p->height);
        if (!c->sum) return PT_ERR_NOMEM;
        memset(c->sum->rgb, 0, n * sizeof(float));
        c->spp = 0;
    }
    for (size_t i = 0; i < n; i++) c->sum->rgb[i] += fb->rgb[i] * (float)spp;
    c->spp += spp;
    float k = 1.0f / (float)c->spp;
    for (size_t i = 0; i < n; i++) fb->rgb[i] = c->sum->rgb[i] * k;
    return PT_OK;
}

static void ref_describe(void *ctx, char *buf, int n)
{
    ref_ctx *c = ctx;
    if (c->mode == GI_PMFG)
        snprintf(buf, (size_t)n, "reference preview, %d spp, %d photons/pass (photon maps %.0f ms)", c->spp, c->photons,
                 c->t_photons * 1e3);
    else
        snprintf(buf, (size_t)n, "reference preview, %d spp", c->spp);
}

static void ref_close(void *ctx) { fb_free(((ref_ctx *)ctx)->sum); }

/* ----------------------------------------------------------------- table */

static const gi_backend backends[] = {
    {GI_NONE, 1, sizeof(none_ctx), whitted_last_level, none_open, none_relight, NULL, NULL, none_render, none_describe,
     none_close, NULL, NULL, none_pending},
    {GI_PARTICLE, 1, sizeof(particle_ctx), whitted_last_level, particle_open, particle_relight, particle_has_preview,
     particle_relight_preview, particle_render, particle_describe, particle_close},
    {GI_LINKS, 0, sizeof(links_ctx), whitted_last_level, links_open, links_relight, NULL, NULL, links_render,
     links_describe, links_close, links_reframe, links_adopt},
    {GI_PATH, 0, sizeof(ref_ctx), ref_last_level, path_open, ref_relight, NULL, NULL, ref_render, ref_describe, ref_close},
    {GI_PMFG, 0, sizeof(ref_ctx), ref_last_level, pmfg_open, ref_relight, NULL, NULL, ref_render, ref_describe, ref_close},
};
enum { NBACKENDS = (int)(sizeof backends / sizeof backends[0]) };

static const gi_backend *find(int mode)
{
    for (int i = 0; i < NBACKENDS; i++)
        if (backends[i].mode == mode) return &backends[i];
    return NULL;
}

int view_gi_available(int mode) { return find(mode) != NULL; }

int view_gi_next(int mode)
{
    for (int i = 0; i < NBACKENDS; i++)
        if (backends[i].mode == mode) return backends[(i + 1) % NBACKENDS].mode;
    return backends[0].mode;
}

const char *view_gi_name(int mode) { return gi_mode_name((gi_mode)mode); }

pt_status view_gi_open(view_gi **out, int mode, const scene *sc, const accel *a, const view_gi_opts *o, view_gi_times *t,
                       diag *d)
{
    *out = NULL;
    memset(t, 0, sizeof *t);
    const gi_backend *b = find(mode);
    if (!b) {
        diag_error(d, "GI mode '%s' is not available in the viewer", view_gi_name(mode));
        return PT_ERR_UNSUPPORTED;
    }
    view_gi *g = calloc(1, sizeof *g);
    if (!g) return PT_ERR_NOMEM;
    g->b = b;
    g->o = *o;
    g->last_level = b->last_level(o);
    g->sc = *sc;
    g->lights = malloc((size_t)(sc->nlights > 0 ? sc->nlights : 1) * sizeof *g->lights);
    if (!g->lights) {
        free(g);
        return PT_ERR_NOMEM;
    }
    if (sc->nlights > 0) memcpy(g->lights, sc->lights, (size_t)sc->nlights * sizeof *g->lights);
    g->sc.lights = g->lights;
    g->sc.cap_lights = sc->nlights;
    g->ctx = calloc(1, b->ctx_size);
    if (!g->ctx) {
        free(g->lights);
        free(g);
        return PT_ERR_NOMEM;
    }
    double t0 = timer_now();
    pt_status st = b->open(g->ctx, &g->sc, a, o, t, d);
    if (t->build == 0 && t->light == 0) t->build = timer_now() - t0;
    g->t_light = t->light;
    if (st == PT_OK && b->pending && b->pending(g->ctx)) g->stale = 1;
    if (st != PT_OK) {
        view_gi_close(g);
        return st;
    }
    *out = g;
    return PT_OK;
}

scene *view_gi_scene(view_gi *g) { return &g->sc; }
int view_gi_last_level(const view_gi *g) { return g->last_level; }

void view_gi_lights_changed(view_gi *g)
{
    g->stale = 1;
    g->preview_fresh = 0;
}

int view_gi_has_preview_light(const view_gi *g) { return g->b->has_preview && g->b->has_preview(g->ctx); }

pt_status view_gi_relight_preview(view_gi *g, volatile int *cancel, view_gi_times *t, diag *d)
{
    memset(t, 0, sizeof *t);
    if (!view_gi_has_preview_light(g)) return PT_ERR_UNSUPPORTED;
    pt_status st = g->b->relight_preview(g->ctx, cancel, t, d);
    if (st == PT_OK && !(cancel && *cancel)) g->preview_fresh = 1;
    return st;
}

int view_gi_last_coarse(const view_gi *g) { return g->last_coarse; }
int view_gi_stale(const view_gi *g) { return g->stale; }
/* A stale preview costs about one preview pass before the relight starts:
 * worth it when the lighting stage is longer than a preview (40 ms,
 * view_render.c's target). */
int view_gi_slow_light(const view_gi *g) { return g->b->slow_light && g->t_light > 0.040; }

pt_status view_gi_relight(view_gi *g, volatile int *cancel, view_gi_times *t, diag *d)
{
    memset(t, 0, sizeof *t);
    g->stale = 1;
    pt_status st = g->b->relight(g->ctx, cancel, t, d);
    /* a cancelled stage leaves the old lighting: still stale */
    if (st == PT_OK && !(cancel && *cancel)) {
        g->stale = 0;
        g->t_light = t->light;
    }
    return st;
}

pt_status view_gi_render(view_gi *g, const view_gi_pass *p, framebuffer *fb, view_gi_times *t, diag *d)
{
    memset(t, 0, sizeof *t);
    view_gi_pass q = *p;
    /* the full lighting is stale and the preview lighting is not: the pass
     * uses the preview lighting */
    q.coarse = g->stale && g->preview_fresh;
    g->last_coarse = q.coarse;
    return g->b->render(g->ctx, &q, fb, t, d);
}

void view_gi_describe(const view_gi *g, char *buf, int n)
{
    if (n > 0) buf[0] = 0;
    g->b->describe(g->ctx, buf, n);
}

int view_gi_can_reframe(const view_gi *g) { return g->b->reframe != NULL; }

pt_status view_gi_reframe(view_gi *g, const scene *nsc, const accel *na, const scene_light *lights, volatile int *cancel,
                          view_gi_times *t, diag *d)
{
    memset(t, 0, sizeof *t);
    g->reframed = 0;
    if (!g->b->reframe) return PT_ERR_UNSUPPORTED;
    free(g->next_lights);
    g->next_lights = malloc((size_t)(nsc->nlights > 0 ? nsc->nlights : 1) * sizeof *g->next_lights);
    if (!g->next_lights) return PT_ERR_NOMEM;
    if (nsc->nlights > 0) memcpy(g->next_lights, lights, (size_t)nsc->nlights * sizeof *g->next_lights);
    g->next_sc = *nsc;
    g->next_sc.lights = g->next_lights;
    g->next_sc.cap_lights = nsc->nlights;
    pt_status st = g->b->reframe(g->ctx, &g->next_sc, na, cancel, t, d);
    g->reframed = st == PT_OK && !(cancel && *cancel);
    return g->reframed ? PT_OK : (st == PT_OK ? PT_CANCELLED : st);
}

void view_gi_adopt(view_gi *g)
{
    if (!g->reframed) return;
    scene_camera cam = g->sc.camera;
    free(g->lights);
    g->lights = g->next_lights;
    g->next_lights = NULL;
    g->sc = g->next_sc;
    g->sc.lights = g->lights;
    g->sc.camera = cam;
    g->b->adopt(g->ctx);
    g->reframed = 0;
}

void view_gi_close(view_gi *g)
{
    if (!g) return;
    if (g->b->close) g->b->close(g->ctx);
    free(g->ctx);
    free(g->lights);
    free(g->next_lights);
    free(g);
}
