/* pm_photon.h - photon tracing for pmfg (Jensen 1996; seed 002, appendix A:
 * emission in proportion to power, Russian roulette at every bounce with
 * the surface's scatter probability, power scaled by reflectance/probability).
 *
 * Sources: every POV-Ray light type (point, spot, cylinder, parallel, area
 * grids), the emissive surfaces, and a non-black background. The photons
 * carry only the light that next-event estimation does not: a photon's
 * first hit after leaving a light source or an emitter is not stored (that
 * direct light is computed by shadow rays, pm_nee.h); photons of the
 * background (no NEE) are stored from their first hit on.
 *
 * Power normalisation (POV-Ray units, derived in pm_photon.c): a POV-Ray
 * light of colour C gives irradiance E = pi * C * att * cos at any distance,
 * i.e. a point source of distance-dependent intensity I(d) = pi C att(d) d^2.
 * A photon leaving it along w (density p(w)) and first hitting at distance
 * d gets power  Phi = pi C att(d) d^2 / (N p(w)),  so the photon density
 * times Phi reproduces exactly the E that shade.c's diffuse term uses.
 * Without fade_power these lights are not physical (their total power grows
 * with the scene size); the indirect light is still the one the NEE direct
 * light implies, because every photon's power is fixed at its first hit.
 *
 * Maps: global = photons stored at surfaces with a Lambertian lobe after at
 * least one bounce (all path types); caustic = photons from POV-Ray lights
 * that reached a Lambertian surface through specular bounces only (L S+ D).
 * POV-Ray lights are invisible to BSDF rays, so the path tracer cannot find
 * L S+ ... paths from them; with caustics off, photons from POV-Ray lights
 * whose first bounce is specular are dropped so that pmfg and path converge
 * to the same image. With caustics on (default when the scene has a
 * global photons{} block, which is how POV-Ray asks for caustics) those
 * paths are kept: pmfg then shows caustics that path cannot. Per-object
 * photons { } blocks (scene_obj_photons) as POV-Ray 3.7 reads them: when
 * any object is a `target`, a caustic path (POV-Ray light, specular bounces
 * only) reflects or refracts only at targets where the block and the
 * light's photons { } allow that lobe (scene_photon_lobe: the object says
 * on and the light not off, or the light on and the object not off; other
 * such photons end); without any target every
 * specular surface acts as one (partray's choice, POV-Ray would shoot no
 * caustic photons). `collect off`: never stored on that object;
 * `pass_through`: photons go through it unchanged. Photons are still
 * emitted in all directions, not aimed at the targets' bounding spheres as
 * POV-Ray does (the same estimate, more photons wasted), and the target's
 * spacing multiplier is not used. */
#ifndef PT_PM_PHOTON_H
#define PT_PM_PHOTON_H
#include "accel.h"
#include "pm.h"
#include "pm_kdtree.h"
#include "pm_nee.h"

typedef struct {
    long photons;        /* photon paths emitted (all sources together) */
    int caustics;        /* 1: keep L S+ D paths of POV-Ray lights and fill the caustic map */
    int max_bounces;     /* hard cap on bounces (Russian roulette ends most paths first;
                            past 8 bounces paths also survive with probability 0.8, power / 0.8) */
    uint64_t seed;
    int threads;
    volatile int *cancel;
    progress *progress;  /* its current stage counts the chunks of photon paths traced (NULL: none) */
    int emitters_first;  /* 1: emissive surfaces' photons carry light from their first hit, as the
                            background's do (an estimator without next-event estimation of emitters) */
} pm_photon_settings;

typedef struct {
    pm_photon *global;
    long nglobal;
    pm_photon *caustic;
    long ncaustic;
    long emitted;        /* photon paths actually emitted */
    long rays;           /* segments traced */
    long dropped;        /* photons not stored: the memory cap on stored photons was reached */
    int sources;
    int targets;         /* some object has photons { target } */
    vec3 centre;         /* the sphere the background's and parallel lights' photons are aimed across */
    double radius;       /* (the finite geometry's bounds): beyond it they never land */
} pm_photon_result;

/* Trace. The arrays in `out` are malloc'd (ownership passes to the caller,
 * e.g. to pm_kdtree_build). Deterministic for a given seed, independent of
 * the thread count. */
pt_status pm_photons_trace(const scene *sc, const accel *a, const pm_lights *L, const pm_photon_settings *s,
                           pm_photon_result *out);

/* Photon paths one at a time, for an estimator that keeps them (pm_detp.h).
 * A launch is where a segment of a path starts, with all that tracing the
 * path on from there needs; segment 0 (emission) is resumed by emitting
 * path `index` again. */
typedef struct {
    vec3 o, w;        /* origin and unit direction */
    rgb phi;          /* the path's power along it (segment 0: as emitted, known after its hit) */
    rng r;            /* the path's random stream where the segment starts (segment 0: the seed) */
    accel_from from;  /* the surface it leaves (obj NULL: none) */
    unsigned skip;    /* OBJ_* flags of the objects it passes through */
    int source;       /* which source emitted the path */
    int bounce;       /* surfaces the path met before (0: emission) */
    int nd;           /* diffuse bounces before */
    int spec_only;    /* only specular bounces so far */
    double d1, plen;  /* a light's path: its first hit's distance, its length to where the segment starts */
} pm_photon_launch;
/* One segment traced: its launch, its hit (NULL: left the scene) and the
 * power a receiver it crosses takes: the power the global map would store
 * at a Lambertian hit (after the first bounce, or from the start for the
 * background's photons; brightness^g while the light may still be
 * gathered), 0 otherwise. */
typedef void (*pm_photon_seg_fn)(void *ctx, long index, const pm_photon_launch *l, const accel_hit *h, rgb carried);

typedef struct pm_photon_walker pm_photon_walker;
/* The sources of sc with s->photons shared among them as pm_photons_trace
 * shares them; bounds (lo, hi; NULL: the accel's) fix the allocation
 * proxies and where parallel lights' and the background's photons are aimed,
 * and eps (0: pm_lights_eps(L)) the distance rays start off surfaces, so
 * that a later frame can keep the first frame's (both follow the scene's
 * extent, which moving objects change). *paths: the paths [0, *paths)
 * there are. The scene, accel and L must outlive it. */
pm_photon_walker *pm_photon_walker_new(const scene *sc, const accel *a, const pm_lights *L, const pm_photon_settings *s,
                                       const vec3 *bounds, double eps, long *paths, pt_status *st);
/* Path `index` from its source (resume NULL) or from a launch fn saw (its
 * `from` object in this walker's scene). Thread-safe; *rays counts the
 * intersection queries. */
void pm_photon_walk(const pm_photon_walker *w, long index, const pm_photon_launch *resume, pm_photon_seg_fn fn, void *ctx,
                    long *rays);
void pm_photon_walker_free(pm_photon_walker *w);

#endif
