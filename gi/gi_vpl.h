/* gi_vpl.h - VPL reflectance filtering (seed 003: Maletz, Bowers and Wang,
 * "Reflectance Filtering for Interactive Global Illumination in Semi-Glossy
 * Scenes"): a binary tree over virtual point lights, their lobes filtered
 * bottom-up, and the min-max cut of the tree that the gather kernel
 * (gi/kernels/gi_vpl.cl) walks per gather point.
 *
 * A VPL has a position, the unit normal of the side it shines from, an area
 * (its share of the surfaces), a diffuse radiance l_d and one normalised
 * Phong lobe (eq. 1): L_e(w) = l_d + l_s (kappa+1)/(2 pi) max(w.d, 0)^kappa.
 *
 * Tree (section "kd-tree build"): every node splits its VPLs into two equal
 * halves by 2-means under eq. 5's distance
 *   dist(i, c) = |p_i - p_c| / (D/2) + sqrt(2 - 2 n_i.n_c) / 4
 * (D the scene's bounding-box diagonal): centres start at the VPL farthest
 * from the node's centroid and the VPL farthest from that one (deterministic
 * where the paper draws them at random), VPLs are keyed by
 * dist(i, c1) - dist(i, c2) and split at the median, the centres move to
 * the halves' means, `iterations` times (the paper: "a few"; default 3).
 *
 * Filtering (eqs. 3-4, Toksvig): a node's diffuse radiance is the mean of
 * its VPLs'; its lobe has the mean exponent kappa of its non-zero lobes,
 * the axis of the magnitude-weighted (luminance of l_s) mean d of their
 * axes, the exponent scaled by f_t = |d| / (|d| + kappa (1 - |d|)), and the
 * magnitude l_s = (sum of the VPLs' l_s) / (number of VPLs): the paper
 * averages over the non-zero lobes only, which overstates a node's glossy
 * energy when few of its VPLs have a lobe; dividing by all keeps the
 * node's energy the sum of its VPLs'. Its position is the mean position,
 * its area the summed area, its normal the normalised mean normal.
 *
 * Min-max cuts (section 4.3): the paper keeps the nodes whose "normal
 * variance" lies between sigma2 = 9 (max cut) and sigma1 = 40 (min cut) and
 * leaves the unit unstated. We measure a node's spread as 100 times the
 * largest eq. 5 distance of its VPLs from its centre (mean position,
 * normalised mean normal): percent of the half-diagonal, with the normal
 * term. Nodes wider than the min cut are always subdivided and left out of
 * the array; a node at most as wide as the max cut (or a leaf) is accepted
 * whatever its solid angle, its subtree left out. Subtrees that jump over
 * the band are cut where they cross it, so no VPL is lost. */
#ifndef PT_GI_VPL_H
#define PT_GI_VPL_H
#include "kernels/gi_vpl_types.h"
#include "scene.h"
#include "vec.h"

typedef struct {
    vec3 p, n;      /* position; unit normal of the side it shines from */
    double area;    /* its share of the surfaces */
    rgb ld;         /* diffuse radiance */
    rgb ls;         /* lobe magnitude (eq. 1); 0: no lobe */
    vec3 d;         /* lobe axis, unit */
    double kappa;   /* lobe exponent (0: no lobe) */
} gi_vpl;

typedef struct gi_vpl_tree gi_vpl_tree;

/* The tree over v[0 .. n) (copied; n >= 1), D the scene diagonal; NULL when
 * out of memory. */
gi_vpl_tree *gi_vpl_tree_build(const gi_vpl *v, int n, double diag, int iterations);
void gi_vpl_tree_free(gi_vpl_tree *t);
int gi_vpl_tree_size(const gi_vpl_tree *t);       /* nodes of the full tree, 2n - 1 */
/* Filters the lobes again from new VPL radiances (same positions and
 * normals, the tree kept): v as in the build, n the same. */
void gi_vpl_tree_relight(gi_vpl_tree *t, const gi_vpl *v);

/* The traversal array (DFS pre-order with skip links, gi_vpl_types.h) cut
 * to the band: min_cut, max_cut in the spread units above (the paper's 40
 * and 9); min_cut < 0: no min cut (the full tree from its root), max_cut < 0:
 * no max cut (only leaves are accepted unconditionally). *out is malloc'ed;
 * returns its node count, -1 when out of memory. */
int gi_vpl_tree_cut(const gi_vpl_tree *t, double min_cut, double max_cut, gi_dev_vpl_node **out);
/* The leaves alone, each accepted: brute-force gathering over every VPL. */
int gi_vpl_tree_leaves(const gi_vpl_tree *t, gi_dev_vpl_node **out);

/* A lobe merged from several (eq. 4 on their sum): sum_w_d is the sum of
 * w_i d_i (w_i >= 0 the lobes' luminance weights), sum_w the sum of w_i,
 * kappa their exponent; writes the unit axis and the scaled exponent. */
void gi_vpl_merge_axis(vec3 sum_w_d, double sum_w, double kappa, vec3 *axis, double *kappa_out);

#endif
