/* pm_path.c - the path tracer (see pm_path.h).
 *
 * Estimator per pixel sample (Veach 1997, ch. 9-10): along the path x0, x1, ...
 * with throughput T_k = prod f cos / pdf over the sampled directions,
 *   L = sum_k T_k [ w_bsdf(x_k) Le(x_k) + NEE_lights(x_k) + NEE_emitters(x_k) ]
 * where Le at x_k counts fully after a camera or specular step and with the
 * power-heuristic weight against emitter sampling after a Lambertian or
 * glossy step (one lobe is sampled per vertex, so the weights are per lobe);
 * NEE_emitters carries the complementary weight. A glossy step is a
 * gathering step, like a Lambertian one (brightness, recursion_limit). At the last vertex allowed
 * (max_depth) the emitter NEE is unweighted, since no BSDF step follows.
 * Russian roulette from vertex rr_depth on survives with q = min(1, max(T) / t)
 * (t = rr_threshold) and divides T by q (unbiased for any q > 0). */
#include "pm_path.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "pm_nee.h"
#include "radrules.h"
#include "shade_atmos.h"
#include "shade_material.h"
#include "shade_texture.h"
#include "timer.h"

#define HARD_DEPTH 1024

void pm_path_default_settings(pm_path_settings *s)
{
    *s = (pm_path_settings){.rr_depth = 3, .rr_threshold = 0.1, .area_samples = 1};
    pm_common_defaults(&s->c);
    s->c.spp = 64;
}

typedef struct {
    const scene *sc;
    const accel *a;
    const pm_path_settings *s;
    const pm_lights *L;
    double eps;
    int max_depth;
    radrules rr;
    int gathers;       /* diffuse bounces a path may take (the radiosity recursion_limit) */
} path_ctx;

static inline double tmax3(rgb t) { return fmax(t.r, fmax(t.g, t.b)); }

static rgb path_sample(void *ctx, double px, double py, int thread, rng *r, pm_counts *cnt)
{
    (void)thread;
    const path_ctx *c = ctx;
    const scene *sc = c->sc;
    const double bright = c->rr.brightness;
    vec3 org, dir;
    scene_camera_ray(&sc->camera, px, py, c->s->c.width, c->s->c.height, &org, &dir);
    cnt->camera++;
    rgb L = {0, 0, 0}, T = {1, 1, 1};
    unsigned skip = OBJ_NO_IMAGE;
    unsigned gskip = 0; /* OBJ_NO_RADIOSITY once the path has gathered (radrules rule 3) */
    int nd = 0;         /* diffuse bounces so far */
    int prev_spec = 1;
    double prev_cb = 0.0;
    vec3 prev_org = org;
    accel_from from; /* the surface the ray leaves (contacts, accel_intersect_from) */
    const accel_from *fromp = NULL;
    int level = 0, max_level = radrules_level_limit(sc, 0); /* POV-Ray's trace levels (radrules.h rule 7) */
    for (int depth = 0;; depth++) {
        if (level >= max_level) break;
        accel_hit h;
        int hit = accel_intersect_past(c->a, fromp, org, dir, c->eps, skip | gskip, &h, NULL) > 0;
        if (sc->fogs && (nd == 0 || c->rr.media)) {
            /* fog on the segment: on camera and specular rays, on gathering
             * rays only with radiosity's `media on` (radrules.h rule 5) */
            rgb fa, fc;
            shade_atmos_fog_affine(sc, org, dir, hit ? h.t : INFINITY, &fa, &fc);
            L.r += T.r * fc.r;
            L.g += T.g * fc.g;
            L.b += T.b * fc.b;
            T.r *= fa.r;
            T.g *= fa.g;
            T.b *= fa.b;
        }
        if (!hit) {
            rgb sky = pm_sky(sc, dir); /* background and sky_sphere */
            L.r += T.r * sky.r;
            L.g += T.g * sky.g;
            L.b += T.b * sky.b;
            break;
        }
        /* a segment inside an object fades where it leaves it (the Whitted
         * pass's rule): all the hit returns came through that interior */
        rgb fa = shade_tex_leaving_fade(&h, dir, 0);
        T.r *= fa.r;
        T.g *= fa.g;
        T.b *= fa.b;
        shade_mat_bsdf b;
        shade_mat_setup(&b, sc, &h, dir, c->eps, accel_eps_scale(c->a), r);
        b.gathered = nd > 0;
        if (b.unsupported) cnt->unsupported++;
        rgb le = b.emission;
        if (le.r != 0.0 || le.g != 0.0 || le.b != 0.0) {
            double w = 1.0;
            if (!prev_spec) w = pm_mis(prev_cb, pm_emitter_density(c->L, &h, prev_org, 1));
            L.r += T.r * le.r * w;
            L.g += T.g * le.g * w;
            L.b += T.b * le.b * w;
        }
        int last = depth + 1 >= c->max_depth;
        int gather = nd < c->gathers; /* this vertex may gather (diffuse lobes continue) */
        if (b.nee) {
            rgb d = pm_direct_lights(c->L, &b, c->s->area_samples, r, &cnt->shadow);
            L.r += T.r * d.r;
            L.g += T.g * d.g;
            L.b += T.b * d.b;
        }
        if (gather && (b.m[SHADE_MAT_LOBE_DIFFUSE] > 0.0 || b.m[SHADE_MAT_LOBE_BACK] > 0.0 || b.m[SHADE_MAT_LOBE_GLOSSY] > 0.0) &&
            b.msum > 0.0) {
            /* emissive surfaces light others as gathered light: brightness applies */
            double bf = last ? 0.0 : b.m[SHADE_MAT_LOBE_DIFFUSE] / b.msum, bb = last ? 0.0 : b.m[SHADE_MAT_LOBE_BACK] / b.msum;
            double bg = last ? 0.0 : b.m[SHADE_MAT_LOBE_GLOSSY] / b.msum;
            rgb d = pm_direct_emitters(c->L, &b, 1, bf, bb, bg, r, &cnt->shadow);
            L.r += T.r * d.r * bright;
            L.g += T.g * d.g * bright;
            L.b += T.b * d.b * bright;
        }
        if (last) break;
        shade_mat_scatter s;
        if (!shade_mat_sample(&b, r, 0, &s)) break;
        if (!s.specular) {
            if (!gather) break; /* past recursion_limit: only the specular lobes go on */
            T.r *= bright;
            T.g *= bright;
            T.b *= bright;
            nd++;
            gskip = OBJ_NO_RADIOSITY;
            level = radrules_gather_level(nd);
            max_level = radrules_level_limit(sc, level);
        } else {
            level++;
        }
        T.r *= s.weight.r;
        T.g *= s.weight.g;
        T.b *= s.weight.b;
        if (depth + 1 >= c->s->rr_depth) {
            double thr = c->s->rr_threshold > 0.0 ? c->s->rr_threshold : 1.0;
            double q = fmin(1.0, tmax3(T) / thr);
            if (!(q > 0.0)) break;
            if (q < 1.0) {
                if (rng_f64(r) >= q) break;
                T.r /= q;
                T.g /= q;
                T.b /= q;
            }
        }
        if (s.specular) {
            prev_spec = 1;
            if (s.lobe == SHADE_MAT_LOBE_REFLECT) skip = OBJ_NO_REFLECTION;
        } else {
            prev_spec = 0;
            prev_cb = s.pdf;
            skip = 0;
        }
        org = s.org;
        dir = s.dir;
        prev_org = s.org;
        from = b.from;
        fromp = &from;
        cnt->bsdf++;
    }
    return L;
}

static pt_status path_run(const pm_job *j, const void *settings)
{
    const pm_path_settings *s = settings;
    double t1 = timer_now();
    path_ctx c = {j->sc, j->a, s, j->L, pm_lights_eps(j->L), s->max_depth > 0 ? s->max_depth : HARD_DEPTH,
                  radrules_of(j->sc, 1), 0};
    c.gathers = pm_gathers(&c.rr);
    if (c.max_depth > HARD_DEPTH) c.max_depth = HARD_DEPTH;
    pt_status status = pm_image_render(j->sc, &s->c, 16, j->fb, path_sample, &c, j->st);
    j->st->t_render = timer_now() - t1;
    return status;
}

pt_status pm_path_render(const scene *sc, const accel *a, const pm_path_settings *s, framebuffer *fb, pm_stats *st,
                         diag *d)
{
    return pm_lights_run(sc, a, fb, st, d, path_run, s);
}
