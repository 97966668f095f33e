/* pm.c - the image loop shared by the reference renderers (see pm.h). */
#include "pm.h"
#include "hash.h"
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include "pool.h"
#include "timer.h"

#define TILE 16
#define MAX_THREADS 256

void pm_common_defaults(pm_common *c)
{
    *c = (pm_common){.width = 320, .height = 240, .spp = 1, .jitter = 1, .image_interval = 10.0};
}

uint64_t pm_mix64(uint64_t z) { return pt_mix64(z + 0x9e3779b97f4a7c15ULL); }

int pm_gathers(const radrules *rr) { return rr->recursion_limit > 0 ? rr->recursion_limit : 1 << 20; }

int pm_threads(int requested)
{
    int t = requested > 0 ? requested : pool_default_threads();
    return t > MAX_THREADS ? MAX_THREADS : (t < 1 ? 1 : t);
}

/* Sum of counters into st. */
static void pm_counts_add(pm_stats *st, const pm_counts *cnt, int n)
{
    for (int i = 0; i < n; i++) {
        st->camera_rays += cnt[i].camera;
        st->bsdf_rays += cnt[i].bsdf;
        st->gather_rays += cnt[i].gather;
        st->shadow_rays += cnt[i].shadow;
        st->gather_points += cnt[i].gather_points;
        st->discarded_samples += cnt[i].discarded;
        st->unsupported += cnt[i].unsupported;
        st->samples += cnt[i].samples;
    }
}

/* Sobol' (0,2)-sequence in base 2: first dimension the van der Corput
 * sequence (bit reversal), second the generator v_k = v_{k-1} ^ (v_{k-1} >> 1).
 * Every aligned block of 2^m points is stratified in all elementary
 * intervals of area 2^-m; random XOR scrambling per pixel keeps that. */
static uint32_t sobol_dim0(uint32_t i)
{
    i = (i << 16) | (i >> 16);
    i = ((i & 0x00ff00ffu) << 8) | ((i & 0xff00ff00u) >> 8);
    i = ((i & 0x0f0f0f0fu) << 4) | ((i & 0xf0f0f0f0u) >> 4);
    i = ((i & 0x33333333u) << 2) | ((i & 0xccccccccu) >> 2);
    i = ((i & 0x55555555u) << 1) | ((i & 0xaaaaaaaau) >> 1);
    return i;
}

static uint32_t sobol_dim1(uint32_t i)
{
    uint32_t v = 1u << 31, r = 0;
    for (; i; i >>= 1, v ^= v >> 1)
        if (i & 1u) r ^= v;
    return r;
}

typedef struct {
    const scene *sc;
    const pm_common *c;
    pm_sample_fn fn;
    void *ctx;
    pm_counts *cnt;
    double *acc;             /* w*h*3 sums */
    int s0, s1;              /* samples of this pass */
    int tiles_x, tiles_y;
    int *tile_spp;           /* samples per pixel finished, per tile */
    atomic_long done;        /* pixel samples finished (all passes) */
    long total;
    pthread_mutex_t mu;
    double last_progress;
} loop_ctx;

static void tile_job(void *p, int tile, int thread)
{
    loop_ctx *L = p;
    const pm_common *c = L->c;
    if (c->cancel && *c->cancel) return;
    int tx = tile % L->tiles_x, ty = tile / L->tiles_x;
    int x0 = tx * TILE, y0 = ty * TILE;
    int x1 = x0 + TILE < c->width ? x0 + TILE : c->width;
    int y1 = y0 + TILE < c->height ? y0 + TILE : c->height;
    pm_counts *cnt = &L->cnt[thread];
    for (int y = y0; y < y1; y++) {
        for (int x = x0; x < x1; x++) {
            uint64_t pix = (uint64_t)y * (uint64_t)c->width + (uint64_t)x;
            uint64_t h = pm_mix64(c->seed ^ pm_mix64(pix + 0x51ed270b27e1d6b5ULL));
            uint32_t scr0 = (uint32_t)h, scr1 = (uint32_t)(h >> 32);
            double *a = L->acc + pix * 3;
            for (int s = L->s0; s < L->s1; s++) {
                double jx = 0.5, jy = 0.5;
                if (c->jitter) {
                    jx = (double)(sobol_dim0((uint32_t)s) ^ scr0) * 0x1p-32;
                    jy = (double)(sobol_dim1((uint32_t)s) ^ scr1) * 0x1p-32;
                }
                rng r;
                rng_seed(&r, pm_mix64(c->seed * 0x2545f4914f6cdd1dULL + (uint64_t)s), pix);
                rgb v = L->fn(L->ctx, x + jx, y + jy, thread, &r, cnt);
                cnt->samples++;
                if (!isfinite(v.r) || !isfinite(v.g) || !isfinite(v.b)) {
                    cnt->discarded++;
                    continue;
                }
                a[0] += v.r;
                a[1] += v.g;
                a[2] += v.b;
            }
        }
    }
    L->tile_spp[tile] = L->s1;
    long done = atomic_fetch_add(&L->done, (long)(x1 - x0) * (y1 - y0) * (L->s1 - L->s0)) +
                (long)(x1 - x0) * (y1 - y0) * (L->s1 - L->s0);
    progress_add(c->progress, (long long)(x1 - x0) * (y1 - y0) * (L->s1 - L->s0));
    if (c->on_progress) {
        double now = timer_now();
        if (now - L->last_progress >= 0.1 && pthread_mutex_trylock(&L->mu) == 0) {
            L->last_progress = now;
            c->on_progress(c->progress_ctx, L->total > 0 ? (double)done / (double)L->total : 1.0);
            pthread_mutex_unlock(&L->mu);
        }
    }
}

static void normalise(const loop_ctx *L, framebuffer *fb)
{
    for (int y = 0; y < fb->height; y++) {
        for (int x = 0; x < fb->width; x++) {
            int n = L->tile_spp[(y / TILE) * L->tiles_x + x / TILE];
            double inv = n > 0 ? 1.0 / n : 0.0;
            size_t i = ((size_t)y * (size_t)fb->width + (size_t)x) * 3;
            for (int k = 0; k < 3; k++) fb->rgb[i + k] = (float)(L->acc[i + k] * inv);
        }
    }
}

pt_status pm_image_render(const scene *sc, const pm_common *c, int max_pass, framebuffer *fb, pm_sample_fn fn,
                          void *ctx, pm_stats *st)
{
    if (!sc || !c || !fb || fb->width != c->width || fb->height != c->height || c->width <= 0 || c->height <= 0)
        return PT_ERR_INTERNAL;
    int threads = pm_threads(c->threads);
    int spp = c->spp > 0 ? c->spp : 1;
    if (max_pass < 1) max_pass = 1;
    loop_ctx L = {.sc = sc, .c = c, .fn = fn, .ctx = ctx, .cnt = calloc((size_t)threads, sizeof(pm_counts)),
                  .acc = calloc((size_t)c->width * (size_t)c->height * 3, sizeof(double)),
                  .tiles_x = (c->width + TILE - 1) / TILE, .tiles_y = (c->height + TILE - 1) / TILE};
    L.tile_spp = calloc((size_t)L.tiles_x * (size_t)L.tiles_y, sizeof(int));
    if (!L.cnt || !L.acc || !L.tile_spp) {
        free(L.cnt);
        free(L.acc);
        free(L.tile_spp);
        return PT_ERR_NOMEM;
    }
    pthread_mutex_init(&L.mu, NULL);
    L.total = (long)c->width * c->height * spp;
    atomic_init(&L.done, 0);
    progress_stage(c->progress, "render", L.total);
    double last_image = timer_now();
    int passes = 0, pass = 1, s = 0;
    while (s < spp) {
        if (c->cancel && *c->cancel) break;
        int n = pass < spp - s ? pass : spp - s;
        L.s0 = s;
        L.s1 = s + n;
        pool_run(threads, L.tiles_x * L.tiles_y, tile_job, &L);
        passes++;
        s += n;
        if (passes >= 2 && pass < max_pass) pass = pass * 2 < max_pass ? pass * 2 : max_pass;
        if (c->on_image && s < spp && !(c->cancel && *c->cancel)) {
            double now = timer_now();
            if (now - last_image >= (c->image_interval > 0.0 ? c->image_interval : 10.0)) {
                normalise(&L, fb);
                c->on_image(c->image_ctx, fb, s, spp);
                last_image = now;
            }
        }
    }
    /* after a cancel, tiles differ in their sample counts: each is
     * normalised by its own */
    normalise(&L, fb);
    if (c->on_progress) c->on_progress(c->progress_ctx, 1.0);
    pm_counts_add(st, L.cnt, threads);
    st->passes += passes;
    st->spp = spp;
    st->threads = threads;
    long fixed = fb_sanitize(fb);
    st->discarded_samples += fixed;
    pthread_mutex_destroy(&L.mu);
    free(L.cnt);
    free(L.acc);
    free(L.tile_spp);
    return PT_OK;
}
