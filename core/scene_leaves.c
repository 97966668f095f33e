/* scene_leaves.c - leaf enumeration and object hashes (see scene_leaves.h). */
#include "scene_leaves.h"
#include <stdlib.h>
#include <string.h>
#include "hash.h"

struct scene_leaves {
    const scene_object **leaf;
    int *top;                 /* top-level object of each leaf */
    int n, cap;
    /* pointer -> leaf index, open addressing */
    const scene_object **key;
    int *val;
    unsigned mask;
};

static int leaves_push(scene_leaves *L, const scene_object *o, int top)
{
    if (L->n == L->cap) {
        int nc = L->cap ? 2 * L->cap : 64;
        const scene_object **nl = realloc(L->leaf, sizeof *nl * (size_t)nc);
        if (!nl) return 0;
        L->leaf = nl;
        int *nt = realloc(L->top, sizeof *nt * (size_t)nc);
        if (!nt) return 0;
        L->top = nt;
        L->cap = nc;
    }
    L->leaf[L->n] = o;
    L->top[L->n] = top;
    L->n++;
    return 1;
}

int scene_object_is_csg(const scene_object *o)
{
    return o->kind == SHAPE_UNION || o->kind == SHAPE_MERGE || o->kind == SHAPE_INTERSECTION || o->kind == SHAPE_DIFFERENCE;
}

int scene_object_any(const scene_object *o, int (*pred)(const scene_object *o))
{
    if (pred(o)) return 1;
    if (scene_object_is_csg(o))
        for (int i = 0; i < o->u.csg.nkids; i++)
            if (scene_object_any(o->u.csg.kids[i], pred)) return 1;
    return 0;
}

static int leaves_walk(scene_leaves *L, const scene_object *o, int top)
{
    if (scene_object_is_csg(o)) {
        for (int i = 0; i < o->u.csg.nkids; i++)
            if (!leaves_walk(L, o->u.csg.kids[i], top)) return 0;
        return 1;
    }
    return leaves_push(L, o, top);
}

static int leaves_make(scene_leaves *L, const scene *sc)
{
    for (int i = 0; i < sc->nobjects; i++)
        if (!leaves_walk(L, sc->objects[i], i)) return 0;
    unsigned sz = 16;
    while (sz < 2u * (unsigned)L->n + 16u) sz <<= 1;
    L->mask = sz - 1;
    L->key = calloc(sz, sizeof *L->key);
    L->val = malloc(sizeof *L->val * sz);
    if (!L->key || !L->val) return 0;
    for (int i = 0; i < L->n; i++) {
        unsigned k = pt_ptr_hash(L->leaf[i]) & L->mask;
        while (L->key[k] && L->key[k] != L->leaf[i]) k = (k + 1) & L->mask;
        if (!L->key[k]) {
            L->key[k] = L->leaf[i];
            L->val[k] = i;
        }
    }
    return 1;
}

int scene_leaves_find(const scene_leaves *L, const scene_object *o)
{
    if (!o) return -1;
    unsigned k = pt_ptr_hash(o) & L->mask;
    while (L->key[k]) {
        if (L->key[k] == o) return L->val[k];
        k = (k + 1) & L->mask;
    }
    return -2;
}

void scene_leaves_free(scene_leaves *L)
{
    if (!L) return;
    free(L->leaf);
    free(L->top);
    free(L->key);
    free(L->val);
    free(L);
}


uint64_t scene_object_hash(uint64_t h, const scene_object *o, int *opaque)
{
    h = pt_fnv1a(h, &o->kind, sizeof o->kind);
    h = pt_fnv1a(h, o->transform.m, sizeof o->transform.m);
    h = pt_fnv1a(h, &o->flags, sizeof o->flags);
    switch (o->kind) {
    case SHAPE_SPHERE: h = pt_fnv1a(h, &o->u.sphere, sizeof o->u.sphere); break;
    case SHAPE_BOX: h = pt_fnv1a(h, &o->u.box, sizeof o->u.box); break;
    case SHAPE_PLANE: h = pt_fnv1a(h, &o->u.plane, sizeof o->u.plane); break;
    case SHAPE_TRIANGLE:
    case SHAPE_SMOOTH_TRIANGLE: h = pt_fnv1a(h, &o->u.triangle, sizeof o->u.triangle); break;
    case SHAPE_CYLINDER:
    case SHAPE_CONE: h = pt_fnv1a(h, &o->u.cone, sizeof o->u.cone); break;
    case SHAPE_DISC: h = pt_fnv1a(h, &o->u.disc, sizeof o->u.disc); break;
    case SHAPE_TORUS: h = pt_fnv1a(h, &o->u.torus, sizeof o->u.torus); break;
    case SHAPE_SUPERELLIPSOID: h = pt_fnv1a(h, &o->u.superellipsoid, sizeof o->u.superellipsoid); break;
    case SHAPE_QUADRIC: h = pt_fnv1a(h, &o->u.quadric, sizeof o->u.quadric); break;
    case SHAPE_OVUS: h = pt_fnv1a(h, &o->u.ovus, sizeof o->u.ovus); break;
    case SHAPE_MESH: {
        const scene_mesh *m = o->u.mesh.mesh;
        if (!m) break;
        h = pt_fnv1a(h, &m->nverts, sizeof m->nverts);
        h = pt_fnv1a(h, &m->ntris, sizeof m->ntris);
        if (m->verts) h = pt_fnv1a(h, m->verts, sizeof *m->verts * (size_t)m->nverts);
        if (m->tris) h = pt_fnv1a(h, m->tris, sizeof *m->tris * (size_t)m->ntris);
        if (m->normals) h = pt_fnv1a(h, m->normals, sizeof *m->normals * (size_t)m->nnormals);
        break;
    }
    case SHAPE_UNION:
    case SHAPE_MERGE:
    case SHAPE_INTERSECTION:
    case SHAPE_DIFFERENCE:
        h = pt_fnv1a(h, &o->u.csg.nkids, sizeof o->u.csg.nkids);
        for (int i = 0; i < o->u.csg.nkids; i++) h = scene_object_hash(h, o->u.csg.kids[i], opaque);
        break;
    default: *opaque = 1; break;
    }
    if (o->clip) h = scene_object_hash(h ^ 0x636c6970ULL, o->clip, opaque);
    if (o->bound) h = scene_object_hash(h ^ 0x626f756eULL, o->bound, opaque);
    return h;
}

scene_leaves *scene_leaves_new(const scene *sc)
{
    scene_leaves *L = calloc(1, sizeof *L);
    if (!L) return NULL;
    if (!leaves_make(L, sc)) {
        scene_leaves_free(L);
        return NULL;
    }
    return L;
}

int scene_leaves_count(const scene_leaves *L) { return L->n; }
const scene_object *scene_leaves_get(const scene_leaves *L, int i) { return L->leaf[i]; }
int scene_leaves_top(const scene_leaves *L, int i) { return L->top[i]; }

int scene_object_finite(const scene_object *o)
{
    if (scene_object_is_csg(o)) {
        for (int i = 0; i < o->u.csg.nkids; i++)
            if (!scene_object_finite(o->u.csg.kids[i])) return 0;
        return 1;
    }
    switch (o->kind) {
    case SHAPE_SPHERE: case SHAPE_BOX: case SHAPE_TRIANGLE: case SHAPE_SMOOTH_TRIANGLE: case SHAPE_MESH:
    case SHAPE_CYLINDER: case SHAPE_CONE: case SHAPE_DISC: case SHAPE_TORUS: case SHAPE_SUPERELLIPSOID:
    case SHAPE_OVUS: return 1;
    default: return 0;
    }
}
