/* gi_area_particles.c - area particles: sampling, the hash grid and the link lookup. */
#include "gi_area_particles.h"
#include "grow.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "geom_shape.h"
#include "hash.h"
#include "radrules.h"
#include "rng.h"
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define LK_X86 1
#endif

/* R2 low-discrepancy sequence (M. Roberts, "The unreasonable effectiveness of
 * quasirandom sequences", 2018): alpha = (1/g, 1/g^2) with g the plastic
 * number, the real root of x^3 = x + 1. */
#define R2_G 1.32471795724474602596
#define R2_A1 (1.0 / R2_G)
#define R2_A2 (1.0 / (R2_G * R2_G))

static double frac(double x) { return x - floor(x); }

/* POV-Ray's greyscale weights (as shade.c). */
static double grey(double r, double g, double b) { return 0.297 * r + 0.589 * g + 0.114 * b; }

/* c: the pigment (NULL: the texture's base colour). */
static void material(const scene *sc, const scene_texture *tex, const colour5 *c, const radrules *rr,
                     gi_dev_particle *p)
{
    if (!tex) tex = &sc->default_texture;
    const scene_finish *f = &tex->finish;
    if (!c) c = &tex->pigment.colour;
    double tr = c->f * c->r + c->t, tg = c->f * c->g + c->t, tb = c->f * c->b + c->t;
    double opacity = 1.0 - fmin(1.0, fmax(0.0, grey(tr, tg, tb)));
    double pig[3] = {c->r, c->g, c->b};
    const rgb e = radrules_emission(rr, sc, f);
    double em[3] = {e.r, e.g, e.b};
    for (int k = 0; k < 3; k++) {
        double rho = f->diffuse * pig[k] * opacity;
        double le = pig[k] * em[k] * opacity;
        p->rho[k] = isfinite(rho) ? (float)rho : 0.0f;
        p->le[k] = isfinite(le) ? (float)le : 0.0f;
    }
    p->brilliance = isfinite(f->brilliance) && f->brilliance > 0.0 ? (float)f->brilliance : 1.0f;
    /* diffuse_back as a fraction of diffuse (gi_types.h); with diffuse 0
     * rho is 0 and so is rho_b: not modelled (the render's last bounce,
     * gi_particle_hook.c, takes the same rule) */
    double back = f->diffuse > 0.0 && f->diffuse_back > 0.0 ? f->diffuse_back / f->diffuse : 0.0;
    p->back = isfinite(back) ? (float)back : 0.0f;
    p->twin = -1;
}

void gi_particles_material(const scene *sc, const scene_texture *tex, const colour5 *c, float rho[3], float le[3])
{
    const radrules rr = radrules_of(sc, 1);
    gi_dev_particle p;
    material(sc, tex, c, &rr, &p);
    for (int k = 0; k < 3; k++) {
        rho[k] = p.rho[k];
        le[k] = p.le[k];
    }
}

typedef struct {
    gi_dev_particle *p;
    int *patch;
    unsigned char *side;
    long n, cap;
} pbuf;

static int push(pbuf *b, const gi_dev_particle *p, int patch, int side)
{
    if (b->n == b->cap) {
        long nc = b->cap ? b->cap * 2 : 4096;
        gi_dev_particle *np = realloc(b->p, (size_t)nc * sizeof *np);
        if (!np) return 0;
        b->p = np;
        int *npa = realloc(b->patch, (size_t)nc * sizeof *npa);
        if (!npa) return 0;
        b->patch = npa;
        unsigned char *ns = realloc(b->side, (size_t)nc);
        if (!ns) return 0;
        b->side = ns;
        b->cap = nc;
    }
    b->p[b->n] = *p;
    b->patch[b->n] = patch;
    b->side[b->n] = (unsigned char)side;
    b->n++;
    return 1;
}

/* Does the rendered surface of `o` pass through pos (a CSG member's surface
 * may be cut away)? A short ray towards the surface along -nrm must hit o
 * near pos. The ray's length is a quarter of the particle spacing
 * (`spacing`), not a part of the scene's size: a sky dome of radius 1e4
 * around a courtyard made it longer than the walls are thick, and a
 * cut-away face then found its member's own surface elsewhere and passed.
 * A quarter spacing still covers the distance of a tessellated patch's
 * points from the exact surface, and it stays beyond the ray's epsilon. */
static int probe_ok(const accel *a, const scene_object *o, vec3 pos, vec3 nrm, double spacing)
{
    double mag = fmax(fabs(pos.x), fmax(fabs(pos.y), fabs(pos.z)));
    double delta = fmin(1e-3 * (accel_scale(a) + mag), 0.25 * spacing);
    delta = fmax(delta, 4.0 * accel_epsilon(a, pos, nrm));
    for (int s = 0; s < 2; s++) {
        vec3 nn = s ? v3_neg(nrm) : nrm;
        accel_hit h;
        if (accel_intersect(a, v3_madd(pos, nn, delta), v3_neg(nn), 0.0, 2.0 * delta, &h) && h.obj == o &&
            fabs(h.t - delta) < 0.5 * delta)
            return 1;
    }
    return 0;
}

/* Most candidates a side gets per survivor the pilot predicts there. */
#define SIDE_INFLATION 8.0

/* Particles by what the view shows, beyond the paper (which spreads them
 * uniformly by area): VIEW_SHARE of the count is what an object at least
 * gets in proportion to the part of the image it covers
 * (gi_surface_view_share), so that the columns of a courtyard or the blocks
 * on a sky-lit ground get particles enough to resolve their light where a
 * uniform spread gives them one or two and the ground the rest. POV-Ray
 * places its radiosity samples by the image, too. The rest goes by area.
 * Each object's weight w >= 1 multiplies its density; a particle on it
 * stands for dA / w of surface, so every estimate (area-weighted) stays
 * unbiased. At most VIEW_MAX_WEIGHT. */
#define VIEW_SHARE 0.5
#define VIEW_MAX_WEIGHT 256.0

static float *view_weights(const gi_surface *g, const float *inclip, const float *side_frac)
{
    int np = gi_surface_npatches(g), no = gi_surface_nobjs(g);
    float *vw = malloc((size_t)(np > 0 ? np : 1) * sizeof *vw);
    double *ao = calloc((size_t)(no > 0 ? no : 1), sizeof *ao);
    if (!vw || !ao) {
        free(vw);
        free(ao);
        return NULL;
    }
    double total = 0.0;
    for (int i = 0; i < np; i++) {
        vw[i] = 1.0f;
        double a = 0.0;
        for (int s = 0; s < gi_surface_sides(g, i); s++)
            if (gi_surface_side_mask(g, i) >> s & 1)
                a += gi_surface_area(g, i) * inclip[i] * (side_frac ? side_frac[2 * i + s] : 1.0);
        ao[gi_surface_obj_index(g, i)] += a;
        total += a;
    }
    if (total > 0.0)
        for (int i = 0; i < np; i++) {
            int k = gi_surface_obj_index(g, i);
            if (!(ao[k] > 0.0)) continue;
            /* uniform: count * ao / total particles; by view: VIEW_SHARE * count * share */
            double w = VIEW_SHARE * gi_surface_view_share(g, k) * total / ao[k];
            vw[i] = (float)fmin(VIEW_MAX_WEIGHT, fmax(1.0, w));
        }
    free(ao);
    return vw;
}

pt_status gi_particles_sample(gi_particles *ps, const gi_surface *g, const accel *a, const scene *sc, long count,
                              uint64_t seed, const float *side_frac, gi_pigment_fn pig, diag *d)
{
    const radrules rr = radrules_of(sc, 1);
    memset(ps, 0, sizeof *ps);
    int np = gi_surface_npatches(g);
    float *inclip = malloc((size_t)(np > 0 ? np : 1) * sizeof *inclip);
    if (!inclip) return PT_ERR_NOMEM;
    for (int i = 0; i < np; i++) inclip[i] = gi_surface_clip_fraction(g, i, seed);
    float *vw = view_weights(g, inclip, side_frac);
    if (!vw) {
        free(inclip);
        return PT_ERR_NOMEM;
    }
    double total = 0.0;
    for (int i = 0; i < np; i++)
        for (int s = 0; s < gi_surface_sides(g, i); s++)
            if (gi_surface_side_mask(g, i) >> s & 1)
                total += gi_surface_area(g, i) * inclip[i] * vw[i] * (side_frac ? side_frac[2 * i + s] : 1.0);
    if (count < 1) count = 1;
    if (!(total > 0.0)) {
        free(inclip);
        free(vw);
        return PT_OK;
    }
    double density = (double)count / total;
    ps->dA = total / (double)count;
    ps->spacing = sqrt(ps->dA);
    pbuf b = {0};
    rng r;
    rng_seed(&r, seed, 0x9a17c1e5ULL);
    double offset = rng_f64(&r), cum = 0.0;
    for (int i = 0; i < np; i++) {
        double area = gi_surface_area(g, i);
        int sides = gi_surface_sides(g, i);
        if (sides == 0 || !(area > 0.0)) continue;
        if (side_frac && side_frac[2 * i] <= 0.0f && (sides < 2 || side_frac[2 * i + 1] <= 0.0f)) continue;
        if (!(inclip[i] > 0.0f)) continue;
        /* systematic sampling of the patch counts: exactly `count` over all.
         * A side the pilot found mostly unreached gets count * area / total
         * candidates so that its survivors stand at the density asked; at
         * most SIDE_INFLATION times the survivors expected, so that a large
         * surface the links hardly reach cannot multiply the candidates
         * (its survivors then stand sparser). */
        double keep = 1.0;
        if (side_frac) {
            double fmax = 0.0;
            for (int s = 0; s < sides && s < 2; s++)
                if (gi_surface_side_mask(g, i) >> s & 1) fmax = fmax > side_frac[2 * i + s] ? fmax : side_frac[2 * i + s];
            keep = fmin(1.0, SIDE_INFLATION * fmax);
        }
        long before = (long)floor(cum * density + offset);
        cum += area * inclip[i] * vw[i] * keep;
        long m = (long)floor(cum * density + offset) - before;
        if (m <= 0) continue;
        rng pr;
        rng_seed(&pr, seed, (uint64_t)i * 2 + 1);
        double su = rng_f64(&pr), sv = rng_f64(&pr);
        const scene_object *o = gi_surface_object(g, i);
        gi_dev_particle proto;
        memset(&proto, 0, sizeof proto);
        proto.area = (float)(ps->dA / vw[i]);
        const scene_texture *tex = gi_surface_texture(g, i);
        if (!tex) tex = &sc->default_texture;
        material(sc, tex, NULL, &rr, &proto);
        int probe = gi_surface_probe(g, i), mask = gi_surface_side_mask(g, i);
        /* uv_mapping: the pigment is read at the particle's UV (geom_shape_uv;
         * world x, y for meshes and the shapes it does not know, as accel.c) */
        geom_shape ush;
        int have_ush = pig && o->uv_mapping && geom_shape_init(&ush, o) == 0;
        long got = 0, tries = 0, limit = 64 * m + 64;
        for (long q = 0; got < m && tries < limit; q++, tries++) {
            double u = frac(su + (double)q * R2_A1), v = frac(sv + (double)q * R2_A2);
            vec3 pos, nrm;
            if (!gi_surface_sample(g, i, u, v, &pr, &pos, &nrm)) continue;
            if (inclip[i] < 1.0f && !gi_surface_in_clip(g, pos)) continue;
            got++;
            gi_dev_particle mat = proto;
            if (pig) {
                /* the pigment where the particle is (a checker floor reflects its checks) */
                accel_hit h;
                memset(&h, 0, sizeof h);
                h.p = pos;
                h.ng = h.ns = nrm;
                h.obj = o;
                h.texture = tex;
                h.flags = o->flags;
                h.uv[0] = pos.x;
                h.uv[1] = pos.y;
                if (have_ush) geom_shape_uv(&ush, pos, 0, h.uv);
                colour5 c;
                if (pig(sc, tex, &h, &c) && isfinite(c.r) && isfinite(c.g) && isfinite(c.b) && isfinite(c.f) &&
                    isfinite(c.t))
                    material(sc, tex, &c, &rr, &mat);
            }
            for (int s = 0; s < sides; s++) {
                if (side_frac && side_frac[2 * i + s] <= 0.0f) continue;
                if (!(mask >> s & 1)) continue;
                vec3 nn = s ? v3_neg(nrm) : nrm;
                if (probe && !probe_ok(a, o, pos, nn, sqrt(ps->dA))) {
                    ps->probed_out++;
                    continue;
                }
                gi_dev_particle p = mat;
                v3_store_f(p.p, pos);
                v3_store_f(p.n, nn);
                if (!push(&b, &p, i, s)) {
                    if (have_ush) geom_shape_release(&ush);
                    free(inclip);
                    free(vw);
                    free(b.p);
                    free(b.patch);
                    free(b.side);
                    return PT_ERR_NOMEM;
                }
            }
        }
        if (have_ush) geom_shape_release(&ush);
        if (b.n > 2147483000L) {
            diag_report(d, DIAG_ERROR, (src_loc){0}, NULL, "particle GI: too many particles");
            free(inclip);
            free(vw);
            free(b.p);
            free(b.patch);
            free(b.side);
            return PT_ERR_LIMIT;
        }
    }
    free(inclip);
    free(vw);
    ps->n = (int)b.n;
    ps->p = b.p;
    ps->patch = b.patch;
    ps->side = b.side;
    return PT_OK;
}

int gi_particles_twin(const gi_particles *ps, int i)
{
    /* gi_particles_sample pushes a point's sides in a row, side 0 first;
     * compaction keeps the order */
    int j = ps->side[i] == 0 ? i + 1 : i - 1;
    if (j < 0 || j >= ps->n || ps->patch[j] != ps->patch[i] || ps->side[j] == ps->side[i]) return -1;
    const float *a = ps->p[i].p, *b = ps->p[j].p;
    return a[0] == b[0] && a[1] == b[1] && a[2] == b[2] ? j : -1;
}

void gi_particles_set_twins(gi_particles *ps)
{
    for (int i = 0; i < ps->n; i++) ps->p[i].twin = ps->p[i].back > 0.0f ? gi_particles_twin(ps, i) : -1;
}

pt_status gi_particles_compact(gi_particles *ps, const unsigned char *keep)
{
    int m = 0;
    for (int i = 0; i < ps->n; i++) {
        if (!keep[i]) continue;
        ps->p[m] = ps->p[i];
        ps->patch[m] = ps->patch[i];
        ps->side[m] = ps->side[i];
        m++;
    }
    ps->n = m;
    return PT_OK;
}

void gi_particles_free(gi_particles *ps)
{
    if (!ps) return;
    free(ps->p);
    free(ps->patch);
    free(ps->side);
    memset(ps, 0, sizeof *ps);
}

/* ------------------------------------------------------------------ grid */

typedef struct {
    float x, y, z;
    int idx;
    float nx, ny, nz;
    float pad;
} gentry;

struct gi_grid {
    double cell, inv;
    vec3 origin;
    unsigned mask;
    int *start; /* mask+2 */
    gentry *e;
    int n;
};

static unsigned cell_hash(long ix, long iy, long iz, unsigned mask)
{
    /* primes from Teschner et al. 2003 */
    unsigned long h = ((unsigned long)ix * 73856093UL) ^ ((unsigned long)iy * 19349663UL) ^
                      ((unsigned long)iz * 83492791UL);
    return (unsigned)(h & mask);
}

gi_grid *gi_grid_build(const gi_dev_particle *p, int n, double cell)
{
    gi_grid *g = calloc(1, sizeof *g);
    if (!g) return NULL;
    g->cell = cell > 0.0 ? cell : 1.0;
    g->inv = 1.0 / g->cell;
    g->n = n;
    vec3 lo = v3s(INFINITY);
    for (int i = 0; i < n; i++) lo = v3_min(lo, v3(p[i].p[0], p[i].p[1], p[i].p[2]));
    g->origin = n > 0 ? v3_sub(lo, v3s(g->cell)) : v3s(0.0);
    unsigned size = 1024;
    while (size < 2u * (unsigned)n && size < (1u << 30)) size *= 2;
    g->mask = size - 1;
    g->start = calloc((size_t)size + 2, sizeof *g->start);
    g->e = malloc((size_t)(n > 0 ? n : 1) * sizeof *g->e);
    unsigned *key = malloc((size_t)(n > 0 ? n : 1) * sizeof *key);
    if (!g->start || !g->e || !key) {
        free(key);
        gi_grid_free(g);
        return NULL;
    }
    for (int i = 0; i < n; i++) {
        long ix = (long)floor((p[i].p[0] - g->origin.x) * g->inv);
        long iy = (long)floor((p[i].p[1] - g->origin.y) * g->inv);
        long iz = (long)floor((p[i].p[2] - g->origin.z) * g->inv);
        key[i] = cell_hash(ix, iy, iz, g->mask);
        g->start[key[i] + 2]++;
    }
    for (unsigned b = 0; b <= size; b++) g->start[b + 1] += g->start[b];
    /* start[b+1] is now the beginning of bucket b; fill (stable) */
    for (int i = 0; i < n; i++) {
        gentry *e = &g->e[g->start[key[i] + 1]++];
        e->x = p[i].p[0];
        e->y = p[i].p[1];
        e->z = p[i].p[2];
        e->idx = i;
        e->nx = p[i].n[0];
        e->ny = p[i].n[1];
        e->nz = p[i].n[2];
        e->pad = 0.0f;
    }
    /* now start[b] .. start[b+1] is bucket b */
    free(key);
    return g;
}

void gi_grid_free(gi_grid *g)
{
    if (!g) return;
    free(g->start);
    free(g->e);
    free(g);
}

/* A nearest-particle answer must also lie near the hit's tangent plane as
 * the particle sees it: |n.(p - q)| <= 0.5 |p - q| (within 30 degrees of
 * its plane; on a sphere, within 60 degrees of arc). Without it a ray that
 * hit the outside of a sphere where no outside particle was near enough
 * took a particle on the inside of the far wall (its normal faces the ray's
 * origin too), and light from a lamp inside the sphere leaked out. */
#define NEAR_PLANE2 0.25f

static int gi_grid_nearest_on(const gi_grid *g, vec3 q, vec3 dir, vec3 org, double maxdist, const void *const *pobj,
                              const void *obj, vec3 agree, double min_agree, const unsigned char *skip);

int gi_grid_nearest(const gi_grid *g, vec3 q, vec3 dir, vec3 org, double maxdist)
{
    return gi_grid_nearest_on(g, q, dir, org, maxdist, NULL, NULL, v3s(0.0), 0.0, NULL);
}

/* As gi_grid_nearest, among the particles i with pobj[i] == obj only
 * (pobj NULL: all) whose normal n has n.agree >= min_agree (agree = 0:
 * any normal) and skip[i] == 0 (skip may be NULL). */
static int gi_grid_nearest_on(const gi_grid *g, vec3 q, vec3 dir, vec3 org, double maxdist, const void *const *pobj,
                              const void *obj, vec3 agree, double min_agree, const unsigned char *skip)
{
    float ax = (float)agree.x, ay = (float)agree.y, az = (float)agree.z;
    float amin = agree.x == 0.0 && agree.y == 0.0 && agree.z == 0.0 ? -2.0f : (float)min_agree;
    if (g->n == 0) return -1;
    double fx = (q.x - g->origin.x) * g->inv, fy = (q.y - g->origin.y) * g->inv, fz = (q.z - g->origin.z) * g->inv;
    if (!isfinite(fx) || !isfinite(fy) || !isfinite(fz)) return -1;
    long ix = (long)floor(fx), iy = (long)floor(fy), iz = (long)floor(fz);
    double rx = fx - ix, ry = fy - iy, rz = fz - iz;
    float qx = (float)q.x, qy = (float)q.y, qz = (float)q.z;
    float dx = (float)dir.x, dy = (float)dir.y, dz = (float)dir.z;
    float orx = (float)org.x, ory = (float)org.y, orz = (float)org.z;
    double best = maxdist * maxdist;
    int bi = -1;
    int rings = (int)ceil(maxdist * g->inv) + 1;
    if (rings > 64) rings = 64;
    for (int ring = 0; ring <= rings; ring++) {
        for (int ox = -ring; ox <= ring; ox++) {
            double bx = ox < 0 ? (rx - ox - 1) : (ox > 0 ? (ox - rx) : 0.0);
            for (int oy = -ring; oy <= ring; oy++) {
                double by = oy < 0 ? (ry - oy - 1) : (oy > 0 ? (oy - ry) : 0.0);
                for (int oz = -ring; oz <= ring; oz++) {
                    if (abs(ox) != ring && abs(oy) != ring && abs(oz) != ring) continue;
                    double bz = oz < 0 ? (rz - oz - 1) : (oz > 0 ? (oz - rz) : 0.0);
                    double md = (bx * bx + by * by + bz * bz) * g->cell * g->cell;
                    if (md >= best) continue;
                    unsigned h = cell_hash(ix + ox, iy + oy, iz + oz, g->mask);
                    for (int k = g->start[h]; k < g->start[h + 1]; k++) {
                        const gentry *e = &g->e[k];
                        if (e->nx * dx + e->ny * dy + e->nz * dz >= 0.0f) continue;
                        if (e->nx * (orx - e->x) + e->ny * (ory - e->y) + e->nz * (orz - e->z) <= 0.0f) continue;
                        float ex = e->x - qx, ey = e->y - qy, ez = e->z - qz;
                        double d2 = (double)(ex * ex + ey * ey + ez * ez);
                        float pe = e->nx * ex + e->ny * ey + e->nz * ez;
                        if ((double)(pe * pe) > NEAR_PLANE2 * d2) continue;
                        if (pobj && pobj[e->idx] != obj) continue;
                        if (skip && skip[e->idx]) continue;
                        if (e->nx * ax + e->ny * ay + e->nz * az < amin) continue;
                        if (d2 < best || (d2 == best && e->idx < bi)) {
                            best = d2;
                            bi = e->idx;
                        }
                    }
                }
            }
        }
        /* every cell of the next ring is at least ring*cell away */
        if (bi >= 0 && best <= (double)ring * ring * g->cell * g->cell) break;
    }
    return bi;
}

static int cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

long gi_grid_radius(const gi_grid *g, vec3 q, vec3 nq, double r, double cos_thr, int **out, long *len, long *cap)
{
    long start = *len;
    int reach = (int)ceil(r * g->inv);
    long ix = (long)floor((q.x - g->origin.x) * g->inv);
    long iy = (long)floor((q.y - g->origin.y) * g->inv);
    long iz = (long)floor((q.z - g->origin.z) * g->inv);
    double r2 = r * r;
    /* hash collisions may scan a bucket twice: duplicates go below */
    for (int ox = -reach; ox <= reach; ox++) {
        for (int oy = -reach; oy <= reach; oy++) {
            for (int oz = -reach; oz <= reach; oz++) {
                unsigned h = cell_hash(ix + ox, iy + oy, iz + oz, g->mask);
                for (int k = g->start[h]; k < g->start[h + 1]; k++) {
                    const gentry *e = &g->e[k];
                    double ex = e->x - q.x, ey = e->y - q.y, ez = e->z - q.z;
                    if (ex * ex + ey * ey + ez * ez > r2) continue;
                    if (e->nx * nq.x + e->ny * nq.y + e->nz * nq.z <= cos_thr) continue;
                    if (!grow_array_long((void **)out, cap, *len + 1, sizeof **out)) return -1;
                    (*out)[(*len)++] = e->idx;
                }
            }
        }
    }
    long m = *len - start;
    if (m > 1) {
        int *o = *out + start;
        qsort(o, (size_t)m, sizeof *o, cmp_int);
        long u = 1;
        for (long i = 1; i < m; i++)
            if (o[i] != o[u - 1]) o[u++] = o[i];
        m = u;
        *len = start + m;
    }
    return m;
}

/* ------------------------------------------------------------------ dense lookup */

/* Nearest-particle lookup by a dense grid of `cell`-wide cells, each particle
 * stored once, in its own cell (a counting sort by cell index). The nearest
 * particle to q within margin = cell/2 lies in the cells the box
 * [q - margin, q + margin] overlaps, which are the 2x2x2 block of cells
 * around the cell corner nearest to q. Cells are numbered with x fastest,
 * so the two cells of a block row are one contiguous run of entries: a
 * query reads 4 runs. Farther answers (up to 1.5 cells) come from the 16
 * runs of the 4x4x4 block around the same corner, and beyond that from the
 * hashed grid's ring search.
 *
 * Layout: every cell's entries are padded to whole blocks of LK_W stored as
 * structure-of-arrays (position and normal as floats, then the particle
 * indices: 128 bytes per block; padding lies at infinity), so a query tests LK_W entries at once with
 * 4-lane vector operations; the particle indices complete the block to two
 * cache lines. About 50 bytes per particle (padding included) against the previous layout's 8 copies of every particle (one
 * per cell of its margin box): the structure stays in cache while link
 * rays land all over the scene. */
#define LK_W 4
typedef struct {
    float x[LK_W], y[LK_W], z[LK_W];
    float nx[LK_W], ny[LK_W], nz[LK_W]; /* unit normal */
    int idx[LK_W];                      /* particle of each slot, -1 for padding */
    int obj[LK_W];                      /* object id (gi_lookup_set_objects), -1 unknown */
} lblock;
_Static_assert(sizeof(lblock) == 128, "lookup block is two cache lines");

struct gi_lookup {
    double cell, inv, margin;
    vec3 origin;
    long dim[3];
    int *start; /* ncells + 2, in slots (multiples of LK_W) */
    lblock *b;  /* ne / LK_W */
    long ne;
    int n;
    gi_grid *fallback;
    int avx2; /* scan 8 slots (two blocks) at a time (the CPU has AVX2) */
    /* object pointer -> id (open addressing, power-of-two size) */
    const void **okey;
    const void *const *opobj; /* the pobj array the ids were set from */
    int omask;
};

int gi_lookup_covers(const gi_lookup *g, vec3 q)
{
    if (!g || g->n == 0) return 0;
    const double lo[3] = {g->origin.x - g->cell, g->origin.y - g->cell, g->origin.z - g->cell};
    const double qq[3] = {q.x, q.y, q.z};
    for (int k = 0; k < 3; k++)
        if (!(qq[k] >= lo[k] && qq[k] <= lo[k] + (double)(g->dim[k] + 2) * g->cell)) return 0;
    return 1;
}

int gi_lookup_object_id(const gi_lookup *g, const void *obj)
{
    if (!g->okey || !obj) return -1;
    for (unsigned h = pt_ptr_hash(obj) & (unsigned)g->omask;; h = (h + 1) & (unsigned)g->omask) {
        if (g->okey[h] == obj) return (int)h;
        if (!g->okey[h]) return -1;
    }
}

pt_status gi_lookup_set_objects(gi_lookup *g, const void *const *pobj)
{
    if (!pobj || g->n == 0) return PT_OK;
    g->opobj = pobj;
    /* distinct objects: at most n; table at least twice that count */
    int distinct = 0;
    unsigned size = 64;
    free(g->okey);
    g->okey = NULL;
    for (;;) {
        g->okey = calloc(size, sizeof *g->okey);
        if (!g->okey) return PT_ERR_NOMEM;
        g->omask = (int)size - 1;
        distinct = 0;
        int full = 0;
        for (int i = 0; i < g->n && !full; i++) {
            if (!pobj[i]) continue;
            unsigned h = pt_ptr_hash(pobj[i]) & (unsigned)g->omask;
            while (g->okey[h] && g->okey[h] != pobj[i]) h = (h + 1) & (unsigned)g->omask;
            if (!g->okey[h]) {
                g->okey[h] = pobj[i];
                if (2 * (unsigned)++distinct > size) full = 1;
            }
        }
        if (!full) break;
        free(g->okey);
        g->okey = NULL;
        size *= 4;
    }
    long nb = g->ne / LK_W;
    for (long k = 0; k < nb; k++)
        for (int l = 0; l < LK_W; l++) {
            int i = g->b[k].idx[l];
            g->b[k].obj[l] = i >= 0 ? gi_lookup_object_id(g, pobj[i]) : -1;
        }
    return PT_OK;
}

gi_lookup *gi_lookup_build(const gi_particles *ps, double cell)
{
    gi_lookup *g = calloc(1, sizeof *g);
    if (!g) return NULL;
    int n = ps->n;
    g->n = n;
    vec3 lo = v3s(INFINITY), hi = v3s(-INFINITY);
    for (int i = 0; i < n; i++) {
        vec3 p = v3(ps->p[i].p[0], ps->p[i].p[1], ps->p[i].p[2]);
        lo = v3_min(lo, p);
        hi = v3_max(hi, p);
    }
    if (n == 0) lo = hi = v3s(0.0);
    if (!(cell > 0.0)) cell = 1.0;
    vec3 ext = v3_sub(hi, lo);
    double limit = 8.0 * n + 4096.0;
    for (;;) {
        double cells = 1.0;
        for (int k = 0; k < 3; k++) cells *= floor(v3_idx(ext, k) / cell) + 3.0;
        if (cells <= limit) break;
        cell *= 1.25;
    }
    g->cell = cell;
    g->inv = 1.0 / cell;
#ifdef LK_X86
    __builtin_cpu_init();
    g->avx2 = __builtin_cpu_supports("avx2");
#endif
    g->margin = 0.5 * cell;
    g->origin = v3_sub(lo, v3s(cell));
    for (int k = 0; k < 3; k++) g->dim[k] = (long)floor(v3_idx(ext, k) / cell) + 3;
    long ncells = g->dim[0] * g->dim[1] * g->dim[2];
    g->start = calloc((size_t)ncells + 2, sizeof *g->start);
    long *key = malloc((size_t)(n > 0 ? n : 1) * sizeof *key);
    g->fallback = gi_grid_build(ps->p, n, g->margin);
    if (!g->start || !key || !g->fallback) {
        free(key);
        gi_lookup_free(g);
        return NULL;
    }
    for (int i = 0; i < n; i++) {
        const float *p = ps->p[i].p;
        long c[3];
        for (int k = 0; k < 3; k++) {
            double f = ((double)p[k] - v3_idx(g->origin, k)) * g->inv;
            long ci = isfinite(f) ? (long)floor(f) : 0;
            c[k] = ci < 0 ? 0 : (ci >= g->dim[k] ? g->dim[k] - 1 : ci);
        }
        key[i] = (c[2] * g->dim[1] + c[1]) * g->dim[0] + c[0];
        g->start[key[i] + 2]++;
    }
    /* pad every cell to whole blocks, then prefix sums */
    for (long c = 0; c < ncells; c++) g->start[c + 2] = (g->start[c + 2] + LK_W - 1) / LK_W * LK_W;
    for (long c = 0; c <= ncells; c++) g->start[c + 1] += g->start[c];
    g->ne = g->start[ncells + 1];
    /* one more block of padding after the last: an 8-slot scan reads a
     * block pair and may step past the last cell's entries */
    long nb = g->ne / LK_W + 1;
    g->b = aligned_alloc(64, ((size_t)nb * sizeof *g->b + 63) / 64 * 64);
    if (!g->b) {
        free(key);
        gi_lookup_free(g);
        return NULL;
    }
    for (long k = 0; k < nb; k++)
        for (int l = 0; l < LK_W; l++) {
            g->b[k].x[l] = g->b[k].y[l] = g->b[k].z[l] = INFINITY;
            g->b[k].nx[l] = g->b[k].ny[l] = g->b[k].nz[l] = 0.0f;
            g->b[k].idx[l] = -1;
            g->b[k].obj[l] = -1;
        }
    for (int i = 0; i < n; i++) {
        const gi_dev_particle *p = &ps->p[i];
        long s = g->start[key[i] + 1]++;
        lblock *e = &g->b[s / LK_W];
        int l = (int)(s % LK_W);
        e->x[l] = p->p[0];
        e->y[l] = p->p[1];
        e->z[l] = p->p[2];
        /* the particle's own unit normal, as the hashed grid's (was
         * rounded to 127ths and stored unscaled, which made the
         * near-plane test 127 times stricter and sent 2% of the cbox link
         * queries to the ring search) */
        e->nx[l] = p->n[0];
        e->ny[l] = p->n[1];
        e->nz[l] = p->n[2];
        e->idx[l] = i;
    }
    /* start[c + 1] is now the end of cell c's entries: round it up to the
     * cell's padded end */
    for (long c = 0; c < ncells; c++) g->start[c + 1] = (g->start[c + 1] + LK_W - 1) / LK_W * LK_W;
    free(key);
    return g;
}

void gi_lookup_free(gi_lookup *g)
{
    if (!g) return;
    free(g->start);
    free(g->b);
    free(g->okey);
    gi_grid_free(g->fallback);
    free(g);
}

/* The lowest corner cell of the 2x2x2 block a query at q reads. (Per link
 * ray: no floor() calls; a coordinate past the grid, or NaN, is clamped
 * before the conversion.) */
long gi_lookup_cell(const gi_lookup *g, vec3 q)
{
    if (!g->n) return 0;
    long c[3];
    double qq[3] = {q.x - g->origin.x, q.y - g->origin.y, q.z - g->origin.z};
    for (int k = 0; k < 3; k++) {
        /* floor(f - 1/2) clamped to [0, dim - 2]; t >= 0 converts by truncation */
        double t = qq[k] * g->inv - 0.5, top = (double)(g->dim[k] - 2);
        c[k] = !(t >= 0.0) ? 0 : (t >= top ? g->dim[k] - 2 : (long)t); /* NaN: 0 */
    }
    return (c[2] * g->dim[1] + c[1]) * g->dim[0] + c[0];
}

void gi_lookup_cells(const gi_lookup *g, int n, const vec3 *q, long *cell)
{
    if (g->n == 0) return;
    long d0 = g->dim[0], d01 = g->dim[0] * g->dim[1];
    double top[3] = {(double)(g->dim[0] - 2), (double)(g->dim[1] - 2), (double)(g->dim[2] - 2)};
    for (int i = 0; i < n; i++) {
        if (cell[i] < -1) continue;
        /* as gi_lookup_cell */
        double qq[3] = {q[i].x - g->origin.x, q[i].y - g->origin.y, q[i].z - g->origin.z};
        long c[3];
        for (int k = 0; k < 3; k++) {
            double t = qq[k] * g->inv - 0.5;
            c[k] = !(t >= 0.0) ? 0 : (t >= top[k] ? (long)top[k] : (long)t);
        }
        long ce = (c[2] * g->dim[1] + c[1]) * d0 + c[0];
        cell[i] = ce;
        __builtin_prefetch(&g->start[ce]);
        __builtin_prefetch(&g->start[ce + d0]);
        __builtin_prefetch(&g->start[ce + d01]);
        __builtin_prefetch(&g->start[ce + d01 + d0]);
    }
    for (int i = 0; i < n; i++) {
        if (cell[i] < 0) continue;
        long ce = cell[i];
        long rows[4] = {ce, ce + d0, ce + d01, ce + d01 + d0};
        for (int r = 0; r < 4; r++) {
            int k = g->start[rows[r]];
            __builtin_prefetch(&g->b[k / LK_W]);
            __builtin_prefetch((const char *)&g->b[k / LK_W] + 64);
        }
    }
}

int gi_lookup_nearest_on(const gi_lookup *g, vec3 q, vec3 dir, vec3 org, double maxdist, const void *const *pobj,
                         const void *obj, vec3 agree, double min_agree, const unsigned char *skip)
{
    if (g->n == 0 || !v3_finite(q)) return -1;
    if (!pobj || pobj != g->opobj || !obj || !(maxdist <= 1.5 * g->cell))
        return gi_grid_nearest_on(g->fallback, q, dir, org, maxdist, pobj, obj, agree, min_agree, skip);
    /* the same answer from the dense grid: the 2x2x2 block holds every
     * particle within the margin, the 4x4x4 block every one within 1.5
     * cells (as gi_lookup_nearest_in2), with gi_grid_nearest_on's filters
     * in its arithmetic, the object compared by its id (the ring search
     * cost 3,600 instructions a call on cbox) */
    int oid = gi_lookup_object_id(g, obj);
    if (oid < 0) return -1; /* no particle lies on obj */
    float ax = (float)agree.x, ay = (float)agree.y, az = (float)agree.z;
    float amin = agree.x == 0.0 && agree.y == 0.0 && agree.z == 0.0 ? -2.0f : (float)min_agree;
    float qx = (float)q.x, qy = (float)q.y, qz = (float)q.z;
    float dx = (float)dir.x, dy = (float)dir.y, dz = (float)dir.z;
    float orx = (float)org.x, ory = (float)org.y, orz = (float)org.z;
    long cell = gi_lookup_cell(g, q);
    long d0 = g->dim[0], d01 = g->dim[0] * g->dim[1];
    long cx = cell % d0, cy = (cell / d0) % g->dim[1], cz = cell / d01;
    int bi = -1;
    for (int pass = 0; pass < 2 && bi < 0; pass++) {
        double m = pass == 0 ? (g->margin < maxdist ? g->margin : maxdist) : maxdist;
        if (pass == 1 && !(maxdist > g->margin)) break;
        double best = m * m;
        long w = pass == 0 ? 0 : 1; /* cells either side of the 2x2x2 block */
        long x0 = cx - w > 0 ? cx - w : 0, x1 = cx + 1 + w < d0 ? cx + 1 + w : d0 - 1;
        long y0 = cy - w > 0 ? cy - w : 0, y1 = cy + 1 + w < g->dim[1] ? cy + 1 + w : g->dim[1] - 1;
        long z0 = cz - w > 0 ? cz - w : 0, z1 = cz + 1 + w < g->dim[2] ? cz + 1 + w : g->dim[2] - 1;
        for (long z = z0; z <= z1; z++)
            for (long y = y0; y <= y1; y++) {
                long row = z * d01 + y * d0;
                for (int k = g->start[row + x0]; k < g->start[row + x1 + 1]; k++) {
                    const lblock *e = &g->b[k / LK_W];
                    int l = k % LK_W, idx = e->idx[l];
                    if (idx < 0 || e->obj[l] != oid) continue;
                    float ex_ = e->x[l], ey_ = e->y[l], ez_ = e->z[l];
                    float nx = e->nx[l], ny = e->ny[l], nz = e->nz[l];
                    if (nx * dx + ny * dy + nz * dz >= 0.0f) continue;
                    if (nx * (orx - ex_) + ny * (ory - ey_) + nz * (orz - ez_) <= 0.0f) continue;
                    float ex = ex_ - qx, ey = ey_ - qy, ez = ez_ - qz;
                    double d2 = (double)(ex * ex + ey * ey + ez * ez);
                    float pe = nx * ex + ny * ey + nz * ez;
                    if ((double)(pe * pe) > NEAR_PLANE2 * d2) continue;
                    if (skip && skip[idx]) continue;
                    if (nx * ax + ny * ay + nz * az < amin) continue;
                    if (d2 < best || (d2 == best && idx < bi)) {
                        best = d2;
                        bi = idx;
                    }
                }
            }
    }
    return bi;
}

/* GCC/Clang vector extensions: 4 lanes (SSE2 on x86-64) */
typedef float v4f __attribute__((vector_size(16)));
typedef int v4i __attribute__((vector_size(16)));

/* One query: its point, ray direction and origin (9 floats), and its
 * answer so far: the nearest squared distance (strictly below the start
 * value) and its slot, -1 if none. */
typedef struct {
    float q[9];
    float best;
    int slot;
} lquery;

/* Tests the slots of the runs [k0[r], k1[r]) (whole blocks) against the
 * query's filters (as gi_grid_nearest: the normal faces against the ray,
 * the origin lies in front of the particle, the hit lies near its tangent
 * plane), branch-free but for skipping blocks with no slot nearer than
 * the best so far (the filters' comparisons are unpredictable). Each lane
 * keeps its first strictly nearest slot; the answer is the nearest over
 * the lanes, ties to the lower slot. */
static void scan_runs4(const gi_lookup *g, const int *k0, const int *k1, int nr, lquery *q)
{
    const v4f zero = {0, 0, 0, 0}, vnp = {NEAR_PLANE2, NEAR_PLANE2, NEAR_PLANE2, NEAR_PLANE2};
    const v4i lane = {0, 1, 2, 3};
    const v4f qx = zero + q->q[0], qy = zero + q->q[1], qz = zero + q->q[2];
    const v4f dx = zero + q->q[3], dy = zero + q->q[4], dz = zero + q->q[5];
    const v4f ox = zero + q->q[6], oy = zero + q->q[7], oz = zero + q->q[8];
    v4f best = zero + q->best;
    v4i slot = {-1, -1, -1, -1};
    for (int r = 0; r < nr; r++)
        for (int k = k0[r]; k < k1[r]; k += LK_W) {
            const lblock *e = &g->b[k / LK_W];
            v4f x, y, z, nx, ny, nz;
            memcpy(&x, e->x, sizeof x);
            memcpy(&y, e->y, sizeof y);
            memcpy(&z, e->z, sizeof z);
            v4f ex = x - qx, ey = y - qy, ez = z - qz;
            v4f d2 = ex * ex + ey * ey + ez * ez;
            /* most slots of the block lie beyond the best so far (the block of
             * cells is 4 margins wide): skip the filters then */
            v4i near = d2 < best;
#ifdef LK_X86
            if (!_mm_movemask_ps((__m128)near)) continue;
#else
            if (!(near[0] | near[1] | near[2] | near[3])) continue;
#endif
            memcpy(&nx, e->nx, sizeof nx);
            memcpy(&ny, e->ny, sizeof ny);
            memcpy(&nz, e->nz, sizeof nz);
            v4f f = nx * dx + ny * dy + nz * dz;
            v4f hh = nx * (ox - x) + ny * (oy - y) + nz * (oz - z);
            v4f pe = nx * ex + ny * ey + nz * ez;
            v4i ok = near & (f < zero) & (hh > zero) & (pe * pe <= vnp * d2);
            best = (v4f)(((v4i)d2 & ok) | ((v4i)best & ~ok));
            slot = ((lane + k) & ok) | (slot & ~ok);
        }
    for (int l = 0; l < LK_W; l++) {
        if (slot[l] < 0) continue;
        if (q->slot < 0 || best[l] < q->best || (best[l] == q->best && slot[l] < q->slot)) {
            q->slot = slot[l];
            q->best = best[l];
        }
    }
}

#ifdef LK_X86
/* The same with AVX2, 8 slots (a pair of blocks) at a time; the same
 * operations in the same order (no FMA contraction: the target is avx2
 * only), so the same answers. A run of an odd number of blocks reads the
 * next block too: its slots are other cells' particles or padding, and a
 * particle there can only win if it is nearer than everything in the runs,
 * which hold every particle within the searched distance (so it cannot). */
__attribute__((target("avx2"))) static void scan_runs8(const gi_lookup *g, const int *k0, const int *k1, int nr,
                                                        lquery *q)
{
    const __m256 zero = _mm256_setzero_ps(), vnp = _mm256_set1_ps(NEAR_PLANE2);
    const __m256 qx = _mm256_set1_ps(q->q[0]), qy = _mm256_set1_ps(q->q[1]), qz = _mm256_set1_ps(q->q[2]);
    const __m256 dx = _mm256_set1_ps(q->q[3]), dy = _mm256_set1_ps(q->q[4]), dz = _mm256_set1_ps(q->q[5]);
    const __m256 ox = _mm256_set1_ps(q->q[6]), oy = _mm256_set1_ps(q->q[7]), oz = _mm256_set1_ps(q->q[8]);
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    __m256 best = _mm256_set1_ps(q->best);
    __m256i slot = _mm256_set1_epi32(-1);
#define LK_LOAD8(f) _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(e[0].f)), _mm_load_ps(e[1].f), 1)
    for (int r = 0; r < nr; r++)
        for (int k = k0[r]; k < k1[r]; k += 2 * LK_W) {
            const lblock *e = &g->b[k / LK_W];
            __m256 x = LK_LOAD8(x), y = LK_LOAD8(y), z = LK_LOAD8(z);
            __m256 ex = _mm256_sub_ps(x, qx), ey = _mm256_sub_ps(y, qy), ez = _mm256_sub_ps(z, qz);
            __m256 d2 = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(ex, ex), _mm256_mul_ps(ey, ey)), _mm256_mul_ps(ez, ez));
            __m256 near = _mm256_cmp_ps(d2, best, _CMP_LT_OQ);
            if (!_mm256_movemask_ps(near)) continue;
            __m256 nx = LK_LOAD8(nx), ny = LK_LOAD8(ny), nz = LK_LOAD8(nz);
            __m256 f = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(nx, dx), _mm256_mul_ps(ny, dy)), _mm256_mul_ps(nz, dz));
            __m256 hh = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(nx, _mm256_sub_ps(ox, x)), _mm256_mul_ps(ny, _mm256_sub_ps(oy, y))),
                                      _mm256_mul_ps(nz, _mm256_sub_ps(oz, z)));
            __m256 pe = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(nx, ex), _mm256_mul_ps(ny, ey)), _mm256_mul_ps(nz, ez));
            __m256 ok = _mm256_and_ps(_mm256_and_ps(near, _mm256_cmp_ps(f, zero, _CMP_LT_OQ)),
                                      _mm256_and_ps(_mm256_cmp_ps(hh, zero, _CMP_GT_OQ),
                                                    _mm256_cmp_ps(_mm256_mul_ps(pe, pe), _mm256_mul_ps(vnp, d2), _CMP_LE_OQ)));
            best = _mm256_blendv_ps(best, d2, ok);
            slot = _mm256_blendv_epi8(slot, _mm256_add_epi32(lane, _mm256_set1_epi32(k)), _mm256_castps_si256(ok));
        }
#undef LK_LOAD8
    /* a lane with a slot holds a distance below the query's best on entry,
     * a lane without one holds that best: the answer is the lanes'
     * minimum distance and, among the lanes holding it, the lowest slot */
    __m256i has = _mm256_cmpgt_epi32(slot, _mm256_set1_epi32(-1));
    if (!_mm256_movemask_ps(_mm256_castsi256_ps(has))) return;
    __m256 m = _mm256_min_ps(best, _mm256_permute2f128_ps(best, best, 1));
    m = _mm256_min_ps(m, _mm256_shuffle_ps(m, m, _MM_SHUFFLE(1, 0, 3, 2)));
    m = _mm256_min_ps(m, _mm256_shuffle_ps(m, m, _MM_SHUFFLE(2, 3, 0, 1)));
    __m256i eq = _mm256_and_si256(has, _mm256_castps_si256(_mm256_cmp_ps(best, m, _CMP_EQ_OQ)));
    __m256i s = _mm256_blendv_epi8(_mm256_set1_epi32(0x7fffffff), slot, eq);
    s = _mm256_min_epi32(s, _mm256_permute2x128_si256(s, s, 1));
    s = _mm256_min_epi32(s, _mm256_shuffle_epi32(s, _MM_SHUFFLE(1, 0, 3, 2)));
    s = _mm256_min_epi32(s, _mm256_shuffle_epi32(s, _MM_SHUFFLE(2, 3, 0, 1)));
    q->best = _mm256_cvtss_f32(m);
    q->slot = _mm256_cvtsi256_si32(s);
}
#endif

static void scan_runs(const gi_lookup *g, const int *k0, const int *k1, int nr, lquery *q)
{
#ifdef LK_X86
    if (g->avx2) {
        scan_runs8(g, k0, k1, nr, q);
        return;
    }
#endif
    scan_runs4(g, k0, k1, nr, q);
}

int gi_lookup_nearest_in2(const gi_lookup *g, long cell, vec3 q, vec3 dir, vec3 org, double maxdist, float nrm[3],
                          int *obj)
{
    if (obj) *obj = -2;
    if (g->n == 0 || !v3_finite(q)) return -1;
    double m = g->margin < maxdist ? g->margin : maxdist;
    lquery Q = {{(float)q.x, (float)q.y, (float)q.z, (float)dir.x, (float)dir.y, (float)dir.z, (float)org.x, (float)org.y,
                 (float)org.z},
                (float)(m * m),
                -1};
    long d0 = g->dim[0], d01 = g->dim[0] * g->dim[1];
    /* the 4 runs of the 2x2x2 block, in a fixed order */
    int k0[16], k1[16];
    long rows[4] = {cell, cell + d0, cell + d01, cell + d01 + d0};
    for (int r = 0; r < 4; r++) {
        k0[r] = g->start[rows[r]];
        k1[r] = g->start[rows[r] + 2];
    }
    scan_runs(g, k0, k1, 4, &Q);
    int bs = Q.slot;
    if (bs < 0 && maxdist > m && maxdist <= 1.5 * g->cell) {
        /* nothing within the margin: the 4x4x4 block of cells around the
         * same corner holds every particle within 1.5 cells of q (q lies
         * within half a cell of that corner on every axis; the clamped
         * block still holds every particle, which lie in cells 1..dim-2),
         * so one scan of its 16 runs replaces the ring search (16K
         * instructions a query on cbox, 2% of the link rays) */
        float md2 = (float)(maxdist * maxdist);
        Q.best = md2;
        Q.slot = -1;
        long cx = cell % d0, cy = (cell / d0) % g->dim[1], cz = cell / d01;
        long x0 = cx > 0 ? cx - 1 : 0, x1 = cx + 2 < d0 ? cx + 2 : d0 - 1;
        long y0 = cy > 0 ? cy - 1 : 0, y1 = cy + 2 < g->dim[1] ? cy + 2 : g->dim[1] - 1;
        long z0 = cz > 0 ? cz - 1 : 0, z1 = cz + 2 < g->dim[2] ? cz + 2 : g->dim[2] - 1;
        int nr = 0;
        for (long z = z0; z <= z1; z++)
            for (long y = y0; y <= y1; y++) {
                long row = z * d01 + y * d0;
                k0[nr] = g->start[row + x0];
                k1[nr] = g->start[row + x1 + 1];
                nr++;
            }
        scan_runs(g, k0, k1, nr, &Q);
        bs = Q.slot;
        if (bs < 0) return -1;
    }
    if (bs >= 0) {
        /* the winner's rounded normal and object id ride in its block (no
         * second random read of the particle records) */
        const lblock *e = &g->b[bs / LK_W];
        int l = bs % LK_W;
        if (nrm) {
            nrm[0] = e->nx[l];
            nrm[1] = e->ny[l];
            nrm[2] = e->nz[l];
        }
        if (obj) *obj = e->obj[l];
        return e->idx[l];
    }
    /* nothing within the margin: the ring search, up to maxdist */
    return maxdist > m ? gi_grid_nearest(g->fallback, q, dir, org, maxdist) : -1;
}
