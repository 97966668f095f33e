/* gi_vlinks_c.c - gi_vlinks.cl compiled as C (gi_shim.h maps the OpenCL
 * subset; this file and gi_cl_c.c are its includers) and its launchers. */
#include "kernels/gi_shim.h"
#include "kernels/gi_vlinks.cl"
#include "gi_vlinks_c.h"
#include "pool.h"

#define VL_CHUNK 256

typedef struct {
    int kernel;
    int n;
    const int *off, *idx;
    const float *w, *in, *rho;
    float *out, *out2;
} vl_launch;

static void vl_chunk(void *ctx, int chunk, int thread)
{
    (void)thread;
    const vl_launch *a = ctx;
    int lo = chunk * VL_CHUNK, hi = lo + VL_CHUNK < a->n ? lo + VL_CHUNK : a->n;
    for (int g = lo; g < hi; g++) {
        gi_shim_gid = (size_t)g;
        if (a->kernel == 0) gi_k_vgather(a->off, a->idx, a->w, a->in, a->rho, a->n, a->out, a->out2);
        else gi_k_vsmooth(a->off, a->idx, a->in, a->n, a->out);
    }
}

static void vl_run(int threads, const vl_launch *a)
{
    int chunks = (a->n + VL_CHUNK - 1) / VL_CHUNK;
    if (chunks <= 0) return;
    if (threads <= 1 || chunks == 1) {
        for (int c = 0; c < chunks; c++) vl_chunk((void *)a, c, 0);
        return;
    }
    pool_run(threads, chunks, vl_chunk, (void *)a);
}

void gi_c_vgather(int threads, const int *off, const int *peer, const float *w, const float *bin, const float *rho,
                  int n, float *bout, float *itot)
{
    vl_launch a = {0, n, off, peer, w, bin, rho, bout, itot};
    vl_run(threads, &a);
}

void gi_c_vsmooth(int threads, const int *off, const int *nb, const float *in, int n, float *out)
{
    vl_launch a = {1, n, off, nb, NULL, in, NULL, out, NULL};
    vl_run(threads, &a);
}
