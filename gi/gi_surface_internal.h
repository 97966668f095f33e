/* gi_surface_internal.h - the surface patches' records, shared by the files
 * of gi_surface (gi_surface.c: patches from the scene's objects, access;
 * gi_surface_csg.c: CSG members; gi_surface_mesh.c: grids of implicit
 * shapes; gi_surface_layout.c: radiance particles shared between patches,
 * and locating hits among them). Not for use outside them. */
#ifndef PT_GI_SURFACE_INTERNAL_H
#define PT_GI_SURFACE_INTERNAL_H
#include <stdint.h>
#include "geom_shape.h"
#include "accel_surface.h"
#include "geom_csg.h"
#include "geom_tess.h"
#include "hash.h"
#include "gi_surface.h"

/* PATCH_PIECE: a surface sampled through accel_surface (or, as a member of
 * CSG, by its own Crofton sampler); the implicit shapes among them get
 * radiance particles at the vertices of a marching-tetrahedra grid (mesh). */
enum { PATCH_TRI = 0, PATCH_SPHERE = 1, PATCH_DISC = 2, PATCH_PIECE = 3 };

typedef struct {
    unsigned char kind;
    unsigned char nsides;
    unsigned char probe;
    int obj;          /* object record */
    int k;            /* TRI: edge subdivisions */
    int nu, nv;       /* grids */
    long slot_first;  /* radiance-particle slots of side s: slot_first + s * rp_count + local */
    long rp_count;    /* slots per side (radiance particles before sharing: gi_surface_layout) */
    double area;      /* one side, world */
    vec3 v0, e1, e2;  /* TRI */
    vec3 nrm;         /* TRI: unit front normal */
    /* grids, object space: sphere centre c, radius r; disc centre c, normal n, radii */
    vec3 c, gn, ga, gb;
    double r0, r1;    /* sphere: r, -; disc: hole, outer */
    double lu, lv;    /* TRI: longest edge; grids: longest u and v lines */
    double jmax, jmin, jobj, detm;
    int piece;        /* accel_surface piece, -1 if none; PIECE: the first of npieces */
    int npieces;      /* PIECE: consecutive accel_surface pieces of the object */
    long cdf0;        /* PIECE with npieces > 1: their cumulative areas at cdf[cdf0..] */
    const scene_texture *tex;
    unsigned char mask; /* sides that get particles (bit s: side s); CSG members: the visible one */
    int cnode;        /* CSG member: its index in gi_surface.cm, -1 otherwise */
    /* PIECE: the shape (for its grid) and, for CSG members, its own sampler */
    geom_shape *sh;
    int own_sh;
    struct keep_sampler *ks;
    /* PIECE with a grid: vertices mv[vfirst .. vfirst + rp_count), triangles mt[tfirst .. tfirst + nt) */
    long vfirst, tfirst, nt;
    double cell;      /* locate hash cell */
} patch;

/* What gi_surface_locate reads of a patch, packed apart from the patch
 * records (392 bytes, the hot fields spread over 3-4 cache lines): a
 * lookup on a mesh triangle touches the 2 lines of one 128-byte record
 * (maze: 242,160 triangles, 95 MB of patches, 31 MB of these). Copies of
 * the patch's own values (rs: sqrt(area) + 1e-300 as locate divides by),
 * so locate computes bit for bit what it did from the patches. */
typedef struct {
    vec3 v0, e1, e2, nrm;
    double rs;
    long slot_first;
    int k, rp_count;
    unsigned char kind, nsides;
} tri_loc;
_Static_assert(sizeof(tri_loc) == 128, "tri_loc: two cache lines (aligned_alloc size)");

/* A member of a CSG tree with particles: its tree (gi_surface.ct), its
 * leaf node and shape there. */
typedef struct {
    int tree, node, shape;
} csg_member;

typedef struct keep_sampler {
    geom_tess_sampler cs;
    const struct gi_surface *g;
    int node;
} keep_sampler;

typedef struct {
    uint64_t key;
    long tri;
} cell_entry;

typedef struct {
    const scene_object *obj;
    int first, count; /* patches */
    int kind;         /* shape_kind */
} obj_rec;

struct gi_surface {
    patch *p;
    int np, capp;
    obj_rec *o;
    int no, capo;
    float *view;      /* per object record: the fraction of the view's probe rays that hit it first */
    int *hash;        /* open addressing: object pointer -> record, -1 empty */
    int hcap;
    long nrp;
    long skipped;
    double total_area;
    double tess;
    vec3 lo, hi;      /* clip box for planes */
    const scene *sc;
    diag *d;
    accel_surf *as;   /* area sampling shared with reference/ (accel_surface.h) */
    double *cdf;      /* PIECE patches of several pieces (polygons, height fields) */
    long ncdf, capcdf;
    geom_csg *ct;     /* CSG trees (geom_csg_build) of the objects walked with the CSG rule */
    int nct, capct;
    csg_member *cm;   /* their members (gi_surface_csg_keep) */
    int ncm, capcm;
    int cur_node;     /* while walking CSG members: the member's index in cm, else -1 */
    unsigned char cur_mask;
    /* grids of implicit shapes (PIECE patches): world vertices and normals,
     * triangles (local vertex indices), and the locate hash (sorted cells) */
    vec3 *mv, *mn;
    long nmv, capmv;
    int (*mt)[3];
    int *mtp;         /* patch of each triangle */
    long nmt, capmt;
    cell_entry *ce;
    long nce;
    /* radiance particles shared between patches (gi_surface_layout): every patch side
     * lays out rp_count slots; slot_rp maps a slot to its radiance
     * particle, rp_slot a radiance particle to its first slot (NULL: one
     * particle per slot, as when the map could not be allocated) */
    long nslot;
    int *slot_rp, *rp_slot;
    int *rp_patch;    /* the patch of each radiance particle's first slot (NULL: slot_patch searches) */
    tri_loc *tl;      /* np records (gi_surface_layout), NULL when out of memory: locate reads the patches */
};

/* Building patches (gi_surface.c). */
int gi_surface_add_patch(gi_surface *g, const patch *p);                  /* its index, -1: no memory */
int gi_surface_add_obj(gi_surface *g, const scene_object *o);             /* its record, -1: no memory */
void gi_surface_free_patch(patch *p);
/* Patches of one object that is not CSG (probe: its particles are probed
 * against the scene, as CSG members' are). */
pt_status gi_surface_add_leaf(gi_surface *g, const scene_object *o, const scene_texture *tex, int probe);
const obj_rec *gi_surface_find_obj(const gi_surface *g, const scene_object *o);
/* Point and front (outward) normal of a grid patch at (u, v); world. */
void gi_surface_grid_eval(const gi_surface *g, const patch *p, double u, double v, vec3 *pos, vec3 *nrm);
/* Sub-tessellation / grid resolution from the tessellation bound. */
void gi_surface_set_resolution(const gi_surface *g, patch *p);
/* Cells for a length at the tessellation bound tess: ceil(len / tess)
 * within [lo, hi]. */
int gi_surface_grid_count(double len, double tess, int lo, int hi);
/* Shapes whose radiance particles are the vertices of their grid. */
int gi_surface_has_grid(shape_kind k);

/* CSG members (gi_surface_csg.c). */
/* Walks CSG object o as one tree of members with the CSG rule and returns 1
 * (the result in *status); 0 when o is to be walked as a union. */
int gi_surface_csg_walk(gi_surface *g, const scene_object *o, const scene_texture *tex, pt_status *status);
/* A PIECE-kind member of CSG (g->cur_node): sampled by Crofton lines over
 * its own shape, keeping the crossings on the result's surface; its area
 * is estimated by gi_surface_csg_finish. */
pt_status gi_surface_csg_add_piece(gi_surface *g, const scene_object *o, const scene_texture *tex);
/* After the walk: the areas of those members on `threads` threads (the
 * same for any count); members with none on the result's surface are
 * removed with their object records, as if never added. */
pt_status gi_surface_csg_finish(gi_surface *g, int threads);
/* Is world point p (on the surface of member `node`) on the CSG result's surface? */
int gi_surface_csg_keep(const gi_surface *g, int node, vec3 p);
/* Frees the trees. */
void gi_surface_csg_free(gi_surface *g);

/* Grids of implicit shapes (gi_surface_mesh.c). */
void gi_surface_build_meshes(gi_surface *g);
/* The grid triangle of PIECE patch pi nearest to q: its index, or -1. */
long gi_surface_mesh_locate(const gi_surface *g, int pi, vec3 q, vec3 ng, double w[3]);

/* Radiance particles' slots and their sharing (gi_surface_layout.c); builds
 * the grids first. */
void gi_surface_layout(gi_surface *g);
#endif
