/* shade_funcenv.h - what core/func.h leaves to the renderer, supplied from
 * shade/: POV-Ray's noise (shade_noise: f_noise3d and the other noise
 * internals, vturbulence) and pigment/pattern functions (shade_pattern).
 * The app passes it to the parser (sdl_options.func_env) so such functions
 * can also be called while a scene is parsed; renderers pass it to
 * func_eval. The environment uses noise_generator 2 (POV-Ray's default). */
#ifndef PT_SHADE_FUNCENV_H
#define PT_SHADE_FUNCENV_H
#include "func.h"

const func_env *shade_func_env(void);

#endif
