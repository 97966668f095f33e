/* render_vpl.c - `--gi vpl` (see render_vpl.h).
 *
 * Light model: the path tracer's (reference/README.md), so the two
 * converge where the method's approximations hold.
 *  - Eye samples (spp per pixel): emission, direct light of POV-Ray lights
 *    (pm_direct_lights: --gi none's terms, highlights included) and of
 *    emitters (an area sample and a BSDF sample with MIS, as the path
 *    tracer; gathered light: brightness), mirror and refraction lobes
 *    followed Whitted-style within POV-Ray's trace levels.
 *  - VPLs: `vpls` points uniform by area over the surfaces gathering rays
 *    see (accel_surface.h; infinite planes within the scene's finite bounds
 *    grown to what a 32 x 32 grid of camera rays hits within twice their
 *    diagonal), each on the side
 *    that receives more light, with
 *    the Lambertian radiance of its direct light as seen by a gathering ray
 *    (POV-Ray's rules: no highlights, area lights as points; emitters
 *    through the Lambertian lobes). Direct light reflected by a VPL's glossy
 *    lobe is left out, as the path tracer leaves it out at gathered hits.
 *  - Bounces (paper, multi-bounce): each VPL gathers from the filtered tree
 *    (kernel bounce mode); its Lambertian lobe turns the irradiance into
 *    l_d = kd/pi E, its glossy lobe the incoming energy into a lobe l_s =
 *    kg sum L dw about the merged mirror directions (eq. 4) with its own
 *    exponent; each bounce is scaled by brightness, and at most
 *    recursion_limit - 1 are taken (the eye gather is one more).
 *  - Indirect light at a pixel's first hit: the kernel's eq. 2 at the
 *    pixel-centre hit with the hit's Lambertian and glossy lobes, on the
 *    pixels the adaptive scheme samples (paper, section 4.4: 16x16 grid,
 *    then 8, 4, 2, 1 with the coherence error over the parents), the others
 *    reconstructed by bilateral upsampling from their 2 or 4 parents;
 *    at mirror and refraction hits gathered at every hit.
 *  - Fog on camera and mirror/refraction segments (the pixel-centre ray's
 *    transmittance scales the pixel's indirect light), as the path tracer.
 *  - The sky: at eye hits by the same BSDF sample of the Lambertian and
 *    glossy lobes (counted when it escapes), at VPLs by SKY_RAYS cosine
 *    rays through their Lambertian lobe, which also find emitters (MIS with
 *    4 area samples).
 * Not modelled: visibility between gather points and VPLs (the paper's
 * limitation), caustics, glossy reflection of direct light and of the sky
 * at VPLs. */
#include "render_vpl.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "accel_surface.h"
#include "gi_cl.h"
#include "gi_vpl.h"
#include "mirror.h"
#include "glossy.h"
#include "pm_nee.h"
#include "pool.h"
#include "radrules.h"
#include "rng.h"
#include "shade_atmos.h"
#include "shade_light.h"
#include "shade_material.h"
#include "timer.h"

#define EYE_RR 1e-3
#define COARSE 16
#define VIEW_GRID 32 /* camera rays per image side that bound the planes' VPLs */
#define SKY_RAYS 16 /* gathering rays per VPL side for the sky and emitters */

void render_vpl_default_settings(render_vpl_settings *s)
{
    *s = (render_vpl_settings){.spp = 16, .vpls = 16384, .bounces = 1, .threshold = 0.02, .cut = RENDER_VPL_MINMAX,
                               .min_cut = 40.0, .max_cut = 9.0, .adaptive = 1, .epsilon = 0.3, .lambda = 16.0};
}

static inline double lum(rgb c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }
static inline rgb mk(double r, double g, double b) { rgb c = {r, g, b}; return c; }

/* A gather point with what the host keeps beside the device record. */
typedef struct {
    gi_dev_vpl_point dev;
    const glossy_table *gt[2];
    rgb w;      /* weight of its result in the pixel (secondary points) */
    int pixel;
} gpoint;

typedef struct {
    gpoint *v;
    int n, cap;
} gvec;

static int gvec_push(gvec *g, const gpoint *p)
{
    if (g->n == g->cap) {
        int nc = g->cap ? 2 * g->cap : 64;
        gpoint *nv = realloc(g->v, sizeof *nv * (size_t)nc);
        if (!nv) return 0;
        g->v = nv;
        g->cap = nc;
    }
    g->v[g->n++] = *p;
    return 1;
}

/* The gather point of a surface hit seen along b->dir: its Lambertian lobe on
 * the viewer's side and its glossy sub-lobes (metallic tint at cos(n, wo)). */
static void point_of(const shade_mat_bsdf *b, double lift, gpoint *g)
{
    memset(g, 0, sizeof *g);
    vec3 p = v3_madd(b->p, b->ng, lift), wo = v3_neg(b->dir);
    float *dst[3] = {g->dev.p, g->dev.n, g->dev.wo};
    vec3 src[3] = {p, b->n, wo};
    for (int k = 0; k < 3; k++) {
        v3_store_f(dst[k], src[k]);
    }
    rgb kd = b->k[SHADE_MAT_LOBE_DIFFUSE];
    g->dev.kd[0] = (float)kd.r;
    g->dev.kd[1] = (float)kd.g;
    g->dev.kd[2] = (float)kd.b;
    g->dev.tab[0] = g->dev.tab[1] = -1;
    for (int j = 0; j < b->nglossy && j < 2; j++) { /* the two first (blurred mirror, phong) */
        rgb c = mk(b->gl_w[j] * b->gl_c[j].r, b->gl_w[j] * b->gl_c[j].g, b->gl_w[j] * b->gl_c[j].b);
        if (b->gl_tint[j] && b->gl_metallic != 0.0)
            mirror_metallic_tint(&c, b->gl_metallic, b->pigment, v3_dot(wo, b->n));
        g->dev.kg[j][0] = (float)c.r;
        g->dev.kg[j][1] = (float)c.g;
        g->dev.kg[j][2] = (float)c.b;
        g->dev.kg[j][3] = (float)glossy_exponent(b->gl[j]);
        g->gt[j] = b->gl[j];
        g->dev.tab[j] = 0; /* set by tables_assign */
    }
}

/* The E(mu) tables the points use, as the kernel reads them. */
typedef struct {
    const glossy_table **t;
    int n, cap;
    float *vals;
} tables;

static int table_id(tables *ts, const glossy_table *t)
{
    for (int i = 0; i < ts->n; i++)
        if (ts->t[i] == t) return i;
    if (ts->n == ts->cap) {
        int nc = ts->cap ? 2 * ts->cap : 8;
        const glossy_table **nt = realloc(ts->t, sizeof *nt * (size_t)nc);
        float *nv = realloc(ts->vals, sizeof *nv * (size_t)nc * GI_VPL_TAB);
        if (nt) ts->t = nt;
        if (nv) ts->vals = nv;
        if (!nt || !nv) return -1;
        ts->cap = nc;
    }
    const double *v = glossy_table_values(t);
    for (int k = 0; k < GI_VPL_TAB - 1; k++) ts->vals[ts->n * GI_VPL_TAB + k] = (float)v[k];
    ts->vals[ts->n * GI_VPL_TAB + GI_VPL_TAB - 1] = (float)glossy_table_eavg(t);
    ts->t[ts->n] = t;
    return ts->n++;
}

static void tables_assign(tables *ts, gpoint *g, int n)
{
    for (int i = 0; i < n; i++)
        for (int j = 0; j < 2; j++)
            if (g[i].gt[j]) {
                int id = table_id(ts, g[i].gt[j]);
                g[i].dev.tab[j] = id;
                if (id < 0) g[i].dev.kg[j][0] = g[i].dev.kg[j][1] = g[i].dev.kg[j][2] = 0.0f, g[i].dev.tab[j] = -1;
            }
}

/* ------------------------------------------------------------------ VPLs */

static double vpl_weight(void *ctx, const scene_object *leaf, const scene_texture *tex, unsigned flags)
{
    (void)ctx;
    (void)leaf;
    (void)tex;
    return radrules_gathers(flags) ? 1.0 : 0.0; /* no_radiosity: unseen by gathering rays */
}

typedef struct {
    gi_vpl *v;
    rgb *kd;            /* the VPL side's Lambertian albedo */
    double *kg, *kappa; /* its glossy weight and exponent (the larger sub-lobe's) */
    int n;
} vpl_set;

static void vpl_set_free(vpl_set *s)
{
    free(s->v);
    free(s->kd);
    free(s->kg);
    free(s->kappa);
}

/* The hit of a gathering ray from b's surface along w (it passes
 * no_radiosity objects, radrules.h rule 3); 0 when it leaves the scene. */
static int gather_hit(const accel *a, const shade_mat_bsdf *b, vec3 w, double eps, accel_hit *h)
{
    vec3 org = v3_dot(w, b->ng) > 0.0 ? b->p_out : b->p_in;
    /* a ray past ACCEL_PASS_MAX no_radiosity objects takes the last one */
    return accel_intersect_past(a, &b->from, org, w, eps, OBJ_NO_RADIOSITY, h, NULL) != 0;
}

typedef struct {
    const scene *sc;
    const accel *a;
    const pm_lights *L;
    const accel_surf *S;
    int n, gather;
    double bright, eps;
    uint64_t seed;
    vpl_set *out;
    unsigned char *ok;
    long *shadow; /* per block */
} vpl_job;

#define VPL_BLOCK 256

/* VPL i into out slot i (1), or 0 when its sample failed. */
static int make_one(const vpl_job *j, int i, rng *r, long *shadow)
{
    const scene *sc = j->sc;
    const accel *a = j->a;
    const pm_lights *L = j->L;
    const accel_surf *S = j->S;
    const int n = j->n, gather = j->gather, k = i;
    const double bright = j->bright, eps = j->eps;
    vpl_set *out = j->out;
    accel_surf_sample s;
    if (!accel_surf_sample_point(S, (i + rng_f64(r)) / n, rng_f64(r), rng_f64(r), r, &s)) return 0;
    accel_hit h;
    memset(&h, 0, sizeof h);
    h.p = s.p;
    h.ng = h.ns = s.n;
    h.obj = s.obj;
    h.texture = s.texture;
    h.prim = s.prim;
    h.flags = s.flags;
    h.uv[0] = s.p.x;
    h.uv[1] = s.p.y;
    /* the side that receives more light */
    double best = -1.0;
    for (int side = 0; side < 2; side++) {
        vec3 ns = side ? v3_neg(s.n) : s.n;
        shade_mat_bsdf b;
        shade_mat_setup(&b, sc, &h, v3_neg(ns), eps, accel_eps_scale(j->a), r);
        b.gathered = 1; /* what a gathering ray sees: no highlights, area lights at their centre */
        rgb e = pm_direct_lights(L, &b, 1, r, shadow);
        shade_mat_bsdf bl = b; /* emitters through the Lambertian lobes only */
        bl.nglossy = 0;
        bl.gl_wsum = 0.0;
        bl.m[SHADE_MAT_LOBE_GLOSSY] = 0.0;
        rgb em = pm_direct_emitters(L, &bl, 4, gather ? SKY_RAYS : 0.0, 0.0, 0.0, r, shadow);
        if (gather) {
            /* the sky and emitters through the Lambertian lobe by SKY_RAYS
             * cosine gathering rays (emitters weighted against the 4
             * area samples above, as the path tracer does) */
            rgb acc = {0, 0, 0};
            for (int j = 0; j < SKY_RAYS; j++) {
                vec3 w = v3_cosine_dir(b.n, (j + rng_f64(r)) / SKY_RAYS, rng_f64(r));
                if (v3_dot(w, b.ng) <= 0.0) continue;
                accel_hit gh;
                rgb c = {0, 0, 0};
                if (!gather_hit(a, &b, w, eps, &gh)) {
                    c = pm_sky(sc, w);
                } else {
                    rgb le = shade_mat_emission_at(sc, NULL, &gh);
                    if (le.r != 0.0 || le.g != 0.0 || le.b != 0.0) {
                        double cb = SKY_RAYS * v3_dot(w, b.n) / M_PI;
                        double wt = pm_mis(cb, pm_emitter_density(L, &gh, b.p_out, 4));
                        c = mk(le.r * wt, le.g * wt, le.b * wt);
                    }
                }
                acc = mk(acc.r + c.r, acc.g + c.g, acc.b + c.b);
            }
            rgb ks = b.k[SHADE_MAT_LOBE_DIFFUSE];
            em = mk(em.r + ks.r * acc.r / SKY_RAYS, em.g + ks.g * acc.g / SKY_RAYS, em.b + ks.b * acc.b / SKY_RAYS);
        }
        e = mk(e.r + em.r * bright, e.g + em.g * bright, e.b + em.b * bright);
        double l = lum(e) + (side ? 0.0 : 1e-30); /* ties: the front */
        if (!(l > best)) continue;
        best = l;
        gi_vpl *v = &out->v[k];
        v->p = s.p;
        v->n = b.n;
        v->area = s.pdf_area > 0.0 ? 1.0 / (n * s.pdf_area) : 0.0;
        v->ld = mk(isfinite(e.r) ? e.r : 0.0, isfinite(e.g) ? e.g : 0.0, isfinite(e.b) ? e.b : 0.0);
        v->kappa = 0.0;
        out->kd[k] = b.k[SHADE_MAT_LOBE_DIFFUSE];
        out->kg[k] = 0.0;
        out->kappa[k] = 0.0;
        double wbest = 0.0;
        for (int j = 0; j < b.nglossy; j++) {
            out->kg[k] += b.gl_w[j] * lum(b.gl_c[j]);
            if (b.gl_w[j] > wbest) {
                wbest = b.gl_w[j];
                out->kappa[k] = glossy_exponent(b.gl[j]);
            }
        }
    }
    return 1;
}

static void vpl_block(void *ctx, int blk, int thread)
{
    (void)thread;
    vpl_job *j = ctx;
    rng r;
    rng_seed(&r, j->seed ^ 0x5eed0003ULL, 3 + (uint64_t)blk);
    int i1 = (blk + 1) * VPL_BLOCK < j->n ? (blk + 1) * VPL_BLOCK : j->n;
    for (int i = blk * VPL_BLOCK; i < i1; i++) j->ok[i] = (unsigned char)make_one(j, i, &r, &j->shadow[blk]);
}

static pt_status make_vpls(const scene *sc, const accel *a, const pm_lights *L, long want, uint64_t seed, double bright,
                           int threads, int width, int height, vpl_set *out, long *shadow, diag *d)
{
    /* gathering rays at the VPLs find the sky and emitters */
    const int gather = pm_sky_any(sc) || accel_surf_count(pm_lights_emitters(L)) > 0;
    pt_status st = PT_OK;
    /* planes: the scene's finite bounds grown to what a coarse grid of
     * camera rays sees, so the floor and walls in view get VPLs */
    vec3 lo, hi;
    accel_bounds(a, &lo, &hi);
    /* only hits within twice the finite bounds' diagonal of their centre: a
     * plane seen to the horizon would spread the VPLs thin */
    const vec3 centre = v3_scale(v3_add(lo, hi), 0.5);
    const double reach = 2.0 * v3_len(v3_sub(hi, lo));
    for (int y = 0; y < VIEW_GRID; y++)
        for (int x = 0; x < VIEW_GRID; x++) {
            vec3 org, dir;
            scene_camera_ray(&sc->camera, (x + 0.5) / VIEW_GRID * width, (y + 0.5) / VIEW_GRID * height, width, height,
                             &org, &dir);
            accel_hit h;
            if (accel_intersect(a, org, dir, pm_lights_eps(L), INFINITY, &h) && v3_finite(h.p) &&
                v3_len(v3_sub(h.p, centre)) <= reach) {
                lo = v3_min(lo, h.p);
                hi = v3_max(hi, h.p);
            }
        }
    accel_surf *S = accel_surf_build_in(sc, a, &lo, &hi, vpl_weight, NULL, threads > 0 ? threads : pool_default_threads(), d, &st);
    if (!S) return st;
    memset(out, 0, sizeof *out);
    if (accel_surf_count(S) == 0 || want < 1) {
        accel_surf_free(S);
        return PT_OK;
    }
    int n = (int)(want > (1 << 24) ? (1 << 24) : want);
    out->v = calloc((size_t)n, sizeof *out->v);
    out->kd = calloc((size_t)n, sizeof *out->kd);
    out->kg = calloc((size_t)n, sizeof *out->kg);
    out->kappa = calloc((size_t)n, sizeof *out->kappa);
    if (!out->v || !out->kd || !out->kg || !out->kappa) {
        vpl_set_free(out);
        accel_surf_free(S);
        return PT_ERR_NOMEM;
    }
    const int nblk = (n + VPL_BLOCK - 1) / VPL_BLOCK;
    unsigned char *ok = calloc((size_t)n, 1);
    long *sh = calloc((size_t)nblk, sizeof *sh);
    if (!ok || !sh) {
        free(ok);
        free(sh);
        vpl_set_free(out);
        accel_surf_free(S);
        return PT_ERR_NOMEM;
    }
    vpl_job job = {sc, a, L, S, n, gather, bright, pm_lights_eps(L), seed, out, ok, sh};
    pool_run(threads > 0 ? threads : pool_default_threads(), nblk, vpl_block, &job);
    int k = 0;
    for (int i = 0; i < n; i++) {
        if (!ok[i]) continue;
        out->v[k] = out->v[i];
        out->kd[k] = out->kd[i];
        out->kg[k] = out->kg[i];
        out->kappa[k] = out->kappa[i];
        k++;
    }
    for (int b = 0; b < nblk; b++) *shadow += sh[b];
    free(ok);
    free(sh);
    out->n = k;
    accel_surf_free(S);
    return PT_OK;
}

/* The VPLs' bounce points (kernel bounce mode: position, normal). */
static gi_dev_vpl_point *vpl_points(const vpl_set *vs, double lift)
{
    gi_dev_vpl_point *p = calloc((size_t)vs->n, sizeof *p);
    if (!p) return NULL;
    for (int i = 0; i < vs->n; i++) {
        vec3 q = v3_madd(vs->v[i].p, vs->v[i].n, lift);
        v3_store_f(p[i].p, q);
        p[i].n[0] = p[i].wo[0] = (float)vs->v[i].n.x;
        p[i].n[1] = p[i].wo[1] = (float)vs->v[i].n.y;
        p[i].n[2] = p[i].wo[2] = (float)vs->v[i].n.z;
        p[i].tab[0] = p[i].tab[1] = -1;
    }
    return p;
}

/* a + b, lobes merged by eq. 4 with luminance weights */
static void add_light(gi_vpl *a, const gi_vpl *b)
{
    a->ld = mk(a->ld.r + b->ld.r, a->ld.g + b->ld.g, a->ld.b + b->ld.b);
    double wa = a->kappa > 0.0 ? lum(a->ls) : 0.0, wb = b->kappa > 0.0 ? lum(b->ls) : 0.0;
    if (!(wb > 0.0)) return;
    if (!(wa > 0.0)) {
        a->ls = b->ls;
        a->d = b->d;
        a->kappa = b->kappa;
        return;
    }
    vec3 axis;
    double kappa;
    gi_vpl_merge_axis(v3_add(v3_scale(a->d, wa), v3_scale(b->d, wb)), wa + wb, (wa * a->kappa + wb * b->kappa) / (wa + wb),
                      &axis, &kappa);
    a->ls = mk(a->ls.r + b->ls.r, a->ls.g + b->ls.g, a->ls.b + b->ls.b);
    a->d = axis;
    a->kappa = kappa;
}

static int cut_array(const gi_vpl_tree *t, const render_vpl_settings *s, gi_dev_vpl_node **nodes)
{
    if (s->cut == RENDER_VPL_BRUTE) return gi_vpl_tree_leaves(t, nodes);
    if (s->cut == RENDER_VPL_FULL) return gi_vpl_tree_cut(t, -1.0, -1.0, nodes);
    return gi_vpl_tree_cut(t, s->min_cut, s->max_cut, nodes);
}

/* ------------------------------------------------------------ eye pass */

typedef struct {
    const scene *sc;
    const accel *a;
    const render_vpl_settings *s;
    const pm_lights *L;
    double eps, lift, bright;
    int levels;
    rgb *direct;       /* per pixel, summed over samples */
    rgb *fog_t;        /* per pixel: the fog's transmittance to the pixel centre's hit */
    gpoint *centre;    /* per pixel: the pixel-centre gather point */
    unsigned char *valid;
    gvec *rows;        /* per row: the secondary gather points */
    long *shadow, *camera, *secondary; /* per row */
    int oom;
} eye_ctx;

/* One eye path: direct light into *L; gather points of mirror and
 * refraction hits (depth > 0) into the row's list with weight T. */
static void eye_trace(eye_ctx *c, int y, int pixel, const accel_from *from, vec3 org, vec3 dir, unsigned skip, rgb T,
                      int depth, rng *r, rgb *L)
{
    if (depth >= c->levels) return;
    accel_hit h;
    int hit = accel_intersect_past(c->a, from, org, dir, c->eps, skip, &h, NULL) > 0;
    if (c->sc->fogs) {
        /* fog on camera and mirror/refraction segments, as the path tracer */
        rgb fa, fc;
        shade_atmos_fog_affine(c->sc, org, dir, hit ? h.t : INFINITY, &fa, &fc);
        *L = mk(L->r + T.r * fc.r, L->g + T.g * fc.g, L->b + T.b * fc.b);
        T = mk(T.r * fa.r, T.g * fa.g, T.b * fa.b);
    }
    if (!hit) {
        rgb sky = pm_sky(c->sc, dir);
        *L = mk(L->r + T.r * sky.r, L->g + T.g * sky.g, L->b + T.b * sky.b);
        return;
    }
    shade_mat_bsdf b;
    shade_mat_setup(&b, c->sc, &h, dir, c->eps, accel_eps_scale(c->a), r);
    rgb e = b.emission;
    if (b.nee) {
        rgb dl = pm_direct_lights(c->L, &b, 1, r, &c->shadow[y]);
        e = mk(e.r + dl.r, e.g + dl.g, e.b + dl.b);
    }
    /* emitters: one sample by area and one BSDF sample, weighted by the
     * power heuristic lobe by lobe as in the path tracer (the BSDF sample
     * finds the parts of emitters the area sampling leaves out: planes
     * beyond the scene's bounds); the same BSDF sample carries the sky
     * through the Lambertian and glossy lobes. A delta lobe drawn adds
     * nothing (the Whitted branches below carry those); surfaces without
     * emission that it meets are the VPLs' part. */
    const double ms = b.msum > 0.0 ? b.msum : 1.0;
    rgb em = pm_direct_emitters(c->L, &b, 1, b.m[SHADE_MAT_LOBE_DIFFUSE] / ms, b.m[SHADE_MAT_LOBE_BACK] / ms,
                                b.m[SHADE_MAT_LOBE_GLOSSY] / ms, r, &c->shadow[y]);
    e = mk(e.r + em.r * c->bright, e.g + em.g * c->bright, e.b + em.b * c->bright);
    *L = mk(L->r + T.r * e.r, L->g + T.g * e.g, L->b + T.b * e.b);
    shade_mat_scatter sm;
    if (shade_mat_sample(&b, r, 0, &sm) && !sm.specular) {
        accel_hit gh;
        rgb in = {0, 0, 0};
        if (!gather_hit(c->a, &b, sm.dir, c->eps, &gh)) {
            in = pm_sky(c->sc, sm.dir);
        } else {
            rgb le = shade_mat_emission_at(c->sc, NULL, &gh);
            if (le.r != 0.0 || le.g != 0.0 || le.b != 0.0) {
                double w = pm_mis(sm.pdf, pm_emitter_density(c->L, &gh, sm.org, 1));
                in = mk(le.r * w, le.g * w, le.b * w);
            }
        }
        const double k = c->bright;
        *L = mk(L->r + T.r * sm.weight.r * in.r * k, L->g + T.g * sm.weight.g * in.g * k,
                L->b + T.b * sm.weight.b * in.b * k);
    }
    if (depth > 0 && (b.m[SHADE_MAT_LOBE_DIFFUSE] > 0.0 || b.m[SHADE_MAT_LOBE_GLOSSY] > 0.0)) {
        gpoint g;
        point_of(&b, c->lift, &g);
        g.w = mk(T.r * c->bright, T.g * c->bright, T.b * c->bright);
        g.pixel = pixel;
        if (!gvec_push(&c->rows[y], &g)) c->oom = 1;
    }
    for (int lobe = SHADE_MAT_LOBE_REFLECT; lobe <= SHADE_MAT_LOBE_TRANSMIT; lobe++) {
        if (b.m[lobe] <= 0.0) continue;
        rgb T2 = mk(T.r * b.k[lobe].r, T.g * b.k[lobe].g, T.b * b.k[lobe].b);
        double mt = fmax(T2.r, fmax(T2.g, T2.b));
        if (!(mt > 0.0)) continue;
        if (mt < EYE_RR) {
            double q = mt / EYE_RR;
            if (rng_f64(r) >= q) continue;
            T2 = mk(T2.r / q, T2.g / q, T2.b / q);
        }
        c->secondary[y]++;
        if (lobe == SHADE_MAT_LOBE_REFLECT)
            eye_trace(c, y, pixel, &b.from, b.p_out, b.refl_dir, OBJ_NO_REFLECTION, T2, depth + 1, r, L);
        else
            eye_trace(c, y, pixel, &b.from, b.p_in, b.trans_dir, skip, T2, depth + 1, r, L);
    }
}

static void eye_row(void *ctx, int y, int thread)
{
    (void)thread;
    eye_ctx *c = ctx;
    const int W = c->s->width, H = c->s->height, spp = c->s->spp > 0 ? c->s->spp : 1;
    for (int x = 0; x < W; x++) {
        int pixel = y * W + x;
        rng r;
        rng_seed(&r, c->s->seed * 0x9E3779B97F4A7C15ULL + (uint64_t)pixel, 7);
        rgb sum = {0, 0, 0};
        int g = (int)floor(sqrt((double)spp));
        for (int k = 0; k < spp; k++) {
            double jx, jy;
            if (k < g * g) {
                jx = ((k % g) + rng_f64(&r)) / g;
                jy = ((k / g) + rng_f64(&r)) / g;
            } else {
                jx = rng_f64(&r);
                jy = rng_f64(&r);
            }
            vec3 org, dir;
            scene_camera_ray(&c->sc->camera, x + jx, y + jy, W, H, &org, &dir);
            c->camera[y]++;
            rgb one = {1, 1, 1};
            eye_trace(c, y, pixel, NULL, org, dir, OBJ_NO_IMAGE, one, 0, &r, &sum);
        }
        c->direct[pixel] = mk(sum.r / spp, sum.g / spp, sum.b / spp);
        /* the pixel centre's first hit: the G-buffer of the adaptive pass */
        vec3 org, dir;
        scene_camera_ray(&c->sc->camera, x + 0.5, y + 0.5, W, H, &org, &dir);
        accel_hit h;
        c->valid[pixel] = 0;
        int hit = accel_intersect_past(c->a, NULL, org, dir, c->eps, OBJ_NO_IMAGE, &h, NULL) > 0;
        c->fog_t[pixel] = mk(1, 1, 1);
        if (hit && c->sc->fogs) {
            rgb fc;
            shade_atmos_fog_affine(c->sc, org, dir, h.t, &c->fog_t[pixel], &fc);
        }
        if (hit) {
            shade_mat_bsdf b;
            shade_mat_setup(&b, c->sc, &h, dir, c->eps, accel_eps_scale(c->a), &r);
            if (b.m[SHADE_MAT_LOBE_DIFFUSE] > 0.0 || b.m[SHADE_MAT_LOBE_GLOSSY] > 0.0) {
                point_of(&b, c->lift, &c->centre[pixel]);
                c->centre[pixel].pixel = pixel;
                c->valid[pixel] = 1;
            }
        }
    }
}

/* ------------------------------------------------- adaptive image sampling */

typedef struct {
    gi_dev *dv;
    const gi_dev_vpl_node *nodes;
    int nnodes;
    const tables *ts;
    float thr;
    long visits_sum, visits_min, visits_max, gathered;
    double t_gather;
} gather_ctx;

/* Gathers points idx[0 .. n) of g (eye mode) into res (rgb each). */
static pt_status gather_list(gather_ctx *gc, const gpoint *g, const int *idx, int n, rgb *res, int count_visits,
                             diag *d)
{
    if (n <= 0) return PT_OK;
    gi_dev_vpl_point *pts = malloc(sizeof *pts * (size_t)n);
    float *out = malloc(sizeof(float) * 4 * (size_t)n);
    int *vis = malloc(sizeof(int) * (size_t)n);
    pt_status st = PT_ERR_NOMEM;
    if (pts && out && vis) {
        for (int i = 0; i < n; i++) pts[i] = g[idx ? idx[i] : i].dev;
        double t0 = timer_now();
        st = gi_dev_vpl_gather(gc->dv, pts, n, gc->nodes, gc->nnodes, gc->ts->vals, gc->ts->n, gc->thr, GI_VPL_EYE, out,
                               vis, d);
        gc->t_gather += timer_now() - t0;
        if (st == PT_OK)
            for (int i = 0; i < n; i++) {
                res[i] = mk(out[4 * i], out[4 * i + 1], out[4 * i + 2]);
                if (count_visits) {
                    gc->visits_sum += vis[i];
                    if (gc->visits_min < 0 || vis[i] < gc->visits_min) gc->visits_min = vis[i];
                    if (vis[i] > gc->visits_max) gc->visits_max = vis[i];
                    gc->gathered++;
                }
            }
    }
    free(pts);
    free(out);
    free(vis);
    return st;
}

static vec3 gp_pos(const gpoint *g) { return v3(g->dev.p[0], g->dev.p[1], g->dev.p[2]); }
static vec3 gp_nrm(const gpoint *g) { return v3(g->dev.n[0], g->dev.n[1], g->dev.n[2]); }

/* Indirect light of every pixel centre (ind; 0 where not valid): adaptive
 * sampling over the levels COARSE, COARSE/2, ..., 1 and bilateral upsampling
 * (paper, section 4.4), or every valid pixel. */
static pt_status pixel_indirect(gather_ctx *gc, const render_vpl_settings *s, const gpoint *centre,
                                const unsigned char *valid, double half_diag, rgb *ind, long *sampled, diag *d)
{
    const int W = s->width, H = s->height;
    const size_t np = (size_t)W * H;
    int *list = malloc(sizeof(int) * np);
    rgb *res = malloc(sizeof(rgb) * np);
    pt_status st = PT_ERR_NOMEM;
    if (!list || !res) goto done;
    for (size_t i = 0; i < np; i++) ind[i] = mk(0, 0, 0);
    *sampled = 0;
    if (!s->adaptive) {
        int n = 0;
        for (size_t i = 0; i < np; i++)
            if (valid[i]) list[n++] = (int)i;
        st = gather_list(gc, centre, list, n, res, 1, d);
        if (st == PT_OK)
            for (int i = 0; i < n; i++) ind[list[i]] = res[i];
        *sampled = n;
        goto done;
    }
    /* the coarsest grid: every pixel at multiples of COARSE */
    int n = 0;
    for (int y = 0; y < H; y += COARSE)
        for (int x = 0; x < W; x += COARSE) {
            int i = y * W + x;
            if (valid[i]) list[n++] = i;
        }
    if ((st = gather_list(gc, centre, list, n, res, 1, d)) != PT_OK) goto done;
    double lsum = 0.0;
    for (int k = 0; k < n; k++) {
        ind[list[k]] = res[k];
        lsum += lum(res[k]);
    }
    *sampled += n;
    /* colour differences read as display values: the mean indirect at 0.25 */
    const double cscale = n > 0 && lsum > 0.0 ? 0.25 / (lsum / n) : 1.0;
    double eps = s->epsilon;
    for (int step = COARSE / 2; step >= 1; step /= 2, eps *= 2.0) {
        const int s2 = 2 * step;
        n = 0;
        /* pass 1: decide; interpolate the coherent ones */
        for (int y = 0; y < H; y += step)
            for (int x = 0; x < W; x += step) {
                if (x % s2 == 0 && y % s2 == 0) continue;
                int i = y * W + x;
                int x0 = x / s2 * s2, y0 = y / s2 * s2, x1 = x0 + s2 < W ? x0 + s2 : x0, y1 = y0 + s2 < H ? y0 + s2 : y0;
                if (x % s2 == 0) x1 = x0;
                if (y % s2 == 0) y1 = y0;
                int par[4] = {y0 * W + x0, y0 * W + x1, y1 * W + x0, y1 * W + x1};
                double bw[4] = {(1.0 - (double)(x - x0) / s2) * (1.0 - (double)(y - y0) / s2),
                                ((double)(x - x0) / s2) * (1.0 - (double)(y - y0) / s2),
                                (1.0 - (double)(x - x0) / s2) * ((double)(y - y0) / s2),
                                ((double)(x - x0) / s2) * ((double)(y - y0) / s2)};
                if (x1 == x0) bw[0] += bw[1], bw[2] += bw[3], bw[1] = bw[3] = 0.0;
                if (y1 == y0) bw[0] += bw[2], bw[1] += bw[3], bw[2] = bw[3] = 0.0;
                if (!valid[i]) continue;
                double err = 0.0;
                int bad = 0;
                vec3 pc = gp_pos(&centre[i]), nc = gp_nrm(&centre[i]);
                for (int k = 0; k < 4; k++) {
                    if (!(bw[k] > 0.0)) continue;
                    if (!valid[par[k]]) { bad = 1; continue; }
                    double dn = 2.0 - 2.0 * v3_dot(nc, gp_nrm(&centre[par[k]]));
                    double e = v3_len(v3_sub(pc, gp_pos(&centre[par[k]]))) / half_diag + sqrt(dn > 0.0 ? dn : 0.0);
                    if (e > err) err = e;
                }
                double csum = 0.0;
                for (int j = 0; j < 4; j++)
                    for (int k = j + 1; k < 4; k++)
                        if (bw[j] > 0.0 && bw[k] > 0.0 && valid[par[j]] && valid[par[k]])
                            csum += fabs(lum(ind[par[j]]) - lum(ind[par[k]])) * cscale;
                err += s->lambda * csum;
                if (!bad && err <= eps) {
                    /* bilateral upsampling (Sloan et al. 2007): bilinear x
                     * position x normal weights */
                    double wsum = 0.0;
                    rgb acc = {0, 0, 0};
                    for (int k = 0; k < 4; k++) {
                        if (!(bw[k] > 0.0) || !valid[par[k]]) continue;
                        double dp = v3_len(v3_sub(pc, gp_pos(&centre[par[k]]))) / half_diag * 20.0;
                        double cn = fmax(0.0, v3_dot(nc, gp_nrm(&centre[par[k]])));
                        double w = bw[k] / (1.0 + dp * dp) * pow(cn, 8.0);
                        wsum += w;
                        acc = mk(acc.r + w * ind[par[k]].r, acc.g + w * ind[par[k]].g, acc.b + w * ind[par[k]].b);
                    }
                    if (wsum > 1e-9) {
                        ind[i] = mk(acc.r / wsum, acc.g / wsum, acc.b / wsum);
                        continue;
                    }
                }
                list[n++] = i;
            }
        if ((st = gather_list(gc, centre, list, n, res, 1, d)) != PT_OK) goto done;
        for (int k = 0; k < n; k++) ind[list[k]] = res[k];
        *sampled += n;
    }
    st = PT_OK;
done:
    free(list);
    free(res);
    return st;
}

/* ------------------------------------------------------------ the render */

pt_status render_vpl(const scene *sc, const accel *a, const render_vpl_settings *s, framebuffer *fb,
                     render_vpl_stats *st, diag *d)
{
    render_vpl_stats local;
    if (!st) st = &local;
    memset(st, 0, sizeof *st);
    if (!sc || !a || !s || !fb || fb->width != s->width || fb->height != s->height) return PT_ERR_INTERNAL;
    const double t_start = timer_now();
    const int W = s->width, H = s->height;
    const size_t np = (size_t)W * H;
    pt_status status = PT_OK;
    const radrules rr = radrules_of(sc, 1);
    pm_lights *L = pm_lights_new(sc, a, d, &status);
    if (!L) return status;
    gi_dev_options go = {s->cl_device, NULL, s->threads, s->cl_max_bytes};
    gi_dev *dv = gi_dev_open(&go, d, &status);
    if (!dv) {
        pm_lights_free(L);
        return status;
    }
    snprintf(st->device, sizeof st->device, "%s", gi_dev_name(dv));
    vec3 lo, hi;
    accel_bounds(a, &lo, &hi);
    double diag_len = v3_len(v3_sub(hi, lo));
    if (!(diag_len > 0.0) || !isfinite(diag_len)) diag_len = 1.0;
    const double lift = pm_lights_eps(L) * 100.0;

    /* VPLs and their direct light */
    double t0 = timer_now();
    vpl_set vs = {0};
    status = make_vpls(sc, a, L, s->vpls, s->seed, rr.brightness, s->threads, W, H, &vs, &st->shadow_rays, d);
    st->t_vpls = timer_now() - t0;
    st->vpls = vs.n;
    gi_vpl_tree *tree = NULL;
    gi_dev_vpl_node *nodes = NULL;
    int nnodes = 0;
    tables ts = {0};
    if (status == PT_OK && vs.n > 0) {
        t0 = timer_now();
        /* eq. 5's D: the VPLs' own extent (planes reach past the finite bounds) */
        vec3 vlo = vs.v[0].p, vhi = vs.v[0].p;
        for (int i = 1; i < vs.n; i++) {
            vlo = v3_min(vlo, vs.v[i].p);
            vhi = v3_max(vhi, vs.v[i].p);
        }
        double vdiag = v3_len(v3_sub(vhi, vlo));
        tree = gi_vpl_tree_build(vs.v, vs.n, vdiag > 0.0 ? vdiag : diag_len, 3);
        st->t_tree = timer_now() - t0;
        if (!tree) status = PT_ERR_NOMEM;
    }
    /* bounces gathered at the VPLs */
    if (tree) {
        t0 = timer_now();
        st->tree_nodes = gi_vpl_tree_size(tree);
        int nb = s->bounces;
        if (rr.recursion_limit > 0 && nb > rr.recursion_limit - 1) nb = rr.recursion_limit - 1;
        gi_vpl *total = malloc(sizeof *total * (size_t)vs.n), *cur = malloc(sizeof *cur * (size_t)vs.n);
        gi_dev_vpl_point *bp = vpl_points(&vs, lift);
        float *out = malloc(sizeof(float) * 12 * (size_t)vs.n);
        int *vis = malloc(sizeof(int) * (size_t)vs.n);
        if (!total || !cur || !bp || !out || !vis) status = PT_ERR_NOMEM;
        if (status == PT_OK) {
            memcpy(total, vs.v, sizeof *total * (size_t)vs.n);
            memcpy(cur, vs.v, sizeof *cur * (size_t)vs.n);
        }
        for (int b = 0; b < nb && status == PT_OK && !(s->cancel && *s->cancel); b++) {
            gi_vpl_tree_relight(tree, cur);
            gi_dev_vpl_node *bn = NULL;
            int nbn = cut_array(tree, s, &bn);
            if (nbn < 0) {
                status = PT_ERR_NOMEM;
                break;
            }
            status = gi_dev_vpl_gather(dv, bp, vs.n, bn, nbn, NULL, 0, (float)s->threshold, GI_VPL_BOUNCE, out, vis, d);
            free(bn);
            for (int i = 0; status == PT_OK && i < vs.n; i++) {
                const float *o = out + 12 * (size_t)i;
                gi_vpl *v = &cur[i];
                const double br = rr.brightness;
                rgb kd = vs.kd[i];
                v->ld = mk(kd.r / M_PI * o[0] * br, kd.g / M_PI * o[1] * br, kd.b / M_PI * o[2] * br);
                double kg = vs.kg[i] * br;
                v->ls = mk(kg * o[3], kg * o[4], kg * o[5]);
                double wsum = lum(mk(o[3], o[4], o[5]));
                gi_vpl_merge_axis(v3(o[6], o[7], o[8]), wsum, vs.kappa[i], &v->d, &v->kappa);
                if (!(kg > 0.0)) v->kappa = 0.0;
                add_light(&total[i], v);
            }
            st->bounces++;
        }
        if (status == PT_OK) gi_vpl_tree_relight(tree, total);
        free(total);
        free(cur);
        free(bp);
        free(out);
        free(vis);
        if (status == PT_OK) {
            nnodes = cut_array(tree, s, &nodes);
            if (nnodes < 0) status = PT_ERR_NOMEM;
            st->cut_nodes = nnodes;
        }
        st->t_bounce = timer_now() - t0;
    }

    /* eye samples and the pixel-centre G-buffer */
    eye_ctx ec = {sc, a, s, L, pm_lights_eps(L), lift, rr.brightness, radrules_level_limit(sc, 0)};
    ec.direct = calloc(np, sizeof *ec.direct);
    ec.fog_t = calloc(np, sizeof *ec.fog_t);
    ec.centre = calloc(np, sizeof *ec.centre);
    ec.valid = calloc(np, 1);
    ec.rows = calloc((size_t)H, sizeof *ec.rows);
    ec.shadow = calloc((size_t)H, sizeof(long));
    ec.camera = calloc((size_t)H, sizeof(long));
    ec.secondary = calloc((size_t)H, sizeof(long));
    rgb *ind = calloc(np, sizeof *ind);
    if (!ec.direct || !ec.fog_t || !ec.centre || !ec.valid || !ec.rows || !ec.shadow || !ec.camera || !ec.secondary || !ind)
        status = status == PT_OK ? PT_ERR_NOMEM : status;
    if (status == PT_OK) {
        t0 = timer_now();
        pool_run_cancel(s->threads > 0 ? s->threads : pool_default_threads(), H, eye_row, &ec, s->cancel);
        st->t_trace = timer_now() - t0;
        if (ec.oom) status = PT_ERR_NOMEM;
        for (int y = 0; y < H; y++) {
            st->shadow_rays += ec.shadow[y];
            st->camera_rays += ec.camera[y];
            st->secondary_rays += ec.secondary[y];
        }
    }
    gather_ctx gc = {dv, nodes, nnodes, &ts, (float)s->threshold, 0, -1, 0, 0, 0.0};
    rgb *sec = NULL;
    gvec all = {0};
    if (status == PT_OK && nnodes > 0) {
        tables_assign(&ts, ec.centre, (int)np);
        for (int y = 0; y < H && status == PT_OK; y++) {
            tables_assign(&ts, ec.rows[y].v, ec.rows[y].n);
            for (int k = 0; k < ec.rows[y].n; k++)
                if (!gvec_push(&all, &ec.rows[y].v[k])) status = PT_ERR_NOMEM;
        }
        if (status == PT_OK)
            status = pixel_indirect(&gc, s, ec.centre, ec.valid, diag_len / 2.0, ind, &st->pixels_sampled, d);
        st->t_gather_pixels = gc.t_gather;
        if (status == PT_OK && all.n > 0) {
            sec = malloc(sizeof *sec * (size_t)all.n);
            status = sec ? gather_list(&gc, all.v, NULL, all.n, sec, 0, d) : PT_ERR_NOMEM;
        }
    }
    if (status == PT_OK) {
        const int spp = s->spp > 0 ? s->spp : 1;
        for (size_t i = 0; i < np; i++) {
            rgb v = ec.direct[i];
            const rgb ft = ec.fog_t[i];
            if (ec.valid[i])
                v = mk(v.r + ind[i].r * rr.brightness * ft.r, v.g + ind[i].g * rr.brightness * ft.g,
                       v.b + ind[i].b * rr.brightness * ft.b);
            ec.direct[i] = v;
        }
        for (int k = 0; sec && k < all.n; k++) {
            rgb *v = &ec.direct[all.v[k].pixel];
            const rgb w = all.v[k].w;
            *v = mk(v->r + w.r * sec[k].r / spp, v->g + w.g * sec[k].g / spp, v->b + w.b * sec[k].b / spp);
        }
        for (size_t i = 0; i < np; i++) {
            float *px = fb->rgb + 3 * i;
            rgb v = ec.direct[i];
            px[0] = isfinite(v.r) ? (float)v.r : 0.0f;
            px[1] = isfinite(v.g) ? (float)v.g : 0.0f;
            px[2] = isfinite(v.b) ? (float)v.b : 0.0f;
        }
        st->pixels = (long)np;
        for (size_t i = 0; i < np; i++) st->pixels_valid += ec.valid[i];
        st->secondary_points = all.n;
        st->visits_mean = gc.gathered > 0 ? (double)gc.visits_sum / gc.gathered : 0.0;
        st->visits_min = gc.visits_min > 0 ? gc.visits_min : 0;
        st->visits_max = gc.visits_max;
        st->t_gather = gc.t_gather;
    }
    if (ec.rows)
        for (int y = 0; y < H; y++) free(ec.rows[y].v);
    free(all.v);
    free(sec);
    free(ind);
    free(ec.direct);
    free(ec.fog_t);
    free(ec.centre);
    free(ec.valid);
    free(ec.rows);
    free(ec.shadow);
    free(ec.camera);
    free(ec.secondary);
    free(ts.t);
    free(ts.vals);
    free(nodes);
    gi_vpl_tree_free(tree);
    vpl_set_free(&vs);
    gi_dev_free(dv);
    pm_lights_free(L);
    st->t_total = timer_now() - t_start;
    return status;
}
