/* ini.c - POV-Ray 3.7 INI files read into switches.
 *
 * The syntax follows POV-Ray 3.7's front end (source/frontend/
 * processoptions.cpp, ProcessOptions::ParseFile and Parse_INI_Option):
 *  - `Key = value`, keys case-insensitive, one option per line; a value is
 *    quoted ("..." or '...') or runs to a comment or the end of the line;
 *  - `;` and `#` start comments (partray also takes a line starting with
 *    `//`, which distribution files such as raddem.ini carry);
 *  - a line starting with `+` or `-` holds switches, as on the command line;
 *  - `[Label]` starts a section: options before the first section always
 *    apply; FILE.ini[Label] applies that section too, FILE.ini no other;
 *  - a line holding only a name is a scene (`.pov`), a library path
 *    (ending in `/`) or another INI file, read in its place.
 * The keys and what they set are POV-Ray 3.7's "Options" reference
 * (processrenderoptions.cpp RenderOptions_INI_Table). POV-Ray stops at an
 * unknown key; partray warns about it and goes on. Relative file names are
 * taken from the working directory, as POV-Ray does; Input_File_Name and an
 * included INI file that are not there are also looked for beside the INI
 * file that names them (so `partray render dir/anim.ini` works from
 * anywhere). */
#include "ini.h"
#include "grow.h"
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#define INI_MAX_DEPTH 16       /* INI files including INI files */
#define INI_MAX_FILE (1 << 20) /* bytes of one INI file */

struct ini_args {
    char **v;
    int n, cap;
};

typedef enum { K_INT, K_FLOAT, K_BOOL, K_STR, K_DECLARE, K_FTYPE, K_INPUT, K_IGNORED } key_kind;

/* A key and the switch it becomes. The kind says how: K_INT sw then the
 * value (%d), K_FLOAT sw then %.17g, K_BOOL +sw when true and -sw when
 * false, K_STR and K_INPUT sw then the text; K_FTYPE (+F) and K_DECLARE
 * (-D) check and rewrite the value. */
typedef struct {
    key_kind kind;
    const char *sw;
} ini_key;

typedef struct {
    const char *key, *sw;
} key_switch;

static const key_switch int_keys[] = {
    {"Width", "+W"}, {"Height", "+H"}, {"Antialias_Depth", "+R"}, {"Initial_Frame", "+KFI"}, {"Final_Frame", "+KFF"},
    {"Quality", "+Q"}, {"Work_Threads", "+WT"},
};
static const key_switch float_keys[] = {
    {"Antialias_Threshold", "--aa-threshold="}, {"Jitter_Amount", "+J"}, {"Clock", "+K"}, {"Initial_Clock", "+KI"},
    {"Final_Clock", "+KF"}, {"Subset_Start_Frame", "+SF"}, {"Subset_End_Frame", "+EF"}, {"Start_Column", "+SC"},
    {"End_Column", "+EC"}, {"Start_Row", "+SR"}, {"End_Row", "+ER"},
};
static const key_switch bool_keys[] = {
    {"Antialias", "A"}, {"Jitter", "J"}, {"Cyclic_Animation", "KC"}, {"Output_Alpha", "UA"},
};
static const key_switch str_keys[] = {{"Library_Path", "+L"}, {"Output_File_Name", "+O"}};
static const key_switch input_keys[] = {{"Input_File_Name", "+I"}};
static const key_switch ftype_keys[] = {{"Output_File_Type", "+F"}};
static const key_switch declare_keys[] = {{"Declare", "-D"}};

#define KEYS_OF(kind, t) {kind, t, sizeof t / sizeof t[0]}
static const struct {
    key_kind kind;
    const key_switch *keys;
    size_t n;
} key_tables[] = {
    KEYS_OF(K_INT, int_keys), KEYS_OF(K_FLOAT, float_keys), KEYS_OF(K_BOOL, bool_keys), KEYS_OF(K_STR, str_keys),
    KEYS_OF(K_INPUT, input_keys), KEYS_OF(K_FTYPE, ftype_keys), KEYS_OF(K_DECLARE, declare_keys),
};
#undef KEYS_OF

/* POV-Ray 3.7's other INI keys: accepted, warned about as not used. */
static const char *const pov_keys[] = {
    "All_Console", "All_File", "Antialias_Confidence", "Antialias_Gamma", "Append_File", "Bits_Per_Color",
    "Bits_Per_Colour", "Bounding", "Bounding_Method", "Bounding_Threshold", "BSP_BaseAccessCost",
    "BSP_ChildAccessCost", "BSP_ISectCost", "BSP_MaxDepth", "BSP_MissChance", "Buffer_Output", "Buffer_Size",
    "Clockless_Animation", "Compression", "Continue_Trace", "Create_Continue_Trace_Log", "Create_Histogram",
    "Create_Ini", "Debug_Console", "Debug_File", "Display", "Display_Gamma", "Dither", "Dither_Method",
    "Draw_Vistas", "Fatal_Console", "Fatal_Error_Command", "Fatal_Error_Return", "Fatal_File", "Field_Render",
    "File_Gamma", "Frame_Step", "Grayscale_Output", "Greyscale_Output", "High_Reproducibility", "Histogram_Name",
    "Histogram_Grid_Size", "Histogram_Type", "Include_Header", "Include_Ini",
    "Light_Buffer", "Max_Image_Buffer_Memory", "Odd_Field", "Output_To_File", "Palette",
    "Pause_When_Done", "Post_Frame_Command", "Post_Frame_Return", "Post_Scene_Command", "Post_Scene_Return",
    "Preview_End_Size", "Preview_Start_Size", "Pre_Frame_Command", "Pre_Frame_Return", "Pre_Scene_Command",
    "Pre_Scene_Return", "Radiosity_File_Name", "Radiosity_From_File", "Radiosity_To_File",
    "Radiosity_Vain_Pretrace", "Real_Time_Raytracing", "Remove_Bounds", "Render_Block_Size", "Render_Block_Step",
    "Render_Console", "Render_File", "Render_Pattern", "Sampling_Method", "Split_Unions", "Statistic_Console",
    "Statistic_File", "Stochastic_Seed", "Test_Abort_Count", "Test_Abort", "User_Abort_Command",
    "User_Abort_Return", "Verbose", "Version", "Video_Mode", "Vista_Buffer", "Warning_Console", "Warning_File",
    "Warning_Level",
};

static int key_is(const char *name, const char *k, size_t n)
{
    return strlen(name) == n && strncasecmp(name, k, n) == 0;
}

/* The key k (n bytes); 0 when partray does not know it. */
static int find_key(const char *k, size_t n, ini_key *out)
{
    for (size_t t = 0; t < sizeof key_tables / sizeof key_tables[0]; t++)
        for (size_t i = 0; i < key_tables[t].n; i++)
            if (key_is(key_tables[t].keys[i].key, k, n)) {
                *out = (ini_key){key_tables[t].kind, key_tables[t].keys[i].sw};
                return 1;
            }
    for (size_t i = 0; i < sizeof pov_keys / sizeof pov_keys[0]; i++)
        if (key_is(pov_keys[i], k, n)) {
            *out = (ini_key){K_IGNORED, NULL};
            return 1;
        }
    return 0;
}

ini_args *ini_args_new(void) { return calloc(1, sizeof(ini_args)); }

int ini_args_push(ini_args *a, const char *s)
{
    if (!a) return 0;
    /* room for s and the NULL after it */
    if (!grow_array_int((void **)&a->v, &a->cap, a->n + 2, sizeof *a->v)) return 0;
    char *c = strdup(s);
    if (!c) return 0;
    a->v[a->n++] = c;
    a->v[a->n] = NULL;
    return 1;
}

typedef struct {
    ini_args *a;
    diag *d;
    const char *file; /* interned */
    const char *dir;  /* the INI file's directory ("" for the command line) */
    int line;
    int depth;
} reader;

static pt_status read_file(ini_args *a, const char *spec, const char *near_dir, int depth, diag *d);

static void err_at(reader *r, int col, const char *fmt, const char *arg)
{
    diag_report(r->d, DIAG_ERROR, (src_loc){r->file, r->line, col}, NULL, fmt, arg);
}

static int exists(const char *p)
{
    return access(p, F_OK) == 0;
}

/* A relative name not found from the working directory, found beside the
 * INI file: that path (in buf); otherwise the name as given. */
static const char *beside(const reader *r, const char *name, char *buf, size_t n)
{
    if (name[0] == '/' || exists(name) || !r->dir[0]) return name;
    snprintf(buf, n, "%s/%s", r->dir, name);
    return exists(buf) ? buf : name;
}

static int parse_bool(const char *v, int *out)
{
    static const char *const t[] = {"on", "true", "yes", "1"}, *const f[] = {"off", "false", "no", "0"};
    for (int i = 0; i < 4; i++) {
        if (strcasecmp(v, t[i]) == 0) { *out = 1; return 1; }
        if (strcasecmp(v, f[i]) == 0) { *out = 0; return 1; }
    }
    return 0;
}

/* One option `key` = `val` (val starts at column vcol). */
static pt_status option(reader *r, const char *k, size_t kn, int kcol, const char *val, int vcol)
{
    ini_key keyv;
    const ini_key *key = find_key(k, kn, &keyv) ? &keyv : NULL;
    char name[64];
    snprintf(name, sizeof name, "%.*s", (int)(kn < 60 ? kn : 60), k);
    if (!key) {
        diag_report(r->d, DIAG_WARNING, (src_loc){r->file, r->line, kcol}, NULL, "unknown INI key '%s' ignored", name);
        return PT_OK;
    }
    if (key->kind == K_IGNORED) {
        diag_report(r->d, DIAG_WARNING, (src_loc){r->file, r->line, kcol}, NULL,
                    "INI option '%s' is not used by partray; ignored", name);
        return PT_OK;
    }
    char sw[4200], buf[4096];
    char *end;
    errno = 0;
    switch (key->kind) {
    case K_INT: {
        long v = strtol(val, &end, 10);
        if (!*val || *end || errno || v < -2147483647L || v > 2147483647L) {
            err_at(r, vcol, "'%s' wants an integer", name);
            return PT_ERR_USAGE;
        }
        snprintf(sw, sizeof sw, "%s%d", key->sw, (int)v);
        break;
    }
    case K_FLOAT: {
        double v = strtod(val, &end);
        if (!*val || *end || errno || !isfinite(v)) {
            err_at(r, vcol, "'%s' wants a number", name);
            return PT_ERR_USAGE;
        }
        snprintf(sw, sizeof sw, "%s%.17g", key->sw, v);
        break;
    }
    case K_BOOL: {
        int b;
        if (!parse_bool(val, &b)) {
            err_at(r, vcol, "'%s' wants on/off, true/false, yes/no or 1/0", name);
            return PT_ERR_USAGE;
        }
        snprintf(sw, sizeof sw, "%c%s", b ? '+' : '-', key->sw);
        break;
    }
    case K_STR:
    case K_INPUT:
        if (!*val) {
            err_at(r, vcol, "'%s' wants a value", name);
            return PT_ERR_USAGE;
        }
        snprintf(sw, sizeof sw, "%s%s", key->sw, key->kind == K_INPUT ? beside(r, val, buf, sizeof buf) : val);
        break;
    case K_FTYPE: {
        /* N png, E exr; POV-Ray's other types (T, C, P, J, B, H, S) are
         * not written by partray: PNG then, with a warning. */
        char t = (char)toupper((unsigned char)val[0]);
        if (t != 'N' && t != 'E') {
            if (!strchr("TCPJBHS", t) || !t) {
                err_at(r, vcol, "'%s' wants one of the letters N, E, T, C, P, J, B, H, S", name);
                return PT_ERR_USAGE;
            }
            diag_report(r->d, DIAG_WARNING, (src_loc){r->file, r->line, vcol}, NULL,
                        "Output_File_Type %c: partray writes PNG (N), OpenEXR (E) or PFM; PNG used", t);
            t = 'N';
        }
        snprintf(sw, sizeof sw, "%s%c", key->sw, t);
        break;
    }
    case K_DECLARE: {
        /* IDENTIFIER=FLOAT, or IDENTIFIER="string" (POV-Ray 3.7: a value
         * with a quote is the string between the first two quotes) */
        const char *eq = strchr(val, '=');
        if (!eq || eq == val) {
            err_at(r, vcol, "'%s' wants IDENTIFIER=VALUE", name);
            return PT_ERR_USAGE;
        }
        const char *q = strchr(eq + 1, '"');
        if (q) {
            const char *q2 = strchr(q + 1, '"');
            int len = q2 ? (int)(q2 - q - 1) : (int)strlen(q + 1);
            snprintf(sw, sizeof sw, "%s%.*s=\"%.*s\"", key->sw, (int)(eq - val), val, len, q + 1);
        } else {
            double v = strtod(eq + 1, &end);
            if (!eq[1] || *end || errno) {
                err_at(r, vcol + (int)(eq + 1 - val), "'%s' wants a number or a quoted string after '='", name);
                return PT_ERR_USAGE;
            }
            snprintf(sw, sizeof sw, "%s%.*s=%.17g", key->sw, (int)(eq - val), val, v);
        }
        break;
    }
    default:
        return PT_OK;
    }
    return ini_args_push(r->a, sw) ? PT_OK : PT_ERR_NOMEM;
}

/* A line holding a name only: a scene, a library path or an INI file. */
static pt_status plain_name(reader *r, const char *s, int col)
{
    size_t n = strlen(s);
    char sw[4200], buf[4096];
    const char *dot = strrchr(s, '.');
    if (dot && strcasecmp(dot, ".pov") == 0) {
        snprintf(sw, sizeof sw, "+I%s", beside(r, s, buf, sizeof buf));
        return ini_args_push(r->a, sw) ? PT_OK : PT_ERR_NOMEM;
    }
    if (n && s[n - 1] == '/') {
        snprintf(sw, sizeof sw, "+L%s", s);
        return ini_args_push(r->a, sw) ? PT_OK : PT_ERR_NOMEM;
    }
    if (r->depth + 1 >= INI_MAX_DEPTH) {
        err_at(r, col, "INI files include each other more than 16 deep at '%s'", s);
        return PT_ERR_USAGE;
    }
    pt_status st = read_file(r->a, s, r->dir, r->depth + 1, r->d);
    if (st == PT_ERR_IO) err_at(r, col, "cannot read the INI file '%s' named here", s);
    return st;
}

/* Reads a value from *p: quoted, or to a comment or the end of the line
 * (trailing blanks dropped). Returns 0 for an unterminated quote. */
static int read_value(const char **p, char *out, size_t n)
{
    const char *s = *p;
    size_t k = 0;
    if (*s == '"' || *s == '\'') {
        char q = *s++;
        while (*s && *s != q) {
            if (k + 1 < n) out[k++] = *s;
            s++;
        }
        out[k] = 0;
        if (*s != q) return 0;
        *p = s + 1;
        return 1;
    }
    while (*s && *s != ';' && *s != '#') {
        if (k + 1 < n) out[k++] = *s;
        s++;
    }
    while (k > 0 && (out[k - 1] == ' ' || out[k - 1] == '\t')) k--;
    out[k] = 0;
    *p = s;
    return 1;
}

/* One line (no newline). *active says whether options apply here (the part
 * before any section, or the section asked for). */
static pt_status read_line(reader *r, const char *line, const char *section, int *active)
{
    const char *p = line;
    while (*p == ' ' || *p == '\t') p++;
    int col = (int)(p - line) + 1;
    if (!*p || *p == ';' || *p == '#' || (p[0] == '/' && p[1] == '/')) return PT_OK;
    if (*p == '[') {
        const char *e = strchr(p, ']');
        if (!e) {
            err_at(r, col, "section label without its ']'%s", "");
            return PT_ERR_USAGE;
        }
        *active = section && (size_t)(e - p - 1) == strlen(section) && strncasecmp(p + 1, section, strlen(section)) == 0;
        return PT_OK;
    }
    if (!*active) return PT_OK;
    char val[4096];
    if (*p == '+' || *p == '-') {
        /* switches separated by blanks, up to a comment */
        while (*p && *p != ';' && *p != '#') {
            const char *s = p;
            while (*p && *p != ' ' && *p != '\t' && *p != ';' && *p != '#') p++;
            snprintf(val, sizeof val, "%.*s", (int)(p - s), s);
            if (val[0] == '+' || val[0] == '-') {
                if (!ini_args_push(r->a, val)) return PT_ERR_NOMEM;
            } else if (val[0]) {
                err_at(r, (int)(s - line) + 1, "'%s' is not a switch (a switch starts with + or -)", val);
                return PT_ERR_USAGE;
            }
            while (*p == ' ' || *p == '\t') p++;
        }
        return PT_OK;
    }
    if (isalnum((unsigned char)*p) || *p == '_' || *p == '"' || *p == '\'' || *p == '.' || *p == '/') {
        const char *k = p;
        while (isalnum((unsigned char)*p) || *p == '_') p++;
        size_t kn = (size_t)(p - k);
        const char *q = p;
        while (*q == ' ' || *q == '\t') q++;
        if (kn > 0 && *q == '=') {
            q++;
            while (*q == ' ' || *q == '\t') q++;
            int vcol = (int)(q - line) + 1;
            if (!read_value(&q, val, sizeof val)) {
                err_at(r, vcol, "unterminated quoted value%s", "");
                return PT_ERR_USAGE;
            }
            return option(r, k, kn, (int)(k - line) + 1, val, vcol);
        }
        /* a plain name */
        p = k;
        if (!read_value(&p, val, sizeof val)) {
            err_at(r, col, "unterminated quoted name%s", "");
            return PT_ERR_USAGE;
        }
        if (strchr(val, '=')) {
            err_at(r, col, "'%s' is not an INI option (KEY=VALUE)", val);
            return PT_ERR_USAGE;
        }
        return plain_name(r, val, col);
    }
    err_at(r, col, "cannot read this line as an INI option, a switch, a section or a file name%s", "");
    return PT_ERR_USAGE;
}

static pt_status read_text(reader *r, char *text, const char *section)
{
    int active = 1;
    char *p = text;
    r->line = 0;
    while (*p) {
        char *nl = p + strcspn(p, "\r\n");
        char c = *nl;
        *nl = 0;
        r->line++;
        pt_status st = read_line(r, p, section, &active);
        if (st != PT_OK) return st;
        if (!c) break;
        p = nl + 1;
        if (c == '\r' && *p == '\n') p++;
    }
    return PT_OK;
}

/* FILE.ini or FILE.ini[Label]; a relative FILE not found from the working
 * directory is looked for in near_dir. */
static pt_status read_file(ini_args *a, const char *spec, const char *near_dir, int depth, diag *d)
{
    char path[4096], section[256] = "", dir[4096];
    const char *br = strchr(spec, '[');
    size_t n = br ? (size_t)(br - spec) : strlen(spec);
    if (br) {
        const char *e = strchr(br, ']');
        if (!e || e[1]) {
            diag_error(d, "INI file '%s': a section is given as FILE.ini[Label]", spec);
            return PT_ERR_USAGE;
        }
        snprintf(section, sizeof section, "%.*s", (int)(e - br - 1), br + 1);
    }
    snprintf(path, sizeof path, "%.*s", (int)(n < 4000 ? n : 4000), spec);
    if (path[0] != '/' && !exists(path) && near_dir && near_dir[0]) {
        char alt[8200];
        snprintf(alt, sizeof alt, "%s/%s", near_dir, path);
        if (exists(alt) && strlen(alt) < sizeof path) memcpy(path, alt, strlen(alt) + 1);
    }
    FILE *f = fopen(path, "rb");
    if (!f) {
        diag_error(d, "cannot read INI file '%s': %s", path, strerror(errno));
        return PT_ERR_IO;
    }
    char *text = malloc(INI_MAX_FILE + 1);
    size_t len = text ? fread(text, 1, INI_MAX_FILE + 1, f) : 0;
    fclose(f);
    if (!text) return PT_ERR_NOMEM;
    if (len > INI_MAX_FILE) {
        free(text);
        diag_error(d, "INI file '%s' is larger than %d bytes", path, INI_MAX_FILE);
        return PT_ERR_USAGE;
    }
    text[len] = 0;
    if (memchr(text, 0, len)) {
        free(text);
        diag_error(d, "INI file '%s' is not a text file (it holds a NUL byte)", path);
        return PT_ERR_USAGE;
    }
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    if (slash) *slash = 0;
    else dir[0] = 0;
    reader r = {a, d, diag_intern(d, path), dir, 0, depth};
    pt_status st = read_text(&r, text, section[0] ? section : NULL);
    free(text);
    return st;
}

static int is_ini_name(const char *s)
{
    if (s[0] == '+' || s[0] == '-') return 0;
    const char *br = strchr(s, '[');
    size_t n = br ? (size_t)(br - s) : strlen(s);
    return n > 4 && strncasecmp(s + n - 4, ".ini", 4) == 0;
}

/* KEY=VALUE on the command line with KEY one of POV-Ray's INI keys. */
static int is_ini_option(const char *s)
{
    const char *eq = strchr(s, '=');
    if (!eq || s[0] == '+' || s[0] == '-') return 0;
    for (const char *p = s; p < eq; p++)
        if (!isalnum((unsigned char)*p) && *p != '_') return 0;
    ini_key key;
    return find_key(s, (size_t)(eq - s), &key);
}

pt_status ini_expand(int argc, char **argv, ini_args **out, diag *d)
{
    *out = NULL;
    ini_args *a = calloc(1, sizeof *a);
    if (!a) return PT_ERR_NOMEM;
    pt_status st = ini_args_push(a, "") ? PT_OK : PT_ERR_NOMEM; /* keeps v non-NULL; dropped below */
    a->n = 0;
    free(a->v[0]);
    a->v[0] = NULL;
    for (int i = 0; i < argc && st == PT_OK; i++) {
        const char *s = argv[i];
        int after_d = i > 0 && strcmp(argv[i - 1], "-D") == 0;
        if (!after_d && is_ini_name(s)) {
            st = read_file(a, s, NULL, 0, d);
        } else if (!after_d && is_ini_option(s)) {
            char *line = strdup(s);
            if (!line) { st = PT_ERR_NOMEM; break; }
            reader r = {a, d, diag_intern(d, "<command line>"), "", 0, 0};
            st = read_text(&r, line, NULL);
            free(line);
        } else if (!ini_args_push(a, s)) {
            st = PT_ERR_NOMEM;
        }
    }
    if (st != PT_OK) {
        ini_free(a);
        return st;
    }
    *out = a;
    return PT_OK;
}

int ini_argc(const ini_args *a)
{
    return a->n;
}

char **ini_argv(const ini_args *a)
{
    return a->v;
}

void ini_free(ini_args *a)
{
    if (!a) return;
    for (int i = 0; i < a->n; i++) free(a->v[i]);
    free(a->v);
    free(a);
}
