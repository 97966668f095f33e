/* render_gi.c - render a scene with one GI mode and collect its figures.
 *
 *  none      Whitted (shade_render) with POV-Ray's ambient term (radiosity off).
 *  particle  seed 000: geometry stage, lighting stage, view preparation,
 *            then the Whitted pass with the particles' indirect light
 *            (ambient under POV-Ray's rules with radiosity on, radrules.h).
 *  pmfg      photon map + final gathering (reference/pm_fg.h).
 *  path      path tracer (reference/pm_path.h).
 *  links     vertex links over the meshes' vertices (gi/gi_vlinks.h) as the
 *            indirect hook of the Whitted pass.
 *  detp      incremental photon paths and the fixed-radius estimate
 *            (reference/pm_detp.h) as the indirect hook of the Whitted pass. */
#include "render_gi.h"
#include "shade_gamma.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "func_internal.h"
#include "gi.h"
#include "img_io.h"
#include "pm_fg.h"
#include "pm_path.h"
#include "radrules.h"
#include "shade_media.h"
#include "shade_atmos.h"
#include "shade_texture.h"
#include "timer.h"

/* The Whitted pass's settings that render_gi_opts carries under
 * shade_settings' own names; the rest keep shade_default_settings'. */
#define WHITTED_FIELDS(X) \
    X(width) X(height) X(threads) X(seed) X(antialias) X(aa_threshold) X(aa_depth) X(aa_jitter) X(cancel) X(progress) \
    X(quality)

static void fill_shade(shade_settings *ss, const render_gi_opts *o)
{
    shade_default_settings(ss);
#define COPY_FIELD(f) ss->f = o->f;
    WHITTED_FIELDS(COPY_FIELD)
#undef COPY_FIELD
    if (o->spp > 0) ss->spp = o->spp;
    memcpy(ss->window, o->window, sizeof ss->window);
}

/* The AOV pass (shade_aov.h) with the Whitted settings of the render and,
 * for particle GI, its indirect hook. */
static pt_status render_aovs(const scene *sc, const accel *a, const render_gi_opts *o, const shade_settings *ss,
                             render_gi_result *r, diag *d)
{
    if (!o->aov) return PT_OK;
    double t0 = timer_now();
    pt_status st = shade_aov_render(sc, a, ss, o->aov, d);
    r->t_aov = timer_now() - t0;
    return st;
}

/* render_aovs for a mode that renders without shade_render (path, pmfg,
 * vpl): direct, albedo, normal, depth and illuminance as for none, from the
 * Whitted settings of the render's options; no indirect AOV (0). */
static pt_status render_whitted_aovs(const scene *sc, const accel *a, const render_gi_opts *o, render_gi_result *r,
                                     diag *d)
{
    if (!o->aov) return PT_OK;
    shade_settings ss;
    fill_shade(&ss, o);
    return render_aovs(sc, a, o, &ss, r, d);
}

static pt_status render_none(const scene *sc, const accel *a, const render_gi_opts *o, framebuffer *fb,
                             render_gi_result *r, diag *d)
{
    shade_settings ss;
    fill_shade(&ss, o);
    ss.use_ambient = radrules_of(sc, 0).ambient; /* radiosity off: always */
    double t0 = timer_now();
    pt_status st = caustics_build(&r->caus, sc, a, o->width, o->height, o->threads, o->seed, o->cl_device,
                                  o->cl_max_bytes, o->photon_scale, o->photon_roulette, o->cancel, d);
    r->t_gi_lighting = timer_now() - t0;
    if (st != PT_OK) return st;
    caustics_attach(&r->caus, &ss);
    t0 = timer_now();
    r->image_begun = 1;
    st = shade_render(sc, a, &ss, fb, &r->shade, d);
    r->t_render = timer_now() - t0;
    if (st == PT_OK) st = render_aovs(sc, a, o, &ss, r, d);
    return st;
}

void render_gi_particle_settings(gi_particle_settings *gs, const scene *sc)
{
    gi_particle_settings_from_scene(gs, sc);
    gs->pigment = shade_tex_pigment_at; /* particles reflect the pigment where they are */
    gs->sky = shade_atmos_sky; /* what escaping rays see (shade_atmos.h) */
    /* POV-Ray's filtered shadows reach the particles too (its radiosity
     * sees them), with its photon targets' full shadows */
    if (shade_tex_scene_transparent(sc)) gs->shadow = shade_tex_shadow_ray;
    gs->photon_shadows = sc->global.photons.enabled;
}

static pt_status render_particle(const scene *sc, const accel *a, const render_gi_opts *o, framebuffer *fb,
                                 render_gi_result *r, diag *d)
{
    gi_particle_settings gs;
    render_gi_particle_settings(&gs, sc);
    /* radiosity `normal on`: the final gather about the perturbed normal */
    if (radrules_of(sc, 1).normal) gs.normal_at = shade_tex_normal_at;
    gi_particle_scale_quality(&gs, o->gi_quality);
    if (o->particles > 0) gs.count = o->particles;
    if (o->bounces > 0) gs.bounces = o->bounces;
    gs.seed = o->seed;
    gs.threads = o->threads;
    if (o->cl_device) gs.cl_device = o->cl_device;
    gs.cl_max_bytes = o->cl_max_bytes;
    gs.cancel = o->cancel; /* Ctrl-C stops the geometry stage too */
    gs.progress = o->progress;
    /* camera rays through pixel centres (no fixed supersampling): the
     * pre-pass's hits serve the render (gi_particle_primary_hit) */
    gs.keep_hits = o->antialias != 2;
    gs.camera = o->geometry_camera;
    pt_status st = PT_OK;
    double t0 = timer_now();
    gi_particle *gp = o->reuse;
    if (!gp) {
        int load = o->gi_cache && o->gi_cache_load;
        gp = load ? gi_particle_load(sc, a, &gs, o->gi_cache, o->gi_cache_key, &r->particle, d, &st)
                  : gi_particle_build(sc, a, &gs, &r->particle, d, &st);
        r->t_gi_geometry = timer_now() - t0;
        /* cancelled: nothing rendered, the caller sees its flag (as in the
         * other modes, which stop at a tile) */
        if (!gp) return st == PT_CANCELLED ? PT_OK : (st == PT_OK ? PT_ERR_INTERNAL : st);
        r->ran_geometry = !load;
        r->gi_cache_loaded = load;
        if (o->gi_cache && !load && (st = gi_particle_save(gp, o->gi_cache, o->gi_cache_key, d)) != PT_OK) {
            gi_particle_free(gp);
            return st;
        }
    }
    r->has_particle = 1;
    gi_particle_set_cancel(gp, o->cancel);
    gi_particle_set_progress(gp, o->progress);
    /* the caustic layer of the scene's photons{} (caustics.h), first: the
     * lighting stage takes its photons as light at the particles (POV-Ray's
     * radiosity sees photons), and the render shows it */
    t0 = timer_now();
    st = caustics_build(&r->caus, sc, a, o->width, o->height, o->threads, o->seed, o->cl_device, o->cl_max_bytes,
                        o->photon_scale, o->photon_roulette, o->cancel, d);
    r->t_gi_lighting = timer_now() - t0;
    /* this frame's layer: the lighting stage and the view's gathers read
     * its photons until the render ends (cleared below) */
    gi_particle_set_caustic(gp, r->caus.layer);
    if (st == PT_OK && (!o->reuse || o->relight)) {
        t0 = timer_now();
        st = o->reuse ? gi_particle_relight(gp, d) : gi_particle_light(gp, d);
        r->t_gi_lighting += timer_now() - t0;
        r->ran_lighting = 1;
    }
    if (st == PT_OK) {
        shade_settings ss;
        fill_shade(&ss, o);
        /* POV-Ray's rule under radiosity (core/radrules.h): a surface seen
         * directly shows ambient only in scenes below #version 3.7, where
         * the particles also carry it to other surfaces. */
        ss.use_ambient = radrules_of(sc, 1).ambient;
        ss.indirect = gi_particle_indirect;
        ss.indirect_ctx = gp;
        caustics_attach(&r->caus, &ss);
        if (gs.keep_hits) {
            ss.primary_begin = gi_particle_primary_begin;
            ss.primary = gi_particle_primary_hit;
            ss.primary_ctx = gp;
        }
        t0 = timer_now();
        double c0 = timer_cpu_now();
        /* view preparation (pre-pass, gathering, estimation) belongs to the frame */
        st = gi_particle_prepare_view(gp, &sc->camera, o->width, o->height, d);
        /* prepare_view returns PT_OK when cancelled: the render then stops at once */
        if (st == PT_OK && !(o->cancel && *o->cancel)) {
            r->image_begun = 1;
            st = shade_render(sc, a, &ss, fb, &r->shade, d);
        }
        r->t_render = timer_now() - t0;
        r->c_render = timer_cpu_now() - c0;
        if (st == PT_OK) st = render_aovs(sc, a, o, &ss, r, d);
    }
    r->particle = *gi_particle_get_stats(gp);
    gi_particle_set_progress(gp, NULL); /* o->progress ends with this render */
    gi_particle_set_caustic(gp, NULL);  /* and the caustic layer (freed with the result) */
    if (o->keep && st == PT_OK) r->kept = gp;
    else if (!o->reuse) gi_particle_free(gp);
    return st;
}

/* After a GI mode's frame ended with st (detp, links): the Whitted pass
 * with the mode's indirect hook under radiosity's rule for ambient (as
 * particle), then the AOVs; skipped when the frame failed or the render was
 * cancelled. Cancelling is not an error: PT_CANCELLED comes back as PT_OK. */
static pt_status render_with_hook(const scene *sc, const accel *a, const render_gi_opts *o, framebuffer *fb,
                                  render_gi_result *r, diag *d, pt_status st, shade_indirect_fn fn, void *ctx)
{
    if (st != PT_OK || (o->cancel && *o->cancel)) return st == PT_CANCELLED ? PT_OK : st;
    shade_settings ss;
    fill_shade(&ss, o);
    ss.use_ambient = radrules_of(sc, 1).ambient;
    ss.indirect = fn;
    ss.indirect_ctx = ctx;
    double t0 = timer_now();
    r->image_begun = 1;
    st = shade_render(sc, a, &ss, fb, &r->shade, d);
    r->t_render = timer_now() - t0;
    if (st == PT_OK) st = render_aovs(sc, a, o, &ss, r, d);
    return st == PT_CANCELLED ? PT_OK : st;
}

/* A mode whose work may outlive the frame and lights the Whitted pass
 * through a hook (detp, links): how to make, drive and free its state. */
typedef struct {
    void *(*make)(const render_gi_opts *o);
    void (*set_progress)(void *g, progress *p);
    /* the mode's own frame, its figures into r (before the Whitted pass) */
    pt_status (*frame)(void *g, const scene *sc, const accel *a, const render_gi_opts *o, render_gi_result *r, diag *d);
    shade_indirect_fn indirect;
    void (*after)(void *g, render_gi_result *r); /* figures of the pass (lookups) */
    void (*free)(void *g);
} hook_mode;

struct render_gi_kept {
    const hook_mode *m;
    void *g;
};

/* One frame of a hook mode: with the caller's state (kept, from the
 * previous frame; the caller frees it) or one made and freed here. */
static pt_status render_hook_mode(const hook_mode *m, const scene *sc, const accel *a, const render_gi_opts *o,
                                  framebuffer *fb, render_gi_result *r, diag *d)
{
    void *g = o->kept ? o->kept->g : m->make(o);
    if (!g) return PT_ERR_NOMEM;
    m->set_progress(g, o->progress);
    pt_status st = m->frame(g, sc, a, o, r, d);
    st = render_with_hook(sc, a, o, fb, r, d, st, m->indirect, g);
    m->after(g, r);
    m->set_progress(g, NULL); /* o->progress ends with this render */
    if (!o->kept) m->free(g);
    return st;
}

static void *detp_make(const render_gi_opts *o)
{
    pm_detp_settings s;
    pm_detp_default_settings(&s);
    if (o->photons > 0) s.photons = o->photons;
    s.radius = o->detp_radius;
    s.full = o->detp_full;
    s.seed = o->seed;
    s.threads = o->threads;
    s.cancel = o->cancel;
    return pm_detp_new(&s);
}

static pt_status detp_frame(void *g, const scene *sc, const accel *a, const render_gi_opts *o, render_gi_result *r,
                            diag *d)
{
    r->has_detp = 1;
    const pm_detp_frame_info fi = {.lights_changed = o->lights_changed, .objects_may_change = o->objects_may_change};
    pt_status st = pm_detp_frame(g, sc, a, o->width, o->height, &fi, &r->detp, d);
    r->t_gi_geometry = r->detp.t_trace;
    r->t_gi_lighting = r->detp.t_estimate;
    return st;
}

static void detp_progress(void *g, progress *p) { pm_detp_set_progress(g, p); }
static void detp_after(void *g, render_gi_result *r) { pm_detp_lookups(g, &r->detp.lookups, &r->detp.lookups_none); }
static void detp_free(void *g) { pm_detp_free(g); }
static const hook_mode detp_mode = {detp_make, detp_progress, detp_frame, pm_detp_indirect, detp_after, detp_free};

void render_gi_links_settings(gi_vlinks_settings *s, int threads, int bounces)
{
    gi_vlinks_default_settings(s);
    s->pigment = shade_tex_pigment_at;
    s->threads = threads;
    if (bounces > 0) s->bounces = bounces;
}

static void *links_make(const render_gi_opts *o)
{
    gi_vlinks_settings s;
    render_gi_links_settings(&s, o->threads, o->bounces);
    s.cancel = o->cancel;
    return gi_vlinks_new(&s);
}

static pt_status links_frame(void *g, const scene *sc, const accel *a, const render_gi_opts *o, render_gi_result *r,
                             diag *d)
{
    r->has_links = 1;
    pt_status st = gi_vlinks_frame(g, sc, a, o->kept ? o->objects_may_change : 1, &r->links, d);
    if (st == PT_OK && r->links.other_objects > 0)
        diag_report(d, DIAG_WARNING, (src_loc){0}, NULL,
                    "--gi links: %ld objects are not meshes: they block light but neither receive nor pass on indirect light",
                    r->links.other_objects);
    r->t_gi_geometry = r->links.t_links;
    r->t_gi_lighting = r->links.t_light + r->links.t_bounces + r->links.t_smooth;
    return st;
}

static void links_progress(void *g, progress *p) { gi_vlinks_set_progress(g, p); }
static void links_after(void *g, render_gi_result *r) { r->links.lookups_other = gi_vlinks_lookups_other(g); }
static void links_free(void *g) { gi_vlinks_free(g); }
static const hook_mode links_mode = {links_make, links_progress, links_frame, gi_vlinks_indirect, links_after,
                                     links_free};

render_gi_kept *render_gi_kept_new(const render_gi_opts *o)
{
    const hook_mode *m = o->mode == GI_DETP ? &detp_mode : o->mode == GI_LINKS ? &links_mode : NULL;
    render_gi_kept *k = m ? malloc(sizeof *k) : NULL;
    if (!k) return NULL;
    k->m = m;
    k->g = m->make(o);
    if (!k->g) {
        free(k);
        return NULL;
    }
    return k;
}

void render_gi_kept_free(render_gi_kept *k)
{
    if (!k) return;
    k->m->free(k->g);
    free(k);
}

typedef struct {
    const char *path;
    double last;
    diag *notes;
    int *image_begun;
    const scene *sc;
} progressive_ctx;

static void on_image(void *ctx, const framebuffer *fb, int done, int total)
{
    progressive_ctx *p = ctx;
    if (!p->path) return;
    /* the image leaves the working space as the final one does */
    framebuffer *out = fb_new(fb->width, fb->height);
    if (!out) return;
    memcpy(out->rgb, fb->rgb, (size_t)fb->width * (size_t)fb->height * 3 * sizeof *out->rgb);
    shade_gamma_fb_to_linear(p->sc, out, 0);
    out->alpha = fb->alpha; /* borrowed for the write */
    diag *d = diag_new();
    img_write_opts wo;
    img_default_write_opts(&wo);
    if (img_write(p->path, out, &wo, d) == PT_OK && p->notes)
        diag_report(p->notes, DIAG_NOTE, (src_loc){0}, NULL, "%d/%d samples per pixel written to %s", done, total, p->path);
    diag_free(d);
    out->alpha = NULL;
    fb_free(out);
}

/* the reference renderers report the fraction of their image loop done:
 * from the first report on, the framebuffer holds rendered pixels (their
 * stages count on the progress themselves, pm_common.progress) */
static void on_progress(void *ctx, double f)
{
    (void)f;
    progressive_ctx *p = ctx;
    *p->image_begun = 1;
}

static void fill_common(pm_common *c, const render_gi_opts *o, progressive_ctx *pc)
{
    pm_common_defaults(c);
    c->width = o->width;
    c->height = o->height;
    c->threads = o->threads;
    c->seed = o->seed;
    if (o->spp > 0) c->spp = o->spp;
    c->cancel = o->cancel;
    if (pc->path) {
        c->on_image = on_image;
        c->image_ctx = pc;
    }
    c->on_progress = on_progress;
    c->progress_ctx = pc;
    c->progress = o->progress;
}

static pt_status render_reference(const scene *sc, const accel *a, const render_gi_opts *o, framebuffer *fb,
                                  render_gi_result *r, diag *d)
{
    progressive_ctx pc = {o->progressive_path, 0.0, o->notes, &r->image_begun, sc};
    pt_status st;
    r->has_pm = 1;
    double t0 = timer_now();
    if (o->mode == GI_PATH) {
        pm_path_settings ps;
        pm_path_default_settings(&ps);
        fill_common(&ps.c, o, &pc);
        if (o->max_depth > 0) ps.max_depth = o->max_depth;
        st = pm_path_render(sc, a, &ps, fb, &r->pm, d);
    } else {
        pm_fg_settings fs;
        pm_fg_default_settings(&fs);
        const int eye_spp = fs.c.spp;
        fill_common(&fs.c, o, &pc);
        if (o->spp <= 0) fs.c.spp = eye_spp; /* no --spp: pmfg's own (pm_fg.h) */
        if (o->fg_rays > 0) fs.fg_rays = o->fg_rays;
        if (o->photons > 0) fs.photons = o->photons;
        st = pm_fg_render(sc, a, &fs, fb, &r->pm, d);
    }
    /* The references shade in the scene's working space as the Whitted
     * renderer does (POV-Ray's assumed_gamma: the scene's colours and the
     * arithmetic on them), so their image leaves it the same way. */
    if (st == PT_OK) shade_gamma_fb_to_linear(sc, fb, o->threads);
    double total = timer_now() - t0;
    r->t_gi_lighting = r->pm.t_lights + r->pm.t_photons + r->pm.t_maps + r->pm.t_irradiance;
    r->t_render = r->pm.t_render > 0 ? r->pm.t_render : total - r->t_gi_lighting;
    r->primary_rays = r->pm.camera_rays;
    r->shadow_rays = r->pm.shadow_rays;
    r->secondary_rays = r->pm.bsdf_rays + r->pm.gather_rays;
    r->other_rays = r->pm.photon_rays;
    r->discarded = r->pm.discarded_samples;
    if (st == PT_OK) st = render_whitted_aovs(sc, a, o, r, d);
    return st;
}

static pt_status render_vpl_mode(const scene *sc, const accel *a, const render_gi_opts *o, framebuffer *fb,
                                 render_gi_result *r, diag *d)
{
    render_vpl_settings vs;
    render_vpl_default_settings(&vs);
    vs.width = o->width;
    vs.height = o->height;
    vs.threads = o->threads;
    vs.seed = o->seed;
    if (o->spp > 0) vs.spp = o->spp; /* no --spp: vpl's own */
    if (o->vpls > 0) vs.vpls = o->vpls;
    if (o->bounces > 0) vs.bounces = o->bounces;
    vs.cut = o->vpl_cut;
    if (o->vpl_adaptive) vs.adaptive = o->vpl_adaptive == 1;
    vs.cl_device = o->cl_device;
    vs.cl_max_bytes = o->cl_max_bytes;
    vs.cancel = o->cancel;
    r->has_vpl = 1;
    r->image_begun = 1;
    pt_status st = render_vpl(sc, a, &vs, fb, &r->vpl, d);
    r->t_gi_lighting = r->vpl.t_vpls + r->vpl.t_tree + r->vpl.t_bounce;
    r->t_render = r->vpl.t_trace + r->vpl.t_gather;
    r->primary_rays = r->vpl.camera_rays;
    r->shadow_rays = r->vpl.shadow_rays;
    r->secondary_rays = r->vpl.secondary_rays;
    if (st == PT_OK) st = render_whitted_aovs(sc, a, o, r, d);
    return st;
}

/* What render_gi_result's nm_* say, counted and warned once. */
static void light_not_modelled(const scene *sc, int mode, int final_gather, render_gi_result *r, diag *d)
{
    const int media = shade_media_scene_has(sc), fog = sc->fogs != NULL, rainbow = sc->rainbows != NULL;
    const char *who = mode == GI_PATH ? "path" : mode == GI_PMFG ? "pmfg" : "particle";
    if (mode == GI_PATH || mode == GI_PMFG) {
        r->nm_media = media;
        r->nm_rainbow = rainbow;
    } else if (mode == GI_PARTICLE && radrules_of(sc, 1).media) {
        /* `media on`: POV-Ray's gathering rays see media, fog and rainbows */
        r->nm_media = media;
        r->nm_fog = fog;
        r->nm_rainbow = rainbow;
    }
    /* the final gather (keep_hits) gathers about the perturbed normal
     * (gi_particle.h normal_at); the paper's estimate (--spp) cannot */
    if (mode == GI_PARTICLE && !final_gather) r->nm_normal = radrules_of(sc, 1).normal;
    src_loc nowhere = {0};
    if (r->nm_normal)
        diag_report(d, DIAG_WARNING, nowhere, NULL,
                    "--gi particle: radiosity normal on is not modelled without the final gather (--spp): light is "
                    "gathered about the unperturbed normal, so a normal pattern does not shade the gathered light");
    if (sc->global.photons.enabled && mode != GI_NONE && mode != GI_PARTICLE) {
        r->nm_photons = mode != GI_PMFG;
        r->nm_photon_count = mode == GI_PMFG;
        if (r->nm_photons)
            diag_report(d, DIAG_WARNING, nowhere, NULL,
                        "--gi %s: the scene's photons{} are not modelled: no caustics of its light sources (--gi none "
                        "and particle have them)", gi_mode_name(mode));
        else
            diag_report(d, DIAG_WARNING, nowhere, NULL,
                        "--gi pmfg: photons{} spacing and count are not used: its caustic map shoots --photons from "
                        "every light");
    }
    if (r->nm_media)
        diag_report(d, DIAG_WARNING, nowhere, NULL, "--gi %s: participating media are not modelled%s; the image lacks their light",
                    who, mode == GI_PARTICLE ? " along gathering rays (radiosity media on)" : "");
    if (r->nm_fog)
        diag_report(d, DIAG_WARNING, nowhere, NULL, "--gi %s: fog is not modelled along gathering rays (radiosity media on)", who);
    if (r->nm_rainbow)
        diag_report(d, DIAG_WARNING, nowhere, NULL, "--gi %s: rainbow is not modelled%s", who,
                    mode == GI_PARTICLE ? " along gathering rays (radiosity media on)" : "");
}

pt_status render_gi(const scene *sc, const accel *a, const render_gi_opts *o, framebuffer *fb, render_gi_result *r,
                    diag *d)
{
    memset(r, 0, sizeof *r);
    light_not_modelled(sc, o->mode, o->antialias != 2, r, d);
    /* f_ridged_mf's weights as POV-Ray's render fixes them, before any pass
     * (photons, GI, the image) calls it; the whole image's order, so that a
     * window (a farm's tile) takes the frame's */
    shade_ridged_mf_first(sc, a, o->width, o->height);
    pt_status st;
    switch (o->mode) {
    case GI_PARTICLE: st = render_particle(sc, a, o, fb, r, d); break;
    case GI_DETP: st = render_hook_mode(&detp_mode, sc, a, o, fb, r, d); break;
    case GI_VPL:
        st = render_vpl_mode(sc, a, o, fb, r, d);
        func_ridged_mf_reset();
        return st;
    case GI_LINKS: st = render_hook_mode(&links_mode, sc, a, o, fb, r, d); break;
    case GI_PMFG:
    case GI_PATH:
        st = render_reference(sc, a, o, fb, r, d);
        func_ridged_mf_reset();
        return st;
    default: st = render_none(sc, a, o, fb, r, d); break;
    }
    caustics_free(&r->caus);
    func_ridged_mf_reset(); /* a later scene's calls take their own */
    r->primary_rays = r->shade.primary_rays;
    r->shadow_rays = r->shade.shadow_rays;
    r->secondary_rays = r->shade.secondary_rays;
    r->discarded = r->shade.discarded_samples;
    if (r->has_detp) r->other_rays = r->detp.rays;
    if (r->has_links) r->other_rays = r->links.link_rays + r->links.light_rays;
    if (r->has_particle) {
        r->other_rays = r->particle.link_rays + r->particle.shadow_rays + r->particle.prepass_rays;
        r->discarded += r->particle.discarded;
    }
    return st;
}

void render_gi_json(const render_gi_result *r, int mode, stats_json *js)
{
    caustics_json((caustics *)&r->caus, js);
    stats_obj_begin(js, "light_not_modelled");
    STATS_INTS_PRE(js, r, nm_, media, fog, rainbow, normal, photons, photon_count);
    stats_obj_end(js);
    if (r->has_particle) {
        const gi_particle_stats *p = &r->particle;
        stats_obj_begin(js, "particle");
        stats_str(js, "device", p->device);
        STATS_INTS(js, p, particles, radiance_particles, radiance_slots, list_entries, link_rays, link_misses,
                   visibility_rays, sources, bounces, found, used);
        /* the hook's lookups: all, without particles, estimated at the hit */
        STATS_INTS(js, p, lookups, lookups_none, lookups_gathered, lookups_gathered_here, view_gathers, view_gather_rays, lookups_onthefly, skipped_objects, discarded);
        STATS_NUMS(js, p, spacing, radius);
        /* flux into the particles (grey): from the lights and the caustic photons, of it the photons' */
        STATS_NUMS(js, p, flux_direct, flux_caustic);
        STATS_INTS(js, p, bytes_total);
        stats_obj_begin(js, "timings");
        STATS_NUMS_PRE(js, p, t_, kernel_build, surfaces, sampling, scatter_links, gather_links, lists, visibility,
                       emit, scatter, prepass, gather, estimate, view_gather);
        stats_obj_end(js);
        /* process CPU seconds (all threads) */
        stats_obj_begin(js, "cpu");
        STATS_NUMS_PRE(js, p, c_, geometry, lists);
        stats_num(js, "render", r->c_render);
        stats_obj_end(js);
        stats_obj_end(js);
    }
    if (r->has_vpl) {
        const render_vpl_stats *p = &r->vpl;
        stats_obj_begin(js, "vpl");
        stats_str(js, "device", p->device);
        STATS_INTS(js, p, vpls, tree_nodes, cut_nodes, bounces, pixels, pixels_valid, pixels_sampled);
        stats_num(js, "fraction_sampled", p->pixels_valid > 0 ? (double)p->pixels_sampled / (double)p->pixels_valid : 0.0);
        STATS_INTS(js, p, secondary_points);
        STATS_NUMS(js, p, visits_mean);
        STATS_INTS(js, p, visits_min, visits_max);
        stats_obj_begin(js, "timings");
        STATS_NUMS_PRE(js, p, t_, vpls, tree, bounce, trace, gather, gather_pixels, total);
        stats_obj_end(js);
        stats_obj_end(js);
    }
    if (r->has_links) {
        const gi_vlinks_stats *p = &r->links;
        stats_obj_begin(js, "links");
        STATS_INTS(js, p, vertices, elements, meshes, other_objects, full, sweeps, objects_moved, meshes_moved,
                   elements_linked, raw_links, merged_links, link_rays, light_rays, hits_other, lookups_other);
        stats_obj_begin(js, "timings");
        STATS_NUMS_PRE(js, p, t_, links, light, bounces, smooth);
        stats_obj_end(js);
        stats_obj_end(js);
    }
    if (r->has_detp) {
        const pm_detp_stats *p = &r->detp;
        stats_obj_begin(js, "detp");
        STATS_INTS(js, p, paths, segments, paths_retraced);
        stats_num(js, "fraction_retraced", p->paths > 0 ? (double)p->paths_retraced / (double)p->paths : 0.0);
        STATS_INTS(js, p, segments_old, segments_new, receivers, receivers_full, objects, moving_objects, full_frame);
        stats_str(js, "full_reason", p->full_reason ? p->full_reason : "");
        STATS_INTS(js, p, rays, lookups, lookups_none);
        STATS_NUMS(js, p, radius);
        stats_obj_begin(js, "timings");
        STATS_NUMS_PRE(js, p, t_, trace, estimate);
        stats_obj_end(js);
        stats_obj_end(js);
    }
    if (r->has_pm) {
        const pm_stats *p = &r->pm;
        stats_obj_begin(js, mode == GI_PATH ? "path" : "pmfg");
        STATS_INTS(js, p, spp, samples, camera_rays, bsdf_rays, gather_rays, shadow_rays, photon_rays, photons_emitted,
                   photons_global, photons_caustic, photons_dropped);
        stats_str(js, "caustic_map", p->caustic_reason ? p->caustic_reason : (p->caustic_map ? "built" : "not built"));
        STATS_INTS(js, p, gather_points, emitter_pieces);
        stats_obj_begin(js, "timings");
        STATS_NUMS_PRE(js, p, t_, lights, photons, maps, irradiance, render);
        stats_obj_end(js);
        stats_obj_end(js);
    }
}
