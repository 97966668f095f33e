/* scene_settings.h - the scene IR's global_settings, radiosity
 * included (scene.h). */
#ifndef PT_SCENE_SETTINGS_H
#define PT_SCENE_SETTINGS_H
#include "scene_material.h"

/* ---------------------------------------------------------------- global settings */
typedef struct {
    int enabled;            /* a radiosity{} block was present */
    int count;              /* default 35 */
    int recursion_limit;    /* default 2 */
    double error_bound;     /* default 1.8 */
    double pretrace_start, pretrace_end; /* 0.08, 0.04 */
    int nearest_count;      /* default 5 */
    double brightness;      /* default 1 */
    double gray_threshold;
    double low_error_factor;
    double minimum_reuse;
    int always_sample;
    int normal, media;
    /* The rest of POV-Ray 3.7's radiosity keywords. */
    double adc_bailout;     /* default 0.01 */
    double max_sample;      /* default -1 = no limit */
    double maximum_reuse;   /* default 0.2 */
    int direction_pool;     /* "count N, M": M, default max(1600, count) */
    int nearest_count_pretrace; /* "nearest_count N, M": M (adaptive pretrace), default 0 */
    int subsurface;
} scene_radiosity;

/* global_settings { photons { } } (POV-Ray 3.7, parser.cpp's defaults; the
 * reference's "Photons" section). Photons are shot only at objects with
 * photons { target } from lights whose merged flags allow it
 * (scene_photon_* in scene_shape.h). `given` has a bit per keyword seen
 * (SCENE_PH_*), so what a scene uses can be reported when it is not
 * modelled. */
enum {
    SCENE_PH_SPACING = 1u << 0, SCENE_PH_COUNT = 1u << 1, SCENE_PH_AUTOSTOP = 1u << 2, SCENE_PH_JITTER = 1u << 3,
    SCENE_PH_MAX_TRACE_LEVEL = 1u << 4, SCENE_PH_ADC_BAILOUT = 1u << 5, SCENE_PH_EXPAND = 1u << 6,
    SCENE_PH_GATHER = 1u << 7, SCENE_PH_RADIUS = 1u << 8, SCENE_PH_MEDIA = 1u << 9, SCENE_PH_SAVE_FILE = 1u << 10,
    SCENE_PH_LOAD_FILE = 1u << 11
};
typedef struct {
    int enabled;            /* a photons{} block was present (and gather max > 0) */
    src_loc loc;            /* its `photons` keyword */
    unsigned given;         /* SCENE_PH_* bits */
    double spacing;         /* surface separation, default 1 (count 0: it decides) */
    int count;              /* 0 = none: spacing decides; else the spacing is scaled to give ~count */
    double autostop;        /* default 0.5 (fraction of the target's bounding cone) */
    double jitter;          /* default 0.4 (fraction of a shooting cell) */
    int max_trace_level;    /* -1 = global_settings' */
    double adc_bailout;     /* -1 = global_settings' */
    double expand_tolerance;/* default 0.2 */
    int expand_min;         /* default 35 */
    int gather_min, gather_max; /* default 20, 100 */
    double radius[4];       /* gather radius, its multiplier, media radius, its multiplier: -1, 1, -1, 1 */
    int media_steps;        /* default 0: no media photons */
    double media_factor;    /* default 1 */
    const char *file;       /* save_file / load_file name (NULL none) */
    int load;               /* 1: load_file, 0: save_file */
} scene_photons;

typedef struct {
    double assumed_gamma;   /* 0 = not given */
    rgb ambient_light;      /* default <1,1,1> */
    int max_trace_level;    /* default 5 */
    double adc_bailout;     /* default 1/255 */
    int max_intersections;
    scene_radiosity radiosity;
    scene_photons photons;
    double irid_wavelength[3];
    int noise_generator;    /* default 2 */
    int number_of_waves;    /* ripples/waves sources, 0 = POV-Ray's 10 */
} scene_global;

#endif
