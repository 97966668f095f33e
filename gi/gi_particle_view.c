/* gi_particle_view.c - the particle GI mode's view pre-pass
 * (gi_particle_prepare_view). */
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

#define VIEW_REC_MAX_BYTES ((size_t)256 << 20) /* keep_hits: at most this much of view_rec */

/* The pre-pass (gi_particle_prepare_view) in two steps. Step 1 traces the
 * pixels of a coarse grid (every stride-th pixel in x and y, and the last
 * column and row) as the Whitted pass will: primary, reflected and
 * transmitted rays, marking the radiance particles around every diffuse
 * hit. Step 2 visits the pixels in between: when the coarse pixels around
 * one (2 on a coarse row or column, else the 4 corners of its block) all
 * hit the same planar piece (one mesh triangle, triangle, box face, plane
 * or disc: a convex flat piece, and the object seen directly, no reflected
 * or transmitted rays from it), the pixel's ray meets that piece too (the
 * block's pixels lie inside the corners' convex hull, and so does their hit
 * on a convex piece), so its hit is the ray's intersection with the
 * piece's plane and no ray is traced (nor located, when they all lie in
 * one cell of the piece); when they all left the scene (the background),
 * neither is it; else the pixel is traced as in step 1. What
 * this misses: something smaller than the block standing in front of the
 * piece, or in the background, between the coarse pixels, or a hole cut
 * into the piece by CSG there; the radiance particles of those hits are
 * estimated late, in the hook (stats late_radiance). */
typedef struct {
    const scene_object *obj; /* NULL: no plane to reuse (a miss, a curved object, secondary rays) */
    int miss;                /* the ray left the scene */
    unsigned prim;
    int diffuse;             /* the piece has diffuse > 0 (its hits are marked) */
    int located;             /* cell holds the radiance particles marked for this hit */
    int whole;               /* located on a mesh triangle of one cell (gi_surface_one_cell) */
    long cell[3];
    vec3 p, ng, n;           /* the hit, its geometric normal, the viewer-side normal mark_hit took */
} coarse_hit;

typedef struct {
    gi_particle *gp;
    const scene_camera *cam;
    int w, h, max_level;
    int stride;     /* every stride-th pixel in x and y, and the last ones */
    int ncx, ncy;   /* coarse grid */
    coarse_hit *ch; /* ncx x ncy, NULL: step 2 traces every pixel */
    double eps;
    view_rec *rec;  /* keep_hits: w x h records, NULL: none kept */
    atomic_long rays, planar, missed, kept;
} view_job;

/* Marks the 3 radiance particles around the hit; returns 1 and them in
 * rp (their weights in w), or 0 when the hit has none. */
static int mark_hit(gi_particle *gp, const accel_hit *h, vec3 n, long rp[3], double w[3])
{
    if (gp->no_rp || !gi_surface_locate(gp->surf, h, n, rp, w)) return 0;
    for (int k = 0; k < 3; k++) atomic_store_explicit(&gp->mark[rp[k]], 1, memory_order_relaxed);
    return 1;
}

/* Objects whose surface pieces (hit->prim) are flat and convex. */
static int flat_pieces(const scene_object *o)
{
    switch (o->kind) {
    case SHAPE_MESH:
    case SHAPE_TRIANGLE:
    case SHAPE_SMOOTH_TRIANGLE:
    case SHAPE_BOX:
    case SHAPE_PLANE:
        return 1;
    case SHAPE_DISC:
        return !(o->u.disc.hole_radius > 0.0); /* an annulus is not convex */
    default:
        return 0;
    }
}

/* The rays the Whitted pass will trace (shade.c): primary, then reflected
 * and transmitted ones; shadow rays are not needed. Marks the radiance
 * particles around every diffuse hit. rec (may be NULL): the first hit, when
 * it is on a flat piece and spawns no further rays. Returns the rays
 * traced. */
static long prepass_ray(gi_particle *gp, vec3 org, vec3 dir, int level, int max_level, double eps, coarse_hit *rec,
                        view_rec *vr, view_memo *m)
{
    accel_hit h;
    if (rec) {
        rec->obj = NULL;
        rec->miss = 0;
    }
    if (vr) {
        vr->kind = 0;
        vr->located = 0;
    }
    if (!accel_intersect(gp->a, org, dir, eps, INFINITY, &h)) {
        if (rec) rec->miss = 1;
        if (vr) {
            vr->org = org;
            vr->dir = dir;
            vr->kind = 1;
        }
        return 1;
    }
    long rays = 1;
    const scene_texture *tex = h.texture ? h.texture : &gp->sc->default_texture;
    const scene_finish *f = &tex->finish;
    vec3 n = h.ns, ng = h.ng;
    int entering = v3_dot(dir, ng) < 0.0;
    if (v3_dot(dir, n) > 0.0) n = v3_neg(n);
    if (!entering) ng = v3_neg(ng);
    long cell[3];
    double cw[3];
    int located = f->diffuse > 0.0 && mark_hit(gp, &h, n, cell, cw);
    if (vr && !(h.flags & OBJ_NO_IMAGE)) {
        /* the render's camera ray would stop here too (it steps past
         * no_image surfaces only) */
        int verdict = located && gp->cells ? gi_particle_kept_verdict(gp, cell, h.obj, m, vr) : GI_CELL_UNKNOWN;
        vr->h = h;
        vr->org = org;
        vr->dir = dir;
        vr->kind = 2;
        vr->located = (unsigned char)located;
        vr->side = v3_dot(n, h.ng) >= 0.0;
        vr->verdict = (unsigned char)verdict;
        for (int k = 0; k < 3; k++) {
            vr->rp[k] = located ? cell[k] : -1;
            vr->w[k] = located ? cw[k] : 0.0;
        }
    }
    /* any channel > 0 (fmax's answer, without its libm calls: a NaN
     * channel counts as not > 0 either way) */
    int refl = f->reflection_max.r > 0.0 || f->reflection_max.g > 0.0 || f->reflection_max.b > 0.0 ||
               f->reflection_min.r > 0.0 || f->reflection_min.g > 0.0 || f->reflection_min.b > 0.0;
    const colour5 *pc = &tex->pigment.colour;
    int trans = pc->f > 0.0 || pc->t > 0.0;
    if (rec && h.obj && flat_pieces(h.obj) && ((!refl && !trans) || level >= max_level)) {
        rec->obj = h.obj;
        rec->prim = h.prim;
        rec->diffuse = f->diffuse > 0.0;
        rec->located = located;
        rec->whole = located && gi_surface_one_cell(gp->surf, &h);
        for (int k = 0; k < 3; k++) rec->cell[k] = located ? cell[k] : -1;
        rec->p = h.p;
        rec->ng = h.ng;
        rec->n = n;
    }
    if (level >= max_level) return rays;
    double cos_i = -v3_dot(dir, n);
    vec3 p = v3_madd(h.p, ng, eps);
    if (refl) rays += prepass_ray(gp, p, v3_madd(dir, n, 2.0 * cos_i), level + 1, max_level, eps, NULL, NULL, NULL);
    if (trans) {
        const scene_interior *in = h.obj->interior;
        double rel = 1.0;
        if (in && in->ior > 0.0) rel = entering ? in->ior : 1.0 / in->ior;
        vec3 td = dir;
        vec3 q = v3_madd(h.p, ng, -eps);
        if (fabs(rel - 1.0) > 1e-9) {
            double eta = 1.0 / rel, k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
            if (k < 0.0)
                return rays + prepass_ray(gp, p, v3_madd(dir, n, 2.0 * cos_i), level + 1, max_level, eps, NULL, NULL, NULL);
            td = v3_norm(v3_add(v3_scale(dir, eta), v3_scale(n, eta * cos_i - sqrt(k))));
        }
        rays += prepass_ray(gp, q, td, level + 1, max_level, eps, NULL, NULL, NULL);
    }
    return rays;
}

/* Coarse grid coordinate i along an axis of n pixels: stride * i, the last
 * one n - 1. */
static int coarse_at(int i, int stride, int n) { return i * stride < n - 1 ? i * stride : n - 1; }
static int coarse_count(int stride, int n) { return n > 0 ? (n - 1 + stride - 1) / stride + 1 : 0; }

static void coarse_row(void *ctx, int j, int thread)
{
    view_job *J = ctx;
    view_memo m = gi_particle_row_memo(J->gp, J->rec, thread);
    long rays = 0, kept = 0;
    int y = coarse_at(j, J->stride, J->h);
    for (int i = 0; i < J->ncx; i++) {
        int x = coarse_at(i, J->stride, J->w);
        vec3 org, dir;
        view_rec *vr = J->rec ? &J->rec[(size_t)y * J->w + x] : NULL;
        int cam = camera_ray(J->cam, x + 0.5, y + 0.5, J->w, J->h, 0.0, 0.0, &org, &dir);
        if (!cam) scene_camera_ray(J->cam, x + 0.5, y + 0.5, J->w, J->h, &org, &dir);
        rays += prepass_ray(J->gp, org, dir, 1, J->max_level, J->eps, J->ch ? &J->ch[(size_t)j * J->ncx + i] : NULL,
                            cam ? vr : NULL, &m);
        if (vr && !cam) vr->kind = 0; /* the render shows no ray there */
        kept += vr && vr->kind;
    }
    gi_particle_batch_test(J->gp, m.b, m.tc);
    atomic_fetch_add(&J->rays, rays);
    atomic_fetch_add(&J->kept, kept);
}

/* Whether world point p lies in triangle `prim` of mesh object o (its
 * barycentrics in object space, where the mesh is stored; affine maps keep
 * them). */
static int in_mesh_triangle(const scene_object *o, unsigned prim, vec3 p)
{
    const scene_mesh *m = o->u.mesh.mesh;
    if (!m || prim >= (unsigned)m->ntris) return 0;
    const int *t = m->tris[prim];
    if (t[0] < 0 || t[1] < 0 || t[2] < 0 || t[0] >= m->nverts || t[1] >= m->nverts || t[2] >= m->nverts) return 0;
    const float *a = m->verts[t[0]], *b = m->verts[t[1]], *c = m->verts[t[2]];
    vec3 q = xform_inv_point(&o->transform, p);
    vec3 v0 = v3(a[0], a[1], a[2]);
    vec3 e1 = v3_sub(v3(b[0], b[1], b[2]), v0), e2 = v3_sub(v3(c[0], c[1], c[2]), v0), d = v3_sub(q, v0);
    double d00 = v3_dot(e1, e1), d01 = v3_dot(e1, e2), d11 = v3_dot(e2, e2);
    double d20 = v3_dot(d, e1), d21 = v3_dot(d, e2), den = d00 * d11 - d01 * d01;
    if (!(den > 0.0)) return 0;
    double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
    return v >= 0.0 && w >= 0.0 && v + w <= 1.0;
}

/* The hit of the ray (org, dir) on the flat pieces of the coarse hits
 * c[0..nc): NULL unless they all lie on one object, seen from the same
 * side; then, on one piece (its convexity puts the ray's hit on it), that
 * piece, and on several pieces of a mesh, the nearest one whose triangle
 * holds the ray's point on its plane. *t: the ray parameter. */
static const coarse_hit *piece_hit(const coarse_hit *const *c, int nc, vec3 org, vec3 dir, double *t)
{
    int one = 1;
    for (int k = 0; k < nc; k++) {
        if (!c[k]->obj || c[k]->obj != c[0]->obj || !(v3_dot(c[k]->n, c[0]->n) > 0.0)) return NULL;
        one &= c[k]->prim == c[0]->prim;
    }
    if (!one && c[0]->obj->kind != SHAPE_MESH) return NULL;
    const coarse_hit *best = NULL;
    double bt = INFINITY;
    for (int k = 0; k < nc; k++) {
        int seen = 0;
        for (int q = 0; q < k && !seen; q++) seen = c[q]->prim == c[k]->prim;
        if (seen) continue;
        double den = v3_dot(dir, c[k]->ng);
        double tk = fabs(den) > 1e-12 ? v3_dot(v3_sub(c[k]->p, org), c[k]->ng) / den : -1.0;
        if (!(tk > 0.0) || !isfinite(tk) || !(tk < bt)) continue;
        if (!one && !in_mesh_triangle(c[k]->obj, c[k]->prim, v3_madd(org, dir, tk))) continue;
        best = c[k];
        bt = tk;
    }
    *t = bt;
    return best;
}

static void fill_row(void *ctx, int y, int thread)
{
    view_job *J = ctx;
    gi_particle *gp = J->gp;
    view_memo m = gi_particle_row_memo(gp, J->rec, thread);
    long rays = 0, planar = 0, missed = 0, kept = 0;
    int s = J->stride, j = y == J->h - 1 ? J->ncy - 1 : y / s, on_row = y % s == 0 || y == J->h - 1;
    int j1 = j + 1 < J->ncy ? j + 1 : j;
    for (int x = 0; x < J->w; x++) {
        int i = x == J->w - 1 ? J->ncx - 1 : x / s, on_col = x % s == 0 || x == J->w - 1;
        if (on_row && on_col) continue; /* a coarse pixel */
        view_rec *vr = J->rec ? &J->rec[(size_t)y * J->w + x] : NULL;
        if (vr) vr->kind = 0; /* unless traced below */
        int i1 = i + 1 < J->ncx ? i + 1 : i;
        const coarse_hit *c[4];
        int nc = 0;
        if (on_row) {
            c[nc++] = &J->ch[(size_t)j * J->ncx + i];
            c[nc++] = &J->ch[(size_t)j * J->ncx + i1];
        } else if (on_col) {
            c[nc++] = &J->ch[(size_t)j * J->ncx + i];
            c[nc++] = &J->ch[(size_t)j1 * J->ncx + i];
        } else {
            c[nc++] = &J->ch[(size_t)j * J->ncx + i];
            c[nc++] = &J->ch[(size_t)j * J->ncx + i1];
            c[nc++] = &J->ch[(size_t)j1 * J->ncx + i];
            c[nc++] = &J->ch[(size_t)j1 * J->ncx + i1];
        }
        int all_miss = 1;
        for (int k = 0; k < nc && all_miss; k++) all_miss = c[k]->miss;
        if (all_miss) {
            missed++;
            continue;
        }
        /* all in one cell of one piece: so is the pixel (a cell is a convex
         * part of the piece), whose radiance particles are marked already */
        int one_cell = c[0]->obj && c[0]->located;
        for (int k = 1; k < nc && one_cell; k++)
            one_cell = c[k]->obj == c[0]->obj && c[k]->prim == c[0]->prim && c[k]->located &&
                       c[k]->cell[0] == c[0]->cell[0] && c[k]->cell[1] == c[0]->cell[1] &&
                       c[k]->cell[2] == c[0]->cell[2];
        if (one_cell) {
            planar++;
            continue;
        }
        vec3 org, dir;
        int cam = camera_ray(J->cam, x + 0.5, y + 0.5, J->w, J->h, 0.0, 0.0, &org, &dir);
        if (!cam) scene_camera_ray(J->cam, x + 0.5, y + 0.5, J->w, J->h, &org, &dir);
        if (!cam) vr = NULL; /* the render shows no ray there: nothing kept */
        double t;
        const coarse_hit *b = piece_hit(c, nc, org, dir, &t);
        if (b) {
            planar++;
            /* on a triangle of one cell, seen from b's side (the hit takes
             * b's ng and n): locate would give b's 3, marked already */
            if (b->diffuse && !(b->located && b->whole)) {
                accel_hit hh = {.t = t, .p = v3_madd(org, dir, t), .ng = b->ng, .ns = b->ng, .obj = b->obj,
                                .prim = b->prim};
                long rp[3];
                double w[3];
                mark_hit(gp, &hh, b->n, rp, w);
            }
            continue;
        }
        rays += prepass_ray(gp, org, dir, 1, J->max_level, J->eps, NULL, vr, &m);
        kept += vr && vr->kind;
    }
    gi_particle_batch_test(gp, m.b, m.tc);
    atomic_fetch_add(&J->rays, rays);
    atomic_fetch_add(&J->kept, kept);
    atomic_fetch_add(&J->planar, planar);
    atomic_fetch_add(&J->missed, missed);
}

/* The pre-pass's rows go to the threads in bands of VIEW_BAND rows, top
 * down: a cell's next row is mostly the same thread's (cell_batch). */
#define VIEW_BAND 8
static void coarse_band(void *ctx, int b, int thread)
{
    const view_job *J = ctx;
    for (int j = b * VIEW_BAND; j < J->ncy && j < (b + 1) * VIEW_BAND; j++) coarse_row(ctx, j, thread);
}

static void fill_band(void *ctx, int b, int thread)
{
    const view_job *J = ctx;
    for (int y = b * VIEW_BAND; y < J->h && y < (b + 1) * VIEW_BAND; y++) fill_row(ctx, y, thread);
}

pt_status gi_particle_prepare_view(gi_particle *gp, const scene_camera *c, int w, int h, diag *d)
{
    double t0 = timer_now();
    gi_particle_stats *S = &gp->st;
    pt_status st = PT_OK;
    if (!gp->lit) {
        st = gi_particle_light(gp, d);
        if (st != PT_OK || !gp->lit) return st; /* !lit: cancelled (gi_particle_set_cancel) */
    }
    progress_stage(gp->set.progress, "gi view: pre-pass", 0);
    view_job J;
    J.gp = gp;
    J.cam = c;
    J.w = w;
    J.h = h;
    J.max_level = gp->set.max_trace_level > 0 ? gp->set.max_trace_level : gp->sc->global.max_trace_level;
    if (J.max_level < 1) J.max_level = 1;
    /* the render's tmin for camera rays (shade.c's scene_eps), so that its
     * rays are these (gi_particle_primary_begin compares the two) */
    J.eps = accel_surface_eps(gp->a);
    double c0 = timer_cpu_now();
    J.ch = NULL;
    J.rec = NULL;
    atomic_init(&J.rays, 0);
    atomic_init(&J.planar, 0);
    atomic_init(&J.missed, 0);
    atomic_init(&J.kept, 0);
    gp->vw = gp->vh = 0; /* no kept hits while the pre-pass runs, nor after it fails */
    if (gp->set.keep_hits && w > 0 && h > 0 && (size_t)w * (size_t)h <= VIEW_REC_MAX_BYTES / sizeof(view_rec)) {
        size_t need = (size_t)w * (size_t)h;
        if (gp->vrec_cap < need) {
            free(gp->vrec);
            /* zero: no record holds a verdict yet (gi_particle_kept_verdict) */
            gp->vrec = calloc(need, sizeof *gp->vrec);
            gp->vrec_cap = gp->vrec ? need : 0;
        }
        J.rec = gp->vrec;
    }
    /* kept hits: every pixel traced (unless told otherwise); none (too
     * large, no memory): the coarse pre-pass */
    J.stride = gp->set.prepass_stride > 0 ? gp->set.prepass_stride : (J.rec ? 1 : 2);
    J.ncx = coarse_count(J.stride, w);
    J.ncy = coarse_count(J.stride, h);
    if (w > 0 && h > 0) {
        /* step 1, then step 2; every pixel traced (step 1 alone, without
         * records) at stride 1 or when the grid's memory is not there */
        J.ch = J.stride > 1 ? malloc((size_t)J.ncx * (size_t)J.ncy * sizeof *J.ch) : NULL;
        if (!J.ch) {
            J.stride = 1;
            J.ncx = w;
            J.ncy = h;
        }
        /* the progress counts the coarse bands; the fill between them is short */
        pool_run_counted(gp->threads, (J.ncy + VIEW_BAND - 1) / VIEW_BAND, coarse_band, &J, NULL, gp->set.progress);
        if (J.ch) pool_run(gp->threads, (h + VIEW_BAND - 1) / VIEW_BAND, fill_band, &J);
        free(J.ch);
    }
    S->prepass_rays = atomic_load(&J.rays);
    S->prepass_planar = atomic_load(&J.planar);
    S->prepass_missed = atomic_load(&J.missed);
    S->prepass_kept = atomic_load(&J.kept);
    S->bytes_view = gp->vrec_cap * sizeof(view_rec);
    if (J.rec) {
        gp->vw = w;
        gp->vh = h;
        gp->veps = J.eps;
        memcpy(&gp->vcam, c, sizeof gp->vcam); /* bytes, padding too: primary_begin compares them */
    }
    S->t_prepass = timer_now() - t0;
    S->c_prepass = timer_cpu_now() - c0;
    if (J.rec && gp->set.view_gather_side > 0) {
        progress_stage(gp->set.progress, "gi view: final gather", 0);
        double tv = timer_now();
        st = gi_particle_view_gather(gp, d);
        S->t_view_gather = timer_now() - tv;
        if (st != PT_OK) return st;
    } else {
        gi_particle_view_gather_free(gp);
    }

    progress_stage(gp->set.progress, "gi view: gather", 0);
    /* found radiance particles (not yet estimated) and the area particles
     * their lists need (not yet gathered on the device) */
    double tg = timer_now();
    long nrp = gp->lists.nrp;
    int *found = malloc((size_t)(nrp > 0 ? nrp : 1) * sizeof *found);
    int *used = malloc((size_t)(gp->ps.n > 0 ? gp->ps.n : 1) * sizeof *used);
    unsigned char *umark = calloc((size_t)(gp->ps.n > 0 ? gp->ps.n : 1), 1);
    float *vout = NULL;
    if (!found || !used || !umark) {
        st = PT_ERR_NOMEM;
        goto done;
    }
    int nfound = 0, nused = 0;
    for (long l = 0; l < nrp; l++) {
        if (!atomic_load_explicit(&gp->mark[l], memory_order_relaxed)) continue;
        atomic_store_explicit(&gp->mark[l], 0, memory_order_relaxed);
        if (atomic_load(&gp->rp_state[l]) == 2) continue;
        found[nfound++] = (int)l;
        for (int q = gp->lists.off[l]; q < gp->lists.off[l + 1]; q++) {
            int m = gp->lists.idx[q];
            if (!gp->dev_gathered[m]) umark[m] = 1;
        }
    }
    for (int i = 0; i < gp->ps.n; i++)
        if (umark[i]) used[nused++] = i;
    S->found = nfound;
    S->used = nused;
    st = gi_dev_gather(gp->dev, used, nused, gp->eind, d);
    if (st != PT_OK) goto done;
    for (int t = 0; t < nused; t++) {
        gp->dev_gathered[used[t]] = 1;
        atomic_store(&gp->e_state[used[t]], 2);
    }
    S->t_gather = timer_now() - tg;

    progress_stage(gp->set.progress, "gi view: estimate", 0);
    double te = timer_now();
    vout = malloc((size_t)(nfound > 0 ? nfound : 1) * 4 * sizeof *vout);
    if (!vout) {
        st = PT_ERR_NOMEM;
        goto done;
    }
    st = gi_dev_estimate(gp->dev, found, nfound, vout, d);
    if (st != PT_OK) goto done;
    for (int t = 0; t < nfound; t++) {
        long l = found[t];
        int empty = gp->lists.off[l] == gp->lists.off[l + 1];
        if (empty) gi_particle_rp_far_field(gp, l);
        else
            for (int c = 0; c < 3; c++) gp->rp_val[4 * l + c] = vout[4 * t + c];
        gp->rp_val[4 * l + 3] = 0.0f;
        atomic_store(&gp->rp_state[l], 2);
    }
    S->t_estimate = timer_now() - te;
done:
    free(found);
    free(used);
    free(umark);
    free(vout);
    S->t_view = timer_now() - t0;
    return st;
}

