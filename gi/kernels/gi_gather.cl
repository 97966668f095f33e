/* gi_gather.cl - the ray-tracing stage's particle work (Chang, Park, Ihm 2015,
 * sections 4.3.1 and 4.3.2): gathering at the area particles the view uses,
 * and radiance estimation at the radiance particles it found.
 * Compiled by OpenCL and as C (gi_shim.h), like gi_lighting.cl. */

/* Indirect light gathering (section 4.3.1). With cosine-weighted links
 * (pdf cos/pi) the Monte Carlo estimate of the irradiance is
 *   E~^(i) = (pi / N_gather) sum_k L_in(p^(i), w_k),   L_in ~ L^(k*),
 * where k* is the end particle of gathering link k. In E/pi units this is
 * the plain mean of L^(k*) (lout, which includes emission). A link of -1
 * (the ray left the scene) sees the background radiance bg. One work-item
 * per used area particle i = used[t]; the result goes to eind[i] (4 floats).
 * Reads only: no atomics. */
__kernel void gi_k_gather(__global const int *glink, int ng, __global const float *lout, __global const int *used,
                          int nused, float bg_r, float bg_g, float bg_b, __global float *eind)
{
    int t = (int)get_global_id(0);
    if (t >= nused) return;
    int i = used[t];
    float s[3] = {0.0f, 0.0f, 0.0f};
    int miss = 0;
    __global const int *lk = &glink[(long)i * ng];
    for (int k = 0; k < ng; k++) {
        int j = lk[k];
        if (j < 0) {
            miss++;
            continue;
        }
        s[0] += lout[4 * j];
        s[1] += lout[4 * j + 1];
        s[2] += lout[4 * j + 2];
    }
    float inv = 1.0f / (float)ng;
    float e[3] = {(s[0] + bg_r * (float)miss) * inv, (s[1] + bg_g * (float)miss) * inv,
                  (s[2] + bg_b * (float)miss) * inv};
    for (int c = 0; c < 3; c++) eind[4 * i + c] = isfinite(e[c]) ? e[c] : 0.0f;
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
