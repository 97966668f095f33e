/* pm_photon.c - photon tracing (see pm_photon.h).
 *
 * Power of a photon from a POV-Ray point-like light. POV-Ray's diffuse term
 * d * P * C * att * cos (shade.c) is a Lambertian BRDF d*P/pi under the
 * irradiance E(y) = pi C att(y) cos. Photons leave the light with direction
 * density p(w) (per solid angle), N of them; the number landing on a patch
 * dA at distance d with cosine cos is N p(w) dA cos / d^2, so giving each
 * the power Phi = pi C att d^2 / (N p(w)) makes the flux density
 * Phi * N p(w) cos / d^2 = pi C att cos = E. An area light shoots from
 * its centre, as POV-Ray's photons and its radiosity rays see it. Parallel and cylinder lights send photons along their
 * fixed direction from a disc of area A perpendicular to it: flux density
 * per unit perpendicular area N/A, so Phi = pi C att A / N. Emissive surfaces
 * of radiance Le (both sides): point y with area density p_A, side 1/2,
 * cosine direction: Phi = Le cos / (N p_A (1/2) cos/pi) = 2 pi Le / (N p_A).
 * Background (and sky_sphere, pm_sky) of radiance B(-w) for a photon travelling along w:
 * direction uniform on the sphere, origin uniform
 * on a disc of radius R (the bounding sphere) across it: Phi = B 4 pi pi R^2 / N
 * (check: an unoccluded patch inside receives N (1/4pi) (1/(pi R^2)) int cos dw
 * = N / (4 pi R^2) photons per unit area; times Phi that is pi B, the
 * irradiance under a uniform sky).
 *
 * Bounces: Russian roulette on the BSDF of shade_material.h (seed 002,
 * appendix A, steps 2(b)-(d)): lobe k with probability max-channel(k_k)
 * (scaled down if their sum exceeds 1), power times k_k / p_k (and
 * (eta_i/eta_t)^2 through refraction, see shade_material.c). */
#include "pm_photon.h"
#include "grow.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "pool.h"
#include "scene_leaves.h"
#include "radrules.h"
#include "shade_light.h"
#include "shade_material.h"
#include "shade_texture.h"

#define CHUNK 1024
/* photons { pass_through } is POV-Ray's rule for its lights' photons: a
 * light's photon goes straight through such objects before its first hit,
 * filtered by each surface (POV-Ray 3.7 builds photons.cpp with
 * PT_FILTER_BEFORE_TARGET; shade_mat_photon_filter, as the caustic layer
 * does), and meets them as any other object afterwards. Emitted and sky
 * photons, which stand for gathered (radiosity) light, pass them unchanged.
 * First hits seen from a POV-Ray light pass no_shadow objects too, as
 * shade.c's shadow rays do. */
#define PHOTON_SKIP ACCEL_SKIP_PASS_THROUGH
#define LIGHT_SKIP OBJ_NO_SHADOW
/* Termination that does not depend on the albedo: from bounce RR_BOUNCES on,
 * a path survives each further bounce with probability RR_SURVIVE and its
 * power is divided by it (unbiased); with albedo 1 the material's roulette
 * never ends a path, so this bounds the expected photons stored per emitted
 * one near RR_BOUNCES + 1 / (1 - RR_SURVIVE). */
#define RR_BOUNCES 8
#define RR_SURVIVE 0.8
#define RR_MASS 0.95
/* Hard cap on stored photons (memory): STORED_PER_EMITTED per emitted
 * photon, at most STORED_MAX in all; photons beyond it are dropped and
 * counted (pm_photon_result.dropped). */
#define STORED_PER_EMITTED 16
#define STORED_MAX (1L << 25)

typedef enum { SRC_LIGHT, SRC_EMIT, SRC_ENV } src_kind;

typedef struct {
    src_kind kind;
    const scene_light *l;
    double power;      /* allocation proxy only */
    long n, first;     /* photons of this source: [first, first + n) */
    double cos_max;    /* cone of directions (point-like lights) about axis */
    vec3 axis;
} source;

typedef struct {
    pm_photon *g, *c;
    long ng, cg, nc, cc;
    long rays;
    long cap;          /* stored photons allowed in this chunk (both maps) */
    long dropped;
    int oom;
} chunk_out;

typedef struct {
    const scene *sc;
    const accel *a;
    const pm_lights *L;
    const pm_photon_settings *s;
    source *src;
    int nsrc;
    long total;
    chunk_out *chunks;
    int nchunks;
    double eps;
    int targets;       /* some object has photons { target }: caustic paths bounce on targets only */
    vec3 centre;       /* bounding sphere of finite geometry */
    double radius;
    radrules rr;       /* POV-Ray's rules for gathered light (core/radrules.h) */
    int gathers;       /* recursion_limit: gathering steps light may take to the eye */
    int transparent;   /* some surface lets light through: filtered shadows (shade_tex_scene_transparent) */
} trace_ctx;

static inline rgb crgb(double r, double g, double b) { rgb c = {r, g, b}; return c; }
static inline double cmax(rgb c) { return fmax(fabs(c.r), fmax(fabs(c.g), fabs(c.b))); }

static int push(pm_photon **arr, long *n, long *cap, vec3 p, rgb pw, vec3 nrm, uint32_t surf)
{
    if (!grow_array_long((void **)arr, cap, *n + 1, sizeof **arr)) return 0;
    pm_photon_set(&(*arr)[(*n)++], p, pw, nrm, surf);
    return 1;
}

/* Uniform direction in the cone cos(theta) >= cos_max about unit axis. */
static vec3 cone_dir(vec3 axis, double cos_max, double u1, double u2)
{
    double ct = 1.0 - u1 * (1.0 - cos_max), st = sqrt(fmax(0.0, 1.0 - ct * ct)), phi = 2.0 * M_PI * u2;
    vec3 t, b;
    v3_basis(axis, &t, &b);
    return v3_add(v3_add(v3_scale(t, st * cos(phi)), v3_scale(b, st * sin(phi))), v3_scale(axis, ct));
}

static vec3 disc_point(vec3 c, vec3 axis, double radius, double u1, double u2)
{
    vec3 t, b;
    v3_basis(axis, &t, &b);
    double rho = radius * sqrt(u1), phi = 2.0 * M_PI * u2;
    return v3_add(c, v3_add(v3_scale(t, rho * cos(phi)), v3_scale(b, rho * sin(phi))));
}

/* With targets in the scene (POV-Ray 3.7 semantics), a photon on a caustic
 * path (a POV-Ray light, specular bounces only so far) is reflected or
 * refracted only by a target where the target's and light l's flags allow
 * that lobe (scene_photon_lobe). */
static int caustic_bounce_ok(const scene_light *l, const accel_hit *h, int lobe)
{
    const scene_obj_photons *ph = h->obj ? h->obj->photons : NULL;
    if (!ph || !ph->target) return 0;
    return scene_photon_lobe(l, ph, lobe != SHADE_MAT_LOBE_REFLECT);
}

/* Whether a POV-Ray light's photon passes the transparent surface at h
 * straight, filtered, as the direct light's shadow ray does (pm_nee's
 * filtered shadows, shade_tex_shadow_ray): not where that surface is a
 * photon target refracting this light's photons under the scene's
 * photons{} (a full shadow: the light through it is the caustic's; with
 * photons{} and no target every surface acts as one, and the NEE's shadows
 * are full, pm_nee.c), and
 * only with probability q, the filter's largest channel (at most 1): the
 * rest of the photons meet the surface and bounce on it as any first hit
 * (its diffuse part; its specular lobes are caustic paths), each weight
 * divided by its branch's probability. Then the NEE's filtered direct
 * light behind the surface and the map's photons that carry it on agree. */
static int filtered_pass(const trace_ctx *c, const scene_light *l, const accel_hit *h, vec3 w, double tprev, rng *r,
                         rgb *phi)
{
    if (!c->transparent || !l || !r) return 0;
    const scene_obj_photons *ph = h->obj ? h->obj->photons : NULL;
    if (c->sc->global.photons.enabled && (!c->targets || (ph && ph->target && scene_photon_lobe(l, ph, 1)))) return 0;
    accel_hit hp = *h;
    hp.t = h->t - tprev;
    rgb f = shade_tex_shadow_filter(c->sc, &hp, w);
    double q = fmin(1.0, fmax(f.r, fmax(f.g, f.b)));
    if (!(q > 0.0) || !isfinite(f.r + f.g + f.b)) return 0;
    if (rng_f64(r) >= q) {
        *phi = crgb(phi->r / (1.0 - q), phi->g / (1.0 - q), phi->b / (1.0 - q));
        return 0;
    }
    *phi = crgb(phi->r * fmax(f.r, 0.0) / q, phi->g * fmax(f.g, 0.0) / q, phi->b * fmax(f.b, 0.0) / q);
    return 1;
}

/* The first hit of a light's photon from o along unit w (LIGHT_SKIP), its
 * power *phi filtered by the pass_through objects crossed on the way (the
 * rule above; each surface's fade over the way since the one before, the
 * ray kept from o) and by the transparent surfaces it passes as a filtered
 * shadow (filtered_pass). Returns 1 on a hit, 0 when the photon left the
 * scene or was filtered out. */
static int light_first_hit(const trace_ctx *c, const scene_light *l, vec3 o, vec3 w, accel_hit *h, rgb *phi, rng *r,
                           long *rays)
{
    double tmin = c->eps, tprev = 0.0;
    for (int k = 0; k < ACCEL_PASS_MAX; k++) {
        if (accel_intersect_past(c->a, NULL, o, w, tmin, LIGHT_SKIP, h, rays) <= 0) return 0;
        if (!(h->obj && h->obj->photons && h->obj->photons->pass_through)) {
            if (!filtered_pass(c, l, h, w, tprev, r, phi)) return 1;
            if (!(cmax(*phi) > 0.0) || !isfinite(phi->r + phi->g + phi->b)) return 0;
            tprev = h->t;
            tmin = h->t + fmax(c->eps, h->t * 1e-7);
            continue;
        }
        accel_hit hp = *h;
        hp.t = h->t - tprev;
        shade_mat_bsdf b;
        shade_mat_setup(&b, c->sc, &hp, w, c->eps, accel_eps_scale(c->a), NULL);
        rgb f = shade_mat_photon_filter(c->sc, &hp, w, &b, b.k[SHADE_MAT_LOBE_REFLECT], NULL);
        *phi = crgb(phi->r * f.r, phi->g * f.g, phi->b * f.b);
        if (!(cmax(*phi) > 0.0) || !isfinite(phi->r + phi->g + phi->b)) return 0;
        tprev = h->t;
        tmin = h->t + fmax(c->eps, h->t * 1e-7);
    }
    return 0;
}

/* A photon of a beam (a cylinder light, or a parallel light over the
 * scene): from a uniform point of the disc of radius R about `centre`
 * across `axis`, along `dir`; its first hit and its power (one of n over
 * the disc's area, attenuated as the light's direct light is). */
static int beam_photon(const trace_ctx *c, const scene_light *l, vec3 centre, vec3 axis, vec3 dir, double R, double n,
                       rng *r, accel_hit *h, vec3 *o, vec3 *w, rgb *phi, long *rays)
{
    double u1 = rng_f64(r), u2 = rng_f64(r);
    *o = disc_point(centre, axis, R, u1, u2);
    *w = dir;
    rgb f = {1.0, 1.0, 1.0};
    if (!light_first_hit(c, l, *o, dir, h, &f, r, rays)) return 0;
    vec3 dl;
    double depth;
    shade_light_ray(l, l->position, h->p, &dl, &depth);
    double att = shade_light_attenuation(l, h->p, dl, depth);
    double k = M_PI * att * M_PI * R * R / n;
    *phi = crgb(l->colour.r * k * f.r, l->colour.g * k * f.g, l->colour.b * k * f.b);
    return 1;
}

/* Emit one photon of source `src`: its origin *o and direction *w, the
 * first hit and the photon's power. Returns 1 on a hit, 0 when the photon
 * left the scene, -1 when no photon was emitted (no emitter sample). */
static int emit(const trace_ctx *c, const source *src, rng *r, accel_hit *h, vec3 *o, vec3 *w, rgb *phi, long *rays)
{
    double n = (double)src->n;
    if (src->kind == SRC_LIGHT) {
        const scene_light *l = src->l;
        rgb C = l->colour;
        if (l->kind == LIGHT_CYLINDER) {
            vec3 axis = v3_norm(v3_sub(l->point_at, l->position));
            return beam_photon(c, l, l->position, axis, axis, fabs(l->falloff), n, r, h, o, w, phi, rays);
        }
        if (l->parallel || l->kind == LIGHT_PARALLEL) {
            vec3 to_light = v3_norm(v3_sub(l->position, l->point_at));
            vec3 cp = v3_sub(c->centre, v3_scale(to_light, v3_dot(v3_sub(c->centre, l->position), to_light)));
            return beam_photon(c, l, cp, to_light, v3_neg(to_light), c->radius, n, r, h, o, w, phi, rays);
        }
        /* an area light shoots from its centre: POV-Ray's photons do
         * (photons.cpp: the area only with the light's photons { area_light }),
         * and so does the direct light its gathering rays see (radrules.h) */
        vec3 q = l->position;
        vec3 axis = src->axis;
        double cos_max = src->cos_max;
        double u1 = rng_f64(r), u2 = rng_f64(r);
        *w = cone_dir(axis, cos_max, u1, u2);
        double pdf = 1.0 / (2.0 * M_PI * (1.0 - cos_max));
        *o = q;
        rgb f = {1.0, 1.0, 1.0};
        if (!light_first_hit(c, l, q, *w, h, &f, r, rays)) return 0;
        vec3 dl;
        double depth;
        shade_light_ray(l, q, h->p, &dl, &depth);
        double att = shade_light_attenuation(l, h->p, dl, depth);
        double d = v3_len(v3_sub(h->p, q));
        double k = M_PI * att * d * d / (n * pdf);
        *phi = crgb(C.r * k * f.r, C.g * k * f.g, C.b * k * f.b);
        return 1;
    }
    if (src->kind == SRC_EMIT) {
        const accel_surf *es = pm_lights_emitters(c->L);
        accel_surf_sample s;
        double u1 = rng_f64(r), u2 = rng_f64(r), u3 = rng_f64(r);
        if (!accel_surf_sample_point(es, u1, u2, u3, r, &s)) return -1;
        vec3 ns = rng_f64(r) < 0.5 ? s.n : v3_neg(s.n);
        double u4 = rng_f64(r), u5 = rng_f64(r);
        *w = v3_cosine_dir(ns, u4, u5);
        *o = v3_madd(s.p, ns, c->eps);
        if (accel_intersect_past(c->a, NULL, *o, *w, c->eps, OBJ_NO_RADIOSITY | PHOTON_SKIP, h, rays) <= 0) return 0;
        rgb le = pm_lights_piece_emission(c->L, &s);
        double k = 2.0 * M_PI / (n * s.pdf_area);
        *phi = crgb(le.r * k, le.g * k, le.b * k);
        return 1;
    }
    /* background */
    double u1 = rng_f64(r), u2 = rng_f64(r);
    vec3 wd = cone_dir(v3(0, 0, 1), -1.0, u1, u2);
    double R = c->radius;
    double u3 = rng_f64(r), u4 = rng_f64(r);
    *o = disc_point(v3_madd(c->centre, wd, -R * 1.001), wd, R, u3, u4);
    *w = wd;
    /* The disc lies at a finite distance, within reach of infinite objects
     * (above a ground plane that the sky below the horizon lies behind): a
     * photon whose way back towards the sky meets something carries no sky
     * light (counted, not traced), as a path's ray towards it sees that
     * object and not the sky. */
    if (accel_intersect_past(c->a, NULL, *o, v3_neg(wd), c->eps, OBJ_NO_RADIOSITY | PHOTON_SKIP, h, rays) > 0) return 0;
    if (accel_intersect_past(c->a, NULL, *o, wd, c->eps, OBJ_NO_RADIOSITY | PHOTON_SKIP, h, rays) <= 0) return 0;
    /* it arrives from the sky in direction -wd */
    rgb bg = pm_sky(c->sc, v3_neg(wd));
    double k = 4.0 * M_PI * M_PI * R * R / n;
    *phi = crgb(bg.r * k, bg.g * k, bg.b * k);
    return 1;
}

static const source *source_of(const trace_ctx *c, long index)
{
    int si = 0;
    while (si < c->nsrc - 1 && index >= c->src[si].first + c->src[si].n) si++;
    return &c->src[si];
}

/* Photon path `index`, from its source (resume NULL) or from a segment
 * launched before (resume: a launch that fn saw, its `from` surface in
 * this scene). Photons go into `out` (NULL: none stored); fn (NULL: none)
 * sees every segment traced, with its hit (NULL: it left the scene) and the
 * power a receiver crossed by it takes (after the first bounce, or from
 * the start for the background's photons, scaled by brightness^g while the
 * light may still be gathered: the rule the global map stores by; 0
 * otherwise). The random stream of a path depends on the path's index
 * only, and a resumed segment carries the stream's state, so resuming at
 * segment k gives the path that tracing from the source would give when
 * segments 0..k-1 hit the same surfaces. */
static void walk(const trace_ctx *c, long index, const pm_photon_launch *resume, chunk_out *out, pm_photon_seg_fn fn,
                 void *fctx, long *rays)
{
    pm_photon_launch L;
    accel_hit h;
    rng r;
    const rgb none = {0.0, 0.0, 0.0};
    if (!resume || resume->bounce == 0) {
        /* segment 0 is resumed by emitting again */
        memset(&L, 0, sizeof L);
        const source *s0 = source_of(c, index);
        L.source = (int)(s0 - c->src);
        L.spec_only = 1;
        L.skip = OBJ_NO_RADIOSITY;
        rng_seed(&r, pm_mix64(c->s->seed ^ 0x70686f746f6e73ULL), (uint64_t)index);
        L.r = r;
        int e = emit(c, s0, &r, &h, &L.o, &L.w, &L.phi, rays);
        if (e < 0) return;
        if (e == 0) {
            if (fn) fn(fctx, index, &L, NULL, none);
            return;
        }
    } else {
        L = *resume;
        r = L.r;
        unsigned pass = c->src[L.source].kind == SRC_LIGHT ? 0u : PHOTON_SKIP;
        if (accel_intersect_past(c->a, L.from.obj ? &L.from : NULL, L.o, L.w, c->eps, L.skip | pass, &h, rays) <= 0) {
            if (fn) fn(fctx, index, &L, NULL, none);
            return;
        }
    }
    const source *src = &c->src[L.source];
    vec3 w = L.w;
    rgb phi = L.phi;
    int from_light = src->kind == SRC_LIGHT;
    /* POV-Ray's photon power (photons.cpp, addSurfacePhoton): the light's
     * colour times the photon's spread squared times D^2 (not for parallel
     * lights), faded at D, D the photon's whole path; emit() gives the
     * power at the first hit's distance d1, so a photon on a specular path
     * from a light is stored with (D / d1)^2 fade(D) / fade(d1) of it (a
     * mirrored POV-Ray light does not fall off, as its direct light does
     * not). */
    double d1 = L.d1, plen = L.plen;
    if (!resume || resume->bounce == 0) d1 = plen = v3_len(v3_sub(h.p, L.o));
    else plen += h.t;
    int beam = from_light && (src->l->parallel || src->l->kind == LIGHT_PARALLEL || src->l->kind == LIGHT_CYLINDER);
    unsigned pass = from_light ? 0u : PHOTON_SKIP; /* the pass_through rule above */
    int store_first = src->kind == SRC_ENV || (src->kind == SRC_EMIT && c->s->emitters_first);
    int spec_only = L.spec_only;
    int nd = L.nd;
    /* light_group: a light's photons land only on what it lights (its
     * group's members, or for a global light what global_lights reaches);
     * elsewhere they end at once, as that light's direct light is absent
     * there (shade.c); after the first bounce the light is indirect and
     * reaches everything */
    /* POV-Ray's rules (radrules.h): what a no_radiosity object reflects
     * reaches no gathering ray; light that has been gathered g times (g
     * diffuse bounces of a light's photon; one more for emitted and sky
     * light, which reach any surface only by gathering) is scaled by
     * brightness^g, and reaches the eye (one more gathering) only while
     * g + 1 <= recursion_limit. */
    if (L.bounce == 0 && ((from_light && !scene_light_reaches(src->l, h.obj)) || !radrules_gathers(h.flags))) {
        if (fn) fn(fctx, index, &L, &h, none);
        return;
    }
    for (int bounce = L.bounce;; bounce++) {
        /* a photon that crossed an object fades where it leaves it, by the
         * shadow rule, as the caustic layer's (shade_mat_photon_filter) */
        rgb fa = shade_tex_leaving_fade(&h, w, 1);
        phi = crgb(phi.r * fa.r, phi.g * fa.g, phi.b * fa.b);
        if (!(cmax(phi) > 0.0)) return;
        shade_mat_bsdf b;
        shade_mat_setup(&b, c->sc, &h, w, c->eps, accel_eps_scale(c->a), &r);
        int lambert = b.m[SHADE_MAT_LOBE_DIFFUSE] > 0.0 || b.m[SHADE_MAT_LOBE_BACK] > 0.0;
        int collect = !(h.obj && h.obj->photons && !h.obj->photons->collect); /* photons { collect off } */
        int g = from_light ? nd : nd + 1;
        rgb pg = none;
        rgb phs = phi; /* the power stored here (the rule above) */
        if (from_light && spec_only && bounce >= 1 && d1 > 0.0) {
            double kd = shade_light_fade(src->l, plen) / fmax(shade_light_fade(src->l, d1), 1e-300);
            if (!beam) kd *= (plen / d1) * (plen / d1);
            phs = crgb(phi.r * kd, phi.g * kd, phi.b * kd);
        }
        int eligible = (bounce >= 1 || store_first) && g + 1 <= c->gathers && cmax(phs) > 0.0;
        if (eligible) {
            double bk = g > 0 ? pow(c->rr.brightness, g) : 1.0;
            pg = crgb(phs.r * bk, phs.g * bk, phs.b * bk);
        }
        if (fn) fn(fctx, index, &L, &h, pg);
        if (out && lambert && collect && eligible) {
            /* stored on the side of the object it arrived at (pm_kdtree.h) */
            uint32_t key = pm_surface_key(h.obj, b.entering);
            if (out->ng + out->nc >= out->cap) { out->dropped++; return; }
            if (!push(&out->g, &out->ng, &out->cg, h.p, pg, b.ng, key)) { out->oom = 1; return; }
            if (c->s->caustics && from_light && spec_only && bounce >= 1)
                if (!push(&out->c, &out->nc, &out->cc, h.p, phs, b.ng, key)) { out->oom = 1; return; }
        }
        if (bounce >= c->s->max_bounces) return;
        shade_mat_scatter s;
        if (!shade_mat_sample(&b, &r, 1, &s)) return;
        if (s.specular && bounce == 0 && from_light && !c->s->caustics) return;
        if (s.specular && from_light && spec_only && c->targets && !caustic_bounce_ok(src->l, &h, s.lobe)) return;
        if (!s.specular) {
            if (spec_only) phi = phs; /* diffusely reflected: the power it arrived with */
            spec_only = 0;
            nd++;
            if ((from_light ? nd : nd + 1) + 1 > c->gathers) return; /* never stored again */
        }
        double k = s.eta2;
        /* Only where the material's own roulette hardly ends paths (total
         * lobe size near 1): elsewhere it would add variance for nothing
         * (the rho = 0.9 furnace's worst pixel went from 0.55% to 3%). */
        double mass = b.m[SHADE_MAT_LOBE_DIFFUSE] + b.m[SHADE_MAT_LOBE_BACK] + b.m[SHADE_MAT_LOBE_REFLECT] + b.m[SHADE_MAT_LOBE_TRANSMIT] +
                      b.m[SHADE_MAT_LOBE_GLOSSY];
        if (bounce + 1 >= RR_BOUNCES && mass > RR_MASS) {
            if (rng_f64(&r) >= RR_SURVIVE) return;
            k /= RR_SURVIVE;
        }
        phi = crgb(phi.r * s.weight.r * k, phi.g * s.weight.g * k, phi.b * s.weight.b * k);
        if (!(cmax(phi) > 0.0) || !isfinite(phi.r + phi.g + phi.b)) return;
        w = s.dir;
        /* the next segment's launch: what resuming it needs */
        L.o = s.org;
        L.w = w;
        L.phi = phi;
        L.from = b.from;
        /* gathered light passes no_radiosity objects; a light's caustic path does not */
        L.skip = from_light && spec_only ? 0u : OBJ_NO_RADIOSITY;
        L.r = r;
        L.bounce = bounce + 1;
        L.nd = nd;
        L.spec_only = spec_only;
        L.d1 = d1;
        L.plen = plen;
        if (accel_intersect_past(c->a, &b.from, s.org, w, c->eps, L.skip | pass, &h, rays) <= 0) {
            if (fn) fn(fctx, index, &L, NULL, none);
            return;
        }
        plen += h.t;
    }
}

static void chunk_job(void *ctx, int ci, int thread)
{
    (void)thread;
    trace_ctx *c = ctx;
    if (c->s->cancel && *c->s->cancel) return;
    long i0 = (long)ci * CHUNK, i1 = i0 + CHUNK < c->total ? i0 + CHUNK : c->total;
    chunk_out *out = &c->chunks[ci];
    for (long i = i0; i < i1 && !out->oom && !(c->s->cancel && *c->s->cancel); i++) walk(c, i, NULL, out, NULL, NULL, &out->rays);
}

/* The sources and their shares of s->photons (c->src, c->nsrc, c->total;
 * c->src NULL when there is nothing to trace). bounds (NULL: the accel's):
 * the box the parallel lights' and the background's photons are aimed
 * across and the allocation proxies are taken over. */
static pt_status setup(trace_ctx *cp, const scene *sc, const accel *a, const pm_lights *L, const pm_photon_settings *s,
                       const vec3 *bounds, int *sources, int *targets)
{
    trace_ctx c = {.sc = sc, .a = a, .L = L, .s = s, .eps = pm_lights_eps(L), .rr = radrules_of(sc, 1)};
    c.gathers = pm_gathers(&c.rr);
    c.transparent = shade_tex_scene_transparent(sc);
    c.targets = pm_any_target(sc);
    *targets = c.targets;
    vec3 lo, hi;
    if (bounds) {
        lo = bounds[0];
        hi = bounds[1];
    } else {
        accel_bounds(a, &lo, &hi);
    }
    c.centre = v3_scale(v3_add(lo, hi), 0.5);
    c.radius = 0.5 * v3_len(v3_sub(hi, lo)) * 1.01 + 1e-9;
    double D = 0.5 * v3_len(v3_sub(hi, lo));
    if (!(D > 0.0)) D = 1.0;

    source *src = calloc((size_t)sc->nlights + 2, sizeof(source));
    if (!src) return PT_ERR_NOMEM;
    int ns = 0;
    for (int i = 0; i < sc->nlights; i++) {
        const scene_light *l = &sc->lights[i];
        source *q = &src[ns];
        q->kind = SRC_LIGHT;
        q->l = l;
        q->cos_max = -1.0;
        q->axis = v3(0, 0, 1);
        double cm = cmax(l->colour);
        if (l->kind == LIGHT_CYLINDER) {
            q->power = cm * M_PI * M_PI * l->falloff * l->falloff;
        } else if (l->parallel || l->kind == LIGHT_PARALLEL) {
            q->power = cm * M_PI * M_PI * c.radius * c.radius;
        } else {
            if (l->kind == LIGHT_SPOT) {
                double cr = cos(l->radius * M_PI / 180.0), cf = cos(l->falloff * M_PI / 180.0);
                q->cos_max = cr > 0.0 ? fmax(0.0, fmin(cf, cr)) : 0.0;
                q->axis = v3_norm(v3_sub(l->point_at, l->position));
            }
            /* A light outside the sphere around the finite objects (a sun
             * placed far away, as POV-Ray scenes do) reaches them only
             * within the cone that subtends the sphere: shot over all
             * directions, nearly every photon would miss (a room lit
             * through its window by such a light got almost none, and its
             * second bounce was lost). Photons go into that cone when it is
             * narrower than the spot's; directions outside it meet only
             * infinite objects beyond the sphere, whose gather hits do not
             * read the map (pm_fg.c, far_irradiance), as for parallel
             * lights. Either cone holds every direction that matters, so
             * the estimate stays unbiased inside the sphere. */
            vec3 to = v3_sub(c.centre, l->position);
            double dl = v3_len(to);
            int aimed = 0;
            if (dl > c.radius) {
                double cs = sqrt(fmax(0.0, 1.0 - (c.radius / dl) * (c.radius / dl)));
                if (cs > q->cos_max) {
                    q->cos_max = cs;
                    q->axis = v3_scale(to, 1.0 / dl);
                    aimed = 1;
                }
            }
            /* allocation proxy: the flux across the sphere's disc for an
             * aimed light (E = pi C att over pi R^2), else over a sphere of
             * radius D about the light */
            q->power = aimed ? cm * M_PI * M_PI * c.radius * c.radius * shade_light_fade(l, dl)
                             : cm * M_PI * 2.0 * M_PI * (1.0 - q->cos_max) * D * D * shade_light_fade(l, D);
        }
        if (q->power > 0.0 && isfinite(q->power)) ns++;
    }
    const accel_surf *es = pm_lights_emitters(L);
    if (accel_surf_count(es) > 0 && accel_surf_total_weight(es) > 0.0) {
        src[ns].kind = SRC_EMIT;
        src[ns].power = 2.0 * M_PI * accel_surf_total_weight(es);
        ns++;
    }
    if (pm_sky_any(sc) && D > 0.0) {
        /* allocation proxy: mean max channel of the sky over 256 spiral
         * directions (the photons' own powers are exact) */
        double m = 0.0;
        for (int i = 0; i < 256; i++) {
            double z = 1.0 - (i + 0.5) / 128.0, rr = sqrt(fmax(0.0, 1.0 - z * z)), ph = i * 2.399963229728653;
            m += cmax(pm_sky(sc, v3(rr * cos(ph), rr * sin(ph), z)));
        }
        m /= 256.0;
        if (m > 0.0 && isfinite(m)) {
            src[ns].kind = SRC_ENV;
            src[ns].power = m * M_PI * 4.0 * M_PI * c.radius * c.radius;
            ns++;
        }
    }
    *sources = ns;
    if (ns == 0 || s->photons <= 0) {
        free(src);
        *cp = c;
        return PT_OK;
    }
    double ptotal = 0.0;
    for (int i = 0; i < ns; i++) ptotal += src[i].power;
    long total = 0;
    long minimum = s->photons / 10 < 1000 ? s->photons / 10 : 1000;
    if (minimum < 1) minimum = 1;
    for (int i = 0; i < ns; i++) {
        long n = (long)floor((double)s->photons * src[i].power / ptotal + 0.5);
        if (n < minimum) n = minimum;
        src[i].n = n;
        src[i].first = total;
        total += n;
    }
    c.src = src;
    c.nsrc = ns;
    c.total = total;
    *cp = c;
    return PT_OK;
}

pt_status pm_photons_trace(const scene *sc, const accel *a, const pm_lights *L, const pm_photon_settings *s,
                           pm_photon_result *out)
{
    memset(out, 0, sizeof *out);
    trace_ctx c;
    pt_status st = setup(&c, sc, a, L, s, NULL, &out->sources, &out->targets);
    if (st != PT_OK) return st;
    out->centre = c.centre;
    out->radius = c.radius;
    if (!c.src) return st;
    source *src = c.src;
    long total = c.total;
    c.nchunks = (int)((total + CHUNK - 1) / CHUNK);
    c.chunks = calloc((size_t)c.nchunks, sizeof(chunk_out));
    if (!c.chunks) {
        free(src);
        return PT_ERR_NOMEM;
    }
    double cap = fmin((double)STORED_PER_EMITTED * (double)total, (double)STORED_MAX);
    for (int i = 0; i < c.nchunks; i++) {
        long i0 = (long)i * CHUNK, i1 = i0 + CHUNK < total ? i0 + CHUNK : total;
        c.chunks[i].cap = (long)ceil(cap * (double)(i1 - i0) / (double)total);
    }
    pool_run_counted(pm_threads(s->threads), c.nchunks, chunk_job, &c, NULL, s->progress);

    long ng = 0, nc = 0;
    int oom = 0;
    for (int i = 0; i < c.nchunks; i++) {
        ng += c.chunks[i].ng;
        nc += c.chunks[i].nc;
        out->rays += c.chunks[i].rays;
        out->dropped += c.chunks[i].dropped;
        oom |= c.chunks[i].oom;
    }
    out->global = malloc(sizeof(pm_photon) * (size_t)(ng > 0 ? ng : 1));
    out->caustic = malloc(sizeof(pm_photon) * (size_t)(nc > 0 ? nc : 1));
    if (!out->global || !out->caustic) oom = 1;
    long kg = 0, kc = 0;
    for (int i = 0; i < c.nchunks; i++) {
        if (!oom) {
            /* an empty chunk's array may be NULL: memcpy must not get it */
            if (c.chunks[i].ng) memcpy(out->global + kg, c.chunks[i].g, sizeof(pm_photon) * (size_t)c.chunks[i].ng);
            if (c.chunks[i].nc) memcpy(out->caustic + kc, c.chunks[i].c, sizeof(pm_photon) * (size_t)c.chunks[i].nc);
        }
        kg += c.chunks[i].ng;
        kc += c.chunks[i].nc;
        free(c.chunks[i].g);
        free(c.chunks[i].c);
    }
    free(c.chunks);
    free(src);
    if (oom) {
        free(out->global);
        free(out->caustic);
        memset(out, 0, sizeof *out);
        return PT_ERR_NOMEM;
    }
    out->nglobal = ng;
    out->ncaustic = nc;
    out->emitted = total;
    return PT_OK;
}

struct pm_photon_walker {
    trace_ctx c;
    pm_photon_settings s;
};

pm_photon_walker *pm_photon_walker_new(const scene *sc, const accel *a, const pm_lights *L, const pm_photon_settings *s,
                                       const vec3 *bounds, double eps, long *paths, pt_status *st)
{
    pm_photon_walker *w = calloc(1, sizeof *w);
    *paths = 0;
    if (!w) {
        *st = PT_ERR_NOMEM;
        return NULL;
    }
    w->s = *s;
    int sources, targets;
    *st = setup(&w->c, sc, a, L, &w->s, bounds, &sources, &targets);
    if (*st != PT_OK) {
        free(w);
        return NULL;
    }
    w->c.s = &w->s;
    if (eps > 0.0) w->c.eps = eps;
    *paths = w->c.src ? w->c.total : 0;
    return w;
}

void pm_photon_walk(const pm_photon_walker *w, long index, const pm_photon_launch *resume, pm_photon_seg_fn fn, void *ctx,
                    long *rays)
{
    if (w->c.src && index >= 0 && index < w->c.total) walk(&w->c, index, resume, NULL, fn, ctx, rays);
}

void pm_photon_walker_free(pm_photon_walker *w)
{
    if (!w) return;
    free(w->c.src);
    free(w);
}
