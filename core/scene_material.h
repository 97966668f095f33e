/* scene_material.h - the scene IR's appearance records: colours,
 * pigments, finishes, interiors and media, textures (scene.h). */
#ifndef PT_SCENE_MATERIAL_H
#define PT_SCENE_MATERIAL_H
#include "diag.h"
#include "vec.h"
#include "xform.h"
#include "scene_pattern.h"

/* Colour with POV-Ray's filter and transmit channels. */
typedef struct { double r, g, b, f, t; } colour5;
typedef struct { double r, g, b; } rgb;

/* ---------------------------------------------------------------- pigment */
typedef enum {
    PIGMENT_SOLID = 0,
    PIGMENT_OTHER,  /* a pattern the renderer does not evaluate yet: uses `colour` */
    PIGMENT_PATTERN /* `pat` evaluated through `map` (shade_pattern.h) */
} pigment_kind;

typedef struct scene_pigment {
    pigment_kind kind;
    colour5 colour;      /* solid colour (also the fallback for patterns) */
    const char *pattern; /* pattern keyword for PIGMENT_OTHER/PATTERN, else NULL */
    xform transform;     /* pattern space -> object space */
    /* PIGMENT_PATTERN (scene_pattern.h): the pattern (its warps follow
     * `transform`) and its colour_map or pigment_map; map NULL = the
     * pattern's POV-Ray default map (image_map: the image's colours). */
    const scene_pattern *pat;
    const scene_blend_map *map;
} scene_pigment;

/* ---------------------------------------------------------------- finish */
typedef struct {
    rgb ambient;          /* default 0.1 (POV-Ray 3.7 docs, finish) */
    rgb emission;         /* default 0 */
    double diffuse;       /* default 0.6 */
    double diffuse_back;  /* "diffuse a, b": backside value, default 0 */
    double brilliance;    /* default 1 */
    double crand;         /* default 0 */
    double phong;         /* default 0 */
    double phong_size;    /* default 40 */
    double specular;      /* default 0 */
    double roughness;     /* default 0.05 */
    double metallic;      /* highlight metallic, default 0 */
    rgb reflection_min;   /* reflection {min, max}; plain "reflection c" sets both */
    rgb reflection_max;
    double reflection_falloff;  /* default 1 */
    double reflection_exponent; /* as written, default 1 (never 0) */
    double reflection_metallic; /* default 0 */
    int fresnel;                /* reflection { fresnel on } */
    int conserve_energy;
    /* irid { amount thickness t turbulence u }: thin-film
     * interference as POV-Ray 3.7 models it, single precision as it keeps
     * them; defaults 0 */
    double irid, irid_thickness, irid_turb;
} scene_finish;

/* ---------------------------------------------------------------- interior */
typedef struct {
    double ior;           /* default 1 */
    double dispersion;    /* default 1 */
    int dispersion_samples; /* dispersion elements, default 7 (POV-Ray 3.7's interior.cpp), at least 2 */
    double fade_distance; /* 0 = off */
    double fade_power;
    rgb fade_colour;
    int caustics_set;
    double caustics;      /* POV-Ray's internal value, 45 * the given one (faked caustics) */
    /* the media { } blocks in order */
    int nmedia;
    const struct scene_media *const *media;
} scene_interior;

/* ---------------------------------------------------------------- media
 * Participating media (shade/shade_media.c renders
 * them). One media { } block as POV-Ray 3.7 keeps it. Defaults of a media
 * written at #version 3.5 or later (POV-Ray's Parse_Media): method 3,
 * intervals 1, samples 10,10; earlier: method 1, intervals 10, samples 1,1.
 * Always: ratio 0.9, confidence 0.9, variance 1/128, jitter 0,
 * aa_threshold 0.1, aa_level 3, scattering type 1 (isotropic),
 * eccentricity 0, extinction 1. */
typedef enum {
    MEDIA_ISOTROPIC = 1, MEDIA_MIE_HAZY, MEDIA_MIE_MURKY, MEDIA_RAYLEIGH, MEDIA_HENYEY_GREENSTEIN
} media_scatter_kind;

typedef struct scene_media {
    src_loc loc;
    int method;           /* 1, 2, 3 */
    int intervals;
    int min_samples, max_samples;
    double jitter, aa_threshold;
    int aa_level;
    double ratio, confidence, variance;
    rgb absorption, emission, scattering;
    int scattering_type;  /* media_scatter_kind (other values scatter isotropically) */
    double eccentricity;  /* Henyey-Greenstein g */
    double extinction;    /* scattering's share of the extinction (POV-Ray's sc_ext) */
    int collect;          /* photons collected (parsed; photons in media are not modelled) */
    /* density { } blocks (their colours multiply); each is a pigment
     * evaluated in media space; ndensity 0 = constant density 1 */
    int ndensity;
    const scene_pigment *const *density;
    /* media space -> the container's object space (interior media: the
     * object's transforms written before the interior are undone here, so
     * object -> world is the container's transform), or -> world
     * (atmospheric media) */
    xform transform;
} scene_media;

/* A texture: one pigment, finish and (later) normal. Layered textures are a
 * list linked through `next`, the first entry on top. */
typedef struct scene_texture {
    scene_pigment pigment;
    scene_finish finish;
    int has_normal;            /* a normal{} block was given (not evaluated yet) */
    xform transform;           /* texture transform (applied after the object's) */
    struct scene_texture *next;
    src_loc loc;
    /* normal (scene_pattern.h): NULL = unperturbed. A patterned
     * texture (texture_map, checker/hexagon/brick of textures, average,
     * tiles) has `pat` and `map` (MAP_TEXTURE) set; its pigment and finish
     * then hold the first entry's look for code that needs one colour. */
    const scene_normal *normal;
    const scene_pattern *pat;
    const scene_blend_map *map;
    /* `texture { uv_mapping ... }`: the texture is
     * evaluated at the hit's <u, v, 0> (POV-Ray's UV_MAP_PATTERN), with its
     * own transforms only */
    int uv_mapping;
    /* uv_mapping: the transforms applied to the texture from outside (its
     * object's), which POV-Ray 3.7 composes into the UV_MAP_PATTERN's own
     * warps (texture.cpp Transform_Textures): they move no point, but its
     * layers' normals are warped by them around their perturbation
     * (trace.cpp ComputeOneTextureColour pushes the texture on the warps
     * list; ComputeLightedTexture's Warp_Normal / UnWarp_Normal), so a
     * rotated uv-mapped object's bumps turn with it. uv_warped: any. */
    xform uv_warp;
    int uv_warped;
} scene_texture;

#endif
