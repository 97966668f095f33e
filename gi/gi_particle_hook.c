/* gi_particle_hook.c - the particle GI mode's hooks into the render: the
 * kept primary hits and the indirect-light hook (gi_particle_indirect). */
#include "gi_particle_internal.h"
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "camera.h"
#include "gi_cellvis.h"
#include "gi_cl.h"
#include "gi_cl_c.h"
#include "gi_links.h"
#include "gi_area_particles.h"
#include "gi_radiance.h"
#include "gi_surface.h"
#include "pool.h"
#include "rng.h"
#include "timer.h"

int gi_particle_primary_begin(void *ctx, const scene *sc, const accel *a, int w, int h, double tmin)
{
    const gi_particle *gp = ctx;
    /* the camera compared byte for byte with the pre-pass's copy: every
     * field camera_ray reads is held in the struct (the pointers it holds,
     * a camera normal and mesh_camera's meshes, are not used here) */
    return gp && sc && gp->vrec && gp->vw > 0 && gp->vw == w && gp->vh == h && a == gp->a && tmin == gp->veps &&
           !memcmp(&sc->camera, &gp->vcam, sizeof gp->vcam);
}

int gi_particle_primary_hit(void *ctx, int x, int y, vec3 *org, vec3 *dir, const accel_hit **hit)
{
    const gi_particle *gp = ctx;
    if ((unsigned)x >= (unsigned)gp->vw || (unsigned)y >= (unsigned)gp->vh) return 0;
    const view_rec *r = &gp->vrec[(size_t)y * (size_t)gp->vw + (size_t)x];
    if (!r->kind) return 0;
    *org = r->org;
    *dir = r->dir;
    *hit = r->kind == 2 ? &r->h : NULL;
    return 1;
}

/* The kept record whose hit this is (the render passes the pointer
 * gi_particle_primary_hit gave it on to the hook), or NULL. */
static const view_rec *kept_rec(const gi_particle *gp, const accel_hit *hit)
{
    if (!gp->vrec || gp->vw <= 0) return NULL;
    uintptr_t off = (uintptr_t)hit - (uintptr_t)gp->vrec;
    size_t n = (size_t)gp->vw * (size_t)gp->vh;
    if ((uintptr_t)hit < (uintptr_t)gp->vrec || off >= n * sizeof(view_rec) || off % sizeof(view_rec)) return NULL;
    return (const view_rec *)((const char *)gp->vrec + off);
}

/* Claim a state slot: returns 1 if the caller must compute it, 0 once it is
 * done (waiting while another thread computes). */
static int claim(atomic_uchar *s)
{
    for (;;) {
        unsigned char v = atomic_load_explicit(s, memory_order_acquire);
        if (v == 2) return 0;
        if (v == 0) {
            unsigned char expect = 0;
            if (atomic_compare_exchange_weak_explicit(s, &expect, 1, memory_order_acq_rel, memory_order_acquire))
                return 1;
            continue;
        }
        /* 1: someone else is on it */
        for (volatile int k = 0; k < 64; k++) {
        }
    }
}

/* A radiance particle whose estimation list is empty (no area particle
 * near it on its object and side: a small object among few particles)
 * takes the far field, the unoccluded sky about its normal (gi_sky.h;
 * black under a black sky). */
void gi_particle_rp_far_field(gi_particle *gp, long l)
{
    vec3 q, nq;
    gi_surface_rp(gp->surf, l, &q, &nq);
    float e[3];
    gi_sky_irradiance(gp->sky, nq, e);
    for (int c = 0; c < 3; c++) gp->rp_val[4 * l + c] = e[c];
}

static void late_rp(gi_particle *gp, long l, thread_count *tc)
{
    if (!claim(&gp->rp_state[l])) return;
    tc->late_rp++;
    int lo = gp->lists.off[l], hi = gp->lists.off[l + 1];
    for (int q = lo; q < hi; q++) {
        int m = gp->lists.idx[q];
        if (claim(&gp->e_state[m])) {
            /* the gathering kernel, C build, on this thread */
            gi_c_gather(1, gp->glink, gp->ng, gp->lout, &m, 1, gp->esky, gp->eind);
            atomic_store_explicit(&gp->e_state[m], 2, memory_order_release);
            tc->late_area++;
        }
    }
    int li = (int)l;
    float v[4];
    gi_c_estimate(1, gp->ps.p, gp->lists.off, gp->lists.idx, gp->eind, &li, 1, v);
    if (lo == hi) gi_particle_rp_far_field(gp, l);
    else
        for (int c = 0; c < 3; c++) gp->rp_val[4 * l + c] = v[c];
    atomic_store_explicit(&gp->rp_state[l], 2, memory_order_release);
}

/* Surfaces with area particles but no radiance particles (a grid that
 * failed: gi_surface.h): the estimation list is made at the hit (the same radius,
 * normal test and widening as gi_radiance), then the estimate of section
 * 4.3.2 over it, gathering its particles first where needed. */
/* Keeps the particles of the hit's own object (as gi_radiance's lists do;
 * these pieces have one side unless open, and the normal test separates
 * the sides of an open one only roughly). */
static long onthefly_own(const gi_particle *gp, const scene_object *obj, thread_count *tc, long m)
{
    if (m <= 0) return m;
    long w = 0;
    for (long q = 0; q < m; q++)
        if (gi_surface_object(gp->surf, gp->ps.patch[tc->buf[q]]) == obj) tc->buf[w++] = tc->buf[q];
    tc->len = w;
    return w;
}

static int onthefly(gi_particle *gp, const accel_hit *h, vec3 n, thread_count *tc, rgb *out)
{
    vec3 ng = v3_dot(n, h->ng) >= 0.0 ? h->ng : v3_neg(h->ng);
    double r = gp->st.radius;
    tc->len = 0;
    long m = gi_grid_radius(gp->rgrid, h->p, ng, r, gp->set.normal_cos, &tc->buf, &tc->len, &tc->cap);
    m = onthefly_own(gp, h->obj, tc, m);
    for (int widen = 2; m == 0 && widen <= 4; widen *= 2) {
        m = gi_grid_radius(gp->rgrid, h->p, ng, r * widen, gp->set.normal_cos, &tc->buf, &tc->len, &tc->cap);
        m = onthefly_own(gp, h->obj, tc, m);
    }
    if (m <= 0) return 0;
    double s[3] = {0.0, 0.0, 0.0}, a = 0.0;
    for (long q = 0; q < m; q++) {
        int k = tc->buf[q];
        if (claim(&gp->e_state[k])) {
            gi_c_gather(1, gp->glink, gp->ng, gp->lout, &k, 1, gp->esky, gp->eind);
            atomic_store_explicit(&gp->e_state[k], 2, memory_order_release);
            tc->late_area++;
        }
        double da = gp->ps.p[k].area;
        for (int c = 0; c < 3; c++) s[c] += gp->eind[4 * (size_t)k + c] * da;
        a += da;
    }
    if (!(a > 0.0)) return 0;
    out->r = s[0] / a;
    out->g = s[1] / a;
    out->b = s[2] / a;
    tc->onthefly++;
    return 1;
}


/* E/pi on the side of the hit that n faces: barycentric interpolation of
 * the radiance particles around it, or the estimate at the hit on surfaces
 * without radiance particles. 0 when that side has no particles. */
static int side_value(gi_particle *gp, const accel_hit *hit, vec3 n, thread_count *tc, rgb *out)
{
    long rp[3];
    double w[3];
    out->r = out->g = out->b = 0.0;
    if (gp->no_rp) return gi_surface_has_particles(gp->surf, hit) && onthefly(gp, hit, n, tc, out);
    const view_rec *kr = kept_rec(gp, hit);
    if (kr && !(kr->located && kr->side == (v3_dot(n, hit->ng) >= 0.0))) kr = NULL;
    if (kr) {
        /* the pre-pass located this very hit on this side (locate reads
         * only the hit and the side of n) */
        for (int k = 0; k < 3; k++) {
            rp[k] = kr->rp[k];
            w[k] = kr->w[k];
        }
        tc->kept++;
    } else if (!gi_surface_locate(gp->surf, hit, n, rp, w)) {
        return gi_surface_has_particles(gp->surf, hit) && onthefly(gp, hit, n, tc, out);
    }
    /* only radiance particles the hit sees (gi_visible): one under a box
     * standing on the floor must not lend its light to the floor outside.
     * A clear cell (cell_clear) sees all three from everywhere; the other
     * cells test them from the hit. */
    double wsum = 0.0;
    int verdict;
    if (kr && kr->verdict != GI_CELL_UNKNOWN)
        verdict = kr->verdict; /* decided in the pre-pass (gi_particle_kept_verdict) */
    else
        verdict = gi_particle_cell_verdict(gp, gi_cellvis_key(gp->cells, rp), rp, hit->obj, tc);
    if (verdict == GI_CELL_CLEAR) tc->clear++;
    vec3 ngv = v3_dot(n, hit->ng) >= 0.0 ? hit->ng : v3_neg(hit->ng);
    for (int k = 0; k < 3; k++) {
        if (!(w[k] > 0.0)) continue;
        if (verdict == GI_CELL_CLEAR) {
            wsum += w[k];
            continue;
        }
        vec3 q, nq;
        gi_surface_rp(gp->surf, rp[k], &q, &nq);
        tc->vis_rays++;
        if (!gi_visible(gp->a, gp->vis_eps, hit->p, ngv, q, nq, hit->obj)) {
            w[k] = 0.0;
            continue;
        }
        wsum += w[k];
    }
    /* None of the three is visible from the hit (a post's grid vertices at
     * its ends, buried in the base it stands in): the estimate at the hit
     * from the area particles around it on its own object, as for surfaces
     * without radiance particles. */
    if (!(wsum > 0.0)) return gi_surface_has_particles(gp->surf, hit) && onthefly(gp, hit, n, tc, out);
    for (int k = 0; k < 3; k++) {
        if (!(w[k] > 0.0)) continue;
        if (atomic_load_explicit(&gp->rp_state[rp[k]], memory_order_acquire) != 2) {
            tc->late++;
            late_rp(gp, rp[k], tc);
        }
        const float *v = &gp->rp_val[4 * rp[k]];
        out->r += w[k] / wsum * v[0];
        out->g += w[k] / wsum * v[1];
        out->b += w[k] / wsum * v[2];
    }
    return 1;
}

rgb gi_particle_indirect(void *ctx, const accel_hit *hit, vec3 n, int thread)
{
    gi_particle *gp = ctx;
    rgb out = {0.0, 0.0, 0.0};
    thread_count *tc = &gp->tc[(unsigned)thread < GI_MAX_THREADS ? thread : 0];
    tc->lookups++;
    if (!gp->lit) {
        tc->none++;
        return out;
    }
    /* Beyond the clip box an infinite plane has no particles. Under a sky
     * the far field below answers there; under a black sky (the light
     * comes from objects: an emissive dome, light_sources) the nearest
     * point of the plane's clipped part stands for it (gi_surface_locate
     * takes the triangle nearest to the hit). */
    int far = !gi_sky_black(gp->sky) && !gi_surface_in_clip(gp->surf, hit->p);
    if (gi_particle_view_value(gp, hit, kept_rec(gp, hit), n, &out)) {
        tc->gathered++;
    } else if (gi_particle_gather_here(gp, hit, n, thread, &out)) {
        tc->gathered++;
        tc->gathered_here++;
    } else if (far || !side_value(gp, hit, n, tc, &out)) {
        /* No particle answers here: a surface the geometry stage left out
         * (beyond the clip box, an object far from what the camera sees, a
         * shape without particles). The far field: what it would gather
         * from a sky nothing occludes, E/pi about its normal (gi_sky.h);
         * black under a black sky. */
        tc->none++;
        vec3 ngv = v3_dot(n, hit->ng) >= 0.0 ? hit->ng : v3_neg(hit->ng);
        float e[3];
        gi_sky_irradiance(gp->sky, ngv, e);
        out.r = e[0];
        out.g = e[1];
        out.b = e[2];
    }
    /* finish { diffuse A, B } (3.7's backside diffuse, shade_material.h:
     * kb/pi for light arriving from the other side): shade.c multiplies the
     * hook by diffuse, so the other side's E/pi enters scaled by B / A:
     * the final gather's value on that side where it has one (gathered
     * like the side seen, as POV-Ray gathers both), else the particles'
     * estimate there. */
    const scene_texture *tex = hit->texture ? hit->texture : &gp->sc->default_texture;
    const scene_finish *f = &tex->finish;
    if (f->diffuse_back != 0.0 && f->diffuse > 0.0) {
        rgb back;
        const vec3 nb = v3_neg(n);
        if (gi_particle_view_value(gp, hit, kept_rec(gp, hit), nb, &back) ||
            (gp->final_only ? gi_particle_gather_here(gp, hit, nb, thread, &back) : side_value(gp, hit, nb, tc, &back))) {
            double k = f->diffuse_back / f->diffuse;
            out.r += k * back.r;
            out.g += k * back.g;
            out.b += k * back.b;
        }
    }
    double b = gp->set.brightness;
    out.r *= b;
    out.g *= b;
    out.b *= b;
    if (!isfinite(out.r) || !isfinite(out.g) || !isfinite(out.b)) {
        tc->discarded++;
        out.r = out.g = out.b = 0.0;
    }
    return out;
}
