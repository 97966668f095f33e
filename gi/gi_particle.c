/* gi_particle.c - the particle GI mode (see gi_particle.h): settings, the
 * geometry stage, stats and the debug access; the other stages are in
 * gi_particle_light.c, gi_particle_view.c, gi_particle_cells.c and
 * gi_particle_hook.c (gi_particle_internal.h). */
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

/* ------------------------------------------------------------------ settings */

void gi_particle_default_settings(gi_particle_settings *s)
{
    *s = (gi_particle_settings){.count = 50000, .scatter_side = 4, .gather_side = 16, .bounces = 8, .tess_factor = 3.0,
                                .radius_factor = 3.0, .normal_cos = 0.9, .brightness = 1.0};
}

void gi_particle_settings_from_scene(gi_particle_settings *s, const scene *sc)
{
    gi_particle_default_settings(s);
    const scene_radiosity *r = &sc->global.radiosity;
    if (!r->enabled) return;
    long count = GI_PARTICLES_PER_COUNT * (r->count > 0 ? r->count : 35);
    s->count = count < GI_PARTICLES_MIN ? GI_PARTICLES_MIN : (count > GI_PARTICLES_MAX ? GI_PARTICLES_MAX : count);
    s->bounces = r->recursion_limit - 1 > 0 ? r->recursion_limit - 1 : 0;
    if (r->error_bound > 0.0) {
        double f = 3.0 * r->error_bound / 1.8;
        s->radius_factor = f < 2.0 ? 2.0 : (f > 5.0 ? 5.0 : f);
    }
    if (r->brightness > 0.0) s->brightness = r->brightness;
    /* the final gather's rays: about the scene's count, as POV-Ray's
     * radiosity samples take count rays each; 1.7 times as many with
     * further bounces, where a ray costs a particle lookup, not a shadow
     * ray a light, and ends on a particle whose own estimate is noisy
     * (docs/gi.md: cornell.pov's figures). Without them, nearest_count / 2.5
     * times as many, within 1 and 2: POV-Ray blends up to nearest_count
     * records (default 5) at a point, each of count rays, where a pixel
     * here blends its gather with its filtered neighbours' (docs/gi.md:
     * patio-radio and baking_demo) */
    double nc = r->nearest_count > 0 ? r->nearest_count / 2.5 : 2.0;
    double want = (double)(r->count > 0 ? r->count : 35) * (s->bounces >= 1 ? 1.7 : (nc < 1.0 ? 1.0 : (nc > 2.0 ? 2.0 : nc)));
    int side = (int)lround(sqrt(want));
    s->view_gather_side = side < 6 ? 6 : (side > 20 ? 20 : side);
    /* POV-Ray's error_bound sets how densely its cache samples where the
     * light changes. Below 0.1 (stackernight.pov's 0.01: blocks lit by the
     * glowing letters on their faces; stackerday.pov's 0.05) a record is
     * reused only within a twentieth of its reach or less, so nearly every
     * hit is a record of its own with count rays: every pixel gathers, no
     * filter blends neighbours (it blurs the contact light and the small
     * blocks' faces such a scene asks for), and a hit that gathers itself
     * takes more of the kept pixels' rays: POV-Ray gives such a record
     * count rays, and 0.6 of the side keeps most of what the whole side
     * gains there at half its time (docs/gi.md: stackerday, stackernight) */
    const int dense = r->error_bound > 0.0 && r->error_bound < 0.1;
    /* ... and there every pixel keeps its own gather's error, as grain
     * that no filter blends away, where POV-Ray's records, each of count
     * rays from one cosine-weighted sub-random sequence (radiosity.cpp,
     * SampleDirectionGenerator: a low-discrepancy pool per depth, the frame
     * fixed by the normal), err smoothly. The side grows 1.8 times (3.2
     * times the rays, at most GI_DENSE_SIDE_MAX): the accuracy of POV-Ray's
     * default render on the distribution's two scenes that ask for it, a
     * calibration, not a derivation (docs/gi.md: stackerday, stackernight) */
    if (dense) s->view_gather_side = (int)lround(fmin(1.8 * s->view_gather_side, (double)GI_DENSE_SIDE_MAX));
    /* Under `normal on` POV-Ray files a record under the perturbed normal
     * it gathered about and reuses it only where the hit's perturbed
     * normal agrees (radiosity.cpp, ComputeAmbient's effectiveNormal; rule
     * 5 of core/radrules.h), so on a bumped surface (balcony.pov's quilted
     * cloth, granite floor and stone) its cache holds a record of count
     * rays at nearly every pixel. Here then every pixel gathers too, and
     * the side grows 1.45 times (2.1 times the rays): what a gather blended
     * from fewer neighbours needs to reach the accuracy of POV-Ray's
     * default render on balcony.pov, a calibration like the dense rule's
     * (docs/gi.md: balcony) */
    const int bumped = r->normal && !dense;
    if (bumped) s->view_gather_side = (int)lround(fmin(GI_NORMAL_ON_SIDE_GAIN * s->view_gather_side, (double)GI_DENSE_SIDE_MAX));
    s->view_gather_stride = dense || bumped ? 1 : 2;
    s->view_gather_filter = dense ? -1.0 : 1.0;
    s->here_side_frac = dense ? 0.6 : 1.0 / 3.0;
    /* what POV-Ray's cache reuses where the antialiasing and secondary
     * rays hit (gi_particle_gather.c, reusable) */
    s->reuse_error = r->error_bound > 0.0 ? r->error_bound : 1.8;
    s->reuse_min = r->minimum_reuse;
    s->reuse_max = r->maximum_reuse;
    /* the area particles' own gathers then feed only further bounces and
     * the hits the final gather does not answer: a quarter of the rays,
     * a sixteenth without further bounces */
    s->gather_side = s->bounces >= 1 ? 8 : 4;
}

void gi_particle_scale_quality(gi_particle_settings *s, double q)
{
    if (!(q > 0.0) || !isfinite(q)) return;
    double c = (double)s->count * q;
    s->count = c < 500.0 ? 500 : (c > 4e6 ? 4000000 : (long)c);
    /* and the final gather's rays */
    if (s->view_gather_side > 0) {
        double side = s->view_gather_side * sqrt(q);
        s->view_gather_side = side < 4.0 ? 4 : (side > 48.0 ? 48 : (int)lround(side));
    }
}

/* ------------------------------------------------------------------ build */

void *gi_particle_calloc(size_t n, size_t size, pt_status *st)
{
    void *p = calloc(n ? n : 1, size);
    if (!p) *st = PT_ERR_NOMEM;
    return p;
}

static void update_bytes(gi_particle *gp)
{
    gi_particle_stats *s = &gp->st;
    size_t n = (size_t)gp->ps.n, nrp = (size_t)gp->lists.nrp;
    s->bytes_particles = n * (sizeof(gi_dev_particle) + 1) + n * 4 * sizeof(float) * 4 + n * 2 +
                         (size_t)gp->nlights * n * sizeof(float);
    s->bytes_links = n * (size_t)(2 * gp->ns2 + gp->ng) * sizeof(int) + (n + 2) * sizeof(int) +
                     (gp->woff ? (n + 1) * sizeof(int) + (size_t)gp->woff[n] * sizeof(gi_walk_entry) : 0);
    s->bytes_lists = (nrp + 1) * sizeof(int) + (gp->lists.off ? (size_t)gp->lists.off[nrp] : 0) * sizeof(int) +
                     nrp * (4 * sizeof(float) + 2);
    s->bytes_surfaces = gp->surf ? gi_surface_bytes(gp->surf) : 0;
    s->bytes_device = gi_dev_bytes(gp->dev);
    s->bytes_cells = gi_cellvis_bytes(gp->cells);
    s->bytes_total = s->bytes_particles + s->bytes_links + s->bytes_lists + s->bytes_surfaces + s->bytes_device +
                     s->bytes_cells;
}

static void fill_stats(gi_particle *gp, gi_particle_stats *out)
{
    update_bytes(gp);
    long look = 0, late = 0, none = 0, disc = 0, otf = 0, vis = gp->lists.vis_rays;
    long lrp = 0, larea = 0, cells = 0, cclear = 0, clear = 0, kept = 0, gathered = 0, here = 0;
    for (int t = 0; t < GI_MAX_THREADS; t++) {
        lrp += gp->tc[t].late_rp;
        larea += gp->tc[t].late_area;
        cells += gp->tc[t].cells;
        cclear += gp->tc[t].cells_clear;
        clear += gp->tc[t].clear;
        kept += gp->tc[t].kept;
        gathered += gp->tc[t].gathered;
        here += gp->tc[t].gathered_here;
        vis += gp->tc[t].vis_rays;
        otf += gp->tc[t].onthefly;
        look += gp->tc[t].lookups;
        late += gp->tc[t].late;
        none += gp->tc[t].none;
        disc += gp->tc[t].discarded;
    }
    gp->st.lookups = look;
    gp->st.lookups_late = late;
    gp->st.lookups_none = none;
    gp->st.discarded = disc;
    gp->st.lookups_onthefly = otf;
    gp->st.visibility_rays = vis;
    gp->st.late_radiance = lrp;
    gp->st.late_area = larea;
    gp->st.cells = cells;
    gp->st.cells_clear = cclear;
    gp->st.lookups_clear = clear;
    gp->st.lookups_kept = kept;
    gp->st.lookups_gathered = gathered;
    gp->st.lookups_gathered_here = here;
    if (out && out != &gp->st) *out = gp->st;
}

/* Scattering links of the particles in ps, then keep only the particles
 * the light transport needs: those with at least one link ray that hit
 * something (they receive indirect light) or that some link points at
 * (they send light to others). The rest face only the void, and nothing
 * sees them (the outside of a closed room, the underside of a floor): the
 * indirect light there is just the background. Links are remapped to the
 * kept particles (a link target is always kept). *links_out gets the
 * n x ns2 scattering links of the kept particles. */
#define MAX_BURY_SOLIDS 256

/* The object of each particle and the solid it is buried in (2n pointers,
 * for gi_links_build), and its 2n flags
 * *pin: on the inside of a closed sphere or box; buried: on the surface of
 * another closed sphere or box, facing its inside (moved a little along its
 * normal the particle is inside it, moved back it is not: the floor under a
 * box standing on it; tested against the first MAX_BURY_SOLIDS of them). */
const void **gi_particle_objects(const gi_particle *gp, const gi_particles *ps, unsigned char **pin,
                                 pt_status *st)
{
    int n = ps->n, np = gi_surface_npatches(gp->surf), ns = 0;
    const void **o = gi_particle_calloc(2 * (size_t)n, sizeof *o, st);
    *pin = gi_particle_calloc(2 * (size_t)n, 1, st);
    const scene_object **solid = gi_particle_calloc(MAX_BURY_SOLIDS, sizeof *solid, st);
    if (!o || !*pin || !solid) {
        free(solid);
        return o;
    }
    for (int pa = 0; pa < np && ns < MAX_BURY_SOLIDS; pa++) {
        const scene_object *so = gi_surface_object(gp->surf, pa);
        if (!so || (so->kind != SHAPE_SPHERE && so->kind != SHAPE_BOX) || (so->flags & OBJ_INVERSE) ||
            gi_surface_csg_member(gp->surf, pa))
            continue;
        if (ns == 0 || solid[ns - 1] != so) solid[ns++] = so; /* a box's faces are consecutive patches */
    }
    for (int i = 0; i < n; i++) {
        const scene_object *so = gi_surface_object(gp->surf, ps->patch[i]);
        o[i] = so;
        /* CSG members are not closed solids: the inside of a subtracted
         * sphere is the outside of the result */
        (*pin)[i] = so && ps->side[i] == 1 && (so->kind == SHAPE_SPHERE || so->kind == SHAPE_BOX) &&
                    !(so->flags & OBJ_INVERSE) && !gi_surface_csg_member(gp->surf, ps->patch[i]);
        const gi_dev_particle *t = &ps->p[i];
        vec3 p = v3(t->p[0], t->p[1], t->p[2]);
        double lift = 1e-5 * (1.0 + fmax(fabs(p.x), fmax(fabs(p.y), fabs(p.z))));
        vec3 nn = v3(t->n[0], t->n[1], t->n[2]);
        vec3 q = v3_madd(p, nn, lift), qb = v3_madd(p, nn, -lift);
        for (int k = 0; k < ns; k++)
            if (solid[k] != so && gi_surface_inside_solid(solid[k], q) && !gi_surface_inside_solid(solid[k], qb)) {
                (*pin)[n + i] = 1;
                o[n + i] = solid[k];
                break;
            }
    }
    free(solid);
    return o;
}

/* use_tl: build gp->tl for these particles (kept, compacted, for the
 * gathering links); the pilot's particles take the grid path. */
static pt_status trace_and_prune(gi_particle *gp, gi_particles *ps, uint64_t seed, int **links_out,
                                 gi_link_stats *ls, int use_tl)
{
    pt_status st = PT_OK;
    int n = ps->n, k = gp->ns2;
    gi_link_stats local = {0};
    if (!ls) ls = &local;
    gi_lookup *grid = gi_lookup_build(ps, 2.0 * (ps->spacing > 0.0 ? ps->spacing : 1.0));
    int *links = gi_particle_calloc((size_t)n * (size_t)k, sizeof(int), &st);
    unsigned char *keep = gi_particle_calloc((size_t)n, 1, &st);
    unsigned char *linked = gi_particle_calloc((size_t)n, 1, &st);
    int *remap = gi_particle_calloc((size_t)n, sizeof(int), &st);
    unsigned char *pin = NULL;
    const void **pobj = gi_particle_objects(gp, ps, &pin, &st);
    if (!grid) st = PT_ERR_NOMEM;
    if (st == PT_OK) st = gi_lookup_set_objects(grid, (const void *const *)pobj);
    if (st == PT_OK && !gp->lscene) gp->lscene = accel_rtc_link_scene(gp->a);
    gi_trilook_free(gp->tl);
    gp->tl = NULL;
    if (st == PT_OK && use_tl)
        gp->tl = gi_trilook_build(gp->a, ps->p, n, (const void *const *)pobj, grid, pin + n, ps->spacing, GI_LINKS_AGREE,
                                  3.0 * ps->spacing, gp->threads, gp->set.cancel, &st);
    if (st == PT_OK)
        st = gi_links_build(gp->a, gp->lscene, ps->p, pobj, pin, n, 0, gp->set.scatter_side, seed, grid, gp->tl,
                            3.0 * ps->spacing, gp->threads, links, keep, ls, gp->set.cancel, gp->set.progress, NULL,
                            NULL, NULL, NULL, 0.0, NULL, NULL, NULL);
    gi_lookup_free(grid);
    free(pobj);
    free(pin);
    if (st == PT_OK) {
        for (size_t j = 0; j < (size_t)n * (size_t)k; j++)
            if (links[j] >= 0) linked[links[j]] = 1;
        /* linked: the particles some link ray ends on; keep: those with a
         * ray that hit something (they receive indirect light). Of the
         * latter only those the camera may see matter beyond the links:
         * the ones facing the camera's position (a surface facing away
         * from it is invisible to it; the underside of a ground plane).
         * Under a sky that is not black, a particle facing the camera
         * receives light even when all its rays leave the scene (the top
         * of a box under the open sky). */
        if (gp->set.camera || gp->sc->camera_set) {
            const scene_camera *cam = gp->set.camera ? gp->set.camera : &gp->sc->camera;
            int sky = !gi_sky_black(gp->sky);
            for (int i = 0; i < n; i++) {
                if (linked[i]) continue;
                const gi_dev_particle *t = &ps->p[i];
                vec3 to = v3_sub(cam->location, v3(t->p[0], t->p[1], t->p[2]));
                int faces = v3_dot(to, v3(t->n[0], t->n[1], t->n[2])) > 0.0;
                keep[i] = faces && (keep[i] || sky);
            }
        } else if (!gi_sky_black(gp->sky)) {
            memset(keep, 1, (size_t)n);
        }
        for (int i = 0; i < n; i++) keep[i] |= linked[i];
        /* a diffuse_back particle reflects what its twin receives (the
         * sunlit outer face of a curtain lights the room through it): the
         * two are kept together */
        for (int i = 0; i < n; i++) {
            int j = ps->p[i].back > 0.0f ? gi_particles_twin(ps, i) : -1;
            if (j >= 0 && (keep[i] || keep[j])) keep[i] = keep[j] = 1;
        }
        int m = 0;
        for (int i = 0; i < n; i++) remap[i] = keep[i] ? m++ : -1;
        for (int i = 0; i < n; i++) {
            if (!keep[i]) continue;
            for (int j = 0; j < k; j++) {
                int t = links[(size_t)i * k + j];
                links[(size_t)remap[i] * k + j] = t >= 0 ? remap[t] : -1;
            }
        }
        st = gi_particles_compact(ps, keep);
        gi_trilook_compact(gp->tl, remap, ps->p, ps->n);
    }
    free(keep);
    free(linked);
    free(remap);
    if (st != PT_OK) {
        free(links);
        links = NULL;
    }
    *links_out = links;
    return st;
}

/* The WALK mode's bounces after the first (gi_k_walk, the paper's
 * single-link random bounces): in bounce b (1 <= b <= nwalk) particle i
 * sends all it received along its scattering link c(i, b), drawn here once
 * with probability 1/ns2 each (a hash of the seed, i and b; links of -1
 * lose the flux, as a packet leaving the scene). So what particle j
 * received in bounce 0 follows a fixed path, P_0 = j, P_b = c(P_(b-1), b),
 * and reaches P_b in bounce b times w_b = rho(P_0) rho(P_1) ... rho(P_(b-1))
 * (per colour, float products in that order; at a particle with a
 * diffuse_back twin the link may be the twin's, below). The table lists per target k
 * the entries (j, b, w_b) with P_b(j) = k, sorted by b, then j (a fixed
 * summation order for gi_k_walk); a path ends at a -1 link or where w_b is
 * 0 in every colour (it carries nothing on). 16 bytes per entry, at most n
 * per bounce, plus n + 1 offsets. Uploaded to the device; kept until the
 * bounce count grows (gi_particle_set_scattering): gi_k_walk stops at the
 * bounce count it is given. */
pt_status gi_particle_build_walk(gi_particle *gp, int nwalk, diag *d)
{
    if (nwalk < 0) nwalk = 0;
    if (gp->woff && nwalk <= gp->nwalk) return PT_OK;
    pt_status st = PT_OK;
    int n = gp->ps.n, k = gp->ns2;
    if ((gi_u32)n > GI_WALK_MASK + 1u || nwalk > GI_MAX_BOUNCES - 1) {
        src_loc nowhere = {0};
        diag_report(d, DIAG_ERROR, nowhere, NULL,
                    "particle GI: %d particles and %d random bounces are more than the walk table holds (%u, %d)", n,
                    nwalk, GI_WALK_MASK + 1u, GI_MAX_BOUNCES - 1);
        return PT_ERR_UNSUPPORTED;
    }
    size_t nn = (size_t)(n > 0 ? n : 0);
    int *woff = gi_particle_calloc(nn + 1, sizeof(int), &st);
    int *pos = gi_particle_calloc(nn, sizeof(int), &st);
    float *w = gi_particle_calloc(nn * 3, sizeof(float), &st);
    if (st != PT_OK) {
        free(woff);
        free(pos);
        free(w);
        return st;
    }
    gi_u32 seed = (gi_u32)(gp->set.seed * 2654435761u + 12345u);
    gi_walk_entry *went = NULL;
    /* pass 0 counts the entries per target, pass 1 writes them (woff[t] is
     * target t's write cursor there, shifted back to offsets after) */
    for (int pass = 0; pass < 2 && st == PT_OK; pass++) {
        for (int j = 0; j < n; j++) {
            pos[j] = j;
            w[3 * (size_t)j] = w[3 * (size_t)j + 1] = w[3 * (size_t)j + 2] = 1.0f;
        }
        for (int b = 1; b <= nwalk; b++) {
            gi_u32 hb = gi_hash((gi_u32)b);
            for (int j = 0; j < n; j++) {
                int p = pos[j];
                if (p < 0) continue;
                gi_u32 h = gi_hash(seed ^ gi_hash((gi_u32)p ^ hb));
                float *wj = &w[3 * (size_t)j];
                /* diffuse_back (gi_types.h): what p received leaves by p's
                 * own lobe (rho_p) and by its twin's back lobe (back_t
                 * rho_t, along the twin's links); the walk takes the twin's
                 * way with probability q = back_t / (1 + back_t) and
                 * divides by the probability taken: the same expectation,
                 * rho_p own + back_t rho_t twin */
                int from = p, tw = gp->ps.p[p].twin;
                float scale = 1.0f;
                const float *rho = gp->ps.p[p].rho;
                if (tw >= 0 && gp->ps.p[tw].back > 0.0f) {
                    float bt = gp->ps.p[tw].back, q = bt / (1.0f + bt);
                    if ((float)(gi_hash(h ^ 0x9e3779b9u) >> 8) * (1.0f / 16777216.0f) < q) {
                        from = tw;
                        rho = gp->ps.p[tw].rho;
                        scale = bt / q;
                    } else {
                        scale = 1.0f / (1.0f - q);
                    }
                }
                int t = gp->slink[(size_t)from * (size_t)k + (size_t)(h % (gi_u32)k)];
                for (int c = 0; c < 3; c++) wj[c] *= rho[c] * scale;
                if (t < 0 || (wj[0] == 0.0f && wj[1] == 0.0f && wj[2] == 0.0f)) {
                    pos[j] = -1;
                    continue;
                }
                pos[j] = t;
                if (pass == 0) {
                    woff[t + 1]++;
                } else {
                    gi_walk_entry *e = &went[woff[t]++];
                    e->jb = (gi_u32)j | (gi_u32)(b - 1) << GI_WALK_SHIFT;
                    for (int c = 0; c < 3; c++) e->w[c] = wj[c];
                }
            }
        }
        if (pass == 0) {
            for (int j = 0; j < n; j++) woff[j + 1] += woff[j];
            went = gi_particle_calloc((size_t)woff[nn], sizeof *went, &st);
        }
    }
    free(pos);
    free(w);
    if (st != PT_OK) {
        free(woff);
        free(went);
        return st;
    }
    for (int j = n; j > 0; j--) woff[j] = woff[j - 1];
    woff[0] = 0;
    free(gp->woff);
    free(gp->went);
    gp->woff = woff;
    gp->went = went;
    gp->nwalk = nwalk;
    return gi_dev_set_walk(gp->dev, gp->woff, gp->went, gp->nwalk, d);
}

/* Catchment areas. A link ends on the area particle nearest its hit, so
 * particle j receives scattered flux, and is read by gathering links, in
 * proportion to the area V_j of the surface nearer to it than to any other
 * particle (its Voronoi cell on the surface), not to the nominal dA = A/N it
 * was sampled with. With L_j = rho phi_j / (pi dA) a gather then meets
 * phi_j ~ E V_j with probability ~ V_j: the scattered light reads high by
 * E[V^2] / (dA E[V]) = 1 + the squared coefficient of variation of the
 * cells' areas (random points leave that variation well above zero;
 * test_gi's integrating sphere tells the two apart). The direct and
 * emitted parts of L are not
 * affected (evaluated at the particle, they cancel dA). With V_j as the
 * particle's area, emission and the first bounce send E V_j (a Voronoi
 * quadrature) and the estimation lists weight by V_j too.
 *
 * V_j is estimated from the gathering links already traced, by reciprocity:
 * every particle casts ng cosine-distributed rays, and particles stand at a
 * uniform density 1/dA, so the links ending per unit area at x number
 * (ng / dA) times the cosine-weighted fraction c(x) of x's hemisphere
 * covered by surfaces with particles (integral of cos cos / (pi r^2) over
 * those surfaces); c at particle j is the fraction r_j / ng of its own links
 * that resolved. With g_j the links ending on j:
 *   V_j ~ dA g_j / r_j,
 * taken as dA (g_j + k) / (r_j + k) with k = CATCH_PRIOR links: where few
 * links resolve (a floor under the open sky) the estimate stays near dA
 * instead of following a ratio of small counts. Relative noise about
 * 1/sqrt(g_j), so the noise's own bias E[V / V^] - 1 is about 1/ng
 * (0.4% of the scattered light at 256 links). Where every link resolves
 * (a closed room) the areas sum exactly to N dA (every link ends on one
 * particle: sum g = sum r); elsewhere they follow the area the links
 * reach (cbox 1.0001 N dA, maze 1.0025). */
#define CATCH_PRIOR 8.0
static pt_status catchment_areas(gi_particles *ps, const int *glink, int ng)
{
    int n = ps->n;
    if (n <= 0 || ng <= 0) return PT_OK;
    pt_status st = PT_OK;
    double *g = gi_particle_calloc((size_t)n, sizeof(double), &st), *a0 = gi_particle_calloc((size_t)n, sizeof(double), &st);
    int *r = gi_particle_calloc((size_t)n, sizeof(int), &st);
    if (st != PT_OK) {
        free(g);
        free(a0);
        free(r);
        return st;
    }
    /* Where the particles stand at different densities (gi_particles_sample's
     * view weights: dA / w_i each), the links ending per unit area at x come
     * from senders of different densities, and each link stands for its
     * sender's nominal area a_i: sum over the links ending on j of a_i is
     * ng V_j c(x_j), so V_j ~ (sum a_i) / r_j, which is dA g_j / r_j when
     * every a_i is dA. The prior is CATCH_PRIOR links of j's own area. */
    for (int i = 0; i < n; i++) a0[i] = ps->p[i].area > 0.0f ? ps->p[i].area : ps->dA;
    for (int i = 0; i < n; i++) {
        const int *lk = glink + (size_t)i * (size_t)ng;
        for (int k = 0; k < ng; k++)
            if (lk[k] >= 0) {
                g[lk[k]] += a0[i];
                r[i]++;
            }
    }
    for (int j = 0; j < n; j++) {
        double v = (g[j] + CATCH_PRIOR * a0[j]) / ((double)r[j] + CATCH_PRIOR);
        if (isfinite(v) && v > 0.0) ps->p[j].area = (float)v;
    }
    free(g);
    free(a0);
    free(r);
    return PT_OK;
}

/* Sky light in the lighting stage (beyond the paper, which leaves open
 * scenes out): what a particle's gathering links that left the scene saw
 * (and the far field of those no particle answered: an emitting dome
 * beyond the clip box, under a black sky too) is light arriving at it,
 * E/pi = esky (gi_links.h), which it reflects as rho * E / pi like
 * light from a light_source. That reflected radiance is added to the
 * particle's emitted radiance le, so emission (gi_k_emit) sends it along
 * the scattering links and the gathering step reads it, with no further
 * kernel input. The sky reaches surfaces only as gathered light, so it is
 * scaled by brightness (core/radrules.h rule 2), and it is a bounce of
 * gathered light: with no scattering bounce (recursion_limit 1) the sky
 * reaches a surface only through its own gathering (gi_k_gather), not by
 * way of another surface. */
static float sky_reflected(const gi_particle *gp, int i, int c)
{
    if (gp->set.bounces < 1 || !gp->esky) return 0.0f;
    const gi_dev_particle *p = &gp->ps.p[i];
    float e = gp->esky[4 * (size_t)i + c];
    /* diffuse_back: the sky its twin sees, too (gi_types.h) */
    if (p->back > 0.0f && p->twin >= 0) e += p->back * gp->esky[4 * (size_t)p->twin + c];
    float v = p->rho[c] * (float)gp->set.brightness * e;
    return isfinite(v) ? v : 0.0f;
}

static void sky_as_emission(gi_particle *gp)
{
    for (int i = 0; i < gp->ps.n; i++)
        for (int c = 0; c < 3; c++) gp->ps.p[i].le[c] += sky_reflected(gp, i, c);
}

float gi_particle_own_emission(const gi_particle *gp, int i, int c)
{
    float v = gp->ps.p[i].le[c] - sky_reflected(gp, i, c);
    return v > 0.0f ? v : 0.0f;
}

gi_particle *gi_particle_begin(const scene *sc, const accel *a, const gi_particle_settings *s, diag *d,
                               pt_status *status)
{
    pt_status st = PT_OK;
    gi_particle *gp = calloc(1, sizeof *gp);
    if (!gp) {
        *status = PT_ERR_NOMEM;
        return NULL;
    }
    gp->vg = &gp->vgs[0];
    gp->vgs[1].back = 1;
    gp->sc = sc;
    gp->a = a;
    gp->vis_eps = 1e-6 * (accel_eps_scale(a) > 0.0 && isfinite(accel_eps_scale(a)) ? accel_eps_scale(a) : 1.0);
    if (s) gp->set = *s;
    else gi_particle_default_settings(&gp->set);
    gi_particle_settings *set = &gp->set;
    if (set->camera) {
        /* the geometry stage sees the scene from settings.camera */
        gp->gcam = *set->camera;
        set->camera = &gp->gcam;
        gp->gsc = *sc;
        gp->gsc.camera = gp->gcam;
        gp->gsc.camera_set = 1;
    }
    if (set->scatter_side < 1) set->scatter_side = 1;
    if (set->scatter_side > 4) set->scatter_side = 4; /* GI_MAX_SCATTER links */
    if (set->gather_side < 1) set->gather_side = 1;
    if (set->bounces < 0) set->bounces = 0;
    if (set->bounces > GI_MAX_BOUNCES) set->bounces = GI_MAX_BOUNCES;
    if (!(set->brightness > 0.0)) set->brightness = 1.0;
    gp->threads = set->threads > 0 ? set->threads : pool_default_threads();
    if (gp->threads > GI_MAX_THREADS) gp->threads = GI_MAX_THREADS;
    gp->ns2 = set->scatter_side * set->scatter_side;
    gp->ng = set->gather_side * set->gather_side;
    gp->sky = gi_sky_new(sc, set->sky);
    if (!gp->sky) {
        *status = PT_ERR_NOMEM;
        gi_particle_free(gp);
        return NULL;
    }
    gi_particle_stats *S = &gp->st;
    S->bounces = set->bounces;

    /* the device first: a missing OpenCL driver should fail before seconds of ray tracing */
    gi_dev_options o = {set->cl_device, set->cl_source, gp->threads, set->cl_max_bytes};
    /* auto, and a scene asking for few particles: the kernels' C build. At
     * that size the driver's start-up and program build cost more than
     * the kernels themselves (bench/gi_vs_povray.sh's small scenes; the
     * stats' kernel_build), and a GPU would not pay back its transfers. */
    gp->final_only = gi_particle_final_only(set);
    if ((!o.spec || !*o.spec || !strcmp(o.spec, "auto")) &&
        (set->count < GI_CL_AUTO_MIN_PARTICLES || gp->final_only) && !set->cl_source && !set->cl_max_bytes)
        o.spec = "c";
    gp->dev = gi_dev_open(&o, d, &st);
    if (!gp->dev) {
        *status = st == PT_OK ? PT_ERR_INTERNAL : st;
        gi_particle_free(gp);
        return NULL;
    }
    S->t_kernel_build = gi_dev_build_seconds(gp->dev);
    snprintf(S->device, sizeof S->device, "%s", gi_dev_name(gp->dev));

    progress_stage(set->progress, "gi geometry: surfaces", 0);
    double tg = timer_now();
    /* final_only: the surfaces of no object (the clip box, which the
     * hook's far field asks, comes from the scene's bounds), so no
     * particle is placed */
    if (gp->final_only) {
        if (!set->camera) gp->gsc = *sc;
        gp->gsc.nobjects = 0;
    }
    gp->surf = gi_surface_build(set->camera || gp->final_only ? &gp->gsc : sc, a, 1e30, gp->threads, d, &st);
    if (!gp->surf) {
        *status = st == PT_OK ? PT_ERR_INTERNAL : st;
        gi_particle_free(gp);
        return NULL;
    }
    S->skipped_objects = gi_surface_skipped(gp->surf);
    S->t_surfaces = timer_now() - tg;
    *status = PT_OK;
    return gp;
}

gi_particle *gi_particle_build(const scene *sc, const accel *a, const gi_particle_settings *s,
                               gi_particle_stats *stats, diag *d, pt_status *status)
{
    pt_status dummy, st = PT_OK;
    if (!status) status = &dummy;
    double t0 = timer_now(), c0 = timer_cpu_now();
    gi_particle *gp = gi_particle_begin(sc, a, s, d, status);
    if (!gp) return NULL;
    gi_particle_settings *set = &gp->set;
    gi_particle_stats *S = &gp->st;
    double tg;

    /* pilot: a quarter of the particles on every side, to learn which sides
     * are needed (see keep_needed) and what fraction of each survives */
    progress_stage(set->progress, "gi geometry: pilot", 0);
    tg = timer_now();
    double cg = timer_cpu_now();
    int np = gi_surface_npatches(gp->surf);
    float *frac = gi_particle_calloc(2 * (size_t)np + 2, sizeof(float), &st);
    if (!frac) goto fail;
    {
        gi_particles pilot;
        long pc = set->count / 4 > 500 ? set->count / 4 : 500;
        st = gi_particles_sample(&pilot, gp->surf, a, sc, pc, set->seed ^ 0x9170ULL, NULL, NULL, d);
        int *pl = NULL;
        if (st == PT_OK) st = trace_and_prune(gp, &pilot, set->seed ^ 0x5eedULL, &pl, NULL, 0);
        free(pl);
        if (st == PT_OK) {
            /* pilot.patch/side now list the survivors; count them per side */
            gi_particles all;
            st = gi_particles_sample(&all, gp->surf, a, sc, pc, set->seed ^ 0x9170ULL, NULL, NULL, d);
            if (st == PT_OK) {
                float *tot = gi_particle_calloc(2 * (size_t)np + 2, sizeof(float), &st);
                if (tot) {
                    for (int i = 0; i < all.n; i++) tot[2 * all.patch[i] + all.side[i]] += 1.0f;
                    for (int i = 0; i < pilot.n; i++) frac[2 * pilot.patch[i] + pilot.side[i]] += 1.0f;
                    for (int k = 0; k < 2 * np; k++) frac[k] = tot[k] > 0.0f ? frac[k] / tot[k] : 1.0f;
                }
                free(tot);
            }
            gi_particles_free(&all);
        }
        gi_particles_free(&pilot);
    }
    if (st != PT_OK) {
        free(frac);
        goto fail;
    }
    S->t_prune = timer_now() - tg;
    S->c_prune = timer_cpu_now() - cg;
    if (set->cancel && *set->cancel) {
        st = PT_CANCELLED;
        goto fail;
    }

    /* the area particles */
    progress_stage(set->progress, "gi geometry: particles", 0);
    tg = timer_now();
    st = gi_particles_sample(&gp->ps, gp->surf, a, sc, set->count, set->seed, frac, set->pigment, d);
    free(frac);
    if (st != PT_OK) goto fail;
    S->candidates = gp->ps.n;
    S->probed_out = gp->ps.probed_out;
    double spacing = gp->ps.spacing > 0.0 ? gp->ps.spacing : 1.0;
    S->spacing = spacing;
    S->tess = set->tess > 0.0 ? set->tess : set->tess_factor * spacing;
    S->radius = set->radius > 0.0 ? set->radius : set->radius_factor * spacing;
    /* the radiance particles' layout at the particles' spacing, unless the
     * final gather answers the kept hits: then no radiance particle is
     * built (no_rp below) and the layout would go unread */
    if (!(set->view_gather_side > 0 && set->keep_hits)) gi_surface_retess(gp->surf, S->tess);
    S->t_sampling = timer_now() - tg;

    /* scattering links (and the final pruning), then gathering links.
     * The 4x4 links are traced on their own, as the paper does (seed 000,
     * Table 1 times them apart). Taking them from the 16x16 rays (one
     * sub-stratum of each 4x4 block: a 16x16 stratum lies inside one 4x4
     * stratum of the concentric map, so that is still one stratified
     * cosine-weighted ray per 4x4 stratum) would save their 16 rays a
     * particle but costs more than it saves: the pruning needs the
     * scattering links first, so the 256 rays would go to every candidate
     * (cbox, 50K: 50,000 x 256 = 12.80 M rays against 50,000 x 16 + 45,802
     * x 256 = 12.53 M now), and a particle's scattering and gathering
     * directions would be the same 16 rays. */
    {
        gi_link_stats ls = {0};
        progress_stage(set->progress, "gi geometry: scatter links", 0);
        tg = timer_now();
        cg = timer_cpu_now();
        st = trace_and_prune(gp, &gp->ps, set->seed ^ 0x51ULL, &gp->slink, &ls, 1);
        if (st == PT_OK) gi_particles_set_twins(&gp->ps);
        S->t_scatter_links = timer_now() - tg;
        S->c_scatter_links = timer_cpu_now() - cg;
        if (st != PT_OK) goto fail;
        S->pruned = S->candidates - gp->ps.n;
        S->particles = gp->ps.n;
        int n = gp->ps.n;
        gi_lookup *grid = gi_lookup_build(&gp->ps, 2.0 * spacing);
        gp->glink = gi_particle_calloc((size_t)n * (size_t)gp->ng, sizeof(int), &st);
        unsigned char *pin = NULL;
        const void **pobj = gi_particle_objects(gp, &gp->ps, &pin, &st);
        if (!grid) st = PT_ERR_NOMEM;
        if (st == PT_OK) st = gi_lookup_set_objects(grid, (const void *const *)pobj);
        progress_stage(set->progress, "gi geometry: gather links", 0);
        tg = timer_now();
        cg = timer_cpu_now();
        gp->esky = gi_particle_calloc((size_t)n * 4, sizeof(float), &st);
        if (st == PT_OK)
            st = gi_links_build(a, gp->lscene, gp->ps.p, pobj, pin, n, 0, set->gather_side, set->seed ^ 0x6a7ULL, grid,
                                gp->tl, 3.0 * spacing, gp->threads, gp->glink, NULL, &ls, set->cancel, set->progress,
                                gp->sky, gp->esky, sc, set->pigment,
                                set->bounces >= 1 ? set->brightness : 0.0, NULL, NULL, NULL);
        S->t_gather_links = timer_now() - tg;
        S->c_gather_links = timer_cpu_now() - cg;
        gi_lookup_free(grid);
        free(pobj);
        free(pin);
        S->bytes_trilook = gi_trilook_bytes(gp->tl);
        S->trilook_entries = gi_trilook_entries(gp->tl);
        S->trilook_lists = gi_trilook_cells(gp->tl);
        /* (the final gather builds lists of its own for the kept
         * particles, gi_particle_gather.c) */
        gi_trilook_free(gp->tl);
        gp->tl = NULL;
        /* the final gather at the camera's hits traces the same scene */
        if (set->view_gather_side <= 0 || !set->keep_hits) {
            accel_rtc_link_scene_free(gp->lscene);
            gp->lscene = NULL;
        }
        if (st != PT_OK) goto fail;
        S->link_tri = ls.tri_answered;
        S->link_tri_fallback = ls.tri_fallback;
        S->link_rays = ls.rays;
        S->link_misses = ls.misses;
        S->link_unresolved = ls.unresolved;
        st = catchment_areas(&gp->ps, gp->glink, gp->ng);
        if (st != PT_OK) goto fail;
        sky_as_emission(gp);
    }

    /* radiance particles and estimation lists */
    if (set->cancel && *set->cancel) {
        st = PT_CANCELLED;
        goto fail;
    }
    progress_stage(set->progress, "gi geometry: lists", 0);
    tg = timer_now();
    cg = timer_cpu_now();
    /* with the final gather at the kept hits, the radiance particles would
     * answer only the hits it does not (reflections, a few antialiasing
     * rays): those take the estimate at the hit (gi_particle_hook.c,
     * onthefly), and no list is built */
    gp->no_rp = set->view_gather_side > 0 && set->keep_hits;
    if (gp->no_rp) {
        gp->lists.nrp = 0;
        gp->lists.off = gi_particle_calloc(1, sizeof(int), &st);
        gp->lists.idx = gi_particle_calloc(1, sizeof(int), &st);
    } else {
        st = gi_radiance_lists(&gp->lists, gp->surf, &gp->ps, gp->a, S->radius, set->normal_cos, gp->threads,
                               set->cancel, set->progress, d);
    }
    if (st != PT_OK) goto fail;
    S->radiance_particles = gp->lists.nrp;
    S->list_entries = gp->lists.off[gp->lists.nrp];
    S->lists_widened = gp->lists.widened;
    S->lists_empty = gp->lists.empty;
    S->t_lists = timer_now() - tg;
    S->c_lists = timer_cpu_now() - cg;
    st = gi_particle_finish(gp, d);
    if (st != PT_OK) goto fail;
    S->t_geometry = timer_now() - t0 - S->t_kernel_build;
    S->c_geometry = timer_cpu_now() - c0;
    fill_stats(gp, stats);
    *status = PT_OK;
    return gp;
fail:
    if (st == PT_OK) st = PT_ERR_INTERNAL;
    *status = st;
    gi_particle_free(gp);
    return NULL;
}

pt_status gi_particle_finish(gi_particle *gp, diag *d)
{
    pt_status st = PT_OK;
    gi_particle_stats *S = &gp->st;
    S->radiance_slots = gp->no_rp ? 0 : gi_surface_rp_slots(gp->surf); /* none laid out for the final gather */
    double tg = timer_now();
    gp->rgrid = gi_grid_build(gp->ps.p, gp->ps.n, S->radius);
    if (!gp->rgrid) return PT_ERR_NOMEM;
    S->t_lists += timer_now() - tg;

    /* host state */
    {
        size_t n = (size_t)gp->ps.n, nrp = (size_t)gp->lists.nrp;
        gp->edir = gi_particle_calloc(n * 4, sizeof(float), &st);
        gp->phi = gi_particle_calloc(n * 4, sizeof(float), &st);
        gp->lout = gi_particle_calloc(n * 4, sizeof(float), &st);
        gp->eind = gi_particle_calloc(n * 4, sizeof(float), &st);
        gp->e_state = gi_particle_calloc(n, sizeof(atomic_uchar), &st);
        gp->dev_gathered = gi_particle_calloc(n, 1, &st);
        gp->rp_val = gi_particle_calloc(nrp * 4, sizeof(float), &st);
        gp->rp_state = gi_particle_calloc(nrp, sizeof(atomic_uchar), &st);
        gp->mark = gi_particle_calloc(nrp, sizeof(atomic_uchar), &st);
        if (st != PT_OK) return st;
        /* about 2 cells per radiance particle; room for twice that, within
         * 4M slots (32 MiB): more cells than a 1920x1080 frame's hits.
         * Without a table (out of memory) every hit is tested. */
        long slots = 4 * (long)nrp;
        gp->cells = gi_cellvis_new(slots < (1L << 22) ? slots : (1L << 22), (long)nrp);
    }

    /* incoming scattering links, sources ascending (FULL scattering) */
    {
        int n = gp->ps.n;
        size_t nl = (size_t)n * (size_t)gp->ns2;
        gp->rin_off = gi_particle_calloc((size_t)n + 2, sizeof(int), &st);
        gp->rin_src = gi_particle_calloc(nl, sizeof(int), &st);
        if (st != PT_OK) return st;
        gi_links_reverse_count(gp->slink, n, gp->ns2, NULL, gp->rin_off);
        gi_links_reverse_fill(gp->slink, n, gp->ns2, NULL, gp->rin_off, gp->rin_src);
    }

    tg = timer_now();
    st = gi_dev_set_particles(gp->dev, gp->ps.p, gp->ps.n, gp->slink, gp->ns2, gp->glink, gp->ng, gp->esky, d);
    if (st == PT_OK) st = gi_dev_set_lists(gp->dev, gp->lists.off, (int)gp->lists.nrp, gp->lists.idx, d);
    if (st == PT_OK) st = gi_dev_set_reverse(gp->dev, gp->rin_off, gp->rin_src, d);
    if (st == PT_OK && gp->set.scatter != GI_PARTICLE_SCATTER_FULL) st = gi_particle_build_walk(gp, gp->set.bounces - 1, d);
    S->t_upload = timer_now() - tg;
    return st;
}

void gi_particle_fill_stats(gi_particle *gp, gi_particle_stats *out)
{
    fill_stats(gp, out);
}

void gi_particle_free(gi_particle *gp)
{
    if (!gp) return;
    gi_dev_free(gp->dev);
    gi_trilook_free(gp->tl);
    accel_rtc_link_scene_free(gp->lscene);
    gi_surface_free(gp->surf);
    gi_particles_free(&gp->ps);
    gi_lists_free(&gp->lists);
    gi_grid_free(gp->rgrid);
    gi_cellvis_free(gp->cells);
    for (int t = 0; t < GI_MAX_THREADS; t++) {
        free(gp->tc[t].buf);
        gi_particle_cell_batch_free(gp->tc[t].cb);
    }
    free(gp->slink);
    free(gp->glink);
    free(gp->esky);
    gi_sky_free(gp->sky);
    free(gp->rin_off);
    free(gp->rin_src);
    free(gp->lights);
    free(gp->vis);
    free(gp->visf);
    free(gp->vis_lights);
    free(gp->dirty);
    free(gp->edir);
    free(gp->extra);
    free(gp->phi);
    free(gp->lout);
    free(gp->eind);
    free(gp->woff);
    free(gp->went);
    free(gp->e_state);
    free(gp->dev_gathered);
    free(gp->rp_val);
    free(gp->rp_state);
    free(gp->mark);
    free(gp->vrec);
    gi_particle_view_gather_free(gp);
    free(gp);
}

const gi_particle_stats *gi_particle_get_stats(gi_particle *gp)
{
    fill_stats(gp, NULL);
    return &gp->st;
}


/* ------------------------------------------------------------------ debug */

int gi_particle_debug(const gi_particle *gp, const float **edir, const float **phi, const float **lout,
                      const double **bounce_flux, int *nbounces)
{
    if (edir || phi) gi_dev_fetch(gp->dev, NULL); /* the last lighting stage's, kept on the device until now */
    if (edir) *edir = gp->edir;
    if (phi) *phi = gp->phi;
    if (lout) *lout = gp->lout;
    if (bounce_flux) *bounce_flux = gp->bounce_flux;
    if (nbounces) *nbounces = gp->nbounce_flux;
    return gp->ps.n;
}

void gi_particle_debug_particle(const gi_particle *gp, int i, double *area, double rho[3], vec3 *pos, vec3 *nrm)
{
    const gi_dev_particle *p = &gp->ps.p[i];
    if (area) *area = p->area;
    if (rho)
        for (int c = 0; c < 3; c++) rho[c] = p->rho[c];
    if (pos) *pos = v3(p->p[0], p->p[1], p->p[2]);
    if (nrm) *nrm = v3(p->n[0], p->n[1], p->n[2]);
}
