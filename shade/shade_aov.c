/* shade_aov.c - AOV pass: one camera ray per pixel centre, the quantities of
 * shade_aov.h at its first visible hit. Direct light and illuminance come
 * from shade.c's own direct-light loop (shade_direct), so they are exactly
 * the Whitted terms, area-light grids, spotlights and fade included. */
#include "shade_aov.h"
#include "hash.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "camera.h"
#include "pool.h"
#include "shade_light.h"
#include "shade_texture.h"

static const char *const aov_names[AOV_COUNT] = {"direct", "indirect", "albedo", "normal", "depth", "illuminance"};

const char *shade_aov_name(int k) { return k >= 0 && k < AOV_COUNT ? aov_names[k] : NULL; }
static int shade_aov_channels(int k) { return k == AOV_DEPTH ? 1 : 3; }
const char *shade_aov_suffixes(int k) { return k == AOV_DEPTH ? "Z" : (k == AOV_NORMAL ? "XYZ" : "RGB"); }
int shade_aov_is_colour(int k) { return k == AOV_DIRECT || k == AOV_INDIRECT || k == AOV_ALBEDO || k == AOV_ILLUMINANCE; }

pt_status shade_aov_parse(const char *list, unsigned *mask, diag *d)
{
    *mask = 0;
    if (!list || !*list) {
        diag_error(d, "--aovs wants a list such as direct,indirect,albedo,normal,depth,illuminance");
        return PT_ERR_USAGE;
    }
    const char *p = list;
    while (*p) {
        const char *e = strchr(p, ',');
        size_t n = e ? (size_t)(e - p) : strlen(p);
        int found = -1;
        if (n == 3 && strncmp(p, "all", 3) == 0) {
            *mask = (1u << AOV_COUNT) - 1u;
            found = AOV_COUNT;
        }
        for (int k = 0; k < AOV_COUNT && found < 0; k++)
            if (strlen(aov_names[k]) == n && strncmp(p, aov_names[k], n) == 0) found = k;
        if (found < 0) {
            diag_error(d, "--aovs: unknown AOV '%.*s' (direct, indirect, albedo, normal, depth, illuminance, all)",
                       (int)n, p);
            return PT_ERR_USAGE;
        }
        if (found < AOV_COUNT) *mask |= 1u << found;
        if (!e) break;
        p = e + 1;
    }
    if (!*mask) {
        diag_error(d, "--aovs: empty list");
        return PT_ERR_USAGE;
    }
    return PT_OK;
}

shade_aov *shade_aov_new(int width, int height, unsigned mask)
{
    if (width <= 0 || height <= 0) return NULL;
    shade_aov *a = calloc(1, sizeof *a);
    if (!a) return NULL;
    a->width = width;
    a->height = height;
    a->mask = mask & ((1u << AOV_COUNT) - 1u);
    for (int k = 0; k < AOV_COUNT; k++) {
        if (!(a->mask & (1u << k))) continue;
        a->buf[k] = calloc((size_t)width * (size_t)height * (size_t)shade_aov_channels(k), sizeof(float));
        if (!a->buf[k]) {
            shade_aov_free(a);
            return NULL;
        }
    }
    return a;
}

void shade_aov_free(shade_aov *a)
{
    if (!a) return;
    for (int k = 0; k < AOV_COUNT; k++) free(a->buf[k]);
    free(a);
}

typedef struct {
    const scene *sc;
    const accel *a;
    const shade_settings *s;
    shade_aov *out;
    double eps;
    scene_finish white; /* diffuse 1, brilliance 1, nothing else: the illuminance probe */
} aov_ctx;

static void put3(shade_aov *o, int k, size_t i, double x, double y, double z)
{
    float *p = o->buf[k];
    if (!p) return;
    p[i * 3] = (float)x;
    p[i * 3 + 1] = (float)y;
    p[i * 3 + 2] = (float)z;
}

static void put_rgb(shade_aov *o, int k, size_t i, rgb c) { put3(o, k, i, c.r, c.g, c.b); }

static void aov_pixel(aov_ctx *c, int x, int y, int thread)
{
    shade_aov *o = c->out;
    const scene *sc = c->sc;
    size_t i = (size_t)y * (size_t)o->width + (size_t)x;
    vec3 org, dir;
    if (!camera_ray(&sc->camera, x + 0.5, y + 0.5, o->width, o->height, 0.0, 0.0, &org, &dir)) return;
    accel_hit h;
    if (accel_intersect_past(c->a, NULL, org, dir, c->eps, OBJ_NO_IMAGE, &h, NULL) <= 0) return;

    rng r;
    rng_seed(&r, pt_mix64(c->s->seed * 0x9e3779b97f4a7c15ULL + 0x616f76ULL), ((uint64_t)y << 32) | (uint64_t)x);
    vec3 n = h.ns, ng = h.ng;
    if (v3_dot(dir, n) > 0.0) n = v3_neg(n);
    if (v3_dot(dir, ng) > 0.0) ng = v3_neg(ng);
    vec3 p_out = v3_madd(h.p, ng, c->eps);
    const scene_texture *tex = h.texture ? h.texture : &sc->default_texture;
    const scene_finish *f = &tex->finish;
    colour5 pc = {0, 0, 0, 0, 0};
    if (!shade_tex_pigment_at(sc, NULL, &h, &pc)) memset(&pc, 0, sizeof pc);
    rgb pig = {pc.r, pc.g, pc.b};
    double att = 1.0 - pc.f - pc.t;

    if (o->buf[AOV_DEPTH]) o->buf[AOV_DEPTH][i] = (float)h.t;
    put3(o, AOV_NORMAL, i, n.x, n.y, n.z);
    put3(o, AOV_ALBEDO, i, pig.r * f->diffuse, pig.g * f->diffuse, pig.b * f->diffuse);
    if (o->buf[AOV_DIRECT] && (f->diffuse != 0.0 || f->diffuse_back != 0.0 || f->specular != 0.0 || f->phong != 0.0)) {
        shade_light_surface ls = {f, pig, n, dir, att, &r};
        put_rgb(o, AOV_DIRECT, i, shade_direct(sc, c->a, &ls, &h, p_out, &r));
    }
    if (o->buf[AOV_INDIRECT] && c->s->indirect && f->diffuse > 0.0) {
        rgb e = c->s->indirect(c->s->indirect_ctx, &h, n, thread);
        double k = f->diffuse * att;
        put3(o, AOV_INDIRECT, i, pig.r * e.r * k, pig.g * e.g * k, pig.b * e.b * k);
    }
    if (o->buf[AOV_ILLUMINANCE]) {
        rgb white = {1, 1, 1};
        shade_light_surface ls = {&c->white, white, n, dir, 1.0, &r};
        rgb e = shade_direct(sc, c->a, &ls, &h, p_out, &r);
        put3(o, AOV_ILLUMINANCE, i, M_PI * e.r, M_PI * e.g, M_PI * e.b);
    }
}

static void aov_row(void *ctx, int y, int thread)
{
    aov_ctx *c = ctx;
    if (c->s->cancel && *c->s->cancel) return;
    for (int x = 0; x < c->out->width; x++) aov_pixel(c, x, y, thread);
}

pt_status shade_aov_render(const scene *sc, const accel *a, const shade_settings *s, shade_aov *out, diag *d)
{
    if (!sc || !a || !s || !out || out->width != s->width || out->height != s->height) {
        diag_error(d, "shade_aov_render: bad arguments");
        return PT_ERR_INTERNAL;
    }
    aov_ctx c = {.sc = sc, .a = a, .s = s, .out = out};
    /* shade.c's distance epsilon: a fixed fraction of the scene's extent */
    double scale = accel_scale(a);
    if (!(scale > 0.0) || !isfinite(scale)) scale = 1.0;
    c.eps = scale * 1e-6;
    scene_default_finish(&c.white);
    c.white.diffuse = 1.0;
    c.white.diffuse_back = 0.0;
    c.white.brilliance = 1.0;
    c.white.crand = 0.0;
    c.white.phong = 0.0;
    c.white.specular = 0.0;
    c.white.metallic = 0.0;
    int threads = s->threads > 0 ? s->threads : pool_default_threads();
    if (threads > 256) threads = 256;
    pool_run(threads, out->height, aov_row, &c);
    return PT_OK;
}

typedef struct {
    const scene *sc;
    const accel *a;
    const shade_settings *s;
    float *alpha;
    double eps, miss; /* opacity of a ray that leaves the scene */
    int n;
} alpha_ctx;

static int alpha_hit(const alpha_ctx *c, double px, double py)
{
    vec3 org, dir;
    if (!camera_ray(&c->sc->camera, px, py, c->s->width, c->s->height, 0.0, 0.0, &org, &dir)) return 0;
    accel_hit h;
    return accel_intersect_past(c->a, NULL, org, dir, c->eps, OBJ_NO_IMAGE, &h, NULL) > 0;
}

static void alpha_row(void *ctx, int y, int thread)
{
    (void)thread;
    alpha_ctx *c = ctx;
    if (c->s->cancel && *c->s->cancel) return;
    for (int x = 0; x < c->s->width; x++) {
        double sum = 0.0;
        for (int j = 0; j < c->n; j++)
            for (int i = 0; i < c->n; i++)
                sum += alpha_hit(c, x + (i + 0.5) / c->n, y + (j + 0.5) / c->n) ? 1.0 : c->miss;
        c->alpha[(size_t)y * (size_t)c->s->width + (size_t)x] = (float)(sum / (c->n * c->n));
    }
}

void shade_alpha(const scene *sc, const accel *a, const shade_settings *s, float *alpha)
{
    alpha_ctx c = {sc, a, s, alpha, 1e-6, 0.0, s->antialias ? 3 : 1};
    double scale = accel_scale(a);
    if (scale > 0.0 && isfinite(scale)) c.eps = scale * 1e-6;
    int v37 = sc->version_major > 3 || (sc->version_major == 3 && sc->version_minor >= 7);
    if (sc->sky_sphere) c.miss = 1.0;
    else if (v37) c.miss = fmin(1.0, fmax(0.0, 1.0 - sc->background.t));
    int threads = s->threads > 0 ? s->threads : pool_default_threads();
    pool_run(threads, s->height, alpha_row, &c);
}
