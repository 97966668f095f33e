/* gi_lighting.cl - the lighting stage of particle-space GI (Chang, Park, Ihm,
 * "Diffuse Global Illumination in Particle Spaces", MTAP 2015, section 4.2):
 * emission from lights into area particles, scattering along the particle
 * links, and the per-particle reflected radiance L^(i).
 *
 * Compiled by OpenCL (gi_cl.c) and, unchanged, as C through gi_shim.h
 * (gi_cl_c.c): both builds run this code. Units: see gi_types.h (E/pi). */

#ifdef __OPENCL_VERSION__
#pragma OPENCL EXTENSION cl_khr_int64_base_atomics : enable
#endif

/* Fixed-point flux accumulation. The paper scatters with atomic float adds
 * (section 4.2.2); float addition is not associative, so the result would
 * depend on thread timing. We add 64-bit integers instead: each deposit x is
 * rounded once to rint(x * scale) (scale a power of two chosen on the host so
 * that the total cannot overflow), and integer sums do not depend on order,
 * so scattering is deterministic on any device. */
static inline gi_i64 gi_fixed(float x, float scale) { return (gi_i64)rint(x * scale); }

/* Emission (section 4.2.1). The paper gives point lights only, with
 *   phi^(i) += Phi_j/(4 pi) * dA^(i) cos(theta_i) / d_i^2.
 * partray follows POV-Ray's light model instead, so that the particles'
 * direct light is exactly what the Whitted pass shows (shade.c): a light of
 * colour C reaches a particle with E/pi = C * att * cos^brilliance * V, where
 * att is the spot/cylinder/fade attenuation (gi_light_attenuation) and V the
 * visibility fraction traced by Embree on the host (area lights: the average
 * over the light's grid). The direct flux is phi_d = pi * (E/pi) * dA.
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
        float depth = gi_light_ray(lt, lt->pos[0], lt->pos[1], lt->pos[2], pt->p[0], pt->p[1], pt->p[2], d);
        float ci = pt->n[0] * d[0] + pt->n[1] * d[1] + pt->n[2] * d[2];
        if (ci < 1e-10f) continue; /* the other side's particle takes it (shade.c: backside rule) */
        float att = gi_light_attenuation(lt, pt->p[0], pt->p[1], pt->p[2], d, depth);
        float intensity = pt->brilliance != 1.0f ? pow(ci, pt->brilliance) : ci;
        float w = att * intensity * v;
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

/* Indirect light scattering (section 4.2.2, Fig. 5), from source particle i
 * (directly lit or emitting):
 *  - first bounce: all ns2 = n_s x n_s scattering links get src[i]/ns2
 *    (the paper's rho^(i) phi^(i) / n_s^2, plus emission);
 *  - then every one of those ns2 packets walks on: at the end particle j the
 *    packet is multiplied by rho^(j) and deposited in full at the end of ONE
 *    link of j chosen at random (probability 1/ns2 for each of j's links, so
 *    the expected deposit equals the full fan-out rho^(j) P / ns2 per link).
 * Bounce convention: nb counts ALL scattering bounces, the full fan-out
 * included (nb = 1: fan-out only; nb = 0: no scattering, the kernel is not
 * run). With the gathering step the rendered indirect light has up to nb + 1
 * diffuse bounces, as the paper's text counts it ("n_b + 1 including the
 * indirect light gathering step").
 * Links of -1 (rays that left the scene) end the packet. tl[3b + c] sums
 * what bounce b deposited (fixed point), for energy checks.
 *
 * gi_walk runs the packets of `cnt` sources (srcidx[t0], srcidx[t0 + step],
 * ...; at most GI_WALK_BATCH) in lockstep, one bounce at a time, in passes
 * over all packets: prefetch what the next pass reads (rho and link row of
 * each packet's particle; then the accumulator lines), then read it. The
 * walks are chains of dependent random reads; in passes, hundreds of them
 * are in flight at once instead of one. (Same packets, same random choices
 * and same integer sums as walking them one by one.) `atomic`: deposits
 * are atomic adds (many work-items share acc), else plain adds (acc is
 * this work-item's own). */
#define GI_WALK_BATCH 32
static inline void gi_walk(__global const float *rho4, __global const int *slink, int ns2, int nb,
                           uint seed, float scale, __global const int *srcidx, int t0, int step, int cnt,
                           __global const float *src, GI_GLOBAL gi_i64 *acc, int atomic, gi_i64 *tl)
{
    int nbc = nb < GI_MAX_BOUNCES ? nb : GI_MAX_BOUNCES;
    int nk = ns2 < GI_MAX_SCATTER ? ns2 : GI_MAX_SCATTER;
    int jj[GI_WALK_BATCH * GI_MAX_SCATTER];
    gi_u32 hi[GI_WALK_BATCH];
    float pk[GI_WALK_BATCH * GI_MAX_SCATTER * 3];
    float w = 1.0f / (float)ns2;
    int np = cnt * nk;
    for (int b = 0; b < cnt; b++) {
        int i = srcidx[t0 + b * step];
        hi[b] = (gi_u32)i;
        for (int k = 0; k < nk; k++) {
            int p = b * nk + k;
            jj[p] = slink[(long)i * ns2 + k];
            pk[3 * p] = src[4 * i] * w;
            pk[3 * p + 1] = src[4 * i + 1] * w;
            pk[3 * p + 2] = src[4 * i + 2] * w;
        }
    }
    for (int s = 0; s < nbc; s++) {
        if (s > 0) {
            for (int p = 0; p < np; p++)
                if (jj[p] >= 0) {
                    prefetch(&rho4[4 * jj[p]], 1);
                    prefetch(&slink[(long)jj[p] * ns2], 1);
                }
            /* move every live packet one link on from where it lies */
            for (int p = 0; p < np; p++) {
                int j = jj[p];
                if (j < 0) continue;
                pk[3 * p] *= rho4[4 * j];
                pk[3 * p + 1] *= rho4[4 * j + 1];
                pk[3 * p + 2] *= rho4[4 * j + 2];
                if (pk[3 * p] == 0.0f && pk[3 * p + 1] == 0.0f && pk[3 * p + 2] == 0.0f) {
                    jj[p] = -1;
                    continue;
                }
                int k = p % nk;
                gi_u32 h = gi_hash(seed ^ gi_hash(hi[p / nk] ^ gi_hash((gi_u32)(k + ns2 * s))));
                jj[p] = slink[(long)j * ns2 + (int)(h % (gi_u32)ns2)];
            }
        }
        int live = 0;
        for (int p = 0; p < np; p++)
            if (jj[p] >= 0) {
                prefetch(&acc[3 * jj[p]], 3);
                live++;
            }
        if (live == 0) break;
        for (int p = 0; p < np; p++) {
            int j = jj[p];
            if (j < 0) continue;
            for (int c = 0; c < 3; c++) {
                gi_i64 q = gi_fixed(pk[3 * p + c], scale);
                if (q == 0) continue;
                if (atomic)
                    atom_add(&acc[3 * j + c], q);
                else
                    acc[3 * j + c] += q;
                tl[3 * s + c] += q;
            }
        }
    }
}

/* The walks of section 4.2.2 (gi_walk above) for the nsrc source particles
 * srcidx[]. rho4: the particles' reflectances, 4 floats each (a compact
 * copy of part[].rho: the walks read it at random, and 16 bytes a particle
 * stay in cache where the 64-byte records do not). Two launch shapes, the
 * same integer sums:
 *  - nslices = 0 (GPUs): one work-item per source; deposits and tallies are
 *    atomic adds into acc and tally;
 *  - nslices > 0 (CPUs): one work-item per slice w < nslices, adding,
 *    without atomics, into its own slice acc + 3 n w and tally +
 *    3 GI_MAX_BOUNCES w; gi_k_resolve sums the slices. On a CPU an atomic
 *    add costs a locked bus cycle per deposit (three per step); a private
 *    slice costs one memory add. The work-items take batches of
 *    GI_WALK_BATCH sources from a shared counter (*next, zero at launch),
 *    so a thread the system holds up leaves its share to the others.
 * Integer sums do not depend on order, so both shapes, any slice count,
 * any batch assignment and any thread timing give the same acc and tally. */
__kernel void gi_k_scatter(__global const float *rho4, __global const int *slink, int ns2, int nb,
                           uint seed, float scale, __global const int *srcidx, int nsrc, __global const float *src,
                           __global gi_i64 *acc, __global gi_i64 *tally, int n, int nslices,
                           __global int *next)
{
    int w = (int)get_global_id(0);
    gi_i64 tl[GI_MAX_BOUNCES * 3];
    int nbc = nb < GI_MAX_BOUNCES ? nb : GI_MAX_BOUNCES;
    for (int b = 0; b < 3 * nbc; b++) tl[b] = 0;
    if (nslices > 0) {
        if (w >= nslices) return;
        __global gi_i64 *mine = acc + (long)w * 3 * n;
        for (;;) {
            int t0 = atomic_add(next, GI_WALK_BATCH);
            if (t0 >= nsrc) break;
            int cnt = nsrc - t0 < GI_WALK_BATCH ? nsrc - t0 : GI_WALK_BATCH;
            gi_walk(rho4, slink, ns2, nb, seed, scale, srcidx, t0, 1, cnt, src, mine, 0, tl);
        }
        for (int b = 0; b < 3 * nbc; b++) tally[(long)w * 3 * GI_MAX_BOUNCES + b] = tl[b];
        return;
    }
    if (w >= nsrc) return;
    gi_walk(rho4, slink, ns2, nb, seed, scale, srcidx, w, 1, 1, src, acc, 1, tl);
    for (int b = 0; b < 3 * nbc; b++)
        if (tl[b] != 0) atom_add(&tally[b], tl[b]);
}

/* Alternative scattering (settings scatter_mode "full"): every bounce along
 * all ns2 links, as the paper's first bounce, written as a gather so that
 * no atomics are needed. One launch per bounce: particle j receives
 *   recv_j = sum over links i -> j of bin_i,   bin_i = rho_i recv_i / ns2
 * (bin for the first bounce: src_i / ns2), over the incoming links listed
 * in rin_src[rin_off[j] .. rin_off[j+1]) in ascending source order (fixed
 * summation order: deterministic in float). It adds recv_j to total_j and
 * writes bout_j = rho_j recv_j / ns2 for the next bounce. Same expected
 * flux as the random walks, without their noise; 4 floats per particle. */
__kernel void gi_k_pull(__global const gi_dev_particle *part, int n, int ns2, __global const int *rin_off,
                        __global const int *rin_src, __global const float *bin, __global float *bout,
                        __global float *total)
{
    int j = (int)get_global_id(0);
    if (j >= n) return;
    float r[3] = {0.0f, 0.0f, 0.0f};
    for (int q = rin_off[j]; q < rin_off[j + 1]; q++) {
        int i = rin_src[q];
        r[0] += bin[4 * i];
        r[1] += bin[4 * i + 1];
        r[2] += bin[4 * i + 2];
    }
    float w = 1.0f / (float)ns2;
    __global const gi_dev_particle *pj = &part[j];
    for (int c = 0; c < 3; c++) {
        total[4 * j + c] += r[c];
        bout[4 * j + c] = pj->rho[c] * r[c] * w;
    }
    total[4 * j + 3] = 0.0f;
    bout[4 * j + 3] = 0.0f;
}

/* First-bounce input of gi_k_pull: bin_i = src_i / ns2. */
__kernel void gi_k_pull_init(int n, int ns2, __global const float *src, __global float *bin, __global float *total)
{
    int i = (int)get_global_id(0);
    if (i >= n) return;
    float w = 1.0f / (float)ns2;
    for (int c = 0; c < 4; c++) {
        bin[4 * i + c] = c < 3 ? src[4 * i + c] * w : 0.0f;
        total[4 * i + c] = 0.0f;
    }
}

/* Reflected radiance of every area particle after scattering (section 4.2.2,
 * the equation after Fig. 5): L^(i) = f_rd^(i) phi^(i) / dA^(i) with
 * f_rd = rho/pi, phi = phi_d + scattered flux; plus the particle's own
 * emission, since the gathering step (eq. for E~ in 4.3.1) reads L^(k*) as
 * the radiance arriving from k*. The scattered flux is acc (fixed point,
 * gi_k_scatter; the sum of its nslices slices) plus total (float, gi_k_pull); the mode not used left its
 * array at zero. Writes lout[i] (radiance) and phi[i] (total received
 * flux), 4 floats each. */
__kernel void gi_k_resolve(__global const gi_dev_particle *part, int n, __global const float *edir,
                           __global const gi_i64 *acc, int nslices, float inv_scale, __global const float *total,
                           __global float *lout, __global float *phi)
{
    int i = (int)get_global_id(0);
    if (i >= n) return;
    __global const gi_dev_particle *pt = &part[i];
    int ns = nslices > 0 ? nslices : 1;
    for (int c = 0; c < 3; c++) {
        gi_i64 a = 0;
        for (int w = 0; w < ns; w++) a += acc[(long)w * 3 * n + 3 * i + c];
        float f = GI_PI_F * edir[4 * i + c] * pt->area + (float)a * inv_scale + total[4 * i + c];
        float l = pt->le[c] + pt->rho[c] * f / (GI_PI_F * pt->area);
        if (!isfinite(l)) l = 0.0f;
        if (!isfinite(f)) f = 0.0f;
        lout[4 * i + c] = l;
        phi[4 * i + c] = f;
    }
    lout[4 * i + 3] = 0.0f;
    phi[4 * i + 3] = 0.0f;
}
