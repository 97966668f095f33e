/* gi_cl_c.h - the particle GI kernels (gi/kernels, .cl files) compiled as C through
 * gi/kernels/gi_shim.h, with launchers that run work-items on core/pool.
 * This is the device used when OpenCL is off (PARTRAY_OPENCL=OFF or the "c"
 * device) and the host's own path for radiance particles that the view
 * pre-pass missed: the same kernel code either way. `threads` <= 1 runs on
 * the calling thread. Argument meanings: see the kernels. */
#ifndef PT_GI_CL_C_H
#define PT_GI_CL_C_H
#include "kernels/gi_types.h"
#include "kernels/gi_vpl_types.h"

/* gi_k_emit: ceil(n / GI_EMIT_CHUNK) work-items, one srcmask word and dsum
 * float each; extra: E/pi besides the lights', 4 floats per particle (NULL: none). */
void gi_c_emit(int threads, const gi_dev_particle *part, int n, const gi_dev_light *lights, int nlights,
               const float *vis, const unsigned *emits, float *edir, float *src, unsigned *srcmask, float *dsum,
               const float *extra);
/* gi_k_bounce: ceil(n / GI_BOUNCE_CHUNK) work-items; tally gets 3 floats
 * per work-item from tbase. */
void gi_c_bounce(int threads, int n, const int *off, int obase, const int *from, int sbase, float w_in,
                 const float *bin, const unsigned *mask_in, const float *rho4, int first, float *bout,
                 unsigned *mask_out, float *total, float *tally, int tbase);
/* gi_k_walk: ceil(n / GI_BOUNCE_CHUNK) work-items (`items` of them: the
 * tally's stride per bounce). */
void gi_c_walk(int threads, const gi_dev_particle *part, int n, const float *edir, const float *recv0,
               const unsigned *live, const int *woff, const gi_walk_entry *went, int nwalk, float *lout, float *phi,
               float *tally, int items);
void gi_c_resolve(int threads, const gi_dev_particle *part, int n, const float *edir, int scattered,
                  const float *total, float *lout, float *phi);
/* gi_k_back: n work-items, after gi_c_resolve or gi_c_walk. */
void gi_c_back(int threads, const gi_dev_particle *part, int n, const float *phi, float *lout);
/* gi_k_back_send: ceil(n / GI_EMIT_CHUNK) work-items, one mask word each. */
void gi_c_back_send(int threads, const gi_dev_particle *part, int n, const float *rho4, const float *bin, float *bout,
                    unsigned *mask);
void gi_c_gather(int threads, const int *glink, int ng, const float *lout, const int *used, int nused,
                 const float *esky, float *eind);
void gi_c_estimate(int threads, const gi_dev_particle *part, const int *list_off, const int *list_idx,
                   const float *eind, const int *found, int nfound, float *vout);
/* gi_k_vpl_gather: one work-item per point (gi_vpl.cl). */
void gi_c_vpl_gather(int threads, const gi_dev_vpl_point *pts, int npts, const gi_dev_vpl_node *nodes, int nnodes,
                     const float *tabs, float thr, int mode, float *out, int *visits);
 
/* gi_k_caustic_splat (gi_caustic.cl): w x h work-items. */
void gi_c_caustic_splat(int threads, const gi_caus_photon *ph, const int *tile_off, const int *tile_idx,
                        const gi_caus_pixel *gbuf, int w, int h, int tiles_x, float *e);
/* The same photon volume sum (gi_caus_add) at one receiver point s with
 * normal nrm, finish brilliance and diffuse_back fraction back, over photons idx[0 .. n) (idx NULL:
 * photons 0 .. n), on the calling thread: the caustic layer's lookups away
 * from the G-buffer. */
void gi_c_caustic_at(const gi_caus_photon *ph, const int *idx, int n, const float s[3], const float nrm[3], float brilliance,
                     float back, float e[3]);

/* gi_caus_kappa (gi_caustic.cl): photon q's filter kernel at s. */
float gi_c_caustic_kappa(const gi_caus_photon *q, const float s[3]);

#endif
