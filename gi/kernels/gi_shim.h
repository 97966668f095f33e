/* gi_shim.h - lets the OpenCL C kernels in this folder compile as C11, so the
 * build without OpenCL (PARTRAY_OPENCL=OFF, or the "c" device) runs the very
 * same kernel code. Only the small subset the kernels use is mapped:
 * address-space qualifiers vanish, get_global_id(0) reads a thread-local
 * index set by the launcher (gi_cl_c.c, this header's only includer), atom_add and atomic_add are relaxed
 * atomic adds,
 * prefetch a write prefetch.
 * Math calls (pow, sqrt, fabs, rint) resolve to the C library's double
 * versions (native_exp2, native_log2 to exp2f, log2f), so results can differ from the OpenCL build in the last float
 * bits; tests compare the two with a tolerance. */
#ifndef GI_SHIM_H
#define GI_SHIM_H
#ifdef __OPENCL_VERSION__
#error "gi_shim.h is for the C build of the kernels only"
#endif
#include <math.h>
#include <stddef.h>
#include <stdint.h>

/* the kernels are file-local to gi_cl_c.c, their one includer */
#define __kernel static
#define __global
#define __constant const
#define __local
#define __private

typedef unsigned int uint;

static _Thread_local size_t gi_shim_gid;
#define get_global_id(dim) ((void)(dim), gi_shim_gid)
#define atom_add(p, v) __atomic_fetch_add((p), (v), __ATOMIC_RELAXED)
#define atomic_add(p, v) __atomic_fetch_add((p), (v), __ATOMIC_RELAXED)
#define prefetch(p, n) ((void)(n), __builtin_prefetch((p), 1))
/* OpenCL's native exp2 and log2, in float as there */
#define native_exp2(x) exp2f(x)
#define native_log2(x) log2f(x)

#endif
