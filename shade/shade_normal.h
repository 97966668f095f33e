/* shade_normal.h - POV-Ray 3.7 normal{} perturbation: the bump patterns
 * (bumps, dents, ripples, waves, wrinkles, quilted), any other pattern as a
 * height field sampled at four tetrahedral points (with bump_size, accuracy
 * and slope_map), normal_map blends and average. */
#ifndef PT_SHADE_NORMAL_H
#define PT_SHADE_NORMAL_H
#include "scene.h"
#include "shade_pattern.h"

/* Perturb the normal n (world space, facing the viewer) by `nm` evaluated
 * at p, given in the normal's owner space (texture space). `xf` is the
 * texture transform (texture -> world) whose inverse took the world point
 * to p: normals go into pattern space through it (NULL = none). The result
 * is normalised unless no_bump_scale is set (POV-Ray's Perturb_Normal; the
 * caller normalises after it in that case, as POV-Ray does). */
vec3 shade_normal_perturb(const scene_normal *nm, vec3 n, vec3 p, const xform *xf, const shade_pattern_ctx *c);

/* POV-Ray's Warp_Normal / UnWarp_Normal: a normal into / out of the space of
 * a pattern through the owner transform `xf` (may be NULL), an outermost
 * transform `outer` (may be NULL) and the pattern's transform warps (pat may
 * be NULL). Normalised before and after unless dont_scale. */
vec3 shade_normal_warp(vec3 n, const xform *xf, const xform *outer, const scene_pattern *pat, int dont_scale);
vec3 shade_normal_unwarp(vec3 n, const xform *xf, const xform *outer, const scene_pattern *pat, int dont_scale);

#endif
