/* shade_material.c - POV-Ray finish -> BSDF + emission (model in the header).
 *
 * Photon weight through refraction (used by shade_mat_scatter.eta2). Camera-side
 * transport is L(x, wo) = kt L(y, T(wo)), T the refraction map (no radiance
 * scaling, as shade.c). As a BSDF: f(wi, wo) = kt delta(wi - T(wo)) / |cos wi|.
 * A particle carrying flux uses the adjoint: arriving along wi it leaves along
 * wo = T^-1(wi) with weight  int f(wi, wo) |cos wo| dwo
 *   = kt |cos wo| / |cos wi| * |dwo/dwi| = kt * eta_i^2 / eta_t^2,
 * by Snell's law in the form eta_i^2 cos_i dw_i = eta_t^2 cos_t dw_t (the
 * radiance-invariance relation, Veach 1997, ch. 5). So entering glass of ior
 * 1.5 a photon keeps 1/2.25 of kt, leaving it gets 2.25: a round trip is kt^2,
 * and surfaces inside a medium receive what the camera-side transport sees. */
#include "shade_material.h"
#include "mirror.h"
#include "radrules.h"
#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "shade_normal.h"
#include "shade_texture.h"

static inline rgb mrgb(double r, double g, double b) { rgb c = {r, g, b}; return c; }
static inline rgb mrgb_scale(rgb a, double s) { return mrgb(a.r * s, a.g * s, a.b * s); }
static inline double mrgb_max(rgb a) { return fmax(a.r, fmax(a.g, a.b)); }

/* Pigment at a hit: patterns, image maps and texture maps through
 * shade_texture's shade_tex_pigment_at (the colour `shade.c` would see on the top
 * layer); solid colours directly. h NULL: the texture's fallback colour. */
static rgb texture_pigment(const scene *sc, const scene_texture *tex, const accel_hit *h, double *filt, double *transm,
                           int *unsupported)
{
    const scene_pigment *pg = &tex->pigment;
    if (unsupported) *unsupported = pg->kind == PIGMENT_OTHER;
    if (h && (pg->kind == PIGMENT_PATTERN || tex->pat)) {
        colour5 c;
        if (shade_tex_pigment_at(sc, tex, h, &c)) {
            *filt = c.f;
            *transm = c.t;
            return mrgb(c.r, c.g, c.b);
        }
    }
    *filt = pg->colour.f;
    *transm = pg->colour.t;
    return mrgb(pg->colour.r, pg->colour.g, pg->colour.b);
}

/* One layer of a texture as POV-Ray shades it (trace.cpp
 * ComputeLightedTexture): its finish, pigment, opacity att (1 - filter -
 * transmit; before #version 3.7 1 - (filter * max channel + transmit), as
 * shade_texture.c) and the filter colour `fil` of the layers above it. */
typedef struct {
    const scene_finish *f;
    rgb pig, fil;
    double att;
} layer;

/* The layers of tex from the top down (at most SHADE_MAT_MAX_LAYERS, and none
 * once the layers above pass no light, as POV-Ray stops); *through: the
 * colour that passes them all (filter * pigment + transmit, multiplied). */
static int texture_layers(const scene *sc, const scene_texture *tex, const accel_hit *h, layer *L, rgb *through,
                          int *unsupported)
{
    const int legacy = radrules_legacy(sc);
    rgb fil = {1, 1, 1};
    int n = 0;
    for (const scene_texture *t = tex; t && n < SHADE_MAT_MAX_LAYERS; t = t->next) {
        double filt, transm;
        int uns = 0;
        rgb pig = texture_pigment(sc, t, h, &filt, &transm, &uns);
        if (unsupported && uns) *unsupported = 1;
        layer *l = &L[n++];
        l->f = &t->finish;
        l->pig = pig;
        l->fil = fil;
        l->att = legacy ? 1.0 - (filt * mrgb_max(pig) + transm) : 1.0 - filt - transm;
        fil = mrgb(fil.r * (filt * pig.r + transm), fil.g * (filt * pig.g + transm), fil.b * (filt * pig.b + transm));
        if (!(mrgb_max(fil) > 1e-7)) {
            fil = mrgb(0, 0, 0);
            break;
        }
    }
    *through = fil;
    return n;
}

/* Le: each layer's pigment * att * E (core/radrules.h, the reference modes
 * gather light) through the layers above it. */
static rgb emission_of(const scene *sc, const layer *L, int n)
{
    const radrules rr = radrules_of(sc, 1);
    rgb le = {0, 0, 0};
    for (int k = 0; k < n; k++) {
        rgb e = radrules_emission(&rr, sc, L[k].f);
        le.r += L[k].fil.r * L[k].pig.r * e.r * L[k].att;
        le.g += L[k].fil.g * L[k].pig.g * e.g * L[k].att;
        le.b += L[k].fil.b * L[k].pig.b * e.b * L[k].att;
    }
    return le;
}

rgb shade_mat_emission_at(const scene *sc, const scene_texture *tex, const accel_hit *h)
{
    if (!tex) tex = h && h->texture ? h->texture : &sc->default_texture;
    layer L[SHADE_MAT_MAX_LAYERS];
    rgb through;
    int n = texture_layers(sc, tex, h, L, &through, NULL);
    return emission_of(sc, L, n);
}

rgb shade_mat_texture_emission(const scene *sc, const scene_texture *tex) { return shade_mat_emission_at(sc, tex, NULL); }

int shade_mat_texture_varies(const scene_texture *tex)
{
    return tex && (tex->pigment.kind == PIGMENT_PATTERN || tex->pat);
}

/* ------------------------------------------------ blurred reflection */

#define BLUR_SLOTS 256
#define BLUR_SAMPLES 256

typedef struct {
    const scene_normal *key;
    double e; /* 0: not micro-scale */
} blur_entry;

static _Atomic(blur_entry *) blur_cache[BLUR_SLOTS];

/* The Phong exponent that stands for nm's perturbation of a flat surface,
 * or 0 when its normals still agree 2e-3 scene sizes apart (a visible
 * bump pattern, which the BSDF ignores). Deterministic: fixed sample
 * points (golden-ratio sequences) in texture space around the origin. */
static double blur_measure(const scene *sc, const scene_normal *nm, double size)
{
    shade_pattern_ctx pc = shade_pattern_ctx_plain(sc);
    const vec3 up = v3(0, 0, 1);
    const double delta = 2e-3 * size;
    double tilt = 0.0, near = 0.0, far = 0.0;
    vec3 prev = up;
    for (int k = 0; k < BLUR_SAMPLES; k++) {
        double a = fmod((k + 0.5) * 0.6180339887498949, 1.0), b = fmod((k + 0.5) * 0.7548776662466927, 1.0),
               c = fmod((k + 0.5) * 0.5698402909980532, 1.0);
        vec3 p = v3_scale(v3(a - 0.5, b - 0.5, c - 0.5), 0.05 * size);
        vec3 n1 = v3_norm(shade_normal_perturb(nm, up, p, NULL, &pc));
        vec3 n2 = v3_norm(shade_normal_perturb(nm, up, v3_add(p, v3(delta * 0.6, delta * 0.8, 0.0)), NULL, &pc));
        if (!v3_finite(n1) || !v3_finite(n2)) return 0.0;
        tilt += 1.0 - fmin(1.0, v3_dot(n1, up));
        near += 1.0 - fmin(1.0, v3_dot(n1, n2));
        if (k > 0) far += 1.0 - fmin(1.0, v3_dot(n1, prev));
        prev = n1;
    }
    tilt /= BLUR_SAMPLES;
    near /= BLUR_SAMPLES;
    far /= BLUR_SAMPLES - 1;
    /* micro-scale: neighbours 2e-3 sizes apart differ as much as far points */
    if (!(tilt > 1e-9) || !(far > 0.0) || near < 0.5 * far) return 0.0;
    return fmin(1e5, fmax(1.0, 1.0 / (4.0 * tilt)));
}

static double blur_exponent(const scene *sc, const scene_normal *nm, double size)
{
    size_t h = ((size_t)(uintptr_t)nm >> 4) * 0x9E3779B97F4A7C15ULL;
    for (int probe = 0; probe < BLUR_SLOTS; probe++) {
        int i = (int)((h + (size_t)probe) % BLUR_SLOTS);
        blur_entry *e = atomic_load_explicit(&blur_cache[i], memory_order_acquire);
        if (e && e->key == nm) return e->e;
        if (e) continue;
        blur_entry *mine = malloc(sizeof *mine);
        if (!mine) return blur_measure(sc, nm, size);
        mine->key = nm;
        mine->e = blur_measure(sc, nm, size);
        blur_entry *expected = NULL;
        if (atomic_compare_exchange_strong_explicit(&blur_cache[i], &expected, mine, memory_order_acq_rel,
                                                    memory_order_acquire))
            return mine->e;
        double v = mine->e;
        free(mine);
        if (expected->key == nm) return expected->e;
        (void)v;
    }
    return blur_measure(sc, nm, size); /* table full: measure every time */
}

/* The glossy lobe of the top layer's finish f (model in the header): the
 * blurred mirror (when tex's normal is micro-scale), phong (exponent
 * phong_size) and specular (exponent 1/(4 roughness), glossy.h), the
 * highlights' weights scaled down together to what the other lobes leave. */
static void setup_glossy(shade_mat_bsdf *b, const scene *sc, const scene_texture *tex, const scene_finish *f,
                         double size)
{
    b->nglossy = 0;
    b->gl_wsum = 0.0;
    b->k[SHADE_MAT_LOBE_GLOSSY] = mrgb(0, 0, 0);
    b->gl_metallic = f->metallic;
    rgb kr = b->k[SHADE_MAT_LOBE_REFLECT];
    const scene_normal *nm = tex->normal;
    if (mrgb_max(kr) > 0.0 && nm && nm->pat && nm->pat->kind != PAT_PLAIN && size > 0.0) {
        double e = blur_exponent(sc, nm, size);
        const glossy_table *t = e > 0.0 ? glossy_table_for(e) : NULL;
        if (t) {
            double w = mrgb_max(kr);
            b->gl[0] = t;
            b->gl_w[0] = w;
            b->gl_c[0] = mrgb(kr.r / w, kr.g / w, kr.b / w);
            b->gl_tint[0] = 0;
            b->nglossy = 1;
            b->k[SHADE_MAT_LOBE_REFLECT] = mrgb(0, 0, 0); /* the mirror is blurred */
        }
    }
    double w[2] = {f->phong > 0.0 && isfinite(f->phong) ? f->phong : 0.0,
                   f->specular > 0.0 && isfinite(f->specular) ? f->specular : 0.0};
    double e[2] = {f->phong_size, 1.0 / (4.0 * (f->roughness > 0.0 ? f->roughness : 0.05))};
    double wsum = w[0] + w[1];
    double used = 0.0;
    for (int i = 0; i < SHADE_MAT_LOBE_GLOSSY; i++) {
        double m = mrgb_max(b->k[i]);
        if (m > 0.0 && isfinite(m)) used += m;
    }
    if (b->nglossy) used += b->gl_w[0];
    double room = wsum > 0.0 ? fmin(wsum, fmax(0.0, 1.0 - used)) : 0.0;
    for (int i = 0; i < 2 && room > 0.0; i++) {
        if (!(w[i] > 0.0)) continue;
        const glossy_table *t = glossy_table_for(e[i]);
        if (!t) continue;
        b->gl[b->nglossy] = t;
        b->gl_w[b->nglossy] = w[i] * room / wsum;
        b->gl_c[b->nglossy] = mrgb(1, 1, 1);
        b->gl_tint[b->nglossy] = 1;
        b->nglossy++;
    }
    rgb kg = {0, 0, 0};
    for (int i = 0; i < b->nglossy; i++) {
        b->gl_wsum += b->gl_w[i];
        kg = mrgb(kg.r + b->gl_w[i] * b->gl_c[i].r, kg.g + b->gl_w[i] * b->gl_c[i].g, kg.b + b->gl_w[i] * b->gl_c[i].b);
    }
    b->k[SHADE_MAT_LOBE_GLOSSY] = kg;
}

void shade_mat_setup(shade_mat_bsdf *b, const scene *sc, const accel_hit *h, vec3 dir, double eps, double scale,
                     rng *r)
{
    shade_mat_setup_fresnel(b, sc, h, dir, eps, scale, r, 0.0);
}

void shade_mat_setup_fresnel(shade_mat_bsdf *b, const scene *sc, const accel_hit *h, vec3 dir, double eps,
                             double scale, rng *r,
                             double fresnel_ior)
{
    memset(b, 0, sizeof *b);
    const scene_texture *tex = h->texture ? h->texture : &sc->default_texture;
    const scene_finish *f = &tex->finish;
    layer L[SHADE_MAT_MAX_LAYERS];
    rgb tc;
    int nl = texture_layers(sc, tex, h, L, &tc, &b->unsupported);
    rgb pig = L[0].pig;
    b->obj = h->obj;
    accel_from_hit(&b->from, h);
    b->tex = tex;
    b->pigment = pig;
    b->dir = dir;
    b->p = h->p;

    /* Normals face the viewer (shade.c's rule). */
    vec3 ng = h->ng, n = h->ns;
    b->entering = v3_dot(dir, ng) < 0.0;
    if (v3_dot(dir, n) > 0.0) n = v3_neg(n);
    if (!b->entering) ng = v3_neg(ng);
    b->n = n;
    b->ng = ng;
    b->p_out = v3_madd(h->p, ng, eps);
    b->p_in = v3_madd(h->p, ng, -eps);

    double opacity = L[0].att;
    b->opacity = opacity;
    b->emission = emission_of(sc, L, nl);
    b->double_illum = (h->obj && (h->obj->flags & OBJ_DOUBLE_ILLUMINATE)) || (h->flags & OBJ_DOUBLE_ILLUMINATE);

    /* Lambertian terms and direct light of every layer, each through the
     * layers above it (POV-Ray sums the layers' shading so) */
    rgb kd = {0, 0, 0}, kb = {0, 0, 0};
    b->nee = 0;
    b->nlayers = nl;
    for (int k = 0; k < nl; k++) {
        const scene_finish *lf = L[k].f;
        double d = lf->diffuse * L[k].att, db = (b->double_illum ? lf->diffuse : lf->diffuse_back) * L[k].att;
        kd = mrgb(kd.r + L[k].fil.r * L[k].pig.r * d, kd.g + L[k].fil.g * L[k].pig.g * d, kd.b + L[k].fil.b * L[k].pig.b * d);
        kb = mrgb(kb.r + L[k].fil.r * L[k].pig.r * db, kb.g + L[k].fil.g * L[k].pig.g * db,
                  kb.b + L[k].fil.b * L[k].pig.b * db);
        int lit = lf->diffuse != 0.0 || lf->diffuse_back != 0.0 || lf->phong != 0.0 || lf->specular != 0.0;
        b->nee |= lit;
        shade_light_surface lls = {lf, L[k].pig, n, dir, L[k].att, r};
        b->layer_ls[k] = lls;
        b->layer_fil[k] = lit ? L[k].fil : mrgb(0, 0, 0);
    }
    b->k[SHADE_MAT_LOBE_DIFFUSE] = kd;
    b->k[SHADE_MAT_LOBE_BACK] = kb;

    double cos_i = -v3_dot(dir, n);
    const scene_interior *in = h->obj ? h->obj->interior : NULL;
    double rel_ior = 1.0;
    if (in && in->ior > 0.0) rel_ior = b->entering ? in->ior : 1.0 / in->ior;
    b->refl_dir = v3_madd(dir, n, 2.0 * cos_i);
    b->eta2 = 1.0;

    /* Reflection (mirror.h: falloff blend or fresnel, metallic tint). */
    rgb refl = {0, 0, 0};
    if (mirror_reflects(f)) {
        double wdummy = 1.0;
        refl = mirror_reflectivity(f, cos_i, fresnel_ior > 0.0 ? fresnel_ior : rel_ior, &wdummy);
        mirror_metallic_tint(&refl, f->reflection_metallic, pig, cos_i);
    }
    /* conserve_energy: what the reflection takes is not transmitted
     * (trace.cpp: filCol *= min(1, 1 - reflectivity), as shade_texture.c);
     * without it a glass of reflection 1 and transmit 1 returns up to twice
     * what it receives at every bounce */
    if (f->conserve_energy)
        tc = mrgb(tc.r * fmin(1.0, 1.0 - refl.r), tc.g * fmin(1.0, 1.0 - refl.g), tc.b * fmin(1.0, 1.0 - refl.b));
    /* Transmission: straight through, or refracted when an ior is given. */
    rgb trans = {0, 0, 0};
    if (mrgb_max(tc) > 0.0) {
        trans = tc;
        b->trans_dir = dir;
        if (fabs(rel_ior - 1.0) > 1e-9) {
            double eta = 1.0 / rel_ior;
            double k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
            if (k < 0.0) {
                /* total internal reflection: the transmitted part reflects */
                b->tir = 1;
                b->tir_trans = trans;
                refl = mrgb(refl.r + trans.r, refl.g + trans.g, refl.b + trans.b);
                trans = mrgb(0, 0, 0);
            } else {
                b->trans_dir = v3_norm(v3_add(v3_scale(dir, eta), v3_scale(n, eta * cos_i - sqrt(k))));
                b->eta2 = eta * eta;
            }
        }
    }
    b->k[SHADE_MAT_LOBE_REFLECT] = refl;
    b->k[SHADE_MAT_LOBE_TRANSMIT] = trans;
    setup_glossy(b, sc, tex, f, scale);
    b->msum = 0.0;
    for (int i = 0; i < SHADE_MAT_NLOBES; i++) {
        double m = mrgb_max(b->k[i]);
        b->m[i] = m > 0.0 && isfinite(m) ? m : 0.0;
        b->msum += b->m[i];
    }
    b->ls = b->layer_ls[0];
}

rgb shade_mat_eval(const shade_mat_bsdf *b, vec3 wi)
{
    double cn = v3_dot(wi, b->n), cg = v3_dot(wi, b->ng);
    if (cn > 0.0 && cg > 0.0) return mrgb_scale(b->k[SHADE_MAT_LOBE_DIFFUSE], 1.0 / M_PI);
    if (cn < 0.0 && cg < 0.0) return mrgb_scale(b->k[SHADE_MAT_LOBE_BACK], 1.0 / M_PI);
    return mrgb(0, 0, 0);
}

/* The glossy sub-lobes' sum, tinted by metallic (mirror_metallic_tint, at
 * the mean cosine of wi and wo: symmetric); 0 unless wi is on the viewer's
 * side by both normals. */
rgb shade_mat_eval_glossy(const shade_mat_bsdf *b, vec3 wi)
{
    rgb out = {0, 0, 0};
    if (b->nglossy == 0 || !(v3_dot(wi, b->ng) > 0.0)) return out;
    vec3 wo = v3_neg(b->dir);
    rgb tinted = {0, 0, 0};
    for (int i = 0; i < b->nglossy; i++) {
        double f = b->gl_w[i] * glossy_eval(b->gl[i], b->n, wo, wi);
        if (!(f > 0.0)) continue;
        rgb c = mrgb_scale(b->gl_c[i], f);
        if (b->gl_tint[i]) tinted = mrgb(tinted.r + c.r, tinted.g + c.g, tinted.b + c.b);
        else out = mrgb(out.r + c.r, out.g + c.g, out.b + c.b);
    }
    if (b->gl_metallic != 0.0)
        mirror_metallic_tint(&tinted, b->gl_metallic, b->pigment, 0.5 * (v3_dot(wi, b->n) + v3_dot(wo, b->n)));
    return mrgb(out.r + tinted.r, out.g + tinted.g, out.b + tinted.b);
}

double shade_mat_pdf_glossy(const shade_mat_bsdf *b, vec3 wi)
{
    if (b->nglossy == 0 || !(v3_dot(wi, b->ng) > 0.0)) return 0.0;
    double kg = b->gl_wsum, p = 0.0;
    if (!(kg > 0.0)) return 0.0;
    vec3 wo = v3_neg(b->dir);
    for (int i = 0; i < b->nglossy; i++) p += b->gl_w[i] / kg * glossy_pdf(b->gl[i], b->n, wo, wi);
    return p;
}

/* A sub-lobe is chosen in proportion to its weight (u0 picks it, then is
 * reused, rescaled, for glossy_sample's own choice); the weight is the whole
 * lobe's f cos over the mixture density, so MIS sees one strategy. */
int shade_mat_sample_glossy(const shade_mat_bsdf *b, double u0, double u1, double u2, shade_mat_scatter *s)
{
    memset(s, 0, sizeof *s);
    s->eta2 = 1.0;
    s->lobe = SHADE_MAT_LOBE_GLOSSY;
    double kg = b->gl_wsum;
    if (b->nglossy == 0 || !(kg > 0.0)) return 0;
    int j = 0;
    double acc = 0.0;
    for (; j < b->nglossy - 1; j++) {
        double pj = b->gl_w[j] / kg;
        if (u0 < acc + pj) break;
        acc += pj;
    }
    double pj = b->gl_w[j] / kg;
    double uu = pj > 0.0 ? fmin(fmax((u0 - acc) / pj, 0.0), 0.999999999) : 0.5;
    vec3 wi;
    double pdf1, w1;
    if (!glossy_sample(b->gl[j], b->n, v3_neg(b->dir), uu, u1, u2, &wi, &pdf1, &w1)) return 0;
    if (!(v3_dot(wi, b->ng) > 0.0)) return 0;
    double pdf = shade_mat_pdf_glossy(b, wi);
    rgb f = shade_mat_eval_glossy(b, wi);
    if (!(pdf > 0.0)) return 0;
    double k = v3_dot(wi, b->n) / pdf;
    s->dir = wi;
    s->org = b->p_out;
    s->pdf = pdf;
    s->weight = mrgb_scale(f, k);
    return isfinite(k) && k > 0.0;
}

/* Sample a lobe and a direction. absorb = 0: a lobe is always chosen, with
 * probability m_k / sum m (path tracer; Russian roulette is separate).
 * absorb = 1: probability m_k (scaled down when sum m > 1), else the particle
 * is absorbed (photon Russian roulette, seed 002 appendix A step 2(b)-(d),
 * with the max channel as scatter probability so powers never grow).
 * Returns 0 when nothing is sampled (absorbed, black, or a diffuse direction
 * that the shading normal allows but the geometric normal does not). */
static int mat_sample_lobe(const shade_mat_bsdf *b, double u_lobe, double u1, double u2, int absorb, shade_mat_scatter *s)
{
    memset(s, 0, sizeof *s);
    s->eta2 = 1.0;
    if (!(b->msum > 0.0)) return 0;
    double scale = absorb ? (b->msum > 1.0 ? 1.0 / b->msum : 1.0) : 1.0 / b->msum;
    int lobe = -1;
    double acc = 0.0, p = 0.0;
    for (int i = 0; i < SHADE_MAT_NLOBES; i++) {
        if (b->m[i] <= 0.0) continue;
        acc += b->m[i] * scale;
        if (u_lobe < acc) {
            lobe = i;
            p = b->m[i] * scale;
            break;
        }
    }
    if (lobe < 0) {
        if (absorb) return 0;
        /* rounding at the top end: take the last non-empty lobe */
        for (int i = SHADE_MAT_NLOBES - 1; i >= 0; i--)
            if (b->m[i] > 0.0) { lobe = i; p = b->m[i] * scale; break; }
        if (lobe < 0) return 0;
    }
    if (lobe == SHADE_MAT_LOBE_GLOSSY) {
        /* u_lobe within the lobe's interval, rescaled: a fresh uniform */
        double u0 = fmin(fmax((u_lobe - (acc - p)) / p, 0.0), 0.999999999);
        if (!shade_mat_sample_glossy(b, u0, u1, u2, s)) return 0;
        s->weight = mrgb_scale(s->weight, 1.0 / p);
        s->pdf *= p;
        return 1;
    }
    s->lobe = lobe;
    s->weight = mrgb_scale(b->k[lobe], 1.0 / p);
    switch (lobe) {
    case SHADE_MAT_LOBE_DIFFUSE:
        s->dir = v3_cosine_dir(b->n, u1, u2);
        if (v3_dot(s->dir, b->ng) <= 0.0) return 0;
        s->org = b->p_out;
        s->pdf = p * v3_dot(s->dir, b->n) / M_PI;
        break;
    case SHADE_MAT_LOBE_BACK:
        s->dir = v3_cosine_dir(v3_neg(b->n), u1, u2);
        if (v3_dot(s->dir, b->ng) >= 0.0) return 0;
        s->org = b->p_in;
        s->pdf = p * -v3_dot(s->dir, b->n) / M_PI;
        break;
    case SHADE_MAT_LOBE_REFLECT:
        s->dir = b->refl_dir;
        s->org = b->p_out;
        s->specular = 1;
        break;
    default:
        s->dir = b->trans_dir;
        s->org = b->p_in;
        s->specular = 1;
        s->eta2 = b->eta2;
        break;
    }
    if (!(s->pdf > 0.0) && !s->specular) return 0;
    return 1;
}

int shade_mat_sample(const shade_mat_bsdf *b, rng *r, int absorb, shade_mat_scatter *s)
{
    double ul = rng_f64(r), u1 = rng_f64(r), u2 = rng_f64(r);
    return mat_sample_lobe(b, ul, u1, u2, absorb, s);
}

rgb shade_mat_light_nee(const shade_mat_bsdf *b, const shade_light_ctx *c, const scene_light *l, int nsamples, rng *r)
{
    shade_light_ctx cf = *c;
    cf.from = &b->from;
    scene_light pl;
    if (b->gathered && l->area) {
        /* gathering rays see area lights as points at their centre */
        pl = *l;
        pl.area = 0;
        l = &pl;
        nsamples = 1;
    }
    rgb total = {0, 0, 0};
    for (int k = 0; k < b->nlayers; k++) {
        rgb fil = b->layer_fil[k];
        if (!(mrgb_max(fil) > 0.0)) continue;
        shade_light_surface ls = b->layer_ls[k];
        ls.r = r;
        scene_finish f;
        if (b->gathered) {
            /* no highlights at the hits of gathering rays */
            f = *ls.f;
            f.phong = f.specular = 0.0;
            ls.f = &f;
        }
        rgb v = shade_light_nee(&cf, l, &ls, b->p_out, b->double_illum, nsamples, r);
        total = mrgb(total.r + fil.r * v.r, total.g + fil.g * v.g, total.b + fil.b * v.b);
    }
    return total;
}

rgb shade_mat_photon_filter(const scene *sc, const accel_hit *h, vec3 dir, const shade_mat_bsdf *b, rgb kr, double *trace_w)
{
    rgb f = shade_tex_shadow_filter(sc, h, dir), fa = shade_tex_leaving_fade(h, dir, 1);
    if (b->ls.f && b->ls.f->conserve_energy)
        f = (rgb){f.r * fmin(1.0, 1.0 - kr.r), f.g * fmin(1.0, 1.0 - kr.g), f.b * fmin(1.0, 1.0 - kr.b)};
    if (trace_w)
        *trace_w = fmax(fa.r > 0.0 ? f.r / fa.r : 0.0, fmax(fa.g > 0.0 ? f.g / fa.g : 0.0, fa.b > 0.0 ? f.b / fa.b : 0.0));
    return f;
}
