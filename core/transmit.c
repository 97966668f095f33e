/* transmit.c - POV-Ray 3.7's transmission through a surface (see transmit.h). */
#include "transmit.h"
#include <math.h>
#include "vec.h"

/* POV-Ray's EPSILON (trace.cpp's fade_distance test) */
#define TRANSMIT_EPSILON 1.0e-10
/* nesting of maps scanned by transmit_texture_may (deeper ones are not) */
#define TRANSMIT_DEPTH 32

rgb transmit_layer_filter(rgb filcol, const colour5 *c, const scene_finish *f, rgb reflec)
{
    rgb r = {filcol.r * (c->r * c->f + c->t), filcol.g * (c->g * c->f + c->t), filcol.b * (c->b * c->f + c->t)};
    if (f->conserve_energy) {
        r.r *= fmin_inline(1.0, 1.0 - reflec.r);
        r.g *= fmin_inline(1.0, 1.0 - reflec.g);
        r.b *= fmin_inline(1.0, 1.0 - reflec.b);
    }
    return r;
}

int transmit_refract(vec3 d, vec3 local, double cos_n, double eta, vec3 *out)
{
    double t = 1.0 + eta * eta * (cos_n * cos_n - 1.0);
    if (t < 0.0) return 1;
    t = eta * cos_n - sqrt(t);
    *out = v3_norm(v3_add(v3_scale(d, eta), v3_scale(local, t)));
    return 0;
}

int transmit_fade_none(const scene_interior *in, int shadow)
{
    return !in || fabs(in->fade_distance) <= TRANSMIT_EPSILON || (shadow && in->fade_power <= 0.0);
}

rgb transmit_fade(const scene_interior *in, double d, int shadow)
{
    rgb one = {1, 1, 1};
    if (transmit_fade_none(in, shadow)) return one;
    rgb fc = in->fade_colour;
    if (in->fade_power >= 1000) {
        double k = d / in->fade_distance;
        rgb r = {exp(-(1.0 - fc.r) * k), exp(-(1.0 - fc.g) * k), exp(-(1.0 - fc.b) * k)};
        return r;
    }
    double a = 1.0 + pow(d / in->fade_distance, in->fade_power);
    rgb r = {fc.r + (1.0 - fc.r) / a, fc.g + (1.0 - fc.g) / a, fc.b + (1.0 - fc.b) / a};
    return r;
}

static int pigment_may(const scene_pigment *pg, int depth);

static int map_may(const scene_blend_map *m, int depth)
{
    if (!m || depth > TRANSMIT_DEPTH) return 0;
    for (int i = 0; i < m->n; i++) {
        const scene_map_entry *e = &m->e[i];
        if (m->kind == MAP_COLOUR && (e->c[3] != 0.0 || e->c[4] != 0.0)) return 1;
        if (m->kind == MAP_PIGMENT && e->pigment && pigment_may(e->pigment, depth + 1)) return 1;
        if (m->kind == MAP_TEXTURE && e->texture && transmit_texture_may(e->texture)) return 1;
    }
    return 0;
}

static int pigment_may(const scene_pigment *pg, int depth)
{
    if (pg->colour.f != 0.0 || pg->colour.t != 0.0) return 1;
    if (pg->kind != PIGMENT_PATTERN || !pg->pat) return 0;
    const scene_pattern *pat = pg->pat;
    if (pat->kind == PAT_IMAGE && !pg->map) {
        const scene_image_map *im = &pat->image;
        /* an image whose every pixel is opaque (a palette with a
         * transparent entry no pixel uses) stops all light */
        return im->once || im->filter_all_set || im->transmit_all_set || !im->image ||
               (im->image->pixels ? im->image->clear : im->image->has_alpha);
    }
    return map_may(pg->map, depth);
}

int transmit_texture_may(const scene_texture *t)
{
    /* A layered texture's filters multiply (POV-Ray 3.7's trace.cpp,
     * ComputeShadowTexture and ComputeLightedTexture: each layer's
     * filter and transmit scale the light let through; shade_texture.c's
     * shadow_layers), so one layer of a solid colour without filter or
     * transmit (stones.inc's T_StoneN over their pigment{color Black})
     * stops all light, whatever the layers over it let through. A texture
     * map at the head stands for the whole texture there. */
    const int layered = t && !(t->pat && t->map);
    int may = 0;
    for (const scene_texture *l = t; l; l = l->next) {
        if (layered && (l->pigment.kind != PIGMENT_PATTERN || !l->pigment.pat) && l->pigment.colour.f == 0.0 &&
            l->pigment.colour.t == 0.0)
            return 0;
        if (l->pat && l->map) {
            if (map_may(l->map, 0)) may = 1;
        } else if (pigment_may(&l->pigment, 0)) {
            may = 1;
        }
    }
    return may;
}
