/* gi_cl.c - OpenCL host code for the particle GI kernels, and dispatch to the
 * C build of the same kernels (gi_cl_c.c). See gi_cl.h. */
#include "gi_cl.h"
#include <ctype.h>
#include <stddef.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "gi_cl_c.h"
#include "gi_links.h"
#include "pool.h"
#include "timer.h"

/* Device records: 4-byte scalars only, layout fixed (gi_types.h). */
_Static_assert(sizeof(gi_dev_particle) == 64, "gi_dev_particle is 64 bytes");
_Static_assert(offsetof(gi_dev_particle, p) == 0, "p");
_Static_assert(offsetof(gi_dev_particle, area) == 12, "area");
_Static_assert(offsetof(gi_dev_particle, n) == 16, "n");
_Static_assert(offsetof(gi_dev_particle, brilliance) == 28, "brilliance");
_Static_assert(offsetof(gi_dev_particle, rho) == 32, "rho");
_Static_assert(offsetof(gi_dev_particle, back) == 44, "back");
_Static_assert(offsetof(gi_dev_particle, le) == 48, "le");
_Static_assert(offsetof(gi_dev_particle, twin) == 60, "twin");
_Static_assert(sizeof(gi_dev_light) == 80, "gi_dev_light is 80 bytes");
_Static_assert(offsetof(gi_dev_light, pos) == 0, "pos");
_Static_assert(offsetof(gi_dev_light, kind) == 12, "kind");
_Static_assert(offsetof(gi_dev_light, colour) == 16, "colour");
_Static_assert(offsetof(gi_dev_light, parallel) == 28, "parallel");
_Static_assert(offsetof(gi_dev_light, point_at) == 32, "point_at");
_Static_assert(offsetof(gi_dev_light, tightness) == 44, "tightness");
_Static_assert(offsetof(gi_dev_light, cos_radius) == 48, "cos_radius");
_Static_assert(offsetof(gi_dev_light, cos_falloff) == 52, "cos_falloff");
_Static_assert(offsetof(gi_dev_light, radius) == 56, "radius");
_Static_assert(offsetof(gi_dev_light, falloff) == 60, "falloff");
_Static_assert(offsetof(gi_dev_light, fade_distance) == 64, "fade_distance");
_Static_assert(offsetof(gi_dev_light, fade_power) == 68, "fade_power");
_Static_assert(offsetof(gi_dev_light, shadowless) == 72, "shadowless");
_Static_assert(sizeof(gi_walk_entry) == 16 && offsetof(gi_walk_entry, w) == 4, "gi_walk_entry is 16 bytes");
_Static_assert(sizeof(gi_caus_photon) == 64 && offsetof(gi_caus_photon, r_xy) == 12 && offsetof(gi_caus_photon, n) == 16 &&
                   offsetof(gi_caus_photon, r_z) == 28 && offsetof(gi_caus_photon, w) == 32 &&
                   offsetof(gi_caus_photon, inv_rxy2) == 44 && offsetof(gi_caus_photon, phi) == 48 &&
                   offsetof(gi_caus_photon, inv_rz2) == 60,
               "gi_caus_photon is 64 bytes");
_Static_assert(sizeof(gi_caus_pixel) == 48 && offsetof(gi_caus_pixel, valid) == 12 && offsetof(gi_caus_pixel, n) == 16 &&
                   offsetof(gi_caus_pixel, brilliance) == 28 && offsetof(gi_caus_pixel, back) == 32,
               "gi_caus_pixel is 48 bytes");
_Static_assert(GI_BOUNCE_CHUNK % 32 == 0, "gi_k_bounce writes whole mask words");
_Static_assert(sizeof(gi_i64) == 8 && sizeof(gi_u32) == 4 && sizeof(float) == 4 && sizeof(int) == 4,
               "scalar sizes match OpenCL C");

#ifdef PARTRAY_HAVE_OPENCL
#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>
/* Generated at build time from gi/kernels (gi/CMakeLists.txt). */
extern const char gi_kernel_source[];
extern const char *const gi_kernel_files[];
extern const int gi_kernel_nfiles;
#endif

#define GI_CL_LOCAL 64
/* gi_k_bounce work-items (GI_BOUNCE_CHUNK particles each) per work-group */
#define GI_BOUNCE_LOCAL 4

enum { KE_EMIT, KE_BOUNCE, KE_WALK, KE_RESOLVE, KE_GATHER, KE_ESTIMATE, KE_VPL, KE_CAUSTIC, KE_BACK, KE_BACK_SEND, KE_COUNT };

struct gi_dev {
    int is_cl;
    char name[256];
    int threads;
    double build_seconds;
    size_t bytes;
    size_t max_alloc, max_total; /* OpenCL: CL_DEVICE_MAX_MEM_ALLOC_SIZE; memory budget (gi_dev_options.max_bytes) */
    /* geometry (host pointers, caller-owned) */
    const gi_dev_particle *part;
    int n, ns2, ng, nrp;
    float *rho4;   /* n x 4: the particles' reflectances (gi_k_bounce) */
    unsigned *emits; /* (n + 31) / 32 words: particles with emission (gi_k_emit) */
    size_t nmask;    /* words of a particle mask, (n + 63) / 64 * 2 */
    const int *slink, *glink, *list_off, *list_idx, *rin_off, *rin_src;
    const float *esky; /* 4 floats a particle: the sky's share of its gather (gi_links.h) */
    /* the first bounce's incoming lists cut to the candidate sources (rin
     * entries whose source has emission or some vis > 0; compact_sources),
     * rebuilt when that set changes */
    unsigned *cand, *cand_new; /* nmask words: the last stage's set (cin's when valid), scratch */
    int *cin_off, *cin_src;    /* n + 1 offsets (n + 2 ints), entries */
    size_t cin_cap;
    int cin_valid;  /* cin is built for the set in cand */
    int cand_seen;  /* cand holds a stage's set */
    const int *woff;            /* WALK path table (gi_dev_set_walk): n + 1 offsets */
    const gi_walk_entry *went;  /* and woff[n] entries */
    int nwalk;
    float *tally;  /* nb x 3 floats per gi_k_bounce work-item (read back) */
    size_t tally_cap;
    float *dsum;   /* gi_k_emit's direct flux per work-item (read back) */
    unsigned *srcmask_host; /* gi_k_emit's source mask (OpenCL: read back) */
    double emitted; /* grey emitted flux (gi_dev_sums), fixed by the particles */
    int has_back;   /* some particle has a diffuse_back lobe and a twin (gi_k_back runs) */
    /* edir and phi of the last completed stage go to these when asked
     * (gi_dev_fetch); stale: not written yet */
    float *edir_host, *phi_host;
    int stale;
    int vis_ok; /* the device's vis holds the last call's (OpenCL) */
    int had_extra; /* the last lighting stage had extra light (gi_dev_lighting) */
    /* C build scratch */
    float *edir, *src, *bin, *bout, *total;
    unsigned *mask_src, *mask_a, *mask_b; /* source masks (gi_k_emit, gi_k_bounce) */
    const float *lout_host;  /* last scatter's output (C build reads it in gather) */
    const float *eind_host;  /* last gather's output (C build reads it in estimate) */
#ifdef PARTRAY_HAVE_OPENCL
    cl_context ctx;
    cl_command_queue q;
    cl_program prog;
    cl_kernel k[KE_COUNT];
    cl_mem b_part, b_slink, b_glink, b_off, b_idx, b_rho, b_esky;
    cl_mem b_lights, b_vis, b_edir, b_src, b_tally, b_lout, b_phi, b_eind, b_list, b_vout;
    cl_mem b_rin_off, b_rin_src, b_bin, b_bout, b_total, b_woff, b_went;
    cl_mem b_emits, b_mask_src, b_mask_a, b_mask_b, b_cin_off, b_cin_src;
    cl_mem b_enew, b_dsum; /* gi_k_emit's edir (swapped with b_edir when a stage completes), direct sums */
    cl_mem b_extra;        /* gi_k_emit's extra E/pi (caustic photons), 4 floats per particle */
    cl_mem b_cph, b_ctoff, b_ctidx, b_cpix, b_ce; /* gi_k_caustic_splat's photons, tile lists, G-buffer, output */
    size_t sz_cph, sz_ctoff, sz_ctidx, sz_cpix, sz_ce;
    size_t sz_extra;
    size_t sz_lights, sz_vis, sz_tally, sz_list, sz_vout, sz_woff, sz_went, sz_cin_off, sz_cin_src;
    cl_mem b_vpts, b_vnodes, b_vtabs, b_vres, b_visits; /* gi_dev_vpl_gather */
    size_t sz_vpts, sz_vnodes, sz_vtabs, sz_vres, sz_visits;
    float *tmp;  /* n*4 readback scratch */
#endif
};

int gi_dev_opencl_built(void)
{
#ifdef PARTRAY_HAVE_OPENCL
    return 1;
#else
    return 0;
#endif
}

const char *gi_dev_name(const gi_dev *dv) { return dv ? dv->name : "none"; }
double gi_dev_build_seconds(const gi_dev *dv) { return dv ? dv->build_seconds : 0.0; }
size_t gi_dev_bytes(const gi_dev *dv) { return dv ? dv->bytes : 0; }

/* One error with one string argument. */
static void err(diag *d, const char *fmt, const char *a)
{
    src_loc nowhere = {0};
    diag_report(d, DIAG_ERROR, nowhere, NULL, fmt, a);
}

/* ------------------------------------------------------------------ OpenCL */
#ifdef PARTRAY_HAVE_OPENCL

static const char *cl_err_name(cl_int e)
{
    switch (e) {
    case CL_DEVICE_NOT_FOUND: return "CL_DEVICE_NOT_FOUND";
    case CL_DEVICE_NOT_AVAILABLE: return "CL_DEVICE_NOT_AVAILABLE";
    case CL_COMPILER_NOT_AVAILABLE: return "CL_COMPILER_NOT_AVAILABLE";
    case CL_MEM_OBJECT_ALLOCATION_FAILURE: return "CL_MEM_OBJECT_ALLOCATION_FAILURE";
    case CL_OUT_OF_RESOURCES: return "CL_OUT_OF_RESOURCES";
    case CL_OUT_OF_HOST_MEMORY: return "CL_OUT_OF_HOST_MEMORY";
    case CL_BUILD_PROGRAM_FAILURE: return "CL_BUILD_PROGRAM_FAILURE";
    case CL_INVALID_VALUE: return "CL_INVALID_VALUE";
    case CL_INVALID_DEVICE: return "CL_INVALID_DEVICE";
    case CL_INVALID_BINARY: return "CL_INVALID_BINARY";
    case CL_INVALID_BUILD_OPTIONS: return "CL_INVALID_BUILD_OPTIONS";
    case CL_INVALID_PROGRAM: return "CL_INVALID_PROGRAM";
    case CL_INVALID_KERNEL_NAME: return "CL_INVALID_KERNEL_NAME";
    case CL_INVALID_KERNEL_ARGS: return "CL_INVALID_KERNEL_ARGS";
    case CL_INVALID_ARG_INDEX: return "CL_INVALID_ARG_INDEX";
    case CL_INVALID_ARG_VALUE: return "CL_INVALID_ARG_VALUE";
    case CL_INVALID_ARG_SIZE: return "CL_INVALID_ARG_SIZE";
    case CL_INVALID_WORK_GROUP_SIZE: return "CL_INVALID_WORK_GROUP_SIZE";
    case CL_INVALID_BUFFER_SIZE: return "CL_INVALID_BUFFER_SIZE";
    case CL_INVALID_MEM_OBJECT: return "CL_INVALID_MEM_OBJECT";
    case CL_INVALID_COMMAND_QUEUE: return "CL_INVALID_COMMAND_QUEUE";
    case -1001: return "CL_PLATFORM_NOT_FOUND_KHR";
    default: return "OpenCL error";
    }
}

static pt_status cl_fail(diag *d, const char *what, cl_int e)
{
    src_loc nowhere = {0};
    diag_report(d, DIAG_ERROR, nowhere, NULL, "OpenCL: %s failed: %s (%d)", what, cl_err_name(e), (int)e);
    if (e == CL_MEM_OBJECT_ALLOCATION_FAILURE || e == CL_OUT_OF_HOST_MEMORY || e == CL_OUT_OF_RESOURCES)
        return PT_ERR_NOMEM;
    return PT_ERR_DEVICE;
}

static int contains_ci(const char *hay, const char *needle)
{
    size_t nl = strlen(needle);
    for (const char *h = hay; *h; h++) {
        size_t i = 0;
        while (i < nl && h[i] && tolower((unsigned char)h[i]) == tolower((unsigned char)needle[i])) i++;
        if (i == nl) return 1;
    }
    return nl == 0;
}

/* Concatenate the kernel files from $PARTRAY_CL_DIR; NULL if unset. */
static char *source_from_dir(const char *dir, diag *d, pt_status *st)
{
    size_t cap = 1 << 16, len = 0;
    char *s = malloc(cap);
    if (!s) { *st = PT_ERR_NOMEM; return NULL; }
    for (int f = 0; f < gi_kernel_nfiles; f++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, gi_kernel_files[f]);
        FILE *fp = fopen(path, "rb");
        if (!fp) {
            err(d, "OpenCL: PARTRAY_CL_DIR is set but %s cannot be read", path);
            free(s);
            *st = PT_ERR_IO;
            return NULL;
        }
        char buf[8192];
        size_t k;
        while ((k = fread(buf, 1, sizeof buf, fp)) > 0) {
            if (len + k + 2 > cap) {
                while (len + k + 2 > cap) cap *= 2;
                char *ns = realloc(s, cap);
                if (!ns) { fclose(fp); free(s); *st = PT_ERR_NOMEM; return NULL; }
                s = ns;
            }
            memcpy(s + len, buf, k);
            len += k;
        }
        fclose(fp);
        s[len++] = '\n';
    }
    s[len] = 0;
    return s;
}

static pt_status pick_device(const char *spec, cl_platform_id *pp, cl_device_id *dd, diag *d)
{
    cl_platform_id plats[16];
    cl_uint np = 0;
    cl_int e = clGetPlatformIDs(16, plats, &np);
    if (e != CL_SUCCESS || np == 0) {
        src_loc nowhere = {0};
        diag_report(d, DIAG_ERROR, nowhere, NULL,
                    "OpenCL: no platform found (%s). Install an OpenCL driver -- on Debian the CPU driver is the "
                    "package pocl-opencl-icd, with the ICD loader ocl-icd-libopencl1 -- or run the kernels "
                    "as C with --cl-device c",
                    e == CL_SUCCESS ? "0 platforms" : cl_err_name(e));
        return PT_ERR_DEVICE;
    }
    int want_p = -1, want_d = -1;
    int automatic = !spec || !*spec || strcmp(spec, "auto") == 0;
    if (!automatic && isdigit((unsigned char)spec[0]) && strchr(spec, ':')) {
        want_p = atoi(spec);
        want_d = atoi(strchr(spec, ':') + 1);
    }
    cl_device_id first = NULL, first_gpu = NULL;
    cl_platform_id first_p = NULL, first_gpu_p = NULL;
    for (cl_uint p = 0; p < np; p++) {
        cl_device_id devs[16];
        cl_uint nd = 0;
        if (clGetDeviceIDs(plats[p], CL_DEVICE_TYPE_ALL, 16, devs, &nd) != CL_SUCCESS) continue;
        char pname[256] = "";
        clGetPlatformInfo(plats[p], CL_PLATFORM_NAME, sizeof pname, pname, NULL);
        for (cl_uint k = 0; k < nd; k++) {
            char dname[256] = "";
            clGetDeviceInfo(devs[k], CL_DEVICE_NAME, sizeof dname, dname, NULL);
            cl_device_type ty = 0;
            clGetDeviceInfo(devs[k], CL_DEVICE_TYPE, sizeof ty, &ty, NULL);
            if (want_p >= 0) {
                if ((int)p == want_p && (int)k == want_d) {
                    *pp = plats[p];
                    *dd = devs[k];
                    return PT_OK;
                }
                continue;
            }
            if (!automatic) {
                if (contains_ci(dname, spec) || contains_ci(pname, spec)) {
                    *pp = plats[p];
                    *dd = devs[k];
                    return PT_OK;
                }
                continue;
            }
            if (!first) { first = devs[k]; first_p = plats[p]; }
            if (!first_gpu && (ty & CL_DEVICE_TYPE_GPU)) { first_gpu = devs[k]; first_gpu_p = plats[p]; }
        }
    }
    if (first_gpu) { *pp = first_gpu_p; *dd = first_gpu; return PT_OK; }
    if (automatic && first) { *pp = first_p; *dd = first; return PT_OK; }
    src_loc nowhere = {0};
    if (automatic)
        diag_report(d, DIAG_ERROR, nowhere, NULL,
                    "OpenCL: no device found on %u platform(s); on Debian install pocl-opencl-icd for the CPU "
                    "device, or run the kernels as C with --cl-device c", (unsigned)np);
    else
        diag_report(d, DIAG_ERROR, nowhere, NULL, "OpenCL: no device matches '%s' (use auto, c, P:D or part of a name)",
                    spec);
    return PT_ERR_DEVICE;
}

static pt_status cl_open(gi_dev *dv, const gi_dev_options *o, diag *d)
{
    cl_platform_id plat;
    cl_device_id dev;
    pt_status st = pick_device(o ? o->spec : NULL, &plat, &dev, d);
    if (st != PT_OK) return st;
    char dname[200] = "", pname[48] = "";
    clGetDeviceInfo(dev, CL_DEVICE_NAME, sizeof dname, dname, NULL);
    clGetPlatformInfo(plat, CL_PLATFORM_NAME, sizeof pname, pname, NULL);
    snprintf(dv->name, sizeof dv->name, "OpenCL: %s (%s)", dname, pname);
    cl_ulong max_alloc = 0, global = 0;
    clGetDeviceInfo(dev, CL_DEVICE_MAX_MEM_ALLOC_SIZE, sizeof max_alloc, &max_alloc, NULL);
    clGetDeviceInfo(dev, CL_DEVICE_GLOBAL_MEM_SIZE, sizeof global, &global, NULL);
    dv->max_alloc = max_alloc > 0 && max_alloc < (cl_ulong)SIZE_MAX ? (size_t)max_alloc : SIZE_MAX;
    dv->max_total = global > 0 && global < (cl_ulong)SIZE_MAX ? (size_t)global : SIZE_MAX;
    if (o && o->max_bytes > 0 && o->max_bytes < dv->max_total) dv->max_total = o->max_bytes;
    cl_int e;
    cl_context_properties props[] = {CL_CONTEXT_PLATFORM, (cl_context_properties)plat, 0};
    dv->ctx = clCreateContext(props, 1, &dev, NULL, NULL, &e);
    if (!dv->ctx) return cl_fail(d, "clCreateContext", e);
    dv->q = clCreateCommandQueue(dv->ctx, dev, 0, &e);
    if (!dv->q) return cl_fail(d, "clCreateCommandQueue", e);

    char *owned = NULL;
    const char *src = o ? o->source : NULL;
    if (!src) {
        const char *dir = getenv("PARTRAY_CL_DIR");
        if (dir && *dir) {
            pt_status s2 = PT_OK;
            owned = source_from_dir(dir, d, &s2);
            if (!owned) return s2;
            src = owned;
        } else {
            src = gi_kernel_source;
        }
    }
    double t0 = timer_now();
    dv->prog = clCreateProgramWithSource(dv->ctx, 1, &src, NULL, &e);
    free(owned);
    if (!dv->prog) return cl_fail(d, "clCreateProgramWithSource", e);
    e = clBuildProgram(dv->prog, 1, &dev, "-cl-std=CL1.2", NULL, NULL);
    dv->build_seconds = timer_now() - t0;
    if (e != CL_SUCCESS) {
        size_t loglen = 0;
        clGetProgramBuildInfo(dv->prog, dev, CL_PROGRAM_BUILD_LOG, 0, NULL, &loglen);
        char *log = malloc(loglen + 1);
        if (log) {
            log[0] = 0;
            clGetProgramBuildInfo(dv->prog, dev, CL_PROGRAM_BUILD_LOG, loglen, log, NULL);
            log[loglen] = 0;
        }
        src_loc nowhere = {0};
        diag_report(d, DIAG_ERROR, nowhere, NULL, "OpenCL: kernel build failed on %s (%s); build log:\n%s", dname,
                    cl_err_name(e), log ? log : "(no log)");
        free(log);
        return PT_ERR_DEVICE;
    }
    static const char *const names[KE_COUNT] = {"gi_k_emit", "gi_k_bounce", "gi_k_walk", "gi_k_resolve",
                                                "gi_k_gather", "gi_k_estimate", "gi_k_vpl_gather",
                                                "gi_k_caustic_splat", "gi_k_back", "gi_k_back_send"};
    for (int k = 0; k < KE_COUNT; k++) {
        dv->k[k] = clCreateKernel(dv->prog, names[k], &e);
        if (!dv->k[k]) return cl_fail(d, names[k], e);
    }
    return PT_OK;
}

static void rel(cl_mem *m)
{
    if (*m) clReleaseMemObject(*m);
    *m = NULL;
}

/* Every device buffer of dv released (gi_dev_free, and gi_dev_set_particles
 * before a new geometry's): the one list of them. */
static void release_buffers(gi_dev *dv)
{
    cl_mem *ms[] = {&dv->b_part, &dv->b_rho, &dv->b_esky, &dv->b_slink, &dv->b_glink, &dv->b_off, &dv->b_idx, &dv->b_lights,
                    &dv->b_vis, &dv->b_edir, &dv->b_src, &dv->b_tally, &dv->b_lout, &dv->b_phi,
                    &dv->b_eind, &dv->b_list, &dv->b_vout, &dv->b_rin_off, &dv->b_rin_src, &dv->b_bin,
                    &dv->b_bout, &dv->b_total, &dv->b_woff, &dv->b_went,
                    &dv->b_emits, &dv->b_mask_src, &dv->b_mask_a, &dv->b_mask_b, &dv->b_cin_off,
                    &dv->b_cin_src, &dv->b_enew, &dv->b_dsum, &dv->b_extra, &dv->b_vpts, &dv->b_vnodes, &dv->b_vtabs,
                    &dv->b_vres, &dv->b_visits, &dv->b_cph, &dv->b_ctoff, &dv->b_ctidx, &dv->b_cpix, &dv->b_ce};
    for (size_t i = 0; i < sizeof ms / sizeof ms[0]; i++) rel(ms[i]);
}

static const char *mib(size_t n, char *buf, size_t cap)
{
    snprintf(buf, cap, "%.1f MiB", (double)n / (1024.0 * 1024.0));
    return buf;
}

/* (Re)allocate buffer *m to at least `size` bytes; *have tracks its size.
 * Sizes the device cannot hold are refused before they are requested (an
 * implementation may crash or fail late instead of returning an error). */
static pt_status ensure(gi_dev *dv, cl_mem *m, size_t *have, size_t size, diag *d)
{
    if (size == 0) size = 16;
    if (*m && *have >= size) return PT_OK;
    if (*m) { dv->bytes -= *have; rel(m); *have = 0; }
    char a[32], b[32], c[32];
    src_loc nowhere = {0};
    if (size > dv->max_alloc) {
        diag_report(d, DIAG_ERROR, nowhere, NULL,
                    "OpenCL: out of device memory: particle GI needs a buffer of %s on %s, more than its largest "
                    "allocation of %s (CL_DEVICE_MAX_MEM_ALLOC_SIZE); use fewer particles or --cl-device c",
                    mib(size, a, sizeof a), dv->name, mib(dv->max_alloc, b, sizeof b));
        return PT_ERR_NOMEM;
    }
    if (size > dv->max_total || dv->bytes > dv->max_total - size) {
        diag_report(d, DIAG_ERROR, nowhere, NULL,
                    "OpenCL: out of device memory: particle GI needs %s more on %s (%s held), more than the %s it "
                    "may use (CL_DEVICE_GLOBAL_MEM_SIZE or --cl-max-memory); use fewer particles or --cl-device c",
                    mib(size, a, sizeof a), dv->name, mib(dv->bytes, b, sizeof b), mib(dv->max_total, c, sizeof c));
        return PT_ERR_NOMEM;
    }
    cl_int e;
    *m = clCreateBuffer(dv->ctx, CL_MEM_READ_WRITE, size, NULL, &e);
    if (!*m) {
        *have = 0;
        cl_fail(d, "clCreateBuffer", e);
        return PT_ERR_NOMEM;
    }
    *have = size;
    dv->bytes += size;
    return PT_OK;
}

static pt_status upload(gi_dev *dv, cl_mem *m, size_t *have, const void *data, size_t size, diag *d)
{
    pt_status st = ensure(dv, m, have, size, d);
    if (st != PT_OK) return st;
    if (size == 0) return PT_OK;
    cl_int e = clEnqueueWriteBuffer(dv->q, *m, CL_TRUE, 0, size, data, 0, NULL, NULL);
    return e == CL_SUCCESS ? PT_OK : cl_fail(d, "clEnqueueWriteBuffer", e);
}

/* A read of m into data: waited for (blocking), or only enqueued (the queue
 * is in order: a later blocking read or settle() waits for it too). */
static pt_status read_buf(gi_dev *dv, cl_mem m, void *data, size_t size, cl_bool blocking, diag *d)
{
    if (size == 0) return PT_OK;
    cl_int e = clEnqueueReadBuffer(dv->q, m, blocking, 0, size, data, 0, NULL, NULL);
    return e == CL_SUCCESS ? PT_OK : cl_fail(d, "clEnqueueReadBuffer", e);
}

static pt_status download(gi_dev *dv, cl_mem m, void *data, size_t size, diag *d)
{
    return read_buf(dv, m, data, size, CL_TRUE, d);
}

/* Waits for what the queue holds (the reads read_buf only enqueued), also
 * after a failed enqueue, so that no read lands in host memory after the
 * call returned; st: the status so far, kept when it is an error. */
static pt_status settle(gi_dev *dv, pt_status st, diag *d)
{
    cl_int e = clFinish(dv->q);
    if (st != PT_OK) return st;
    return e == CL_SUCCESS ? PT_OK : cl_fail(d, "clFinish", e);
}

static pt_status zero(gi_dev *dv, cl_mem m, size_t size, diag *d)
{
    if (size == 0) return PT_OK;
    static const gi_i64 z = 0;
    cl_int e = clEnqueueFillBuffer(dv->q, m, &z, sizeof z, 0, size, 0, NULL, NULL);
    return e == CL_SUCCESS ? PT_OK : cl_fail(d, "clEnqueueFillBuffer", e);
}

typedef struct {
    size_t size;
    const void *ptr;
} karg;
#define KMEM(m) ((karg){sizeof(cl_mem), &(m)})
#define KINT(v) ((karg){sizeof(int), &(v)})
#define KF(v) ((karg){sizeof(float), &(v)})

static pt_status run_kernel_local(gi_dev *dv, int which, size_t n, size_t local, const karg *args, int nargs,
                                  diag *d);
static pt_status run_kernel(gi_dev *dv, int which, size_t n, const karg *args, int nargs, diag *d)
{
    return run_kernel_local(dv, which, n, GI_CL_LOCAL, args, nargs, d);
}

static pt_status run_kernel_local(gi_dev *dv, int which, size_t n, size_t local, const karg *args, int nargs,
                                  diag *d)
{
    cl_kernel k = dv->k[which];
    for (int i = 0; i < nargs; i++) {
        cl_int e = clSetKernelArg(k, (cl_uint)i, args[i].size, args[i].ptr);
        if (e != CL_SUCCESS) return cl_fail(d, "clSetKernelArg", e);
    }
    if (n == 0) return PT_OK;
    /* a fixed work-group size (PoCL compiles a kernel once per size) and a
     * global size rounded up to it; the kernels ignore ids past n */
    size_t global = (n + local - 1) / local * local;
    cl_int e = clEnqueueNDRangeKernel(dv->q, k, 1, NULL, &global, &local, 0, NULL, NULL);
    if (e != CL_SUCCESS) return cl_fail(d, "clEnqueueNDRangeKernel", e);
    e = clFinish(dv->q);
    return e == CL_SUCCESS ? PT_OK : cl_fail(d, "clFinish", e);
}
#endif /* PARTRAY_HAVE_OPENCL */

/* The C build's work buffers (gi_dev_set_particles allocates them; an
 * OpenCL device has its own on the device). */
static void free_c_work(gi_dev *dv)
{
    free(dv->edir);
    free(dv->src);
    free(dv->bin);
    free(dv->bout);
    free(dv->total);
    free(dv->mask_src);
    free(dv->mask_a);
    free(dv->mask_b);
}

/* ------------------------------------------------------------------ common */

gi_dev *gi_dev_open(const gi_dev_options *o, diag *d, pt_status *status)
{
    pt_status dummy;
    if (!status) status = &dummy;
    gi_dev *dv = calloc(1, sizeof *dv);
    if (!dv) { *status = PT_ERR_NOMEM; return NULL; }
    dv->threads = o && o->threads > 0 ? o->threads : pool_default_threads();
    const char *spec = o ? o->spec : NULL;
    if (spec && strcmp(spec, "c") == 0) {
        snprintf(dv->name, sizeof dv->name, "C build of the kernels (%d threads)", dv->threads);
        *status = PT_OK;
        return dv;
    }
#ifdef PARTRAY_HAVE_OPENCL
    dv->is_cl = 1;
    *status = cl_open(dv, o, d);
    if (*status != PT_OK) {
        gi_dev_free(dv);
        return NULL;
    }
    return dv;
#else
    if (spec && *spec && strcmp(spec, "auto") != 0) {
        err(d, "OpenCL device '%s' requested but partray was built with PARTRAY_OPENCL=OFF", spec);
        free(dv);
        *status = PT_ERR_UNSUPPORTED;
        return NULL;
    }
    snprintf(dv->name, sizeof dv->name, "C build of the kernels (%d threads, OpenCL off)", dv->threads);
    *status = PT_OK;
    return dv;
#endif
}

void gi_dev_free(gi_dev *dv)
{
    if (!dv) return;
#ifdef PARTRAY_HAVE_OPENCL
    if (dv->is_cl) {
        release_buffers(dv);
        for (int k = 0; k < KE_COUNT; k++)
            if (dv->k[k]) clReleaseKernel(dv->k[k]);
        if (dv->prog) clReleaseProgram(dv->prog);
        if (dv->q) clReleaseCommandQueue(dv->q);
        if (dv->ctx) clReleaseContext(dv->ctx);
        free(dv->tmp);
    }
#endif
    free_c_work(dv);
    free(dv->rho4);
    free(dv->emits);
    free(dv->cand);
    free(dv->cand_new);
    free(dv->cin_off);
    free(dv->cin_src);
    free(dv->tally);
    free(dv->dsum);
    free(dv->srcmask_host);
    free(dv);
}

pt_status gi_dev_set_particles(gi_dev *dv, const gi_dev_particle *part, int n, const int *slink, int ns2,
                               const int *glink, int ng, const float *esky, diag *d)
{
    dv->part = part;
    dv->esky = esky;
    dv->n = n;
    dv->slink = slink;
    dv->ns2 = ns2;
    dv->glink = glink;
    dv->ng = ng;
    size_t nn = (size_t)(n > 0 ? n : 1);
    free(dv->rho4);
    dv->rho4 = calloc(nn * 4, sizeof(float));
    if (!dv->rho4) return PT_ERR_NOMEM;
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) dv->rho4[4 * (size_t)i + c] = part[i].rho[c];
    /* masks: whole 64-particle chunks (gi_k_bounce writes 2 words each) */
    dv->nmask = (nn + 63) / 64 * 2;
    free(dv->emits);
    free(dv->cand);
    free(dv->cand_new);
    free(dv->cin_off);
    dv->cin_valid = dv->cand_seen = 0;
    dv->emits = calloc(dv->nmask, sizeof(unsigned));
    dv->cand = calloc(dv->nmask, sizeof(unsigned));
    dv->cand_new = calloc(dv->nmask, sizeof(unsigned));
    dv->cin_off = calloc(nn + 2, sizeof(int)); /* gi_links_reverse_count */
    free(dv->dsum);
    free(dv->srcmask_host);
    dv->dsum = calloc(dv->nmask, sizeof(float));
    dv->srcmask_host = calloc(dv->nmask, sizeof(unsigned));
    if (!dv->emits || !dv->cand || !dv->cand_new || !dv->cin_off || !dv->dsum || !dv->srcmask_host)
        return PT_ERR_NOMEM;
    dv->emitted = 0.0;
    dv->has_back = 0;
    for (int i = 0; i < n; i++) {
        /* emits: particles gi_k_emit must read without a light on them, the
         * emitters and the diffuse_back particles (their twin's light) */
        int back = part[i].back > 0.0f && part[i].twin >= 0;
        dv->has_back |= back;
        if (back || part[i].le[0] != 0.0f || part[i].le[1] != 0.0f || part[i].le[2] != 0.0f)
            dv->emits[i >> 5] |= 1u << (i & 31);
        for (int c = 0; c < 3; c++) dv->emitted += 3.14159265358979323846 * part[i].le[c] * part[i].area / 3.0;
    }
    dv->stale = 0;
    dv->vis_ok = 0;
    if (!dv->is_cl) {
        free_c_work(dv);
        dv->edir = calloc(nn * 4, sizeof(float));
        dv->src = calloc(nn * 4, sizeof(float));
        dv->bin = calloc(nn * 4, sizeof(float));
        dv->bout = calloc(nn * 4, sizeof(float));
        dv->total = calloc(nn * 4, sizeof(float));
        dv->mask_src = calloc(dv->nmask, sizeof(unsigned));
        dv->mask_a = calloc(dv->nmask, sizeof(unsigned));
        dv->mask_b = calloc(dv->nmask, sizeof(unsigned));
        dv->bytes = nn * 6 * 16 + 4 * dv->nmask * sizeof(unsigned);
        if (!dv->edir || !dv->src || !dv->bin || !dv->bout || !dv->total || !dv->mask_src || !dv->mask_a ||
            !dv->mask_b)
            return PT_ERR_NOMEM;
        return PT_OK;
    }
#ifdef PARTRAY_HAVE_OPENCL
    size_t have = 0;
    pt_status st;
    /* a new geometry: drop every buffer and start the byte count again */
    release_buffers(dv);
    dv->sz_lights = dv->sz_vis = dv->sz_tally = dv->sz_list = dv->sz_vout = dv->sz_woff = dv->sz_went = 0;
    dv->sz_cin_off = dv->sz_cin_src = dv->sz_extra = 0;
    dv->bytes = 0;
    /* the real count: with no particles the arrays may be NULL (buffers get a
     * minimal size, nothing is written) */
    size_t nr = n > 0 ? (size_t)n : 0;
    if ((st = upload(dv, &dv->b_part, &have, part, nr * sizeof *part, d)) != PT_OK) return st;
    have = 0;
    if ((st = upload(dv, &dv->b_rho, &have, dv->rho4, nr * 4 * sizeof(float), d)) != PT_OK) return st;
    have = 0;
    if ((st = upload(dv, &dv->b_slink, &have, slink, nr * (size_t)ns2 * sizeof(int), d)) != PT_OK) return st;
    have = 0;
    if ((st = upload(dv, &dv->b_glink, &have, glink, nr * (size_t)ng * sizeof(int), d)) != PT_OK) return st;
    have = 0;
    if ((st = upload(dv, &dv->b_esky, &have, esky, nr * 4 * sizeof(float), d)) != PT_OK) return st;
    have = 0;
    if ((st = upload(dv, &dv->b_emits, &have, dv->emits, dv->nmask * sizeof(unsigned), d)) != PT_OK) return st;
    cl_mem *mb[] = {&dv->b_mask_src, &dv->b_mask_a, &dv->b_mask_b};
    for (int k = 0; k < 3; k++) {
        have = 0;
        if ((st = ensure(dv, mb[k], &have, dv->nmask * sizeof(unsigned), d)) != PT_OK) return st;
        if ((st = zero(dv, *mb[k], dv->nmask * sizeof(unsigned), d)) != PT_OK) return st;
    }
    size_t f4 = nn * 4 * sizeof(float);
    have = 0;
    if ((st = ensure(dv, &dv->b_edir, &have, f4, d)) != PT_OK) return st;
    have = 0;
    if ((st = ensure(dv, &dv->b_src, &have, f4, d)) != PT_OK) return st;
    have = 0;
    if ((st = ensure(dv, &dv->b_enew, &have, f4, d)) != PT_OK) return st;
    have = 0;
    if ((st = ensure(dv, &dv->b_dsum, &have, dv->nmask * sizeof(float), d)) != PT_OK) return st;
    have = 0;
    if ((st = ensure(dv, &dv->b_lout, &have, f4, d)) != PT_OK) return st;
    have = 0;
    if ((st = ensure(dv, &dv->b_phi, &have, f4, d)) != PT_OK) return st;
    have = 0;
    if ((st = ensure(dv, &dv->b_eind, &have, f4, d)) != PT_OK) return st;
    if ((st = zero(dv, dv->b_eind, f4, d)) != PT_OK) return st;
    cl_mem *fb[] = {&dv->b_bin, &dv->b_bout, &dv->b_total};
    for (int k = 0; k < 3; k++) {
        have = 0;
        if ((st = ensure(dv, fb[k], &have, f4, d)) != PT_OK) return st;
        if ((st = zero(dv, *fb[k], f4, d)) != PT_OK) return st;
    }
    if ((st = zero(dv, dv->b_lout, f4, d)) != PT_OK) return st;
    free(dv->tmp);
    dv->tmp = malloc(f4);
    if (!dv->tmp) return PT_ERR_NOMEM;
    return PT_OK;
#else
    return PT_ERR_INTERNAL;
#endif
}

pt_status gi_dev_set_lists(gi_dev *dv, const int *list_off, int nrp, const int *list_idx, diag *d)
{
    dv->list_off = list_off;
    dv->list_idx = list_idx;
    dv->nrp = nrp;
    if (!dv->is_cl) return PT_OK;
#ifdef PARTRAY_HAVE_OPENCL
    rel(&dv->b_off);
    rel(&dv->b_idx);
    size_t have = 0;
    pt_status st = upload(dv, &dv->b_off, &have, list_off, ((size_t)nrp + 1) * sizeof(int), d);
    if (st != PT_OK) return st;
    have = 0;
    return upload(dv, &dv->b_idx, &have, list_idx, (size_t)list_off[nrp] * sizeof(int), d);
#else
    return PT_ERR_INTERNAL;
#endif
}

pt_status gi_dev_set_reverse(gi_dev *dv, const int *rin_off, const int *rin_src, diag *d)
{
    dv->rin_off = rin_off;
    dv->rin_src = rin_src;
    dv->cin_valid = 0;
    if (!dv->is_cl) return PT_OK;
#ifdef PARTRAY_HAVE_OPENCL
    rel(&dv->b_rin_off);
    rel(&dv->b_rin_src);
    size_t have = 0;
    pt_status st = upload(dv, &dv->b_rin_off, &have, rin_off, ((size_t)dv->n + 1) * sizeof(int), d);
    if (st != PT_OK) return st;
    have = 0;
    return upload(dv, &dv->b_rin_src, &have, rin_src, (size_t)rin_off[dv->n] * sizeof(int), d);
#else
    return PT_ERR_INTERNAL;
#endif
}

pt_status gi_dev_set_walk(gi_dev *dv, const int *woff, const gi_walk_entry *went, int nwalk, diag *d)
{
    dv->woff = woff;
    dv->went = went;
    dv->nwalk = nwalk;
    if (!dv->is_cl) return PT_OK;
#ifdef PARTRAY_HAVE_OPENCL
    if (dv->b_woff) dv->bytes -= dv->sz_woff;
    if (dv->b_went) dv->bytes -= dv->sz_went;
    rel(&dv->b_woff);
    rel(&dv->b_went);
    dv->sz_woff = dv->sz_went = 0;
    size_t nr = (size_t)(dv->n > 0 ? dv->n : 0);
    pt_status st = upload(dv, &dv->b_woff, &dv->sz_woff, woff, (nr + 1) * sizeof(int), d);
    if (st != PT_OK) return st;
    return upload(dv, &dv->b_went, &dv->sz_went, went, (size_t)woff[nr] * sizeof *went, d);
#else
    (void)d;
    return PT_ERR_INTERNAL;
#endif
}

/* The first bounce reads only particles that send light (gi_k_emit's source
 * mask), but a gather over every incoming link (rin) still reads every link
 * and tests its source's bit. cin holds the incoming links of the candidate
 * sources only: particles with emission, some vis > 0 or extra light, the ones gi_k_emit
 * may give a non-zero src (the others get 0, and adding a 0 changes no
 * float sum: the same sums as over rin, bit for bit). It is a counting sort
 * of the candidates' own scattering links (slink) by target, candidates
 * ascending: per target the same entries in the same order as rin's. The
 * set changes only with the visibility and the extra light (changed). The
 * sort costs about what it saves in one bounce (more when most particles
 * are candidates; bench/bench_gi prints the lighting stage), so a stage whose
 * set differs from the previous stage's gathers over rin with the mask, and
 * the lists are built when a stage finds the same set again (a colour
 * change, a frame relit with nothing moved) and reused while it stays. The
 * first stage after gi_dev_set_particles (every light traced, the sort a
 * small part of it) builds them at once. */
static pt_status compact_sources(gi_dev *dv, const float *vis, int nlights, int changed, const float *extra,
                                 diag *d)
{
    int n = dv->n, ns2 = dv->ns2;
    size_t words = ((size_t)n + 31) / 32;
    if (!changed && dv->cand_seen) goto same; /* the same vis and extra light: the same set */
    memcpy(dv->cand_new, dv->emits, words * sizeof(unsigned));
    /* no lights: vis may be NULL (no offset from it, C11 6.5.6) */
    for (int i = 0; nlights > 0 && i < n; i++) {
        const float *v = vis + (size_t)i * (size_t)nlights;
        int lit = 0;
        for (int l = 0; l < nlights; l++) lit |= v[l] > 0.0f;
        if (lit) dv->cand_new[i >> 5] |= 1u << (i & 31);
    }
    for (int i = 0; extra && i < n; i++)
        if (extra[4 * (size_t)i] > 0.0f || extra[4 * (size_t)i + 1] > 0.0f || extra[4 * (size_t)i + 2] > 0.0f)
            dv->cand_new[i >> 5] |= 1u << (i & 31);
    unsigned *t = dv->cand;
    dv->cand = dv->cand_new;
    dv->cand_new = t;
    if (dv->cand_seen && memcmp(dv->cand_new, dv->cand, words * sizeof(unsigned)) != 0) {
        dv->cin_valid = 0; /* a new set: this stage gathers over rin */
        return PT_OK;
    }
    dv->cand_seen = 1; /* the first stage builds at once: it traces every light anyway */
same:
    if (dv->cin_valid) return PT_OK;
    int *off = dv->cin_off;
    size_t m = gi_links_reverse_count(dv->slink, n, ns2, dv->cand, off);
    if (m > dv->cin_cap || !dv->cin_src) {
        free(dv->cin_src);
        dv->cin_src = malloc((m > 0 ? m : 1) * sizeof(int));
        dv->cin_cap = dv->cin_src ? m : 0;
        if (!dv->cin_src) return PT_ERR_NOMEM;
    }
    gi_links_reverse_fill(dv->slink, n, ns2, dv->cand, off, dv->cin_src);
#ifdef PARTRAY_HAVE_OPENCL
    if (dv->is_cl) {
        pt_status st = upload(dv, &dv->b_cin_off, &dv->sz_cin_off, off, ((size_t)n + 1) * sizeof(int), d);
        if (st == PT_OK) st = upload(dv, &dv->b_cin_src, &dv->sz_cin_src, dv->cin_src, m * sizeof(int), d);
        if (st != PT_OK) return st;
    }
#else
    (void)d;
#endif
    dv->cin_valid = 1;
    return PT_OK;
}

/* The per-bounce tallies (3 floats per gi_k_bounce work-item) summed in a
 * fixed order, grey (mean of the colours). */
static void sum_bounces(const float *tally, size_t items, int nb, double *bounce_flux)
{
    for (int b = 0; b < nb; b++) {
        double t = 0.0;
        const float *tb = tally + (size_t)b * 3 * items;
        for (size_t k = 0; k < 3 * items; k++) t += tb[k];
        if (bounce_flux) bounce_flux[b] = t / 3.0;
    }
}

static int cancelled(volatile int *cancel) { return cancel && *cancel; }

/* After a bounce (or gi_k_back_send): what it wrote (bout, mask_a) becomes
 * the next one's input (bin, mask_b), and the old input the free pair. */
static void swap_c_pairs(gi_dev *dv)
{
    float *t = dv->bin;
    dv->bin = dv->bout;
    dv->bout = t;
    unsigned *m = dv->mask_b;
    dv->mask_b = dv->mask_a;
    dv->mask_a = m;
}

#ifdef PARTRAY_HAVE_OPENCL
static void swap_cl_pairs(gi_dev *dv)
{
    cl_mem t = dv->b_bin;
    dv->b_bin = dv->b_bout;
    dv->b_bout = t;
    t = dv->b_mask_b;
    dv->b_mask_b = dv->b_mask_a;
    dv->b_mask_a = t;
}
#endif
/* What gi_dev_sums reports, from the per-work-item sums and masks. */
static void fill_sums(const gi_dev *dv, size_t eitems, int nb, const double *bounce_flux, gi_dev_sums *sums)
{
    if (!sums) return;
    double dsum = 0.0;
    long nsrc = 0;
    for (size_t g = 0; g < eitems; g++) {
        dsum += dv->dsum[g];
        nsrc += __builtin_popcount(dv->srcmask_host[g]);
    }
    sums->direct = dsum / 3.0;
    sums->emitted = dv->emitted;
    sums->sources = nsrc;
    double sc = 0.0;
    for (int b = 0; b < nb && bounce_flux; b++) sc += bounce_flux[b];
    sums->scattered = sc;
}

pt_status gi_dev_lighting(gi_dev *dv, const gi_dev_light *lights, int nlights, const float *vis, int vis_changed,
                          const float *extra, int mode, int nb, volatile int *cancel, float *edir, float *lout, float *phi,
                          double *bounce_flux, gi_dev_sums *sums, int *done, double times[2], diag *d)
{
    double t0 = timer_now(), t1 = t0;
    size_t nn = (size_t)dv->n;
    int n = dv->n, ns2 = dv->ns2 > 0 ? dv->ns2 : 1;
    *done = 0;
    if (nb > GI_MAX_BOUNCES) nb = GI_MAX_BOUNCES;
    if (nb < 0) nb = 0;
    if (!dv->rin_off) nb = 0;
    int walk = mode == GI_SCATTER_WALK;
    if (walk && nb > dv->nwalk + 1) {
        err(d, "particle GI: %s", "the walk lists are shorter than the bounce count (gi_dev_set_walk)");
        return PT_ERR_INTERNAL;
    }
    /* WALK: bounce 0 (gi_k_bounce), then bounces 1 .. nb - 1 and the
     * radiance in one gi_k_walk; FULL (or nb 0): every bounce by
     * gi_k_bounce, then gi_k_resolve */
    int fused = walk && nb > 0;
    int nbounce = fused ? 1 : nb;
    float w_fan = 1.0f / (float)ns2;
    size_t items = (nn + GI_BOUNCE_CHUNK - 1) / GI_BOUNCE_CHUNK;
    size_t eitems = (nn + GI_EMIT_CHUNK - 1) / GI_EMIT_CHUNK;
    size_t tcount = (size_t)(nb > 0 ? nb : 1) * 3 * (items > 0 ? items : 1);
    if (tcount > dv->tally_cap) {
        free(dv->tally);
        dv->tally = malloc(tcount * sizeof(float));
        dv->tally_cap = dv->tally ? tcount : 0;
        if (!dv->tally) return PT_ERR_NOMEM;
    }
#ifdef PARTRAY_HAVE_OPENCL
    /* the device's vis is the last call's only if that one uploaded it */
    if (dv->is_cl && !dv->vis_ok) vis_changed = 1;
#endif
    /* the extra light may differ from the last stage's: the sources' set
     * is found again (compact_sources keeps its lists when it is the same);
     * vis itself is uploaded only when it changed */
    int sources_changed = vis_changed || extra || dv->had_extra;
    dv->had_extra = extra != NULL;
    if (nb > 0) {
        pt_status cs = compact_sources(dv, vis, nlights, sources_changed, extra, d);
        if (cs != PT_OK) return cs;
    }
    if (!dv->is_cl) {
        if (cancelled(cancel)) return PT_OK;
        gi_c_emit(dv->threads, dv->part, n, lights, nlights, vis, dv->emits, dv->edir, dv->src, dv->mask_src,
                  dv->dsum, extra);
        t1 = timer_now();
        const float *bin = dv->src;
        const unsigned *min = dv->mask_src;
        for (int b = 0; b < nbounce; b++) {
            if (cancelled(cancel)) return PT_OK;
            int c0 = b == 0 && dv->cin_valid;
            gi_c_bounce(dv->threads, n, c0 ? dv->cin_off : dv->rin_off, 0, c0 ? dv->cin_src : dv->rin_src, 0,
                        w_fan, bin, min, dv->rho4, b == 0, dv->bout, dv->mask_a, dv->total, dv->tally,
                        b * 3 * (int)items);
            swap_c_pairs(dv);
            if (dv->has_back && b + 1 < nbounce) {
                /* the back lobes' share of what this bounce sends on
                 * (gi_k_back_send), into the free pair, then swapped in */
                gi_c_back_send(dv->threads, dv->part, n, dv->rho4, dv->bin, dv->bout, dv->mask_a);
                swap_c_pairs(dv);
            }
            bin = dv->bin;
            min = dv->mask_b;
        }
        if (cancelled(cancel)) return PT_OK;
        /* from here on the results are written: not cancelled any more */
        if (fused)
            gi_c_walk(dv->threads, dv->part, n, dv->edir, dv->total, min, dv->woff, dv->went, nb - 1, lout, phi,
                      dv->tally, (int)items);
        else
            gi_c_resolve(dv->threads, dv->part, n, dv->edir, nb > 0, dv->total, lout, phi);
        if (dv->has_back) gi_c_back(dv->threads, dv->part, n, phi, lout);
        memcpy(edir, dv->edir, nn * 4 * sizeof(float));
        memcpy(dv->srcmask_host, dv->mask_src, eitems * sizeof(unsigned));
        sum_bounces(dv->tally, items, nb, bounce_flux);
        fill_sums(dv, eitems, nb, bounce_flux, sums);
        dv->lout_host = lout;
        dv->stale = 0;
        *done = 1;
        if (times) {
            times[0] = t1 - t0;
            times[1] = timer_now() - t1;
        }
        return PT_OK;
    }
#ifdef PARTRAY_HAVE_OPENCL
    pt_status st;
    size_t f4 = nn * 4 * sizeof(float);
    if (cancelled(cancel)) return PT_OK;
    if ((st = upload(dv, &dv->b_lights, &dv->sz_lights, lights, (size_t)nlights * sizeof *lights, d)) != PT_OK)
        return st;
    if (vis_changed) {
        dv->vis_ok = 0;
        if ((st = upload(dv, &dv->b_vis, &dv->sz_vis, vis, nn * (size_t)nlights * sizeof(float), d)) != PT_OK)
            return st;
        dv->vis_ok = 1;
    }
    if ((st = ensure(dv, &dv->b_tally, &dv->sz_tally, tcount * sizeof(float), d)) != PT_OK) return st;
    /* emission into b_enew: b_edir keeps the last completed stage's (gi_dev_fetch) */
    /* no extra light: a minimal buffer the kernel does not read */
    if ((st = extra ? upload(dv, &dv->b_extra, &dv->sz_extra, extra, f4, d)
                    : ensure(dv, &dv->b_extra, &dv->sz_extra, 16, d)) != PT_OK)
        return st;
    int has_extra = extra != NULL;
    karg a[] = {KMEM(dv->b_part),  KINT(n),          KMEM(dv->b_lights), KINT(nlights),        KMEM(dv->b_vis),
                KMEM(dv->b_emits), KMEM(dv->b_enew), KMEM(dv->b_src),    KMEM(dv->b_mask_src), KMEM(dv->b_dsum),
                KMEM(dv->b_extra), KINT(has_extra)};
    if ((st = run_kernel(dv, KE_EMIT, eitems, a, 12, d)) != PT_OK) return st;
    t1 = timer_now();
    cl_mem bin = dv->b_src, min = dv->b_mask_src;
    for (int b = 0; b < nbounce; b++) {
        if (cancelled(cancel)) return PT_OK;
        int obase = 0, sbase = 0, first = b == 0;
        int tbase = b * 3 * (int)items;
        int c0 = b == 0 && dv->cin_valid;
        cl_mem off = c0 ? dv->b_cin_off : dv->b_rin_off, from = c0 ? dv->b_cin_src : dv->b_rin_src;
        karg k[] = {KINT(n),         KMEM(off),           KINT(obase),         KMEM(from),          KINT(sbase),
                    KF(w_fan),       KMEM(bin),           KMEM(min),           KMEM(dv->b_rho),     KINT(first),
                    KMEM(dv->b_bout), KMEM(dv->b_mask_a), KMEM(dv->b_total),   KMEM(dv->b_tally),   KINT(tbase)};
        if ((st = run_kernel_local(dv, KE_BOUNCE, items, GI_BOUNCE_LOCAL, k, 15, d)) != PT_OK) return st;
        swap_cl_pairs(dv);
        if (dv->has_back && b + 1 < nbounce) {
            /* the back lobes' share of what this bounce sends on
             * (gi_k_back_send), into the free pair, then swapped in */
            karg bs[] = {KMEM(dv->b_part), KINT(n), KMEM(dv->b_rho), KMEM(dv->b_bin), KMEM(dv->b_bout),
                         KMEM(dv->b_mask_a)};
            if ((st = run_kernel(dv, KE_BACK_SEND, eitems, bs, 6, d)) != PT_OK) return st;
            swap_cl_pairs(dv);
        }
        bin = dv->b_bin;
        min = dv->b_mask_b;
    }
    if (cancelled(cancel)) return PT_OK;
    /* from here on the results are written: not cancelled any more */
    if (fused) {
        int nwalk = nb - 1, it = (int)items;
        karg w[] = {KMEM(dv->b_part), KINT(n),           KMEM(dv->b_enew), KMEM(dv->b_total), KMEM(min),
                    KMEM(dv->b_woff), KMEM(dv->b_went),  KINT(nwalk),      KMEM(dv->b_lout),  KMEM(dv->b_phi),
                    KMEM(dv->b_tally), KINT(it)};
        if ((st = run_kernel_local(dv, KE_WALK, items, GI_BOUNCE_LOCAL, w, 12, d)) != PT_OK) return st;
    } else {
        int scattered = nb > 0;
        karg r[] = {KMEM(dv->b_part), KINT(n),          KMEM(dv->b_enew), KINT(scattered), KMEM(dv->b_total),
                    KMEM(dv->b_lout), KMEM(dv->b_phi)};
        if ((st = run_kernel(dv, KE_RESOLVE, nn, r, 7, d)) != PT_OK) return st;
    }
    if (dv->has_back) {
        karg bk[] = {KMEM(dv->b_part), KINT(n), KMEM(dv->b_phi), KMEM(dv->b_lout)};
        if ((st = run_kernel(dv, KE_BACK, nn, bk, 4, d)) != PT_OK) return st;
    }
    cl_mem te = dv->b_edir;
    dv->b_edir = dv->b_enew;
    dv->b_enew = te;
    dv->edir_host = edir;
    dv->phi_host = phi;
    dv->stale = 1;
    /* edir and phi stay on the device until gi_dev_fetch (only stats and
     * tests read them); lout is the gather's input on the host too */
    st = read_buf(dv, dv->b_lout, lout, f4, CL_FALSE, d);
    if (st == PT_OK) st = read_buf(dv, dv->b_dsum, dv->dsum, eitems * sizeof(float), CL_FALSE, d);
    if (st == PT_OK) st = read_buf(dv, dv->b_mask_src, dv->srcmask_host, eitems * sizeof(unsigned), CL_FALSE, d);
    if (st == PT_OK && nb > 0)
        st = read_buf(dv, dv->b_tally, dv->tally, (size_t)nb * 3 * items * sizeof(float), CL_FALSE, d);
    if ((st = settle(dv, st, d)) != PT_OK) return st; /* one wait for the four reads */
    sum_bounces(dv->tally, items, nb, bounce_flux);
    fill_sums(dv, eitems, nb, bounce_flux, sums);
    *done = 1;
    if (times) {
        times[0] = t1 - t0;
        times[1] = timer_now() - t1;
    }
    return PT_OK;
#else
    return PT_ERR_INTERNAL;
#endif
}

pt_status gi_dev_fetch(gi_dev *dv, diag *d)
{
    if (!dv || !dv->stale) return PT_OK;
#ifdef PARTRAY_HAVE_OPENCL
    size_t f4 = (size_t)dv->n * 4 * sizeof(float);
    pt_status st = read_buf(dv, dv->b_edir, dv->edir_host, f4, CL_FALSE, d);
    if (st == PT_OK) st = read_buf(dv, dv->b_phi, dv->phi_host, f4, CL_FALSE, d);
    if ((st = settle(dv, st, d)) != PT_OK) return st;
#else
    (void)d;
#endif
    dv->stale = 0;
    return PT_OK;
}

pt_status gi_dev_gather(gi_dev *dv, const int *used, int nused, float *eind, diag *d)
{
    if (!dv->is_cl) {
        gi_c_gather(dv->threads, dv->glink, dv->ng, dv->lout_host, used, nused, dv->esky, eind);
        dv->eind_host = eind;
        return PT_OK;
    }
#ifdef PARTRAY_HAVE_OPENCL
    if (nused <= 0) return PT_OK;
    pt_status st;
    if ((st = upload(dv, &dv->b_list, &dv->sz_list, used, (size_t)nused * sizeof(int), d)) != PT_OK) return st;
    int ng = dv->ng;
    karg a[] = {KMEM(dv->b_glink), KINT(ng), KMEM(dv->b_lout), KMEM(dv->b_list), KINT(nused), KMEM(dv->b_esky),
                KMEM(dv->b_eind)};
    if ((st = run_kernel(dv, KE_GATHER, (size_t)nused, a, 7, d)) != PT_OK) return st;
    size_t nn = (size_t)dv->n;
    if ((st = download(dv, dv->b_eind, dv->tmp, nn * 4 * sizeof(float), d)) != PT_OK) return st;
    for (int t = 0; t < nused; t++) memcpy(&eind[4 * (size_t)used[t]], &dv->tmp[4 * (size_t)used[t]], 4 * sizeof(float));
    return PT_OK;
#else
    return PT_ERR_INTERNAL;
#endif
}

pt_status gi_dev_estimate(gi_dev *dv, const int *found, int nfound, float *vout, diag *d)
{
    if (!dv->is_cl) {
        gi_c_estimate(dv->threads, dv->part, dv->list_off, dv->list_idx, dv->eind_host, found, nfound, vout);
        return PT_OK;
    }
#ifdef PARTRAY_HAVE_OPENCL
    if (nfound <= 0) return PT_OK;
    pt_status st;
    if ((st = upload(dv, &dv->b_list, &dv->sz_list, found, (size_t)nfound * sizeof(int), d)) != PT_OK) return st;
    if ((st = ensure(dv, &dv->b_vout, &dv->sz_vout, (size_t)nfound * 4 * sizeof(float), d)) != PT_OK) return st;
    karg a[] = {KMEM(dv->b_part), KMEM(dv->b_off), KMEM(dv->b_idx), KMEM(dv->b_eind), KMEM(dv->b_list), KINT(nfound),
                KMEM(dv->b_vout)};
    if ((st = run_kernel(dv, KE_ESTIMATE, (size_t)nfound, a, 7, d)) != PT_OK) return st;
    return download(dv, dv->b_vout, vout, (size_t)nfound * 4 * sizeof(float), d);
#else
    return PT_ERR_INTERNAL;
#endif
}

pt_status gi_dev_vpl_gather(gi_dev *dv, const gi_dev_vpl_point *pts, int npts, const gi_dev_vpl_node *nodes, int nnodes,
                            const float *tabs, int ntabs, float thr, int mode, float *out, int *visits, diag *d)
{
    if (npts <= 0) return PT_OK;
    static const float no_tables[GI_VPL_TAB]; /* points without glossy lobes read none */
    if (!tabs || ntabs <= 0) {
        tabs = no_tables;
        ntabs = 1;
    }
    if (!dv->is_cl) {
        gi_c_vpl_gather(dv->threads, pts, npts, nodes, nnodes, tabs, thr, mode, out, visits);
        return PT_OK;
    }
#ifdef PARTRAY_HAVE_OPENCL
    pt_status st;
    size_t per = mode == GI_VPL_EYE ? 4 : 12;
    if ((st = upload(dv, &dv->b_vpts, &dv->sz_vpts, pts, (size_t)npts * sizeof *pts, d)) != PT_OK) return st;
    if ((st = upload(dv, &dv->b_vnodes, &dv->sz_vnodes, nodes, (size_t)(nnodes > 0 ? nnodes : 1) * sizeof *nodes, d)) !=
        PT_OK)
        return st;
    if ((st = upload(dv, &dv->b_vtabs, &dv->sz_vtabs, tabs, (size_t)(ntabs > 0 ? ntabs : 1) * GI_VPL_TAB * sizeof(float),
                     d)) != PT_OK)
        return st;
    if ((st = ensure(dv, &dv->b_vres, &dv->sz_vres, (size_t)npts * per * sizeof(float), d)) != PT_OK) return st;
    if ((st = ensure(dv, &dv->b_visits, &dv->sz_visits, (size_t)npts * sizeof(int), d)) != PT_OK) return st;
    karg a[] = {KMEM(dv->b_vpts), KINT(npts), KMEM(dv->b_vnodes), KINT(nnodes), KMEM(dv->b_vtabs), KF(thr), KINT(mode),
                KMEM(dv->b_vres), KMEM(dv->b_visits)};
    if ((st = run_kernel(dv, KE_VPL, (size_t)npts, a, 9, d)) != PT_OK) return st;
    if ((st = download(dv, dv->b_vres, out, (size_t)npts * per * sizeof(float), d)) != PT_OK) return st;
    return download(dv, dv->b_visits, visits, (size_t)npts * sizeof(int), d);
#else
    return PT_ERR_INTERNAL;
#endif
}

pt_status gi_dev_caustic_splat(gi_dev *dv, const gi_caus_photon *ph, int nph, const int *tile_off, int ntiles,
                               const int *tile_idx, const gi_caus_pixel *gbuf, int w, int h, int tiles_x, float *e,
                               diag *d)
{
    if (!dv->is_cl) {
        gi_c_caustic_splat(dv->threads, ph, tile_off, tile_idx, gbuf, w, h, tiles_x, e);
        return PT_OK;
    }
#ifdef PARTRAY_HAVE_OPENCL
    size_t npx = (size_t)w * (size_t)h;
    if (npx == 0) return PT_OK;
    pt_status st;
    size_t nidx = (size_t)tile_off[ntiles];
    if ((st = upload(dv, &dv->b_cph, &dv->sz_cph, ph, (size_t)nph * sizeof *ph, d)) != PT_OK) return st;
    if ((st = upload(dv, &dv->b_ctoff, &dv->sz_ctoff, tile_off, (size_t)(ntiles + 1) * sizeof(int), d)) != PT_OK)
        return st;
    if ((st = upload(dv, &dv->b_ctidx, &dv->sz_ctidx, tile_idx, nidx * sizeof(int), d)) != PT_OK) return st;
    if ((st = upload(dv, &dv->b_cpix, &dv->sz_cpix, gbuf, npx * sizeof *gbuf, d)) != PT_OK) return st;
    if ((st = ensure(dv, &dv->b_ce, &dv->sz_ce, npx * 4 * sizeof(float), d)) != PT_OK) return st;
    karg a[] = {KMEM(dv->b_cph), KMEM(dv->b_ctoff), KMEM(dv->b_ctidx), KMEM(dv->b_cpix), KINT(w), KINT(h),
                KINT(tiles_x), KMEM(dv->b_ce)};
    if ((st = run_kernel(dv, KE_CAUSTIC, npx, a, 8, d)) != PT_OK) return st;
    return download(dv, dv->b_ce, e, npx * 4 * sizeof(float), d);
#else
    (void)nph;
    (void)ntiles;
    return PT_ERR_INTERNAL;
#endif
}
