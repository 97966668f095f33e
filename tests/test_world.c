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

const char *tu_sky_furnace(char *buf, size_t n, double L, int background, int radiosity)
{
    char sky[128];
    if (background) snprintf(sky, sizeof sky, "background { rgb %.17g }", L);
    else snprintf(sky, sizeof sky, "sky_sphere { pigment { rgb %.17g } }", L);
    snprintf(buf, n,
             "#version 3.7;\n"
             "global_settings { assumed_gamma 1.0 %s }\n"
             "camera { location <0, 0, -3> look_at <0, 0, 0> angle 20 }\n"
             "%s\n"
             "sphere { 0, 1 pigment { rgb 1 } finish { ambient 0 diffuse 1 } }\n",
             radiosity ? "radiosity { }" : "", sky);
    return buf;
}

void tu_world_free(tu_world *w)
{
    accel_free(w->a);
    scene_free(w->s);
    diag_free(w->d);
}
