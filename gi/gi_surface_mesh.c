/* gi_surface_mesh.c - grids of implicit shapes: their radiance particles are
 * a grid's vertices, and hits are located on its triangles. */
#include "gi_surface_internal.h"
#include <math.h>
#include "geom_shape.h"
#include "geom_hfield.h"
#include "geom_mesh.h"
#include "accel_surface.h"
#include "geom_sweep.h"
#include "geom_tess.h"
#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------ grids of implicit shapes */

typedef struct {
    gi_surface *g;
    int pi;
    const geom_shape *sh;
    long *vh;         /* vertex hash: global vertex index, -1 empty */
    long vcap;
    int oom;
    double split;     /* > 0: world triangles with a longer edge are bisected (split_grid) */
} mesh_ctx;

static uint64_t vkey(vec3 p)
{
    uint64_t a, b, c;
    memcpy(&a, &p.x, 8);
    memcpy(&b, &p.y, 8);
    memcpy(&c, &p.z, 8);
    return pt_mix64(a ^ pt_mix64(b ^ pt_mix64(c)));
}

static int mesh_grow_v(gi_surface *g)
{
    if (g->nmv < g->capmv) return 1;
    long nc = g->capmv ? 2 * g->capmv : 4096;
    vec3 *nv = realloc(g->mv, (size_t)nc * sizeof *nv);
    if (!nv) return 0;
    g->mv = nv;
    vec3 *nn = realloc(g->mn, (size_t)nc * sizeof *nn);
    if (!nn) return 0;
    g->mn = nn;
    g->capmv = nc;
    return 1;
}

/* Global index of the vertex at world point w (shared by the triangles
 * around it: the grid computes each lattice-edge crossing once). */
static long mesh_vertex(mesh_ctx *m, vec3 w, vec3 n)
{
    gi_surface *g = m->g;
    long first = g->p[m->pi].vfirst, used = g->nmv - first;
    if (2 * (used + 1) > m->vcap) {
        long nc = m->vcap ? 2 * m->vcap : 1024;
        long *nh = malloc((size_t)nc * sizeof *nh);
        if (!nh) return -1;
        for (long i = 0; i < nc; i++) nh[i] = -1;
        for (long v = first; v < g->nmv; v++) {
            long h = (long)(vkey(g->mv[v]) & (uint64_t)(nc - 1));
            while (nh[h] >= 0) h = (h + 1) & (nc - 1);
            nh[h] = v;
        }
        free(m->vh);
        m->vh = nh;
        m->vcap = nc;
    }
    long h = (long)(vkey(w) & (uint64_t)(m->vcap - 1));
    while (m->vh[h] >= 0) {
        vec3 q = g->mv[m->vh[h]];
        vec3 qn = g->mn[m->vh[h]];
        /* a cap's rim and the side's share positions, not normals */
        if (q.x == w.x && q.y == w.y && q.z == w.z && qn.x == n.x && qn.y == n.y && qn.z == n.z) return m->vh[h];
        h = (h + 1) & (m->vcap - 1);
    }
    if (!mesh_grow_v(g)) return -1;
    g->mv[g->nmv] = w;
    g->mn[g->nmv] = n;
    m->vh[h] = g->nmv;
    return g->nmv++;
}

/* Most grid triangles one patch may have (beyond: no grid, estimated at the hit). */
#define MESH_MAX_TRIS 4000000L

static int mesh_add(mesh_ctx *m, const vec3 w[3], const vec3 nw[3]);

/* Longest-edge bisection of a world triangle until no edge is longer than
 * m->split (Rivara's refinement: the midpoint of the longest edge joined to
 * the opposite vertex). Midpoints are 0.5 (a + b), the same bits from both
 * triangles sharing the edge, so mesh_vertex shares them; normals are the
 * normalised mean of the edge's ends (the grids' vertex normals). */
static int mesh_split(mesh_ctx *m, const vec3 w[3], const vec3 nw[3], int depth)
{
    int e = 0;
    double l = -1.0;
    for (int k = 0; k < 3; k++) {
        double d = v3_len2(v3_sub(w[(k + 1) % 3], w[k]));
        if (d > l) {
            l = d;
            e = k;
        }
    }
    if (!(l > m->split * m->split) || depth >= 40) return mesh_add(m, w, nw);
    int a = e, b = (e + 1) % 3, c = (e + 2) % 3;
    vec3 mid = v3_scale(v3_add(w[a], w[b]), 0.5);
    vec3 mn = v3_add(nw[a], nw[b]);
    mn = v3_len2(mn) > 0.0 ? v3_norm(mn) : nw[a];
    vec3 t0[3] = {w[a], mid, w[c]}, n0[3] = {nw[a], mn, nw[c]};
    vec3 t1[3] = {mid, w[b], w[c]}, n1[3] = {mn, nw[b], nw[c]};
    return mesh_split(m, t0, n0, depth + 1) && mesh_split(m, t1, n1, depth + 1);
}

static int mesh_tri(void *ctx, const vec3 p[3], const vec3 n[3])
{
    mesh_ctx *m = ctx;
    gi_surface *g = m->g;
    const patch *pp = &g->p[m->pi];
    vec3 w[3], nw[3];
    for (int k = 0; k < 3; k++) {
        w[k] = m->sh->identity ? p[k] : xform_point(&m->sh->x, p[k]);
        nw[k] = v3_norm(m->sh->identity ? n[k] : xform_normal(&m->sh->x, n[k]));
        if (!v3_finite(w[k]) || !v3_finite(nw[k])) return 1;
    }
    if (!(v3_len2(v3_cross(v3_sub(w[1], w[0]), v3_sub(w[2], w[0]))) > 0.0)) return 1; /* a cone's apex */
    if (pp->cnode >= 0) {
        /* CSG members: the triangles touching the result's surface */
        int keep = 0;
        for (int k = 0; k < 3 && !keep; k++) keep = gi_surface_csg_keep(g, pp->cnode, w[k]);
        if (!keep) return 1;
    }
    return m->split > 0.0 ? mesh_split(m, w, nw, 0) : mesh_add(m, w, nw);
}

static int mesh_add(mesh_ctx *m, const vec3 w[3], const vec3 nw[3])
{
    gi_surface *g = m->g;
    const patch *pp = &g->p[m->pi];
    if (g->nmt - pp->tfirst >= MESH_MAX_TRIS) { m->oom = 1; return 0; }
    if (!(v3_len2(v3_cross(v3_sub(w[1], w[0]), v3_sub(w[2], w[0]))) > 0.0)) return 1;
    if (g->nmt == g->capmt) {
        long nc = g->capmt ? 2 * g->capmt : 4096;
        int (*nt)[3] = realloc(g->mt, (size_t)nc * sizeof *nt);
        if (!nt) { m->oom = 1; return 0; }
        g->mt = nt;
        int *ntp = realloc(g->mtp, (size_t)nc * sizeof *ntp);
        if (!ntp) { m->oom = 1; return 0; }
        g->mtp = ntp;
        g->capmt = nc;
    }
    for (int k = 0; k < 3; k++) {
        long v = mesh_vertex(m, w[k], nw[k]);
        if (v < 0) { m->oom = 1; return 0; }
        g->mt[g->nmt][k] = (int)(v - pp->vfirst);
    }
    g->mtp[g->nmt] = m->pi;
    g->nmt++;
    return 1;
}

/* Parametric grids of the analytic shapes geom_shape_grid leaves to GI
 * (cylinder, cone, torus), in object space, n_* cells from the tessellation
 * bound (gi_surface_grid_count, at most 256 a side; object lengths times the
 * transform's largest stretch): the side of a cone/cylinder by angle and
 * height, its end caps by angle and radius (not on open ones; their rim
 * vertices are separate from the side's, each with its own normal), a torus
 * by its two angles. Vertices lie on the exact surface with its exact
 * outward normals. */

/* World length of the shape's object axis c (its transform's column c). */
static double axis_stretch(const geom_shape *sh, int c)
{
    if (sh->identity) return 1.0;
    const double (*m)[4] = sh->x.m;
    return sqrt(m[0][c] * m[0][c] + m[1][c] * m[1][c] + m[2][c] * m[2][c]);
}

/* The transform's largest stretch (1 for none). */
static double max_stretch(const geom_shape *sh)
{
    return fmax(axis_stretch(sh, 0), fmax(axis_stretch(sh, 1), axis_stretch(sh, 2)));
}

static int analytic_grid(const geom_shape *sh, double tess, geom_grid_fn fn, void *ctx)
{
    double s = max_stretch(sh);
    if (!(s > 0.0) || !isfinite(s)) return 0;
    double t = tess / s; /* the bound in object units */
    if (sh->kind == SHAPE_TORUS) {
        double R = sh->g.torus.R, r = sh->g.torus.r;
        int nu = gi_surface_grid_count(2.0 * M_PI * (R + r), t, 3, 256), nv = gi_surface_grid_count(2.0 * M_PI * r, t, 3, 256);
        for (int j = 0; j < nv; j++)
            for (int i = 0; i < nu; i++) {
                vec3 P[4], N[4];
                for (int k = 0; k < 4; k++) {
                    int ii = (i + (k & 1)) % nu, jj = (j + (k >> 1)) % nv;
                    double th = 2.0 * M_PI * ii / nu, ph = 2.0 * M_PI * jj / nv;
                    N[k] = v3(cos(ph) * cos(th), sin(ph), cos(ph) * sin(th));
                    P[k] = v3((R + r * cos(ph)) * cos(th), r * sin(ph), (R + r * cos(ph)) * sin(th));
                }
                vec3 a[3] = {P[0], P[1], P[3]}, na[3] = {N[0], N[1], N[3]};
                vec3 b[3] = {P[0], P[3], P[2]}, nb[3] = {N[0], N[3], N[2]};
                if (!fn(ctx, a, na) || !fn(ctx, b, nb)) return -1;
            }
        return 2 * nu * nv;
    }
    if (sh->kind != SHAPE_CYLINDER && sh->kind != SHAPE_CONE) return 0;
    vec3 base = sh->g.cone.base, U = sh->g.cone.u, V = sh->g.cone.v, W = sh->g.cone.w;
    double H = sh->g.cone.h, r0 = sh->g.cone.r0, r1 = sh->g.cone.r1, k = sh->g.cone.k;
    int nu = gi_surface_grid_count(2.0 * M_PI * fmax(r0, r1), t, 3, 256), nv = gi_surface_grid_count(H, t, 1, 256);
    int count = 0;
    /* side: z = H v, radius r0 + k z; normal (x u + y v) - w k rz, normalised */
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            vec3 P[4], N[4];
            for (int q = 0; q < 4; q++) {
                int ii = (i + (q & 1)) % nu, jj = j + (q >> 1);
                double th = 2.0 * M_PI * ii / nu, z = H * jj / nv, rz = r0 + k * z;
                vec3 radial = v3_add(v3_scale(U, cos(th)), v3_scale(V, sin(th)));
                P[q] = v3_add(v3_add(base, v3_scale(W, z)), v3_scale(radial, rz));
                vec3 nn = v3_sub(v3_scale(radial, rz), v3_scale(W, k * rz));
                N[q] = v3_len2(nn) > 0.0 ? v3_norm(nn) : v3_scale(W, k <= 0.0 ? 1.0 : -1.0);
            }
            vec3 a[3] = {P[0], P[1], P[3]}, na[3] = {N[0], N[1], N[3]};
            vec3 b[3] = {P[0], P[3], P[2]}, nb[3] = {N[0], N[3], N[2]};
            if (!fn(ctx, a, na) || !fn(ctx, b, nb)) return -1;
            count += 2;
        }
    if (sh->open) return count;
    /* caps: rings around the centre */
    for (int e = 0; e < 2; e++) {
        double rr = e ? r1 : r0;
        if (!(rr > 0.0)) continue;
        vec3 c = e ? v3_add(base, v3_scale(W, H)) : base, nn = e ? W : v3_neg(W);
        int nr = gi_surface_grid_count(rr, t, 1, 256);
        for (int j = 0; j < nr; j++)
            for (int i = 0; i < nu; i++) {
                vec3 P[4], N[3] = {nn, nn, nn};
                for (int q = 0; q < 4; q++) {
                    int ii = (i + (q & 1)) % nu, jj = j + (q >> 1);
                    double th = 2.0 * M_PI * ii / nu, rad = rr * jj / nr;
                    P[q] = v3_add(c, v3_scale(v3_add(v3_scale(U, cos(th)), v3_scale(V, sin(th))), rad));
                }
                vec3 b[3] = {P[0], P[3], P[2]};
                if (!fn(ctx, b, N)) return -1;
                count++;
                if (j > 0) {
                    vec3 a[3] = {P[0], P[1], P[3]};
                    if (!fn(ctx, a, N)) return -1;
                    count++;
                }
            }
    }
    return count;
}

static uint64_t cell_key(int pi, long ix, long iy, long iz)
{
    uint64_t h = pt_mix64((uint64_t)(unsigned)pi * 0x9e3779b97f4a7c15ULL ^ (uint64_t)ix);
    h = pt_mix64(h ^ (uint64_t)iy * 0xc2b2ae3d27d4eb4fULL);
    return pt_mix64(h ^ (uint64_t)iz * 0x165667b19e3779f9ULL);
}

static int cmp_cell(const void *a, const void *b)
{
    const cell_entry *x = a, *y = b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return (x->tri > y->tri) - (x->tri < y->tri);
}

/* Grids for the PIECE patches with a shape (implicit shapes) at the
 * tessellation bound: n lattice cells along the longest side of the
 * shape's world bounds, n = ceil(extent / tess) within [2, 128]; then the
 * locate hash (each triangle in the cells its box, widened by a quarter
 * cell, touches). Patches whose grid fails keep rp_count 0 (estimated at
 * the hit, as before). */
/* Shapes whose grid is split to the tessellation bound (mesh_split):
 * polygons (their even-odd region's triangles), height fields (their cells,
 * or a coarser grid of every s-th point where the cells are smaller than
 * the bound), lathe, sor, prism and text (geom_sweep_grid_cell: profile
 * segments by arc length, around or along the sweep; prism and text caps
 * are long trapezoids between vertex heights, split here). */
static int split_grid(shape_kind k)
{
    return k == SHAPE_POLYGON || k == SHAPE_HEIGHT_FIELD || k == SHAPE_LATHE || k == SHAPE_SOR || k == SHAPE_PRISM ||
           k == SHAPE_TEXT;
}

/* Triangles are split until no edge is longer than 1.5 tess: a grid cell
 * of tess x tess has a diagonal of 1.41 tess and stays two triangles (on
 * curved parts every split puts a vertex on a chord, off the surface). */
#define SPLIT_FACTOR 1.5

/* Sweep cells (lathe, sor, prism and text sides) span at most this much
 * turning of the normal, acos(0.9) = 25.8 degrees: the estimation lists'
 * default normal threshold (gi_particle.h normal_cos), so that the three
 * radiance particles a hit interpolates face within a list's cone of each
 * other. Cells sized by length alone (the bound) spanned up to 58 degrees
 * on test_gi_grids' lathe at 8,000 particles (the rim of its top: two cells
 * over 116 degrees), and a hit on the lit top interpolated radiance
 * particles of the dark side below the rim, which faces down: the lathe read -7.9% and the sor -6.4% (means of
 * particle seeds 11-14 against path 1024 spp); with this bound -2.4% and
 * -0.4% (test_gi_grids' lathe and sor). */
#define SWEEP_TURN 0.4510268117962624

static int split_grid_build(const geom_shape *sh, double tess, mesh_ctx *m)
{
    double s = max_stretch(sh);
    if (!(s > 0.0) || !isfinite(s)) return 0;
    m->split = SPLIT_FACTOR * tess;
    switch (sh->kind) {
    case SHAPE_HEIGHT_FIELD: {
        /* strides: every s-th grid point where a cell is shorter than the
         * bound in world space (x = i / nx, z = j / nz in object space) */
        int nx, nz;
        geom_hfield_cells(sh, &nx, &nz);
        if (nx < 1 || nz < 1) return 0;
        double cx = axis_stretch(sh, 0) / nx, cz = axis_stretch(sh, 2) / nz;
        double fx = cx > 0.0 ? floor(tess / cx) : 1.0, fz = cz > 0.0 ? floor(tess / cz) : 1.0;
        int sx = !(fx >= 1.0) ? 1 : (fx > nx ? nx : (int)fx), sz = !(fz >= 1.0) ? 1 : (fz > nz ? nz : (int)fz);
        return geom_hfield_coarse_grid(sh, sx, sz, mesh_tri, m);
    }
    case SHAPE_POLYGON: return geom_shape_grid(sh, 1, mesh_tri, m);
    default: return geom_sweep_grid_cell(sh, tess / s, SWEEP_TURN, mesh_tri, m);
    }
}

/* Range of locate-hash cells [x0, x1] x [y0, y1] x [z0, z1] that piece
 * p's triangle t touches: its bounding box grown by a quarter cell. */
static void tri_cells(const gi_surface *g, const patch *p, long t, long *x0, long *x1, long *y0, long *y1, long *z0,
                      long *z1)
{
    vec3 lo = v3s(INFINITY), hi = v3s(-INFINITY);
    for (int k = 0; k < 3; k++) {
        lo = v3_min(lo, g->mv[p->vfirst + g->mt[t][k]]);
        hi = v3_max(hi, g->mv[p->vfirst + g->mt[t][k]]);
    }
    double e = 0.25 * p->cell;
    *x0 = (long)floor((lo.x - e) / p->cell), *x1 = (long)floor((hi.x + e) / p->cell);
    *y0 = (long)floor((lo.y - e) / p->cell), *y1 = (long)floor((hi.y + e) / p->cell);
    *z0 = (long)floor((lo.z - e) / p->cell), *z1 = (long)floor((hi.z + e) / p->cell);
}

void gi_surface_build_meshes(gi_surface *g)
{
    g->nmv = g->nmt = 0;
    free(g->ce);
    g->ce = NULL;
    g->nce = 0;
    if (!(g->tess < 1e29)) {
        for (int i = 0; i < g->np; i++)
            if (g->p[i].kind == PATCH_PIECE) g->p[i].rp_count = 0;
        return;
    }
    long nce = 0;
    for (int i = 0; i < g->np; i++) {
        patch *p = &g->p[i];
        if (p->kind != PATCH_PIECE) continue;
        p->rp_count = 0;
        p->nt = 0;
        p->vfirst = g->nmv;
        p->tfirst = g->nmt;
        if (!p->sh || !gi_surface_has_grid(g->o[p->obj].kind) || p->nsides == 0) continue;
        double ext = v3_maxc(v3_sub(p->sh->hi, p->sh->lo));
        if (!(ext > 0.0) || !isfinite(ext)) continue;
        int n = gi_surface_grid_count(ext, g->tess, 2, 128);
        mesh_ctx m = {g, i, p->sh, NULL, 0, 0, 0.0};
        shape_kind kind = g->o[p->obj].kind;
        /* A sweep, text, cylinder, cone or torus smaller than the bound (a
         * baluster's spindle, a letter, a rod) gets no grid: its cells follow
         * the normal bound (SWEEP_TURN, the analytic grids' three cells a
         * turn) whatever its size, tens to hundreds of radiance particles
         * whose lists, one list radius across, all hold the same few area
         * particles; hits on it are estimated where they are (onthefly in
         * gi_particle_hook.c), over those same particles. */
        int analytic = kind == SHAPE_CYLINDER || kind == SHAPE_CONE || kind == SHAPE_TORUS;
        if ((analytic || (split_grid(kind) && kind != SHAPE_POLYGON && kind != SHAPE_HEIGHT_FIELD)) && ext < g->tess)
            continue;
        int r = analytic ? analytic_grid(p->sh, g->tess, mesh_tri, &m)
                    : split_grid(kind) ? split_grid_build(p->sh, g->tess, &m)
                                       : geom_shape_grid(p->sh, n, mesh_tri, &m);
        free(m.vh);
        if (r < 0 || m.oom) {
            g->nmv = p->vfirst;
            g->nmt = p->tfirst;
            continue;
        }
        p->rp_count = g->nmv - p->vfirst;
        p->nt = g->nmt - p->tfirst;
        double cell = 0.0;
        for (long t = p->tfirst; t < p->tfirst + p->nt; t++)
            for (int k = 0; k < 3; k++) {
                vec3 a = g->mv[p->vfirst + g->mt[t][k]], b = g->mv[p->vfirst + g->mt[t][(k + 1) % 3]];
                cell = fmax(cell, v3_len(v3_sub(a, b)));
            }
        p->cell = cell > 0.0 ? cell : 1.0;
        for (long t = p->tfirst; t < p->tfirst + p->nt; t++) {
            long x0, x1, y0, y1, z0, z1;
            tri_cells(g, p, t, &x0, &x1, &y0, &y1, &z0, &z1);
            nce += (x1 - x0 + 1) * (y1 - y0 + 1) * (z1 - z0 + 1);
        }
    }
    if (nce == 0) return;
    g->ce = malloc((size_t)nce * sizeof *g->ce);
    if (!g->ce) {
        /* no locate hash: hits are estimated where they are */
        for (int i = 0; i < g->np; i++)
            if (g->p[i].kind == PATCH_PIECE) g->p[i].nt = 0;
        return;
    }
    for (int i = 0; i < g->np; i++) {
        const patch *p = &g->p[i];
        if (p->kind != PATCH_PIECE) continue;
        for (long t = p->tfirst; t < p->tfirst + p->nt; t++) {
            long x0, x1, y0, y1, z0, z1;
            tri_cells(g, p, t, &x0, &x1, &y0, &y1, &z0, &z1);
            for (long z = z0; z <= z1; z++)
                for (long y = y0; y <= y1; y++)
                    for (long x = x0; x <= x1; x++) {
                        g->ce[g->nce].key = cell_key(i, x, y, z);
                        g->ce[g->nce].tri = t;
                        g->nce++;
                    }
        }
    }
    qsort(g->ce, (size_t)g->nce, sizeof *g->ce, cmp_cell);
    /* Side 0 of a patch is its sampler's normal (gi_particles); the split
     * grids' vertex normals are outward or up, accel_surface's triangles of
     * polygons and height fields have their world winding (a height
     * field's faces down): turn the grid's normals to the sampler's side. */
    for (int i = 0; i < g->np; i++) {
        const patch *p = &g->p[i];
        if (p->kind != PATCH_PIECE || p->nt == 0 || p->piece < 0 || !split_grid(g->o[p->obj].kind)) continue;
        accel_surf_sample smp;
        double w[3];
        if (!accel_surf_sample_piece(g->as, p->piece, 1.0 / 3.0, 1.0 / 3.0, NULL, &smp)) continue;
        long t = gi_surface_mesh_locate(g, i, smp.p, smp.n, w);
        if (t < 0) continue;
        const vec3 *v = g->mv + p->vfirst, *vn = g->mn + p->vfirst;
        const int *tv = g->mt[t];
        vec3 ns = v3_add(v3_add(vn[tv[0]], vn[tv[1]]), vn[tv[2]]);
        vec3 fn = v3_cross(v3_sub(v[tv[1]], v[tv[0]]), v3_sub(v[tv[2]], v[tv[0]]));
        if (v3_dot(fn, ns) < 0.0) fn = v3_neg(fn);
        if (v3_dot(fn, smp.n) < 0.0)
            for (long k = p->vfirst; k < p->vfirst + p->rp_count; k++) g->mn[k] = v3_neg(g->mn[k]);
    }
}

/* The grid triangle of PIECE patch pi nearest to q: its index, or -1.
 * ng: the hit's geometric normal (either orientation). A triangle whose
 * plane is more than 60 degrees off it counts a cell farther away: at a
 * crease (a prism's cap and side, a cylinder's rim) a hit between the
 * curve and its chords is about as near to both, and must take its own
 * part's triangle (smooth grids never differ that much between
 * neighbours). */
long gi_surface_mesh_locate(const gi_surface *g, int pi, vec3 q, vec3 ng, double w[3])
{
    const patch *p = &g->p[pi];
    if (p->nt == 0 || g->nce == 0) return -1;
    uint64_t key = cell_key(pi, (long)floor(q.x / p->cell), (long)floor(q.y / p->cell), (long)floor(q.z / p->cell));
    long lo = 0, hi = g->nce;
    while (lo < hi) {
        long mid = lo + (hi - lo) / 2;
        if (g->ce[mid].key < key) lo = mid + 1;
        else hi = mid;
    }
    long best = -1;
    double bd = INFINITY;
    for (long e = lo; e < g->nce && g->ce[e].key == key; e++) {
        long t = g->ce[e].tri;
        if (g->mtp[t] != pi) continue;
        double ww[3];
        const vec3 *v = g->mv + p->vfirst;
        vec3 a = v[g->mt[t][0]], b = v[g->mt[t][1]], c = v[g->mt[t][2]];
        double d = geom_tri_closest(q, a, b, c, ww);
        vec3 fn = v3_cross(v3_sub(b, a), v3_sub(c, a));
        double c2 = v3_dot(fn, ng);
        if (c2 * c2 < 0.25 * v3_len2(fn) * v3_len2(ng)) d += p->cell * p->cell;
        if (d < bd) {
            bd = d;
            best = t;
            w[0] = ww[0];
            w[1] = ww[1];
            w[2] = ww[2];
        }
    }
    return best;
}

