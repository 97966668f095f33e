/* sdl_directive.c - input stack, directives, conditionals, loops, macros. */
#include "sdl_directive.h"
#include "grow.h"
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "fileio.h"
#include "sdl_array.h"
#include "sdl_expr.h"
#include "sdl_file.h"
#include "sdl_function.h"
#include "sdl_material.h"
#include "sdl_object.h"
#include "sdl_scene.h"

#define SDL_DEFAULT_LIB "/usr/share/povray-3.7/include"

typedef enum { SKIP_TO_END, SKIP_IF_FALSE, SKIP_SWITCH } skip_mode;

static void directive(sdl_parser *p, const sdl_token *hash);

/* ------------------------------------------------------------ sources */

static sdl_source *add_source(sdl_parser *p, const char *path, char *text, size_t len)
{
    sdl_source *s = calloc(1, sizeof *s);
    if (!s) {
        free(text);
        return NULL;
    }
    s->path = strdup(path);
    s->name = sdl_strndup(p, path, strlen(path));
    s->text = text;
    s->len = len;
    s->next = p->sources;
    p->sources = s;
    p->s->nfiles++;
    sdl_hash_input(p, text, len);
    return s;
}

static int is_readable(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    fclose(f);
    return 1;
}

/* Try dir/name then dir/name.inc; on success the malloc'd path. */
static char *try_dir(const char *dir, const char *name)
{
    size_t n = (dir ? strlen(dir) + 1 : 0) + strlen(name) + 5;
    char *path = malloc(n);
    if (!path) return NULL;
    if (dir && *dir)
        snprintf(path, n, "%s/%s", dir, name);
    else
        snprintf(path, n, "%s", name);
    if (is_readable(path)) return path;
    strcat(path, ".inc");
    if (is_readable(path)) return path;
    free(path);
    return NULL;
}

/* Directory part of a path ("." if none); malloc'd. */
static char *dir_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash) return strdup(".");
    if (slash == path) return strdup("/");
    char *d = malloc((size_t)(slash - path) + 1);
    if (!d) return NULL;
    memcpy(d, path, (size_t)(slash - path));
    d[slash - path] = 0;
    return d;
}

/* Search order: -L directories, the including file's directory, then
 * POV-Ray's include directory unless no_default_lib. */
static char *find_include(sdl_parser *p, const char *name)
{
    if (name[0] == '/') return try_dir(NULL, name);
    char *found = NULL;
    for (int i = 0; i < p->opt.nlib_paths && !found; i++) found = try_dir(p->opt.lib_paths[i], name);
    if (!found && p->nframes > 0) {
        char *d = dir_of(p->frames[p->nframes - 1].src->path);
        if (d) found = try_dir(d, name);
        free(d);
    }
    if (!found && !p->opt.no_default_lib) found = try_dir(SDL_DEFAULT_LIB, name);
    return found;
}

int sdl_file_exists(sdl_parser *p, const char *name)
{
    char *f = find_include(p, name);
    free(f);
    return f != NULL;
}

/* ------------------------------------------------------------ frames */

static int push_frame(sdl_parser *p, sdl_frame_kind kind, const sdl_source *src, src_loc from, const char *name)
{
    if (!grow_array_int((void **)&p->frames, &p->cap_frames, p->nframes + 1, sizeof *p->frames)) {
        sdl_error(p, from, PT_ERR_NOMEM, "out of memory");
        return 0;
    }
    sdl_frame *f = &p->frames[p->nframes++];
    memset(f, 0, sizeof *f);
    f->kind = kind;
    f->src = src;
    f->from = from;
    f->name = name;
    f->cond_base = p->nconds;
    sdl_scan_init(&f->sc, src->name, src->text, src->len);
    return 1;
}

static sdl_frame *top_frame(sdl_parser *p) { return &p->frames[p->nframes - 1]; }

char *sdl_chain(const sdl_parser *p)
{
    if (p->nframes <= 1) return NULL;
    size_t cap = 256 * (size_t)p->nframes, n = 0;
    char *s = malloc(cap);
    if (!s) return NULL;
    s[0] = 0;
    for (int i = p->nframes - 1; i >= 1 && n + 256 < cap; i--) {
        const sdl_frame *f = &p->frames[i];
        if (n) s[n++] = '\n';
        if (f->kind == FRAME_MACRO)
            n += (size_t)snprintf(s + n, cap - n, "  in macro %.80s called from %.120s:%d:%d", f->name, f->from.file, f->from.line, f->from.col);
        else
            n += (size_t)snprintf(s + n, cap - n, "  included from %.160s:%d:%d", f->from.file, f->from.line, f->from.col);
    }
    return s;
}

pt_status sdl_open_main(sdl_parser *p, const char *path, const char *text)
{
    src_loc none = {NULL, 0, 0};
    size_t len = 0;
    char *buf;
    if (text) {
        len = strlen(text);
        buf = malloc(len + 1);
        if (buf) memcpy(buf, text, len + 1);
    } else {
        buf = pt_read_file(path, 0, (size_t)p->opt.max_memory, &len);
        if (!buf) {
            src_loc at = {path, 0, 0};
            sdl_error(p, at, PT_ERR_IO, "cannot read scene file: %s", strerror(errno ? errno : ENOENT));
            return p->status;
        }
    }
    if (!buf) {
        sdl_error(p, none, PT_ERR_NOMEM, "out of memory");
        return p->status;
    }
    sdl_source *src = add_source(p, path, buf, len);
    if (!src || !push_frame(p, FRAME_FILE, src, none, NULL)) {
        if (sdl_ok(p)) sdl_error(p, none, PT_ERR_NOMEM, "out of memory");
        return p->status;
    }
    progress_stage(p->opt.progress, "parse", (long long)len);
    return PT_OK;
}

void sdl_close_inputs(sdl_parser *p)
{
    while (p->sources) {
        sdl_source *n = p->sources->next;
        free(p->sources->path);
        free(p->sources->text);
        free(p->sources);
        p->sources = n;
    }
    free(p->frames);
    free(p->conds);
    p->frames = NULL;
    p->conds = NULL;
    p->nframes = p->nconds = 0;
}

/* ------------------------------------------------------------ conditionals */

static sdl_cond *push_cond(sdl_parser *p, sdl_cond_kind kind, src_loc loc)
{
    if (p->nconds >= SDL_MAX_CONDITIONALS) {
        sdl_error(p, loc, PT_ERR_LIMIT, "more than %d nested conditionals and macro calls", SDL_MAX_CONDITIONALS);
        return NULL;
    }
    if (!grow_array_int((void **)&p->conds, &p->cap_conds, p->nconds + 1, sizeof *p->conds)) {
        sdl_error(p, loc, PT_ERR_NOMEM, "out of memory");
        return NULL;
    }
    sdl_cond *c = &p->conds[p->nconds++];
    memset(c, 0, sizeof *c);
    c->kind = kind;
    c->loc = loc;
    c->frame = p->nframes - 1;
    return c;
}

/* The innermost conditional opened in the current frame, or NULL. */
static sdl_cond *local_cond(sdl_parser *p)
{
    if (p->nconds > top_frame(p)->cond_base) return &p->conds[p->nconds - 1];
    return NULL;
}

static const char *cond_name(sdl_cond_kind k)
{
    switch (k) {
    case COND_IF: return "#if";
    case COND_WHILE: return "#while";
    case COND_FOR: return "#for";
    case COND_SWITCH: return "#switch";
    default: return "#macro";
    }
}

static void unterminated_cond(sdl_parser *p, src_loc at, const char *what, src_loc opened)
{
    sdl_error(p, at, PT_ERR_SYNTAX, "unterminated %s opened at %d:%d (missing #end)", what, opened.line, opened.col);
}

void sdl_check_closed(sdl_parser *p)
{
    if (!sdl_ok(p) || p->nconds == 0) return;
    sdl_cond *c = &p->conds[p->nconds - 1];
    unterminated_cond(p, p->last_loc, cond_name(c->kind), c->loc);
}

static int opens_block(sdl_kw k)
{
    return k == KW_IF || k == KW_IFDEF || k == KW_IFNDEF || k == KW_WHILE || k == KW_FOR || k == KW_SWITCH || k == KW_MACRO;
}

/* Skip raw tokens of the current input until a directive ends the skip:
 * #end at nesting depth 0 (consumed) or, by mode, #else/#elseif or
 * #case/#range/#else at depth 0. Returns that directive's keyword. */
static sdl_kw skip_tokens(sdl_parser *p, skip_mode mode, int depth, const char *what, src_loc opened)
{
    sdl_scanner *sc = &top_frame(p)->sc;
    for (;;) {
        sdl_token t = sdl_scan_next(sc);
        if (!sdl_count_token(p, t.loc)) return KW_END;
        if (t.kind == TOK_EOF) {
            unterminated_cond(p, t.loc, what, opened);
            return KW_END;
        }
        if (t.kind != TOK_HASH) continue;
        sdl_token k = sdl_scan_next(sc);
        if (k.kind != TOK_KEYWORD) continue;
        if (opens_block(k.kw)) {
            depth++;
        } else if (k.kw == KW_END) {
            if (depth == 0) return KW_END;
            depth--;
        } else if (depth == 0 && mode == SKIP_IF_FALSE && (k.kw == KW_ELSE || k.kw == KW_ELSEIF)) {
            return k.kw;
        } else if (depth == 0 && mode == SKIP_SWITCH && (k.kw == KW_ELSE || k.kw == KW_CASE || k.kw == KW_RANGE)) {
            return k.kw;
        }
    }
}

/* Condition in parentheses; macros are not expanded there (as POV-Ray). */
static double cond_param(sdl_parser *p)
{
    p->hold_macros++;
    double v = sdl_float_param(p);
    p->hold_macros--;
    return v;
}

/* After a false #if branch: look for the branch to run, if any. */
static void false_branch(sdl_parser *p, src_loc loc)
{
    for (;;) {
        sdl_kw k = skip_tokens(p, SKIP_IF_FALSE, 0, "#if", loc);
        if (!sdl_ok(p) || k == KW_END) return;
        if (k == KW_ELSE || sdl_true(cond_param(p))) {
            push_cond(p, COND_IF, loc);
            return;
        }
    }
}

/* if_directive := ( '#if' '(' float ')' | '#ifdef' '(' id ')' | '#ifndef' '(' id ')' ) */
static void if_directive(sdl_parser *p, sdl_kw kw, src_loc loc)
{
    int truth;
    if (kw == KW_IF) truth = sdl_true(cond_param(p));
    else truth = sdl_defined_param(p) == (kw == KW_IFDEF);
    if (!sdl_ok(p)) return;
    if (truth) push_cond(p, COND_IF, loc);
    else false_branch(p, loc);
}

/* Skip from inside the innermost local conditional to its #end and pop it. */
static void skip_rest(sdl_parser *p, sdl_cond *c)
{
    src_loc loc = c->loc;
    const char *what = cond_name(c->kind);
    p->nconds--;
    skip_tokens(p, SKIP_TO_END, 0, what, loc);
}

/* else_directive := '#else' | '#elseif' '(' float ')' (inside a running branch) */
static void else_directive(sdl_parser *p, sdl_kw kw, src_loc loc)
{
    sdl_cond *c = local_cond(p);
    if (c && c->kind == COND_SWITCH && kw == KW_ELSE) return; /* falls through */
    if (!c || c->kind != COND_IF) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "#%s without matching #if", sdl_kw_text(kw));
        return;
    }
    skip_rest(p, c);
}

/* while_directive := '#while' '(' float ')' body '#end' */
static void while_directive(sdl_parser *p, src_loc loc)
{
    sdl_scan_pos pos = sdl_scan_tell(&top_frame(p)->sc);
    double v = cond_param(p);
    if (!sdl_ok(p)) return;
    if (!sdl_true(v)) {
        skip_tokens(p, SKIP_TO_END, 0, "#while", loc);
        return;
    }
    sdl_cond *c = push_cond(p, COND_WHILE, loc);
    if (c) c->pos = pos;
}

/* for_directive := '#for' '(' identifier ',' start ',' end [',' step] ')' body '#end' */
static void for_directive(sdl_parser *p, src_loc loc)
{
    sdl_expect(p, TOK_LPAREN, "'('");
    p->hold_macros++;
    sdl_tok id = sdl_next(p);
    p->hold_macros--;
    if (id.tk.kind != TOK_IDENT) {
        sdl_unexpected(p, &id, "loop variable");
        return;
    }
    sdl_accept(p, TOK_COMMA);
    double start = sdl_float(p);
    sdl_accept(p, TOK_COMMA);
    double end = sdl_float(p);
    double step = sdl_accept(p, TOK_COMMA) ? sdl_float(p) : 1.0;
    sdl_expect(p, TOK_RPAREN, "')'");
    if (!sdl_ok(p)) return;
    if (step == 0) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "#for step must not be 0");
        return;
    }
    sdl_value v = {VAL_FLOAT, 1, {start, 0, 0, 0, 0}, NULL, NULL};
    sdl_symtab_local(p->sym, id.tk.text, (size_t)id.tk.len, &v);
    if (step > 0 ? start > end : start < end) {
        skip_tokens(p, SKIP_TO_END, 0, "#for", loc);
        return;
    }
    sdl_cond *c = push_cond(p, COND_FOR, loc);
    if (!c) return;
    c->pos = sdl_scan_tell(&top_frame(p)->sc);
    c->for_end = end;
    c->for_step = step;
    c->for_var = sdl_strndup(p, id.tk.text, (size_t)id.tk.len);
}

/* Run the next #case/#range/#else clause that matches, else stop at #end. */
static void switch_clauses(sdl_parser *p, sdl_cond *c, sdl_kw k)
{
    int ci = (int)(c - p->conds);
    for (;;) {
        if (!sdl_ok(p) || k == KW_END) {
            p->nconds = ci;
            return;
        }
        sdl_cond *sc = &p->conds[ci];
        int match = 0;
        if (k == KW_ELSE) {
            match = 1;
        } else if (k == KW_CASE) {
            match = !sdl_true(cond_param(p) - sc->switch_value);
        } else {
            double lo, hi;
            sdl_expect(p, TOK_LPAREN, "'('");
            lo = sdl_float(p);
            sdl_accept(p, TOK_COMMA);
            hi = sdl_float(p);
            sdl_expect(p, TOK_RPAREN, "')'");
            match = sc->switch_value >= lo && sc->switch_value <= hi;
        }
        if (match) {
            p->conds[ci].switch_taken = 1;
            return;
        }
        k = skip_tokens(p, SKIP_SWITCH, 0, "#switch", p->conds[ci].loc);
    }
}

/* switch_directive := '#switch' '(' float ')' { clause } [ '#else' body ] '#end'
 * clause := ( '#case' '(' float ')' | '#range' '(' lo ',' hi ')' ) body [ '#break' ] */
static void switch_directive(sdl_parser *p, src_loc loc)
{
    double v = cond_param(p);
    if (!sdl_ok(p)) return;
    sdl_cond *c = push_cond(p, COND_SWITCH, loc);
    if (!c) return;
    c->switch_value = v;
    sdl_kw k = skip_tokens(p, SKIP_SWITCH, 0, "#switch", loc);
    switch_clauses(p, &p->conds[p->nconds - 1], k);
}

/* case_directive: '#case'/'#range' met while a clause runs: fall through. */
static void case_directive(sdl_parser *p, sdl_kw kw, src_loc loc)
{
    sdl_cond *c = local_cond(p);
    if (!c || c->kind != COND_SWITCH) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "#%s outside #switch", sdl_kw_text(kw));
        return;
    }
    if (kw == KW_CASE) {
        cond_param(p);
    } else {
        sdl_expect(p, TOK_LPAREN, "'('");
        sdl_float(p);
        sdl_accept(p, TOK_COMMA);
        sdl_float(p);
        sdl_expect(p, TOK_RPAREN, "')'");
    }
}

/* break_directive := '#break': leave the innermost #switch, #while or #for. */
static void break_directive(sdl_parser *p, src_loc loc)
{
    int base = top_frame(p)->cond_base;
    for (int i = p->nconds - 1; i >= base; i--) {
        sdl_cond_kind k = p->conds[i].kind;
        if (k != COND_SWITCH && k != COND_WHILE && k != COND_FOR) continue;
        int depth = p->nconds - 1 - i;
        src_loc at = p->conds[i].loc;
        const char *what = cond_name(k);
        p->nconds = i;
        skip_tokens(p, SKIP_TO_END, depth, what, at);
        return;
    }
    sdl_error(p, loc, PT_ERR_SYNTAX, "#break outside #switch, #while or #for");
}

static int loop_limit_hit(sdl_parser *p, sdl_cond *c)
{
    if (++c->iterations <= p->opt.max_loop_iterations) return 0;
    sdl_error(p, c->loc, PT_ERR_LIMIT, "%s loop exceeded %ld iterations", cond_name(c->kind), p->opt.max_loop_iterations);
    return 1;
}

/* #end of a #while: re-test the condition. */
static void end_while(sdl_parser *p, sdl_cond *c)
{
    if (loop_limit_hit(p, c)) return;
    sdl_scan_seek(&top_frame(p)->sc, c->pos);
    int ci = (int)(c - p->conds);
    double v = cond_param(p);
    if (sdl_ok(p) && !sdl_true(v)) skip_rest(p, &p->conds[ci]);
}

/* #end of a #for: step the variable and go round again while in range. */
static void end_for(sdl_parser *p, sdl_cond *c)
{
    if (loop_limit_hit(p, c)) return;
    const sdl_value *v = sdl_symtab_find(p->sym, c->for_var, strlen(c->for_var));
    if (!v || v->kind != VAL_FLOAT) {
        sdl_error(p, c->loc, PT_ERR_SYNTAX, "#for loop variable '%s' must stay a float", c->for_var);
        return;
    }
    sdl_value nv = *v;
    nv.v[0] += c->for_step;
    sdl_symtab_local(p->sym, c->for_var, strlen(c->for_var), &nv);
    if (c->for_step > 0 ? nv.v[0] > c->for_end : nv.v[0] < c->for_end) {
        p->nconds--;
        return;
    }
    sdl_scan_seek(&top_frame(p)->sc, c->pos);
}

static void return_from_macro(sdl_parser *p)
{
    p->nframes--;
    p->nconds--;
    p->macro_depth--;
    sdl_symtab_pop(p->sym);
}

/* end_directive := '#end' */
static void end_directive(sdl_parser *p, src_loc loc)
{
    sdl_cond *c = local_cond(p);
    if (!c) {
        sdl_frame *f = top_frame(p);
        if (f->kind == FRAME_MACRO && p->nconds > 0 && p->conds[p->nconds - 1].kind == COND_MACRO) {
            return_from_macro(p);
            return;
        }
        sdl_error(p, loc, PT_ERR_SYNTAX, "#end without matching #if, #while, #for, #switch or #macro");
        return;
    }
    switch (c->kind) {
    case COND_WHILE: end_while(p, c); break;
    case COND_FOR: end_for(p, c); break;
    default: p->nconds--; break;
    }
}

/* ------------------------------------------------------------ declarations */

/* Read the identifier after #declare/#local/#undef/#macro without expanding it. */
static sdl_tok name_token(sdl_parser *p, const char *what)
{
    p->hold_macros++;
    p->hold_arrays++;
    sdl_tok t = sdl_next(p);
    p->hold_arrays--;
    p->hold_macros--;
    if (t.tk.kind == TOK_KEYWORD)
        sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "'%s' is a reserved word and cannot be used as %s", sdl_kw_text(t.tk.kw), what);
    else if (t.tk.kind != TOK_IDENT)
        sdl_unexpected(p, &t, what);
    return t;
}

static void opaque_value(sdl_parser *p, sdl_value *out, const char *what)
{
    memset(out, 0, sizeof *out);
    out->kind = VAL_OPAQUE;
    out->str = what;
}

/* function_rvalue := 'function' ... (sdl_function.h) */
static void function_rvalue(sdl_parser *p, src_loc loc, sdl_value *out)
{
    scene_function *f = sdl_parse_function(p, loc, NULL);
    if (!f) return;
    out->kind = VAL_FUNCTION;
    out->dim = f->nterms;
    out->ptr = f;
}

/* Keyword rvalues that are skipped and kept as opaque values. */
static const char *opaque_rvalue_name(sdl_kw k)
{
    switch (k) {
    case KW_COLOR_MAP: case KW_COLOUR_MAP: return "colour_map";
    case KW_PIGMENT_MAP: return "pigment_map";
    case KW_NORMAL_MAP: return "normal_map";
    case KW_SLOPE_MAP: return "slope_map";
    case KW_TEXTURE_MAP: return "texture_map";
    case KW_DENSITY_MAP: return "density_map";
    case KW_DENSITY: return "density";
    case KW_MEDIA: return "media";
    case KW_FOG: return "fog";
    case KW_RAINBOW: return "rainbow";
    case KW_SKY_SPHERE: return "sky_sphere";
    default: return NULL;
    }
}

/* layered_texture := texture_block { 'texture' texture_block } (last on top) */
static scene_texture *layered_texture(sdl_parser *p)
{
    scene_texture *top = sdl_parse_texture(p);
    for (;;) {
        p->defer++;
        int more = sdl_ok(p) && top && sdl_accept_kw(p, KW_TEXTURE);
        p->defer--;
        if (!more) break;
        scene_texture *t = sdl_parse_texture(p);
        if (!t) break;
        scene_texture *last = t;
        while (last->next) last = last->next;
        last->next = top;
        top = t;
    }
    return top;
}

/* keyword_rvalue: texture/pigment/finish/normal/interior/material/camera/
 * transform/object/function/array/maps */
static void keyword_rvalue(sdl_parser *p, sdl_value *out)
{
    const sdl_tok *t = sdl_peek(p);
    sdl_kw k = t->tk.kw;
    const char *opaque = opaque_rvalue_name(k);
    memset(out, 0, sizeof *out);
    if (sdl_starts_object(t)) {
        out->kind = VAL_OBJECT;
        out->ptr = sdl_parse_object(p);
        return;
    }
    sdl_tok kt = sdl_next(p);
    switch (k) {
    case KW_TEXTURE: out->kind = VAL_TEXTURE; out->ptr = layered_texture(p); return;
    case KW_PIGMENT: out->kind = VAL_PIGMENT; out->ptr = sdl_parse_pigment_new(p); return;
    case KW_FINISH: out->kind = VAL_FINISH; out->ptr = sdl_parse_finish_new(p); return;
    case KW_NORMAL: out->kind = VAL_NORMAL; out->ptr = sdl_parse_normal(p); return;
    case KW_INTERIOR: out->kind = VAL_INTERIOR; out->ptr = sdl_parse_interior_new(p); return;
    case KW_MATERIAL: out->kind = VAL_MATERIAL; out->ptr = sdl_parse_material_new(p); return;
    case KW_CAMERA: out->kind = VAL_CAMERA; out->ptr = sdl_parse_camera_new(p); return;
    case KW_TRANSFORM: {
        xform *x = sdl_alloc(p, sizeof *x);
        if (x) *x = sdl_parse_transform(p);
        out->kind = VAL_TRANSFORM;
        out->ptr = x;
        return;
    }
    case KW_FUNCTION: function_rvalue(p, kt.tk.loc, out); return;
    case KW_SPLINE:
        out->ptr = sdl_parse_spline(p, kt.tk.loc);
        out->kind = out->ptr ? VAL_SPLINE : VAL_NONE;
        return;
    case KW_ARRAY:
        out->ptr = sdl_parse_array(p, kt.tk.loc);
        out->kind = out->ptr ? VAL_ARRAY : VAL_NONE;
        return;
    default:
        break;
    }
    if (opaque && sdl_parse_look_value(p, k, out)) return; /* maps, fog, sky_sphere */
    if (opaque) {
        sdl_ignore_block(p, kt.tk.loc, opaque, "'%s' is not supported yet and is ignored", opaque);
        opaque_value(p, out, opaque);
        return;
    }
    sdl_unexpected(p, &kt, "value to declare");
}

/* A function or spline identifier not followed by '(' is a copy of it
 * (#declare G = F). Returns 1 if that was the case. */
static int callable_copy(sdl_parser *p, sdl_value *out)
{
    const sdl_tok *t = sdl_peek(p);
    if (t->tk.kind != TOK_IDENT || (t->val.kind != VAL_FUNCTION && t->val.kind != VAL_SPLINE)) return 0;
    sdl_tok id = sdl_next(p);
    if (sdl_is(sdl_peek(p), TOK_LPAREN)) {
        sdl_unget(p, &id);
        return 0;
    }
    *out = id.val;
    return 1;
}

void sdl_rvalue(sdl_parser *p, sdl_value *out)
{
    const sdl_tok *t = sdl_peek(p);
    memset(out, 0, sizeof *out);
    if (sdl_starts_string(t)) {
        out->kind = VAL_STRING;
        out->str = sdl_string(p);
    } else if (t->tk.kind == TOK_KEYWORD && sdl_starts_colour(t)) {
        colour5 c = sdl_colour(p, 1);
        out->kind = VAL_COLOUR;
        out->dim = 5;
        out->v[0] = c.r; out->v[1] = c.g; out->v[2] = c.b; out->v[3] = c.f; out->v[4] = c.t;
    } else if (callable_copy(p, out)) {
        return;
    } else if (sdl_starts_expr(t)) {
        sdl_sum(p, out); /* POV-Ray reads a declared value at the sum level: comparisons need ( ) */
    } else if (t->tk.kind == TOK_IDENT && t->val.kind != VAL_NONE) {
        sdl_tok id = sdl_next(p);
        *out = id.val;
        if (out->kind == VAL_ARRAY && out->ptr) out->ptr = sdl_array_copy(p, out->ptr); /* arrays are copied */
    } else if (t->tk.kind == TOK_IDENT) {
        sdl_error(p, t->tk.loc, PT_ERR_SYNTAX, "undeclared identifier '%.*s'", t->tk.len, t->tk.text);
    } else if (t->tk.kind == TOK_KEYWORD) {
        keyword_rvalue(p, out);
    } else {
        sdl_unexpected(p, t, "value");
    }
}

/* element_lvalue := array_identifier '[' i ']' { '[' i ']' } ; nested arrays
 * are followed down. Returns the array holding the element and its index. */
static sdl_array *element_lvalue(sdl_parser *p, const sdl_tok *id, long *index)
{
    sdl_array *a = id->val.ptr;
    for (;;) {
        long i = sdl_array_subscripts(p, a, id->tk.loc);
        if (i < 0) return NULL;
        const sdl_value *e = &a->elems[i];
        if (e->kind == VAL_ARRAY && e->ptr && sdl_is(sdl_peek(p), TOK_LBRACKET)) {
            a = e->ptr;
            continue;
        }
        *index = i;
        return a;
    }
}

/* declare_directive := ('#declare' | '#local') [ 'deprecated' ['once'] [string] ]
 *                      identifier { '[' float ']' } '=' rvalue [';'] */
static void declare_directive(sdl_parser *p, int local)
{
    /* the look-ahead for 'deprecated' must not run a macro or index an array */
    p->hold_macros++;
    p->hold_arrays++;
    int deprecated = sdl_accept_kw(p, KW_DEPRECATED);
    p->hold_arrays--;
    p->hold_macros--;
    if (deprecated) {
        sdl_accept_kw(p, KW_ONCE);
        if (sdl_starts_string(sdl_peek(p))) sdl_string(p);
    }
    sdl_tok id = name_token(p, "an identifier");
    if (!sdl_ok(p)) return;
    sdl_array *arr = NULL;
    long index = -1;
    if (sdl_is(sdl_peek(p), TOK_LBRACKET)) {
        if (id.val.kind != VAL_ARRAY || !id.val.ptr) {
            sdl_error(p, sdl_peek(p)->tk.loc, PT_ERR_SYNTAX, "'%.*s' is not an array and cannot take a subscript", id.tk.len, id.tk.text);
            return;
        }
        arr = element_lvalue(p, &id, &index);
        if (!arr) return;
    } else if (id.val.kind == VAL_FUNCTION) {
        sdl_error(p, id.tk.loc, PT_ERR_SYNTAX, "function '%.*s' cannot be redeclared (#undef it first)", id.tk.len, id.tk.text);
        return;
    }
    /* the target is resolved now: the value may call macros or end the
     * running macro (POV-Ray's Parse_Declare adds the symbol first) */
    sdl_symtarget target = sdl_symtab_target(p->sym, id.tk.text, (size_t)id.tk.len, local);
    if (!sdl_expect(p, TOK_EQ, "'='")) return;
    /* Directives after the value must run after the assignment: look-ahead
     * past an expression (and the ';' check) defers them, as POV-Ray does. */
    const sdl_tok *first = sdl_peek(p);
    src_loc at = first->tk.loc;
    int expression = sdl_starts_expr(first) || sdl_starts_string(first);
    sdl_value v;
    p->defer += expression;
    sdl_rvalue(p, &v);
    p->defer += !expression;
    if (!arr && target.elem_owner) { /* a parameter that stands for an array element */
        arr = target.elem_owner;
        index = target.elem_index;
    }
    if (arr) {
        sdl_array_set(p, arr, index, &v, at);
    } else {
        if (sdl_ok(p) && sdl_symtab_assign(p->sym, &target, id.tk.text, (size_t)id.tk.len, &v) == 0)
            sdl_error(p, id.tk.loc, PT_ERR_NOMEM, "out of memory");
    }
    sdl_accept(p, TOK_SEMI);
    p->defer--;
}

/* undef_directive := '#undef' identifier */
static void undef_directive(sdl_parser *p)
{
    sdl_tok id = name_token(p, "an identifier");
    if (!sdl_ok(p)) return;
    if (!sdl_symtab_undef(p->sym, id.tk.text, (size_t)id.tk.len))
        sdl_warning(p, id.tk.loc, "#undef of undeclared identifier '%.*s'", id.tk.len, id.tk.text);
}

/* version_directive := '#version' float [';'] */
static void version_directive(sdl_parser *p)
{
    sdl_peek(p);
    p->defer++;
    double v = sdl_float(p);
    sdl_accept(p, TOK_SEMI);
    p->defer--;
    if (!sdl_ok(p)) return;
    p->version = v;
    if (p->nframes == 1) {
        p->s->version_major = sdl_to_int(floor(v + 1e-9));
        p->s->version_minor = sdl_to_int(floor((v - p->s->version_major) * 10 + 0.5));
    }
}

/* message_directive := ('#debug' | '#warning' | '#error' | '#render' | '#statistics') string
 * (#render and #statistics go to POV-Ray's render and statistics streams:
 * notes here, like #debug) */
static void message_directive(sdl_parser *p, sdl_kw kw, src_loc loc)
{
    const char *msg = sdl_string(p);
    if (!sdl_ok(p)) return;
    msg = sdl_c_string(p, msg);
    if (kw == KW_ERROR) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "#error: %s", msg);
    } else if (kw == KW_WARNING) {
        sdl_warning(p, loc, "%s", msg);
    } else {
        /* #debug text usually ends with "\n"; keep the note on one line */
        size_t n = strlen(msg);
        while (n > 0 && (msg[n - 1] == '\n' || msg[n - 1] == '\r')) n--;
        sdl_note(p, loc, "%.*s", (int)n, msg);
    }
}

/* include_directive := '#include' string */
static void include_directive(sdl_parser *p, src_loc loc)
{
    const char *name = sdl_string(p);
    if (!sdl_ok(p)) return;
    if (p->include_depth + 1 > p->opt.max_include_depth) {
        sdl_error(p, loc, PT_ERR_LIMIT, "includes nested more than %d deep", p->opt.max_include_depth);
        return;
    }
    char *path = find_include(p, name);
    if (!path) {
        sdl_error(p, loc, PT_ERR_IO, "cannot find include file \"%s\"", name);
        return;
    }
    size_t len = 0;
    char *text = pt_read_file(path, 1, (size_t)p->opt.max_memory, &len);
    if (!text) {
        sdl_error(p, loc, PT_ERR_IO, "cannot read include file \"%s\": %s", path,
                  errno == EINVAL ? "not a regular file" : strerror(errno));
        free(path);
        return;
    }
    sdl_source *src = add_source(p, path, text, len);
    free(path);
    if (!src || !sdl_symtab_push(p->sym)) {
        sdl_error(p, loc, PT_ERR_NOMEM, "out of memory");
        return;
    }
    if (!push_frame(p, FRAME_FILE, src, loc, NULL)) return;
    p->include_depth++;
}

/* macro_directive := '#macro' identifier '(' [ identifier { ',' identifier } ] ')' body '#end' */
static void macro_directive(sdl_parser *p, src_loc loc)
{
    sdl_tok id = name_token(p, "a macro name");
    if (!sdl_expect(p, TOK_LPAREN, "'(' after the macro name")) return;
    const char *params[64];
    int n = 0;
    /* parameter names may be macro or array names elsewhere (debug.inc's Str) */
    p->hold_macros++;
    p->hold_arrays++;
    while (sdl_ok(p) && !sdl_accept(p, TOK_RPAREN) && n <= 64) {
        sdl_tok t = name_token(p, "a macro parameter");
        if (!sdl_ok(p)) break;
        if (n == 64) {
            sdl_error(p, t.tk.loc, PT_ERR_LIMIT, "too many macro parameters");
            break;
        }
        params[n++] = sdl_strndup(p, t.tk.text, (size_t)t.tk.len);
        sdl_accept(p, TOK_COMMA); /* optional, as in POV-Ray (shapes3.inc omits one) */
    }
    p->hold_arrays--;
    p->hold_macros--;
    if (!sdl_ok(p)) return;
    sdl_macro *m = sdl_alloc(p, sizeof *m);
    const char **pp = sdl_alloc(p, sizeof(char *) * (size_t)(n ? n : 1));
    if (!m || !pp) return;
    memcpy(pp, params, sizeof(char *) * (size_t)n);
    m->name = sdl_strndup(p, id.tk.text, (size_t)id.tk.len);
    m->loc = loc;
    m->src = top_frame(p)->src;
    m->body = sdl_scan_tell(&top_frame(p)->sc);
    m->nparams = n;
    m->params = pp;
    sdl_value v;
    memset(&v, 0, sizeof v);
    v.kind = VAL_MACRO;
    v.ptr = m;
    sdl_symtab_declare(p->sym, id.tk.text, (size_t)id.tk.len, &v);
    skip_tokens(p, SKIP_TO_END, 0, "#macro", loc);
}

/* A macro argument passed by reference: an identifier (ref) or an array
 * element (arr, index). */
typedef struct {
    sdl_symref *ref;
    sdl_array *arr;
    long index;
} macro_ref;

/* macro_argument := identifier | element | rvalue ; an identifier or an
 * array element standing alone (a ',' or ')' follows) is passed by
 * reference, except a function (POV-Ray 3.7 Parse_RValue, which keeps the
 * element's slot too): #declare or #local of the parameter inside the macro
 * assigns the caller's identifier or element. The element keeps the
 * array's type: 3.7 lets the parameter change it (Test_Redefine) and then
 * reads every element of the array as the new type; here that is an error. */
static void macro_argument(sdl_parser *p, const sdl_macro *m, sdl_value *arg, macro_ref *r)
{
    memset(r, 0, sizeof *r);
    const sdl_tok *t = sdl_peek(p);
    if (t->tk.kind == TOK_IDENT && t->elem && t->elem_arr && t->val.kind != VAL_FUNCTION) {
        sdl_tok el = sdl_next(p);
        sdl_tok_kind after = sdl_peek(p)->tk.kind;
        if (after == TOK_COMMA || after == TOK_RPAREN) {
            *arg = el.val;
            r->arr = el.elem_arr;
            r->index = el.elem_idx;
            return;
        }
        sdl_unget(p, &el);
    }
    if (t->tk.kind == TOK_IDENT && !t->elem && t->val.kind != VAL_FUNCTION) {
        sdl_tok id = sdl_next(p);
        sdl_tok_kind after = sdl_peek(p)->tk.kind;
        if (after == TOK_COMMA || after == TOK_RPAREN) {
            if (id.val.kind == VAL_NONE) {
                sdl_error(p, id.tk.loc, PT_ERR_SYNTAX, "undeclared identifier '%.*s' cannot be passed to macro %s (declare it first)",
                          id.tk.len, id.tk.text, m->name);
                return;
            }
            *arg = id.val;
            r->ref = sdl_symtab_ref(p->sym, id.tk.text, (size_t)id.tk.len);
            return;
        }
        sdl_unget(p, &id);
    }
    sdl_rvalue(p, arg);
}

/* macro_call := macro_identifier '(' [ macro_argument { [','] macro_argument } [','] ] ')' */
static void macro_invoke(sdl_parser *p, const sdl_tok *id, sdl_value *args, macro_ref *refs);

static void macro_call(sdl_parser *p, const sdl_tok *id)
{
    /* argument storage lives only until the parameters are bound */
    sdl_value *args = malloc(sizeof(sdl_value) * 64);
    macro_ref *refs = malloc(sizeof(macro_ref) * 64);
    if (args && refs) macro_invoke(p, id, args, refs);
    else sdl_error(p, id->tk.loc, PT_ERR_NOMEM, "out of memory");
    free(args);
    free(refs);
}

static void macro_invoke(sdl_parser *p, const sdl_tok *id, sdl_value *args, macro_ref *refs)
{
    const sdl_macro *m = id->val.ptr;
    int n = 0;
    if (!sdl_expect(p, TOK_LPAREN, "'(' after the macro name")) return;
    if (!sdl_enter(p, id->tk.loc)) return;
    while (sdl_ok(p) && !sdl_accept(p, TOK_RPAREN)) {
        if (n == 64) {
            sdl_error(p, id->tk.loc, PT_ERR_LIMIT, "too many macro arguments");
            break;
        }
        macro_argument(p, m, &args[n], &refs[n]);
        n++;
        sdl_accept(p, TOK_COMMA);
    }
    sdl_leave(p);
    if (!sdl_ok(p)) return;
    if (n != m->nparams) {
        sdl_error(p, id->tk.loc, PT_ERR_SYNTAX, "macro %s expects %d argument%s, %d given", m->name, m->nparams, m->nparams == 1 ? "" : "s", n);
        return;
    }
    if (p->macro_depth + 1 > p->opt.max_macro_depth) {
        sdl_error(p, id->tk.loc, PT_ERR_LIMIT, "macro calls nested more than %d deep", p->opt.max_macro_depth);
        return;
    }
    if (!push_cond(p, COND_MACRO, id->tk.loc) || !sdl_symtab_push(p->sym)) return;
    for (int i = 0; i < n; i++) {
        size_t len = strlen(m->params[i]);
        int ok;
        if (refs[i].ref) ok = sdl_symtab_alias(p->sym, m->params[i], len, refs[i].ref);
        else if (refs[i].arr)
            ok = sdl_symtab_alias_elem(p->sym, m->params[i], len, &refs[i].arr->elems[refs[i].index], refs[i].arr, refs[i].index);
        else ok = sdl_symtab_local(p->sym, m->params[i], len, &args[i]);
        if (!ok) {
            sdl_error(p, id->tk.loc, PT_ERR_NOMEM, "out of memory");
            return;
        }
    }
    if (!push_frame(p, FRAME_MACRO, m->src, id->tk.loc, m->name)) return;
    sdl_scan_seek(&top_frame(p)->sc, m->body);
    p->macro_depth++;
}

/* directive := '#' directive_keyword ... */
static void directive_body(sdl_parser *p, const sdl_token *hash);

static void directive(sdl_parser *p, const sdl_token *hash)
{
    if (!sdl_enter(p, hash->loc)) return;
    directive_body(p, hash);
    sdl_leave(p);
}

static void directive_body(sdl_parser *p, const sdl_token *hash)
{
    sdl_token k = sdl_scan_next(&top_frame(p)->sc);
    src_loc loc = hash->loc;
    if (k.kind != TOK_KEYWORD) {
        /* POV-Ray ignores a '#' that no directive follows */
        sdl_warning(p, loc, "'#' without a directive ignored");
        sdl_tok t;
        memset(&t, 0, sizeof t);
        t.tk = k;
        if (k.kind == TOK_IDENT) {
            const sdl_value *v = sdl_symtab_find(p->sym, k.text, (size_t)k.len);
            if (v) t.val = *v;
        }
        if (k.kind == TOK_ERROR) sdl_error(p, k.loc, PT_ERR_SYNTAX, "%s", top_frame(p)->sc.err);
        else sdl_unget(p, &t);
        return;
    }
    switch (k.kw) {
    case KW_DECLARE: declare_directive(p, 0); break;
    case KW_LOCAL: declare_directive(p, 1); break;
    case KW_UNDEF: undef_directive(p); break;
    case KW_IF: case KW_IFDEF: case KW_IFNDEF: if_directive(p, k.kw, loc); break;
    case KW_ELSE: case KW_ELSEIF: else_directive(p, k.kw, loc); break;
    case KW_WHILE: while_directive(p, loc); break;
    case KW_FOR: for_directive(p, loc); break;
    case KW_SWITCH: switch_directive(p, loc); break;
    case KW_CASE: case KW_RANGE: case_directive(p, k.kw, loc); break;
    case KW_BREAK: break_directive(p, loc); break;
    case KW_END: end_directive(p, loc); break;
    case KW_INCLUDE: include_directive(p, loc); break;
    case KW_VERSION: version_directive(p); break;
    case KW_DEBUG: case KW_WARNING: case KW_ERROR: message_directive(p, k.kw, loc); break;
    case KW_MACRO: macro_directive(p, loc); break;
    case KW_DEFAULT: sdl_parse_default(p); break;
    case KW_FOPEN: sdl_fopen_directive(p, loc); break;
    case KW_FCLOSE: sdl_fclose_directive(p, loc); break;
    case KW_READ: sdl_read_directive(p, loc); break;
    case KW_WRITE: sdl_write_directive(p, loc); break;
    case KW_RENDER: case KW_STATISTICS: message_directive(p, k.kw, loc); break;
    default:
        sdl_error(p, k.loc, PT_ERR_SYNTAX, "unknown directive #%s", sdl_kw_text(k.kw));
        break;
    }
}

/* ------------------------------------------------------------ the stream */

/* End of the current input: leave an included file (checking its
 * conditionals are closed). Returns 1 if reading can go on. */
static int end_of_input(sdl_parser *p, const sdl_token *eof)
{
    sdl_frame *f = top_frame(p);
    if (p->nconds > f->cond_base) {
        sdl_cond *c = &p->conds[p->nconds - 1];
        unterminated_cond(p, eof->loc, cond_name(c->kind), c->loc);
        return 0;
    }
    if (p->nframes == 1) return 0;
    if (f->kind == FRAME_MACRO) {
        sdl_error(p, eof->loc, PT_ERR_SYNTAX, "macro %s has no #end", f->name);
        return 0;
    }
    p->nframes--;
    p->include_depth--;
    sdl_symtab_pop(p->sym);
    return 1;
}

/* After a '#' read while directives are deferred: is it the #end of the
 * running macro body? (That one always runs: the macro's value ends there.)
 * Consumes the 'end' if so. */
static int macro_end_ahead(sdl_parser *p)
{
    sdl_frame *f = top_frame(p);
    if (f->kind != FRAME_MACRO || local_cond(p)) return 0;
    sdl_scan_pos at = sdl_scan_tell(&f->sc);
    sdl_token k = sdl_scan_next(&f->sc);
    if (k.kind == TOK_KEYWORD && k.kw == KW_END) return 1;
    sdl_scan_seek(&f->sc, at);
    return 0;
}

static sdl_tok eof_token(const sdl_parser *p)
{
    sdl_tok t;
    memset(&t, 0, sizeof t);
    t.tk.kind = TOK_EOF;
    t.tk.loc = p->last_loc;
    return t;
}

/* A pushed-back token: a deferred '#' or macro name runs now unless
 * look-ahead is still deferring. Returns 1 if t is to be returned. */
static int resume_token(sdl_parser *p, sdl_tok *t)
{
    if (t->tk.kind == TOK_HASH && p->defer == 0) {
        directive(p, &t->tk);
        return 0;
    }
    if (t->tk.kind == TOK_IDENT && t->val.kind == VAL_MACRO && p->hold_macros == 0 && p->defer == 0) {
        macro_call(p, t);
        return 0;
    }
    return 1;
}

/* A token just scanned from the current input: errors, end of input,
 * directives and macro calls are dealt with here. Returns 1 if t is to be
 * returned. */
static int fresh_token(sdl_parser *p, sdl_tok *t)
{
    switch (t->tk.kind) {
    case TOK_ERROR:
        sdl_error(p, t->tk.loc, PT_ERR_SYNTAX, "%s", top_frame(p)->sc.err);
        return 0;
    case TOK_EOF:
        return !end_of_input(p, &t->tk) && sdl_ok(p);
    case TOK_HASH:
        if (p->defer > 0 && macro_end_ahead(p)) {
            return_from_macro(p);
            return 0;
        }
        if (p->defer > 0) return 1;
        directive(p, &t->tk);
        return 0;
    case TOK_IDENT: {
        const sdl_value *v = sdl_symtab_find(p->sym, t->tk.text, (size_t)t->tk.len);
        if (v) t->val = *v;
        if (t->tk.len == 12 && memcmp(t->tk.text, "frame_number", 12) == 0) sdl_note_frame_value(p);
        if (v && v->kind == VAL_MACRO && p->hold_macros == 0 && p->defer == 0) {
            macro_call(p, t);
            return 0;
        }
        return 1;
    }
    default:
        return 1;
    }
}

sdl_tok sdl_next(sdl_parser *p)
{
    for (;;) {
        if (!sdl_ok(p) || p->nframes == 0) return eof_token(p);
        sdl_tok t;
        t.val.kind = VAL_NONE;
        t.elem = 0;
        t.elem_arr = NULL;
        t.elem_idx = 0;
        int take;
        if (p->nahead > 0) {
            t = p->ahead[--p->nahead];
            take = resume_token(p, &t);
        } else {
            t.tk = sdl_scan_next(&top_frame(p)->sc);
            take = sdl_count_token(p, t.tk.loc) && fresh_token(p, &t);
        }
        if (take && sdl_ok(p) && t.tk.kind == TOK_IDENT && t.val.kind == VAL_ARRAY && p->hold_arrays == 0)
            sdl_array_resolve(p, &t);
        if (take && sdl_ok(p)) {
            p->last_loc = t.tk.loc;
            return t;
        }
    }
}

const sdl_tok *sdl_peek(sdl_parser *p)
{
    if (!sdl_ok(p)) p->nahead = 0;
    if (p->nahead == 0) {
        sdl_tok t = sdl_next(p);
        sdl_unget(p, &t);
    }
    return &p->ahead[p->nahead - 1];
}

int sdl_raw_next_is(sdl_parser *p, sdl_tok_kind k)
{
    if (p->nahead > 0) return p->ahead[p->nahead - 1].tk.kind == k;
    if (p->nframes == 0) return 0;
    sdl_scanner *sc = &top_frame(p)->sc;
    sdl_scan_pos at = sdl_scan_tell(sc);
    sdl_token t = sdl_scan_next(sc);
    sdl_scan_seek(sc, at);
    return t.kind == k;
}

void sdl_unget(sdl_parser *p, const sdl_tok *t)
{
    if (p->nahead < (int)(sizeof p->ahead / sizeof p->ahead[0])) {
        p->ahead[p->nahead++] = *t;
    } else if (sdl_ok(p)) {
        sdl_error(p, t->tk.loc, PT_ERR_INTERNAL, "parser pushed back too many tokens");
    }
}
