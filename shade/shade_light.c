/* shade_light.c - POV-Ray 3.7 light sources and the surface response to them
 * (moved out of shade.c unchanged), plus a continuous direct-light estimator
 * for the GI modes. Formulas follow the POV-Ray 3.7 reference manual
 * ("Light Source", "Finish"); see shade.c's header for the model. */
#include "shade_light.h"
#include <math.h>
#include <stdlib.h>
#include "mirror.h"
#include "shade_noise.h"
#include "shade_texture.h"

static inline rgb lrgb(double r, double g, double b) { rgb c = {r, g, b}; return c; }
static inline rgb lrgb_add(rgb a, rgb b) { return lrgb(a.r + b.r, a.g + b.g, a.b + b.b); }
static inline rgb lrgb_mul(rgb a, rgb b) { return lrgb(a.r * b.r, a.g * b.g, a.b * b.b); }
static inline rgb lrgb_scale(rgb a, double s) { return lrgb(a.r * s, a.g * s, a.b * s); }
static inline int lrgb_near_zero(rgb a) { return fabs(a.r) < 1e-10 && fabs(a.g) < 1e-10 && fabs(a.b) < 1e-10; }

/* POV-Ray's spotlight falloff: 0 below low, 1 above high, (3-2t)t^2 between. */
static double light_cubic_step(double low, double high, double x)
{
    if (x <= low) return 0.0;
    if (x >= high) return 1.0;
    double t = (x - low) / (high - low);
    return (3.0 - 2.0 * t) * t * t;
}

/* Kept for the last angles this thread asked about: they are asked per
 * light sample (per media sample in a lit medium) and per lit interval of
 * a media segment, and two cos() calls there were a tenth of media2's
 * render. */
void shade_light_spot_cosines(const scene_light *l, double *cos_radius, double *cos_falloff)
{
    static _Thread_local double radius = NAN, falloff = NAN, cr, cf;
    if (!(l->radius == radius && l->falloff == falloff)) {
        cr = cos(l->radius * M_PI / 180.0);
        cf = cos(l->falloff * M_PI / 180.0);
        radius = l->radius;
        falloff = l->falloff;
    }
    *cos_radius = cr;
    *cos_falloff = cf;
}

/* x^tightness, 1 for tightness 0; pow(x, 1) is x exactly (the exact
 * result is a double), and tightness 1 is common in spotlit media scenes,
 * where this is asked per media sample and light */
static double tightness_power(double x, double tightness)
{
    return tightness == 0.0 ? 1.0 : tightness == 1.0 ? x : pow(x, tightness);
}

/* x^e of a highlight (x in (0, 1], e > 0): pow's value, without the call
 * where that value is 0. At or below 2^(-1100 / e), x^e is at most 2^-1100,
 * far below half the smallest subnormal (2^-1075), which glibc's pow rounds
 * to 0 (its results are within about half an ulp, also where they
 * underflow). A tight highlight (specular's 1/roughness of 1000) has
 * x^e = 0 over half the directions; the bound is kept for the last
 * exponent this thread asked about. */
static double highlight_power(double x, double e)
{
    static _Thread_local double last = NAN, below = 0.0;
    if (!(e == last)) {
        below = e > 0.0 && isfinite(e) ? exp2(-1100.0 / e) : 0.0;
        last = e;
    }
    return x <= below ? 0.0 : pow(x, e);
}

double shade_light_attenuation(const scene_light *l, vec3 p, vec3 dir, double depth)
{
    double att = 1.0;
    if (l->kind == LIGHT_SPOT) {
        vec3 axis = v3_norm(v3_sub(l->point_at, l->position));
        double c = -v3_dot(dir, axis);
        if (c <= 0.0) return 0.0;
        double cos_radius, cos_falloff;
        shade_light_spot_cosines(l, &cos_radius, &cos_falloff);
        att = tightness_power(c, l->tightness);
        if (cos_radius > 0.0 && c < cos_radius) att *= light_cubic_step(cos_falloff, cos_radius, c);
    } else if (l->kind == LIGHT_CYLINDER) {
        /* radius and falloff are distances from the axis for cylinder lights */
        vec3 axis = v3_norm(v3_sub(l->point_at, l->position));
        vec3 v1 = v3_sub(p, l->position);
        double k = v3_dot(v1, axis);
        if (k <= 0.0) return 0.0;
        double len = v3_len(v3_sub(v1, v3_scale(axis, k)));
        if (len >= l->falloff) return 0.0;
        double d = 1.0 - len / l->falloff;
        att = tightness_power(d, l->tightness);
        if (l->radius > 0.0 && len > l->radius) att *= light_cubic_step(0.0, 1.0 - l->radius / l->falloff, d);
    }
    if (att > 0.0) att *= shade_light_fade(l, depth);
    return att;
}

double shade_light_fade(const scene_light *l, double depth)
{
    if (l->fade_power <= 0.0) return 1.0;
    if (fabs(l->fade_distance) >= 1e-10) return 2.0 / (1.0 + pow(depth / l->fade_distance, l->fade_power));
    return pow(depth, -l->fade_power);
}

void shade_light_ray(const scene_light *l, vec3 centre, vec3 p, vec3 *dir, double *depth)
{
    if (l->kind == LIGHT_CYLINDER) {
        vec3 d = v3_sub(centre, l->point_at);
        double dl = v3_len(d);
        *dir = v3_scale(d, 1.0 / dl);
        *depth = v3_dot(v3_sub(centre, p), *dir);
    } else {
        vec3 d = v3_sub(centre, p);
        *depth = v3_len(d);
        *dir = *depth > 0 ? v3_scale(d, 1.0 / *depth) : v3(0, 1, 0);
    }
    if (l->parallel || l->kind == LIGHT_PARALLEL) {
        vec3 axis = v3_norm(v3_sub(centre, l->point_at));
        double a = v3_dot(axis, *dir);
        *depth *= a;
        *dir = axis;
    }
}

void shade_light_area_axes(const scene_light *l, vec3 p, vec3 *ax1, vec3 *ax2)
{
    *ax1 = l->axis1;
    *ax2 = l->axis2;
    if (l->orient) {
        vec3 dir;
        double depth;
        shade_light_ray(l, l->position, p, &dir, &depth);
        scene_light_orient_axes(l, dir, ax1, ax2);
    }
}

static rgb light_terms_plain(const shade_light_surface *s, vec3 l, rgb lc, int backside);

rgb shade_light_irid(const scene_finish *f, vec3 l, vec3 e, vec3 n, vec3 ipoint, const scene_global *g)
{
    double thickness = f->irid_thickness;
    int gen = g && g->noise_generator ? g->noise_generator : 2;
    if (f->irid_turb != 0.0) {
        /* fixed octaves 5, omega 0.5, lambda 2 (POV-Ray 3.7 trace.cpp) */
        double nz = shade_noise_turbulence(ipoint, 5, 0.5, 2.0, gen);
        thickness *= 1.0 + (2.0 * nz - 1.0) * f->irid_turb;
    }
    /* default wavelengths 0.70, 0.52, 0.48 (POV-Ray 3.7 scene.cpp; kept as floats) */
    double wl[3] = {(float)0.70, (float)0.52, (float)0.48};
    if (g && g->irid_wavelength[0] > 0.0)
        for (int i = 0; i < 3; i++) wl[i] = g->irid_wavelength[i];
    double phase = 2.0 * M_PI * thickness * (fabs(v3_dot(n, l)) + fabs(v3_dot(n, e)));
    return lrgb(1.0 + f->irid * cos(phase / wl[0]), 1.0 + f->irid * cos(phase / wl[1]), 1.0 + f->irid * cos(phase / wl[2]));
}

rgb shade_light_terms(const shade_light_surface *s, vec3 l, rgb lc, int backside)
{
    rgb out = light_terms_plain(s, l, lc, backside);
    if (s->f->irid > 0.0) out = lrgb_mul(out, shade_light_irid(s->f, l, s->eye, s->n, s->ipoint, s->global));
    return out;
}

static rgb light_terms_plain(const shade_light_surface *s, vec3 l, rgb lc, int backside)
{
    const scene_finish *f = s->f;
    rgb out = {0, 0, 0};
    double diffuse = backside ? f->diffuse_back : f->diffuse;
    if (diffuse > 0.0) {
        double ci = v3_dot(s->n, l);
        double intensity = f->brilliance != 1.0 ? pow(fabs(ci), f->brilliance) : fabs(ci);
        intensity *= diffuse * s->att;
        if (f->crand > 0.0) intensity -= rng_f64(s->r) * f->crand;
        out = lrgb_add(out, lrgb_scale(lrgb_mul(s->pigment, lc), intensity));
    }
    if (backside) return out;
    if (f->phong > 0.0) {
        vec3 refl = v3_madd(s->eye, s->n, -2.0 * v3_dot(s->eye, s->n));
        double ca = v3_dot(refl, l);
        if (ca > 0.0 && (f->phong_size < 60 || ca > 0.0008)) {
            double intensity = f->phong * highlight_power(ca, f->phong_size);
            rgb cs = {1, 1, 1};
            mirror_metallic_tint(&cs, f->metallic, s->pigment, v3_dot(s->n, l));
            out = lrgb_add(out, lrgb_scale(lrgb_mul(lc, cs), intensity));
        }
    }
    if (f->specular > 0.0) {
        vec3 h = v3_scale(v3_sub(l, s->eye), 0.5);
        double hl = v3_len(h);
        if (hl > 0.0) {
            double ca = v3_dot(h, s->n) / hl;
            if (ca > 0.0) {
                /* POV-Ray stores 1/roughness as the exponent. */
                double rough = f->roughness > 0.0 ? f->roughness : 0.05;
                double intensity = f->specular * highlight_power(ca, 1.0 / rough);
                rgb cs = {1, 1, 1};
                mirror_metallic_tint(&cs, f->metallic, s->pigment, v3_dot(h, l) / hl);
                out = lrgb_add(out, lrgb_scale(lrgb_mul(lc, cs), intensity));
            }
        }
    }
    return out;
}

/* ------------------------------------------------------------ GI direct light */

/* The light of l that reaches p along dir: shade.c's shadow_blocked, and
 * contacts: the ray leaves c->from (accel_occluded_from); a blocked ray in
 * a scene with transparent surfaces passes their filters (shade.c's
 * filtered shadows, shade_tex_shadow_ray). */
static rgb pass_light(const shade_light_ctx *c, const scene_light *l, vec3 p, vec3 dir, double depth)
{
    const rgb one = {1, 1, 1}, zero = {0, 0, 0};
    if (c->shadow_rays) (*c->shadow_rays)++;
    double tmax = depth - fmax(c->eps, depth * 1e-6);
    if (tmax <= c->eps) return one;
    if (!accel_occluded_from(c->a, c->from, p, dir, c->eps, tmax)) return one;
    if (!c->sc || !c->transparent) return zero;
    rgb t = shade_tex_shadow_ray(c->sc, c->a, p, dir, c->eps, tmax, c->photon_shadows ? l : NULL);
    if (!(t.r > 0.0 || t.g > 0.0 || t.b > 0.0) || !isfinite(t.r + t.g + t.b)) return zero;
    return lrgb(fmax(t.r, 0.0), fmax(t.g, 0.0), fmax(t.b, 0.0));
}

/* 1 when l is an area light whose points do not all coincide: an axis with
 * more than one sample and a non-zero length. An area light with zero axes
 * (or a 1x1 grid) is the point light at its position; the Monte Carlo
 * renderers sample it as one, so it draws no random numbers of its own and
 * gives the point light's image exactly. */
static int light_extended(const scene_light *l)
{
    if (!l->area) return 0;
    int e1 = l->size1 > 1 && v3_dot(l->axis1, l->axis1) > 0.0;
    int e2 = l->size2 > 1 && v3_dot(l->axis2, l->axis2) > 0.0;
    return e1 || e2;
}

/* Point of the continuous area light for (u, v) in [0,1)^2: uniform over the
 * parallelogram spanned by the axes whose grid size exceeds 1, or over the
 * ellipse inscribed in it for `circular` (POV-Ray applies circular only when
 * both sizes exceed 1; its square-to-disc mapping of the grid is not
 * area-preserving, the continuous version is uniform by area). */
static vec3 area_offset(const scene_light *l, vec3 ax1, vec3 ax2, double u, double v)
{
    vec3 e1 = l->size1 > 1 ? ax1 : v3s(0.0), e2 = l->size2 > 1 ? ax2 : v3s(0.0);
    if (l->circular && l->size1 > 1 && l->size2 > 1) {
        double rho = 0.5 * sqrt(u), phi = 2.0 * M_PI * v;
        return v3_add(v3_scale(e1, rho * cos(phi)), v3_scale(e2, rho * sin(phi)));
    }
    return v3_add(v3_scale(e1, u - 0.5), v3_scale(e2, v - 0.5));
}

/* Stratum k of n (k*k grid, the remainder uniformly random). */
static void stratum(int k, int n, rng *r, double *u, double *v)
{
    int g = (int)floor(sqrt((double)n));
    if (g < 1) g = 1;
    if (k < g * g) {
        *u = ((k % g) + rng_f64(r)) / g;
        *v = ((k / g) + rng_f64(r)) / g;
    } else {
        *u = rng_f64(r);
        *v = rng_f64(r);
    }
}

rgb shade_light_nee(const shade_light_ctx *c, const scene_light *l, const shade_light_surface *s, vec3 p, int double_illum,
              int nsamples, rng *r)
{
    rgb zero = {0, 0, 0};
    if (nsamples < 1) nsamples = 1;
    vec3 dir;
    double depth;
    shade_light_ray(l, l->position, p, &dir, &depth);
    int full_area = l->area && l->area_illumination && l->size1 * l->size2 > 0;
    if (full_area) {
        /* area_illumination: every point of the light shades on its own. */
        rgb total = zero;
        for (int k = 0; k < nsamples; k++) {
            double u, v;
            stratum(k, nsamples, r, &u, &v);
            vec3 q = v3_add(l->position, area_offset(l, l->axis1, l->axis2, u, v));
            vec3 d2;
            double dep2;
            shade_light_ray(l, q, p, &d2, &dep2);
            rgb slc = lrgb_scale(l->colour, shade_light_attenuation(l, p, d2, dep2));
            int back2 = 0;
            if (!double_illum && v3_dot(s->n, d2) < 1e-10) {
                if (s->f->diffuse_back != 0.0) back2 = 1;
                else continue;
            }
            if (!l->shadowless) {
                rgb t = pass_light(c, l, p, d2, dep2);
                if (lrgb_near_zero(t)) continue;
                slc = lrgb(slc.r * t.r, slc.g * t.g, slc.b * t.b);
            }
            total = lrgb_add(total, shade_light_terms(s, d2, slc, back2));
        }
        return lrgb_scale(total, 1.0 / nsamples);
    }
    rgb lc = lrgb_scale(l->colour, shade_light_attenuation(l, p, dir, depth));
    if (lrgb_near_zero(lc)) return zero;
    int backside = 0;
    if (!double_illum && v3_dot(s->n, dir) < 1e-10) {
        if (s->f->diffuse_back != 0.0) backside = 1;
        else return zero;
    }
    if (!l->shadowless) {
        rgb vis = zero;
        if (light_extended(l)) {
            vec3 ax1, ax2;
            shade_light_area_axes(l, p, &ax1, &ax2);
            for (int k = 0; k < nsamples; k++) {
                double u, v;
                stratum(k, nsamples, r, &u, &v);
                vec3 q = v3_add(l->position, area_offset(l, ax1, ax2, u, v));
                vec3 d2;
                double dep2;
                shade_light_ray(l, q, p, &d2, &dep2);
                vis = lrgb_add(vis, pass_light(c, l, p, d2, dep2));
            }
            vis = lrgb_scale(vis, 1.0 / nsamples);
        } else {
            vis = pass_light(c, l, p, dir, depth);
        }
        if (lrgb_near_zero(vis)) return zero;
        lc = lrgb(lc.r * vis.r, lc.g * vis.g, lc.b * vis.b);
    }
    return shade_light_terms(s, dir, lc, backside);
}

/* ------------------------------------------------------ photometric units */

pt_status shade_light_units_apply(scene *sc, double metres_per_unit, diag *d)
{
    if (!(metres_per_unit > 0.0) || !isfinite(metres_per_unit)) {
        diag_error(d, "units: %g metres per scene unit is not a positive number", metres_per_unit);
        return PT_ERR_USAGE;
    }
    for (int i = 0; i < sc->nlights; i++) {
        scene_light *l = &sc->lights[i];
        if (l->fade_power > 0.0)
            diag_report(d, DIAG_WARNING, l->loc, NULL,
                        "photometric units: this light's fade_distance %g / fade_power %g are ignored "
                        "(inverse-square falloff in metres instead)",
                        l->fade_distance, l->fade_power);
        if (l->parallel || l->kind == LIGHT_PARALLEL || l->kind == LIGHT_CYLINDER) {
            /* illuminance I lux on a surface facing the light: E = pi C' */
            l->colour = lrgb_scale(l->colour, 1.0 / M_PI);
            l->fade_distance = 0.0;
            l->fade_power = 0.0;
        } else {
            /* E = I cos / (m d)^2 = pi C' cos d^-2 with d in scene units */
            l->colour = lrgb_scale(l->colour, 1.0 / (M_PI * metres_per_unit * metres_per_unit));
            l->fade_distance = 0.0;
            l->fade_power = 2.0;
        }
    }
    return PT_OK;
}
