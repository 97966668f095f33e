/* test_gi_links.c - the link builder's two nearest-particle lookups give the
 * same links: the lookup by the hit triangle (gi_trilook, which the
 * geometry stage uses first) against the 3D grid alone (gi_links_build
 * with no trilook), on the particles the geometry stage kept, for the 4x4
 * scattering and the 16x16 gathering directions, on scenes/cbox.pov and on
 * a maze-like scene made to hit the rules' corners: a tessellated floor
 * with a primitive box standing on it (buried floor particles) and a
 * sphere, closed mesh walls (one 0.05 thick: thin-slab inner sides), a wall
 * turned 30 degrees, a tessellated ball (curved: normals near the agreement
 * threshold and the near-plane filter), an instanced mesh (grid path) and
 * a coarse ceiling (triangles much larger than the particle spacing: many
 * cells a triangle). Every link must be identical (ties between two
 * particles at exactly the same distance aside, which these scenes do not
 * have: the test would report them as differences), and most link hits
 * must be answered by the triangle lists (else the test would compare the
 * grid with itself). gi_trilook.h states why the answers are exact. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include "accel.h"
#include "diag.h"
#include "gi_particle_internal.h"
#include "sdl.h"

static void print_diag(diag *d)
{
    for (int i = 0; i < diag_count(d); i++) {
        char *m = diag_format(diag_get(d, i));
        fprintf(stderr, "  diag: %s\n", m);
        free(m);
    }
}

/* Links of gp's particles in nside x nside directions with the triangle
 * lists (tl) and without (grid only); asserts they are the same and
 * returns the fraction of link rays the lists answered. */
static double compare_links(gi_particle *gp, void *lscene, const void *const *pobj, const unsigned char *pin,
                            const gi_lookup *grid, const gi_trilook *tl, int nside, uint64_t seed)
{
    const gi_particles *ps = &gp->ps;
    int n = ps->n;
    size_t nl = (size_t)n * (size_t)nside * (size_t)nside;
    int *links[2] = {malloc(nl * sizeof(int)), malloc(nl * sizeof(int))};
    assert_non_null(links[0]);
    assert_non_null(links[1]);
    gi_link_stats st[2] = {{0}, {0}};
    double maxdist = 3.0 * ps->spacing;
    for (int k = 0; k < 2; k++)
        assert_int_equal(gi_links_build(gp->a, lscene, ps->p, pobj, pin, n, 0, nside, seed, grid, k == 0 ? tl : NULL,
                                        maxdist, 2, links[k], NULL, &st[k], NULL, NULL, NULL, NULL, NULL, NULL, 0.0, NULL, NULL, NULL),
                         PT_OK);
    long diff = 0;
    for (size_t i = 0; i < nl; i++) diff += links[0][i] != links[1][i];
    double frac = (double)st[0].tri_answered / (double)(st[0].rays > 0 ? st[0].rays : 1);
    printf("  %dx%d: %zu links, differing %ld; rays %ld, misses %ld, answered by the triangle lists %ld (%.1f%%), "
           "left to the grid %ld\n",
           nside, nside, nl, diff, st[0].rays, st[0].misses, st[0].tri_answered, 100.0 * frac, st[0].tri_fallback);
    assert_int_equal(st[1].tri_answered, 0);
    assert_int_equal(st[0].rays, st[1].rays);
    assert_int_equal(st[0].misses, st[1].misses);
    assert_int_equal(st[0].unresolved, st[1].unresolved);
    assert_int_equal(diff, 0);
    free(links[0]);
    free(links[1]);
    return frac;
}

/* The geometry stage on the scene, then both lookups on its particles;
 * returns the smaller fraction of the two link passes answered by the
 * triangle lists. */
static double compare(const char *name, const char *path, const char *text, long count)
{
    diag *d = diag_new();
    sdl_options o;
    sdl_default_options(&o);
    scene *sc = NULL;
    pt_status st = path ? sdl_parse_file(path, &o, &sc, d) : sdl_parse_string("maze.pov", text, &o, &sc, d);
    if (st != PT_OK) print_diag(d);
    assert_int_equal(st, PT_OK);
    accel *a = accel_build(sc, 2, d, &st);
    assert_non_null(a);
    gi_particle_settings set;
    gi_particle_default_settings(&set);
    set.count = count;
    set.threads = 2;
    set.cl_device = "c";
    set.seed = 7;
    gi_particle *gp = gi_particle_build(sc, a, &set, NULL, d, &st);
    if (!gp) print_diag(d);
    assert_non_null(gp);
    gi_particles *ps = &gp->ps;
    printf("%s: %d particles, spacing %g\n", name, ps->n, ps->spacing);
    unsigned char *pin = NULL;
    const void **pobj = gi_particle_objects(gp, ps, &pin, &st);
    assert_int_equal(st, PT_OK);
    gi_lookup *grid = gi_lookup_build(ps, 2.0 * ps->spacing);
    assert_non_null(grid);
    assert_int_equal(gi_lookup_set_objects(grid, (const void *const *)pobj), PT_OK);
    gi_trilook *tl = gi_trilook_build(a, ps->p, ps->n, (const void *const *)pobj, grid, pin + ps->n, ps->spacing,
                                      GI_LINKS_AGREE, 3.0 * ps->spacing, 2, NULL, &st);
    assert_int_equal(st, PT_OK);
    assert_non_null(tl);
    void *lscene = accel_rtc_link_scene(a);
    double f4 = compare_links(gp, lscene, (const void *const *)pobj, pin, grid, tl, 4, 0x51);
    double f16 = compare_links(gp, lscene, (const void *const *)pobj, pin, grid, tl, 16, 0x6a7);
    accel_rtc_link_scene_free(lscene);
    gi_trilook_free(tl);
    gi_lookup_free(grid);
    free(pobj);
    free(pin);
    gi_particle_free(gp);
    accel_free(a);
    scene_free(sc);
    diag_free(d);
    return f4 < f16 ? f4 : f16;
}

static void test_cbox_links(void **state)
{
    (void)state;
    double f = compare("cbox", PT_SOURCE_DIR "/scenes/cbox.pov", NULL, 10000);
    /* 16% of cbox's link rays miss; nearly all hits are on its meshes */
    assert_true(f > 0.80);
}

static const char maze_text[] =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 }\n"
    "camera { location <0, 8, -12> look_at <0, 0, 0> }\n"
    "light_source { <0, 3.5, 0> color rgb 1 }\n"
    "#declare T = texture { pigment { rgb 0.7 } finish { ambient 0 diffuse 0.8 } }\n"
    "#macro Grid(Y, N, S)\n"
    "  mesh {\n"
    "  #local i = 0; #while (i < N) #local j = 0; #while (j < N)\n"
    "    #local x0 = -S + 2*S*i/N; #local x1 = -S + 2*S*(i+1)/N;\n"
    "    #local z0 = -S + 2*S*j/N; #local z1 = -S + 2*S*(j+1)/N;\n"
    "    triangle { <x0,Y,z0>, <x1,Y,z0>, <x1,Y,z1> } triangle { <x0,Y,z0>, <x1,Y,z1>, <x0,Y,z1> }\n"
    "  #local j = j + 1; #end #local i = i + 1; #end\n"
    "  texture { T } }\n"
    "#end\n"
    "#macro Wall(A, B)\n"
    "  #local P0 = <A.x,A.y,A.z>; #local P1 = <B.x,A.y,A.z>; #local P2 = <B.x,A.y,B.z>; #local P3 = <A.x,A.y,B.z>;\n"
    "  #local P4 = <A.x,B.y,A.z>; #local P5 = <B.x,B.y,A.z>; #local P6 = <B.x,B.y,B.z>; #local P7 = <A.x,B.y,B.z>;\n"
    "  mesh { triangle { P0, P1, P2 } triangle { P0, P2, P3 } triangle { P4, P5, P6 } triangle { P4, P6, P7 }\n"
    "    triangle { P0, P1, P5 } triangle { P0, P5, P4 } triangle { P1, P2, P6 } triangle { P1, P6, P5 }\n"
    "    triangle { P2, P3, P7 } triangle { P2, P7, P6 } triangle { P3, P0, P4 } triangle { P3, P4, P7 }\n"
    "    texture { T } }\n"
    "#end\n"
    "#macro Ball(C, R, N)\n"
    "  mesh {\n"
    "  #local i = 0; #while (i < N) #local j = 0; #while (j < 2*N)\n"
    "    #local t0 = pi*i/N; #local t1 = pi*(i+1)/N; #local p0 = pi*j/N; #local p1 = pi*(j+1)/N;\n"
    "    #local A = C + R*<sin(t0)*cos(p0), cos(t0), sin(t0)*sin(p0)>;\n"
    "    #local B = C + R*<sin(t0)*cos(p1), cos(t0), sin(t0)*sin(p1)>;\n"
    "    #local E = C + R*<sin(t1)*cos(p1), cos(t1), sin(t1)*sin(p1)>;\n"
    "    #local F = C + R*<sin(t1)*cos(p0), cos(t1), sin(t1)*sin(p0)>;\n"
    "    #if (i > 0) triangle { A, B, E } #end\n"
    "    #if (i < N - 1) triangle { A, E, F } #end\n"
    "  #local j = j + 1; #end #local i = i + 1; #end\n"
    "  texture { T } }\n"
    "#end\n"
    "Grid(0, 24, 6)\n"
    "Grid(4, 2, 6)\n"
    "Wall(<-6,0,-6>, <6,4,-5.8>) Wall(<-6,0,5.8>, <6,4,6>) Wall(<-6,0,-6>, <-5.8,4,6>) Wall(<5.8,0,-6>, <6,4,6>)\n"
    "Wall(<-4,0,-2>, <1,2.5,-1.7>) Wall(<2,0,-5.8>, <2.05,3,1>)\n"
    "object { Wall(<-1,0,2>, <3,3,2.3>) rotate y*30 }\n"
    "Ball(<-3, 1.2, 3>, 1.2, 12)\n"
    "box { <3,0,3>, <4.5,1.5,4.5> texture { T } }\n"
    "sphere { <-3.5, 1, -4>, 0.8 texture { T } }\n"
    "#declare M = mesh { triangle { <0,0,0>, <1,0,0>, <0,1.5,0> } triangle { <1,0,0>, <1,1.5,0>, <0,1.5,0> } texture { T } }\n"
    "object { M translate <-5, 0, 0> } object { M rotate y*90 translate <4, 0, -3> }\n";

static void test_maze_links(void **state)
{
    (void)state;
    double f = compare("maze-like", NULL, maze_text, 12000);
    assert_true(f > 0.60);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cbox_links),
        cmocka_unit_test(test_maze_links),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
