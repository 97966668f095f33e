/* pm_path.h - unbiased path tracer (Kajiya 1986) on shade_material.h's
 * light-transport model: next-event estimation at every vertex for all
 * POV-Ray light types (pm_nee.h; area lights sampled continuously),
 * emissive surfaces found both by BSDF sampling and by area sampling,
 * combined with multiple importance sampling (power heuristic), Russian
 * roulette by throughput after a few vertices, stratified pixel samples,
 * one random stream per pixel sample, tiles on core/pool, progressive
 * output between passes.
 *
 * Vertex 0 is where the camera ray lands: emission there plus the NEE there
 * is exactly `--gi none`'s direct light (same terms as shade.c; POV-Ray's
 * jittered area-light grid replaced by continuous sampling), so max_depth 1
 * renders the direct light only. Camera rays skip no_image objects and mirror
 * rays no_reflection objects (as shade.c); diffuse rays see everything
 * (no_radiosity is not read). */
#ifndef PT_PM_PATH_H
#define PT_PM_PATH_H
#include "accel.h"
#include "pm.h"

typedef struct {
    pm_common c;        /* c.spp = samples per pixel */
    int max_depth;      /* vertices per path; 1 = direct light only; 0 = unlimited (capped at 1024) */
    int rr_depth;       /* Russian roulette from this vertex on (default 3) */
    double rr_threshold;/* survival probability min(1, max(T) / rr_threshold) (default 0.1: paths run
                           on while their throughput T is above it, which costs longer paths but
                           removes most of the roulette noise; 1 = the usual min(1, max T)) */
    int area_samples;   /* shadow rays per area light per vertex (default 1) */
} pm_path_settings;

void pm_path_default_settings(pm_path_settings *s);

/* Render into fb (c.width x c.height). Stats: t_lights, t_render, t_total,
 * ray counts, samples, discarded samples. */
pt_status pm_path_render(const scene *sc, const accel *a, const pm_path_settings *s, framebuffer *fb, pm_stats *st,
                         diag *d);

#endif
