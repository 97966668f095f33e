/* shade.h - Whitted integrator with POV-Ray 3.7's lighting model: camera
 * rays, direct light from every light type (with area-light sampling),
 * shadows, reflection, antialiasing; multithreaded over tiles. An optional
 * hook supplies the indirect diffuse term (GI modes plug in there). */
#ifndef PT_SHADE_H
#define PT_SHADE_H
#include <stdint.h>
#include "accel.h"
#include "diag.h"
#include "framebuffer.h"
#include "progress.h"
#include "rng.h"
#include "scene.h"
#include "shade_light.h"
#include "shade_media.h"

/* Irradiance-like indirect term at a diffuse hit: returns the incoming
 * indirect radiance weighting that multiplies pigment*diffuse (POV-Ray's
 * radiosity "ambient" replacement). `n` faces the viewer. */
typedef rgb (*shade_indirect_fn)(void *ctx, const accel_hit *hit, vec3 n, int thread);
/* Highlights (specular, phong) from light the indirect hook carries as
 * directed samples (the caustic layer's photons) on the layer surface s at
 * hit; the Lambertian share stays the indirect hook's. */
typedef rgb (*shade_highlight_fn)(void *ctx, const accel_hit *hit, const shade_light_surface *s, int thread);

/* Primary hits found before the render (the particle GI's view pre-pass
 * traces the same camera rays). primary_begin is asked once per render:
 * 1 when the hits it holds are those of this camera (sc->camera, compared
 * whole), image size and accel, traced with accel_intersect(a, org, dir,
 * tmin, INFINITY). Then, for the camera ray through the centre of pixel
 * (x, y) (camera_ray's org and dir: *org, *dir), primary returns 1 when it
 * holds its first hit on a surface without OBJ_NO_IMAGE: *hit (NULL: the
 * ray left the scene); shade.c shades it as if it had traced the ray, and
 * passes that same pointer on to the indirect hook (which may recognise its
 * own record). 0: the render computes and traces the ray itself. Used for
 * the first sample of a pixel at its centre only (no focal blur, camera
 * normal or mesh camera); primary is called from every render thread. */
typedef int (*shade_primary_begin_fn)(void *ctx, const scene *sc, const accel *a, int w, int h, double tmin);
typedef int (*shade_primary_fn)(void *ctx, int x, int y, vec3 *org, vec3 *dir, const accel_hit **hit);

typedef struct {
    int width, height;
    int threads;            /* <=0: all cores */
    uint64_t seed;
    int antialias;          /* 0 off, 1 POV-Ray +A adaptive (method 1), 2 fixed supersampling */
    double aa_threshold;    /* +A0.3 -> 0.3 */
    int aa_depth;           /* +R, default 3 */
    double aa_jitter;       /* +J amount (POV-Ray's Jitter_Amount), default 1; 0: no jitter */
    int spp;                /* fixed supersampling: samples per pixel (n x n grid rounded) */
    int max_trace_level;    /* 0 = scene's global_settings value */
    int use_ambient;        /* 1: add finish ambient * ambient_light (no GI); 0: GI supplies it */
    shade_indirect_fn indirect;
    void *indirect_ctx;
    shade_highlight_fn highlights; /* NULL: none */
    void *highlights_ctx;
    shade_primary_begin_fn primary_begin; /* both NULL: every camera ray is traced */
    shade_primary_fn primary;
    void *primary_ctx;
    volatile int *cancel;   /* set non-zero to stop early (SIGINT) */
    /* The render window x0,y0,x1,y1 (x1,y1 exclusive; all 0 = the whole
     * image): only these pixels are rendered, the others are 0. Every pixel
     * has its own random streams and the +A decisions of a pixel look at its
     * four neighbours' first-pass colours, so the first pass also covers a
     * one-pixel apron around the window: a window's pixels equal the whole
     * image's, bit for bit. */
    int window[4];
    progress *progress;     /* stages "render" and "antialias" count pixels (NULL: none) */
    /* POV-Ray's +Q quality level, 0..9 (default 9: everything), as POV-Ray
     * 3.7's QUALITY_n flags (povrayold.h): 0-1 pigment colour only, no
     * lighting; 2-3 diffuse and ambient light without shadows; 4 shadows;
     * 5 area lights (below: a point light at the centre); 6-7 refraction and
     * transmission; 8 reflection and normal perturbation; 9 media. Quick
     * colours (levels 0-5) are not modelled: pigments are evaluated. */
    int quality;
    /* 1 when a caustic layer carries the photons of the scene's lights
     * (the indirect hook adds it): shadow rays follow POV-Ray's photon
     * rule (shade_tex_shadow_ray's photon_light), except for surfaces with
     * photons { collect off }, which take no photons */
    int photon_shadows;
    /* a caustic layer's media photons, added at every sample of the media
     * on view rays (shade_media_env.photons); NULL: none */
    shade_media_photons_fn media_photons;
    void *media_photons_ctx;
} shade_settings;

typedef struct {
    long primary_rays, shadow_rays, secondary_rays;
    long discarded_samples;  /* NaN/Inf samples replaced by 0 */
    long unsupported;        /* hits on things the shader cannot evaluate */
    double seconds;
} shade_stats;

void shade_default_settings(shade_settings *s);
pt_status shade_render(const scene *sc, const accel *a, const shade_settings *s, framebuffer *fb, shade_stats *st, diag *d);
/* Radiance along one ray (for tests and other integrators). */
rgb shade_trace(const scene *sc, const accel *a, const shade_settings *s, vec3 org, vec3 dir, int thread, rng *r);
/* POV-Ray's first call of f_ridged_mf (func_internal.h), in a scene with two
 * or more functions calling it: the camera's rays through the pixel centres
 * of a width x height image in POV-Ray 3.7's render order (its 32 x 32
 * blocks, row by row; view.cpp's default Render_Block_Size), one thread,
 * shaded at +Q8 (no media: a sky's media cost the most and seldom call it)
 * until one calls it, whose H and lacunarity then weigh every call of the
 * render. None calling it: each call its own. Does nothing in other
 * scenes. */
void shade_ridged_mf_first(const scene *sc, const accel *a, int width, int height);
/* The Whitted direct term (every light, its attenuation, area grid and
 * shadows: what shade_tex_shade's direct callback gets) of surface s at hit h,
 * shaded from p (off the surface on the viewer's side). For shade_aov.c. */
rgb shade_direct(const scene *sc, const accel *a, const shade_light_surface *s, const accel_hit *h, vec3 p, rng *r);

#endif
