/* gi_caustic.c - the caustic layer (see gi_caustic.h). */
#include "gi_caustic.h"
#include "grow.h"
#include "scene_leaves.h"
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "geom_extent.h"
#include "gi_cl.h"
#include "gi_cl_c.h"
#include "pool.h"
#include "timer.h"

/* A photon ray passes no_shadow objects (POV-Ray trace.cpp: a photon ray
 * skips NO_SHADOW objects). On its way to the target it goes straight on
 * through pass_through objects, filtered by them (the hooks' pass: POV-Ray
 * 3.7 builds photons.cpp with PT_FILTER_BEFORE_TARGET, "pass_through
 * objects encountered before target do affect photons color"); a lemon
 * slice hanging over grenadine's glass tints, or with its opaque peel
 * stops, the photons that cross it before the glass. Past the target a
 * pass_through object is like any other (PhotonTrace::TraceRay tests the
 * flag only for the first ray and after a pass-through). */
#define PHOTON_SKIP OBJ_NO_SHADOW
#define GBUF_LAYERS 8
/* k of r_xy = k s_D / sqrt(rho_p): 9 unfocused spacings, about 250
 * photons of an unfocused beam within r_xy. The paper gives no constant;
 * this one was chosen on phot_met_glass, glassthing and grenadine at
 * 160x120 against POV-Ray (bench/caustics.sh: k = 2.5, POV-Ray's minimum
 * gather count of 20 photons, left visible speckle; 9 came closer to
 * POV-Ray's images than 6 on all three, 12 blurred phot_met_glass) */
#define RADIUS_K 9.0
/* k of a media photon's sphere radius r = k (s_l^2 s_a)^(1/3), s_l its
 * lateral spacing (s_D / sqrt(rho_p)) and s_a its step along the way: the
 * sphere holds about 4 pi k^3 / 3 = 65 photons of an unfocused beam, of
 * the order of POV-Ray's media gather, which takes up to its gather
 * maximum (100 by default) within a radius sized from the map's mean
 * density (photons.cpp, setGatherOptions). Chosen on optics.pov against
 * POV-Ray's render at 4x its photons (docs/caustics.md, step 8). */
#define MEDIA_RADIUS_K 2.5
#define CHUNK 2048
/* most photons shot in all (memory and time stay bounded whatever the scene asks) */
#define MAX_CELLS 4194304.0
/* most media photons kept in all (64 bytes each, and up to 8 grid entries):
 * each chunk of bounce-map cells keeps at most its share, thinning its own
 * (deposit_media) */
#define MAX_MEDIA_PHOTONS 2097152L

static inline rgb crgb(double r, double g, double b)
{
    rgb c = {r, g, b};
    return c;
}
static inline rgb cscale(rgb a, double k) { return crgb(a.r * k, a.g * k, a.b * k); }

/* ------------------------------------------------------------ hash grid */

/* Items (spheres) binned into cubic cells of edge `cell`: each item is
 * listed in every cell its sphere's box touches, or, when that is more
 * than BIG_CELLS cells, in `up`, the same kind of grid with cells 4 times
 * as large (up to HGRID_LEVELS levels; past the last, in `big`, which
 * every lookup reads whole). Photon volumes' radii span orders of
 * magnitude (the gather minimum widens the sparse ones up to threefold):
 * one flat list of the wide ones made every lookup read thousands. A
 * lookup reads its cell at each level. Cells are found by hashing their
 * integer coordinates; a collision only adds candidates that the exact
 * tests drop. */
#define BIG_CELLS 64
#define HGRID_LEVELS 6
typedef struct {
    uint64_t key;
    int id;
} cell_entry;
typedef struct hgrid {
    double cell;
    cell_entry *e;
    long n;
    int *big;
    long nbig;
    struct hgrid *up; /* the items too wide for these cells, or NULL */
} hgrid;

static uint64_t cell_key(long ix, long iy, long iz)
{
    uint64_t h = (uint64_t)ix * 0x9E3779B97F4A7C15ULL ^ (uint64_t)iy * 0xC2B2AE3D27D4EB4FULL ^
                 (uint64_t)iz * 0x165667B19E3779F9ULL;
    h ^= h >> 29;
    h *= 0xBF58476D1CE4E5B9ULL;
    return h ^ (h >> 32);
}

static int entry_cmp(const void *a, const void *b)
{
    const cell_entry *x = a, *y = b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return x->id - y->id;
}

static long cidx(double v, double cell) { return (long)floor(v / cell); }

static void hgrid_free(hgrid *g);

/* The grid of items ids[0..n) (NULL: 0..n-1) at level `level`. */
static int hgrid_build_at(hgrid *g, double cell, long n, const int *ids, const float *c, size_t stride, const float *r,
                          size_t rstride, int level)
{
    memset(g, 0, sizeof *g);
    g->cell = cell;
    long cap = 0, nwide = 0;
    for (long j = 0; j < n; j++) {
        long i = ids ? ids[j] : j;
        const float *p = c + (size_t)i * stride;
        double rad = r[(size_t)i * rstride];
        long nx = cidx(p[0] + rad, cell) - cidx(p[0] - rad, cell) + 1;
        long ny = cidx(p[1] + rad, cell) - cidx(p[1] - rad, cell) + 1;
        long nz = cidx(p[2] + rad, cell) - cidx(p[2] - rad, cell) + 1;
        long k = nx * ny * nz;
        if (k > BIG_CELLS) nwide++;
        else cap += k;
    }
    g->e = malloc(sizeof(cell_entry) * (size_t)(cap > 0 ? cap : 1));
    g->big = malloc(sizeof(int) * (size_t)(nwide > 0 ? nwide : 1));
    if (!g->e || !g->big) return 0;
    for (long j = 0; j < n; j++) {
        long i = ids ? ids[j] : j;
        const float *p = c + (size_t)i * stride;
        double rad = r[(size_t)i * rstride];
        long x0 = cidx(p[0] - rad, cell), x1 = cidx(p[0] + rad, cell);
        long y0 = cidx(p[1] - rad, cell), y1 = cidx(p[1] + rad, cell);
        long z0 = cidx(p[2] - rad, cell), z1 = cidx(p[2] + rad, cell);
        if ((x1 - x0 + 1) * (y1 - y0 + 1) * (z1 - z0 + 1) > BIG_CELLS) {
            g->big[g->nbig++] = (int)i;
            continue;
        }
        for (long x = x0; x <= x1; x++)
            for (long y = y0; y <= y1; y++)
                for (long z = z0; z <= z1; z++) g->e[g->n++] = (cell_entry){cell_key(x, y, z), (int)i};
    }
    qsort(g->e, (size_t)g->n, sizeof *g->e, entry_cmp);
    if (g->nbig > 0 && level + 1 < HGRID_LEVELS) {
        g->up = malloc(sizeof *g->up);
        if (!g->up) return 0;
        int ok = hgrid_build_at(g->up, 4.0 * cell, g->nbig, g->big, c, stride, r, rstride, level + 1);
        g->nbig = 0; /* they are up there */
        if (!ok) return 0;
    }
    return 1;
}

/* centres c (stride floats apart, 3 coordinates at c + i*stride) with radii r */
static int hgrid_build(hgrid *g, double cell, long n, const float *c, size_t stride, const float *r, size_t rstride)
{
    return hgrid_build_at(g, cell, n, NULL, c, stride, r, rstride, 0);
}

static void hgrid_free(hgrid *g)
{
    if (g->up) {
        hgrid_free(g->up);
        free(g->up);
    }
    free(g->e);
    free(g->big);
    memset(g, 0, sizeof *g);
}

/* The entries of cell (x, y, z): [*lo, *hi). */
static void hgrid_cell(const hgrid *g, long x, long y, long z, long *lo, long *hi)
{
    uint64_t k = cell_key(x, y, z);
    long a = 0, b = g->n;
    while (a < b) {
        long m = (a + b) / 2;
        if (g->e[m].key < k) a = m + 1;
        else b = m;
    }
    long e = a;
    while (e < g->n && g->e[e].key == k) e++;
    *lo = a;
    *hi = e;
}

/* ------------------------------------------------------------ the layer */

typedef struct {
    const scene_light *l;
    const scene_object *target;
    const scene_object **leaves; /* the target's leaf objects, sorted by address */
    int nleaves;
    int parallel;
    vec3 origin;       /* light position (point-like) */
    vec3 axis;         /* towards the target's centre / the parallel direction */
    vec3 ctr;
    double rad;
    double cos_max;    /* cone of directions (point-like) */
    int m;             /* bounce map: m x m cells */
    double cell;       /* solid angle (point-like) or area (parallel) of a cell */
    rgb phi0;          /* colour x cell */
    long first;        /* index of its first cell among all */
    gi_caustic_inside in0; /* the objects holding the light (hooks.containers), where its photons start */
} combo;

struct gi_caustic {
    const scene *sc;
    const accel *a;
    gi_caustic_settings s;
    gi_caustic_hooks hk;
    double eps;
    combo *cb;
    int ncb;
    long total;        /* bounce-map cells of all combos */
    int max_level;
    double adc;
    double r_max;
    /* photons */
    gi_caus_photon *ph;
    long nph;
    hgrid pgrid;
    /* photons on highlight-only surfaces (GI_CAUSTIC_HIGHLIGHTS): never
     * splatted, only visited */
    gi_caus_photon *hl;
    long nhl;
    hgrid hlgrid;
    /* media photons (spheres: r_xy = r_z = their radius, n unused) */
    gi_caus_photon *mp;
    long nmp;
    hgrid mgrid;
    /* G-buffer */
    int w, h;
    gi_caus_pixel *gb;
    const scene_object **gobj;
    float *grad;       /* per pixel footprint radius (0: invalid) */
    hgrid ggrid;
    float *img;        /* splat result, 4 floats a pixel */
    int *tile_off, *tile_idx;
    int tiles_x, tiles_y;
    gi_dev *dev;
    gi_caustic_stats st;
};

static int ptr_cmp(const void *a, const void *b)
{
    const void *x = *(const void *const *)a, *y = *(const void *const *)b;
    return x < y ? -1 : x > y;
}

static int count_leaves(const scene_object *o)
{
    if (!scene_object_is_csg(o)) return 1;
    int n = 0;
    for (int i = 0; i < o->u.csg.nkids; i++) n += count_leaves(o->u.csg.kids[i]);
    return n;
}

static void add_leaves(const scene_object *o, const scene_object **out, int *n)
{
    if (!scene_object_is_csg(o)) {
        out[(*n)++] = o;
        return;
    }
    for (int i = 0; i < o->u.csg.nkids; i++) add_leaves(o->u.csg.kids[i], out, n);
}

static int in_target(const combo *c, const scene_object *o)
{
    return o && bsearch(&o, c->leaves, (size_t)c->nleaves, sizeof *c->leaves, ptr_cmp) != NULL;
}

static double cmax3(rgb c) { return fmax(c.r, fmax(c.g, c.b)); }

/* POV-Ray's shooting targets (photonestimationtask.cpp
 * SearchThroughObjectsEstimatePhotons): a target object as a whole, else
 * the members of a CSG; objects with global lights off get no photons. */
static int collect_targets(const scene_object *o, const scene_object ***list, int *n, int *cap)
{
    if (o->photons && o->photons->target) {
        if (o->no_global_lights) return 1;
        if (!grow_array_int((void **)list, cap, *n + 1, sizeof **list)) return 0;
        (*list)[(*n)++] = o;
        return 1;
    }
    if (scene_object_is_csg(o))
        for (int i = 0; i < o->u.csg.nkids; i++)
            if (!collect_targets(o->u.csg.kids[i], list, n, cap)) return 0;
    return 1;
}

static int light_parallel(const scene_light *l) { return l->parallel || l->kind == LIGHT_PARALLEL || l->kind == LIGHT_CYLINDER; }

/* POV-Ray's estimate of the photons one light-target pair shoots
 * (photonestimationtask.cpp EstimatePhotonsForObjectAndLight), for spacing s. */
static double pov_estimate(const scene_light *l, const scene_obj_photons *t, double rad, double s)
{
    double x = rad / (t->spacing * s);
    x = x * x * M_PI;
    int rfr = (l->ph_refraction || t->refraction) && !(l->ph_refraction_off || t->refraction_off);
    int rfl = (l->ph_reflection || t->reflection) && !(l->ph_reflection_off || t->reflection_off);
    if (rfr && rfl) x *= 1.5;
    if (t->collect && rfr) x *= rfl ? 3.0 : 2.0;
    return x * 0.5;
}

/* Equal-area map of [0,1)^2 onto the unit disc (Shirley and Chiu's
 * concentric map): (rho, phi). */
static void concentric(double u, double v, double *rho, double *phi)
{
    double a = 2.0 * u - 1.0, b = 2.0 * v - 1.0;
    if (a == 0.0 && b == 0.0) {
        *rho = 0.0;
        *phi = 0.0;
    } else if (fabs(a) > fabs(b)) {
        *rho = a;
        *phi = (M_PI / 4.0) * (b / a);
    } else {
        *rho = b;
        *phi = M_PI / 2.0 - (M_PI / 4.0) * (a / b);
    }
    if (*rho < 0.0) {
        *rho = -*rho;
        *phi += M_PI;
    }
}

typedef struct {
    gi_caus_photon *p;
    long n, cap;
    gi_caus_photon *hl; /* highlight-only surfaces' photons */
    long nhl, caphl;
    gi_caus_photon *mp; /* media photons */
    long nmp, capmp;
    long mquota;        /* most media photons this chunk keeps (MAX_MEDIA_PHOTONS shared out) */
    long mstride, mseen; /* every mstride-th media photon left is kept (1 until the quota is met) */
    long rays, first_hits, absorbed_first;
    long alive[GI_CAUSTIC_MAX_BOUNCES + 1];
    int oom;
} chunk_out;

enum { STORE_SPLAT, STORE_HIGHLIGHT, STORE_MEDIA };
static int push_photon(chunk_out *o, const gi_caus_photon *q, int kind)
{
    gi_caus_photon **p = kind == STORE_MEDIA ? &o->mp : kind == STORE_HIGHLIGHT ? &o->hl : &o->p;
    long *n = kind == STORE_MEDIA ? &o->nmp : kind == STORE_HIGHLIGHT ? &o->nhl : &o->n;
    long *cap = kind == STORE_MEDIA ? &o->capmp : kind == STORE_HIGHLIGHT ? &o->caphl : &o->cap;
    if (!grow_array_long((void **)p, cap, *n + 1, sizeof **p)) return 0;
    (*p)[(*n)++] = *q;
    return 1;
}

/* The direction a photon came from (unit d) as POV-Ray 3.7 stores and
 * reads it: two signed bytes, its elevation above the world's xz plane and
 * its azimuth about the y axis, each angle * 127 / pi truncated towards
 * zero (photons.cpp, addSurfacePhoton), decoded as angle = byte * pi / 127
 * (SinCosOptimizations) when the gather shades the photon
 * (trace.cpp, ComputePhotonDiffuseLight). The truncation tilts a photon
 * up to 1.4 degrees towards the xz plane and about y; a receiver of
 * brilliance b sees the tilt in its weight c^b / c (brilliance 1 does not:
 * the cosines cancel), most at low elevations (docs/caustics.md,
 * Receivers). The side test (c > 0) sees it too, as POV-Ray's does. */
static vec3 pov_photon_dir(vec3 d)
{
    double l = v3_len(d);
    if (!(l > 0.0)) return d;
    d = v3_scale(d, 1.0 / l);
    double dl = sqrt(d.x * d.x + d.z * d.z);
    double phi = dl > 0.0 ? acos(fmax(-1.0, fmin(1.0, d.x / dl))) : 0.0;
    if (d.z < 0.0) phi = -phi;
    double theta = acos(fmin(1.0, dl));
    if (d.y < 0.0) theta = -theta;
    double tq = (double)(int)(theta * 127.0 / M_PI) * M_PI / 127.0;
    double pq = (double)(int)(phi * 127.0 / M_PI) * M_PI / 127.0;
    return v3(cos(tq) * cos(pq), sin(tq), cos(tq) * sin(pq));
}
/* Media photons along one straight segment of a photon's path, org + t w
 * for 0 <= t <= len, that starts at path length D (POV-Ray 3.7's
 * photons.cpp, DepositMediaPhotons and addMediaPhoton, for semantics):
 *  - spacing: u = s D (point lights; s = the cell's angular spacing,
 *    sqrt of its solid angle) or u = s (parallel lights; s = the cell's
 *    edge), the distance to the photon's neighbours at the segment's start;
 *  - count: n = floor(len / (f u)), f the media spacing factor; when n
 *    exceeds max_steps, n = max_steps and f = len / (u n) (the steps grow);
 *    n = 0 leaves no photon (POV-Ray's integer truncation);
 *  - place j: t = (j + 1/2 + jitter (xi - 1/2)) / n len;
 *  - colour: the photon's light (tr x the cell's colour) times the cell's
 *    cross-section at D + t times its step f s (D + t) (point: f s^3
 *    (D + t)^3; parallel: f s^3, phi0 holding s^2), times the light's
 *    fade and spot attenuation at D + t: a light colour once summed over a
 *    volume (gi_caustic_media_visit's kernel), as a surface photon is once
 *    summed over an area. tr is the photon's colour at the segment's start:
 *    POV-Ray deposits before the segment's extinction and fade. */
static int deposit_media(const gi_caustic *c, const combo *cb, vec3 org, vec3 w, double len, double D, rgb tr,
                         double rho_p, vec3 p_first, rng *r, chunk_out *out)
{
    const scene_photons *ps = &c->sc->global.photons;
    double s = sqrt(cb->cell), u = cb->parallel ? s : s * D, f = ps->media_factor > 0.0 ? ps->media_factor : 1.0;
    if (!(u > 0.0) || !(len > 0.0)) return 1;
    double nd = floor(len / (f * u));
    long n = nd > (double)ps->media_steps ? ps->media_steps : (long)nd;
    if (n <= 0) return 1;
    if (nd > (double)ps->media_steps) f = len / (u * (double)n);
    double jit = ps->jitter, sa = len / (double)n;
    vec3 wq = pov_photon_dir(v3_neg(w));
    for (long j = 0; j < n; j++) {
        double t = (j + 0.5 + jit * (rng_f64(r) - 0.5)) / (double)n * len, Dt = D + t;
        /* past the chunk's quota only every mstride-th photon is kept, with
         * mstride times the power and a sphere holding as many of them */
        if (out->mseen++ % out->mstride) continue;
        double thin = (double)out->mstride;
        double att = c->hk.attenuation(c->hk.ctx, cb->l, p_first, Dt);
        double k = att * f * s * (cb->parallel ? 1.0 : Dt * Dt * Dt) * thin;
        double sl = (cb->parallel ? s : s * Dt) / sqrt(rho_p);
        double rad = fmin(MEDIA_RADIUS_K * cbrt(sl * sl * sa * thin), c->r_max);
        vec3 x = v3_madd(org, w, t);
        float ir2 = (float)(1.0 / (rad * rad));
        gi_caus_photon q = {{(float)x.x, (float)x.y, (float)x.z},
                            (float)rad,
                            {0, 0, 0},
                            (float)rad,
                            {(float)wq.x, (float)wq.y, (float)wq.z},
                            ir2,
                            {(float)(cb->phi0.r * tr.r * k), (float)(cb->phi0.g * tr.g * k), (float)(cb->phi0.b * tr.b * k)},
                            ir2};
        if (!(rad > 0.0) || !isfinite(q.phi[0] + q.phi[1] + q.phi[2]) || !(cmax3(crgb(q.phi[0], q.phi[1], q.phi[2])) > 0.0))
            continue;
        if (!push_photon(out, &q, STORE_MEDIA)) return 0;
        if (out->nmp >= out->mquota) {
            /* the quota met: every other photon kept so far goes, the rest
             * take their power and a sphere as wide as theirs and their
             * neighbour's together (deterministic: one chunk, in order) */
            long m = 0;
            for (long i = 0; i < out->nmp; i += 2) {
                gi_caus_photon p = out->mp[i];
                for (int ch = 0; ch < 3; ch++) p.phi[ch] *= 2.0f;
                double r2 = fmin(p.r_xy * cbrt(2.0), c->r_max);
                p.r_xy = p.r_z = (float)r2;
                p.inv_rxy2 = p.inv_rz2 = (float)(1.0 / (r2 * r2));
                out->mp[m++] = p;
            }
            out->nmp = m;
            out->mstride *= 2;
        }
    }
    return 1;
}

/* r_z, a photon volume's reach along its surface normal, for in-plane
 * radius r_xy: as far as POV-Ray's gather reaches off the surface. Its
 * gather (photons.cpp, PhotonGatherer::gatherPhotonsRec with `flatten`)
 * takes up to the gather maximum (`gather min, max`, 100 by default) within
 * a sphere, and "flattens" it by adding 16 |n . d| d^2 to a photon's squared
 * distance d^2, |n . d| the photon's distance off the surface in scene
 * units (not a ratio): along the normal a photon is gathered within z of
 * z^2 (1 + 16 z) = r^2, r the gather radius. The volume takes for r the
 * radius that holds the gather maximum of its own photons' unfocused beam,
 * r_xy sqrt(max / pi) / RADIUS_K. So on a glass wall thinner than that
 * reach (balcony's drinking glass, 0.0022 thick under photons 0.002 apart)
 * a point on one face takes the photons stored on the other face, as
 * POV-Ray's gather does. Newton's method from z = r, where the cubic is
 * above r^2, converges from above. */
static double normal_reach(const gi_caustic *c, double rxy)
{
    int gmax = c->sc->global.photons.gather_max > 0 ? c->sc->global.photons.gather_max : 100;
    double r = rxy * sqrt(gmax / M_PI) / RADIUS_K, z = r;
    for (int i = 0; i < 40; i++) {
        double f = z * z * (1.0 + 16.0 * z) - r * r, dz = f / (2.0 * z + 48.0 * z * z);
        z -= dz;
        if (!(dz > 1e-9 * z)) break;
    }
    return isfinite(z) && z > 0.0 ? fmin(z, rxy) : 0.25 * rxy;
}

/* A photon volume's radii from its in-plane radius: r_xy, the reach off
 * its surface (normal_reach) and their inverse squares. */
static void set_radii(const gi_caustic *c, gi_caus_photon *q, double rxy)
{
    double rz = normal_reach(c, rxy);
    q->r_xy = (float)rxy;
    q->r_z = (float)rz;
    q->inv_rxy2 = (float)(1.0 / (rxy * rxy));
    q->inv_rz2 = (float)(1.0 / (rz * rz));
}

/* One bounce-map cell: the photon's direction (and origin), then its path. */
static void trace_cell(const gi_caustic *c, const combo *cb, long cell, chunk_out *out)
{
    const scene_light *l = cb->l;
    rng r;
    rng_seed(&r, c->s.seed ^ 0x6361757374696373ULL, (uint64_t)(cb->first + cell));
    int i = (int)(cell % cb->m), j = (int)(cell / cb->m);
    double jit = c->sc->global.photons.jitter;
    double u = (i + 0.5 + jit * (rng_f64(&r) - 0.5)) / cb->m, v = (j + 0.5 + jit * (rng_f64(&r) - 0.5)) / cb->m;
    u = fmin(fmax(u, 0.0), 1.0 - 1e-12);
    v = fmin(fmax(v, 0.0), 1.0 - 1e-12);
    double rho, ang;
    concentric(u, v, &rho, &ang);
    vec3 t, b;
    v3_basis(cb->axis, &t, &b);
    vec3 o, w;
    if (cb->parallel) {
        vec3 q = v3_add(cb->ctr, v3_add(v3_scale(t, cb->rad * rho * cos(ang)), v3_scale(b, cb->rad * rho * sin(ang))));
        o = v3_sub(q, v3_scale(cb->axis, v3_dot(v3_sub(q, l->position), cb->axis)));
        w = cb->axis;
    } else {
        /* equal area: the cap fraction (1 - cos) / (1 - cos_max) is rho^2 */
        double ct = 1.0 - rho * rho * (1.0 - cb->cos_max), st = sqrt(fmax(0.0, 1.0 - ct * ct));
        w = v3_add(v3_add(v3_scale(t, st * cos(ang)), v3_scale(b, st * sin(ang))), v3_scale(cb->axis, ct));
        o = cb->origin;
        if (l->area && l->ph_area_light && l->size1 * l->size2 > 1) {
            /* photons { area_light }: POV-Ray shoots every grid point per
             * direction with 1/(size1 size2) of the colour; one point per
             * cell here, in turn, with the full colour: the same density */
            int np = l->size1 * l->size2, k = (int)((cb->first + cell) % np);
            o = v3_add(o, scene_light_area_point(l, l->axis1, l->axis2, k / l->size2, k % l->size2, &r));
        }
    }
    /* the photon's branches still to trace, depth first (a split pushes
     * both; each level adds at most one pending branch) */
    typedef struct {
        vec3 o, w;
        accel_from from;
        int has_from, level;
        double depth, rho_p;
        rgb tr;
        double tw; /* POV-Ray's ray weight (gi_caustic_step.trace_w): the photon goes on while it is at least
                      adc_bailout (photons.cpp, TraceRay) */
        gi_caustic_inside in;
        double t0; /* hits from here on (0: the self-intersection distance) */
        double tp; /* the last pass_through surface crossed along this ray (0: none) */
    } branch;
    branch stack[2 * GI_CAUSTIC_MAX_BOUNCES + 4];
    int ns = 0;
    stack[ns++] = (branch){o, w, {0}, 0, 0, 0.0, 1.0, {1, 1, 1}, 1.0, cb->in0, 0.0, 0.0};
    vec3 p_first = o;
    int passes = 0;
    while (ns > 0) {
        branch br = stack[--ns];
        accel_hit h;
        if (accel_intersect_past(c->a, br.has_from ? &br.from : NULL, br.o, br.w, fmax(c->eps, br.t0), PHOTON_SKIP,
                                 &h, &out->rays) <= 0)
            continue;
        int level = br.level;
        double depth = br.depth + h.t;
        if (level == 0) {
            /* the first hit must be the target, or a pass_through object
             * that the photon crosses towards it (POV-Ray's PhotonTrace) */
            if (!in_target(cb, h.obj)) {
                gi_caustic_step st;
                accel_hit hp = h; /* its fade over the way since the surface before */
                hp.t = h.t - br.tp;
                if (!(h.obj && h.obj->photons && h.obj->photons->pass_through) || !c->hk.pass ||
                    ++passes > ACCEL_PASS_MAX || !c->hk.pass(c->hk.ctx, &hp, br.w, &br.in, &st))
                    return;
                rgb tr = crgb(br.tr.r * st.weight.r, br.tr.g * st.weight.g, br.tr.b * st.weight.b);
                double tw = br.tw * st.trace_w;
                if (!(tw >= c->adc) || !(cmax3(tr) > 0.0) || !isfinite(tr.r + tr.g + tr.b)) return;
                /* on along the same ray from the same origin, past the
                 * hit as accel_intersect_past steps (an isosurface's
                 * crossings, found from the ray's start, stay the same) */
                stack[ns++] = (branch){br.o, br.w, br.from, br.has_from, 0, br.depth, br.rho_p, tr, tw, st.inside,
                                       h.t + fmax(c->eps, h.t * 1e-7), h.t};
                continue;
            }
            out->first_hits++;
            p_first = h.p;
        }
        if (level >= 1 && c->hk.media && br.in.n > 0) {
            /* the media of the containers over the way here: photons left
             * in them (after the first surface, POV-Ray's traceLevel > 1),
             * then the photon dimmed by their extinction */
            rgb trm = {1, 1, 1};
            if (c->hk.media(c->hk.ctx, &br.in, br.o, br.w, h.t, &trm) && c->sc->global.photons.media_steps > 0 &&
                !deposit_media(c, cb, br.o, br.w, h.t, br.depth, br.tr, br.rho_p, p_first, &r, out)) {
                out->oom = 1;
                return;
            }
            br.tr = crgb(br.tr.r * trm.r, br.tr.g * trm.g, br.tr.b * trm.b);
        }
        gi_caustic_step step[2];
        int sf = c->hk.surface(c->hk.ctx, &h, br.w, &br.in, &r, step);
        const scene_obj_photons *ph = h.obj ? h.obj->photons : NULL;
        if (level >= 1 && (sf & (GI_CAUSTIC_RECEIVES | GI_CAUSTIC_HIGHLIGHTS)) && !(ph && !ph->collect) &&
            scene_light_reaches(l, h.obj)) {
            /* store the photon before this bounce (paper, step 1(d)) */
            double att = c->hk.attenuation(c->hk.ctx, l, p_first, depth);
            double k = att * (cb->parallel ? 1.0 : depth * depth);
            rgb fd = c->hk.fade ? c->hk.fade(c->hk.ctx, &h, br.w) : (rgb){1, 1, 1};
            double sd = cb->parallel ? sqrt(cb->cell) : depth * sqrt(cb->cell);
            double rxy = fmin(RADIUS_K * sd / sqrt(br.rho_p), c->r_max);
            vec3 np = v3_dot(h.ng, br.w) < 0.0 ? h.ng : v3_neg(h.ng), wq = pov_photon_dir(v3_neg(br.w));
            gi_caus_photon q = {.x = {(float)h.p.x, (float)h.p.y, (float)h.p.z},
                                .n = {(float)np.x, (float)np.y, (float)np.z},
                                .w = {(float)wq.x, (float)wq.y, (float)wq.z},
                                .phi = {(float)(cb->phi0.r * br.tr.r * fd.r * k), (float)(cb->phi0.g * br.tr.g * fd.g * k),
                                        (float)(cb->phi0.b * br.tr.b * fd.b * k)}};
            set_radii(c, &q, rxy);
            if (rxy > 0.0 && isfinite(q.phi[0] + q.phi[1] + q.phi[2]) && cmax3(crgb(q.phi[0], q.phi[1], q.phi[2])) > 0.0)
                if (!push_photon(out, &q, sf & GI_CAUSTIC_RECEIVES ? STORE_SPLAT : STORE_HIGHLIGHT)) {
                    out->oom = 1;
                    return;
                }
        }
        if (level + 1 >= c->max_level || level >= GI_CAUSTIC_MAX_BOUNCES) continue;
        if (!(sf & GI_CAUSTIC_CONTINUES)) {
            /* no specular lobe: absorbed, or only a Lambertian or glossy lobe */
            if (level == 0) out->absorbed_first++;
            continue;
        }
        int nstep = sf & GI_CAUSTIC_SPLIT ? 2 : 1, went = 0;
        for (int k = nstep - 1; k >= 0; k--) {
            const gi_caustic_step *st = &step[k];
            if (!scene_photon_lobe(l, ph, st->refract)) continue;
            rgb tr = crgb(br.tr.r * st->weight.r, br.tr.g * st->weight.g, br.tr.b * st->weight.b);
            double tw = br.tw * st->trace_w;
            if (!(tw >= c->adc) || !(cmax3(tr) > 0.0) || !isfinite(tr.r + tr.g + tr.b)) continue;
            if (ns >= (int)(sizeof stack / sizeof stack[0])) continue;
            stack[ns++] = (branch){st->org, st->dir, st->from, 1, level + 1, depth,
                                   br.rho_p * fmin(1.0, fmax(st->rho, 1e-6)), tr, tw, st->inside, 0.0, 0.0};
            went = 1;
        }
        if (went) out->alive[level + 1]++;
    }
}

typedef struct {
    gi_caustic *c;
    chunk_out *outs;
} trace_job;

static void trace_chunk(void *ctx, int ci, int thread)
{
    (void)thread;
    trace_job *tj = ctx;
    gi_caustic *c = tj->c;
    if (c->s.cancel && *c->s.cancel) return;
    long i0 = (long)ci * CHUNK, i1 = i0 + CHUNK < c->total ? i0 + CHUNK : c->total;
    int k = 0;
    for (long i = i0; i < i1 && !tj->outs[ci].oom; i++) {
        while (k < c->ncb - 1 && i >= c->cb[k + 1].first) k++;
        trace_cell(c, &c->cb[k], i - c->cb[k].first, &tj->outs[ci]);
    }
}

/* ------------------------------------------------------------ setup */

static pt_status make_combos(gi_caustic *c, diag *d)
{
    const scene *sc = c->sc;
    const scene_object **tg = NULL;
    int nt = 0, cap = 0;
    for (int i = 0; i < sc->nobjects; i++)
        if (!collect_targets(sc->objects[i], &tg, &nt, &cap)) {
            free(tg);
            return PT_ERR_NOMEM;
        }
    c->cb = calloc((size_t)(nt * sc->nlights + 1), sizeof *c->cb);
    if (!c->cb) {
        free(tg);
        return PT_ERR_NOMEM;
    }
    src_loc nowhere = {0};
    for (int li = 0; li < sc->nlights; li++) {
        const scene_light *l = &sc->lights[li];
        if (cmax3(l->colour) <= 0.0) continue;
        for (int ti = 0; ti < nt; ti++) {
            const scene_object *t = tg[ti];
            if (!scene_photon_shoots(l, t->photons)) continue;
            vec3 lo, hi;
            const char *what = NULL;
            if (geom_extent(t, &lo, &hi, &what) != 0 || !(fabs(lo.x) < 1e9 && fabs(hi.x) < 1e9 && fabs(lo.y) < 1e9 &&
                                                         fabs(hi.y) < 1e9 && fabs(lo.z) < 1e9 && fabs(hi.z) < 1e9)) {
                diag_warn_once(d, t->photons->loc, "photons: target without a finite bounding box (%s) gets no photons",
                               what ? what : t->name);
                continue;
            }
            combo *cb = &c->cb[c->ncb];
            cb->l = l;
            cb->target = t;
            cb->ctr = v3_scale(v3_add(lo, hi), 0.5);
            cb->rad = 0.5 * v3_len(v3_sub(hi, lo));
            cb->parallel = light_parallel(l);
            int n = count_leaves(t);
            cb->leaves = malloc(sizeof *cb->leaves * (size_t)n);
            if (!cb->leaves) {
                free(tg);
                return PT_ERR_NOMEM;
            }
            add_leaves(t, cb->leaves, &cb->nleaves);
            qsort(cb->leaves, (size_t)cb->nleaves, sizeof *cb->leaves, ptr_cmp);
            /* POV-Ray starts each photon inside every object holding the
             * light (photonshootingtask.cpp: the interiors of the objects
             * Inside the ray's origin); the light's position stands for
             * the points of an area light and a parallel light's plane */
            if (c->hk.containers) c->hk.containers(c->hk.ctx, l->position, &cb->in0);
            c->ncb++;
        }
    }
    free(tg);
    (void)nowhere;
    return PT_OK;
}

/* Sets cb's direction frame; the photons it asks for at global spacing s. */
static double combo_cells(combo *cb, double s)
{
    const scene_light *l = cb->l;
    double spread = cb->target->photons->spacing * s;
    if (cb->parallel) {
        cb->axis = v3_norm(v3_sub(l->point_at, l->position));
        return M_PI * cb->rad * cb->rad / (spread * spread);
    }
    cb->origin = l->position;
    vec3 to = v3_sub(cb->ctr, l->position);
    double dist = v3_len(to);
    cb->axis = dist > 0.0 ? v3_scale(to, 1.0 / dist) : v3(0, 0, 1);
    if (dist > cb->rad) {
        double sa = cb->rad / dist;
        cb->cos_max = sqrt(fmax(0.0, 1.0 - sa * sa));
    } else {
        cb->cos_max = -1.0;
        dist = cb->rad;
    }
    /* POV-Ray's angular step atan(spread / dist) in both angles */
    double dt = atan(spread / dist);
    return 2.0 * M_PI * (1.0 - cb->cos_max) / (dt * dt);
}

/* The global spacing (POV-Ray: `count` rescales it from the estimate of
 * all pairs), then each pair's bounce map. */
static void size_combos(gi_caustic *c, diag *d)
{
    const scene_photons *ps = &c->sc->global.photons;
    double s = ps->spacing > 0.0 ? ps->spacing : 1.0;
    if (ps->count > 0) {
        double est = 0.0;
        for (int i = 0; i < c->ncb; i++) est += pov_estimate(c->cb[i].l, c->cb[i].target->photons, c->cb[i].rad, s);
        if (est > 0.0) s *= sqrt(est / ps->count);
    }
    if (c->s.count_scale > 0.0) s /= sqrt(c->s.count_scale);
    /* at most MAX_CELLS photons in all: a larger request (a tiny spacing, a
     * huge count) is scaled down, with a warning */
    for (int pass = 0; pass < 2; pass++) {
        double want = 0.0;
        for (int i = 0; i < c->ncb; i++) want += combo_cells(&c->cb[i], s);
        if (pass == 0 && want > MAX_CELLS) {
            diag_warn_once(d, c->sc->global.photons.loc, "photons: %.3g photons asked for; shooting %.3g (the caustic layer's limit)",
                           want, (double)MAX_CELLS);
            s *= sqrt(want / MAX_CELLS) * 1.0001;
        } else {
            break;
        }
    }
    c->st.spacing = s;
    long total = 0;
    for (int i = 0; i < c->ncb; i++) {
        combo *cb = &c->cb[i];
        const scene_light *l = cb->l;
        double n = combo_cells(cb, s);
        int m = (int)ceil(sqrt(fmin(fmax(n, 1.0), MAX_CELLS)));
        cb->m = m;
        long cells = (long)m * m;
        cb->cell = cb->parallel ? M_PI * cb->rad * cb->rad / cells : 2.0 * M_PI * (1.0 - cb->cos_max) / cells;
        cb->phi0 = cscale(l->colour, cb->cell);
        cb->first = total;
        total += cells;
    }
    c->total = total;
}

/* ------------------------------------------------------------ G-buffer */

typedef struct {
    gi_caustic *c;
} gb_job;

static void gbuf_row(void *ctx, int y, int thread)
{
    (void)thread;
    gi_caustic *c = ((gb_job *)ctx)->c;
    const scene *sc = c->sc;
    for (int x = 0; x < c->w; x++) {
        size_t k = (size_t)y * c->w + x;
        gi_caus_pixel *px = &c->gb[k];
        memset(px, 0, sizeof *px);
        c->gobj[k] = NULL;
        c->grad[k] = 0.0f;
        vec3 o, d, o1, d1, o2, d2;
        scene_camera_ray(&sc->camera, x + 0.5, y + 0.5, c->w, c->h, &o, &d);
        scene_camera_ray(&sc->camera, x + 1.5, y + 0.5, c->w, c->h, &o1, &d1);
        scene_camera_ray(&sc->camera, x + 0.5, y + 1.5, c->w, c->h, &o2, &d2);
        rng r;
        rng_seed(&r, c->s.seed ^ 0x67627566ULL, k);
        double tmin = c->eps;
        accel_hit h;
        for (int layer = 0; layer < GBUF_LAYERS; layer++) {
            if (!accel_intersect(c->a, o, d, tmin, INFINITY, &h)) break;
            tmin = h.t + fmax(c->eps, h.t * 1e-7);
            if (h.flags & OBJ_NO_IMAGE) continue;
            const scene_obj_photons *ph = h.obj ? h.obj->photons : NULL;
            if (ph && !ph->collect) continue;
            if (!(c->hk.surface(c->hk.ctx, &h, d, NULL, &r, NULL) & GI_CAUSTIC_RECEIVES)) continue;
            vec3 n = v3_dot(h.ng, d) < 0.0 ? h.ng : v3_neg(h.ng);
            v3_store_f(px->s, h.p);
            px->valid = 1.0f;
            v3_store_f(px->n, n);
            double back = 0.0;
            px->brilliance = c->hk.brilliance ? (float)c->hk.brilliance(c->hk.ctx, &h, d, &back) : 1.0f;
            px->back = (float)back;
            c->gobj[k] = h.obj;
            /* footprint: the distance to the neighbouring pixels' rays at
             * the same distance, so a lookup at this point takes its own
             * splatted value alone and one between points a tent mix of
             * the nearest (gi_caustic_at); a wider footprint blurred
             * every pixel's caustic with its neighbours' */
            double t = h.t;
            double f1 = v3_len(v3_sub(v3_madd(o1, d1, t), h.p)), f2 = v3_len(v3_sub(v3_madd(o2, d2, t), h.p));
            c->grad[k] = (float)fmax(fmax(f1, f2), 1e-6 * (t + 1.0));
            break;
        }
    }
}

/* ------------------------------------------------------------ binning and splat */


/* Binning, photon by photon: the tiles' bounds (the valid G-buffer points
 * of each GI_CAUS_TILE-pixel tile) sit in a hierarchy, tiles in blocks of
 * BIN_FAN x BIN_FAN tiles, blocks in blocks of those, up to a top level of
 * at most BIN_FAN x BIN_FAN boxes; a photon goes down into each box its
 * kernel sphere reaches and is listed in each tile it reaches. The cost is the photons' overlap with
 * the image plus a few box tests each, whatever the photons' spread in
 * space (a walk over a grid of photons per tile visited every empty cell of
 * a tile's bounds: a tile seeing far-off walls spans many). */
#define BIN_FAN 4
#define BIN_MAX_LEVELS 12
#define BIN_CHUNK 4096

typedef struct {
    float lo[3], hi[3]; /* lo > hi: no valid point */
} bin_box;

typedef struct {
    int nx, ny;   /* boxes in a row, rows */
    bin_box *box;
} bin_level;

typedef struct {
    gi_caustic *c;
    bin_level lv[BIN_MAX_LEVELS]; /* 0: tiles, then blocks of the level below */
    int nlv;
    int **pairs;      /* per chunk: (tile, photon) pairs, photons ascending */
    long *npairs, *caps;
} bin_job;

static int sphere_meets_box(const gi_caus_photon *p, const bin_box *b)
{
    if (!(b->lo[0] <= b->hi[0])) return 0;
    float dd = 0.0f;
    for (int k = 0; k < 3; k++) {
        float e = p->x[k] < b->lo[k] ? b->lo[k] - p->x[k] : (p->x[k] > b->hi[k] ? p->x[k] - b->hi[k] : 0.0f);
        dd += e * e;
    }
    return dd <= p->r_xy * p->r_xy;
}

static void box_add(bin_box *b, const float *s)
{
    for (int k = 0; k < 3; k++) {
        b->lo[k] = fminf(b->lo[k], s[k]);
        b->hi[k] = fmaxf(b->hi[k], s[k]);
    }
}

static int bin_levels(gi_caustic *c, bin_level *lv, int *nlv)
{
    lv[0].nx = c->tiles_x;
    lv[0].ny = c->tiles_y;
    int n = 1;
    while (n < BIN_MAX_LEVELS && (lv[n - 1].nx > BIN_FAN || lv[n - 1].ny > BIN_FAN)) {
        lv[n].nx = (lv[n - 1].nx + BIN_FAN - 1) / BIN_FAN;
        lv[n].ny = (lv[n - 1].ny + BIN_FAN - 1) / BIN_FAN;
        n++;
    }
    *nlv = n;
    for (int l = 0; l < n; l++) {
        lv[l].box = malloc(sizeof(bin_box) * (size_t)lv[l].nx * (size_t)lv[l].ny);
        if (!lv[l].box) return 0;
        for (long i = 0; i < (long)lv[l].nx * lv[l].ny; i++)
            for (int k = 0; k < 3; k++) {
                lv[l].box[i].lo[k] = INFINITY;
                lv[l].box[i].hi[k] = -INFINITY;
            }
    }
    for (int y = 0; y < c->h; y++)
        for (int x = 0; x < c->w; x++) {
            const gi_caus_pixel *px = &c->gb[(size_t)y * c->w + x];
            if (!(px->valid > 0.0f)) continue;
            int tx = x / GI_CAUS_TILE, ty = y / GI_CAUS_TILE;
            for (int l = 0; l < *nlv; l++) {
                box_add(&lv[l].box[(size_t)ty * lv[l].nx + tx], px->s);
                tx /= BIN_FAN;
                ty /= BIN_FAN;
            }
        }
    return 1;
}

static int push_pair(bin_job *bj, int ci, int tile, int id)
{
    if (!grow_array_long((void **)&bj->pairs[ci], &bj->caps[ci], 2 * (bj->npairs[ci] + 1), sizeof(int))) return 0;
    bj->pairs[ci][2 * bj->npairs[ci]] = tile;
    bj->pairs[ci][2 * bj->npairs[ci] + 1] = id;
    bj->npairs[ci]++;
    return 1;
}

/* The children of box (x, y) of level l that photon p reaches, down to the
 * tiles. 0: out of memory. */
static int bin_descend(bin_job *bj, int ci, const gi_caus_photon *p, int id, int l, int x, int y)
{
    const bin_level *lv = &bj->lv[l];
    if (!sphere_meets_box(p, &lv->box[(size_t)y * lv->nx + x])) return 1;
    if (l == 0) return push_pair(bj, ci, y * lv->nx + x, id);
    const bin_level *dn = &bj->lv[l - 1];
    for (int j = y * BIN_FAN; j < (y + 1) * BIN_FAN && j < dn->ny; j++)
        for (int i = x * BIN_FAN; i < (x + 1) * BIN_FAN && i < dn->nx; i++)
            if (!bin_descend(bj, ci, p, id, l - 1, i, j)) return 0;
    return 1;
}

static void bin_chunk(void *ctx, int ci, int thread)
{
    (void)thread;
    bin_job *bj = ctx;
    gi_caustic *c = bj->c;
    long i0 = (long)ci * BIN_CHUNK, i1 = i0 + BIN_CHUNK < c->nph ? i0 + BIN_CHUNK : c->nph;
    const bin_level *top = &bj->lv[bj->nlv - 1];
    for (long i = i0; i < i1; i++)
        for (int y = 0; y < top->ny; y++)
            for (int x = 0; x < top->nx; x++)
                if (!bin_descend(bj, ci, &c->ph[i], (int)i, bj->nlv - 1, x, y)) {
                    bj->npairs[ci] = -1;
                    return;
                }
}

static pt_status bin_and_splat(gi_caustic *c, diag *d)
{
    double t0 = timer_now();
    int nt = c->tiles_x * c->tiles_y;
    int threads = c->s.threads > 0 ? c->s.threads : pool_default_threads();
    int nchunks = (int)((c->nph + BIN_CHUNK - 1) / BIN_CHUNK);
    bin_job bj = {c, {{0}}, 0, calloc((size_t)(nchunks > 0 ? nchunks : 1), sizeof(int *)),
                  calloc((size_t)(nchunks > 0 ? nchunks : 1), sizeof(long)),
                  calloc((size_t)(nchunks > 0 ? nchunks : 1), sizeof(long))};
    free(c->tile_off);
    free(c->tile_idx);
    c->tile_idx = NULL;
    c->tile_off = calloc((size_t)nt + 1, sizeof(int));
    pt_status st = PT_OK;
    if (!bj.pairs || !bj.npairs || !bj.caps || !c->tile_off || !bin_levels(c, bj.lv, &bj.nlv)) st = PT_ERR_NOMEM;
    if (st == PT_OK) {
        pool_run(threads, nchunks, bin_chunk, &bj);
        /* counting sort by tile; the chunks in order keep each tile's
         * photons ascending, so the sums do not depend on the binning */
        long tot = 0;
        for (int ci = 0; ci < nchunks; ci++) {
            if (bj.npairs[ci] < 0) st = PT_ERR_NOMEM;
            for (long k = 0; k < bj.npairs[ci]; k++) c->tile_off[bj.pairs[ci][2 * k] + 1]++;
            tot += bj.npairs[ci] > 0 ? bj.npairs[ci] : 0;
        }
        if (tot > 0x7fffffffL) st = PT_ERR_NOMEM; /* tile_off is int (the kernel's) */
        for (int t = 0; t < nt; t++) c->tile_off[t + 1] += c->tile_off[t];
        c->st.tile_entries = tot;
        if (st == PT_OK) c->tile_idx = malloc(sizeof(int) * (size_t)(tot > 0 ? tot : 1));
        if (!c->tile_idx) st = PT_ERR_NOMEM;
        if (st == PT_OK) {
            int *fill = malloc(sizeof(int) * (size_t)(nt > 0 ? nt : 1));
            if (!fill) st = PT_ERR_NOMEM;
            else {
                memcpy(fill, c->tile_off, sizeof(int) * (size_t)nt);
                for (int ci = 0; ci < nchunks; ci++)
                    for (long k = 0; k < bj.npairs[ci]; k++)
                        c->tile_idx[fill[bj.pairs[ci][2 * k]]++] = bj.pairs[ci][2 * k + 1];
                free(fill);
            }
        }
    }
    for (int ci = 0; bj.pairs && ci < nchunks; ci++) free(bj.pairs[ci]);
    free(bj.pairs);
    free(bj.npairs);
    free(bj.caps);
    for (int l = 0; l < BIN_MAX_LEVELS; l++) free(bj.lv[l].box);
    c->st.t_bin = timer_now() - t0;
    if (st != PT_OK) return st;
    t0 = timer_now();
    st = gi_dev_caustic_splat(c->dev, c->ph, (int)c->nph, c->tile_off, nt, c->tile_idx, c->gb, c->w, c->h, c->tiles_x,
                              c->img, d);
    c->st.t_splat = timer_now() - t0;
    return st;
}

/* ------------------------------------------------------------ build */

static int float_cmp(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return x < y ? -1 : x > y;
}

static double median_of(const float *v, long n, size_t stride)
{
    if (n <= 0) return 0.0;
    float *t = malloc(sizeof(float) * (size_t)n);
    if (!t) return v[0];
    long m = 0;
    for (long i = 0; i < n; i++)
        if (v[(size_t)i * stride] > 0.0f) t[m++] = v[(size_t)i * stride];
    double r = 0.0;
    if (m > 0) {
        qsort(t, (size_t)m, sizeof(float), float_cmp);
        r = t[m / 2];
    }
    free(t);
    return r;
}

/* POV-Ray's gather minimum for the photon volumes. Its gather
 * (photons.cpp, PhotonGatherer::gatherPhotonsAdaptive) widens a search that
 * finds fewer than the minimum count (`gather min, max`, 20 by default) by
 * a step of twice its starting radius, once by default (gatherNumSteps
 * 2): up to three times the radius (WIDEN_MAX). The photon volumes are the
 * scatter form of the same estimate: a photon whose volume holds fewer
 * than the scene's gather minimum m of photon positions (its own included, of photons on the same side of the same
 * surface: normals within 60 degrees, by the volume's own ellipsoidal
 * distance) is widened to hold m, at most WIDEN_MAX times its radius and
 * r_max. A volume integrates to its photon's power
 * whatever its radius, so this spreads, not adds, light: where the path
 * density rho_p over-states the real density (a beam spread by a convex
 * reflector, whose divergence rho_p does not see) the sparse photons
 * were each a speckle. Each photon's new radius depends on the old radii
 * and positions alone (any thread count gives the same layer). */
#define WIDEN_MAX 3.0
#define WIDEN_CHUNK 1024
/* The photons' positions are binned at several cell sizes, r_median times
 * 1, 4, 16, ...: a search of reach R reads the level whose cells are at
 * least R / 2, so it visits at most 5^3 cells whatever R is (the volumes'
 * radii span orders of magnitude: a dim caustic's photons are few and
 * wide, and one level of cells r_median across made their searches visit
 * up to (6 r / r_median)^3 cells each). */
#define WIDEN_LEVELS 8

typedef struct {
    gi_caustic *c;
    int m;         /* the gather minimum */
    int nlv;       /* levels of g in use */
    hgrid g[WIDEN_LEVELS]; /* photon positions (zero radius), cells r_median 4^k */
    float *r;      /* the new radii */
    atomic_long widened;
    atomic_int oom;
} widen_job;

/* The k-th smallest (0-based) of v[0..n), v reordered (Hoare's select). */
static double kth_smallest(double *v, long n, long k)
{
    long lo = 0, hi = n - 1;
    while (lo < hi) {
        double pivot = v[lo + (hi - lo) / 2];
        long i = lo, j = hi;
        while (i <= j) {
            while (v[i] < pivot) i++;
            while (v[j] > pivot) j--;
            if (i <= j) {
                double t = v[i];
                v[i++] = v[j];
                v[j--] = t;
            }
        }
        if (k <= j) hi = j;
        else if (k >= i) lo = i;
        else return v[k];
    }
    return v[k];
}

/* The distances (the volume's own: sqrt(d_plane^2 + (d_n r_xy / r_z)^2))
 * of the photons within `reach` of photon q on the same side of the same
 * surface, appended to *buf (NULL: only counted); how many, -1 out of
 * memory. Stops counting at `enough` when buf is NULL. */
static long widen_scan(const widen_job *wj, const gi_caus_photon *q, double reach, long enough, double **buf,
                       long *cap)
{
    const gi_caustic *c = wj->c;
    int lv = 0;
    while (lv + 1 < wj->nlv && wj->g[lv].cell < 0.5 * reach) lv++;
    const hgrid *g = &wj->g[lv];
    double cell = g->cell;
    long n = 0;
    long x0 = cidx(q->x[0] - reach, cell), x1 = cidx(q->x[0] + reach, cell);
    long y0 = cidx(q->x[1] - reach, cell), y1 = cidx(q->x[1] + reach, cell);
    long z0 = cidx(q->x[2] - reach, cell), z1 = cidx(q->x[2] + reach, cell);
    for (long x = x0; x <= x1; x++)
        for (long y = y0; y <= y1; y++)
            for (long z = z0; z <= z1; z++) {
                long lo, hi;
                hgrid_cell(g, x, y, z, &lo, &hi);
                for (long e = lo; e < hi; e++) {
                    const gi_caus_photon *o = &c->ph[g->e[e].id];
                    if (o->n[0] * q->n[0] + o->n[1] * q->n[1] + o->n[2] * q->n[2] < 0.5f) continue;
                    double dx = o->x[0] - q->x[0], dy = o->x[1] - q->x[1], dz = o->x[2] - q->x[2];
                    double dn = dx * q->n[0] + dy * q->n[1] + dz * q->n[2];
                    double dp2 = fmax(dx * dx + dy * dy + dz * dz - dn * dn, 0.0);
                    double t = sqrt(dp2 + dn * dn * (double)q->r_xy * q->r_xy * q->inv_rz2);
                    if (!(t < reach)) continue;
                    if (buf) {
                        if (!grow_array_long((void **)buf, cap, n + 1, sizeof(double))) return -1;
                        (*buf)[n] = t;
                    }
                    if (++n >= enough && !buf) return n;
                }
            }
    return n;
}

static void widen_chunk(void *ctx, int ci, int thread)
{
    (void)thread;
    widen_job *wj = ctx;
    const gi_caustic *c = wj->c;
    long i0 = (long)ci * WIDEN_CHUNK, i1 = i0 + WIDEN_CHUNK < c->nph ? i0 + WIDEN_CHUNK : c->nph;
    double *buf = NULL;
    long cap = 0;
    for (long i = i0; i < i1; i++) {
        const gi_caus_photon *q = &c->ph[i];
        double r = q->r_xy, R = fmin(WIDEN_MAX * r, c->r_max);
        wj->r[i] = (float)r;
        if (!(R > r) || widen_scan(wj, q, r, wj->m, NULL, NULL) >= wj->m) continue;
        long n = widen_scan(wj, q, R, 0, &buf, &cap);
        if (n < 0) {
            atomic_store(&wj->oom, 1);
            break;
        }
        double w = n >= wj->m ? kth_smallest(buf, n, wj->m - 1) : R;
        if (w > r) {
            wj->r[i] = (float)fmin(w, R);
            atomic_fetch_add(&wj->widened, 1);
        }
    }
    free(buf);
}

/* widens the splatted photons' volumes to the gather minimum; 0 out of memory */
static int widen_sparse(gi_caustic *c, int threads)
{
    int m = c->sc->global.photons.gather_min;
    if (c->nph <= 0 || m <= 1) return 1;
    widen_job wj = {c, m, 0, {{0}}, malloc(sizeof(float) * (size_t)c->nph), 0, 0};
    float zero = 0.0f, rmax = 0.0f;
    for (long i = 0; i < c->nph; i++) rmax = fmaxf(rmax, c->ph[i].r_xy);
    double cell = c->st.r_median > 0.0 ? c->st.r_median : 1.0;
    /* levels up to cells of half the widest reach */
    int ok = wj.r != NULL;
    for (int k = 0; ok && k < WIDEN_LEVELS; k++) {
        ok = hgrid_build(&wj.g[k], cell, c->nph, c->ph[0].x, sizeof(gi_caus_photon) / sizeof(float), &zero, 0);
        wj.nlv = k + 1;
        if (cell >= 0.5 * WIDEN_MAX * rmax) break;
        cell *= 4.0;
    }
    if (ok) {
        int nchunks = (int)((c->nph + WIDEN_CHUNK - 1) / WIDEN_CHUNK);
        pool_run(threads, nchunks, widen_chunk, &wj);
        ok = !atomic_load(&wj.oom);
    }
    if (ok) {
        for (long i = 0; i < c->nph; i++) {
            set_radii(c, &c->ph[i], wj.r[i]);
        }
        c->st.widened = atomic_load(&wj.widened);
    }
    free(wj.r);
    for (int k = 0; k < WIDEN_LEVELS; k++) hgrid_free(&wj.g[k]);
    return ok;
}

gi_caustic *gi_caustic_build(const scene *sc, const accel *a, const gi_caustic_settings *s, const gi_caustic_hooks *hk,
                             diag *d, pt_status *status)
{
    *status = PT_OK;
    if (!sc->global.photons.enabled) return NULL;
    gi_caustic *c = calloc(1, sizeof *c);
    if (!c) {
        *status = PT_ERR_NOMEM;
        return NULL;
    }
    c->sc = sc;
    c->a = a;
    c->s = *s;
    c->hk = *hk;
    c->eps = accel_surface_eps(a); /* the shader's, so photons cross thin walls as eye rays do */
    c->r_max = 0.05 * accel_scale(a);
    const scene_photons *ps = &sc->global.photons;
    c->max_level = ps->max_trace_level >= 0 ? ps->max_trace_level : sc->global.max_trace_level;
    c->adc = ps->adc_bailout >= 0.0 ? ps->adc_bailout : sc->global.adc_bailout;
    pt_status st = make_combos(c, d);
    if (st != PT_OK || c->ncb == 0) {
        gi_caustic_free(c);
        *status = st;
        return NULL;
    }
    size_combos(c, d);
    c->st.combos = c->ncb;
    c->st.emitted = c->total;

    /* steps 1 and 2: bounce map and world-space bounces */
    double t0 = timer_now();
    int threads = s->threads > 0 ? s->threads : pool_default_threads();
    int nchunks = (int)((c->total + CHUNK - 1) / CHUNK);
    trace_job tj = {c, calloc((size_t)(nchunks > 0 ? nchunks : 1), sizeof(chunk_out))};
    if (!tj.outs) st = PT_ERR_NOMEM;
    for (int i = 0; tj.outs && i < nchunks; i++) {
        long q = MAX_MEDIA_PHOTONS / nchunks;
        tj.outs[i].mquota = q > 1024 ? q : 1024;
        tj.outs[i].mstride = 1;
    }
    if (st == PT_OK) pool_run(threads, nchunks, trace_chunk, &tj);
    long nph = 0, nhl = 0, nmp = 0;
    long thinned = 1;
    for (int i = 0; tj.outs && i < nchunks; i++) {
        if (tj.outs[i].oom) st = PT_ERR_NOMEM;
        if (tj.outs[i].mstride > thinned) thinned = tj.outs[i].mstride;
        nph += tj.outs[i].n;
        nhl += tj.outs[i].nhl;
        nmp += tj.outs[i].nmp;
        c->st.rays += tj.outs[i].rays;
        c->st.first_hits += tj.outs[i].first_hits;
        c->st.absorbed_first += tj.outs[i].absorbed_first;
        for (int b = 0; b <= GI_CAUSTIC_MAX_BOUNCES; b++) c->st.alive[b] += tj.outs[i].alive[b];
    }
    if (st == PT_OK) {
        c->ph = malloc(sizeof *c->ph * (size_t)(nph > 0 ? nph : 1));
        c->hl = malloc(sizeof *c->hl * (size_t)(nhl > 0 ? nhl : 1));
        c->mp = malloc(sizeof *c->mp * (size_t)(nmp > 0 ? nmp : 1));
        if (!c->ph || !c->hl || !c->mp) st = PT_ERR_NOMEM;
    }
    for (int i = 0; tj.outs && i < nchunks; i++) {
        if (st == PT_OK && tj.outs[i].n) memcpy(c->ph + c->nph, tj.outs[i].p, sizeof *c->ph * (size_t)tj.outs[i].n);
        if (st == PT_OK && tj.outs[i].nhl)
            memcpy(c->hl + c->nhl, tj.outs[i].hl, sizeof *c->hl * (size_t)tj.outs[i].nhl);
        if (st == PT_OK && tj.outs[i].nmp)
            memcpy(c->mp + c->nmp, tj.outs[i].mp, sizeof *c->mp * (size_t)tj.outs[i].nmp);
        if (st == PT_OK) {
            c->nph += tj.outs[i].n;
            c->nhl += tj.outs[i].nhl;
            c->nmp += tj.outs[i].nmp;
        }
        free(tj.outs[i].p);
        free(tj.outs[i].hl);
        free(tj.outs[i].mp);
    }
    free(tj.outs);
    for (int b = 1; b <= GI_CAUSTIC_MAX_BOUNCES; b++)
        if (c->st.alive[b] > 0) c->st.max_bounce = b;
    c->st.stored = c->nph;
    c->st.stored_highlights = c->nhl;
    c->st.stored_media = c->nmp;
    c->st.media_thinned = thinned;
    if (thinned > 1)
        diag_warn_once(d, sc->global.photons.loc,
                       "photons: more media photons than the caustic layer keeps (%ld); some were kept at up to %ld "
                       "times the power in wider spheres",
                       MAX_MEDIA_PHOTONS, thinned);
    for (long i = 0; i < c->nph; i++) c->st.flux += (c->ph[i].phi[0] + c->ph[i].phi[1] + c->ph[i].phi[2]) / 3.0;
    c->st.t_trace = timer_now() - t0;
    if (st != PT_OK || (s->cancel && *s->cancel)) {
        gi_caustic_free(c);
        *status = st;
        return NULL;
    }
    c->st.r_median = median_of(&c->ph[0].r_xy, c->nph, sizeof(gi_caus_photon) / sizeof(float));
    if (!widen_sparse(c, threads)) {
        gi_caustic_free(c);
        *status = PT_ERR_NOMEM;
        return NULL;
    }
    c->st.r_median = median_of(&c->ph[0].r_xy, c->nph, sizeof(gi_caus_photon) / sizeof(float));
    double pcell = 2.0 * (c->st.r_median > 0.0 ? c->st.r_median : accel_scale(a) * 1e-3);
    if (!hgrid_build(&c->pgrid, pcell, c->nph, c->ph[0].x, sizeof(gi_caus_photon) / sizeof(float), &c->ph[0].r_xy,
                     sizeof(gi_caus_photon) / sizeof(float)) ||
        !hgrid_build(&c->hlgrid, pcell, c->nhl, c->hl[0].x, sizeof(gi_caus_photon) / sizeof(float), &c->hl[0].r_xy,
                     sizeof(gi_caus_photon) / sizeof(float))) {
        gi_caustic_free(c);
        *status = PT_ERR_NOMEM;
        return NULL;
    }
    if (c->nmp > 0) {
        const size_t fs = sizeof(gi_caus_photon) / sizeof(float);
        c->st.r_media_median = median_of(&c->mp[0].r_xy, c->nmp, fs);
        if (!hgrid_build(&c->mgrid, 2.0 * c->st.r_media_median, c->nmp, c->mp[0].x, fs, &c->mp[0].r_xy, fs)) {
            gi_caustic_free(c);
            *status = PT_ERR_NOMEM;
            return NULL;
        }
    }

    /* step 2 of the paper's frame: the eye G-buffer */
    t0 = timer_now();
    c->w = s->width;
    c->h = s->height;
    size_t npx = (size_t)c->w * (size_t)c->h;
    c->gb = calloc(npx ? npx : 1, sizeof *c->gb);
    c->gobj = calloc(npx ? npx : 1, sizeof *c->gobj);
    c->grad = calloc(npx ? npx : 1, sizeof *c->grad);
    c->img = calloc(npx ? npx * 4 : 4, sizeof *c->img);
    c->tiles_x = (c->w + GI_CAUS_TILE - 1) / GI_CAUS_TILE;
    c->tiles_y = (c->h + GI_CAUS_TILE - 1) / GI_CAUS_TILE;
    if (!c->gb || !c->gobj || !c->grad || !c->img) {
        gi_caustic_free(c);
        *status = PT_ERR_NOMEM;
        return NULL;
    }
    gb_job gj = {c};
    pool_run(threads, c->h, gbuf_row, &gj);
    double gcell = 2.0 * median_of(c->grad, (long)npx, 1);
    if (!(gcell > 0.0)) gcell = accel_scale(a) * 1e-3;
    if (!hgrid_build(&c->ggrid, gcell, (long)npx, c->gb[0].s, sizeof(gi_caus_pixel) / sizeof(float), c->grad, 1)) {
        gi_caustic_free(c);
        *status = PT_ERR_NOMEM;
        return NULL;
    }
    c->st.t_gbuffer = timer_now() - t0;

    /* step 4: photon volumes over the G-buffer, on the GI device */
    gi_dev_options o = {s->cl_device, NULL, s->threads, s->cl_max_bytes};
    c->dev = gi_dev_open(&o, d, &st);
    if (c->dev) snprintf(c->st.device, sizeof c->st.device, "%s", gi_dev_name(c->dev));
    if (st == PT_OK) st = bin_and_splat(c, d);
    if (st != PT_OK) {
        gi_caustic_free(c);
        *status = st;
        return NULL;
    }
    return c;
}

pt_status gi_caustic_resplat(gi_caustic *c, double *t_bin, double *t_splat, diag *d)
{
    pt_status st = bin_and_splat(c, d);
    if (t_bin) *t_bin = c->st.t_bin;
    if (t_splat) *t_splat = c->st.t_splat;
    return st;
}

void gi_caustic_free(gi_caustic *c)
{
    if (!c) return;
    for (int i = 0; i < c->ncb; i++) free(c->cb[i].leaves);
    free(c->cb);
    free(c->ph);
    hgrid_free(&c->pgrid);
    free(c->hl);
    hgrid_free(&c->hlgrid);
    free(c->mp);
    hgrid_free(&c->mgrid);
    hgrid_free(&c->ggrid);
    free(c->gb);
    free(c->gobj);
    free(c->grad);
    free(c->img);
    free(c->tile_off);
    free(c->tile_idx);
    gi_dev_free(c->dev);
    free(c);
}

void gi_caustic_get_stats(const gi_caustic *c, gi_caustic_stats *st)
{
    *st = c->st;
    st->lookups_gbuffer = __atomic_load_n(&c->st.lookups_gbuffer, __ATOMIC_RELAXED);
    st->lookups_photons = __atomic_load_n(&c->st.lookups_photons, __ATOMIC_RELAXED);
}

const gi_caus_photon *gi_caustic_photons(const gi_caustic *c, long *n)
{
    *n = c->nph;
    return c->ph;
}
const gi_caus_photon *gi_caustic_media_photons(const gi_caustic *c, long *n)
{
    *n = c ? c->nmp : 0;
    return c && c->nmp > 0 ? c->mp : NULL;
}
const float *gi_caustic_image(const gi_caustic *c) { return c->img; }
const gi_caus_pixel *gi_caustic_gbuffer(const gi_caustic *c) { return c->gb; }

/* ------------------------------------------------------------ lookups */

rgb gi_caustic_at(void *ctx, const accel_hit *h, vec3 n, int thread)
{
    (void)thread;
    gi_caustic *c = ctx;
    rgb e = {0, 0, 0};
    if (!h || !h->obj || (h->obj->photons && !h->obj->photons->collect)) return e;
    vec3 p = h->p;
    /* the G-buffer points of the same surface whose footprint holds p */
    long lo, hi;
    double ws = 0.0;
    for (const hgrid *gl = &c->ggrid; gl; gl = gl->up)
    for (int pass = 0; pass < 2; pass++) {
        hgrid_cell(gl, cidx(p.x, gl->cell), cidx(p.y, gl->cell), cidx(p.z, gl->cell), &lo, &hi);
        long m = pass ? gl->nbig : hi - lo;
        for (long q = 0; q < m; q++) {
            int i = pass ? gl->big[q] : gl->e[lo + q].id;
            if (c->gobj[i] != h->obj) continue;
            const gi_caus_pixel *px = &c->gb[i];
            if (px->n[0] * n.x + px->n[1] * n.y + px->n[2] * n.z < 0.7) continue;
            double dx = px->s[0] - p.x, dy = px->s[1] - p.y, dz = px->s[2] - p.z;
            double dist = sqrt(dx * dx + dy * dy + dz * dz), r = c->grad[i];
            if (dist >= r) continue;
            double wgt = 1.0 - dist / r;
            const float *v = &c->img[4 * (size_t)i];
            e.r += wgt * v[0];
            e.g += wgt * v[1];
            e.b += wgt * v[2];
            ws += wgt;
        }
    }
    if (ws > 0.0) {
        __atomic_fetch_add(&c->st.lookups_gbuffer, 1, __ATOMIC_RELAXED);
        return cscale(e, 1.0 / ws);
    }
    /* elsewhere: the same photon volumes, summed at p */
    __atomic_fetch_add(&c->st.lookups_photons, 1, __ATOMIC_RELAXED);
    double back = 0.0;
    float b = c->hk.brilliance ? (float)c->hk.brilliance(c->hk.ctx, h, v3_neg(n), &back) : 1.0f;
    return gi_caustic_world_at(c, p, n, b, back);
}

rgb gi_caustic_world_at(const gi_caustic *c, vec3 p, vec3 n, double brilliance, double back)
{
    if (!c) return crgb(0, 0, 0);
    long lo, hi;
    float s[3] = {(float)p.x, (float)p.y, (float)p.z}, nn[3] = {(float)n.x, (float)n.y, (float)n.z}, acc[3] = {0, 0, 0};
    float b = (float)brilliance;
    for (const hgrid *gl = &c->pgrid; gl; gl = gl->up) {
        hgrid_cell(gl, cidx(p.x, gl->cell), cidx(p.y, gl->cell), cidx(p.z, gl->cell), &lo, &hi);
        for (long q = lo; q < hi; q++) {
            float one[3];
            gi_c_caustic_at(c->ph, &gl->e[q].id, 1, s, nn, b, (float)back, one);
            acc[0] += one[0];
            acc[1] += one[1];
            acc[2] += one[2];
        }
        if (gl->nbig) {
            float one[3];
            gi_c_caustic_at(c->ph, gl->big, (int)gl->nbig, s, nn, b, (float)back, one);
            acc[0] += one[0];
            acc[1] += one[1];
            acc[2] += one[2];
        }
    }
    return crgb(acc[0], acc[1], acc[2]);
}

/* gi_caustic_visit's photon q at s (normal n facing the viewer). */
static void visit_one(const gi_caus_photon *q, const float s[3], vec3 n, gi_caustic_visit_fn fn, void *ctx)
{
    vec3 w = {q->w[0], q->w[1], q->w[2]};
    double c = v3_dot(w, n);
    if (c <= 0.0) return;
    double k = gi_c_caustic_kappa(q, s);
    if (k <= 0.0) return;
    k /= fmax(fmin(c, 1.0), 0.1);
    fn(ctx, w, crgb(q->phi[0] * k, q->phi[1] * k, q->phi[2] * k));
}

static void visit_grid(const hgrid *g, const gi_caus_photon *ph, vec3 p, vec3 n, gi_caustic_visit_fn fn, void *ctx)
{
    if (!ph) return;
    float s[3] = {(float)p.x, (float)p.y, (float)p.z};
    long lo, hi;
    for (const hgrid *gl = g; gl; gl = gl->up) {
        hgrid_cell(gl, cidx(p.x, gl->cell), cidx(p.y, gl->cell), cidx(p.z, gl->cell), &lo, &hi);
        for (long q = lo; q < hi; q++) visit_one(&ph[gl->e[q].id], s, n, fn, ctx);
        for (long q = 0; q < gl->nbig; q++) visit_one(&ph[gl->big[q]], s, n, fn, ctx);
    }
}

void gi_caustic_visit(const gi_caustic *c, const accel_hit *h, vec3 n, gi_caustic_visit_fn fn, void *ctx)
{
    if (!c || !h || !h->obj || (h->obj->photons && !h->obj->photons->collect)) return;
    visit_grid(&c->pgrid, c->ph, h->p, n, fn, ctx);
    visit_grid(&c->hlgrid, c->hl, h->p, n, fn, ctx);
}

/* One media photon q at p: Phi kappa with kappa the cone 3 (1 - d/r) /
 * (pi r^3) over its sphere (normalised: its integral over the sphere is 1). */
static void media_one(const gi_caus_photon *q, vec3 p, gi_caustic_visit_fn fn, void *ctx)
{
    double dx = p.x - q->x[0], dy = p.y - q->x[1], dz = p.z - q->x[2], r = q->r_xy;
    double d2 = dx * dx + dy * dy + dz * dz;
    if (!(d2 < r * r)) return;
    double k = 3.0 * (1.0 - sqrt(d2) / r) / (M_PI * r * r * r);
    fn(ctx, v3(q->w[0], q->w[1], q->w[2]), crgb(q->phi[0] * k, q->phi[1] * k, q->phi[2] * k));
}

void gi_caustic_media_visit(const gi_caustic *c, vec3 p, gi_caustic_visit_fn fn, void *ctx)
{
    if (!c || c->nmp <= 0) return;
    long lo, hi;
    for (const hgrid *gl = &c->mgrid; gl; gl = gl->up) {
        hgrid_cell(gl, cidx(p.x, gl->cell), cidx(p.y, gl->cell), cidx(p.z, gl->cell), &lo, &hi);
        for (long q = lo; q < hi; q++) media_one(&c->mp[gl->e[q].id], p, fn, ctx);
        for (long q = 0; q < gl->nbig; q++) media_one(&c->mp[gl->big[q]], p, fn, ctx);
    }
}
