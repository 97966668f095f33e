/* pm_nee.c - next-event estimation for the reference renderers (see pm_nee.h).
 *
 * Emitter sampling: a point y with density p_A (per unit area, from
 * accel_surface) seen from x along wi at distance d has the solid-angle
 * density p_l = p_A d^2 / |cos theta_y| (emission is two-sided). The
 * estimator of  int f(wi) Le(y) |cos theta_x| dwi  is
 *     f(wi) Le |cos theta_x| V(x, y) / p_l,
 * weighted by the power heuristic (Veach & Guibas 1995, eq. for beta = 2)
 * against the BSDF strategy. */
#include "pm_nee.h"
#include "shade_texture.h"
#include "shade_atmos.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "radrules.h"
#include "scene_leaves.h"
#include "shade_light.h"
#include "timer.h"

struct pm_lights {
    const scene *sc;
    const accel *a;
    double eps;
    int transparent; /* filtered shadows (shade_light_ctx) */
    accel_surf *emit;
    rgb *le;          /* emission per piece (its fallback colour when it varies) */
    unsigned char *varies; /* the piece's colour varies: evaluate Le at the sampled point */
};

static double emit_weight(void *ctx, const scene_object *leaf, const scene_texture *tex, unsigned flags)
{
    (void)leaf;
    /* emissive surfaces light others only through gathering rays, which
     * no_radiosity objects do not meet (core/radrules.h rule 3) */
    if (!radrules_gathers(flags)) return 0.0;
    const scene *sc = ctx;
    rgb e = shade_mat_texture_emission(sc, tex);
    double w = fmax(fabs(e.r), fmax(fabs(e.g), fabs(e.b)));
    if (shade_mat_texture_varies(tex)) {
        /* the fallback colour says little: weigh by the finish alone */
        const radrules rr = radrules_of(sc, 1);
        rgb f = radrules_emission(&rr, sc, &tex->finish);
        w = fmax(w, fmax(fabs(f.r), fmax(fabs(f.g), fabs(f.b))));
    }
    return w;
}

static int is_target(const scene_object *o) { return o->photons && o->photons->target; }

int pm_any_target(const scene *sc)
{
    for (int i = 0; i < sc->nobjects; i++)
        if (scene_object_any(sc->objects[i], is_target)) return 1;
    return 0;
}

pm_lights *pm_lights_new(const scene *sc, const accel *a, diag *d, pt_status *st)
{
    *st = PT_OK;
    pm_lights *L = calloc(1, sizeof *L);
    if (!L) {
        *st = PT_ERR_NOMEM;
        return NULL;
    }
    L->sc = sc;
    L->a = a;
    L->eps = accel_surface_eps(a); /* median object size: a far object does not grow it */
    /* filtered shadows, but full ones in a scene with photons{} and no
     * target, where every specular surface makes caustics (pm_photon.c) */
    L->transparent = shade_tex_scene_transparent(sc) && !(sc->global.photons.enabled && !pm_any_target(sc));
    L->emit = accel_surf_build(sc, a, emit_weight, (void *)sc, d, st);
    if (!L->emit) {
        free(L);
        return NULL;
    }
    int n = accel_surf_count(L->emit);
    L->le = malloc(sizeof(rgb) * (size_t)(n > 0 ? n : 1));
    L->varies = calloc((size_t)(n > 0 ? n : 1), 1);
    if (!L->le || !L->varies) {
        pm_lights_free(L);
        *st = PT_ERR_NOMEM;
        return NULL;
    }
    for (int i = 0; i < n; i++) {
        const scene_texture *t = accel_surf_piece_at(L->emit, i)->texture;
        L->le[i] = shade_mat_texture_emission(sc, t);
        L->varies[i] = (unsigned char)shade_mat_texture_varies(t);
    }
    return L;
}

pt_status pm_lights_run(const scene *sc, const accel *a, framebuffer *fb, pm_stats *st, diag *d, pm_run_fn run,
                        const void *settings)
{
    double t0 = timer_now();
    pm_stats local;
    if (!st) st = &local;
    memset(st, 0, sizeof *st);
    if (!sc || !a || !fb || !settings) return PT_ERR_INTERNAL;
    pt_status status;
    pm_lights *L = pm_lights_new(sc, a, d, &status);
    if (!L) return status;
    st->emitter_pieces = accel_surf_count(L->emit);
    st->t_lights = timer_now() - t0;
    pm_job j = {sc, a, fb, d, L, st};
    status = run(&j, settings);
    st->t_total = timer_now() - t0;
    pm_lights_free(L);
    return status;
}

void pm_lights_free(pm_lights *L)
{
    if (!L) return;
    accel_surf_free(L->emit);
    free(L->le);
    free(L->varies);
    free(L);
}

const accel_surf *pm_lights_emitters(const pm_lights *L) { return L->emit; }
rgb pm_lights_piece_emission(const pm_lights *L, const accel_surf_sample *s)
{
    if (!L->varies[s->piece]) return L->le[s->piece];
    accel_hit eh;
    memset(&eh, 0, sizeof eh);
    eh.p = s->p;
    eh.ng = eh.ns = s->n;
    eh.obj = s->obj;
    eh.texture = s->texture;
    eh.prim = s->prim;
    eh.flags = s->flags;
    return shade_mat_emission_at(L->sc, s->texture, &eh);
}
double pm_lights_eps(const pm_lights *L) { return L->eps; }

int pm_sky_any(const scene *sc)
{
    const colour5 *bg = &sc->background;
    return bg->r != 0.0 || bg->g != 0.0 || bg->b != 0.0 || (sc->sky_sphere && sc->sky_sphere->npigments > 0);
}

rgb pm_sky(const scene *sc, vec3 dir)
{
    double l = v3_len(dir);
    rgb c = shade_atmos_sky(sc, l > 0.0 ? v3_scale(dir, 1.0 / l) : v3(0, 0, 1));
    if (!(isfinite(c.r) && isfinite(c.g) && isfinite(c.b))) c.r = c.g = c.b = 0.0;
    return c;
}

rgb pm_direct_lights(const pm_lights *L, const shade_mat_bsdf *b, int area_samples, rng *r, long *shadow_rays)
{
    rgb total = {0, 0, 0};
    if (!b->nee) return total;
    shade_light_ctx c = {L->a, L->eps, shadow_rays, NULL, L->sc, L->transparent, L->sc->global.photons.enabled};
    for (int i = 0; i < L->sc->nlights; i++) {
        if (!scene_light_reaches(&L->sc->lights[i], b->obj)) continue; /* light_group, as shade.c */
        rgb v = shade_mat_light_nee(b, &c, &L->sc->lights[i], area_samples, r);
        total.r += v.r;
        total.g += v.g;
        total.b += v.b;
    }
    return total;
}

rgb pm_direct_one_light(const pm_lights *L, const shade_mat_bsdf *b, rng *r, long *shadow_rays)
{
    rgb zero = {0, 0, 0};
    int n = L->sc->nlights;
    if (!b->nee || n == 0) return zero;
    if (n == 1) return pm_direct_lights(L, b, 1, r, shadow_rays);
    double wsum = 0.0, wstack[64];
    double *w = n <= 64 ? wstack : malloc(sizeof(double) * (size_t)n);
    if (!w) return pm_direct_lights(L, b, 1, r, shadow_rays);
    for (int i = 0; i < n; i++) {
        const scene_light *l = &L->sc->lights[i];
        vec3 dir;
        double depth;
        shade_light_ray(l, l->position, b->p_out, &dir, &depth);
        double att = l->area && l->area_illumination ? 1.0 : shade_light_attenuation(l, b->p_out, dir, depth);
        double c = fmax(fabs(l->colour.r), fmax(fabs(l->colour.g), fabs(l->colour.b)));
        w[i] = isfinite(att * c) && att * c > 0.0 ? att * c : 0.0;
        if (!scene_light_reaches(l, b->obj)) w[i] = 0.0; /* light_group: never picked */
        wsum += w[i];
    }
    rgb out = zero;
    if (wsum > 0.0) {
        double u = rng_f64(r) * wsum, acc = 0.0;
        int pick = n - 1;
        for (int i = 0; i < n; i++) {
            acc += w[i];
            if (u < acc && w[i] > 0.0) { pick = i; break; }
        }
        while (pick > 0 && w[pick] <= 0.0) pick--;
        double p = w[pick] / wsum;
        shade_light_ctx c = {L->a, L->eps, shadow_rays, NULL, L->sc, L->transparent, L->sc->global.photons.enabled};
        rgb v = shade_mat_light_nee(b, &c, &L->sc->lights[pick], 1, r);
        out.r = v.r / p;
        out.g = v.g / p;
        out.b = v.b / p;
    }
    if (w != wstack) free(w);
    return out;
}

/* Visibility of y from o: nothing in between (emitters are found by BSDF
 * rays with accel_intersect, so no_shadow objects block here too), except
 * no_radiosity objects, which gathering rays pass (radrules.h rule 3). */
static int visible(const pm_lights *L, const accel_from *from, vec3 o, vec3 y, vec3 *dir, double *dist)
{
    vec3 d = v3_sub(y, o);
    double len = v3_len(d);
    if (!(len > 0.0)) return 0;
    *dir = v3_scale(d, 1.0 / len);
    *dist = len;
    double tmax = len - fmax(L->eps, len * 1e-5);
    if (tmax <= L->eps) return 1;
    accel_hit h;
    double tmin = L->eps;
    for (int k = 0; k < 64; k++) {
        if (!accel_intersect_from(L->a, k == 0 ? from : NULL, o, *dir, tmin, tmax, &h)) return 1;
        if (radrules_gathers(h.flags)) return 0;
        tmin = h.t + fmax(L->eps, h.t * 1e-7);
        if (tmin >= tmax) return 1;
    }
    return 0;
}

rgb pm_direct_emitters(const pm_lights *L, const shade_mat_bsdf *b, int n_light, double bsdf_front, double bsdf_back,
                       double bsdf_glossy, rng *r, long *shadow_rays)
{
    rgb total = {0, 0, 0};
    if (n_light < 1 || accel_surf_count(L->emit) == 0) return total;
    if (b->m[SHADE_MAT_LOBE_DIFFUSE] <= 0.0 && b->m[SHADE_MAT_LOBE_BACK] <= 0.0 && b->m[SHADE_MAT_LOBE_GLOSSY] <= 0.0)
        return total;
    int g = (int)floor(sqrt((double)n_light));
    for (int k = 0; k < n_light; k++) {
        double u1, u2;
        if (k < g * g) {
            u1 = ((k % g) + rng_f64(r)) / g;
            u2 = ((k / g) + rng_f64(r)) / g;
        } else {
            u1 = rng_f64(r);
            u2 = rng_f64(r);
        }
        accel_surf_sample s;
        if (!accel_surf_sample_point(L->emit, rng_f64(r), u1, u2, r, &s)) break;
        /* which side of the surface the light arrives on decides the origin */
        int front = v3_dot(v3_sub(s.p, b->p), b->ng) > 0.0;
        vec3 o = front ? b->p_out : b->p_in;
        vec3 wi;
        double dist;
        vec3 d0 = v3_sub(s.p, o);
        double l0 = v3_len(d0);
        if (!(l0 > 0.0)) continue;
        wi = v3_scale(d0, 1.0 / l0);
        rgb f = shade_mat_eval(b, wi), fg = shade_mat_eval_glossy(b, wi);
        if (f.r == 0.0 && f.g == 0.0 && f.b == 0.0 && fg.r == 0.0 && fg.g == 0.0 && fg.b == 0.0) continue;
        double cos_y = fabs(v3_dot(s.n, wi));
        if (!(cos_y > 1e-12)) continue;
        if (shadow_rays) (*shadow_rays)++;
        if (!visible(L, &b->from, o, s.p, &wi, &dist)) continue;
        double p_l = s.pdf_area * dist * dist / cos_y;
        double cos_x = fabs(v3_dot(b->n, wi));
        double c_b = (v3_dot(b->n, wi) > 0.0 ? bsdf_front : bsdf_back) * cos_x / M_PI;
        double w = pm_mis(n_light * p_l, c_b);
        double wg = fg.r != 0.0 || fg.g != 0.0 || fg.b != 0.0
                        ? pm_mis(n_light * p_l, bsdf_glossy > 0.0 ? bsdf_glossy * shade_mat_pdf_glossy(b, wi) : 0.0)
                        : 0.0;
        rgb le = pm_lights_piece_emission(L, &s);
        double k_ = cos_x / p_l;
        total.r += (f.r * w + fg.r * wg) * le.r * k_;
        total.g += (f.g * w + fg.g * wg) * le.g * k_;
        total.b += (f.b * w + fg.b * wg) * le.b * k_;
    }
    total.r /= n_light;
    total.g /= n_light;
    total.b /= n_light;
    return total;
}

double pm_emitter_density(const pm_lights *L, const accel_hit *h, vec3 from, int n_light)
{
    if (n_light < 1) return 0.0;
    double pa = accel_surf_pdf(L->emit, h);
    if (!(pa > 0.0)) return 0.0;
    vec3 d = v3_sub(h->p, from);
    double d2 = v3_len2(d);
    double cos_y = fabs(v3_dot(h->ng, d)) / sqrt(d2);
    if (!(cos_y > 1e-12)) return INFINITY;
    return n_light * pa * d2 / cos_y;
}
