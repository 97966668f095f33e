/* scene.c - scene IR construction helpers and POV-Ray 3.7 defaults. */
#include "scene.h"
#include "grow.h"
#include <stdatomic.h>
#include "camera.h"
#include "hash.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

void scene_default_finish(scene_finish *f)
{
    /* POV-Ray 3.7 reference, section "Finish": ambient 0.1, diffuse 0.6,
     * brilliance 1, phong_size 40, roughness 0.05, falloff/exponent 1. */
    *f = (scene_finish){.ambient = {0.1, 0.1, 0.1}, .diffuse = 0.6, .brilliance = 1.0, .phong_size = 40.0,
                        .roughness = 0.05, .reflection_falloff = 1.0, .reflection_exponent = 1.0};
}

void scene_default_pigment(scene_pigment *p)
{
    /* Default pigment is black (POV-Ray 3.7 reference, "Pigment"). */
    *p = (scene_pigment){.kind = PIGMENT_SOLID, .transform = xform_identity()};
}

void scene_default_interior(scene_interior *i)
{
    *i = (scene_interior){.ior = 1.0, .dispersion = 1.0, .dispersion_samples = 7};
}

void scene_default_camera(scene_camera *c)
{
    /* POV-Ray 3.7 defaults: location <0,0,0>, direction <0,0,1>, up <0,1,0>,
     * right <1.33,0,0>, sky <0,1,0>; confidence and variance: camera.cpp. */
    *c = (scene_camera){.kind = CAMERA_PERSPECTIVE, .direction = {0, 0, 1}, .up = {0, 1, 0}, .right = {1.33, 0, 0},
                        .sky = {0, 1, 0}, .look_at = {0, 0, 1}, .confidence = 0.9, .variance = 1.0 / 10000.0};
}

void scene_default_light(scene_light *l)
{
    /* spotlight defaults: radius 30, falloff 45, tightness 0 (3.7 docs);
     * adaptive 100, POV-Ray 3.7's Adaptive_Level without the keyword
     * (lighting/point.cpp, the LightSource constructor): every point of an
     * area grid is sampled. */
    *l = (scene_light){.kind = LIGHT_POINT, .colour = {1, 1, 1}, .point_at = {0, 0, 1}, .radius = 30.0,
                       .falloff = 45.0, .adaptive = 100, .media_interaction = 1};
}

void scene_default_photons(scene_photons *p)
{
    /* POV-Ray 3.7 parser.cpp, global_settings photons: the values it sets
     * before reading the block */
    *p = (scene_photons){.spacing = 1.0, .autostop = 0.5, .jitter = 0.4, .max_trace_level = -1, .adc_bailout = -1.0,
                         .expand_tolerance = 0.2, .expand_min = 35, .gather_min = 20, .gather_max = 100,
                         .radius = {-1.0, 1.0, -1.0, 1.0}, .media_factor = 1.0};
}

static void scene_default_global(scene_global *g)
{
    *g = (scene_global){.ambient_light = {1, 1, 1}, .max_trace_level = 5, .adc_bailout = 1.0 / 255.0,
                        .noise_generator = 2};
    /* radiosity defaults, POV-Ray 3.7 reference "Radiosity"; the direction
     * pool is raised to `count` when that is larger */
    g->radiosity = (scene_radiosity){.count = 35, .recursion_limit = 2, .error_bound = 1.8, .pretrace_start = 0.08,
                                     .pretrace_end = 0.04, .nearest_count = 5, .brightness = 1.0,
                                     .low_error_factor = 0.5, .minimum_reuse = 0.015, .adc_bailout = 0.01,
                                     .max_sample = -1.0, .maximum_reuse = 0.2, .direction_pool = 1600};
    scene_default_photons(&g->photons);
}

scene *scene_new(void)
{
    scene *s = calloc(1, sizeof *s);
    if (!s) return NULL;
    s->mem = arena_new();
    if (!s->mem) { free(s); return NULL; }
    static atomic_ulong next_serial = 1;
    s->serial = atomic_fetch_add(&next_serial, 1);
    s->input_hash = PT_FNV1A_BASIS;
    scene_default_global(&s->global);
    scene_default_camera(&s->camera);
    scene_default_pigment(&s->default_texture.pigment);
    scene_default_finish(&s->default_texture.finish);
    s->default_texture.transform = xform_identity();
    return s;
}

void scene_free(scene *s)
{
    if (!s) return;
    arena_free(s->mem);
    free(s->objects);
    free(s->lights);
    free(s);
}

scene_object *scene_new_object(scene *s, shape_kind kind, src_loc loc)
{
    scene_object *o = arena_alloc(s->mem, sizeof *o);
    if (!o) return NULL;
    o->kind = kind;
    o->loc = loc;
    o->transform = xform_identity();
    return o;
}

scene_texture *scene_new_texture(scene *s)
{
    scene_texture *t = arena_alloc(s->mem, sizeof *t);
    if (!t) return NULL;
    *t = s->default_texture;
    t->next = NULL;
    return t;
}

scene_mesh *scene_new_mesh(scene *s) { return arena_alloc(s->mem, sizeof(scene_mesh)); }

const scene_texture *scene_mesh_tri_texture(const scene_object *o, int t)
{
    const scene_mesh *m = o->u.mesh.mesh;
    if (!m || !m->tri_texture || t < 0 || t >= m->ntris || !o->u.mesh.textures) return NULL;
    int ti = m->tri_texture[t];
    return ti >= 0 && ti < m->ntextures ? o->u.mesh.textures[ti] : NULL;
}

pt_status scene_add_object(scene *s, scene_object *o)
{
    if (!grow_array_int((void **)&s->objects, &s->cap_objects, s->nobjects + 1, sizeof *s->objects)) return PT_ERR_NOMEM;
    s->objects[s->nobjects++] = o;
    return PT_OK;
}

pt_status scene_add_light(scene *s, const scene_light *l)
{
    if (!grow_array_int((void **)&s->lights, &s->cap_lights, s->nlights + 1, sizeof *s->lights)) return PT_ERR_NOMEM;
    s->lights[s->nlights++] = *l;
    return PT_OK;
}

static void count_object(const scene_object *o, scene_counts *c)
{
    switch (o->kind) {
    case SHAPE_UNION: case SHAPE_MERGE: case SHAPE_INTERSECTION: case SHAPE_DIFFERENCE:
        c->csg++;
        for (int i = 0; i < o->u.csg.nkids; i++) count_object(o->u.csg.kids[i], c);
        return;
    case SHAPE_TRIANGLE: case SHAPE_SMOOTH_TRIANGLE:
        c->triangles++;
        break;
    case SHAPE_MESH:
        c->meshes++;
        if (o->u.mesh.mesh) c->triangles += o->u.mesh.mesh->ntris;
        break;
    case SHAPE_UNSUPPORTED:
        c->unsupported++;
        break;
    default:
        break;
    }
    c->objects++;
}

scene_counts scene_count(const scene *s)
{
    scene_counts c;
    memset(&c, 0, sizeof c);
    for (int i = 0; i < s->nobjects; i++) count_object(s->objects[i], &c);
    c.lights = s->nlights;
    return c;
}

void scene_camera_ray(const scene_camera *c, double px, double py, int w, int h, vec3 *org, vec3 *dir)
{
    if (!camera_ray(c, px, py, w, h, 0.0, 0.0, org, dir)) {
        *org = c->location;
        *dir = v3_norm(c->direction);
    }
}

vec3 scene_light_area_point(const scene_light *l, vec3 ax1, vec3 ax2, int u, int v, rng *r)
{
    double ju = u, jv = v;
    if (l->jitter) {
        ju += rng_f64(r) - 0.5;
        jv += rng_f64(r) - 0.5;
    }
    if (l->circular && l->size1 > 1 && l->size2 > 1) {
        ju = ju / (l->size1 - 1) - 0.5 + 0.001;
        jv = jv / (l->size2 - 1) - 0.5 + 0.001;
        double sf = fmax(fabs(ju), fabs(jv)) / sqrt(ju * ju + jv * jv);
        return v3_add(v3_scale(ax1, ju * sf), v3_scale(ax2, jv * sf));
    }
    vec3 o = v3(0, 0, 0);
    if (l->size1 > 1) o = v3_add(o, v3_scale(ax1, ju / (l->size1 - 1) - 0.5));
    if (l->size2 > 1) o = v3_add(o, v3_scale(ax2, jv / (l->size2 - 1) - 0.5));
    return o;
}

void scene_light_orient_axes(const scene_light *l, vec3 dir, vec3 *ax1, vec3 *ax2)
{
    double len = v3_len(l->axis1);
    vec3 helper = fabs(fabs(dir.z) - 1.0) < 0.01 ? v3(0, 1, 0) : v3(0, 0, 1);
    *ax1 = v3_scale(v3_norm(v3_cross(dir, helper)), len);
    *ax2 = v3_scale(v3_norm(v3_cross(dir, v3_norm(*ax1))), len);
}
