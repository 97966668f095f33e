/* gi_particle_light.c - the particle GI mode's lighting stage: emission from
 * the lights (shadow rays on the host), scattering bounces (gi_particle.h). */
#include "gi_particle_internal.h"
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "camera.h"
#include "gi_cellvis.h"
#include "gi_cl.h"
#include "gi_cl_c.h"
#include "gi_links.h"
#include "gi_area_particles.h"
#include "gi_caustic.h"
#include "gi_radiance.h"
#include "gi_surface.h"
#include "pool.h"
#include "rng.h"
#include "timer.h"

void gi_light_pack(const scene_light *l, gi_dev_light *o)
{
    memset(o, 0, sizeof *o);
    v3_store_f(o->pos, l->position);
    o->kind = l->kind == LIGHT_SPOT ? GI_LIGHT_SPOT
              : l->kind == LIGHT_CYLINDER ? GI_LIGHT_CYLINDER
              : l->kind == LIGHT_PARALLEL ? GI_LIGHT_PARALLEL
                                          : GI_LIGHT_POINT;
    o->colour[0] = (float)l->colour.r;
    o->colour[1] = (float)l->colour.g;
    o->colour[2] = (float)l->colour.b;
    o->parallel = l->parallel;
    v3_store_f(o->point_at, l->point_at);
    o->tightness = (float)l->tightness;
    o->cos_radius = (float)cos(l->radius * M_PI / 180.0);
    o->cos_falloff = (float)cos(l->falloff * M_PI / 180.0);
    o->radius = (float)l->radius;
    o->falloff = (float)l->falloff;
    o->fade_distance = (float)l->fade_distance;
    o->fade_power = (float)l->fade_power;
    o->shadowless = l->shadowless;
}

typedef struct {
    gi_particle *gp;
    double eps;
    atomic_long rays;
} vis_job;

#define VIS_CHUNK 256

/* The shadow rays of one chunk and light, traced together
 * (accel_occluded_n: Embree packets of 16). */
typedef struct {
    vec3 *org, *dir;
    double *tmin, *tmax;
    int *owner; /* particle index within the chunk */
    unsigned char *hit;
    int n, cap;
} ray_batch;

static int batch_add(ray_batch *b, vec3 org, vec3 dir, double tmin, double tmax, int owner)
{
    if (b->n == b->cap) {
        int cap = b->cap ? 2 * b->cap : 1024;
        vec3 *o = realloc(b->org, (size_t)cap * sizeof *o);
        if (o) b->org = o;
        vec3 *d = realloc(b->dir, (size_t)cap * sizeof *d);
        if (d) b->dir = d;
        double *t0 = realloc(b->tmin, (size_t)cap * sizeof *t0);
        if (t0) b->tmin = t0;
        double *t1 = realloc(b->tmax, (size_t)cap * sizeof *t1);
        if (t1) b->tmax = t1;
        int *w = realloc(b->owner, (size_t)cap * sizeof *w);
        if (w) b->owner = w;
        unsigned char *h = realloc(b->hit, (size_t)cap);
        if (h) b->hit = h;
        if (!o || !d || !t0 || !t1 || !w || !h) return 0;
        b->cap = cap;
    }
    b->org[b->n] = org;
    b->dir[b->n] = dir;
    b->tmin[b->n] = tmin;
    b->tmax[b->n] = tmax;
    b->owner[b->n] = owner;
    b->n++;
    return 1;
}

static void batch_free(ray_batch *b)
{
    free(b->org);
    free(b->dir);
    free(b->tmin);
    free(b->tmax);
    free(b->owner);
    free(b->hit);
}

/* A shadow ray from p towards a light point at `depth` along dir: 1 (seen,
 * no ray needed: the point is within eps) or queued (0); its length is
 * gi_shadow_tmax's. */
static int shadow_ray(ray_batch *b, vec3 p, vec3 dir, double depth, double eps, int owner, const accel *a)
{
    double tmax = gi_shadow_tmax(depth, eps);
    if (tmax <= eps) return 1;
    if (!batch_add(b, p, dir, eps, tmax, owner)) return accel_occluded(a, p, dir, eps, tmax) ? 0 : 1;
    return 0;
}

static void vis_chunk(void *ctx, int chunk, int thread)
{
    (void)thread;
    vis_job *J = ctx;
    gi_particle *gp = J->gp;
    if (gp->cancel && *gp->cancel) return; /* superseded: the rest of the chunks are skipped */
    const scene *sc = gp->sc;
    int n = gp->ps.n, nl = gp->nlights;
    int i0 = chunk * VIS_CHUNK, i1 = i0 + VIS_CHUNK < n ? i0 + VIS_CHUNK : n;
    long rays = 0;
    float att[VIS_CHUNK], seen[VIS_CHUNK], tf[VIS_CHUNK][3];
    int m_of[VIS_CHUNK];
    ray_batch B = {0};
    for (int li = 0; li < nl; li++) {
        if (!gp->dirty[li]) continue;
        const scene_light *l = &sc->lights[li];
        const gi_dev_light *dl = &gp->lights[li];
        int last_patch = -1, reaches = 0;
        B.n = 0;
        for (int i = i0; i < i1; i++) {
            int o = i - i0;
            const gi_dev_particle *pt = &gp->ps.p[i];
            vec3 nrm = v3(pt->n[0], pt->n[1], pt->n[2]);
            vec3 org = v3_madd(v3(pt->p[0], pt->p[1], pt->p[2]), nrm, J->eps);
            float d[3];
            float depth = gi_light_ray(dl, dl->pos[0], dl->pos[1], dl->pos[2], pt->p[0], pt->p[1], pt->p[2], d);
            float ci = pt->n[0] * d[0] + pt->n[1] * d[1] + pt->n[2] * d[2];
            att[o] = ci >= 1e-10f ? gi_light_attenuation(dl, pt->p[0], pt->p[1], pt->p[2], d, depth) : 0.0f;
            seen[o] = 0.0f;
            m_of[o] = 1;
            if (!(att[o] > 0.0f)) continue;
            /* light_group: no light on objects the light does not reach (as
             * shade.c); a chunk's particles mostly share a few patches */
            if (gp->ps.patch[i] != last_patch) {
                last_patch = gp->ps.patch[i];
                reaches = scene_light_reaches(l, gi_surface_object(gp->surf, last_patch));
            }
            if (!reaches) {
                att[o] = 0.0f;
                continue;
            }
            if (l->shadowless) {
                seen[o] = 1.0f;
            } else if (l->area && l->size1 * l->size2 > 1) {
                vec3 ax1 = l->axis1, ax2 = l->axis2;
                if (l->orient) scene_light_orient_axes(l, v3(d[0], d[1], d[2]), &ax1, &ax2);
                rng r;
                rng_seed(&r, gp->set.seed ^ 0xa11ULL, (uint64_t)i * 131u + (uint64_t)li);
                int total = l->size1 * l->size2;
                int m = gp->set.area_samples > 0 && gp->set.area_samples < total ? gp->set.area_samples : total;
                /* a subset: every (total/m)-th grid point from a random start */
                double stride = (double)total / m, start = rng_f64(&r) * stride;
                for (int k = 0; k < m; k++) {
                    int g = m == total ? k : (int)(start + k * stride);
                    if (g >= total) g = total - 1;
                    int u = g % l->size1, vv = g / l->size1;
                    vec3 c = v3_add(l->position, scene_light_area_point(l, ax1, ax2, u, vv, &r));
                    float dd[3];
                    float dep = gi_light_ray(dl, (float)c.x, (float)c.y, (float)c.z, pt->p[0], pt->p[1], pt->p[2], dd);
                    seen[o] += (float)shadow_ray(&B, org, v3(dd[0], dd[1], dd[2]), dep, J->eps, o, gp->a);
                    rays++;
                }
                m_of[o] = m;
            } else {
                seen[o] = (float)shadow_ray(&B, org, v3(d[0], d[1], d[2]), depth, J->eps, o, gp->a);
                rays++;
            }
        }
        if (B.n > 0) accel_occluded_n(gp->a, B.n, B.org, B.dir, B.tmin, B.tmax, B.hit);
        for (int k = 0; k < B.n; k++)
            if (!B.hit[k]) seen[B.owner[k]] += 1.0f;
        /* POV-Ray's filtered shadows: a blocked ray walks the surfaces it
         * crosses and passes their filters (gi_shadow_fn); the light through
         * them joins the particle's direct light (particle_extra) */
        if (gp->visf) {
            memset(tf, 0, sizeof tf);
            const scene_light *pl = gp->set.photon_shadows ? l : NULL;
            for (int k = 0; k < B.n; k++) {
                if (!B.hit[k]) continue;
                rgb t = gp->set.shadow(sc, gp->a, B.org[k], B.dir[k], B.tmin[k], B.tmax[k], pl);
                if (!isfinite(t.r + t.g + t.b)) continue;
                tf[B.owner[k]][0] += (float)fmax(t.r, 0.0);
                tf[B.owner[k]][1] += (float)fmax(t.g, 0.0);
                tf[B.owner[k]][2] += (float)fmax(t.b, 0.0);
            }
            for (int i = i0; i < i1; i++) {
                int o = i - i0;
                float *v = &gp->visf[((size_t)i * nl + li) * 4];
                for (int c = 0; c < 3; c++) v[c] = att[o] > 0.0f ? att[o] * tf[o][c] / (float)m_of[o] : 0.0f;
                v[3] = 0.0f;
            }
        }
        /* gi_k_emit reads att * V, V the fraction of the light seen */
        for (int i = i0; i < i1; i++) {
            int o = i - i0;
            gp->vis[(size_t)i * nl + li] = att[o] > 0.0f ? att[o] * (seen[o] / (float)m_of[o]) : 0.0f;
        }
    }
    batch_free(&B);
    atomic_fetch_add(&J->rays, rays);
}

/* Whether two lights cast the same shadows on the particles (everything
 * but the colour: visibility also skips particles the attenuation zeroes). */
static int same_geometry(const scene_light *a, const scene_light *b)
{
    return a->kind == b->kind && v3_len2(v3_sub(a->position, b->position)) == 0.0 &&
           v3_len2(v3_sub(a->point_at, b->point_at)) == 0.0 && a->radius == b->radius && a->falloff == b->falloff &&
           a->tightness == b->tightness && a->parallel == b->parallel && a->area == b->area &&
           v3_len2(v3_sub(a->axis1, b->axis1)) == 0.0 && v3_len2(v3_sub(a->axis2, b->axis2)) == 0.0 &&
           a->size1 == b->size1 && a->size2 == b->size2 && a->jitter == b->jitter && a->circular == b->circular &&
           a->orient == b->orient && a->area_illumination == b->area_illumination &&
           a->fade_distance == b->fade_distance && a->fade_power == b->fade_power && a->shadowless == b->shadowless;
}

/* The caustic photons' E/pi at each particle (gi_caustic_world_at: the
 * photon volumes that hold its point, arriving on its side; its twin's
 * side is its twin's, gi_k_emit adds it through the back lobe), none on
 * objects with photons { collect off }.
 * The back lobe (diffuse_back) takes the twin's photons as the twin sees
 * them, each divided by its cosine; POV-Ray's radiosity rays see such a
 * photon divided by 0.1 instead (the caustic layer's rule, gi_caustic.cl
 * gi_caus_add), tenfold whatever its angle. back_over[i] is the photons
 * from behind particle i weighted so (gi_caustic_world_at with back 1,
 * less its front part), and particle_extra adds back x (that - the
 * twin's own sum) to particle i's extra: its back lobe then sends what
 * POV-Ray's would. */
typedef struct {
    gi_particle *gp;
    float *back_over; /* 3 floats per particle; NULL: no diffuse_back particle */
} caus_job;

#define CAUS_CHUNK 1024

static void caus_chunk(void *ctx, int ci, int thread)
{
    (void)thread;
    caus_job *J = ctx;
    gi_particle *gp = J->gp;
    int i0 = ci * CAUS_CHUNK, i1 = i0 + CAUS_CHUNK < gp->ps.n ? i0 + CAUS_CHUNK : gp->ps.n;
    for (int i = i0; i < i1; i++) {
        const gi_dev_particle *p = &gp->ps.p[i];
        const scene_object *o = gi_surface_object(gp->surf, gp->ps.patch[i]);
        rgb e = {0, 0, 0};
        int collects = o && !(o->photons && !o->photons->collect);
        vec3 pp = v3(p->p[0], p->p[1], p->p[2]), pn = v3(p->n[0], p->n[1], p->n[2]);
        if (collects) e = gi_caustic_world_at(gp->caus, pp, pn, p->brilliance, 0.0);
        if (J->back_over) {
            float *b = &J->back_over[3 * (size_t)i];
            b[0] = b[1] = b[2] = 0.0f;
            if (collects && p->back > 0.0f && p->twin >= 0) {
                rgb t = gi_caustic_world_at(gp->caus, pp, pn, p->brilliance, 1.0);
                double v[3] = {t.r - e.r, t.g - e.g, t.b - e.b};
                for (int c = 0; c < 3; c++) b[c] = isfinite(v[c]) && v[c] > 0.0 ? (float)v[c] : 0.0f;
            }
        }
        float *x = &gp->extra[4 * (size_t)i];
        x[0] = isfinite(e.r) && e.r > 0.0 ? (float)e.r : 0.0f;
        x[1] = isfinite(e.g) && e.g > 0.0 ? (float)e.g : 0.0f;
        x[2] = isfinite(e.b) && e.b > 0.0 ? (float)e.b : 0.0f;
        x[3] = 0.0f;
    }
}

/* The light through transparent surfaces (visf) at particle i, E/pi
 * added to e: each light's colour times the cosine term gi_k_emit's
 * gi_direct gives it (brilliance; none from behind). */
static void filtered_direct(const gi_particle *gp, int i, float e[3])
{
    const gi_dev_particle *pt = &gp->ps.p[i];
    for (int l = 0; l < gp->nlights; l++) {
        const float *v = &gp->visf[((size_t)i * gp->nlights + l) * 4];
        if (!(v[0] > 0.0f || v[1] > 0.0f || v[2] > 0.0f)) continue;
        const gi_dev_light *lt = &gp->lights[l];
        float d[3];
        gi_light_ray(lt, lt->pos[0], lt->pos[1], lt->pos[2], pt->p[0], pt->p[1], pt->p[2], d);
        float ci = pt->n[0] * d[0] + pt->n[1] * d[1] + pt->n[2] * d[2];
        if (ci < 1e-10f) continue;
        float in = pt->brilliance != 1.0f ? powf(ci, pt->brilliance) : ci;
        for (int c = 0; c < 3; c++) e[c] += lt->colour[c] * in * v[c];
    }
}

/* Fills gp->extra from the caustic layer and the light through transparent
 * surfaces; NULL when there is neither (or it reaches no particle).
 * *fcaus: the light the photons bring (grey). */
static const float *particle_extra(gi_particle *gp, double *fcaus, pt_status *st)
{
    *fcaus = 0.0;
    int n = gp->ps.n;
    if ((!gp->caus && !gp->visf) || n <= 0) return NULL;
    if (!gp->extra && !(gp->extra = gi_particle_calloc((size_t)n * 4, sizeof(float), st))) return NULL;
    if (gp->caus) {
        caus_job J = {gp, NULL};
        int backs = 0;
        for (int i = 0; i < n && !backs; i++) backs = gp->ps.p[i].back > 0.0f && gp->ps.p[i].twin >= 0;
        if (backs && !(J.back_over = gi_particle_calloc((size_t)n * 3, sizeof(float), st))) return NULL;
        pool_run(gp->threads, (n + CAUS_CHUNK - 1) / CAUS_CHUNK, caus_chunk, &J);
        if (J.back_over) {
            /* less what the twin's own sum brings through gi_k_emit's
             * back lobe (all twins' sums read before any is changed) */
            for (int i = 0; i < n; i++) {
                int t = gp->ps.p[i].twin;
                float *b = &J.back_over[3 * (size_t)i];
                for (int c = 0; c < 3; c++) b[c] = t >= 0 ? fmaxf(b[c] - gp->extra[4 * (size_t)t + c], 0.0f) : 0.0f;
            }
            for (int i = 0; i < n; i++)
                for (int c = 0; c < 3; c++) gp->extra[4 * (size_t)i + c] += gp->ps.p[i].back * J.back_over[3 * (size_t)i + c];
            free(J.back_over);
        }
    } else {
        memset(gp->extra, 0, (size_t)n * 4 * sizeof(float));
    }
    double f = 0.0;
    int any = 0;
    for (int i = 0; i < n; i++) {
        float *x = &gp->extra[4 * (size_t)i];
        f += M_PI * gp->ps.p[i].area * (x[0] + x[1] + x[2]) / 3.0;
        if (gp->visf) {
            float e[3] = {0.0f, 0.0f, 0.0f};
            filtered_direct(gp, i, e);
            for (int c = 0; c < 3; c++)
                if (isfinite(e[c]) && e[c] > 0.0f) x[c] += e[c];
        }
        any |= x[0] > 0.0f || x[1] > 0.0f || x[2] > 0.0f;
    }
    *fcaus = f;
    return any ? gp->extra : NULL;
}

static void reset_view(gi_particle *gp)
{
    /* no hook runs now (the stages are not run during a render): relaxed
     * stores, plain byte writes instead of a locked exchange each */
    size_t n = (size_t)gp->ps.n, nrp = (size_t)gp->lists.nrp;
    for (size_t i = 0; i < n; i++) atomic_store_explicit(&gp->e_state[i], 0, memory_order_relaxed);
    memset(gp->dev_gathered, 0, n);
    for (size_t l = 0; l < nrp; l++) atomic_store_explicit(&gp->rp_state[l], 0, memory_order_relaxed);
    atomic_thread_fence(memory_order_release);
}

pt_status gi_particle_light(gi_particle *gp, diag *d)
{
    double t0 = timer_now();
    const scene *sc = gp->sc;
    gi_particle_stats *S = &gp->st;
    int n = gp->ps.n;
    pt_status st = PT_OK;
    /* lights and visibility (host, Embree shadow rays); a light whose
     * geometry did not change since the last lighting stage (only its
     * colour, say) keeps its visibility */
    progress_stage(gp->set.progress, "gi lighting: visibility", 0);
    double tv = timer_now();
    int nl = sc->nlights;
    if (nl != gp->nlights) {
        free(gp->lights);
        free(gp->vis);
        free(gp->visf);
        gp->visf = NULL;
        free(gp->vis_lights);
        free(gp->dirty);
        gp->lights = gi_particle_calloc((size_t)nl, sizeof *gp->lights, &st);
        gp->vis = gi_particle_calloc((size_t)n * (size_t)(nl > 0 ? nl : 1), sizeof(float), &st);
        if (gp->set.shadow && nl > 0)
            gp->visf = gi_particle_calloc((size_t)n * (size_t)nl * 4, sizeof(float), &st);
        gp->vis_lights = gi_particle_calloc((size_t)nl, sizeof *gp->vis_lights, &st);
        gp->dirty = gi_particle_calloc((size_t)nl, 1, &st);
        if (st != PT_OK) {
            gp->nlights = 0;
            return st;
        }
        gp->nlights = nl;
        for (int l = 0; l < nl; l++) gp->dirty[l] = 1;
    }
    int ndirty = 0;
    for (int l = 0; l < nl; l++) {
        gi_light_pack(&sc->lights[l], &gp->lights[l]);
        if (!gp->dirty[l] && !same_geometry(&gp->vis_lights[l], &sc->lights[l])) gp->dirty[l] = 1;
        ndirty += gp->dirty[l];
    }
    vis_job J;
    J.gp = gp;
    J.eps = 1e-6 * (accel_eps_scale(gp->a) > 0.0 ? accel_eps_scale(gp->a) : 1.0);
    atomic_init(&J.rays, 0);
    if (ndirty > 0 && n > 0)
        pool_run_counted(gp->threads, (n + VIS_CHUNK - 1) / VIS_CHUNK, vis_chunk, &J, NULL, gp->set.progress);
    if (gp->cancel && *gp->cancel) {
        /* cancelled during (or before) the visibility pass: nothing the
         * indirect hook reads has changed yet (edir, src, lout, phi, the
         * view's gathered values), so the previous lighting stays in place;
         * the lights stay dirty and the next call traces them again */
        S->t_visibility = timer_now() - tv;
        return PT_OK;
    }
    for (int l = 0; l < nl; l++) {
        gp->vis_lights[l] = sc->lights[l];
        gp->dirty[l] = 0;
    }
    S->shadow_rays = atomic_load(&J.rays);
    S->t_visibility = timer_now() - tv;

    /* emission, scattering and radiance on the device (gi_lighting.cl):
     * cancellable before each kernel, and then nothing the view reads has
     * changed (gi_dev_lighting writes edir, lout, phi only at its end) */
    int nb = gp->set.bounces, full = gp->set.scatter == GI_PARTICLE_SCATTER_FULL;
    if (!full && nb - 1 > gp->nwalk) {
        st = gi_particle_build_walk(gp, nb - 1, d);
        if (st != PT_OK) return st;
    }
    double kt[2] = {0.0, 0.0};
    int done = 0;
    /* stats sums (direct, emitted and scattered flux, grey; the particles
     * that send light in the first bounce) come from the kernels' partial
     * sums: no pass over the particles here. The device keeps edir and phi
     * until gi_particle_debug asks (gi_dev_fetch). */
    gi_dev_sums sums;
    double fcaus = 0.0;
    const float *extra = particle_extra(gp, &fcaus, &st);
    if (st != PT_OK) return st;
    progress_stage(gp->set.progress, "gi lighting: emit and scatter", 0);
    st = gi_dev_lighting(gp->dev, gp->lights, gp->nlights, gp->vis, ndirty > 0, extra,
                         full ? GI_SCATTER_FULL : GI_SCATTER_WALK, nb, gp->cancel, gp->edir, gp->lout, gp->phi,
                         gp->bounce_flux, &sums, &done, kt, d);
    if (st != PT_OK) return st;
    if (!done) return PT_OK; /* cancelled: the previous lighting stays */
    S->t_emit = kt[0];
    S->t_scatter = kt[1];
    gp->nbounce_flux = nb;
    S->sources = sums.sources;
    S->flux_direct = sums.direct;
    S->flux_caustic = fcaus;
    S->flux_emitted = sums.emitted;
    S->flux_scattered = sums.scattered;
    reset_view(gp);
    gp->lit = 1;
    /* the final gather's values for this light: its rays took the direct
     * light where no particle answers (and everywhere when no bounce
     * follows), so with lights they are traced again */
    if ((gp->vgs[0].n > 0 || gp->vgs[1].n > 0) && gp->nlights > 0) {
        st = gi_particle_view_gather(gp, d);
        if (st != PT_OK) return st;
    } else {
        gi_particle_view_regather(gp);
    }
    S->t_lighting = timer_now() - t0;
    return PT_OK;
}

pt_status gi_particle_relight(gi_particle *gp, diag *d) { return gi_particle_light(gp, d); }

void gi_particle_set_cancel(gi_particle *gp, volatile int *cancel) { gp->cancel = cancel; }

void gi_particle_set_progress(gi_particle *gp, progress *p) { gp->set.progress = p; }

gi_hit_light gi_particle_hit_light(const gi_particle *gp)
{
    return (gi_hit_light){gp->caus, gp->set.shadow, gp->set.photon_shadows};
}

void gi_particle_set_caustic(gi_particle *gp, const gi_caustic *layer)
{
    gp->caus = layer;
    /* the view's gatherers (hits no gathered point answers) see it too */
    gi_hit_light hl = gi_particle_hit_light(gp);
    for (int v = 0; v < 2; v++) gi_gatherer_set_light(gp->vgs[v].gatherer, &hl);
}

void gi_particle_set_scattering(gi_particle *gp, int bounces, int scatter)
{
    gp->set.bounces = bounces < 0 ? 0 : (bounces > GI_MAX_BOUNCES ? GI_MAX_BOUNCES : bounces);
    gp->set.scatter = scatter;
    gp->st.bounces = gp->set.bounces;
}

