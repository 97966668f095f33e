/* gi_links.h - area particle links (paper section 3.1): for every particle,
 * n x n stratified cosine-weighted directions over its hemisphere, one ray
 * each (Embree ray streams, rtcIntersect1M, on core/pool threads), and for
 * every ray the area particle closest to the hit point on the side the ray
 * arrives at. 4 x 4 of them are the scattering links, 16 x 16 the gathering
 * links. A ray that leaves the scene, or finds no particle within maxdist of
 * its hit, gives -1. Internal to gi/. */
#ifndef PT_GI_LINKS_H
#define PT_GI_LINKS_H
#include <math.h>
#include <stdint.h>
#include "accel.h"
#include "scene.h"
#include "gi_area_particles.h"
#include "gi_shadow.h"
#include "gi_sky.h"
#include "gi_surface.h"
#include "gi_trilook.h"
#include "progress.h"

typedef struct {
    long rays;       /* traced */
    long misses;     /* left the scene */
    long unresolved; /* hit, but no particle near the hit on that side */
    long other_object; /* the nearest particle lay on another object than the one hit: searched again */
    long tri_answered; /* hits answered by the hit triangle's list (gi_trilook) */
    long tri_fallback; /* hits on a listed triangle that the list could not decide (grid path) */
} gi_link_stats;

/* links: n * nside^2 ints (may be NULL when only anyhit is wanted);
 * grid: particle lookup (NULL: links are not resolved); anyhit (may be
 * NULL): 1 where at least one ray of the particle hit something. pobj (may
 * be NULL): 2n pointers, [0, n) the object (const scene_object *) of each
 * particle, [n, 2n) the closed solid it is buried in (pin) or NULL; a link then
 * ends on a particle of the object its ray hit (where accel_rtc_object
 * knows it), on the side hit. pin (may be NULL): 2n flags: [0, n) 1 for
 * particles on the inside of a closed sphere or box (their links end
 * inside it), [n, 2n) 1 for particles buried in another closed sphere or
 * box (the floor under a box standing on it: only rays from inside that
 * solid end on them). tl (may be NULL; needs grid and pobj, built with
 * the same particles, pobj, pin + n as buried flags, GI_LINKS_AGREE and
 * maxdist): hits on its triangles take its answer when it has one (the
 * same answer, gi_trilook.h), else the grid path; the points' rays
 * (first > 0, or reach given), when gi_trilook_centres has been made,
 * take the answer at the centre of the hit's cell where it has one (a
 * cell's edge is at most a particle spacing: the particles' light,
 * constant over each particle's own cell of the surface, sampled at the
 * cells' centres instead of at the hit; no list is scanned). scene (may be NULL):
 * the RTCScene to trace (accel_rtc_link_scene's, built once by the
 * caller); NULL: the link scene is built and freed here. prog (may be
 * NULL): its current stage counts the chunks of particles traced. first:
 * only particles [first, n) send rays (all n are targets); links, anyhit
 * and esky are then indexed i - first. first > 0 means those are points
 * to gather at, not particles: a link that ends on a particle adds the
 * emission where its ray hit to esky, so its gather must take the
 * particle's reflected radiance (lout - le), not lout. When no bounce
 * follows (far_bounce 0) no link ends on a particle: every hit takes its
 * emission and the direct light of sc's lights it reflects (a shadow ray
 * a light, from the light's centre), computed there. */
/* sky, esky and sc (all or none; NULL: none): esky receives 4 floats a
 * particle (the fourth 0): the radiance its rays that leave the scene see
 * (sky), plus the far field of those that hit where no particle answers
 * (gi_links.c hit_light: emission and the sky reflected times far_bounce,
 * at the pigment pig gives where the ray hit, NULL: base colours), summed and
 * divided by nside^2: their share of the cosine-weighted mean incoming
 * radiance, in E/pi units. */
#define GI_LINKS_AGREE 0.3
/* A final-gather ray's continuation (a mirror's reflection, a clear
 * surface's transmission) that ends on particle t: point src (i - first)
 * gathers w times t's reflected radiance besides its rays' own (w: the
 * reflectivity and filter along the way, over the point's ray count). */
typedef struct {
    int src, t;
    float w[3];
} gi_link_cont;
typedef struct {
    gi_link_cont *e;
    long n, cap;
} gi_link_conts;
void gi_link_conts_free(gi_link_conts *c);

/* What the hits of the final gather's rays add to the lights' direct
 * light they reflect, as POV-Ray's radiosity rays see light: the caustic
 * layer's photons there (caus, NULL: none) and filtered shadows (shadow,
 * NULL: full ones; photon_shadows: the scene's photons{} is on). */
struct gi_caustic;
typedef struct {
    const struct gi_caustic *caus;
    gi_shadow_fn shadow;
    int photon_shadows;
} gi_hit_light;
/* hl (may be NULL: none of it): gi_hit_light. */
pt_status gi_links_build(const accel *a, void *rtc_scene, const gi_dev_particle *p, const void *const *pobj,
                         const unsigned char *pin, int n, int first, int nside, uint64_t seed, const gi_lookup *grid,
                         const gi_trilook *tl, double maxdist, int threads, int *links, unsigned char *anyhit,
                         gi_link_stats *st, volatile int *cancel, progress *prog,
                         const gi_sky *sky, float *esky, const scene *sc, gi_pigment_fn pig, double far_bounce,
                         float *reach, gi_link_conts *conts, const gi_hit_light *hl);

/* conts (may be NULL; the final gather's points): where a continuation
 * of a point's ray ends on a surface with particles, the particle it ends
 * on is appended there, and that hit adds only its emission to esky (the
 * particle's reflected light, direct and indirect, is the caller's to
 * add, as for the rays' own targets); without it, or where no particle
 * answers, the hit takes the far field (its direct light, and the sky it
 * reflects as one traced ray sees it). */
/* reach (may be NULL): four floats per point (i - first): the harmonic
 * mean distance of its rays' hits (INFINITY when none hit), how far its
 * gather may be reused (gi_particle_gather.c), then the vector from the
 * point to its rays' nearest hit (zero when none hit); given, the sources are points to
 * gather at (as with first > 0) even when first is 0 (no particles). */

/* The gatherer: the final gather's exact form (no bounce after the hit,
 * as gi_links_build's points with far_bounce 0) at one point at a time,
 * for hits that arise while the image renders (antialiasing rays, a
 * reflection of a seen surface) where no gathered point may answer. The
 * same rays as gi_links_build's (nside^2 stratified cosine-weighted ones
 * from random stream `stream` of seed); each that leaves the scene takes
 * the sky, each that hits takes the emission and the direct light of sc's
 * lights there (hit_light). e: E/pi at p about the unit normal n; reach
 * (may be NULL): the rays' harmonic mean hit distance. thread: the
 * caller's thread index, below GI_MAX_THREADS; 0: no answer. */
typedef struct gi_gatherer gi_gatherer;
gi_gatherer *gi_gatherer_new(const accel *a, void *rtc_scene, int nside, uint64_t seed,
                             const gi_sky *sky, const scene *sc, gi_pigment_fn pig);
int gi_gatherer_point(gi_gatherer *g, int thread, vec3 p, vec3 n, uint64_t stream, float e[3], float *reach);
/* 1 when no ray of g that hits something can bring light back (no light
 * to reflect, no texture that emits, mirrors or lets light through: a
 * sky-lit scene of diffuse surfaces): its points without a reach are then
 * answered by occlusion tests alone, the same answer for less time. */
int gi_gatherer_dark(const gi_gatherer *g);
/* What its hits add to the lights' direct light (gi_hit_light, copied;
 * NULL: none); the layer must outlive the gatherer's use of it. */
void gi_gatherer_set_light(gi_gatherer *g, const gi_hit_light *hl);
void gi_gatherer_free(gi_gatherer *g);

/* Incoming links, a counting sort by target: the sources i < n in mask
 * (bit i of word i / 32; NULL: all) whose links[i * k + j] are >= 0, per
 * target in ascending order of i (then j). count fills off (n + 2 ints)
 * and returns the number of entries; fill writes them to src, after which
 * target t's sources are src[off[t] .. off[t + 1] - 1] (off[0..n]). */
size_t gi_links_reverse_count(const int *links, int n, int k, const unsigned *mask, int *off);
void gi_links_reverse_fill(const int *links, int n, int k, const unsigned *mask, int *off, int *src);

/* How far a shadow ray from a surface point runs towards a light `depth`
 * away (eps the ray's epsilon): it stops 1e-5 x depth short of the light
 * (as the path tracer's pm_nee.c), so that a light lying in a surface's
 * plane (cornell.pov's lights in its ceiling) is not shadowed by that
 * surface: Embree's single-precision t there is off by ~2e-6 x depth. The
 * particles' visibility and the final gather's direct light both use it. */
static inline double gi_shadow_tmax(double depth, double eps) { return depth - fmax(eps, depth * 1e-5); }

#endif
