/* scene_pattern.h - IR for POV-Ray 3.7 patterns and what hangs off them:
 * warps (transforms, turbulence, repeat, black_hole, mapping warps), blend
 * maps (color_map, pigment_map, normal_map, slope_map, texture_map),
 * normals, images (image_map), and the atmosphere (fog, sky_sphere).
 * Included by scene.h; the parser fills these records, shade/ evaluates them
 * (shade_pattern.h, shade_normal.h, shade_texture.h, shade_atmos.h).
 *
 * Pattern space. A pattern is evaluated at a point p given in the space of
 * its owner (texture space for a pigment or normal of a texture, the parent's
 * warped point for an entry of a pigment_map/texture_map, world space for a
 * sky_sphere pigment). The point first goes through the inverse of the
 * owner's outermost `transform` (the transforms written after the last warp,
 * e.g. scene_pigment.transform), then through `warps[0..nwarps-1]` in order,
 * as POV-Ray's Warp_EPoint walks its warp list (its list holds transforms
 * as warps too; a transform written before a warp{} stays in `warps` as a
 * WARP_TRANSFORM, applied as its inverse). Classic turbulence (the
 * `turbulence`, `octaves`, `omega`, `lambda` keywords outside warp{}) is
 * always the last warp, as POV-Ray keeps it (Check_Turb). */
#ifndef PT_SCENE_PATTERN_H
#define PT_SCENE_PATTERN_H
#include "vec.h"
#include "xform.h"

struct scene_pigment;
struct scene_texture;
struct scene_normal;

/* ---------------------------------------------------------------- warps */
typedef enum {
    WARP_TRANSFORM,   /* p = inverse(transform)(p) */
    WARP_TURBULENCE,  /* p += DTurbulence(p) * turbulence (classic or warp{turbulence}) */
    WARP_REPEAT,
    WARP_BLACK_HOLE,
    WARP_CYLINDRICAL,
    WARP_SPHERICAL,
    WARP_TOROIDAL,
    WARP_PLANAR,
    WARP_CUBIC
} warp_kind;

typedef struct {
    warp_kind kind;
    xform transform;               /* WARP_TRANSFORM */
    /* turbulence (defaults octaves 6, omega 0.5, lambda 2) */
    int classic;                   /* the classic turbulence of the pattern (last warp) */
    vec3 turbulence;
    int octaves;
    double omega, lambda;
    /* repeat */
    int axis;                      /* 0..2 */
    double width;
    vec3 offset, flip;             /* flip: -1 on flipped axes, else 1 */
    /* black_hole */
    vec3 centre;
    double radius, strength, power;
    int inverted, bh_type, bh_repeat, uncertain;
    vec3 repeat_vec, uncertainty;
    /* cylindrical/spherical/toroidal/planar */
    vec3 orientation;              /* default <0,0,1> */
    double dist_exp;               /* default 0 */
    double major_radius;           /* toroidal, default 1 */
    double plane_offset;           /* planar */
} scene_warp;

/* ---------------------------------------------------------------- patterns */
typedef enum {
    PAT_PLAIN = 0,    /* no pattern (solid colour) */
    PAT_AGATE, PAT_AVERAGE, PAT_BOXED, PAT_BOZO, PAT_BRICK, PAT_BUMPS, PAT_CELLS,
    PAT_CHECKER, PAT_CRACKLE, PAT_CUBIC, PAT_CYLINDRICAL, PAT_DENTS, PAT_FACETS,
    PAT_GRADIENT, PAT_GRANITE, PAT_HEXAGON, PAT_IMAGE, PAT_LEOPARD, PAT_MARBLE,
    PAT_ONION, PAT_PIGMENT, PAT_PLANAR, PAT_QUILTED, PAT_RADIAL, PAT_RIPPLES,
    PAT_SPHERICAL, PAT_SPIRAL1, PAT_SPIRAL2, PAT_SPOTTED, PAT_SQUARE,
    PAT_TRIANGULAR, PAT_WAVES, PAT_WOOD, PAT_WRINKLES, PAT_MANDEL, PAT_JULIA,
    PAT_SLOPE, PAT_AOI, PAT_TILING, PAT_DENSITY, PAT_OBJECT,
    PAT_UNSUPPORTED,  /* parsed (name kept), evaluates to 0 */
    PAT_FUNCTION,     /* function { ... } (core/func.h) */
    PAT_PAVEMENT      /* pavement (shade/shade_pavement.h) */
} pattern_kind;

typedef enum { WAVE_RAMP, WAVE_SINE, WAVE_TRIANGLE, WAVE_SCALLOP, WAVE_CUBIC, WAVE_POLY } wave_kind;

/* An image for image_map / image_pattern / bump_map, decoded to linear
 * RGBFT floats (POV-Ray 3.7 gamma rules applied when loading). */
typedef struct scene_image {
    const char *path;       /* resolved file path */
    double gamma;           /* file gamma given in the scene, 0 = POV-Ray's default rules */
    int width, height;
    float *pixels;          /* width*height*5: r g b filter transmit, row 0 = top; NULL until
                               loaded (io/img_scene.h fills it after parsing) */
    int has_alpha;
    int clear;              /* some pixel has a filter or transmit other than 0
                               (sdl_image_note_clear; set with the pixels) */
    struct scene_image *next; /* the scene's list of images (scene.images) */
    unsigned char *indices; /* palette images: width*height palette indices, else NULL */
} scene_image;

typedef struct {
    const scene_image *image;   /* NULL: file not loaded (evaluates as transparent/0) */
    int map_type;               /* 0 planar, 1 spherical, 2 cylindrical, 5 torus */
    int interpolate;            /* 0 none, 2 bilinear, 3 bicubic, 4 normalised distance */
    int once;
    int use_alpha;
    double filter_all, transmit_all; /* applied to every pixel when set */
    int filter_all_set, transmit_all_set;
    double major_radius;        /* torus map */
    int material;               /* a material_map (texture chosen by palette index / red) */
    /* `repeat <u, v>` scales the mapped size (0 = 1);
     * `offset <u, v>` shifts the image, kept in pixels as POV-Ray keeps it
     * (-u * width, -v * height); use_index: bump_map heights from palette
     * indices */
    double repeat_u, repeat_v;
    double offset_x, offset_y;
    int use_index;
} scene_image_map;

typedef struct scene_pattern {
    pattern_kind kind;
    const char *name;          /* keyword ("bozo", "image_map", ...) */
    int noise_generator;       /* 0 = the scene's (global_settings), else 1..3 */
    wave_kind wave;            /* default ramp (triangle for marble, wood, spiral) */
    double exponent;           /* poly_wave exponent, default 1 */
    double frequency, phase;   /* default 1, 0 (0 for checker, brick, hexagon...) */
    const scene_warp *warps;   /* evaluation order */
    int nwarps;
    /* parameters */
    vec3 gradient;             /* normalised */
    vec3 brick_size;           /* default <8,3,4.5> */
    double mortar;             /* stored as POV-Ray stores it: given - 2e-10 */
    vec3 crackle_form;         /* default <-1,1,0> */
    double crackle_metric;     /* default 2 */
    double crackle_offset;
    int crackle_solid;
    double agate_turb;         /* default 1 */
    double control0, control1; /* quilted, default 1, 1 */
    int arms;                  /* spiral1/2 */
    scene_image_map image;     /* PAT_IMAGE */
    const struct scene_pigment *pigment; /* PAT_PIGMENT (pigment_pattern) */
    vec3 slope_dir;            /* PAT_SLOPE: direction (normalised), or the point_at point */
    double slope_lo, slope_hi; /* slope range as POV-Ray keeps it: value = (s - lo) / hi when hi != 0 */
    int slope_point_at;
    double slope_len, altit_len;   /* weights of slope and altitude (sum 1) */
    vec3 altit_dir;                /* altitude direction (normalised) */
    double altit_lo, altit_hi;     /* altitude range as the slope's */
    double facets_size, facets_coords, facets_metric;
    const struct scene_function *function; /* PAT_FUNCTION */
    /* PAT_MANDEL / PAT_JULIA (magnet 1 or 2 for the magnet fractals) */
    int magnet;
    int iterations, fractal_exponent; /* exponent default 2 */
    int interior_type, exterior_type; /* defaults 0, 1 */
    double ifactor, efactor;       /* defaults 1, 1 */
    double julia_c[2];             /* julia / magnet julia parameter */
    int tiling;                    /* PAT_TILING: tiling number 1..27 */
    const struct scene_density *density; /* PAT_DENSITY (NULL: file not read, evaluates to 0) */
    int density_interpolate;       /* 0 none, 1 trilinear, 2 tricubic */
    const struct scene_object *object;   /* PAT_OBJECT: inside 1, outside 0 */
    /* PAT_OBJECT: the serial of the scene that owns `object` (keys the
     * renderer's cache of its shapes where the caller names no scene: a
     * pigment function's evaluation) */
    unsigned long object_serial;
    /* `pigment/normal { uv_mapping ... }`: evaluated at
     * the hit's <u, v, 0> instead of the point it is given (POV-Ray's
     * UV_MAP_PATTERN: the transforms of the enclosing texture and object
     * do not apply, the pattern's own do) */
    int uv_mapping;
    /* PAT_PAVEMENT: number_of_sides, number_of_tiles, pattern, exterior,
     * interior, form (defaults 3, 1, 1, 0, 0, 0; each kept as POV-Ray keeps
     * it, an unsigned char) */
    int pave_sides, pave_tiles, pave_number, pave_exterior, pave_interior, pave_form;
} scene_pattern;

/* density_file df3 data (POV-Ray's DF3 format: three big-endian 16-bit
 * sizes, then nx*ny*nz samples of 1, 2 or 4 bytes, x fastest), values
 * scaled to 0..1 as POV-Ray reads them. */
typedef struct scene_density {
    const char *path;
    int nx, ny, nz;
    double *v;                     /* nx*ny*nz, x fastest, then y, then z */
} scene_density;

/* ---------------------------------------------------------------- blend maps */
typedef enum { MAP_COLOUR, MAP_PIGMENT, MAP_NORMAL, MAP_TEXTURE, MAP_SLOPE } map_kind;

typedef struct {
    double value;                          /* stored as float as POV-Ray does (SNGL) */
    double c[5];                           /* MAP_COLOUR: r g b filter transmit */
    const struct scene_pigment *pigment;   /* MAP_PIGMENT */
    const struct scene_normal *normal;     /* MAP_NORMAL */
    const struct scene_texture *texture;   /* MAP_TEXTURE (layer list) */
    double height, slope;                  /* MAP_SLOPE: <height, slope> */
} scene_map_entry;

typedef struct {
    map_kind kind;
    int n;
    const scene_map_entry *e;
} scene_blend_map;

/* ---------------------------------------------------------------- normals */
typedef struct scene_normal {
    const scene_pattern *pat;      /* PAT_PLAIN: no perturbation */
    double amount;                 /* bump_size / the float after the pattern, default 0.5 */
    double delta;                  /* accuracy, default 0.02 */
    int no_bump_scale;
    xform transform;               /* outermost transform (pattern space -> texture space) */
    const scene_blend_map *map;    /* normal_map, slope_map, or listed normals (checker...) */
} scene_normal;

/* ---------------------------------------------------------------- atmosphere */
typedef struct scene_fog {
    int type;                      /* 1 constant, 2 ground */
    double distance;
    double colour[5];              /* r g b filter transmit */
    vec3 up;                       /* ground fog: default <0,1,0> */
    double offset, alt;            /* ground fog */
    int has_turb;                  /* turbulence/octaves/omega/lambda given */
    vec3 turbulence;
    int octaves;
    double omega, lambda, turb_depth;
    struct scene_fog *next;
} scene_fog;

/* rainbow { } (angles in radians as POV-Ray keeps them: `angle` already
 * less half the width; arc and falloff angles halved). */
typedef struct scene_rainbow {
    double angle, width, distance, jitter;
    double arc_angle, falloff_angle, falloff_width;
    vec3 antisolar, up, right;     /* unit, perpendicular */
    const struct scene_pigment *pigment; /* gradient x through the colour_map */
    struct scene_rainbow *next;
} scene_rainbow;

typedef struct {
    int npigments;
    const struct scene_pigment **pigments; /* layered, first on top (evaluated at the ray direction) */
    xform transform;
    double emission[3];            /* default 1 (POV-Ray 3.7 sky_sphere emission) */
} scene_sky_sphere;

#endif
