/* shade_pattern.h - POV-Ray 3.7 pattern evaluation: warps, the pattern
 * functions, frequency/phase/wave types, blend-map lookup and pigments
 * (solid, patterned with color_map/pigment_map, image_map).
 *
 * This is the function the GI modes use to get a surface's colour where it
 * varies: shade_pigment_eval at the hit point (see also shade_texture.h,
 * shade_tex_pigment_at, which resolves texture transforms and texture_maps). */
#ifndef PT_SHADE_PATTERN_H
#define PT_SHADE_PATTERN_H
#include "scene.h"

/* What patterns may need besides the point. */
typedef struct {
    int noise_generator;  /* the scene's global_settings noise_generator (1..3) */
    vec3 ipoint;          /* world hit point (slope point_at) */
    vec3 normal;          /* perturbed world normal facing the viewer (slope, aoi); zero if unknown */
    vec3 dir;             /* ray direction (aoi) */
    int has_hit;          /* normal/dir are meaningful */
    int nwaves;           /* global_settings number_of_waves (default 10) */
    /* The hit's POV-Ray UV coordinates (accel_hit.uv) for patterns,
     * pigments, normals and textures with uv_mapping; has_uv 0 away from
     * a surface (they then use the point they are given). */
    int has_uv;
    double uv[2];
    unsigned long scene_serial; /* the scene's serial (object patterns cache their shapes by it); 0: none */
} shade_pattern_ctx;

/* A context for evaluating patterns away from a surface. */
shade_pattern_ctx shade_pattern_ctx_plain(const scene *sc);

/* Apply a pattern's warps (POV-Ray's Warp_EPoint) to p. */
vec3 shade_pattern_warp(const scene_pattern *pat, vec3 p);
/* Pattern value at an already warped point, with frequency, phase and the
 * wave type applied (POV-Ray's Evaluate_TPat). */
double shade_pattern_value(const scene_pattern *pat, vec3 tp, const shade_pattern_ctx *c);

/* Blend-map lookup (POV-Ray's Search_Blend_Map): indices of the entries
 * below and above v (equal when v is on or outside an end). */
void shade_blend_map_search(const scene_blend_map *m, double v, int *prev, int *cur);

/* Pigment colour (rgb, filter, transmit) at p in the pigment's owner space
 * (texture space for a texture's pigment). Returns 0 when no colour was
 * found (outside an image_map used `once`), POV-Ray's Compute_Pigment. */
int shade_pigment_eval(const scene_pigment *pg, vec3 p, const shade_pattern_ctx *c, colour5 *out);

/* The image coordinates (pixels, wrapped, row 0 at the top) of a warped
 * point (POV-Ray's map_pos); 0 outside a `once` image or without pixels. */
int shade_pattern_image_pos(const scene_image_map *im, vec3 tp, double *x, double *y);
/* The palette index of the pixel at image coordinates (nearest pixel), -1
 * for images without a palette. */
int shade_pattern_image_index(const scene_image_map *im, double x, double y);
/* The image's colour at image coordinates, interpolated as asked. */
colour5 shade_pattern_image_at(const scene_image_map *im, double x, double y);

/* A linear transform's transpose applied to a vector (POV-Ray's
 * MInvTransNormal: world normal -> pattern space). */
vec3 shade_pattern_normal_to_pattern(const xform *x, vec3 n);

#endif
