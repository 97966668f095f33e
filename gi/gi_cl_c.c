/* gi_cl_c.c - the OpenCL kernels compiled as C (see gi_shim.h) and their
 * launchers: work-items run in chunks of GI_C_CHUNK on core/pool threads,
 * each setting the thread-local global id before calling the kernel body. */
#include "kernels/gi_shim.h"
/* The kernel program, in the order gi/CMakeLists.txt concatenates it. */
#include "kernels/gi_types.h"
#include "kernels/gi_lighting.cl"
#include "kernels/gi_gather.cl"
/* (gi_shim.h must come first; this header only declares the launchers.) */
#include "gi_cl_c.h"
#include "pool.h"

_Thread_local size_t gi_shim_gid;

#define GI_C_CHUNK 256

typedef struct {
    int kernel;
    size_t n;
    const gi_dev_particle *part;
    int np;
    const gi_dev_light *lights;
    int nlights;
    const float *vis, *src, *edir, *lout, *eind, *bg;
    float *fout, *fout2;
    const int *slink, *glink, *idx, *list_off, *list_idx;
    int ns2, nb, ng;
    gi_u32 seed;
    float scale;
    gi_i64 *acc, *tally;
    const gi_i64 *cacc;
    const float *total;
    float *ftot;
    const int *rin_off, *rin_src;
    int np_slices; /* scatter: slices (one work-item each) */
    int nsrc;      /* scatter: sources */
    const float *rho4;
    int *next; /* scatter: the shared batch counter */
    size_t chunk;  /* work-items per pool job (0: GI_C_CHUNK) */
} c_launch;

enum { K_EMIT, K_SCATTER, K_RESOLVE, K_GATHER, K_ESTIMATE, K_PULL_INIT, K_PULL };

static void run_chunk(void *ctx, int chunk, int thread)
{
    (void)thread;
    const c_launch *a = ctx;
    size_t cs = a->chunk ? a->chunk : GI_C_CHUNK;
    size_t lo = (size_t)chunk * cs, hi = lo + cs < a->n ? lo + cs : a->n;
    for (size_t g = lo; g < hi; g++) {
        gi_shim_gid = g;
        switch (a->kernel) {
        case K_EMIT: gi_k_emit(a->part, a->np, a->lights, a->nlights, a->vis, a->fout, a->fout2); break;
        case K_SCATTER:
            gi_k_scatter(a->rho4, a->slink, a->ns2, a->nb, a->seed, a->scale, a->idx, a->nsrc, a->src, a->acc,
                         a->tally, a->np, a->np_slices, a->next);
            break;
        case K_RESOLVE:
            gi_k_resolve(a->part, a->np, a->edir, a->cacc, a->np_slices, a->scale, a->total, a->fout, a->fout2);
            break;
        case K_PULL_INIT: gi_k_pull_init(a->np, a->ns2, a->src, a->fout, a->ftot); break;
        case K_PULL:
            gi_k_pull(a->part, a->np, a->ns2, a->rin_off, a->rin_src, a->src, a->fout, a->ftot);
            break;
        case K_GATHER:
            gi_k_gather(a->glink, a->ng, a->lout, a->idx, (int)a->n, a->bg[0], a->bg[1], a->bg[2], a->fout);
            break;
        case K_ESTIMATE: gi_k_estimate(a->part, a->list_off, a->list_idx, a->eind, a->idx, (int)a->n, a->fout); break;
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
               const float *vis, float *edir, float *src)
{
    c_launch a = {.kernel = K_EMIT, .n = (size_t)n, .part = part, .np = n, .lights = lights, .nlights = nlights,
                  .vis = vis, .fout = edir, .fout2 = src};
    launch(threads, &a);
}

void gi_c_scatter(int threads, const float *rho4, int n, const int *slink, int ns2, int nb, gi_u32 seed,
                  float scale, const int *srcidx, int nsrc, const float *src, int nslices, gi_i64 *acc, gi_i64 *tally)
{
    /* one work-item per slice (nslices > 0), one pool job each */
    int next = 0;
    c_launch a = {.kernel = K_SCATTER, .n = (size_t)(nslices > 0 ? nslices : nsrc), .rho4 = rho4, .np = n,
                  .slink = slink, .ns2 = ns2, .nb = nb, .seed = seed, .scale = scale, .idx = srcidx,
                  .nsrc = nsrc, .src = src, .acc = acc, .tally = tally, .np_slices = nslices,
                  .chunk = nslices > 0 ? 1 : 0, .next = &next};
    launch(threads, &a);
}

void gi_c_pull_init(int threads, int n, int ns2, const float *src, float *bin, float *total)
{
    c_launch a = {.kernel = K_PULL_INIT, .n = (size_t)n, .np = n, .ns2 = ns2, .src = src, .fout = bin, .ftot = total};
    launch(threads, &a);
}

void gi_c_pull(int threads, const gi_dev_particle *part, int n, int ns2, const int *rin_off, const int *rin_src,
               const float *bin, float *bout, float *total)
{
    c_launch a = {.kernel = K_PULL, .n = (size_t)n, .part = part, .np = n, .ns2 = ns2, .rin_off = rin_off,
                  .rin_src = rin_src, .src = bin, .fout = bout, .ftot = total};
    launch(threads, &a);
}

void gi_c_resolve(int threads, const gi_dev_particle *part, int n, const float *edir, const gi_i64 *acc,
                  int nslices, float inv_scale, const float *total, float *lout, float *phi)
{
    c_launch a = {.kernel = K_RESOLVE, .n = (size_t)n, .part = part, .np = n, .edir = edir, .cacc = acc,
                  .np_slices = nslices, .scale = inv_scale, .total = total, .fout = lout, .fout2 = phi};
    launch(threads, &a);
}

void gi_c_gather(int threads, const int *glink, int ng, const float *lout, const int *used, int nused,
                 const float bg[3], float *eind)
{
    c_launch a = {.kernel = K_GATHER, .n = (size_t)nused, .glink = glink, .ng = ng, .lout = lout, .idx = used,
                  .bg = bg, .fout = eind};
    launch(threads, &a);
}

void gi_c_estimate(int threads, const gi_dev_particle *part, const int *list_off, const int *list_idx,
                   const float *eind, const int *found, int nfound, float *vout)
{
    c_launch a = {.kernel = K_ESTIMATE, .n = (size_t)nfound, .part = part, .list_off = list_off,
                  .list_idx = list_idx, .eind = eind, .idx = found, .fout = vout};
    launch(threads, &a);
}
