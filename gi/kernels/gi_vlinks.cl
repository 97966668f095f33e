/* gi_vlinks.cl - light exchange over vertex links (seed 001: Schmitz,
 * Tavenrath and Kobbelt, "Interactive Global Illumination for Deformable
 * Geometry in CUDA", equations 3-5). Compiled by OpenCL and as C
 * (gi_shim.h, gi_vlinks_c.c), like gi_lighting.cl.
 *
 * Elements are mesh vertices (one per side of the surface). Element i's
 * links k = off[i] .. off[i+1] name a peer element peer[k] and a weight
 * w[k]: the barycentric share of the peer among the i's n_C cosine-weighted
 * rays, divided by n_C, merged per peer. With cosine-weighted directions
 * (pdf cos/pi) the mean radiance over the rays is E/pi, so the gathered
 * sum_k w[k] L_out(peer[k]) is the element's incoming E/pi, and a
 * Lambertian element sends on L_out = rho E/pi. Values are 4 floats an
 * element (RGB, unused). */

/* One Jacobi sweep (one bounce): from the previous bounce's outgoing
 * radiance bin, each element gathers g = sum w L; itot += g (the indirect
 * E/pi so far), bout = rho g (the next bounce's outgoing radiance). Reads
 * only other elements' bin: no atomics, any order. */
__kernel void gi_k_vgather(__global const int *off, __global const int *peer, __global const float *w,
                           __global const float *bin, __global const float *rho, int n, __global float *bout,
                           __global float *itot)
{
    int i = (int)get_global_id(0);
    if (i >= n) return;
    float s0 = 0.0f, s1 = 0.0f, s2 = 0.0f;
    for (int k = off[i]; k < off[i + 1]; k++) {
        int j = peer[k];
        float wk = w[k];
        s0 += wk * bin[4 * j];
        s1 += wk * bin[4 * j + 1];
        s2 += wk * bin[4 * j + 2];
    }
    float s[3] = {s0, s1, s2};
    for (int c = 0; c < 3; c++) {
        float g = isfinite(s[c]) ? s[c] : 0.0f;
        itot[4 * i + c] += g;
        bout[4 * i + c] = rho[4 * i + c] * g;
    }
    itot[4 * i + 3] = 0.0f;
    bout[4 * i + 3] = 0.0f;
}

/* One-ring smoothing (equations 5 and 6): the mean of the element and its
 * neighbours nb[off[i] .. off[i+1]) (the one-ring, feature edges already
 * left out by the host: |N^(v)| + 1 in the denominator). */
__kernel void gi_k_vsmooth(__global const int *off, __global const int *nb, __global const float *in, int n,
                           __global float *out)
{
    int i = (int)get_global_id(0);
    if (i >= n) return;
    float s[3] = {in[4 * i], in[4 * i + 1], in[4 * i + 2]};
    int m = 1;
    for (int k = off[i]; k < off[i + 1]; k++) {
        int j = nb[k];
        s[0] += in[4 * j];
        s[1] += in[4 * j + 1];
        s[2] += in[4 * j + 2];
        m++;
    }
    for (int c = 0; c < 3; c++) out[4 * i + c] = s[c] / (float)m;
    out[4 * i + 3] = 0.0f;
}
