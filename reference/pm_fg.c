/* pm_fg.c - photon map + final gathering (see pm_fg.h).
 *
 * Final gather at an eye vertex x with Lambertian albedos kd (viewer's side)
 * and kb (other side): N_f rays cosine-distributed about n, N_b about -n,
 * stratified on a grid over the unit square that the cosine map takes to
 * the hemisphere. Each ray's estimate of  int kd/pi L(w) cos dw  is kd L(w)
 * (cosine density cos/pi), so the gathered radiance is
 *     kd (1/N_f) sum L(w_i) + kb (1/N_b) sum L(w_j).
 * L at a gather hit y (seen along w) is its emission (weighted against the
 * emitter samples taken at x, pm_nee.h) plus its reflected radiance:
 * direct light by shadow rays (one POV-Ray light picked in proportion to its
 * unoccluded intensity, one emitter sample) + k_y/pi E_ind(y) + specular
 * lobes, where
 * E_ind is the photon irradiance estimate (vis_irradiance; the maps
 * hold only light that made at least one bounce, pm_photon.h).
 *
 * The caustic map adds at x: kd/pi E_c(x, n) + kb/pi E_c(x, -n). */
#include "pm_fg.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "pm_kdtree.h"
#include "pm_nee.h"
#include "pm_photon.h"
#include "pool.h"
#include "radrules.h"
#include "shade_atmos.h"
#include "shade_material.h"
#include "shade_texture.h"
#include "timer.h"

#define KMAX 1024
#define NORMAL_DOT 0.5   /* photons count for a query when their normals are within 60 degrees */
#define EYE_RR 1e-3      /* eye branches below this weight go on by Russian roulette */

void pm_fg_default_settings(pm_fg_settings *s)
{
    *s = (pm_fg_settings){.photons = 1000000, .fg_rays = 4096, .k_global = 64, .k_caustic = 32, .irradiance_stride = 4,
                          .caustics = -1, .area_samples = 4, .emitter_samples = 4, .max_eye_depth = 16,
                          .max_gather_depth = 8, .max_photon_bounces = 256};
    pm_common_defaults(&s->c);
    /* 64 eye samples per pixel, the gather rays and light samples split over
     * them (4 area-light and 4 emitter samples each: 256 per pixel): with
     * one jittered eye sample a pixel on a silhouette or a contact took one
     * side only (black and bright pixels along the room's edges and block
     * tops of radiosity/cornell.pov against an antialiased path image); 16
     * still left pixels of thin lit strips at half of path's (balcony.pov) */
    s->c.spp = 64;
}

typedef struct {
    const scene *sc;
    const accel *a;
    const pm_fg_settings *s;
    const pm_lights *L;
    double eps;
    pm_kdtree *global, *caustic, *irr;
    double r_global, r_caustic;
    int k_global, k_caustic;
    int fg_per_sample;
    pm_neighbour *scratch; /* KMAX per thread */
    radrules rr;           /* POV-Ray's rules for gathered light (core/radrules.h) */
    int gathers;           /* recursion_limit: gathering steps from the eye */
    int eye_levels;        /* eye rays: levels 0 .. eye_levels - 1 (max_trace_level, radrules.h rule 7) */
    int gather_specular;   /* specular bounces after a gather hit within the level limit */
    vec3 pcentre;          /* the photons' sphere (pm_photon_result's centre, radius) */
    double pradius;
} fg_ctx;

static inline rgb frgb(double r, double g, double b) { rgb c = {r, g, b}; return c; }
static inline void acc_add(rgb *a, rgb t, rgb v)
{
    a->r += t.r * v.r;
    a->g += t.g * v.g;
    a->b += t.b * v.b;
}
static inline double fmax3(rgb t) { return fmax(t.r, fmax(t.g, t.b)); }


/* Whether the photon (or irradiance point) at y, normal ny, may stand for
 * light at x, normal nx, on the surface of key `surf`: the segment between
 * the two points lifted off the surface by 16 eps along their normals
 * crosses no other object. Hits on the surface's own object are passed
 * (a chord of a curved surface dips under it). Without this test a density
 * estimate reaches across walls: the floor just outside a box standing on
 * it gathered the photons of a light inside the box, stored on the floor
 * under the box (the two coplanar faces tie, and the ray hits the floor);
 * likewise the dark side of a thin wall near the lit side. */
static int same_surface(const scene_object *obj, const void *surf)
{
    return (pm_surface_key(obj, 0) | 1u) == (*(const uint32_t *)surf | 1u);
}

static int vis_ok(const fg_ctx *c, vec3 x, vec3 nx, vec3 y, vec3 ny, uint32_t surf)
{
    return accel_mutually_visible(c->a, c->eps, x, nx, y, ny, same_surface, &surf);
}

/* Keeps the neighbours (a max-heap from pm_kdtree_knn) that vis_ok sees
 * from x, in their order; returns how many. */
static int vis_filter(const fg_ctx *c, const pm_kdtree *t, vec3 x, vec3 nx, uint32_t surf, pm_neighbour *nb, int n,
                      long *rays)
{
    const pm_photon *ph = pm_kdtree_photons(t);
    int w = 0;
    for (int i = 0; i < n; i++) {
        const pm_photon *p = &ph[nb[i].idx];
        (*rays)++;
        if (vis_ok(c, x, nx, pm_photon_pos(p), pm_photon_normal(p), surf)) nb[w++] = nb[i];
    }
    return w;
}

/* Irradiance on the side nx of x from the k nearest photons of key surf
 * that x sees (vis_ok): the sum of the k-1 nearest visible powers over
 * pi r_k^2, r_k the distance of the k-th (fewer than k in reach: all of
 * them over pi max_r^2). The k-1 rule is unbiased for a uniform (Poisson)
 * photon density: given r_k, the k-1 photons inside are uniform in the
 * disc, and E[(k-1)/(pi r_k^2)] equals the density (r_k^2 is Gamma(k)
 * distributed); Jensen's sum of all k over pi r_k^2 overestimates by
 * k/(k-1). */
static int vis_irradiance(const fg_ctx *c, const pm_kdtree *t, vec3 x, vec3 nx, uint32_t surf, int k, double max_r,
                          pm_neighbour *scratch, long *rays, rgb *e)
{
    e->r = e->g = e->b = 0.0;
    int n = pm_kdtree_knn(t, x, nx, surf, NORMAL_DOT, k, max_r * max_r, scratch);
    if (n == 0) return 0;
    int full = n == k;
    n = vis_filter(c, t, x, nx, surf, scratch, n, rays);
    if (n == 0) return 0;
    const pm_photon *ph = pm_kdtree_photons(t);
    double area, sr = 0.0, sg = 0.0, sb = 0.0, far = 0.0;
    int fi = 0;
    for (int i = 0; i < n; i++)
        if (scratch[i].d2 > far) {
            far = scratch[i].d2;
            fi = i;
        }
    int used = 0;
    if (full && n >= 2) {
        area = M_PI * far; /* the farthest visible photon gives the radius and is left out */
    } else {
        area = M_PI * max_r * max_r;
        fi = -1;
    }
    for (int i = 0; i < n; i++) {
        if (i == fi) continue;
        sr += ph[scratch[i].idx].power[0];
        sg += ph[scratch[i].idx].power[1];
        sb += ph[scratch[i].idx].power[2];
        used++;
    }
    if (!(area > 0.0)) return 0;
    e->r = sr / area;
    e->g = sg / area;
    e->b = sb / area;
    return used;
}

/* Indirect irradiance at p on the side n (surface key surf) from the global
 * map: the nearest precomputed irradiance point that p sees (vis_ok; of the
 * IRR_NEAR nearest), else none. */
#define IRR_NEAR 4
static rgb global_irradiance(const fg_ctx *c, vec3 p, vec3 n, uint32_t surf, int thread, long *rays)
{
    rgb e = {0, 0, 0};
    if (!c->global || pm_kdtree_size(c->global) == 0) return e;
    pm_neighbour *nb = c->scratch + (size_t)thread * KMAX;
    if (c->irr) {
        int m = pm_kdtree_knn(c->irr, p, n, surf, NORMAL_DOT, IRR_NEAR, c->r_global * c->r_global, nb);
        /* nearest first: the heap's order is not sorted */
        for (int a = 1; a < m; a++)
            for (int b = a; b > 0 && nb[b].d2 < nb[b - 1].d2; b--) {
                pm_neighbour t = nb[b];
                nb[b] = nb[b - 1];
                nb[b - 1] = t;
            }
        const pm_photon *ph = pm_kdtree_photons(c->irr);
        for (int a = 0; a < m; a++) {
            const pm_photon *q = &ph[nb[a].idx];
            (*rays)++;
            if (vis_ok(c, p, n, pm_photon_pos(q), pm_photon_normal(q), surf))
                return frgb(q->power[0], q->power[1], q->power[2]);
        }
        return e;
    }
    vis_irradiance(c, c->global, p, n, surf, c->k_global, c->r_global, nb, rays, &e);
    return e;
}

static rgb gather_hit(const fg_ctx *c, const shade_mat_bsdf *b, uint32_t surf, int level, int ng, int thread, rng *r,
                      pm_counts *cnt);

/* Irradiance at a gather hit beyond the photons' sphere (an infinite
 * ground far from the finite objects), where the sky's and parallel
 * lights' photons never land: one cosine-weighted ray about axis from org
 * estimates what the map would hold there, pi times the sky's radiance
 * where it leaves the scene, else the reflected radiance of what it hits
 * (its direct light, and its own gathering within recursion_limit;
 * emitters are sampled at the hit itself, so their emission is not
 * counted), times brightness for the gathering at the hit, as the map's
 * photons carry it (pm_photon.c). */
static rgb far_irradiance(const fg_ctx *c, const shade_mat_bsdf *b, vec3 axis, vec3 org, int ng, int thread, rng *r,
                          pm_counts *cnt)
{
    vec3 w = v3_cosine_dir(axis, rng_f64(r), rng_f64(r));
    const double k = M_PI * c->rr.brightness;
    cnt->bsdf++;
    accel_hit h;
    if (accel_intersect_past(c->a, &b->from, org, w, c->eps, OBJ_NO_RADIOSITY, &h, NULL) <= 0) {
        rgb sky = pm_sky(c->sc, w);
        return frgb(k * sky.r, k * sky.g, k * sky.b);
    }
    rgb fa = shade_tex_leaving_fade(&h, w, 0);
    shade_mat_bsdf b2;
    shade_mat_setup(&b2, c->sc, &h, w, c->eps, accel_eps_scale(c->a), r);
    b2.gathered = 1;
    rgb v = gather_hit(c, &b2, pm_surface_key(h.obj, b2.entering), 0, ng + 1, thread, r, cnt);
    return frgb(k * fa.r * v.r, k * fa.g * v.g, k * fa.b * v.b);
}

/* Reflected radiance at a gather hit (not its emission); surf: the key of
 * the side the gather ray arrived at (pm_surface_key); ng: the gathering
 * steps taken to reach it (1 for the hit of a gather ray from the eye). */
static rgb gather_hit(const fg_ctx *c, const shade_mat_bsdf *b, uint32_t surf, int level, int ng, int thread, rng *r,
                      pm_counts *cnt)
{
    rgb L = {0, 0, 0};
    if (b->nee) {
        rgb d = pm_direct_one_light(c->L, b, r, &cnt->shadow);
        L.r += d.r;
        L.g += d.g;
        L.b += d.b;
    }
    /* The hit gathers in its turn (emitters, photon irradiance, its glossy
     * lobe) only within recursion_limit. Its specular lobes and, when it may
     * gather, its glossy lobe are followed by one ray chosen by Russian
     * roulette; pg is the probability that the glossy one is, the density
     * the emitter samples are weighted against (pm_nee.h). */
    const int can_gather = ng + 1 <= c->gathers;
    const double mg = can_gather ? b->m[SHADE_MAT_LOBE_GLOSSY] : 0.0;
    const double ms = b->m[SHADE_MAT_LOBE_REFLECT] + b->m[SHADE_MAT_LOBE_TRANSMIT] + mg;
    const int follow = ms > 0.0 && level < c->s->max_gather_depth && level < c->gather_specular;
    const double q = fmin(1.0, ms);
    const double pg = follow ? q * mg / ms : 0.0;
    const double br = c->rr.brightness;
    if (can_gather && (b->m[SHADE_MAT_LOBE_DIFFUSE] > 0.0 || b->m[SHADE_MAT_LOBE_BACK] > 0.0 || mg > 0.0)) {
        /* emitters' light is gathered light: brightness */
        rgb d = pm_direct_emitters(c->L, b, 1, 0.0, 0.0, pg, r, &cnt->shadow);
        L.r += d.r * br;
        L.g += d.g * br;
        L.b += d.b * br;
        const int beyond = v3_len(v3_sub(b->p, c->pcentre)) > c->pradius;
        if (b->m[SHADE_MAT_LOBE_DIFFUSE] > 0.0) {
            rgb e = beyond ? far_irradiance(c, b, b->n, b->p_out, ng, thread, r, cnt)
                           : global_irradiance(c, b->p, b->n, surf, thread, &cnt->shadow);
            acc_add(&L, b->k[SHADE_MAT_LOBE_DIFFUSE], frgb(e.r / M_PI, e.g / M_PI, e.b / M_PI));
        }
        if (b->m[SHADE_MAT_LOBE_BACK] > 0.0) {
            rgb e = beyond ? far_irradiance(c, b, v3_neg(b->n), b->p_in, ng, thread, r, cnt)
                           : global_irradiance(c, b->p, v3_neg(b->n), surf ^ 1u, thread, &cnt->shadow);
            acc_add(&L, b->k[SHADE_MAT_LOBE_BACK], frgb(e.r / M_PI, e.g / M_PI, e.b / M_PI));
        }
    }
    if (follow && rng_f64(r) < q) {
        double u = rng_f64(r) * ms;
        int lobe = u < b->m[SHADE_MAT_LOBE_REFLECT] ? SHADE_MAT_LOBE_REFLECT
                   : u < b->m[SHADE_MAT_LOBE_REFLECT] + b->m[SHADE_MAT_LOBE_TRANSMIT] ? SHADE_MAT_LOBE_TRANSMIT
                                                                                    : SHADE_MAT_LOBE_GLOSSY;
        if (b->m[lobe] <= 0.0) return L; /* rounding at an interval's end */
        double p = lobe == SHADE_MAT_LOBE_GLOSSY ? pg : q * b->m[lobe] / ms;
        rgb w = b->k[lobe];
        vec3 org = lobe == SHADE_MAT_LOBE_TRANSMIT ? b->p_in : b->p_out;
        vec3 dir = lobe == SHADE_MAT_LOBE_REFLECT ? b->refl_dir : b->trans_dir;
        double pdf = 0.0;
        if (lobe == SHADE_MAT_LOBE_GLOSSY) {
            shade_mat_scatter s;
            if (!shade_mat_sample_glossy(b, rng_f64(r), rng_f64(r), rng_f64(r), &s)) return L;
            w = frgb(s.weight.r * br, s.weight.g * br, s.weight.b * br);
            org = s.org;
            dir = s.dir;
            pdf = s.pdf;
        }
        w = frgb(w.r / p, w.g / p, w.b / p);
        cnt->bsdf++;
        accel_hit h;
        unsigned skip = OBJ_NO_RADIOSITY | (lobe == SHADE_MAT_LOBE_REFLECT ? OBJ_NO_REFLECTION : 0u);
        if (accel_intersect_past(c->a, &b->from, org, dir, c->eps, skip, &h, NULL) <= 0) {
            acc_add(&L, w, pm_sky(c->sc, dir));
        } else {
            rgb fa = shade_tex_leaving_fade(&h, dir, 0); /* as pm_path.c */
            w = frgb(w.r * fa.r, w.g * fa.g, w.b * fa.b);
            shade_mat_bsdf b2;
            shade_mat_setup(&b2, c->sc, &h, dir, c->eps, accel_eps_scale(c->a), r);
            b2.gathered = 1;
            double we = lobe == SHADE_MAT_LOBE_GLOSSY ? pm_mis(pg * pdf, pm_emitter_density(c->L, &h, org, 1)) : 1.0;
            acc_add(&L, w, frgb(b2.emission.r * we, b2.emission.g * we, b2.emission.b * we));
            acc_add(&L, w, gather_hit(c, &b2, pm_surface_key(h.obj, b2.entering), level + 1,
                                      lobe == SHADE_MAT_LOBE_GLOSSY ? ng + 1 : ng, thread, r, cnt));
        }
    }
    return L;
}

/* Radiance arriving at an eye vertex along the gather ray (org, w): its
 * emission, weighted against the emitter samples taken there by the power
 * heuristic (cb: the gather strategy's count-weighted density of w), plus
 * what the hit reflects (gather_hit). */
static rgb gather_ray(const fg_ctx *c, const shade_mat_bsdf *b, vec3 org, vec3 w, double cb, int thread, rng *r,
                      pm_counts *cnt)
{
    rgb sum = {0, 0, 0};
    cnt->gather++;
    accel_hit h;
    int hit = accel_intersect_past(c->a, &b->from, org, w, c->eps, OBJ_NO_RADIOSITY, &h, NULL) > 0;
    rgb fa = {1, 1, 1};
    if (c->rr.media && c->sc->fogs) {
        /* `media on`: gathering rays see fog too (radrules.h rule 5) */
        rgb fc;
        shade_atmos_fog_affine(c->sc, org, w, hit ? h.t : INFINITY, &fa, &fc);
        sum = fc;
    }
    if (!hit) {
        acc_add(&sum, fa, pm_sky(c->sc, w));
        return sum;
    }
    rgb ff = shade_tex_leaving_fade(&h, w, 0); /* as pm_path.c */
    fa = frgb(fa.r * ff.r, fa.g * ff.g, fa.b * ff.b);
    shade_mat_bsdf b2;
    shade_mat_setup(&b2, c->sc, &h, w, c->eps, accel_eps_scale(c->a), r);
    b2.gathered = 1;
    rgb le = b2.emission;
    if (le.r != 0.0 || le.g != 0.0 || le.b != 0.0) {
        double wt = pm_mis(cb, pm_emitter_density(c->L, &h, org, c->s->emitter_samples));
        acc_add(&sum, fa, frgb(le.r * wt, le.g * wt, le.b * wt));
    }
    acc_add(&sum, fa, gather_hit(c, &b2, pm_surface_key(h.obj, b2.entering), 0, 1, thread, r, cnt));
    return sum;
}

/* Stratum i of n on a g1 x g2 grid of the unit square (the remainder uniform). */
static void gather_stratum(int i, int n, rng *r, double *u1, double *u2)
{
    int g1 = (int)floor(sqrt((double)n));
    if (g1 < 1) g1 = 1;
    int g2 = n / g1;
    if (i < g1 * g2) {
        *u1 = ((i % g1) + rng_f64(r)) / g1;
        *u2 = ((i / g1) + rng_f64(r)) / g2;
    } else {
        *u1 = rng_f64(r);
        *u2 = rng_f64(r);
    }
}

/* (1/n) sum of radiance over n stratified cosine directions about `axis`. */
static rgb gather_lobe(const fg_ctx *c, const shade_mat_bsdf *b, vec3 axis, vec3 org, int front, int n, int nf, int nb,
                       int thread, rng *r, pm_counts *cnt)
{
    rgb sum = {0, 0, 0};
    if (n <= 0) return sum;
    for (int i = 0; i < n; i++) {
        double u1, u2;
        gather_stratum(i, n, r, &u1, &u2);
        vec3 w = v3_cosine_dir(axis, u1, u2);
        double cg = v3_dot(w, b->ng);
        if (front ? cg <= 0.0 : cg >= 0.0) continue;
        double cb = (front ? nf : nb) * fabs(v3_dot(w, b->n)) / M_PI;
        rgb v = gather_ray(c, b, org, w, cb, thread, r, cnt);
        sum.r += v.r;
        sum.g += v.g;
        sum.b += v.b;
    }
    return frgb(sum.r / n, sum.g / n, sum.b / n);
}

/* The glossy lobe's part: (1/n) sum of f_g cos / pdf * L over n directions
 * sampled from the lobe (stratified in the lobe's two direction numbers). */
static rgb gather_glossy(const fg_ctx *c, const shade_mat_bsdf *b, int n, int thread, rng *r, pm_counts *cnt)
{
    rgb sum = {0, 0, 0};
    if (n <= 0) return sum;
    for (int i = 0; i < n; i++) {
        double u1, u2;
        gather_stratum(i, n, r, &u1, &u2);
        shade_mat_scatter s;
        if (!shade_mat_sample_glossy(b, rng_f64(r), u1, u2, &s)) continue;
        acc_add(&sum, s.weight, gather_ray(c, b, s.org, s.dir, n * s.pdf, thread, r, cnt));
    }
    return frgb(sum.r / n, sum.g / n, sum.b / n);
}

static void eye_trace(const fg_ctx *c, const accel_from *from, vec3 org, vec3 dir, unsigned skip, rgb T, int depth,
                      int thread, rng *r, pm_counts *cnt, rgb *L)
{
    if (depth >= c->s->max_eye_depth || depth >= c->eye_levels) return;
    accel_hit h;
    int hit = accel_intersect_past(c->a, from, org, dir, c->eps, skip, &h, NULL) > 0;
    if (c->sc->fogs) {
        /* fog on eye segments (gathering rays see it only with `media on`) */
        rgb fa, fc;
        shade_atmos_fog_affine(c->sc, org, dir, hit ? h.t : INFINITY, &fa, &fc);
        acc_add(L, T, fc);
        T = frgb(T.r * fa.r, T.g * fa.g, T.b * fa.b);
    }
    if (!hit) {
        acc_add(L, T, pm_sky(c->sc, dir));
        return;
    }
    rgb fa = shade_tex_leaving_fade(&h, dir, 0); /* as pm_path.c */
    T = frgb(T.r * fa.r, T.g * fa.g, T.b * fa.b);
    shade_mat_bsdf b;
    shade_mat_setup(&b, c->sc, &h, dir, c->eps, accel_eps_scale(c->a), r);
    if (b.unsupported) cnt->unsupported++;
    acc_add(L, T, b.emission);
    if (b.nee) acc_add(L, T, pm_direct_lights(c->L, &b, c->s->area_samples, r, &cnt->shadow));
    double md = b.m[SHADE_MAT_LOBE_DIFFUSE], mb = b.m[SHADE_MAT_LOBE_BACK], mg = b.m[SHADE_MAT_LOBE_GLOSSY];
    if (md > 0.0 || mb > 0.0 || mg > 0.0) {
        double scale = depth == 0 ? 1.0 : fmin(1.0, fmax3(T));
        int ng = (int)lround(c->fg_per_sample * scale);
        if (ng < 4) ng = 4; /* 2 x 2 strata at least */
        /* the gather rays split over the lobes in proportion to their size */
        int nf = md > 0.0 ? (int)lround(ng * md / (md + mb + mg)) : 0;
        int nb = mb > 0.0 ? (int)lround(ng * mb / (md + mb + mg)) : 0;
        if (md > 0.0 && nf < 1) nf = 1;
        if (mb > 0.0 && nb < 1) nb = 1;
        int ngl = mg > 0.0 ? ng - nf - nb : 0;
        if (mg > 0.0 && ngl < 1) ngl = 1;
        /* gathered light (emitters, the final gather) is scaled by brightness */
        const double br = c->rr.brightness;
        const rgb Tg = frgb(T.r * br, T.g * br, T.b * br);
        acc_add(L, Tg, pm_direct_emitters(c->L, &b, c->s->emitter_samples, nf, nb, ngl, r, &cnt->shadow));
        if (c->caustic && pm_kdtree_size(c->caustic) > 0) {
            pm_neighbour *sc = c->scratch + (size_t)thread * KMAX;
            uint32_t key = pm_surface_key(h.obj, b.entering);
            rgb e;
            if (md > 0.0) {
                vis_irradiance(c, c->caustic, b.p, b.n, key, c->k_caustic, c->r_caustic, sc, &cnt->shadow, &e);
                acc_add(L, T, frgb(b.k[SHADE_MAT_LOBE_DIFFUSE].r * e.r / M_PI, b.k[SHADE_MAT_LOBE_DIFFUSE].g * e.g / M_PI,
                                   b.k[SHADE_MAT_LOBE_DIFFUSE].b * e.b / M_PI));
            }
            if (mb > 0.0) {
                vis_irradiance(c, c->caustic, b.p, v3_neg(b.n), key ^ 1u, c->k_caustic, c->r_caustic, sc, &cnt->shadow,
                               &e);
                acc_add(L, T, frgb(b.k[SHADE_MAT_LOBE_BACK].r * e.r / M_PI, b.k[SHADE_MAT_LOBE_BACK].g * e.g / M_PI,
                                   b.k[SHADE_MAT_LOBE_BACK].b * e.b / M_PI));
            }
        }
        cnt->gather_points++;
        if (nf > 0) {
            rgb g = gather_lobe(c, &b, b.n, b.p_out, 1, nf, nf, nb, thread, r, cnt);
            acc_add(L, Tg, frgb(b.k[SHADE_MAT_LOBE_DIFFUSE].r * g.r, b.k[SHADE_MAT_LOBE_DIFFUSE].g * g.g,
                               b.k[SHADE_MAT_LOBE_DIFFUSE].b * g.b));
        }
        if (nb > 0) {
            rgb g = gather_lobe(c, &b, v3_neg(b.n), b.p_in, 0, nb, nf, nb, thread, r, cnt);
            acc_add(L, Tg, frgb(b.k[SHADE_MAT_LOBE_BACK].r * g.r, b.k[SHADE_MAT_LOBE_BACK].g * g.g, b.k[SHADE_MAT_LOBE_BACK].b * g.b));
        }
        if (ngl > 0) acc_add(L, Tg, gather_glossy(c, &b, ngl, thread, r, cnt));
    }
    /* specular lobes: both followed (Whitted-style), small weights by roulette */
    for (int lobe = SHADE_MAT_LOBE_REFLECT; lobe <= SHADE_MAT_LOBE_TRANSMIT; lobe++) {
        if (b.m[lobe] <= 0.0) continue;
        rgb T2 = frgb(T.r * b.k[lobe].r, T.g * b.k[lobe].g, T.b * b.k[lobe].b);
        double mt = fmax3(T2);
        if (!(mt > 0.0)) continue;
        if (mt < EYE_RR) {
            double q = mt / EYE_RR;
            if (rng_f64(r) >= q) continue;
            T2 = frgb(T2.r / q, T2.g / q, T2.b / q);
        }
        cnt->bsdf++;
        if (lobe == SHADE_MAT_LOBE_REFLECT)
            eye_trace(c, &b.from, b.p_out, b.refl_dir, OBJ_NO_REFLECTION, T2, depth + 1, thread, r, cnt, L);
        else
            eye_trace(c, &b.from, b.p_in, b.trans_dir, skip, T2, depth + 1, thread, r, cnt, L);
    }
}

static rgb fg_sample(void *ctx, double px, double py, int thread, rng *r, pm_counts *cnt)
{
    const fg_ctx *c = ctx;
    vec3 org, dir;
    scene_camera_ray(&c->sc->camera, px, py, c->s->c.width, c->s->c.height, &org, &dir);
    cnt->camera++;
    rgb L = {0, 0, 0}, T = {1, 1, 1};
    eye_trace(c, NULL, org, dir, OBJ_NO_IMAGE, T, 0, thread, r, cnt, &L);
    return L;
}

/* ------------------------------------------------------------ precomputed irradiance */

typedef struct {
    const fg_ctx *c;
    const pm_photon *src;
    long n, stride;
    pm_photon *out;
    pm_neighbour *scratch;
    long *rays;        /* visibility rays, per thread */
} irr_job;

#define IRR_BLOCK 2048

static void irr_block(void *ctx, int bi, int thread)
{
    irr_job *j = ctx;
    long i0 = (long)bi * IRR_BLOCK, i1 = i0 + IRR_BLOCK < j->n ? i0 + IRR_BLOCK : j->n;
    for (long i = i0; i < i1; i++) {
        const pm_photon *ph = &j->src[i * j->stride];
        vec3 p = pm_photon_pos(ph), n = v3_norm(pm_photon_normal(ph));
        rgb e;
        vis_irradiance(j->c, j->c->global, p, n, ph->surf, j->c->k_global, j->c->r_global,
                       j->scratch + (size_t)thread * KMAX, &j->rays[thread], &e);
        pm_photon_set(&j->out[i], p, e, n, ph->surf);
    }
}

static pt_status fg_run(const pm_job *j, const void *settings)
{
    const pm_fg_settings *s = settings;
    const scene *sc = j->sc;
    const accel *a = j->a;
    const pm_lights *L = j->L;
    pm_stats *st = j->st;
    double t1 = timer_now();
    int threads = pm_threads(s->c.threads);
    pt_status status = PT_OK;

    fg_ctx c = {.sc = sc, .a = a, .s = s, .L = L, .eps = pm_lights_eps(L), .rr = radrules_of(sc, 1),
                .eye_levels = radrules_level_limit(sc, 0)};
    c.gathers = pm_gathers(&c.rr);
    /* a gather ray is at level g1, its hit's specular rays at g1 + 1, ... */
    const int g1 = radrules_gather_level(1);
    c.gather_specular = radrules_level_limit(sc, g1) - g1 - 1;
    double scale = accel_scale(a);
    if (!(scale > 0.0) || !isfinite(scale)) scale = 1.0;
    c.r_global = s->radius_global > 0.0 ? s->radius_global : 0.1 * scale;
    c.r_caustic = s->radius_caustic > 0.0 ? s->radius_caustic : 0.02 * scale;
    c.k_global = s->k_global < 2 ? 2 : (s->k_global > KMAX ? KMAX : s->k_global);
    c.k_caustic = s->k_caustic < 2 ? 2 : (s->k_caustic > KMAX ? KMAX : s->k_caustic);
    int spp = s->c.spp > 0 ? s->c.spp : 1;
    c.fg_per_sample = (s->fg_rays + spp - 1) / spp;
    if (c.fg_per_sample < 1) c.fg_per_sample = 1;
    c.scratch = malloc(sizeof(pm_neighbour) * KMAX * (size_t)threads);
    if (!c.scratch) return PT_ERR_NOMEM;

    int caustics = s->caustics < 0 ? sc->global.photons.enabled : s->caustics != 0;
    st->caustic_reason = s->caustics < 0 ? (caustics ? "on: the scene has a photons{} block"
                                                     : "off: no photons{} block in the scene")
                                         : (caustics ? "on: requested" : "off: requested");

    /* 1. photons */
    pm_photon_settings ps = {s->photons, caustics, s->max_photon_bounces > 0 ? s->max_photon_bounces : 256, s->c.seed,
                             threads, s->c.cancel, s->c.progress};
    progress_stage(s->c.progress, "pmfg: photons", 0);
    pm_photon_result pr;
    status = pm_photons_trace(sc, a, L, &ps, &pr);
    double t2 = timer_now();
    st->t_photons = t2 - t1;
    if (status != PT_OK) {
        free(c.scratch);
        return status;
    }
    c.pcentre = pr.centre;
    c.pradius = pr.radius;
    st->photons_emitted = pr.emitted;
    st->photons_global = pr.nglobal;
    st->photons_caustic = pr.ncaustic;
    st->photon_rays = pr.rays;
    st->photons_dropped = pr.dropped;
    if (pr.dropped > 0) {
        src_loc nowhere = {0};
        diag_report(j->d, DIAG_WARNING, nowhere, NULL,
                    "pmfg: %ld photons not stored, the cap on stored photons (memory) was reached; indirect light is "
                    "too dark (fewer --photons or a lower albedo)", pr.dropped);
    }

    /* 2. maps */
    progress_stage(s->c.progress, "pmfg: photon maps", 0);
    c.global = pm_kdtree_build(pr.global, pr.nglobal, threads);
    c.caustic = pm_kdtree_build(pr.caustic, pr.ncaustic, threads);
    st->caustic_map = caustics && pr.ncaustic > 0;
    if (caustics && pr.ncaustic == 0) st->caustic_reason = "on, but no photon reached a diffuse surface through specular ones";
    double t3 = timer_now();
    if (!c.global || !c.caustic) status = PT_ERR_NOMEM;

    /* 3. precomputed irradiance */
    if (status == PT_OK && s->irradiance_stride > 0 && pr.nglobal > 0) {
        long stride = s->irradiance_stride;
        long n = (pr.nglobal + stride - 1) / stride;
        pm_photon *pts = malloc(sizeof(pm_photon) * (size_t)n);
        if (!pts) {
            status = PT_ERR_NOMEM;
        } else {
            long *vrays = calloc((size_t)threads, sizeof *vrays);
            irr_job j = {&c, pm_kdtree_photons(c.global), n, stride, pts, c.scratch, vrays};
            progress_stage(s->c.progress, "pmfg: irradiance", 0);
            if (vrays) pool_run_counted(threads, (int)((n + IRR_BLOCK - 1) / IRR_BLOCK), irr_block, &j, NULL, s->c.progress);
            else status = PT_ERR_NOMEM;
            for (int t = 0; vrays && t < threads; t++) st->shadow_rays += vrays[t]; /* visibility tests (vis_ok) */
            free(vrays);
            double t4 = timer_now();
            st->t_irradiance = t4 - t3;
            c.irr = pm_kdtree_build(pts, n, threads);
            if (!c.irr) status = PT_ERR_NOMEM;
            st->irradiance_points = n;
            st->t_maps += timer_now() - t4;
        }
    }
    st->t_maps += t3 - t2;

    /* 4. eye pass */
    double t5 = timer_now();
    if (status == PT_OK) status = pm_image_render(sc, &s->c, 1, j->fb, fg_sample, &c, st);
    double t6 = timer_now();
    st->t_render = t6 - t5;
    pm_kdtree_free(c.global);
    pm_kdtree_free(c.caustic);
    pm_kdtree_free(c.irr);
    free(c.scratch);
    return status;
}

pt_status pm_fg_render(const scene *sc, const accel *a, const pm_fg_settings *s, framebuffer *fb, pm_stats *st,
                       diag *d)
{
    return pm_lights_run(sc, a, fb, st, d, fg_run, s);
}
