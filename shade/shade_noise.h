/* shade_noise.h - POV-Ray 3.7's noise functions, reproduced so that patterns
 * land where POV-Ray puts them: Noise with noise_generator 1 (original),
 * 2 (range-corrected, the default) and 3 (Perlin gradient noise), the
 * vector-valued DNoise, fractal Turbulence/DTurbulence, the cycloidal and
 * triangle waves, the lattice hash and the random values used by cells and
 * crackle, and the wave sources of the ripples/waves patterns.
 *
 * The tables are generated at first use exactly as POV-Ray defines them
 * (see shade_noise.c for each rule); nothing here is copied from POV-Ray's
 * sources. All functions are thread-safe: the tables are built once, on
 * first use (pthread_once). */
#ifndef PT_SHADE_NOISE_H
#define PT_SHADE_NOISE_H
#include <limits.h>
#include "vec.h"

/* A double truncated to int as POV-Ray's (int) casts behave on x86-64
 * (cvttsd2si): NaN and values outside int's range give INT_MIN. Patterns use
 * it where coordinates can be arbitrarily large (far points of infinite
 * planes), where a plain C cast would be undefined. */
static inline int shade_noise_to_int(double x)
{
    return (x > -2147483649.0 && x < 2147483648.0) ? (int)x : INT_MIN;
}

/* POV-Ray's Noise(p, generator): a value in [0, 1]. generator 1..3. */
double shade_noise_value(vec3 p, int generator);
/* Noise(p * l_i, generator) for i = 0 .. n-1 into out, l_0 = 1 and
 * l_i = l_(i-1) * lambda (the octave scales Turbulence and wrinkles use,
 * formed the same way): each value bit for bit shade_noise_value's,
 * evaluated together (two octaves at a time, no call per octave). */
void shade_noise_octaves(vec3 p, int n, double lambda, int generator, double *out);
/* POV-Ray's DNoise(p): vector noise, components roughly in [-1, 1]. */
vec3 shade_noise_dvector(vec3 p);
/* DNoise(p * l_i) for i = 0 .. n-1, the scales as shade_noise_octaves's
 * (each bit for bit shade_noise_dvector's, two at a time). */
void shade_noise_dvector_octaves(vec3 p, int n, double lambda, vec3 *out);

/* Fractal sums (POV-Ray's Turbulence and DTurbulence) with the given
 * octaves, omega and lambda. */
double shade_noise_turbulence(vec3 p, int octaves, double omega, double lambda, int generator);
vec3 shade_noise_dturbulence(vec3 p, int octaves, double omega, double lambda);

/* sin(2 pi x) as POV-Ray computes it (fraction quantised to 1/50000), and
 * the triangle wave 0..1..0 of period 1. */
double shade_noise_cycloidal(double x);
double shade_noise_triangle_wave(double x);

/* POV-Ray's Hash3d lattice hash (each argument masked to 12 bits): 0..4095. */
int shade_noise_hash3d(int a, int b, int c);
/* POV-Ray's antialiasing jitter of the subsample at pixel coordinates
 * (x, y): a fixed offset pair in [-0.5, 0.5], a function of the position
 * only, so every render of a scene jitters alike. */
void shade_noise_jitter2d(double x, double y, double *jx, double *jy);
/* POV-Ray's PatternRands(i): 32768 uniform doubles in [0,1) (mt19937 with its
 * default seed, divided by 2^32), index taken modulo 32768. */
double shade_noise_pattern_rand(unsigned long i);

/* The ripples/waves sources (POV-Ray's number_of_waves, default 10; up to
 * SHADE_NOISE_MAX_WAVES are generated). */
#define SHADE_NOISE_WAVES 10
#define SHADE_NOISE_MAX_WAVES 1000
vec3 shade_noise_wave_source(int i);
double shade_noise_wave_frequency(int i);

#endif
