/* gi_gather.cl - the ray-tracing stage's particle work (Chang, Park, Ihm 2015,
 * sections 4.3.1 and 4.3.2): gathering at the area particles the view uses,
 * and radiance estimation at the radiance particles it found.
 * Compiled by OpenCL and as C (gi_shim.h), like gi_lighting.cl. */

/* Indirect light gathering (section 4.3.1). With cosine-weighted links
 * (pdf cos/pi) the Monte Carlo estimate of the irradiance is
 *   E~^(i) = (pi / N_gather) sum_k L_in(p^(i), w_k),   L_in ~ L^(k*),
 * where k* is the end particle of gathering link k. In E/pi units this is
 * the plain mean of L^(k*) (lout, which includes emission). A link of -1
 * either left the scene or hit where no particle answers. Beyond the paper,
 * which leaves open scenes out: a link that left the scene sees the sky,
 * and one that hit where no particle answers sees the far field; the
 * geometry stage summed their share of the mean into esky[4i..4i+2]
 * (gi_links.h).
 * One work-item per used area particle i = used[t]; the result goes to
 * eind[i] (4 floats). Reads only: no atomics. */
__kernel void gi_k_gather(__global const int *glink, int ng, __global const float *lout, __global const int *used,
                          int nused, __global const float *esky, __global float *eind)
{
    int t = (int)get_global_id(0);
    if (t >= nused) return;
    int i = used[t];
    float s[3] = {0.0f, 0.0f, 0.0f};
    __global const int *lk = &glink[(long)i * ng];
    for (int k = 0; k < ng; k++) {
        int j = lk[k];
        if (j < 0) continue;
        s[0] += lout[4 * j];
        s[1] += lout[4 * j + 1];
        s[2] += lout[4 * j + 2];
    }
    float inv = 1.0f / (float)ng;
    __global const float *sk = &esky[4 * (long)i];
    for (int c = 0; c < 3; c++) {
        float e = s[c] * inv + sk[c];
        eind[4 * i + c] = isfinite(e) ? e : 0.0f;
    }
    eind[4 * i + 3] = 0.0f;
}

/* Radiance estimation at radiance particles (section 4.3.2):
 *   L-bar^(l) = f_rd^(l) sum_m phi~^(m) / sum_m dA^(m),   phi~^(m) = E~^(m) dA^(m),
 * over the estimation list of l. Dividing by the summed particle areas
 * rather than pi r^2 is the paper's fix for boundary bias. We store the
 * E/pi part, sum_m (E~/pi)^(m) dA^(m) / sum_m dA^(m): the Whitted pass
 * multiplies it by diffuse * pigment at the hit (shade.c), which is
 * f_rd^(l) * pi in these units and lets textures modulate indirect light.
 * One work-item per found radiance particle found[t]; eind holds the
 * gathered E~/pi of every area particle; the result goes to vout[t]. */
__kernel void gi_k_estimate(__global const gi_dev_particle *part, __global const int *list_off,
                            __global const int *list_idx, __global const float *eind, __global const int *found,
                            int nfound, __global float *vout)
{
    int t = (int)get_global_id(0);
    if (t >= nfound) return;
    int l = found[t];
    float s[3] = {0.0f, 0.0f, 0.0f};
    float a = 0.0f;
    for (int q = list_off[l]; q < list_off[l + 1]; q++) {
        int m = list_idx[q];
        float da = part[m].area;
        s[0] += eind[4 * m] * da;
        s[1] += eind[4 * m + 1] * da;
        s[2] += eind[4 * m + 2] * da;
        a += da;
    }
    float inv = a > 0.0f ? 1.0f / a : 0.0f;
    for (int c = 0; c < 3; c++) {
        float v = s[c] * inv;
        vout[4 * t + c] = isfinite(v) ? v : 0.0f;
    }
    vout[4 * t + 3] = 0.0f;
}
