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

#endif
