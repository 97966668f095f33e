/* gi_vlinks.h - vertex links (`--gi links`, seed 001: Schmitz, Tavenrath
 * and Kobbelt, "Interactive Global Illumination for Deformable Geometry in
 * CUDA"): diffuse interreflection between the vertices of the scene's
 * meshes (mesh, mesh2 and what the parser builds as meshes).
 *
 *  - elements: every mesh vertex, one element per side of the surface
 *    (side 0 along the winding normal, averaged over the vertex's
 *    triangles by area; side 1 against it), at the vertex's world position;
 *  - links: nside x nside cosine-weighted directions per element (16 x 16,
 *    the paper's), a fixed set taken in 4 x 4 blocks of the unit square
 *    (Shirley-Chiu concentric map to the disc, projected to the
 *    hemisphere), rotated into the element's frame; a ray's hit on a mesh
 *    triangle gives three links, to the triangle's vertices on the side
 *    the ray arrives at, weighted by the hit's barycentrics / n_C; links to
 *    one peer are merged (the raw and merged counts are in the stats);
 *  - light links: a shadow ray from every element to every light
 *    (POV-Ray's attenuation, spot and cylinder cones, fade; area lights
 *    from their centre);
 *  - gathering: `bounces` Jacobi sweeps over the links (gi_vlinks.cl; the
 *    scene's recursion_limit by default, brightness applied per bounce), then
 *    one-ring smoothing between vertices whose normals are within the
 *    feature angle;
 *  - the hook: the smoothed indirect E/pi of the hit triangle's three
 *    elements, interpolated by the hit's barycentrics.
 *
 * Across the frames of an animation (gi_vlinks_frame with the previous
 * frame's state): objects whose geometry or transform changed
 * (scene_object_hash) are "moved"; only the elements of moved meshes, and
 * the elements one of whose rays ended on a moved object or now meets one
 * (a query against the moved objects only, up to the stored hit), trace
 * their rays again; the light links and gathering run every frame.
 *
 * Surfaces of other objects (spheres, boxes, planes, ...) get no
 * vertices: their indirect light is 0 (counted in the stats); a link ray
 * that ends on one brings the light that surface reflects of the lights
 * (one bounce, its direct light recomputed every frame). Rays that leave
 * the scene bring nothing (no sky light). Finish emission of a
 * mesh is light its vertices send (POV-Ray's rules, radrules.h); both
 * sides of a vertex take the texture (not interior_texture). */
#ifndef PT_GI_VLINKS_H
#define PT_GI_VLINKS_H
#include <stdint.h>
#include "accel.h"
#include "diag.h"
#include "gi_particle.h"
#include "progress.h"
#include "scene.h"

typedef struct gi_vlinks gi_vlinks;

typedef struct {
    int nside;             /* directions per element: nside^2, nside a multiple of 4 (16) */
    int bounces;           /* Jacobi sweeps; 0: the scene's radiosity recursion_limit, 3 without
                              one (the paper's Table 2) */
    double feature_deg;    /* smoothing takes one-ring neighbours within this angle (30) */
    int threads;           /* <= 0: all cores */
    gi_pigment_fn pigment; /* pigment at a vertex; NULL: each texture's base colour */
    volatile int *cancel;
    progress *progress;
} gi_vlinks_settings;

typedef struct {
    long vertices, elements, meshes;
    long other_objects;    /* leaf objects that are not meshes: no indirect light on them */
    long meshes_moved, objects_moved; /* since the previous frame */
    long elements_linked;  /* elements that traced their rays this frame */
    long raw_links, merged_links; /* over all elements: before and after merging per peer */
    long link_rays, light_rays;
    long hits_other;       /* link rays of this frame that ended on a surface without vertices */
    long lookups_other;    /* hook calls on surfaces without vertices (gi_vlinks_lookups_other, after the render) */
    int full;              /* every element linked (first frame, structure changed) */
    int sweeps;            /* gathering sweeps run */
    double t_links, t_light, t_bounces, t_smooth; /* seconds */
} gi_vlinks_stats;

void gi_vlinks_default_settings(gi_vlinks_settings *s);
gi_vlinks *gi_vlinks_new(const gi_vlinks_settings *s);
void gi_vlinks_free(gi_vlinks *v);
void gi_vlinks_set_progress(gi_vlinks *v, progress *p);
/* While *cancel (NULL: never) is non-zero a frame stops at its next chunk
 * of link rays or light links and returns PT_CANCELLED. */
void gi_vlinks_set_cancel(gi_vlinks *v, volatile int *cancel);
/* One frame: sc and a must stay alive until the next frame or free (the
 * hook reads them). objects_may_change 0: the caller knows that nothing
 * but the camera and lights changed since the previous frame. */
pt_status gi_vlinks_frame(gi_vlinks *v, const scene *sc, const accel *a, int objects_may_change, gi_vlinks_stats *st,
                          diag *d);
/* shade_indirect_fn: the indirect E/pi at a hit on a mesh (0 elsewhere). */
rgb gi_vlinks_indirect(void *ctx, const accel_hit *hit, vec3 n, int thread);
/* A finished solution kept apart from the instance: the hook on a shot
 * reads only the shot, so passes can render with it on one thread while
 * gi_vlinks_frame computes the next frame on another (the paper's
 * asynchronous updates: the view shows the newest finished solution). The
 * scene of the frame it was taken after must outlive it. NULL: no
 * solution yet, or no memory. */
typedef struct gi_vlinks_shot gi_vlinks_shot;
gi_vlinks_shot *gi_vlinks_shot_new(const gi_vlinks *v);
/* shade_indirect_fn on a shot (ctx: the shot), as gi_vlinks_indirect. */
rgb gi_vlinks_shot_indirect(void *ctx, const accel_hit *hit, vec3 n, int thread);
void gi_vlinks_shot_free(gi_vlinks_shot *s);
/* Element i's indirect E/pi after smoothing (tests); n: the count. */
rgb gi_vlinks_element(const gi_vlinks *v, long i, vec3 *p, vec3 *nrm);
long gi_vlinks_count(const gi_vlinks *v);
/* Hook calls since the last frame on surfaces without vertices (they got 0). */
long gi_vlinks_lookups_other(const gi_vlinks *v);

#endif
