/* gi_vlinks_c.h - the vertex links' kernels (gi/kernels/gi_vlinks.cl)
 * compiled as C through gi/kernels/gi_shim.h, launched on core/pool
 * (`threads` <= 1: the calling thread). Arguments: see the kernels. */
#ifndef PT_GI_VLINKS_C_H
#define PT_GI_VLINKS_C_H

void gi_c_vgather(int threads, const int *off, const int *peer, const float *w, const float *bin, const float *rho,
                  int n, float *bout, float *itot);
void gi_c_vsmooth(int threads, const int *off, const int *nb, const float *in, int n, float *out);

#endif
