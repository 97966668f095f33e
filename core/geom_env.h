/* geom_env.h - ray and inside queries on one IR shape, answered by the
 * renderer's own intersection code.
 *
 * The parser's trace() and inside() need them at parse time but depend on
 * core/ only; the application passes accel_geom_env() (accel/accel_query.h),
 * the same geom_shape code that renders the shape, so a parse-time answer
 * and the rendered surface agree. */
#ifndef PT_GEOM_ENV_H
#define PT_GEOM_ENV_H
#include "scene.h"

typedef struct geom_env {
    /* Prepare leaf object o (its shape data and o->transform, object ->
     * world) for queries. NULL: degenerate (the renderer skips it too: no
     * hits, never inside) or out of memory (*nomem set). */
    void *(*prepare)(const scene_object *o, int *nomem);
    void (*release)(void *shape);
    /* Crossings of the world ray org + t*dir with t in (tmin, tmax),
     * ascending, at most max: t[i] and the unit outward world normal n[i]
     * (the shading normal where the shape has one, e.g. a smooth
     * height_field, as POV-Ray's trace() reports it). Returns their number. */
    int (*hits)(const void *shape, vec3 org, vec3 dir, double tmin, double tmax, double *t, vec3 *n, int max);
    /* World point p strictly inside the solid (before `inverse`). */
    int (*inside)(const void *shape, vec3 p);
} geom_env;

#endif
