/* shade_atmos.c - background, sky_sphere and fog (see shade_atmos.h).
 *
 * POV-Ray 3.7's Trace::ComputeSky (language version 3.7 rules) and
 * ComputeFog / ComputeConstantFogColour / ComputeGroundFogColour, studied
 * for semantics:
 *  - sky_sphere (#version 3.7; older scenes: sky_legacy): the pigments are layers evaluated at the ray direction
 *    (through the inverse sky transform, applied as to a point), the LAST
 *    listed on top: colour += pigment * (1 - filter - transmit) * filter_so_far
 *    * emission, filter_so_far *= rgb*filter + transmit; the background colour
 *    (filter and transmit ignored) is the bottom layer.
 *  - fog: per fog, attenuation a = exp(-d / distance) (constant fog) or
 *    exp(-d * density / distance) with ground fog's density the mean of
 *    1/(1+y^2) (y = (height along up - offset) / fog_alt, 1 below 0) over the
 *    segment, from atan; turbulence shortens d by
 *    k * min(1, Turbulence(mid point * turbulence) * turb_depth), k =
 *    exp(-d/distance); a >= the fog's transmit; the seen colour becomes
 *    sum (1-a) fog + prod a ((1 - filter) + filter * fog) * colour.
 *    A ray that hits nothing travels an unbounded distance (POV-Ray's
 *    BOUND_HUGE). Shadow rays of lights with media_attenuation on are
 *    dimmed by the attenuation part (POV-Ray's ComputeShadowMedia). */
#include "shade_atmos.h"
#include "radrules.h"
#include <math.h>
#include "shade_noise.h"
#include "shade_pattern.h"

#define ATM_EPSILON 1.0e-10
#define BOUND_HUGE 2.0e10

/* Before #version 3.7 POV-Ray filtered the sky layers with the full
 * five-channel colour product: the layers add colour * trans * (1 - filter
 * - transmit) with trans = |filter| + |transmit| of the product so far, and
 * the background shows through rgb * filter + transmit of the product. */
static rgb sky_legacy(const scene *sc, const scene_sky_sphere *sky, vec3 dir)
{
    double fc[5] = {1, 1, 1, 1, 1}, trans = 1.0;
    rgb col = {0, 0, 0};
    vec3 p = xform_inv_point(&sky->transform, dir);
    shade_pattern_ctx pc = shade_pattern_ctx_plain(sc);
    for (int i = sky->npigments - 1; i >= 0; i--) {
        colour5 c;
        shade_pigment_eval(sky->pigments[i], p, &pc, &c);
        double att = trans * (1.0 - c.f - c.t);
        col.r += c.r * att;
        col.g += c.g * att;
        col.b += c.b * att;
        fc[0] *= c.r;
        fc[1] *= c.g;
        fc[2] *= c.b;
        fc[3] *= c.f;
        fc[4] *= c.t;
        trans = fabs(fc[3]) + fabs(fc[4]);
    }
    rgb out = {col.r * sky->emission[0] + sc->background.r * (fc[0] * fc[3] + fc[4]),
               col.g * sky->emission[1] + sc->background.g * (fc[1] * fc[3] + fc[4]),
               col.b * sky->emission[2] + sc->background.b * (fc[2] * fc[3] + fc[4])};
    return out;
}

rgb shade_atmos_sky(const scene *sc, vec3 dir)
{
    rgb col = {0, 0, 0}, fil = {1, 1, 1};
    const scene_sky_sphere *sky = sc->sky_sphere;
    if (sky && sky->npigments > 0 && radrules_legacy(sc))
        return sky_legacy(sc, sky, dir);
    if (sky && sky->npigments > 0) {
        vec3 p = xform_inv_point(&sky->transform, dir);
        shade_pattern_ctx pc = shade_pattern_ctx_plain(sc);
        for (int i = sky->npigments - 1; i >= 0; i--) {
            colour5 c;
            shade_pigment_eval(sky->pigments[i], p, &pc, &c);
            double att = 1.0 - c.f - c.t;
            col.r += c.r * att * fil.r * sky->emission[0];
            col.g += c.g * att * fil.g * sky->emission[1];
            col.b += c.b * att * fil.b * sky->emission[2];
            fil.r *= c.r * c.f + c.t;
            fil.g *= c.g * c.f + c.t;
            fil.b *= c.b * c.f + c.t;
        }
    }
    col.r += sc->background.r * fil.r;
    col.g += sc->background.g * fil.g;
    col.b += sc->background.b * fil.b;
    return col;
}

static double fog_turb(const scene *sc, const scene_fog *f, vec3 p)
{
    p = v3_mul(p, f->turbulence);
    int g = sc->global.noise_generator >= 1 && sc->global.noise_generator <= 3 ? sc->global.noise_generator : 2;
    return shade_noise_turbulence(p, f->octaves, f->omega, f->lambda, g);
}

static double fog_att(const scene *sc, const scene_fog *f, vec3 org, vec3 dir, double width)
{
    if (f->type == 2) {
        vec3 p1 = org, p2 = v3_madd(org, dir, width);
        double y1 = v3_dot(p1, f->up), y2 = v3_dot(p2, f->up);
        double s = (y1 - f->offset) / f->alt, e = (y2 - f->offset) / f->alt, density;
        if (s <= 0.0) {
            density = e <= 0.0 ? 1.0 : (atan(e) - s) / (e - s);
        } else if (e <= 0.0) {
            density = (atan(s) - e) / (s - e);
        } else {
            double delta = s - e;
            density = fabs(delta) > ATM_EPSILON ? (atan(s) - atan(e)) / delta : 1.0 / (s * s + 1.0);
        }
        if (f->has_turb) {
            vec3 mid = v3_scale(v3_add(p1, p2), 0.5);
            double k = exp(-width / f->distance);
            width *= 1.0 - k * fmin(1.0, fog_turb(sc, f, mid) * f->turb_depth);
        }
        return exp(-width * density / f->distance);
    }
    if (f->has_turb) {
        vec3 p = v3_madd(org, dir, width / 2.0);
        double k = exp(-width / f->distance);
        width *= 1.0 - k * fmin(1.0, fog_turb(sc, f, p) * f->turb_depth);
    }
    return exp(-width / f->distance);
}

static void fog_sums(const scene *sc, vec3 org, vec3 dir, double depth, rgb *att, rgb *col);

/* POV-Ray's ComputeRainbow: inside the arc, a colour from the map at the
 * angle to the antisolar direction (jittered), blended over c by
 * k = max(exp(-depth/distance), fade*(1-transmit)+transmit); several
 * rainbows average. */
static rgb rainbow(const scene *sc, vec3 dir, double depth, rgb c)
{
    rgb ct = {0, 0, 0};
    int n = 0;
    shade_pattern_ctx pc = shade_pattern_ctx_plain(sc);
    for (const scene_rainbow *r = sc->rainbows; r; r = r->next) {
        if (!r->pigment || r->distance == 0.0 || r->width == 0.0) continue;
        double x = v3_dot(dir, r->right), y = v3_dot(dir, r->up), l = x * x + y * y;
        if (l > 0.0) y /= sqrt(l);
        double angle = fabs(acos(fmax(-1.0, fmin(1.0, y))));
        if (angle > r->arc_angle) continue;
        double d1 = v3_dot(dir, r->antisolar);
        if (d1 < 0.0) continue;
        double index = (acos(fmin(1.0, d1)) - r->angle) / r->width;
        if (r->jitter > 0.0) {
            /* POV-Ray draws a random number; a hash of the direction here */
            unsigned long h = (unsigned long)(fabs(dir.x) * 1e9) * 2654435761ul ^ (unsigned long)(fabs(dir.y) * 1e9) * 40503ul ^
                              (unsigned long)(fabs(dir.z) * 1e9);
            index += (2.0 * shade_noise_pattern_rand(h) - 1.0) * r->jitter;
        }
        if (index < 0.0 || index > 1.0 - ATM_EPSILON) continue;
        colour5 cr;
        shade_pigment_eval(r->pigment, v3(index, 0, 0), &pc, &cr);
        double fade = 0.0;
        if (r->falloff_width > 0.0 && angle > r->falloff_angle) {
            fade = (angle - r->falloff_angle) / r->falloff_width;
            fade = (3.0 - 2.0 * fade) * fade * fade;
        }
        double k = exp(-depth / r->distance);
        k = fmax(k, fade * (1.0 - cr.t) + cr.t);
        double ki = 1.0 - k, f = cr.f * ki;
        ct.r += k * c.r * ((1.0 - f) + f * cr.r) + ki * cr.r;
        ct.g += k * c.g * ((1.0 - f) + f * cr.g) + ki * cr.g;
        ct.b += k * c.b * ((1.0 - f) + f * cr.b) + ki * cr.b;
        n++;
    }
    if (n == 0) return c;
    rgb out = {ct.r / n, ct.g / n, ct.b / n};
    return out;
}

rgb shade_atmos_fog(const scene *sc, vec3 org, vec3 dir, double depth, rgb c)
{
    if (sc->rainbows) c = rainbow(sc, dir, isfinite(depth) ? depth : BOUND_HUGE, c);
    if (!sc->fogs) return c;
    rgb satt, scol;
    fog_sums(sc, org, dir, depth, &satt, &scol);
    rgb r = {scol.r + satt.r * c.r, scol.g + satt.g * c.g, scol.b + satt.b * c.b};
    return r;
}

void shade_atmos_fog_affine(const scene *sc, vec3 org, vec3 dir, double depth, rgb *att, rgb *add)
{
    rgb one = {1, 1, 1}, zero = {0, 0, 0};
    *att = one;
    *add = zero;
    if (sc->fogs) fog_sums(sc, org, dir, depth, att, add);
}

rgb shade_atmos_fog_attenuation(const scene *sc, vec3 org, vec3 dir, double depth)
{
    rgb satt = {1, 1, 1}, scol;
    if (sc->fogs) fog_sums(sc, org, dir, depth, &satt, &scol);
    return satt;
}

static void fog_sums(const scene *sc, vec3 org, vec3 dir, double depth, rgb *att, rgb *col)
{
    double width = isfinite(depth) ? depth : BOUND_HUGE;
    rgb satt = {1, 1, 1}, scol = {0, 0, 0};
    for (const scene_fog *f = sc->fogs; f; f = f->next) {
        if (fabs(f->distance) <= ATM_EPSILON) continue;
        double a = fog_att(sc, f, org, dir, width);
        const double *fc = f->colour;
        if (a < fc[4]) a = fc[4];
        satt.r *= a * ((1.0 - fc[3]) + fc[3] * fc[0]);
        satt.g *= a * ((1.0 - fc[3]) + fc[3] * fc[1]);
        satt.b *= a * ((1.0 - fc[3]) + fc[3] * fc[2]);
        scol.r += (1.0 - a) * fc[0];
        scol.g += (1.0 - a) * fc[1];
        scol.b += (1.0 - a) * fc[2];
    }
    *att = satt;
    *col = scol;
}
