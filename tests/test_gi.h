/* test_gi.h - what test_gi.c (particle GI: energy, accuracy, shapes) shares
 * with test_gi_frame.c (the frame's stages: the light-leak guard per cell,
 * the coarse pre-pass, kept hits): one scene parsed and its accel built,
 * the particles built and lit, and the tests main() runs from there. */
#ifndef PT_TEST_GI_H
#define PT_TEST_GI_H
#include "accel.h"
#include "diag.h"
#include "gi_particle.h"
#include "scene.h"

typedef struct {
    scene *sc;
    accel *a;
    diag *d;
} fixture;

/* Parses `text` (asserting it parses) and builds its accel on 2 threads. */
void tg_load(fixture *f, const char *text);
void tg_unload(fixture *f);
/* Builds the particles of f's scene with settings s and lights them. */
gi_particle *tg_build_with(fixture *f, const gi_particle_settings *s);
/* The C build of the kernels (gi_cl.h "c"). */
extern const char *const tg_device_c;
/* A closed cube (mesh, 12 triangles) of uniform reflectance with a point
 * light inside. */
extern const char *const tg_cube_scene;

/* test_gi_frame.c */
void test_cell_cache(void **state);
void test_prepass_grid(void **state);
void test_kept_hits(void **state);

/* test_gi_sky.c */
void test_sky_furnace(void **state);
void test_sky_final_gather(void **state);
void test_normal_on_gather(void **state);
void test_csg_emitter_gather(void **state);
void test_mirror_gather(void **state);
void test_transmit_gather(void **state);
void test_closed_room_gather(void **state);
void test_diffuse_back_gather(void **state);
void test_dark_gather(void **state);
void test_sky_second_bounce(void **state);

#endif
