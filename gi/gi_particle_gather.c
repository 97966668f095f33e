/* gi_particle_gather.c - the particle GI mode's final gather at the
 * camera's hits (gi_particle_view_gather).
 *
 * Beyond seed 000: the paper ends at the radiance particles, E/pi estimated
 * from the area particles within the list radius and interpolated over the
 * surfaces' tessellation (section 4.3.2). That estimate is as coarse as the
 * particles: where the light changes within a list radius (the sky's
 * occlusion under an eave, a thin post, the contact of an object with the
 * floor) it blurs or misses it, and where none of a hit's radiance
 * particles is visible from it there is no answer. Here every kept primary
 * hit (keep_hits) that shows diffuse light gathers as an area particle
 * does: side x side stratified cosine-weighted rays from the hit (the same
 * link rays, gi_links_build), each taking the outgoing radiance of the
 * area particle it ends on, the sky where it leaves the scene and the far
 * field where no particle answers, their mean being E/pi (the gathering
 * step, equation 5 of the paper, at the pixel). This is final gathering
 * (as pbrt's photon mapper and POV-Ray's radiosity sample rays do): one
 * bounce exact in position and visibility, the rest from the particles.
 *
 * To spend rays where the light changes, the gather points are every
 * stride-th pixel in x and y; a pixel between takes the bilinear mean of
 * those of its block's corners that lie on its object, face its way and
 * are at its depth (within DEPTH_TOL), and gathers itself when none does
 * (edges and small objects get their own gathers, as an irradiance cache
 * refines where its records do not reach).
 *
 * The links (targets and the sky's share) are kept, so a new lighting
 * (gi_particle_relight) costs one pass over them (gi_particle_view_regather). */
#include "gi_particle_internal.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "gi_cl_c.h"
#include "gi_links.h"
#include "timer.h"

#define DEPTH_TOL 0.05 /* relative depth a neighbour may differ by */
#define NORMAL_COS 0.9 /* and the cosine between the two normals */

/* The normal the gather at this kept hit uses: the smooth normal turned to
 * the side the camera sees (the hook's n has that side), unless it leans
 * away from the geometric normal of that side (then the geometric one). */
static vec3 view_normal(const view_rec *r)
{
    vec3 ng = r->side ? r->h.ng : v3_neg(r->h.ng);
    double l = v3_len(ng);
    if (!(l > 0.0)) return ng;
    ng = v3_scale(ng, 1.0 / l);
    vec3 ns = r->h.ns;
    double ls = v3_len(ns);
    if (!(ls > 0.0) || !isfinite(ls)) return ng;
    ns = v3_scale(ns, 1.0 / ls);
    if (v3_dot(ns, ng) < 0.0) ns = v3_neg(ns);
    return v3_dot(ns, ng) > 0.5 ? ns : ng;
}

/* A kept hit that takes diffuse light from the hook. */
static int gathers(const gi_particle *gp, const view_rec *r)
{
    if (r->kind != 2 || !r->h.obj) return 0;
    const scene_texture *t = r->h.texture ? r->h.texture : &gp->sc->default_texture;
    return t->finish.diffuse > 0.0;
}

/* May pixel b take pixel a's gather? */
static int compatible(const view_rec *a, const view_rec *b)
{
    if (a->h.obj != b->h.obj || a->side != b->side) return 0;
    if (!(fabs(a->h.t - b->h.t) <= DEPTH_TOL * b->h.t)) return 0;
    return v3_dot(view_normal(a), view_normal(b)) > NORMAL_COS;
}

void gi_particle_view_gather_free(gi_particle *gp)
{
    free(gp->vg_pt);
    free(gp->vg_key);
    gp->vg_pt = NULL;
    gp->vg_key = NULL;
    free(gp->vg_link);
    free(gp->vg_esky);
    free(gp->vg_val);
    free(gp->vg_pix);
    gp->vg_link = NULL;
    gp->vg_esky = gp->vg_val = NULL;
    gp->vg_pix = NULL;
    gp->vg_n = 0;
    gp->vg_w = gp->vg_h = 0;
}

/* The corners of pixel (x, y)'s block and their bilinear weights (fewer
 * on the last row and column). */
static int corners(int x, int y, int w, int h, int s, int cx[4], int cy[4], double cw[4])
{
    int x0 = x - x % s, y0 = y - y % s, x1 = x0 + s, y1 = y0 + s;
    double fx = (double)(x - x0) / s, fy = (double)(y - y0) / s;
    int n = 0;
    int xs[2] = {x0, x1}, ys[2] = {y0, y1};
    double wx[2] = {1.0 - fx, fx}, wy[2] = {1.0 - fy, fy};
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            if (xs[i] >= w || ys[j] >= h || !(wx[i] * wy[j] > 0.0)) continue;
            cx[n] = xs[i];
            cy[n] = ys[j];
            cw[n] = wx[i] * wy[j];
            n++;
        }
    return n;
}

/* ---- the gather points by position, for hits that are not kept (the
 * antialiasing's extra rays, a reflection of a seen surface): a point
 * answers within its radius, stride pixels' footprint at its depth. Cells
 * of the largest radius (the 90th percentile; larger radii are cut to it),
 * each point in its own cell, sorted by cell key; a query visits the 27
 * cells around it. */

static uint64_t cell_key(vec3 p, double c)
{
    int64_t ix = (int64_t)floor(p.x / c), iy = (int64_t)floor(p.y / c), iz = (int64_t)floor(p.z / c);
    return ((uint64_t)(ix & 0x1fffff) << 42) | ((uint64_t)(iy & 0x1fffff) << 21) | (uint64_t)(iz & 0x1fffff);
}

static int cmp_key(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* key in the high bits of vg_key, the point in the low 32: one sort */
static pt_status build_index(gi_particle *gp)
{
    int m = gp->vg_n;
    double *r = malloc((size_t)m * sizeof *r);
    gp->vg_key = malloc((size_t)m * sizeof *gp->vg_key);
    if (!r || !gp->vg_key) {
        free(r);
        return PT_ERR_NOMEM;
    }
    for (int k = 0; k < m; k++) r[k] = gp->vg_pt[k].r;
    qsort(r, (size_t)m, sizeof *r, cmp_double);
    double c = r[(size_t)(0.9 * (m - 1))];
    free(r);
    if (!(c > 0.0) || !isfinite(c)) c = 1.0;
    gp->vg_cell = c;
    /* keys of 63 bits: cell coordinates 21 bits each hashed into 31 bits
     * beside the 32-bit point (equal hashes of far cells only cost a
     * distance test) */
    for (int k = 0; k < m; k++) {
        if (gp->vg_pt[k].r > c) gp->vg_pt[k].r = (float)c;
        uint64_t h = cell_key(gp->vg_pt[k].p, c) * 0x9E3779B97F4A7C15ULL;
        gp->vg_key[k] = ((h >> 33) << 32) | (uint64_t)(uint32_t)k;
    }
    qsort(gp->vg_key, (size_t)m, sizeof *gp->vg_key, cmp_key);
    return PT_OK;
}

/* E/pi at a hit that is not kept, from the gather points around it on its
 * object and side that face its way: weights 1 - d/r. 0: none. */
static int nearby_value(const gi_particle *gp, const accel_hit *hit, vec3 n, rgb *out)
{
    if (!gp->vg_key || !hit->obj) return 0;
    int side = v3_dot(n, hit->ng) >= 0.0;
    vec3 ng = side ? hit->ng : v3_neg(hit->ng);
    double c = gp->vg_cell, s[3] = {0.0, 0.0, 0.0}, ws = 0.0;
    for (int dz = -1; dz <= 1; dz++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++) {
                vec3 q = v3(hit->p.x + dx * c, hit->p.y + dy * c, hit->p.z + dz * c);
                uint64_t hk = (cell_key(q, c) * 0x9E3779B97F4A7C15ULL) >> 33;
                /* the first entry of key hk */
                size_t lo = 0, hi = (size_t)gp->vg_n;
                while (lo < hi) {
                    size_t mid = (lo + hi) / 2;
                    if ((gp->vg_key[mid] >> 32) < hk) lo = mid + 1;
                    else hi = mid;
                }
                for (size_t e = lo; e < (size_t)gp->vg_n && (gp->vg_key[e] >> 32) == hk; e++) {
                    const vg_point *pt = &gp->vg_pt[(uint32_t)gp->vg_key[e]];
                    if (pt->obj != hit->obj || pt->side != side) continue;
                    vec3 dv = v3_sub(hit->p, pt->p);
                    double d = v3_len(dv);
                    if (!(d < pt->r) || fabs(v3_dot(dv, pt->n)) > 0.25 * pt->r) continue;
                    if (v3_dot(pt->n, ng) < NORMAL_COS * v3_len(ng)) continue;
                    double w = 1.0 - d / pt->r;
                    const float *v = &gp->vg_val[4 * (size_t)(uint32_t)gp->vg_key[e]];
                    for (int q3 = 0; q3 < 3; q3++) s[q3] += w * v[q3];
                    ws += w;
                }
            }
    if (!(ws > 0.0)) return 0;
    out->r = s[0] / ws;
    out->g = s[1] / ws;
    out->b = s[2] / ws;
    return 1;
}

pt_status gi_particle_view_gather(gi_particle *gp, diag *d)
{
    (void)d;
    gi_particle_view_gather_free(gp);
    int side = gp->set.view_gather_side, s = gp->set.view_gather_stride > 0 ? gp->set.view_gather_stride : 2;
    if (side <= 0 || !gp->vrec || gp->vw <= 0 || gp->vh <= 0 || !gp->lout || gp->ps.n <= 0) return PT_OK;
    int w = gp->vw, h = gp->vh, n = gp->ps.n;
    size_t npix = (size_t)w * (size_t)h;
    pt_status st = PT_OK;
    /* vg_pix: the gather point of a pixel, -1 none (it interpolates or
     * takes the old estimate) */
    gp->vg_pix = malloc(npix * sizeof *gp->vg_pix);
    if (!gp->vg_pix) return PT_ERR_NOMEM;
    int m = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            gp->vg_pix[i] = -1;
            if (x % s == 0 && y % s == 0 && gathers(gp, &gp->vrec[i])) gp->vg_pix[i] = m++;
        }
    /* pixels no corner answers gather themselves */
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            if (gp->vg_pix[i] >= 0 || !gathers(gp, &gp->vrec[i])) continue;
            int cx[4], cy[4];
            double cw[4];
            int nc = corners(x, y, w, h, s, cx, cy, cw), ok = 0;
            for (int k = 0; k < nc && !ok; k++) {
                size_t c = (size_t)cy[k] * w + cx[k];
                ok = gp->vg_pix[c] >= 0 && (cx[k] % s == 0 && cy[k] % s == 0) && compatible(&gp->vrec[c], &gp->vrec[i]);
            }
            if (!ok) gp->vg_pix[i] = m++;
        }
    if (m == 0) return PT_OK;
    /* the area particles, then the gather points (gi_links_build's sources
     * [n, n + m), its targets the area particles) */
    long N = (long)n + m;
    gi_dev_particle *cp = calloc((size_t)N, sizeof *cp);
    const void **cobj = NULL;
    unsigned char *cpin = NULL, *pin = NULL;
    const void **pobj = gi_particle_objects(gp, &gp->ps, &pin, &st);
    cobj = calloc(2 * (size_t)N, sizeof *cobj);
    cpin = calloc(2 * (size_t)N, 1);
    gp->vg_link = malloc((size_t)m * side * side * sizeof *gp->vg_link);
    gp->vg_esky = calloc((size_t)m * 4, sizeof *gp->vg_esky);
    gp->vg_val = calloc((size_t)m * 4, sizeof *gp->vg_val);
    gp->vg_pt = calloc((size_t)m, sizeof *gp->vg_pt);
    gi_lookup *grid = NULL;
    if (!cp || !pobj || !pin || !cobj || !cpin || !gp->vg_link || !gp->vg_esky || !gp->vg_val || !gp->vg_pt ||
        st != PT_OK) {
        st = PT_ERR_NOMEM;
        goto done;
    }
    memcpy(cp, gp->ps.p, (size_t)n * sizeof *cp);
    for (int t = 0; t < n; t++) {
        cobj[t] = pobj[t];
        cobj[N + t] = pobj[n + t];
        cpin[t] = pin[t];
        cpin[N + t] = pin[n + t];
    }
    for (size_t i = 0; i < npix; i++) {
        int k = gp->vg_pix[i];
        if (k < 0) continue;
        const view_rec *r = &gp->vrec[i];
        vec3 nv = view_normal(r);
        gi_dev_particle *q = &cp[n + k];
        q->p[0] = (float)r->h.p.x;
        q->p[1] = (float)r->h.p.y;
        q->p[2] = (float)r->h.p.z;
        q->n[0] = (float)nv.x;
        q->n[1] = (float)nv.y;
        q->n[2] = (float)nv.z;
        q->area = 0.0f;
        const scene_object *o = r->h.obj;
        /* its radius: stride pixels' footprint on the surface (the angle
         * between neighbouring camera rays, at its depth, over the cosine) */
        size_t x = i % (size_t)w, y = i / (size_t)w;
        const view_rec *nb = &gp->vrec[x + 1 < (size_t)w ? i + 1 : (y + 1 < (size_t)h ? i + (size_t)w : i)];
        double ang = nb != r && nb->kind ? v3_len(v3_sub(v3_norm(nb->dir), v3_norm(r->dir))) : 0.0;
        double cs = fabs(v3_dot(v3_norm(r->dir), nv));
        vg_point *vp = &gp->vg_pt[k];
        vp->p = r->h.p;
        vp->n = nv;
        vp->obj = o;
        vp->side = r->side;
        vp->r = (float)(s * r->h.t * ang / (cs > 0.25 ? cs : 0.25));
        cobj[n + k] = o;
        /* on the inside of a closed sphere or box (as gi_particle_objects
         * marks particles): its rays end inside it */
        if ((o->kind == SHAPE_SPHERE || o->kind == SHAPE_BOX) && !(o->flags & OBJ_INVERSE)) {
            vec3 p = r->h.p;
            double lift = 1e-5 * (1.0 + fmax(fabs(p.x), fmax(fabs(p.y), fabs(p.z))));
            cpin[n + k] = (unsigned char)gi_surface_inside_solid(o, v3_madd(p, nv, lift));
        }
    }
    double spacing = gp->ps.spacing > 0.0 ? gp->ps.spacing : 1.0;
    grid = gi_lookup_build(&gp->ps, 2.0 * spacing);
    if (!grid) {
        st = PT_ERR_NOMEM;
        goto done;
    }
    st = gi_lookup_set_objects(grid, (const void *const *)pobj);
    gi_link_stats ls = {0};
    if (st == PT_OK)
        st = gi_links_build(gp->a, gp->lscene, cp, cobj, cpin, (int)N, n, side, gp->set.seed ^ 0x7a9e7ULL, grid, NULL,
                            3.0 * spacing, gp->threads, gp->vg_link, NULL, &ls, gp->set.cancel, NULL, gp->sky,
                            gp->vg_esky, gp->sc, gp->set.pigment, gp->set.bounces >= 1 ? gp->set.brightness : 0.0);
    if (st == PT_OK) {
        gp->vg_n = m;
        gp->vg_k = side * side;
        gp->vg_w = w;
        gp->vg_h = h;
        gp->vg_s = s;
        gp->st.view_gathers = m;
        gp->st.view_gather_rays = ls.rays;
        gi_particle_view_regather(gp);
        st = build_index(gp);
    }
done:
    gi_lookup_free(grid);
    free(cp);
    free(cobj);
    free(cpin);
    free(pobj);
    free(pin);
    if (st != PT_OK) gi_particle_view_gather_free(gp);
    return st;
}

void gi_particle_view_regather(gi_particle *gp)
{
    if (gp->vg_n <= 0 || !gp->lout) return;
    int *idx = malloc((size_t)gp->vg_n * sizeof *idx);
    if (!idx) {
        gi_particle_view_gather_free(gp);
        return;
    }
    for (int i = 0; i < gp->vg_n; i++) idx[i] = i;
    /* the gathering kernel's C build (equation 5 at the pixels) */
    gi_c_gather(gp->threads, gp->vg_link, gp->vg_k, gp->lout, idx, gp->vg_n, gp->vg_esky, gp->vg_val);
    free(idx);
}

int gi_particle_view_value(const gi_particle *gp, const accel_hit *hit, const view_rec *r, vec3 n, rgb *out)
{
    if (gp->vg_n <= 0 || gp->vg_w != gp->vw || gp->vg_h != gp->vh) return 0;
    if (!r) return nearby_value(gp, hit, n, out);
    if ((v3_dot(n, r->h.ng) >= 0.0) != r->side) return 0; /* the other side (diffuse_back) */
    size_t i = (size_t)(r - gp->vrec);
    int x = (int)(i % (size_t)gp->vw), y = (int)(i / (size_t)gp->vw);
    int k = gp->vg_pix[i];
    if (k >= 0) {
        const float *v = &gp->vg_val[4 * (size_t)k];
        out->r = v[0];
        out->g = v[1];
        out->b = v[2];
        return 1;
    }
    int cx[4], cy[4];
    double cw[4], s[3] = {0.0, 0.0, 0.0}, ws = 0.0;
    int nc = corners(x, y, gp->vw, gp->vh, gp->vg_s, cx, cy, cw);
    for (int c = 0; c < nc; c++) {
        size_t j = (size_t)cy[c] * gp->vw + cx[c];
        int kc = gp->vg_pix[j];
        if (kc < 0 || !compatible(&gp->vrec[j], r)) continue;
        const float *v = &gp->vg_val[4 * (size_t)kc];
        for (int q = 0; q < 3; q++) s[q] += cw[c] * v[q];
        ws += cw[c];
    }
    if (!(ws > 0.0)) return nearby_value(gp, hit, n, out);
    out->r = s[0] / ws;
    out->g = s[1] / ws;
    out->b = s[2] / ws;
    return 1;
}
