/* gi_links.c - link rays with Embree streams (see gi_links.h). */
#include "gi_links.h"
#include <embree3/rtcore.h>
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include "pool.h"
#include "rng.h"

/* particles per job: about 256 rays per rtcIntersect1M call */
#define RAYS_PER_CALL 256

vec3 gi_links_direction(vec3 nrm, int nside, int j, double u1, double u2)
{
    double su = 2.0 * ((j % nside) + u1) / nside - 1.0;
    double sv = 2.0 * ((j / nside) + u2) / nside - 1.0;
    double r, th;
    if (su == 0.0 && sv == 0.0) {
        r = 0.0;
        th = 0.0;
    } else if (fabs(su) > fabs(sv)) {
        r = su;
        th = (M_PI / 4.0) * (sv / su);
    } else {
        r = sv;
        th = M_PI / 2.0 - (M_PI / 4.0) * (su / sv);
    }
    double x = r * cos(th), y = r * sin(th);
    double z = sqrt(fmax(0.0, 1.0 - x * x - y * y));
    vec3 t, b;
    v3_basis(nrm, &t, &b);
    return v3_norm(v3_add(v3_add(v3_scale(t, x), v3_scale(b, y)), v3_scale(nrm, z)));
}

typedef struct {
    const accel *a;
    RTCScene scene;
    const gi_dev_particle *p;
    int n, nside, k, per_job;
    uint64_t seed;
    const gi_lookup *grid;
    double maxdist;
    int *links;
    unsigned char *anyhit;
    struct RTCRayHit **buf; /* per thread */
    vec3 **hp;
    long **cell;
    atomic_long misses, unresolved;
    double off, scale;
} link_job;

static void job(void *ctx, int index, int thread)
{
    link_job *J = ctx;
    struct RTCRayHit *rh = J->buf[thread];
    int i0 = index * J->per_job, i1 = i0 + J->per_job < J->n ? i0 + J->per_job : J->n;
    int m = 0;
    long miss = 0, unres = 0;
    for (int i = i0; i < i1; i++) {
        const gi_dev_particle *pt = &J->p[i];
        vec3 pos = v3(pt->p[0], pt->p[1], pt->p[2]);
        vec3 nrm = v3(pt->n[0], pt->n[1], pt->n[2]);
        double off = J->off * (J->scale + fmax(fabs(pos.x), fmax(fabs(pos.y), fabs(pos.z))));
        vec3 org = v3_madd(pos, nrm, off);
        rng r;
        rng_seed(&r, J->seed, (uint64_t)i);
        for (int j = 0; j < J->k; j++) {
            double u1 = rng_f64(&r), u2 = rng_f64(&r);
            vec3 d = gi_links_direction(nrm, J->nside, j, u1, u2);
            struct RTCRayHit *h = &rh[m++];
            memset(h, 0, sizeof *h);
            h->ray.org_x = (float)org.x;
            h->ray.org_y = (float)org.y;
            h->ray.org_z = (float)org.z;
            h->ray.dir_x = (float)d.x;
            h->ray.dir_y = (float)d.y;
            h->ray.dir_z = (float)d.z;
            h->ray.tnear = (float)accel_epsilon(J->a, org, d);
            h->ray.tfar = INFINITY;
            h->ray.mask = 0xFFFFFFFFu;
            h->hit.geomID = RTC_INVALID_GEOMETRY_ID;
            h->hit.primID = RTC_INVALID_GEOMETRY_ID;
            h->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        }
    }
    struct RTCIntersectContext c;
    rtcInitIntersectContext(&c);
    rtcIntersect1M(J->scene, &c, rh, (unsigned)m, sizeof *rh);
    /* hit points and their lookup cells; the lookups are bound by memory
     * latency, so the whole batch prefetches first (gi_particles.h) */
    vec3 *hp = J->hp[thread];
    long *cell = J->cell[thread];
    for (int t = 0; t < m; t++) {
        const struct RTCRayHit *h = &rh[t];
        int hit = h->hit.geomID != RTC_INVALID_GEOMETRY_ID && isfinite(h->ray.tfar);
        hp[t] = v3(h->ray.org_x + h->ray.tfar * h->ray.dir_x, h->ray.org_y + h->ray.tfar * h->ray.dir_y,
                   h->ray.org_z + h->ray.tfar * h->ray.dir_z);
        cell[t] = hit ? -1 : -2;
        if (hit && J->grid && J->links) {
            cell[t] = gi_lookup_cell(J->grid, hp[t]);
            gi_lookup_prefetch(J->grid, cell[t], 0);
        }
    }
    if (J->grid && J->links)
        for (int t = 0; t < m; t++)
            if (cell[t] >= 0) gi_lookup_prefetch(J->grid, cell[t], 1);
    m = 0;
    for (int i = i0; i < i1; i++) {
        int any = 0;
        for (int j = 0; j < J->k; j++, m++) {
            int hit = cell[m] != -2;
            any |= hit;
            if (!hit) miss++;
            if (!J->links) continue;
            int target = -1;
            if (hit && J->grid) {
                const struct RTCRayHit *h = &rh[m];
                vec3 d = v3(h->ray.dir_x, h->ray.dir_y, h->ray.dir_z);
                vec3 o = v3(h->ray.org_x, h->ray.org_y, h->ray.org_z);
                target = gi_lookup_nearest_in(J->grid, cell[m], hp[m], d, o, J->maxdist);
                if (target < 0) unres++;
            }
            J->links[(size_t)i * J->k + j] = target;
        }
        if (J->anyhit) J->anyhit[i] = (unsigned char)any;
    }
    atomic_fetch_add(&J->misses, miss);
    atomic_fetch_add(&J->unresolved, unres);
}

pt_status gi_links_build(const accel *a, const gi_dev_particle *p, int n, int nside, uint64_t seed,
                         const gi_lookup *grid, double maxdist, int threads, int *links, unsigned char *anyhit,
                         gi_link_stats *st)
{
    if (threads <= 0) threads = pool_default_threads();
    link_job J;
    memset(&J, 0, sizeof J);
    J.a = a;
    J.scene = (RTCScene)accel_rtc_scene(a);
    J.p = p;
    J.n = n;
    J.nside = nside;
    J.k = nside * nside;
    J.per_job = J.k >= RAYS_PER_CALL ? 1 : RAYS_PER_CALL / J.k;
    J.seed = seed;
    J.grid = grid;
    J.maxdist = maxdist;
    J.links = links;
    J.anyhit = anyhit;
    J.off = 1e-6;
    J.scale = accel_scale(a);
    atomic_init(&J.misses, 0);
    atomic_init(&J.unresolved, 0);
    if (!J.scene) return PT_ERR_INTERNAL;
    J.buf = calloc((size_t)threads, sizeof *J.buf);
    J.hp = calloc((size_t)threads, sizeof *J.hp);
    J.cell = calloc((size_t)threads, sizeof *J.cell);
    pt_status rc = PT_OK;
    if (!J.buf || !J.hp || !J.cell) rc = PT_ERR_NOMEM;
    size_t rays = (size_t)J.per_job * (size_t)J.k;
    size_t bytes = rays * sizeof(struct RTCRayHit);
    for (int t = 0; rc == PT_OK && t < threads; t++) {
        J.buf[t] = aligned_alloc(64, (bytes + 63) / 64 * 64);
        J.hp[t] = malloc(rays * sizeof(vec3));
        J.cell[t] = malloc(rays * sizeof(long));
        if (!J.buf[t] || !J.hp[t] || !J.cell[t]) rc = PT_ERR_NOMEM;
    }
    if (rc == PT_OK && n > 0) pool_run(threads, (n + J.per_job - 1) / J.per_job, job, &J);
    for (int t = 0; t < threads; t++) {
        if (J.buf) free(J.buf[t]);
        if (J.hp) free(J.hp[t]);
        if (J.cell) free(J.cell[t]);
    }
    free(J.buf);
    free(J.hp);
    free(J.cell);
    if (st) {
        st->rays += (long)n * J.k;
        st->misses += atomic_load(&J.misses);
        st->unresolved += atomic_load(&J.unresolved);
    }
    return rc;
}
