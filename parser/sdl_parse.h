/* sdl_parse.h - parser state shared by the parser's modules (internal to
 * parser/; the public interface is sdl.h).
 *
 * Error handling: the first error is recorded in the diag with its location
 * and include/macro chain, and `status` becomes non-zero. From then on the
 * token stream returns only end-of-file, so every loop ends and every grammar
 * function unwinds; callers check sdl_ok() where they must stop early. */
#ifndef PT_SDL_PARSE_H
#define PT_SDL_PARSE_H
#include <limits.h>
#include "scene.h"
#include "sdl.h"
#include "sdl_scan.h"
#include "sdl_symtab.h"

/* Limits that keep bad input from exhausting the stack or memory. */
#define SDL_MAX_NESTING 1000                 /* nested blocks, nested expressions */
#define SDL_MAX_CONDITIONALS 100000          /* open #if/#while/... and macro calls */

/* A token as the grammar sees it: identifiers carry their value as it was
 * when the token was read (VAL_NONE: undeclared). */
typedef struct {
    sdl_token tk;
    sdl_value val;
    int elem;             /* an array element: val is the element's value */
    struct sdl_array *elem_arr; /* the element's array and index (elem != 0), */
    long elem_idx;        /* so a macro can take the element by reference */
} sdl_tok;

/* A loaded file; kept until the parse ends (macro bodies point into it). */
typedef struct sdl_source {
    char *path;           /* as opened */
    const char *name;     /* interned, used in locations */
    char *text;
    size_t len;
    struct sdl_source *next;
} sdl_source;

typedef enum { FRAME_FILE, FRAME_MACRO } sdl_frame_kind;

/* One input: a file or a macro body being read. */
typedef struct {
    sdl_frame_kind kind;
    sdl_scanner sc;
    const sdl_source *src;
    src_loc from;         /* the #include / macro call that opened it */
    const char *name;     /* macro name */
    int cond_base;        /* conditional stack depth when it was entered */
} sdl_frame;

typedef enum { COND_IF, COND_WHILE, COND_FOR, COND_SWITCH, COND_MACRO } sdl_cond_kind;

/* An open #if/#while/#for/#switch or a running macro body. */
typedef struct {
    sdl_cond_kind kind;
    src_loc loc;
    int frame;            /* index of the frame it belongs to */
    sdl_scan_pos pos;     /* while: the condition; for: the body */
    long iterations;
    double for_end, for_step;
    const char *for_var;  /* arena string */
    int switch_taken;     /* switch: a clause has run */
    double switch_value;
} sdl_cond;

/* A #macro definition. */
typedef struct {
    const char *name;
    src_loc loc;
    const sdl_source *src;
    sdl_scan_pos body;
    int nparams;
    const char **params;
} sdl_macro;

/* A parsed object statement: the IR node (NULL for a bare light) plus the
 * light sources it contains, which move with it. */
typedef struct {
    scene_object *obj;
    scene_light *lights;
    int nlights;
} sdl_obj;

/* material { texture interior_texture interior } */
typedef struct {
    scene_texture *texture;
    scene_texture *interior_texture;
    scene_interior *interior;
} sdl_material;

typedef struct {
    const char *name;
    src_loc loc;
} sdl_block;

typedef struct sdl_parser {
    int view_depth;      /* inside camera{} or light_source{} blocks (sdl_note_frame_value) */
    int frame_dependent; /* sdl_options.frame_dependent */
    scene *s;
    diag *d;
    sdl_options opt;
    pt_status status;
    sdl_symtab *sym;
    sdl_source *sources;
    sdl_frame *frames;
    int nframes, cap_frames;
    sdl_cond *conds;
    int nconds, cap_conds;
    sdl_tok ahead[4];     /* pushed-back tokens, last pushed = next read */
    int nahead;
    sdl_block *blocks;    /* open { } blocks, for "unterminated" messages */
    int nblocks, cap_blocks;
    int hold_macros;      /* >0: macro identifiers are returned, not invoked */
    int hold_arrays;      /* >0: an array identifier followed by '[' is returned
                             as the array (lvalues, defined()), not indexed */
    int defer;            /* >0: a '#' or macro name met while looking ahead is
                             returned as a token and runs when read again (the
                             look-ahead past the end of a #declare) */
    int macro_depth;
    int depth;            /* C recursion through expressions, directives and
                             macro arguments (bounded by SDL_MAX_NESTING) */
    int include_depth;
    double version;       /* language version from #version, 3.7 by default */
    int charset;          /* global_settings { charset }: 0 ascii (POV-Ray's default), 1 utf8, 2 sys */
    int default_texture_set;
    src_loc last_loc;     /* last token returned (for end-of-file locations) */
    void *geom_cache;     /* sdl_geom: the objects' trees prepared for trace/inside */
    int nlight_groups;    /* light_group ids handed out */
    void *files;          /* sdl_file: every #fopen'ed file (closed at the end) */
    void *fonts;          /* sdl_font_cache: the font files text{} opened (closed at the end) */
    long long ntokens;    /* tokens read so far (opt.max_tokens) */
    size_t build_bytes;   /* malloc'd work memory outside the arena (meshes being
                             built), counted against opt.max_memory */
} sdl_parser;

/* A number from the scene as an int: truncated toward zero, clamped to the
 * int range, NaN as 0 (a plain (int) cast is undefined out of range). */
static inline int sdl_to_int(double v)
{
    if (!(v == v)) return 0;
    if (v >= (double)INT_MAX) return INT_MAX;
    if (v <= (double)INT_MIN) return INT_MIN;
    return (int)v;
}

/* --- recursion guard: 0 (with an error recorded) when nested too deep --- */
int sdl_enter(sdl_parser *p, src_loc loc);
static inline void sdl_leave(sdl_parser *p) { p->depth--; }

/* --- the scene's inputs (scene.input_hash; sdl_parse.c) --- */
/* Adds n bytes the parse read (a file's contents) to scene.input_hash. */
void sdl_hash_input(sdl_parser *p, const void *bytes, size_t n);
/* Adds the contents of the file at path (read again: images and density
 * files are decoded by their own readers); an unreadable file adds its
 * path's bytes, so the hash still differs from a scene without it. */
void sdl_hash_file(sdl_parser *p, const char *path);

/* --- errors and warnings (sdl_parse.c) --- */
static inline int sdl_ok(const sdl_parser *p) { return p->status == PT_OK; }
void sdl_error(sdl_parser *p, src_loc loc, pt_status st, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
void sdl_warning(sdl_parser *p, src_loc loc, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
void sdl_note(sdl_parser *p, src_loc loc, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* Warn once per distinct message. */
void sdl_warn_once(sdl_parser *p, src_loc loc, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* "expected X, found Y", or "unterminated B block opened at L:C" when Y is
 * the end of the file inside an open block. */
void sdl_unexpected(sdl_parser *p, const sdl_tok *t, const char *expected);

/* --- token helpers (sdl_parse.c, on top of sdl_directive.c's stream) --- */
int sdl_is(const sdl_tok *t, sdl_tok_kind k);
int sdl_is_kw(const sdl_tok *t, sdl_kw k);
/* Consume the next token if it is k / keyword k. */
int sdl_accept(sdl_parser *p, sdl_tok_kind k);
int sdl_accept_kw(sdl_parser *p, sdl_kw k);
/* Consume a token of kind k or report an error (returns 0). */
int sdl_expect(sdl_parser *p, sdl_tok_kind k, const char *what);
/* '{' that opens a block named `name` / the matching '}'. */
int sdl_begin_block(sdl_parser *p, const char *name);
int sdl_end_block(sdl_parser *p);
/* After sdl_begin_block: skip to the matching '}' (directives still run). */
void sdl_skip_block(sdl_parser *p);
/* For syntax read but not modelled: warn once (fmt), then skip the
 * '{...}' block named `name` that follows. */
void sdl_ignore_block(sdl_parser *p, src_loc loc, const char *name, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
/* Skip a keyword's optional '{...}' argument, or one expression if one follows. */
void sdl_skip_item(sdl_parser *p);

/* --- memory --- */
void *sdl_alloc(sdl_parser *p, size_t n);
/* sdl_alloc of n bytes holding a copy of src (a record copied into the scene's arena). */
void *sdl_dup(sdl_parser *p, const void *src, size_t n);
/* Room for `extra` more bytes of work memory within opt.max_memory? If not,
 * a located limit error naming `what` is recorded and 0 returned. */
int sdl_memory_ok(sdl_parser *p, size_t extra, src_loc loc, const char *what);
/* Count one token read (opt.max_tokens); 0 with an error when over. */
int sdl_count_token(sdl_parser *p, src_loc loc);
char *sdl_strndup(sdl_parser *p, const char *s, size_t n);

/* A value that changes from frame to frame (clock, frame_number, now) was
 * read: outside camera{} and light_source{} it makes the rest of the scene
 * frame-dependent (sdl_options.frame_dependent). */
static inline void sdl_note_frame_value(sdl_parser *p)
{
    if (p->view_depth == 0) p->frame_dependent = 1;
}

#endif
