/* shade.c - Whitted ray tracing with POV-Ray 3.7's classic lighting model.
 *
 * What is modelled, following the POV-Ray 3.7 reference manual (sections
 * "Finish", "Light Source", "Anti-Aliasing Options") and the behaviour of
 * POV-Ray 3.7's renderer as read from its sources (semantics only):
 *  - colour = pigment * (emission + ambient * ambient_light)   [ambient only without GI]
 *           + sum over lights of diffuse, phong and specular terms
 *           + reflection * reflected ray + transmitted ray (filter/transmit, ior)
 *  - diffuse:  diffuse * |cos i|^brilliance * pigment * light
 *  - phong:    phong * cos(R, L)^phong_size * light (R = mirror of the eye ray)
 *  - specular: specular * cos(H, N)^(1/roughness) * light (H = half vector)
 *  - metallic highlight tint: POV-Ray's empirical Fresnel curve
 *    F(x) = 0.014567225/(x-1.12)^2 - 0.011612903, x = angle/(pi/2).
 *  - light attenuation: spotlight cos^tightness with a cubic falloff between
 *    cos(radius) and cos(falloff); cylinder lights; fade
 *    2/(1+(d/fade_distance)^fade_power).
 *  - area lights: the intensity (spot, fade, cosine) is taken from the light's
 *    centre; shadows are the average visibility over the size1 x size2 grid,
 *    sampled adaptively as POV-Ray does (corners first, subdivide while the
 *    corner values differ by more than 0.1 or the level is below `adaptive`,
 *    100 unless given: the whole grid),
 *    each grid point jittered by up to half a cell when `jitter` is set.
 *    `area_illumination on` evaluates the shading per grid point instead.
 *  - antialiasing (+A, method 1): one ray through each pixel centre; then,
 *    in POV-Ray's 32 x 32 render blocks and its order within a block
 *    (tracetask.cpp, NonAdaptiveSupersamplingM1), each pixel is compared
 *    with its left and upper neighbours after the Antialias_Gamma curve:
 *    a pair that differs by at least the threshold supersamples the
 *    neighbour (unless done already) and the pixel, with depth x depth
 *    jittered rays averaged with the first sample. Comparisons read the
 *    neighbours as they are by then (supersampled or not); across a block's
 *    left and upper edges they read the neighbours' first samples, and
 *    those neighbours are left to their own block (at the image's edges
 *    the neighbour is a ray through the pixel centre outside the image).
 */
#include "shade.h"
#include "hash.h"
#include "camera.h"
#include "func_internal.h"
#include <assert.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include "pool.h"
#include "shade_atmos.h"
#include "shade_focal.h"
#include "shade_gamma.h"
#include "shade_light.h"
#include "shade_media.h"
#include "shade_noise.h"
#include "shade_normal.h"
#include "shade_project.h"
#include "shade_texture.h"
#include "timer.h"

#define SHADE_MAX_THREADS 256
#define TILE 16

#define LIGHT_CACHE 16 /* lights whose shadow result a hit keeps */

typedef struct {
    long primary, shadow, secondary, discarded, unsupported;
    /* The shadow results of the last hit lit, per light: every texture
     * layer (and layered texture) at one hit sees the same shadow, so the
     * test is done once per hit and light, as POV-Ray's lightColorCache. */
    const void *lc_obj;
    vec3 lc_p;
    unsigned lc_valid;
    rgb lc_vis[LIGHT_CACHE];
    /* per light, the primitive that last blocked one of this thread's
     * shadow rays (accel_occluded_cached: POV-Ray's shadow cache) */
    unsigned blocker[LIGHT_CACHE];
    /* while a media sample's light is traced: 1 its media take photons, 2
     * they do not; 0 a surface's light (the photon shadow rule asks the
     * lit surface's collect, photon_light) */
    int media_lit;
    char pad[64];
} thread_stats;

typedef struct {
    const scene *sc;
    const accel *a;
    const shade_settings *s;
    double eps;          /* scene-scaled distance epsilon */
    int max_level;
    thread_stats *ts;
    framebuffer *fb;
    float *first;        /* +A: the first pass's colours (rgb per pixel) */
    int *block_order;    /* +A: the blocks, likely costliest first */
    int tiles_x, tiles_y;
    int transparent;     /* some surface lets light through: filtered shadows */
    shade_light_projection *proj; /* projected_through lights (shade_project.c), NULL = none */
    /* Media (shade_media.c): whether the scene has any, the
     * containers of the camera's location, and per thread the hit being
     * shaded (its incoming ray's containers) for the rays it spawns. */
    int media;
    /* shadow rays take the media's extinction: 0 where no media can dim
     * light (emission only: shade_media_scene_attenuates) */
    int media_shadow;
    shade_media_inside cam_in;
    const struct hit_frame *frame[SHADE_MAX_THREADS];
    int primary_on;      /* s->primary holds this render's centre rays (shade_primary_begin_fn) */
    int win[4];          /* the pixels rendered (shade_settings.window) */
    int first_win[4];    /* the first pass's: win and, with +A, the AA blocks it meets and a one-pixel apron */
    shade_focal focal;   /* focal blur's budget (camera_focal_blur) */
} render_ctx;

/* The hit shade_tex_shade is working on, for its callbacks: the containers of
 * the ray that reached it. */
typedef struct hit_frame {
    const accel_hit *h;
    vec3 dir;
    const shade_media_inside *in;
    int depth;   /* hits on the stack, this one included (shade_tex_env.depth) */
} hit_frame;

static const shade_media_inside no_containers = {0, {0}};

static const shade_media_inside *frame_inside(const render_ctx *c, int thread)
{
    return c->frame[thread] ? c->frame[thread]->in : &no_containers;
}

static inline rgb rgb_make(double r, double g, double b) { rgb c = {r, g, b}; return c; }
static inline rgb rgb_add(rgb a, rgb b) { return rgb_make(a.r + b.r, a.g + b.g, a.b + b.b); }
static inline rgb rgb_mul(rgb a, rgb b) { return rgb_make(a.r * b.r, a.g * b.g, a.b * b.b); }
static inline rgb rgb_scale(rgb a, double s) { return rgb_make(a.r * s, a.g * s, a.b * s); }
static inline double rgb_max(rgb a) { return fmax(a.r, fmax(a.g, a.b)); }
static inline int rgb_near_zero(rgb a) { return fabs(a.r) < 1e-10 && fabs(a.g) < 1e-10 && fabs(a.b) < 1e-10; }
/* POV-Ray's greyscale weights (0.297, 0.589, 0.114). */
static inline double rgb_grey(rgb a) { return 0.297 * a.r + 0.589 * a.g + 0.114 * a.b; }

/* POV-Ray's colour distance used for antialiasing decisions: sum of the
 * absolute channel differences. */
static double shade_colour_distance(rgb a, rgb b) { return fabs(a.r - b.r) + fabs(a.g - b.g) + fabs(a.b - b.b); }

void shade_default_settings(shade_settings *s)
{
    /* POV-Ray's defaults: +A threshold 0.3, +R3, +Q9 */
    *s = (shade_settings){.width = 320, .height = 240, .aa_threshold = 0.3, .aa_depth = 3, .aa_jitter = 1.0, .spp = 1,
                          .use_ambient = 1, .quality = 9};
}

/* ------------------------------------------------------------------ lights */

/* Where a shadow ray toward a light at distance depth stops: short of the
 * light by the scene's epsilon or 1e-6 of the distance, whichever is
 * larger; at most c->eps means the light touches p (nothing in between). */
static double shadow_tmax(const render_ctx *c, double depth)
{
    return depth - fmax_inline(c->eps, depth * 1e-6);
}

static int shadow_blocked(render_ctx *c, int thread, vec3 p, vec3 dir, double depth, const scene_light *l)
{
    c->ts[thread].shadow++;
    double tmax = shadow_tmax(c, depth);
    if (tmax <= c->eps) return 0;
    ptrdiff_t li = l ? l - c->sc->lights : -1;
    unsigned *last = li >= 0 && li < c->sc->nlights && li < LIGHT_CACHE ? &c->ts[thread].blocker[li] : NULL;
    return accel_occluded_cached(c->a, last, p, dir, c->eps, tmax);
}

static rgb media_light(void *ctx, int thread, const scene_light *l, vec3 p, const shade_media_inside *in, int collect,
                       vec3 *to_light);

/* The light whose photons a caustic layer carries, where the shadow ray's
 * lit thing takes photons (POV-Ray 3.7's trace.cpp, ComputeShadowColour:
 * not when the lit object has collect off, or the lit media all ignore
 * photons): shadow rays then stop at photon targets that refract it. */
static const scene_light *photon_light(const render_ctx *c, int thread, const scene_light *l)
{
    if (!c->s->photon_shadows) return NULL;
    int m = c->ts[thread].media_lit;
    if (m) return m == 1 ? l : NULL;
    const accel_hit *lit = c->frame[thread] ? c->frame[thread]->h : NULL;
    if (lit && lit->obj && lit->obj->photons && !lit->obj->photons->collect) return NULL;
    return l;
}

/* Media along shadow rays (shade_media.c): the light's media_attenuation
 * through the atmosphere and fog, the containers' media on the way. */
static int media_shadows(const render_ctx *c, const scene_light *l)
{
    return c->media_shadow || (l && c->sc->fogs && l->media_interaction && l->media_attenuation);
}

/* Light reaching p along a shadow ray: 0 or 1 in scenes without transparent
 * surfaces or media, else filtered by the surfaces crossed
 * (shade_texture.c) and attenuated by the media on the way. rest non-NULL
 * (an area light's sample): the atmosphere after the last surface crossed
 * is left to the caller, *rest its length (shade_media_shadow_ray). */
static rgb shadow_rgb(render_ctx *c, int thread, vec3 p, vec3 dir, double depth, const scene_light *l, const shade_media_inside *in,
                      double *rest)
{
    int media = media_shadows(c, l);
    if (!media && !c->transparent)
        return shadow_blocked(c, thread, p, dir, depth, l) ? rgb_make(0, 0, 0) : rgb_make(1, 1, 1);
    c->ts[thread].shadow++;
    double tmax = shadow_tmax(c, depth);
    if (tmax <= c->eps) return rgb_make(1, 1, 1);
    const scene_light *pl = photon_light(c, thread, l);
    if (media) {
        shade_media_env me = {c->sc, c, thread, NULL, media_light, NULL, NULL, NULL};
        return shade_media_shadow_ray(c->sc, c->a, &me, l, p, dir, c->eps, tmax, in ? in : &no_containers, rest, pl);
    }
    return shade_tex_shadow_ray(c->sc, c->a, p, dir, c->eps, tmax, pl);
}

/* Visibility (0..1) of the rectangle [u1,u2]x[v1,v2] of the grid, adaptively. */
typedef struct {
    render_ctx *c;
    const scene_light *l;
    vec3 p, ax1, ax2;
    rgb *grid; /* size1*size2, r < 0 = not sampled */
    rng *r;
    int thread;
    const shade_media_inside *in;
    double depth; /* to the light's centre */
    double rest;  /* the atmosphere's part of the way (POV-Ray's lightsourcedepth, area_visibility) */
} area_job;

static rgb area_sample(area_job *j, int u, int v)
{
    rgb *g = &j->grid[u * j->l->size2 + v];
    if (g->r >= 0.0) return *g;
    vec3 centre = v3_add(j->l->position, scene_light_area_point(j->l, j->ax1, j->ax2, u, v, j->r));
    vec3 dir;
    double depth;
    shade_light_ray(j->l, centre, j->p, &dir, &depth);
    *g = shadow_rgb(j->c, j->thread, j->p, dir, depth, j->l, j->in, &j->rest);
    return *g;
}

static rgb area_subset(area_job *j, int u1, int v1, int u2, int v2, int level)
{
    rgb s[4] = {area_sample(j, u1, v1), area_sample(j, u2, v1), area_sample(j, u1, v2), area_sample(j, u2, v2)};
    if (u2 - u1 > 1 || v2 - v1 > 1) {
        /* POV-Ray's ColourDistance: |a-b| summed over the 3 channels. */
        int differ = shade_colour_distance(s[0], s[1]) > 0.1 || shade_colour_distance(s[1], s[3]) > 0.1 ||
                     shade_colour_distance(s[3], s[2]) > 0.1 || shade_colour_distance(s[2], s[0]) > 0.1;
        if (level < j->l->adaptive || differ) {
            int um0 = (int)floor((u1 + u2) / 2.0), um1 = (int)ceil((u1 + u2) / 2.0);
            int vm0 = (int)floor((v1 + v2) / 2.0), vm1 = (int)ceil((v1 + v2) / 2.0);
            /* POV-Ray re-aims at the centre (its whole depth) before each part */
            j->rest = j->depth;
            s[0] = area_subset(j, u1, v1, um0, vm0, level + 1);
            j->rest = j->depth;
            s[1] = area_subset(j, um1, v1, u2, vm0, level + 1);
            j->rest = j->depth;
            s[2] = area_subset(j, u1, vm1, um0, v2, level + 1);
            j->rest = j->depth;
            s[3] = area_subset(j, um1, vm1, u2, v2, level + 1);
        }
    }
    return rgb_scale(rgb_add(rgb_add(s[0], s[1]), rgb_add(s[2], s[3])), 0.25);
}

static rgb area_visibility(render_ctx *c, int thread, const scene_light *l, vec3 p, rng *r, const shade_media_inside *in)
{
    rgb stack_grid[256];
    int n = l->size1 * l->size2;
    rgb *grid = n <= 256 ? stack_grid : malloc(sizeof(rgb) * (size_t)n);
    if (!grid) return rgb_make(1, 1, 1);
    for (int i = 0; i < n; i++) grid[i].r = -1.0;
    vec3 dir;
    double depth;
    shade_light_ray(l, l->position, p, &dir, &depth);
    area_job j = {c, l, p, l->axis1, l->axis2, grid, r, thread, in, depth, depth};
    shade_light_area_axes(l, p, &j.ax1, &j.ax2);
    rgb vis = area_subset(&j, 0, 0, l->size1 - 1, l->size2 - 1, 0);
    if (grid != stack_grid) free(grid);
    /* the atmosphere once, from p over what the last sample traced left of
     * its way (POV-Ray 3.7's TraceShadowRay; shade_media_shadow_rest) */
    if (media_shadows(c, l) && !rgb_near_zero(vis)) {
        shade_media_env me = {c->sc, c, thread, NULL, media_light, NULL, NULL, NULL};
        vis = shade_media_shadow_rest(c->sc, &me, l, in ? in : &no_containers, p, dir, fmin(j.rest, shadow_tmax(c, depth)), vis);
    }
    return vis;
}

/* Light of l reaching a media sample at p (POV-Ray's TestShadow): its
 * attenuation there, then unless shadowless the shadow ray (area grid
 * included) from the sampled ray's containers. */
static rgb media_light(void *ctx, int thread, const scene_light *l, vec3 p, const shade_media_inside *in, int collect,
                       vec3 *to_light)
{
    render_ctx *c = ctx;
    vec3 dir;
    double depth;
    shade_light_ray(l, l->position, p, &dir, &depth);
    *to_light = dir;
    double sdepth = depth;
    if (l->projected_through && !shade_projection_pass(c->proj, (int)(l - c->sc->lights), p, dir, depth, &sdepth))
        return rgb_make(0, 0, 0);
    rgb lc = rgb_scale(l->colour, shade_light_attenuation(l, p, dir, depth));
    if (rgb_near_zero(lc) || l->shadowless) return lc;
    rgb vis;
    int outer = c->ts[thread].media_lit;
    c->ts[thread].media_lit = collect ? 1 : 2;
    if (l->area && l->size1 * l->size2 > 1) {
        rng r; /* jittered area lights: a stream of the sample's own, from
                * where it lies alone (never the thread: an image is the
                * same on any thread count, and a tile equals the frame) */
        uint64_t k;
        double coords[3] = {p.x, p.y, p.z};
        memcpy(&k, &coords[0], sizeof k);
        uint64_t k2, k3;
        memcpy(&k2, &coords[1], sizeof k2);
        memcpy(&k3, &coords[2], sizeof k3);
        rng_seed(&r, k ^ (k2 * 0x9e3779b97f4a7c15ULL) ^ (k3 * 0xbf58476d1ce4e5b9ULL), 0);
        vis = area_visibility(c, thread, l, p, &r, in);
    } else {
        vis = shadow_rgb(c, thread, p, dir, sdepth, l, in, NULL);
    }
    c->ts[thread].media_lit = outer;
    return rgb_mul(lc, vis);
}

/* --------------------------------------------------------------- BRDF terms */

static rgb direct_light(render_ctx *c, int thread, const shade_light_surface *s, const accel_hit *h, vec3 p, rng *r)
{
    rgb total = {0, 0, 0};
    const shade_media_inside *in = frame_inside(c, thread);
    int double_illum = (h->obj->flags & OBJ_DOUBLE_ILLUMINATE) != 0;
    thread_stats *ts = &c->ts[thread];
    if (ts->lc_obj != (const void *)h->obj || ts->lc_p.x != p.x || ts->lc_p.y != p.y || ts->lc_p.z != p.z) {
        ts->lc_obj = h->obj;
        ts->lc_p = p;
        ts->lc_valid = 0;
    }
    for (int i = 0; i < c->sc->nlights; i++) {
        const scene_light *l = &c->sc->lights[i];
        if (!scene_light_reaches(l, h->obj)) continue; /* light_group */
        vec3 dir;
        double depth;
        shade_light_ray(l, l->position, p, &dir, &depth);
        double sdepth = depth; /* shadows are tested up to a projected_through object */
        if (l->projected_through && !shade_projection_pass(c->proj, i, p, dir, depth, &sdepth)) continue;
        /* +Q: area lights from level 5, shadows from 4 (POV-Ray's Q_AREA_LIGHT, Q_SHADOW) */
        int area_on = c->s->quality >= 5, shadows_on = c->s->quality >= 4;
        int full_area = area_on && l->area && l->area_illumination && l->size1 * l->size2 > 0;
        double att = full_area ? 1.0 : shade_light_attenuation(l, p, dir, depth);
        rgb lc = rgb_scale(l->colour, att);
        if (rgb_near_zero(lc)) continue;
        int backside = 0;
        if (!double_illum && !full_area && v3_dot(s->n, dir) < 1e-10) {
            if (s->f->diffuse_back != 0.0) backside = 1;
            else continue;
        }
        if (full_area) {
            /* area_illumination: shade every grid point on its own. */
            int n = l->size1 * l->size2;
            rgb sample_lc = rgb_scale(l->colour, 1.0 / n);
            for (int v = 0; v < l->size2; v++) {
                for (int u = 0; u < l->size1; u++) {
                    vec3 q = v3_add(l->position, scene_light_area_point(l, l->axis1, l->axis2, u, v, r));
                    vec3 d2;
                    double dep2;
                    shade_light_ray(l, q, p, &d2, &dep2);
                    rgb slc = rgb_scale(sample_lc, shade_light_attenuation(l, p, d2, dep2));
                    int back2 = 0;
                    if (!double_illum && v3_dot(s->n, d2) < 1e-10) {
                        if (s->f->diffuse_back != 0.0) back2 = 1;
                        else continue;
                    }
                    if (!l->shadowless && shadows_on) {
                        slc = rgb_mul(slc, shadow_rgb(c, thread, p, d2, dep2, l, in, NULL));
                        if (rgb_near_zero(slc)) continue;
                    }
                    total = rgb_add(total, shade_light_terms(s, d2, slc, back2));
                }
            }
            continue;
        }
        if (!l->shadowless && shadows_on) {
            rgb vis;
            if (i < LIGHT_CACHE && (ts->lc_valid >> i & 1u)) {
                vis = ts->lc_vis[i];
            } else {
                if (area_on && l->area && l->size1 * l->size2 > 1)
                    vis = area_visibility(c, thread, l, p, r, in);
                else
                    vis = shadow_rgb(c, thread, p, dir, sdepth, l, in, NULL);
                if (i < LIGHT_CACHE) {
                    ts->lc_vis[i] = vis;
                    ts->lc_valid |= 1u << i;
                }
            }
            if (rgb_near_zero(vis)) continue;
            lc = rgb_mul(lc, vis);
            /* media_attenuation: fog dims the light on its way (shade_atmos.c;
             * with media, per segment in shadow_rgb) */
            if (l->media_attenuation && l->media_interaction && c->sc->fogs && !media_shadows(c, l))
                lc = rgb_mul(lc, shade_atmos_fog_attenuation(c->sc, p, dir, depth));
        }
        if (l->shadowless && (s->f->phong != 0.0 || s->f->specular != 0.0)) {
            /* POV-Ray: fill lights (shadowless) add no highlights */
            scene_finish ff = *s->f;
            ff.phong = ff.specular = 0.0;
            shade_light_surface fs = *s;
            fs.f = &ff;
            total = rgb_add(total, shade_light_terms(&fs, dir, lc, backside));
            continue;
        }
        total = rgb_add(total, shade_light_terms(s, dir, lc, backside));
    }
    return total;
}

/* ------------------------------------------------------------------ tracing */

/* `skip`: objects with any of these flags are invisible to this ray (no_image
 * for camera rays, no_reflection for reflected rays); `in`: the objects the
 * ray starts inside (shade_media.h). */
static rgb trace_ray(render_ctx *c, int thread, vec3 org, vec3 dir, int level, double weight, unsigned skip, float wavelength,
                     rng *r, const shade_media_inside *in);

/* The surface model (patterns, layers, normals, reflection, refraction,
 * interior fade) is POV-Ray's ComputeLightedTexture in shade_texture.c; it
 * calls back here for rays, direct light and the GI indirect term. */
static rgb tex_cb_trace(void *ctx, int thread, vec3 org, vec3 dir, int level, double weight, unsigned skip, float wavelength,
                        rng *r)
{
    render_ctx *c = ctx;
    c->ts[thread].secondary++;
    const hit_frame *f = c->frame[thread];
    if (!f) return trace_ray(c, thread, org, dir, level, weight, skip, wavelength, r, &no_containers);
    /* a ray going on through the surface (refracted or straight) enters or
     * leaves the object; a reflected one stays where the incoming ray was */
    shade_media_inside in = *f->in;
    /* leaving an object the list does not hold (the camera inside a CSG
     * result, shade_texture.c's ior_setup) does not put the ray inside it */
    int leaving_unlisted = in.n == 0 && v3_dot(f->dir, f->h->ng) > 0.0 && shade_media_inside_find(&in, f->h->obj) < 0;
    if (v3_dot(dir, f->h->ng) * v3_dot(f->dir, f->h->ng) > 0.0 && !leaving_unlisted) shade_media_inside_cross(&in, f->h->obj);
    return trace_ray(c, thread, org, dir, level, weight, skip, wavelength, r, &in);
}

static rgb tex_cb_direct(void *ctx, int thread, const shade_light_surface *s, const accel_hit *h, vec3 p, rng *r)
{
    return direct_light(ctx, thread, s, h, p, r);
}

static rgb tex_cb_indirect(void *ctx, int thread, const accel_hit *h, vec3 n)
{
    render_ctx *c = ctx;
    return c->s->indirect(c->s->indirect_ctx, h, n, thread);
}

static rgb tex_cb_highlights(void *ctx, int thread, const accel_hit *h, const shade_light_surface *s)
{
    render_ctx *c = ctx;
    return c->s->highlights(c->s->highlights_ctx, h, s, thread);
}

static rgb shade_hit(render_ctx *c, int thread, const accel_hit *h, vec3 dir, int level, double weight, unsigned skip,
                     float wavelength, rng *r, const shade_media_inside *in)
{
    const hit_frame *outer = c->frame[thread];
    hit_frame f = {h, dir, in, outer ? outer->depth + 1 : 1};
    shade_tex_env e = {c->sc, c->eps, c->s->use_ambient, c->max_level, c, thread, r, tex_cb_trace, tex_cb_direct,
                 c->s->indirect ? tex_cb_indirect : NULL, &c->ts[thread].unsupported, c->s->quality, in,
                 c->s->highlights ? tex_cb_highlights : NULL, f.depth};
    c->frame[thread] = &f;
    rgb col = shade_tex_shade(&e, h, dir, level, weight, skip, wavelength);
    c->frame[thread] = outer;
    return col;
}

/* What the ray sees besides the surface at depth (INFINITY: none), in
 * POV-Ray's TraceRay order: the containers' media (with a surface), then
 * for a hollow ray the atmosphere's media, rainbows and fog. */
static rgb along_ray(render_ctx *c, int thread, vec3 org, vec3 dir, double depth, rgb col, rng *r, const shade_media_inside *in,
                     const scene_object *hit)
{
    int hollow = shade_media_inside_hollow(in);
    if (!hollow) return col;
    if (c->media && c->s->quality >= 9) { /* +Q: media from level 9 (Q_VOLUME) */
        shade_media_env me = {c->sc, c, thread, r, media_light, hit, c->s->media_photons, c->s->media_photons_ctx};
        if (isfinite(depth) && in->n > 0 && shade_media_inside_has_media(in))
            col = shade_media_segment(&me, SHADE_MEDIA_INTERIOR, in, org, dir, depth, col, 0);
        if (c->sc->natmosphere > 0)
            col = shade_media_segment(&me, SHADE_MEDIA_ATMOSPHERE, in, org, dir, isfinite(depth) ? depth : 2.0e10 /* POV-Ray's BOUND_HUGE */,
                                col, 0);
    }
    return shade_atmos_fog(c->sc, org, dir, depth, col);
}

static rgb trace_ray(render_ctx *c, int thread, vec3 org, vec3 dir, int level, double weight, unsigned skip, float wavelength,
                     rng *r, const shade_media_inside *in)
{
    assert(level >= 1 && thread >= 0 && thread < SHADE_MAX_THREADS);
    if (level > c->max_level) return rgb_make(0, 0, 0);
    accel_hit h;
    /* Past objects this ray must not see (bounded: a pathological stack of
     * such surfaces ends as background). */
    if (accel_intersect_past(c->a, NULL, org, dir, c->eps, skip, &h, NULL) > 0)
        return along_ray(c, thread, org, dir, h.t, shade_hit(c, thread, &h, dir, level, weight, skip, wavelength, r, in), r, in, h.obj);
    return along_ray(c, thread, org, dir, INFINITY, shade_atmos_sky(c->sc, dir), r, in, NULL);
}

/* Distance epsilon: a fixed fraction of the median object size, so that
 * tiny and huge scenes behave alike (single-precision Embree hits carry a
 * relative error near 1e-7 of the coordinates). */
static double scene_eps(const accel *a) { return accel_surface_eps(a); }

rgb shade_trace(const scene *sc, const accel *a, const shade_settings *s, vec3 org, vec3 dir, int thread, rng *r)
{
    thread_stats ts[1];
    memset(ts, 0, sizeof ts);
    render_ctx c = {.sc = sc, .a = a, .s = s, .eps = scene_eps(a),
                    .max_level = s->max_trace_level > 0 ? s->max_trace_level : sc->global.max_trace_level, .ts = ts,
                    .transparent = 1 /* filtered shadows: exact for opaque surfaces too */};
    c.media = shade_media_scene_has(sc);
    c.media_shadow = c.media;
    return trace_ray(&c, 0, org, v3_norm(dir), 1, 1.0, OBJ_NO_IMAGE, 0.0f, r, &no_containers);
}

#define POV_BLOCK 32 /* POV-Ray 3.7's render block (view.cpp, Render_Block_Size) */

void shade_ridged_mf_first(const scene *sc, const accel *a, int width, int height)
{
    func_ridged_mf_reset();
    if (!sc || sc->ridged_mf_callers < 2 || width < 1 || height < 1) return;
    shade_settings s;
    shade_default_settings(&s);
    s.width = width;
    s.height = height;
    s.quality = 8; /* shade.h */
    rng r;
    rng_seed(&r, 0, 0);
    func_ridged_mf_record();
    for (int by = 0; by < height; by += POV_BLOCK)
        for (int bx = 0; bx < width; bx += POV_BLOCK)
            for (int y = by; y < by + POV_BLOCK && y < height; y++)
                for (int x = bx; x < bx + POV_BLOCK && x < width; x++) {
                    vec3 org, dir;
                    if (camera_ray(&sc->camera, x + 0.5, y + 0.5, width, height, 0.0, 0.0, &org, &dir))
                        (void)shade_trace(sc, a, &s, org, dir, 0, &r);
                    if (func_ridged_mf_fixed(NULL, NULL)) return;
                }
    func_ridged_mf_reset();
}

/* --------------------------------------------------------------- the image */

static void pixel_rng(rng *r, uint64_t seed, int x, int y, int pass)
{
    rng_seed(r, pt_mix64(seed * 0x9e3779b97f4a7c15ULL + (uint64_t)pass), ((uint64_t)y << 32) | (uint64_t)x);
}

static rgb primary_ray(render_ctx *c, int thread, double px, double py, vec3 org, vec3 dir, rng *r);

static rgb sample_ray(render_ctx *c, int thread, double px, double py, double lu, double lv, rng *r)
{
    vec3 org, dir;
    /* Every camera type (core/camera.h); no ray (outside a fisheye) is black. */
    if (!camera_ray(&c->sc->camera, px, py, c->s->width, c->s->height, lu, lv, &org, &dir)) return rgb_make(0, 0, 0);
    return primary_ray(c, thread, px, py, org, dir, r);
}

/* mesh_camera with several rays per pixel: the mean of the rays that are
 * shot (POV-Ray 3.7's TracePixel divides by the number traced; none: black). */
static rgb sample_mesh_rays(render_ctx *c, int thread, double px, double py, rng *r)
{
    const scene_camera *cam = &c->sc->camera;
    rgb acc = {0, 0, 0};
    int shot = 0;
    for (int k = 0; k < cam->mesh_rays_per_pixel; k++) {
        vec3 org, dir;
        if (!camera_mesh_ray(cam, px, py, c->s->width, c->s->height, k, &org, &dir)) continue;
        acc = rgb_add(acc, primary_ray(c, thread, px, py, org, dir, r));
        shot++;
    }
    return shot ? rgb_scale(acc, 1.0 / shot) : rgb_make(0, 0, 0);
}

static rgb primary_ray(render_ctx *c, int thread, double px, double py, vec3 org, vec3 dir, rng *r)
{
    assert(v3_finite(org) && v3_finite(dir));
    if (c->sc->camera.normal) {
        /* camera normal: POV-Ray perturbs the direction at the screen point <x0, y0, 0> */
        shade_pattern_ctx pc = shade_pattern_ctx_plain(c->sc);
        vec3 sp = v3(px / c->s->width - 0.5, 0.5 - py / c->s->height, 0.0);
        dir = v3_norm(shade_normal_perturb(c->sc->camera.normal, dir, sp, NULL, &pc));
    }
    c->ts[thread].primary++;
    rgb v = trace_ray(c, thread, org, dir, 1, 1.0, OBJ_NO_IMAGE, 0.0f, r, &c->cam_in);
    if (!isfinite(v.r) || !isfinite(v.g) || !isfinite(v.b)) {
        c->ts[thread].discarded++;
        return rgb_make(0, 0, 0);
    }
    return v;
}

/* The centre sample of pixel (x, y) when the render's primary provider
 * holds its ray and first hit (shade_primary_fn): what sample() gives
 * (sample_ray, primary_ray and trace_ray's first step) without tracing;
 * 0 when it holds none. */
static int sample_known(render_ctx *c, int thread, int x, int y, rng *r, rgb *out)
{
    vec3 org, dir;
    const accel_hit *h;
    if (!c->s->primary(c->s->primary_ctx, x, y, &org, &dir, &h)) return 0;
    c->ts[thread].primary++;
    rgb v;
    if (h)
        v = along_ray(c, thread, org, dir, h->t, shade_hit(c, thread, h, dir, 1, 1.0, OBJ_NO_IMAGE, 0.0f, r, &c->cam_in),
                      r, &c->cam_in, h->obj);
    else
        v = along_ray(c, thread, org, dir, INFINITY, shade_atmos_sky(c->sc, dir), r, &c->cam_in, NULL);
    if (!isfinite(v.r) || !isfinite(v.g) || !isfinite(v.b)) {
        c->ts[thread].discarded++;
        v = rgb_make(0, 0, 0);
    }
    *out = v;
    return 1;
}

static rgb sample(render_ctx *c, int thread, double px, double py, rng *r)
{
    const scene_camera *cam = &c->sc->camera;
    if (cam->kind == CAMERA_MESH && cam->mesh_rays_per_pixel > 1) return sample_mesh_rays(c, thread, px, py, r);
    if (!camera_focal_blur(cam)) return sample_ray(c, thread, px, py, 0.0, 0.0, r);
    /* Focal blur: rays over the lens and the pixel in POV-Ray's batches
     * until the mean is known well enough (shade_focal.h) */
    const shade_focal *f = &c->focal;
    double shift[4]; /* this sample's shift of the lens and pixel sequence */
    for (int k = 0; k < 4; k++) shift[k] = rng_f64(r);
    double s1[3] = {0, 0, 0}, s2[3] = {0, 0, 0};
    int n = 0;
    for (int level = 0; n < f->max; level++) {
        int m = shade_focal_batch(f, level);
        for (int i = 0; i < m && n < f->max; i++, n++) {
            double lu, lv, jx, jy;
            shade_focal_point(n, shift, &lu, &lv, &jx, &jy);
            rgb v = sample_ray(c, thread, px + jx - 0.5, py + jy - 0.5, lu, lv, r);
            s1[0] += v.r; s1[1] += v.g; s1[2] += v.b;
            s2[0] += v.r * v.r; s2[1] += v.g * v.g; s2[2] += v.b * v.b;
        }
        if (shade_focal_done(f, n, s1, s2)) break;
    }
    return rgb_make(s1[0] / n, s1[1] / n, s1[2] / n);
}

#ifndef NDEBUG
static int fb_all_finite(const framebuffer *fb)
{
    for (size_t i = 0; i < (size_t)fb->width * (size_t)fb->height * 3u; i++)
        if (!isfinite(fb->rgb[i])) return 0;
    return 1;
}
#endif

/* Tile `tile` of the image clipped to the rectangle win (x0,y0,x1,y1). */
static void tile_bounds(const render_ctx *c, int tile, const int *win, int *x0, int *y0, int *x1, int *y1)
{
    int tx = tile % c->tiles_x, ty = tile / c->tiles_x;
    *x0 = tx * TILE;
    *y0 = ty * TILE;
    *x1 = *x0 + TILE < c->s->width ? *x0 + TILE : c->s->width;
    *y1 = *y0 + TILE < c->s->height ? *y0 + TILE : c->s->height;
    if (*x0 < win[0]) *x0 = win[0];
    if (*y0 < win[1]) *y0 = win[1];
    if (*x1 > win[2]) *x1 = win[2];
    if (*y1 > win[3]) *y1 = win[3];
    /* an empty tile (x1 <= x0) is allowed; a non-empty one lies in the image */
    assert(*x0 >= 0 && *y0 >= 0 && (*x1 <= *x0 || *x1 <= c->s->width) && (*y1 <= *y0 || *y1 <= c->s->height));
}

/* Pass 1: one ray per pixel centre (or a fixed n x n stratified grid). */
static void tile_first_pass(void *ctx, int tile, int thread)
{
    render_ctx *c = ctx;
    if (c->s->cancel && *c->s->cancel) return;
    int x0, y0, x1, y1;
    tile_bounds(c, tile, c->first_win, &x0, &y0, &x1, &y1);
    int n = 1;
    if (c->s->antialias == 2) {
        n = (int)floor(sqrt((double)(c->s->spp > 1 ? c->s->spp : 1)) + 0.5);
        if (n < 1) n = 1;
    }
    for (int y = y0; y < y1; y++) {
        if (c->s->cancel && *c->s->cancel) return;
        for (int x = x0; x < x1; x++) {
            rng r;
            pixel_rng(&r, c->s->seed, x, y, 0);
            rgb acc = {0, 0, 0};
            if (n == 1) {
                if (!c->primary_on || !sample_known(c, thread, x, y, &r, &acc)) acc = sample(c, thread, x + 0.5, y + 0.5, &r);
            } else {
                for (int j = 0; j < n; j++)
                    for (int i = 0; i < n; i++) {
                        double jx = rng_f64(&r), jy = rng_f64(&r); /* in this order, whatever the compiler */
                        acc = rgb_add(acc, sample(c, thread, x + (i + jx) / n, y + (j + jy) / n, &r));
                    }
                acc = rgb_scale(acc, 1.0 / (n * n));
            }
            /* primary_ray and sample_known discard non-finite samples */
            assert(isfinite(acc.r) && isfinite(acc.g) && isfinite(acc.b));
            float *px = fb_px(c->fb, x, y);
            px[0] = (float)acc.r;
            px[1] = (float)acc.g;
            px[2] = (float)acc.b;
        }
        progress_add(c->s->progress, x1 - x0);
    }
}

/* The colour adaptive antialiasing compares (shade_gamma_aa_value:
 * POV-Ray's Antialias_Gamma curve on the working-space values). */
static rgb aa_encode(const scene *sc, const float *px)
{
    rgb c = {shade_gamma_aa_value(sc, px[0]), shade_gamma_aa_value(sc, px[1]), shade_gamma_aa_value(sc, px[2])};
    return c;
}

/* POV-Ray 3.7's default Render_Block_Size (view.cpp): its +A method 1
 * decides per block of this many pixels square, from the image's corner. */
#define AA_BLOCK 32

/* Pixel (x, y) supersampled: depth x depth jittered rays averaged with its
 * first sample `px`, which it replaces. As POV-Ray's tracetask.cpp
 * (SupersampleOnePixel): grid offsets run from -(1/2 - step/2) by step,
 * accumulated by addition, rows outer; each sample moves by POV-Ray's
 * jitter at (x + offset, y + offset) times the jitter amount over depth.
 * The jitter is a fixed function of position (shade_noise_jitter2d), so
 * two renders of a scene take the same subsamples. */
static void supersample_pixel(render_ctx *c, int thread, int x, int y, float *px)
{
    int d = c->s->aa_depth > 0 ? c->s->aa_depth : 3;
    double step = 1.0 / d, range = 0.5 - step * 0.5, js = c->s->aa_jitter / d;
    rng r;
    pixel_rng(&r, c->s->seed, x, y, 1);
    rgb acc = {px[0], px[1], px[2]};
    double yy = -range;
    for (int j = 0; j < d; j++, yy += step) {
        double xx = -range;
        for (int i = 0; i < d; i++, xx += step) {
            double jx = 0.0, jy = 0.0;
            if (js > 0.0) shade_noise_jitter2d(x + xx, y + yy, &jx, &jy);
            double sx = x + 0.5 + xx + jx * js, sy = y + 0.5 + yy + jy * js;
            acc = rgb_add(acc, sample(c, thread, sx, sy, &r));
        }
    }
    acc = rgb_scale(acc, 1.0 / (d * d + 1));
    px[0] = (float)acc.r;
    px[1] = (float)acc.g;
    px[2] = (float)acc.b;
}

/* The first sample of (x, y), which may lie one pixel outside the image
 * (left of column 0 or above row 0): traced there, as POV-Ray does for a
 * block's neighbours. */
static void first_sample(render_ctx *c, int thread, int x, int y, float *out)
{
    if (x >= 0 && y >= 0) {
        const float *f = c->first + 3 * ((size_t)y * c->s->width + x);
        out[0] = f[0];
        out[1] = f[1];
        out[2] = f[2];
        return;
    }
    rng r;
    /* a stream of its own: (width, y) or (x, height) is no pixel */
    pixel_rng(&r, c->s->seed, x < 0 ? c->s->width : x, y < 0 ? c->s->height : y, 0);
    rgb v = sample(c, thread, x + 0.5, y + 0.5, &r);
    out[0] = (float)v.r;
    out[1] = (float)v.g;
    out[2] = (float)v.b;
}

/* Whether two pixels' encoded colours (aa_encode) differ enough to
 * supersample. Each pixel is encoded once where it is compared several
 * times (with its left and upper neighbours, as either): the encoding is
 * three powers. */
static int aa_differ(const render_ctx *c, rgb a, rgb b) { return shade_colour_distance(a, b) >= c->s->aa_threshold; }

/* Pass 2 of +A: block `block` of the AA_BLOCK grid, in POV-Ray's order. */
static void block_supersample(void *ctx, int k, int thread)
{
    render_ctx *c = ctx;
    if (c->s->cancel && *c->s->cancel) return;
    int block = c->block_order[k];
    int bw = (c->s->width + AA_BLOCK - 1) / AA_BLOCK;
    int X0 = block % bw * AA_BLOCK, Y0 = block / bw * AA_BLOCK;
    int X1 = X0 + AA_BLOCK < c->s->width ? X0 + AA_BLOCK : c->s->width;
    int Y1 = Y0 + AA_BLOCK < c->s->height ? Y0 + AA_BLOCK : c->s->height;
    /* blocks outside the window are not rendered; those it meets are
     * decided whole, as in the whole image */
    if (X1 <= c->win[0] || X0 >= c->win[2] || Y1 <= c->win[1] || Y0 >= c->win[3]) return;
    unsigned char done[AA_BLOCK][AA_BLOCK];
    memset(done, 0, sizeof done);
    float above[AA_BLOCK][3], left[3];
    /* the encodings of the block's pixels as they are now (first samples
     * until supersampled) and of the neighbours above */
    rgb enc[AA_BLOCK][AA_BLOCK], above_e[AA_BLOCK];
    for (int y = Y0; y < Y1; y++)
        for (int x = X0; x < X1; x++) enc[y - Y0][x - X0] = aa_encode(c->sc, fb_px(c->fb, x, y));
    for (int x = X0; x < X1; x++) {
        first_sample(c, thread, x, Y0 - 1, above[x - X0]);
        above_e[x - X0] = aa_encode(c->sc, above[x - X0]);
    }
    for (int y = Y0; y < Y1; y++) {
        if (c->s->cancel && *c->s->cancel) return;
        first_sample(c, thread, X0 - 1, y, left);
        rgb left_e = aa_encode(c->sc, left);
        for (int x = X0; x < X1; x++) {
            int i = x - X0, j = y - Y0;
            float *cur = fb_px(c->fb, x, y);
            float *lp = i > 0 ? fb_px(c->fb, x - 1, y) : left, *tp = j > 0 ? fb_px(c->fb, x, y - 1) : above[i];
            int ldiff = aa_differ(c, i > 0 ? enc[j][i - 1] : left_e, enc[j][i]);
            int tdiff = aa_differ(c, j > 0 ? enc[j - 1][i] : above_e[i], enc[j][i]);
            /* the block's neighbours count as done (POV-Ray's SetFlag) */
            if (ldiff && i > 0 && !done[j][i - 1]) {
                supersample_pixel(c, thread, x - 1, y, lp);
                done[j][i - 1] = 1;
                enc[j][i - 1] = aa_encode(c->sc, lp); /* the next row compares with it */
            }
            if (tdiff && j > 0 && !done[j - 1][i]) {
                supersample_pixel(c, thread, x, y - 1, tp);
                done[j - 1][i] = 1;
                enc[j - 1][i] = aa_encode(c->sc, tp);
            }
            if (ldiff || tdiff) {
                supersample_pixel(c, thread, x, y, cur);
                done[j][i] = 1;
                enc[j][i] = aa_encode(c->sc, cur);
            }
        }
        progress_add(c->s->progress, X1 - X0);
    }
}

typedef struct {
    long cost;
    int block;
} block_cost;

static int cmp_block_cost(const void *x, const void *y)
{
    const block_cost *a = x, *b = y;
    if (a->cost != b->cost) return a->cost < b->cost ? 1 : -1;
    return (a->block > b->block) - (a->block < b->block);
}

/* The cost count of one row of blocks (aa_block_order): jobs write the
 * costs of their own row of blocks only. */
typedef struct {
    const render_ctx *c;
    block_cost *bc;
    int bw;
    volatile int failed; /* a job's scratch could not be allocated */
} order_job;

static void aa_order_band(void *ctx, int br, int thread)
{
    (void)thread;
    order_job *j = ctx;
    const render_ctx *c = j->c;
    int w = c->s->width;
    /* the encoded first samples of the row and of the row above, from the
     * column left of the window on */
    int x0 = c->first_win[0] > 0 ? c->first_win[0] - 1 : 0, x1 = c->first_win[2];
    int y0 = br * AA_BLOCK > c->first_win[1] ? br * AA_BLOCK : c->first_win[1];
    int y1 = (br + 1) * AA_BLOCK < c->first_win[3] ? (br + 1) * AA_BLOCK : c->first_win[3];
    if (y0 >= y1) return;
    rgb *rows = malloc(sizeof *rows * (size_t)w * 2), *row = rows, *up = rows ? rows + w : NULL;
    if (!rows) {
        j->failed = 1;
        return;
    }
    if (y0 > 0)
        for (int x = x0; x < x1; x++) up[x] = aa_encode(c->sc, c->first + 3 * ((size_t)(y0 - 1) * w + x));
    for (int y = y0; y < y1; y++) {
        for (int x = x0; x < x1; x++) row[x] = aa_encode(c->sc, c->first + 3 * ((size_t)y * w + x));
        for (int x = c->first_win[0]; x < x1; x++) {
            int differ = (x > 0 && aa_differ(c, row[x - 1], row[x])) || (y > 0 && aa_differ(c, up[x], row[x]));
            if (differ) j->bc[y / AA_BLOCK * j->bw + x / AA_BLOCK].cost++;
        }
        rgb *t = up;
        up = row;
        row = t;
    }
    free(rows);
}

/* The blocks in the order the threads take them: by the number of pixels
 * whose first sample differs from a neighbour's (about the rays the block
 * will trace), most first, so that no costly block is left to one thread
 * at the end. The order changes no pixel: blocks are independent. The
 * count runs on the render's threads, a row of blocks per job (each
 * encodes the row above its own first: the encodings are three powers a
 * pixel, which one thread took a while over at the end of the first pass). */
static int *aa_block_order(const render_ctx *c, int threads, int bw, int bh)
{
    int nb = bw * bh;
    block_cost *bc = malloc(sizeof *bc * (size_t)nb);
    int *order = malloc(sizeof *order * (size_t)nb);
    if (!bc || !order) {
        free(bc);
        free(order);
        return NULL;
    }
    for (int b = 0; b < nb; b++) bc[b] = (block_cost){0, b};
    order_job j = {c, bc, bw, 0};
    pool_run(threads, bh, aa_order_band, &j);
    if (j.failed) {
        free(bc);
        free(order);
        return NULL;
    }
    qsort(bc, (size_t)nb, sizeof *bc, cmp_block_cost);
    for (int b = 0; b < nb; b++) order[b] = bc[b].block;
    free(bc);
    return order;
}

pt_status shade_render(const scene *sc, const accel *a, const shade_settings *s, framebuffer *fb, shade_stats *st, diag *d)
{
    double t0 = timer_now();
    if (!sc || !a || !s || !fb || fb->width != s->width || fb->height != s->height) {
        diag_report(d, DIAG_ERROR, (src_loc){0}, NULL, "shade_render: bad arguments");
        return PT_ERR_INTERNAL;
    }
    thread_stats *ts = calloc(SHADE_MAX_THREADS, sizeof *ts);
    if (!ts) return PT_ERR_NOMEM;
    int threads = s->threads > 0 ? s->threads : pool_default_threads();
    if (threads > SHADE_MAX_THREADS) threads = SHADE_MAX_THREADS;
    render_ctx c = {.sc = sc, .a = a, .s = s, .eps = scene_eps(a),
                    .max_level = s->max_trace_level > 0 ? s->max_trace_level : sc->global.max_trace_level};
    if (c.max_level < 1) c.max_level = 1;
    c.ts = ts;
    c.fb = fb;
    c.tiles_x = (s->width + TILE - 1) / TILE;
    c.tiles_y = (s->height + TILE - 1) / TILE;
    c.transparent = shade_tex_scene_transparent(sc);
    c.proj = shade_projection_build(sc, d);
    c.media = shade_media_scene_has(sc);
    c.media_shadow = c.media && shade_media_scene_attenuates(sc);
    if (camera_focal_blur(&sc->camera)) shade_focal_init(&c.focal, &sc->camera);
    /* the camera's containers: they set the ior ratios at the surfaces its
     * rays meet, and media and fog act only in hollow ones */
    shade_media_inside_at(sc, sc->camera.location, &c.cam_in);
    int ntiles = c.tiles_x * c.tiles_y;
    const int *sw = s->window;
    int whole = !(sw[2] > sw[0] && sw[3] > sw[1]);
    if (!whole && (sw[0] < 0 || sw[1] < 0 || sw[2] > s->width || sw[3] > s->height)) {
        diag_report(d, DIAG_ERROR, (src_loc){0}, NULL, "shade_render: window outside the image");
        shade_projection_free(c.proj);
        shade_focal_release(&c.focal);
        free(ts);
        return PT_ERR_INTERNAL;
    }
    for (int i = 0; i < 4; i++) c.win[i] = whole ? (i == 2 ? s->width : i == 3 ? s->height : 0) : sw[i];
    for (int i = 0; i < 4; i++) c.first_win[i] = c.win[i];
    if (s->antialias == 1) {
        /* the AA blocks the window meets, and the pixel left of and above
         * each: their decisions read those first samples */
        int bx0 = c.win[0] / AA_BLOCK * AA_BLOCK, by0 = c.win[1] / AA_BLOCK * AA_BLOCK;
        int bx1 = (c.win[2] + AA_BLOCK - 1) / AA_BLOCK * AA_BLOCK, by1 = (c.win[3] + AA_BLOCK - 1) / AA_BLOCK * AA_BLOCK;
        c.first_win[0] = bx0 > 0 ? bx0 - 1 : 0;
        c.first_win[1] = by0 > 0 ? by0 - 1 : 0;
        c.first_win[2] = bx1 < s->width ? bx1 : s->width;
        c.first_win[3] = by1 < s->height ? by1 : s->height;
    }
    /* hits found before the render serve the centre rays of plain cameras
     * (primary_ray perturbs a camera normal's rays, sample() blurs) */
    const scene_camera *cam = &sc->camera;
    c.primary_on = s->primary && s->primary_begin && cam->kind != CAMERA_MESH && !camera_focal_blur(cam) &&
                   !cam->normal && s->primary_begin(s->primary_ctx, sc, a, s->width, s->height, c.eps);

    progress_stage(s->progress, "render",
                   (long long)(c.first_win[2] - c.first_win[0]) * (long long)(c.first_win[3] - c.first_win[1]));
    pool_run(threads, ntiles, tile_first_pass, &c);

    if (s->antialias == 1 && !(s->cancel && *s->cancel)) {
        size_t nv = (size_t)s->width * (size_t)s->height * 3u;
        c.first = malloc(sizeof *c.first * nv);
        if (!c.first) { shade_projection_free(c.proj); shade_focal_release(&c.focal); free(ts); return PT_ERR_NOMEM; }
        memcpy(c.first, fb->rgb, sizeof *c.first * nv);
        int bw = (s->width + AA_BLOCK - 1) / AA_BLOCK, bh = (s->height + AA_BLOCK - 1) / AA_BLOCK;
        /* the pixels of the blocks the window meets (block_supersample) */
        int ax0 = c.win[0] / AA_BLOCK * AA_BLOCK, ay0 = c.win[1] / AA_BLOCK * AA_BLOCK;
        progress_stage(s->progress, "antialias", (long long)(c.first_win[2] - ax0) * (long long)(c.first_win[3] - ay0));
        c.block_order = aa_block_order(&c, threads, bw, bh);
        if (!c.block_order) { free(c.first); shade_projection_free(c.proj); shade_focal_release(&c.focal); free(ts); return PT_ERR_NOMEM; }
        pool_run(threads, bw * bh, block_supersample, &c);
        free(c.block_order);
        free(c.first);
    }

    if (!whole) /* the apron is not part of the window */
        for (int y = 0; y < s->height; y++)
            for (int x = 0; x < s->width; x++)
                if (x < c.win[0] || x >= c.win[2] || y < c.win[1] || y >= c.win[3]) {
                    float *px = fb_px(fb, x, y);
                    px[0] = px[1] = px[2] = 0.0f;
                }
    shade_gamma_fb_to_linear(sc, fb, threads); /* assumed_gamma: working space -> linear (shade_gamma.c) */
    long fixed = fb_sanitize(fb);
    assert(fb_all_finite(fb)); /* no NaN or Inf reaches a framebuffer */
    if (st) {
        memset(st, 0, sizeof *st);
        for (int i = 0; i < SHADE_MAX_THREADS; i++) {
            st->primary_rays += ts[i].primary;
            st->shadow_rays += ts[i].shadow;
            st->secondary_rays += ts[i].secondary;
            st->discarded_samples += ts[i].discarded;
            st->unsupported += ts[i].unsupported;
        }
        st->discarded_samples += fixed;
        st->seconds = timer_now() - t0;
    }
    shade_projection_free(c.proj);
    shade_focal_release(&c.focal);
    free(ts);
    return PT_OK;
}

/* ------------------------------------------------------ for shade_aov.c */

rgb shade_direct(const scene *sc, const accel *a, const shade_light_surface *s, const accel_hit *h, vec3 p, rng *r)
{
    thread_stats ts[1];
    memset(ts, 0, sizeof ts);
    shade_settings ss;
    shade_default_settings(&ss);
    render_ctx c = {.sc = sc, .a = a, .s = &ss, .eps = scene_eps(a), .max_level = 1, .ts = ts};
    c.transparent = 1; /* filtered shadows, as shade_trace: exact for opaque surfaces too */
    return direct_light(&c, 0, s, h, p, r);
}
