/* test_world.c - see test_world.h. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include "sdl.h"
#include "test_world.h"

tu_world tu_world_build(const char *name, const char *src)
{
    tu_world w;
    w.d = diag_new();
    sdl_options opt;
    sdl_default_options(&opt);
    pt_status st = sdl_parse_string(name, src, &opt, &w.s, w.d);
    if (st != PT_OK) {
        for (int i = 0; i < diag_count(w.d); i++) {
            char *m = diag_format(diag_get(w.d, i));
            fprintf(stderr, "%s\n", m);
            free(m);
        }
        fail_msg("parse failed");
    }
    w.a = accel_build(w.s, 1, w.d, &st);
    assert_non_null(w.a);
    return w;
}

void tu_world_free(tu_world *w)
{
    accel_free(w->a);
    scene_free(w->s);
    diag_free(w->d);
}
