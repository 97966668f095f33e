/* sdl_symtab.h - identifiers and their values, in nested scopes.
 *
 * Scope 0 is global (#declare); every included file and every macro call
 * opens a scope for its #local identifiers (POV-Ray 3.7 semantics):
 *   #declare X: assigns the innermost visible X, else creates a global X;
 *   #local X:   assigns X in the innermost scope, creating it there. */
#ifndef PT_SDL_SYMTAB_H
#define PT_SDL_SYMTAB_H
#include <stddef.h>

typedef enum {
    VAL_NONE = 0,
    VAL_FLOAT,     /* dim 1 */
    VAL_VECTOR,    /* dim 2..5 (u/v vectors, 3D vectors, 4D, 5D) */
    VAL_COLOUR,    /* dim 5: r g b filter transmit */
    VAL_STRING,    /* str */
    VAL_TEXTURE,   /* ptr: scene_texture (layered list) */
    VAL_PIGMENT,   /* ptr: scene_pigment */
    VAL_FINISH,    /* ptr: scene_finish */
    VAL_NORMAL,    /* no data yet */
    VAL_INTERIOR,  /* ptr: scene_interior */
    VAL_MATERIAL,  /* ptr: sdl_material (parser-internal) */
    VAL_OBJECT,    /* ptr: sdl_obj (parser-internal; may be a light) */
    VAL_CAMERA,    /* ptr: scene_camera */
    VAL_TRANSFORM, /* ptr: xform */
    VAL_MACRO,     /* ptr: sdl_macro (parser-internal) */
    VAL_OPAQUE,    /* something parsed but not modelled (media, fog,
                      colour_map...): str names the kind */
    VAL_ARRAY,     /* ptr: sdl_array (sdl_array.h) */
    VAL_FUNCTION,  /* ptr: scene_function (core/func.h); dim = result terms */
    VAL_SPLINE,    /* ptr: user_spline (core/uspline.h) */
    VAL_FILE       /* ptr: sdl_file (sdl_file.h), an #fopen'ed file */
} sdl_val_kind;

typedef struct {
    sdl_val_kind kind;
    int dim;
    double v[5];
    const char *str;
    void *ptr;
} sdl_value;

typedef struct sdl_symtab sdl_symtab;

sdl_symtab *sdl_symtab_new(void);
void sdl_symtab_free(sdl_symtab *t);
/* Returns 0 on out-of-memory. */
int sdl_symtab_push(sdl_symtab *t);
void sdl_symtab_pop(sdl_symtab *t);
/* Innermost visible value, or NULL. */
const sdl_value *sdl_symtab_find(const sdl_symtab *t, const char *name, size_t n);
/* #declare / #local assignment; returns 0 on out-of-memory. */
int sdl_symtab_declare(sdl_symtab *t, const char *name, size_t n, const sdl_value *v);
int sdl_symtab_local(sdl_symtab *t, const char *name, size_t n, const sdl_value *v);
/* #undef: removes the innermost visible entry; returns 0 if there was none. */
int sdl_symtab_undef(sdl_symtab *t, const char *name, size_t n);

/* Macro parameters passed by reference (POV-Ray 3.7: an argument that is a
 * lone identifier). sdl_symtab_ref returns a handle on the innermost visible
 * entry (NULL if none); sdl_symtab_alias creates `name` in the innermost
 * scope as an alias of that entry: reading it reads the caller's identifier,
 * #declare/#local of it assign the caller's identifier. Entries removed by
 * #undef stay allocated (undefined) until the table is freed, so a handle
 * never dangles. */
typedef struct sym_entry sdl_symref;
sdl_symref *sdl_symtab_ref(const sdl_symtab *t, const char *name, size_t n);
int sdl_symtab_alias(sdl_symtab *t, const char *name, size_t n, sdl_symref *target);
/* A parameter that stands for an array element (POV-Ray 3.7 passes `M(A[i])`
 * by reference too): reading `name` reads *slot; a #declare/#local of it is
 * reported by sdl_symtab_target (elem_owner, elem_index) so that the caller
 * stores the value with the array's type rule. owner is opaque here. */
int sdl_symtab_alias_elem(sdl_symtab *t, const char *name, size_t n, sdl_value *slot, void *owner, long index);
/* Where a #declare/#local assigns, resolved when the directive starts (as
 * POV-Ray does): parsing the value may call macros or leave the current
 * macro, so the scope is remembered by identity. local: the innermost
 * scope; else the innermost visible entry, or the global scope. */
typedef struct {
    sdl_symref *entry;    /* the entry to assign (NULL: create one) */
    int depth;
    unsigned long scope;  /* serial number of the scope at `depth` */
    void *elem_owner;     /* non-NULL: the target is element elem_index of */
    long elem_index;      /* this array (sdl_symtab_alias_elem) */
} sdl_symtarget;
sdl_symtarget sdl_symtab_target(const sdl_symtab *t, const char *name, size_t n, int local);
/* Assign v to the target: 1 done, 0 out of memory, -1 the target's scope has
 * ended meanwhile (nothing assigned). */
int sdl_symtab_assign(sdl_symtab *t, const sdl_symtarget *tg, const char *name, size_t n, const sdl_value *v);

#endif
