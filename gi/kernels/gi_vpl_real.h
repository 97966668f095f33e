/* gi_vpl_real.h - core/glossy_lobe.h in the kernel program: float values, the
 * E(mu) tables in global memory (the C build's shim makes __global empty). */
#ifndef GLOSSY_REAL
#define GLOSSY_REAL float
#define GLOSSY_GLOBAL __global
#endif
