/* sdl_symtab.c - chained hash table with a per-scope list for cheap pops. */
#include "sdl_symtab.h"
#include <assert.h>
#include <stdlib.h>
#include <string.h>

#define SYM_BUCKETS 1024u

typedef struct sym_entry {
    struct sym_entry *hnext;     /* hash chain, innermost scope first */
    struct sym_entry *snext;     /* entries of the same scope */
    struct sym_entry *alias;     /* by-reference macro parameter: the caller's entry */
    sdl_value *slot;             /* by-reference array element: its storage, */
    void *owner;                 /* its array (opaque) and index */
    long index;
    int depth;
    size_t len;                  /* strlen(name) */
    char *name;
    sdl_value val;
} sym_entry;

struct sdl_symtab {
    sym_entry *buckets[SYM_BUCKETS];
    sym_entry **scopes;          /* scopes[d]: list of entries of depth d */
    unsigned long *ids;          /* ids[d]: serial number of the scope at depth d */
    unsigned long next_id;
    int depth, cap;
    sym_entry *undefined;        /* #undef'd entries, freed with the table */
};

static unsigned hash_name(const char *s, size_t n)
{
    unsigned h = 2166136261u;
    for (size_t i = 0; i < n; i++) h = (h ^ (unsigned char)s[i]) * 16777619u;
    return h % SYM_BUCKETS;
}

sdl_symtab *sdl_symtab_new(void)
{
    sdl_symtab *t = calloc(1, sizeof *t);
    if (!t) return NULL;
    t->cap = 16;
    t->scopes = calloc((size_t)t->cap, sizeof *t->scopes);
    t->ids = calloc((size_t)t->cap, sizeof *t->ids);
    if (!t->scopes || !t->ids) {
        free(t->scopes);
        free(t->ids);
        free(t);
        return NULL;
    }
    t->next_id = 1;
    return t;
}

static void free_entry(sym_entry *e)
{
    free(e->name);
    free(e);
}

static void unlink_entry(sdl_symtab *t, sym_entry *e)
{
    sym_entry **pp = &t->buckets[hash_name(e->name, e->len)];
    while (*pp && *pp != e) pp = &(*pp)->hnext;
    if (*pp) *pp = e->hnext;
    sym_entry **sp = &t->scopes[e->depth];
    while (*sp && *sp != e) sp = &(*sp)->snext;
    if (*sp) *sp = e->snext;
}

void sdl_symtab_free(sdl_symtab *t)
{
    if (!t) return;
    for (int d = 0; d <= t->depth; d++) {
        sym_entry *e = t->scopes[d];
        while (e) {
            sym_entry *n = e->snext;
            free_entry(e);
            e = n;
        }
    }
    while (t->undefined) {
        sym_entry *n = t->undefined->snext;
        free_entry(t->undefined);
        t->undefined = n;
    }
    free(t->scopes);
    free(t->ids);
    free(t);
}

int sdl_symtab_push(sdl_symtab *t)
{
    if (t->depth + 1 >= t->cap) {
        int nc = t->cap * 2;
        sym_entry **n = realloc(t->scopes, sizeof *n * (size_t)nc);
        if (!n) return 0;
        t->scopes = n;
        unsigned long *ni = realloc(t->ids, sizeof *ni * (size_t)nc);
        if (!ni) return 0;
        t->ids = ni;
        t->cap = nc;
    }
    t->scopes[++t->depth] = NULL;
    assert(t->depth < t->cap);
    t->ids[t->depth] = t->next_id++;
    return 1;
}

void sdl_symtab_pop(sdl_symtab *t)
{
    if (t->depth == 0) return;
    while (t->scopes[t->depth]) {
        sym_entry *e = t->scopes[t->depth];
        unlink_entry(t, e);
        free_entry(e);
    }
    assert(t->scopes[t->depth] == NULL); /* unlink_entry took every entry of the scope */
    t->depth--;
}

static sym_entry *find_entry(const sdl_symtab *t, const char *name, size_t n)
{
    for (sym_entry *e = t->buckets[hash_name(name, n)]; e; e = e->hnext)
        if (e->len == n && memcmp(e->name, name, n) == 0) return e;
    return NULL;
}

/* The entry an alias stands for (the entry itself if it is no alias). */
static sym_entry *resolve(sym_entry *e)
{
    /* aliases (macro parameters by reference) point to outer scopes, so
     * the chain ends */
    for (int guard = 0; e && e->alias; guard++) {
        assert(guard < 1 << 20);
        e = e->alias;
    }
    return e;
}

const sdl_value *sdl_symtab_find(const sdl_symtab *t, const char *name, size_t n)
{
    sym_entry *e = resolve(find_entry(t, name, n));
    if (e && e->slot) return e->slot->kind != VAL_NONE ? e->slot : NULL;
    return e && e->val.kind != VAL_NONE ? &e->val : NULL;
}

/* Store v in the entry (or in the element it stands for). */
static void store(sym_entry *e, const sdl_value *v)
{
    if (e->slot) *e->slot = *v;
    else e->val = *v;
}

/* Insert a new entry at `depth`. Hash chains stay ordered innermost first. */
static int insert_entry(sdl_symtab *t, const char *name, size_t n, int depth, const sdl_value *v)
{
    sym_entry *e = calloc(1, sizeof *e);
    if (!e) return 0;
    e->name = malloc(n + 1);
    if (!e->name) {
        free(e);
        return 0;
    }
    memcpy(e->name, name, n);
    e->name[n] = 0;
    e->len = n;
    e->depth = depth;
    e->val = *v;
    sym_entry **pp = &t->buckets[hash_name(name, n)];
    while (*pp && (*pp)->depth > depth) pp = &(*pp)->hnext;
    e->hnext = *pp;
    *pp = e;
    e->snext = t->scopes[depth];
    t->scopes[depth] = e;
    return 1;
}

int sdl_symtab_declare(sdl_symtab *t, const char *name, size_t n, const sdl_value *v)
{
    sym_entry *e = resolve(find_entry(t, name, n));
    if (e) {
        store(e, v);
        return 1;
    }
    return insert_entry(t, name, n, 0, v);
}

int sdl_symtab_local(sdl_symtab *t, const char *name, size_t n, const sdl_value *v)
{
    sym_entry *e = find_entry(t, name, n);
    if (e && e->depth == t->depth) {
        store(resolve(e), v);
        return 1;
    }
    return insert_entry(t, name, n, t->depth, v);
}

int sdl_symtab_undef(sdl_symtab *t, const char *name, size_t n)
{
    sym_entry *e = find_entry(t, name, n);
    if (!e) return 0;
    unlink_entry(t, e);
    /* kept (undefined) for aliases that may still point at it */
    memset(&e->val, 0, sizeof e->val);
    e->alias = NULL;
    e->slot = NULL;
    e->hnext = NULL;
    e->snext = t->undefined;
    t->undefined = e;
    return 1;
}

/* The entry for `name` in the innermost scope, made (with no value) when
 * that scope has none; NULL when out of memory. */
static sym_entry *local_entry(sdl_symtab *t, const char *name, size_t n)
{
    sym_entry *e = find_entry(t, name, n);
    if (e && e->depth == t->depth) return e;
    sdl_value none;
    memset(&none, 0, sizeof none);
    if (!insert_entry(t, name, n, t->depth, &none)) return NULL;
    return find_entry(t, name, n);
}

sdl_symref *sdl_symtab_ref(const sdl_symtab *t, const char *name, size_t n)
{
    return resolve(find_entry(t, name, n));
}

int sdl_symtab_alias(sdl_symtab *t, const char *name, size_t n, sdl_symref *target)
{
    sym_entry *e = local_entry(t, name, n);
    if (!e) return 0;
    e->slot = NULL;
    e->alias = resolve(target);
    if (e->alias == e) e->alias = NULL;
    return 1;
}

int sdl_symtab_alias_elem(sdl_symtab *t, const char *name, size_t n, sdl_value *slot, void *owner, long index)
{
    sym_entry *e = local_entry(t, name, n);
    if (!e) return 0;
    e->alias = NULL;
    e->slot = slot;
    e->owner = owner;
    e->index = index;
    return 1;
}

sdl_symtarget sdl_symtab_target(const sdl_symtab *t, const char *name, size_t n, int local)
{
    sdl_symtarget tg;
    memset(&tg, 0, sizeof tg);
    sym_entry *e = find_entry(t, name, n);
    if (local) {
        tg.depth = t->depth;
        tg.entry = e && e->depth == t->depth ? e : NULL;
    } else if (e) {
        tg.depth = e->depth;
        tg.entry = e;
    } else {
        tg.depth = 0;
    }
    tg.scope = t->ids[tg.depth];
    sym_entry *r = resolve(tg.entry);
    if (r && r->slot) {
        tg.elem_owner = r->owner;
        tg.elem_index = r->index;
    }
    return tg;
}

int sdl_symtab_assign(sdl_symtab *t, const sdl_symtarget *tg, const char *name, size_t n, const sdl_value *v)
{
    if (tg->depth > t->depth || t->ids[tg->depth] != tg->scope) return -1; /* the scope has ended */
    if (tg->entry) {
        store(resolve(tg->entry), v);
        return 1;
    }
    sym_entry *e = find_entry(t, name, n);
    while (e && e->depth > tg->depth) { /* an entry made meanwhile further in: look past it */
        sym_entry *o = e->hnext;
        while (o && !(o->len == n && memcmp(o->name, name, n) == 0)) o = o->hnext;
        e = o;
    }
    if (e && e->depth == tg->depth) {
        store(resolve(e), v);
        return 1;
    }
    return insert_entry(t, name, n, tg->depth, v);
}
