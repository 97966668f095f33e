/* gi_types.h - records and helpers shared by the host (C11) and the particle
 * GI kernels (OpenCL C 1.2). This file is the first part of the kernel
 * program (see gi/CMakeLists.txt for the order) and is also included by the
 * host and by the C build of the kernels (gi_cl_c.c through gi_shim.h).
 *
 * Records hold only 4-byte scalars (float, int, uint), so their layout is the
 * same in both languages; gi_cl.c checks sizeof and every offsetof with
 * _Static_assert. Vector types (float3, float4) are deliberately not used:
 * the same source compiles as C.
 *
 * Units. POV-Ray's diffuse term is diffuse * pigment * colour * cos (no 1/pi,
 * shade.c), i.e. a light of colour C delivers the radiance rho*C*cos from a
 * surface of reflectance rho = diffuse*pigment. A Lambertian surface reflects
 * L = rho*E/pi, so C*cos is E/pi: every "irradiance" below is stored divided
 * by pi ("E/pi units"), and a flux is E*dA = pi*(E/pi)*dA. */
#ifndef GI_TYPES_H
#define GI_TYPES_H

#ifdef __OPENCL_VERSION__
typedef long gi_i64;
typedef uint gi_u32;
typedef float gi_wide; /* what pow returns */
#define GI_GLOBAL __global
#else
#include <math.h>
#include <stdint.h>
typedef int64_t gi_i64;
typedef uint32_t gi_u32;
typedef double gi_wide; /* what pow returns */
#ifndef GI_GLOBAL
#define GI_GLOBAL
#endif
#endif

#define GI_PI_F 3.14159265358979323846f
/* Most scattering bounces the kernels accept, and most scattering links
 * per particle (n_s <= 4). GI_BOUNCE_CHUNK: particles per work-item of
 * gi_k_bounce (one tally entry each). */
#define GI_MAX_BOUNCES 64
#define GI_MAX_SCATTER 16
#define GI_BOUNCE_CHUNK 64
/* Particles per work-item of gi_k_emit: one 32-bit word of the source mask
 * (bit i % 32 of word i / 32: particle i sends light in the first bounce). */
#define GI_EMIT_CHUNK 32

/* One entry of the WALK bounces' path table (gi_k_walk, built on the host
 * from the per-particle link choices): the flux that origin particle j
 * received in the first bounce reaches this entry's target particle in
 * random bounce b (1 <= b <= 63) times w (per colour, the product of the
 * reflectances along the path). jb = j | (b - 1) << GI_WALK_SHIFT, so j <
 * 2^26. 16 bytes. */
#define GI_WALK_SHIFT 26
#define GI_WALK_MASK 0x3ffffffu
typedef struct {
    gi_u32 jb;
    float w[3];
} gi_walk_entry;

/* One area particle (paper section 4.2.1: position p, normal n, area dA,
 * diffuse reflectance rho_d; the BRDF is rho_d/pi). `n` is the normal of the
 * side the particle stands for (two-sided surfaces get one particle per
 * side). `le` is the emitted radiance (finish emission, and ambient when
 * radiosity{} makes it a light source).
 * finish { diffuse A, B } (POV-Ray 3.7's diffuse_back) adds to the paper's
 * BRDF a second lobe, rho_b/pi for light arriving from the other side, with
 * rho_b = B * pigment * opacity = back * rho (back = B / A): the particle
 * reflects towards its side what its twin, the particle of the other side
 * at the same point, receives. twin is that particle's index, -1 none
 * (back 0: unused). 64 bytes. */
typedef struct {
    float p[3];
    float area;
    float n[3];
    float brilliance;
    float rho[3];
    float back;
    float le[3];
    int twin;
} gi_dev_particle;

enum { GI_LIGHT_POINT = 0, GI_LIGHT_SPOT = 1, GI_LIGHT_CYLINDER = 2, GI_LIGHT_PARALLEL = 3 };

/* One light_source with POV-Ray semantics (shade.c). Spotlights carry the
 * cosines of radius and falloff; cylinder lights carry radius and falloff as
 * distances from the axis. 80 bytes. */
typedef struct {
    float pos[3];
    int kind;
    float colour[3];
    int parallel;
    float point_at[3];
    float tightness;
    float cos_radius, cos_falloff, radius, falloff;
    float fade_distance, fade_power;
    int shadowless;
    int pad;
} gi_dev_light;

/* Direction from p towards the light point (cx, cy, cz) (the light's
 * position, or a point of an area light) and the distance along it.
 * Mirrors shade.c shade_light_ray: cylinder lights shine along their axis,
 * `parallel` lights along position - point_at. Returns the depth. */
static inline float gi_light_ray(GI_GLOBAL const gi_dev_light *l, float cx, float cy, float cz, float px, float py,
                                 float pz, float *d)
{
    float depth;
    if (l->kind == GI_LIGHT_CYLINDER) {
        float ax = cx - l->point_at[0], ay = cy - l->point_at[1], az = cz - l->point_at[2];
        float al = sqrt(ax * ax + ay * ay + az * az);
        float inv = al > 0.0f ? 1.0f / al : 0.0f;
        d[0] = ax * inv;
        d[1] = ay * inv;
        d[2] = az * inv;
        depth = (cx - px) * d[0] + (cy - py) * d[1] + (cz - pz) * d[2];
    } else {
        float vx = cx - px, vy = cy - py, vz = cz - pz;
        depth = sqrt(vx * vx + vy * vy + vz * vz);
        if (depth > 0.0f) {
            d[0] = vx / depth;
            d[1] = vy / depth;
            d[2] = vz / depth;
        } else {
            d[0] = 0.0f;
            d[1] = 1.0f;
            d[2] = 0.0f;
        }
    }
    if (l->parallel || l->kind == GI_LIGHT_PARALLEL) {
        float ax = cx - l->point_at[0], ay = cy - l->point_at[1], az = cz - l->point_at[2];
        float al = sqrt(ax * ax + ay * ay + az * az);
        float inv = al > 0.0f ? 1.0f / al : 0.0f;
        ax *= inv;
        ay *= inv;
        az *= inv;
        depth *= ax * d[0] + ay * d[1] + az * d[2];
        d[0] = ax;
        d[1] = ay;
        d[2] = az;
    }
    return depth;
}

/* POV-Ray's spotlight falloff curve: (3 - 2t) t^2 between low and high. */
static inline float gi_cubic_step(float low, float high, float x)
{
    if (x <= low) return 0.0f;
    if (x >= high) return 1.0f;
    float t = (x - low) / (high - low);
    return (3.0f - 2.0f * t) * t * t;
}

/* Angle and distance attenuation of light l seen from p along unit d at
 * distance depth. Mirrors shade.c shade_light_attenuation (spot cos^tightness with
 * a cubic falloff, cylinder lights, fade 2/(1+(d/fade_distance)^fade_power)). */
static inline float gi_light_attenuation(GI_GLOBAL const gi_dev_light *l, float px, float py, float pz,
                                         const float *d, float depth)
{
    float att = 1.0f;
    if (l->kind == GI_LIGHT_SPOT || l->kind == GI_LIGHT_CYLINDER) {
        float ax = l->point_at[0] - l->pos[0], ay = l->point_at[1] - l->pos[1], az = l->point_at[2] - l->pos[2];
        float al = sqrt(ax * ax + ay * ay + az * az);
        float inv = al > 0.0f ? 1.0f / al : 0.0f;
        ax *= inv;
        ay *= inv;
        az *= inv;
        if (l->kind == GI_LIGHT_SPOT) {
            float c = -(d[0] * ax + d[1] * ay + d[2] * az);
            if (c <= 0.0f) return 0.0f;
            /* tightness 1 (cosine spotlights: cbox, conference) needs no
             * pow: pow(c, 1) is c exactly */
            att = l->tightness == 1.0f ? c : (l->tightness != 0.0f ? pow(c, l->tightness) : 1.0f);
            if (l->cos_radius > 0.0f && c < l->cos_radius) att *= gi_cubic_step(l->cos_falloff, l->cos_radius, c);
        } else {
            float vx = px - l->pos[0], vy = py - l->pos[1], vz = pz - l->pos[2];
            float k = vx * ax + vy * ay + vz * az;
            if (k <= 0.0f) return 0.0f;
            float rx = vx - ax * k, ry = vy - ay * k, rz = vz - az * k;
            float len = sqrt(rx * rx + ry * ry + rz * rz);
            if (len >= l->falloff) return 0.0f;
            float dd = 1.0f - len / l->falloff;
            att = l->tightness != 0.0f ? pow(dd, l->tightness) : 1.0f;
            if (l->radius > 0.0f && len > l->radius) att *= gi_cubic_step(0.0f, 1.0f - l->radius / l->falloff, dd);
        }
    }
    if (att > 0.0f && l->fade_power > 0.0f) {
        if (fabs(l->fade_distance) >= 1e-10f) {
            /* fade_power 2 (the inverse-square fade) as x * x, in the
             * precision pow returns (C: double, where the square of a float
             * is exact and equals pow(x, 2); OpenCL: float): the same
             * value without a pow per particle and light on the host */
            float x = depth / l->fade_distance;
            gi_wide xx = (gi_wide)x * (gi_wide)x;
            att *= 2.0f / (1.0f + (l->fade_power == 2.0f ? xx : pow(x, l->fade_power)));
        } else {
            att *= pow(depth, -l->fade_power);
        }
    }
    return att;
}

/* Integer hash for the random link choices: PCG-based hash from Jarzynski
 * and Olano, "Hash Functions for GPU Rendering", JCGT 9(3), 2020. */
static inline gi_u32 gi_hash(gi_u32 v)
{
    gi_u32 state = v * 747796405u + 2891336453u;
    gi_u32 word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

/* Image-space photon mapping (McGuire and Luebke 2009, seed 002): the
 * caustic layer's records (gi_caustic.cl, gi/gi_caustic.h).
 *
 * One stored photon as the paper's photon map holds it (section 3's table:
 * position x, hit normal n_p, incoming direction w_i, power Phi) with the
 * kernel's two radii beside them: r_xy, the major radii in the plane of the
 * photon's surface, and r_z <= r_xy along n_p (section 2.5 of the digest,
 * Fig. 4). w points back towards where the light came from, as POV-Ray
 * stores it (gi_caustic.c, pov_photon_dir: its two angles truncated to
 * steps of pi/127). phi is in the
 * "E/pi units" above times area: sum phi * kappa is a POV-Ray light colour
 * (E/pi) that the diffuse term multiplies by diffuse * pigment. 64 bytes. */
typedef struct {
    float x[3];
    float r_xy;
    float n[3];
    float r_z;
    float w[3];
    float inv_rxy2; /* 1 / r_xy^2, 1 / r_z^2: the kernel's divisions, made once */
    float phi[3];
    float inv_rz2;
} gi_caus_photon;

/* One eye G-buffer texel (paper step 2): the world position s and normal n
 * of the camera's first receiving hit through the pixel's centre, n turned
 * towards the camera, and the brilliance of its finish and its diffuse_back
 * as a fraction of diffuse (back, gi_caus_add); valid 0 where the pixel
 * sees no receiver. 48 bytes. */
typedef struct {
    float s[3];
    float valid;
    float n[3];
    float brilliance;
    float back;
    float pad[3];
} gi_caus_pixel;

/* Tile edge (pixels) of the splat's binning: a photon is listed in every
 * tile whose G-buffer bounds its kernel ellipsoid's sphere reaches. Smaller
 * tiles have tighter bounds (a tile of floor at grazing view spans a long
 * depth range), so fewer (photon, pixel) pairs miss; the binning grows with
 * the tiles' count, which its two levels (gi_caustic.c, bin_block) keep
 * small (bench_caustics prints both). */
#define GI_CAUS_TILE 4

#endif
