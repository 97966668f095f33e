/* gi_caustic.cl - the caustic layer's radiance estimate by scattering photon
 * volumes over the eye G-buffer (McGuire and Luebke, "Hardware-Accelerated
 * Global Illumination by Image Space Photon Mapping", HPG 2009, seed 002:
 * algorithm step 4, "scatter photon volumes", equations 1-3).
 * Compiled by OpenCL and as C (gi_shim.h), like gi_lighting.cl.
 *
 * The paper rasterises an icosahedron around each photon and lets the depth
 * test pick the eye-visible surface point s under every covered pixel. There
 * is no rasteriser here: the host bins the photons into GI_CAUS_TILE-pixel
 * tiles of the G-buffer (a photon goes to each tile whose G-buffer points'
 * bounding box its kernel sphere reaches, gi_caustic.c), and one work-item
 * per pixel adds up the photons of its tile. Each (photon, pixel) pair gets
 * exactly the value the paper's fragment shader computes for it, without
 * float atomics (OpenCL 1.2) and without the near-plane clipping the paper
 * lists among its limitations. */

/* The filter kernel kappa (equations 2 and 3) of photon q at receiver point
 * (sx, sy, sz). The ellipsoid has radii r_xy in the photon's surface plane
 * and r_z along its normal n_p. Equation 2 as printed stretches instead of
 * compresses along n_p when r_xy > 2 r_z (see the digest), so the distance
 * is the ellipsoid's own: t = sqrt((d_plane / r_xy)^2 + (d_n / r_z)^2).
 * Falloff (equation 3's kernel1D): the cone 3 (1 - t) / (pi r_xy^2), which
 * integrates to 1 over the disc of radius r_xy in the photon's plane (the
 * paper's Fig. 2 "conic falloff"); 0 for t >= 1. */
static inline float gi_caus_kappa(GI_GLOBAL const gi_caus_photon *q, float sx, float sy, float sz)
{
    float dx = q->x[0] - sx, dy = q->x[1] - sy, dz = q->x[2] - sz;
    float dn = dx * q->n[0] + dy * q->n[1] + dz * q->n[2];
    float d2 = dx * dx + dy * dy + dz * dz;
    float dp2 = d2 - dn * dn;
    if (dp2 < 0.0f) dp2 = 0.0f;
    float t2 = dp2 * q->inv_rxy2 + dn * dn * q->inv_rz2;
    if (!(t2 < 1.0f)) return 0.0f;
    return (3.0f / GI_PI_F) * (1.0f - sqrt(t2)) * q->inv_rxy2;
}

/* Equation 1 without the BSDF: what photon q adds to the receiver's
 * irradiance (E/pi units) at s with normal n facing the viewer, of finish
 * brilliance b: Phi * kappa * g where the light arrives on n's side
 * (c = w_i . n > 0). The paper's equation 1 multiplies by c; the photon
 * density already carries that cosine (a beam of photons spreads over
 * area / c), so the estimate is Jensen's sum f Phi / area, with POV-Ray's
 * own weight g = c^b / max(c, 0.1): its gather shades each photon as a
 * light through the finish's diffuse term, cos^brilliance, after dividing
 * by the cosine, at most tenfold (trace.cpp, ComputePhotonDiffuseLight and
 * ComputeDiffuseColour). g is 1 for brilliance 1 above c = 0.1. The BSDF's
 * diffuse * pigment is applied by the shader. A photon arriving on the
 * other side (c < 0) lights a finish with diffuse_back through it, as
 * POV-Ray's gather shades it as a light from behind: weight back = B / A
 * (the shader's diffuse A times it gives B) at |c|^b; back 0: not at all.
 * Such a photon is divided by 0.1, not by |c|: POV-Ray takes the cosine
 * against the normal turned to the viewer, negative from behind, and its
 * clamp to at least 0.1 makes the division tenfold whatever the angle
 * (ComputePhotonDiffuseLight; ComputeDiffuseColour then takes |c|^b
 * times diffuse_back). */
static inline void gi_caus_add(GI_GLOBAL const gi_caus_photon *q, float sx, float sy, float sz, float nx, float ny,
                               float nz, float b, float back, float *e)
{
    float c = q->w[0] * nx + q->w[1] * ny + q->w[2] * nz;
    float side = 1.0f, div;
    if (c <= 0.0f) {
        if (!(back > 0.0f) || c == 0.0f) return;
        c = -c;
        side = back;
        div = 0.1f;
    } else {
        div = c > 0.1f ? c : 0.1f;
    }
    float k = gi_caus_kappa(q, sx, sy, sz);
    if (k <= 0.0f) return;
    if (c > 1.0f) c = 1.0f;
    /* c^b as exp2(b log2 c), c > 0 here: the native pair, where pow cost
     * PoCL as much as the rest of the sum (bench_caustics on glassthing,
     * whose walls have brilliance 0.6) */
    k *= side * (b == 1.0f ? c : native_exp2(b * native_log2(c))) / (div < 1.0f ? div : 1.0f);
    e[0] += q->phi[0] * k;
    e[1] += q->phi[1] * k;
    e[2] += q->phi[2] * k;
}

/* Step 4 of the paper, the scatter: one work-item per G-buffer pixel
 * (w x h), summing the photons listed for its tile, tile_idx[tile_off[t] ..
 * tile_off[t + 1]), tiles in rows of tiles_x. Writes e[4 * pixel] (rgb, 0). */
__kernel void gi_k_caustic_splat(__global const gi_caus_photon *ph, __global const int *tile_off,
                                 __global const int *tile_idx, __global const gi_caus_pixel *gbuf, int w, int h,
                                 int tiles_x, __global float *e)
{
    int g = (int)get_global_id(0);
    if (g >= w * h) return;
    __global const gi_caus_pixel *px = &gbuf[g];
    float acc[3] = {0.0f, 0.0f, 0.0f};
    if (px->valid > 0.0f) {
        int t = (g / w) / GI_CAUS_TILE * tiles_x + (g % w) / GI_CAUS_TILE;
        for (int k = tile_off[t]; k < tile_off[t + 1]; k++)
            gi_caus_add(&ph[tile_idx[k]], px->s[0], px->s[1], px->s[2], px->n[0], px->n[1], px->n[2], px->brilliance,
                        px->back, acc);
    }
    for (int c = 0; c < 3; c++) e[4 * g + c] = isfinite(acc[c]) ? acc[c] : 0.0f;
    e[4 * g + 3] = 0.0f;
}
