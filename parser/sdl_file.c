/* sdl_file.c - #fopen/#fclose/#read/#write. */
#include "sdl_file.h"
#include <errno.h>
#include <math.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "fileio.h"
#include "sdl_array.h"
#include "sdl_directive.h"
#include "sdl_expr.h"

typedef struct sdl_file {
    char *path;            /* as opened */
    const char *name;      /* interned (arena), used in locations */
    FILE *out;             /* write / append */
    char *text;            /* read: the whole file */
    sdl_scanner sc;
    int reading, open;
    struct sdl_file *next;
} sdl_file;

/* ------------------------------------------------------------ paths */

static char *dir_part(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash) return strdup(".");
    if (slash == path) return strdup("/");
    return strndup(path, (size_t)(slash - path));
}

static char *join(const char *dir, const char *name)
{
    size_t n = strlen(dir) + strlen(name) + 2;
    char *s = malloc(n);
    if (s) snprintf(s, n, "%s/%s", dir, name);
    return s;
}

static int regular_file(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

/* The scene file's directory (malloc'd). */
static char *scene_dir(const sdl_parser *p)
{
    if (p->nframes > 0 && p->frames[0].src && p->frames[0].src->path) return dir_part(p->frames[0].src->path);
    return strdup(".");
}

/* A file to read: the write_dir option's directory (files this parse
 * wrote), the scene's directory, the including file's directory, the
 * library path, the working directory. */
static char *find_read(sdl_parser *p, const char *name)
{
    if (name[0] == '/') return regular_file(name) ? strdup(name) : NULL;
    if (p->opt.write_dir) { /* a file this parse wrote there */
        const char *base = strrchr(name, '/');
        char *w = join(p->opt.write_dir, base ? base + 1 : name);
        if (w && regular_file(w)) return w;
        free(w);
    }
    char *dirs[4] = {scene_dir(p), NULL, NULL, NULL};
    if (p->nframes > 0 && p->frames[p->nframes - 1].src) dirs[1] = dir_part(p->frames[p->nframes - 1].src->path);
    char *found = NULL;
    for (int i = 0; i < 2 && !found; i++) {
        if (!dirs[i]) continue;
        char *c = join(dirs[i], name);
        if (c && regular_file(c)) found = c;
        else free(c);
    }
    for (int i = 0; i < p->opt.nlib_paths && !found; i++) {
        char *c = join(p->opt.lib_paths[i], name);
        if (c && regular_file(c)) found = c;
        else free(c);
    }
    if (!found && regular_file(name)) found = strdup(name);
    free(dirs[0]);
    free(dirs[1]);
    return found;
}

/* Is `path`'s directory inside `root` (both made absolute)? */
static int within(const char *dir_real, const char *root)
{
    char rr[PATH_MAX];
    if (!realpath(root, rr)) return 0;
    size_t n = strlen(rr);
    if (strncmp(dir_real, rr, n) != 0) return 0;
    return dir_real[n] == 0 || dir_real[n] == '/' || (n == 1 && rr[0] == '/');
}

/* A file to write: relative to the scene's directory (or the write_dir
 * option), only inside the scene's directory or the working directory. */
static char *place_write(sdl_parser *p, const char *name, src_loc loc)
{
    char *path;
    if (p->opt.write_dir) {
        const char *base = strrchr(name, '/');
        path = join(p->opt.write_dir, base ? base + 1 : name);
        return path;
    }
    char *sd = scene_dir(p);
    path = name[0] == '/' ? strdup(name) : join(sd, name);
    char *d = path ? dir_part(path) : NULL;
    char real[PATH_MAX];
    int ok = d && realpath(d, real) && (within(real, sd) || within(real, "."));
    if (!ok) {
        sdl_error(p, loc, PT_ERR_IO, "writing \"%s\" is not permitted: files may only be written in the scene's directory or the current directory", name);
        free(path);
        path = NULL;
    }
    free(d);
    free(sd);
    return path;
}

/* ------------------------------------------------------------ #fopen / #fclose */

static sdl_file *new_file(sdl_parser *p, char *path, const char *given)
{
    sdl_file *f = calloc(1, sizeof *f);
    if (!f) {
        free(path);
        return NULL;
    }
    f->path = path;
    f->name = sdl_strndup(p, given, strlen(given)); /* messages name it as the scene does */
    f->next = p->files;
    p->files = f;
    return f;
}

void sdl_fopen_directive(sdl_parser *p, src_loc loc)
{
    p->hold_macros++;
    p->hold_arrays++;
    sdl_tok id = sdl_next(p);
    p->hold_arrays--;
    p->hold_macros--;
    if (id.tk.kind != TOK_IDENT || (id.val.kind != VAL_NONE && id.val.kind != VAL_FILE)) {
        sdl_unexpected(p, &id, "a new identifier for the file");
        return;
    }
    src_loc nloc = sdl_peek(p)->tk.loc;
    const char *name = sdl_string(p);
    sdl_tok mode = sdl_next(p);
    if (!sdl_ok(p)) return;
    if (!sdl_is_kw(&mode, KW_READ) && !sdl_is_kw(&mode, KW_WRITE) && !sdl_is_kw(&mode, KW_APPEND)) {
        sdl_unexpected(p, &mode, "read, write or append");
        return;
    }
    sdl_file *f = NULL;
    if (mode.tk.kw == KW_READ) {
        char *path = find_read(p, name);
        size_t len = 0;
        /* regular files only: /dev/zero would be read forever, a FIFO or
         * /dev/stdin could block the parse */
        char *text = path ? pt_read_file(path, 1, (size_t)-1, &len) : NULL;
        if (!text) {
            sdl_error(p, nloc, PT_ERR_IO, "cannot open user file \"%s\" for reading", name);
            free(path);
            return;
        }
        f = new_file(p, path, name);
        if (!f) {
            free(text);
            sdl_error(p, loc, PT_ERR_NOMEM, "out of memory");
            return;
        }
        f->text = text;
        f->reading = 1;
        sdl_hash_input(p, text, len);
        sdl_scan_init(&f->sc, f->name, f->text, len);
    } else {
        char *path = place_write(p, name, nloc);
        if (!path) return;
        FILE *out = fopen(path, mode.tk.kw == KW_APPEND ? "ab" : "wb");
        if (!out) {
            sdl_error(p, nloc, PT_ERR_IO, "cannot open user file \"%s\" for %s: %s", name, mode.tk.kw == KW_APPEND ? "appending" : "writing",
                      strerror(errno));
            free(path);
            return;
        }
        f = new_file(p, path, name);
        if (!f) {
            fclose(out);
            sdl_error(p, loc, PT_ERR_NOMEM, "out of memory");
            return;
        }
        f->out = out;
    }
    f->open = 1;
    sdl_value v = {.kind = VAL_FILE, .ptr = f, .str = f->name};
    if (!sdl_symtab_declare(p->sym, id.tk.text, (size_t)id.tk.len, &v)) sdl_error(p, loc, PT_ERR_NOMEM, "out of memory");
}

static void close_file(sdl_file *f)
{
    if (f->out) fclose(f->out);
    f->out = NULL;
    free(f->text);
    f->text = NULL;
    f->open = 0;
}

void sdl_fclose_directive(sdl_parser *p, src_loc loc)
{
    (void)loc;
    p->hold_macros++;
    p->hold_arrays++;
    sdl_tok id = sdl_next(p);
    p->hold_arrays--;
    p->hold_macros--;
    if (id.tk.kind != TOK_IDENT || id.val.kind != VAL_FILE) {
        /* POV-Ray ignores #fclose of anything but an open file */
        if (id.tk.kind != TOK_IDENT) sdl_unget(p, &id);
        return;
    }
    close_file(id.val.ptr);
    sdl_symtab_undef(p->sym, id.tk.text, (size_t)id.tk.len);
}

void sdl_files_close(sdl_parser *p)
{
    sdl_file *f = p->files;
    while (f) {
        sdl_file *n = f->next;
        close_file(f);
        free(f->path);
        free(f);
        f = n;
    }
    p->files = NULL;
}

/* ------------------------------------------------------------ #read */

/* file_param := '(' file_identifier ; the open file (its identifier in *id) */
static sdl_file *file_param(sdl_parser *p, const char *what, sdl_tok *id)
{
    if (!sdl_expect(p, TOK_LPAREN, "'('")) return NULL;
    p->hold_macros++;
    *id = sdl_next(p);
    p->hold_macros--;
    if (id->tk.kind != TOK_IDENT || id->val.kind != VAL_FILE || !id->val.ptr) {
        sdl_unexpected(p, id, "file identifier (from #fopen)");
        return NULL;
    }
    sdl_file *f = id->val.ptr;
    if (f->reading != (what[0] == 'r')) {
        sdl_error(p, id->tk.loc, PT_ERR_SYNTAX, "cannot %s file \"%s\": it is open for %s", what, f->name, f->reading ? "reading" : "writing");
        return NULL;
    }
    return f;
}

/* data_float := [ '+' | '-' ] number */
static int data_float(sdl_parser *p, sdl_file *f, double *out)
{
    sdl_token t = sdl_scan_next(&f->sc);
    double sign = 1;
    if (t.kind == TOK_PLUS || t.kind == TOK_MINUS) {
        sign = t.kind == TOK_MINUS ? -1 : 1;
        t = sdl_scan_next(&f->sc);
    }
    if (t.kind != TOK_NUMBER) {
        char what[96];
        sdl_error(p, t.loc, PT_ERR_SYNTAX, "expected a number in data file, found %s", sdl_tok_describe(&t, what, sizeof what));
        return 0;
    }
    *out = sign * t.num;
    return 1;
}

/* Skip an optional ',' in the data; 1 if the data end right here (no
 * comma, then the end of the file: POV-Ray then ends the file with this
 * value, so a #while (defined(F)) loop stops after it). */
static int data_comma(sdl_file *f)
{
    sdl_scan_pos at = sdl_scan_tell(&f->sc);
    sdl_token t = sdl_scan_next(&f->sc);
    if (t.kind == TOK_COMMA) return 0;
    sdl_scan_seek(&f->sc, at);
    return t.kind == TOK_EOF;
}

/* data_value := data_float | '<' data_float [','] data_float { [','] data_float } '>' | string
 * Returns 1 with a value, 0 at the end of the file (or after an error);
 * *ends: the file ends right after this value. */
static int data_value(sdl_parser *p, sdl_file *f, sdl_value *v, int *ends)
{
    memset(v, 0, sizeof *v);
    sdl_scan_pos at = sdl_scan_tell(&f->sc);
    sdl_token t = sdl_scan_next(&f->sc);
    switch (t.kind) {
    case TOK_EOF: return 0;
    case TOK_NUMBER: case TOK_PLUS: case TOK_MINUS:
        sdl_scan_seek(&f->sc, at);
        v->kind = VAL_FLOAT;
        v->dim = 1;
        if (!data_float(p, f, &v->v[0])) return 0;
        break;
    case TOK_LT: {
        int n = 0;
        for (;;) {
            sdl_scan_pos q = sdl_scan_tell(&f->sc);
            sdl_token c = sdl_scan_next(&f->sc);
            if (c.kind == TOK_GT && n >= 2) break;
            sdl_scan_seek(&f->sc, q);
            if (n == 5) {
                sdl_error(p, c.loc, PT_ERR_SYNTAX, "vector data has more than 5 terms");
                return 0;
            }
            if (!data_float(p, f, &v->v[n++])) return 0;
            data_comma(f);
        }
        v->kind = n == 5 ? VAL_COLOUR : VAL_VECTOR;
        v->dim = n;
        break;
    }
    case TOK_STRING: {
        char *s = sdl_alloc(p, (size_t)t.len * 3 + 1);
        if (!s) return 0;
        sdl_scan_unescape(&t, s, (size_t)t.len * 3 + 1);
        v->kind = VAL_STRING;
        v->str = s;
        break;
    }
    default: {
        char what[96];
        if (t.kind == TOK_ERROR) sdl_error(p, t.loc, PT_ERR_SYNTAX, "%s", f->sc.err);
        else sdl_error(p, t.loc, PT_ERR_SYNTAX, "expected a float, vector or string in data file, found %s", sdl_tok_describe(&t, what, sizeof what));
        return 0;
    }
    }
    *ends = data_comma(f);
    return 1;
}

/* read_target := identifier { '[' float ']' } ; stores v there */
static void read_store(sdl_parser *p, const sdl_tok *id, sdl_array *arr, long index, const sdl_value *v)
{
    if (arr) {
        sdl_array_set(p, arr, index, v, id->tk.loc);
        return;
    }
    /* new identifiers are global (POV-Ray adds them to the global table) */
    sdl_symtarget tg = sdl_symtab_target(p->sym, id->tk.text, (size_t)id->tk.len, 0);
    if (sdl_symtab_assign(p->sym, &tg, id->tk.text, (size_t)id->tk.len, v) == 0) sdl_error(p, id->tk.loc, PT_ERR_NOMEM, "out of memory");
}

void sdl_read_directive(sdl_parser *p, src_loc loc)
{
    (void)loc;
    sdl_tok fid;
    sdl_file *f = file_param(p, "read", &fid);
    if (!f) return;
    int at_end = 0;
    while (sdl_ok(p)) {
        sdl_accept(p, TOK_COMMA);
        if (sdl_accept(p, TOK_RPAREN)) break;
        p->hold_macros++;
        p->hold_arrays++;
        sdl_tok id = sdl_next(p);
        p->hold_arrays--;
        p->hold_macros--;
        sdl_val_kind k = id.val.kind;
        if (id.tk.kind != TOK_IDENT || !(k == VAL_NONE || k == VAL_FLOAT || k == VAL_VECTOR || k == VAL_COLOUR || k == VAL_STRING || k == VAL_ARRAY)) {
            sdl_unexpected(p, &id, "identifier to read into");
            return;
        }
        sdl_array *arr = NULL;
        long index = -1;
        if (k == VAL_ARRAY && id.val.ptr && sdl_is(sdl_peek(p), TOK_LBRACKET)) {
            arr = id.val.ptr;
            index = sdl_array_subscripts(p, arr, id.tk.loc);
            if (index < 0) return;
        } else if (k == VAL_ARRAY) {
            sdl_error(p, id.tk.loc, PT_ERR_SYNTAX, "#read into the array '%.*s' needs a subscript", id.tk.len, id.tk.text);
            return;
        }
        if (at_end) continue; /* after the end of the file the rest keep their values */
        sdl_value v;
        int ends = 0;
        if (!data_value(p, f, &v, &ends)) {
            if (!sdl_ok(p)) return;
            at_end = 1;
            continue;
        }
        read_store(p, &id, arr, index, &v);
        at_end = ends;
    }
    if (at_end && sdl_ok(p)) {
        /* the end of the file closes it and undefines its identifier */
        close_file(f);
        sdl_symtab_undef(p->sym, fid.tk.text, (size_t)fid.tk.len);
    }
}

/* ------------------------------------------------------------ #write */

/* Binary forms: bytes per term and range. */
static int binary_form(sdl_kw k, int *bytes, long *lo, long *hi, int *big)
{
    *big = 0;
    switch (k) {
    case KW_SINT8: *bytes = 1; *lo = -128; *hi = 127; return 1;
    case KW_UINT8: *bytes = 1; *lo = 0; *hi = 255; return 1;
    case KW_SINT16BE: *big = 1; /* fall through */
    case KW_SINT16LE: *bytes = 2; *lo = -32768; *hi = 32767; return 1;
    case KW_UINT16BE: *big = 1; /* fall through */
    case KW_UINT16LE: *bytes = 2; *lo = 0; *hi = 65535; return 1;
    case KW_SINT32BE: *big = 1; /* fall through */
    case KW_SINT32LE: *bytes = 4; *lo = -2147483647L - 1; *hi = 2147483647L; return 1;
    default: return 0;
    }
}

/* write_item := string | expression | binary_form expression */
static void write_item(sdl_parser *p, sdl_file *f)
{
    const sdl_tok *t = sdl_peek(p);
    int bytes, big;
    long lo, hi;
    if (t->tk.kind == TOK_KEYWORD && binary_form(t->tk.kw, &bytes, &lo, &hi, &big)) {
        sdl_next(p);
        sdl_value v;
        sdl_sum(p, &v);
        for (int i = 0; i < v.dim && sdl_ok(p); i++) {
            double x = v.v[i];
            long n = x <= (double)lo ? lo : (x >= (double)hi ? hi : (long)floor(x + 0.5));
            for (int b = 0; b < bytes; b++) fputc((int)((n >> (8 * (big ? bytes - 1 - b : b))) & 0xFF), f->out);
        }
        return;
    }
    if (sdl_starts_string(t)) {
        fputs(sdl_c_string(p, sdl_string(p)), f->out);
        return;
    }
    if (sdl_starts_expr(t)) {
        sdl_value v;
        sdl_sum(p, &v);
        if (!sdl_ok(p)) return;
        if (v.dim <= 1) {
            fprintf(f->out, "%g", v.v[0]);
            return;
        }
        fputc('<', f->out);
        for (int i = 0; i < v.dim; i++) fprintf(f->out, i ? ",%g" : "%g", v.v[i]);
        fputs("> ", f->out);
        return;
    }
    sdl_tok bad = sdl_next(p);
    sdl_unexpected(p, &bad, "string or expression to write");
}

void sdl_write_directive(sdl_parser *p, src_loc loc)
{
    (void)loc;
    sdl_tok fid;
    sdl_file *f = file_param(p, "write", &fid);
    if (!f) return;
    while (sdl_ok(p)) {
        sdl_accept(p, TOK_COMMA);
        if (sdl_accept(p, TOK_RPAREN)) break;
        write_item(p, f);
    }
    if (f->out && ferror(f->out)) sdl_error(p, loc, PT_ERR_IO, "writing file \"%s\" failed", f->name);
}
