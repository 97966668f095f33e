/* bench_rays.c - ray throughput of the renderer's path (accel_intersect +
 * accel_occluded) against a bare Embree loop (rtcIntersect1/rtcOccluded1 on
 * the same RTCScene) for the same rays: W x H primary rays from the camera of
 * POV-Ray's radiosity/cornell.pov and one shadow ray per hit towards a point
 * light. Single thread and N threads; several repetitions, median. Prints
 * figures; not a test.
 *
 * The scene is built in code (independent of the parser): the 30 triangles of
 * scenes/radiosity/cornell.pov from POV-Ray 3.7's sample scenes, its light
 * patch box (no_shadow), its camera, and a point light at <27.8,54,27.95>.
 * --triangles N adds a tessellated sphere mesh of about N triangles;
 * --copies K places K instances of it (K > 1 makes them Embree instances). */
#include <embree3/rtcore.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "accel.h"
#include "bench_util.h"
#include "pipeline.h"
#include "pool.h"
#include "scene.h"
#include "timer.h"

typedef struct {
    int w, h, threads, reps, triangles, copies;
} options;

static const double cornell_tris[30][9] = {
    /* floor */
    {55.28, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 55.92},
    {55.28, 0.0, 0.0, 0.0, 0.0, 55.92, 54.96, 0.0, 55.92},
    /* ceiling */
    {55.60, 54.88, 0.0, 55.60, 54.88, 55.92, 0.0, 54.88, 55.92},
    {55.60, 54.88, 0.0, 0.0, 54.88, 55.92, 0.0, 54.88, 0.0},
    /* back wall */
    {0.0, 54.88, 55.92, 55.60, 54.88, 55.92, 54.96, 0.0, 55.92},
    {0.0, 54.88, 55.92, 54.96, 0.0, 55.92, 0.0, 0.0, 55.92},
    /* right wall (green) */
    {0.0, 54.88, 0.0, 0.0, 54.88, 55.92, 0.0, 0.0, 55.92},
    {0.0, 54.88, 0.0, 0.0, 0.0, 55.92, 0.0, 0.0, 0.0},
    /* left wall (red) */
    {55.28, 0.0, 0.0, 54.96, 0.0, 55.92, 55.60, 54.88, 55.92},
    {55.28, 0.0, 0.0, 55.60, 54.88, 55.92, 55.60, 54.88, 0.0},
    /* short block */
    {13.00, 16.50, 6.50, 8.20, 16.50, 22.50, 24.00, 16.50, 27.20},
    {13.00, 16.50, 6.50, 24.00, 16.50, 27.20, 29.00, 16.50, 11.40},
    {29.00, 0.0, 11.40, 29.00, 16.50, 11.40, 24.00, 16.50, 27.20},
    {29.00, 0.0, 11.40, 24.00, 16.50, 27.20, 24.00, 0.0, 27.20},
    {13.00, 0.0, 6.50, 13.00, 16.50, 6.50, 29.00, 16.50, 11.40},
    {13.00, 0.0, 6.50, 29.00, 16.50, 11.40, 29.00, 0.0, 11.40},
    {8.20, 0.0, 22.50, 8.20, 16.50, 22.50, 13.00, 16.50, 6.50},
    {8.20, 0.0, 22.50, 13.00, 16.50, 6.50, 13.00, 0.0, 6.50},
    {24.00, 0.0, 27.20, 24.00, 16.50, 27.20, 8.20, 16.50, 22.50},
    {24.00, 0.0, 27.20, 8.20, 16.50, 22.50, 8.20, 0.0, 22.50},
    /* tall block */
    {42.30, 33.00, 24.70, 26.50, 33.00, 29.60, 31.40, 33.00, 45.60},
    {42.30, 33.00, 24.70, 31.40, 33.00, 45.60, 47.20, 33.00, 40.60},
    {42.30, 0.0, 24.70, 42.30, 33.00, 24.70, 47.20, 33.00, 40.60},
    {42.30, 0.0, 24.70, 47.20, 33.00, 40.60, 47.20, 0.0, 40.60},
    {47.20, 0.0, 40.60, 47.20, 33.00, 40.60, 31.40, 33.00, 45.60},
    {47.20, 0.0, 40.60, 31.40, 33.00, 45.60, 31.40, 0.0, 45.60},
    {31.40, 0.0, 45.60, 31.40, 33.00, 45.60, 26.50, 33.00, 29.60},
    {31.40, 0.0, 45.60, 26.50, 33.00, 29.60, 26.50, 0.0, 29.60},
    {26.50, 0.0, 29.60, 26.50, 33.00, 29.60, 42.30, 33.00, 24.70},
    {26.50, 0.0, 29.60, 42.30, 33.00, 24.70, 42.30, 0.0, 24.70},
};

static const src_loc bench_loc = {"bench_rays", 0, 0};

/* UV sphere of radius 1 with about n triangles (4 nv (nv - 1) of them). */
static scene_mesh *sphere_mesh(scene *s, int n)
{
    int nv = 2;
    while (4 * (nv + 1) * nv <= n) nv++;
    int nu = 2 * nv;
    scene_mesh *m = scene_new_mesh(s);
    m->nverts = 2 + (nv - 1) * nu;
    m->ntris = 2 * nu * (nv - 1);
    m->verts = arena_alloc(s->mem, sizeof(float[3]) * (size_t)m->nverts);
    m->tris = arena_alloc(s->mem, sizeof(int[3]) * (size_t)m->ntris);
    if (!m->verts || !m->tris) return NULL;
    const double pi = 3.14159265358979323846;
    m->verts[0][0] = 0; m->verts[0][1] = 1; m->verts[0][2] = 0;
    m->verts[1][0] = 0; m->verts[1][1] = -1; m->verts[1][2] = 0;
    for (int i = 1; i < nv; i++) {
        double th = pi * i / nv;
        for (int j = 0; j < nu; j++) {
            double ph = 2 * pi * j / nu;
            float *v = m->verts[2 + (i - 1) * nu + j];
            v[0] = (float)(sin(th) * cos(ph));
            v[1] = (float)cos(th);
            v[2] = (float)(sin(th) * sin(ph));
        }
    }
    int t = 0;
#define RING(i, j) (2 + ((i) - 1) * nu + ((j) % nu))
    for (int j = 0; j < nu; j++) {
        m->tris[t][0] = 0; m->tris[t][1] = RING(1, j + 1); m->tris[t][2] = RING(1, j); t++;
        m->tris[t][0] = 1; m->tris[t][1] = RING(nv - 1, j); m->tris[t][2] = RING(nv - 1, j + 1); t++;
    }
    for (int i = 1; i < nv - 1; i++)
        for (int j = 0; j < nu; j++) {
            m->tris[t][0] = RING(i, j); m->tris[t][1] = RING(i, j + 1); m->tris[t][2] = RING(i + 1, j + 1); t++;
            m->tris[t][0] = RING(i, j); m->tris[t][1] = RING(i + 1, j + 1); m->tris[t][2] = RING(i + 1, j); t++;
        }
#undef RING
    m->ntris = t;
    return m;
}

static scene *cornell_scene(const options *op)
{
    scene *s = scene_new();
    if (!s) return NULL;
    for (int i = 0; i < 30; i++) {
        scene_object *o = scene_new_object(s, SHAPE_TRIANGLE, bench_loc);
        o->name = "triangle";
        for (int k = 0; k < 3; k++)
            o->u.triangle.v[k] = v3(cornell_tris[i][3 * k], cornell_tris[i][3 * k + 1], cornell_tris[i][3 * k + 2]);
        scene_add_object(s, o);
    }
    /* light patch: box{<21.3,54.87,33.2><34.3,54.88,22.7> no_shadow} */
    scene_object *b = scene_new_object(s, SHAPE_BOX, bench_loc);
    b->name = "box";
    b->u.box.c1 = v3(21.3, 54.87, 22.7);
    b->u.box.c2 = v3(34.3, 54.88, 33.2);
    b->flags = OBJ_NO_SHADOW;
    scene_add_object(s, b);
    if (op->triangles > 0) {
        scene_mesh *m = sphere_mesh(s, op->triangles);
        if (!m) { scene_free(s); return NULL; }
        for (int c = 0; c < op->copies; c++) {
            /* radius 7 spheres floating above the short block, spread along x */
            scene_object *o = scene_new_object(s, SHAPE_MESH, bench_loc);
            o->name = "mesh";
            o->u.mesh.mesh = m;
            m->uses++;
            double x = op->copies > 1 ? 9.0 + 30.0 * c / (op->copies - 1) : 18.0;
            o->transform = xform_then(xform_scale(v3s(7.0)), xform_translate(v3(x, 26.0, 16.0)));
            scene_add_object(s, o);
        }
    }
    /* camera{location <27.8,27.3,-80> direction z up y right -x angle 39.5} */
    scene_camera *c = &s->camera;
    c->kind = CAMERA_PERSPECTIVE;
    c->location = v3(27.8, 27.3, -80.0);
    c->up = v3(0, 1, 0);
    c->right = v3(-1, 0, 0);
    c->angle = 39.5;
    /* POV-Ray: angle sets |direction| = 0.5 |right| / tan(angle / 2) */
    c->direction = v3(0, 0, 0.5 / tan(39.5 / 2.0 * 3.14159265358979323846 / 180.0));
    s->camera_set = 1;
    scene_light l;
    scene_default_light(&l);
    l.position = v3(27.8, 54.0, 27.95);
    scene_add_light(s, &l);
    return s;
}

typedef struct {
    const accel *a;
    RTCScene rs;
    const options *op;
    vec3 *org, *dir; /* primary rays, row-major */
    vec3 light;
    long *hits, *shadowed; /* per row */
} bench_ctx;

static void row_renderer(void *p, int y, int thread)
{
    (void)thread;
    bench_ctx *c = p;
    long hits = 0, shadowed = 0;
    for (int x = 0; x < c->op->w; x++) {
        size_t i = (size_t)y * (size_t)c->op->w + (size_t)x;
        accel_hit h;
        if (!accel_intersect(c->a, c->org[i], c->dir[i], 0.0, INFINITY, &h)) continue;
        hits++;
        shadowed += accel_occluded(c->a, h.p, v3_sub(c->light, h.p), 0.0, 1.0);
    }
    c->hits[y] = hits;
    c->shadowed[y] = shadowed;
}

static void row_bare(void *p, int y, int thread)
{
    (void)thread;
    bench_ctx *c = p;
    long hits = 0, shadowed = 0;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    double scale = accel_scale(c->a);
    for (int x = 0; x < c->op->w; x++) {
        size_t i = (size_t)y * (size_t)c->op->w + (size_t)x;
        vec3 o = c->org[i], d = c->dir[i];
        struct RTCRayHit rh;
        rh.ray.org_x = (float)o.x; rh.ray.org_y = (float)o.y; rh.ray.org_z = (float)o.z;
        rh.ray.dir_x = (float)d.x; rh.ray.dir_y = (float)d.y; rh.ray.dir_z = (float)d.z;
        rh.ray.tnear = 0.0f;
        rh.ray.tfar = INFINITY;
        rh.ray.time = 0.0f;
        rh.ray.mask = 0xFFFFFFFFu;
        rh.ray.id = 0;
        rh.ray.flags = 0;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(c->rs, &ctx, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
        hits++;
        float px = rh.ray.org_x + rh.ray.tfar * rh.ray.dir_x;
        float py = rh.ray.org_y + rh.ray.tfar * rh.ray.dir_y;
        float pz = rh.ray.org_z + rh.ray.tfar * rh.ray.dir_z;
        struct RTCRay sr;
        sr.org_x = px; sr.org_y = py; sr.org_z = pz;
        sr.dir_x = (float)c->light.x - px; sr.dir_y = (float)c->light.y - py; sr.dir_z = (float)c->light.z - pz;
        float m = fmaxf(fabsf(px), fmaxf(fabsf(py), fabsf(pz)));
        float l = sqrtf(sr.dir_x * sr.dir_x + sr.dir_y * sr.dir_y + sr.dir_z * sr.dir_z);
        sr.tnear = (float)ACCEL_EPS_REL * ((float)scale + m) / l; /* the renderer's epsilon rule */
        sr.tfar = 1.0f;
        sr.time = 0.0f;
        sr.mask = 0xFFFFFFFFu;
        sr.id = 0;
        sr.flags = 0;
        rtcOccluded1(c->rs, &ctx, &sr);
        shadowed += sr.tfar == -INFINITY;
    }
    c->hits[y] = hits;
    c->shadowed[y] = shadowed;
}

static void totals(const bench_ctx *c, long *hits, long *shadowed)
{
    *hits = *shadowed = 0;
    for (int y = 0; y < c->op->h; y++) {
        *hits += c->hits[y];
        *shadowed += c->shadowed[y];
    }
}

/* Renderer and bare runs alternate, so both see the same machine load; the
 * figures are medians over the repetitions, the ratio the median of the
 * per-repetition ratios. */
static void run_pair(bench_ctx *c, int threads, size_t nprimary)
{
    int reps = c->op->reps;
    double *mr = malloc(sizeof(double) * (size_t)reps * 3), *mb = mr + reps, *ratio = mr + 2 * reps;
    long h1 = 0, s1 = 0, h2 = 0, s2 = 0;
    for (int r = 0; r < reps; r++) {
        double t0 = timer_now();
        pool_run(threads, c->op->h, row_renderer, c);
        double t1 = timer_now();
        totals(c, &h1, &s1);
        pool_run(threads, c->op->h, row_bare, c);
        double t2 = timer_now();
        totals(c, &h2, &s2);
        mr[r] = ((double)nprimary + (double)h1) / (t1 - t0) * 1e-6;
        mb[r] = ((double)nprimary + (double)h2) / (t2 - t1) * 1e-6;
        ratio[r] = mr[r] / mb[r];
    }
    printf("  threads %2d: renderer %7.2f Mrays/s  bare Embree %7.2f Mrays/s  ratio %.3f"
           "  (hits %ld/%ld, shadowed %ld/%ld)\n",
           threads, bench_median(mr, reps), bench_median(mb, reps), bench_median(ratio, reps), h1, h2, s1, s2);
    free(mr);
}

static void usage(void)
{
    fprintf(stderr, "usage: bench_rays [--size WxH] [--threads N] [--reps N] [--triangles N] [--copies K]\n");
}

int main(int argc, char **argv)
{
    options op = {512, 512, pool_default_threads(), 7, 0, 1};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--size") && v && sscanf(v, "%dx%d", &op.w, &op.h) == 2) i++;
        else if (!strcmp(a, "--threads") && v) { op.threads = atoi(v); i++; }
        else if (!strcmp(a, "--reps") && v) { op.reps = atoi(v); i++; }
        else if (!strcmp(a, "--triangles") && v) { op.triangles = atoi(v); i++; }
        else if (!strcmp(a, "--copies") && v) { op.copies = atoi(v); i++; }
        else { usage(); return 2; }
    }
    if (op.w < 1 || op.h < 1 || op.reps < 1 || op.threads < 1 || op.triangles < 0 || op.copies < 1) {
        usage();
        return 2;
    }
    scene *s = cornell_scene(&op);
    if (!s) { fprintf(stderr, "bench_rays: out of memory\n"); return 1; }
    diag *d = diag_new();
    pt_status st;
    accel *a = pipeline_accel(s, op.threads, d, &st, NULL);
    for (int i = 0; i < diag_count(d); i++) {
        char *m = diag_format(diag_get(d, i));
        fprintf(stderr, "%s\n", m);
        free(m);
    }
    if (!a) return 1;
    accel_stats as = accel_get_stats(a);
    size_t n = (size_t)op.w * (size_t)op.h;
    bench_ctx c = {a, (RTCScene)accel_rtc_scene(a), &op, malloc(n * sizeof(vec3)), malloc(n * sizeof(vec3)),
                   v3(27.8, 54.0, 27.95), calloc((size_t)op.h, sizeof(long)), calloc((size_t)op.h, sizeof(long))};
    if (!c.org || !c.dir || !c.hits || !c.shadowed) { fprintf(stderr, "bench_rays: out of memory\n"); return 1; }
    for (int y = 0; y < op.h; y++)
        for (int x = 0; x < op.w; x++)
            scene_camera_ray(&s->camera, x + 0.5, y + 0.5, op.w, op.h, &c.org[(size_t)y * op.w + x],
                             &c.dir[(size_t)y * op.w + x]);
    printf("bench_rays: Cornell box, %ld triangles + %ld user prims, %ld instances, build %.3f ms\n",
           as.triangles, as.user_prims, as.instances, as.build_seconds * 1e3);
    printf("  %dx%d primary rays + 1 shadow ray per hit, %d reps (median), Embree %s\n", op.w, op.h, op.reps,
           RTC_VERSION_STRING);
    run_pair(&c, 1, n);
    if (op.threads > 1) run_pair(&c, op.threads, n);
    printf("  (renderer/bare; shadowed counts may differ by a few rays where the bare loop's float hit\n"
           "   points self-shadow at grazing angles: the renderer refines hit points in double)\n");
    free(c.org);
    free(c.dir);
    free(c.hits);
    free(c.shadowed);
    accel_free(a);
    diag_free(d);
    scene_free(s);
    return 0;
}
