/* gi_links.c - link rays with Embree streams (see gi_links.h). */
#include "gi_links.h"
#include <embree3/rtcore.h>
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include "gi_caustic.h"
#include "gi_particle_internal.h"
#include "grow.h"
#include "mirror.h"
#include "pool.h"
#include "radrules.h"
#include "rng.h"
#include "transmit.h"

/* particles per job: about 256 rays per rtcIntersect1M call */
#define RAYS_PER_CALL 256

typedef struct {
    const accel *a;
    RTCScene scene;
    const gi_dev_particle *p;
    int n, first, nside, k, per_job; /* sources [first, n); outputs indexed i - first */
    uint64_t seed;
    const gi_lookup *grid;
    const gi_trilook *tl;
    double maxdist;
    int *links;
    unsigned char *anyhit;
    struct RTCRayHit **buf; /* per thread */
    vec3 **hp;
    long **cell;
    long **tcell; /* the hit's gi_trilook list, -1 none */
    atomic_long misses, unresolved, other, tri_ok, tri_fb;
    const void *const *pobj;
    const unsigned char *pin;
    double off, scale;
    int *order; /* stratum of the j-th ray of a particle */
    float *su0, *sv0, sw; /* the j-th ray's stratum corner in [-1, 1]^2 and the strata's width */
    const gi_sky *sky;    /* with esky: what the rays that leave the scene see */
    float *esky;
    const scene *sc;      /* for the far field of unanswered hits */
    gi_pigment_fn pig;    /* and their pigment (NULL: base colours) */
    float far_bounce;     /* brightness when the far field reflects the sky, else 0 */
    gi_dev_light *lights; /* the scene's, for the far field's direct light */
    int nlights;
    gi_hit_light hl;      /* the caustics' light and filtered shadows at the hits (gi_links.h) */
    int exact;            /* view points with no bounce after the hit: every hit takes hit_light */
    float *reach;         /* per source (i - first), 4 floats: the harmonic mean of its rays' hit
                             distances, the vector to their nearest hit */
    int occlude;          /* the gatherer's rays where a hit brings nothing (hits_dark): occlusion tests */
    int lone;             /* points' rays that end on a particle: no emission or mirror there to add (leaves_dark) */
    int points;           /* the sources are the final gather's points, not particles */
    /* mirror reflections at the hits (the final gather's points and the
     * gatherer, job_mirror): the gather rays' trace level and weight, the
     * level at which a ray returns black and the radiosity block's
     * adc_bailout (radrules.h rule 7); mirror 0: not followed */
    int mirror, mlevel, mlimit;
    double mweight, madc;
    void *lscene;         /* the link scene built here, or NULL */
    int threads;          /* buffers */
    gi_link_conts *cont;  /* per thread: the continuations ending on particles (gi_links_build's conts), or NULL */
} link_job;

/* Where ray h hit: the point and the normal turned to the ray (the
 * geometric one; minus the ray's direction in an instance). */
static void hit_point(const struct RTCRayHit *h, vec3 *pt, vec3 *nrm)
{
    vec3 d = v3(h->ray.dir_x, h->ray.dir_y, h->ray.dir_z), n = v3_neg(d);
    if (h->hit.instID[0] == RTC_INVALID_GEOMETRY_ID) {
        vec3 ng = v3(h->hit.Ng_x, h->hit.Ng_y, h->hit.Ng_z);
        double l = v3_len(ng);
        if (l > 0.0 && isfinite(l)) n = v3_dot(ng, d) > 0.0 ? v3_scale(ng, -1.0 / l) : v3_scale(ng, 1.0 / l);
    }
    *pt = v3(h->ray.org_x + h->ray.tfar * d.x, h->ray.org_y + h->ray.tfar * d.y, h->ray.org_z + h->ray.tfar * d.z);
    *nrm = n;
}

/* The material of object o at p (hit_point's, normal n, of ray h): rho
 * and le at the pigment there (a sky dome's gradient, a terrain's colours;
 * the texture's base colour without a pigment function), and that pigment
 * with its filter and transmit. */
static void hit_material(const link_job *J, const struct RTCRayHit *h, const scene_object *o,
                         const scene_texture *tex, vec3 p, vec3 n, float rho[3], float le[3], colour5 *pigment)
{
    colour5 c, *cp = NULL;
    if (J->pig) {
        accel_hit ah;
        memset(&ah, 0, sizeof ah);
        ah.p = p;
        ah.ng = ah.ns = n;
        ah.obj = o;
        ah.texture = tex;
        ah.flags = o->flags;
        ah.uv[0] = ah.p.x;
        ah.uv[1] = ah.p.y;
        /* a mesh's uv_vectors where a uv-mapped texture reads them, as
         * POV-Ray's radiosity rays shade their hits in full (a cloth's
         * hem stripes, not the world's x and y) */
        if (o->kind == SHAPE_MESH) {
            unsigned local;
            if (accel_rtc_object_tri(J->a, h->hit.geomID, h->hit.primID, h->hit.instID[0], &local) == o)
                accel_mesh_uv(o, local, h->hit.u, h->hit.v, ah.uv);
        }
        /* on a flat shape, the texture read where the hit lies in double
         * precision: POV-Ray intersects its radiosity rays so, and its
         * patterns' 1e-10 offsets (checker, brick, cells: pattern.cpp)
         * put a face lying in a cell boundary wholly in one cell
         * (balcony.pov's floor at z = 0 in a checker of textures).
         * Embree's float hit lies up to about 1e-7 of its coordinates off
         * the face on either side, and took either cell at random. Found
         * again by accel_intersect over a short stretch of the same ray.
         * Only a planar face can lie in a boundary as a whole; on other
         * surfaces the float error moves a cell's edge by as little,
         * which no gather sees. */
        if (o->kind == SHAPE_BOX || o->kind == SHAPE_PLANE || o->kind == SHAPE_DISC || o->kind == SHAPE_POLYGON) {
            vec3 org = v3(h->ray.org_x, h->ray.org_y, h->ray.org_z), d = v3(h->ray.dir_x, h->ray.dir_y, h->ray.dir_z);
            double t = h->ray.tfar, dt = 1e-4 * t + 1e-6 * J->scale; /* relative, and the working scale's */
            accel_hit dh;
            if (accel_intersect(J->a, org, d, t - dt, t + dt, &dh) && dh.obj == o) ah.p = dh.p;
        }
        if (J->pig(J->sc, tex, &ah, &c) && isfinite(c.r) &&
            isfinite(c.g) && isfinite(c.b) && isfinite(c.f) && isfinite(c.t))
            cp = &c;
    }
    gi_particles_material(J->sc, tex, cp, rho, le);
    if (pigment) *pigment = cp ? *cp : tex->pigment.colour;
}

/* The leaf a link ray hit and its effective texture (never NULL when the
 * leaf is found), CSG members included. */
static const scene_object *hit_leaf(const link_job *J, const struct RTCRayHit *h, const scene_texture **tex)
{
    const scene_object *o = accel_rtc_leaf(J->a, h->hit.geomID, h->hit.primID, h->hit.instID[0], h->hit.u, tex);
    if (o && !*tex) *tex = o->texture ? o->texture : &J->sc->default_texture;
    return o;
}

/* The light at the hit of link ray h that does not come from particles,
 * added to out (nothing without esky): the surface's emission; with
 * direct, for the final gather's links (J->lights), the direct light it
 * reflects; and with far, the far field's sky term below.
 *
 * The far field (beyond the paper, which leaves open scenes out): a link
 * ray that hits a surface where no particle answers (an infinite plane
 * beyond the geometry stage's clip box, a shape without particles) sees
 * that surface's emission, plus, when the light has a bounce to spare
 * (far_bounce > 0), the sky it reflects, taken as unoccluded: rho * b *
 * E_sky(n)/pi about the hit's normal turned to the ray, at the texture's
 * base colour. In a closed room under a black sky this is the emission
 * alone. Where a particle answers (far 0, direct 0) the particle's
 * reflected light is added by the caller (gi_particle_view_regather). */
/* Whether a texture emits at all (its finish's emission under a white
 * pigment), for the last texture asked: consecutive link rays mostly hit
 * one object. */
typedef struct {
    const scene_texture *tex;
    int emits;
    /* under some pigment: it emits (its emission is not 0), it reflects
     * (diffuse is not 0); where neither, no pigment gives light */
    int glows, reflects;
    int mirrors; /* its finish reflects as a mirror (mirror_reflects) */
    int clear;   /* its pigment can let light through (transmit_texture_may) */
} emit_memo_entry;

/* The last few textures asked (a gather's rays alternate between a few
 * objects: the sky dome, a wall, the floor), replaced in turn. */
#define EMIT_MEMO 4
/* the lights whose shadow rays keep a shadow cache (accel_occluded_cached) */
#define MEMO_LIGHTS 8
typedef struct {
    emit_memo_entry e[EMIT_MEMO];
    int next;
    unsigned blocker[MEMO_LIGHTS]; /* light l's last blocker (accel_occluded_cached's *last) */
    /* the continuations' particles (J->cont): this thread's list, the
     * source (i - first) whose ray is followed, the weight its
     * continuation carries so far (products of continue_ray's scales, over
     * the ray count), and 0 once a reflection_exponent made it nonlinear */
    gi_link_conts *cb;
    int src;
    float acc[3];
    int linear;
} emit_memo;

static const emit_memo_entry *memo_of(const link_job *J, emit_memo *memo, const scene_texture *tex)
{
    for (int i = 0; i < EMIT_MEMO; i++)
        if (memo->e[i].tex == tex) return &memo->e[i];
    emit_memo_entry *m = &memo->e[memo->next];
    memo->next = (memo->next + 1) % EMIT_MEMO;
    const colour5 white = {1.0, 1.0, 1.0, 0.0, 0.0};
    float rho[3], le[3];
    gi_particles_material(J->sc, tex, &white, rho, le);
    m->tex = tex;
    m->emits = le[0] > 0.0f || le[1] > 0.0f || le[2] > 0.0f;
    m->glows = le[0] != 0.0f || le[1] != 0.0f || le[2] != 0.0f;
    m->reflects = rho[0] != 0.0f || rho[1] != 0.0f || rho[2] != 0.0f;
    m->mirrors = mirror_reflects(&tex->finish);
    m->clear = transmit_texture_may(tex);
    return m;
}

static void hit_specular(const link_job *J, const struct RTCRayHit *h, const scene_object *o, const scene_texture *tex,
                         vec3 p, vec3 n, const colour5 *pigment, int level, double weight, emit_memo *memo, float out[3]);

/* E/pi of the sky at p about unit n, estimated by one cosine-weighted
 * shadow ray (its radiance where it leaves the scene, 0 where it is
 * blocked: the estimator of (1/pi) * integral of L cos over the
 * hemisphere). The direction comes from a hash of the point and the
 * arriving ray's direction d: the same hit gives the same answer. */
static void sky_traced(const link_job *J, vec3 p, vec3 n, vec3 d, float out[3])
{
    union { float f; gi_u32 u; } b0 = {(float)p.x}, b1 = {(float)p.y}, b2 = {(float)p.z}, b3 = {(float)(d.x + 2.0 * d.y + 4.0 * d.z)};
    gi_u32 h1 = gi_hash(b0.u ^ gi_hash(b1.u ^ gi_hash(b2.u ^ gi_hash(b3.u)))), h2 = gi_hash(h1 ^ 0x9e3779b9u);
    vec3 dir = v3_cosine_dir(n, (double)(h1 >> 8) / 16777216.0, (double)(h2 >> 8) / 16777216.0);
    double eps = accel_epsilon(J->a, p, n);
    out[0] = out[1] = out[2] = 0.0f;
    if (accel_occluded(J->a, v3_madd(p, n, eps), dir, 0.0, INFINITY)) return;
    const float df[3] = {(float)dir.x, (float)dir.y, (float)dir.z};
    gi_sky_radiance(J->sky, df, out);
}

/* org lies on n's side of p (the memo's last blocker is for that side). */
static int org_front(vec3 p, vec3 org, vec3 n) { return v3_dot(v3_sub(org, p), n) > 0.0; }

/* far: 0 no sky term; 1 the far field's, the sky taken as unoccluded (a
 * hit beyond the particles' box); 2 the sky as one traced ray sees it
 * (sky_traced: a hit within the box where no particle answers, which may
 * lie in a closed room) */
static void hit_light_at(const link_job *J, const struct RTCRayHit *h, int far, int direct, emit_memo *memo, float out[3],
                         int level, double weight)
{
    if (!J->esky) return;
    const scene_texture *tex;
    const scene_object *o = hit_leaf(J, h, &tex);
    if (!o) return;
    float rho[3], le[3];
    const emit_memo_entry *mt = memo_of(J, memo, tex);
    const int sky_term = far && J->far_bounce > 0.0f, lit = direct && J->nlights > 0;
    /* a mirror's reflection and a clear surface's transmission
     * (hit_specular), where followed */
    const int mir = J->mirror && (mt->mirrors || mt->clear);
    /* with no far-field sky, no lights and no mirror to reflect, only the
     * emission counts: none where the finish emits nothing */
    if (!sky_term && !lit && !mt->emits && !mir) return;
    vec3 p, n;
    hit_point(h, &p, &n);
    /* and, for the final gather's links (J->lights), the direct light it
     * reflects (the particles' edir at the hit, gi_k_emit's sum, a shadow
     * ray each; area lights from their centre): sunlit ground beyond the
     * clip box is bright, not black. This is no further bounce: POV-Ray's
     * radiosity rays see the direct light of what they hit at every
     * recursion_limit. It comes before the pigment: a hit in shadow that
     * neither emits nor sees the far field's sky adds nothing, whatever
     * its pigment (a turbulent pigment's noise is most of a textured
     * scene's gather). */
    float dir[3] = {0.0f, 0.0f, 0.0f};
    if (lit && mt->reflects) {
        /* finish { diffuse A, B }: a light behind the hit lights it
         * through diffuse_back, B / A of what the same light would give
         * in front (POV-Ray's radiosity rays shade what they hit as the
         * camera's rays do, trace.cpp ComputeDiffuseLight's backside) */
        const scene_finish *fin = tex ? &tex->finish : NULL;
        double bk = fin && fin->diffuse > 0.0 && fin->diffuse_back > 0.0 ? fin->diffuse_back / fin->diffuse : 0.0;
        /* the shadow ray starts eps off the surface, on the light's side,
         * and ends short of the light (gi_shadow_tmax), its length
         * measured from where it starts */
        double eps = accel_epsilon(J->a, p, n);
        for (int l = 0; l < J->nlights; l++) {
            const gi_dev_light *lt = &J->lights[l];
            float dl[3];
            float depth = gi_light_ray(lt, lt->pos[0], lt->pos[1], lt->pos[2], (float)p.x, (float)p.y, (float)p.z, dl);
            double ci = n.x * dl[0] + n.y * dl[1] + n.z * dl[2];
            if (!(ci > 0.0) && !(ci < 0.0 && bk > 0.0)) continue;
            vec3 org = v3_madd(p, n, ci > 0.0 ? eps : -eps);
            if (ci < 0.0) ci = -ci * bk;
            float att = gi_light_attenuation(lt, (float)p.x, (float)p.y, (float)p.z, dl, depth);
            if (!(att > 0.0f)) continue;
            /* the light let through: all, or POV-Ray's filtered shadow of
             * the transparent surfaces that block it */
            float tr[3] = {1.0f, 1.0f, 1.0f};
            if (!lt->shadowless) {
                float ds[3];
                double dep = gi_light_ray(lt, lt->pos[0], lt->pos[1], lt->pos[2], (float)org.x, (float)org.y, (float)org.z, ds);
                double tmax = dep > 0.0 ? gi_shadow_tmax(dep, eps) : INFINITY;
                unsigned *last = l < MEMO_LIGHTS && org_front(p, org, n) ? &memo->blocker[l] : NULL;
                if (tmax > eps && accel_occluded_cached(J->a, last, org, v3(ds[0], ds[1], ds[2]), 0.0, tmax)) {
                    if (!J->hl.shadow) continue;
                    rgb t = J->hl.shadow(J->sc, J->a, org, v3(ds[0], ds[1], ds[2]), 0.0, tmax,
                                         J->hl.photon_shadows ? &J->sc->lights[l] : NULL);
                    if (!(t.r > 0.0 || t.g > 0.0 || t.b > 0.0) || !isfinite(t.r + t.g + t.b)) continue;
                    tr[0] = (float)t.r;
                    tr[1] = (float)t.g;
                    tr[2] = (float)t.b;
                }
            }
            for (int c = 0; c < 3; c++) dir[c] += lt->colour[c] * att * (float)ci * tr[c];
        }
        /* and the caustic photons there: POV-Ray's radiosity rays see
         * photons at every hit (trace.cpp, ComputeLightedTexture) */
        if (J->hl.caus && !(o->photons && !o->photons->collect)) {
            rgb e = gi_caustic_world_at(J->hl.caus, p, n, 1.0, bk);
            if (isfinite(e.r + e.g + e.b)) {
                dir[0] += (float)e.r;
                dir[1] += (float)e.g;
                dir[2] += (float)e.b;
            }
        }
    }
    if (!sky_term && !mt->glows && !mir && dir[0] == 0.0f && dir[1] == 0.0f && dir[2] == 0.0f) return;
    colour5 pigment;
    hit_material(J, h, o, tex, p, n, rho, le, &pigment);
    /* no direct light where this pigment reflects nothing */
    if (!(rho[0] > 0.0f || rho[1] > 0.0f || rho[2] > 0.0f)) dir[0] = dir[1] = dir[2] = 0.0f;
    float irr[3] = {0.0f, 0.0f, 0.0f};
    if (sky_term && far == 2)
        sky_traced(J, p, n, v3(h->ray.dir_x, h->ray.dir_y, h->ray.dir_z), irr);
    else if (sky_term)
        gi_sky_irradiance(J->sky, n, irr);
    for (int c = 0; c < 3; c++) {
        float v = le[c] + rho[c] * (J->far_bounce * irr[c] + dir[c]);
        if (isfinite(v) && v > 0.0f) out[c] += v;
    }
    if (mir) hit_specular(J, h, o, tex, p, n, &pigment, level, weight, memo, out);
}

static void hit_light(const link_job *J, const struct RTCRayHit *h, int far, int direct, emit_memo *memo, float out[3])
{
    hit_light_at(J, h, far, direct, memo, out, J->mlevel, J->mweight);
}

/* The sky term of a hit where no particle answers (hit_light_at's far):
 * beyond the particles' box, the far field's unoccluded sky (an infinite
 * plane past the clip box); within it, where walls may close the sky off
 * (a thin post in a closed room), the sky one traced ray sees. */
static int unanswered_far(const link_job *J, const struct RTCRayHit *h)
{
    vec3 p, n;
    hit_point(h, &p, &n);
    return J->grid && gi_lookup_covers(J->grid, p) ? 2 : 1;
}

/* The particle a continuation's hit h takes (the nearest on the object
 * and side hit, as a point's own ray's), -1 none. */
static int cont_target(const link_job *J, const struct RTCRayHit *h)
{
    if (!J->grid || !J->pobj || h->hit.instID[0] != RTC_INVALID_GEOMETRY_ID) return -1;
    const void *ho = accel_rtc_object(J->a, h->hit.geomID, h->hit.primID, h->hit.instID[0]);
    if (!ho) return -1;
    vec3 p, n;
    hit_point(h, &p, &n);
    vec3 d = v3(h->ray.dir_x, h->ray.dir_y, h->ray.dir_z), o = v3(h->ray.org_x, h->ray.org_y, h->ray.org_z);
    return gi_lookup_nearest_on(J->grid, p, d, o, J->maxdist, J->pobj, ho, n, GI_LINKS_AGREE, J->pin ? J->pin + J->n : NULL);
}

static int cont_push(gi_link_conts *c, int src, int t, const float w[3])
{
    if (!grow_array_long((void **)&c->e, &c->cap, c->n + 1, sizeof *c->e)) return 0;
    gi_link_cont *e = &c->e[c->n++];
    e->src = src;
    e->t = t;
    for (int k = 0; k < 3; k++) e->w[k] = w[k];
    return 1;
}

void gi_link_conts_free(gi_link_conts *c)
{
    if (!c) return;
    free(c->e);
    c->e = NULL;
    c->n = c->cap = 0;
}

/* The threads' lists appended to out in the order of their sources (a
 * counting sort: a source's entries all come from one job, in the order
 * its rays were followed), so that their sums come out the same for any
 * thread count and schedule. nsrc: the sources' count. */
static pt_status conts_gather(const gi_link_conts *per, int threads, int nsrc, gi_link_conts *out)
{
    long total = 0;
    for (int t = 0; t < threads; t++) total += per[t].n;
    if (total == 0) return PT_OK;
    long *off = calloc((size_t)nsrc + 1, sizeof *off);
    gi_link_cont *e = realloc(out->e, (size_t)(out->n + total) * sizeof *e);
    if (!off || !e) {
        free(off);
        if (e) out->e = e;
        return PT_ERR_NOMEM;
    }
    out->e = e;
    out->cap = out->n + total;
    for (int t = 0; t < threads; t++)
        for (long q = 0; q < per[t].n; q++) off[per[t].e[q].src + 1]++;
    for (int s = 0; s < nsrc; s++) off[s + 1] += off[s];
    for (int t = 0; t < threads; t++)
        for (long q = 0; q < per[t].n; q++) out->e[out->n + off[per[t].e[q].src]++] = per[t].e[q];
    out->n += total;
    free(off);
    return PT_OK;
}

/* Trace one continuation of a gather ray (a mirror's reflection, a
 * transmission) from org along unit d at trace level `level` with weight
 * w, and add scale times what it brings back to out: what a gather ray
 * takes where it hits (hit_light_at: emission, direct light, the far
 * field's sky, and its own continuations) or the sky where it leaves; ex
 * (reflection_exponent's reciprocal) raises that to a power first. */
static void continue_ray(const link_job *J, vec3 org, vec3 d, int level, double w, emit_memo *memo, rgb scale,
                         double ex, float out[3])
{
    const float of[3] = {(float)org.x, (float)org.y, (float)org.z}, df[3] = {(float)d.x, (float)d.y, (float)d.z};
    struct RTCRayHit rh;
    accel_rtc_rayhit_init(&rh, of, (float)accel_epsilon(J->a, org, d), df);
    struct RTCIntersectContext c;
    rtcInitIntersectContext(&c);
    rtcIntersect1(J->scene, &c, &rh);
    float sub[3] = {0.0f, 0.0f, 0.0f};
    const double sc[3] = {scale.r, scale.g, scale.b};
    /* the weight down the chain, for a particle where it ends */
    float acc[3] = {memo->acc[0], memo->acc[1], memo->acc[2]};
    int linear = memo->linear;
    for (int k = 0; k < 3; k++) memo->acc[k] = (float)(acc[k] * sc[k]);
    memo->linear = linear && ex == 1.0;
    if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID && isfinite(rh.ray.tfar)) {
        int t = memo->cb && memo->linear ? cont_target(J, &rh) : -1;
        if (t >= 0 && cont_push(memo->cb, memo->src, t, memo->acc))
            hit_light_at(J, &rh, 0, 0, memo, sub, level, w); /* the particle's light through gi_link_cont */
        else
            hit_light_at(J, &rh, 2, 1, memo, sub, level, w);
    } else {
        gi_sky_radiance(J->sky, df, sub);
    }
    for (int k = 0; k < 3; k++) memo->acc[k] = acc[k];
    memo->linear = linear;
    for (int k = 0; k < 3; k++) {
        double v = ex != 1.0 ? pow(fmax(sub[k], 0.0), ex) : sub[k];
        v *= sc[k];
        if (isfinite(v) && v > 0.0) out[k] += (float)v;
    }
}

/* The mirror reflection and the transmission at the hit of ray h (at
 * trace level `level`, of weight `weight`) on object o with texture tex,
 * at p with the normal n turned to the ray and the pigment there, added to
 * out. POV-Ray traces its radiosity rays in full (radiosity.cpp
 * GatherLight calls TraceRay), so one that meets a mirror (balcony.pov's
 * sea: no diffuse, a fresnel reflection up to 0.95) brings back what the
 * mirror reflects, and one that meets glass what lies behind it. Both
 * follow the Whitted pass's rules (trace.cpp ComputeLightedTexture): the
 * reflectivity of mirror.h (fresnel at the interior's ior, falloff,
 * metallic; reflection_exponent on what comes back), and transmit.h's
 * filter (filter and transmit, less the reflectivity under
 * conserve_energy), refraction at the interior's ior (total internal
 * reflection: the reflected ray alone, unfiltered, in place of the
 * mirror's) and fade over the way inside for a ray that leaves the
 * interior. They are taken for the texture's top finish and its composite
 * pigment, as the rest of the GI takes them, about the geometric normal
 * (a normal pattern's ripples are not followed, nor dispersion, nor a
 * mirror or glass in an instance, whose hit carries no normal here), and
 * from the geometric side alone (no list of the interiors the ray is
 * in: overlapping glass takes each object's own ior against air). Each
 * continuation goes one trace level up and is not traced at or past the
 * level limit nor below the radiosity block's adc_bailout (trace.cpp
 * TraceRay, ComputeRefraction; radrules.h rule 7). */
static void hit_specular(const link_job *J, const struct RTCRayHit *h, const scene_object *o, const scene_texture *tex,
                         vec3 p, vec3 n, const colour5 *pigment, int level, double weight, emit_memo *memo, float out[3])
{
    /* in an instance the hit's normal is not known here (hit_point takes
     * minus the ray's direction): no direction to follow */
    if (level + 1 >= J->mlimit || h->hit.instID[0] != RTC_INVALID_GEOMETRY_ID) return;
    const scene_finish *f = &tex->finish;
    vec3 d = v3(h->ray.dir_x, h->ray.dir_y, h->ray.dir_z);
    double dl = v3_len(d);
    if (!(dl > 0.0)) return;
    d = v3_scale(d, 1.0 / dl);
    double cos_i = -v3_dot(d, n);
    if (!(cos_i > 0.0)) return;
    /* a ray entering the object meets the outer side of the raw geometric
     * normal; the relative ior is outside over inside for it */
    const int entering = h->hit.Ng_x * d.x + h->hit.Ng_y * d.y + h->hit.Ng_z * d.z <= 0.0;
    const double ior = o->interior && o->interior->ior > 0.0 ? o->interior->ior : 1.0;
    const double rel_ior = entering ? ior : 1.0 / ior;
    double w = weight;
    rgb refl = {0.0, 0.0, 0.0};
    if (memo_of(J, memo, tex)->mirrors) {
        refl = mirror_reflectivity(f, cos_i, rel_ior, &w);
        mirror_metallic_tint(&refl, f->reflection_metallic, (rgb){pigment->r, pigment->g, pigment->b}, cos_i);
    }
    double off = J->off * (J->scale + fmax(fabs(p.x), fmax(fabs(p.y), fabs(p.z))));
    const double ex = f->reflection_exponent != 0.0 ? 1.0 / f->reflection_exponent : 1.0;
    int tir = 0;
    const rgb filcol = transmit_layer_filter((rgb){1.0, 1.0, 1.0}, pigment, f, refl);
    const double trans = fmin(1.0, fabs(transmit_grey(filcol)));
    const double tw = weight * fmax(fabs(filcol.r), fmax(fabs(filcol.g), fabs(filcol.b)));
    if (trans > J->madc && tw >= J->madc) {
        /* the fade over the way this ray came inside the object it leaves */
        const rgb att = entering ? (rgb){1.0, 1.0, 1.0} : transmit_fade(o->interior, h->ray.tfar * dl, 0);
        vec3 td = d;
        if (fabs(1.0 / rel_ior - 1.0) >= 1e-10) tir = transmit_refract(d, n, cos_i, 1.0 / rel_ior, &td);
        if (tir)
            continue_ray(J, v3_madd(p, n, off), v3_madd(d, n, 2.0 * cos_i), level + 1, tw, memo, att, 1.0, out);
        else
            continue_ray(J, v3_madd(p, n, -off), td, level + 1, tw, memo,
                         (rgb){att.r * filcol.r, att.g * filcol.g, att.b * filcol.b}, 1.0, out);
    }
    if (tir || w < J->madc || !(refl.r > 0.0 || refl.g > 0.0 || refl.b > 0.0)) return;
    continue_ray(J, v3_madd(p, n, off), v3_madd(d, n, 2.0 * cos_i), level + 1, w, memo, refl, ex, out);
}

/* sin and cos of a = (pi/4) t for t in [-1, 1] (the concentric map's
 * angle within one octant) by their Taylor polynomials, sin to a^9 and cos
 * to a^8: the remainders are at most (pi/4)^11/11! = 1.8e-9 and
 * (pi/4)^10/10! = 2.5e-8, below a float ulp of 1 (6e-8); with the
 * rounding of the evaluation the result is within a few ulps of sinf and
 * cosf. */
static inline void sincos_octant(float t, float *s, float *c)
{
    const float a = 0.785398163f * t, a2 = a * a;
    *s = a * (1.0f + a2 * (-1.0f / 6.0f + a2 * (1.0f / 120.0f + a2 * (-1.0f / 5040.0f + a2 * (1.0f / 362880.0f)))));
    *c = 1.0f + a2 * (-0.5f + a2 * (1.0f / 24.0f + a2 * (-1.0f / 720.0f + a2 * (1.0f / 40320.0f))));
}

/* Direction j of the n x n stratified cosine-weighted set around a unit
 * normal, in float for the hot loop: Shirley and Chiu's concentric
 * square-to-disk map (JGT 2(3), 1997) lifted to the hemisphere (Malley's
 * method), with the frame (t, b, nrm) built once per
 * particle and the stratum's corner (su0, sv0) and width (w, in the
 * [-1, 1]^2 square) once per link. On |su| > |sv|, r = su and
 * theta = (pi/4) sv/su, so (x, y) = r (cos, sin)(pi/4 sv/su); otherwise
 * r = sv and theta = pi/2 - (pi/4) su/sv, so (x, y) = r (sin, cos)(pi/4 su/sv). */
static inline void direction_f(const float t[3], const float b[3], const float nrm[3], float su0, float sv0, float w,
                               float u1, float u2, float out[3])
{
    float su = su0 + w * u1, sv = sv0 + w * u2;
    int big = fabsf(su) > fabsf(sv);
    float r = big ? su : sv, num = big ? sv : su;
    float q = r != 0.0f ? num / r : 0.0f, sn, cs;
    sincos_octant(q, &sn, &cs);
    float x = r * (big ? cs : sn), y = r * (big ? sn : cs);
    float z2 = 1.0f - r * r, z = sqrtf(z2 > 0.0f ? z2 : 0.0f);
    for (int k = 0; k < 3; k++) out[k] = t[k] * x + b[k] * y + nrm[k] * z;
}

#define AGREE GI_LINKS_AGREE

/* Particle t moved a little along its normal, inside solid o? */
static int inside_lifted(const scene_object *o, const gi_dev_particle *t)
{
    vec3 p = v3(t->p[0], t->p[1], t->p[2]);
    double lift = 1e-5 * (1.0 + fmax(fabs(p.x), fmax(fabs(p.y), fabs(p.z))));
    return gi_surface_inside_solid(o, v3_madd(p, v3(t->n[0], t->n[1], t->n[2]), lift));
}

/* The k = nside^2 rays of one source at pos with unit normal nrm into rh:
 * the stratified cosine-weighted set (direction_f) from random stream
 * `stream` of the job's seed, from a point lifted off the surface by the
 * job's offset. */
static void source_rays(const link_job *J, vec3 pos, vec3 nrm, uint64_t stream, struct RTCRayHit *rh)
{
    double off = J->off * (J->scale + fmax(fabs(pos.x), fmax(fabs(pos.y), fabs(pos.z))));
    vec3 org = v3_madd(pos, nrm, off);
    /* per source: the frame and the ray epsilon (unit directions) */
    vec3 tv, bv;
    v3_basis(nrm, &tv, &bv);
    float t[3] = {(float)tv.x, (float)tv.y, (float)tv.z}, bb[3] = {(float)bv.x, (float)bv.y, (float)bv.z};
    float nf[3] = {(float)nrm.x, (float)nrm.y, (float)nrm.z};
    float tnear = (float)accel_epsilon(J->a, org, nrm);
    const float of[3] = {(float)org.x, (float)org.y, (float)org.z};
    rng r;
    rng_seed(&r, J->seed, stream);
    for (int j = 0; j < J->k; j++) {
        float u1 = (float)rng_f64(&r), u2 = (float)rng_f64(&r);
        float d[3];
        direction_f(t, bb, nf, J->su0[j], J->sv0[j], J->sw, u1, u2, d);
        accel_rtc_rayhit_init(&rh[j], of, tnear, d);
    }
}

static void trace_rays(const link_job *J, struct RTCRayHit *rh, int m)
{
    struct RTCIntersectContext c;
    rtcInitIntersectContext(&c);
    /* incoherent: a batch's rays start at many particles and spread over
     * the hemisphere, so Embree's stream mode for incoherent rays beats
     * coherent packets (per 4x4 block of strata) and single rays on them
     * (docs/gi.md; bench/bench_gi prints the link stage's time). */
    c.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    rtcIntersect1M(J->scene, &c, rh, (unsigned)m, sizeof *rh);
}

static int ray_hit(const struct RTCRayHit *h)
{
    return h->hit.geomID != RTC_INVALID_GEOMETRY_ID && isfinite(h->ray.tfar);
}

/* How far one source's k rays reach: k over the sum of 1/distance of
 * those that hit (a miss adds nothing), INFINITY when none hit. This is
 * the harmonic mean distance an irradiance cache sizes a record's reach
 * by (Ward, Rubinstein and Clear 1988; POV-Ray's radiosity.cpp takes the
 * same mean of its sample rays' depths, a miss's depth infinite). */
static float harmonic_reach(const struct RTCRayHit *rh, int k)
{
    double inv = 0.0;
    for (int j = 0; j < k; j++)
        if (ray_hit(&rh[j]) && rh[j].ray.tfar > 0.0f) inv += 1.0 / rh[j].ray.tfar;
    return inv > 0.0 ? (float)(k / inv) : INFINITY;
}

/* The vector from the source to the nearest hit of its k rays (zero when
 * none hit): POV-Ray's record keeps it (radiosity.cpp, To_Nearest_Surface
 * and Nearest_Distance) to shrink the record's reach toward that surface. */
static void nearest_hit(const struct RTCRayHit *rh, int k, float v[3])
{
    float best = INFINITY;
    v[0] = v[1] = v[2] = 0.0f;
    for (int j = 0; j < k; j++) {
        if (!ray_hit(&rh[j]) || !(rh[j].ray.tfar > 0.0f)) continue;
        float dx = rh[j].ray.dir_x, dy = rh[j].ray.dir_y, dz = rh[j].ray.dir_z;
        float l = sqrtf(dx * dx + dy * dy + dz * dz), d = rh[j].ray.tfar * l;
        if (!(d < best) || !(l > 0.0f)) continue;
        best = d;
        v[0] = dx * rh[j].ray.tfar;
        v[1] = dy * rh[j].ray.tfar;
        v[2] = dz * rh[j].ray.tfar;
    }
}

/* What a ray that leaves the scene adds: the sky's radiance in its
 * direction. */
static void ray_sky(const link_job *J, const struct RTCRayHit *h, float sky[3])
{
    const float d[3] = {h->ray.dir_x, h->ray.dir_y, h->ray.dir_z};
    float L[3];
    gi_sky_radiance(J->sky, d, L);
    for (int c = 0; c < 3; c++) sky[c] += L[c];
}

static void job(void *ctx, int index, int thread)
{
    link_job *J = ctx;
    struct RTCRayHit *rh = J->buf[thread];
    int i0 = J->first + index * J->per_job, i1 = i0 + J->per_job < J->n ? i0 + J->per_job : J->n;
    int m = 0;
    long miss = 0, unres = 0, other = 0, tri_ok = 0, tri_fb = 0;
    for (int i = i0; i < i1; i++) {
        const gi_dev_particle *pt = &J->p[i];
        source_rays(J, v3(pt->p[0], pt->p[1], pt->p[2]), v3(pt->n[0], pt->n[1], pt->n[2]), (uint64_t)i, rh + m);
        m += J->k;
    }
    trace_rays(J, rh, m);
    if (J->reach)
        for (int i = i0; i < i1; i++) {
            const struct RTCRayHit *r0 = rh + (size_t)(i - i0) * J->k;
            float *o = &J->reach[4 * (size_t)(i - J->first)];
            o[0] = harmonic_reach(r0, J->k);
            nearest_hit(r0, J->k, o + 1);
        }
    /* hit points and their lookup cells; the lookups are bound by memory
     * latency, so the whole batch prefetches first (gi_area_particles.h) */
    vec3 *hp = J->hp[thread];
    long *cell = J->cell[thread], *tcell = J->tcell[thread];
    /* hits on a triangle gi_trilook lists take its list (cell -3: no grid
     * cell, unless the list cannot decide) */
    const gi_trilook *tl = J->tl && J->grid && J->links && J->pobj && !J->exact ? J->tl : NULL;
    /* the final gather's points: the answer at the centre of the hit's
     * cell where it has one (gi_links.h); only the others scan a list */
    const int *rep = tl && J->points ? gi_trilook_centre_table(tl) : NULL;
    for (int t = 0; t < m; t++) {
        const struct RTCRayHit *h = &rh[t];
        int hit = ray_hit(h);
        hp[t] = v3(h->ray.org_x + h->ray.tfar * h->ray.dir_x, h->ray.org_y + h->ray.tfar * h->ray.dir_y,
                   h->ray.org_z + h->ray.tfar * h->ray.dir_z);
        cell[t] = hit ? -1 : -2;
        tcell[t] = -1;
        if (hit && tl && h->hit.instID[0] == RTC_INVALID_GEOMETRY_ID) {
            const float d[3] = {h->ray.dir_x, h->ray.dir_y, h->ray.dir_z};
            tcell[t] = gi_trilook_cell(tl, h->hit.geomID, h->hit.primID, h->hit.u, h->hit.v, d);
            if (tcell[t] >= 0) {
                cell[t] = -3;
                if (rep) __builtin_prefetch(&rep[tcell[t]]);
                else gi_trilook_prefetch(tl, tcell[t], 0);
            }
        }
    }
    if (tl && rep)
        for (int t = 0; t < m; t++)
            if (tcell[t] >= 0 && rep[tcell[t]] < 0) gi_trilook_prefetch(tl, tcell[t], 0);
    if (tl)
        for (int st = 1; st <= 2; st++)
            for (int t = 0; t < m; t++)
                if (tcell[t] >= 0 && !(rep && rep[tcell[t]] >= 0)) gi_trilook_prefetch(tl, tcell[t], st);
    if (J->grid && J->links && !J->exact) gi_lookup_cells(J->grid, m, hp, cell);
    m = 0;
    const void *last_obj = NULL;
    int last_hid = -1;
    emit_memo memo = {0};
    memo.cb = J->cont ? &J->cont[thread] : NULL;
    for (int i = i0; i < i1; i++) {
        int any = 0;
        float sky[3] = {0.0f, 0.0f, 0.0f};
        memo.src = i - J->first;
        memo.linear = 1;
        memo.acc[0] = memo.acc[1] = memo.acc[2] = 1.0f / (float)J->k;
        const gi_dev_particle *pt_i = &J->p[i];
        for (int j = 0; j < J->k; j++, m++) {
            int hit = cell[m] != -2;
            any |= hit;
            if (!hit) {
                miss++;
                if (J->esky) ray_sky(J, &rh[m], sky);
            }
            if (!J->links) continue;
            int target = -1;
            if (J->exact) {
                /* no bounce after this hit (POV-Ray's recursion_limit 1, or
                 * brightness 0): what the ray sees there is the hit's
                 * emission and the direct light it reflects, computed at
                 * the hit itself (hit_light, a shadow ray a light from its
                 * centre, as POV-Ray's radiosity rays take area lights)
                 * rather than read from the nearest particle, whose value
                 * blurs shadow edges over a particle spacing */
                if (hit) hit_light(J, &rh[m], 1, 1, &memo, sky);
                J->links[(size_t)(i - J->first) * J->k + J->order[j]] = -1;
                continue;
            }
            /* a hit on an object that carries no particles (unsupported
             * shapes, CSG results whose members are not sampled) has no
             * answer: the checks below would only accept a particle on that
             * object, and the lookup would first search to maxdist for one
             * (10 blobs without particles, 20K particles: gather links
             * 11.7 -> 6.6 s). Same links, without the search. */
            /* (a hit on a triangle the lists cover is on an object with
             * particles: its object is needed only if the list leaves the
             * hit to the grid) */
            const void *hobj = hit && J->grid && J->pobj && cell[m] != -3
                                   ? accel_rtc_object(J->a, rh[m].hit.geomID, rh[m].hit.primID, rh[m].hit.instID[0])
                                   : NULL;
            /* consecutive hits are often on one object: its id once (hits
             * the triangle lists answer, hobj NULL, leave the cache be) */
            if (hobj && hobj != last_obj) {
                last_obj = hobj;
                last_hid = gi_lookup_object_id(J->grid, hobj);
            }
            int hid = hobj ? last_hid : -1;
            if (hobj && hid < 0) {
                unres++;
                hit_light(J, &rh[m], unanswered_far(J, &rh[m]), 1, &memo, sky);
            } else if (hit && J->grid) {
                const struct RTCRayHit *h = &rh[m];
                vec3 d = v3(h->ray.dir_x, h->ray.dir_y, h->ray.dir_z);
                vec3 o = v3(h->ray.org_x, h->ray.org_y, h->ray.org_z);
                float tn[3];
                int tobj, fast = 0;
                if (cell[m] == -3) {
                    /* the hit triangle's list: the nearest particle on the
                     * object and side hit (gi_trilook.h), or -2 */
                    const float qf[3] = {(float)hp[m].x, (float)hp[m].y, (float)hp[m].z};
                    const float df[3] = {h->ray.dir_x, h->ray.dir_y, h->ray.dir_z};
                    const float of[3] = {h->ray.org_x, h->ray.org_y, h->ray.org_z};
                    target = rep && rep[tcell[m]] >= 0 ? rep[tcell[m]] : gi_trilook_nearest(tl, tcell[m], qf, df, of);
                    if (target >= -1) {
                        fast = 1;
                        tri_ok++;
                    } else {
                        tri_fb++;
                        cell[m] = gi_lookup_cell(J->grid, hp[m]);
                        hobj = accel_rtc_object(J->a, h->hit.geomID, h->hit.primID, h->hit.instID[0]);
                        hid = gi_lookup_object_id(J->grid, hobj);
                    }
                }
                if (!fast) target = gi_lookup_nearest_in2(J->grid, cell[m], hp[m], d, o, J->maxdist, tn, &tobj);
                if (!fast && target >= 0 && J->pobj) {
                    /* the answer must lie on the object hit: near a contact
                     * (a sphere on the floor) or where a box stands on the
                     * floor the nearest particle can be another object's,
                     * on the other side of a wall */
                    const void *ho = hobj;
                    /* and on the face and side hit: its normal agrees with
                     * the hit's geometric normal turned to the ray (within
                     * about 70 degrees; Ng is in world space unless the
                     * hit is in an instance) */
                    vec3 agree = v3s(0.0);
                    if (h->hit.instID[0] == RTC_INVALID_GEOMETRY_ID) {
                        agree = v3(h->hit.Ng_x, h->hit.Ng_y, h->hit.Ng_z);
                        if (v3_dot(agree, d) > 0.0) agree = v3_neg(agree);
                    }
                    /* the answer's object and normal from the lookup's
                     * copy when it has them (no random read of pobj[] and
                     * the particle records) */
                    int other_obj;
                    double ag;
                    if (tobj >= -1) {
                        other_obj = ho && tobj != hid;
                        ag = tn[0] * agree.x + tn[1] * agree.y + tn[2] * agree.z;
                    } else {
                        const gi_dev_particle *tp = &J->p[target];
                        other_obj = J->pobj[target] != ho;
                        ag = tp->n[0] * agree.x + tp->n[1] * agree.y + tp->n[2] * agree.z;
                    }
                    if (ho && (other_obj || ag < AGREE * v3_len(agree))) {
                        double al = v3_len(agree);
                        target = gi_lookup_nearest_on(J->grid, hp[m], d, o, J->maxdist, J->pobj, ho,
                                                      al > 0.0 ? v3_scale(agree, 1.0 / al) : agree, AGREE,
                                                      J->pin ? J->pin + J->n : NULL);
                        other++;
                    }
                }
                if (target >= 0 && J->pin && J->pin[i]) {
                    /* a ray from the inside of a closed sphere or box must
                     * end inside it too: where the box stands on the floor
                     * its ray hits the floor (the coplanar faces tie), and
                     * the nearest floor particle may lie outside the box */
                    const scene_object *so = J->pobj[i];
                    if (!inside_lifted(so, &J->p[target])) {
                        const struct RTCRayHit *h = &rh[m];
                        vec3 d = v3(h->ray.dir_x, h->ray.dir_y, h->ray.dir_z);
                        vec3 o = v3(h->ray.org_x, h->ray.org_y, h->ray.org_z);
                        vec3 agree = v3_neg(d);
                        target = gi_lookup_nearest_on(J->grid, hp[m], d, o, J->maxdist, J->pobj, so, agree, 0.0, NULL);
                        if (target >= 0 && !inside_lifted(so, &J->p[target])) target = -1;
                        other++;
                    }
                }
                if (target >= 0 && J->pin && J->pin[J->n + target] && !inside_lifted(J->pobj[J->n + target], pt_i)) {
                    /* and a ray from outside must not end on a particle
                     * buried in a closed solid (the floor under a box) */
                    const struct RTCRayHit *h = &rh[m];
                    vec3 d = v3(h->ray.dir_x, h->ray.dir_y, h->ray.dir_z);
                    vec3 o = v3(h->ray.org_x, h->ray.org_y, h->ray.org_z);
                    target = gi_lookup_nearest_on(J->grid, hp[m], d, o, J->maxdist, J->pobj, J->pobj[target],
                                                  v3_neg(d), 0.0, J->pin + J->n);
                    other++;
                }
                if (target >= 0 && J->pin && J->pin[target] && !inside_lifted(J->pobj[target], pt_i)) {
                    /* the inside of a closed sphere or box is reached only
                     * by rays from inside it */
                    const struct RTCRayHit *h = &rh[m];
                    vec3 d = v3(h->ray.dir_x, h->ray.dir_y, h->ray.dir_z);
                    vec3 o = v3(h->ray.org_x, h->ray.org_y, h->ray.org_z);
                    target = gi_lookup_nearest_on(J->grid, hp[m], d, o, J->maxdist, J->pobj, J->pobj[target],
                                                  v3_neg(d), 0.0, J->pin);
                    other++;
                }
                if (target < 0) {
                    unres++;
                    if (hit) hit_light(J, &rh[m], unanswered_far(J, &rh[m]), 1, &memo, sky);
                } else if (J->points && J->esky && !J->lone) {
                    /* the emission where it hit; the particle's reflected
                     * light, direct and indirect, follows in the regather */
                    hit_light(J, &rh[m], 0, 0, &memo, sky);
                }
            }
            J->links[(size_t)(i - J->first) * J->k + J->order[j]] = target;
        }
        if (J->anyhit) J->anyhit[i - J->first] = (unsigned char)any;
        if (J->esky) {
            float *e = &J->esky[4 * (size_t)(i - J->first)];
            for (int c = 0; c < 3; c++) e[c] = sky[c] / (float)J->k;
            e[3] = 0.0f;
        }
    }
    atomic_fetch_add(&J->misses, miss);
    atomic_fetch_add(&J->unresolved, unres);
    atomic_fetch_add(&J->other, other);
    atomic_fetch_add(&J->tri_ok, tri_ok);
    atomic_fetch_add(&J->tri_fb, tri_fb);
}

/* the sources of gi_links_reverse_*: i ascending, in mask */
static int next_source(const unsigned *mask, int n, int i)
{
    for (i++; i < n; i++) {
        if (!mask) return i;
        unsigned wd = mask[i >> 5] >> (i & 31);
        if (wd) return i + __builtin_ctz(wd);
        i |= 31; /* the rest of this word is clear */
    }
    return n;
}

size_t gi_links_reverse_count(const int *links, int n, int k, const unsigned *mask, int *off)
{
    memset(off, 0, ((size_t)n + 2) * sizeof(int));
    for (int i = next_source(mask, n, -1); i < n; i = next_source(mask, n, i)) {
        const int *lk = links + (size_t)i * (size_t)k;
        for (int j = 0; j < k; j++)
            if (lk[j] >= 0) off[lk[j] + 2]++;
    }
    for (int t = 0; t < n; t++) off[t + 2] += off[t + 1];
    return (size_t)off[n + 1];
}

void gi_links_reverse_fill(const int *links, int n, int k, const unsigned *mask, int *off, int *src)
{
    /* off[t + 1] is target t's write cursor; it ends at t's end, t + 1's start */
    for (int i = next_source(mask, n, -1); i < n; i = next_source(mask, n, i)) {
        const int *lk = links + (size_t)i * (size_t)k;
        for (int j = 0; j < k; j++)
            if (lk[j] >= 0) src[off[lk[j] + 1]++] = i;
    }
}

/* The set-up gi_links_build and the gatherer share: the scene to trace,
 * the strata, the offsets and `threads` buffers of `rays` rays (with
 * cells: the lookup's per-ray arrays too). Undone by job_close. */
static pt_status job_open(link_job *J, const accel *a, void *rtc_scene, int nside, int threads, size_t rays, int cells)
{
    J->a = a;
    /* the link scene (accel.h): without the main scene's robust mode and
     * filters it is cheaper per link ray; the main scene is the fallback */
    J->lscene = rtc_scene ? NULL : accel_rtc_link_scene(a);
    J->scene = rtc_scene ? (RTCScene)rtc_scene : J->lscene ? (RTCScene)J->lscene : (RTCScene)accel_rtc_scene(a);
    if (!J->scene) return PT_ERR_INTERNAL;
    J->nside = nside;
    J->k = nside * nside;
    J->threads = threads;
    /* rays in 4x4 blocks of strata (a narrow cone each) when the side
     * divides by 4 (the order fixes which random numbers each stratum
     * gets, so it stays although the rays are traced as incoherent) */
    J->order = malloc((size_t)J->k * sizeof *J->order);
    J->su0 = malloc((size_t)J->k * sizeof *J->su0);
    J->sv0 = malloc((size_t)J->k * sizeof *J->sv0);
    J->buf = calloc((size_t)threads, sizeof *J->buf);
    if (cells) {
        J->hp = calloc((size_t)threads, sizeof *J->hp);
        J->cell = calloc((size_t)threads, sizeof *J->cell);
        J->tcell = calloc((size_t)threads, sizeof *J->tcell);
    }
    if (!J->order || !J->su0 || !J->sv0 || !J->buf || (cells && (!J->hp || !J->cell || !J->tcell))) return PT_ERR_NOMEM;
    for (int j = 0; j < J->k; j++) {
        if (nside % 4 == 0) {
            int blk = j / 16, w = j % 16, bpr = nside / 4;
            J->order[j] = ((blk / bpr) * 4 + w / 4) * nside + (blk % bpr) * 4 + w % 4;
        } else {
            J->order[j] = j;
        }
    }
    /* su = 2 (jx + u1) / nside - 1 = su0 + sw u1, as direction_f takes it */
    J->sw = 2.0f / (float)nside;
    for (int j = 0; j < J->k; j++) {
        J->su0[j] = 2.0f * (float)(J->order[j] % nside) / (float)nside - 1.0f;
        J->sv0[j] = 2.0f * (float)(J->order[j] / nside) / (float)nside - 1.0f;
    }
    /* origins leave the surface by 1e-6 of the working scale (the median
     * object size, accel_eps_scale) plus the point's magnitude: the scene's
     * diagonal would let one far object (a sky sphere of radius 1e6 around
     * a room) lift every origin past the room's walls */
    J->off = 1e-6;
    J->scale = accel_eps_scale(a);
    size_t bytes = rays * sizeof(struct RTCRayHit);
    for (int t = 0; rays > 0 && t < threads; t++) {
        J->buf[t] = aligned_alloc(64, (bytes + 63) / 64 * 64);
        if (!J->buf[t]) return PT_ERR_NOMEM;
        if (!cells) continue;
        J->hp[t] = malloc(rays * sizeof(vec3));
        J->cell[t] = malloc(rays * sizeof(long));
        J->tcell[t] = malloc(rays * sizeof(long));
        if (!J->hp[t] || !J->cell[t] || !J->tcell[t]) return PT_ERR_NOMEM;
    }
    return PT_OK;
}

/* The direct light of sc's lights at what the rays hit (hit_light). */
static pt_status job_lights(link_job *J, const scene *sc)
{
    if (sc->nlights <= 0) return PT_OK;
    J->lights = malloc((size_t)sc->nlights * sizeof *J->lights);
    if (!J->lights) return PT_ERR_NOMEM;
    for (int l = 0; l < sc->nlights; l++) gi_light_pack(&sc->lights[l], &J->lights[l]);
    J->nlights = sc->nlights;
    return PT_OK;
}

/* Mirror reflections at the hits, with POV-Ray's trace level and weight
 * for the rays of the first gathering step (radiosity.cpp
 * GetRecursionSettings: level int(1.5), weight 0.5 brightness, at least
 * the block's adc_bailout; GatherLight raises the level limit to one
 * above the rays' level). */
static void job_mirror(link_job *J, const scene *sc)
{
    const radrules rr = radrules_of(sc, 1);
    const scene_radiosity *rs = &sc->global.radiosity;
    J->mirror = 1;
    J->mlevel = radrules_gather_level(1);
    J->mlimit = radrules_level_limit(sc, J->mlevel);
    J->madc = isfinite(rs->adc_bailout) && rs->adc_bailout > 0.0 ? rs->adc_bailout : 0.0;
    J->mweight = fmax(J->madc + 1e-10, 0.5 * (isfinite(rr.brightness) ? rr.brightness : 1.0));
}

/* Whether texture t, where an exact gather's ray hits it, can bring light
 * back without a light to reflect: its emission, or (where followed) a
 * mirror's reflection or a transmission (hit_light_at's cases). */
static int tex_dark(const link_job *J, emit_memo *memo, const scene_texture *t)
{
    const emit_memo_entry *m = memo_of(J, memo, t);
    return !m->emits && !(J->mirror && (m->mirrors || m->clear));
}

/* Whether no leaf texture (hit_leaf's choice where a leaf has none, a
 * mesh's texture_list entries too) emits, mirrors or lets light through
 * (tex_dark): then a hit's emission and its mirror and glass rays
 * (hit_light_at without the far field and direct light) add nothing. */
static int leaves_dark(const link_job *J)
{
    if (!J->sc) return 0;
    emit_memo memo = {0};
    if (!tex_dark(J, &memo, &J->sc->default_texture)) return 0;
    for (int i = 0, n = accel_leaf_count(J->a); i < n; i++) {
        const scene_texture *t;
        const scene_object *o = accel_leaf_at(J->a, i, &t);
        if (!o) continue;
        if (!tex_dark(J, &memo, t ? t : o->texture ? o->texture : &J->sc->default_texture)) return 0;
        if (o->kind == SHAPE_MESH && o->u.mesh.mesh && o->u.mesh.textures)
            for (int k = 0; k < o->u.mesh.mesh->ntextures; k++)
                if (o->u.mesh.textures[k] && !tex_dark(J, &memo, o->u.mesh.textures[k])) return 0;
    }
    return 1;
}

/* Whether every ray of J's exact gather that hits something brings
 * nothing back: no light to reflect there, no far-field sky, and no leaf
 * texture that emits, mirrors or lets light through (leaves_dark). A sky-lit scene
 * of diffuse surfaces under recursion_limit 1 is one (stackerday.pov):
 * what reaches a point is the sky its rays see, so an occlusion test
 * answers each ray. */
static int hits_dark(const link_job *J)
{
    if (!J->esky || !J->exact || J->nlights > 0 || J->far_bounce > 0.0f || !J->sc) return 0;
    return leaves_dark(J);
}

static void job_close(link_job *J)
{
    for (int t = 0; t < J->threads; t++) {
        if (J->buf) free(J->buf[t]);
        if (J->hp) free(J->hp[t]);
        if (J->cell) free(J->cell[t]);
        if (J->tcell) free(J->tcell[t]);
    }
    free(J->buf);
    free(J->hp);
    free(J->cell);
    free(J->tcell);
    free(J->order);
    free(J->su0);
    free(J->sv0);
    free(J->lights);
    accel_rtc_link_scene_free(J->lscene);
}

pt_status gi_links_build(const accel *a, void *rtc_scene, const gi_dev_particle *p, const void *const *pobj,
                         const unsigned char *pin, int n, int first, int nside, uint64_t seed, const gi_lookup *grid,
                         const gi_trilook *tl, double maxdist, int threads, int *links, unsigned char *anyhit,
                         gi_link_stats *st, volatile int *cancel, progress *prog,
                         const gi_sky *sky, float *esky, const scene *sc, gi_pigment_fn pig, double far_bounce,
                         float *reach, gi_link_conts *conts, const gi_hit_light *hl)
{
    if (threads <= 0) threads = pool_default_threads();
    link_job J = {.sky = sky, .esky = sky && sc ? esky : NULL, .sc = sc, .pig = pig, .hl = hl ? *hl : (gi_hit_light){0},
                  .far_bounce = isfinite(far_bounce) && far_bounce > 0.0 ? (float)far_bounce : 0.0f};
    J.p = p;
    J.pobj = pobj;
    J.pin = pobj ? pin : NULL;
    J.n = n;
    J.first = first > 0 && first <= n ? first : 0;
    /* points: sources after the particles, or a reach wanted for each
     * (the final gather's points, when there are no particles at all) */
    J.points = J.first > 0 || reach;
    J.reach = J.points ? reach : NULL;
    int k = nside * nside;
    J.per_job = k >= RAYS_PER_CALL ? 1 : RAYS_PER_CALL / k;
    J.seed = seed;
    J.grid = grid;
    J.tl = tl;
    J.maxdist = maxdist;
    J.links = links;
    J.anyhit = anyhit;
    atomic_init(&J.misses, 0);
    atomic_init(&J.unresolved, 0);
    atomic_init(&J.other, 0);
    atomic_init(&J.tri_ok, 0);
    atomic_init(&J.tri_fb, 0);
    pt_status rc = job_open(&J, a, rtc_scene, nside, threads, (size_t)J.per_job * (size_t)k, 1);
    /* the far field's direct light: only for the final gather's points,
     * whose links are traced again for every view; the particles' links
     * are geometry and outlive a change of the lights (relighting) */
    if (rc == PT_OK && J.esky && J.points) {
        rc = job_lights(&J, sc);
        job_mirror(&J, sc);
    }
    J.exact = J.esky && J.points && !(J.far_bounce > 0.0f);
    /* with no texture that emits, mirrors or lets light through, a point's
     * ray that ends on a particle takes that particle's light alone: its
     * hit's texture is not looked up (cornell.pov) */
    if (rc == PT_OK && J.esky && J.points && !J.exact) J.lone = leaves_dark(&J);
    /* continuations that end on particles, where the points follow mirrors */
    if (rc == PT_OK && conts && J.points && J.mirror && !J.exact && J.grid && J.links) {
        J.cont = calloc((size_t)threads, sizeof *J.cont);
        if (!J.cont) rc = PT_ERR_NOMEM;
    }
    if (rc == PT_OK && n > 0 && !pool_run_counted(threads, (n - J.first + J.per_job - 1) / J.per_job, job, &J, cancel, prog))
        rc = PT_CANCELLED;
    if (J.cont) {
        if (rc == PT_OK) rc = conts_gather(J.cont, threads, n - J.first, conts);
        for (int t = 0; t < threads; t++) gi_link_conts_free(&J.cont[t]);
        free(J.cont);
    }
    job_close(&J);
    if (st && rc == PT_OK) {
        st->rays += (long)(n - J.first) * J.k;
        st->misses += atomic_load(&J.misses);
        st->unresolved += atomic_load(&J.unresolved);
        st->other_object += atomic_load(&J.other);
        st->tri_answered += atomic_load(&J.tri_ok);
        st->tri_fallback += atomic_load(&J.tri_fb);
    }
    return rc;
}

/* ---- the gatherer: gi_links_build's exact gather at one point at a time */

struct gi_gatherer {
    link_job J;
    float want; /* J.esky points here: hit_light takes it as the flag that light is wanted */
};

gi_gatherer *gi_gatherer_new(const accel *a, void *rtc_scene, int nside, uint64_t seed,
                             const gi_sky *sky, const scene *sc, gi_pigment_fn pig)
{
    gi_gatherer *g = calloc(1, sizeof *g);
    if (!g) return NULL;
    link_job *J = &g->J;
    *J = (link_job){.sky = sky, .esky = &g->want, .sc = sc, .pig = pig, .seed = seed, .exact = 1};
    /* a buffer per thread, made by the thread on its first point */
    if (job_open(J, a, rtc_scene, nside, GI_MAX_THREADS, 0, 0) != PT_OK || job_lights(J, sc) != PT_OK) {
        gi_gatherer_free(g);
        return NULL;
    }
    job_mirror(J, sc);
    J->occlude = hits_dark(J);
    return g;
}

int gi_gatherer_dark(const gi_gatherer *g) { return g && g->J.occlude; }

int gi_gatherer_point(gi_gatherer *g, int thread, vec3 p, vec3 n, uint64_t stream, float e[3], float *reach)
{
    const link_job *J = &g->J;
    if ((unsigned)thread >= (unsigned)J->threads) return 0;
    struct RTCRayHit *rh = J->buf[thread];
    if (!rh) {
        size_t bytes = (size_t)J->k * sizeof *rh;
        rh = J->buf[thread] = aligned_alloc(64, (bytes + 63) / 64 * 64);
        if (!rh) return 0;
    }
    source_rays(J, p, n, stream, rh);
    float sky[3] = {0.0f, 0.0f, 0.0f};
    if (J->occlude && !reach) {
        /* a hit brings nothing (hits_dark): a ray that leaves the scene
         * takes the sky, found by an occlusion test (Embree stops at any
         * hit, a CSG at its first kept crossing: geom_csg_occludes) */
        struct RTCIntersectContext c;
        rtcInitIntersectContext(&c);
        c.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
        rtcOccluded1M(J->scene, &c, &rh[0].ray, (unsigned)J->k, sizeof *rh);
        for (int j = 0; j < J->k; j++)
            if (rh[j].ray.tfar >= 0.0f) ray_sky(J, &rh[j], sky); /* an occluded ray's tfar is -inf */
        for (int c3 = 0; c3 < 3; c3++) e[c3] = sky[c3] / (float)J->k;
        return 1;
    }
    trace_rays(J, rh, J->k);
    emit_memo memo = {0};
    for (int j = 0; j < J->k; j++) {
        if (ray_hit(&rh[j]))
            hit_light(J, &rh[j], 1, 1, &memo, sky);
        else
            ray_sky(J, &rh[j], sky);
    }
    for (int c = 0; c < 3; c++) e[c] = sky[c] / (float)J->k;
    if (reach) *reach = harmonic_reach(rh, J->k);
    return 1;
}

void gi_gatherer_set_light(gi_gatherer *g, const gi_hit_light *hl)
{
    if (g) g->J.hl = hl ? *hl : (gi_hit_light){0};
}

void gi_gatherer_free(gi_gatherer *g)
{
    if (!g) return;
    job_close(&g->J);
    free(g);
}
