/* pm_nee.h - next-event estimation shared by the path tracer and the final
 * gatherer: POV-Ray light sources (shade_light.h's shade_light_nee: the same terms
 * and attenuation as shade.c, area lights sampled continuously) and emissive
 * surfaces (sampled by area with accel_surface.h, combined with BSDF
 * sampling by multiple importance sampling, Veach & Guibas 1995, power
 * heuristic with sample counts).
 *
 * POV-Ray lights are invisible to camera and BSDF rays (looks_like is
 * ignored): they are reached by next-event estimation only. Emissive
 * surfaces (pigment * emission, plus ambient in scenes below #version 3.7:
 * core/radrules.h) are found both ways. */
#ifndef PT_PM_NEE_H
#define PT_PM_NEE_H
#include "accel.h"
#include "accel_surface.h"
#include "diag.h"
#include "pm.h"
#include "rng.h"
#include "scene.h"
#include "shade_material.h"

typedef struct pm_lights pm_lights;

pm_lights *pm_lights_new(const scene *sc, const accel *a, diag *d, pt_status *st);
void pm_lights_free(pm_lights *L);

/* What a reference renderer's stages after the light set work on. */
typedef struct {
    const scene *sc;
    const accel *a;
    framebuffer *fb;
    diag *d;
    const pm_lights *L;
    pm_stats *st; /* zeroed, then emitter_pieces and t_lights filled */
} pm_job;
typedef pt_status (*pm_run_fn)(const pm_job *j, const void *settings);
/* The frame of a reference render (pm_path.c, pm_fg.c): zeroes *st (a local
 * one when st is NULL), builds the light set (st->emitter_pieces,
 * st->t_lights), calls run, sets st->t_total and frees the light set.
 * PT_ERR_INTERNAL when sc, a, fb or settings is NULL. */
pt_status pm_lights_run(const scene *sc, const accel *a, framebuffer *fb, pm_stats *st, diag *d, pm_run_fn run,
                        const void *settings);

const accel_surf *pm_lights_emitters(const pm_lights *L); /* may be empty */
/* Le at an emitter sample (evaluated at the point when the texture varies). */
rgb pm_lights_piece_emission(const pm_lights *L, const accel_surf_sample *s);
double pm_lights_eps(const pm_lights *L);                  /* distance epsilon (shade.c's) */
/* Radiance arriving along a ray of direction dir (any length) that leaves
 * the scene: the sky_sphere over the background, evaluated by shade's
 * shade_atmos_sky (the code --gi none uses; fog and rainbow are not applied). It
 * is emitted radiance of the environment, reached by camera, BSDF and
 * gather rays that escape, and the source of environment photons. */
rgb pm_sky(const scene *sc, vec3 dir);
/* 1 when pm_sky can be non-zero (a background colour or a sky_sphere). */
int pm_sky_any(const scene *sc);
/* Whether some object has photons { target } (a CSG's block reaches its
 * members). */
int pm_any_target(const scene *sc);

/* Direct light of all POV-Ray light sources at b (diffuse, diffuse_back,
 * phong, specular), area lights with `area_samples` stratified samples. */
rgb pm_direct_lights(const pm_lights *L, const shade_mat_bsdf *b, int area_samples, rng *r, long *shadow_rays);

/* The same estimated with one light chosen at random, with probability
 * proportional to max-channel(colour) * attenuation seen from b (spot,
 * cylinder and fade factors; unoccluded), one shadow ray: unbiased, for
 * places that take many samples anyway (final-gather hits). */
rgb pm_direct_one_light(const pm_lights *L, const shade_mat_bsdf *b, rng *r, long *shadow_rays);

/* Direct light of the emissive surfaces at b through its Lambertian and
 * glossy lobes, `n_light` samples by area. MIS, lobe by lobe, against BSDF
 * strategies whose count-weighted densities for a direction wi are
 *     c_b(wi) = bsdf_front * cos(n, wi)/pi   (Lambertian, wi on the viewer's side)
 *             = bsdf_back * |cos(n, wi)|/pi  (Lambertian, other side)
 *     c_g(wi) = bsdf_glossy * shade_mat_pdf_glossy(b, wi)   (glossy)
 * (path tracer: 1 sample, bsdf_front = m_d/sum m, bsdf_back = m_b/sum m,
 * bsdf_glossy = m_g/sum m; final gather: the numbers of gather rays of each
 * lobe); 0 for a lobe whose BSDF strategy does not count emission. Each
 * light sample of a lobe gets weight (n p_l)^2 / ((n p_l)^2 + c^2). */
rgb pm_direct_emitters(const pm_lights *L, const shade_mat_bsdf *b, int n_light, double bsdf_front, double bsdf_back,
                       double bsdf_glossy, rng *r, long *shadow_rays);

/* Count-weighted light-sampling density n_light * p_l (solid angle, seen
 * from `from`) of the hit point h, 0 if h is not on a sampled emitter. */
double pm_emitter_density(const pm_lights *L, const accel_hit *h, vec3 from, int n_light);

/* Power heuristic weight of strategy a: a^2 / (a^2 + b^2) for count-weighted densities. */
static inline double pm_mis(double a, double b)
{
    if (!(a > 0.0)) return 0.0;
    if (!(b > 0.0) || !isfinite(b)) return isfinite(b) ? 1.0 : 0.0;
    if (!isfinite(a)) return 1.0;
    double r = b / a;
    return 1.0 / (1.0 + r * r);
}

#endif
