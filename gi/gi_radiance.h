/* gi_radiance.h - radiance particles and their estimation lists (paper
 * section 3.2). Radiance particles are the vertices of the patches'
 * sub-tessellations (gi_surface); each gets the list of area particles
 * within radius r whose normal is within the threshold of its own
 * (n_m . n_q > cos_thr), so radiance estimation is a list scan (kernel
 * gi_k_estimate). A radiance particle with an empty list (a small patch, or
 * a corner) takes the particles within 2r, then 4r, then the nearest one
 * facing the same way within 4r. Radiance particles on a side that kept no
 * particles (pruned: it faces only the void) get an empty list; their value
 * is the background. Lists are stored as CSR arrays for the device.
 * Internal to gi/. */
#ifndef PT_GI_RADIANCE_H
#define PT_GI_RADIANCE_H
#include "gi_particles.h"
#include "gi_surface.h"

typedef struct {
    long nrp;
    int *off;        /* nrp + 1 */
    int *idx;        /* off[nrp] entries */
    long widened;    /* lists that needed a larger radius */
    long empty;      /* lists still empty (no particle faces that way) */
    long dead;       /* on a side without particles (it faces only the void) */
} gi_lists;

pt_status gi_radiance_lists(gi_lists *L, const gi_surface *g, const gi_particles *ps, double r, double cos_thr,
                            int threads, diag *d);
void gi_lists_free(gi_lists *L);

#endif
