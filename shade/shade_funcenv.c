/* shade_funcenv.c - func_env callbacks on shade_noise and shade_pattern. */
#include "shade_funcenv.h"
#include <string.h>
#include "shade_noise.h"
#include "shade_pattern.h"

static double env_noise(void *user, vec3 p, int generator)
{
    (void)user;
    return shade_noise_value(p, generator < 1 || generator > 3 ? 2 : generator);
}

static vec3 env_dturbulence(void *user, vec3 p, int octaves, double omega, double lambda)
{
    (void)user;
    return shade_noise_dturbulence(p, octaves, omega, lambda);
}

/* pigment { } functions give the colour; pattern { } functions the
 * pattern's value after its transforms and warps (POV-Ray's f_pattern). */
static int env_pigment(void *user, const scene_function *f, vec3 p, double out[5])
{
    (void)user;
    const scene_pigment *pg = f->pigment;
    if (!pg) return 0;
    shade_pattern_ctx ctx;
    memset(&ctx, 0, sizeof ctx);
    ctx.noise_generator = 2;
    if (f->kind == FUNC_PIGMENT) {
        colour5 c = {0, 0, 0, 0, 0};
        shade_pigment_eval(pg, p, &ctx, &c);
        out[0] = c.r;
        out[1] = c.g;
        out[2] = c.b;
        out[3] = c.f;
        out[4] = c.t;
        return 1;
    }
    if (pg->kind != PIGMENT_PATTERN || !pg->pat) return 0;
    vec3 q = xform_is_identity(&pg->transform) ? p : xform_inv_point(&pg->transform, p);
    out[0] = shade_pattern_value(pg->pat, shade_pattern_warp(pg->pat, q), &ctx);
    return 1;
}

static const func_env shade_env = {env_pigment, env_noise, env_dturbulence, 2, NULL};

const func_env *shade_func_env(void) { return &shade_env; }
