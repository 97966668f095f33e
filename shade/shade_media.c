/* shade_media.c - participating media (see shade_media.h).
 *
 * POV-Ray 3.7's media model, from its reference manual ("Media") and its
 * MediaFunction (media.cpp) and Trace (trace.cpp), studied for semantics:
 *  - Coefficients at a point: every density of a media multiplies (a
 *    density is a pigment; its rgb is the density; no density = 1); the
 *    media's absorption, emission and scattering times the density are
 *    summed over the media acting on the segment; extinction = absorption
 *    + extinction_factor * scattering.
 *  - Lit intervals: every light with media_interaction lights the part of
 *    the segment inside its cone (spotlight: the cone of its falloff angle),
 *    cylinder (falloff radius) or all of it (point and area lights); a
 *    shadowless light lights no media (its type is FILL_LIGHT_SOURCE, which
 *    ComputeOneMediaLightInterval's switch leaves out of the list). The
 *    interval starts and ends are sorted separately and merged into lit
 *    and unlit intervals.
 *  - Sampling intervals: max(intervals, number of lit intervals) of them;
 *    one lit interval (or one unlit one of non-constant media) is cut into
 *    `intervals` equal parts; one unlit interval of constant media is one
 *    interval; several are given n = floor(w / sum(w) * intervals) + 1
 *    parts each (w = ratio for lit, 1 - ratio for unlit), bounded so the
 *    later ones still get one. The media with the most intervals decides
 *    (and its method, samples, jitter, ratio); aa_threshold is the smallest.
 *  - Method 3 (adaptive, POV-Ray 3.5+'s default): an interval gets
 *    count = floor(min_samples / 2) + 1 sub-intervals of 1 / (count + 1)
 *    of it from its start (the samples leave its last 1 / (count + 1)
 *    out, as POV-Ray's); samples at their ends (moved by
 *    jitter * (rand - 0.5) of a sub-interval); between two samples whose
 *    colours differ by more than aa_threshold (sum of |channel
 *    differences|) a middle sample is taken recursively, aa_level - 1
 *    levels deep; at the last level the three samples average 1:1:1,
 *    otherwise each half weighs its outer sample 1/3 and the middle one
 *    1/6. A sub-interval's emitted light (a sample's coefficients times
 *    the whole interval's length, averaged over the count) is attenuated
 *    by the optical depth of the sub-intervals before it only, not within
 *    itself, so thick media emit more than the closed form (a left
 *    Riemann sum of it).
 *  - Methods 1 and 2: min_samples samples per interval at a random place
 *    (1) or stratified (j + 0.5) / n + jitter * rand / n (2); each sample's
 *    emitted light is ds * exp(-extinction * d) (d = its distance into the
 *    interval); the interval's light and optical depth are the samples'
 *    means. With samples min, max (max > min) an interval of a view ray
 *    gets further random samples while the variance of the mean of its
 *    samples' light, var(mean) = (E[x^2] - E[x]^2) / n per channel, is not
 *    below threshold(n) = variance * chi2inv(n) / chi2inv(max - 1), chi2inv(k)
 *    the chi-square value with k degrees of freedom that is exceeded with
 *    probability `confidence` (POV-Ray's Sample_Threshold), up to max + 1
 *    samples.
 *  - In-scattering at a sample in a lit interval: for each light whose
 *    interval holds the sample, the light reaching the point (attenuation,
 *    shadows through surfaces, media on the way) times scattering times the
 *    phase function averaged over the media acting: isotropic 1, Rayleigh
 *    0.799372013 (1 + a^2), Mie hazy 0.576655375 (1 + 9 ((1 + a)/2)^8),
 *    Mie murky 0.495714547 (1 + 50 ((1 + a)/2)^32), Henyey-Greenstein
 *    (1 - g^2) / (1 + g^2 - 2 g a)^1.5, a = cos(angle between the view ray
 *    and the direction towards the light) (POV-Ray's constants).
 *  - Intervals in order: colour * exp(-sum od) + sum te * exp(-od before).
 *  - Shadow rays: extinction only; media whose densities are all constant
 *    take a single sample per interval.
 *  - Media photons (a caustic layer's, shade_media_env.photons): at every
 *    sample of a view ray, lit or not, each photon around the sample adds
 *    scattering x phase x its light, as a light would (POV-Ray's
 *    ComputeMediaPhotons). A photon target that refracts a light's photons
 *    shadows that light fully at samples whose media collect photons
 *    (shade_media_light_fn). */
#include "shade_media.h"
#include "shade_chi2.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "geom_extent.h"
#include "geom_shape.h"
#include "scene_leaves.h"
#include "shade_atmos.h"
#include "shade_light.h"
#include "shade_pattern.h"
#include "shade_texture.h"

#define MEDIA_MAX_DISTANCE 1.0e7   /* POV-Ray's MAX_DISTANCE */
#define MEDIA_EPSILON 1.0e-10      /* POV-Ray's EPSILON */
#define MEDIA_SMALL_TOLERANCE 1.0e-3 /* POV-Ray's SMALL_TOLERANCE */
#define MAX_REFS 64
#define MAX_LIGHTS 64
#define MAX_INTERVALS 256

static inline rgb mk(double r, double g, double b) { rgb c = {r, g, b}; return c; }
static inline rgb add(rgb a, rgb b) { return mk(a.r + b.r, a.g + b.g, a.b + b.b); }
static inline rgb mul(rgb a, rgb b) { return mk(a.r * b.r, a.g * b.g, a.b * b.b); }
static inline rgb scl(rgb a, double s) { return mk(a.r * s, a.g * s, a.b * s); }
/* exp(-a) per channel; one exp() where the channels are equal (grey
 * media, the usual case), the same value three times. */
static inline rgb expn(rgb a)
{
    if (a.r == a.g && a.g == a.b) {
        double e = exp(-a.r);
        return mk(e, e, e);
    }
    return mk(exp(-a.r), exp(-a.g), exp(-a.b));
}
static inline int is_zero(rgb a) { return a.r == 0.0 && a.g == 0.0 && a.b == 0.0; }
static inline double dist3(rgb a, rgb b) { return fabs(a.r - b.r) + fabs(a.g - b.g) + fabs(a.b - b.b); }

/* ------------------------------------------------------------ containers */

/* POV-Ray's Interior identity (scene_object.medium) */
static const void *key_of(const scene_object *o)
{
    return o->medium ? o->medium : o->interior ? (const void *)o->interior : (const void *)o;
}

static int has_interior_media(const scene_object *o) { return o->interior && o->interior->nmedia > 0; }

static int media_attenuates(const scene_media *m)
{
    return m && (m->absorption.r != 0.0 || m->absorption.g != 0.0 || m->absorption.b != 0.0 || m->scattering.r != 0.0 ||
                 m->scattering.g != 0.0 || m->scattering.b != 0.0);
}

static int has_attenuating_media(const scene_object *o)
{
    if (!o->interior) return 0;
    for (int k = 0; k < o->interior->nmedia; k++)
        if (media_attenuates(o->interior->media[k])) return 1;
    return 0;
}

int shade_media_scene_attenuates(const scene *sc)
{
    for (int k = 0; k < sc->natmosphere; k++)
        if (media_attenuates(sc->atmosphere[k])) return 1;
    for (int i = 0; i < sc->nobjects; i++)
        if (scene_object_any(sc->objects[i], has_attenuating_media)) return 1;
    return 0;
}

int shade_media_scene_has(const scene *sc)
{
    if (sc->natmosphere > 0) return 1;
    /* interior media: any object's (CSG members included) */
    for (int i = 0; i < sc->nobjects; i++)
        if (scene_object_any(sc->objects[i], has_interior_media)) return 1;
    return 0;
}

int shade_media_inside_hollow(const shade_media_inside *in)
{
    for (int i = 0; i < in->n; i++)
        if (!(in->obj[i]->flags & OBJ_HOLLOW)) return 0;
    return 1;
}

int shade_media_inside_has_media(const shade_media_inside *in)
{
    for (int i = 0; i < in->n; i++)
        if (in->obj[i]->interior && in->obj[i]->interior->nmedia > 0) return 1;
    return 0;
}

int shade_media_inside_find(const shade_media_inside *in, const scene_object *o)
{
    const void *k = key_of(o);
    for (int i = 0; i < in->n; i++)
        if (key_of(in->obj[i]) == k) return i;
    return -1;
}

void shade_media_inside_cross(shade_media_inside *in, const scene_object *o)
{
    if (!o) return;
    const void *k = key_of(o);
    for (int i = 0; i < in->n; i++) {
        if (key_of(in->obj[i]) == k) {
            memmove(&in->obj[i], &in->obj[i + 1], sizeof in->obj[0] * (size_t)(in->n - i - 1));
            in->n--;
            return;
        }
    }
    if (in->n < SHADE_MEDIA_MAX_INSIDE) in->obj[in->n++] = o;
}

/* A degenerate shape (the renderer skips it too) is never inside. A
 * blob's field is 0 outside its components' reach, so with a threshold of
 * 0 or more a point outside the reach's box (geom_extent's, padded) is not
 * inside; nor is one outside a text's box (its glyphs' control points,
 * which hold the curves, over the depth): answered without building the
 * blob's component hierarchy or the text's outline, which the camera's
 * container test would otherwise build for every such object. */
static int leaf_inside(const scene_object *o, vec3 p)
{
    /* an inverse object is answered in full: a degenerate one is never
     * inside, inverse or not */
    int inverse = (o->flags & OBJ_INVERSE) != 0;
    if (!inverse && ((o->kind == SHAPE_BLOB && o->u.blob && o->u.blob->threshold >= 0.0) || o->kind == SHAPE_TEXT)) {
        vec3 lo, hi;
        const char *what = NULL;
        if (geom_extent(o, &lo, &hi, &what) == 0) {
            vec3 pad = v3s(1e-9 * (v3_maxc(v3_sub(hi, lo)) + v3_maxc(v3_max(v3_neg(lo), hi))));
            lo = v3_sub(lo, pad);
            hi = v3_add(hi, pad);
            if (!(p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z)) return 0;
        }
    }
    if (!inverse && o->kind == SHAPE_HEIGHT_FIELD && o->u.height_field && o->u.height_field->heights) {
        /* inside is below the surface over the unit square (object
         * space), so never above the highest height or the water: a point
         * there is answered without building the field's min/max tree */
        const scene_height_field *h = o->u.height_field;
        double top = h->water_level;
        for (long i = 0; i < (long)h->width * h->height; i++) top = h->heights[i] > top ? h->heights[i] : top;
        vec3 q = xform_inv_point(&o->transform, p);
        if (q.y > top + 1e-6 * (fabs(top) + 1.0) || q.x < -1e-9 || q.x > 1.0 + 1e-9 || q.z < -1e-9 || q.z > 1.0 + 1e-9) return 0;
    }
    geom_shape sh;
    if (geom_shape_init(&sh, o) != 0) return 0;
    int r = geom_shape_inside(&sh, p);
    geom_shape_release(&sh);
    return (o->flags & OBJ_INVERSE) ? !r : r;
}

/* Whether p is inside o's solid: CSG by its rule over the members (an
 * inverse node turned around), leaves by their own test; clipped and
 * unsupported objects never. */
static int solid_inside(const scene_object *o, vec3 p, int depth)
{
    if (depth > 32 || o->clip || o->kind == SHAPE_UNSUPPORTED) return 0;
    int r;
    switch (o->kind) {
    case SHAPE_UNION: case SHAPE_MERGE:
        r = 0;
        for (int k = 0; k < o->u.csg.nkids && !r; k++) r = solid_inside(o->u.csg.kids[k], p, depth + 1);
        break;
    case SHAPE_INTERSECTION:
        r = o->u.csg.nkids > 0;
        for (int k = 0; k < o->u.csg.nkids && r; k++) r = solid_inside(o->u.csg.kids[k], p, depth + 1);
        break;
    case SHAPE_DIFFERENCE:
        r = o->u.csg.nkids > 0 && solid_inside(o->u.csg.kids[0], p, depth + 1);
        for (int k = 1; k < o->u.csg.nkids && r; k++) r = !solid_inside(o->u.csg.kids[k], p, depth + 1);
        break;
    default:
        return leaf_inside(o, p);
    }
    return (o->flags & OBJ_INVERSE) ? !r : r;
}

static void inside_at(const scene_object *o, vec3 p, shade_media_inside *in, int depth)
{
    if (depth > 32) return;
    if (o->kind == SHAPE_UNION || o->kind == SHAPE_MERGE) {
        for (int k = 0; k < o->u.csg.nkids; k++) inside_at(o->u.csg.kids[k], p, in, depth + 1);
        return;
    }
    if (o->kind == SHAPE_UNSUPPORTED) return;
    if (o->clip) return;
    /* an intersection or difference holding p goes on the list as a whole
     * (its members share its interior identity, scene_object.medium), as
     * POV-Ray's InitRayContainerState tests the object and lists its
     * interior */
    if (!solid_inside(o, p, depth)) return;
    for (int i = 0; i < in->n; i++)
        if (key_of(in->obj[i]) == key_of(o)) return;
    if (in->n < SHADE_MEDIA_MAX_INSIDE) in->obj[in->n++] = o;
}

void shade_media_inside_at(const scene *sc, vec3 p, shade_media_inside *in)
{
    in->n = 0;
    for (int i = 0; i < sc->nobjects; i++) inside_at(sc->objects[i], p, in, 0);
}

/* ------------------------------------------------------------ coefficients */

typedef struct {
    const scene_media *m;
    const xform *obj; /* container's object -> world, NULL for the atmosphere */
} media_ref;

typedef struct {
    rgb ext, emit, scat;
} coeffs;

/* A density that costs a few operations to evaluate: a plain colour, or a
 * pattern that is a closed form of the point (no noise, cells or
 * functions) through a colour map, without turbulence. */
static int density_cheap(const scene_pigment *pg)
{
    if (pg->kind != PIGMENT_PATTERN) return 1;
    const scene_pattern *pat = pg->pat;
    if (!pat || (pg->map && pg->map->kind != MAP_COLOUR)) return 0;
    switch (pat->kind) {
    case PAT_SPHERICAL: case PAT_GRADIENT: case PAT_PLANAR: case PAT_BOXED: case PAT_CYLINDRICAL:
    case PAT_ONION: case PAT_RADIAL: case PAT_CHECKER:
        break;
    default:
        return 0;
    }
    for (int i = 0; i < pat->nwarps; i++)
        if (pat->warps[i].kind == WARP_TURBULENCE) return 0;
    return 1;
}

#define MAX_DENSITIES 16
/* The density of media r at po, the point in its object's space. */
static rgb density_at(const media_ref *r, vec3 po, const shade_pattern_ctx *pc)
{
    const scene_media *m = r->m;
    if (m->ndensity == 0) return mk(1, 1, 1);
    vec3 q = po;
    if (!xform_is_identity(&m->transform)) q = xform_inv_point(&m->transform, q);
    /* The densities multiply, so one that is 0 in every channel makes the
     * product 0 (their colours are finite): the cheap ones are evaluated
     * first, and an expensive one (crackle, noise) is not where a cheap
     * one is 0 (micro: a crackle density times a spherical one that is 0
     * outside the unit sphere). Otherwise the product is formed in the
     * written order, as before. */
    rgb v[MAX_DENSITIES];
    unsigned have = 0;
    int n = m->ndensity <= MAX_DENSITIES ? m->ndensity : 0;
    for (int i = 0; n > 1 && i < n; i++) {
        if (!density_cheap(m->density[i])) continue;
        colour5 c = {0, 0, 0, 0, 0};
        shade_pigment_eval(m->density[i], q, pc, &c);
        v[i] = mk(c.r, c.g, c.b);
        have |= 1u << i;
        if (is_zero(v[i])) return mk(0, 0, 0);
    }
    rgb d = {1, 1, 1};
    for (int i = 0; i < m->ndensity; i++) {
        if (i < n && (have & (1u << i))) {
            d = mul(d, v[i]);
            continue;
        }
        colour5 c = {0, 0, 0, 0, 0};
        shade_pigment_eval(m->density[i], q, pc, &c);
        d = mul(d, mk(c.r, c.g, c.b));
    }
    return d;
}

static coeffs coeffs_at(const media_ref *refs, int n, vec3 p, int shadow, const shade_pattern_ctx *pc)
{
    coeffs c = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    /* the point in each object's space, once for the media of one object */
    const xform *obj = NULL;
    vec3 po = p;
    for (int i = 0; i < n; i++) {
        const scene_media *m = refs[i].m;
        if (refs[i].obj != obj) {
            obj = refs[i].obj;
            po = obj ? xform_inv_point(obj, p) : p;
        }
        rgb d = density_at(&refs[i], po, pc);
        rgb ext = add(m->absorption, scl(m->scattering, m->extinction));
        c.ext = add(c.ext, mul(d, ext));
        if (!shadow) {
            c.emit = add(c.emit, mul(d, m->emission));
            c.scat = add(c.scat, mul(d, m->scattering));
        }
    }
    return c;
}

/* The phase function averaged over the media acting (POV-Ray's constants);
 * a = cos(view ray, direction towards the light). */
static double phase(const media_ref *refs, int n, double a)
{
    double k = 0.0;
    for (int i = 0; i < n; i++) {
        const scene_media *m = refs[i].m;
        switch (m->scattering_type) {
        case MEDIA_RAYLEIGH: k += 0.799372013 * (1.0 + a * a); break;
        case MEDIA_MIE_HAZY: k += 0.576655375 * (1.0 + 9.0 * pow(0.5 * (1.0 + a), 8.0)); break;
        case MEDIA_MIE_MURKY: k += 0.495714547 * (1.0 + 50.0 * pow(0.5 * (1.0 + a), 32.0)); break;
        case MEDIA_HENYEY_GREENSTEIN: {
            double g = m->eccentricity;
            k += (1.0 - g * g) / pow(1.0 + g * g - 2.0 * g * a, 1.5);
            break;
        }
        default: k += 1.0; break;
        }
    }
    return n > 0 ? k / n : 0.0;
}

/* ------------------------------------------------------------ lit intervals */

/* The crossings t1 <= t2 of a ray with a light's cone or cylinder,
 * a t^2 + 2 b t + c = 0 with discriminant d = b^2 - a c > 0, and which of
 * them lie ahead of the light along its axis (axial position k2 + t k1 > 0):
 * bit 0 for t1, bit 1 for t2 (0: neither, the ray meets only the back half). */
static int axial_roots(double a, double b, double d, double k1, double k2, double *t1, double *t2)
{
    d = sqrt(d);
    double r1 = (-b + d) / a, r2 = (-b - d) / a;
    if (r1 > r2) { double t = r1; r1 = r2; r2 = t; }
    *t1 = r1;
    *t2 = r2;
    int ahead1 = !(k2 + r1 * k1 <= 0.0), ahead2 = !(k2 + r2 * k1 <= 0.0);
    return ahead1 | ahead2 << 1;
}

/* Part of the ray org + t dir inside a spotlight's cone (half angle =
 * falloff): the quadric |X - C|^2 cos^2 = ((X - C).D)^2 solved for t, with
 * the branch rules for a ray starting inside the cone or meeting only its
 * back half (POV-Ray's spotlight media interval). */
static int spot_interval(vec3 org, vec3 dir, const scene_light *l, double *d1, double *d2)
{
    vec3 axis = v3_norm(v3_sub(l->point_at, l->position));
    double cr, cf;
    shade_light_spot_cosines(l, &cr, &cf);
    double m = 1.0 / (cf * cf);
    vec3 v1 = v3_sub(org, l->position);
    double k1 = v3_dot(dir, axis), k2 = v3_dot(v1, axis), len = v3_len(v1);
    int in_cone = len > MEDIA_EPSILON ? k2 / len >= cf : 0;
    if (k1 <= 0.0 && k2 < 0.0) return 0;
    double k3 = v3_dot(v1, dir), k4 = v3_dot(v1, v1);
    double a = 1.0 - k1 * k1 * m, b = k3 - k1 * k2 * m, c = k4 - k2 * k2 * m;
    if (a != 0.0) {
        double d = b * b - a * c;
        if (d > MEDIA_EPSILON) {
            double t1, t2;
            int ahead = axial_roots(a, b, d, k1, k2, &t1, &t2);
            if (!ahead) return 0;
            if (ahead == 2) { /* t1 behind the light */
                if (in_cone) { t1 = 0.0; t2 = t2 > 0.0 ? t2 : MEDIA_MAX_DISTANCE; }
                else { t1 = t2; t2 = MEDIA_MAX_DISTANCE; }
            } else if (ahead == 1) { /* t2 behind */
                if (in_cone) { t2 = t1; t1 = 0.0; }
                else t2 = MEDIA_MAX_DISTANCE;
            }
            *d1 = t1;
            *d2 = t2;
            return 1;
        }
        if (d > -MEDIA_EPSILON) {
            if (in_cone) { *d1 = 0.0; *d2 = -b / a; }
            else { *d1 = -b / a; *d2 = MEDIA_MAX_DISTANCE; }
            return 1;
        }
        return 0;
    }
    if (in_cone) {
        *d1 = 0.0;
        *d2 = -c / b;
        return 1;
    }
    return 0;
}

/* Part of the ray within a cylinder light's falloff radius of its axis,
 * ahead of the light. */
static int cylinder_interval(vec3 org, vec3 dir, const scene_light *l, double *d1, double *d2)
{
    vec3 axis = v3_norm(v3_sub(l->point_at, l->position));
    vec3 v1 = v3_sub(org, l->position);
    double k1 = v3_dot(dir, axis), k2 = v3_dot(v1, axis);
    if (k1 <= 0.0 && k2 < 0.0) return 0;
    double a = 1.0 - k1 * k1;
    if (a == 0.0) return 0;
    double k3 = v3_dot(v1, dir), k4 = v3_dot(v1, v1);
    double b = k3 - k1 * k2, c = k4 - k2 * k2 - l->falloff * l->falloff;
    double d = b * b - a * c;
    if (!(d > MEDIA_EPSILON)) return 0;
    double t1, t2;
    int ahead = axial_roots(a, b, d, k1, k2, &t1, &t2);
    if (!ahead) return 0;
    if (ahead == 2) t1 = 0.0;
    else if (ahead == 1) t2 = (MEDIA_MAX_DISTANCE - k2) / k1;
    *d1 = t1;
    *d2 = t2;
    return 1;
}

typedef struct {
    const scene_light *l;
    double s0, s1;
} lit_light;

typedef struct {
    int lit;
    double s0, s1, ds;
    rgb te, od;
    int samples;
    rgb te2; /* sum of the squared sample lights (methods 1, 2) */
} interval;

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* ------------------------------------------------------------ sampling */

typedef struct {
    const shade_media_env *e;
    const media_ref *refs;
    int nrefs;
    vec3 org, dir;
    int shadow, use_scattering;
    const lit_light *lights;
    int nlights;
    const shade_media_inside *in;
    shade_pattern_ctx pc;
    int collect; /* some media acting takes photons */
} sampler;

/* The media photons around a sample, each through the phase function. */
typedef struct {
    const sampler *s;
    rgb sum;
} photon_acc;

static void photon_one(void *ctx, vec3 to_light, rgb light)
{
    photon_acc *a = ctx;
    double k = phase(a->s->refs, a->s->nrefs, v3_dot(to_light, a->s->dir));
    a->sum = add(a->sum, scl(light, k));
}

/* One sample at fraction d of interval iv: its emitted (and in-scattered)
 * light times ds in *col, its optical depth over ds in *od. Methods 1/2
 * accumulate into the interval (light attenuated over d * ds). */
static void one_sample(const sampler *s, interval *iv, double d, int method, rgb *col, rgb *od)
{
    double d0 = d * iv->ds, d1 = iv->s0 + d0;
    vec3 h = v3_madd(s->org, s->dir, d1);
    coeffs c = coeffs_at(s->refs, s->nrefs, h, s->shadow, &s->pc);
    *od = scl(c.ext, iv->ds);
    if (method != 3) iv->od = add(iv->od, *od);
    if (s->shadow) { /* extinction only: no light to add up */
        *col = mk(0, 0, 0);
        iv->samples++;
        return;
    }
    rgb emit = c.emit;
    if (!s->shadow && s->use_scattering && iv->lit && s->e->light && !is_zero(c.scat)) {
        for (int i = 0; i < s->nlights; i++) {
            if (d1 < s->lights[i].s0 || d1 > s->lights[i].s1) continue;
            vec3 to;
            rgb lc = s->e->light(s->e->ctx, s->e->thread, s->lights[i].l, h, s->in, s->collect, &to);
            if (is_zero(lc)) continue;
            double k = phase(s->refs, s->nrefs, v3_dot(to, s->dir));
            emit = add(emit, scl(mul(c.scat, lc), k));
        }
    }
    if (s->use_scattering && s->e->photons && !is_zero(c.scat)) {
        photon_acc pa = {s, {0, 0, 0}};
        s->e->photons(s->e->photons_ctx, h, photon_one, &pa);
        emit = add(emit, mul(c.scat, pa.sum));
    }
    if (method == 3) {
        emit = scl(emit, iv->ds);
    } else {
        emit = mul(scl(emit, iv->ds), expn(scl(c.ext, d0)));
        iv->te = add(iv->te, emit);
        iv->te2 = add(iv->te2, mul(emit, emit));
    }
    *col = emit;
    iv->samples++;
}

static double rnd(const shade_media_env *e) { return e->r ? rng_f64(e->r) : 0.5; }

/* POV-Ray's recursive adaptive sample between fractions d1 and d3. */
static void recursive_sample(const sampler *s, interval *iv, double d1, double d3, rgb c1, rgb c3, rgb od1, rgb od3,
                             int depth, double jitter, double aa, rgb *res, rgb *odres)
{
    double d2 = 0.5 * (d1 + d3);
    double jd = d2 + (jitter != 0.0 ? jitter * (d3 - d1) * (rnd(s->e) - 0.5) : 0.0);
    rgb c2, od2, r2, o2;
    one_sample(s, iv, jd, 3, &c2, &od2);
    if (depth <= 0) {
        *res = scl(add(add(c1, c2), c3), 1.0 / 3.0);
        *odres = scl(add(add(od1, od2), od3), 1.0 / 3.0);
        return;
    }
    if (dist3(c1, c2) > aa) {
        recursive_sample(s, iv, d1, d2, c1, c2, od1, od2, depth - 1, jitter, aa, &r2, &o2);
        *res = scl(r2, 0.5);
        *odres = scl(o2, 0.5);
    } else {
        *res = add(scl(c1, 1.0 / 3.0), scl(c2, 1.0 / 6.0));
        *odres = add(scl(od1, 1.0 / 3.0), scl(od2, 1.0 / 6.0));
    }
    if (dist3(c2, c3) > aa) {
        recursive_sample(s, iv, d2, d3, c2, c3, od2, od3, depth - 1, jitter, aa, &r2, &o2);
        *res = add(*res, scl(r2, 0.5));
        *odres = add(*odres, scl(o2, 0.5));
    } else {
        *res = add(*res, add(scl(c2, 1.0 / 6.0), scl(c3, 1.0 / 3.0)));
        *odres = add(*odres, add(scl(od2, 1.0 / 6.0), scl(od3, 1.0 / 3.0)));
    }
}

static void adaptive(const sampler *s, interval *iv, const scene_media *im, double aa)
{
    /* POV-Ray 3.7's ComputeMediaAdaptiveSampling: min_samples / 2 + 1
     * sub-intervals, their ends 1 / (count + 1) apart from the interval's
     * start (so the samples span count / (count + 1) of it); each
     * sub-interval's light is attenuated by the optical depth before it
     * only, not within itself. */
    int sub = im->min_samples / 2 + 1;
    if (sub < 2) sub = 2;
    double dd = 1.0 / (sub + 1);
    double n = 1.0 / sub;
    rgb c0, od0, c1, od1, res, odres;
    double j0 = im->jitter != 0.0 ? dd * im->jitter * (rnd(s->e) - 0.5) : 0.0;
    one_sample(s, iv, j0, 3, &c0, &od0);
    iv->te = mk(0, 0, 0);
    iv->od = mk(0, 0, 0);
    double d0 = 0.0;
    for (int j = 1; j <= sub; j++) {
        double d1 = d0 + dd;
        double jj = im->jitter != 0.0 ? dd * im->jitter * (rnd(s->e) - 0.5) : 0.0;
        one_sample(s, iv, d1 + jj, 3, &c1, &od1);
        recursive_sample(s, iv, d0, d1, c0, c1, od0, od1, im->aa_level - 1, im->jitter, aa, &res, &odres);
        if (!s->shadow) iv->te = add(iv->te, mul(res, expn(scl(iv->od, n))));
        iv->od = add(iv->od, odres);
        c0 = c1;
        od0 = od1;
        d0 = d1;
    }
    iv->samples = sub;
}

/* Variance of the mean of an interval's sample lights, per channel. */
static rgb sample_variance(const interval *iv)
{
    double n = 1.0 / iv->samples;
    rgb m = scl(iv->te, n);
    return scl(add(scl(iv->te2, n), scl(mul(m, m), -1.0)), n);
}

static int collect_refs(const shade_media_env *e, int which, const shade_media_inside *in, media_ref *refs)
{
    int n = 0;
    if (which == SHADE_MEDIA_ATMOSPHERE) {
        for (int i = 0; i < e->sc->natmosphere && n < MAX_REFS; i++) {
            refs[n].m = e->sc->atmosphere[i];
            refs[n].obj = NULL;
            n++;
        }
        return n;
    }
    for (int k = 0; in && k < in->n; k++) {
        const scene_object *o = in->obj[k];
        if (!o->interior) continue;
        for (int i = 0; i < o->interior->nmedia && n < MAX_REFS; i++) {
            refs[n].m = o->interior->media[i];
            refs[n].obj = &o->transform;
            n++;
        }
    }
    return n;
}

static int light_acts(const scene_light *l, const scene_object *hit)
{
    if (!l->media_interaction || l->shadowless) return 0;
    return scene_light_reaches(l, hit);
}

rgb shade_media_segment(const shade_media_env *e, int which, const shade_media_inside *in, vec3 org, vec3 dir, double depth, rgb c,
                  int shadow)
{
    media_ref refs[MAX_REFS];
    int nrefs = collect_refs(e, which, in, refs);
    if (nrefs == 0 || !(depth > 0.0)) return c;
    const scene_media *im = refs[0].m;
    double aa = HUGE_VAL;
    int use_ext = 0, use_scat = 0, all_constant = shadow, no_density = 1, collect = 0;
    for (int i = 0; i < nrefs; i++) {
        const scene_media *m = refs[i].m;
        if (m->intervals > im->intervals) im = m;
        if (m->aa_threshold < aa) aa = m->aa_threshold;
        if (!is_zero(m->absorption) || !is_zero(m->scattering)) use_ext = 1;
        if (!is_zero(m->scattering)) use_scat = 1;
        if (m->collect) collect = 1;
        if (m->ndensity > 0) no_density = 0;
        /* a density counts as constant when it is a plain colour */
        for (int k = 0; k < m->ndensity; k++)
            if (m->density[k]->kind == PIGMENT_PATTERN) all_constant = 0;
    }
    if (shadow && !use_ext) return c;
    if (shadow && no_density) {
        /* a shadow ray through media without densities: one interval of
         * one sample (see below), whose light is 0; what that sample
         * computes, the sum of the extinctions times the depth, without
         * the emission's exponentials */
        rgb ext = {0, 0, 0};
        for (int i = 0; i < nrefs; i++) ext = add(ext, add(refs[i].m->absorption, scl(refs[i].m->scattering, refs[i].m->extinction)));
        return mul(c, expn(scl(ext, depth)));
    }

    /* lit intervals */
    lit_light lights[MAX_LIGHTS];
    int nl = 0;
    if (!shadow) {
        for (int i = 0; i < e->sc->nlights && nl < MAX_LIGHTS; i++) {
            const scene_light *l = &e->sc->lights[i];
            if (!light_acts(l, e->hit)) continue;
            double t1 = 0.0, t2 = 0.0;
            int ins = 0;
            if (l->kind == LIGHT_SPOT) {
                if (spot_interval(org, dir, l, &t1, &t2)) ins = t1 < depth && t2 > MEDIA_SMALL_TOLERANCE;
            } else if (l->kind == LIGHT_CYLINDER) {
                if (cylinder_interval(org, dir, l, &t1, &t2)) ins = t1 < depth && t2 > MEDIA_SMALL_TOLERANCE;
            } else {
                t1 = 0.0;
                t2 = depth;
                ins = 1;
            }
            if (!ins) continue;
            lights[nl].l = l;
            lights[nl].s0 = fmax(t1, 0.0);
            lights[nl].s1 = fmin(t2, depth);
            nl++;
        }
    }
    typedef struct { int lit; double s0, s1; } lit_iv;
    lit_iv lit[2 * MAX_LIGHTS + 2];
    int nlit = 0;
    if (nl > 0) {
        double s0[MAX_LIGHTS], s1[MAX_LIGHTS];
        for (int i = 0; i < nl; i++) { s0[i] = lights[i].s0; s1[i] = lights[i].s1; }
        qsort(s0, (size_t)nl, sizeof s0[0], cmp_double);
        qsort(s1, (size_t)nl, sizeof s1[0], cmp_double);
        if (s0[0] > 0.0) lit[nlit++] = (lit_iv){0, 0.0, s0[0]};
        lit[nlit++] = (lit_iv){1, s0[0], s1[0]};
        for (int i = 1; i < nl; i++) {
            if (s0[i] > lit[nlit - 1].s1) {
                double prev = lit[nlit - 1].s1;
                lit[nlit++] = (lit_iv){0, prev, s0[i]};
                lit[nlit++] = (lit_iv){1, s0[i], s1[i]};
            } else if (s1[i] > lit[nlit - 1].s1) {
                lit[nlit - 1].s1 = s1[i];
            }
        }
        if (lit[nlit - 1].s1 < depth) {
            double prev = lit[nlit - 1].s1;
            lit[nlit++] = (lit_iv){0, prev, depth};
        }
    } else {
        lit[nlit++] = (lit_iv){0, 0.0, depth};
    }

    /* sampling intervals */
    interval ivs[MAX_INTERVALS + 2];
    int niv = 0;
    int want = im->intervals > nlit ? im->intervals : nlit;
    if (want > MAX_INTERVALS) want = MAX_INTERVALS;
    int constant = im->ndensity == 0;
    if (nlit == 1) {
        if (!lit[0].lit && constant) {
            ivs[niv++] = (interval){0, lit[0].s0, lit[0].s1, lit[0].s1 - lit[0].s0, {0, 0, 0}, {0, 0, 0}, 0, {0, 0, 0}};
        } else {
            double delta = (lit[0].s1 - lit[0].s0) / want;
            for (int i = 0; i < want; i++)
                ivs[niv++] = (interval){lit[0].lit, lit[0].s0 + delta * i, lit[0].s0 + delta * (i + 1), delta,
                                        {0, 0, 0}, {0, 0, 0}, 0, {0, 0, 0}};
        }
    } else {
        double sum = 0.0;
        for (int i = 0; i < nlit; i++) sum += lit[i].lit ? im->ratio : 1.0 - im->ratio;
        int remaining = want;
        for (int i = 0; i < nlit; i++) {
            double w = lit[i].lit ? im->ratio : 1.0 - im->ratio;
            int n = (int)(w / sum * want) + 1;
            int r = remaining - nlit + i + 1;
            if (n > r) n = r;
            if (n < 1) n = 1;
            double delta = (lit[i].s1 - lit[i].s0) / n;
            for (int j = 0; j < n && niv < MAX_INTERVALS; j++)
                ivs[niv++] = (interval){lit[i].lit, lit[i].s0 + delta * j, lit[i].s0 + delta * (j + 1), delta,
                                        {0, 0, 0}, {0, 0, 0}, 0, {0, 0, 0}};
            remaining -= n;
        }
    }
    if (niv == 0) return c;

    sampler s = {.e = e, .refs = refs, .nrefs = nrefs, .org = org, .dir = dir, .shadow = shadow,
                 .use_scattering = use_scat, .lights = lights, .nlights = nl, .in = in,
                 .pc = shade_pattern_ctx_plain(e->sc), .collect = collect};

    int nmin = im->min_samples > 0 ? im->min_samples : 1;
    for (int i = 0; i < niv; i++) {
        interval *iv = &ivs[i];
        if (im->method == 3 && !all_constant) {
            adaptive(&s, iv, im, aa);
            continue;
        }
        for (int j = 0; j < nmin; j++) {
            rgb col, od;
            double d;
            if (im->method == 2) d = (j + 0.5) / nmin + rnd(e) * im->jitter / nmin;
            else d = rnd(e);
            one_sample(&s, iv, d, im->method == 2 ? 2 : 1, &col, &od);
            if (all_constant) break;
        }
    }
    /* further samples where the view ray's samples vary too much */
    if (!shadow && im->method != 3 && im->max_samples > nmin) {
        double t = shade_chi2_inv_q(im->max_samples - 1, im->confidence);
        t = t > 0.0 ? im->variance / t : im->variance * MEDIA_EPSILON;
        for (int i = 0; i < niv; i++) {
            interval *iv = &ivs[i];
            if (iv->samples < 1 || iv->samples >= im->max_samples) continue;
            for (;;) {
                rgb va = sample_variance(iv);
                double thr = t * shade_chi2_inv_q(iv->samples, im->confidence);
                if (fabs(va.r) < thr && fabs(va.g) < thr && fabs(va.b) < thr) break;
                rgb col, od;
                one_sample(&s, iv, rnd(e), 1, &col, &od);
                if (iv->samples > im->max_samples) break;
            }
        }
    }

    rgb od = {0, 0, 0}, te = {0, 0, 0};
    for (int i = 0; i < niv; i++) {
        double n = ivs[i].samples > 0 ? 1.0 / ivs[i].samples : 0.0;
        if (!shadow) te = add(te, mul(scl(ivs[i].te, n), expn(od)));
        od = add(od, scl(ivs[i].od, n));
    }
    return add(mul(c, expn(od)), te);
}

/* ------------------------------------------------------------ shadow rays */

rgb shade_media_shadow_rest(const scene *sc, const shade_media_env *e, const scene_light *l, const shade_media_inside *in,
                            vec3 p, vec3 dir, double len, rgb c)
{
    if (!(l && l->media_interaction && l->media_attenuation) || !shade_media_inside_hollow(in) || !(len > 0.0)) return c;
    if (sc->natmosphere) c = shade_media_segment(e, SHADE_MEDIA_ATMOSPHERE, in, p, dir, len, c, 1);
    if (sc->fogs) c = mul(c, shade_atmos_fog_attenuation(sc, p, dir, len));
    return c;
}

typedef struct {
    const scene *sc;
    const shade_media_env *e;
    const scene_light *photon_light;
    vec3 p, dir;
    shade_tex_walk walk; /* POV-Ray's crossings taken */
    double prev;         /* where the current segment starts: the last crossing that let light through */
    int atmos;
    shade_media_inside in;
    rgb c;
} media_shadow_walk;

static int media_shadow_crossing(void *ctx, const accel_hit *h)
{
    media_shadow_walk *w = ctx;
    double depth;
    int inside;
    if (!shade_tex_walk_take(&w->walk, h, w->dir, &depth, &inside)) return 1;
    const scene_obj_photons *ph = h->obj ? h->obj->photons : NULL;
    if (w->photon_light && ph && ph->target && scene_photon_lobe(w->photon_light, ph, 1)) {
        w->c = mk(0, 0, 0); /* shade_tex_shadow_ray's photon rule */
        return 0;
    }
    const scene *sc = w->sc;
    accel_hit hh = *h;
    hh.t = depth;
    rgb f = shade_tex_shadow_filter_inside(sc, &hh, w->dir, inside);
    if (fabs(f.r) < MEDIA_EPSILON && fabs(f.g) < MEDIA_EPSILON && fabs(f.b) < MEDIA_EPSILON) {
        w->c = mk(0, 0, 0);
        return 0;
    }
    vec3 q = v3_madd(w->p, w->dir, w->prev);
    double len = h->t - w->prev;
    int hollow = shade_media_inside_hollow(&w->in);
    /* the containers' media over the segment (a hollow ray) */
    if (w->in.n > 0 && hollow && shade_media_inside_has_media(&w->in))
        f = shade_media_segment(w->e, SHADE_MEDIA_INTERIOR, &w->in, q, w->dir, len, f, 1);
    w->c = mul(w->c, f);
    /* POV-Ray applies the atmosphere before every surface crossed (each
     * object has an interior there); fog only while hollow */
    if (w->atmos && !is_zero(w->c)) {
        if (sc->natmosphere) w->c = shade_media_segment(w->e, SHADE_MEDIA_ATMOSPHERE, &w->in, q, w->dir, len, w->c, 1);
        if (sc->fogs && hollow) w->c = mul(w->c, shade_atmos_fog_attenuation(sc, q, w->dir, len));
    }
    if (fabs(w->c.r) < MEDIA_EPSILON && fabs(w->c.g) < MEDIA_EPSILON && fabs(w->c.b) < MEDIA_EPSILON) {
        w->c = mk(0, 0, 0);
        return 0;
    }
    shade_media_inside_cross(&w->in, h->obj);
    w->prev = h->t;
    return 1;
}

rgb shade_media_shadow_ray(const scene *sc, const accel *a, const shade_media_env *e, const scene_light *l, vec3 p, vec3 dir,
                           double tmin, double tmax, const shade_media_inside *in0, double *rest,
                           const scene_light *photon_light)
{
    media_shadow_walk w = {sc, e, photon_light, p, dir, {0.0, {0, {0}}}, 0.0, l && l->media_interaction && l->media_attenuation,
                           *in0, {1, 1, 1}};
    /* every surface crossed, each the nearest just past the one before,
     * from one traversal where the scene allows (accel_crossings) */
    accel_crossings_skip(a, p, dir, tmin, tmax, tmin, OBJ_NO_SHADOW, media_shadow_crossing, &w);
    /* past the last surface that let light through (a blocked sample's
     * too: its way is what an area light's last sample leaves) */
    if (rest) *rest = tmax - w.prev;
    if (is_zero(w.c)) return w.c;
    /* the rest of the way to the light: the atmosphere (a hollow ray) */
    if (!rest && tmax > w.prev) return shade_media_shadow_rest(sc, e, l, &w.in, v3_madd(p, dir, w.prev), dir, tmax - w.prev, w.c);
    return w.c;
}
