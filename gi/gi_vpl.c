/* gi_vpl.c - the VPL tree, its filtered lobes and its min-max cut (see
 * gi_vpl.h for the model and the paper's equations). */
#include "gi_vpl.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

_Static_assert(sizeof(gi_dev_vpl_node) == 96, "gi_dev_vpl_node is a fixed 96-byte device record");
_Static_assert(sizeof(gi_dev_vpl_point) == 112, "gi_dev_vpl_point is a fixed 112-byte device record");

typedef struct {
    int lo, hi;      /* its VPLs: order[lo .. hi) */
    int left, right; /* children (pre-order indices), -1 for a leaf */
    double spread;   /* gi_vpl.h's spread (percent) */
    gi_dev_vpl_node dev;
} hnode;

struct gi_vpl_tree {
    int n, nn, iterations;
    double half_diag;
    gi_vpl *v;
    int *order;
    hnode *nodes;
    struct keyed { double key; int idx; } *scratch;
};

/* eq. 5 */
static double dist5(const gi_vpl_tree *t, vec3 p, vec3 n, vec3 cp, vec3 cn)
{
    double dn = 2.0 - 2.0 * v3_dot(n, cn);
    return v3_len(v3_sub(p, cp)) / t->half_diag + sqrt(dn > 0.0 ? dn : 0.0) / 4.0;
}

static int cmp_key(const void *a, const void *b)
{
    double x = ((const struct keyed *)a)->key, y = ((const struct keyed *)b)->key;
    if (x < y) return -1;
    if (x > y) return 1;
    int i = ((const struct keyed *)a)->idx, j = ((const struct keyed *)b)->idx;
    return (i > j) - (i < j); /* ties by index: deterministic */
}

static void centre_of(const gi_vpl_tree *t, int lo, int hi, vec3 *cp, vec3 *cn)
{
    vec3 sp = v3s(0.0), sn = v3s(0.0);
    for (int k = lo; k < hi; k++) {
        sp = v3_add(sp, t->v[t->order[k]].p);
        sn = v3_add(sn, t->v[t->order[k]].n);
    }
    *cp = v3_scale(sp, 1.0 / (hi - lo));
    *cn = v3_len(sn) > 0.0 ? v3_norm(sn) : v3(0, 0, 1);
}

static int farthest(const gi_vpl_tree *t, int lo, int hi, vec3 cp, vec3 cn)
{
    int best = t->order[lo];
    double bd = -1.0;
    for (int k = lo; k < hi; k++) {
        const gi_vpl *v = &t->v[t->order[k]];
        double d = dist5(t, v->p, v->n, cp, cn);
        if (d > bd) {
            bd = d;
            best = t->order[k];
        }
    }
    return best;
}

/* 2-means into two equal halves: order[lo .. mid) nearer c1 */
static void split(gi_vpl_tree *t, int lo, int hi)
{
    vec3 cp, cn;
    centre_of(t, lo, hi, &cp, &cn);
    int a = farthest(t, lo, hi, cp, cn);
    int b = farthest(t, lo, hi, t->v[a].p, t->v[a].n);
    vec3 p1 = t->v[a].p, n1 = t->v[a].n, p2 = t->v[b].p, n2 = t->v[b].n;
    int mid = lo + (hi - lo) / 2;
    for (int it = 0; it < t->iterations; it++) {
        for (int k = lo; k < hi; k++) {
            const gi_vpl *v = &t->v[t->order[k]];
            t->scratch[k].key = dist5(t, v->p, v->n, p1, n1) - dist5(t, v->p, v->n, p2, n2);
            t->scratch[k].idx = t->order[k];
        }
        qsort(t->scratch + lo, (size_t)(hi - lo), sizeof *t->scratch, cmp_key);
        for (int k = lo; k < hi; k++) t->order[k] = t->scratch[k].idx;
        centre_of(t, lo, mid, &p1, &n1);
        centre_of(t, mid, hi, &p2, &n2);
    }
}

static int build(gi_vpl_tree *t, int lo, int hi)
{
    int i = t->nn++;
    hnode *h = &t->nodes[i];
    h->lo = lo;
    h->hi = hi;
    h->left = h->right = -1;
    if (hi - lo > 1) {
        split(t, lo, hi);
        int mid = lo + (hi - lo) / 2;
        int l = build(t, lo, mid);
        int r = build(t, mid, hi);
        t->nodes[i].left = l;
        t->nodes[i].right = r;
    }
    return i;
}

static inline double lum(rgb c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }

void gi_vpl_merge_axis(vec3 sum_w_d, double sum_w, double kappa, vec3 *axis, double *kappa_out)
{
    double len = v3_len(sum_w_d);
    if (!(sum_w > 0.0) || !(len > 0.0) || !(kappa > 0.0)) {
        *axis = v3(0, 0, 1);
        *kappa_out = 0.0;
        return;
    }
    double dl = fmin(1.0, len / sum_w);            /* |mean d| (eq. 3: sigma^2 = (1 - |d|) / |d|) */
    double ft = dl / (dl + kappa * (1.0 - dl));    /* eq. 4 */
    *axis = v3_scale(sum_w_d, 1.0 / len);
    *kappa_out = ft * kappa;
}

/* The node's filtered record (and, with spread, its spread) from its VPLs. */
static void filter(gi_vpl_tree *t, hnode *h, int spread)
{
    int m = h->hi - h->lo, nl = 0;
    vec3 sp = v3s(0.0), sn = v3s(0.0), swd = v3s(0.0);
    rgb sld = {0, 0, 0}, sls = {0, 0, 0};
    double area = 0.0, skappa = 0.0, sw = 0.0;
    for (int k = h->lo; k < h->hi; k++) {
        const gi_vpl *v = &t->v[t->order[k]];
        sp = v3_add(sp, v->p);
        sn = v3_add(sn, v->n);
        area += v->area;
        sld.r += v->ld.r;
        sld.g += v->ld.g;
        sld.b += v->ld.b;
        double w = lum(v->ls);
        if (v->kappa > 0.0 && w > 0.0) {
            nl++;
            skappa += v->kappa;
            sls.r += v->ls.r;
            sls.g += v->ls.g;
            sls.b += v->ls.b;
            swd = v3_add(swd, v3_scale(v->d, w));
            sw += w;
        }
    }
    gi_dev_vpl_node *d = &h->dev;
    memset(d, 0, sizeof *d);
    vec3 cp = v3_scale(sp, 1.0 / m);
    double nlen = v3_len(sn) / m;
    vec3 cn = nlen > 0.0 ? v3_norm(sn) : v3(0, 0, 1);
    v3_store_f(d->p, cp);
    d->p[3] = (float)area;
    v3_store_f(d->n, cn);
    d->n[3] = (float)nlen;
    d->ld[0] = (float)(sld.r / m);
    d->ld[1] = (float)(sld.g / m);
    d->ld[2] = (float)(sld.b / m);
    d->ld[3] = (float)m;
    if (nl > 0) {
        vec3 axis;
        double kappa;
        gi_vpl_merge_axis(swd, sw, skappa / nl, &axis, &kappa);
        if (kappa > 0.0) {
            d->ls[0] = (float)(sls.r / m);
            d->ls[1] = (float)(sls.g / m);
            d->ls[2] = (float)(sls.b / m);
            d->ls[3] = (float)kappa;
            v3_store_f(d->d, axis);
        }
    }
    if (spread) {
        double r = 0.0;
        for (int k = h->lo; k < h->hi; k++) {
            const gi_vpl *v = &t->v[t->order[k]];
            r = fmax(r, dist5(t, v->p, v->n, cp, cn));
        }
        h->spread = 100.0 * r;
    }
}

gi_vpl_tree *gi_vpl_tree_build(const gi_vpl *v, int n, double diag, int iterations)
{
    if (n < 1) return NULL;
    gi_vpl_tree *t = calloc(1, sizeof *t);
    if (!t) return NULL;
    t->n = n;
    t->iterations = iterations > 0 ? iterations : 3;
    t->half_diag = diag > 0.0 && isfinite(diag) ? diag / 2.0 : 1.0;
    t->v = malloc(sizeof *t->v * (size_t)n);
    t->order = malloc(sizeof *t->order * (size_t)n);
    t->nodes = malloc(sizeof *t->nodes * (size_t)(2 * n - 1));
    t->scratch = malloc(sizeof *t->scratch * (size_t)n);
    if (!t->v || !t->order || !t->nodes || !t->scratch) {
        gi_vpl_tree_free(t);
        return NULL;
    }
    memcpy(t->v, v, sizeof *t->v * (size_t)n);
    for (int i = 0; i < n; i++) t->order[i] = i;
    build(t, 0, n);
    for (int i = 0; i < t->nn; i++) filter(t, &t->nodes[i], 1);
    free(t->scratch);
    t->scratch = NULL;
    return t;
}

void gi_vpl_tree_relight(gi_vpl_tree *t, const gi_vpl *v)
{
    for (int i = 0; i < t->n; i++) {
        t->v[i].ld = v[i].ld;
        t->v[i].ls = v[i].ls;
        t->v[i].d = v[i].d;
        t->v[i].kappa = v[i].kappa;
    }
    for (int i = 0; i < t->nn; i++) filter(t, &t->nodes[i], 0);
}

void gi_vpl_tree_free(gi_vpl_tree *t)
{
    if (!t) return;
    free(t->v);
    free(t->order);
    free(t->nodes);
    free(t->scratch);
    free(t);
}

int gi_vpl_tree_size(const gi_vpl_tree *t) { return t->nn; }

/* Appends node i's part of the cut array (gi_vpl.h's rules). */
static void cut(const gi_vpl_tree *t, int i, double min_cut, double max_cut, gi_dev_vpl_node *out, int *k)
{
    const hnode *h = &t->nodes[i];
    int leaf = h->left < 0;
    if (!leaf && min_cut >= 0.0 && h->spread > min_cut) {
        cut(t, h->left, min_cut, max_cut, out, k);
        cut(t, h->right, min_cut, max_cut, out, k);
        return;
    }
    int me = (*k)++;
    out[me] = h->dev;
    out[me].accept = leaf || (max_cut >= 0.0 && h->spread <= max_cut);
    if (!out[me].accept) {
        /* below the min cut: the whole subtree is kept, down to the max cut */
        cut(t, h->left, -1.0, max_cut, out, k);
        cut(t, h->right, -1.0, max_cut, out, k);
    }
    out[me].skip = *k;
}

int gi_vpl_tree_cut(const gi_vpl_tree *t, double min_cut, double max_cut, gi_dev_vpl_node **out)
{
    *out = malloc(sizeof **out * (size_t)t->nn);
    if (!*out) return -1;
    int k = 0;
    cut(t, 0, min_cut, max_cut, *out, &k);
    return k;
}

int gi_vpl_tree_leaves(const gi_vpl_tree *t, gi_dev_vpl_node **out)
{
    *out = malloc(sizeof **out * (size_t)t->n);
    if (!*out) return -1;
    int k = 0;
    for (int i = 0; i < t->nn; i++) {
        if (t->nodes[i].left >= 0) continue;
        (*out)[k] = t->nodes[i].dev;
        (*out)[k].accept = 1;
        (*out)[k].skip = k + 1;
        k++;
    }
    return k;
}
