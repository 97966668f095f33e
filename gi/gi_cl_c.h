/* gi_cl_c.h - the particle GI kernels (gi/kernels, .cl files) compiled as C through
 * gi/kernels/gi_shim.h, with launchers that run work-items on core/pool.
 * This is the device used when OpenCL is off (PARTRAY_OPENCL=OFF or the "c"
 * device) and the host's own path for radiance particles that the view
 * pre-pass missed: the same kernel code either way. `threads` <= 1 runs on
 * the calling thread. Argument meanings: see the kernels. */
#ifndef PT_GI_CL_C_H
#define PT_GI_CL_C_H
#include "kernels/gi_types.h"

void gi_c_emit(int threads, const gi_dev_particle *part, int n, const gi_dev_light *lights, int nlights,
               const float *vis, float *edir, float *src);
/* nslices > 0: acc holds nslices slices of 3n, tally nslices x 3 GI_MAX_BOUNCES
 * (gi_k_scatter); nslices = 0: one of each, atomic adds. rho4: n x 4 floats. */
void gi_c_scatter(int threads, const float *rho4, int n, const int *slink, int ns2, int nb, gi_u32 seed,
                  float scale, const int *srcidx, int nsrc, const float *src, int nslices, gi_i64 *acc, gi_i64 *tally);
void gi_c_pull_init(int threads, int n, int ns2, const float *src, float *bin, float *total);
void gi_c_pull(int threads, const gi_dev_particle *part, int n, int ns2, const int *rin_off, const int *rin_src,
               const float *bin, float *bout, float *total);
void gi_c_resolve(int threads, const gi_dev_particle *part, int n, const float *edir, const gi_i64 *acc,
                  int nslices, float inv_scale, const float *total, float *lout, float *phi);
void gi_c_gather(int threads, const int *glink, int ng, const float *lout, const int *used, int nused,
                 const float bg[3], float *eind);
void gi_c_estimate(int threads, const gi_dev_particle *part, const int *list_off, const int *list_idx,
                   const float *eind, const int *found, int nfound, float *vout);

#endif
