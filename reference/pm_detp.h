/* pm_detp.h - incremental photon paths for animations (seed 004: García
 * Hernández, Ureña and Lastra, "Real Time Global Illumination for
 * Quasi-Static Scenes"): the photon paths of pm_photon.h kept from frame to
 * frame, each frame re-tracing only the segments whose stored hit is on an
 * object that moved or that now meet one, and the fixed-radius estimator
 * DETP (the segments crossing a disc of radius r in the receiver's tangent
 * plane, E = sum(Phi) / (pi r^2)) updated as
 *     E(t) = E(t-1) + E(new segments) - E(old segments)
 * at receivers that stayed where they were; receivers that are new or
 * moved (camera hits on a moving object, a camera that moved) are
 * estimated from all segments (the paper's mobile vertices).
 *
 * Receivers are the camera's hits at pixel centres; the indirect hook
 * answers a hit with the nearest receiver within r whose normal agrees
 * (the primary hit itself: its own receiver). The light they carry is the
 * indirect light: segments after a path's first surface (from the start
 * for the background's and emissive surfaces' photons, whose light reaches
 * surfaces only by gathering), with POV-Ray's brightness and
 * recursion_limit rules (pm_photon.h). Direct light from light_sources is
 * the Whitted pass's.
 *
 * Exactness: each receiver's sum is an integer (every segment's share
 * quantised once, at a scale fixed in the first frame), so the incremental
 * sums equal those of tracing every path and estimating every receiver
 * anew with the same random streams (settings.full), bit for bit, whatever
 * the order or thread count. What "moved" means: a top-level object whose
 * transform or geometry (shape parameters, mesh vertices and triangles,
 * CSG members, clip and bound) hashes differently from the previous frame;
 * shapes whose data are not hashed (lathe, prism, blob, isosurface, ...)
 * count as moved in every frame when objects may change. A light that
 * changed, an emissive object that moved, or a change in the number of
 * objects makes the frame a full one (moving lights are outside the
 * paper's scope). Textures that change with the clock are not detected. */
#ifndef PT_PM_DETP_H
#define PT_PM_DETP_H
#include <stdint.h>
#include "accel.h"
#include "pm.h"
#include "progress.h"

typedef struct pm_detp pm_detp;

typedef struct {
    long photons;      /* photon paths (all sources together) */
    double radius;     /* disc radius in world units; 0: PM_DETP_RADIUS of the first frame's bounding-box diagonal */
    int full;          /* 1: every frame traces every path and estimates every receiver anew */
    int max_bounces;
    uint64_t seed;
    int threads;       /* <= 0: all cores */
    volatile int *cancel;
    progress *progress;
} pm_detp_settings;

#define PM_DETP_PHOTONS 100000
#define PM_DETP_RADIUS 0.02

typedef struct {
    long paths, segments;           /* the paths and their segments this frame */
    long paths_retraced;            /* paths traced again in part or whole (all on a full frame) */
    long segments_old, segments_new; /* segments removed and added (the paper's O and N) */
    long receivers, receivers_full; /* camera hits; those estimated from all segments */
    long objects, moving_objects;   /* top-level objects; those that moved since the previous frame */
    int full_frame;                 /* 1: everything traced and estimated anew */
    const char *full_reason;        /* why (static text) */
    long rays;                      /* intersection queries (photons, validity tests, camera) */
    long lookups, lookups_none;     /* hook calls, and those no receiver answered (they got 0;
                                       pm_detp_lookups, after the render) */
    double radius;
    double t_trace, t_estimate;     /* seconds: paths (tests and tracing), the receivers' sums */
} pm_detp_stats;

/* What the caller knows about the frame against the previous one: the
 * lights changed (any field); objects may have changed (the parser read a
 * per-frame value outside camera and lights). A first frame is full. */
typedef struct {
    int lights_changed;
    int objects_may_change;
} pm_detp_frame_info;

void pm_detp_default_settings(pm_detp_settings *s);
pm_detp *pm_detp_new(const pm_detp_settings *s);
void pm_detp_free(pm_detp *dp);
/* One frame: sc and a must stay alive until the next frame or free (the
 * hook reads them). width x height: the image the camera's hits are taken
 * for. */
pt_status pm_detp_frame(pm_detp *dp, const scene *sc, const accel *a, int width, int height,
                        const pm_detp_frame_info *fi, pm_detp_stats *st, diag *d);
/* Where the stages report (NULL: nowhere); the settings' progress until set. */
void pm_detp_set_progress(pm_detp *dp, progress *p);
/* Hook calls since the frame began, and those no receiver answered. */
void pm_detp_lookups(const pm_detp *dp, long *lookups, long *none);
/* shade_indirect_fn: E / pi of the receiver that answers the hit (0 when
 * none does). */
rgb pm_detp_indirect(void *ctx, const accel_hit *hit, vec3 n, int thread);
/* The receivers' integer sums, 3 per pixel (row by row; 0 without a
 * hit), and the scale that turns them into irradiance (E = sum * scale). */
const int64_t *pm_detp_sums(const pm_detp *dp, long *npixels, double *scale);
/* FNV-1a of every stored segment's origin, direction, hit distance, hit
 * object and power, path by path (tests: the paths themselves equal). */
uint64_t pm_detp_paths_hash(const pm_detp *dp);

#endif
