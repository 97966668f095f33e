/* test_world.h - a scene parsed from SDL text with its accelerator, for the
 * tests (part of pt_testutil; kept out of test_util.h so that tests which
 * only use the shell/file helpers do not see scene.h's names). */
#ifndef PT_TEST_WORLD_H
#define PT_TEST_WORLD_H

#include "accel.h"
#include "diag.h"
#include "scene.h"

/* A scene parsed from SDL text, its accelerator (1 thread) and its
 * diagnostics. */
typedef struct {
    scene *s;
    accel *a;
    diag *d;
} tu_world;

/* Parse `src` (diagnostics name it `name`) with the default options and
 * build its accelerator; prints the diagnostics and fails the test when
 * parsing fails, and fails when the accelerator cannot be built. */
tu_world tu_world_build(const char *name, const char *src);
/* Free what tu_world_build made. */
void tu_world_free(tu_world *w);

/* SDL of a white furnace under the sky, written into buf (n bytes): a
 * diffuse white sphere (pigment 1, diffuse 1, ambient 0) filling the view,
 * under a uniform sky of radiance L given as a sky_sphere (background = 0)
 * or as the background colour (1), no lights; with `radiosity` a
 * radiosity {} block (defaults). A convex object sees only the sky, so
 * every pixel of every GI mode converges to L (POV-Ray's rules for
 * gathering rays that leave the scene, core/radrules.h rule 4). */
const char *tu_sky_furnace(char *buf, size_t n, double L, int background, int radiosity);

#endif
