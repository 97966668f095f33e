/* geom_csg.c - CSG intersection/difference along a ray (rules in geom_csg.h).
 *
 * Bounds: every node gets two boxes, S (where its surface can be) and V
 * (where its inside can be), with infinite sides where half-spaces leave
 * them open. Leaves: S is the shape's bounds, V the solid's (a plane or disc
 * is the half-space behind it, a triangle has none, an inverse leaf is
 * everywhere). union/merge: unions of both. intersection: S is the union over
 * members of S_i clipped by the other members' V, V the intersection of all
 * V. difference: S is S_0 plus the subtracted S_k clipped by V_0, V is V_0.
 * The root's S bounds the primitive; an intersection of six planes gets a
 * tight box this way. */
#include "geom_csg.h"
#include "scene_leaves.h"
#include "grow.h"
#include "geom_implicit.h"
#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct { vec3 lo, hi; } bbox;

static bbox bb_all(void) { bbox b = {v3s(-INFINITY), v3s(INFINITY)}; return b; }
static bbox bb_empty(void) { bbox b = {v3s(INFINITY), v3s(-INFINITY)}; return b; }
static bbox bb_union(bbox a, bbox b) { bbox r = {v3_min(a.lo, b.lo), v3_max(a.hi, b.hi)}; return r; }
static bbox bb_inter(bbox a, bbox b) { bbox r = {v3_max(a.lo, b.lo), v3_min(a.hi, b.hi)}; return r; }
static int bb_empty_p(bbox b) { return !(b.lo.x <= b.hi.x && b.lo.y <= b.hi.y && b.lo.z <= b.hi.z); }
/* outwards by 1e-7 of the box's size and coordinates (infinite sides stay) */
static bbox pad_box(bbox b)
{
    if (bb_empty_p(b)) return b;
    for (int i = 0; i < 3; i++) {
        double l = v3_idx(b.lo, i), h = v3_idx(b.hi, i);
        double ext = isfinite(h - l) ? h - l : 0.0;
        double pad = 1e-7 * ((isfinite(l) ? fabs(l) : 0.0) + (isfinite(h) ? fabs(h) : 0.0) + ext) + 1e-300;
        if (i == 0) { b.lo.x = l - pad; b.hi.x = h + pad; }
        if (i == 1) { b.lo.y = l - pad; b.hi.y = h + pad; }
        if (i == 2) { b.lo.z = l - pad; b.hi.z = h + pad; }
    }
    return b;
}
static int in_box(const vec3 *b, vec3 p)
{
    return p.x >= b[0].x && p.x <= b[1].x && p.y >= b[0].y && p.y <= b[1].y && p.z >= b[0].z && p.z <= b[1].z;
}

/* Building: nodes are added parent first; returns the node index or -1 on
 * out-of-memory. Leaves take a copy of `sh`. */
static int geom_csg_add_node(geom_csg *c, geom_csg_op op, int inverse, int parent)
{
    if (!grow_array_int((void **)&c->nodes, &c->capnodes, c->nnodes + 1, sizeof(geom_csg_node))) return -1;
    geom_csg_node *n = &c->nodes[c->nnodes];
    memset(n, 0, sizeof *n);
    n->op = op;
    n->inverse = inverse != 0;
    n->parent = parent;
    n->shape = -1;
    return c->nnodes++;
}

static int geom_csg_add_leaf(geom_csg *c, const geom_shape *sh, unsigned tag, int inverse, int parent)
{
    if (!grow_array_int((void **)&c->shapes, &c->capshapes, c->nshapes + 1, sizeof(geom_shape))) return -1;
    int cap = c->capshapes;
    /* shape_leaf and shape_node follow the capacity of shapes */
    unsigned *sl = realloc(c->shape_leaf, (size_t)cap * sizeof *sl);
    if (!sl) return -1;
    c->shape_leaf = sl;
    int *sn = realloc(c->shape_node, (size_t)cap * sizeof *sn);
    if (!sn) return -1;
    c->shape_node = sn;
    int node = geom_csg_add_node(c, GEOM_CSG_LEAF, inverse, parent);
    if (node < 0) return -1;
    c->shapes[c->nshapes] = *sh;
    c->shape_leaf[c->nshapes] = tag;
    c->shape_node[c->nshapes] = node;
    c->nodes[node].shape = c->nshapes++;
    return node;
}

/* Half-space behind a plane through p0 with unit normal n: bounded on one
 * side only when n is along an axis. */
static bbox half_space(vec3 n, vec3 p0)
{
    bbox b = bb_all();
    double a[3] = {n.x, n.y, n.z};
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        if (fabs(a[j]) > 1e-12 || fabs(a[k]) > 1e-12) continue;
        double c = v3_idx(p0, i);
        if (a[i] > 0) { if (i == 0) b.hi.x = c; else if (i == 1) b.hi.y = c; else b.hi.z = c; }
        if (a[i] < 0) { if (i == 0) b.lo.x = c; else if (i == 1) b.lo.y = c; else b.lo.z = c; }
    }
    return b;
}

static void leaf_boxes(const geom_shape *sh, int inverse, bbox *s, bbox *v)
{
    const xform *x = &sh->x;
    bbox own = {sh->lo, sh->hi};
    switch (sh->kind) {
    case SHAPE_PLANE: {
        vec3 n = sh->identity ? sh->g.plane.n : v3_norm(xform_normal(x, sh->g.plane.n));
        vec3 p0 = v3_scale(sh->g.plane.n, sh->g.plane.d);
        if (!sh->identity) p0 = xform_point(x, p0);
        *v = half_space(n, p0);
        /* the surface: the plane itself, a slice when axis-aligned */
        bbox hs = *v, neg = half_space(v3_neg(n), p0);
        *s = bb_inter(hs, neg);
        break;
    }
    case SHAPE_DISC: {
        vec3 n = sh->identity ? sh->g.disc.n : v3_norm(xform_normal(x, sh->g.disc.n));
        vec3 p0 = sh->identity ? sh->g.disc.c : xform_point(x, sh->g.disc.c);
        *s = own;
        *v = half_space(n, p0);
        break;
    }
    case SHAPE_TRIANGLE:
    case SHAPE_SMOOTH_TRIANGLE:
    case SHAPE_POLYGON:
        *s = own;
        *v = bb_empty();
        break;
    case SHAPE_SPHERE: case SHAPE_BOX: case SHAPE_CYLINDER: case SHAPE_CONE: case SHAPE_TORUS:
        *s = own;
        *v = own;
        break;
    default:
        /* the other shapes: unbounded surfaces and solids get infinite boxes */
        *s = sh->infinite ? bb_all() : own;
        *v = geom_shape_solid_bounded(sh) ? own : bb_all();
        break;
    }
    if (inverse) *v = bb_all();
}

/* Plane pl's solid (n.p < d in world; `outside`: its complement, n.p >= d)
 * in shape q's own object space: where it is a half-space along one of q's
 * axes there, that axis's range in lo/hi is narrowed to it. */
static void plane_limit(const geom_shape *q, const geom_shape *pl, int outside, double *lo, double *hi)
{
    /* world n.p < d with p = A y + t: (A^T n).y < d - n.t */
    vec3 nw = pl->identity ? pl->g.plane.n : v3_norm(xform_normal(&pl->x, pl->g.plane.n));
    vec3 p0 = v3_scale(pl->g.plane.n, pl->g.plane.d);
    if (!pl->identity) p0 = xform_point(&pl->x, p0);
    if (outside) nw = v3_neg(nw);
    double d = v3_dot(nw, p0), nl[3], big = 0.0;
    for (int a = 0; a < 3; a++) {
        nl[a] = q->x.m[0][a] * nw.x + q->x.m[1][a] * nw.y + q->x.m[2][a] * nw.z;
        big = fmax(big, fabs(nl[a]));
    }
    int axis = -1, others = 0;
    for (int a = 0; a < 3; a++)
        if (fabs(nl[a]) > 1e-9 * big) {
            if (axis < 0) axis = a;
            else others = 1;
        }
    if (axis < 0 || others) return;
    double bound = (d - (nw.x * q->x.m[0][3] + nw.y * q->x.m[1][3] + nw.z * q->x.m[2][3])) / nl[axis];
    if (nl[axis] > 0.0) hi[axis] = fmin(hi[axis], bound);
    else lo[axis] = fmax(lo[axis], bound);
}

/* A difference whose first member is a bounded leaf and whose subtracted
 * members include planes (a hull cut into quarters by the planes x = 0,
 * z = 0 of its own frame and turned as a whole): the part of the first
 * member that can remain is its object-space box with the subtracted
 * half-spaces cut away there, carried to world. The first member's boxes
 * (where it is inside, where its kept crossings lie) shrink to it; every
 * point cut away is inside a subtracted member, so nothing kept is lost. */
static void difference_cut(const geom_csg *c, const int *k, int n, bbox *S, bbox *V)
{
    const geom_csg_node *first = &c->nodes[k[0]];
    if (first->op != GEOM_CSG_LEAF || first->inverse) return;
    const geom_shape *q = &c->shapes[first->shape];
    if (q->infinite || !v3_finite(q->olo) || !v3_finite(q->ohi) || q->kind == SHAPE_PLANE) return;
    double lo[3] = {q->olo.x, q->olo.y, q->olo.z}, hi[3] = {q->ohi.x, q->ohi.y, q->ohi.z};
    int cut = 0;
    for (int j = 1; j < n; j++) {
        const geom_csg_node *kj = &c->nodes[k[j]];
        if (kj->op != GEOM_CSG_LEAF || c->shapes[kj->shape].kind != SHAPE_PLANE) continue;
        /* what remains is outside the subtracted solid */
        plane_limit(q, &c->shapes[kj->shape], !kj->inverse, lo, hi);
        cut = 1;
    }
    if (!cut) return;
    bbox r = bb_empty();
    if (lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2])
        for (int corner = 0; corner < 8; corner++) {
            vec3 y = v3(corner & 1 ? hi[0] : lo[0], corner & 2 ? hi[1] : lo[1], corner & 4 ? hi[2] : lo[2]);
            vec3 w = xform_point(&q->x, y);
            r.lo = v3_min(r.lo, w);
            r.hi = v3_max(r.hi, w);
        }
    r = bb_empty_p(r) ? bb_empty() : pad_box(r);
    V[k[0]] = bb_inter(V[k[0]], r);
    S[k[0]] = bb_inter(S[k[0]], r);
}

/* Where quadric q's inside can be in its own object space, from the
 * members it is intersected with: gathered in lo/hi from node `node` (a
 * member that must contain the point): an axis-aligned plane there bounds
 * one side, an intersection passes on to its members, another member with
 * a finite inside box carries that box over corner by corner. */
static void local_limits(const geom_csg *c, const geom_shape *q, int node, const bbox *V, double *lo, double *hi, int depth)
{
    const geom_csg_node *nd = &c->nodes[node];
    if (nd->inverse || depth > 64) return;
    if (nd->op == GEOM_CSG_INTERSECTION) {
        for (int i = 0; i < nd->nkids; i++) local_limits(c, q, c->kids[nd->first + i], V, lo, hi, depth + 1);
        return;
    }
    if (nd->op == GEOM_CSG_LEAF && c->shapes[nd->shape].kind == SHAPE_PLANE) {
        plane_limit(q, &c->shapes[nd->shape], 0, lo, hi);
        return;
    }
    bbox b = V[node];
    if (!v3_finite(b.lo) || !v3_finite(b.hi)) return;
    vec3 blo = v3s(INFINITY), bhi = v3s(-INFINITY);
    for (int corner = 0; corner < 8; corner++) {
        vec3 w = v3(corner & 1 ? b.hi.x : b.lo.x, corner & 2 ? b.hi.y : b.lo.y, corner & 4 ? b.hi.z : b.lo.z);
        vec3 y = xform_inv_point(&q->x, w);
        blo = v3_min(blo, y);
        bhi = v3_max(bhi, y);
    }
    lo[0] = fmax(lo[0], blo.x); lo[1] = fmax(lo[1], blo.y); lo[2] = fmax(lo[2], blo.z);
    hi[0] = fmin(hi[0], bhi.x); hi[1] = fmin(hi[1], bhi.y); hi[2] = fmin(hi[2], bhi.z);
}

/* The world box of the inside of quadric leaf `leaf`, from everything it is
 * intersected with (its siblings and, up through intersections, theirs),
 * worked out in the quadric's own space and carried back to world: an
 * object defined axis-aligned and turned as a whole (a clipped quadric the
 * scene rotates) gets a finite box, as POV-Ray's box computed before the
 * turn and transformed with it. 0 when nothing bounded comes out. */
static int quadric_box_local(const geom_csg *c, int leaf, const bbox *V, bbox *out)
{
    const geom_shape *q = &c->shapes[c->nodes[leaf].shape];
    double lo[3] = {-INFINITY, -INFINITY, -INFINITY}, hi[3] = {INFINITY, INFINITY, INFINITY};
    for (int child = leaf, par = c->nodes[leaf].parent; par >= 0; child = par, par = c->nodes[par].parent) {
        const geom_csg_node *P = &c->nodes[par];
        if (P->op != GEOM_CSG_INTERSECTION || P->inverse) break;
        for (int i = 0; i < P->nkids; i++)
            if (c->kids[P->first + i] != child) local_limits(c, q, c->kids[P->first + i], V, lo, hi, 0);
    }
    vec3 ql, qh;
    if (!geom_quadric_solid_box(q, 1, v3(lo[0], lo[1], lo[2]), v3(hi[0], hi[1], hi[2]), &ql, &qh)) return 0;
    if (!v3_finite(ql) || !v3_finite(qh)) return 0;
    bbox r = bb_empty();
    for (int corner = 0; corner < 8; corner++) {
        vec3 y = v3(corner & 1 ? qh.x : ql.x, corner & 2 ? qh.y : ql.y, corner & 4 ? qh.z : ql.z);
        vec3 w = xform_point(&q->x, y);
        r.lo = v3_min(r.lo, w);
        r.hi = v3_max(r.hi, w);
    }
    *out = pad_box(r);
    return 1;
}

/* ------------------------------------------------------------ members' hierarchy */

#define CSG_BVH_LEAF 4

static double keep_centre(const geom_csg *c, int s, int axis)
{
    return 0.5 * (v3_idx(c->keep_box[2 * s], axis) + v3_idx(c->keep_box[2 * s + 1], axis));
}

/* Reorders it[0 .. n) so that it[k] has the k-th smallest keep-box centre
 * along axis, the smaller ones before it (Hoare's selection). */
static void select_kth(const geom_csg *c, int *it, int n, int k, int axis)
{
    int lo = 0, hi = n - 1;
    while (lo < hi) {
        double piv = keep_centre(c, it[(lo + hi) / 2], axis);
        int i = lo, j = hi;
        while (i <= j) {
            while (keep_centre(c, it[i], axis) < piv) i++;
            while (keep_centre(c, it[j], axis) > piv) j--;
            if (i <= j) {
                int tmp = it[i];
                it[i++] = it[j];
                it[j--] = tmp;
            }
        }
        if (k <= j) hi = j;
        else if (k >= i) lo = i;
        else break;
    }
}

/* Node over bvh_items[first .. first + n): median split along the longest
 * axis of the boxes' centres; returns its index (*nn nodes so far). */
static int bvh_node(geom_csg *c, int first, int n, int *nn)
{
    int me = (*nn)++;
    bbox box = bb_empty(), cen = bb_empty();
    for (int i = first; i < first + n; i++) {
        int s = c->bvh_items[i];
        bbox b = {c->keep_box[2 * s], c->keep_box[2 * s + 1]};
        vec3 m = v3_scale(v3_add(b.lo, b.hi), 0.5);
        box = bb_union(box, b);
        cen = bb_union(cen, (bbox){m, m});
    }
    c->bvh[me].lo = box.lo;
    c->bvh[me].hi = box.hi;
    if (n <= CSG_BVH_LEAF) {
        c->bvh[me].first = first;
        c->bvh[me].count = n;
        return me;
    }
    vec3 ext = v3_sub(cen.hi, cen.lo);
    int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : ext.y >= ext.z ? 1 : 2;
    select_kth(c, c->bvh_items + first, n, n / 2, axis);
    bvh_node(c, first, n / 2, nn);
    c->bvh[me].first = bvh_node(c, first + n / 2, n - n / 2, nn);
    c->bvh[me].count = 0;
    return me;
}

/* The hierarchy over the members with a finite keep box (those with an
 * empty one are never tried, nor surfaceless ones); without memory for
 * it, rays try every member as below it. */
static void build_bvh(geom_csg *c)
{
    int n = 0, nu = 0;
    c->bvh_items = malloc((size_t)c->nshapes * sizeof(int));
    c->unbounded = malloc((size_t)c->nshapes * sizeof(int));
    c->bvh = malloc((size_t)(2 * c->nshapes) * sizeof(geom_csg_bvh));
    if (!c->bvh_items || !c->unbounded || !c->bvh) goto fail;
    for (int s = 0; s < c->nshapes; s++) {
        const vec3 *kb = c->keep_box + 2 * s;
        if (c->nodes[c->shape_node[s]].nosurf || !(kb[0].x <= kb[1].x)) continue;
        if (v3_finite(kb[0]) && v3_finite(kb[1])) c->bvh_items[n++] = s;
        else c->unbounded[nu++] = s;
    }
    c->nunbounded = nu;
    if (n == 0) goto fail;
    int nn = 0;
    bvh_node(c, 0, n, &nn);
    return;
fail:
    free(c->bvh_items);
    free(c->unbounded);
    free(c->bvh);
    c->bvh_items = c->unbounded = NULL;
    c->bvh = NULL;
    c->nunbounded = 0;
}

/* c->keep_lo/hi and the holes (geom_csg.h), from the keep boxes. */
static void find_holes(geom_csg *c)
{
    c->nholes = 0;
    bbox u = bb_empty();
    for (int sh = 0; sh < c->nshapes; sh++) {
        vec3 lo = c->keep_box[2 * sh], hi = c->keep_box[2 * sh + 1];
        if (!(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z)) continue; /* never searched */
        /* an unbounded keep box, or a member searched from the ray's start
         * (try_member: isosurfaces), leaves no stretch to test */
        if (!v3_finite(lo) || !v3_finite(hi) || c->shapes[sh].kind == SHAPE_ISOSURFACE) return;
        u = bb_union(u, (bbox){lo, hi});
    }
    if (bb_empty_p(u)) return;
    c->keep_lo = u.lo;
    c->keep_hi = u.hi;
    const geom_csg_node *root = &c->nodes[0];
    if (root->op != GEOM_CSG_DIFFERENCE || root->inverse) return;
    const int *k = c->kids + root->first;
    for (int j = 1; j < root->nkids && c->nholes < GEOM_CSG_MAX_HOLES; j++) {
        const geom_csg_node *nd = &c->nodes[k[j]];
        if (nd->op != GEOM_CSG_LEAF || nd->inverse) continue;
        const geom_shape *sh = &c->shapes[nd->shape];
        if (sh->kind != SHAPE_BOX || !sh->identity) continue;
        /* geom_shape_inside's box is open: a point is inside it when
         * strictly within its faces; the margin (1e-9 of its size, 1e-12
         * of the coordinates) keeps the points tested, and the crossings
         * computed between them on the same line, strictly within */
        vec3 lo = sh->g.box.lo, hi = sh->g.box.hi, m;
        for (int a = 0; a < 3; a++) {
            double l = v3_idx(lo, a), h = v3_idx(hi, a);
            double mm = 1e-9 * (h - l) + 1e-12 * fmax(fabs(l), fabs(h)) + 1e-300;
            if (a == 0) m.x = mm;
            else if (a == 1) m.y = mm;
            else m.z = mm;
        }
        lo = v3_add(lo, m);
        hi = v3_sub(hi, m);
        if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z) || !v3_finite(lo) || !v3_finite(hi)) continue;
        c->hole_lo[c->nholes] = lo;
        c->hole_hi[c->nholes] = hi;
        c->nholes++;
    }
}

int geom_csg_finish(geom_csg *c)
{
    if (c->nnodes == 0) return 0;
    /* member lists, in insertion order */
    int *count = calloc((size_t)c->nnodes, sizeof(int));
    bbox *S = malloc((size_t)c->nnodes * sizeof(bbox)), *V = malloc((size_t)c->nnodes * sizeof(bbox));
    c->kids = malloc((size_t)c->nnodes * sizeof(int));
    if (!count || !S || !V || !c->kids) {
        free(count); free(S); free(V);
        return 0;
    }
    c->nkids = c->capkids = c->nnodes;
    for (int i = 1; i < c->nnodes; i++) count[c->nodes[i].parent]++;
    int pos = 0;
    for (int i = 0; i < c->nnodes; i++) {
        c->nodes[i].first = pos;
        c->nodes[i].nkids = 0;
        pos += count[i];
    }
    for (int i = 1; i < c->nnodes; i++) {
        geom_csg_node *p = &c->nodes[c->nodes[i].parent];
        c->kids[p->first + p->nkids++] = i;
    }
    /* inverse parity, parents before children (parents have smaller
     * indices); a subtracted member counts as inverted (POV-Ray's
     * difference is an intersection with its other members inverted) */
    for (int i = 0; i < c->nnodes; i++) {
        geom_csg_node *nd = &c->nodes[i];
        int odd = nd->inverse;
        if (nd->parent >= 0) {
            const geom_csg_node *p = &c->nodes[nd->parent];
            odd ^= p->inv_odd;
            if (p->op == GEOM_CSG_DIFFERENCE && c->kids[p->first] != i) odd ^= 1;
        }
        nd->inv_odd = odd;
    }
    /* normal flips: inverse nodes and subtracted members on the way to the root */
    for (int s = 0; s < c->nshapes; s++) {
        int flip = 0;
        for (int n = c->shape_node[s]; n >= 0; n = c->nodes[n].parent) {
            const geom_csg_node *nd = &c->nodes[n];
            if (nd->inverse) flip ^= 1;
            if (nd->parent >= 0) {
                const geom_csg_node *p = &c->nodes[nd->parent];
                if (p->op == GEOM_CSG_DIFFERENCE && c->kids[p->first] != n) flip ^= 1;
            }
        }
        c->nodes[c->shape_node[s]].flip = flip;
    }
    /* bounds, children before parents (children have larger indices) */
    for (int i = c->nnodes - 1; i >= 0; i--) {
        geom_csg_node *nd = &c->nodes[i];
        const int *k = c->kids + nd->first;
        int n = nd->nkids;
        bbox s = bb_empty(), v = bb_empty();
        switch (nd->op) {
        case GEOM_CSG_LEAF:
            leaf_boxes(&c->shapes[nd->shape], nd->inverse, &s, &v);
            if (nd->nosurf) s = bb_empty();
            break;
        case GEOM_CSG_UNION:
        case GEOM_CSG_MERGE:
            for (int j = 0; j < n; j++) {
                s = bb_union(s, S[k[j]]);
                v = bb_union(v, V[k[j]]);
            }
            break;
        case GEOM_CSG_INTERSECTION:
            v = n > 0 ? bb_all() : bb_empty();
            for (int j = 0; j < n; j++) v = bb_inter(v, V[k[j]]);
            /* an unbounded quadric member: the box of its inside within the
             * others' box (POV-Ray bounds quadrics last, within what the
             * other members leave); its surface lies in that box too */
            for (int j = 0; j < n; j++) {
                const geom_csg_node *kj = &c->nodes[k[j]];
                if (kj->op != GEOM_CSG_LEAF || kj->inverse || !c->shapes[kj->shape].infinite) continue;
                bbox q;
                if (!geom_quadric_solid_box(&c->shapes[kj->shape], 0, v.lo, v.hi, &q.lo, &q.hi) &&
                    !quadric_box_local(c, k[j], V, &q))
                    continue;
                V[k[j]] = bb_inter(V[k[j]], q);
                S[k[j]] = bb_inter(S[k[j]], q);
                v = bb_inter(v, q);
            }
            for (int j = 0; j < n; j++) {
                bbox sj = S[k[j]];
                for (int m = 0; m < n; m++)
                    if (m != j) sj = bb_inter(sj, V[k[m]]);
                s = bb_union(s, sj);
            }
            break;
        case GEOM_CSG_DIFFERENCE:
            if (n > 0) {
                difference_cut(c, k, n, S, V);
                s = S[k[0]];
                v = V[k[0]];
                for (int j = 1; j < n; j++) s = bb_union(s, bb_inter(S[k[j]], V[k[0]]));
            }
            break;
        }
        if (nd->op != GEOM_CSG_LEAF && nd->inverse) v = bb_all();
        /* normalise empty boxes so unions with them stay neutral */
        S[i] = bb_empty_p(s) ? bb_empty() : s;
        V[i] = bb_empty_p(v) ? bb_empty() : v;
    }
    c->lo = S[0].lo;
    c->hi = S[0].hi;
    int ok = !bb_empty_p(S[0]) && c->nshapes > 0;
    /* the boxes kept for rays and inside tests, padded against rounding */
    free(c->keep_box);
    free(c->inside_box);
    c->keep_box = malloc((size_t)(c->nshapes > 0 ? c->nshapes : 1) * 2 * sizeof(vec3));
    c->inside_box = malloc((size_t)c->nnodes * 2 * sizeof(vec3));
    if (c->keep_box && c->inside_box) {
        for (int i = 0; i < c->nnodes; i++) {
            bbox v = pad_box(V[i]);
            c->inside_box[2 * i] = v.lo;
            c->inside_box[2 * i + 1] = v.hi;
        }
        for (int sh = 0; sh < c->nshapes; sh++) {
            int node = c->shape_node[sh];
            bbox kb = S[node];
            /* a crossing is kept only inside an intersection's other members
             * and, for a subtracted member, inside the first one
             * (geom_csg_kept) */
            for (int child = node, par = c->nodes[node].parent; par >= 0 && !bb_empty_p(kb);
                 child = par, par = c->nodes[par].parent) {
                const geom_csg_node *P = &c->nodes[par];
                const int *k = c->kids + P->first;
                if (P->op == GEOM_CSG_INTERSECTION) {
                    for (int j = 0; j < P->nkids; j++)
                        if (k[j] != child) kb = bb_inter(kb, V[k[j]]);
                } else if (P->op == GEOM_CSG_DIFFERENCE && P->nkids > 0 && k[0] != child) {
                    kb = bb_inter(kb, V[k[0]]);
                }
            }
            kb = bb_empty_p(kb) ? bb_empty() : pad_box(kb);
            c->keep_box[2 * sh] = kb.lo;
            c->keep_box[2 * sh + 1] = kb.hi;
        }
        if (c->nshapes > GEOM_CSG_BVH_MIN) build_bvh(c);
        find_holes(c);
    } else {
        free(c->keep_box);
        free(c->inside_box);
        c->keep_box = c->inside_box = NULL;
        c->nholes = 0;
    }
    free(count);
    free(S);
    free(V);
    return ok;
}

void geom_csg_clip(geom_csg *c, vec3 lo, vec3 hi)
{
    for (int i = 0; i < c->nshapes; i++)
        if (c->shapes[i].kind == SHAPE_PLANE || c->shapes[i].infinite) geom_shape_clip_plane(&c->shapes[i], lo, hi);
    c->lo = v3_max(c->lo, lo);
    c->hi = v3_min(c->hi, hi);
}

void geom_csg_free(geom_csg *c)
{
    if (!c) return;
    for (int i = 0; i < c->nshapes; i++) geom_shape_release(&c->shapes[i]);
    free(c->nodes);
    free(c->kids);
    free(c->shapes);
    free(c->shape_leaf);
    free(c->shape_node);
    free(c->keep_box);
    free(c->inside_box);
    free(c->bvh);
    free(c->bvh_items);
    free(c->unbounded);
    memset(c, 0, sizeof *c);
}

int geom_csg_inside(const geom_csg *c, int node, vec3 p)
{
    const geom_csg_node *nd = &c->nodes[node];
    /* outside the box of its inside (an inverse node's box is everything) */
    if (c->inside_box && !in_box(c->inside_box + 2 * node, p)) return 0;
    const int *k = c->kids + nd->first;
    int r = 0;
    switch (nd->op) {
    case GEOM_CSG_LEAF:
        r = geom_shape_inside(&c->shapes[nd->shape], p);
        break;
    case GEOM_CSG_UNION:
    case GEOM_CSG_MERGE:
        for (int j = 0; j < nd->nkids && !r; j++) r = geom_csg_inside(c, k[j], p);
        break;
    case GEOM_CSG_INTERSECTION:
        r = nd->nkids > 0;
        for (int j = 0; j < nd->nkids && r; j++) r = geom_csg_inside(c, k[j], p);
        break;
    case GEOM_CSG_DIFFERENCE:
        r = nd->nkids > 0 && geom_csg_inside(c, k[0], p);
        for (int j = 1; j < nd->nkids && r; j++) r = !geom_csg_inside(c, k[j], p);
        break;
    }
    return r ^ nd->inverse;
}

int geom_csg_kept(const geom_csg *c, int node, vec3 p)
{
    assert(node >= 0 && node < c->nnodes && c->nodes[node].op == GEOM_CSG_LEAF);
    int child = node;
    for (int par = c->nodes[child].parent; par >= 0; child = par, par = c->nodes[par].parent) {
        const geom_csg_node *P = &c->nodes[par];
        const int *k = c->kids + P->first;
        geom_csg_op op = P->op;
        /* an inverted union is POV-Ray's intersection of inverted members:
         * its surfaces are a merge's (geom_csg.h) */
        if (op == GEOM_CSG_UNION && P->inv_odd) op = GEOM_CSG_MERGE;
        switch (op) {
        case GEOM_CSG_MERGE:
            for (int j = 0; j < P->nkids; j++)
                if (k[j] != child && geom_csg_inside(c, k[j], p)) return 0;
            break;
        case GEOM_CSG_INTERSECTION:
            for (int j = 0; j < P->nkids; j++)
                if (k[j] != child && !geom_csg_inside(c, k[j], p)) return 0;
            break;
        case GEOM_CSG_DIFFERENCE:
            if (k[0] != child && !geom_csg_inside(c, k[0], p)) return 0;
            for (int j = 1; j < P->nkids; j++)
                if (k[j] != child && geom_csg_inside(c, k[j], p)) return 0;
            break;
        default:
            break;
        }
    }
    return 1;
}

/* Each member's crossings are walked in order, a chunk at a time (shapes
 * the sweeps and implicit shapes may have many), until one that the inside rules keep; the
 * nearest kept crossing over all members is the answer. */
#define CSG_CHUNK 8

/* A ray as the members are searched: inv = 1 / dir per component for the
 * keep boxes' slab tests (one ray meets many boxes), whether every
 * component of dir is non-zero with a finite inverse (regular: the slab
 * tests need no case for a ray parallel to a face), and whether any kept
 * crossing will do (an occlusion query) rather than the nearest; the
 * rule the members' crossings are placed by. */
typedef struct {
    vec3 org, dir, inv;
    double tmin;
    int any, regular;
    geom_ray_rule rule;
} csg_ray;

/* One axis of keep_slab: v3_slab_axis's arithmetic for a ray that is not
 * parallel to the slab, so that the interval is the same to the bit. */
#define KEEP_SLAB_AXIS(c)                                                                                              \
    do {                                                                                                               \
        double x_ = (lo.c - R->org.c) * R->inv.c, y_ = (hi.c - R->org.c) * R->inv.c;                                   \
        if (x_ > y_) {                                                                                                 \
            double t_ = x_;                                                                                            \
            x_ = y_;                                                                                                   \
            y_ = t_;                                                                                                   \
        }                                                                                                              \
        if (x_ > a) a = x_;                                                                                            \
        if (y_ < b) b = y_;                                                                                            \
    } while (0)

/* v3_slab_inv of the ray against the box [lo, hi], the same interval;
 * inline and without the parallel cases for a regular ray, which is most
 * of them (a ray meets most of a CSG's keep boxes only to be turned away
 * by this test). */
__attribute__((always_inline)) static inline int keep_slab(const csg_ray *R, vec3 lo, vec3 hi, double *t0, double *t1)
{
    if (!R->regular) return v3_slab_inv(R->org, R->dir, R->inv, lo, hi, t0, t1);
    double a = -INFINITY, b = INFINITY;
    KEEP_SLAB_AXIS(x);
    KEEP_SLAB_AXIS(y);
    KEEP_SLAB_AXIS(z);
    if (!(a <= b)) return 0;
    *t0 = a;
    *t1 = b;
    return 1;
}

/* The stretch [*from, *upto] of the ray where member s's crossings can be
 * kept, within (tmin, best): 0 when there is none. The ray must cross
 * where this member's crossings can be kept, and only that stretch is
 * searched (a clipped quartic's root finder then works on the clip box's
 * chord, not the whole ray); an isosurface's crossings count from the
 * ray's start (max_trace), so its search starts there. The stretch is
 * padded by 1e-9 of its distances, far above the ulp by which the product
 * with inv may move its ends. Inline: the search loops turn most members
 * away here, before a call. */
__attribute__((always_inline)) static inline int member_stretch(const geom_csg *c, int s, const csg_ray *R, double best, double *from, double *upto)
{
    *from = R->tmin;
    *upto = INFINITY;
    if (c->keep_box) {
        const vec3 *kb = c->keep_box + 2 * s;
        double t0, t1;
        if (!(kb[0].x <= kb[1].x) || !keep_slab(R, kb[0], kb[1], &t0, &t1)) return 0;
        double pad = 1e-9 * (fabs(t0) + fabs(t1)) + 1e-300;
        if (t1 + pad < R->tmin || t0 - pad > best) return 0;
        *upto = t1 + pad;
        if (c->shapes[s].kind != SHAPE_ISOSURFACE && t0 - pad > R->tmin) *from = t0 - pad;
    }
    return !c->nodes[c->shape_node[s]].nosurf;
}

/* Member s's nearest kept crossing in (from, min(*best, upto)), its stretch
 * from member_stretch: into *h, *best lowered, 1 returned. Not inlined: the
 * loops over the members call it only for those member_stretch lets
 * through, and inline it would make every member's test pay its set-up. */
__attribute__((noinline)) static int search_member(const geom_csg *c, int s, const csg_ray *R, double from, double upto, double *bestp,
                         geom_csg_hit *h)
{
    int found = 0;
    double best = *bestp;
    vec3 org = R->org, dir = R->dir;
    int node = c->shape_node[s];
    for (int guard = 0; guard < 1000; guard++) {
        geom_shape_hit tmp[CSG_CHUNK];
        int k = geom_shape_ray_hits(&c->shapes[s], org, dir, from, fmin(best, upto), tmp, CSG_CHUNK, R->rule);
        int kept_one = 0;
        for (int j = 0; j < k; j++) {
            if (geom_csg_kept(c, node, v3_madd(org, dir, tmp[j].t))) {
                best = tmp[j].t;
                h->t = tmp[j].t;
                h->shape = s;
                h->part = tmp[j].part;
                h->flip = c->nodes[node].flip;
                found = 1;
                kept_one = 1;
                break;
            }
        }
        if (kept_one || k < CSG_CHUNK) break;
        if (!(tmp[k - 1].t > from)) break;
        from = tmp[k - 1].t;
    }
    *bestp = best;
    return found;
}

/* Member s's nearest kept crossing in (tmin, *best): into *h, *best
 * lowered, 1 returned. */
__attribute__((always_inline)) static inline int try_member(const geom_csg *c, int s, const csg_ray *R, double *bestp, geom_csg_hit *h)
{
    double from, upto;
    if (!member_stretch(c, s, R, *bestp, &from, &upto)) return 0;
    return search_member(c, s, R, from, upto, bestp, h);
}

static inline int in_hole_box(const geom_csg *c, int i, vec3 p)
{
    vec3 lo = c->hole_lo[i], hi = c->hole_hi[i];
    return p.x > lo.x && p.x < hi.x && p.y > lo.y && p.y < hi.y && p.z > lo.z && p.z < hi.z;
}

/* Where the ray's kept crossings can start: the holes (geom_csg.h) no
 * crossing is kept in, chained along the ray from where it enters the
 * keep boxes' box (keep_lo..keep_hi) or from tmin, whichever is later.
 * Returns R->tmin when that point lies in no hole (or the ray misses that
 * box within (tmin, tmax): the members' own tests answer), INFINITY when the
 * whole stretch through the keep boxes' box lies inside the chain of
 * holes (no crossing), else a distance t (> R->tmin) such that no
 * crossing in (R->tmin, t] is kept: each point there lies before that box
 * or strictly inside some hole.
 *
 * Each link is a stretch between two points strictly inside one shrunk
 * hole (boxes are convex, so the points between are too): from the start
 * to a point inside this hole and the next one (halfway through their
 * common stretch), and so on; the last hole's stretch is cut back by the
 * pad, 4e-9 of the wider box's distances. A member is searched only on
 * its keep box's stretch padded by 1e-9 of its distances (try_member),
 * which the same pad covers. Every crossing but a hole's own is kept only
 * outside it, and a hole's own crossings lie on its faces, outside its
 * shrunk box: so none in the chain is kept. A ray from a courtyard's
 * floor out through an arcade or a column ring (radiosity_37.pov's
 * courtyard: the walls' and the column base's subtracted boxes) crosses
 * two holes before any surface. */
static double hole_clear(const geom_csg *c, const csg_ray *R, double tmax)
{
    double t0, t1;
    if (!keep_slab(R, c->keep_lo, c->keep_hi, &t0, &t1)) return R->tmin;
    double pad = 4e-9 * (fabs(t0) + fabs(t1)) + 1e-300;
    double a = fmax_inline(t0 - pad, R->tmin), b = fmin_inline(t1 + pad, tmax);
    if (!(a <= b)) return R->tmin;
    vec3 pa = v3_madd(R->org, R->dir, a), pb = v3_madd(R->org, R->dir, b);
    int cur = -1;
    for (int i = 0; i < c->nholes && cur < 0; i++)
        if (in_hole_box(c, i, pa)) cur = i;
    if (cur < 0) return R->tmin;
    unsigned used = 1u << cur;
    double at = a; /* a point strictly inside hole cur */
    for (;;) {
        if (in_hole_box(c, cur, pb)) return INFINITY;
        double e0, e1;
        if (!keep_slab(R, c->hole_lo[cur], c->hole_hi[cur], &e0, &e1)) break;
        int next = -1;
        double next_at = 0.0, next_end = e1;
        for (int j = 0; j < c->nholes; j++) {
            double f0, f1;
            if (used >> j & 1u || !keep_slab(R, c->hole_lo[j], c->hole_hi[j], &f0, &f1)) continue;
            if (!(f1 > next_end)) continue;
            double m = 0.5 * (fmax_inline(f0, at) + e1);
            vec3 pm = v3_madd(R->org, R->dir, m);
            if (!(m > at) || !in_hole_box(c, cur, pm) || !in_hole_box(c, j, pm)) continue;
            next = j;
            next_at = m;
            next_end = f1;
        }
        if (next < 0) {
            double t = e1 - pad;
            return t > at ? t : at;
        }
        used |= 1u << next;
        cur = next;
        at = next_at;
    }
    return at;
}

/* The nearest kept crossing in (tmin, tmax), or with R->any the first one
 * met in the members' order: both find one exactly when one exists, since
 * before a member answers every search runs to tmax. */
static int csg_search(const geom_csg *c, const csg_ray *R, double tmax, geom_csg_hit *h)
{
    csg_ray Rh;
    if (c->nholes > 0) {
        double clear = hole_clear(c, R, tmax);
        if (!(clear < tmax)) return 0;
        if (clear > R->tmin) {
            Rh = *R;
            Rh.tmin = clear;
            R = &Rh;
        }
    }
    int found = 0;
    double best = tmax;
    if (!c->bvh) {
        for (int s = 0; s < c->nshapes && !(found && R->any); s++) found |= try_member(c, s, R, &best, h);
    } else {
        for (int i = 0; i < c->nunbounded && !(found && R->any); i++)
            found |= try_member(c, c->unbounded[i], R, &best, h);
        /* a node's box holds its members' keep boxes, so skipping a node
         * whose interval lies outside (tmin, best) skips only members that
         * try_member would skip (both pad the interval alike); depth is
         * log2 of the members */
        int stack[64], sp = 0;
        stack[sp++] = 0;
        while (sp > 0 && !(found && R->any)) {
            int ni = stack[--sp];
            const geom_csg_bvh *nd = &c->bvh[ni];
            double t0, t1;
            if (!keep_slab(R, nd->lo, nd->hi, &t0, &t1)) continue;
            double pad = 1e-9 * (fabs(t0) + fabs(t1)) + 1e-300;
            if (t1 + pad < R->tmin || t0 - pad > best) continue;
            if (nd->count > 0) {
                for (int k = 0; k < nd->count && !(found && R->any); k++)
                    found |= try_member(c, c->bvh_items[nd->first + k], R, &best, h);
            } else if (sp + 2 <= 64) {
                stack[sp++] = nd->first;
                stack[sp++] = ni + 1;
            }
        }
    }
    assert(!found || (h->t > R->tmin && h->t < tmax && h->shape >= 0 && h->shape < c->nshapes));
    return found;
}

static csg_ray make_ray(vec3 org, vec3 dir, double tmin, int any, geom_ray_rule rule)
{
    csg_ray R = {org, dir, v3(1.0 / dir.x, 1.0 / dir.y, 1.0 / dir.z), tmin, any, 0, rule};
    R.regular = dir.x != 0.0 && dir.y != 0.0 && dir.z != 0.0 && isfinite(R.inv.x) && isfinite(R.inv.y) &&
                isfinite(R.inv.z);
    return R;
}

int geom_csg_intersect(const geom_csg *c, vec3 org, vec3 dir, double tmin, double tmax, geom_csg_hit *h,
                       geom_ray_rule rule)
{
    csg_ray R = make_ray(org, dir, tmin, 0, rule);
    return csg_search(c, &R, tmax, h);
}

int geom_csg_occludes(const geom_csg *c, vec3 org, vec3 dir, double tmin, double tmax, geom_ray_rule rule)
{
    csg_ray R = make_ray(org, dir, tmin, 1, rule);
    geom_csg_hit h;
    return csg_search(c, &R, tmax, &h);
}

/* Member s's kept crossings in (R->tmin, tmax) appended to out[*n..max):
 * 0, or -1 when out is full or s is an isosurface. */
static int member_crossings(const geom_csg *c, int s, const csg_ray *R, double tmax, geom_csg_hit *out, int *n, int max)
{
    int node = c->shape_node[s];
    if (c->nodes[node].nosurf) return 0;
    if (c->shapes[s].kind == SHAPE_ISOSURFACE) return -1;
    double from = R->tmin, upto = tmax;
    if (c->keep_box) {
        /* try_member's stretch, with the whole interval for *best */
        const vec3 *kb = c->keep_box + 2 * s;
        double t0, t1;
        if (!(kb[0].x <= kb[1].x) || !keep_slab(R, kb[0], kb[1], &t0, &t1)) return 0;
        double pad = 1e-9 * (fabs(t0) + fabs(t1)) + 1e-300;
        if (t1 + pad < R->tmin || t0 - pad > tmax) return 0;
        upto = fmin(tmax, t1 + pad);
        if (t0 - pad > R->tmin) from = t0 - pad;
    }
    for (int guard = 0; guard < 1000; guard++) {
        geom_shape_hit tmp[CSG_CHUNK];
        int k = geom_shape_ray_hits(&c->shapes[s], R->org, R->dir, from, upto, tmp, CSG_CHUNK, R->rule);
        for (int j = 0; j < k; j++) {
            if (!geom_csg_kept(c, node, v3_madd(R->org, R->dir, tmp[j].t))) continue;
            if (*n == max) return -1;
            out[(*n)++] = (geom_csg_hit){tmp[j].t, s, tmp[j].part, c->nodes[node].flip};
        }
        if (k < CSG_CHUNK || !(tmp[k - 1].t > from)) break;
        from = tmp[k - 1].t;
    }
    return 0;
}

int geom_csg_crossings(const geom_csg *c, vec3 org, vec3 dir, double tmin, double tmax, double step, geom_csg_hit *out,
                       int max, geom_ray_rule rule)
{
    csg_ray R = make_ray(org, dir, tmin, 0, rule);
    int n = 0;
    if (!c->bvh) {
        for (int s = 0; s < c->nshapes; s++)
            if (member_crossings(c, s, &R, tmax, out, &n, max) < 0) return -1;
    } else {
        for (int i = 0; i < c->nunbounded; i++)
            if (member_crossings(c, c->unbounded[i], &R, tmax, out, &n, max) < 0) return -1;
        /* csg_search's walk with the whole interval */
        int stack[64], sp = 0;
        stack[sp++] = 0;
        while (sp > 0) {
            int ni = stack[--sp];
            const geom_csg_bvh *nd = &c->bvh[ni];
            double t0, t1;
            if (!keep_slab(&R, nd->lo, nd->hi, &t0, &t1)) continue;
            double pad = 1e-9 * (fabs(t0) + fabs(t1)) + 1e-300;
            if (t1 + pad < R.tmin || t0 - pad > tmax) continue;
            if (nd->count > 0) {
                for (int k = 0; k < nd->count; k++)
                    if (member_crossings(c, c->bvh_items[nd->first + k], &R, tmax, out, &n, max) < 0) return -1;
            } else if (sp + 2 <= 64) {
                stack[sp++] = nd->first;
                stack[sp++] = ni + 1;
            }
        }
    }
    /* nearest first; of equal ones the lower member, as the search keeps
     * the first member's crossing when another's is not nearer */
    for (int i = 1; i < n; i++) {
        geom_csg_hit h = out[i];
        int j = i;
        for (; j > 0 && (out[j - 1].t > h.t || (out[j - 1].t == h.t && out[j - 1].shape > h.shape)); j--) out[j] = out[j - 1];
        out[j] = h;
    }
    int m = 0;
    double from = tmin;
    for (int i = 0; i < n; i++) {
        if (!(out[i].t > from) || !(out[i].t < tmax)) continue;
        out[m++] = out[i];
        from = out[i].t + fmax(step, out[i].t * 1e-7);
    }
    return m;
}

/* ------------------------------------------------------------ building */

int geom_csg_has_mesh(const scene_object *o, int depth)
{
    if (!o || depth > GEOM_CSG_MAX_DEPTH) return 0;
    if (o->kind == SHAPE_MESH) return 1;
    if (scene_object_is_csg(o))
        for (int i = 0; i < o->u.csg.nkids; i++)
            if (geom_csg_has_mesh(o->u.csg.kids[i], depth + 1)) return 1;
    return 0;
}

long geom_csg_leaf_count(const scene_object *o, int depth)
{
    if (!o || depth > GEOM_CSG_MAX_DEPTH) return 0;
    if (!scene_object_is_csg(o)) return 1;
    long n = 0;
    for (int i = 0; i < o->u.csg.nkids; i++) n += geom_csg_leaf_count(o->u.csg.kids[i], depth + 1);
    return n;
}

/* `post` (clipped_by solids, whose transforms are relative to their host)
 * is applied after the member's own transform; `nosurf` marks leaves that
 * only take part in inside tests; `clip_done` says o's own clipped_by has
 * been wrapped around it already. */
static pt_status build(geom_csg *c, const scene_object *o, const scene_texture *ptex, unsigned pflags, int parent,
                       int depth, geom_csg_builder *b, const xform *post, int nosurf, int clip_done)
{
    if (!o) return PT_OK;
    const scene_texture *tex = o->texture ? o->texture : ptex;
    unsigned flags = o->flags | (pflags & b->inherit);
    int inverse = (o->flags & OBJ_INVERSE) != 0;
    geom_csg_op parent_op = parent >= 0 ? c->nodes[parent].op : GEOM_CSG_UNION;
    if ((o->clip && !clip_done) || scene_object_is_csg(o)) {
        if (depth >= GEOM_CSG_MAX_DEPTH) {
            if (b->d) diag_report(b->d, DIAG_ERROR, o->loc, NULL, "CSG nesting deeper than %d levels", GEOM_CSG_MAX_DEPTH);
            return PT_ERR_LIMIT;
        }
    }
    if (o->clip && !clip_done) {
        int node = geom_csg_add_node(c, GEOM_CSG_INTERSECTION, 0, parent);
        if (node < 0) return PT_ERR_NOMEM;
        pt_status st = build(c, o, ptex, pflags, node, depth + 1, b, post, nosurf, 1);
        if (st != PT_OK) return st;
        xform host = post ? xform_then(o->transform, *post) : o->transform;
        return build(c, o->clip, tex, flags, node, depth + 1, b, &host, 1, 0);
    }
    if (scene_object_is_csg(o)) {
        geom_csg_op op = o->kind == SHAPE_UNION ? GEOM_CSG_UNION
                       : o->kind == SHAPE_MERGE ? GEOM_CSG_MERGE
                       : o->kind == SHAPE_INTERSECTION ? GEOM_CSG_INTERSECTION : GEOM_CSG_DIFFERENCE;
        int node = geom_csg_add_node(c, op, inverse, parent);
        if (node < 0) return PT_ERR_NOMEM;
        for (int i = 0; i < o->u.csg.nkids; i++) {
            pt_status st = build(c, o->u.csg.kids[i], tex, flags, node, depth + 1, b, post, nosurf, 0);
            if (st != PT_OK) return st;
        }
        return PT_OK;
    }
    int ok = 0;
    geom_shape sh;
    scene_object moved;
    const scene_object *src = o;
    if (post) {
        moved = *o;
        moved.transform = xform_then(o->transform, *post);
        src = &moved;
    }
    switch (o->kind) {
    case SHAPE_SPHERE: case SHAPE_BOX: case SHAPE_PLANE: case SHAPE_TRIANGLE: case SHAPE_SMOOTH_TRIANGLE:
    case SHAPE_CYLINDER: case SHAPE_CONE: case SHAPE_DISC: case SHAPE_TORUS:
    case SHAPE_POLYGON: case SHAPE_LATHE: case SHAPE_SOR: case SHAPE_PRISM: case SHAPE_SUPERELLIPSOID:
    case SHAPE_QUADRIC: case SHAPE_POLY: case SHAPE_BLOB: case SHAPE_HEIGHT_FIELD: case SHAPE_TEXT: case SHAPE_ISOSURFACE:
    case SHAPE_JULIA: case SHAPE_OVUS:
        ok = geom_shape_init(&sh, src) == 0;
        break;
    case SHAPE_MESH:
        if (!b->meshes) goto unsupported;
        ok = geom_shape_init_mesh(&sh, src) == 0;
        break;
    default:
    unsupported:
        b->unsupported++;
        if (b->d) diag_warn_once(b->d, o->loc, "%s is not rendered yet", o->name ? o->name : "this shape");
        if (parent_op == GEOM_CSG_INTERSECTION) return PT_OK;
        return geom_csg_add_node(c, GEOM_CSG_UNION, inverse, parent) < 0 ? PT_ERR_NOMEM : PT_OK;
    }
    if (!ok) {
        if (b->d)
            diag_warn_once(b->d, o->loc, "degenerate %s ignored (zero size, singular transform or non-finite numbers)",
                           o->name ? o->name : "shape");
        if (parent_op == GEOM_CSG_INTERSECTION) return PT_OK;
        return geom_csg_add_node(c, GEOM_CSG_UNION, inverse, parent) < 0 ? PT_ERR_NOMEM : PT_OK;
    }
    int tag = b->leaf ? b->leaf(b->ctx, o, tex, flags) : 0;
    int leaf = tag < 0 ? -1 : geom_csg_add_leaf(c, &sh, (unsigned)tag, inverse, parent);
    if (leaf < 0) {
        geom_shape_release(&sh);
        return PT_ERR_NOMEM;
    }
    c->nodes[leaf].nosurf = nosurf;
    return PT_OK;
}

pt_status geom_csg_build(geom_csg *c, const scene_object *o, const scene_texture *tex, unsigned flags, int parent,
                         int depth, geom_csg_builder *b)
{
    return build(c, o, tex, flags, parent, depth, b, NULL, 0, 0);
}
