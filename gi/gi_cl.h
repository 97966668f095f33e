/* gi_cl.h - the device that runs the particle GI kernels: an OpenCL device
 * (PoCL's CPU device on the development machines, a GPU where one is lent)
 * or the same kernels compiled as C (gi_cl_c.h). One interface for both.
 *
 * Device selection (`spec`): NULL, "" or "auto" = the first GPU of any
 * platform, else the first device; "c" = the C build (always available);
 * "P:D" = platform P, device D (numbers); any other text = the first device
 * whose name or platform name contains it (case-insensitive).
 *
 * Kernel source: embedded in the binary at build time (CMake concatenates
 * gi/kernels/gi_types.h, gi_lighting.cl, gi_gather.cl); when the environment
 * variable PARTRAY_CL_DIR names a folder, the same files are read from there
 * instead (for editing kernels without rebuilding). PoCL caches compiled
 * kernels itself (~/.cache/pocl), so only the first build of a source costs
 * a full compile (about 0.9 s here; 0.03 s cached).
 *
 * Errors never crash: no platform/device, a build failure (the build log is
 * in the diagnostics), or allocation failure return PT_ERR_DEVICE,
 * PT_ERR_UNSUPPORTED or PT_ERR_NOMEM with a message in `d`.
 *
 * Data: the caller owns the host arrays passed to gi_dev_set_*; they must
 * stay alive and unchanged while the device is used (the C build reads them
 * in place, OpenCL copies them). */
#ifndef PT_GI_CL_H
#define PT_GI_CL_H
#include <stddef.h>
#include "diag.h"
#include "kernels/gi_types.h"
#include "kernels/gi_vpl_types.h"

typedef struct gi_dev gi_dev;

typedef struct {
    const char *spec;   /* see above */
    const char *source; /* NULL: embedded (or $PARTRAY_CL_DIR); else this program text (tests) */
    int threads;        /* worker threads of the C build; <= 0: all cores */
    size_t max_bytes;   /* OpenCL: device memory the buffers may take in all; 0 = the
                           device's CL_DEVICE_GLOBAL_MEM_SIZE (never more). A buffer
                           beyond it or beyond CL_DEVICE_MAX_MEM_ALLOC_SIZE is a
                           PT_ERR_NOMEM error naming the sizes, before it is requested */
} gi_dev_options;

gi_dev *gi_dev_open(const gi_dev_options *o, diag *d, pt_status *status);
void gi_dev_free(gi_dev *dv);
const char *gi_dev_name(const gi_dev *dv);
double gi_dev_build_seconds(const gi_dev *dv); /* program build (0 for the C build) */
size_t gi_dev_bytes(const gi_dev *dv);          /* device buffers held (OpenCL) or scratch (C) */
/* Whether this binary was built with OpenCL (PARTRAY_OPENCL=ON). */
int gi_dev_opencl_built(void);

/* Geometry stage results: n particles, ns2 scattering links and ng gathering
 * links per particle (-1 = miss), esky (4 floats a particle, gi_links.h:
 * the sky's and the far field's share of its gather),
 * and the estimation lists (CSR: entries list_idx[list_off[l] ..
 * list_off[l+1]) of radiance particle l). The arrays must outlive dv's use
 * of them (the C build reads them in place). */
pt_status gi_dev_set_particles(gi_dev *dv, const gi_dev_particle *part, int n, const int *slink, int ns2,
                               const int *glink, int ng, const float *esky, diag *d);
pt_status gi_dev_set_lists(gi_dev *dv, const int *list_off, int nrp, const int *list_idx, diag *d);
/* Incoming scattering links (CSR by target, sources ascending): the first
 * bounce, and every bounce of the "full" mode. */
pt_status gi_dev_set_reverse(gi_dev *dv, const int *rin_off, const int *rin_src, diag *d);
/* The WALK mode's bounces 1..nwalk (gi_k_walk): the path table, per target
 * particle k the entries went[woff[k] .. woff[k + 1]) (origin j, bounce b,
 * weight; sorted by b, then j), n + 1 offsets. */
pt_status gi_dev_set_walk(gi_dev *dv, const int *woff, const gi_walk_entry *went, int nwalk, diag *d);

/* Lighting stage (gi_lighting.cl): emission from the lights with vis
 * (n x nlights: attenuation times visibility fraction; vis_changed 0: the
 * same values as the previous call's, not uploaded again) and extra (NULL
 * or n*4 floats: E/pi arriving besides the lights', the caustic photons',
 * treated as direct light), nb scattering
 * bounces (mode GI_SCATTER_WALK: the first along all links, then the walk
 * table; GI_SCATTER_FULL: all along all links), then the reflected
 * radiance. The host array lout (radiance, n*4 floats), bounce_flux (nb grey
 * sums of what each bounce delivered; may be NULL) and sums (may be NULL)
 * are written only at the end, and *done set to 1. edir (direct E/pi) and
 * phi (received flux), n*4 floats each, are written by the time
 * gi_dev_fetch returns (OpenCL keeps them on the device until asked; they
 * must stay valid until then). While *cancel (may be NULL) is non-zero the
 * stage stops before its next kernel, writes nothing the caller reads and
 * returns PT_OK with *done 0: the previous results stay in place (on the
 * device too). times (may be NULL): seconds of emission (uploads included)
 * and of the rest. */
enum { GI_SCATTER_WALK = 0, GI_SCATTER_FULL = 1 };
typedef struct {
    double direct;    /* direct flux, grey (mean of the colours) */
    double emitted;   /* emitted flux, grey */
    double scattered; /* flux the bounces delivered, grey (sum of bounce_flux) */
    long sources;     /* particles sending light in the first bounce */
} gi_dev_sums;
pt_status gi_dev_lighting(gi_dev *dv, const gi_dev_light *lights, int nlights, const float *vis, int vis_changed,
                          const float *extra, int mode, int nb, volatile int *cancel, float *edir, float *lout, float *phi,
                          double *bounce_flux, gi_dev_sums *sums, int *done, double times[2], diag *d);
/* Writes the last completed lighting stage's edir and phi into the arrays
 * it was given (nothing when they are written already). d may be NULL. */
pt_status gi_dev_fetch(gi_dev *dv, diag *d);
/* Ray-tracing stage. gather: E~/pi of the used particles, written into the
 * device's copy and into eind[4*used[t]] on the host. estimate: radiance
 * particles found[t] into vout[4*t] (compact). */
pt_status gi_dev_gather(gi_dev *dv, const int *used, int nused, float *eind, diag *d);
pt_status gi_dev_estimate(gi_dev *dv, const int *found, int nfound, float *vout, diag *d);
/* VPL reflectance filtering (gi_vpl.cl's gi_k_vpl_gather): npts points
 * against the node array (ntabs E(mu) tables of GI_VPL_TAB floats); out
 * gets 4 (GI_VPL_EYE) or 12 (GI_VPL_BOUNCE) floats a point, visits one int.
 * Needs no particles (any device from gi_dev_open). */
pt_status gi_dev_vpl_gather(gi_dev *dv, const gi_dev_vpl_point *pts, int npts, const gi_dev_vpl_node *nodes, int nnodes,
                            const float *tabs, int ntabs, float thr, int mode, float *out, int *visits, diag *d);
/* Caustic layer (gi_caustic.cl, seed 002 step 4): the photon volumes ph
 * (nph) scattered over the w x h G-buffer gbuf through the tile lists
 * (ntiles tiles in rows of tiles_x; CSR tile_off, ntiles + 1 offsets, and
 * tile_idx); e gets 4 floats a pixel. Independent of the particle data. */
pt_status gi_dev_caustic_splat(gi_dev *dv, const gi_caus_photon *ph, int nph, const int *tile_off, int ntiles,
                               const int *tile_idx, const gi_caus_pixel *gbuf, int w, int h, int tiles_x, float *e,
                               diag *d);

#endif
