/* gi_particle_cache.c - the geometry stage's result in a file, and the
 * geometry stage taken from one (gi_particle_save, gi_particle_load;
 * gi_particle.h). In spirit POV-Ray's radiosity save_file/load_file: a
 * render in another process (a tile or a frame on another machine) skips
 * the particles, links and lists and runs only the lighting and view
 * stages, with the same bits, so its image is the image of the process
 * that saved the file.
 *
 * What is stored is what gi_particle_build computes between
 * gi_particle_begin and gi_particle_finish (gi_particle_internal.h): the
 * area particles (records, patch, side, spacing), the scattering and
 * gathering links, the sky's share of each gather, the estimation lists,
 * and the geometry stage's counts. The surfaces are built again from the
 * scene (deterministic, and they hold pointers into it); the number of
 * radiance particles they give must equal the stored lists'.
 *
 * Layout (native byte order, refused elsewhere by the byte-order mark):
 *   magic "partray GI cache\n" (17 bytes), u32 version, u32 0x01020304,
 *   u32 sizeof(gi_dev_particle), u64 scene key (the caller's),
 *   the geometry settings (cache_settings), the counts (cache_counts),
 *   the arrays in the order of cache_arrays, then u64 FNV-1a 64 of every
 *   byte before it. A file is written under a temporary name beside the
 *   target and renamed (rename(2) is atomic on one filesystem), so two
 *   processes saving the same cache at once leave one whole file. */
#include "gi_particle_internal.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "fileio.h"
#include "hash.h"
#include "timer.h"

static const char cache_magic[17] = "partray GI cache\n";
#define CACHE_BOM 0x01020304u

/* The settings the geometry stage reads: a cache serves only a render that
 * asks for the same ones (the lighting and view settings may differ). */
typedef struct {
    int64_t count;
    int32_t scatter_side, gather_side, bounces, scatter;
    double tess, tess_factor, radius, radius_factor, normal_cos, brightness;
    uint64_t seed;
    int32_t no_rp;      /* made without radiance particles (the final gather's runs) */
    int32_t final_only; /* made without particles at all (gi_particle_final_only) */
} cache_settings;

typedef struct {
    int32_t n, ns2, ng, pad;
    int64_t nrp, entries;
    double dA, spacing, tess, radius;
    int64_t probed_out, candidates, pruned;
    int64_t link_rays, link_misses, link_unresolved, link_tri, link_tri_fallback;
    int64_t trilook_lists, trilook_entries, bytes_trilook;
    int64_t widened, empty, dead, vis_rays;
} cache_counts;

static cache_settings settings_of(const gi_particle_settings *s)
{
    cache_settings c;
    memset(&c, 0, sizeof c); /* padding hashed and compared as bytes */
    c.count = s->count;
    c.scatter_side = s->scatter_side;
    c.gather_side = s->gather_side;
    c.bounces = s->bounces;
    c.scatter = s->scatter;
    c.tess = s->tess;
    c.tess_factor = s->tess_factor;
    c.radius = s->radius;
    c.radius_factor = s->radius_factor;
    c.normal_cos = s->normal_cos;
    c.brightness = s->brightness;
    c.seed = s->seed;
    c.no_rp = s->view_gather_side > 0 && s->keep_hits;
    c.final_only = gi_particle_final_only(s);
    return c;
}

/* The arrays: pointer and byte size of each, in file order. */
typedef struct {
    void **ptr;
    size_t bytes;
} cache_array;

static int cache_arrays(gi_particle *gp, const cache_counts *k, cache_array out[6])
{
    size_t n = (size_t)k->n;
    out[0] = (cache_array){(void **)&gp->ps.p, n * sizeof(gi_dev_particle)};
    out[1] = (cache_array){(void **)&gp->ps.patch, n * sizeof(int)};
    out[2] = (cache_array){(void **)&gp->ps.side, n};
    out[3] = (cache_array){(void **)&gp->slink, n * (size_t)k->ns2 * sizeof(int)};
    out[4] = (cache_array){(void **)&gp->glink, n * (size_t)k->ng * sizeof(int)};
    out[5] = (cache_array){(void **)&gp->esky, n * 4 * sizeof(float)};
    return 6;
}

typedef struct {
    FILE *f;
    uint64_t h;
    int bad;
} writer;

static void put(writer *w, const void *p, size_t n)
{
    if (w->bad || n == 0) return;
    w->h = pt_fnv1a(w->h, p, n);
    if (fwrite(p, 1, n, w->f) != n) w->bad = 1;
}

pt_status gi_particle_save(gi_particle *gp, const char *path, uint64_t scene_key, diag *d)
{
    size_t plen = strlen(path);
    char *tmp = malloc(plen + 32);
    if (!tmp) return PT_ERR_NOMEM;
    snprintf(tmp, plen + 32, "%s.%ld.tmp", path, (long)getpid());
    writer w = {fopen(tmp, "wb"), PT_FNV1A_BASIS, 0};
    if (!w.f) {
        diag_error(d, "%s: cannot write the GI cache", tmp);
        free(tmp);
        return PT_ERR_IO;
    }
    const gi_particle_stats *S = &gp->st;
    cache_counts k;
    memset(&k, 0, sizeof k);
    k.n = gp->ps.n;
    k.ns2 = gp->ns2;
    k.ng = gp->ng;
    k.nrp = gp->lists.nrp;
    k.entries = gp->lists.off[gp->lists.nrp];
    k.dA = gp->ps.dA;
    k.spacing = gp->ps.spacing;
    k.tess = S->tess;
    k.radius = S->radius;
    k.probed_out = gp->ps.probed_out;
    k.candidates = S->candidates;
    k.pruned = S->pruned;
    k.link_rays = S->link_rays;
    k.link_misses = S->link_misses;
    k.link_unresolved = S->link_unresolved;
    k.link_tri = S->link_tri;
    k.link_tri_fallback = S->link_tri_fallback;
    k.trilook_lists = S->trilook_lists;
    k.trilook_entries = S->trilook_entries;
    k.bytes_trilook = (int64_t)S->bytes_trilook;
    k.widened = gp->lists.widened;
    k.empty = gp->lists.empty;
    k.dead = gp->lists.dead;
    k.vis_rays = gp->lists.vis_rays;
    uint32_t head[3] = {GI_PARTICLE_CACHE_VERSION, CACHE_BOM, (uint32_t)sizeof(gi_dev_particle)};
    cache_settings cs = settings_of(&gp->set);
    put(&w, cache_magic, sizeof cache_magic);
    put(&w, head, sizeof head);
    put(&w, &scene_key, sizeof scene_key);
    put(&w, &cs, sizeof cs);
    put(&w, &k, sizeof k);
    cache_array arr[6];
    int na = cache_arrays(gp, &k, arr);
    for (int i = 0; i < na; i++) put(&w, *arr[i].ptr, arr[i].bytes);
    put(&w, gp->lists.off, ((size_t)k.nrp + 1) * sizeof(int));
    put(&w, gp->lists.idx, (size_t)k.entries * sizeof(int));
    uint64_t sum = w.h;
    if (!w.bad && fwrite(&sum, sizeof sum, 1, w.f) != 1) w.bad = 1;
    if (fclose(w.f) != 0) w.bad = 1;
    pt_status st = PT_OK;
    if (w.bad || rename(tmp, path) != 0) {
        diag_error(d, "%s: cannot write the GI cache", path);
        remove(tmp);
        st = PT_ERR_IO;
    }
    free(tmp);
    return st;
}

/* The file's bytes, read in order; every read is bounds-checked. */
typedef struct {
    const unsigned char *b;
    size_t n, at;
} reader;

static int take(reader *r, void *out, size_t n)
{
    if (n > r->n - r->at) return 0;
    memcpy(out, r->b + r->at, n);
    r->at += n;
    return 1;
}

/* The first setting that differs, named for the message; NULL: none. */
static const char *settings_differ(const cache_settings *a, const cache_settings *b)
{
    if (a->count != b->count) return "particle count";
    if (a->scatter_side != b->scatter_side) return "scattering links";
    if (a->gather_side != b->gather_side) return "gathering links";
    if (a->bounces != b->bounces) return "bounces";
    if (a->scatter != b->scatter) return "scattering mode";
    if (a->seed != b->seed) return "seed";
    if (a->no_rp != b->no_rp) return "final gather (radiance particles)";
    if (a->final_only != b->final_only) return "final gather (no particles)";
    if (memcmp(a, b, sizeof *a) != 0) return "tessellation, list radius, normal threshold or brightness";
    return NULL;
}

gi_particle *gi_particle_load(const scene *sc, const accel *a, const gi_particle_settings *s, const char *path,
                              uint64_t scene_key, gi_particle_stats *stats, diag *d, pt_status *status)
{
    pt_status dummy;
    if (!status) status = &dummy;
    *status = PT_OK;
    src_loc at = {diag_intern(d, path), 0, 0};
    double t0 = timer_now(), c0 = timer_cpu_now();
    size_t len = 0;
    unsigned char *bytes = (unsigned char *)pt_read_file(path, 1, (size_t)-1, &len);
    if (!bytes) {
        diag_error(d, "%s: cannot read the GI cache", path);
        *status = PT_ERR_IO;
        return NULL;
    }
    reader r = {bytes, len, 0};
    char magic[sizeof cache_magic];
    uint32_t head[3];
    uint64_t key = 0, sum = 0;
    cache_settings cs;
    cache_counts k;
    const char *why = NULL;
    if (!take(&r, magic, sizeof magic) || memcmp(magic, cache_magic, sizeof magic) != 0) why = "not a partray GI cache";
    else if (!take(&r, head, sizeof head)) why = "truncated header";
    else if (head[1] != CACHE_BOM) why = "written on a machine of another byte order";
    else if (head[0] != GI_PARTICLE_CACHE_VERSION) {
        diag_report(d, DIAG_ERROR, at, NULL, "GI cache format version %u; this partray reads version %d (delete it to make a new one)",
                    head[0], GI_PARTICLE_CACHE_VERSION);
        why = "";
    } else if (head[2] != sizeof(gi_dev_particle)) why = "particle records of another size";
    else if (len < r.at + sizeof sum) why = "truncated";
    else {
        memcpy(&sum, bytes + len - sizeof sum, sizeof sum);
        if (pt_fnv1a(PT_FNV1A_BASIS, bytes, len - sizeof sum) != sum) why = "corrupt (checksum mismatch: truncated or altered)";
        r.n = len - sizeof sum;
    }
    if (!why && (!take(&r, &key, sizeof key) || !take(&r, &cs, sizeof cs) || !take(&r, &k, sizeof k)))
        why = "truncated header";
    gi_particle *gp = NULL;
    if (!why && key != scene_key) {
        diag_report(d, DIAG_ERROR, at, NULL,
                    "GI cache made for another scene (scene key %016llx, this render's %016llx: the scene's files, "
                    "declarations, camera, size or frame differ); delete it or name another file",
                    (unsigned long long)key, (unsigned long long)scene_key);
        why = "";
    }
    if (!why) {
        gp = gi_particle_begin(sc, a, s, d, status);
        if (!gp) {
            free(bytes);
            return NULL;
        }
        cache_settings want = settings_of(&gp->set);
        const char *what = settings_differ(&cs, &want);
        if (what) {
            diag_report(d, DIAG_ERROR, at, NULL, "GI cache made with another %s than this render asks for", what);
            why = "";
        } else if (k.n < 0 || k.nrp < 0 || k.entries < 0 || k.ns2 != gp->ns2 || k.ng != gp->ng || k.entries > INT32_MAX ||
                   k.nrp > INT32_MAX) {
            why = "inconsistent counts";
        } else {
            /* the arrays' sizes from the counts must be what is left of the
             * file (nothing is allocated from counts the file cannot hold) */
            uint64_t n = (uint64_t)k.n, per = sizeof(gi_dev_particle) + sizeof(int) + 1 +
                                                   ((uint64_t)k.ns2 + (uint64_t)k.ng + 4) * sizeof(int);
            uint64_t want = n * per + ((uint64_t)k.nrp + 1 + (uint64_t)k.entries) * sizeof(int);
            if (want != (uint64_t)(r.n - r.at)) why = "arrays of the wrong size";
        }
    }
    if (!why) {
        gi_particle_stats *S = &gp->st;
        gp->ps.n = k.n;
        gp->ps.dA = k.dA;
        gp->ps.spacing = k.spacing;
        gp->ps.probed_out = k.probed_out;
        cache_array arr[6];
        int na = cache_arrays(gp, &k, arr);
        for (int i = 0; i < na && !why; i++) {
            *arr[i].ptr = malloc(arr[i].bytes ? arr[i].bytes : 1);
            if (!*arr[i].ptr) {
                *status = PT_ERR_NOMEM;
                why = "";
            } else if (!take(&r, *arr[i].ptr, arr[i].bytes)) {
                why = "truncated arrays";
            }
        }
        gp->lists.nrp = k.nrp;
        gp->lists.off = why ? NULL : malloc(((size_t)k.nrp + 1) * sizeof(int));
        gp->lists.idx = why ? NULL : malloc((size_t)(k.entries ? k.entries : 1) * sizeof(int));
        if (!why && (!gp->lists.off || !gp->lists.idx)) {
            *status = PT_ERR_NOMEM;
            why = "";
        }
        if (!why && (!take(&r, gp->lists.off, ((size_t)k.nrp + 1) * sizeof(int)) ||
                     !take(&r, gp->lists.idx, (size_t)k.entries * sizeof(int)) || r.at != r.n))
            why = "arrays of the wrong size";
        /* every index in range: the kernels and the hook trust them */
        for (long i = 0; !why && i < (long)k.n * k.ns2; i++)
            if (gp->slink[i] < -1 || gp->slink[i] >= k.n) why = "scattering link out of range";
        for (long i = 0; !why && i < (long)k.n * k.ng; i++)
            if (gp->glink[i] < -1 || gp->glink[i] >= k.n) why = "gathering link out of range";
        for (int i = 0; !why && i < k.n; i++)
            if (gp->ps.patch[i] < 0 || gp->ps.patch[i] >= gi_surface_npatches(gp->surf) || gp->ps.side[i] > 1)
                why = "particle on a patch this scene does not have";
        for (long i = 0; !why && i < k.nrp; i++)
            if (gp->lists.off[i] < 0 || gp->lists.off[i] > gp->lists.off[i + 1]) why = "estimation lists out of order";
        if (!why && (gp->lists.off[0] != 0 || gp->lists.off[k.nrp] != k.entries)) why = "estimation lists out of order";
        for (long i = 0; !why && i < k.entries; i++)
            if (gp->lists.idx[i] < 0 || gp->lists.idx[i] >= k.n) why = "estimation list entry out of range";
        if (!why) {
            gp->lists.widened = k.widened;
            gp->lists.empty = k.empty;
            gp->lists.dead = k.dead;
            gp->lists.vis_rays = k.vis_rays;
            gp->no_rp = gp->set.view_gather_side > 0 && gp->set.keep_hits; /* as the key's settings say */
            S->candidates = k.candidates;
            S->probed_out = k.probed_out;
            S->pruned = k.pruned;
            S->particles = k.n;
            S->spacing = k.spacing;
            S->tess = k.tess;
            S->radius = k.radius;
            S->link_rays = k.link_rays;
            S->link_misses = k.link_misses;
            S->link_unresolved = k.link_unresolved;
            S->link_tri = k.link_tri;
            S->link_tri_fallback = k.link_tri_fallback;
            S->trilook_lists = k.trilook_lists;
            S->trilook_entries = k.trilook_entries;
            S->bytes_trilook = (size_t)k.bytes_trilook;
            S->radiance_particles = k.nrp;
            S->list_entries = k.entries;
            S->lists_widened = k.widened;
            S->lists_empty = k.empty;
            /* the radiance particles' layout (a cache made for the final
             * gather has none: cs.no_rp, compared above, and needs none) */
            if (!cs.no_rp) {
                gi_surface_retess(gp->surf, S->tess);
                if (gi_surface_nrp(gp->surf) != k.nrp) why = "radiance particles do not match this scene's surfaces";
            }
        }
    }
    free(bytes);
    if (why) {
        if (*why) diag_report(d, DIAG_ERROR, at, NULL, "%s", why);
        if (*status == PT_OK) *status = PT_ERR_SYNTAX; /* bad input: exit 1 */
        gi_particle_free(gp);
        return NULL;
    }
    pt_status st = gi_particle_finish(gp, d);
    if (st != PT_OK) {
        *status = st;
        gi_particle_free(gp);
        return NULL;
    }
    gp->st.t_geometry = timer_now() - t0 - gp->st.t_kernel_build;
    gp->st.c_geometry = timer_cpu_now() - c0;
    gi_particle_fill_stats(gp, stats);
    *status = PT_OK;
    return gp;
}
