/* shade_normal.c - POV-Ray 3.7 normal perturbation (see shade_normal.h).
 *
 * Reproduced semantics (POV-Ray 3.7 normal.cpp and warps.cpp, studied, not
 * copied):
 *  - Warp_Normal takes a normal into pattern space through every transform
 *    of the pattern's warp list in order (n' = M^T n, M the forward
 *    transform), UnWarp_Normal back in reverse order (n' = M^-T n); both
 *    normalise before and after unless no_bump_scale.
 *  - bumps: n += amount * DNoise(p); dents: n += amount * Noise(p)^3 *
 *    DNoise(p); wrinkles: n += amount * sum_{i<10} |DNoise(2^i p)| / 2^i;
 *    ripples/waves: n += amount * sum over the 10 wave sources of
 *    cycloidal(|p - s| f (* wave frequency) + phase) (/ wave frequency)
 *    * (p - s) / (|p - s| * 10); quilted: n += amount * q(p) with the
 *    quilt cubic.
 *  - Any other pattern: four samples at p + accuracy * v_i over a regular
 *    tetrahedron v_i, each value (through the slope_map's Hermite segments
 *    if any) times -5 * amount * 0.02/accuracy added along v_i.
 *  - normal_map: entries evaluated at the warped point, blended linearly,
 *    normalised; average: weighted mean of the entries' perturbed normals. */
#include "shade_normal.h"
#include <math.h>
#include <stdlib.h>
#include "shade_noise.h"

static const vec3 pyramid[4] = {{0.942809041, -0.333333333, 0.0},
                                {-0.471404521, -0.333333333, 0.816496581},
                                {-0.471404521, -0.333333333, -0.816496581},
                                {0.0, 1.0, 0.0}};

static inline double pov_floor(double x) { return x >= 0.0 ? floor(x) : (0.0 - floor(0.0 - x) - 1.0); }

vec3 shade_normal_warp(vec3 n, const xform *xf, const xform *outer, const scene_pattern *pat, int dont_scale)
{
    if (!dont_scale) n = v3_norm(n);
    if (xf) n = shade_pattern_normal_to_pattern(xf, n);
    if (outer) n = shade_pattern_normal_to_pattern(outer, n);
    if (pat)
        for (int i = 0; i < pat->nwarps; i++)
            if (pat->warps[i].kind == WARP_TRANSFORM) n = shade_pattern_normal_to_pattern(&pat->warps[i].transform, n);
    if (!dont_scale) n = v3_norm(n);
    return n;
}

vec3 shade_normal_unwarp(vec3 n, const xform *xf, const xform *outer, const scene_pattern *pat, int dont_scale)
{
    if (!dont_scale) n = v3_norm(n);
    if (pat)
        for (int i = pat->nwarps - 1; i >= 0; i--)
            if (pat->warps[i].kind == WARP_TRANSFORM) n = xform_normal(&pat->warps[i].transform, n);
    if (outer) n = xform_normal(outer, n);
    if (xf) n = xform_normal(xf, n);
    if (!dont_scale) n = v3_norm(n);
    return n;
}

static double hermite(double t, double h1, double s1, double h2, double s2)
{
    double tt = t * t, ttt = tt * t;
    double rv = ttt * (s1 + s2 + 2.0 * (h1 - h2));
    rv += -tt * (2.0 * s1 + s2 + 3.0 * (h1 - h2));
    rv += t * s1 + h1;
    return rv;
}

static double slope_map(double v, const scene_blend_map *m)
{
    if (!m || m->kind != MAP_SLOPE) return v;
    int ip, ic;
    shade_blend_map_search(m, v, &ip, &ic);
    if (ip == ic) return m->e[ic].height;
    double t = (v - m->e[ip].value) / (m->e[ic].value - m->e[ip].value);
    return hermite(t, m->e[ip].height, m->e[ip].slope, m->e[ic].height, m->e[ic].slope);
}

static vec3 waves_normal(const scene_normal *nm, vec3 p, vec3 n, int ripples, int nw)
{
    const scene_pattern *pat = nm->pat;
    for (int i = 0; i < nw; i++) {
        vec3 d = v3_sub(p, shade_noise_wave_source(i));
        double len = v3_len(d);
        if (len == 0.0) len = 1.0;
        double s;
        if (ripples) {
            s = shade_noise_cycloidal(len * pat->frequency + pat->phase) * nm->amount;
        } else {
            double f = shade_noise_wave_frequency(i);
            s = shade_noise_cycloidal(len * pat->frequency * f + pat->phase) * nm->amount / f;
        }
        n = v3_madd(n, d, s / (len * (double)nw));
    }
    return n;
}

static vec3 perturb(const scene_normal *nm, vec3 n, vec3 p, const xform *xf, const shade_pattern_ctx *c);

/* The bump patterns proper (POV-Ray's normal-only patterns). */
static int is_bump_pattern(pattern_kind k)
{
    return k == PAT_BUMPS || k == PAT_DENTS || k == PAT_RIPPLES || k == PAT_WAVES || k == PAT_WRINKLES ||
           k == PAT_QUILTED || k == PAT_FACETS || k == PAT_AVERAGE || k == PAT_IMAGE;
}

static double grey(colour5 c) { return 0.297 * c.r + 0.589 * c.g + 0.114 * c.b; }

static double wrap_coord(double v, double n)
{
    if (v < 0.0) return v + n;
    if (v >= n) return v - n;
    return v;
}

/* POV-Ray's bump_map: heights (amount * grey) at the pixel and at its
 * lower-left and lower-right neighbours make a triangle whose normal tilts
 * the surface normal in a frame built from it and +y. */
static vec3 bump_map(const scene_normal *nm, vec3 n, vec3 tp)
{
    const scene_image_map *im = &nm->pat->image;
    double xc, yc;
    if (!shade_pattern_image_pos(im, tp, &xc, &yc)) return n;
    double w = im->image->width, h = im->image->height, a = nm->amount;
    /* use_index on a palette image: heights are the palette indices */
    int by_index = im->use_index && im->image->indices;
    double h1 = a * (by_index ? shade_pattern_image_index(im, xc, yc) : grey(shade_pattern_image_at(im, xc, yc)));
    xc = wrap_coord(xc - 1.0, w);
    yc = wrap_coord(yc + 1.0, h);
    double h2 = a * (by_index ? shade_pattern_image_index(im, xc, yc) : grey(shade_pattern_image_at(im, xc, yc)));
    xc = wrap_coord(xc + 2.0, w);
    double h3 = a * (by_index ? shade_pattern_image_index(im, xc, yc) : grey(shade_pattern_image_at(im, xc, yc)));
    vec3 p1 = v3(0, h1, 0), p2 = v3(-1, h2, 1), p3 = v3(1, h3, 1);
    vec3 bn = v3_norm(v3_cross(v3_sub(p3, p2), v3_sub(p1, p2)));
    vec3 yp = n, xp = v3_cross(yp, v3(0, 1, 0));
    double len = v3_len(xp);
    if (len < 1e-10) {
        yp = fabs(n.y - 1.0) < 1e-10 ? v3(0, 1, 0) : v3(0, -1, 0);
        xp = v3(1, 0, 0);
        len = 1.0;
    }
    xp = v3_scale(xp, 1.0 / len);
    vec3 zp = v3_norm(v3_cross(xp, yp));
    return v3_add(v3_add(v3_scale(xp, bn.x), v3_scale(yp, bn.y)), v3_scale(zp, -bn.z));
}

/* facets (POV-Ray 3.7's facets normal): the normal, or with `coords` the
 * point, scaled by 1/size, is snapped to the nearest of the random cell
 * points (one per unit cube, as crackle's) in the 81 cubes around it; the
 * facet's normal is that point. With coords c the point's DNoise gradient,
 * less its part along the normal, is added c times instead. Metric 1 sums
 * the signed differences, as POV-Ray does. */
static vec3 facets(const scene_pattern *pat, vec3 n, vec3 tp)
{
    double metric = pat->facets_metric;
    n = v3_norm(n);
    double scale = pat->facets_size < 1e-6 ? 1e6 : 1.0 / pat->facets_size;
    vec3 tv = v3_scale(pat->facets_coords != 0.0 ? tp : n, scale);
    double best = 0.0;
    vec3 pick = v3(0, 0, 0);
    int first = 1;
    for (int ax = -2; ax <= 2; ax++)
        for (int ay = -2; ay <= 2; ay++)
            for (int az = -2; az <= 2; az++) {
                if ((abs(ax) == 2) + (abs(ay) == 2) + (abs(az) == 2) > 1) continue;
                double fx = floor(tv.x + ax - 1.0e-10), fy = floor(tv.y + ay - 1.0e-10), fz = floor(tv.z + az - 1.0e-10);
                unsigned long seed = (unsigned long)shade_noise_hash3d(shade_noise_to_int(fx) & 0xFFF, shade_noise_to_int(fy) & 0xFFF,
                                                                 shade_noise_to_int(fz) & 0xFFF);
                vec3 cp = v3(fx + shade_noise_pattern_rand(seed), fy + shade_noise_pattern_rand(seed + 1), fz + shade_noise_pattern_rand(seed + 2));
                vec3 d = v3_sub(cp, tv);
                double sum;
                if (metric == 2) sum = d.x * d.x + d.y * d.y + d.z * d.z;
                else if (metric == 1) sum = d.x + d.y + d.z;
                else sum = pow(fabs(d.x), metric) + pow(fabs(d.y), metric) + pow(fabs(d.z), metric);
                if (first || sum < best) {
                    best = sum;
                    pick = cp;
                    first = 0;
                }
            }
    if (pat->facets_coords == 0.0) return pick;
    vec3 pert = shade_noise_dvector(pick);
    pert = v3_sub(pert, v3_scale(n, v3_dot(pert, n)));
    return v3_madd(n, pert, pat->facets_coords);
}

static vec3 bump_pattern(const scene_normal *nm, vec3 n, vec3 tp, const shade_pattern_ctx *c)
{
    const scene_pattern *pat = nm->pat;
    int gen = pat->noise_generator ? pat->noise_generator : c->noise_generator;
    switch (pat->kind) {
    case PAT_BUMPS: return v3_madd(n, shade_noise_dvector(tp), nm->amount);
    case PAT_DENTS: {
        double v = shade_noise_value(tp, gen);
        return v3_madd(n, shade_noise_dvector(tp), v * v * v * nm->amount);
    }
    case PAT_RIPPLES: return waves_normal(nm, tp, n, 1, c->nwaves > 0 ? c->nwaves : SHADE_NOISE_WAVES);
    case PAT_WAVES: return waves_normal(nm, tp, n, 0, c->nwaves > 0 ? c->nwaves : SHADE_NOISE_WAVES);
    case PAT_WRINKLES: {
        /* DNoise at tp scaled by 1, 2, 4, ... 512 */
        vec3 r = v3(0, 0, 0), d[10];
        double scale = 1.0;
        shade_noise_dvector_octaves(tp, 10, 2.0, d);
        for (int i = 0; i < 10; scale *= 2.0, i++) {
            vec3 v = d[i];
            r.x += fabs(v.x / scale);
            r.y += fabs(v.y / scale);
            r.z += fabs(v.z / scale);
        }
        return v3_madd(n, r, nm->amount);
    }
    case PAT_QUILTED: {
        vec3 v = v3(tp.x - pov_floor(tp.x) - 0.5, tp.y - pov_floor(tp.y) - 0.5, tp.z - pov_floor(tp.z) - 0.5);
        double t = sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
        double it = 1 - t;
        t = (t * t * t + 3.0 * t * it * it * pat->control0 + 3.0 * t * t * it * pat->control1) * 1.154700538;
        return v3_madd(n, v3_scale(v, t), nm->amount);
    }
    case PAT_AVERAGE: {
        const scene_blend_map *m = nm->map;
        if (!m || m->kind != MAP_NORMAL) return n;
        vec3 acc = v3(0, 0, 0);
        double total = 0.0;
        for (int i = 0; i < m->n; i++) {
            float w = (float)m->e[i].value;
            vec3 v = m->e[i].normal ? perturb(m->e[i].normal, n, tp, NULL, c) : n;
            acc = v3_madd(acc, v, w);
            total += w;
        }
        return total != 0.0 ? v3_scale(acc, 1.0 / total) : n;
    }
    case PAT_IMAGE: return bump_map(nm, n, tp);
    case PAT_FACETS: return facets(pat, n, tp);
    default: return n;
    }
}

static vec3 perturb(const scene_normal *nm, vec3 n, vec3 p, const xform *xf, const shade_pattern_ctx *c)
{
    const scene_pattern *pat = nm->pat;
    if (!pat || pat->kind == PAT_PLAIN) return n;
    /* normal { uv_mapping ... }: at the hit's <u, v, 0> (POV-Ray's
     * UV_MAP_PATTERN in normal.cpp), without the texture's transforms */
    if (pat->uv_mapping && c && c->has_uv) {
        p = v3(c->uv[0], c->uv[1], 0.0);
        xf = NULL;
    }
    const xform *outer = xform_is_identity(&nm->transform) ? NULL : &nm->transform;
    int ds = nm->no_bump_scale;
    vec3 q = outer ? xform_inv_point(outer, p) : p;
    const scene_blend_map *m = nm->map;
    if (m && m->kind == MAP_NORMAL && pat->kind != PAT_AVERAGE) {
        vec3 tp = shade_pattern_warp(pat, q);
        double v = shade_pattern_value(pat, tp, c);
        int ip, ic;
        shade_blend_map_search(m, v, &ip, &ic);
        n = shade_normal_warp(n, xf, outer, pat, ds);
        vec3 p1 = n;
        if (m->e[ic].normal) n = perturb(m->e[ic].normal, n, tp, NULL, c);
        if (ip != ic) {
            if (m->e[ip].normal) p1 = perturb(m->e[ip].normal, p1, tp, NULL, c);
            double v2 = (v - m->e[ip].value) / (m->e[ic].value - m->e[ip].value);
            double v1 = 1.0 - v2;
            n = v3_add(v3_scale(p1, v1), v3_scale(n, v2));
        }
        n = shade_normal_unwarp(n, xf, outer, pat, ds);
        return v3_norm(n);
    }
    if (is_bump_pattern(pat->kind)) {
        n = shade_normal_warp(n, xf, outer, pat, ds);
        vec3 tp = shade_pattern_warp(pat, q);
        n = bump_pattern(nm, n, tp, c);
        return shade_normal_unwarp(n, xf, outer, pat, ds);
    }
    n = shade_normal_warp(n, xf, outer, pat, ds);
    double amount = nm->amount * -5.0;
    amount *= 0.02 / nm->delta;
    vec3 tp = shade_pattern_warp(pat, q);
    for (int i = 0; i < 4; i++) {
        vec3 p1 = v3_madd(tp, pyramid[i], nm->delta);
        double v = slope_map(shade_pattern_value(pat, p1, c), m);
        n = v3_madd(n, pyramid[i], v * amount);
    }
    return shade_normal_unwarp(n, xf, outer, pat, ds);
}

vec3 shade_normal_perturb(const scene_normal *nm, vec3 n, vec3 p, const xform *xf, const shade_pattern_ctx *c)
{
    if (!nm) return n;
    return perturb(nm, n, p, xf, c);
}
