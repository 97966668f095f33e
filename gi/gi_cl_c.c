/* gi_cl_c.c - the OpenCL kernels compiled as C (see gi_shim.h) and their
 * launchers: work-items run in chunks of GI_C_CHUNK on core/pool threads,
 * each setting the thread-local global id before calling the kernel body. */
#include "kernels/gi_shim.h"
/* The kernel program, in the order gi/CMakeLists.txt concatenates it. */
#include "kernels/gi_types.h"
#include "kernels/gi_lighting.cl"
#include "kernels/gi_gather.cl"
#include "kernels/gi_vpl_types.h"
#include "kernels/gi_vpl_real.h"
#include "glossy_lobe.h"
#include "kernels/gi_vpl.cl"
#include "kernels/gi_caustic.cl"
/* (gi_shim.h must come first; this header only declares the launchers.) */
#include "gi_cl_c.h"
#include "pool.h"

#define GI_C_CHUNK 256

typedef struct {
    int kernel;
    size_t n;
    const gi_dev_particle *part;
    int np;
    const gi_dev_light *lights;
    int nlights;
    const float *vis, *src, *edir, *lout, *eind, *esky;
    float *fout, *fout2;
    const int *glink, *idx, *list_off, *list_idx;
    int ng;
    const float *total;
    float *ftot, *tally;
    const int *off, *from;
    int obase, sbase, first, tbase, scattered, nwalk, items;
    float w_in;
    const float *rho4;
    const unsigned *mask_in, *emits;
    unsigned *mask_out;
    const gi_walk_entry *went;
    const gi_caus_photon *cph;
    const gi_caus_pixel *cpix;
    int w, h, tiles_x;
    size_t chunk;  /* work-items per pool job (0: GI_C_CHUNK) */
    const gi_dev_vpl_point *vpts;  /* gi_k_vpl_gather */
    const gi_dev_vpl_node *vnodes;
    int nvnodes, vmode;
    const float *vtabs;
    float vthr;
    int *visits;
    const float *extra; /* gi_k_emit */
    int has_extra;
} c_launch;

enum { K_EMIT, K_BOUNCE, K_WALK, K_RESOLVE, K_GATHER, K_ESTIMATE, K_VPL, K_CAUSTIC, K_BACK, K_BACK_SEND };

static void run_chunk(void *ctx, int chunk, int thread)
{
    (void)thread;
    const c_launch *a = ctx;
    size_t cs = a->chunk ? a->chunk : GI_C_CHUNK;
    size_t lo = (size_t)chunk * cs, hi = lo + cs < a->n ? lo + cs : a->n;
    for (size_t g = lo; g < hi; g++) {
        gi_shim_gid = g;
        switch (a->kernel) {
        case K_EMIT:
            gi_k_emit(a->part, a->np, a->lights, a->nlights, a->vis, a->emits, a->fout, a->fout2, a->mask_out,
                      a->tally, a->extra, a->has_extra);
            break;
        case K_BOUNCE:
            gi_k_bounce(a->np, a->off, a->obase, a->from, a->sbase, a->w_in, a->src, a->mask_in, a->rho4, a->first,
                        a->fout, a->mask_out, a->ftot, a->tally, a->tbase);
            break;
        case K_WALK:
            gi_k_walk(a->part, a->np, a->edir, a->src, a->mask_in, a->off, a->went, a->nwalk, a->fout, a->fout2,
                      a->tally, a->items);
            break;
        case K_RESOLVE: gi_k_resolve(a->part, a->np, a->edir, a->scattered, a->total, a->fout, a->fout2); break;
        case K_BACK: gi_k_back(a->part, a->np, a->total, a->fout); break;
        case K_BACK_SEND: gi_k_back_send(a->part, a->np, a->rho4, a->src, a->fout, a->mask_out); break;
        case K_GATHER:
            gi_k_gather(a->glink, a->ng, a->lout, a->idx, (int)a->n, a->esky, a->fout);
            break;
        case K_ESTIMATE: gi_k_estimate(a->part, a->list_off, a->list_idx, a->eind, a->idx, (int)a->n, a->fout); break;
        case K_VPL:
            gi_k_vpl_gather(a->vpts, (int)a->n, a->vnodes, a->nvnodes, a->vtabs, a->vthr, a->vmode, a->fout, a->visits);
            break;
        case K_CAUSTIC: gi_k_caustic_splat(a->cph, a->off, a->idx, a->cpix, a->w, a->h, a->tiles_x, a->fout); break;
        }
    }
}

static void launch(int threads, c_launch *a)
{
    if (a->n == 0) return;
    size_t cs = a->chunk ? a->chunk : GI_C_CHUNK;
    int chunks = (int)((a->n + cs - 1) / cs);
    if (threads <= 1 || chunks == 1) {
        for (int c = 0; c < chunks; c++) run_chunk(a, c, 0);
        return;
    }
    pool_run(threads, chunks, run_chunk, a);
}

void gi_c_emit(int threads, const gi_dev_particle *part, int n, const gi_dev_light *lights, int nlights,
               const float *vis, const unsigned *emits, float *edir, float *src, unsigned *srcmask, float *dsum,
               const float *extra)
{
    /* one work-item per GI_EMIT_CHUNK particles, 16 work-items per pool job */
    size_t items = ((size_t)n + GI_EMIT_CHUNK - 1) / GI_EMIT_CHUNK;
    c_launch a = {.kernel = K_EMIT, .n = items, .part = part, .np = n, .lights = lights, .nlights = nlights,
                  .vis = vis, .emits = emits, .fout = edir, .fout2 = src, .mask_out = srcmask, .tally = dsum,
                  .extra = extra, .has_extra = extra != NULL, .chunk = 16};
    launch(threads, &a);
}

void gi_c_bounce(int threads, int n, const int *off, int obase, const int *from, int sbase, float w_in,
                 const float *bin, const unsigned *mask_in, const float *rho4, int first, float *bout,
                 unsigned *mask_out, float *total, float *tally, int tbase)
{
    /* one work-item per GI_BOUNCE_CHUNK particles, 4 work-items per pool job */
    size_t items = ((size_t)n + GI_BOUNCE_CHUNK - 1) / GI_BOUNCE_CHUNK;
    c_launch a = {.kernel = K_BOUNCE, .n = items, .np = n, .off = off, .obase = obase, .from = from, .sbase = sbase,
                  .w_in = w_in, .src = bin, .mask_in = mask_in, .rho4 = rho4, .first = first, .fout = bout,
                  .mask_out = mask_out, .ftot = total, .tally = tally, .tbase = tbase, .chunk = 4};
    launch(threads, &a);
}

void gi_c_walk(int threads, const gi_dev_particle *part, int n, const float *edir, const float *recv0,
               const unsigned *live, const int *woff, const gi_walk_entry *went, int nwalk, float *lout, float *phi,
               float *tally, int items)
{
    size_t wi = ((size_t)n + GI_BOUNCE_CHUNK - 1) / GI_BOUNCE_CHUNK;
    c_launch a = {.kernel = K_WALK, .n = wi, .part = part, .np = n, .edir = edir, .src = recv0, .mask_in = live,
                  .off = woff, .went = went, .nwalk = nwalk, .fout = lout, .fout2 = phi, .tally = tally,
                  .items = items, .chunk = 4};
    launch(threads, &a);
}

void gi_c_resolve(int threads, const gi_dev_particle *part, int n, const float *edir, int scattered,
                  const float *total, float *lout, float *phi)
{
    c_launch a = {.kernel = K_RESOLVE, .n = (size_t)n, .part = part, .np = n, .edir = edir, .scattered = scattered,
                  .total = total, .fout = lout, .fout2 = phi};
    launch(threads, &a);
}

void gi_c_back(int threads, const gi_dev_particle *part, int n, const float *phi, float *lout)
{
    c_launch a = {.kernel = K_BACK, .n = (size_t)n, .part = part, .np = n, .total = phi, .fout = lout};
    launch(threads, &a);
}

void gi_c_back_send(int threads, const gi_dev_particle *part, int n, const float *rho4, const float *bin, float *bout,
                    unsigned *mask)
{
    size_t items = ((size_t)n + GI_EMIT_CHUNK - 1) / GI_EMIT_CHUNK;
    c_launch a = {.kernel = K_BACK_SEND, .n = items, .part = part, .np = n, .rho4 = rho4, .src = bin, .fout = bout,
                  .mask_out = mask, .chunk = 16};
    launch(threads, &a);
}

void gi_c_gather(int threads, const int *glink, int ng, const float *lout, const int *used, int nused,
                 const float *esky, float *eind)
{
    c_launch a = {.kernel = K_GATHER, .n = (size_t)nused, .glink = glink, .ng = ng, .lout = lout, .idx = used,
                  .esky = esky, .fout = eind};
    launch(threads, &a);
}

void gi_c_estimate(int threads, const gi_dev_particle *part, const int *list_off, const int *list_idx,
                   const float *eind, const int *found, int nfound, float *vout)
{
    c_launch a = {.kernel = K_ESTIMATE, .n = (size_t)nfound, .part = part, .list_off = list_off,
                  .list_idx = list_idx, .eind = eind, .idx = found, .fout = vout};
    launch(threads, &a);
}

void gi_c_vpl_gather(int threads, const gi_dev_vpl_point *pts, int npts, const gi_dev_vpl_node *nodes, int nnodes,
                     const float *tabs, float thr, int mode, float *out, int *visits)
{
    c_launch a = {.kernel = K_VPL, .n = (size_t)npts, .vpts = pts, .vnodes = nodes, .nvnodes = nnodes, .vtabs = tabs,
                  .vthr = thr, .vmode = mode, .fout = out, .visits = visits, .chunk = 16};
    launch(threads, &a);
}
void gi_c_caustic_splat(int threads, const gi_caus_photon *ph, const int *tile_off, const int *tile_idx,
                        const gi_caus_pixel *gbuf, int w, int h, int tiles_x, float *e)
{
    c_launch a = {.kernel = K_CAUSTIC, .n = (size_t)w * (size_t)h, .cph = ph, .off = tile_off, .idx = tile_idx,
                  .cpix = gbuf, .w = w, .h = h, .tiles_x = tiles_x, .fout = e};
    launch(threads, &a);
}

void gi_c_caustic_at(const gi_caus_photon *ph, const int *idx, int n, const float s[3], const float nrm[3], float brilliance,
                     float back, float e[3])
{
    e[0] = e[1] = e[2] = 0.0f;
    for (int k = 0; k < n; k++)
        gi_caus_add(&ph[idx ? idx[k] : k], s[0], s[1], s[2], nrm[0], nrm[1], nrm[2], brilliance, back, e);
}

float gi_c_caustic_kappa(const gi_caus_photon *q, const float s[3]) { return gi_caus_kappa(q, s[0], s[1], s[2]); }
