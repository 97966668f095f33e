/* caustics.c - the caustic layer wired to the shader (see caustics.h). */
#include "caustics.h"
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "scene_leaves.h"
#include "shade_light.h"
#include "shade_material.h"
#include "shade_texture.h"

/* The caustic layer's material hook (gi_caustic_hooks.surface):
 * shade_material's BSDF at the hit. A photon goes on along each specular
 * lobe the surface has, weighted by the lobe: what the surface absorbs or
 * takes into a Lambertian or glossy lobe is lost as weight, never by
 * Russian roulette (seed 002 appendix A ends the photon with probability
 * 1 - p and divides the kept ones by p). POV-Ray's photons do the same
 * (photons.cpp, ComputeLightedTexture: the photon colour times the filter
 * or the reflectivity, traced on while its weight stays above adc_bailout),
 * so a surface that keeps a share p of the light passes 1/p times as many
 * photons of p times the power as the roulette did: on grenadine's glass
 * (a filter of 0.7) and phot_met_glass's metal (reflection 0.8 over
 * diffuse 0.15) the roulette's survivors were visibly noisier than
 * POV-Ray's photons. No bounce thins the photons, so each branch's density
 * factor (rho) is 1. A refraction bends by
 * the ior ratio of POV-Ray's interior list (the photon's containers `in`,
 * shade_tex_refraction_eta), as POV-Ray's photons do (photons.cpp,
 * ComputeRefractionForPhotons): a liquid in a glass refracts against the
 * glass, not against air. */
/* A photon going on through the surface at h along tdir: what it keeps is
 * shade_mat_photon_filter's (POV-Ray 3.7's photons.cpp, ComputeLightedTexture:
 * the filter colour times 1 - reflectivity under conserve_energy, the
 * photon carrying LightCol * FilCol). No (eta_i/eta_t)^2 (b.eta2, the
 * path tracer's adjoint rule): POV-Ray's photon keeps LightCol x FilCol
 * through a refraction, so a surface inside a refracting object (a floor
 * that a glass sinks into) gets the photons' full power; through a whole
 * object the two factors cancel anyway. `si` (the containers before) is
 * crossed into the step's. */
/* The step's trace_w is POV-Ray's photon weight factor through a
 * refraction (shade_mat_photon_filter's). */
static gi_caustic_step through(const caustics *c, const accel_hit *h, vec3 dir, const shade_mat_bsdf *b, rgb kr,
                               shade_media_inside *si, vec3 tdir)
{
    double tw;
    rgb f = shade_mat_photon_filter(c->sc, h, dir, b, kr, &tw);
    shade_media_inside_cross(si, h->obj);
    gi_caustic_inside after = {0, {0}};
    after.n = si->n < GI_CAUSTIC_MAX_INSIDE ? si->n : GI_CAUSTIC_MAX_INSIDE;
    for (int i = 0; i < after.n; i++) after.obj[i] = si->obj[i];
    return (gi_caustic_step){b->p_in, tdir, f, 1.0, 1, b->from, after, tw};
}

/* POV-Ray's photon weight factor through a reflection off the top layer of
 * reflectivity kr: its ComputeReflectivity scales the weight by the
 * reflectivity's largest channel (fresnel) or by the larger of reflection
 * min and max (otherwise), and the reflected photon is traced with that
 * weight times kr's largest channel again (photons.cpp,
 * ComputeLightedTexture). A reflection so weighs kr squared: with the
 * default adc_bailout of 1/255 a photon reflected twice inside a glass of
 * reflectivity 0.27 ends there, under conserve_energy (0.73 x 0.07 x 0.07
 * x 0.73 < 1/255) as in POV-Ray. The fresnel factor is taken after the
 * metallic tint (POV-Ray: before it). */
static double reflect_weight(const shade_mat_bsdf *b, rgb kr)
{
    const scene_finish *f = b->ls.f;
    double m = fmax(kr.r, fmax(kr.g, kr.b));
    if (!f || f->fresnel) return m * m;
    rgb a = f->reflection_max, z = f->reflection_min;
    return fmax(fmax(a.r, fmax(a.g, a.b)), fmax(z.r, fmax(z.g, z.b))) * m;
}

/* The photon's containers as the shader's list. */
static shade_media_inside photon_inside(const gi_caustic_inside *in)
{
    shade_media_inside si = {0, {0}};
    if (in) {
        si.n = in->n < SHADE_MEDIA_MAX_INSIDE ? in->n : SHADE_MEDIA_MAX_INSIDE;
        for (int i = 0; i < si.n; i++) si.obj[i] = in->obj[i];
    }
    return si;
}

/* The BSDF at h for a photon inside the containers si (NULL: the eye
 * G-buffer's rays, which keep no list): its fresnel reflectivity takes
 * the relative ior from the list, as POV-Ray's photons do (photons.cpp,
 * ComputeLightedTexture calls ComputeReflectivity with the photon ray's
 * interiors), so a photon leaving a glass inside a closed room reflects
 * only the glass's reflection_min, as the eye rays do there. */
static void setup(const caustics *c, shade_mat_bsdf *b, const accel_hit *h, vec3 dir, const shade_media_inside *si,
                  rng *r)
{
    double fi = si ? shade_tex_fresnel_ior(si, h->obj, v3_dot(dir, h->ng) < 0.0) : 0.0;
    shade_mat_setup_fresnel(b, c->sc, h, dir, c->eps, c->scale, r, fi);
}

static int hook_surface(void *ctx, const accel_hit *h, vec3 dir, const gi_caustic_inside *in, rng *r,
                        gi_caustic_step *step)
{
    const caustics *c = ctx;
    shade_media_inside si = photon_inside(in);
    shade_mat_bsdf b;
    setup(c, &b, h, dir, in ? &si : NULL, r);
    const scene_finish *tf = b.ls.f;
    int out = b.m[SHADE_MAT_LOBE_DIFFUSE] > 0.0                      ? GI_CAUSTIC_RECEIVES
              : tf && (tf->specular > 0.0 || tf->phong > 0.0) ? GI_CAUSTIC_HIGHLIGHTS
                                                               : 0;
    if (!step) return out;
    double mr = b.m[SHADE_MAT_LOBE_REFLECT], mt = b.m[SHADE_MAT_LOBE_TRANSMIT];
    if (!(mr + mt > 0.0)) return out;
    /* Seed 002's appendix A (with --photon-roulette): the photon goes on
     * with probability p, the specular lobes' share of the surface's lobes
     * (as shade_mat_sample(absorb = 1) would choose one of them), and a
     * kept photon's branches carry 1/p of the weight and p as their density
     * factor (rho, so the photon volumes widen where the roulette thins
     * them). The expected flux is the weighted rule's. */
    double p = 1.0;
    if (c->roulette) {
        p = (mr + mt) / (b.msum > 1.0 ? b.msum : 1.0);
        if (!(p > 0.0) || rng_f64(r) >= p) return out;
    }
    /* the surface's own reflectivity (shade_material folds a transmitted
     * part it totally reflects into k[REFLECT]) */
    rgb kr = b.k[SHADE_MAT_LOBE_REFLECT];
    if (b.tir) kr = (rgb){fmax(0.0, kr.r - b.tir_trans.r), fmax(0.0, kr.g - b.tir_trans.g), fmax(0.0, kr.b - b.tir_trans.b)};
    int transmits = mt > 0.0 || b.tir, tir = b.tir;
    vec3 tdir = b.trans_dir;
    if (transmits && in) {
        double eta = shade_tex_refraction_eta(&si, h->obj, b.entering);
        double cos_i = -v3_dot(dir, b.n), k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
        tir = k < 0.0;
        if (!tir) tdir = v3_norm(v3_add(v3_scale(dir, eta), v3_scale(b.n, eta * cos_i - sqrt(k))));
    }
    gi_caustic_inside same = {0, {0}};
    if (in) same = *in;
    /* reflected inside an object, the photon has crossed it: its fade over
     * the way (the refracted branch's filter below has it too) */
    rgb fa = shade_tex_leaving_fade(h, dir, 1);
    int n = 0;
    if (tir) {
        /* total internal reflection keeps the whole photon: POV-Ray's
         * photon refraction reflects the unfiltered photon instead and
         * skips the surface's own reflection (TraceRefractionRayForPhotons),
         * weighted as the refraction it replaces (through's trace_w) */
        shade_media_inside unused = si;
        step[n++] = (gi_caustic_step){b.p_out, b.refl_dir, fa, 1.0, 0, b.from, same,
                                      through(c, h, dir, &b, kr, &unused, tdir).trace_w};
    } else {
        if (fmax(kr.r, fmax(kr.g, kr.b)) > 0.0)
            step[n++] = (gi_caustic_step){b.p_out, b.refl_dir, {fa.r * kr.r, fa.g * kr.g, fa.b * kr.b}, 1.0, 0,
                                          b.from, same, reflect_weight(&b, kr)};
        if (transmits) step[n++] = through(c, h, dir, &b, kr, &si, tdir);
    }
    for (int k = 0; k < n && p < 1.0; k++) {
        step[k].weight = (rgb){step[k].weight.r / p, step[k].weight.g / p, step[k].weight.b / p};
        step[k].rho = p;
    }
    return out | GI_CAUSTIC_CONTINUES | (n == 2 ? GI_CAUSTIC_SPLIT : 0);
}

/* The caustic layer's containers hook: shade_media_inside_at's list (the
 * camera's rule: every object holding p, hollow or not). */
static void hook_containers(void *ctx, vec3 p, gi_caustic_inside *in)
{
    const caustics *c = ctx;
    shade_media_inside si;
    shade_media_inside_at(c->sc, p, &si);
    in->n = si.n < GI_CAUSTIC_MAX_INSIDE ? si.n : GI_CAUSTIC_MAX_INSIDE;
    for (int i = 0; i < in->n; i++) in->obj[i] = si.obj[i];
}

/* The caustic layer's pass hook: a pass_through object before the target
 * lets the photon on along its way with what a refraction through it
 * would keep (through above; POV-Ray 3.7's photons.cpp filters such a
 * photon by the layers' filter and transmit, FilCol, and crosses the
 * object's interior, without bending it). */
static int hook_pass(void *ctx, const accel_hit *h, vec3 dir, const gi_caustic_inside *in, gi_caustic_step *step)
{
    const caustics *c = ctx;
    shade_media_inside si = photon_inside(in);
    shade_mat_bsdf b;
    setup(c, &b, h, dir, in ? &si : NULL, NULL);
    *step = through(c, h, dir, &b, b.k[SHADE_MAT_LOBE_REFLECT], &si, dir);
    return fmax(step->weight.r, fmax(step->weight.g, step->weight.b)) > 0.0;
}

/* The brilliance of the top layer's finish at the hit (POV-Ray shades each
 * photon through it; the caustic layer weights its photons so), and its
 * diffuse_back over its diffuse: photons arriving from behind light it
 * through diffuse_back (trace.cpp, ComputePhotonDiffuseLight shades a
 * photon as a light, and a light behind the surface takes diffuse_back). */
static double hook_brilliance(void *ctx, const accel_hit *h, vec3 dir, double *back)
{
    const caustics *c = ctx;
    shade_mat_bsdf b;
    shade_mat_setup(&b, c->sc, h, dir, c->eps, c->scale, NULL);
    const scene_finish *f = b.ls.f;
    *back = f && f->diffuse > 0.0 && f->diffuse_back > 0.0 && isfinite(f->diffuse_back / f->diffuse)
                ? f->diffuse_back / f->diffuse
                : 0.0;
    return f ? f->brilliance : 1.0;
}

/* Spot and cylinder attenuation seen from the photon's first hit p, fade at
 * the photon's whole path length (POV-Ray's addSurfacePhoton). */
static double hook_attenuation(void *ctx, const scene_light *l, vec3 p, double depth)
{
    (void)ctx;
    vec3 dir;
    double dd;
    shade_light_ray(l, l->position, p, &dir, &dd);
    return shade_light_attenuation(l, p, dir, depth);
}

/* The caustic layer's media hook: the containers' media over a photon's
 * segment, as POV-Ray's photon rays meet them (photons.cpp,
 * ComputeLightedTexture): only on a hollow ray, dimmed by their extinction
 * (shade_media_segment's shadow mode: extinction alone); photons are left
 * there when some media scatters and collects photons (`collect`, the
 * opposite of POV-Ray's ignore_photons; the media list takes photons when
 * any of them does) and some absorbs or scatters (POV-Ray deposits nothing
 * without extinction: ComputeMediaAndDepositPhotons returns first). */
static int hook_media(void *ctx, const gi_caustic_inside *in, vec3 org, vec3 dir, double len, rgb *tr)
{
    const caustics *c = ctx;
    shade_media_inside si = photon_inside(in);
    *tr = (rgb){1, 1, 1};
    if (si.n == 0 || !shade_media_inside_hollow(&si) || !shade_media_inside_has_media(&si)) return 0;
    int scatters = 0, collects = 0, extinction = 0;
    for (int k = 0; k < si.n; k++) {
        const scene_interior *it = si.obj[k]->interior;
        for (int i = 0; it && i < it->nmedia; i++) {
            const scene_media *m = it->media[i];
            int sc = m->scattering.r != 0.0 || m->scattering.g != 0.0 || m->scattering.b != 0.0;
            int ab = m->absorption.r != 0.0 || m->absorption.g != 0.0 || m->absorption.b != 0.0;
            scatters |= sc;
            collects |= m->collect;
            extinction |= sc || ab;
        }
    }
    shade_media_env me = {c->sc, NULL, 0, NULL, NULL, NULL};
    *tr = shade_media_segment(&me, SHADE_MEDIA_INTERIOR, &si, org, dir, len, *tr, 1);
    return scatters && collects && extinction;
}

/* The caustic layer's fade hook: shade_tex_leaving_fade, the fade the
 * bounces' weights carry (hook_surface), for the photon stored at h. */
static rgb hook_fade(void *ctx, const accel_hit *h, vec3 dir)
{
    (void)ctx;
    return shade_tex_leaving_fade(h, dir, 1);
}

static int disperses(const scene_object *o)
{
    return o->photons && o->photons->target && o->interior && o->interior->dispersion != 1.0;
}

/* What the scene's photon settings ask that the layer leaves out (media
 * photons are modelled: hook_media and caustics_media_photons). */
static void not_modelled(caustics *c, const scene *sc, diag *d)
{
    const scene_photons *p = &sc->global.photons;
    caustics_not_modelled *nm = &c->nm;
    nm->gather = (p->given & SCENE_PH_GATHER) != 0;
    nm->radius = (p->given & SCENE_PH_RADIUS) != 0;
    nm->expand_thresholds = (p->given & SCENE_PH_EXPAND) != 0;
    nm->autostop = (p->given & SCENE_PH_AUTOSTOP) != 0 && p->autostop > 0.0;
    nm->save_file = (p->given & SCENE_PH_SAVE_FILE) != 0 && p->file && !p->load;
    nm->load_file = (p->given & SCENE_PH_LOAD_FILE) != 0 && p->file && p->load;
    for (int i = 0; i < sc->nobjects; i++) nm->dispersion |= scene_object_any(sc->objects[i], disperses);
    src_loc nowhere = {0};
    const char *why = "the caustic layer sizes its photon volumes itself (docs/caustics.md)";
    if (nm->gather) diag_warn_once(d, nowhere, "photons: gather is not modelled: %s", why);
    if (nm->radius) diag_warn_once(d, nowhere, "photons: radius is not modelled: %s", why);
    if (nm->expand_thresholds) diag_warn_once(d, nowhere, "photons: expand_thresholds is not modelled: %s", why);
    if (nm->autostop)
        diag_warn_once(d, nowhere, "photons: autostop is not modelled: every direction towards a target is shot");
    if (nm->save_file) diag_warn_once(d, nowhere, "photons: save_file is not modelled: no photon file is written");
    if (nm->load_file)
        diag_warn_once(d, nowhere, "photons: load_file is not modelled: the photons are shot again, not read");
    if (nm->dispersion)
        diag_warn_once(d, nowhere, "photons: dispersion is not modelled: photons through a dispersive target are white");
}

pt_status caustics_build(caustics *c, const scene *sc, const accel *a, int width, int height, int threads,
                         uint64_t seed, const char *cl_device, size_t cl_max_bytes, double count_scale,
                         int roulette, volatile int *cancel, diag *d)
{
    memset(c, 0, sizeof *c);
    c->roulette = roulette != 0;
    c->asked = sc->global.photons.enabled;
    if (!c->asked) return PT_OK;
    not_modelled(c, sc, d);
    c->sc = sc;
    c->eps = accel_surface_eps(a); /* the shader's offsets: photons cross thin walls as eye rays do */
    c->scale = accel_eps_scale(a);
    gi_caustic_hooks hk = {hook_surface, hook_attenuation, c,          hook_brilliance,
                           hook_pass,    hook_containers,  hook_media, hook_fade};
    gi_caustic_settings s = {width, height, threads, seed, cl_device, cl_max_bytes, count_scale, cancel};
    pt_status st = PT_OK;
    c->layer = gi_caustic_build(sc, a, &s, &hk, d, &st);
    if (c->layer) gi_caustic_get_stats(c->layer, &c->st);
    else if (st == PT_OK && !(cancel && *cancel)) {
        src_loc nowhere = {0};
        diag_warn_once(d, nowhere, "photons: no light shoots photons at a photons { target } object: no caustics");
    }
    return st;
}

static rgb chained(void *ctx, const accel_hit *h, vec3 n, int thread)
{
    caustics *c = ctx;
    rgb e = gi_caustic_at(c->layer, h, n, thread);
    if (c->next) {
        rgb f = c->next(c->next_ctx, h, n, thread);
        e.r += f.r;
        e.g += f.g;
        e.b += f.b;
    }
    return e;
}

/* One photon through the highlights of the surface (caustics_highlights). */
typedef struct {
    shade_light_surface s;
    rgb sum;
} highlight_acc;

static void highlight_one(void *ctx, vec3 w, rgb e)
{
    highlight_acc *a = ctx;
    rgb t = shade_light_terms(&a->s, w, e, 0);
    a->sum.r += t.r;
    a->sum.g += t.g;
    a->sum.b += t.b;
}

rgb caustics_highlights(void *ctx, const accel_hit *h, const shade_light_surface *s, int thread)
{
    (void)thread;
    caustics *c = ctx;
    highlight_acc a = {*s, {0, 0, 0}};
    if (!c->layer || !s->f || (s->f->specular <= 0.0 && s->f->phong <= 0.0)) return a.sum;
    /* the highlights alone: the Lambertian share of the same photons is
     * gi_caustic_at's, added through the indirect hook */
    scene_finish f = *s->f;
    f.diffuse = 0.0;
    f.diffuse_back = 0.0;
    a.s.f = &f;
    gi_caustic_visit(c->layer, h, s->n, highlight_one, &a);
    return a.sum;
}

/* The media photons around p, each as a light through each (the layer's
 * gi_caustic_media_visit): the shader's media photon hook. */
static void caustics_media_photons(void *ctx, vec3 p, shade_media_photon_fn each, void *each_ctx)
{
    const caustics *c = ctx;
    gi_caustic_media_visit(c->layer, p, each, each_ctx);
}

void caustics_attach(caustics *c, shade_settings *ss)
{
    if (!c->layer) return;
    c->next = ss->indirect;
    c->next_ctx = ss->indirect_ctx;
    ss->indirect = chained;
    ss->indirect_ctx = c;
    ss->highlights = caustics_highlights;
    ss->highlights_ctx = c;
    ss->photon_shadows = 1;
    if (c->st.stored_media > 0) {
        ss->media_photons = caustics_media_photons;
        ss->media_photons_ctx = c;
    }
}

void caustics_free(caustics *c)
{
    if (c->layer) gi_caustic_get_stats(c->layer, &c->st);
    gi_caustic_free(c->layer);
    c->layer = NULL;
}

void caustics_json(caustics *c, stats_json *js)
{
    if (!c->asked) return;
    if (c->layer) gi_caustic_get_stats(c->layer, &c->st);
    const gi_caustic_stats *s = &c->st;
    stats_obj_begin(js, "caustics");
    stats_str(js, "device", s->device);
    stats_int(js, "pairs", s->combos);
    stats_num(js, "spacing", s->spacing);
    STATS_INTS(js, s, emitted, first_hits);
    stats_int(js, "absorbed_at_bounce_map", s->absorbed_first);
    stats_obj_begin(js, "alive_after_bounce");
    for (int b = 1; b <= s->max_bounce; b++) {
        char k[16];
        snprintf(k, sizeof k, "%d", b);
        stats_int(js, k, s->alive[b]);
    }
    stats_obj_end(js);
    STATS_INTS(js, s, stored, stored_highlights, stored_media, media_thinned, widened);
    STATS_NUMS(js, s, flux, r_median, r_media_median);
    STATS_INTS(js, s, rays, tile_entries, lookups_gbuffer, lookups_photons);
    stats_obj_begin(js, "seconds");
    STATS_NUMS_PRE(js, s, t_, trace, gbuffer, bin, splat);
    stats_obj_end(js);
    stats_obj_begin(js, "not_modelled");
    STATS_INTS(js, &c->nm, gather, radius, expand_thresholds, autostop, save_file, load_file, dispersion);
    stats_obj_end(js);
    stats_obj_end(js);
}
