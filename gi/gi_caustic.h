/* gi_caustic.h - the caustic layer: POV-Ray's photons{} rendered by
 * image-space photon mapping (McGuire and Luebke, HPG 2009, seed 002).
 *
 * What the scene asks for (POV-Ray 3.7 semantics, core/scene_settings.h and
 * scene_light.h): every light shoots photons at every object marked
 * photons { target } for which their merged flags allow reflection or
 * refraction (scene_photon_shoots); a photon's first hit must be that
 * target (pass_through objects and no_shadow objects are passed; any other
 * object ends it; past the target only no_shadow objects are passed),
 * later hits reflect or refract where scene_photon_lobe
 * allows, and every hit after the first on a surface with a Lambertian
 * term and `collect` on stores a photon. Photon count: the global spacing
 * (times the target's multiplier) is the distance between neighbouring
 * photons at the target, as POV-Ray's shooting grid spaces them; `count N`
 * scales the spacing so that POV-Ray's own estimate of the number shot is
 * N (photonestimationtask.cpp). Power: POV-Ray's lights do not fall off with
 * distance, so a photon carries the light's colour times the area its
 * direction cell covers at its path length D (colour x solid angle x D^2,
 * times fade at D and the spot/cylinder attenuation), POV-Ray's
 * addSurfacePhoton rule; parallel lights colour x cell area.
 *
 * The method (the paper's algorithm, section 2 of the digest):
 *  1. bounce map, per light and target: one photon per cell of a grid over
 *     the cone of directions that holds the target's bounding sphere
 *     (POV-Ray's box, geom_extent), equal solid angle per cell (so no
 *     inverse-cosine correction is needed), jittered by the scene's
 *     `jitter`; Embree finds the first hit; the photon goes on along each
 *     specular lobe of the surface (its reflection and its refraction
 *     where it has both, as POV-Ray's photon tracer traces both), weighted
 *     by the lobe (through the hooks: the one BSDF of shade_material.h),
 *     and ends where the surface has none (counted); what the surface
 *     absorbs is lost as weight, as in POV-Ray, not by the paper's Russian
 *     roulette (appendix A), whose survivors were noisier;
 *  2. world-space tracing of the further bounces, storing a photon before
 *     each bounce on a receiving surface (bounce-map photons are not
 *     stored), splitting at each, up to the photons' max_trace_level and
 *     adc_bailout;
 *  3. path density rho_p, the product over bounces of the hook's density
 *     factor (the paper's factor rho_S, which a roulette over the lobes
 *     would give each lobe; 1 where every lobe is followed, as now), sets
 *     the photon volume's radius: r_xy = k s_D / sqrt(rho_p), with s_D the spacing of the
 *     photon's direction cell at its path length (the distance to its
 *     neighbours had nothing focused it) and k = 9 (gi_caustic.c says
 *     why); r_z, along the normal, is as far as POV-Ray's flattened
 *     gather sphere reaches off the surface (gi_caustic.c, normal_reach);
 *  4. eye G-buffer (paper step 2): the first receiving surface through each
 *     pixel centre (non-receiving surfaces, e.g. clear glass, are passed
 *     straight, so what lies behind them is in the buffer too);
 *  5. the photon volumes scattered over the G-buffer (paper step 4,
 *     equations 1-3) by the OpenCL kernel gi_k_caustic_splat
 *     (gi/kernels/gi_caustic.cl; the C build runs the same code).
 * The shader asks gi_caustic_at at every diffuse hit: a hit near a G-buffer
 * point of the same object takes the splatted value of the nearest such
 * points (weighted by distance within their pixel footprint); elsewhere
 * (caustics seen in mirrors or through glass away from the G-buffer) the
 * same photon volume sum is evaluated at the hit from the photon grid.
 * Both counts are in the stats.
 *
 * Media photons (global photons { media max_steps [, factor] }, POV-Ray
 * 3.7's photons.cpp DepositMediaPhotons): along every straight segment of
 * a photon's path after its first surface, inside hollow containers whose
 * media take photons (hooks.media), photons are left at n evenly jittered
 * places, n = floor(len / (factor s_D)) at most max_steps (s_D the
 * photon's spacing at the segment's start; beyond max_steps the step
 * grows to len / n), each carrying the photon's colour times its cell's
 * cross-section and its step along the way; the media sum them over a
 * sphere (gi_caustic_media_visit). Photons are dimmed by the media's
 * extinction over every segment.
 *
 * Not modelled (the caller reports what the scene uses):
 * dispersion, the gather/radius/expand_thresholds/autostop settings (the
 * radius comes from the heuristic above; the bounce map covers the whole
 * cone, so autostop has nothing to cut short), save_file/load_file, light
 * groups beyond scene_light_reaches at the storing surface. */
#ifndef PT_GI_CAUSTIC_H
#define PT_GI_CAUSTIC_H
#include <stdint.h>
#include "accel.h"
#include "diag.h"
#include "rng.h"
#include "scene.h"
#include "kernels/gi_types.h"

typedef struct gi_caustic gi_caustic;

/* The objects a photon is inside, innermost last (POV-Ray's interior list:
 * it sets the ior ratio of each refraction); filled by the hooks, which
 * know when two objects share an interior. */
#define GI_CAUSTIC_MAX_INSIDE 16
typedef struct {
    int n;
    const scene_object *obj[GI_CAUSTIC_MAX_INSIDE];
} gi_caustic_inside;

/* A specular bounce that the photon continues along. */
typedef struct {
    vec3 org, dir;   /* continuation ray, origin off the right side */
    rgb weight;      /* flux multiplier: the lobe's colour (and fade, filter) */
    double rho;      /* the photons' density factor of this bounce (1: no photon of the bounce is dropped), for
                        the path density */
    int refract;     /* 1 refraction, 0 reflection */
    accel_from from; /* the surface left */
    gi_caustic_inside inside; /* the containers after the bounce */
    double trace_w;  /* the factor of POV-Ray's photon ray weight over this bounce (not the flux: the photon
                        ends when the product falls under adc_bailout) */
} gi_caustic_step;

/* GI_CAUSTIC_CONTINUES: step[0] holds the bounce; GI_CAUSTIC_SPLIT as well:
 * step[1] holds a second one (reflection and refraction both). */
/* GI_CAUSTIC_HIGHLIGHTS: the surface has no Lambertian term but a
 * specular or phong highlight (clear glass): a photon arriving there is
 * stored for gi_caustic_visit only (POV-Ray gathers the photons at every
 * surface with diffuse, specular or phong and shades each through the
 * highlight as a light: trace.cpp, ComputePhotonDiffuseLight), never
 * splatted or summed as irradiance. */
enum { GI_CAUSTIC_RECEIVES = 1, GI_CAUSTIC_CONTINUES = 2, GI_CAUSTIC_SPLIT = 4, GI_CAUSTIC_HIGHLIGHTS = 8 };

/* The material and light model, from app/ (gi/ cannot reach shade/). */
typedef struct {
    /* The surface at h for a photon or eye ray arriving along unit dir
     * inside the objects `in` (NULL: the atmosphere):
     * GI_CAUSTIC_RECEIVES when it has a Lambertian term (photons light it),
     * GI_CAUSTIC_HIGHLIGHTS when it has only a highlight;
     * with step non-NULL (room for 2), the bounces the photon goes on
     * along: its mirror reflection and its refraction where the surface
     * has both, as POV-Ray's photon tracer traces both (photons.cpp), each
     * weighted by its lobe (what is absorbed, or taken by a Lambertian or
     * glossy lobe, is lost as weight: no roulette noise); none (no
     * GI_CAUSTIC_CONTINUES) where the surface has no specular lobe. */
    int (*surface)(void *ctx, const accel_hit *h, vec3 dir, const gi_caustic_inside *in, rng *r,
                   gi_caustic_step *step);
    /* Light l's angle and distance attenuation at point p (first hit of a
     * photon) for path length depth (shade_light_attenuation). */
    double (*attenuation)(void *ctx, const scene_light *l, vec3 p, double depth);
    void *ctx;
    /* The brilliance of the receiving finish at h seen along unit dir (the
     * photons' weight, gi_caus_add), and in *back its diffuse_back as a
     * fraction of its diffuse (0: none; photons arriving on the other side
     * light it times that); NULL: brilliance 1, back 0. */
    double (*brilliance)(void *ctx, const accel_hit *h, vec3 dir, double *back);
    /* A pass_through object met before the target: step->weight is what
     * the surface lets through and step->inside the containers crossed
     * (the photon goes on along the same ray); 0 when nothing passes.
     * NULL: the photon ends there. */
    int (*pass)(void *ctx, const accel_hit *h, vec3 dir, const gi_caustic_inside *in, gi_caustic_step *step);
    /* The objects holding point p (the light's position), innermost last:
     * the list a photon starts with. NULL: none. */
    void (*containers)(void *ctx, vec3 p, gi_caustic_inside *in);
    /* The participating media of the containers `in` over the photon's
     * segment org + t dir, 0 <= t <= len (unit dir): *tr the light left
     * after their extinction over it (POV-Ray's photon rays are dimmed by
     * the media of the interiors they cross, photons.cpp,
     * ComputeLightedTexture); returns 1 when the segment is hollow and its
     * media take photons (some media scatters and has collect on, and
     * some absorbs or scatters: POV-Ray's ComputeMediaAndDepositPhotons
     * returns early without extinction). NULL: no media. */
    int (*media)(void *ctx, const gi_caustic_inside *in, vec3 org, vec3 dir, double len, rgb *tr);
    /* The fade of h's interior over h->t for a photon arriving along unit
     * dir from inside h's object (1 from outside): the colour the photon
     * is stored with at h, before it bounces (POV-Ray 3.7's photons.cpp,
     * PhotonTrace::ComputeLightedTexture fades LightCol by the hit
     * object's interior, then adds the surface photon). The bounces'
     * weights carry the same fade. NULL: none. */
    rgb (*fade)(void *ctx, const accel_hit *h, vec3 dir);
} gi_caustic_hooks;

typedef struct {
    int width, height;      /* the G-buffer: the image's size */
    int threads;            /* <= 0: all cores */
    uint64_t seed;
    const char *cl_device;  /* gi_cl.h's device choice (NULL: auto) */
    size_t cl_max_bytes;
    double count_scale;     /* photons times this (spacing / sqrt); 0 or 1: the scene's */
    volatile int *cancel;
} gi_caustic_settings;

#define GI_CAUSTIC_MAX_BOUNCES 16
typedef struct {
    int combos;             /* light-target pairs that shoot */
    long emitted;           /* bounce-map cells (photons shot) */
    long first_hits;        /* photons whose first hit was their target */
    long absorbed_first;    /* of those, ended at the bounce map (their target has no specular lobe there) */
    long alive[GI_CAUSTIC_MAX_BOUNCES + 1]; /* branches going on after bounce b (b = 1: the bounce map; a
                                               split counts once, so later bounces can exceed the first) */
    int max_bounce;         /* highest b with alive[b] > 0 */
    long stored;            /* photon volumes (splatted) */
    long stored_highlights; /* photons on surfaces with only a highlight (gi_caustic_visit's alone) */
    long stored_media;      /* media photons (global photons { media steps }) */
    double r_media_median;  /* median radius of the media photons' spheres */
    long media_thinned;     /* 1, or the largest factor by which a chunk of photons thinned its media photons to
                               stay within the layer's limit (each kept one carrying that many's power) */
    double flux;            /* their power, summed (grey: mean of the channels) */
    long rays;
    double spacing;         /* the global spacing used (count and count_scale applied) */
    double r_median;        /* median r_xy (after the widening) */
    long widened;           /* photon volumes widened to hold the gather minimum (gi_caustic.c, GATHER_MIN) */
    long tile_entries;      /* (photon, tile) pairs the splat visits */
    long lookups_gbuffer, lookups_photons; /* gi_caustic_at answers from the G-buffer / from the photons */
    double t_trace, t_gbuffer, t_bin, t_splat; /* seconds */
    char device[300];
} gi_caustic_stats;

/* NULL with *status PT_OK when the scene shoots no photons (no enabled
 * global photons block, or no light-target pair). */
gi_caustic *gi_caustic_build(const scene *sc, const accel *a, const gi_caustic_settings *s, const gi_caustic_hooks *hk,
                             diag *d, pt_status *status);
void gi_caustic_free(gi_caustic *c);
/* The stats so far (lookups keep counting during the render). */
void gi_caustic_get_stats(const gi_caustic *c, gi_caustic_stats *st);
/* Irradiance (E/pi units: what diffuse * pigment multiplies) of the caustic
 * layer at hit h, n facing the viewer; shade_indirect_fn-compatible with c
 * as the context. Thread-safe. */
rgb gi_caustic_at(void *c, const accel_hit *h, vec3 n, int thread);
/* The photon volumes' sum at point p alone (gi_caustic_at's answer away
 * from the G-buffer), n the side's normal, brilliance and back (B / A of
 * diffuse_back: the weight of photons arriving on the other side) of the
 * surface there; E/pi. Any point, not only one the camera sees: the
 * particle GI takes the caustics' light into its bounces with it. The
 * caller checks photons { collect off }. Thread-safe. */
rgb gi_caustic_world_at(const gi_caustic *c, vec3 p, vec3 n, double brilliance, double back);
/* Every stored photon (on receivers and on highlight-only surfaces alike)
 * whose volume holds hit h's point and that arrives on the side of n (n
 * facing the viewer), unless h's object has photons { collect off }: fn
 * gets w, the unit direction back towards where the photon came from (as
 * stored), and e = Phi kappa / max(w.n, 0.1), the photon as a light of
 * colour e along w (POV-Ray's gather: a photon's colour over the gather
 * disc's area, times 1 / cos at most tenfold; trace.cpp,
 * ComputePhotonDiffuseLight). Summed through a Lambertian term e c gives
 * gi_caustic_at's irradiance; the caller adds the highlights. Thread-safe. */
typedef void (*gi_caustic_visit_fn)(void *ctx, vec3 w, rgb e);
void gi_caustic_visit(const gi_caustic *c, const accel_hit *h, vec3 n, gi_caustic_visit_fn fn, void *ctx);
/* Media photons (POV-Ray 3.7's global photons { media max_steps, factor }):
 * every media photon whose sphere holds p. fn gets w, the unit direction
 * back towards where the photon came from (as stored), and e = Phi kappa,
 * kappa = 3 (1 - d/r) / (pi r^3) the normalised cone over the photon's
 * sphere of radius r at distance d: the photon as a light of colour e
 * along w at p. The media shade each through its scattering and phase
 * function as a light (POV-Ray's media.cpp, ComputeMediaPhotons: the
 * photons' colours over the gather sphere's volume, each through
 * ComputeMediaScatteringAttenuation). Thread-safe. */
void gi_caustic_media_visit(const gi_caustic *c, vec3 p, gi_caustic_visit_fn fn, void *ctx);
/* The media photons stored (NULL and 0 when none). */
const gi_caus_photon *gi_caustic_media_photons(const gi_caustic *c, long *n);
/* The stored photon volumes (those splatted). */
const gi_caus_photon *gi_caustic_photons(const gi_caustic *c, long *n);
/* The splat's result: 4 floats per G-buffer pixel (row-major, y down), and
 * the G-buffer. */
const float *gi_caustic_image(const gi_caustic *c);
const gi_caus_pixel *gi_caustic_gbuffer(const gi_caustic *c);
/* The tile binning and the splat run again (bench: their time, seconds). */
pt_status gi_caustic_resplat(gi_caustic *c, double *t_bin, double *t_splat, diag *d);

#endif
