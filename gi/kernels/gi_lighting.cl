/* gi_lighting.cl - the lighting stage of particle-space GI (Chang, Park, Ihm,
 * "Diffuse Global Illumination in Particle Spaces", MTAP 2015, section 4.2):
 * emission from lights into area particles, scattering along the particle
 * links, and the per-particle reflected radiance L^(i).
 *
 * Compiled by OpenCL (gi_cl.c) and, unchanged, as C through gi_shim.h
 * (gi_cl_c.c): both builds run this code. Units: see gi_types.h (E/pi). */

/* Emission (section 4.2.1). The paper gives point lights only, with
 *   phi^(i) += Phi_j/(4 pi) * dA^(i) cos(theta_i) / d_i^2.
 * partray follows POV-Ray's light model instead, so that the particles'
 * direct light is exactly what the Whitted pass shows (shade.c): a light of
 * colour C reaches a particle with E/pi = C * att * cos^brilliance * V, where
 * att is the spot/cylinder/fade attenuation (gi_light_attenuation) and V the
 * visibility fraction traced by Embree on the host (area lights: the average
 * over the light's grid). The host computes both when a light's geometry
 * changes and passes their product vis = att * V (a colour change reuses it,
 * and the kernel needs no pow for the spot's cos^tightness, slow on PoCL).
 * The direct flux is phi_d = pi * (E/pi) * dA.
 *
 * Outputs per particle i (4 floats each, w unused):
 *   edir[i] = direct E/pi,
 *   src[i]  = flux leaving i in the first bounce: rho * phi_d + pi * Le * dA
 *             (reflected direct light plus emission of a Lambertian emitter). */
__kernel void gi_k_emit(__global const gi_dev_particle *part, int n, __global const gi_dev_light *lights, int nlights,
                        __global const float *vis, __global float *edir, __global float *src)
{
    int i = (int)get_global_id(0);
    if (i >= n) return;
    __global const gi_dev_particle *pt = &part[i];
    float e[3] = {0.0f, 0.0f, 0.0f};
    for (int l = 0; l < nlights; l++) {
        float v = vis[(long)i * nlights + l];
        if (!(v > 0.0f)) continue;
        __global const gi_dev_light *lt = &lights[l];
        float d[3];
        gi_light_ray(lt, lt->pos[0], lt->pos[1], lt->pos[2], pt->p[0], pt->p[1], pt->p[2], d);
        float ci = pt->n[0] * d[0] + pt->n[1] * d[1] + pt->n[2] * d[2];
        if (ci < 1e-10f) continue; /* the other side's particle takes it (shade.c: backside rule) */
        float intensity = pt->brilliance != 1.0f ? pow(ci, pt->brilliance) : ci;
        float w = intensity * v; /* v = att * V */
        for (int c = 0; c < 3; c++) e[c] += lt->colour[c] * w;
    }
    for (int c = 0; c < 3; c++) {
        if (!isfinite(e[c])) e[c] = 0.0f;
        float phid = GI_PI_F * e[c] * pt->area;
        edir[4 * i + c] = e[c];
        src[4 * i + c] = pt->rho[c] * phid + GI_PI_F * pt->le[c] * pt->area;
    }
    edir[4 * i + 3] = 0.0f;
    src[4 * i + 3] = 0.0f;
}

/* Indirect light scattering (section 4.2.2, Fig. 5), as gathers: one launch
 * per bounce b, no atomics, no private packet state. Particle j receives
 *   recv_j = w_in * sum over q in [off[obase + j], off[obase + j + 1]) of bin[from[sbase + q]]
 * adds it to total_j (bounce 0 writes it), and sends bout_j = rho_j recv_j
 * on. The incoming lists say which links carry flux in this bounce (built
 * on the host, gi_particle.c, sources ascending: a fixed float summation
 * order, so every device gives the same sums):
 *  - bounce 0, the first bounce of the paper (all n_s x n_s links):
 *    the incoming scattering links of j (rin), bin = src (flux leaving the
 *    directly lit and emitting particles), w_in = 1/ns2: each link carries
 *    the paper's rho^(i) phi^(i) / n_s^2 (plus emission);
 *  - later bounces, WALK (the paper's single-link random bounces): every
 *    particle i sends all it received along ONE of its links, chosen at
 *    random with probability 1/ns2 per link (-1 links lose it: the ray
 *    left the scene). The choice c(i, b) is drawn once per particle and
 *    bounce (gi_hash, host), so the lists are fixed at geometry time and
 *    the walk is deterministic; w_in = 1. Expected deposit per link:
 *    rho^(i) recv^(i) / ns2, the same as the full fan-out and as the
 *    paper's per-packet choice (there, packets meeting at i choose
 *    independently; here they share i's choice: the same expectation,
 *    more correlation);
 *  - later bounces, FULL: all links again (rin), w_in = 1/ns2: the
 *    expectation itself, no random-walk noise.
 * Bounce convention: nb counts ALL scattering bounces, the first fan-out
 * included (nb = 1: fan-out only; nb = 0: no scattering, not run). With the
 * gathering step the rendered indirect light has up to nb + 1 diffuse
 * bounces, as the paper's text counts it ("n_b + 1 including the indirect
 * light gathering step").
 * Work-item g handles particles [g GI_BOUNCE_CHUNK, (g + 1) GI_BOUNCE_CHUNK)
 * in order and writes what they received, per colour, to
 * tally[tbase + 3 g + c] (the host sums the chunks: energy checks). */
__kernel void gi_k_bounce(int n, __global const int *off, int obase, __global const int *from, int sbase, float w_in,
                          __global const float *bin, __global const float *rho4, int first, __global float *bout,
                          __global float *total, __global float *tally, int tbase)
{
    int g = (int)get_global_id(0);
    int j0 = g * GI_BOUNCE_CHUNK;
    if (j0 >= n) return;
    int j1 = n - j0 < GI_BOUNCE_CHUNK ? n : j0 + GI_BOUNCE_CHUNK;
    float t0 = 0.0f, t1 = 0.0f, t2 = 0.0f;
    for (int j = j0; j < j1; j++) {
        float r0 = 0.0f, r1 = 0.0f, r2 = 0.0f;
        int q1 = off[obase + j + 1];
        for (int q = off[obase + j]; q < q1; q++) {
            int i = from[sbase + q];
            r0 += bin[4 * i];
            r1 += bin[4 * i + 1];
            r2 += bin[4 * i + 2];
        }
        r0 *= w_in;
        r1 *= w_in;
        r2 *= w_in;
        if (first) {
            total[4 * j] = r0;
            total[4 * j + 1] = r1;
            total[4 * j + 2] = r2;
            total[4 * j + 3] = 0.0f;
        } else {
            total[4 * j] += r0;
            total[4 * j + 1] += r1;
            total[4 * j + 2] += r2;
        }
        bout[4 * j] = rho4[4 * j] * r0;
        bout[4 * j + 1] = rho4[4 * j + 1] * r1;
        bout[4 * j + 2] = rho4[4 * j + 2] * r2;
        bout[4 * j + 3] = 0.0f;
        t0 += r0;
        t1 += r1;
        t2 += r2;
    }
    tally[tbase + 3 * g] = t0;
    tally[tbase + 3 * g + 1] = t1;
    tally[tbase + 3 * g + 2] = t2;
}

/* Reflected radiance of every area particle after scattering (section 4.2.2,
 * the equation after Fig. 5): L^(i) = f_rd^(i) phi^(i) / dA^(i) with
 * f_rd = rho/pi, phi = phi_d + scattered flux; plus the particle's own
 * emission, since the gathering step (eq. for E~ in 4.3.1) reads L^(k*) as
 * the radiance arriving from k*. The scattered flux is total (gi_k_bounce;
 * `scattered` 0: no bounce ran, none). Writes lout[i] (radiance) and phi[i]
 * (total received flux), 4 floats each. */
__kernel void gi_k_resolve(__global const gi_dev_particle *part, int n, __global const float *edir, int scattered,
                           __global const float *total, __global float *lout, __global float *phi)
{
    int i = (int)get_global_id(0);
    if (i >= n) return;
    __global const gi_dev_particle *pt = &part[i];
    for (int c = 0; c < 3; c++) {
        float f = GI_PI_F * edir[4 * i + c] * pt->area + (scattered ? total[4 * i + c] : 0.0f);
        float l = pt->le[c] + pt->rho[c] * f / (GI_PI_F * pt->area);
        if (!isfinite(l)) l = 0.0f;
        if (!isfinite(f)) f = 0.0f;
        lout[4 * i + c] = l;
        phi[4 * i + c] = f;
    }
    lout[4 * i + 3] = 0.0f;
    phi[4 * i + 3] = 0.0f;
}
