/* pm_fg.h - photon mapping with final gathering (Jensen 1996; the
 * "RT/PM/FG" reference of seed 000, section 5, with 4,096 gather rays):
 *
 *  1. photons (pm_photon.h) from every light type into a global and, when
 *     caustics are on, a caustic map; kd-trees built in parallel;
 *  2. irradiance precomputed at every n-th global photon (Christensen 1999,
 *     "Faster photon map global illumination"), looked up at gather hits by
 *     the nearest precomputed point with a compatible normal;
 *  3. eye pass: at each eye vertex (camera hit, then through specular
 *     reflection/refraction, both branches followed while the weight
 *     matters) emission, direct light by shadow rays (pm_nee.h, shared with
 *     the path tracer: POV-Ray lights with area_samples stratified samples,
 *     emitters with emitter_samples samples and MIS against the gather rays),
 *     the caustic map at the eye hit, and a final gather of cosine-weighted,
 *     stratified rays over the Lambertian lobes. At a gather hit: the hit's
 *     own emission (MIS-weighted), its direct light by one shadow ray to a
 *     light picked at random and one to an emitter, the global-map
 *     irradiance times its Lambertian albedo, and its specular lobes
 *     followed by Russian roulette.
 *
 * The photon maps hold only light that NEE does not (pm_photon.h), so the
 * direct light of pmfg is the NEE term of the path tracer, and both converge
 * to shade_material.h's model (with caustics off; see pm_photon.h for what
 * caustics on adds). POV-Ray's photons{} options (spacing, count, per-object
 * targets) are not read; only the presence of a global photons{} block
 * switches caustics on by default. */
#ifndef PT_PM_FG_H
#define PT_PM_FG_H
#include "accel.h"
#include "pm.h"

typedef struct {
    pm_common c;             /* c.spp: eye samples per pixel (default 64, stratified: edges antialiased) */
    long photons;            /* photon paths emitted (default 1,000,000) */
    int fg_rays;             /* final-gather rays per pixel (default 4096), split evenly over the
                                eye samples; fewer at eye vertices behind weak specular lobes */
    int k_global;            /* photons per irradiance estimate (default 64) */
    int k_caustic;           /* photons per caustic estimate (default 32) */
    double radius_global;    /* largest search radius; 0 = 0.1 x the scene size */
    double radius_caustic;   /* 0 = 0.02 x the scene size */
    int irradiance_stride;   /* precompute at every n-th global photon (default 4); 0 = full
                                k-nearest estimate at every gather hit (slow, for checks) */
    int caustics;            /* -1 (default): on when the scene has a photons{} block; 0 off; 1 on */
    int area_samples;        /* shadow rays per area light at an eye vertex (default 4; 256 per pixel) */
    int emitter_samples;     /* emitter samples at an eye vertex (default 4) */
    int max_eye_depth;       /* specular eye vertices (default 16) */
    int max_gather_depth;    /* specular bounces after a gather hit (default 8) */
    int max_photon_bounces;  /* default 256 */
} pm_fg_settings;

void pm_fg_default_settings(pm_fg_settings *s);

/* Render into fb. Stats: t_lights, t_photons, t_maps, t_irradiance,
 * t_render, t_total, photon and ray counts, caustic_map and its reason. */
pt_status pm_fg_render(const scene *sc, const accel *a, const pm_fg_settings *s, framebuffer *fb, pm_stats *st,
                       diag *d);

#endif
