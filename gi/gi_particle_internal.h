/* gi_particle_internal.h - the particle GI mode's state, shared by the
 * files of its stages (gi_particle.c: settings, geometry stage, stats and
 * debug access; gi_particle_light.c: the lighting stage; gi_particle_view.c:
 * the view pre-pass; gi_particle_cells.c: the light-leak guard's cell tests;
 * gi_particle_hook.c: the render's hooks). Not for use outside them. */
#ifndef PT_GI_PARTICLE_INTERNAL_H
#define PT_GI_PARTICLE_INTERNAL_H
#include <stdatomic.h>
#include <stdint.h>
#include "gi_cellvis.h"
#include "gi_cl.h"
#include "gi_links.h"
#include "gi_particle.h"
#include "gi_area_particles.h"
#include "gi_radiance.h"
#include "gi_surface.h"

#define GI_MAX_THREADS 256

typedef struct {
    long lookups, late, none, discarded, onthefly, vis_rays;
    long late_rp, late_area;        /* radiance / area particles computed in the hook (late_rp) */
    long cells, cells_clear, clear; /* cells tested, of them clear; lookups in clear cells */
    long kept;                      /* lookups whose cell came from a kept hit (view_rec) */
    long gathered;                  /* lookups the final gather answered */
    long gathered_here;             /* of them, hits that gathered themselves (gi_gatherer) */
    int *buf; /* on-the-fly estimation list */
    long len, cap;
    struct cell_batch *cb; /* the pre-pass's cell tests waiting for the row's end (cell_batch) */
} thread_count;

/* Levels of the final gather's cells of points (gi_particle_gather.c). */
#define GI_VG_LEVELS 24

/* The final gather at the kept hits for one side of them
 * (gi_particle_gather.c). */
typedef struct gi_view_gather {
    int back;         /* 1: about the other side of the kept hits whose finish has diffuse_back */
    int n, k;         /* gather points, rays each */
    int m1, rk;       /* points from m1 on take rk rays, their rows packed from row m1 */
    int w, h, s;      /* for the pre-pass of this size, every s-th pixel */
    int *link;        /* n x k: the area particle each ray ends on, -1 none */
    float *esky;      /* n x 4: the sky's and far field's share (gi_links.h) */
    gi_link_conts cont; /* the rays' continuations that end on particles, by point (gi_links.h) */
    float *val;       /* n x 4: gathered E/pi */
    int *pix;         /* w x h: a pixel's gather point, -1 none */
    float *pixval;    /* w x h x 4: each kept pixel's filtered E/pi, [3] 1 where it has one */
    vec3 *nrm;        /* w x h: each kept hit's own normal on the side gathered (view_normal) */
    vec3 *pnrm;       /* w x h: the normal its gather takes and its reuse test compares: under radiosity
                         `normal on` the texture's perturbed one (normal_at), else nrm's */
    struct vg_point *pt; /* n: where each gathered (for hits that are not kept) */
    int *ids;         /* n: the points, by cell */
    struct vg_point *cpt; /* n: pt[ids[e]] at e (a cell's points read in a row) */
    struct vg_cell *tab; /* cells (hash table): runs of ids */
    size_t tab_mask;
    double c0;        /* level 0's cell size */
    unsigned levels;  /* bit L: level L has points */
    vec3 lvl_box[2 * GI_VG_LEVELS]; /* per level, the box (lo, hi) of its points */
    struct gi_gatherer *gatherer; /* gathers where no point may answer (reuse_error > 0, no bounce
                                     after the gather's hits); NULL: none */
} gi_view_gather;

struct gi_particle {
    const scene *sc;
    scene gsc;          /* settings.camera given: *sc with that camera, for the geometry stage */
    scene_camera gcam;  /* settings.camera's copy (set.camera points here) */
    const accel *a;
    gi_particle_settings set;
    int threads;
    gi_surface *surf;
    gi_particles ps;
    int ns2, ng;
    int *slink, *glink;
    gi_sky *sky;    /* what links that leave the scene see */
    float *esky;    /* n*4: the sky's and the far field's share of each particle's gather (gi_links.h) */
    void *lscene;   /* accel_rtc_link_scene, for the three link passes (freed after them) */
    gi_trilook *tl; /* the 4x4 pass's lookup by hit triangle, compacted for the 16x16 pass */
    int *rin_off, *rin_src; /* incoming scattering links (first bounce, FULL mode) */
    int *woff;              /* WALK bounces' path table (gi_particle_build_walk): n + 1 offsets */
    gi_walk_entry *went;    /* and its entries */
    int nwalk;
    gi_lists lists;
    int no_rp;      /* no radiance particles (the final gather answers the kept hits): lists empty */
    int final_only; /* gi_particle_final_only: no particles at all, the final gather answers every hit */
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
    const struct gi_caustic *caus; /* gi_particle_set_caustic: its photons are light at the particles */
    float *extra;         /* their E/pi per particle (4 floats), filled by each lighting stage */
    float *visf;          /* set.shadow: the light through transparent surfaces, n x nlights x 4 floats
                             (att times the mean filter over the shadow rays an opaque test blocked) */
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
    double vis_eps; /* gi_visible's eps: 1e-6 x accel_eps_scale */
    /* the final gather at the kept hits (gi_particle_gather.c): vgs[0]
     * about the side the camera sees, vgs[1] about the other side of the
     * kept hits on diffuse_back surfaces; vg the one being built or
     * regathered (vgs[0] outside gi_particle_gather.c's build) */
    gi_view_gather vgs[2];
    gi_view_gather *vg;
    thread_count tc[GI_MAX_THREADS];
    gi_particle_stats st;
};

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

/* The light-leak guard (gi_particle_cells.c). */
struct cell_batch;
/* The memo of a pre-pass row; with kept hits and the table, the thread's
 * batch of cell tests (NULL when out of memory: tested when met). */
view_memo gi_particle_row_memo(gi_particle *gp, const view_rec *rec, int thread);
/* The verdict the hook would take for the cell rp of a hit on `own`, moved
 * to the pre-pass (GI_CELL_UNKNOWN: waiting in the row's batch, or no key). */
int gi_particle_kept_verdict(gi_particle *gp, const long rp[3], const scene_object *own, view_memo *m, view_rec *old);
/* Tests the row's batched cells and writes their verdicts (b may be NULL). */
void gi_particle_batch_test(gi_particle *gp, struct cell_batch *b, thread_count *tc);
/* The table's verdict on cell rp (key: gi_cellvis_key), else tested now and
 * put in the table; GI_CELL_UNKNOWN without a key. */
int gi_particle_cell_verdict(gi_particle *gp, uint64_t key, const long rp[3], const scene_object *own, thread_count *tc);
void gi_particle_cell_batch_free(struct cell_batch *b);

/* The geometry stage in parts (gi_particle.c), shared by gi_particle_build
 * and gi_particle_load (gi_particle_cache.c):
 *  begin: settings clamped, sky, OpenCL device, surfaces (not yet
 *         re-tessellated); NULL with *status set on failure;
 *  then the particles (gp->ps), links (slink, glink, esky), stats
 *  spacing/tess/radius, the re-tessellation and the estimation lists
 *  (gp->lists), built or read;
 *  finish: everything derived from those (the particle grid, host state,
 *         reverse links, device upload, the WALK path table). */
gi_particle *gi_particle_begin(const scene *sc, const accel *a, const gi_particle_settings *s, diag *d,
                               pt_status *status);
pt_status gi_particle_finish(gi_particle *gp, diag *d);
/* The stats with the per-thread counters summed, copied to out (may be NULL). */
void gi_particle_fill_stats(gi_particle *gp, gi_particle_stats *out);

/* The object of each of ps's particles and the closed solid it is buried
 * in (2n pointers), and the 2n inside/buried flags (*pin), as
 * gi_links_build and gi_trilook_build take them (gi_particle.c; the
 * geometry stage, and tests/test_gi_links.c comparing the two lookups).
 * NULL with *st set when out of memory. */
const void **gi_particle_objects(const gi_particle *gp, const gi_particles *ps, unsigned char **pin,
                                 pt_status *st);

/* Particle i's own emission in channel c: its le without the sky light
 * it reflects, which the geometry stage adds to le (sky_as_emission,
 * gi_particle.c). */
float gi_particle_own_emission(const gi_particle *gp, int i, int c);
/* What the final gather's hits add to the lights' direct light: the
 * caustic layer set now and the settings' filtered shadows (gi_links.h). */
gi_hit_light gi_particle_hit_light(const gi_particle *gp);

/* Geometry stage helpers the lighting stage uses (gi_particle.c). */
/* calloc of n (at least 1) elements; sets *st to PT_ERR_NOMEM on failure. */
void *gi_particle_calloc(size_t n, size_t size, pt_status *st);
/* The WALK bounces' path table for nwalk bounces (gp->woff, gp->went). */
pt_status gi_particle_build_walk(gi_particle *gp, int nwalk, diag *d);
/* The far field's E/pi at radiance particle l, for an empty estimation list. */
void gi_particle_rp_far_field(gi_particle *gp, long l);
/* A scene light as the kernels read it (gi_types.h: gi_light_ray,
 * gi_light_attenuation); the vertex links (gi_vlinks.c) light with it too. */
void gi_light_pack(const scene_light *l, gi_dev_light *o);

/* Whether the final gather is exact (no bounce after its hits: POV-Ray's
 * recursion_limit 1) and takes POV-Ray's reuse test, so that a hit no
 * gathered point may answer gathers itself (gi_particle_gather.c). */
static inline int gi_particle_exact_gather(const gi_particle_settings *s)
{
    return s->reuse_error > 0.0 && !(s->bounces >= 1 && s->brightness > 0.0);
}

/* Whether the geometry stage builds no particles: the gather is exact and
 * answers the kept hits (keep_hits) and every other hit (the gatherer),
 * so no particle's light would reach the image; the particles' surfaces,
 * links and lighting would be work for nothing. */
static inline int gi_particle_final_only(const gi_particle_settings *s)
{
    return gi_particle_exact_gather(s) && s->view_gather_side > 0 && s->keep_hits;
}

/* gi_particle_gather.c: the final gather at the kept hits */
typedef struct vg_cell {
    uint64_t key; /* 0: empty */
    int start, count;
} vg_cell;
typedef struct vg_point {
    vec3 p, n;                /* the hit and its own normal on its side */
    vec3 pn;                  /* the normal gathered about (vg_pnrm) */
    const scene_object *obj;
    float r;                  /* it answers hits within r on its object and side */
    float reach;              /* its rays' harmonic mean hit distance, within the reuse bounds
                                 (gi_particle_settings reuse_min/max); INFINITY: unknown */
    float nearest[3];         /* the vector to its rays' nearest hit (POV-Ray's To_Nearest_Surface
                                 times Nearest_Distance); zero: none */
    int side;
} vg_point;
pt_status gi_particle_view_gather(gi_particle *gp, diag *d);
void gi_particle_view_regather(gi_particle *gp);
void gi_particle_view_gather_free(gi_particle *gp);
/* E/pi at hit on the side n faces: at a kept hit r, its gather or the mean
 * of its block's corners that match it; elsewhere (r NULL) the gather
 * points around it (gi_particle_gather.c); 0 when none answers. */
int gi_particle_view_value(const gi_particle *gp, const accel_hit *hit, const view_rec *r, vec3 n, rgb *out);
/* E/pi gathered at a hit no point may answer (the gatherer's exact
 * gather, gi_links.h); 0: no gatherer (or no memory). */
int gi_particle_gather_here(gi_particle *gp, const accel_hit *hit, vec3 n, int thread, rgb *out);
#endif
