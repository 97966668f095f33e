/* gi_particle.c - the particle GI mode: stages, lights, view pre-pass and the
 * shading hook (see gi_particle.h). */
#include "gi_particle.h"
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
#include "gi_particles.h"
#include "gi_radiance.h"
#include "gi_surface.h"
#include "pool.h"
#include "rng.h"
#include "timer.h"

#define GI_MAX_THREADS 256
#define VIEW_REC_MAX_BYTES ((size_t)256 << 20) /* keep_hits: at most this much of view_rec */

typedef struct {
    long lookups, late, none, discarded, onthefly, vis_rays;
    long late_rp, late_area;        /* radiance / area particles computed in the hook (late_rp) */
    long cells, cells_clear, clear; /* cells tested, of them clear; lookups in clear cells */
    long kept;                      /* lookups whose cell came from a kept hit (view_rec) */
    int *buf; /* on-the-fly estimation list */
    long len, cap;
    struct cell_batch *cb; /* the pre-pass's cell tests waiting for the row's end (cell_batch) */
} thread_count;

struct gi_particle {
    const scene *sc;
    const accel *a;
    gi_particle_settings set;
    int threads;
    gi_surface *surf;
    gi_particles ps;
    int ns2, ng;
    int *slink, *glink;
    void *lscene;   /* accel_rtc_link_scene, for the three link passes (freed after them) */
    gi_trilook *tl; /* the 4x4 pass's lookup by hit triangle, compacted for the 16x16 pass */
    int *rin_off, *rin_src; /* incoming scattering links (first bounce, FULL mode) */
    int *woff;              /* WALK bounces' path table (build_walk): n + 1 offsets */
    gi_walk_entry *went;    /* and its entries */
    int nwalk;
    gi_lists lists;
    gi_grid *rgrid; /* particles by list radius: estimates on surfaces without radiance particles */
    gi_dev *dev;
    /* lighting */
    int nlights;
    gi_dev_light *lights;
    float *vis;               /* n x nlights: attenuation x visibility fraction (gi_k_emit) */
    scene_light *vis_lights; /* the lights vis was traced for (colour aside) */
    unsigned char *dirty;
    float *edir, *phi, *lout;
    double bounce_flux[GI_MAX_BOUNCES];
    int nbounce_flux;
    int lit;
    volatile int *cancel; /* gi_particle_set_cancel: non-zero stops the lighting stage */
    /* view */
    float *eind;                 /* n*4: gathered E~/pi */
    atomic_uchar *e_state;       /* 0 none, 1 being computed, 2 done */
    unsigned char *dev_gathered; /* the device's eind holds it */
    float *rp_val;               /* nrp*4: estimated E/pi at radiance particles */
    atomic_uchar *rp_state;
    atomic_uchar *mark;
    gi_cellvis *cells; /* per-cell verdicts of the light-leak guard (side_value); NULL: per hit */
    struct view_rec *vrec; /* keep_hits: one per pixel of the last prepare_view (vw x vh), NULL: none */
    scene_camera vcam;     /* its camera */
    size_t vrec_cap;       /* records allocated */
    int vw, vh;
    double veps;           /* the pre-pass's tmin */
    float bg[3];
    double vis_eps; /* gi_visible's eps: 1e-6 x accel_eps_scale */
    thread_count tc[GI_MAX_THREADS];
    gi_particle_stats st;
};

static void cell_batch_free(struct cell_batch *b);

/* ------------------------------------------------------------------ settings */

void gi_particle_default_settings(gi_particle_settings *s)
{
    memset(s, 0, sizeof *s);
    s->count = 50000;
    s->scatter_side = 4;
    s->gather_side = 16;
    s->bounces = 8;
    s->tess = 0.0;
    s->tess_factor = 3.0;
    s->radius = 0.0;
    s->radius_factor = 3.0;
    s->normal_cos = 0.9;
    s->area_samples = 0;
    s->brightness = 1.0;
    s->seed = 0;
    s->threads = 0;
}

void gi_particle_settings_from_scene(gi_particle_settings *s, const scene *sc)
{
    gi_particle_default_settings(s);
    const scene_radiosity *r = &sc->global.radiosity;
    if (!r->enabled) return;
    long count = 500L * (r->count > 0 ? r->count : 35);
    s->count = count < 10000 ? 10000 : (count > 1000000 ? 1000000 : count);
    s->bounces = r->recursion_limit - 1 > 0 ? r->recursion_limit - 1 : 0;
    if (r->error_bound > 0.0) {
        double f = 3.0 * r->error_bound / 1.8;
        s->radius_factor = f < 2.0 ? 2.0 : (f > 5.0 ? 5.0 : f);
    }
    if (r->brightness > 0.0) s->brightness = r->brightness;
}

/* ------------------------------------------------------------------ build */

static void *xcalloc(size_t n, size_t size, pt_status *st)
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
    long lrp = 0, larea = 0, cells = 0, cclear = 0, clear = 0, kept = 0;
    for (int t = 0; t < GI_MAX_THREADS; t++) {
        lrp += gp->tc[t].late_rp;
        larea += gp->tc[t].late_area;
        cells += gp->tc[t].cells;
        cclear += gp->tc[t].cells_clear;
        clear += gp->tc[t].clear;
        kept += gp->tc[t].kept;
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
static const void **particle_objects(const gi_particle *gp, const gi_particles *ps, unsigned char **pin,
                                     pt_status *st)
{
    int n = ps->n, np = gi_surface_npatches(gp->surf), ns = 0;
    const void **o = xcalloc(2 * (size_t)n, sizeof *o, st);
    *pin = xcalloc(2 * (size_t)n, 1, st);
    const scene_object **solid = xcalloc(MAX_BURY_SOLIDS, sizeof *solid, st);
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
    int *links = xcalloc((size_t)n * (size_t)k, sizeof(int), &st);
    unsigned char *keep = xcalloc((size_t)n, 1, &st);
    int *remap = xcalloc((size_t)n, sizeof(int), &st);
    unsigned char *pin = NULL;
    const void **pobj = particle_objects(gp, ps, &pin, &st);
    if (!grid) st = PT_ERR_NOMEM;
    if (st == PT_OK) st = gi_lookup_set_objects(grid, (const void *const *)pobj);
    if (st == PT_OK && !gp->lscene) gp->lscene = accel_rtc_link_scene(gp->a);
    gi_trilook_free(gp->tl);
    gp->tl = NULL;
    if (st == PT_OK && use_tl && gp->set.link_lookup == 0)
        gp->tl = gi_trilook_build(gp->a, ps->p, n, (const void *const *)pobj, grid, pin + n, ps->spacing, GI_LINKS_AGREE,
                                  3.0 * ps->spacing, gp->threads, gp->set.cancel, &st);
    if (st == PT_OK)
        st = gi_links_build(gp->a, gp->lscene, ps->p, pobj, pin, n, gp->set.scatter_side, seed, grid, gp->tl,
                            3.0 * ps->spacing, gp->threads, links, keep, ls, gp->set.cancel, gp->set.progress);
    gi_lookup_free(grid);
    free(pobj);
    free(pin);
    if (st == PT_OK) {
        for (size_t j = 0; j < (size_t)n * (size_t)k; j++)
            if (links[j] >= 0) keep[links[j]] = 1;
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
 * (per colour, float products in that order). The table lists per target k
 * the entries (j, b, w_b) with P_b(j) = k, sorted by b, then j (a fixed
 * summation order for gi_k_walk); a path ends at a -1 link or where w_b is
 * 0 in every colour (it carries nothing on). 16 bytes per entry, at most n
 * per bounce, plus n + 1 offsets. Uploaded to the device; kept until the
 * bounce count grows (gi_particle_set_scattering): gi_k_walk stops at the
 * bounce count it is given. */
static pt_status build_walk(gi_particle *gp, int nwalk, diag *d)
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
    int *woff = xcalloc(nn + 1, sizeof(int), &st);
    int *pos = xcalloc(nn, sizeof(int), &st);
    float *w = xcalloc(nn * 3, sizeof(float), &st);
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
                int t = gp->slink[(size_t)p * (size_t)k + (size_t)(h % (gi_u32)k)];
                float *wj = &w[3 * (size_t)j];
                for (int c = 0; c < 3; c++) wj[c] *= gp->ps.p[p].rho[c];
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
            went = xcalloc((size_t)woff[nn], sizeof *went, &st);
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
 * cells' areas (cbox, 50K particles: 1.104, measured by 64 stratified
 * points per dA; the image +1.4% at n_b 8; test_gi's integrating sphere
 * +2.5% at 1K particles). The direct and emitted parts of L are not
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
    int *g = xcalloc((size_t)n, sizeof(int), &st), *r = xcalloc((size_t)n, sizeof(int), &st);
    if (st != PT_OK) {
        free(g);
        free(r);
        return st;
    }
    for (int i = 0; i < n; i++) {
        const int *lk = glink + (size_t)i * (size_t)ng;
        for (int k = 0; k < ng; k++)
            if (lk[k] >= 0) {
                g[lk[k]]++;
                r[i]++;
            }
    }
    for (int j = 0; j < n; j++) {
        double v = ps->dA * ((double)g[j] + CATCH_PRIOR) / ((double)r[j] + CATCH_PRIOR);
        if (isfinite(v) && v > 0.0) ps->p[j].area = (float)v;
    }
    free(g);
    free(r);
    return PT_OK;
}

gi_particle *gi_particle_build(const scene *sc, const accel *a, const gi_particle_settings *s,
                               gi_particle_stats *stats, diag *d, pt_status *status)
{
    pt_status dummy, st = PT_OK;
    if (!status) status = &dummy;
    gi_particle *gp = calloc(1, sizeof *gp);
    if (!gp) {
        *status = PT_ERR_NOMEM;
        return NULL;
    }
    gp->sc = sc;
    gp->a = a;
    gp->vis_eps = 1e-6 * (accel_eps_scale(a) > 0.0 && isfinite(accel_eps_scale(a)) ? accel_eps_scale(a) : 1.0);
    if (s) gp->set = *s;
    else gi_particle_default_settings(&gp->set);
    gi_particle_settings *set = &gp->set;
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
    gp->bg[0] = (float)sc->background.r;
    gp->bg[1] = (float)sc->background.g;
    gp->bg[2] = (float)sc->background.b;
    gi_particle_stats *S = &gp->st;
    S->bounces = set->bounces;

    /* the device first: a missing OpenCL driver should fail before seconds of ray tracing */
    double t0 = timer_now();
    gi_dev_options o = {set->cl_device, set->cl_source, gp->threads, set->cl_max_bytes};
    gp->dev = gi_dev_open(&o, d, &st);
    if (!gp->dev) goto fail;
    S->t_kernel_build = gi_dev_build_seconds(gp->dev);
    snprintf(S->device, sizeof S->device, "%s", gi_dev_name(gp->dev));

    double c0 = timer_cpu_now();
    progress_stage(set->progress, "gi geometry: surfaces", 0);
    double tg = timer_now();
    gp->surf = gi_surface_build(sc, a, 1e30, d, &st);
    if (!gp->surf) goto fail;
    S->skipped_objects = gi_surface_skipped(gp->surf);
    S->t_surfaces = timer_now() - tg;

    /* pilot: a quarter of the particles on every side, to learn which sides
     * are needed (see keep_needed) and what fraction of each survives */
    progress_stage(set->progress, "gi geometry: pilot", 0);
    tg = timer_now();
    double cg = timer_cpu_now();
    int np = gi_surface_npatches(gp->surf);
    float *frac = xcalloc(2 * (size_t)np + 2, sizeof(float), &st);
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
                float *tot = xcalloc(2 * (size_t)np + 2, sizeof(float), &st);
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
    gi_surface_retess(gp->surf, S->tess);
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
        S->t_scatter_links = timer_now() - tg;
        S->c_scatter_links = timer_cpu_now() - cg;
        if (st != PT_OK) goto fail;
        S->pruned = S->candidates - gp->ps.n;
        S->particles = gp->ps.n;
        int n = gp->ps.n;
        gi_lookup *grid = gi_lookup_build(&gp->ps, 2.0 * spacing);
        gp->glink = xcalloc((size_t)n * (size_t)gp->ng, sizeof(int), &st);
        unsigned char *pin = NULL;
        const void **pobj = particle_objects(gp, &gp->ps, &pin, &st);
        if (!grid) st = PT_ERR_NOMEM;
        if (st == PT_OK) st = gi_lookup_set_objects(grid, (const void *const *)pobj);
        progress_stage(set->progress, "gi geometry: gather links", 0);
        tg = timer_now();
        cg = timer_cpu_now();
        if (st == PT_OK)
            st = gi_links_build(a, gp->lscene, gp->ps.p, pobj, pin, n, set->gather_side, set->seed ^ 0x6a7ULL, grid,
                                gp->tl, 3.0 * spacing, gp->threads, gp->glink, NULL, &ls, set->cancel, set->progress);
        S->t_gather_links = timer_now() - tg;
        S->c_gather_links = timer_cpu_now() - cg;
        gi_lookup_free(grid);
        free(pobj);
        free(pin);
        S->bytes_trilook = gi_trilook_bytes(gp->tl);
        S->trilook_entries = gi_trilook_entries(gp->tl);
        S->trilook_lists = gi_trilook_cells(gp->tl);
        gi_trilook_free(gp->tl);
        gp->tl = NULL;
        accel_rtc_link_scene_free(gp->lscene);
        gp->lscene = NULL;
        if (st != PT_OK) goto fail;
        S->link_tri = ls.tri_answered;
        S->link_tri_fallback = ls.tri_fallback;
        S->link_rays = ls.rays;
        S->link_misses = ls.misses;
        S->link_unresolved = ls.unresolved;
        if (!set->nominal_areas) st = catchment_areas(&gp->ps, gp->glink, gp->ng);
        if (st != PT_OK) goto fail;
    }

    /* radiance particles and estimation lists */
    if (set->cancel && *set->cancel) {
        st = PT_CANCELLED;
        goto fail;
    }
    progress_stage(set->progress, "gi geometry: lists", 0);
    tg = timer_now();
    cg = timer_cpu_now();
    st = gi_radiance_lists(&gp->lists, gp->surf, &gp->ps, gp->a, S->radius, set->normal_cos, gp->threads, set->cancel,
                           d);
    if (st != PT_OK) goto fail;
    S->radiance_particles = gp->lists.nrp;
    S->radiance_slots = gi_surface_rp_slots(gp->surf);
    S->list_entries = gp->lists.off[gp->lists.nrp];
    S->lists_widened = gp->lists.widened;
    S->lists_empty = gp->lists.empty;
    gp->rgrid = gi_grid_build(gp->ps.p, gp->ps.n, S->radius);
    if (!gp->rgrid) {
        st = PT_ERR_NOMEM;
        goto fail;
    }
    S->t_lists = timer_now() - tg;
    S->c_lists = timer_cpu_now() - cg;

    /* host state */
    {
        size_t n = (size_t)gp->ps.n, nrp = (size_t)gp->lists.nrp;
        gp->edir = xcalloc(n * 4, sizeof(float), &st);
        gp->phi = xcalloc(n * 4, sizeof(float), &st);
        gp->lout = xcalloc(n * 4, sizeof(float), &st);
        gp->eind = xcalloc(n * 4, sizeof(float), &st);
        gp->e_state = xcalloc(n, sizeof(atomic_uchar), &st);
        gp->dev_gathered = xcalloc(n, 1, &st);
        gp->rp_val = xcalloc(nrp * 4, sizeof(float), &st);
        gp->rp_state = xcalloc(nrp, sizeof(atomic_uchar), &st);
        gp->mark = xcalloc(nrp, sizeof(atomic_uchar), &st);
        if (st != PT_OK) goto fail;
        /* about 2 cells per radiance particle; room for twice that, within
         * 4M slots (32 MiB): more cells than a 1920x1080 frame's hits.
         * Without a table (out of memory) every hit is tested. */
        long slots = 4 * (long)nrp;
        if (!set->leak_per_hit) gp->cells = gi_cellvis_new(slots < (1L << 22) ? slots : (1L << 22), (long)nrp);
    }

    /* incoming scattering links, sources ascending (FULL scattering) */
    {
        int n = gp->ps.n;
        size_t nl = (size_t)n * (size_t)gp->ns2;
        gp->rin_off = xcalloc((size_t)n + 2, sizeof(int), &st);
        gp->rin_src = xcalloc(nl, sizeof(int), &st);
        if (st != PT_OK) goto fail;
        gi_links_reverse_count(gp->slink, n, gp->ns2, NULL, gp->rin_off);
        gi_links_reverse_fill(gp->slink, n, gp->ns2, NULL, gp->rin_off, gp->rin_src);
    }

    tg = timer_now();
    st = gi_dev_set_particles(gp->dev, gp->ps.p, gp->ps.n, gp->slink, gp->ns2, gp->glink, gp->ng, d);
    if (st == PT_OK) st = gi_dev_set_lists(gp->dev, gp->lists.off, (int)gp->lists.nrp, gp->lists.idx, d);
    if (st == PT_OK) st = gi_dev_set_reverse(gp->dev, gp->rin_off, gp->rin_src, d);
    if (st == PT_OK && set->scatter != GI_PARTICLE_SCATTER_FULL) st = build_walk(gp, set->bounces - 1, d);
    if (st != PT_OK) goto fail;
    S->t_upload = timer_now() - tg;
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
        cell_batch_free(gp->tc[t].cb);
    }
    free(gp->slink);
    free(gp->glink);
    free(gp->rin_off);
    free(gp->rin_src);
    free(gp->lights);
    free(gp->vis);
    free(gp->vis_lights);
    free(gp->dirty);
    free(gp->edir);
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
    free(gp);
}

const gi_particle_stats *gi_particle_get_stats(gi_particle *gp)
{
    fill_stats(gp, NULL);
    return &gp->st;
}

/* ------------------------------------------------------------------ lighting */

static void pack_light(const scene_light *l, gi_dev_light *o)
{
    memset(o, 0, sizeof *o);
    o->pos[0] = (float)l->position.x;
    o->pos[1] = (float)l->position.y;
    o->pos[2] = (float)l->position.z;
    o->kind = l->kind == LIGHT_SPOT ? GI_LIGHT_SPOT
              : l->kind == LIGHT_CYLINDER ? GI_LIGHT_CYLINDER
              : l->kind == LIGHT_PARALLEL ? GI_LIGHT_PARALLEL
                                          : GI_LIGHT_POINT;
    o->colour[0] = (float)l->colour.r;
    o->colour[1] = (float)l->colour.g;
    o->colour[2] = (float)l->colour.b;
    o->parallel = l->parallel;
    o->point_at[0] = (float)l->point_at.x;
    o->point_at[1] = (float)l->point_at.y;
    o->point_at[2] = (float)l->point_at.z;
    o->tightness = (float)l->tightness;
    o->cos_radius = (float)cos(l->radius * M_PI / 180.0);
    o->cos_falloff = (float)cos(l->falloff * M_PI / 180.0);
    o->radius = (float)l->radius;
    o->falloff = (float)l->falloff;
    o->fade_distance = (float)l->fade_distance;
    o->fade_power = (float)l->fade_power;
    o->shadowless = l->shadowless;
}

typedef struct {
    gi_particle *gp;
    double eps;
    atomic_long rays;
} vis_job;

#define VIS_CHUNK 256

/* The shadow rays of one chunk and light, traced together
 * (accel_occluded_n: Embree packets of 16). */
typedef struct {
    vec3 *org, *dir;
    double *tmin, *tmax;
    int *owner; /* particle index within the chunk */
    unsigned char *hit;
    int n, cap;
} ray_batch;

static int batch_add(ray_batch *b, vec3 org, vec3 dir, double tmin, double tmax, int owner)
{
    if (b->n == b->cap) {
        int cap = b->cap ? 2 * b->cap : 1024;
        vec3 *o = realloc(b->org, (size_t)cap * sizeof *o);
        if (o) b->org = o;
        vec3 *d = realloc(b->dir, (size_t)cap * sizeof *d);
        if (d) b->dir = d;
        double *t0 = realloc(b->tmin, (size_t)cap * sizeof *t0);
        if (t0) b->tmin = t0;
        double *t1 = realloc(b->tmax, (size_t)cap * sizeof *t1);
        if (t1) b->tmax = t1;
        int *w = realloc(b->owner, (size_t)cap * sizeof *w);
        if (w) b->owner = w;
        unsigned char *h = realloc(b->hit, (size_t)cap);
        if (h) b->hit = h;
        if (!o || !d || !t0 || !t1 || !w || !h) return 0;
        b->cap = cap;
    }
    b->org[b->n] = org;
    b->dir[b->n] = dir;
    b->tmin[b->n] = tmin;
    b->tmax[b->n] = tmax;
    b->owner[b->n] = owner;
    b->n++;
    return 1;
}

static void batch_free(ray_batch *b)
{
    free(b->org);
    free(b->dir);
    free(b->tmin);
    free(b->tmax);
    free(b->owner);
    free(b->hit);
}

/* A shadow ray from p towards a light point at `depth` along dir: 1 (seen,
 * no ray needed: the point is within eps) or queued (0). The ray stops
 * 1e-5 x depth short of the light (as the path tracer's pm_nee.c): a light
 * lying in a surface's plane (cornell.pov's lights in its ceiling) must not
 * be shadowed by that surface, and Embree's single-precision t there is
 * off by ~2e-6 x depth, more than the 1e-6 x depth this used to leave. */
static int shadow_ray(ray_batch *b, vec3 p, vec3 dir, double depth, double eps, int owner, const accel *a)
{
    double tmax = depth - fmax(eps, depth * 1e-5);
    if (tmax <= eps) return 1;
    if (!batch_add(b, p, dir, eps, tmax, owner)) return accel_occluded(a, p, dir, eps, tmax) ? 0 : 1;
    return 0;
}

static void vis_chunk(void *ctx, int chunk, int thread)
{
    (void)thread;
    vis_job *J = ctx;
    gi_particle *gp = J->gp;
    if (gp->cancel && *gp->cancel) return; /* superseded: the rest of the chunks are skipped */
    const scene *sc = gp->sc;
    int n = gp->ps.n, nl = gp->nlights;
    int i0 = chunk * VIS_CHUNK, i1 = i0 + VIS_CHUNK < n ? i0 + VIS_CHUNK : n;
    long rays = 0;
    float att[VIS_CHUNK], seen[VIS_CHUNK];
    int m_of[VIS_CHUNK];
    ray_batch B = {0};
    for (int li = 0; li < nl; li++) {
        if (!gp->dirty[li]) continue;
        const scene_light *l = &sc->lights[li];
        const gi_dev_light *dl = &gp->lights[li];
        int last_patch = -1, reaches = 0;
        B.n = 0;
        for (int i = i0; i < i1; i++) {
            int o = i - i0;
            const gi_dev_particle *pt = &gp->ps.p[i];
            vec3 nrm = v3(pt->n[0], pt->n[1], pt->n[2]);
            vec3 org = v3_madd(v3(pt->p[0], pt->p[1], pt->p[2]), nrm, J->eps);
            float d[3];
            float depth = gi_light_ray(dl, dl->pos[0], dl->pos[1], dl->pos[2], pt->p[0], pt->p[1], pt->p[2], d);
            float ci = pt->n[0] * d[0] + pt->n[1] * d[1] + pt->n[2] * d[2];
            att[o] = ci >= 1e-10f ? gi_light_attenuation(dl, pt->p[0], pt->p[1], pt->p[2], d, depth) : 0.0f;
            seen[o] = 0.0f;
            m_of[o] = 1;
            if (!(att[o] > 0.0f)) continue;
            /* light_group: no light on objects the light does not reach (as
             * shade.c); a chunk's particles mostly share a few patches */
            if (gp->ps.patch[i] != last_patch) {
                last_patch = gp->ps.patch[i];
                reaches = scene_light_reaches(l, gi_surface_object(gp->surf, last_patch));
            }
            if (!reaches) {
                att[o] = 0.0f;
                continue;
            }
            if (l->shadowless) {
                seen[o] = 1.0f;
            } else if (l->area && l->size1 * l->size2 > 1) {
                vec3 ax1 = l->axis1, ax2 = l->axis2;
                if (l->orient) scene_light_orient_axes(l, v3(d[0], d[1], d[2]), &ax1, &ax2);
                rng r;
                rng_seed(&r, gp->set.seed ^ 0xa11ULL, (uint64_t)i * 131u + (uint64_t)li);
                int total = l->size1 * l->size2;
                int m = gp->set.area_samples > 0 && gp->set.area_samples < total ? gp->set.area_samples : total;
                /* a subset: every (total/m)-th grid point from a random start */
                double stride = (double)total / m, start = rng_f64(&r) * stride;
                for (int k = 0; k < m; k++) {
                    int g = m == total ? k : (int)(start + k * stride);
                    if (g >= total) g = total - 1;
                    int u = g % l->size1, vv = g / l->size1;
                    vec3 c = v3_add(l->position, scene_light_area_point(l, ax1, ax2, u, vv, &r));
                    float dd[3];
                    float dep = gi_light_ray(dl, (float)c.x, (float)c.y, (float)c.z, pt->p[0], pt->p[1], pt->p[2], dd);
                    seen[o] += (float)shadow_ray(&B, org, v3(dd[0], dd[1], dd[2]), dep, J->eps, o, gp->a);
                    rays++;
                }
                m_of[o] = m;
            } else {
                seen[o] = (float)shadow_ray(&B, org, v3(d[0], d[1], d[2]), depth, J->eps, o, gp->a);
                rays++;
            }
        }
        if (B.n > 0) accel_occluded_n(gp->a, B.n, B.org, B.dir, B.tmin, B.tmax, B.hit);
        for (int k = 0; k < B.n; k++)
            if (!B.hit[k]) seen[B.owner[k]] += 1.0f;
        /* gi_k_emit reads att * V, V the fraction of the light seen */
        for (int i = i0; i < i1; i++) {
            int o = i - i0;
            gp->vis[(size_t)i * nl + li] = att[o] > 0.0f ? att[o] * (seen[o] / (float)m_of[o]) : 0.0f;
        }
    }
    batch_free(&B);
    atomic_fetch_add(&J->rays, rays);
}

/* Whether two lights cast the same shadows on the particles (everything
 * but the colour: visibility also skips particles the attenuation zeroes). */
static int same_geometry(const scene_light *a, const scene_light *b)
{
    return a->kind == b->kind && v3_len2(v3_sub(a->position, b->position)) == 0.0 &&
           v3_len2(v3_sub(a->point_at, b->point_at)) == 0.0 && a->radius == b->radius && a->falloff == b->falloff &&
           a->tightness == b->tightness && a->parallel == b->parallel && a->area == b->area &&
           v3_len2(v3_sub(a->axis1, b->axis1)) == 0.0 && v3_len2(v3_sub(a->axis2, b->axis2)) == 0.0 &&
           a->size1 == b->size1 && a->size2 == b->size2 && a->jitter == b->jitter && a->circular == b->circular &&
           a->orient == b->orient && a->area_illumination == b->area_illumination &&
           a->fade_distance == b->fade_distance && a->fade_power == b->fade_power && a->shadowless == b->shadowless;
}

static void reset_view(gi_particle *gp)
{
    /* no hook runs now (the stages are not run during a render): relaxed
     * stores, plain byte writes instead of a locked exchange each */
    size_t n = (size_t)gp->ps.n, nrp = (size_t)gp->lists.nrp;
    for (size_t i = 0; i < n; i++) atomic_store_explicit(&gp->e_state[i], 0, memory_order_relaxed);
    memset(gp->dev_gathered, 0, n);
    for (size_t l = 0; l < nrp; l++) atomic_store_explicit(&gp->rp_state[l], 0, memory_order_relaxed);
    atomic_thread_fence(memory_order_release);
}

pt_status gi_particle_light(gi_particle *gp, diag *d)
{
    double t0 = timer_now();
    const scene *sc = gp->sc;
    gi_particle_stats *S = &gp->st;
    int n = gp->ps.n;
    pt_status st = PT_OK;
    /* lights and visibility (host, Embree shadow rays); a light whose
     * geometry did not change since the last lighting stage (only its
     * colour, say) keeps its visibility */
    progress_stage(gp->set.progress, "gi lighting: visibility", 0);
    double tv = timer_now();
    int nl = sc->nlights;
    if (nl != gp->nlights) {
        free(gp->lights);
        free(gp->vis);
        free(gp->vis_lights);
        free(gp->dirty);
        gp->lights = xcalloc((size_t)nl, sizeof *gp->lights, &st);
        gp->vis = xcalloc((size_t)n * (size_t)(nl > 0 ? nl : 1), sizeof(float), &st);
        gp->vis_lights = xcalloc((size_t)nl, sizeof *gp->vis_lights, &st);
        gp->dirty = xcalloc((size_t)nl, 1, &st);
        if (st != PT_OK) {
            gp->nlights = 0;
            return st;
        }
        gp->nlights = nl;
        for (int l = 0; l < nl; l++) gp->dirty[l] = 1;
    }
    int ndirty = 0;
    for (int l = 0; l < nl; l++) {
        pack_light(&sc->lights[l], &gp->lights[l]);
        if (!gp->dirty[l] && !same_geometry(&gp->vis_lights[l], &sc->lights[l])) gp->dirty[l] = 1;
        ndirty += gp->dirty[l];
    }
    vis_job J;
    J.gp = gp;
    J.eps = 1e-6 * (accel_eps_scale(gp->a) > 0.0 ? accel_eps_scale(gp->a) : 1.0);
    atomic_init(&J.rays, 0);
    if (ndirty > 0 && n > 0) pool_run(gp->threads, (n + VIS_CHUNK - 1) / VIS_CHUNK, vis_chunk, &J);
    if (gp->cancel && *gp->cancel) {
        /* cancelled during (or before) the visibility pass: nothing the
         * indirect hook reads has changed yet (edir, src, lout, phi, the
         * view's gathered values), so the previous lighting stays in place;
         * the lights stay dirty and the next call traces them again */
        S->t_visibility = timer_now() - tv;
        return PT_OK;
    }
    for (int l = 0; l < nl; l++) {
        gp->vis_lights[l] = sc->lights[l];
        gp->dirty[l] = 0;
    }
    S->shadow_rays = atomic_load(&J.rays);
    S->t_visibility = timer_now() - tv;

    /* emission, scattering and radiance on the device (gi_lighting.cl):
     * cancellable before each kernel, and then nothing the view reads has
     * changed (gi_dev_lighting writes edir, lout, phi only at its end) */
    int nb = gp->set.bounces, full = gp->set.scatter == GI_PARTICLE_SCATTER_FULL;
    if (!full && nb - 1 > gp->nwalk) {
        st = build_walk(gp, nb - 1, d);
        if (st != PT_OK) return st;
    }
    double kt[2] = {0.0, 0.0};
    int done = 0;
    /* stats sums (direct, emitted and scattered flux, grey; the particles
     * that send light in the first bounce) come from the kernels' partial
     * sums: no pass over the particles here. The device keeps edir and phi
     * until gi_particle_debug asks (gi_dev_fetch). */
    gi_dev_sums sums;
    progress_stage(gp->set.progress, "gi lighting: emit and scatter", 0);
    st = gi_dev_lighting(gp->dev, gp->lights, gp->nlights, gp->vis, ndirty > 0,
                         full ? GI_SCATTER_FULL : GI_SCATTER_WALK, nb, gp->cancel, gp->edir, gp->lout, gp->phi,
                         gp->bounce_flux, &sums, &done, kt, d);
    if (st != PT_OK) return st;
    if (!done) return PT_OK; /* cancelled: the previous lighting stays */
    S->t_emit = kt[0];
    S->t_scatter = kt[1];
    gp->nbounce_flux = nb;
    S->sources = sums.sources;
    S->flux_direct = sums.direct;
    S->flux_emitted = sums.emitted;
    S->flux_scattered = sums.scattered;
    reset_view(gp);
    gp->lit = 1;
    S->t_lighting = timer_now() - t0;
    return PT_OK;
}

pt_status gi_particle_relight(gi_particle *gp, diag *d) { return gi_particle_light(gp, d); }

void gi_particle_set_cancel(gi_particle *gp, volatile int *cancel) { gp->cancel = cancel; }

void gi_particle_set_scattering(gi_particle *gp, int bounces, int scatter)
{
    gp->set.bounces = bounces < 0 ? 0 : (bounces > GI_MAX_BOUNCES ? GI_MAX_BOUNCES : bounces);
    gp->set.scatter = scatter;
    gp->st.bounces = gp->set.bounces;
}

/* ------------------------------------------------------------------ the view */

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

/* keep_hits: what the pre-pass found at one pixel's camera ray, for the
 * render (gi_particle_primary_hit) and its hook (side_value). */
typedef struct view_rec {
    accel_hit h;           /* first member: the hook knows &rec->h as a kept hit */
    vec3 org, dir;         /* the ray, compared bit for bit with the render's */
    double w[3];           /* gi_surface_locate's answer for side `side` */
    long rp[3];
    unsigned char kind;    /* 0 nothing kept (the render traces), 1 a miss, 2 a hit */
    unsigned char located; /* rp, w hold locate's answer */
    unsigned char side;    /* the side located: dot(n_view, h.ng) >= 0 */
    unsigned char verdict; /* the light-leak guard's verdict on that cell (GI_CELL_*, UNKNOWN: the hook decides) */
} view_rec;

/* The first frame's cell tests, batched (kept hits). The pre-pass meets
 * most cells for the first time in the first frame after a geometry stage
 * (maze: ~49,000 cells, 6 segments each, traced one by one with
 * accel_intersect). A pre-pass thread instead collects the untested cells
 * of its row here (each once: a small hash by key) with the records that
 * lie in them, and at the row's end traces the six segments of all of
 * them together as coherent packets (accel_hit_any_n: neighbouring cells'
 * short segments) that only ask whether anything lies on a segment. A
 * segment with nothing on it is visible (gi_visible traces no further);
 * one with something gets gi_visible's own test (gi_visible_along, the
 * same ray and rule as cell_clear's). So every verdict is cell_clear's; it
 * is written into the row's records, put in the table and in the thread's
 * small cache of recent verdicts (seen: the next rows meet most of these
 * cells again, and a table probe is a cache and TLB miss). A cell not in
 * that cache goes into the batch, which asks the table first (all the
 * row's probes prefetched together: cells another thread tested). Rows go
 * to the threads in bands (VIEW_BAND), so the row after a row is mostly the
 * same thread's. */
#define BATCH_HASH 512 /* slots of a row's hash of cells (a row of maze at 512 pixels meets ~100 new ones) */
#define BATCH_SEEN 4096 /* the thread's verdicts of the last rows, direct-mapped (32 KiB) */
typedef struct {
    uint64_t key;
    long rp[3];
    const scene_object *own;
    int verdict; /* tested (or the table's) */
    int known;   /* the table's verdict (another thread's test), UNKNOWN: tested here */
} batch_cell_t;

typedef struct {
    view_rec *vr;
    int cell;
} batch_pix_t;

struct cell_batch {
    batch_cell_t *cell;
    int ncell, capcell;
    batch_pix_t *pix;
    int npix, cappix;
    int slot[BATCH_HASH]; /* 1 + index in cell, 0: empty; more cells than slots/2: no hash, linear */
    uint64_t seen[BATCH_SEEN]; /* key << 2 | verdict of cells this thread tested (the next rows meet
                                  them again): no probe of the table (a cache miss each) */
    /* the segments of a test: ray k is segment sg[k] of cell owner[k] */
    gi_segment *sg;
    vec3 *org, *dir;
    double *tmin, *tmax;
    unsigned char *hit;
    int *owner;
    int capray;
};

/* One pre-pass thread's row of kept hits: its counters (cell tests) and
 * the last cell's key and verdict (neighbouring pixels often share a cell:
 * no table probe); b: the thread's batch of cells to test at the row's end
 * (NULL: each is tested when met), and pend the last cell's place in it
 * when its verdict is CELL_PENDING. */
typedef struct {
    thread_count *tc;
    uint64_t key;
    int verdict;
    struct cell_batch *b;
    int pend;
} view_memo;

/* kept_verdict's answer for a cell in the row's batch (never stored in a
 * record or the table: the batch writes the verdict at the row's end) */
#define CELL_PENDING 3

static int cell_clear(gi_particle *gp, const long rp[3], const scene_object *own, thread_count *tc);
static int batch_cell(struct cell_batch *b, uint64_t key, const long rp[3], const scene_object *own);
static unsigned batch_seen_slot(uint64_t key) { return (unsigned)((key * 0x9e3779b97f4a7c15ULL) >> 52); }
static int batch_pixel(struct cell_batch *b, view_rec *vr, int cell);
static void batch_test(gi_particle *gp, struct cell_batch *b, thread_count *tc);

/* The memo of a pre-pass row; with kept hits and the table, the thread's
 * batch of cell tests (NULL when out of memory: tested when met). */
static view_memo row_memo(gi_particle *gp, const view_rec *rec, int thread)
{
    view_memo m = {&gp->tc[thread < GI_MAX_THREADS ? thread : 0], 0, GI_CELL_UNKNOWN, NULL, -1};
    if (rec && gp->cells) {
        if (!m.tc->cb) m.tc->cb = calloc(1, sizeof *m.tc->cb);
        m.b = m.tc->cb;
    }
    return m;
}

/* The light-leak guard's verdict on cell rp (key: gi_cellvis_key) of a hit
 * on `own`: the table's, else tested now (cell_clear) and put in the table;
 * GI_CELL_UNKNOWN without a key (no table: the caller tests per hit). */
static int cell_verdict(gi_particle *gp, uint64_t key, const long rp[3], const scene_object *own, thread_count *tc)
{
    int verdict = gi_cellvis_get(gp->cells, key);
    if (verdict == GI_CELL_UNKNOWN && key) {
        verdict = cell_clear(gp, rp, own, tc) ? GI_CELL_CLEAR : GI_CELL_BLOCKED;
        gi_cellvis_put(gp->cells, key, verdict);
    }
    return verdict;
}

/* The verdict side_value would take for the cell rp of a hit on `own`
 * (tested now when the table has none): the same test, moved to the
 * pre-pass. Before the table (a cache miss a probe), the previous pixel's
 * cell and what this pixel's record held from an earlier frame (rp and
 * verdict are written together, a verdict depends on the cell alone). */
static int kept_verdict(gi_particle *gp, const long rp[3], const scene_object *own, view_memo *m, view_rec *old)
{
    uint64_t key = gi_cellvis_key(gp->cells, rp);
    if (!key) return GI_CELL_UNKNOWN;
    if (key == m->key) {
        /* a cell waiting in the batch: this record gets its verdict too */
        if (m->verdict == CELL_PENDING)
            return batch_pixel(m->b, old, m->pend) ? GI_CELL_UNKNOWN : cell_verdict(gp, key, rp, own, m->tc);
        return m->verdict;
    }
    if (old->verdict != GI_CELL_UNKNOWN && old->rp[0] == rp[0] && old->rp[1] == rp[1] && old->rp[2] == rp[2]) {
        m->key = key;
        m->verdict = old->verdict;
        return old->verdict;
    }
    int verdict = GI_CELL_UNKNOWN;
    if (m->b) {
        uint64_t v = m->b->seen[batch_seen_slot(key)];
        if (v >> 2 == key) verdict = (int)(v & 3u);
    }
    if (verdict == GI_CELL_UNKNOWN && m->b) {
        /* not tested by this thread lately: into the row's batch
         * (cell_batch), which asks the table first; the record's verdict
         * is written when the batch is done */
        int i = batch_cell(m->b, key, rp, own);
        if (i >= 0 && batch_pixel(m->b, old, i)) {
            m->key = key;
            m->verdict = CELL_PENDING;
            m->pend = i;
            return GI_CELL_UNKNOWN;
        }
    }
    if (verdict == GI_CELL_UNKNOWN) verdict = cell_verdict(gp, key, rp, own, m->tc);
    m->key = key;
    m->verdict = verdict;
    return verdict;
}

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
    if (!gi_surface_locate(gp->surf, h, n, rp, w)) return 0;
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
        int verdict = located && gp->cells ? kept_verdict(gp, cell, h.obj, m, vr) : GI_CELL_UNKNOWN;
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
    view_memo m = row_memo(J->gp, J->rec, thread);
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
    batch_test(J->gp, m.b, m.tc);
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
    view_memo m = row_memo(gp, J->rec, thread);
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
                accel_hit hh;
                memset(&hh, 0, sizeof hh);
                hh.t = t;
                hh.p = v3_madd(org, dir, t);
                hh.ng = b->ng;
                hh.ns = b->ng;
                hh.obj = b->obj;
                hh.prim = b->prim;
                long rp[3];
                double w[3];
                mark_hit(gp, &hh, b->n, rp, w);
            }
            continue;
        }
        rays += prepass_ray(gp, org, dir, 1, J->max_level, J->eps, NULL, vr, &m);
        kept += vr && vr->kind;
    }
    batch_test(gp, m.b, m.tc);
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
    double sc = accel_eps_scale(gp->a);
    J.eps = (sc > 0.0 && isfinite(sc) ? sc : 1.0) * 1e-6;
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
            /* zero: no record holds a verdict yet (kept_verdict) */
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
        pool_run(gp->threads, (J.ncy + VIEW_BAND - 1) / VIEW_BAND, coarse_band, &J);
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
    st = gi_dev_gather(gp->dev, used, nused, gp->bg, gp->eind, d);
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
        for (int c = 0; c < 3; c++) gp->rp_val[4 * l + c] = empty ? gp->bg[c] : vout[4 * t + c];
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

/* ------------------------------------------------------------------ the hook */

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

static void late_rp(gi_particle *gp, long l, thread_count *tc)
{
    if (!claim(&gp->rp_state[l])) return;
    tc->late_rp++;
    int lo = gp->lists.off[l], hi = gp->lists.off[l + 1];
    for (int q = lo; q < hi; q++) {
        int m = gp->lists.idx[q];
        if (claim(&gp->e_state[m])) {
            /* the gathering kernel, C build, on this thread */
            gi_c_gather(1, gp->glink, gp->ng, gp->lout, &m, 1, gp->bg, gp->eind);
            atomic_store_explicit(&gp->e_state[m], 2, memory_order_release);
            tc->late_area++;
        }
    }
    int li = (int)l;
    float v[4];
    gi_c_estimate(1, gp->ps.p, gp->lists.off, gp->lists.idx, gp->eind, &li, 1, v);
    for (int c = 0; c < 3; c++) gp->rp_val[4 * l + c] = lo == hi ? gp->bg[c] : v[c];
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
            gi_c_gather(1, gp->glink, gp->ng, gp->lout, &k, 1, gp->bg, gp->eind);
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

/* Whether every point of the cell (the sub-triangle of radiance particles
 * rp, on object own) sees its three vertices, as side_value's per-hit test
 * (gi_visible, the same eps and object rule) would find: tested once per
 * cell on six segments, the three edges and the three from the centroid
 * (normal: the mean of the vertices') to each vertex. An object that cuts
 * the (lifted) cell anywhere crosses an edge, or encloses the centroid and
 * so crosses a spoke (a box standing on the floor, a wall across a cell).
 * What this gives up: an occluder whose cross-section at the lifted cell
 * lies entirely inside it and misses the three spokes (a thin post standing
 * inside one floor cell; on a curved cell, something touching the surface
 * between the chords, e.g. the floor under a sphere resting on it, within
 * the one cell around the contact point). Hits there interpolate all three
 * vertices where the per-hit test dropped some: light from a vertex on the
 * far side of the post, never from inside a closed solid the cell's
 * vertices are outside of.
 * The segments run between the vertices moved 1e-3 of the way to the
 * centroid (CELL_SHRINK): a wall standing on the cell's edge (a floor cell
 * along the foot of a wall, the wall's cells along the floor) touches the
 * exact edge and its grazing rays, and made 5.7% of cbox's cells blocked
 * (0.7% with the margin: the cells its two blocks stand across; maze 6.1% ->
 * 2.7%); the per-hit test there had kept all three vertices but at the odd
 * hit (cbox's mean luminance -0.02%). Given up with it: an occluder within
 * that margin of the edge, parallel to it. */
#define CELL_SHRINK 1e-3

/* The ends of cell rp's six segments: its vertices q (moved CELL_SHRINK of
 * the way to the centroid) with their normals nq, the centroid c with the
 * vertices' mean normal nc. Segment 2k is the edge q[k] -> q[k+1 mod 3],
 * 2k+1 the spoke c -> q[k]. */
static void cell_ends(const gi_particle *gp, const long rp[3], vec3 q[3], vec3 nq[3], vec3 *cp, vec3 *ncp)
{
    vec3 c = v3(0, 0, 0), nc = v3(0, 0, 0);
    for (int k = 0; k < 3; k++) {
        gi_surface_rp(gp->surf, rp[k], &q[k], &nq[k]);
        c = v3_madd(c, q[k], 1.0 / 3.0);
        nc = v3_add(nc, nq[k]);
    }
    nc = v3_len2(nc) > 0.0 ? v3_norm(nc) : nq[0];
    for (int k = 0; k < 3; k++) q[k] = v3_madd(q[k], v3_sub(c, q[k]), CELL_SHRINK);
    *cp = c;
    *ncp = nc;
}

static int cell_clear(gi_particle *gp, const long rp[3], const scene_object *own, thread_count *tc)
{
    vec3 q[3], nq[3], c, nc;
    cell_ends(gp, rp, q, nq, &c, &nc);
    tc->cells++;
    for (int k = 0; k < 3; k++) {
        int j = k + 1 < 3 ? k + 1 : 0;
        tc->vis_rays++;
        if (!gi_visible(gp->a, gp->vis_eps, q[k], nq[k], q[j], nq[j], own)) return 0;
        tc->vis_rays++;
        if (!gi_visible(gp->a, gp->vis_eps, c, nc, q[k], nq[k], own)) return 0;
    }
    tc->cells_clear++;
    return 1;
}

static void cell_batch_free(struct cell_batch *b)
{
    if (!b) return;
    free(b->cell);
    free(b->pix);
    free(b->sg);
    free(b->org);
    free(b->dir);
    free(b->tmin);
    free(b->tmax);
    free(b->hit);
    free(b->owner);
    free(b);
}

static int grow(void **p, int *cap, int need, size_t size)
{
    if (need <= *cap) return 1;
    int n = *cap > 0 ? *cap : 64;
    while (n < need) n *= 2;
    void *q = realloc(*p, (size_t)n * size);
    if (!q) return 0;
    *p = q;
    *cap = n;
    return 1;
}

/* The batch's index of cell key (added when new), -1 out of memory. */
static int batch_cell(struct cell_batch *b, uint64_t key, const long rp[3], const scene_object *own)
{
    unsigned h = (unsigned)((key * 0x9e3779b97f4a7c15ULL) >> 55) & (BATCH_HASH - 1);
    int hashed = b->ncell < BATCH_HASH / 2;
    if (hashed) {
        for (unsigned k = h;; k = (k + 1) & (BATCH_HASH - 1)) {
            int i = b->slot[k] - 1;
            if (i < 0) break;
            if (b->cell[i].key == key) return i;
        }
    } else {
        for (int i = b->ncell - 1; i >= 0; i--)
            if (b->cell[i].key == key) return i;
    }
    if (!grow((void **)&b->cell, &b->capcell, b->ncell + 1, sizeof *b->cell)) return -1;
    int i = b->ncell++;
    b->cell[i].key = key;
    for (int k = 0; k < 3; k++) b->cell[i].rp[k] = rp[k];
    b->cell[i].own = own;
    b->cell[i].verdict = GI_CELL_CLEAR;
    b->cell[i].known = GI_CELL_UNKNOWN;
    if (hashed) {
        unsigned k = h;
        while (b->slot[k]) k = (k + 1) & (BATCH_HASH - 1);
        b->slot[k] = i + 1;
    }
    return i;
}

/* Record vr lies in the batch's cell: 1, or 0 out of memory. */
static int batch_pixel(struct cell_batch *b, view_rec *vr, int cell)
{
    if (!grow((void **)&b->pix, &b->cappix, b->npix + 1, sizeof *b->pix)) return 0;
    b->pix[b->npix].vr = vr;
    b->pix[b->npix].cell = cell;
    b->npix++;
    return 1;
}

/* Tests the batch's cells (the verdicts cell_clear gives), stores them in
 * the table and the waiting records; empties the batch. */
static void batch_test(gi_particle *gp, struct cell_batch *b, thread_count *tc)
{
    if (!b || b->ncell == 0) return;
    int nr = 0, ok = 1;
    int need = 6 * b->ncell;
    if (need > b->capray) {
        int cap = b->capray;
        ok = grow((void **)&b->sg, &cap, need, sizeof *b->sg);
        cap = b->capray;
        ok = ok && grow((void **)&b->org, &cap, need, sizeof *b->org);
        cap = b->capray;
        ok = ok && grow((void **)&b->dir, &cap, need, sizeof *b->dir);
        cap = b->capray;
        ok = ok && grow((void **)&b->tmin, &cap, need, sizeof *b->tmin);
        cap = b->capray;
        ok = ok && grow((void **)&b->tmax, &cap, need, sizeof *b->tmax);
        cap = b->capray;
        ok = ok && grow((void **)&b->hit, &cap, need, sizeof *b->hit);
        cap = b->capray;
        ok = ok && grow((void **)&b->owner, &cap, need, sizeof *b->owner);
        if (ok) b->capray = cap;
    }
    if (ok) {
        /* the table's verdicts first (cells another thread tested): all the
         * probes' cache misses at once, as are the radiance particles' */
        for (int c = 0; c < b->ncell; c++) {
            gi_cellvis_prefetch(gp->cells, b->cell[c].key);
            for (int k = 0; k < 3; k++) gi_surface_rp_prefetch(gp->surf, b->cell[c].rp[k]);
        }
        for (int c = 0; c < b->ncell; c++) {
            b->cell[c].known = gi_cellvis_get(gp->cells, b->cell[c].key);
            if (b->cell[c].known != GI_CELL_UNKNOWN) b->cell[c].verdict = b->cell[c].known;
        }
        for (int c = 0; c < b->ncell; c++) {
            if (b->cell[c].known != GI_CELL_UNKNOWN) continue;
            vec3 q[3], nq[3], ctr, nc;
            cell_ends(gp, b->cell[c].rp, q, nq, &ctr, &nc);
            for (int k = 0; k < 3; k++) {
                int j = k + 1 < 3 ? k + 1 : 0;
                /* cell_clear's order: the edge from q[k], the spoke to q[k] */
                if (gi_visible_segment(gp->a, gp->vis_eps, q[k], nq[k], q[j], nq[j], &b->sg[nr])) b->owner[nr++] = c;
                if (gi_visible_segment(gp->a, gp->vis_eps, ctr, nc, q[k], nq[k], &b->sg[nr])) b->owner[nr++] = c;
            }
        }
        for (int r = 0; r < nr; r++) {
            b->org[r] = b->sg[r].p;
            b->dir[r] = b->sg[r].d;
            b->tmin[r] = 0.0;
            b->tmax[r] = b->sg[r].len;
        }
        accel_hit_any_n(gp->a, nr, b->org, b->dir, b->tmin, b->tmax, b->hit);
        for (int r = 0; r < nr; r++) {
            batch_cell_t *bc = &b->cell[b->owner[r]];
            if (!b->hit[r] || bc->verdict != GI_CELL_CLEAR) continue;
            if (!gi_visible_along(gp->a, gp->vis_eps, &b->sg[r], bc->own)) bc->verdict = GI_CELL_BLOCKED;
        }
        tc->vis_rays += nr;
        for (int c = 0; c < b->ncell; c++) {
            if (b->cell[c].known != GI_CELL_UNKNOWN) continue;
            tc->cells++;
            tc->cells_clear += b->cell[c].verdict == GI_CELL_CLEAR;
            gi_cellvis_put(gp->cells, b->cell[c].key, b->cell[c].verdict);
        }
        for (int c = 0; c < b->ncell; c++)
            b->seen[batch_seen_slot(b->cell[c].key)] = b->cell[c].key << 2 | (uint64_t)b->cell[c].verdict;
    } else {
        /* no memory for the rays: one cell at a time */
        for (int c = 0; c < b->ncell; c++)
            b->cell[c].verdict = cell_verdict(gp, b->cell[c].key, b->cell[c].rp, b->cell[c].own, tc);
    }
    for (int k = 0; k < b->npix; k++) b->pix[k].vr->verdict = (unsigned char)b->cell[b->pix[k].cell].verdict;
    b->ncell = 0;
    b->npix = 0;
    memset(b->slot, 0, sizeof b->slot);
}

/* E/pi on the side of the hit that n faces: barycentric interpolation of
 * the radiance particles around it, or the estimate at the hit on surfaces
 * without radiance particles. 0 when that side has no particles. */
static int side_value(gi_particle *gp, const accel_hit *hit, vec3 n, thread_count *tc, rgb *out)
{
    long rp[3];
    double w[3];
    out->r = out->g = out->b = 0.0;
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
        verdict = kr->verdict; /* decided in the pre-pass (kept_verdict) */
    else
        verdict = cell_verdict(gp, gi_cellvis_key(gp->cells, rp), rp, hit->obj, tc);
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
    if (!(wsum > 0.0)) return 0;
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
    if (!gp->lit || !side_value(gp, hit, n, tc, &out)) {
        tc->none++;
        out.r = out.g = out.b = 0.0;
        return out;
    }
    /* finish { diffuse A, B } (3.7's backside diffuse, shade_material.h:
     * kb/pi for light arriving from the other side): shade.c multiplies the
     * hook by diffuse, so the other side's E/pi enters scaled by B / A.
     * Only at this last bounce: the particles themselves reflect with
     * diffuse alone (the lighting kernels keep the sides apart). */
    const scene_texture *tex = hit->texture ? hit->texture : &gp->sc->default_texture;
    const scene_finish *f = &tex->finish;
    if (f->diffuse_back != 0.0 && f->diffuse > 0.0) {
        rgb back;
        if (side_value(gp, hit, v3_neg(n), tc, &back)) {
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

int gi_particle_debug_links(const gi_particle *gp, const int **slink, int *ns2, const int **glink, int *ng)
{
    if (slink) *slink = gp->slink;
    if (ns2) *ns2 = gp->ns2;
    if (glink) *glink = gp->glink;
    if (ng) *ng = gp->ng;
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
