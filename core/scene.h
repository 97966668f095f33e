/* scene.h - the scene IR: plain records the parser fills and every renderer
 * reads. Nothing here knows about tokens or about Embree. All memory belongs
 * to the scene's arena; pointers between records stay valid for its life.
 *
 * Conventions (POV-Ray's): left-handed world, y up, colours are linear
 * (assumed_gamma 1.0 is the only working space we model; see DESIGN.md). */
#ifndef PT_SCENE_H
#define PT_SCENE_H
#include <stddef.h>
#include "arena.h"
#include "diag.h"
#include "rng.h"
#include "vec.h"
#include "xform.h"
#include "scene_pattern.h"

/* Colour with POV-Ray's filter and transmit channels. */
typedef struct { double r, g, b, f, t; } colour5;
typedef struct { double r, g, b; } rgb;

/* ---------------------------------------------------------------- pigment */
typedef enum {
    PIGMENT_SOLID = 0,
    PIGMENT_OTHER,  /* a pattern the renderer does not evaluate yet: uses `colour` */
    PIGMENT_PATTERN /* `pat` evaluated through `map` (shade_pattern.h) */
} pigment_kind;

typedef struct scene_pigment {
    pigment_kind kind;
    colour5 colour;      /* solid colour (also the fallback for patterns) */
    const char *pattern; /* pattern keyword for PIGMENT_OTHER/PATTERN, else NULL */
    xform transform;     /* pattern space -> object space */
    /* PIGMENT_PATTERN (scene_pattern.h): the pattern (its warps follow
     * `transform`) and its colour_map or pigment_map; map NULL = the
     * pattern's POV-Ray default map (image_map: the image's colours). */
    const scene_pattern *pat;
    const scene_blend_map *map;
} scene_pigment;

/* ---------------------------------------------------------------- finish */
typedef struct {
    rgb ambient;          /* default 0.1 (POV-Ray 3.7 docs, finish) */
    rgb emission;         /* default 0 */
    double diffuse;       /* default 0.6 */
    double diffuse_back;  /* "diffuse a, b": backside value, default 0 */
    double brilliance;    /* default 1 */
    double crand;         /* default 0 */
    double phong;         /* default 0 */
    double phong_size;    /* default 40 */
    double specular;      /* default 0 */
    double roughness;     /* default 0.05 */
    double metallic;      /* highlight metallic, default 0 */
    rgb reflection_min;   /* reflection {min, max}; plain "reflection c" sets both */
    rgb reflection_max;
    double reflection_falloff;  /* default 1 */
    double reflection_exponent; /* default 1 */
    double reflection_metallic; /* default 0 */
    int fresnel;                /* reflection { fresnel on } */
    int conserve_energy;
    /* irid { amount thickness t turbulence u } (appended, issue 5): thin-film
     * interference as POV-Ray 3.7 models it, single precision as it keeps
     * them; defaults 0 */
    double irid, irid_thickness, irid_turb;
} scene_finish;

/* ---------------------------------------------------------------- interior */
typedef struct {
    double ior;           /* default 1 */
    double dispersion;    /* default 1 */
    int dispersion_samples; /* dispersion elements, default 7 (POV-Ray 3.7's interior.cpp), at least 2 */
    double fade_distance; /* 0 = off */
    double fade_power;
    rgb fade_colour;
    int caustics_set;
    double caustics;      /* appended: POV-Ray's internal value, 45 * the given one (faked caustics) */
    /* appended (issue 5): the media { } blocks in order */
    int nmedia;
    const struct scene_media *const *media;
} scene_interior;

/* ---------------------------------------------------------------- media
 * Participating media (appended, issue 5; shade/shade_media.c renders
 * them). One media { } block as POV-Ray 3.7 keeps it. Defaults of a media
 * written at #version 3.5 or later (POV-Ray's Parse_Media): method 3,
 * intervals 1, samples 10,10; earlier: method 1, intervals 10, samples 1,1.
 * Always: ratio 0.9, confidence 0.9, variance 1/128, jitter 0,
 * aa_threshold 0.1, aa_level 3, scattering type 1 (isotropic),
 * eccentricity 0, extinction 1. */
typedef enum {
    MEDIA_ISOTROPIC = 1, MEDIA_MIE_HAZY, MEDIA_MIE_MURKY, MEDIA_RAYLEIGH, MEDIA_HENYEY_GREENSTEIN
} media_scatter_kind;

typedef struct scene_media {
    src_loc loc;
    int method;           /* 1, 2, 3 */
    int intervals;
    int min_samples, max_samples;
    double jitter, aa_threshold;
    int aa_level;
    double ratio, confidence, variance;
    rgb absorption, emission, scattering;
    int scattering_type;  /* media_scatter_kind (other values scatter isotropically) */
    double eccentricity;  /* Henyey-Greenstein g */
    double extinction;    /* scattering's share of the extinction (POV-Ray's sc_ext) */
    int collect;          /* photons collected (parsed; photons in media are not modelled) */
    /* density { } blocks (their colours multiply); each is a pigment
     * evaluated in media space; ndensity 0 = constant density 1 */
    int ndensity;
    const scene_pigment *const *density;
    /* media space -> the container's object space (interior media: the
     * object's transforms written before the interior are undone here, so
     * object -> world is the container's transform), or -> world
     * (atmospheric media) */
    xform transform;
} scene_media;

/* A texture: one pigment, finish and (later) normal. Layered textures are a
 * list linked through `next`, the first entry on top. */
typedef struct scene_texture {
    scene_pigment pigment;
    scene_finish finish;
    int has_normal;            /* a normal{} block was given (not evaluated yet) */
    xform transform;           /* texture transform (applied after the object's) */
    struct scene_texture *next;
    src_loc loc;
    /* Appended (scene_pattern.h). normal: NULL = unperturbed. A patterned
     * texture (texture_map, checker/hexagon/brick of textures, average,
     * tiles) has `pat` and `map` (MAP_TEXTURE) set; its pigment and finish
     * then hold the first entry's look for code that needs one colour. */
    const scene_normal *normal;
    const scene_pattern *pat;
    const scene_blend_map *map;
    /* `texture { uv_mapping ... }` (appended, issue 5): the texture is
     * evaluated at the hit's <u, v, 0> (POV-Ray's UV_MAP_PATTERN), with its
     * own transforms only */
    int uv_mapping;
} scene_texture;

/* ---------------------------------------------------------------- meshes */
/* Triangle data shared between objects (a declared mesh used many times is
 * one scene_mesh referenced by several objects: accel instances it). */
typedef struct scene_mesh {
    int nverts, nnormals, nuvs, ntris;
    float (*verts)[3];
    float (*normals)[3];   /* may be NULL */
    float (*uvs)[2];       /* may be NULL */
    int (*tris)[3];        /* vertex indices */
    int (*tri_normals)[3]; /* normal indices, NULL if none */
    int *tri_texture;      /* index into `textures` per triangle, NULL = object texture */
    int ntextures;
    const scene_texture **textures;
    int uses;              /* number of objects that reference it */
    src_loc loc;
    /* uv_vectors (appended, issue 5): uv indices per triangle into `uvs`
     * (POV-Ray's UV1..UV3), NULL with uvs = NULL: every uv is <0, 0> */
    int (*tri_uvs)[3];
} scene_mesh;

/* ---------------------------------------------------------------- objects */
typedef enum {
    SHAPE_SPHERE,
    SHAPE_BOX,
    SHAPE_PLANE,
    SHAPE_TRIANGLE,
    SHAPE_SMOOTH_TRIANGLE,
    SHAPE_MESH,
    SHAPE_UNION,
    SHAPE_MERGE,
    SHAPE_INTERSECTION,
    SHAPE_DIFFERENCE,
    SHAPE_CYLINDER,
    SHAPE_CONE,
    SHAPE_DISC,
    SHAPE_TORUS,
    SHAPE_UNSUPPORTED, /* parsed, not renderable yet: `name` says which */
    /* Appended for issue 4 (POV-Ray's further shapes); their data live in
     * arena-allocated records (below) referenced from the union. */
    SHAPE_POLYGON,        /* u.polygon */
    SHAPE_LATHE,          /* u.lathe */
    SHAPE_SOR,            /* u.lathe (spline ignored: always POV-Ray's sor curve) */
    SHAPE_PRISM,          /* u.prism */
    SHAPE_SUPERELLIPSOID, /* u.superellipsoid */
    SHAPE_QUADRIC,        /* u.quadric */
    SHAPE_POLY,           /* u.poly: poly, cubic, quartic, polynomial */
    SHAPE_BLOB,           /* u.blob */
    SHAPE_HEIGHT_FIELD,   /* u.height_field */
    SHAPE_TEXT,           /* u.text: glyph outlines extruded along z */
    SHAPE_ISOSURFACE,     /* u.isosurface */
    SHAPE_JULIA,          /* u.julia: julia_fractal */
    SHAPE_OVUS            /* u.ovus: POV-Ray 3.7's egg (bottom sphere at the origin, top sphere at y = bottom) */
} shape_kind;

enum {
    OBJ_NO_SHADOW = 1u << 0,
    OBJ_NO_IMAGE = 1u << 1,
    OBJ_NO_REFLECTION = 1u << 2,
    OBJ_INVERSE = 1u << 3,
    OBJ_HOLLOW = 1u << 4,
    OBJ_DOUBLE_ILLUMINATE = 1u << 5,
    OBJ_OPEN = 1u << 6,
    OBJ_STURM = 1u << 7,
    OBJ_NO_RADIOSITY = 1u << 8
};

/* ---------------------------------------------------------------- further shapes (issue 4)
 * Plain POV-Ray data as written in the scene (object space); accel/ derives
 * what it needs to intersect them. */
typedef enum { SPLINE_LINEAR, SPLINE_QUADRATIC, SPLINE_CUBIC, SPLINE_BEZIER } scene_spline;

/* polygon { n, <p1> ... <pn> }: sub-polygons close where a point repeats
 * the sub-polygon's first point; the last one is closed implicitly. */
typedef struct { int npoints; vec3 *points; } scene_polygon;

/* lathe / sor: 2-D points <radius, height> revolved about the y axis. */
typedef struct { scene_spline spline; int npoints; double (*points)[2]; } scene_lathe;

/* prism: 2-D points <x, z> swept along y from height1 to height2
 * (conic_sweep: scaled by y, apex at the origin). */
typedef struct {
    scene_spline spline;
    int conic;
    double height1, height2;
    int npoints;
    double (*points)[2];
} scene_prism;

/* blob component: sphere (a = centre) or cylinder (axis a..b, hemispherical
 * ends), field strength * (1 - (d/radius)^2)^2; `transform` maps component
 * space to blob space (component transforms). */
typedef struct {
    int cylinder;
    vec3 a, b;
    double radius, strength;
    xform transform;
    const struct scene_texture *texture; /* NULL = the blob's */
} scene_blob_component;
typedef struct { double threshold; int ncomponents; scene_blob_component *components; } scene_blob;

/* poly/cubic/quartic/polynomial: sum of coef[i] x^a y^b z^c over POV-Ray's
 * term order for `order` (x power descending, then y, then z). */
typedef struct { int order; int ncoefs; double *coefs; } scene_poly;

/* height_field: grid of heights in [0,1] (row 0 at z = 0, column 0 at x = 0)
 * over the unit square; water_level cuts away what is below it. */
typedef struct {
    int width, height;   /* columns (x), rows (z) */
    float *heights;      /* width * height */
    int smooth;
    double water_level;
} scene_height_field;

/* text: closed glyph contours as cubic Bezier segments (4 points of 2-D
 * x, y each) in the z = 0 plane, extruded from z = 0 to z = depth. */
typedef struct { int nsegments; double (*segments)[8]; double depth; } scene_text;

/* isosurface: function(x, y, z) = threshold inside a box or sphere
 * (contained_by, default box { -1, 1 }); inside where the function is below
 * the threshold. The function is core/func.h's scene_function. */
typedef struct {
    const struct scene_function *fn;
    int sphere;            /* container: 0 box c1..c2, 1 sphere centre c1 radius */
    vec3 c1, c2;
    double radius;
    double threshold;      /* default 0 */
    double accuracy;       /* default 0.001 */
    double max_gradient;   /* default 1.1 */
    int max_trace;         /* crossings wanted per ray, 0 = all_intersections (default 1) */
} scene_isosurface;

/* julia_fractal: the points p whose 4-D iterates z -> f(z) + c stay within
 * the bailout for max_iteration steps, z0 = p on the slice plane
 * slice . (x, y, z, w) = slice_dist (slice normalised). Quaternions support
 * sqr and cube; hypercomplex numbers any of the functions. */
typedef enum {
    JULIA_SQR, JULIA_CUBE, JULIA_EXP, JULIA_LN, JULIA_SIN, JULIA_ASIN, JULIA_COS, JULIA_ACOS, JULIA_TAN,
    JULIA_ATAN, JULIA_SINH, JULIA_ASINH, JULIA_COSH, JULIA_ACOSH, JULIA_TANH, JULIA_ATANH, JULIA_RECIPROCAL,
    JULIA_PWR
} scene_julia_func;
typedef struct {
    double c[4];
    int hypercomplex;
    scene_julia_func func;
    double pwr[2];          /* pwr(x, y): exponent x + i y */
    int max_iteration;      /* default 20 */
    double precision;       /* default 20: the march's smallest step is 1 / precision */
    double slice[4];        /* default <0,0,0,1> */
    double slice_dist;      /* default 0 */
} scene_julia;

/* Per-object photons { } block (POV-Ray 3.7): which objects caustic photons
 * are shot at and what they do there. As POV-Ray's parser reads it:
 * `target [FLOAT]` (spacing multiplier, default 1; 0 or less: not a target),
 * `reflection on|off`, `refraction on|off` (each off unless said on),
 * `collect off` (photons are not stored on it), `pass_through [on|off]`. */
typedef struct {
    src_loc loc;            /* the `photons` keyword */
    int target;
    double spacing;         /* target's multiplier of the global spacing */
    int reflection, refraction;
    int collect;            /* default 1 */
    int pass_through;
} scene_obj_photons;

typedef struct scene_object scene_object;
struct scene_object {
    shape_kind kind;
    const char *name;       /* keyword that made it ("sphere", "lathe", ...) */
    src_loc loc;
    xform transform;        /* object -> world (already composed with parents) */
    const scene_texture *texture;   /* NULL = default texture */
    const scene_texture *interior_texture;
    const scene_interior *interior; /* NULL = default interior */
    unsigned flags;
    union {
        struct { vec3 centre; double radius; } sphere;
        struct { vec3 c1, c2; } box;            /* c1 <= c2 component-wise */
        struct { vec3 normal; double offset; } plane; /* points p with n.p = offset */
        struct { vec3 v[3]; vec3 n[3]; } triangle;   /* n used for smooth_triangle */
        struct { const scene_mesh *mesh; int inside_vector_set; vec3 inside_vector; } mesh;
        struct { scene_object **kids; int nkids; } csg;
        struct { vec3 base, cap; double base_radius, cap_radius; } cone; /* cylinder: equal radii */
        struct { vec3 centre, normal; double radius, hole_radius; } disc;
        struct { double major, minor; } torus;
        /* issue 4 shapes */
        const scene_polygon *polygon;
        const scene_lathe *lathe;           /* lathe and sor */
        const scene_prism *prism;
        struct { double e, n; } superellipsoid; /* east-west, north-south exponents */
        struct { double a[10]; } quadric;   /* A x2 + B y2 + C z2 + D xy + E xz + F yz + G x + H y + I z + J */
        const scene_poly *poly;
        const scene_blob *blob;
        const scene_height_field *height_field;
        const scene_text *text;
        const scene_isosurface *isosurface;
        const scene_julia *julia;
        struct { double bottom, top; } ovus; /* radii, 0 < top < 2 bottom */
    } u;
    /* clipped_by (issue 4): the clipping solid, its transform relative to
     * this object's space (world = clip->transform then this->transform), so
     * later transforms of the object move it along. NULL = none. */
    const scene_object *clip;
    /* bounded_by (issue 4): a SHAPE_UNION node named "bounded_by" whose kids
     * are the bounding objects, transforms relative to this object as for
     * clip. A ray sees the object only if it meets every bounding object (at
     * any distance ahead) or starts inside it (POV-Ray's Ray_In_Bound).
     * NULL = none. */
    const scene_object *bound;
    /* light_group (appended, issue 5): the innermost group holding the
     * object (0 none; lights with that `group` light it) and whether
     * the scene's global lights are kept from it (global_lights off, the
     * default inside a group) */
    int light_group;
    int no_global_lights;
    /* uv_mapping (appended, issue 5): textures are evaluated at <u, v, 0>
     * of the surface (accel_hit.uv: POV-Ray's UVCoord) and are not moved by
     * the object's transforms (1; 2: inherited by a CSG member, whose own
     * texture the CSG's transforms still move, as POV-Ray sets the flag only
     * after parsing) */
    int uv_mapping;
    /* photons { } (appended, issue 6): NULL = none; a block on a CSG is
     * copied by the parser to its members that have none */
    const scene_obj_photons *photons;
};

/* ---------------------------------------------------------------- lights */
typedef enum { LIGHT_POINT, LIGHT_SPOT, LIGHT_CYLINDER, LIGHT_PARALLEL } light_kind;

typedef struct {
    light_kind kind;
    src_loc loc;
    vec3 position;
    rgb colour;
    vec3 point_at;          /* spot, cylinder, parallel; default <0,0,1> */
    double radius, falloff, tightness; /* degrees for spot; defaults 30, 45, 0 (3.7 docs) */
    int parallel;           /* `parallel` keyword on a point/spot light */
    /* area light */
    int area;
    vec3 axis1, axis2;
    int size1, size2;
    int adaptive;           /* adaptive level, -1 if not given */
    int jitter, circular, orient;
    int area_illumination;
    /* attenuation */
    double fade_distance;   /* 0 = no fading */
    double fade_power;
    int shadowless;
    int media_interaction, media_attenuation;
    const scene_object *looks_like;
    const scene_object *projected_through; /* appended (issue 5): light only through it (shade_project.c) */
    int group;              /* appended (issue 5): light_group id (lights only its objects), 0 = global */
} scene_light;

/* Whether light l lights object o (POV-Ray 3.7's light groups: a group's
 * lights light only its objects; global lights light everything else, and
 * a group's objects only with global_lights on). */
static inline int scene_light_reaches(const scene_light *l, const scene_object *o)
{
    if (!o) return l->group == 0;
    return l->group ? o->light_group == l->group : !o->no_global_lights;
}

/* Offset of grid point (u, v) of area light l from its position (POV-Ray's
 * layout: points span -axis/2 .. +axis/2, an axis with size 1 contributes
 * nothing; `jitter` moves each by up to half a cell; `circular` maps the
 * square onto a disc). Uses r only when the light jitters. The Whitted
 * pass's area lights (shade_light.c) and the particle GI's (gi_particle_light.c). */
vec3 scene_light_area_point(const scene_light *l, vec3 ax1, vec3 ax2, int u, int v, rng *r);

/* The axes of an `orient` area light l seen along unit dir (from the lit
 * point towards the light): axis1's length on both, turned to face dir
 * (POV-Ray's rule). */
void scene_light_orient_axes(const scene_light *l, vec3 dir, vec3 *ax1, vec3 *ax2);

/* ---------------------------------------------------------------- camera */
typedef enum {
    CAMERA_PERSPECTIVE, CAMERA_ORTHOGRAPHIC, CAMERA_FISHEYE, CAMERA_ULTRA_WIDE_ANGLE,
    CAMERA_OMNIMAX, CAMERA_PANORAMIC, CAMERA_CYLINDER, CAMERA_SPHERICAL,
    CAMERA_MESH /* appended (issue 3): mesh_camera, parsed into the fields below */
} camera_kind;

typedef struct {
    camera_kind kind;
    int cylinder_type;
    src_loc loc;
    /* Final vectors after look_at, angle, sky and transforms, as POV-Ray
     * computes them while parsing: a primary ray through normalised screen
     * coordinates (sx, sy) in [-0.5, 0.5] is direction + sx*right + sy*up. */
    vec3 location, direction, up, right, sky, look_at;
    double angle;           /* horizontal field of view in degrees, 0 = unset */
    double aperture;        /* focal blur, 0 = off */
    int blur_samples;
    vec3 focal_point;
    /* Appended (issue 5, core/camera.h). */
    double v_angle;         /* spherical camera: vertical field of view in degrees, 0 = angle/2 */
    double focal_distance;  /* focal blur: distance to the focal plane; 0 = |direction| */
    const struct scene_normal *normal; /* camera { normal {..} }: perturbs primary rays, NULL = none */
    /* Appended (issue 3): mesh_camera { rays_per_pixel, distribution [, max_distance]
     * mesh { } ... [smooth] } (POV-Ray 3.7); meshes are SHAPE_MESH objects with
     * their transforms. location/direction then hold the mesh camera's offsets. */
    int mesh_rays_per_pixel;
    int mesh_distribution;  /* 0..3 */
    double mesh_max_distance; /* 0 = none */
    int mesh_smooth;
    int nmeshes;
    const struct scene_object *const *meshes;
} scene_camera;

/* ---------------------------------------------------------------- global settings */
typedef struct {
    int enabled;            /* a radiosity{} block was present */
    int count;              /* default 35 */
    int recursion_limit;    /* default 2 */
    double error_bound;     /* default 1.8 */
    double pretrace_start, pretrace_end; /* 0.08, 0.04 */
    int nearest_count;      /* default 5 */
    double brightness;      /* default 1 */
    double gray_threshold;
    double low_error_factor;
    double minimum_reuse;
    int always_sample;
    int normal, media;
    /* The rest of POV-Ray 3.7's radiosity keywords (appended). */
    double adc_bailout;     /* default 0.01 */
    double max_sample;      /* default -1 = no limit */
    double maximum_reuse;   /* default 0.2 */
    int direction_pool;     /* "count N, M": M, default max(1600, count) */
    int nearest_count_pretrace; /* "nearest_count N, M": M (adaptive pretrace), default 0 */
    int subsurface;
} scene_radiosity;

typedef struct {
    double assumed_gamma;   /* 0 = not given */
    rgb ambient_light;      /* default <1,1,1> */
    int max_trace_level;    /* default 5 */
    double adc_bailout;     /* default 1/255 */
    int max_intersections;
    scene_radiosity radiosity;
    int photons;            /* a photons{} block was present */
    double photons_spacing;
    int photons_count;
    double irid_wavelength[3];
    int noise_generator;    /* default 2 */
    int number_of_waves;    /* appended (issue 5): ripples/waves sources, 0 = POV-Ray's 10 */
} scene_global;

/* ---------------------------------------------------------------- the scene */
typedef struct {
    arena *mem;
    scene_global global;
    scene_camera camera;
    int camera_set;
    colour5 background;     /* default black */
    int nobjects, cap_objects;
    scene_object **objects; /* top-level objects */
    int nlights, cap_lights;
    scene_light *lights;
    scene_texture default_texture;
    int version_major, version_minor; /* from #version; 0 if absent */
    int nfiles;             /* files read (scene + includes) */
    double clock;
    /* Appended (scene_pattern.h): atmosphere. */
    const scene_fog *fogs;  /* linked through `next`; NULL = none */
    const scene_sky_sphere *sky_sphere; /* NULL = none */
    const scene_rainbow *rainbows;      /* appended (issue 5): linked through `next` */
    scene_image *images;    /* every image the scene references (image_map...), to load */
    int natmosphere;        /* appended (issue 5): atmospheric media { } statements in order */
    const scene_media *const *atmosphere;
} scene;

scene *scene_new(void);
void scene_free(scene *s);
/* Defaults as POV-Ray 3.7 documents them. */
void scene_default_finish(scene_finish *f);
void scene_default_pigment(scene_pigment *p);
void scene_default_camera(scene_camera *c);
void scene_default_light(scene_light *l);
void scene_default_global(scene_global *g);
void scene_default_interior(scene_interior *i);
scene_object *scene_new_object(scene *s, shape_kind kind, src_loc loc);
scene_texture *scene_new_texture(scene *s);
scene_mesh *scene_new_mesh(scene *s);
pt_status scene_add_object(scene *s, scene_object *o);
pt_status scene_add_light(scene *s, const scene_light *l);

/* Counting helpers for `partray parse` and stats. */
typedef struct {
    long objects;     /* leaf objects (CSG children counted) */
    long csg;         /* CSG nodes */
    long triangles;   /* triangle + mesh triangles */
    long meshes;
    long lights;
    long unsupported;
} scene_counts;
scene_counts scene_count(const scene *s);

/* Camera ray for pixel position (px, py) in [0,w)x[0,h), pixel centres at .5,
 * every camera type (core/camera.h; where a camera traces no ray, e.g.
 * outside a fisheye's circle, this gives the camera's direction: use
 * camera_ray to know). Direction is normalised. */
void scene_camera_ray(const scene_camera *c, double px, double py, int w, int h, vec3 *org, vec3 *dir);

#endif
