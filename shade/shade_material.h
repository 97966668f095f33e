/* shade_material.h - the light-transport model every GI mode converges to:
 * a POV-Ray finish read as a BSDF, plus emission. One piece of code for the
 * path tracer, the photon mapper and (later) the particle GI.
 *
 * At a hit seen along unit `dir` (n = shading normal turned towards the
 * viewer, opacity = 1 - filter - transmit, before #version 3.7
 * 1 - (filter * max channel + transmit), as shade_texture.c):
 *
 *   f(wi) = kd/pi   for wi on the viewer's side    kd = diffuse * opacity * pigment
 *         + kb/pi   for wi on the other side        kb = diffuse_back * opacity * pigment
 *                                                        (diffuse for double_illuminate)
 *         + kr * delta(mirror direction)            kr = reflection colour with fresnel or
 *                                                        falloff and metallic tint, as shade.c
 *         + kt * delta(refracted direction)         kt = filter * pigment + transmit (per
 *                                                        channel), ior from the interior;
 *                                                        total internal reflection adds kt to
 *                                                        the mirror direction, as shade.c
 *   Le      = pigment * opacity * (emission [+ ambient * ambient_light: #version < 3.7])
 *
 * The pigment is evaluated at the hit (patterns, image maps, texture maps:
 * shade_texture.h's shade_tex_pigment_at) and the finish is the hit texture's.
 * Layered textures as POV-Ray shades them: every layer's emission,
 * Lambertian terms and direct light count, times its opacity and the filter
 * colour of the layers above (pigment * filter + transmit, multiplied), and
 * what passes all layers is the transmitted colour; the reflection is the
 * top layer's (an approximation), and normal{} perturbation is not applied
 * to the GI BSDF (shade.c applies it; micro-scale normals under reflection
 * become a blurred mirror, below), so `--gi none` equals the direct part of
 * the path tracer only for scenes without normal{} and layered reflection.
 *
 * Lambertian terms ignore brilliance and crand (they are POV-Ray's shaping
 * of direct light only). Phong and specular highlights: for light arriving
 * straight from POV-Ray light sources they are POV-Ray's own (unnormalised)
 * terms, added by shade_light_terms/shade_light_nee (shade_light.h) exactly
 * as shade.c computes them, so `--gi none` (with ambient 0; it shows ambient,
 * being radiosity off) is the direct part (first vertex) of the path tracer.
 * For all other light (emitters, sky, other surfaces) the top layer's phong
 * and specular are one glossy lobe of f (core/glossy.h, normalisation
 * there), each tinted by `metallic` as shade.c tints highlights (at the
 * mean of cos(n, wi) and cos(n, wo), which keeps it reciprocal):
 *
 *   + kg f_glossy(wi, wo)   kg = phong + specular, but at most what the
 *                           finish leaves: 1 - (max kd + max kb + max kr + max kt)
 *
 * POV-Ray finishes often sum past 1 (diffuse 0.6 + phong 1; glass with
 * transmit 1 and specular 1); the glossy lobe yields there, since POV-Ray
 * renders the other terms itself and has no glossy transport.
 *
 * Blurred reflection (POV-Ray's idiom: reflection with a normal{} pattern
 * far finer than anything seen, averaged by antialiasing): when the top
 * layer has reflection and a normal pattern whose perturbed normals are
 * already uncorrelated 2e-3 scene sizes apart (sizes: the median object's),
 * the mirror lobe becomes a
 * glossy sub-lobe of colour kr whose exponent matches the spread of the
 * perturbed normals, measured once per normal{} by shade_normal_perturb
 * (glossy.h: e = 1 / (4 E[1 - cos theta]) for tilts theta of the normal,
 * the reflected direction turning by twice the tilt). Emission is the same
 * on both sides of a surface (POV-Ray turns normals towards the viewer).
 * Emission follows POV-Ray 3.7's rules with radiosity on (core/radrules.h):
 * `ambient * ambient_light` is part of it only in scenes whose effective
 * #version is below 3.7; in 3.7 scenes only `emission` gives off light.
 * conserve_energy takes the reflected part from the transmitted one (the
 * top layer's reflection, as POV-Ray does per layer). reflection_exponent is
 * not modelled (it is non-linear in the reflected radiance); interior fade
 * (absorption) neither, as in shade.c. The weights need not sum to 1 (POV-Ray finishes are not
 * energy-conserving); estimators stay unbiased, Russian roulette bounds the
 * cost.
 *
 * Radiance through refraction is not scaled by the squared ior ratio (shade.c
 * does not); the adjoint rule for particles carrying flux (photons) is then a
 * factor (eta_i/eta_t)^2 per refraction, given in shade_mat_scatter.eta2 (derivation
 * in shade_material.c). */
#ifndef PT_SHADE_MATERIAL_H
#define PT_SHADE_MATERIAL_H
#include "accel.h"
#include "glossy.h"
#include "rng.h"
#include "scene.h"
#include "shade_light.h"

#define SHADE_MAT_MAX_LAYERS 8

enum {
    SHADE_MAT_LOBE_DIFFUSE = 0,
    SHADE_MAT_LOBE_BACK = 1,
    SHADE_MAT_LOBE_REFLECT = 2,
    SHADE_MAT_LOBE_TRANSMIT = 3,
    SHADE_MAT_LOBE_GLOSSY = 4,
    SHADE_MAT_NLOBES = 5
};
#define SHADE_MAT_MAX_GLOSSY 3

typedef struct {
    const scene_texture *tex;
    rgb pigment;
    double opacity;
    vec3 p;            /* hit point */
    vec3 p_out;        /* p moved off the surface towards the viewer (eps along ng) */
    vec3 p_in;         /* p moved off the surface away from the viewer */
    vec3 dir;          /* incoming ray direction, unit */
    vec3 n;            /* shading normal facing the viewer */
    vec3 ng;           /* geometric normal facing the viewer */
    int entering;      /* the ray hits the outside (geometric normal against it) */
    rgb emission;      /* Le */
    rgb k[SHADE_MAT_NLOBES]; /* kd, kb, kr, kt, kg (kg: the glossy weights' sum, untinted) */
    vec3 refl_dir, trans_dir;
    double eta2;       /* (eta_i/eta_t)^2 of the refraction, 1 without */
    int tir;           /* total internal reflection: the transmitted part, tir_trans, is in k[REFLECT] */
    rgb tir_trans;
    double m[SHADE_MAT_NLOBES]; /* lobe sizes: max channel of k (>= 0) */
    double msum;
    int nglossy;       /* glossy sub-lobes of the top layer: blurred reflection (first, when there
                          is one), phong, specular */
    const glossy_table *gl[SHADE_MAT_MAX_GLOSSY];
    double gl_w[SHADE_MAT_MAX_GLOSSY];  /* weight of each (largest channel of its colour) */
    rgb gl_c[SHADE_MAT_MAX_GLOSSY];     /* colour of each over its weight (1 1 1 for highlights) */
    int gl_tint[SHADE_MAT_MAX_GLOSSY];  /* 1: tinted by the highlight `metallic` in eval */
    double gl_wsum;                     /* sum of gl_w */
    double gl_metallic;                 /* the finish's highlight `metallic` */
    int nee;           /* direct light applies (diffuse, diffuse_back, phong or specular) */
    int double_illum;
    int unsupported;   /* a pigment pattern the shader cannot evaluate (its colour is used) */
    shade_light_surface ls;  /* for shade_light_terms / shade_light_nee: the top layer */
    int nlayers;       /* layers of the texture (SHADE_MAT_MAX_LAYERS at most), each shaded through those above */
    shade_light_surface layer_ls[SHADE_MAT_MAX_LAYERS];
    rgb layer_fil[SHADE_MAT_MAX_LAYERS]; /* filter colour of the layers above (0: the layer takes no direct light) */
    const scene_object *obj; /* the hit object: light_group decides which lights reach it (scene_light_reaches) */
    accel_from from;   /* the hit's surface, for rays leaving it (accel_intersect_from) */
    int gathered;      /* set by the integrator: the hit of a gathering (radiosity) ray, where POV-Ray
                          computes no phong/specular highlights and takes area lights as point lights
                          at their centre (trace.cpp's IsRadiosityRay tests, radiosity.cpp's
                          GetRadiosityQualityFlags); shade_mat_light_nee follows it */
} shade_mat_bsdf;

typedef struct {
    vec3 org, dir;     /* continuation ray (origin off the right side of the surface) */
    rgb weight;        /* f cos / pdf: the throughput multiplier (incl. selection probability) */
    double pdf;        /* solid-angle density for diffuse lobes (for MIS), 0 for the delta lobes */
    int lobe;
    int specular;      /* a delta lobe */
    double eta2;       /* photons: multiply flux by this as well (refraction), else 1 */
} shade_mat_scatter;

/* Emission Le (both sides) under the scene's rules above: at a hit (h may
 * be NULL; tex NULL = the hit's texture), or the texture's fallback colour. */
rgb shade_mat_emission_at(const scene *sc, const scene_texture *tex, const accel_hit *h);
rgb shade_mat_texture_emission(const scene *sc, const scene_texture *tex);
/* 1 if the texture's colour varies over the surface (pattern, texture map). */
int shade_mat_texture_varies(const scene_texture *tex);

/* Set up the BSDF at hit `h` for a ray of unit direction `dir`. `eps` is the
 * distance the origins are moved off the surface (accel_surface_eps);
 * `scale` the scene's working scale (accel_eps_scale), against which the
 * glossy blur's test decides that a normal pattern is micro-scale. `r`
 * feeds crand in shade_light_terms. */
void shade_mat_setup(shade_mat_bsdf *b, const scene *sc, const accel_hit *h, vec3 dir, double eps, double scale,
                     rng *r);
/* shade_mat_setup with the fresnel reflectivity's relative ior given
 * (fresnel_ior > 0; POV-Ray's ComputeRelativeIOR from the ray's interior
 * list, shade_tex_fresnel_ior) instead of the hit object's own across its
 * surface; refraction keeps the object's own. */
void shade_mat_setup_fresnel(shade_mat_bsdf *b, const scene *sc, const accel_hit *h, vec3 dir, double eps,
                             double scale, rng *r,
                             double fresnel_ior);

/* Lambertian part of f (no cosine) for unit wi (towards where light comes
 * from); 0 where wi and the geometric normal disagree about the side. */
rgb shade_mat_eval(const shade_mat_bsdf *b, vec3 wi);

/* The glossy lobe (see the model above): f_g(wi) without cosine, and the
 * solid-angle density with which the glossy lobe samples wi (without the
 * lobe's selection probability); both 0 off the viewer's side. */
rgb shade_mat_eval_glossy(const shade_mat_bsdf *b, vec3 wi);
double shade_mat_pdf_glossy(const shade_mat_bsdf *b, vec3 wi);
/* Sample the glossy lobe alone: s->weight = f_g cos / pdf, s->pdf the
 * density; 0 when the direction falls off the viewer's side. */
int shade_mat_sample_glossy(const shade_mat_bsdf *b, double u0, double u1, double u2, shade_mat_scatter *s);

int shade_mat_sample(const shade_mat_bsdf *b, rng *r, int absorb, shade_mat_scatter *s);

/* What a POV-Ray photon keeps going on through the surface of b (set up at
 * h for dir) without reflecting: the layers' filter and transmit and,
 * leaving an object, the interior's fade over h->t, the way inside
 * (shade_tex_shadow_filter), times 1 - kr per channel under the top
 * layer's conserve_energy (POV-Ray 3.7's photons.cpp,
 * ComputeLightedTexture: the photon carries LightCol x FilCol, FilCol
 * scaled by 1 - reflectivity). kr: the reflectivity the surface's
 * reflection takes. *trace_w (NULL: not wanted): POV-Ray's ray-weight
 * factor, the filter's largest channel before the fade (New_Weight =
 * weight x max3(FilCol); the fade dims the colour only). The caustic
 * layer's refractions and pass_through crossings and pmfg's photons
 * through pass_through objects use it. */
rgb shade_mat_photon_filter(const scene *sc, const accel_hit *h, vec3 dir, const shade_mat_bsdf *b, rgb kr, double *trace_w);

/* Direct light of one POV-Ray light at the hit (shade_light_nee at p_out; see
 * `gathered`). */
rgb shade_mat_light_nee(const shade_mat_bsdf *b, const shade_light_ctx *c, const scene_light *l, int nsamples, rng *r);

#endif
