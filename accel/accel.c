/* accel.c - the Embree 3 scene built from the scene IR.
 *
 * Layout of the Embree scene (the root RTCScene):
 *   - up to two triangle geometries holding every triangle, smooth_triangle
 *     and once-used mesh, flattened into world space (float vertices): one for
 *     objects that cast shadows, one for no_shadow objects. A per-primitive
 *     table leads back to the leaf object and the triangle index within it.
 *   - one user geometry (RTC_GEOMETRY_TYPE_USER) whose primitives are the
 *     analytic shapes (geom_shape.c), intersected exactly in double
 *     precision, followed by one primitive per CSG intersection, difference
 *     or merge (geom_csg.c; unions are flattened, and a CSG with a mesh
 *     member falls back to a union with a warning).
 *   - one instance geometry per object that references a shared mesh: a mesh
 *     used by more than one object is built once as its own RTCScene in
 *     object space and placed with the object's transform.
 *
 * no_shadow: accel_occluded must ignore such objects. We use Embree's
 * occlusion filter callbacks (rtcSetGeometryOccludedFilterFunction): the
 * no_shadow triangle geometry rejects every occlusion candidate; a shared
 * mesh with at least one no_shadow instance rejects candidates whose instance
 * is no_shadow (hit instID); user geometry checks the flag in its own occluded
 * callback. Intersection queries run no filter at all, and geometries without
 * no_shadow objects carry no filter, so the common path pays nothing. (Ray
 * masks would also do, but they are an optional Embree build feature.)
 *
 * Epsilon rule (self-intersection): a ray's effective tmin is
 *   max(tmin, ACCEL_EPS_REL * (accel_eps_scale + max|org_i|) / |dir|)
 * i.e. a distance of 1e-5 of the working scale (the median of the leaf
 * objects' bounding-box diagonals, not the scene diagonal, so that one far
 * object does not make the epsilon larger than the room's details) plus
 * 1e-5 of the origin's magnitude. Embree intersects triangles in single precision with the origin
 * rounded to float (relative error 6e-8), so a ray leaving a surface sits up
 * to about one float ulp of |org| off it, and a spurious re-hit lies at a
 * distance of that offset / sin(angle to the surface). The rule covers angles
 * down to about 0.3 degrees (a relative 1e-6 is too small: float hit points
 * then shadow themselves at grazing angles of a few degrees) while losing only contacts
 * closer than 1e-5 of the scene size, and it scales with the scene, so the
 * same scene scaled by 1e-4 or 1e5 behaves identically. A scene of
 * closed-form shapes only takes 1e-3 of the working scale in the scale term
 * (ACCEL_EXACT_EPS_FACTOR, at build below). Analytic shapes are
 * intersected in double precision from the caller's double ray (passed to
 * the callbacks through an extended intersect context), triangle hit
 * distances are refined in double against the triangle's plane.
 *
 * Infinite planes: user geometry needs finite bounds. A plane is clipped to a
 * cube centred on the scene's extent E (finite geometry, camera location,
 * light positions) with half-size PLANE_EXTENT_FACTOR * max(diag(E),
 * distance from E's centre to the plane). Beyond 1e4 scene sizes the plane
 * subtends less than 1e-4 rad seen from inside the scene, below a pixel at
 * any usual resolution, and the bounds stay well inside float range so the
 * BVH is not degraded (the plane sits near the root of the user-geometry BVH
 * and triangles live in their own BVH). Hits outside the cube are rejected,
 * so the answer does not depend on how the BVH culls. */
#include "accel.h"
#include "grow.h"
#include "accel_internal.h"

_Thread_local accel_query *accel_tls_query;

static void leaf_diag(accel *a, vec3 lo, vec3 hi);

/* ------------------------------------------------------------ errors */

static void on_embree_error(void *user, enum RTCError code, const char *str)
{
    accel *a = user;
    int expected = 0;
    if (atomic_compare_exchange_strong(&a->err, &expected, (int)code ? (int)code : -1))
        snprintf(a->errmsg, sizeof a->errmsg, "%s", str ? str : "unknown error");
}

static const char *rtc_error_name(enum RTCError e)
{
    switch (e) {
    case RTC_ERROR_NONE: return "no error";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
    default: return "unknown error";
    }
}

/* Non-zero when Embree reported an error; records it in `d`. */
static int embree_failed(accel *a, diag *d, const char *stage)
{
    enum RTCError e = rtcGetDeviceError(a->dev);
    int cb = atomic_load(&a->err);
    if (e == RTC_ERROR_NONE && cb == 0) return 0;
    src_loc nowhere = {0};
    diag_report(d, DIAG_ERROR, nowhere, NULL, "Embree failed while %s: %s%s%s", stage,
                rtc_error_name(e != RTC_ERROR_NONE ? e : (enum RTCError)cb), cb ? ": " : "", cb ? a->errmsg : "");
    return 1;
}

/* ------------------------------------------------------------ build helpers */

/* Whether a pigment, normal or texture evaluates anything at the hit's UV
 * (uv_mapping in it or in its maps); deep nesting counts as yes. */
static int texture_uses_uv(const scene_texture *t, int depth);
static int pigment_uses_uv(const scene_pigment *pg, int depth);

static int map_uses_uv(const scene_blend_map *m, int depth)
{
    if (!m) return 0;
    for (int i = 0; i < m->n; i++) {
        const scene_map_entry *e = &m->e[i];
        if (e->pigment && pigment_uses_uv(e->pigment, depth + 1)) return 1;
        if (e->normal && e->normal->pat && (e->normal->pat->uv_mapping || map_uses_uv(e->normal->map, depth + 1)))
            return 1;
        if (e->texture && texture_uses_uv(e->texture, depth + 1)) return 1;
    }
    return 0;
}

static int pigment_uses_uv(const scene_pigment *pg, int depth)
{
    if (depth > 12) return 1;
    const scene_pattern *pat = pg->pat;
    if (!pat) return 0;
    if (pat->uv_mapping) return 1;
    if (pat->pigment && pigment_uses_uv(pat->pigment, depth + 1)) return 1;
    return map_uses_uv(pg->map, depth);
}

static int texture_uses_uv(const scene_texture *t, int depth)
{
    if (depth > 12) return 1;
    for (; t; t = t->next) {
        if (t->uv_mapping || (t->pat && t->pat->uv_mapping)) return 1;
        if (pigment_uses_uv(&t->pigment, depth + 1)) return 1;
        if (t->normal && t->normal->pat && (t->normal->pat->uv_mapping || map_uses_uv(t->normal->map, depth + 1)))
            return 1;
        if (map_uses_uv(t->map, depth)) return 1;
    }
    return 0;
}

/* Whether a shape's hits are found in closed form in double precision
 * (quadratic or linear equations, no float vertices, no iteration): such a
 * hit point lies on its surface to double rounding. Containers hold no
 * surface of their own. */
static int shape_closed_form(shape_kind k)
{
    switch (k) {
    case SHAPE_SPHERE: case SHAPE_BOX: case SHAPE_PLANE: case SHAPE_CYLINDER: case SHAPE_CONE: case SHAPE_DISC:
    case SHAPE_QUADRIC: case SHAPE_POLYGON: case SHAPE_UNION: case SHAPE_MERGE: case SHAPE_INTERSECTION:
    case SHAPE_DIFFERENCE: return 1;
    default: return 0;
    }
}

static int add_leaf(accel *a, const scene_object *o, const scene_texture *tex, unsigned flags)
{
    if (a->nleaves == a->capleaves) {
        size_t cap = (size_t)a->capleaves;
        if (!grow_array((void **)&a->leaves, &cap, (size_t)a->nleaves + 1, sizeof(accel_leaf))) return -1;
        a->capleaves = (int)cap;
    }
    accel_leaf *l = &a->leaves[a->nleaves];
    l->obj = o;
    l->texture = tex ? tex : &a->s->default_texture;
    l->flags = flags;
    const double(*m)[4] = o->transform.m;
    double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                 m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    l->wind = det < 0.0 ? -1.0 : 1.0;
    l->identity = xform_is_identity(&o->transform);
    l->in_csg = 0;
    if (!shape_closed_form(o->kind)) a->inexact_leaves++;
    l->group = -1;
    l->b0 = l->bn = 0;
    l->want_uv = o->uv_mapping || texture_uses_uv(l->texture, 0) || (o->interior_texture && texture_uses_uv(o->interior_texture, 0));
    return a->nleaves++;
}


/* ------------------------------------------------------------ CSG */

/* geom_csg_build's leaf callback: the member's leaf record. */
static int csg_leaf(void *ctx, const scene_object *o, const scene_texture *tex, unsigned flags)
{
    accel *a = ctx;
    int li = add_leaf(a, o, tex, flags);
    if (li >= 0) a->leaves[li].in_csg = 1;
    return li;
}

/* An intersection or difference (with everything below it) becomes one
 * user primitive. */
static pt_status build_csg(accel *a, diag *d, const scene_object *o, const scene_texture *ptex, unsigned pflags,
                           int depth)
{
    if (a->ncsgs == a->capcsgs) {
        size_t cap = (size_t)a->capcsgs;
        if (!grow_array((void **)&a->csgs, &cap, (size_t)a->ncsgs + 1, sizeof(geom_csg))) return PT_ERR_NOMEM;
        a->capcsgs = (int)cap;
    }
    geom_csg *c = &a->csgs[a->ncsgs];
    memset(c, 0, sizeof *c);
    c->flags = o->flags | (pflags & INHERITED_FLAGS);
    int cb0 = 0, cbn = 0;
    if (!accel_collect_bounds(a, d, o, accel_keeps_bound(o, depth == 0), &cb0, &cbn))
        return PT_ERR_NOMEM;
    {
        size_t cap = (size_t)a->capcsgs;
        int *n0 = realloc(a->csg_b0, cap * sizeof *n0);
        if (!n0) return PT_ERR_NOMEM;
        a->csg_b0 = n0;
        int *n1 = realloc(a->csg_bn, cap * sizeof *n1);
        if (!n1) return PT_ERR_NOMEM;
        a->csg_bn = n1;
        a->csg_b0[a->ncsgs] = cb0;
        a->csg_bn[a->ncsgs] = cbn;
    }
    geom_csg_builder b = {csg_leaf, a, INHERITED_FLAGS, 0, d, 0};
    pt_status st = geom_csg_build(c, o, ptex, pflags, -1, depth, &b);
    a->stats.unsupported += b.unsupported;
    if (st != PT_OK) {
        geom_csg_free(c);
        return st;
    }
    if (!geom_csg_finish(c)) { /* provably empty */
        geom_csg_free(c);
        return PT_OK;
    }
    a->ncsgs++;
    if (v3_finite(c->lo) && v3_finite(c->hi)) {
        a->lo = v3_min(a->lo, c->lo);
        a->hi = v3_max(a->hi, c->hi);
        leaf_diag(a, c->lo, c->hi);
    }
    return PT_OK;
}

static pt_status collect(accel *a, diag *d, const scene_object *o, const scene_texture *ptex, unsigned pflags,
                         int depth)
{
    if (!o) return PT_OK;
    const scene_texture *tex = o->texture ? o->texture : ptex;
    unsigned flags = o->flags | (pflags & INHERITED_FLAGS);
    if (o->clip && o->kind != SHAPE_UNSUPPORTED) {
        /* clipped_by: one CSG primitive (exact) unless meshes are involved */
        if (depth >= GEOM_CSG_MAX_DEPTH) {
            diag_report(d, DIAG_ERROR, o->loc, NULL, "CSG nesting deeper than %d levels", GEOM_CSG_MAX_DEPTH);
            return PT_ERR_LIMIT;
        }
        if (!geom_csg_has_mesh(o, depth) && !geom_csg_has_mesh(o->clip, depth)) return build_csg(a, d, o, ptex, pflags, depth);
        diag_warn_once(d, o->loc, "clipped_by with a mesh is not evaluated yet: the object is not clipped");
    }
    switch (o->kind) {
    case SHAPE_INTERSECTION:
    case SHAPE_DIFFERENCE: {
        if (depth >= GEOM_CSG_MAX_DEPTH) {
            diag_report(d, DIAG_ERROR, o->loc, NULL, "CSG nesting deeper than %d levels", GEOM_CSG_MAX_DEPTH);
            return PT_ERR_LIMIT;
        }
        if (!geom_csg_has_mesh(o, depth)) return build_csg(a, d, o, ptex, pflags, depth);
        diag_warn_once(d, o->loc,
                       "CSG intersection/difference with a mesh member is not evaluated yet: its parts are rendered as a union");
    }
        /* fall through */
    case SHAPE_MERGE:
        /* merge drops the members' internal surfaces (matters for
         * transparency): evaluated as a CSG primitive while small */
        if (depth < GEOM_CSG_MAX_DEPTH && !geom_csg_has_mesh(o, depth) && geom_csg_leaf_count(o, depth) <= GEOM_CSG_MAX_MERGE)
            return build_csg(a, d, o, ptex, pflags, depth);
        diag_warn_once(d, o->loc, "merge with a mesh or more than %d members keeps its internal surfaces",
                       GEOM_CSG_MAX_MERGE);
        /* fall through */
    case SHAPE_UNION: {
        if (depth >= GEOM_CSG_MAX_DEPTH) {
            diag_report(d, DIAG_ERROR, o->loc, NULL, "CSG nesting deeper than %d levels", GEOM_CSG_MAX_DEPTH);
            return PT_ERR_LIMIT;
        }
        /* the members keep the union's bound */
        const bound_chain *saved = a->cur_chain;
        bound_chain node = {o, saved};
        if (o->bound) a->cur_chain = &node;
        pt_status st = PT_OK;
        for (int i = 0; i < o->u.csg.nkids && st == PT_OK; i++) st = collect(a, d, o->u.csg.kids[i], tex, flags, depth + 1);
        a->cur_chain = saved;
        return st;
    }
    case SHAPE_SPHERE: case SHAPE_BOX: case SHAPE_PLANE: case SHAPE_TRIANGLE: case SHAPE_SMOOTH_TRIANGLE:
    case SHAPE_MESH: case SHAPE_CYLINDER: case SHAPE_CONE: case SHAPE_DISC: case SHAPE_TORUS:
    case SHAPE_POLYGON: case SHAPE_LATHE: case SHAPE_SOR: case SHAPE_PRISM: case SHAPE_SUPERELLIPSOID:
    case SHAPE_QUADRIC: case SHAPE_POLY: case SHAPE_BLOB: case SHAPE_HEIGHT_FIELD: case SHAPE_TEXT: case SHAPE_ISOSURFACE:
    case SHAPE_JULIA: case SHAPE_OVUS: {
        int li = add_leaf(a, o, tex, flags);
        if (li < 0) return PT_ERR_NOMEM;
        if (o->kind != SHAPE_TRIANGLE && o->kind != SHAPE_SMOOTH_TRIANGLE && o->kind != SHAPE_MESH) {
            int b0, bn;
            if (!accel_collect_bounds(a, d, o, accel_keeps_bound(o, depth == 0), &b0, &bn)) return PT_ERR_NOMEM;
            a->leaves[li].b0 = b0;
            a->leaves[li].bn = bn;
        }
        return PT_OK;
    }
    case SHAPE_UNSUPPORTED:
    default:
        a->stats.unsupported++;
        diag_warn_once(d, o->loc, "%s is not rendered yet", o->name ? o->name : "this shape");
        return PT_OK;
    }
}

static void bounds_add(vec3 *lo, vec3 *hi, vec3 p)
{
    if (!v3_finite(p)) return;
    *lo = v3_min(*lo, p);
    *hi = v3_max(*hi, p);
}

/* Records one leaf object's bounding box for the epsilon scale; a failed
 * allocation only leaves that box out. */
static void leaf_diag(accel *a, vec3 lo, vec3 hi)
{
    double dg = v3_len(v3_sub(hi, lo));
    if (!(dg > 0.0) || !isfinite(dg)) return;
    if (a->ndiags == a->capdiags) {
        int nc = a->capdiags ? 2 * a->capdiags : 64;
        double *nd = realloc(a->diags, (size_t)nc * sizeof *nd);
        if (!nd) return;
        a->diags = nd;
        a->capdiags = nc;
    }
    a->diags[a->ndiags++] = dg;
}

static int batch_add_vertex(tri_batch *b, vec3 p)
{
    if (!grow_array((void **)&b->v, &b->capv, (b->nv + 1) * 3, sizeof(float))) return 0;
    b->v[b->nv * 3 + 0] = (float)p.x;
    b->v[b->nv * 3 + 1] = (float)p.y;
    b->v[b->nv * 3 + 2] = (float)p.z;
    b->nv++;
    return 1;
}

static int batch_add_tri(tri_batch *b, unsigned i0, unsigned i1, unsigned i2, unsigned leaf, unsigned local)
{
    if (!grow_array((void **)&b->idx, &b->capi, (b->nt + 1) * 3, sizeof(unsigned))) return 0;
    if (!grow_array((void **)&b->refs, &b->capr, b->nt + 1, sizeof(tri_ref))) return 0;
    b->idx[b->nt * 3 + 0] = i0;
    b->idx[b->nt * 3 + 1] = i1;
    b->idx[b->nt * 3 + 2] = i2;
    b->refs[b->nt].leaf = leaf;
    b->refs[b->nt].local = local;
    b->nt++;
    return 1;
}

static int mesh_tri_ok(const scene_mesh *m, int t)
{
    const int *v = m->tris[t];
    return v[0] >= 0 && v[0] < m->nverts && v[1] >= 0 && v[1] < m->nverts && v[2] >= 0 && v[2] < m->nverts;
}

static vec3 mesh_vert(const scene_mesh *m, int i)
{
    return v3(m->verts[i][0], m->verts[i][1], m->verts[i][2]);
}

static int set_ginfo(accel *a, unsigned id, int kind, unsigned idx)
{
    if (id == RTC_INVALID_GEOMETRY_ID) return 0;
    if (id >= a->nginfo) {
        unsigned nn = a->nginfo ? a->nginfo : 16;
        while (nn <= id) nn *= 2;
        geom_info *g = realloc(a->ginfo, nn * sizeof *g);
        if (!g) return 0;
        memset(g + a->nginfo, 0, (nn - a->nginfo) * sizeof *g);
        a->ginfo = g;
        a->nginfo = nn;
    }
    a->ginfo[id].kind = kind;
    a->ginfo[id].idx = idx;
    if (kind == GEOM_TRI || kind == GEOM_INSTANCE) a->has_tri_geoms = 1;
    return 1;
}


/* ------------------------------------------------------------ geometry */

static pt_status add_flat_triangles(accel *a, diag *d, int li)
{
    const accel_leaf *l = &a->leaves[li];
    const scene_object *o = l->obj;
    tri_batch *b = &a->tri[(l->flags & OBJ_NO_SHADOW) ? 1 : 0];
    const xform *x = &o->transform;
    if (o->kind == SHAPE_TRIANGLE || o->kind == SHAPE_SMOOTH_TRIANGLE) {
        unsigned base = (unsigned)b->nv;
        vec3 tlo = v3s(INFINITY), thi = v3s(-INFINITY);
        for (int k = 0; k < 3; k++) {
            vec3 p = xform_point(x, o->u.triangle.v[k]);
            bounds_add(&a->lo, &a->hi, p);
            bounds_add(&tlo, &thi, p);
            if (!batch_add_vertex(b, p)) return PT_ERR_NOMEM;
        }
        leaf_diag(a, tlo, thi);
        if (!batch_add_tri(b, base, base + 1, base + 2, (unsigned)li, 0)) return PT_ERR_NOMEM;
        a->stats.triangles++;
        return PT_OK;
    }
    const scene_mesh *m = o->u.mesh.mesh;
    unsigned base = (unsigned)b->nv;
    vec3 mlo = v3s(INFINITY), mhi = v3s(-INFINITY);
    for (int i = 0; i < m->nverts; i++) {
        vec3 p = xform_point(x, mesh_vert(m, i));
        bounds_add(&a->lo, &a->hi, p);
        bounds_add(&mlo, &mhi, p);
        if (!batch_add_vertex(b, p)) return PT_ERR_NOMEM;
    }
    if (m->nverts > 0) leaf_diag(a, mlo, mhi);
    for (int t = 0; t < m->ntris; t++) {
        int ok = mesh_tri_ok(m, t);
        if (!ok) diag_warn_once(d, m->loc, "mesh triangle with a vertex index out of range ignored");
        const int *v = m->tris[t];
        if (!batch_add_tri(b, base + (unsigned)(ok ? v[0] : 0), base + (unsigned)(ok ? v[1] : 0),
                           base + (unsigned)(ok ? v[2] : 0), (unsigned)li, (unsigned)t))
            return PT_ERR_NOMEM;
    }
    a->stats.triangles += m->ntris;
    return PT_OK;
}

static RTCGeometry new_triangle_geometry(accel *a, const float *v, size_t nv, const unsigned *idx, size_t nt)
{
    RTCGeometry g = rtcNewGeometry(a->dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (!g) return NULL;
    float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv);
    unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), nt);
    if (!vb || !ib) {
        rtcReleaseGeometry(g);
        return NULL;
    }
    memcpy(vb, v, nv * 3 * sizeof(float));
    memcpy(ib, idx, nt * 3 * sizeof(unsigned));
    return g;
}

static pt_status build_batches(accel *a)
{
    for (int k = 0; k < 2; k++) {
        tri_batch *b = &a->tri[k];
        if (b->nt == 0) continue;
        RTCGeometry g = new_triangle_geometry(a, b->v, b->nv, b->idx, b->nt);
        if (!g) return PT_ERR_DEVICE;
        if (k == 1) rtcSetGeometryOccludedFilterFunction(g, accel_filter_reject_all);
        rtcCommitGeometry(g);
        unsigned id = rtcAttachGeometry(a->root, g);
        rtcReleaseGeometry(g);
        if (!set_ginfo(a, id, GEOM_TRI, (unsigned)k)) return PT_ERR_DEVICE;
        a->stats.geometries++;
        free(b->v);
        free(b->idx);
        b->v = NULL;
        b->idx = NULL;
    }
    return PT_OK;
}

static int cmp_mesh_leaf(const void *pa, const void *pb)
{
    const uintptr_t *x = pa, *y = pb;
    if (x[0] != y[0]) return x[0] < y[0] ? -1 : 1;
    return x[1] < y[1] ? -1 : (x[1] > y[1]);
}

static void xform_to_float(const xform *x, float out[12])
{
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++) out[r * 4 + c] = (float)x->m[r][c];
}

/* Shared meshes: one RTCScene each, one instance per referencing object. */
static pt_status build_mesh_group(accel *a, diag *d, mesh_group *gr, const int *leaves, int n)
{
    const scene_mesh *m = gr->mesh;
    float *v = malloc((size_t)m->nverts * 3 * sizeof(float) + 1);
    unsigned *idx = malloc((size_t)m->ntris * 3 * sizeof(unsigned) + 1);
    if (!v || !idx) { free(v); free(idx); return PT_ERR_NOMEM; }
    vec3 mlo = v3s(INFINITY), mhi = v3s(-INFINITY);
    for (int i = 0; i < m->nverts; i++) {
        for (int k = 0; k < 3; k++) v[i * 3 + k] = m->verts[i][k];
        bounds_add(&mlo, &mhi, mesh_vert(m, i));
    }
    for (int t = 0; t < m->ntris; t++) {
        int ok = mesh_tri_ok(m, t);
        if (!ok) diag_warn_once(d, m->loc, "mesh triangle with a vertex index out of range ignored");
        for (int k = 0; k < 3; k++) idx[t * 3 + k] = ok ? (unsigned)m->tris[t][k] : 0u;
    }
    gr->scene = rtcNewScene(a->dev);
    RTCGeometry g = gr->scene ? new_triangle_geometry(a, v, (size_t)m->nverts, idx, (size_t)m->ntris) : NULL;
    free(v);
    free(idx);
    if (!g) return PT_ERR_DEVICE;
    rtcSetSceneFlags(gr->scene, RTC_SCENE_FLAG_ROBUST);
    for (int i = 0; i < n; i++)
        if (a->leaves[leaves[i]].flags & OBJ_NO_SHADOW) gr->any_no_shadow = 1;
    if (gr->any_no_shadow) {
        rtcSetGeometryUserData(g, a);
        rtcSetGeometryOccludedFilterFunction(g, accel_filter_instance_no_shadow);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometry(gr->scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(gr->scene);
    a->stats.geometries++;
    a->stats.triangles += m->ntris;
    for (int i = 0; i < n; i++) {
        const scene_object *o = a->leaves[leaves[i]].obj;
        RTCGeometry inst = rtcNewGeometry(a->dev, RTC_GEOMETRY_TYPE_INSTANCE);
        if (!inst) return PT_ERR_DEVICE;
        rtcSetGeometryInstancedScene(inst, gr->scene);
        rtcSetGeometryTimeStepCount(inst, 1);
        float xf[12];
        xform_to_float(&o->transform, xf);
        rtcSetGeometryTransform(inst, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, xf);
        rtcCommitGeometry(inst);
        unsigned id = rtcAttachGeometry(a->root, inst);
        rtcReleaseGeometry(inst);
        if (!set_ginfo(a, id, GEOM_INSTANCE, (unsigned)leaves[i])) return PT_ERR_DEVICE;
        a->stats.instances++;
        if (mlo.x <= mhi.x) {
            vec3 ilo = v3s(INFINITY), ihi = v3s(-INFINITY);
            for (int c = 0; c < 8; c++) {
                vec3 p = v3(c & 1 ? mhi.x : mlo.x, c & 2 ? mhi.y : mlo.y, c & 4 ? mhi.z : mlo.z);
                bounds_add(&a->lo, &a->hi, xform_point(&o->transform, p));
                bounds_add(&ilo, &ihi, xform_point(&o->transform, p));
            }
            leaf_diag(a, ilo, ihi);
        }
    }
    return PT_OK;
}

static pt_status build_meshes(accel *a, diag *d)
{
    int n = 0;
    for (int i = 0; i < a->nleaves; i++) {
        const scene_object *o = a->leaves[i].obj;
        if (o->kind == SHAPE_MESH && o->u.mesh.mesh && o->u.mesh.mesh->ntris > 0 && o->u.mesh.mesh->verts &&
            o->u.mesh.mesh->tris)
            n++;
    }
    if (n == 0) return PT_OK;
    uintptr_t *refs = malloc((size_t)n * 2 * sizeof *refs);
    int *lv = malloc((size_t)n * sizeof *lv);
    a->groups = calloc((size_t)n, sizeof *a->groups);
    if (!refs || !lv || !a->groups) { free(refs); free(lv); return PT_ERR_NOMEM; }
    n = 0;
    for (int i = 0; i < a->nleaves; i++) {
        const scene_object *o = a->leaves[i].obj;
        if (o->kind == SHAPE_MESH && o->u.mesh.mesh && o->u.mesh.mesh->ntris > 0 && o->u.mesh.mesh->verts &&
            o->u.mesh.mesh->tris) {
            refs[2 * n] = (uintptr_t)o->u.mesh.mesh;
            refs[2 * n + 1] = (uintptr_t)i;
            n++;
        }
    }
    qsort(refs, (size_t)n, 2 * sizeof *refs, cmp_mesh_leaf);
    pt_status st = PT_OK;
    for (int i = 0; i < n && st == PT_OK;) {
        int j = i;
        while (j < n && refs[2 * j] == refs[2 * i]) j++;
        const scene_mesh *m = (const scene_mesh *)refs[2 * i];
        if (j - i > 1 || m->uses > 1) {
            for (int k = i; k < j; k++) lv[k - i] = (int)refs[2 * k + 1];
            mesh_group *gr = &a->groups[a->ngroups];
            gr->mesh = m;
            for (int k = 0; k < j - i; k++) a->leaves[lv[k]].group = a->ngroups;
            a->ngroups++;
            st = build_mesh_group(a, d, gr, lv, j - i);
        } else {
            st = add_flat_triangles(a, d, (int)refs[2 * i + 1]);
        }
        i = j;
    }
    free(refs);
    free(lv);
    return st;
}

static pt_status build_shapes(accel *a, diag *d)
{
    int n = 0;
    for (int i = 0; i < a->nleaves; i++) {
        shape_kind k = a->leaves[i].obj->kind;
        if (k != SHAPE_TRIANGLE && k != SHAPE_SMOOTH_TRIANGLE && k != SHAPE_MESH && !a->leaves[i].in_csg) n++;
    }
    for (int i = 0; i < a->nleaves; i++) {
        shape_kind k = a->leaves[i].obj->kind;
        if (k == SHAPE_ISOSURFACE || k == SHAPE_JULIA) a->has_costly_crossings = 1;
    }
    if (n == 0) return PT_OK;
    a->shapes = malloc((size_t)n * sizeof *a->shapes);
    a->shape_leaf = malloc((size_t)n * sizeof *a->shape_leaf);
    if (!a->shapes || !a->shape_leaf) return PT_ERR_NOMEM;
    for (int i = 0; i < a->nleaves; i++) {
        const scene_object *o = a->leaves[i].obj;
        if (o->kind == SHAPE_TRIANGLE || o->kind == SHAPE_SMOOTH_TRIANGLE || o->kind == SHAPE_MESH ||
            a->leaves[i].in_csg)
            continue;
        geom_shape *sh = &a->shapes[a->nshapes];
        if (geom_shape_init(sh, o) != 0) {
            diag_warn_once(d, o->loc, "degenerate %s ignored (zero size, singular transform or non-finite numbers)",
                           o->name ? o->name : "shape");
            continue;
        }
        a->shape_leaf[a->nshapes++] = (unsigned)i;
        if (o->kind != SHAPE_PLANE && !sh->infinite) {
            bounds_add(&a->lo, &a->hi, sh->lo);
            bounds_add(&a->lo, &a->hi, sh->hi);
            leaf_diag(a, sh->lo, sh->hi);
        }
    }
    return PT_OK;
}

/* Clip boxes for planes (see the comment at the top) and the scene scale. */
static double plane_distance(const geom_shape *sh, vec3 c)
{
    vec3 nw = sh->identity ? sh->g.plane.n : v3_norm(xform_normal(&sh->x, sh->g.plane.n));
    vec3 p0 = v3_scale(sh->g.plane.n, sh->g.plane.d);
    if (!sh->identity) p0 = xform_point(&sh->x, p0);
    double dist = fabs(v3_dot(v3_sub(c, p0), nw));
    return isfinite(dist) ? dist : 0.0;
}

static int cmp_double(const void *x, const void *y)
{
    double u = *(const double *)x, v = *(const double *)y;
    return (u > v) - (u < v);
}

static void finish_bounds(accel *a)
{
    const scene *s = a->s;
    vec3 elo = a->lo, ehi = a->hi;
    if (s->camera_set) bounds_add(&elo, &ehi, s->camera.location);
    for (int i = 0; i < s->nlights; i++) bounds_add(&elo, &ehi, s->lights[i].position);
    int have_e = elo.x <= ehi.x;
    vec3 c = have_e ? v3_scale(v3_add(elo, ehi), 0.5) : v3s(0.0);
    double diag_e = have_e ? v3_len(v3_sub(ehi, elo)) : 0.0;
    double far_plane = 0.0;
    for (int i = 0; i < a->nshapes; i++) {
        geom_shape *sh = &a->shapes[i];
        if (sh->kind != SHAPE_PLANE && !sh->infinite) continue;
        double dist = sh->kind == SHAPE_PLANE ? plane_distance(sh, c) : 0.0;
        double hsz = PLANE_EXTENT_FACTOR * fmax_inline(diag_e, dist);
        if (!(hsz > 0.0)) hsz = PLANE_EXTENT_FACTOR;
        geom_shape_clip_plane(sh, v3_sub(c, v3s(hsz)), v3_add(c, v3s(hsz)));
        far_plane = fmax_inline(far_plane, dist);
    }
    /* CSG primitives: one cube for all their planes, the largest one needs */
    for (int i = 0; i < a->ncsgs; i++) {
        geom_csg *cs = &a->csgs[i];
        double dist = 0.0;
        for (int k = 0; k < cs->nshapes; k++)
            if (cs->shapes[k].kind == SHAPE_PLANE) dist = fmax_inline(dist, plane_distance(&cs->shapes[k], c));
        double hsz = PLANE_EXTENT_FACTOR * fmax_inline(diag_e, dist);
        if (!(hsz > 0.0)) hsz = PLANE_EXTENT_FACTOR;
        geom_csg_clip(cs, v3_sub(c, v3s(hsz)), v3_add(c, v3s(hsz)));
        far_plane = fmax_inline(far_plane, dist);
    }
    if (a->lo.x <= a->hi.x) {
        a->scale = v3_len(v3_sub(a->hi, a->lo));
    } else {
        a->lo = a->hi = v3s(0.0);
        a->scale = 0.0;
    }
    if (!(a->scale > 0.0) || !isfinite(a->scale)) a->scale = diag_e;
    if (!(a->scale > 0.0) || !isfinite(a->scale)) a->scale = far_plane;
    if (!(a->scale > 0.0) || !isfinite(a->scale)) a->scale = 1.0;
    /* Epsilon scale: the lower median leaf diagonal, so one far or huge
     * object does not grow the epsilon beyond the other objects' details
     * (the lower one: of a sky dome of radius 1e4 and one building, the
     * building's); it scales with the scene like the diagonal does. */
    a->eps_scale = a->scale;
    if (a->ndiags > 0) {
        qsort(a->diags, (size_t)a->ndiags, sizeof *a->diags, cmp_double);
        double med = a->diags[(a->ndiags - 1) / 2];
        if (med < a->eps_scale) a->eps_scale = med;
    }
    /* A scene made only of closed-form shapes (solved in double from the
     * double ray) needs no float margin: its rays' scale term shrinks by
     * ACCEL_EXACT_EPS_FACTOR, so surfaces a far smaller distance apart than
     * the objects' size stay apart (shells of a planet-sized sky 1 unit
     * apart, as POV-Ray's own absolute depth tolerances of 1e-6 to 1e-4 keep
     * them). Any triangle, mesh or iteratively solved shape keeps the rule
     * at its size. The |org| term is unchanged. */
    a->ray_eps_scale = a->inexact_leaves > 0 ? a->eps_scale : a->eps_scale * ACCEL_EXACT_EPS_FACTOR;
    free(a->diags);
    a->diags = NULL;
    a->ndiags = a->capdiags = 0;
}

static pt_status build_user_geometry(accel *a)
{
    if (a->nshapes + a->ncsgs == 0) return PT_OK;
    RTCGeometry g = rtcNewGeometry(a->dev, RTC_GEOMETRY_TYPE_USER);
    if (!g) return PT_ERR_DEVICE;
    unsigned np = (unsigned)(a->nshapes + a->ncsgs);
    a->ubox = malloc((size_t)np * 6 * sizeof *a->ubox);
    a->ubox_test = malloc(np);
    a->ucut = malloc(np);
    if (!a->ubox || !a->ubox_test || !a->ucut) return PT_ERR_NOMEM;
    for (unsigned p = 0; p < np; p++) {
        accel_user_box(a, p, a->ubox + 6 * (size_t)p);
        a->ubox_test[p] = (unsigned char)accel_user_box_test(a, p, np);
        a->ucut[p] = (unsigned char)accel_user_cut(a, p);
        a->has_ucut |= a->ucut[p];
    }
    rtcSetGeometryUserPrimitiveCount(g, (unsigned)(a->nshapes + a->ncsgs));
    rtcSetGeometryUserData(g, a);
    rtcSetGeometryBoundsFunction(g, accel_user_bounds, a);
    rtcSetGeometryIntersectFunction(g, accel_user_intersect);
    rtcSetGeometryOccludedFunction(g, accel_user_occluded);
    rtcCommitGeometry(g);
    unsigned id = rtcAttachGeometry(a->root, g);
    rtcReleaseGeometry(g);
    if (!set_ginfo(a, id, GEOM_USER, 0)) return PT_ERR_DEVICE;
    a->stats.geometries++;
    a->stats.user_prims = a->nshapes + a->ncsgs;
    return PT_OK;
}

/* ------------------------------------------------------------ public */

accel *accel_build(const scene *s, int threads, diag *d, pt_status *status)
{
    double t0 = timer_now();
    pt_status st = PT_OK;
    src_loc nowhere = {0};
    accel *a = calloc(1, sizeof *a);
    if (!a) {
        diag_report(d, DIAG_ERROR, nowhere, NULL, "out of memory while building the Embree scene");
        if (status) *status = PT_ERR_NOMEM;
        return NULL;
    }
    a->s = s;
    a->lo = v3s(INFINITY);
    a->hi = v3s(-INFINITY);
    if (!s) {
        diag_report(d, DIAG_ERROR, nowhere, NULL, "accel_build: no scene");
        st = PT_ERR_INTERNAL;
        goto fail;
    }
    /* frequency_level=simd256: Embree 3.13 defaults to simd128 on CPUs with
     * AVX-512 (Skylake-SP and later, to keep their clock up), which makes it
     * build 4-wide BVHs; simd256 lets it use its 8-wide BVH8 kernels, which
     * trace the GI geometry stage's incoherent link rays faster
     * (docs/gi.md, bench/bench_gi). An extra Embree config (PARTRAY_EMBREE_CONFIG, e.g. "isa=avx2" or
     * "verbose=2") is appended for measurements. */
    char cfg[256];
    int len = snprintf(cfg, sizeof cfg, "frequency_level=simd256");
    if (threads > 0) len += snprintf(cfg + len, sizeof cfg - (size_t)len, ",threads=%d", threads);
    const char *extra = getenv("PARTRAY_EMBREE_CONFIG");
    if (extra && *extra && strlen(extra) < sizeof cfg - (size_t)len - 2)
        snprintf(cfg + len, sizeof cfg - (size_t)len, ",%s", extra);
    a->dev = rtcNewDevice(cfg);
    if (!a->dev) {
        diag_report(d, DIAG_ERROR, nowhere, NULL, "Embree device could not be created: %s",
                    rtc_error_name(rtcGetDeviceError(NULL)));
        st = PT_ERR_DEVICE;
        goto fail;
    }
    rtcSetDeviceErrorFunction(a->dev, on_embree_error, a);
    if (!rtcGetDeviceProperty(a->dev, RTC_DEVICE_PROPERTY_USER_GEOMETRY_SUPPORTED)) {
        diag_report(d, DIAG_ERROR, nowhere, NULL, "this Embree library was built without user geometry support");
        st = PT_ERR_DEVICE;
        goto fail;
    }
    int filters = (int)rtcGetDeviceProperty(a->dev, RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED);
    a->root = rtcNewScene(a->dev);
    if (!a->root) {
        st = PT_ERR_DEVICE;
        goto fail;
    }
    /* Robust mode: watertight triangle tests and conservative traversal, so
     * rays do not slip through shared edges (closed rooms must not leak);
     * it costs throughput (bench/bench_rays), which a leak-free image is
     * worth. */
    rtcSetSceneFlags(a->root, RTC_SCENE_FLAG_ROBUST);

    for (int i = 0; i < s->nobjects && st == PT_OK; i++) st = collect(a, d, s->objects[i], NULL, 0u, 0);
    if (st == PT_OK && !filters)
        for (int i = 0; i < a->nleaves; i++)
            if ((a->leaves[i].flags & OBJ_NO_SHADOW) && (a->leaves[i].obj->kind == SHAPE_TRIANGLE ||
                a->leaves[i].obj->kind == SHAPE_SMOOTH_TRIANGLE || a->leaves[i].obj->kind == SHAPE_MESH))
                diag_warn_once(d, a->leaves[i].obj->loc,
                               "no_shadow on triangles/meshes is ignored: Embree was built without filter functions");
    for (int i = 0; i < a->nleaves && st == PT_OK; i++) {
        shape_kind k = a->leaves[i].obj->kind;
        if ((k == SHAPE_TRIANGLE || k == SHAPE_SMOOTH_TRIANGLE) && !a->leaves[i].in_csg) st = add_flat_triangles(a, d, i);
    }
    if (st == PT_OK) st = build_meshes(a, d);
    if (st == PT_OK) st = build_shapes(a, d);
    if (st == PT_OK) finish_bounds(a);
    if (st == PT_OK) st = build_batches(a);
    if (st == PT_OK) st = build_user_geometry(a);
    if (st == PT_OK) rtcCommitScene(a->root);
    if (embree_failed(a, d, "building the scene")) {
        st = PT_ERR_DEVICE;
        goto fail;
    }
    if (st != PT_OK) {
        if (st == PT_ERR_NOMEM)
            diag_report(d, DIAG_ERROR, nowhere, NULL, "out of memory while building the Embree scene");
        else if (st != PT_ERR_LIMIT)
            diag_report(d, DIAG_ERROR, nowhere, NULL, "Embree scene build failed (%s)", pt_status_name(st));
        goto fail;
    }
    a->stats.build_seconds = timer_now() - t0;
    if (status) *status = PT_OK;
    return a;

fail:
    accel_free(a);
    if (status) *status = st;
    return NULL;
}

void accel_free(accel *a)
{
    if (!a) return;
    if (a->root) rtcReleaseScene(a->root);
    for (int i = 0; i < a->ngroups; i++)
        if (a->groups[i].scene) rtcReleaseScene(a->groups[i].scene);
    if (a->dev) rtcReleaseDevice(a->dev);
    for (int k = 0; k < 2; k++) GROW_FREE_ALL(a->tri[k].v, a->tri[k].idx, a->tri[k].refs);
    for (int i = 0; i < a->nshapes; i++) geom_shape_release(&a->shapes[i]);
    for (int i = 0; i < a->ncsgs; i++) geom_csg_free(&a->csgs[i]);
    for (int i = 0; i < a->nbshapes; i++) geom_shape_release(&a->bshapes[i]);
    GROW_FREE_ALL(a->leaves, a->shapes, a->shape_leaf, a->diags, a->groups, a->csgs, a->bshapes, a->csg_b0, a->csg_bn,
                  a->ubox, a->ubox_test, a->ucut, a->ginfo, a);
}

static inline double eps_rule(double scale, vec3 org, double dirlen)
{
    double ax = fabs(org.x), ay = fabs(org.y), az = fabs(org.z);
    double m = ax > ay ? ax : ay;
    m = m > az ? m : az;
    return ACCEL_EPS_REL * (scale + m) / dirlen;
}


double accel_epsilon(const accel *a, vec3 org, vec3 dir)
{
    double l = v3_len(dir);
    if (!(l > 0.0) || !v3_finite(org)) return INFINITY;
    double e = eps_rule(a ? a->ray_eps_scale : 1.0, org, l);
    assert(e >= 0.0 && isfinite(e)); /* a finite origin, a non-zero direction */
    return e;
}

/* inline at every query: called out of line, its two vectors went through
 * the stack on every shadow ray */
__attribute__((always_inline)) static inline int ray_ok(vec3 org, vec3 dir)
{
    return v3_finite(org) && v3_finite(dir) && v3_len2(dir) > 0.0;
}

static void fill_rtc_ray(struct RTCRay *r, vec3 org, vec3 dir, double tmin, double tmax)
{
    r->org_x = (float)org.x;
    r->org_y = (float)org.y;
    r->org_z = (float)org.z;
    r->dir_x = (float)dir.x;
    r->dir_y = (float)dir.y;
    r->dir_z = (float)dir.z;
    r->tnear = (float)tmin;
    r->tfar = tmax >= (double)FLT_MAX ? INFINITY : (float)tmax;
    r->time = 0.0f;
    r->mask = 0xFFFFFFFFu;
    r->id = 0;
    r->flags = 0;
}


void accel_mesh_uv(const scene_object *o, unsigned local, double bu, double bv, double uv[2])
{
    const scene_mesh *m = o->u.mesh.mesh;
    uv[0] = uv[1] = 0.0;
    if (!m || !m->uvs || !m->tri_uvs || (int)local >= m->ntris) return;
    const int *ti = m->tri_uvs[local];
    double w = 1.0 - bu - bv;
    if (ti[0] >= 0 && ti[0] < m->nuvs && ti[1] >= 0 && ti[1] < m->nuvs && ti[2] >= 0 && ti[2] < m->nuvs) {
        uv[0] = w * m->uvs[ti[0]][0] + bu * m->uvs[ti[1]][0] + bv * m->uvs[ti[2]][0];
        uv[1] = w * m->uvs[ti[0]][1] + bu * m->uvs[ti[1]][1] + bv * m->uvs[ti[2]][1];
    }
}

/* Triangle data in object space for a hit on leaf `l`, triangle `local`. */
static void fill_triangle(const accel *a, const accel_leaf *l, unsigned local, double bu, double bv, double t_emb,
                          vec3 org, vec3 dir, accel_hit *hit)
{
    const scene_object *o = l->obj;
    const xform *x = &o->transform;
    vec3 p[3], n[3];
    int smooth = 0;
    const scene_texture *tex = l->texture;
    if (o->kind == SHAPE_MESH) {
        const scene_mesh *m = o->u.mesh.mesh;
        int ok = (int)local < m->ntris && mesh_tri_ok(m, (int)local);
        const int *tv = m->tris[ok ? local : 0];
        for (int k = 0; k < 3; k++) p[k] = ok ? mesh_vert(m, tv[k]) : v3s(0.0);
        if (ok && m->normals) {
            const int *tn = m->tri_normals ? m->tri_normals[local] : (m->nnormals == m->nverts ? tv : NULL);
            if (tn && tn[0] >= 0 && tn[0] < m->nnormals && tn[1] >= 0 && tn[1] < m->nnormals && tn[2] >= 0 &&
                tn[2] < m->nnormals) {
                for (int k = 0; k < 3; k++) n[k] = v3(m->normals[tn[k]][0], m->normals[tn[k]][1], m->normals[tn[k]][2]);
                smooth = 1;
            }
        }
        const scene_texture *tt = scene_mesh_tri_texture(o, (int)local);
        if (tt) tex = tt;
    } else {
        for (int k = 0; k < 3; k++) p[k] = o->u.triangle.v[k];
        if (o->kind == SHAPE_SMOOTH_TRIANGLE) {
            for (int k = 0; k < 3; k++) n[k] = o->u.triangle.n[k];
            smooth = 1;
        }
    }
    vec3 nobj = v3_cross(v3_sub(p[1], p[0]), v3_sub(p[2], p[0]));
    vec3 ng = l->identity ? nobj : v3_scale(xform_normal(x, nobj), l->wind);
    double t = t_emb;
    /* refine the float distance against the triangle's plane, in double */
    double den = v3_dot(dir, ng), lng = v3_len(ng);
    if (fabs(den) > 1e-6 * lng * v3_len(dir)) {
        vec3 p0 = l->identity ? p[0] : xform_point(x, p[0]);
        double tr = v3_dot(v3_sub(p0, org), ng) / den;
        if (isfinite(tr) && fabs(tr - t_emb) <= 1e-4 * fabs(t_emb)) t = tr;
    }
    if (lng > 0.0 && isfinite(lng)) ng = v3_scale(ng, 1.0 / lng);
    else ng = v3_norm(v3_neg(dir));
    vec3 ns = ng;
    /* POV-Ray's triangle normal (P1-P2) x (P3-P2) (triangle.cpp, mesh.cpp)
     * is the transformed object normal against the winding one */
    hit->pov_flip = l->wind > 0.0;
    if (smooth) {
        double w = 1.0 - bu - bv;
        vec3 sn = v3_add(v3_add(v3_scale(n[0], w), v3_scale(n[1], bu)), v3_scale(n[2], bv));
        if (!l->identity) sn = xform_normal(x, sn);
        double ls = v3_len(sn);
        if (ls > 0.0 && isfinite(ls)) {
            ns = v3_scale(sn, 1.0 / ls);
            hit->pov_flip = v3_dot(ns, ng) < 0.0; /* its smooth normal is the interpolated one */
            if (hit->pov_flip) ns = v3_neg(ns);
        }
    }
    hit->t = t;
    hit->p = v3_madd(org, dir, t);
    hit->ng = ng;
    hit->ns = ns;
    hit->u = bu;
    hit->v = bv;
    /* uv: Mesh::UVCoord interpolates the corners' uv_vectors with the
     * barycentrics (mesh.cpp; <0,0> without uv_vectors); a lone triangle
     * has ObjectBase::UVCoord's world x, y */
    hit->uv[0] = hit->p.x;
    hit->uv[1] = hit->p.y;
    if (o->kind == SHAPE_MESH) accel_mesh_uv(o, local, bu, bv, hit->uv);
    hit->obj = o;
    hit->texture = tex;
    hit->prim = local;
    hit->flags = l->flags;
}

_Static_assert((int)ACCEL_RAY_POV == (int)GEOM_RAY_POV && (int)ACCEL_RAY_EXACT == (int)GEOM_RAY_EXACT,
               "accel's ray rules are geom's");

/* The intersect context of a ray org + t dir from t0 (what the user-geometry
 * callbacks read through accel_tls_query), with no user-geometry hit yet,
 * under `rule`. */
static void query_init(accel_query *q, vec3 org, vec3 dir, double t0, accel_ray_rule rule)
{
    /* the fields every callback reads; the hit's (ut .. uprim) are read
     * only once uhit is set, the collect mode's only with cross set */
    q->org = org;
    q->dir = dir;
    q->tmin = t0;
    q->uhit = 0;
    q->cross = NULL;
    q->rule = (geom_ray_rule)rule;
    q->packet = 0;
    q->oprim = 0;
    q->tie_skip = 0u;
    rtcInitIntersectContext(&q->rtc);
}

/* The hit record of user primitive prim's crossing h of org + t dir. */
static void fill_user(const accel *a, unsigned prim, const geom_csg_hit *h, vec3 org, vec3 dir, accel_hit *hit)
{
    const geom_shape *sh = accel_prim_shape(a, prim, h->shape);
    unsigned li = prim < (unsigned)a->nshapes ? a->shape_leaf[prim]
                                              : a->csgs[prim - (unsigned)a->nshapes].shape_leaf[h->shape];
    assert(li < (unsigned)a->nleaves);
    const accel_leaf *l = &a->leaves[li];
    hit->t = h->t;
    hit->p = v3_madd(org, dir, h->t);
    /* the surface parameters only for triangles (their barycentrics,
     * which the GI links read); no shading reads them for round shapes */
    int tri = sh->kind == SHAPE_TRIANGLE || sh->kind == SHAPE_SMOOTH_TRIANGLE;
    hit->u = hit->v = 0.0;
    geom_shape_surface(sh, hit->p, h->part, &hit->ng, tri ? &hit->u : NULL, tri ? &hit->v : NULL);
    if (l->want_uv) {
        geom_shape_uv(sh, hit->p, h->part, hit->uv);
    } else {
        hit->uv[0] = hit->p.x;
        hit->uv[1] = hit->p.y;
    }
    if (h->flip) hit->ng = v3_neg(hit->ng);
    /* triangles intersected here (CSG members): POV-Ray's normal as in fill_triangle */
    hit->pov_flip = (sh->kind == SHAPE_TRIANGLE || sh->kind == SHAPE_SMOOTH_TRIANGLE) && sh->g.tri.wind > 0.0;
    if (h->flip) hit->pov_flip = !hit->pov_flip;
    geom_shape_shading(sh, hit->p, hit->ng, &hit->ns);
    hit->obj = l->obj;
    hit->texture = l->texture;
    if (sh->kind == SHAPE_BLOB) {
        const scene_texture *bt = geom_shape_texture(sh, hit->p);
        if (bt) hit->texture = bt;
    }
    hit->prim = (unsigned)h->part;
    hit->flags = l->flags;
}

/* fill_user's record, or without the surface where `surface` (given)
 * says it is not read (accel_crossings_cut's walk): no normals, no uv.
 * A blob's is always the full one: its texture depends on the point.
 * Returns whether the record is the bare one (its normals are zero). */
static int fill_user_for(const accel *a, unsigned prim, const geom_csg_hit *h, vec3 org, vec3 dir,
                         accel_surface_fn surface, void *ctx, accel_hit *hit)
{
    const geom_shape *sh = surface ? accel_prim_shape(a, prim, h->shape) : NULL;
    if (sh && sh->kind != SHAPE_BLOB) {
        unsigned li = prim < (unsigned)a->nshapes ? a->shape_leaf[prim]
                                                   : a->csgs[prim - (unsigned)a->nshapes].shape_leaf[h->shape];
        const accel_leaf *l = &a->leaves[li];
        if (!surface(ctx, l->obj, l->texture)) {
            hit->t = h->t;
            hit->p = v3_madd(org, dir, h->t);
            hit->u = hit->v = 0.0;
            hit->uv[0] = hit->uv[1] = 0.0;
            hit->ng = hit->ns = v3(0.0, 0.0, 0.0);
            hit->pov_flip = (sh->kind == SHAPE_TRIANGLE || sh->kind == SHAPE_SMOOTH_TRIANGLE) && sh->g.tri.wind > 0.0;
            if (h->flip) hit->pov_flip = !hit->pov_flip;
            hit->obj = l->obj;
            hit->texture = l->texture;
            hit->prim = (unsigned)h->part;
            hit->flags = l->flags;
            return 1;
        }
    }
    fill_user(a, prim, h, org, dir, hit);
    return 0;
}

/* intersect_at_skip; with `surface`, a user primitive's hit for which
 * it says its surface is not read gets fill_user_for's bare record. */
static int intersect_at_surface(const accel *a, vec3 org, vec3 dir, double t0, double tmax, accel_hit *hit,
                                accel_ray_rule rule, unsigned skip, accel_surface_fn surface, void *ctx)
{
    accel_query q;
    query_init(&q, org, dir, t0, rule);
    q.tie_skip = skip;
    struct RTCRayHit rh;
    fill_rtc_ray(&rh.ray, org, dir, t0, tmax);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    accel_query *saved = accel_tls_query;
    accel_tls_query = &q;
    rtcIntersect1(a->root, &q.rtc, &rh);
    accel_tls_query = saved;
    unsigned gid = rh.hit.geomID, inst = rh.hit.instID[0], prim = rh.hit.primID;
    if (gid == RTC_INVALID_GEOMETRY_ID) return 0;
    if (inst != RTC_INVALID_GEOMETRY_ID) {
        if (inst >= a->nginfo || a->ginfo[inst].kind != GEOM_INSTANCE) return 0;
        fill_triangle(a, &a->leaves[a->ginfo[inst].idx], prim, rh.hit.u, rh.hit.v, rh.ray.tfar, org, dir, hit);
    } else if (gid < a->nginfo && a->ginfo[gid].kind == GEOM_TRI) {
        assert(a->ginfo[gid].idx < 2 && prim < a->tri[a->ginfo[gid].idx].nt);
        const tri_ref *r = &a->tri[a->ginfo[gid].idx].refs[prim];
        assert(r->leaf < (unsigned)a->nleaves);
        fill_triangle(a, &a->leaves[r->leaf], r->local, rh.hit.u, rh.hit.v, rh.ray.tfar, org, dir, hit);
    } else if (gid < a->nginfo && a->ginfo[gid].kind == GEOM_USER && prim < (unsigned)(a->nshapes + a->ncsgs)) {
        geom_csg_hit h;
        if (q.uhit && q.uprim == prim) {
            h.t = q.ut;
            h.part = q.upart;
            h.shape = q.ushape;
            h.flip = q.uflip;
        } else if (!accel_prim_hit(a, prim, org, dir, t0, tmax, &h, q.rule)) {
            return 0;
        }
        if (fill_user_for(a, prim, &h, org, dir, surface, ctx, hit)) {
            assert(hit->obj && hit->texture);
            return isfinite(hit->t) && v3_finite(hit->p);
        }
    } else {
        return 0;
    }
    /* what every caller relies on: a hit inside the query's interval (up
     * to the epsilon rule's distance: triangle distances are refined in
     * double from Embree's float hit), unit normals on one side, the leaf
     * and its effective texture */
    assert(!(hit->t < t0 - eps_rule(a->ray_eps_scale, org, v3_len(dir))) &&
           !(hit->t > tmax + eps_rule(a->ray_eps_scale, org, v3_len(dir))));
    assert(fabs(v3_len2(hit->ng) - 1.0) < 1e-6 && fabs(v3_len2(hit->ns) - 1.0) < 1e-6);
    assert(v3_dot(hit->ng, hit->ns) >= 0.0);
    assert(hit->obj && hit->texture);
    return isfinite(hit->t) && v3_finite(hit->p);
}

/* accel_intersect_rule with the effective tmin t0 as given; user
 * primitives whose effective flags carry one of `skip` (the surfaces the
 * caller passes over, accel_intersect_past) lose the ties of coincident
 * surfaces (accel_user.c). */
static int intersect_at_skip(const accel *a, vec3 org, vec3 dir, double t0, double tmax, accel_hit *hit,
                             accel_ray_rule rule, unsigned skip)
{
    return intersect_at_surface(a, org, dir, t0, tmax, hit, rule, skip, NULL, NULL);
}

static int intersect_at(const accel *a, vec3 org, vec3 dir, double t0, double tmax, accel_hit *hit,
                        accel_ray_rule rule)
{
    return intersect_at_skip(a, org, dir, t0, tmax, hit, rule, 0u);
}

int accel_intersect_rule(const accel *a, accel_ray_rule rule, vec3 org, vec3 dir, double tmin, double tmax,
                         accel_hit *hit)
{
    if (!a || !ray_ok(org, dir)) return 0;
    double t0 = eps_rule(a->ray_eps_scale, org, v3_len(dir));
    if (tmin > t0) t0 = tmin;
    if (!(tmax > t0)) return 0;
    return intersect_at(a, org, dir, t0, tmax, hit, rule);
}

int accel_intersect(const accel *a, vec3 org, vec3 dir, double tmin, double tmax, accel_hit *hit)
{
    return accel_intersect_rule(a, ACCEL_RAY_POV, org, dir, tmin, tmax, hit);
}

double accel_hit_placement(const scene_object *o)
{
    /* the far end of a halving piece shorter than accuracy (geom_shape.h,
     * GEOM_RAY_POV): within accuracy of the root along the ray, so within
     * accuracy of the surface; the parser gives every isosurface a
     * positive accuracy */
    return o && o->kind == SHAPE_ISOSURFACE && o->u.isosurface ? o->u.isosurface->accuracy : 0.0;
}

/* accel_crossings in one traversal: possible when every geometry is user
 * geometry (the callback collects; triangles would need a filter). */
#define CROSS_MAX 256
/* Up to this many user primitives (and no other geometry) the crossings
 * are collected by a loop over the primitives' boxes instead of Embree's
 * traversal, whose fixed cost per ray is then the larger part. */
#define CROSS_DIRECT_MAX 4
static int crossings_collected(const accel *a, vec3 org, vec3 dir, double t0, double tmax, double step, unsigned skip,
                               int cut, accel_crossing *cr)
{
    if (a->has_tri_geoms || a->has_costly_crossings) return -1;
    accel_query q;
    query_init(&q, org, dir, t0, ACCEL_RAY_POV);
    q.cross = cr;
    q.ncross = 0;
    q.overflow = 0;
    q.maxcross = CROSS_MAX;
    q.ctmax = tmax;
    q.cstep = step;
    q.cskip = skip;
    q.ccut = cut;
    struct RTCRayHit rh;
    fill_rtc_ray(&rh.ray, org, dir, t0, tmax);
    rh.hit.geomID = rh.hit.primID = rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    accel_query *saved = accel_tls_query;
    accel_tls_query = &q;
    if (a->nshapes + a->ncsgs <= CROSS_DIRECT_MAX)
        accel_user_cross_all(a, &q, &rh.ray);
    else
        rtcIntersect1(a->root, &q.rtc, &rh);
    accel_tls_query = saved;
    if (q.overflow) return -1;
    /* nearest first (insertion: a handful) */
    for (int i = 1; i < q.ncross; i++) {
        accel_crossing c = cr[i];
        int j = i;
        for (; j > 0 && (cr[j - 1].t > c.t || (cr[j - 1].t == c.t && cr[j - 1].prim > c.prim)); j--) cr[j] = cr[j - 1];
        cr[j] = c;
    }
    return q.ncross;
}

/* accel_crossings_skip; with `cut`, accel_crossings_cut's walk (-1 when
 * it must be walked again without the cut). */
static int crossings_walk(const accel *a, vec3 org, vec3 dir, double tmin, double tmax, double step, unsigned skip,
                          int cut, accel_surface_fn surface, accel_crossing_fn fn, void *ctx)
{
    if (!a || !ray_ok(org, dir)) return 0;
    double t0 = eps_rule(a->ray_eps_scale, org, v3_len(dir));
    if (tmin > t0) t0 = tmin;
    if (!(tmax > t0)) return 0;
    cut = cut && a->has_ucut;
    accel_crossing cr[CROSS_MAX];
    int n = crossings_collected(a, org, dir, t0, tmax, step, skip, cut, cr), visited = 0;
    accel_hit h;
    if (n >= 0) {
        /* the same crossings as the loop below: each the nearest past the
         * one before by the stepping rule */
        for (int i = 0; i < n; i++) {
            /* past a crossing whose primitive's later ones were left out,
             * the walk would miss them */
            if (cut && i > 0 && cr[i - 1].cut) return -1;
            if (!(cr[i].t > t0) || !(cr[i].t < tmax)) continue;
            geom_csg_hit g = {.t = cr[i].t, .part = cr[i].part, .shape = cr[i].shape, .flip = cr[i].flip};
            fill_user_for(a, cr[i].prim, &g, org, dir, surface, ctx, &h);
            if (!isfinite(h.t) || !v3_finite(h.p)) continue;
            t0 = h.t + fmax_inline(step, h.t * 1e-7);
            if (h.flags & skip) continue; /* a member's own flag */
            visited++;
            if (!fn(ctx, &h)) return visited;
        }
        return cut && n > 0 && cr[n - 1].cut ? -1 : visited;
    }
    for (int k = 0; k < CROSS_MAX && t0 < tmax; k++) {
        if (!intersect_at_surface(a, org, dir, t0, tmax, &h, ACCEL_RAY_POV, 0u, surface, ctx)) break;
        t0 = h.t + fmax_inline(step, h.t * 1e-7);
        if (h.flags & skip) continue;
        visited++;
        if (!fn(ctx, &h)) break;
    }
    return visited;
}

int accel_crossings_skip(const accel *a, vec3 org, vec3 dir, double tmin, double tmax, double step, unsigned skip,
                         accel_crossing_fn fn, void *ctx)
{
    return crossings_walk(a, org, dir, tmin, tmax, step, skip, 0, NULL, fn, ctx);
}

int accel_crossings_cut(const accel *a, vec3 org, vec3 dir, double tmin, double tmax, double step, unsigned skip,
                        accel_surface_fn surface, accel_crossing_fn fn, void *ctx)
{
    return crossings_walk(a, org, dir, tmin, tmax, step, skip, 1, surface, fn, ctx);
}

int accel_crossings(const accel *a, vec3 org, vec3 dir, double tmin, double tmax, double step, accel_crossing_fn fn,
                    void *ctx)
{
    return accel_crossings_skip(a, org, dir, tmin, tmax, step, 0u, fn, ctx);
}

/* Contacts (accel_intersect_from): inside the self-intersection distance
 * t_eps a hit counts unless it is on the surface left (same object and
 * part or triangle) or on a surface parallel to it within CONTACT_COS,
 * where a float re-hit of the surface or of its coplanar neighbour (the
 * other triangle of a quad) can fall; `skip` flags also pass. Searches
 * from CONTACT_REL * t_eps on. */
#define CONTACT_COS 0.99
#define CONTACT_REL 1e-4
static int contact_hit(const accel *a, const accel_from *f, vec3 org, vec3 dir, double t_eps, unsigned skip,
                       accel_hit *hit)
{
    double lo = CONTACT_REL * t_eps;
    for (int k = 0; k < 8 && lo < t_eps; k++) {
        if (!intersect_at(a, org, dir, lo, t_eps, hit, ACCEL_RAY_POV)) return 0;
        int own = hit->obj == f->obj && hit->prim == f->prim;
        double c = v3_dot(hit->ng, f->ng);
        double nn = v3_len(hit->ng) * v3_len(f->ng);
        int parallel = nn > 0.0 && fabs(c) > CONTACT_COS * nn;
        if (!own && !parallel && !(hit->flags & skip)) return 1;
        lo = hit->t + fmax_inline(lo, hit->t * 1e-7);
    }
    return 0;
}

void accel_from_hit(accel_from *f, const accel_hit *h)
{
    f->obj = h->obj;
    f->prim = h->prim;
    f->ng = h->ng;
}

int accel_intersect_from(const accel *a, const accel_from *f, vec3 org, vec3 dir, double tmin, double tmax,
                         accel_hit *hit)
{
    if (!a || !ray_ok(org, dir)) return 0;
    double t0 = eps_rule(a->ray_eps_scale, org, v3_len(dir));
    if (tmin > t0) t0 = tmin;
    if (f && contact_hit(a, f, org, dir, fmin_inline(t0, tmax), 0u, hit)) return 1;
    return accel_intersect(a, org, dir, tmin, tmax, hit);
}

_Static_assert(OBJ_NO_RADIOSITY < ACCEL_SKIP_PASS_THROUGH, "ACCEL_SKIP_PASS_THROUGH lies above the OBJ_* flags");

/* accel_intersect_from whose coincident-surface ties go against the
 * primitives carrying one of `skip` (intersect_at_skip): a no_reflection
 * box standing on a floor is passed over from a distance past its
 * bottom face, which would pass over the floor too had the box won. */
static int intersect_from_skip(const accel *a, const accel_from *f, vec3 org, vec3 dir, double tmin, double tmax,
                               unsigned skip, accel_hit *hit)
{
    if (!a || !ray_ok(org, dir)) return 0;
    double t0 = eps_rule(a->ray_eps_scale, org, v3_len(dir));
    if (tmin > t0) t0 = tmin;
    if (f && contact_hit(a, f, org, dir, fmin_inline(t0, tmax), 0u, hit)) return 1;
    if (!(tmax > t0)) return 0;
    return intersect_at_skip(a, org, dir, t0, tmax, hit, ACCEL_RAY_POV, skip & ~ACCEL_SKIP_PASS_THROUGH);
}

int accel_intersect_past(const accel *a, const accel_from *f, vec3 org, vec3 dir, double eps, unsigned skip,
                         accel_hit *hit, long *rays)
{
    double tmin = eps;
    for (int k = 0; k < ACCEL_PASS_MAX; k++) {
        if (rays) (*rays)++;
        if (!intersect_from_skip(a, k == 0 ? f : NULL, org, dir, tmin, INFINITY, skip, hit)) return 0;
        int pass = (hit->flags & skip) ||
                   ((skip & ACCEL_SKIP_PASS_THROUGH) && hit->obj && hit->obj->photons && hit->obj->photons->pass_through);
        if (!pass) return 1;
        tmin = hit->t + fmax_inline(eps, hit->t * 1e-7);
    }
    return -1;
}

int accel_occluded_from(const accel *a, const accel_from *f, vec3 org, vec3 dir, double tmin, double tmax)
{
    if (!a || !ray_ok(org, dir)) return 0;
    double t0 = eps_rule(a->ray_eps_scale, org, v3_len(dir));
    if (tmin > t0) t0 = tmin;
    accel_hit h;
    if (f && contact_hit(a, f, org, dir, fmin_inline(t0, tmax), OBJ_NO_SHADOW, &h)) return 1;
    return accel_occluded(a, org, dir, tmin, tmax);
}

int accel_mutually_visible(const accel *a, double eps, vec3 x, vec3 nx, vec3 y, vec3 ny, accel_same_fn same,
                           const void *ctx)
{
    double lift = 16.0 * eps;
    vec3 p = v3_madd(x, nx, lift), q = v3_madd(y, ny, lift);
    vec3 d = v3_sub(q, p);
    double len = v3_len(d);
    if (!(len > 2.0 * lift)) return 1;
    d = v3_scale(d, 1.0 / len);
    /* within the self-intersection distance of p: an object that is not
     * "same" blocks unless it lies parallel to x's surface (contacts, as
     * accel_intersect_from) */
    double t_eps = fmin_inline(eps_rule(a->ray_eps_scale, p, 1.0), len);
    for (double lo = CONTACT_REL * t_eps; lo < t_eps;) {
        accel_hit h;
        if (!intersect_at(a, p, d, lo, t_eps, &h, ACCEL_RAY_EXACT)) break;
        double c = v3_dot(h.ng, nx), nn = v3_len(h.ng) * v3_len(nx);
        if (!same(h.obj, ctx) && !(nn > 0.0 && fabs(c) > CONTACT_COS * nn)) return 0;
        lo = h.t + fmax_inline(lo, h.t * 1e-7);
    }
    double tmin = 0.0;
    for (int k = 0; k < 8; k++) {
        accel_hit h;
        if (!accel_intersect_rule(a, ACCEL_RAY_EXACT, p, d, tmin, len, &h)) return 1;
        if (!same(h.obj, ctx)) return 0;
        tmin = h.t + fmax_inline(eps, h.t * 1e-7);
    }
    return 1;
}

void *accel_rtc_link_scene(const accel *a)
{
    if (!a || !a->root) return NULL;
    RTCScene s = rtcNewScene(a->dev);
    if (!s) return NULL;
    /* no RTC_SCENE_FLAG_ROBUST: a link ray that slips through a crack
     * between two triangles ends further on or misses, which at 16 or 256
     * rays a particle is noise, not a leak (gi_links.c) */
    rtcSetSceneFlags(s, RTC_SCENE_FLAG_NONE);
    unsigned np = (unsigned)(a->nshapes + a->ncsgs);
    for (unsigned id = 0; id < a->nginfo; id++) {
        int kind = a->ginfo[id].kind;
        if (kind == GEOM_TRI || kind == GEOM_INSTANCE || (kind == GEOM_USER && np > 1)) {
            /* the same geometry, attached under the same id (Embree 3.13's
             * rtcAttachGeometry: a geometry can be attached to several scenes) */
            RTCGeometry g = rtcGetGeometry(a->root, id);
            if (g) rtcAttachGeometryByID(s, g, id);
        } else if (kind == GEOM_USER) {
            RTCGeometry g = rtcNewGeometry(a->dev, RTC_GEOMETRY_TYPE_USER);
            if (!g) continue;
            rtcSetGeometryUserPrimitiveCount(g, np + 1);
            rtcSetGeometryUserData(g, (void *)a);
            rtcSetGeometryBoundsFunction(g, accel_user_bounds_link, (void *)a);
            rtcSetGeometryIntersectFunction(g, accel_user_intersect);
            rtcSetGeometryOccludedFunction(g, accel_user_occluded);
            rtcCommitGeometry(g);
            rtcAttachGeometryByID(s, g, id);
            rtcReleaseGeometry(g);
        }
    }
    rtcCommitScene(s);
    if (rtcGetDeviceError(a->dev) != RTC_ERROR_NONE) {
        rtcReleaseScene(s);
        return NULL;
    }
    return s;
}

void accel_rtc_link_scene_free(void *scene)
{
    if (scene) rtcReleaseScene((RTCScene)scene);
}

void accel_rtc_rayhit_init(struct RTCRayHit *rh, const float o[3], float tnear, const float d[3])
{
    rh->ray.org_x = o[0];
    rh->ray.org_y = o[1];
    rh->ray.org_z = o[2];
    rh->ray.tnear = tnear;
    rh->ray.dir_x = d[0];
    rh->ray.dir_y = d[1];
    rh->ray.dir_z = d[2];
    rh->ray.time = 0.0f;
    rh->ray.tfar = INFINITY;
    rh->ray.mask = 0xFFFFFFFFu;
    rh->ray.id = 0;
    rh->ray.flags = 0;
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

const scene_object *accel_rtc_object(const accel *a, unsigned geom, unsigned prim, unsigned inst)
{
    if (!a || geom == RTC_INVALID_GEOMETRY_ID) return NULL;
    if (inst != RTC_INVALID_GEOMETRY_ID) {
        if (inst >= a->nginfo || a->ginfo[inst].kind != GEOM_INSTANCE) return NULL;
        return a->leaves[a->ginfo[inst].idx].obj;
    }
    if (geom >= a->nginfo) return NULL;
    if (a->ginfo[geom].kind == GEOM_TRI) {
        const tri_batch *b = &a->tri[a->ginfo[geom].idx];
        if ((size_t)prim >= b->nt) return NULL;
        return a->leaves[b->refs[prim].leaf].obj;
    }
    if (a->ginfo[geom].kind == GEOM_USER && prim < (unsigned)a->nshapes) return a->leaves[a->shape_leaf[prim]].obj;
    return NULL;
}

const scene_object *accel_rtc_object_tri(const accel *a, unsigned geom, unsigned prim, unsigned inst, unsigned *local)
{
    *local = 0;
    const scene_object *o = accel_rtc_object(a, geom, prim, inst);
    if (!o) return NULL;
    if (inst != RTC_INVALID_GEOMETRY_ID) *local = prim; /* an instanced mesh: its own triangles */
    else if (a->ginfo[geom].kind == GEOM_TRI) *local = a->tri[a->ginfo[geom].idx].refs[prim].local;
    return o;
}

const scene_object *accel_rtc_leaf(const accel *a, unsigned geom, unsigned prim, unsigned inst, float u,
                                   const scene_texture **tex)
{
    *tex = NULL;
    if (!a || geom == RTC_INVALID_GEOMETRY_ID) return NULL;
    unsigned li;
    if (inst != RTC_INVALID_GEOMETRY_ID) {
        if (inst >= a->nginfo || a->ginfo[inst].kind != GEOM_INSTANCE) return NULL;
        li = a->ginfo[inst].idx;
    } else if (geom >= a->nginfo) {
        return NULL;
    } else if (a->ginfo[geom].kind == GEOM_TRI) {
        const tri_batch *b = &a->tri[a->ginfo[geom].idx];
        if ((size_t)prim >= b->nt) return NULL;
        li = b->refs[prim].leaf;
    } else if (a->ginfo[geom].kind == GEOM_USER && prim < (unsigned)a->nshapes) {
        li = a->shape_leaf[prim];
    } else if (a->ginfo[geom].kind == GEOM_USER && prim < (unsigned)(a->nshapes + a->ncsgs)) {
        /* the member the intersect callback found, from the record's u
         * (accel_user_intersect) */
        const geom_csg *c = &a->csgs[prim - (unsigned)a->nshapes];
        if (!(u >= 0.0f && u < (float)c->nshapes)) return NULL;
        li = c->shape_leaf[(int)u];
    } else {
        return NULL;
    }
    if (li >= (unsigned)a->nleaves) return NULL;
    const scene_object *o = a->leaves[li].obj;
    *tex = a->leaves[li].texture;
    if (o && o->kind == SHAPE_MESH) { /* the triangle's own texture_list entry */
        unsigned local = inst != RTC_INVALID_GEOMETRY_ID ? prim : a->tri[a->ginfo[geom].idx].refs[prim].local;
        const scene_texture *tt = scene_mesh_tri_texture(o, (int)local);
        if (tt) *tex = tt;
    }
    return o;
}

int accel_leaf_count(const accel *a) { return a ? a->nleaves : 0; }

const scene_object *accel_leaf_at(const accel *a, int i, const scene_texture **tex)
{
    *tex = NULL;
    if (!a || i < 0 || i >= a->nleaves) return NULL;
    *tex = a->leaves[i].texture;
    return a->leaves[i].obj;
}

unsigned accel_rtc_ngeoms(const accel *a) { return a ? a->nginfo : 0; }

long accel_rtc_triangles(const accel *a, unsigned geom, const float **v, const unsigned **idx)
{
    if (!a || geom >= a->nginfo || a->ginfo[geom].kind != GEOM_TRI) return 0;
    RTCGeometry g = rtcGetGeometry(a->root, geom);
    if (!g) return 0;
    *v = rtcGetGeometryBufferData(g, RTC_BUFFER_TYPE_VERTEX, 0);
    *idx = rtcGetGeometryBufferData(g, RTC_BUFFER_TYPE_INDEX, 0);
    if (!*v || !*idx) return 0;
    return (long)a->tri[a->ginfo[geom].idx].nt;
}

int accel_occluded(const accel *a, vec3 org, vec3 dir, double tmin, double tmax)
{
    return accel_occluded_cached(a, NULL, org, dir, tmin, tmax);
}

int accel_occluded_cached(const accel *a, unsigned *last, vec3 org, vec3 dir, double tmin, double tmax)
{
    if (!a || !ray_ok(org, dir)) return 0;
    double t0 = eps_rule(a->ray_eps_scale, org, v3_len(dir));
    if (tmin > t0) t0 = tmin;
    if (!(tmax > t0)) return 0;
    accel_query q;
    query_init(&q, org, dir, t0, ACCEL_RAY_POV);
    struct RTCRay r;
    fill_rtc_ray(&r, org, dir, t0, tmax);
    if (last && *last && accel_user_blocks(a, &q, &r, *last - 1u)) return 1;
    accel_query *saved = accel_tls_query;
    accel_tls_query = &q;
    rtcOccluded1(a->root, &q.rtc, &r);
    accel_tls_query = saved;
    int blocked = r.tfar == -INFINITY;
    if (last) *last = blocked ? q.oprim : 0u;
    return blocked;
}

/* Rays k0 .. k0 + 15 of a batch (the first m of them real) as a packet of
 * 16, each with the same effective interval as accel_occluded /
 * accel_intersect; out[] of the real ones cleared. Returns whether any lane
 * is valid. */
static int fill_packet16(const accel *a, int k0, int m, const vec3 *org, const vec3 *dir, const double *tmin,
                         const double *tmax, struct RTCRay16 *r, int *valid, unsigned char *out)
{
    int any = 0;
    for (int k = 0; k < 16; k++) {
        valid[k] = 0;
        r->org_x[k] = r->org_y[k] = r->org_z[k] = 0.0f;
        r->dir_x[k] = r->dir_y[k] = 0.0f;
        r->dir_z[k] = 1.0f;
        r->tnear[k] = 0.0f;
        r->tfar[k] = 0.0f;
        r->time[k] = 0.0f;
        r->mask[k] = 0xFFFFFFFFu;
        r->id[k] = (unsigned)k;
        r->flags[k] = 0;
        if (k >= m) continue;
        int i = k0 + k;
        out[i] = 0;
        if (!a || !ray_ok(org[i], dir[i])) continue;
        double t0 = eps_rule(a->ray_eps_scale, org[i], v3_len(dir[i]));
        if (tmin[i] > t0) t0 = tmin[i];
        if (!(tmax[i] > t0)) continue;
        struct RTCRay one;
        fill_rtc_ray(&one, org[i], dir[i], t0, tmax[i]);
        r->org_x[k] = one.org_x;
        r->org_y[k] = one.org_y;
        r->org_z[k] = one.org_z;
        r->dir_x[k] = one.dir_x;
        r->dir_y[k] = one.dir_y;
        r->dir_z[k] = one.dir_z;
        r->tnear[k] = one.tnear;
        r->tfar[k] = one.tfar;
        valid[k] = -1;
        any = 1;
    }
    return any;
}

/* accel_occluded_n (nearest 0: Embree's occlusion query) and
 * accel_hit_any_n (nearest 1: the nearest-hit query, which an occlusion
 * query's skipping of no_shadow objects would get wrong: they block the
 * cells' segments too), in packets of 16. */
static void query_n(const accel *a, int n, const vec3 *org, const vec3 *dir, const double *tmin, const double *tmax,
                    unsigned char *out, int nearest, accel_ray_rule rule)
{
    for (int k0 = 0; k0 < n; k0 += 16) {
        int m = n - k0 < 16 ? n - k0 : 16;
        struct RTCRayHit16 r;
        RTC_ALIGN(64) int valid[16];
        if (!fill_packet16(a, k0, m, org, dir, tmin, tmax, &r.ray, valid, out)) continue;
        if (nearest)
            for (int k = 0; k < 16; k++) {
                r.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
                r.hit.primID[k] = RTC_INVALID_GEOMETRY_ID;
                r.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
            }
        /* a packet's context: user geometry takes the packet's float
         * rays (no double ray), under the query's rule */
        accel_query q = {.rule = (geom_ray_rule)rule, .packet = 1};
        rtcInitIntersectContext(&q.rtc);
        q.rtc.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        accel_query *saved = accel_tls_query;
        accel_tls_query = &q;
        if (nearest) rtcIntersect16(valid, a->root, &q.rtc, &r);
        else rtcOccluded16(valid, a->root, &q.rtc, &r.ray);
        accel_tls_query = saved;
        for (int k = 0; k < m; k++)
            if (valid[k]) out[k0 + k] = nearest ? r.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID : r.ray.tfar[k] == -INFINITY;
    }
}

void accel_occluded_n(const accel *a, int n, const vec3 *org, const vec3 *dir, const double *tmin,
                      const double *tmax, unsigned char *out)
{
    query_n(a, n, org, dir, tmin, tmax, out, 0, ACCEL_RAY_POV);
}

void accel_hit_any_n(const accel *a, accel_ray_rule rule, int n, const vec3 *org, const vec3 *dir,
                     const double *tmin, const double *tmax, unsigned char *out)
{
    query_n(a, n, org, dir, tmin, tmax, out, 1, rule);
}

void accel_bounds(const accel *a, vec3 *lo, vec3 *hi)
{
    if (lo) *lo = a ? a->lo : v3s(0.0);
    if (hi) *hi = a ? a->hi : v3s(0.0);
}

double accel_scale(const accel *a) { return a ? a->scale : 1.0; }
double accel_eps_scale(const accel *a) { return a ? a->eps_scale : 1.0; }

double accel_surface_eps(const accel *a)
{
    double s = a ? a->ray_eps_scale : 1.0;
    if (!(s > 0.0) || !isfinite(s)) s = 1.0;
    return s * 1e-6;
}

accel_stats accel_get_stats(const accel *a)
{
    accel_stats s;
    memset(&s, 0, sizeof s);
    return a ? a->stats : s;
}

void *accel_rtc_scene(const accel *a) { return a ? (void *)a->root : NULL; }
