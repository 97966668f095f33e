/* gi_vpl.cl - gathering light from the VPL tree of seed 003 (Maletz, Bowers
 * and Wang, "Reflectance Filtering for Interactive Global Illumination in
 * Semi-Glossy Scenes"): per gather point, a stackless walk (Carr et al.
 * 2006: DFS pre-order array, skip links) over the nodes of the tree cut to
 * the min-max band (gi_vpl.h), accepting a node when its solid angle
 * area / d^2 is below `thr` (the paper's 0.02) or when it is marked accept
 * (a leaf, or a node on the max cut), else descending to its first child.
 * Every accepted node acts as one VPL with its mean position, diffuse
 * radiance and filtered lobe (eq. 1):
 *   L_e(s, w) = l_d + l_s (kappa + 1) / (2 pi) max(w . d, 0)^kappa,
 * and the point sums (eq. 2)
 *   L_o(p, wo) = sum L_e(s, -w) f_r(w, wo) (w . n_p) dw,
 * w the unit direction from p to s, f_r = kd / pi + the glossy sub-lobes
 * (core/glossy_lobe.h, the lobe the path tracer samples), and dw the solid
 * angle of the node taken as a disc of its summed area facing along its
 * mean normal: 2 pi (1 - d / sqrt(d^2 + A / pi)) cos_s (A cos_s / d^2 far
 * away, bounded by 2 pi near it, where the paper reads a disc table).
 * Visibility between p and the VPLs is not tested (the paper's stated
 * limitation).
 *
 * Mode GI_VPL_EYE writes L_o (rgb) at out[4 t]; mode GI_VPL_BOUNCE, for a
 * VPL gathering the next bounce (paper, section "multi-bounce"), writes
 * out[12 t ..]: sum L_e cos dw (irradiance, rgb), sum L_e dw over the upper
 * side (what a glossy lobe reflects, rgb) and sum lum(L_e dw) r(w) with r(w)
 * the mirror direction of w (the reflected lobes' axes, merged on the host
 * by eq. 4). visits[t]: nodes the walk looked at. Compiled by OpenCL and, as
 * C, by gi/gi_cl_c.c. */
__kernel void gi_k_vpl_gather(__global const gi_dev_vpl_point *pts, int npts, __global const gi_dev_vpl_node *nodes,
                              int nnodes, __global const float *tabs, float thr, int mode, __global float *out,
                              __global int *visits)
{
    int t = (int)get_global_id(0);
    if (t >= npts) return;
    __global const gi_dev_vpl_point *pt = &pts[t];
    const float px = pt->p[0], py = pt->p[1], pz = pt->p[2];
    const float nx = pt->n[0], ny = pt->n[1], nz = pt->n[2];
    const float ox = pt->wo[0], oy = pt->wo[1], oz = pt->wo[2];
    const float mo = nx * ox + ny * oy + nz * oz;
    /* mirror direction of wo */
    const float rx = 2.0f * mo * nx - ox, ry = 2.0f * mo * ny - oy, rz = 2.0f * mo * nz - oz;
    float acc[9] = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
    int i = 0, nv = 0;
    while (i < nnodes) {
        __global const gi_dev_vpl_node *nd = &nodes[i];
        nv++;
        float dx = nd->p[0] - px, dy = nd->p[1] - py, dz = nd->p[2] - pz;
        float d2 = dx * dx + dy * dy + dz * dz;
        float area = nd->p[3];
        if (!nd->accept && area >= thr * d2) {
            i++; /* too large a solid angle: its first child next */
            continue;
        }
        i = nd->skip;
        if (!(d2 > 0.0f)) continue;
        float dist = sqrt(d2);
        float wx = dx / dist, wy = dy / dist, wz = dz / dist;
        float cp = nx * wx + ny * wy + nz * wz;
        if (!(cp > 0.0f)) continue;
        float cs = -(nd->n[0] * wx + nd->n[1] * wy + nd->n[2] * wz);
        if (!(cs > 0.0f)) continue;
        float dw = 2.0f * GI_PI_F * (1.0f - dist / sqrt(d2 + area / GI_PI_F)) * cs;
        if (!(dw > 0.0f)) continue;
        float le[3] = {nd->ld[0], nd->ld[1], nd->ld[2]};
        float kappa = nd->ls[3];
        if (kappa > 0.0f) {
            float cl = -(nd->d[0] * wx + nd->d[1] * wy + nd->d[2] * wz);
            if (cl > 0.0f) {
                float s = (kappa + 1.0f) / (2.0f * GI_PI_F) * pow(fmin(cl, 1.0f), kappa);
                for (int c = 0; c < 3; c++) le[c] += nd->ls[c] * s;
            }
        }
        if (mode == GI_VPL_EYE) {
            float f[3] = {pt->kd[0] / GI_PI_F, pt->kd[1] / GI_PI_F, pt->kd[2] / GI_PI_F};
            float cr = rx * wx + ry * wy + rz * wz;
            for (int j = 0; j < 2; j++) {
                int tb = pt->tab[j];
                if (tb < 0) continue;
                __global const float *tab = tabs + (long)GI_VPL_TAB * tb;
                float g = glossy_lobe_f(pt->kg[j][3], tab, tab[GI_VPL_TAB - 1], cp, mo, cr);
                for (int c = 0; c < 3; c++) f[c] += pt->kg[j][c] * g;
            }
            for (int c = 0; c < 3; c++) acc[c] += le[c] * f[c] * cp * dw;
        } else {
            for (int c = 0; c < 3; c++) {
                acc[c] += le[c] * cp * dw;
                acc[3 + c] += le[c] * dw;
            }
            float lum = (0.2126f * le[0] + 0.7152f * le[1] + 0.0722f * le[2]) * dw;
            acc[6] += lum * (2.0f * cp * nx - wx);
            acc[7] += lum * (2.0f * cp * ny - wy);
            acc[8] += lum * (2.0f * cp * nz - wz);
        }
    }
    if (mode == GI_VPL_EYE) {
        for (int c = 0; c < 3; c++) out[4 * (long)t + c] = isfinite(acc[c]) ? acc[c] : 0.0f;
        out[4 * (long)t + 3] = 0.0f;
    } else {
        for (int c = 0; c < 9; c++) out[12 * (long)t + c] = isfinite(acc[c]) ? acc[c] : 0.0f;
        for (int c = 9; c < 12; c++) out[12 * (long)t + c] = 0.0f;
    }
    visits[t] = nv;
}
