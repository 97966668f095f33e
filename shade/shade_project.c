/* shade_project.c - projected_through lights (see shade_project.h). Each
 * object gets its own accel built from a one-object copy of the scene (kept
 * alive beside it, as accel requires). */
#include "shade_project.h"
#include <stdlib.h>
#include <string.h>
#include "accel.h"

struct shade_light_projection {
    int nlights;
    accel **acc;    /* per light, NULL without projected_through */
    scene *copies;  /* per light: the one-object scenes the accels point into */
    scene_object **objs;
};

shade_light_projection *shade_projection_build(const scene *sc, diag *d)
{
    int any = 0;
    for (int i = 0; i < sc->nlights; i++) any |= sc->lights[i].projected_through != NULL;
    if (!any) return NULL;
    shade_light_projection *lp = calloc(1, sizeof *lp);
    if (!lp) return NULL;
    lp->nlights = sc->nlights;
    lp->acc = calloc((size_t)sc->nlights, sizeof *lp->acc);
    lp->copies = calloc((size_t)sc->nlights, sizeof *lp->copies);
    lp->objs = calloc((size_t)sc->nlights, sizeof *lp->objs);
    if (!lp->acc || !lp->copies || !lp->objs) {
        shade_projection_free(lp);
        return NULL;
    }
    for (int i = 0; i < sc->nlights; i++) {
        if (!sc->lights[i].projected_through) continue;
        scene *c = &lp->copies[i];
        *c = *sc;
        lp->objs[i] = (scene_object *)sc->lights[i].projected_through;
        c->objects = &lp->objs[i];
        c->nobjects = c->cap_objects = 1;
        c->nlights = c->cap_lights = 0;
        c->lights = NULL;
        pt_status st = PT_OK;
        lp->acc[i] = accel_build(c, 1, d, &st);
        if (!lp->acc[i]) diag_warn_once(d, sc->lights[i].loc, "projected_through object could not be built; the light is unrestricted");
    }
    return lp;
}

void shade_projection_free(shade_light_projection *lp)
{
    if (!lp) return;
    if (lp->acc)
        for (int i = 0; i < lp->nlights; i++) accel_free(lp->acc[i]);
    free(lp->acc);
    free(lp->copies);
    free(lp->objs);
    free(lp);
}

int shade_projection_pass(const shade_light_projection *lp, int light, vec3 p, vec3 dir, double depth, double *shadow_depth)
{
    *shadow_depth = depth;
    if (!lp || light < 0 || light >= lp->nlights || !lp->acc[light]) return 1;
    accel_hit h;
    if (!accel_intersect(lp->acc[light], p, dir, 0.0, depth, &h)) return 0;
    *shadow_depth = h.t;
    return 1;
}
