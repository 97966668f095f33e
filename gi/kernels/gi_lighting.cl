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
 *             (reflected direct light plus emission of a Lambertian emitter).
 * Work-item g handles particles [32 g, 32 g + 32) (GI_EMIT_CHUNK) and writes
 * word g of the source mask: bit i % 32 set when src[i] is not 0 (the first
 * bounce reads only those; the paper runs one scattering thread per directly
 * lit particle, Fig. 5). emits (word per 32 particles, built on the host)
 * marks the particles with emission: a particle no light reaches (every vis
 * 0) and without it gets zeros without reading its record. dsum[g]: the
 * direct flux of the work-item's particles, summed over colours (stats). */
/* Direct E/pi at particle i into e (added), from its row of vis; whether
 * any light reaches it (its record is read only then). */
static inline int gi_direct(__global const gi_dev_particle *part, int i, __global const gi_dev_light *lights,
                            int nlights, __global const float *vis, float *e)
{
    __global const gi_dev_particle *pt = &part[i];
    int lit = 0;
    for (int l = 0; l < nlights; l++) {
        float v = vis[(long)i * nlights + l];
        if (!(v > 0.0f)) continue;
        lit = 1;
        __global const gi_dev_light *lt = &lights[l];
        float d[3];
        gi_light_ray(lt, lt->pos[0], lt->pos[1], lt->pos[2], pt->p[0], pt->p[1], pt->p[2], d);
        float ci = pt->n[0] * d[0] + pt->n[1] * d[1] + pt->n[2] * d[2];
        if (ci < 1e-10f) continue; /* the other side's particle takes it (shade.c: backside rule) */
        float intensity = pt->brilliance != 1.0f ? pow(ci, pt->brilliance) : ci;
        float w = intensity * v; /* v = att * V */
        for (int c = 0; c < 3; c++) e[c] += lt->colour[c] * w;
    }
    return lit;
}

/* diffuse_back (gi_types.h): a particle with a twin also sends
 *   rho_b * phi_d(twin) (dA / dA_twin) = back * rho * pi * (E_twin/pi) * dA,
 * the direct light on the other side that its back lobe reflects; the
 * host marks such particles in emits, so they are always read.
 * extra (4 floats per particle, read when has_extra): E/pi that arrives
 * like direct light but not from a light_source ray, the caustic photons'
 * (beyond the paper: POV-Ray's radiosity rays see photons, trace.cpp
 * ComputeLightedTexture adds ComputePhotonDiffuseLight at every hit); it
 * joins e, so it is sent, scattered and reflected as direct light is. */
static inline int gi_extra(__global const float *extra, int i, float *e)
{
    int any = 0;
    for (int c = 0; c < 3; c++) {
        float v = extra[4 * (long)i + c];
        if (v > 0.0f) {
            e[c] += v;
            any = 1;
        }
    }
    return any;
}

__kernel void gi_k_emit(__global const gi_dev_particle *part, int n, __global const gi_dev_light *lights, int nlights,
                        __global const float *vis, __global const uint *emits, __global float *edir,
                        __global float *src, __global uint *srcmask, __global float *dsum,
                        __global const float *extra, int has_extra)
{
    int g = (int)get_global_id(0);
    int i0 = g * GI_EMIT_CHUNK;
    if (i0 >= n) return;
    int i1 = n - i0 < GI_EMIT_CHUNK ? n : i0 + GI_EMIT_CHUNK;
    uint em = emits[g], bits = 0u;
    float ds = 0.0f;
    for (int i = i0; i < i1; i++) {
        __global const gi_dev_particle *pt = &part[i];
        float e[3] = {0.0f, 0.0f, 0.0f};
        int lit = gi_direct(part, i, lights, nlights, vis, e);
        if (has_extra) lit |= gi_extra(extra, i, e);
        if (!lit && !((em >> (i - i0)) & 1u)) {
            for (int c = 0; c < 4; c++) {
                edir[4 * i + c] = 0.0f;
                src[4 * i + c] = 0.0f;
            }
            continue;
        }
        float eb[3] = {0.0f, 0.0f, 0.0f};
        if (pt->back > 0.0f && pt->twin >= 0) {
            gi_direct(part, pt->twin, lights, nlights, vis, eb);
            if (has_extra) gi_extra(extra, pt->twin, eb);
        }
        int any = 0;
        for (int c = 0; c < 3; c++) {
            if (!isfinite(e[c])) e[c] = 0.0f;
            if (!isfinite(eb[c])) eb[c] = 0.0f;
            float phid = GI_PI_F * e[c] * pt->area;
            float sv = pt->rho[c] * (phid + pt->back * GI_PI_F * eb[c] * pt->area) + GI_PI_F * pt->le[c] * pt->area;
            ds += phid;
            edir[4 * i + c] = e[c];
            src[4 * i + c] = sv;
            any |= sv != 0.0f;
        }
        edir[4 * i + 3] = 0.0f;
        src[4 * i + 3] = 0.0f;
        if (any) bits |= 1u << (i - i0);
    }
    srcmask[g] = bits;
    dsum[g] = ds;
}

/* Reflected radiance of every area particle after scattering (section 4.2.2,
 * the equation after Fig. 5): L^(i) = f_rd^(i) phi^(i) / dA^(i) with
 * f_rd = rho/pi, phi = phi_d + scattered flux; plus the particle's own
 * emission, since the gathering step (eq. for E~ in 4.3.1) reads L^(k*) as
 * the radiance arriving from k*. The scattered flux is t0..t2
 * (`scattered` 0: no bounce ran, none). Writes lo (radiance) and ph (total
 * received flux), 4 floats each. */
static inline void gi_resolve_one(__global const gi_dev_particle *pt, __global const float *e, int scattered, float t0,
                                  float t1, float t2, __global float *lo, __global float *ph)
{
    float t[3] = {t0, t1, t2};
    for (int c = 0; c < 3; c++) {
        float f = GI_PI_F * e[c] * pt->area + (scattered ? t[c] : 0.0f);
        float l = pt->le[c] + pt->rho[c] * f / (GI_PI_F * pt->area);
        if (!isfinite(l)) l = 0.0f;
        if (!isfinite(f)) f = 0.0f;
        lo[c] = l;
        ph[c] = f;
    }
    lo[3] = 0.0f;
    ph[3] = 0.0f;
}

/* Indirect light scattering (section 4.2.2, Fig. 5), as gathers: no
 * atomics, no private packet state. Particle j receives
 *   recv_j = w_in * sum over q in [off[obase + j], off[obase + j + 1]) of bin[from[sbase + q]]
 * adds it to total_j (bounce 0 writes it), and sends bout_j = rho_j recv_j
 * on. The incoming lists say which links carry flux in this bounce (built
 * on the host, gi_particle.c, sources ascending: a fixed float summation
 * order, so every device gives the same sums):
 *  - bounce 0, the first bounce of the paper (all n_s x n_s links):
 *    the incoming scattering links of j (rin), bin = src (flux leaving the
 *    directly lit and emitting particles), w_in = 1/ns2: each link carries
 *    the paper's rho^(i) phi^(i) / n_s^2 (plus emission);
 *  - later bounces, FULL: all links again (rin), w_in = 1/ns2: the
 *    expectation itself, no random-walk noise;
 *  - the WALK mode's later bounces (the paper's single-link random bounces)
 *    run all at once in gi_k_walk, after this kernel's bounce 0.
 * Only sources whose bit is set in mask_in (word per 32 particles: what
 * they send is not 0) are read: adding a 0 changes no float sum, so the
 * sums are those over every link, and the first bounce reads only the
 * directly lit and emitting particles (the paper's one thread per directly
 * lit particle, Fig. 5). mask_out gets the same bits for bout (what this
 * bounce sends on), for the next bounce or gi_k_walk.
 * Bounce convention: nb counts ALL scattering bounces, the first fan-out
 * included (nb = 1: fan-out only; nb = 0: no scattering, not run). With the
 * gathering step the rendered indirect light has up to nb + 1 diffuse
 * bounces, as the paper's text counts it ("n_b + 1 including the indirect
 * light gathering step").
 * Work-item g handles particles [g GI_BOUNCE_CHUNK, (g + 1) GI_BOUNCE_CHUNK)
 * in order and writes what they received, per colour, to
 * tally[tbase + 3 g + c] (the host sums the chunks: energy checks). */
__kernel void gi_k_bounce(int n, __global const int *off, int obase, __global const int *from, int sbase, float w_in,
                          __global const float *bin, __global const uint *mask_in, __global const float *rho4,
                          int first, __global float *bout, __global uint *mask_out, __global float *total,
                          __global float *tally, int tbase)
{
    int g = (int)get_global_id(0);
    int j0 = g * GI_BOUNCE_CHUNK;
    if (j0 >= n) return;
    int j1 = n - j0 < GI_BOUNCE_CHUNK ? n : j0 + GI_BOUNCE_CHUNK;
    float t0 = 0.0f, t1 = 0.0f, t2 = 0.0f;
    uint m[GI_BOUNCE_CHUNK / 32];
    for (int w = 0; w < GI_BOUNCE_CHUNK / 32; w++) m[w] = 0u;
    for (int j = j0; j < j1; j++) {
        float r0 = 0.0f, r1 = 0.0f, r2 = 0.0f;
        int q1 = off[obase + j + 1];
        for (int q = off[obase + j]; q < q1; q++) {
            int i = from[sbase + q];
            if (!((mask_in[i >> 5] >> (i & 31)) & 1u)) continue;
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
        float b0 = rho4[4 * j] * r0, b1 = rho4[4 * j + 1] * r1, b2 = rho4[4 * j + 2] * r2;
        bout[4 * j] = b0;
        bout[4 * j + 1] = b1;
        bout[4 * j + 2] = b2;
        bout[4 * j + 3] = 0.0f;
        if (b0 != 0.0f || b1 != 0.0f || b2 != 0.0f) m[(j - j0) >> 5] |= 1u << ((j - j0) & 31);
        t0 += r0;
        t1 += r1;
        t2 += r2;
    }
    for (int w = 0; w < GI_BOUNCE_CHUNK / 32; w++)
        if (j0 / 32 + w < (n + 31) / 32) mask_out[j0 / 32 + w] = m[w];
    tally[tbase + 3 * g] = t0;
    tally[tbase + 3 * g + 1] = t1;
    tally[tbase + 3 * g + 2] = t2;
}

/* The WALK mode's bounces 1 .. nwalk (the paper's single-link random
 * bounces, section 4.2.2, Fig. 5), all in one launch, with the reflected
 * radiance of gi_k_resolve. In bounce b every particle sends all it
 * received along ONE of its links, c(p, b), chosen at random with
 * probability 1/ns2 per link (a link of -1 loses it: the ray left the
 * scene), drawn once per particle and bounce (gi_hash, host): the choices
 * are fixed at geometry time, so what particle j received in bounce 0
 * (recv0_j, gi_k_bounce) follows one fixed path P_1(j) = c(j, 1),
 * P_b(j) = c(P_(b-1)(j), b), as the paper's thread follows its packet, and
 * arrives at P_b(j) in bounce b as
 *   recv0_j * rho^(j) rho^(P_1(j)) ... rho^(P_(b-1)(j))
 * (the paper's rho^(i) phi^(i) along each link of the walk, Fig. 5).
 * Flux is linear, so what particle k receives in bounce b is the sum of
 * these over the origins j whose path is at k in bounce b: the host lists,
 * per target k, the entries (j, b, w = that product) (gi_walk_entry, sorted
 * by b, then j: a fixed float summation order), and this kernel sums
 *   total_k = recv0_k + sum over k's entries with b <= nwalk of w * recv0_j.
 * Expected deposit per link of a walk bounce: rho^(i) recv^(i) / ns2, the
 * same as the full fan-out and as the paper's per-packet choice (there,
 * packets meeting at i choose independently; here they share i's choice:
 * the same expectation, more correlation). The same sums as bounce-by-bounce
 * gathers within float rounding (the products are formed along the path,
 * not bounce by bounce). live: gi_k_bounce's mask_out of bounce 0 (origins
 * that send nothing are not read). Then the radiance as gi_k_resolve
 * (gi_resolve_one) into lout and phi. Work-item g handles particles
 * [g GI_BOUNCE_CHUNK, (g + 1) GI_BOUNCE_CHUNK) and writes what they received
 * in bounce b to tally[3 b items + 3 g + c], as gi_k_bounce. */
__kernel void gi_k_walk(__global const gi_dev_particle *part, int n, __global const float *edir,
                        __global const float *recv0, __global const uint *live, __global const int *woff,
                        __global const gi_walk_entry *went, int nwalk, __global float *lout, __global float *phi,
                        __global float *tally, int items)
{
    int g = (int)get_global_id(0);
    int k0 = g * GI_BOUNCE_CHUNK;
    if (k0 >= n) return;
    int k1 = n - k0 < GI_BOUNCE_CHUNK ? n : k0 + GI_BOUNCE_CHUNK;
    float tb[3 * (GI_MAX_BOUNCES - 1)];
    for (int q = 0; q < 3 * nwalk; q++) tb[q] = 0.0f;
    for (int k = k0; k < k1; k++) {
        float a0 = recv0[4 * k], a1 = recv0[4 * k + 1], a2 = recv0[4 * k + 2];
        int q1 = woff[k + 1];
        for (int q = woff[k]; q < q1; q++) {
            uint jb = went[q].jb;
            int b = (int)(jb >> GI_WALK_SHIFT);
            if (b >= nwalk) break; /* sorted by bounce: the rest are later bounces */
            int j = (int)(jb & GI_WALK_MASK);
            if (!((live[j >> 5] >> (j & 31)) & 1u)) continue;
            float c0 = went[q].w[0] * recv0[4 * j], c1 = went[q].w[1] * recv0[4 * j + 1],
                  c2 = went[q].w[2] * recv0[4 * j + 2];
            a0 += c0;
            a1 += c1;
            a2 += c2;
            tb[3 * b] += c0;
            tb[3 * b + 1] += c1;
            tb[3 * b + 2] += c2;
        }
        gi_resolve_one(&part[k], &edir[4 * k], 1, a0, a1, a2, &lout[4 * k], &phi[4 * k]);
    }
    for (int b = 0; b < nwalk; b++)
        for (int c = 0; c < 3; c++) tally[3 * (b + 1) * items + 3 * g + c] = tb[3 * b + c];
}

/* diffuse_back's share of the reflected radiance (gi_types.h), after
 * gi_k_resolve or gi_k_walk: a particle with a twin t adds
 *   rho_b phi^(t) / (pi dA^(t)) = back * rho * phi^(t) / (pi dA^(t)),
 * the back lobe of the paper's L^(i) = f_rd phi / dA (section 4.2.2) over
 * the flux its twin received (direct and scattered; the sky its twin sees
 * is in le, gi_particle.c). phi is read, lout written: no particle reads
 * what another writes. */
__kernel void gi_k_back(__global const gi_dev_particle *part, int n, __global const float *phi,
                        __global float *lout)
{
    int i = (int)get_global_id(0);
    if (i >= n) return;
    __global const gi_dev_particle *pt = &part[i];
    int t = pt->twin;
    if (!(pt->back > 0.0f) || t < 0) return;
    float a = part[t].area;
    if (!(a > 0.0f)) return;
    for (int c = 0; c < 3; c++) {
        float l = lout[4 * i + c] + pt->back * pt->rho[c] * phi[4 * t + c] / (GI_PI_F * a);
        if (isfinite(l)) lout[4 * i + c] = l;
    }
}

/* diffuse_back between the FULL mode's bounces (gi_types.h): what a
 * particle sends on is rho_i recv_i (gi_k_bounce's bout), and with a twin t
 * also back_i rho_i recv_t, its back lobe's share of what the twin
 * received, recv_t = bin_t / rho_t. bout_i = bin_i + that, and mask word g
 * (particles [32 g, 32 g + 32), GI_EMIT_CHUNK) says which send something.
 * Reads bin, writes bout: the caller swaps them. */
__kernel void gi_k_back_send(__global const gi_dev_particle *part, int n, __global const float *rho4,
                             __global const float *bin, __global float *bout, __global uint *mask)
{
    int g = (int)get_global_id(0);
    int i0 = g * GI_EMIT_CHUNK;
    if (i0 >= n) return;
    int i1 = n - i0 < GI_EMIT_CHUNK ? n : i0 + GI_EMIT_CHUNK;
    uint bits = 0u;
    for (int i = i0; i < i1; i++) {
        __global const gi_dev_particle *pt = &part[i];
        int t = pt->twin;
        int any = 0;
        for (int c = 0; c < 3; c++) {
            float v = bin[4 * i + c];
            float rt = t >= 0 ? rho4[4 * t + c] : 0.0f;
            if (pt->back > 0.0f && rt > 0.0f) {
                float u = v + pt->back * pt->rho[c] * bin[4 * t + c] / rt;
                if (isfinite(u)) v = u;
            }
            bout[4 * i + c] = v;
            any |= v != 0.0f;
        }
        bout[4 * i + 3] = 0.0f;
        if (any) bits |= 1u << (i - i0);
    }
    mask[g] = bits;
}

/* gi_resolve_one for every particle, the scattered flux from total
 * (gi_k_bounce): after the FULL mode's bounces, or with no bounce. */
__kernel void gi_k_resolve(__global const gi_dev_particle *part, int n, __global const float *edir, int scattered,
                           __global const float *total, __global float *lout, __global float *phi)
{
    int i = (int)get_global_id(0);
    if (i >= n) return;
    float t0 = scattered ? total[4 * i] : 0.0f, t1 = scattered ? total[4 * i + 1] : 0.0f,
          t2 = scattered ? total[4 * i + 2] : 0.0f;
    gi_resolve_one(&part[i], &edir[4 * i], scattered, t0, t1, t2, &lout[4 * i], &phi[4 * i]);
}
