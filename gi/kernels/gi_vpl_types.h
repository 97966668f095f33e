/* gi_vpl_types.h - records of VPL reflectance filtering (seed 003: Maletz,
 * Bowers and Wang, "Reflectance Filtering for Interactive Global
 * Illumination in Semi-Glossy Scenes") shared by the host (gi/gi_vpl.c) and
 * the kernel (gi_vpl.cl), which is compiled by OpenCL and as C. Fixed-size,
 * float4-aligned records; sizes are checked on the host. */
#ifndef GI_VPL_TYPES_H
#define GI_VPL_TYPES_H

/* A node of the VPL tree in the traversal array (DFS pre-order, cut to the
 * min-max band: gi_vpl.h). A leaf is one VPL; an inner node stands for its
 * VPLs with their mean position and diffuse radiance and one filtered
 * Phong lobe (paper, eq. 1 and eqs. 3-4). */
typedef struct {
    float p[4];    /* mean position; w: summed area of the VPLs */
    float n[4];    /* mean normal, normalised; w: |mean normal| (1 for a leaf) */
    float ld[4];   /* diffuse radiance L_d (rgb); w: number of VPLs */
    float ls[4];   /* lobe magnitude l_s (rgb); w: filtered exponent kappa (0: no lobe) */
    float d[4];    /* lobe axis, unit (the direction the lobe reflects into); w: unused */
    int skip;      /* the next node after this node's subtree; == node count at the end */
    int accept;    /* 1: accepted whatever its solid angle (a leaf, or a node on the max cut) */
    int pad[2];
} gi_dev_vpl_node;

/* A gather point: a pixel's first hit, or a VPL gathering the next bounce. */
typedef struct {
    float p[4];    /* position; w: unused */
    float n[4];    /* shading normal, on the side light is gathered from */
    float wo[4];   /* unit direction towards the viewer (eye mode) */
    float kd[4];   /* Lambertian albedo (rgb; f = kd / pi) */
    float kg[2][4];/* glossy sub-lobes: weight (rgb, metallic tint included); w: exponent */
    int tab[2];    /* their E(mu) tables (index into the table array; -1: none) */
    int pad[2];
} gi_dev_vpl_point;

/* GI_VPL_TAB floats per table: GLOSSY_NMU values of E(mu), then Eavg */
#define GI_VPL_TAB 66
/* kernel modes */
#define GI_VPL_EYE 0    /* out[4 p]: reflected radiance towards wo (rgb) */
#define GI_VPL_BOUNCE 1 /* out[12 p ..]: irradiance sum Le cos dw (rgb), glossy sum Le dw (rgb),
                           sum lum(Le dw) * mirror direction (xyz) */

#endif
