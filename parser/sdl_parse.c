/* sdl_parse.c - public entry points (sdl.h), errors, token helpers. */
#include "sdl_parse.h"
#include "sdl_font.h"
#include "grow.h"
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "hash.h"
#include "sdl_directive.h"
#include "sdl_expr.h"
#include "sdl_file.h"
#include "sdl_geom.h"
#include "sdl_scene.h"

/* ------------------------------------------------------------ errors */

void sdl_hash_input(sdl_parser *p, const void *bytes, size_t n)
{
    uint64_t len = n; /* the length first: "ab" + "c" and "a" + "bc" differ */
    p->s->input_hash = pt_fnv1a(pt_fnv1a(p->s->input_hash, &len, sizeof len), bytes, n);
}

void sdl_hash_file(sdl_parser *p, const char *path)
{
    FILE *f = path ? fopen(path, "rb") : NULL;
    if (!f) {
        if (path) sdl_hash_input(p, path, strlen(path));
        return;
    }
    /* length-prefixed like sdl_hash_input: the length is known only at
     * the end, so the bytes are hashed first, then the length */
    uint64_t h = p->s->input_hash, len = 0;
    unsigned char buf[65536];
    size_t got;
    while ((got = fread(buf, 1, sizeof buf, f)) > 0) {
        h = pt_fnv1a(h, buf, got);
        len += got;
    }
    fclose(f);
    p->s->input_hash = pt_fnv1a(h, &len, sizeof len);
}

void sdl_error(sdl_parser *p, src_loc loc, pt_status st, const char *fmt, ...)
{
    if (!sdl_ok(p)) return;
    /* A file the scene's text names (include, image, font, density or user
     * file: reported at the line naming it) that cannot be read is a scene
     * error like any other; PT_ERR_IO is kept for the scene file itself
     * (no line), so the command exits 1 or 3 as cli.h's list says. */
    if (st == PT_ERR_IO && loc.line > 0) st = PT_ERR_SYNTAX;
    p->status = st;
    char *chain = sdl_chain(p);
    va_list ap;
    va_start(ap, fmt);
    char buf[1024];
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    diag_report(p->d, DIAG_ERROR, loc, chain, "%s", buf);
    free(chain);
}

static void report(sdl_parser *p, diag_severity sev, src_loc loc, const char *fmt, va_list ap)
{
    char buf[1024];
    vsnprintf(buf, sizeof buf, fmt, ap);
    char *chain = sdl_chain(p);
    diag_report(p->d, sev, loc, chain, "%s", buf);
    free(chain);
}

void sdl_warning(sdl_parser *p, src_loc loc, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    report(p, DIAG_WARNING, loc, fmt, ap);
    va_end(ap);
}

void sdl_note(sdl_parser *p, src_loc loc, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    report(p, DIAG_NOTE, loc, fmt, ap);
    va_end(ap);
}

static void vwarn_once(sdl_parser *p, src_loc loc, const char *fmt, va_list ap)
{
    char buf[1024];
    vsnprintf(buf, sizeof buf, fmt, ap);
    diag_warn_once(p->d, loc, "%s", buf);
}

void sdl_warn_once(sdl_parser *p, src_loc loc, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vwarn_once(p, loc, fmt, ap);
    va_end(ap);
}

void sdl_ignore_block(sdl_parser *p, src_loc loc, const char *name, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vwarn_once(p, loc, fmt, ap);
    va_end(ap);
    if (sdl_begin_block(p, name)) sdl_skip_block(p);
}

void sdl_unexpected(sdl_parser *p, const sdl_tok *t, const char *expected)
{
    char what[128];
    if (t->tk.kind == TOK_EOF && p->nblocks > 0) {
        const sdl_block *b = &p->blocks[p->nblocks - 1];
        if (b->loc.file && t->tk.loc.file && strcmp(b->loc.file, t->tk.loc.file) != 0)
            sdl_error(p, t->tk.loc, PT_ERR_SYNTAX, "unterminated %s block opened at %s:%d:%d", b->name, b->loc.file, b->loc.line, b->loc.col);
        else
            sdl_error(p, t->tk.loc, PT_ERR_SYNTAX, "unterminated %s block opened at %d:%d", b->name, b->loc.line, b->loc.col);
        return;
    }
    if (t->tk.kind == TOK_IDENT && t->val.kind == VAL_NONE) {
        sdl_error(p, t->tk.loc, PT_ERR_SYNTAX, "expected %s, found undeclared identifier '%.*s'", expected, t->tk.len, t->tk.text);
        return;
    }
    sdl_error(p, t->tk.loc, PT_ERR_SYNTAX, "expected %s, found %s", expected, sdl_tok_describe(&t->tk, what, sizeof what));
}

int sdl_enter(sdl_parser *p, src_loc loc)
{
    if (p->depth >= SDL_MAX_NESTING) {
        sdl_error(p, loc, PT_ERR_LIMIT, "expressions, directives or macro calls nested more than %d deep", SDL_MAX_NESTING);
        return 0;
    }
    p->depth++;
    return 1;
}

/* ------------------------------------------------------------ tokens */

int sdl_is(const sdl_tok *t, sdl_tok_kind k) { return t->tk.kind == k; }
int sdl_is_kw(const sdl_tok *t, sdl_kw k) { return t->tk.kind == TOK_KEYWORD && t->tk.kw == k; }

int sdl_accept(sdl_parser *p, sdl_tok_kind k)
{
    if (!sdl_is(sdl_peek(p), k)) return 0;
    sdl_next(p);
    return 1;
}

int sdl_accept_kw(sdl_parser *p, sdl_kw k)
{
    if (!sdl_is_kw(sdl_peek(p), k)) return 0;
    sdl_next(p);
    return 1;
}

int sdl_expect(sdl_parser *p, sdl_tok_kind k, const char *what)
{
    sdl_tok t = sdl_next(p);
    if (t.tk.kind == k) return 1;
    sdl_unexpected(p, &t, what);
    return 0;
}

int sdl_begin_block(sdl_parser *p, const char *name)
{
    if (p->nblocks >= SDL_MAX_NESTING) {
        sdl_error(p, sdl_peek(p)->tk.loc, PT_ERR_LIMIT, "blocks nested more than %d deep", SDL_MAX_NESTING);
        return 0;
    }
    sdl_tok t = sdl_next(p);
    if (t.tk.kind != TOK_LBRACE) {
        char what[96];
        snprintf(what, sizeof what, "'{' after %s", name);
        sdl_unexpected(p, &t, what);
        return 0;
    }
    if (!grow_array_int((void **)&p->blocks, &p->cap_blocks, p->nblocks + 1, sizeof *p->blocks)) {
        sdl_error(p, t.tk.loc, PT_ERR_NOMEM, "out of memory");
        return 0;
    }
    p->blocks[p->nblocks].name = name;
    p->blocks[p->nblocks].loc = t.tk.loc;
    p->nblocks++;
    return 1;
}

int sdl_end_block(sdl_parser *p)
{
    sdl_tok t = sdl_next(p);
    if (t.tk.kind != TOK_RBRACE) {
        char what[96];
        snprintf(what, sizeof what, "'}' closing %s", p->nblocks ? p->blocks[p->nblocks - 1].name : "block");
        sdl_unexpected(p, &t, what);
        return 0;
    }
    if (p->nblocks > 0) p->nblocks--;
    return 1;
}

void sdl_skip_block(sdl_parser *p)
{
    int depth = 0;
    while (sdl_ok(p)) {
        sdl_tok t = sdl_next(p);
        if (t.tk.kind == TOK_EOF) {
            sdl_unexpected(p, &t, "'}'");
            return;
        }
        if (t.tk.kind == TOK_LBRACE) depth++;
        if (t.tk.kind != TOK_RBRACE) continue;
        if (depth == 0) {
            if (p->nblocks > 0) p->nblocks--;
            return;
        }
        depth--;
    }
}

void sdl_skip_item(sdl_parser *p)
{
    const sdl_tok *t = sdl_peek(p);
    if (sdl_is(t, TOK_LBRACE)) {
        if (sdl_begin_block(p, "block")) sdl_skip_block(p);
        return;
    }
    if (sdl_starts_string(t)) {
        sdl_string(p);
        return;
    }
    while (sdl_ok(p) && sdl_starts_expr(sdl_peek(p))) {
        sdl_value v;
        sdl_expr(p, &v);
        if (!sdl_accept(p, TOK_COMMA)) return;
    }
}

/* ------------------------------------------------------------ memory */

/* "1.5 GiB", "12 MiB", "300 bytes" */
static const char *bytes_text(double b, char *buf, size_t cap)
{
    if (b >= 1024.0 * 1024 * 1024) snprintf(buf, cap, "%.1f GiB", b / (1024.0 * 1024 * 1024));
    else if (b >= 1024.0 * 1024) snprintf(buf, cap, "%.0f MiB", b / (1024.0 * 1024));
    else snprintf(buf, cap, "%.0f bytes", b);
    return buf;
}

int sdl_memory_ok(sdl_parser *p, size_t extra, src_loc loc, const char *what)
{
    double need = (double)arena_bytes(p->s->mem) + (double)p->build_bytes + (double)extra;
    if (need <= (double)p->opt.max_memory) return 1;
    char a[32], b[32];
    sdl_error(p, loc, PT_ERR_LIMIT, "%s needs %s, more than the parser's memory limit of %s (--max-memory)", what,
              bytes_text(need, a, sizeof a), bytes_text((double)p->opt.max_memory, b, sizeof b));
    return 0;
}

int sdl_count_token(sdl_parser *p, src_loc loc)
{
    /* the scene file's position: a loop or a macro holds it where it is */
    if ((p->ntokens & 1023) == 0 && p->opt.progress && p->nframes > 0 && p->frames[0].kind == FRAME_FILE)
        progress_set(p->opt.progress, (long long)p->frames[0].sc.at.pos);
    if (++p->ntokens <= p->opt.max_tokens) return 1;
    sdl_error(p, loc, PT_ERR_LIMIT, "scene reads more than %lld tokens, loop repeats and macro calls included (--max-tokens)",
              p->opt.max_tokens);
    return 0;
}

void *sdl_alloc(sdl_parser *p, size_t n)
{
    if (!sdl_memory_ok(p, n, p->last_loc, "the scene")) return NULL;
    void *m = arena_alloc(p->s->mem, n ? n : 1);
    if (!m && sdl_ok(p)) {
        src_loc none = {NULL, 0, 0};
        sdl_error(p, none, PT_ERR_NOMEM, "out of memory");
    }
    return m;
}

void *sdl_dup(sdl_parser *p, const void *src, size_t n)
{
    void *m = sdl_alloc(p, n);
    if (m) memcpy(m, src, n);
    return m;
}

char *sdl_strndup(sdl_parser *p, const char *s, size_t n)
{
    char *r = sdl_alloc(p, n + 1);
    if (!r) return NULL;
    memcpy(r, s, n);
    r[n] = 0;
    return r;
}

/* ------------------------------------------------------------ entry points */

void sdl_default_options(sdl_options *o)
{
    memset(o, 0, sizeof *o);
    o->image_width = 320;  /* POV-Ray's default +W/+H */
    o->image_height = 240;
    o->max_loop_iterations = 10000000;
    o->max_include_depth = 64;
    o->max_macro_depth = 256;
    o->max_tokens = 10000000000LL;
    o->max_string_length = 1L << 20;
    o->max_array_elements = 100000000LL;
    o->max_image_pixels = 1LL << 28; /* SDL_IMG_MAX_PIXELS */
    /* half the physical memory: the rest is for the acceleration structure
     * and the framebuffer */
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    o->max_memory = pages > 0 && page > 0 ? (long long)pages * page / 2 : 4LL << 30;
}

void sdl_set_still_clock(sdl_options *o, double clock)
{
    o->clock = clock;
    o->clock_on = 1;
    o->clock_delta = o->initial_clock = o->final_clock = 0;
    o->frame_number = o->initial_frame = o->final_frame = 0;
}

int sdl_set_frame(sdl_options *o, int initial_frame, int final_frame, double initial_clock, double final_clock, int cyclic,
                  int frame)
{
    if (final_frame < initial_frame || frame < initial_frame || frame > final_frame) return -1;
    if (initial_frame == 1 && final_frame == 1 && !cyclic) { /* POV-Ray: not an animation */
        o->clock = 0;
        o->clock_on = 0;
        o->clock_delta = o->initial_clock = o->final_clock = 0;
        o->frame_number = o->initial_frame = o->final_frame = 0;
        return 0;
    }
    int span = final_frame - initial_frame + (cyclic ? 1 : 0);
    o->clock_on = 1;
    o->initial_frame = initial_frame;
    o->final_frame = final_frame + (cyclic ? 1 : 0);
    o->frame_number = frame;
    o->initial_clock = initial_clock;
    o->final_clock = final_clock;
    o->clock_delta = span > 0 ? (final_clock - initial_clock) / span : 0;
    o->clock = initial_clock + (frame - initial_frame) * o->clock_delta;
    return 0;
}

static void declare_float(sdl_parser *p, const char *name, double v)
{
    sdl_value val = {VAL_FLOAT, 1, {v, 0, 0, 0, 0}, NULL, NULL};
    sdl_symtab_declare(p->sym, name, strlen(name), &val);
}

/* -D NAME=VALUE: a float when VALUE is a number, else a string. */
static void declare_define(sdl_parser *p, const char *def)
{
    const char *eq = strchr(def, '=');
    size_t n = eq ? (size_t)(eq - def) : strlen(def);
    sdl_value val;
    memset(&val, 0, sizeof val);
    val.kind = VAL_FLOAT;
    val.dim = 1;
    val.v[0] = 1;
    if (eq) {
        char *end = NULL;
        double d = strtod(eq + 1, &end);
        if (end != eq + 1 && end && *end == 0) {
            val.v[0] = d;
        } else {
            const char *s = eq + 1;
            size_t len = strlen(s);
            if (len >= 2 && s[0] == '"' && s[len - 1] == '"') {
                s++;
                len -= 2;
            }
            val.kind = VAL_STRING;
            val.dim = 0;
            val.str = sdl_strndup(p, s, len);
        }
    }
    if (n > 0) sdl_symtab_declare(p->sym, def, n, &val);
}

/* Identifiers POV-Ray's front end declares before parsing. */
static void predeclare(sdl_parser *p)
{
    declare_float(p, "image_width", p->opt.image_width);
    declare_float(p, "image_height", p->opt.image_height);
    declare_float(p, "clock_delta", p->opt.clock_delta);
    declare_float(p, "frame_number", p->opt.frame_number);
    declare_float(p, "initial_clock", p->opt.initial_clock);
    declare_float(p, "final_clock", p->opt.final_clock);
    declare_float(p, "initial_frame", p->opt.initial_frame);
    declare_float(p, "final_frame", p->opt.final_frame);
    for (int i = 0; i < p->opt.ndefines; i++)
        if (p->opt.defines[i]) declare_define(p, p->opt.defines[i]);
}

static void set_options(sdl_parser *p, const sdl_options *opt)
{
    sdl_options def;
    sdl_default_options(&def);
    p->opt = opt ? *opt : def;
    if (p->opt.max_loop_iterations <= 0) p->opt.max_loop_iterations = def.max_loop_iterations;
    if (p->opt.max_include_depth <= 0) p->opt.max_include_depth = def.max_include_depth;
    if (p->opt.max_macro_depth <= 0) p->opt.max_macro_depth = def.max_macro_depth;
    if (p->opt.max_tokens <= 0) p->opt.max_tokens = def.max_tokens;
    if (p->opt.max_memory <= 0) p->opt.max_memory = def.max_memory;
    if (p->opt.max_string_length <= 0) p->opt.max_string_length = def.max_string_length;
    if (p->opt.max_array_elements <= 0) p->opt.max_array_elements = def.max_array_elements;
    if (p->opt.max_image_pixels <= 0) p->opt.max_image_pixels = def.max_image_pixels;
}

static pt_status run(const char *name, const char *text, const sdl_options *opt, scene **out, diag *d)
{
    sdl_parser p;
    memset(&p, 0, sizeof p);
    *out = NULL;
    p.d = d;
    p.version = 3.7;
    set_options(&p, opt);
    p.s = scene_new();
    /* POV-Ray 3.7's default background is <0,0,0,0,1>, clear under +UA
     * (scene.cpp); background{} replaces it */
    if (p.s) p.s->background.t = 1.0;
    p.sym = sdl_symtab_new();
    if (!p.s || !p.sym) {
        scene_free(p.s);
        sdl_symtab_free(p.sym);
        return PT_ERR_NOMEM;
    }
    p.s->clock = p.opt.clock;
    predeclare(&p);
    if (sdl_ok(&p) && sdl_open_main(&p, name, text) == PT_OK) {
        sdl_parse_scene(&p);
        sdl_check_closed(&p);
    }
    if (p.opt.frame_dependent) *p.opt.frame_dependent = p.frame_dependent;
    sdl_close_inputs(&p);
    sdl_geom_free(&p);
    sdl_files_close(&p);
    sdl_font_cache_free(p.fonts);
    sdl_symtab_free(p.sym);
    free(p.blocks);
    if (p.status != PT_OK) {
        scene_free(p.s);
        return p.status;
    }
    *out = p.s;
    return PT_OK;
}

pt_status sdl_parse_file(const char *path, const sdl_options *opt, scene **out, diag *d)
{
    if (!path) {
        src_loc none = {NULL, 0, 0};
        *out = NULL;
        diag_report(d, DIAG_ERROR, none, NULL, "no scene file given");
        return PT_ERR_IO;
    }
    return run(path, NULL, opt, out, d);
}

pt_status sdl_parse_string(const char *name, const char *text, const sdl_options *opt, scene **out, diag *d)
{
    return run(name ? name : "<string>", text ? text : "", opt, out, d);
}
