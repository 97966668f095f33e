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

typedef struct {
    double assumed_gamma;   /* 0 = not given */
    rgb ambient_light;      /* default <1,1,1> */
    int max_trace_level;    /* default 5 */
    double adc_bailout;     /* default 1/255 */
    int max_intersections;
    scene_radiosity radiosity;
    int photons;            /* a photons{} block was present */
    double photons_spacing;
    int photons_count;
    double irid_wavelength[3];
    int noise_generator;    /* default 2 */
    int number_of_waves;    /* ripples/waves sources, 0 = POV-Ray's 10 */
} scene_global;

#endif
