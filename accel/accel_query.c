/* accel_query.c - geom_env on geom_shape (see accel_query.h). */
#include "accel_query.h"
#include <stdlib.h>
#include "geom_shape.h"

static void *query_prepare(const scene_object *o, int *nomem)
{
    geom_shape *sh = malloc(sizeof *sh);
    if (!sh) {
        *nomem = 1;
        return NULL;
    }
    if (geom_shape_init(sh, o) != 0) {
        free(sh);
        return NULL;
    }
    if (sh->kind == SHAPE_PLANE || sh->infinite)
        geom_shape_clip_plane(sh, v3s(-ACCEL_QUERY_EXTENT), v3s(ACCEL_QUERY_EXTENT));
    return sh;
}

static void query_release(void *shape)
{
    if (!shape) return;
    geom_shape_release(shape);
    free(shape);
}

static int query_hits(const void *shape, vec3 org, vec3 dir, double tmin, double tmax, double *t, vec3 *n, int max)
{
    const geom_shape *sh = shape;
    if (max <= 0) return 0;
    geom_shape_hit *h = malloc(sizeof *h * (size_t)max);
    if (!h) return 0;
    int k = 0;
    if (sh->infinite) {
        double a = tmin > 0.0 ? tmin : 0.0, w = ACCEL_QUERY_WINDOW;
        double len = v3_len(dir), reach = len > 0.0 ? 4.0 * ACCEL_QUERY_EXTENT / len : 0.0;
        while (a < tmax && a < reach && k < max) {
            double b = a + w / (len > 0.0 ? len : 1.0);
            if (b > tmax) b = tmax;
            k += geom_shape_hits(sh, org, dir, a, b, h + k, max - k);
            a = b;
            w *= 4.0;
        }
    } else {
        k = geom_shape_hits(sh, org, dir, tmin, tmax, h, max);
    }
    for (int i = 0; i < k; i++) {
        vec3 p = v3_madd(org, dir, h[i].t), ng, ns;
        double u, v;
        geom_shape_surface(sh, p, h[i].part, &ng, &u, &v);
        geom_shape_shading(sh, p, ng, &ns);
        t[i] = h[i].t;
        n[i] = ns;
    }
    free(h);
    return k;
}

static int query_inside(const void *shape, vec3 p) { return geom_shape_inside(shape, p); }

const geom_env *accel_geom_env(void)
{
    static const geom_env env = {query_prepare, query_release, query_hits, query_inside};
    return &env;
}
