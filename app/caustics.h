/* caustics.h - the caustic layer (gi/gi_caustic.h) wired to the shader: its
 * material and light hooks from shade/ (the one BSDF of shade_material.h,
 * shade_light_attenuation), what the scene's photon settings ask that is
 * not modelled (counted and warned once), and the indirect hook that adds
 * the layer to `--gi none` and `--gi particle`. */
#ifndef PT_CAUSTICS_H
#define PT_CAUSTICS_H
#include "accel.h"
#include "diag.h"
#include "gi_caustic.h"
#include "scene.h"
#include "shade.h"
#include "stats_json.h"

/* Photon settings a scene uses that the caustic layer does not model: 1
 * where used (each also warned once by caustics_build). */
typedef struct {
    int gather, radius, expand_thresholds, autostop, save_file, load_file;
    int dispersion;     /* a target's interior has dispersion (photons carry no wavelength) */
} caustics_not_modelled;

typedef struct {
    gi_caustic *layer;  /* NULL: the scene shoots no photons (or the mode takes none) */
    gi_caustic_stats st;
    caustics_not_modelled nm;
    int asked;          /* the scene has an enabled global photons block */
    /* the indirect hook chained behind the layer's (particle GI), NULL none */
    shade_indirect_fn next;
    void *next_ctx;
    const scene *sc;    /* the hooks' scene and offset epsilon (shade.c's rule) */
    double eps;
    double scale;       /* the scene's working scale (accel_eps_scale) */
    int roulette;       /* 1: seed 002's Russian roulette at each bounce instead of POV-Ray's weights */
} caustics;

/* Builds the layer (c must stay where it is while the layer is used: it
 * is the hooks' context) for a w x h image when the scene asks for photons;
 * fills c (c->layer NULL when nothing shoots). count_scale: photons times
 * this (0: the scene's). roulette: 1 ends photons by the paper's Russian
 * roulette at each surface (appendix A) instead of POV-Ray's weights (see
 * hook_surface in caustics.c); the same expected light, more noise. */
pt_status caustics_build(caustics *c, const scene *sc, const accel *a, int width, int height, int threads,
                         uint64_t seed, const char *cl_device, size_t cl_max_bytes, double count_scale,
                         int roulette, volatile int *cancel, diag *d);
/* Puts the layer into shade settings: its indirect hook (after whatever
 * hook ss has: that one is kept and summed), POV-Ray's photon shadows and,
 * when the layer holds media photons, the media's photon hook. */
void caustics_attach(caustics *c, shade_settings *ss);
/* The highlights (specular, phong) that the photons near h give the layer
 * surface s, each photon shaded as a light (POV-Ray's gather, trace.cpp
 * ComputePhotonDiffuseLight; the Lambertian share comes through the
 * indirect hook); shade_highlight_fn-compatible with c as the context. */
rgb caustics_highlights(void *c, const accel_hit *h, const shade_light_surface *s, int thread);
void caustics_free(caustics *c);
/* "caustics": {...} in the stats (nothing when the scene asked for none). */
void caustics_json(caustics *c, stats_json *js);

#endif
