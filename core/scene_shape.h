/* scene_shape.h - the scene IR's objects: shape kinds, each
 * shape's data, meshes, CSG and the object record (scene.h). */
#ifndef PT_SCENE_SHAPE_H
#define PT_SCENE_SHAPE_H
#include "diag.h"
#include "scene_material.h"

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
    /* uv_vectors: uv indices per triangle into `uvs`
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
    /* POV-Ray's further shapes: their data live in
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

/* ---------------------------------------------------------------- further shapes
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
 * the threshold. The function is core/func.h's scene_function; env the
 * evaluators it may call (POV-Ray noise, pigment functions: the parse's
 * sdl_options.func_env), NULL: core/func.h's own functions only (then a
 * function needing more is NaN and the isosurface empty). */
typedef struct {
    const struct scene_function *fn;
    const struct func_env *env;
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
 * `reflection on|off`, `refraction on|off` (POV-Ray keeps an "on" and an
 * "off" flag each: neither set means "as the light says", see
 * scene_photon_lobe in scene_light.h), `collect off` (photons are not
 * stored on it), `pass_through [on|off]`. */
typedef struct {
    src_loc loc;            /* the `photons` keyword */
    int target;
    double spacing;         /* target's multiplier of the global spacing */
    int reflection, refraction;         /* said on */
    int reflection_off, refraction_off; /* said off */
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
    /* The identity of POV-Ray's Interior this object uses, which a ray's
     * list of containers compares (shade_media.h): its own interior, else
     * the one its CSG parent's key names (the same Interior in POV-Ray's
     * Post_Process, also where a member carries a copy rebased for its
     * media), else the top-level object, whose default interior POV-Ray
     * shares with its members. NULL: the interior, else the object. */
    const void *medium;
    unsigned flags;
    union {
        struct { vec3 centre; double radius; } sphere;
        struct { vec3 c1, c2; } box;            /* c1 <= c2 component-wise */
        struct { vec3 normal; double offset; } plane; /* points p with n.p = offset */
        struct { vec3 v[3]; vec3 n[3]; } triangle;   /* n used for smooth_triangle */
        /* textures: this object's copies of the mesh's texture_list
         * (mesh->ntextures entries, NULL without a list), moved by the
         * object's own transforms as POV-Ray moves a mesh's textures with
         * it; read them through scene_mesh_tri_texture */
        struct { const scene_mesh *mesh; int inside_vector_set; vec3 inside_vector; const scene_texture **textures; } mesh;
        struct { scene_object **kids; int nkids; } csg;
        struct { vec3 base, cap; double base_radius, cap_radius; } cone; /* cylinder: equal radii */
        struct { vec3 centre, normal; double radius, hole_radius; } disc;
        struct { double major, minor; } torus;
        /* the further shapes */
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
    /* clipped_by: the clipping solid, its transform relative to
     * this object's space (world = clip->transform then this->transform), so
     * later transforms of the object move it along. NULL = none. */
    const scene_object *clip;
    /* bounded_by: a SHAPE_UNION node named "bounded_by" whose kids
     * are the bounding objects, transforms relative to this object as for
     * clip. A ray sees the object only if it meets every bounding object (at
     * any distance ahead) or starts inside it (POV-Ray's Ray_In_Bound).
     * NULL = none. */
    const scene_object *bound;
    /* light_group: the innermost group holding the
     * object (0 none; lights with that `group` light it) and whether
     * the scene's global lights are kept from it (global_lights off, the
     * default inside a group) */
    int light_group;
    int no_global_lights;
    /* uv_mapping: textures are evaluated at <u, v, 0>
     * of the surface (accel_hit.uv: POV-Ray's UVCoord) and are not moved by
     * the object's transforms (1; 2: inherited by a CSG member, whose own
     * texture the CSG's transforms still move, as POV-Ray sets the flag only
     * after parsing) */
    int uv_mapping;
    /* photons { }: NULL = none; a block on a CSG is
     * copied by the parser to its members that have none */
    const scene_obj_photons *photons;
};

/* The texture_list entry of triangle t of mesh object o (its per-object
 * copy), NULL when the triangle names none: the object's texture applies. */
const scene_texture *scene_mesh_tri_texture(const scene_object *o, int t);

#endif
