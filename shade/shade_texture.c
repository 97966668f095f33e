/* shade_texture.c - POV-Ray 3.7 surface model at a hit (see shade_texture.h).
 *
 * Follows POV-Ray 3.7's Trace::ComputeOneTextureColour and
 * ComputeLightedTexture (render/trace.cpp, studied for semantics):
 *  - A patterned texture evaluates its pattern at the (texture-transformed,
 *    warped) point and blends the fully lit colours of the two map entries
 *    around the value; entries are evaluated at the warped point, and normals
 *    of entries are warped through the parents' transforms first.
 *  - A plain texture is a list of layers, top first. Per layer: the
 *    perturbed normal, the pigment, the reflectivity (falloff or fresnel,
 *    metallic tint), att = 1 - filter - transmit (1 - (filter * max(rgb) +
 *    transmit) before #version 3.7), the layer's emission/ambient and direct
 *    light times att, all filtered by the filter colour of the layers above;
 *    then filter *= rgb*filter + transmit of the layer (and 1 - reflectivity
 *    with conserve_energy); layers stop once grey(filter) drops under
 *    adc_bailout.
 *  - Transmission (trans > adc_bailout): a refracted ray with the top
 *    layer's normal (ior 1 -> straight through); total internal reflection
 *    reflects instead and is added unfiltered, and the layers' reflections
 *    with the top normal are then skipped; otherwise the transmitted colour
 *    is filtered. Interior fade on leaving an object:
 *    fade_colour + (1 - fade_colour) / (1 + (d/fade_distance)^fade_power)
 *    (exp(-(1 - fade_colour) d / fade_distance) for fade_power >= 1000).
 *  - Dispersion (POV-Ray 3.7's ComputeRefraction): across a surface whose
 *    dispersion ratio differs from 1, a ray of all colours is split into
 *    dispersion_samples monochromatic rays, each refracted with its band's
 *    ior (shade_spectral.c) and weighted with its band's hue; the sum is
 *    divided by the number of bands. A band's total internal reflection
 *    adds the reflected ray (traced with the incoming ray's band) times the
 *    hue, and the split as a whole never counts as total internal
 *    reflection. A monochromatic ray keeps its band through every later
 *    reflection and refraction and bends with that band's ior at the next
 *    dispersive surface instead of splitting again.
 *  - Reflection per layer along the layer's normal (POV-Ray's fix when the
 *    mirrored ray goes below the raw surface), weighted by its
 *    reflectivity times the reflected colour raised to 1 / reflection_exponent
 *    (POV-Ray 3.7 stores that reciprocal as Reflect_Exp, parstxtr.cpp, and
 *    trace.cpp raises the colour to it).
 *
 * uv_mapping (object, texture, pigment and normal level) evaluates at the
 * hit's POV-Ray UV coordinates (accel_hit.uv).
 *
 * Not modelled here: photons, media, subsurface. */
#include "shade_texture.h"
#include <math.h>
#include <string.h>
#include "mirror.h"
#include "transmit.h"
#include "shade_noise.h"
#include "shade_normal.h"
#include "shade_pattern.h"
#include "shade_spectral.h"

#define TEX_EPSILON 1.0e-10
#define MAX_PARENTS 32
#define MAX_LAYERS 64
#define GREY(c) transmit_grey(c)

static inline rgb trgb(double r, double g, double b) { rgb c = {r, g, b}; return c; }
static inline rgb tadd(rgb a, rgb b) { return trgb(a.r + b.r, a.g + b.g, a.b + b.b); }
static inline rgb tmul(rgb a, rgb b) { return trgb(a.r * b.r, a.g * b.g, a.b * b.b); }
static inline rgb tscale(rgb a, double s) { return trgb(a.r * s, a.g * s, a.b * s); }
static inline double tmax3(rgb a) { return fmax_inline(a.r, fmax_inline(a.g, a.b)); }

/* A parent patterned texture whose transforms apply to normals below it. */
typedef struct {
    const xform *xf;
    const scene_pattern *pat;
} parent_frame;

/* What stays the same for every texture evaluated at one hit. */
typedef struct {
    const shade_tex_env *e;
    const accel_hit *h;
    vec3 dir;
    vec3 raw;        /* raw normal facing the viewer */
    vec3 ng;         /* geometric normal facing the viewer */
    int entering;
    vec3 p_out, p_in;
    const scene_interior *interior;
    /* From the incoming ray's containers (POV-Ray's interior list): the
     * refraction's ior and dispersion ratios (ComputeRefraction), the
     * relative ior of the fresnel reflectivity (ComputeRelativeIOR) and
     * whether the ray travelled inside this interior (its fade applies). */
    double eta, disp_ratio, rel_ior;
    int inside_interior;
    int level;
    unsigned skip;
    float wavelength; /* the incoming ray's band, 0 = all colours */
    double version;
    shade_pattern_ctx pc;
} hit_info;

static double scene_version(const scene *sc)
{
    if (sc->version_major <= 0) return 3.7;
    return sc->version_major + sc->version_minor / 10.0;
}

/* Where a hit's textures are evaluated: the world point, or <u, v, 0> (the
 * hit's POV-Ray UV coordinates, accel_hit.uv) for an object with
 * uv_mapping (POV-Ray's UV_FLAG, trace.cpp). */
static vec3 texture_point(const accel_hit *h)
{
    if (h->obj && h->obj->uv_mapping) return v3(h->uv[0], h->uv[1], 0.0);
    return h->p;
}

static void ctx_from_hit(shade_pattern_ctx *pc, const accel_hit *h)
{
    pc->ipoint = h->p;
    pc->has_hit = 1;
    pc->has_uv = 1;
    pc->uv[0] = h->uv[0];
    pc->uv[1] = h->uv[1];
}

/* A texture's point in its own space; `texture { uv_mapping .. }` (or a
 * patterned texture whose pattern has uv_mapping) starts from the hit's
 * <u, v, 0> instead (POV-Ray's UV_MAP_PATTERN in trace.cpp). */
static vec3 to_texture_space_at(const scene_texture *t, vec3 p, const shade_pattern_ctx *pc)
{
    if ((t->uv_mapping || (t->pat && t->pat->uv_mapping)) && pc && pc->has_uv) p = v3(pc->uv[0], pc->uv[1], 0.0);
    return xform_is_identity(&t->transform) ? p : xform_inv_point(&t->transform, p);
}

/* Perturbed normal of one layer (POV-Ray: parents' Warp_Normal, Perturb_Normal,
 * normalise with no_bump_scale, parents' UnWarp_Normal). */
static vec3 layer_normal(const hit_info *hi, const scene_texture *layer, vec3 point, const parent_frame *pf, int npf)
{
    vec3 n = hi->raw;
    if (!layer->normal || !layer->normal->pat || layer->normal->pat->kind == PAT_PLAIN) return n;
    for (int i = 0; i < npf; i++) n = shade_normal_warp(n, pf[i].xf, NULL, pf[i].pat, 0);
    const xform *uvw = layer->uv_warped && !(layer->pat && layer->map) ? &layer->uv_warp : NULL;
    if (uvw) n = shade_normal_warp(n, uvw, NULL, NULL, 0);
    vec3 tp = to_texture_space_at(layer, point, &hi->pc);
    n = shade_normal_perturb(layer->normal, n, tp, xform_is_identity(&layer->transform) ? NULL : &layer->transform, &hi->pc);
    if (layer->normal->no_bump_scale) n = v3_norm(n);
    if (uvw) n = shade_normal_unwarp(n, uvw, NULL, NULL, 0);
    for (int i = npf - 1; i >= 0; i--) n = shade_normal_unwarp(n, pf[i].xf, NULL, pf[i].pat, 0);
    return v3_norm(n);
}

static int layer_pigment(const hit_info *hi, const scene_texture *layer, vec3 point, vec3 n, colour5 *out)
{
    shade_pattern_ctx pc = hi->pc;
    pc.normal = n;
    return shade_pigment_eval(&layer->pigment, to_texture_space_at(layer, point, &hi->pc), &pc, out);
}

/* POV-Ray's ComputeReflection direction: mirror about n, fixed with the raw
 * normal when it would leave below the surface. */
static vec3 reflect_dir(vec3 d, vec3 n, vec3 raw)
{
    vec3 r = v3_madd(d, n, -2.0 * v3_dot(d, n));
    double k = v3_dot(r, raw);
    if (k < 0.0) {
        if (v3_dot(r, n) < 0.0) r = v3_madd(d, raw, -2.0 * v3_dot(d, raw));
        else r = v3_madd(r, raw, -2.0 * k);
    }
    return v3_norm(r);
}

/* The reflected ray's radiance; a finish with irid tints it as POV-Ray
 * 3.7's ComputeReflection does (f may be NULL). */
static rgb trace_reflection(const hit_info *hi, vec3 n, double weight, const scene_finish *f)
{
    const shade_tex_env *e = hi->e;
    if (weight < e->sc->global.adc_bailout) return trgb(0, 0, 0);
    vec3 rd = reflect_dir(hi->dir, n, hi->raw);
    rgb c = e->trace(e->ctx, e->thread, hi->p_out, rd, hi->level + 1, weight, OBJ_NO_REFLECTION, hi->wavelength, e->r);
    if (f && f->irid > 0.0) c = tmul(c, shade_light_irid(f, rd, hi->dir, n, hi->pc.ipoint, &e->sc->global));
    return c;
}

static double interior_ior(const scene_interior *in) { return in && in->ior > 0.0 ? in->ior : 1.0; }

/* One refracted ray with the ior ratio eta (POV-Ray's TraceRefractionRay,
 * Heckbert's method), of band `wavelength`; returns 1 on total internal
 * reflection, when colour holds the reflected ray's radiance (traced with
 * the incoming ray's band, as POV-Ray reflects the incoming ray). n is
 * |cos| of the incidence, local the normal facing the incoming ray. */
static int refract_one(const hit_info *hi, vec3 top, double eta, double n, vec3 local, double weight, float wavelength,
                       rgb *colour)
{
    const shade_tex_env *e = hi->e;
    vec3 td;
    if (transmit_refract(hi->dir, local, n, eta, &td)) {
        *colour = trace_reflection(hi, top, weight, NULL);
        return 1;
    }
    *colour = e->trace(e->ctx, e->thread, hi->p_in, td, hi->level + 1, weight, hi->skip, wavelength, e->r);
    return 0;
}

/* Refracted (or straight) ray through the surface, split into bands where
 * the surface disperses (POV-Ray 3.7's ComputeRefraction); returns 1 on
 * total internal reflection (colour then holds the reflected radiance). */
static int refraction(const hit_info *hi, vec3 top, double weight, rgb *colour)
{
    const shade_tex_env *e = hi->e;
    const scene_interior *in = hi->interior;
    double eta = hi->eta, dr = hi->disp_ratio;
    *colour = trgb(0, 0, 0);
    if (weight < e->sc->global.adc_bailout) return 0;
    if (fabs(eta - 1.0) < TEX_EPSILON && fabs(dr - 1.0) < TEX_EPSILON) {
        /* a continued ray (SHADE_TEX_MAX_CONTINUED): POV-Ray still ends it
         * at the level limit, where a raised level would end */
        int level = hi->level + 1;
        if (e->depth > 0 && e->depth - hi->level < SHADE_TEX_MAX_CONTINUED) {
            if (level > e->max_level) return 0;
            level = hi->level;
        }
        *colour = e->trace(e->ctx, e->thread, hi->p_in, hi->dir, level, weight, hi->skip, hi->wavelength, e->r);
        return 0;
    }
    double n = v3_dot(hi->dir, top);
    vec3 local;
    if (n <= 0.0) {
        local = top;
        n = -n;
    } else {
        local = v3_neg(top);
    }
    if (fabs(dr - 1.0) < TEX_EPSILON) return refract_one(hi, top, eta, n, local, weight, hi->wavelength, colour);
    if (hi->wavelength > 0.0f)
        return refract_one(hi, top, shade_spectral_ior(hi->wavelength, eta, dr), n, local, weight, hi->wavelength, colour);
    unsigned nb = in && in->dispersion_samples >= 2 ? (unsigned)in->dispersion_samples : 7u;
    rgb sum = {0, 0, 0};
    for (unsigned i = 0; i < nb; i++) {
        shade_spectral_band b = shade_spectral_band_of(i, nb);
        rgb c;
        refract_one(hi, top, shade_spectral_ior(b.wavelength, eta, dr), n, local, weight, b.wavelength, &c);
        sum = tadd(sum, tmul(c, shade_spectral_hue(b)));
    }
    *colour = tscale(sum, 1.0 / nb);
    return 0;
}

typedef struct {
    double weight;
    vec3 normal;
    rgb reflec;
    double exponent;
    const scene_finish *f;
} layer_refl;

static rgb lighted(const hit_info *hi, const scene_texture *tex, vec3 point, const parent_frame *pf, int npf, double weight)
{
    const shade_tex_env *e = hi->e;
    const scene *sc = e->sc;
    double bail = sc->global.adc_bailout;
    rgb result = {0, 0, 0}, filcol = {1, 1, 1};
    double trans = 1.0;
    int one_colour_found = 0, nl = 0;
    layer_refl lr[MAX_LAYERS];
    vec3 top = hi->raw;

    for (const scene_texture *layer = tex; layer && trans > bail && nl < MAX_LAYERS; layer = layer->next) {
        const scene_finish *f = &layer->finish;
        /* +Q: normal perturbation from level 8 (POV-Ray's Q_NORMAL) */
        vec3 ln = e->quality >= 8 ? layer_normal(hi, layer, point, pf, npf) : hi->raw;
        if (nl == 0) top = ln;
        double new_weight = weight * trans;
        colour5 lc = {0, 0, 0, 0, 0};
        int found = layer_pigment(hi, layer, point, ln, &lc);
        if (layer->pigment.kind == PIGMENT_OTHER && e->unsupported) (*e->unsupported)++;
        one_colour_found |= found;
        rgb pig = {lc.r, lc.g, lc.b};

        layer_refl *L = &lr[nl++];
        L->weight = new_weight;
        L->normal = ln;
        L->exponent = f->reflection_exponent != 0.0 ? 1.0 / f->reflection_exponent : 1.0;
        L->f = f;
        double cos_i = -v3_dot(hi->dir, ln);
        L->reflec = mirror_reflectivity(f, cos_i, hi->rel_ior, &L->weight);
        mirror_metallic_tint(&L->reflec, f->reflection_metallic, pig, cos_i);

        double att = hi->version < 3.7 ? 1.0 - (lc.f * tmax3(pig) + lc.t) : 1.0 - lc.f - lc.t;
        if (e->quality <= 1) {
            /* +Q0, +Q1 (Q_FULL_AMBIENT): the pigment's colour, unlit and
             * opaque (POV-Ray 3.7 trace.cpp, ComputeLightedTexture) */
            result = pig;
            if (found) filcol = tmul(filcol, trgb(lc.r * lc.f + lc.t, lc.g * lc.f + lc.t, lc.b * lc.f + lc.t));
            trans = fmin_inline(1.0, fabs(GREY(filcol)));
            continue;
        }
        rgb tmp = {0, 0, 0};
        /* no gather where its light is multiplied by 0 (a clear glass's
         * opacity, a black pigment): POV-Ray gathers only where the most it
         * can add, (filter x pigment) grey x opacity x diffuse, passes
         * adc_bailout (trace.cpp ComputeLightedTexture); this takes only the
         * exact zeros, so no image changes. A gather point inside a glass
         * wall otherwise sends rays that reflect inside it up to
         * max_trace_level (total internal reflection keeps their weight). */
        if (e->indirect && f->diffuse > 0.0 && att != 0.0 && (pig.r != 0.0 || pig.g != 0.0 || pig.b != 0.0)) tmp = tadd(tmp, tscale(tmul(pig, e->indirect(e->ctx, e->thread, hi->h, ln)), f->diffuse * att));
        if (e->use_ambient) tmp = tadd(tmp, tscale(tmul(pig, tmul(f->ambient, sc->global.ambient_light)), att));
        tmp = tadd(tmp, tscale(tmul(pig, f->emission), att));
        if (f->diffuse != 0.0 || f->diffuse_back != 0.0 || f->specular != 0.0 || f->phong != 0.0) {
            shade_light_surface s = {f, pig, ln, hi->dir, att, e->r, hi->pc.ipoint, &sc->global};
            tmp = tadd(tmp, e->direct(e->ctx, e->thread, &s, hi->h, hi->p_out, e->r));
            if (e->highlights && (f->specular > 0.0 || f->phong > 0.0))
                tmp = tadd(tmp, e->highlights(e->ctx, e->thread, hi->h, &s));
        }
        result = tadd(result, tmul(tmp, filcol));

        if (found) {
            filcol = transmit_layer_filter(filcol, &lc, f, L->reflec);
        }
        trans = fmin_inline(1.0, fabs(GREY(filcol)));
    }

    int tir = 0;
    if (trans > bail && e->quality >= 6) { /* +Q: refraction and transmission from level 6 (Q_REFRACT) */
        double w1 = fmax_inline(fabs(filcol.r), fmax_inline(fabs(filcol.g), fabs(filcol.b)));
        rgb rfr;
        tir = refraction(hi, top, weight * w1, &rfr);
        rgb att = {1, 1, 1};
        if (hi->inside_interior) att = transmit_fade(hi->interior, hi->h->t, 0);
        if (tir || !one_colour_found) result = tadd(result, tmul(att, rfr));
        else result = tadd(result, tmul(tmul(att, rfr), filcol));
    }

    for (int i = 0; i < nl && e->quality >= 8; i++) { /* +Q: reflection from level 8 (Q_REFLECT) */
        if (tir && fabs(top.x - lr[i].normal.x) <= TEX_EPSILON && fabs(top.y - lr[i].normal.y) <= TEX_EPSILON &&
            fabs(top.z - lr[i].normal.z) <= TEX_EPSILON)
            continue;
        rgb rf = lr[i].reflec;
        if (rf.r == 0.0 && rf.g == 0.0 && rf.b == 0.0) continue;
        rgb rc = trace_reflection(hi, lr[i].normal, lr[i].weight, lr[i].f);
        if (lr[i].exponent != 1.0)
            rc = trgb(pow(fmax_inline(rc.r, 0.0), lr[i].exponent), pow(fmax_inline(rc.g, 0.0), lr[i].exponent), pow(fmax_inline(rc.b, 0.0), lr[i].exponent));
        result = tadd(result, tmul(rf, rc));
    }
    return result;
}

/* POV-Ray's material_map: the palette index of the image at the point (its
 * red * 255 for other images), 0 outside a `once` image; past the number of
 * textures it wraps (at exactly that number the last texture is used). */
static int material_index(const scene_image_map *im, vec3 tp, int n)
{
    double x, y;
    int k = 0;
    if (shade_pattern_image_pos(im, tp, &x, &y)) {
        const scene_image *img = im->image;
        if (img->indices) {
            int ix = shade_noise_to_int(x), iy = shade_noise_to_int(y);
            if (ix >= img->width || ix < 0) ix = ix < 0 ? 0 : img->width - 1;
            if (iy >= img->height || iy < 0) iy = iy < 0 ? 0 : img->height - 1;
            k = img->indices[(size_t)iy * img->width + ix];
        } else {
            k = (int)(shade_pattern_image_at(im, x, y).r * 255.0);
        }
    }
    if (k > n) k %= n;
    if (k >= n) k = n - 1;
    return k < 0 ? 0 : k;
}

static rgb one_texture(const hit_info *hi, const scene_texture *tex, vec3 point, parent_frame *pf, int npf, double weight)
{
    if (!tex->pat || !tex->map || tex->map->n == 0 || npf >= MAX_PARENTS) return lighted(hi, tex, point, pf, npf, weight);
    const scene_pattern *pat = tex->pat;
    const scene_blend_map *m = tex->map;
    vec3 tp = shade_pattern_warp(pat, to_texture_space_at(tex, point, &hi->pc));
    if (tex->uv_warped && npf + 1 < MAX_PARENTS) { /* the uv-mapped texture's outer warps, before its own */
        pf[npf].xf = &tex->uv_warp;
        pf[npf].pat = NULL;
        npf++;
    }
    pf[npf].xf = xform_is_identity(&tex->transform) ? NULL : &tex->transform;
    pf[npf].pat = pat;
    if (pat->kind == PAT_AVERAGE) {
        rgb acc = {0, 0, 0};
        double total = 0.0;
        for (int i = 0; i < m->n; i++) {
            float w = (float)m->e[i].value;
            if (m->e[i].texture) acc = tadd(acc, tscale(one_texture(hi, m->e[i].texture, tp, pf, npf + 1, weight), w));
            total += w;
        }
        return total != 0.0 ? tscale(acc, 1.0 / total) : acc;
    }
    if (pat->kind == PAT_IMAGE && pat->image.material) {
        int k = material_index(&pat->image, tp, m->n);
        return m->e[k].texture ? one_texture(hi, m->e[k].texture, tp, pf, npf + 1, weight) : trgb(0, 0, 0);
    }
    shade_pattern_ctx pc = hi->pc;
    double v = shade_pattern_value(pat, tp, &pc);
    int ip, ic;
    shade_blend_map_search(m, v, &ip, &ic);
    rgb c = m->e[ic].texture ? one_texture(hi, m->e[ic].texture, tp, pf, npf + 1, weight) : trgb(0, 0, 0);
    if (ip != ic) {
        rgb c2 = m->e[ip].texture ? one_texture(hi, m->e[ip].texture, tp, pf, npf + 1, weight) : trgb(0, 0, 0);
        double v1 = (v - m->e[ip].value) / (m->e[ic].value - m->e[ip].value);
        c = tadd(tscale(c, v1), tscale(c2, 1.0 - v1));
    }
    return c;
}

/* The texture or, where POV-Ray's own normal faces away from the ray
 * (Determine_Textures' hitinside, trace.cpp), the interior_texture. */
static const scene_texture *hit_texture(const scene *sc, const accel_hit *h, int entering)
{
    if (entering == h->pov_flip && h->obj && h->obj->interior_texture) return h->obj->interior_texture;
    return h->texture ? h->texture : &sc->default_texture;
}

/* the interior keeps dispersion in single precision as POV-Ray does */
static double interior_dispersion(const scene_interior *in) { return in ? (double)(float)in->dispersion : 1.0; }

/* The ior ratios at a hit on object o from the containers of the incoming
 * ray, as POV-Ray 3.7 derives them from the ray's interior list (trace.cpp;
 * the atmosphere's ior and dispersion being 1). Refraction
 * (ComputeRefraction): entering from the atmosphere outside/inside; leaving
 * the innermost container inside/(the next container or 1); leaving an
 * overlap 1; entering a nested object (the innermost container)/inside.
 * Fresnel reflectivity (ComputeRelativeIOR), with its own rule for a ray
 * inside two or more containers leaving one of them: the innermost
 * container's ior over the object's, which is 1 when the object is the
 * innermost (a glass object in a closed room reflects only its
 * reflection_min from inside). Without a list (in NULL) the geometric side
 * decides, as for a ray from the atmosphere. */
static void ior_setup(hit_info *hi, const shade_media_inside *in, const scene_object *o)
{
    double ior = interior_ior(hi->interior), disp = interior_dispersion(hi->interior);
    if (!in) {
        hi->inside_interior = !hi->entering;
        hi->eta = hi->entering ? 1.0 / ior : ior;
        hi->disp_ratio = hi->entering ? 1.0 / disp : disp;
        hi->rel_ior = hi->entering ? ior : 1.0 / ior;
        return;
    }
    int n = in->n, at = o ? shade_media_inside_find(in, o) : -1;
    const scene_interior *last = n > 0 ? in->obj[n - 1]->interior : NULL;
    hi->inside_interior = at >= 0;
    if (at < 0 && !hi->entering && n == 0) {
        /* leaving an object with nothing on the list: the ray started
         * inside an object shade_media_inside_at could not test (a clipped
         * one); POV-Ray's list would hold it. With anything on the list the
         * list decides, as in POV-Ray: leaving a subtracted member's
         * surface into the hollow it leaves enters that member's interior
         * (glasschess), whatever the geometry says. */
        hi->inside_interior = 1;
        hi->eta = ior / interior_ior(last);
        hi->disp_ratio = disp / interior_dispersion(last);
        hi->rel_ior = interior_ior(last) / ior;
    } else if (n == 0) {
        hi->eta = 1.0 / ior;
        hi->disp_ratio = 1.0 / disp;
        hi->rel_ior = ior;
    } else if (at == n - 1) {
        const scene_interior *next = n > 1 ? in->obj[n - 2]->interior : NULL;
        hi->eta = ior / interior_ior(next);
        hi->disp_ratio = disp / interior_dispersion(next);
        hi->rel_ior = n == 1 ? 1.0 / ior : interior_ior(last) / ior;
    } else if (at >= 0) {
        hi->eta = 1.0;
        hi->disp_ratio = 1.0;
        hi->rel_ior = interior_ior(last) / ior;
    } else {
        hi->eta = interior_ior(last) / ior;
        hi->disp_ratio = interior_dispersion(last) / disp;
        hi->rel_ior = ior / interior_ior(last);
    }
}

/* ior_setup for a ray crossing o's surface with the containers `in`. */
static hit_info ior_query(const shade_media_inside *in, const scene_object *o, int entering)
{
    hit_info hi;
    memset(&hi, 0, sizeof hi);
    hi.entering = entering;
    hi.interior = o ? o->interior : NULL;
    ior_setup(&hi, in, o);
    return hi;
}

double shade_tex_refraction_eta(const shade_media_inside *in, const scene_object *o, int entering)
{
    return ior_query(in, o, entering).eta;
}

double shade_tex_fresnel_ior(const shade_media_inside *in, const scene_object *o, int entering)
{
    return ior_query(in, o, entering).rel_ior;
}

rgb shade_tex_shade(const shade_tex_env *e, const accel_hit *h, vec3 dir, int level, double weight, unsigned skip, float wavelength)
{
    hit_info hi = {.e = e, .h = h, .dir = dir, .level = level, .skip = skip, .wavelength = wavelength,
                   .version = scene_version(e->sc)};
    vec3 ng = h->ng, n = h->ns;
    hi.entering = v3_dot(dir, ng) < 0.0;
    if (v3_dot(dir, n) > 0.0) n = v3_neg(n);
    if (!hi.entering) ng = v3_neg(ng);
    hi.raw = n;
    hi.ng = ng;
    hi.p_out = v3_madd(h->p, ng, e->eps);
    hi.p_in = v3_madd(h->p, ng, -e->eps);
    hi.interior = h->obj ? h->obj->interior : NULL;
    ior_setup(&hi, e->inside, h->obj);
    hi.pc = shade_pattern_ctx_plain(e->sc);
    ctx_from_hit(&hi.pc, h);
    hi.pc.normal = n;
    hi.pc.dir = dir;
    parent_frame pf[MAX_PARENTS];
    return one_texture(&hi, hit_texture(e->sc, h, hi.entering), texture_point(h), pf, 0, weight);
}

/* ------------------------------------------------------------ colour only */


static int texture_colour(const scene_texture *tex, vec3 point, const shade_pattern_ctx *pc, colour5 *out, int depth)
{
    if (tex->pat && tex->map && tex->map->n > 0 && depth < MAX_PARENTS) {
        const scene_blend_map *m = tex->map;
        vec3 tp = shade_pattern_warp(tex->pat, to_texture_space_at(tex, point, pc));
        if (tex->pat->kind == PAT_IMAGE && tex->pat->image.material) {
            const scene_texture *st = m->e[material_index(&tex->pat->image, tp, m->n)].texture;
            return st ? texture_colour(st, tp, pc, out, depth + 1) : 0;
        }
        double v = shade_pattern_value(tex->pat, tp, pc);
        int ip, ic;
        shade_blend_map_search(m, v, &ip, &ic);
        colour5 a = {0, 0, 0, 0, 0}, b = {0, 0, 0, 0, 0};
        int found = m->e[ic].texture ? texture_colour(m->e[ic].texture, tp, pc, &a, depth + 1) : 0;
        if (ip != ic && m->e[ip].texture) {
            found |= texture_colour(m->e[ip].texture, tp, pc, &b, depth + 1);
            double f = (v - m->e[ip].value) / (m->e[ic].value - m->e[ip].value);
            a.r = f * a.r + (1 - f) * b.r;
            a.g = f * a.g + (1 - f) * b.g;
            a.b = f * a.b + (1 - f) * b.b;
            a.f = f * a.f + (1 - f) * b.f;
            a.t = f * a.t + (1 - f) * b.t;
        }
        *out = a;
        return found;
    }
    return shade_pigment_eval(&tex->pigment, to_texture_space_at(tex, point, pc), pc, out);
}

int shade_tex_pigment_at(const scene *sc, const scene_texture *tex, const accel_hit *h, colour5 *out)
{
    if (!tex) tex = h->texture ? h->texture : &sc->default_texture;
    shade_pattern_ctx pc = shade_pattern_ctx_plain(sc);
    ctx_from_hit(&pc, h);
    pc.normal = h->ns;
    vec3 p = texture_point(h);
    if (!tex->next) return texture_colour(tex, p, &pc, out, 0);
    /* Layers, the first on top, as lighted() stacks them: layer l shows
     * its pigment times att_l through the filter colour of the layers
     * above, and passes on its own filter colour. The sum S is what the
     * stack shows; what it passes, F, leaves as transmit (grey), so that
     * colour * (1 - t), the reflectance and emission a GI mode takes
     * (gi_area_particles.c's opacity, with f 0), is S. A sky sphere with a
     * transparent cloud layer over its gradient then shows the gradient
     * between the clouds, not the clouds' transparent colour. Every layer
     * takes the top layer's finish here. */
    const double version = scene_version(sc);
    double S[3] = {0.0, 0.0, 0.0}, F[3] = {1.0, 1.0, 1.0};
    int found = 0;
    for (const scene_texture *l = tex; l && GREY(trgb(F[0], F[1], F[2])) > sc->global.adc_bailout; l = l->next) {
        colour5 c;
        if (!texture_colour(l, p, &pc, &c, 0)) continue;
        found = 1;
        const double pig[3] = {c.r, c.g, c.b};
        double att = version < 3.7 ? 1.0 - (c.f * fmax_inline(c.r, fmax_inline(c.g, c.b)) + c.t) : 1.0 - c.f - c.t;
        for (int k = 0; k < 3; k++) {
            S[k] += F[k] * att * pig[k];
            F[k] *= pig[k] * c.f + c.t;
        }
    }
    if (!found) return 0;
    double t = fmin_inline(1.0, fmax_inline(0.0, GREY(trgb(F[0], F[1], F[2])))), o = 1.0 - t;
    out->r = o > 1e-9 ? S[0] / o : 0.0;
    out->g = o > 1e-9 ? S[1] / o : 0.0;
    out->b = o > 1e-9 ? S[2] / o : 0.0;
    out->f = 0.0;
    out->t = t;
    return 1;
}

int shade_tex_normal_at(const scene *sc, const accel_hit *h, vec3 n, vec3 *out)
{
    *out = n;
    const scene_texture *tex = h->texture ? h->texture : &sc->default_texture;
    hit_info hi = {.h = h, .raw = n, .version = scene_version(sc)};
    hi.pc = shade_pattern_ctx_plain(sc);
    ctx_from_hit(&hi.pc, h);
    hi.pc.normal = n;
    vec3 point = texture_point(h);
    parent_frame pf[MAX_PARENTS];
    int npf = 0;
    /* down the texture maps as one_texture walks them, along the entry
     * with the larger weight where two blend (a checker's one) */
    while (tex->pat && tex->map && tex->map->n > 0 && npf + 2 < MAX_PARENTS) {
        const scene_pattern *pat = tex->pat;
        const scene_blend_map *m = tex->map;
        vec3 tp = shade_pattern_warp(pat, to_texture_space_at(tex, point, &hi.pc));
        if (tex->uv_warped) {
            pf[npf].xf = &tex->uv_warp;
            pf[npf].pat = NULL;
            npf++;
        }
        pf[npf].xf = xform_is_identity(&tex->transform) ? NULL : &tex->transform;
        pf[npf].pat = pat;
        npf++;
        const scene_texture *next;
        if (pat->kind == PAT_AVERAGE) {
            next = m->e[0].texture;
        } else if (pat->kind == PAT_IMAGE && pat->image.material) {
            next = m->e[material_index(&pat->image, tp, m->n)].texture;
        } else {
            shade_pattern_ctx pc = hi.pc;
            double v = shade_pattern_value(pat, tp, &pc);
            int ip, ic;
            shade_blend_map_search(m, v, &ip, &ic);
            double v1 = ip != ic ? (v - m->e[ip].value) / (m->e[ic].value - m->e[ip].value) : 1.0;
            next = v1 >= 0.5 ? m->e[ic].texture : m->e[ip].texture;
        }
        if (!next) return 0;
        tex = next;
        point = tp;
    }
    if (!tex->normal || !tex->normal->pat || tex->normal->pat->kind == PAT_PLAIN) return 0;
    vec3 p = layer_normal(&hi, tex, point, pf, npf);
    if (!(v3_dot(p, n) > 0.0) || !isfinite(p.x)) return 0;
    *out = p;
    return 1;
}

static rgb shadow_layers(const scene_texture *tex, vec3 point, const shade_pattern_ctx *pc, int depth, double caustics, vec3 raw,
                         vec3 dir)
{
    if (tex->pat && tex->map && tex->map->n > 0 && depth < MAX_PARENTS) {
        const scene_blend_map *m = tex->map;
        vec3 tp = shade_pattern_warp(tex->pat, to_texture_space_at(tex, point, pc));
        if (tex->pat->kind == PAT_IMAGE && tex->pat->image.material) {
            const scene_texture *st = m->e[material_index(&tex->pat->image, tp, m->n)].texture;
            return st ? shadow_layers(st, tp, pc, depth + 1, caustics, raw, dir) : trgb(0, 0, 0);
        }
        double v = shade_pattern_value(tex->pat, tp, pc);
        int ip, ic;
        shade_blend_map_search(m, v, &ip, &ic);
        rgb a = m->e[ic].texture ? shadow_layers(m->e[ic].texture, tp, pc, depth + 1, caustics, raw, dir) : trgb(0, 0, 0);
        if (ip != ic) {
            rgb b = m->e[ip].texture ? shadow_layers(m->e[ip].texture, tp, pc, depth + 1, caustics, raw, dir) : trgb(0, 0, 0);
            double f = (v - m->e[ip].value) / (m->e[ic].value - m->e[ip].value);
            a = tadd(tscale(a, f), tscale(b, 1.0 - f));
        }
        return a;
    }
    rgb c = {1, 1, 1};
    for (const scene_texture *l = tex; l; l = l->next) {
        colour5 lc;
        if (shade_pigment_eval(&l->pigment, to_texture_space_at(l, point, pc), pc, &lc))
            c = tmul(c, trgb(lc.r * lc.f + lc.t, lc.g * lc.f + lc.t, lc.b * lc.f + lc.t));
        if (caustics != 0.0) {
            /* POV-Ray's faked caustics: 1 + |n.d|^caustics per layer (layer normal) */
            vec3 n = raw;
            if (l->normal && l->normal->pat && l->normal->pat->kind != PAT_PLAIN) {
                n = shade_normal_perturb(l->normal, n, to_texture_space_at(l, point, pc),
                                   xform_is_identity(&l->transform) ? NULL : &l->transform, pc);
                n = v3_norm(n);
            }
            c = tscale(c, 1.0 + pow(fabs(v3_dot(n, dir)), caustics));
        }
    }
    return c;
}

/* Whether shadow_layers(tex, ..) with no faked caustics is a constant: no
 * blend map at the top and every layer's pigment a plain colour. */
static int shadow_layers_plain(const scene_texture *tex)
{
    if (tex->pat && tex->map && tex->map->n > 0) return 0;
    for (const scene_texture *l = tex; l; l = l->next)
        if (l->pigment.kind == PIGMENT_PATTERN && l->pigment.pat) return 0;
    return 1;
}

/* shadow_layers of a texture that shadow_layers_plain accepts: the
 * products over the layers' colours, without the pattern context no plain
 * colour reads. */
static rgb shadow_layers_colours(const scene_texture *tex)
{
    rgb c = {1, 1, 1};
    for (const scene_texture *l = tex; l; l = l->next) {
        colour5 lc = l->pigment.colour;
        c = tmul(c, trgb(lc.r * lc.f + lc.t, lc.g * lc.f + lc.t, lc.b * lc.f + lc.t));
    }
    return c;
}

rgb shade_tex_shadow_filter_inside(const scene *sc, const accel_hit *h, vec3 dir, int inside)
{
    int entering = v3_dot(dir, h->ng) < 0.0;
    const scene_texture *tex = hit_texture(sc, h, entering);
    const scene_interior *in = h->obj ? h->obj->interior : NULL;
    if (!(in && in->caustics != 0.0) && shadow_layers_plain(tex)) {
        rgb c = shadow_layers_colours(tex);
        return inside ? tmul(c, transmit_fade(in, h->t, 1)) : c;
    }
    shade_pattern_ctx pc = shade_pattern_ctx_plain(sc);
    ctx_from_hit(&pc, h);
    pc.normal = h->ns;
    pc.dir = dir;
    vec3 raw = h->ns;
    if (v3_dot(raw, dir) > 0.0) raw = v3_neg(raw);
    rgb c = shadow_layers(tex, texture_point(h), &pc, 0, in ? in->caustics : 0.0, raw, dir);
    return inside ? tmul(c, transmit_fade(in, h->t, 1)) : c;
}

rgb shade_tex_shadow_filter(const scene *sc, const accel_hit *h, vec3 dir)
{
    return shade_tex_shadow_filter_inside(sc, h, dir, v3_dot(dir, h->ng) >= 0.0);
}

rgb shade_tex_leaving_fade(const accel_hit *h, vec3 dir, int shadow)
{
    if (v3_dot(dir, h->ng) < 0.0) return trgb(1, 1, 1);
    return transmit_fade(h->obj ? h->obj->interior : NULL, h->t, shadow);
}

/* ------------------------------------------------------------ shadows */

/* Whether o can filter a shadow ray: a no_shadow object (its members
 * inherit the flag) never meets one (shade_tex_walk_take, accel's
 * occlusion callbacks). */
static int object_transparent(const scene_object *o, int depth)
{
    if (depth > 64) return 1;
    if (o->flags & OBJ_NO_SHADOW) return 0;
    if (o->texture && transmit_texture_may(o->texture)) return 1;
    if (o->interior_texture && transmit_texture_may(o->interior_texture)) return 1;
    switch (o->kind) {
    case SHAPE_UNION: case SHAPE_MERGE: case SHAPE_INTERSECTION: case SHAPE_DIFFERENCE:
        for (int i = 0; i < o->u.csg.nkids; i++)
            if (object_transparent(o->u.csg.kids[i], depth + 1)) return 1;
        return 0;
    case SHAPE_MESH:
        if (o->u.mesh.mesh && o->u.mesh.textures)
            for (int i = 0; i < o->u.mesh.mesh->ntextures; i++)
                if (o->u.mesh.textures[i] && transmit_texture_may(o->u.mesh.textures[i])) return 1;
        return 0;
    default:
        return 0;
    }
}

int shade_tex_scene_transparent(const scene *sc)
{
    if (transmit_texture_may(&sc->default_texture)) return 1;
    for (int i = 0; i < sc->nobjects; i++)
        if (object_transparent(sc->objects[i], 0)) return 1;
    return 0;
}

int shade_tex_walk_take(shade_tex_walk *w, const accel_hit *h, vec3 dir, double *depth, int *inside)
{
    if (h->flags & OBJ_NO_SHADOW) return 0;
    if (!(h->t - w->last > SHADE_TEX_POV_SMALL_TOLERANCE)) {
        shade_media_inside_cross(&w->unseen, h->obj);
        return 0;
    }
    *depth = h->t - w->last;
    w->last = h->t;
    *inside = (v3_dot(dir, h->ng) >= 0.0) != (h->obj && shade_media_inside_find(&w->unseen, h->obj) >= 0);
    return 1;
}

typedef struct {
    const scene *sc;
    const scene_light *photon_light;
    vec3 dir;
    shade_tex_walk walk;
    rgb c;
} shadow_walk;

static int shadow_crossing(void *ctx, const accel_hit *h)
{
    shadow_walk *w = ctx;
    double depth;
    int inside;
    if (!shade_tex_walk_take(&w->walk, h, w->dir, &depth, &inside)) return 1;
    const scene_obj_photons *ph = h->obj ? h->obj->photons : NULL;
    if (w->photon_light && ph && ph->target && scene_photon_lobe(w->photon_light, ph, 1)) {
        w->c = trgb(0, 0, 0);
        return 0;
    }
    if (h->ng.x == 0.0 && h->ng.y == 0.0 && h->ng.z == 0.0) {
        /* a record without its surface (shadow_surface said so): plain
         * colours without interior texture or fade, whose filter is
         * shade_tex_shadow_filter_inside's product of the colours, or an
         * opaque_crossing, whose filter is 0 */
        const scene_texture *tex = h->texture;
        w->c = tex && !shadow_layers_plain(tex) ? trgb(0, 0, 0) : tmul(w->c, shadow_layers_colours(tex));
    } else {
        /* distance inside the object: from the previous crossing taken */
        accel_hit hh = *h;
        hh.t = depth;
        w->c = tmul(w->c, shade_tex_shadow_filter_inside(w->sc, &hh, w->dir, inside));
    }
    if (fabs(w->c.r) < TEX_EPSILON && fabs(w->c.g) < TEX_EPSILON && fabs(w->c.b) < TEX_EPSILON) {
        w->c = trgb(0, 0, 0);
        return 0;
    }
    return 1;
}

/* A crossing of a texture that lets no light through anywhere
 * (transmit_texture_may), on an object without an interior texture that
 * might: its filter is 0 wherever it is crossed, so the walk ends there
 * without reading its surface (its pattern pigments). */
static int opaque_crossing(const scene_object *obj, const scene_texture *tex)
{
    return obj && tex && !obj->interior_texture && !transmit_texture_may(tex);
}

/* Whether shadow_crossing reads the surface of a crossing of obj with
 * texture tex (accel_crossings_cut's `surface`): only for the side it is
 * crossed from (the interior texture's choice; the fade of the stretch
 * inside) and for textures other than plain colours or with faked
 * caustics (the filter's point and normal). Without these its filter is
 * shade_tex_shadow_filter_inside's product of the layers' colours, and
 * the fade it would take inside is 1 (transmit_fade_none). */
static int shadow_surface(void *ctx, const scene_object *obj, const scene_texture *tex)
{
    (void)ctx;
    if (opaque_crossing(obj, tex)) return 0;
    if (!obj || obj->interior_texture || !tex) return 1;
    const scene_interior *in = obj->interior;
    if ((in && in->caustics != 0.0) || !transmit_fade_none(in, 1)) return 1;
    return !shadow_layers_plain(tex);
}

/* A walk from the lit point: no crossing taken, no interior passed unseen
 * (the list's entries from n on are not read), all light let through. */
static void shadow_walk_start(shadow_walk *w, const scene *sc, const scene_light *photon_light, vec3 dir)
{
    w->sc = sc;
    w->photon_light = photon_light;
    w->dir = dir;
    w->walk.last = 0.0;
    w->walk.unseen.n = 0;
    w->c = trgb(1, 1, 1);
}

rgb shade_tex_shadow_ray(const scene *sc, const accel *a, vec3 p, vec3 dir, double tmin, double tmax,
                         const scene_light *photon_light)
{
    /* a crossing of an opaque object ends the walk (its filter is 0), so
     * its crossings behind it are not needed, unless the walk's tolerance
     * passed it over */
    shadow_walk w;
    shadow_walk_start(&w, sc, photon_light, dir);
    if (accel_crossings_cut(a, p, dir, tmin, tmax, tmin, OBJ_NO_SHADOW, shadow_surface, shadow_crossing, &w) < 0) {
        shadow_walk_start(&w, sc, photon_light, dir);
        accel_crossings_skip(a, p, dir, tmin, tmax, tmin, OBJ_NO_SHADOW, shadow_crossing, &w);
    }
    return w.c;
}
