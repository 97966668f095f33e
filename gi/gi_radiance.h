/* gi_radiance.h - radiance particles and their estimation lists (paper
 * section 3.2). Radiance particles are the vertices of the patches'
 * sub-tessellations (gi_surface); each gets the list of area particles
 * within radius r whose normal is within the threshold of its own
 * (n_m . n_q > cos_thr), on its own object and side (gi_same_surface) and
 * in its sight (gi_visible), so radiance estimation is a list scan (kernel
 * gi_k_estimate). A radiance particle with an empty list (a small patch, or
 * a corner) takes the particles within 2r, then 4r, then the nearest one
 * facing the same way within 4r. Radiance particles on a side that kept no
 * particles (pruned: it faces only the void) get an empty list; their value
 * is the background. Lists are stored as CSR arrays for the device.
 * Internal to gi/. */
#ifndef PT_GI_RADIANCE_H
#define PT_GI_RADIANCE_H
#include "gi_area_particles.h"
#include "gi_surface.h"
#include "progress.h"

typedef struct {
    long nrp;
    int *off;        /* nrp + 1 */
    int *idx;        /* off[nrp] entries */
    long widened;    /* lists that needed a larger radius */
    long empty;      /* lists still empty (no particle faces that way) */
    long dead;       /* on a side without particles (it faces only the void) */
    long vis_rays;   /* visibility tests of list entries (gi_radiance.c visible) */
} gi_lists;

/* Whether a sample at y (normal ny) may stand for light at x (normal nx) on
 * object `own`: the segment between the two, lifted off the surface by
 * 16 eps along their normals (and past accel_hit_placement(own)), crosses
 * no other object (exact crossings, ACCEL_RAY_EXACT), and
 * `own` an even number of times (a chord of a curved surface dips under it
 * and out again; one crossing puts y behind a sheet of `own`: the inside of
 * a thin closed slab's other face). Without it
 * estimates reached across walls: the floor around a box standing on it
 * took the particles (and radiance particles) of the floor under the box,
 * lit by a light inside the box; the dark side of a thin wall took the lit
 * side's. Used for the estimation lists and for the radiance particles a
 * shading hit interpolates (gi_particle_hook.c). */
int gi_visible(const accel *a, double eps, vec3 x, vec3 nx, vec3 y, vec3 ny, const scene_object *own);
/* gi_visible in two steps, for callers that trace many segments together
 * (gi_particle_cells.c's cell tests, accel_hit_any_n): the lifted segment from x
 * to y (0 when the points are closer than twice the lift: visible, no ray),
 * then gi_visible's rule along it. gi_visible = !segment || along. A segment
 * whose ray from p along d over [0, len] meets nothing (ACCEL_RAY_EXACT) is
 * visible. */
typedef struct {
    vec3 p, d;   /* from the lifted x along the unit direction to the lifted y */
    double len;  /* its length */
    double lift; /* how far both ends were lifted */
} gi_segment;
int gi_visible_segment(const accel *a, double eps, vec3 x, vec3 nx, vec3 y, vec3 ny, const scene_object *own,
                       gi_segment *sg);
int gi_visible_along(const accel *a, double eps, const gi_segment *sg, const scene_object *own);

/* prog (may be NULL): its current stage counts the chunks of radiance
 * particles whose lists are done. */
pt_status gi_radiance_lists(gi_lists *L, const gi_surface *g, const gi_particles *ps, const accel *a, double r,
                            double cos_thr, int threads, volatile int *cancel, progress *prog, diag *d);
void gi_lists_free(gi_lists *L);

#endif
