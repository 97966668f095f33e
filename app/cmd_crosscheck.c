/* cmd_crosscheck.c - `partray crosscheck SCENE.pov [--size WxH | +Wn +Hn]
 *     [+A[t] | -A] [+Rn] [--threads N | +WTn] [-D NAME=VALUE] [-L DIR]
 *     [--gi MODE] [--out DIR] [--json] [--povray PATH] [--quiet]
 *     [--converged [--cache DIR] [--converged-timeout SECONDS]]`
 *
 * Renders the scene with POV-Ray 3.7 and with partray (its default GI
 * choice unless --gi is given) at the same size (default 320x240, POV-Ray's)
 * and antialiasing (default off; +A0.3 +R3 as POV-Ray reads them), both
 * written as sRGB-encoded 8-bit PNGs (POV-Ray with File_Gamma=sRGB, which is
 * also what partray writes), and reports `partray compare`'s metrics on the
 * display values (LDR: RMSE, relMSE, PSNR, SSIM, LDR-FLIP, POV-Ray's image
 * as the reference), the mean absolute difference of the display values
 * (plain and after a 4x4 box downsample, which absorbs antialiasing and
 * area-light jitter), and the mean luminance (Rec.709 Y of the decoded
 * linear values) of both images with their ratio partray/POV-Ray. The ratio
 * is the figure to read when the scene has radiosity{}: POV-Ray's radiosity
 * is itself an approximation, so a per-pixel difference says little there.
 *
 * POV-Ray may only write in its working directory (Debian's povray.conf):
 * it runs in a temporary directory holding a copy of the scene, with the
 * scene's own directory (and every -L) on its library path; -D becomes
 * Declare=NAME=VALUE. With --out DIR the images (povray.png, partray.png),
 * the FLIP heat map (flip.png), partray's stats and both logs are kept in
 * DIR; otherwise they are removed. POV-Ray is `povray` on PATH, or
 * $PARTRAY_POVRAY, or --povray PATH.
 *
 * --converged adds POV-Ray's converged render of a radiosity scene (its
 * radiosity block at 4x the count and 0.4x the error_bound) as the
 * reference for both renders: LDR-FLIP and mean luminance of POV-Ray's
 * default render and of partray's against it, and partray's time over
 * POV-Ray's. It is cached (--cache DIR, default $XDG_CACHE_HOME or
 * ~/.cache, partray/crosscheck) under a key of the scene's text and the
 * options; a render that runs past --converged-timeout (default 1800 s) is
 * recorded as such and POV-Ray's default render stays the reference.
 *
 * Exit: 0 when both renders were made and compared (this reports; it does
 * not judge); 1 when either renderer failed on the scene; 2 usage; 3 when
 * POV-Ray is missing or a file cannot be read or written; 130 (143) after
 * Ctrl-C (SIGTERM), with the temporary files removed. */
#include "cmd_crosscheck.h"
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "cli.h"
#include "cmd_compare.h"
#include "diag.h"
#include "framebuffer.h"
#include "hash.h"
#include "img_io.h"
#include "img_metrics.h"
#include "scene.h"
#include "sdl.h"
#include "pipeline.h"
#include "stats_json.h"
#include "stats_read.h"
#include "subproc.h"

#define XC_MAX_LIST 64
#define XC_MAX_ARGS (2 * XC_MAX_LIST + 32)

static const char *usage =
    "usage: partray crosscheck SCENE.pov [--size WxH] [+A0.3 | -A] [+R3] [--threads N] [-D NAME=VALUE] [-L DIR]\n"
    "                          [--gi MODE] [--gi-quality Q] [--out DIR] [--json] [--povray PATH] [--quiet]\n"
    "                          [--converged [--cache DIR] [--converged-timeout SECONDS]]\n";

typedef struct {
    const char *scene, *out_dir, *povray, *gi, *cache_dir;
    const char *gi_quality; /* passed to partray render as --gi-quality (render checks it) */
    int converged;       /* also render POV-Ray's converged radiosity reference */
    double converged_timeout; /* seconds; past it the default render is the reference */
    int width, height;
    int aa;           /* 0 off, 1 on */
    double aa_threshold;
    int aa_depth;
    int threads;
    int json, quiet;
    const char *defines[XC_MAX_LIST];
    int ndefines;
    const char *libs[XC_MAX_LIST];
    int nlibs;
} xc_opts;

static int parse_int(const char *s, int *out)
{
    char *end;
    long v = strtol(s, &end, 10);
    if (end == s || *end || v < 0 || v > INT_MAX) return 0;
    *out = (int)v;
    return 1;
}

static int parse_args(int argc, char **argv, xc_opts *o)
{
    *o = (xc_opts){.width = 320, .height = 240, .aa_threshold = 0.3, .aa_depth = 3, .converged_timeout = 1800.0};
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i], *next = i + 1 < argc ? argv[i + 1] : NULL;
        int takes = strcmp(a, "--size") == 0 || strcmp(a, "--threads") == 0 || strcmp(a, "--out") == 0 ||
                    strcmp(a, "--povray") == 0 || strcmp(a, "--gi") == 0 || strcmp(a, "--gi-quality") == 0 || strcmp(a, "-L") == 0 ||
                    strcmp(a, "-D") == 0 || strcmp(a, "--cache") == 0 || strcmp(a, "--converged-timeout") == 0;
        if (takes && !next) {
            fprintf(stderr, "partray crosscheck: option '%s' needs a value\n", a);
            return 0;
        }
        char x;
        if (strcmp(a, "--size") == 0) {
            if (sscanf(next, "%d%c%d", &o->width, &x, &o->height) != 3 || (x != 'x' && x != 'X') || o->width <= 0 ||
                o->height <= 0 || o->width > 65536 || o->height > 65536) {
                fprintf(stderr, "partray crosscheck: --size wants WxH, got '%s'\n", next);
                return 0;
            }
            i++;
        } else if (strcmp(a, "--threads") == 0) {
            if (!parse_int(next, &o->threads)) {
                fprintf(stderr, "partray crosscheck: --threads wants a non-negative integer\n");
                return 0;
            }
            i++;
        } else if (strcmp(a, "--out") == 0) {
            o->out_dir = argv[++i];
        } else if (strcmp(a, "--povray") == 0) {
            o->povray = argv[++i];
        } else if (strcmp(a, "--gi") == 0) {
            o->gi = argv[++i];
        } else if (strcmp(a, "--gi-quality") == 0) {
            char *end;
            double q = strtod(next, &end);
            if (*end || !(q > 0.0) || !isfinite(q)) {
                fprintf(stderr, "partray crosscheck: --gi-quality wants a number > 0\n");
                return 0;
            }
            o->gi_quality = argv[++i];
        } else if (strcmp(a, "--converged") == 0) {
            o->converged = 1;
        } else if (strcmp(a, "--cache") == 0) {
            o->cache_dir = argv[++i];
        } else if (strcmp(a, "--converged-timeout") == 0) {
            char *end;
            o->converged_timeout = strtod(next, &end);
            if (*end || !(o->converged_timeout > 0)) {
                fprintf(stderr, "partray crosscheck: --converged-timeout wants seconds > 0\n");
                return 0;
            }
            i++;
        } else if (strcmp(a, "--json") == 0) {
            o->json = 1;
        } else if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) {
            o->quiet = 1;
        } else if ((strcmp(a, "-D") == 0 || (strncmp(a, "-D", 2) == 0 && a[2])) && o->ndefines < XC_MAX_LIST) {
            const char *v = a[2] ? a + 2 : argv[++i];
            if (!strchr(v, '=')) {
                fprintf(stderr, "partray crosscheck: -D wants NAME=VALUE, got '%s'\n", v);
                return 0;
            }
            o->defines[o->ndefines++] = v;
        } else if ((strcmp(a, "-L") == 0 || (strncmp(a, "-L", 2) == 0 && a[2])) && o->nlibs < XC_MAX_LIST) {
            o->libs[o->nlibs++] = a[2] ? a + 2 : argv[++i];
        } else if ((a[0] == '+' || a[0] == '-') && (a[1] == 'A' || a[1] == 'a')) {
            o->aa = a[0] == '+';
            if (a[2]) {
                char *end;
                o->aa_threshold = strtod(a + 2, &end);
                if (*end || !(o->aa_threshold >= 0)) {
                    fprintf(stderr, "partray crosscheck: bad option '%s'\n", a);
                    return 0;
                }
            }
        } else if (a[0] == '+' && (a[1] == 'R' || a[1] == 'r')) {
            if (!parse_int(a + 2, &o->aa_depth) || o->aa_depth < 1 || o->aa_depth > 9) {
                fprintf(stderr, "partray crosscheck: bad option '%s'\n", a);
                return 0;
            }
        } else if (a[0] == '+' && (a[1] == 'W' || a[1] == 'w') && (a[2] == 'T' || a[2] == 't')) {
            if (!parse_int(a + 3, &o->threads)) {
                fprintf(stderr, "partray crosscheck: bad option '%s'\n", a);
                return 0;
            }
        } else if (a[0] == '+' && (a[1] == 'W' || a[1] == 'w' || a[1] == 'H' || a[1] == 'h')) {
            int v;
            if (!parse_int(a + 2, &v) || v < 1 || v > 65536) {
                fprintf(stderr, "partray crosscheck: bad option '%s'\n", a);
                return 0;
            }
            if (a[1] == 'W' || a[1] == 'w') o->width = v;
            else o->height = v;
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "partray crosscheck: unknown option '%s'\n", a);
            return 0;
        } else if (!o->scene) {
            o->scene = a;
        } else {
            fprintf(stderr, "partray crosscheck: unexpected argument '%s'\n", a);
            return 0;
        }
    }
    if (!o->scene) {
        fprintf(stderr, "partray crosscheck: no scene file given\n");
        return 0;
    }
    return 1;
}

static int copy_file(const char *src, const char *dst)
{
    size_t n = 0;
    char *text = subproc_read_text(src, &n);
    if (!text) return 0;
    FILE *f = fopen(dst, "wb");
    int ok = f && fwrite(text, 1, n, f) == n;
    if (f) ok = (fclose(f) == 0) && ok;
    free(text);
    return ok;
}

static void print_log_tail(const char *path, const char *who)
{
    char *text = subproc_read_text(path, NULL);
    if (!text) return;
    size_t n = strlen(text);
    fprintf(stderr, "--- %s log (%s), last lines ---\n%s\n", who, path, n > 3000 ? text + n - 3000 : text);
    free(text);
}

/* Mean |a - b| over all values, and after a 4x4 box downsample (-1 when the
 * image is smaller than 4x4). */
static void mean_abs_diff(const framebuffer *a, const framebuffer *b, double *plain, double *down)
{
    size_t n = (size_t)a->width * (size_t)a->height * 3u;
    double s = 0.0;
    for (size_t i = 0; i < n; i++) s += fabs((double)a->rgb[i] - (double)b->rgb[i]);
    *plain = n ? s / (double)n : 0.0;
    int w = a->width / 4, h = a->height / 4;
    if (w < 1 || h < 1) {
        *down = -1.0;
        return;
    }
    s = 0.0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 3; c++) {
                double sa = 0.0, sb = 0.0;
                for (int j = 0; j < 4; j++)
                    for (int i = 0; i < 4; i++) {
                        size_t k = ((size_t)(y * 4 + j) * (size_t)a->width + (size_t)(x * 4 + i)) * 3u + (size_t)c;
                        sa += a->rgb[k];
                        sb += b->rgb[k];
                    }
                s += fabs(sa - sb) / 16.0;
            }
    *down = s / (3.0 * w * h);
}

/* Absolute path of `p` (relative to the current directory). */
static void absolute(const char *p, char *buf, size_t n)
{
    if (p[0] == '/') {
        snprintf(buf, n, "%s", p);
        return;
    }
    char cwd[4096];
    if (!getcwd(cwd, sizeof cwd)) cwd[0] = 0;
    snprintf(buf, n, "%s/%s", cwd, p);
}

/* Runs POV-Ray on `input` (a file in `work`) at the options' size,
 * antialiasing, threads, library paths and declarations, writing the sRGB PNG
 * `out_name` in `work`. timeout > 0 runs it under coreutils' timeout(1)
 * (exit 124 when it ran out). Returns subproc_run's status. */
static int run_povray(const xc_opts *o, const char *povray, const char *work, const char *input, const char *out_name,
                      const char *scene_dir, const char *log, double timeout, double *secs, diag *d)
{
    char(*args)[4200] = malloc(XC_MAX_ARGS * sizeof *args);
    if (!args) return -1;
    const char *argvv[XC_MAX_ARGS + 1];
    int n = 0;
    if (timeout > 0) {
        snprintf(args[n++], sizeof args[0], "timeout");
        snprintf(args[n++], sizeof args[0], "%.0f", timeout);
    }
    snprintf(args[n++], sizeof args[0], "%s", povray);
    snprintf(args[n++], sizeof args[0], "+I%s", input);
    snprintf(args[n++], sizeof args[0], "+O%s", out_name);
    snprintf(args[n++], sizeof args[0], "+W%d", o->width);
    snprintf(args[n++], sizeof args[0], "+H%d", o->height);
    if (o->aa) {
        snprintf(args[n++], sizeof args[0], "+A%g", o->aa_threshold);
        snprintf(args[n++], sizeof args[0], "+R%d", o->aa_depth);
    } else {
        snprintf(args[n++], sizeof args[0], "-A");
    }
    snprintf(args[n++], sizeof args[0], "-D");
    snprintf(args[n++], sizeof args[0], "-V");
    snprintf(args[n++], sizeof args[0], "-P");
    snprintf(args[n++], sizeof args[0], "+FN");
    snprintf(args[n++], sizeof args[0], "-UA");
    snprintf(args[n++], sizeof args[0], "File_Gamma=sRGB");
    if (o->threads > 0) snprintf(args[n++], sizeof args[0], "+WT%d", o->threads);
    snprintf(args[n++], sizeof args[0], "+L%s", scene_dir);
    for (int i = 0; i < o->nlibs; i++) {
        char lib[4096];
        absolute(o->libs[i], lib, sizeof lib);
        snprintf(args[n++], sizeof args[0], "+L%s", lib);
    }
    for (int i = 0; i < o->ndefines; i++) snprintf(args[n++], sizeof args[0], "Declare=%s", o->defines[i]);
    for (int i = 0; i < n; i++) argvv[i] = args[i];
    argvv[n] = NULL;
    int prc = subproc_run(argvv, work, log, secs, d);
    free(args);
    return prc;
}

/* The converged reference: POV-Ray with the scene's radiosity at
 * XC_CONVERGED_COUNT times its count and XC_CONVERGED_BOUND times its
 * error_bound. POV-Ray merges a later radiosity{} block into the settings
 * already made (a second block that sets only count keeps the first block's
 * error_bound; checked with povray 3.7.0.10's sample statistics), so the
 * scene is rendered with one global_settings block appended, whatever macros
 * set the original values. */
#define XC_CONVERGED_COUNT 4
#define XC_CONVERGED_BOUND 0.4
typedef struct {
    int made;             /* a converged image exists (else the default render is the reference) */
    int cached;           /* taken from the cache */
    int timed_out;        /* the render ran past --converged-timeout (now or on an earlier run) */
    double seconds;       /* its render time (from the cache's record when cached) */
    int count;
    double error_bound;
    char png[8400];
} xc_converged;

static uint64_t fnv1a_str(uint64_t h, const char *s)
{
    return pt_fnv1a(h, s, strlen(s) + 1);
}

/* Renders (or finds in the cache) the converged reference into c->png. The
 * cache key covers the scene's text, the POV-Ray binary's path, size,
 * antialiasing, library paths and declarations, not the scene's include
 * files. Returns 0, or an exit status for the command. */
static int converged_reference(const xc_opts *o, const char *povray, const char *work, const char *base,
                               const char *scene_dir, const char *out, int count, double error_bound,
                               xc_converged *c, diag *d)
{
    c->count = count * XC_CONVERGED_COUNT;
    c->error_bound = error_bound * XC_CONVERGED_BOUND;
    char cache[4096];
    const char *env = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
    if (o->cache_dir) snprintf(cache, sizeof cache, "%s", o->cache_dir);
    else if (env && *env) snprintf(cache, sizeof cache, "%s/partray/crosscheck", env);
    else snprintf(cache, sizeof cache, "%s/.cache/partray/crosscheck", home && *home ? home : "/tmp");
    if (!subproc_mkdirs(cache)) {
        fprintf(stderr, "partray crosscheck: cannot create cache directory '%s'\n", cache);
        return 3;
    }
    size_t len = 0;
    char *text = subproc_read_text(o->scene, &len);
    if (!text) {
        fprintf(stderr, "partray crosscheck: cannot read scene '%s'\n", o->scene);
        return 3;
    }
    uint64_t h = pt_fnv1a(PT_FNV1A_BASIS, text, len);
    char num[256];
    snprintf(num, sizeof num, "converged/%d/%g|%dx%d|aa %d %g %d", XC_CONVERGED_COUNT, XC_CONVERGED_BOUND, o->width,
             o->height, o->aa, o->aa_threshold, o->aa_depth);
    h = fnv1a_str(h, num);
    h = fnv1a_str(h, povray);
    for (int i = 0; i < o->nlibs; i++) h = fnv1a_str(h, o->libs[i]);
    for (int i = 0; i < o->ndefines; i++) h = fnv1a_str(h, o->defines[i]);
    char stem[1024];
    snprintf(stem, sizeof stem, "%s", base);
    char *dot = strrchr(stem, '.');
    if (dot && dot != stem) *dot = 0;
    char key[8192], record[8400], timeout_mark[8400];
    snprintf(key, sizeof key, "%s/%s-%016llx", cache, stem, (unsigned long long)h);
    snprintf(c->png, sizeof c->png, "%s.png", key);
    snprintf(record, sizeof record, "%s.txt", key);
    snprintf(timeout_mark, sizeof timeout_mark, "%s.timeout", key);
    if (access(c->png, R_OK) == 0) {
        char *r = subproc_read_text(record, NULL);
        if (r) c->seconds = strtod(r, NULL);
        free(r);
        free(text);
        c->made = c->cached = 1;
        return 0;
    }
    if (access(timeout_mark, R_OK) == 0) {
        char *r = subproc_read_text(timeout_mark, NULL);
        double limit = r ? strtod(r, NULL) : 0.0;
        free(r);
        if (limit >= o->converged_timeout) {
            free(text);
            c->timed_out = 1;
            return 0;
        }
    }
    /* The scene with the converged settings appended, beside the copy. */
    char input[1200], path[4300], made_name[1200], made[4300], log[4300];
    snprintf(input, sizeof input, "%s_converged.pov", stem);
    snprintf(path, sizeof path, "%s/%s", work, input);
    snprintf(made_name, sizeof made_name, "%s_converged.png", stem);
    snprintf(made, sizeof made, "%s/%s", work, made_name);
    snprintf(log, sizeof log, "%s/povray_converged.log", out);
    FILE *f = fopen(path, "wb");
    int ok = f && fwrite(text, 1, len, f) == len &&
             fprintf(f, "\nglobal_settings { radiosity { count %d error_bound %.9g } }\n", c->count, c->error_bound) > 0;
    if (f) ok = (fclose(f) == 0) && ok;
    free(text);
    if (!ok) {
        fprintf(stderr, "partray crosscheck: cannot write %s\n", path);
        remove(path);
        return 3;
    }
    remove(log);
    if (!o->quiet)
        fprintf(stderr, "partray crosscheck: POV-Ray's converged render (count %d, error_bound %g; at most %.0f s)...\n",
                c->count, c->error_bound, o->converged_timeout);
    int prc = run_povray(o, povray, work, input, made_name, scene_dir, log, o->converged_timeout, &c->seconds, d);
    if (!o->quiet && prc == 0) fprintf(stderr, "partray crosscheck: converged render done in %.1f s\n", c->seconds);
    remove(path);
    if (prc == 124) {
        remove(made);
        FILE *m = fopen(timeout_mark, "wb");
        if (m) {
            fprintf(m, "%.0f\n", o->converged_timeout);
            fclose(m);
        }
        c->timed_out = 1;
        return 0;
    }
    if (prc != 0 || access(made, R_OK) != 0) {
        fprintf(stderr, "partray crosscheck: POV-Ray's converged render failed on %s (exit %d)\n", o->scene, prc);
        print_log_tail(log, "POV-Ray converged");
        remove(made);
        return prc < 0 ? 3 : 1;
    }
    /* Into the cache under a temporary name, then renamed (atomic). */
    char tmp[8500];
    snprintf(tmp, sizeof tmp, "%s.tmp%d", c->png, (int)getpid());
    if (!copy_file(made, tmp) || rename(tmp, c->png) != 0) {
        remove(tmp);
        remove(made);
        fprintf(stderr, "partray crosscheck: cannot write %s\n", c->png);
        return 3;
    }
    remove(made);
    FILE *r = fopen(record, "wb");
    if (r) {
        fprintf(r, "%.6f seconds, count %d, error_bound %.9g\n", c->seconds, c->count, c->error_bound);
        fclose(r);
    }
    c->made = 1;
    return 0;
}

/* Ctrl-C / SIGTERM stop the running renderer (same process group); the
 * command then cleans up its temporary directory and exits 130 / 143. */
static volatile sig_atomic_t g_stop = 0;
static void on_stop(int sig)
{
    g_stop = sig;
    subproc_forward_signal(sig);
}

int cmd_crosscheck(int argc, char **argv)
{
    xc_opts o;
    if (cli_wants_help(argc, argv)) {
        fputs(usage, stdout);
        fputs("Renders SCENE.pov with partray and with POV-Ray 3.7 at the same size and\n"
              "antialiasing, and compares the two (docs/measuring.md).\n", stdout);
        fputs(cli_exit_codes, stdout);
        return CLI_EXIT_OK;
    }
    if (!parse_args(argc, argv, &o)) {
        fputs(usage, stderr);
        return 2;
    }
    if (access(o.scene, R_OK) != 0) {
        fprintf(stderr, "partray crosscheck: cannot read scene '%s'\n", o.scene);
        return 3;
    }
    char povray[4096];
    const char *pv = o.povray ? o.povray : getenv("PARTRAY_POVRAY");
    if (!subproc_find_program(pv && *pv ? pv : "povray", povray, sizeof povray)) {
        fprintf(stderr, "partray crosscheck: POV-Ray not found (%s); install Debian's povray or pass --povray PATH\n",
                pv && *pv ? pv : "povray on PATH");
        return 3;
    }
    char self[4096];
    if (!subproc_self_exe(self, sizeof self)) {
        fprintf(stderr, "partray crosscheck: cannot find the partray binary (/proc/self/exe)\n");
        return 3;
    }

    /* Does the scene use radiosity? (partray's parser; errors stop here.) */
    diag *d = diag_new();
    sdl_options so;
    pipeline_sdl_options(&so, NULL, o.width, o.height); /* as render parses (pipeline.h) */
    so.lib_paths = o.libs;
    so.nlib_paths = o.nlibs;
    so.defines = o.defines;
    so.ndefines = o.ndefines;
    scene *sc = NULL;
    pt_status st = pipeline_parse(o.scene, &so, &sc, d, NULL);
    if (st != PT_OK) {
        cli_print_diags(d, 0, 0);
        diag_free(d);
        return st == PT_ERR_IO ? 3 : (st == PT_ERR_USAGE ? 2 : 1);
    }
    int radiosity = sc->global.radiosity.enabled != 0;
    int rad_count = sc->global.radiosity.count;
    double rad_error_bound = sc->global.radiosity.error_bound;
    scene_free(sc);

    /* Directories: POV-Ray's working one, and where the results go. */
    char work[] = "/tmp/partray-crosscheck-XXXXXX";
    if (!mkdtemp(work)) {
        fprintf(stderr, "partray crosscheck: cannot create a temporary directory\n");
        diag_free(d);
        return 3;
    }
    char out[4096];
    if (o.out_dir) {
        if (!subproc_mkdirs(o.out_dir)) {
            fprintf(stderr, "partray crosscheck: cannot create directory '%s'\n", o.out_dir);
            diag_free(d);
            return 3;
        }
        absolute(o.out_dir, out, sizeof out);
    } else {
        snprintf(out, sizeof out, "%s", work);
    }
    char scene_abs[4096], scene_dir[4096], base[1024], stem[1024];
    absolute(o.scene, scene_abs, sizeof scene_abs);
    snprintf(scene_dir, sizeof scene_dir, "%s", scene_abs);
    char *slash = strrchr(scene_dir, '/');
    snprintf(base, sizeof base, "%s", slash + 1);
    *slash = 0;
    if (!scene_dir[0]) snprintf(scene_dir, sizeof scene_dir, "/");
    snprintf(stem, sizeof stem, "%s", base);
    char *dot = strrchr(stem, '.');
    if (dot && dot != stem) *dot = 0;

    char copy[4200], pov_out[1100], pov_png[4200], pov_log[4200], pt_png[4200], pt_log[4200], pt_json[4200],
        flip_png[4200];
    snprintf(copy, sizeof copy, "%s/%s", work, base);
    snprintf(pov_out, sizeof pov_out, "%s_pov.png", stem);
    snprintf(pov_png, sizeof pov_png, "%s/povray.png", out);
    snprintf(pov_log, sizeof pov_log, "%s/povray.log", out);
    snprintf(pt_png, sizeof pt_png, "%s/partray.png", out);
    snprintf(pt_log, sizeof pt_log, "%s/partray.log", out);
    snprintf(pt_json, sizeof pt_json, "%s/partray.json", out);
    snprintf(flip_png, sizeof flip_png, "%s/flip.png", out);
    int rc = 0;
    char(*xc_args)[4200] = malloc(XC_MAX_ARGS * sizeof *xc_args);
    framebuffer *a = NULL, *b = NULL, *map = NULL, *ref = NULL;
    double t_pov = 0, t_pt = 0;
    char gi_used[64] = "?";
    xc_converged conv;
    memset(&conv, 0, sizeof conv);
    if (!xc_args) {
        rc = 1;
        goto done;
    }
    if (!copy_file(o.scene, copy)) {
        fprintf(stderr, "partray crosscheck: cannot copy the scene into %s\n", work);
        rc = 3;
        goto done;
    }
    remove(pov_log);
    remove(pt_log);
    signal(SIGINT, on_stop);
    signal(SIGTERM, on_stop);

    /* POV-Ray at the scene's own settings (the default render). Each child
     * writes to its log; a line before and after each says what runs. */
    {
        if (!o.quiet) fprintf(stderr, "partray crosscheck: POV-Ray rendering %s at %dx%d...\n", o.scene, o.width, o.height);
        int prc = run_povray(&o, povray, work, base, pov_out, scene_dir, pov_log, 0.0, &t_pov, d);
        if (!o.quiet && prc == 0) fprintf(stderr, "partray crosscheck: POV-Ray done in %.1f s\n", t_pov);
        char made[4300];
        snprintf(made, sizeof made, "%s/%s", work, pov_out);
        if (prc != 0 || access(made, R_OK) != 0) {
            cli_print_diags(d, 0, 0);
            fprintf(stderr, "partray crosscheck: POV-Ray failed on %s (exit %d)\n", o.scene, prc);
            print_log_tail(pov_log, "POV-Ray");
            rc = prc < 0 ? 3 : 1;
            goto done;
        }
        if (strcmp(made, pov_png) != 0 && rename(made, pov_png) != 0 && !copy_file(made, pov_png)) {
            fprintf(stderr, "partray crosscheck: cannot write %s\n", pov_png);
            rc = 3;
            goto done;
        }
    }

    /* POV-Ray's converged radiosity reference (cached). */
    if (o.converged && radiosity) {
        int crc = converged_reference(&o, povray, work, base, scene_dir, out, rad_count, rad_error_bound, &conv, d);
        if (crc != 0) {
            cli_print_diags(d, 0, 0);
            rc = crc;
            goto done;
        }
    }

    /* partray. */
    {
        char(*args)[4200] = xc_args;
        const char *argvv[XC_MAX_ARGS + 1];
        int n = 0;
        snprintf(args[n++], sizeof args[0], "%s", self);
        snprintf(args[n++], sizeof args[0], "render");
        snprintf(args[n++], sizeof args[0], "%s", o.scene);
        snprintf(args[n++], sizeof args[0], "-o");
        snprintf(args[n++], sizeof args[0], "%s", pt_png);
        snprintf(args[n++], sizeof args[0], "--size");
        snprintf(args[n++], sizeof args[0], "%dx%d", o.width, o.height);
        if (o.aa) {
            snprintf(args[n++], sizeof args[0], "+A%g", o.aa_threshold);
            snprintf(args[n++], sizeof args[0], "+R%d", o.aa_depth);
        }
        if (o.threads > 0) {
            snprintf(args[n++], sizeof args[0], "--threads");
            snprintf(args[n++], sizeof args[0], "%d", o.threads);
        }
        if (o.gi) {
            snprintf(args[n++], sizeof args[0], "--gi");
            snprintf(args[n++], sizeof args[0], "%s", o.gi);
        }
        if (o.gi_quality) {
            snprintf(args[n++], sizeof args[0], "--gi-quality");
            snprintf(args[n++], sizeof args[0], "%s", o.gi_quality);
        }
        for (int i = 0; i < o.nlibs; i++) snprintf(args[n++], sizeof args[0], "-L%s", o.libs[i]);
        for (int i = 0; i < o.ndefines; i++) snprintf(args[n++], sizeof args[0], "-D%s", o.defines[i]);
        snprintf(args[n++], sizeof args[0], "--stats");
        snprintf(args[n++], sizeof args[0], "%s", pt_json);
        for (int i = 0; i < n; i++) argvv[i] = args[i];
        argvv[n] = NULL;
        if (!o.quiet) fprintf(stderr, "partray crosscheck: partray rendering %s at %dx%d...\n", o.scene, o.width, o.height);
        int prc = subproc_run(argvv, NULL, pt_log, &t_pt, d);
        if (!o.quiet && prc == 0) fprintf(stderr, "partray crosscheck: partray done in %.1f s\n", t_pt);
        if (prc != 0) {
            cli_print_diags(d, 0, 0);
            fprintf(stderr, "partray crosscheck: partray render failed (exit %d)\n", prc);
            print_log_tail(pt_log, "partray");
            rc = prc < 0 ? 3 : prc;
            goto done;
        }
        char *js = subproc_read_text(pt_json, NULL);
        if (js) stats_read_str(js, "gi", gi_used, sizeof gi_used);
        free(js);
    }

    /* Compare. */
    img_compare_result r;
    memset(&r, 0, sizeof r);
    st = img_read(pov_png, 1, &a, d);
    if (st == PT_OK) st = img_read(pt_png, 1, &b, d);
    if (st == PT_OK && (a->width != b->width || a->height != b->height)) {
        fprintf(stderr, "partray crosscheck: sizes differ: POV-Ray %dx%d, partray %dx%d\n", a->width, a->height, b->width,
                b->height);
        rc = 1;
        goto done;
    }
    if (st == PT_OK) st = img_compare(a, b, 0, &r, o.out_dir ? &map : NULL, d);
    if (st == PT_OK && map) st = img_write(flip_png, map, NULL, d);
    if (st != PT_OK) {
        cli_print_diags(d, 0, 0);
        rc = st == PT_ERR_IO ? 3 : 1;
        goto done;
    }
    double mad = 0, mad4 = 0;
    mean_abs_diff(a, b, &mad, &mad4);
    double lum_pov = img_mean_luminance(a, 1), lum_pt = img_mean_luminance(b, 1);
    double ratio = lum_pov > 0 ? lum_pt / lum_pov : (lum_pt > 0 ? INFINITY : 1.0);
    /* Against the converged reference: both renders' error, luminance and time. */
    img_compare_result rc_pov, rc_pt;
    memset(&rc_pov, 0, sizeof rc_pov);
    memset(&rc_pt, 0, sizeof rc_pt);
    double lum_ref = 0;
    if (conv.made) {
        st = img_read(conv.png, 1, &ref, d);
        if (st == PT_OK && (ref->width != a->width || ref->height != a->height)) {
            fprintf(stderr, "partray crosscheck: the cached reference %s has another size\n", conv.png);
            rc = 1;
            goto done;
        }
        if (st == PT_OK) st = img_compare(ref, a, 0, &rc_pov, NULL, d);
        if (st == PT_OK) st = img_compare(ref, b, 0, &rc_pt, NULL, d);
        if (st != PT_OK) {
            cli_print_diags(d, 0, 0);
            rc = st == PT_ERR_IO ? 3 : 1;
            goto done;
        }
        lum_ref = img_mean_luminance(ref, 1);
    }
    if (!o.quiet) cli_print_diags(d, 0, 0);
    if (o.json) {
        stats_json js;
        stats_begin(&js);
        stats_str(&js, "scene", o.scene);
        stats_int(&js, "width", a->width);
        stats_int(&js, "height", a->height);
        stats_int(&js, "antialias", o.aa);
        stats_num(&js, "aa_threshold", o.aa ? o.aa_threshold : 0.0);
        stats_int(&js, "radiosity", radiosity);
        stats_obj_begin(&js, "povray");
        stats_num(&js, "seconds", t_pov);
        if (o.out_dir) stats_str(&js, "image", pov_png);
        stats_obj_end(&js);
        stats_obj_begin(&js, "partray");
        stats_num(&js, "seconds", t_pt);
        stats_str(&js, "gi", gi_used);
        if (o.out_dir) stats_str(&js, "image", pt_png);
        stats_obj_end(&js);
        cmd_compare_metrics_json(&js, &r, 0);
        stats_num(&js, "mean_abs_diff", mad);
        stats_num(&js, "mean_abs_diff_4x4", mad4);
        stats_obj_begin(&js, "luminance");
        stats_num(&js, "povray", lum_pov);
        stats_num(&js, "partray", lum_pt);
        stats_num(&js, "ratio", ratio);
        stats_obj_end(&js);
        if (o.converged && radiosity) {
            stats_obj_begin(&js, "converged");
            stats_int(&js, "made", conv.made);
            stats_int(&js, "cached", conv.cached);
            stats_int(&js, "timed_out", conv.timed_out);
            stats_num(&js, "seconds", conv.seconds);
            stats_int(&js, "count", conv.count);
            stats_num(&js, "error_bound", conv.error_bound);
            if (conv.made) {
                stats_str(&js, "image", conv.png);
                stats_num(&js, "luminance", lum_ref);
                stats_num(&js, "povray_flip", rc_pov.flip_mean);
                stats_num(&js, "partray_flip", rc_pt.flip_mean);
                stats_num(&js, "povray_luminance_ratio", lum_ref > 0 ? lum_pov / lum_ref : 1.0);
                stats_num(&js, "partray_luminance_ratio", lum_ref > 0 ? lum_pt / lum_ref : 1.0);
            }
            stats_obj_end(&js);
        }
        fputs(stats_end(&js), stdout);
        stats_free(&js);
    } else {
        printf("scene       %s (%s)\n", o.scene, radiosity ? "radiosity{}: POV-Ray's and partray's GI are both approximate; read the luminance ratio" : "no radiosity");
        if (o.aa)
            printf("size        %dx%d, antialias +A%g +R%d\n", a->width, a->height, o.aa_threshold, o.aa_depth);
        else
            printf("size        %dx%d, antialias off\n", a->width, a->height);
        printf("povray      %.3f s%s%s\n", t_pov, o.out_dir ? ", " : "", o.out_dir ? pov_png : "");
        printf("partray     %.3f s, gi %s%s%s\n", t_pt, gi_used, o.out_dir ? ", " : "", o.out_dir ? pt_png : "");
        printf("(POV-Ray's image is the reference; sRGB-encoded values, LDR-FLIP)\n");
        printf("RMSE        %.6f\n", r.rmse);
        printf("relMSE      %.6f\n", r.relmse);
        printf("PSNR        %.3f dB\n", r.psnr);
        printf("SSIM        %.6f\n", r.ssim);
        printf("FLIP        mean %.6f, weighted median %.6f\n", r.flip_mean, r.flip_wmedian);
        printf("mean |diff| %.6f (after 4x4 downsample %.6f)\n", mad, mad4);
        printf("luminance   povray %.6f, partray %.6f, ratio partray/povray %.4f\n", lum_pov, lum_pt, ratio);
        if (o.out_dir) printf("heat map    %s\n", flip_png);
        if (o.converged && radiosity && conv.made) {
            printf("converged   POV-Ray at count %d, error_bound %g: %.3f s%s, %s\n", conv.count, conv.error_bound,
                   conv.seconds, conv.cached ? " (cached)" : "", conv.png);
            printf("  against it  LDR-FLIP povray %.6f, partray %.6f; luminance ratio povray %.4f, partray %.4f\n",
                   rc_pov.flip_mean, rc_pt.flip_mean, lum_ref > 0 ? lum_pov / lum_ref : 1.0,
                   lum_ref > 0 ? lum_pt / lum_ref : 1.0);
            printf("  time ratio  partray/povray %.3f\n", t_pov > 0 ? t_pt / t_pov : 0.0);
        } else if (o.converged && radiosity) {
            printf("converged   not made: POV-Ray's converged render ran past %.0f s; POV-Ray's default render is the reference\n",
                   o.converged_timeout);
        } else if (o.converged) {
            printf("converged   no radiosity{}: POV-Ray's default render is the reference\n");
        }
    }

done:
    free(xc_args);
    fb_free(a);
    fb_free(b);
    fb_free(map);
    fb_free(ref);
    diag_free(d);
    /* POV-Ray's working directory always goes; with no --out it held everything. */
    {
        char made[4300];
        snprintf(made, sizeof made, "%s/%s", work, pov_out);
        remove(made);
        remove(copy);
        if (!o.out_dir) {
            remove(pov_png);
            remove(pov_log);
            remove(pt_png);
            remove(pt_log);
            remove(pt_json);
            remove(flip_png);
            char conv_log[4300];
            snprintf(conv_log, sizeof conv_log, "%s/povray_converged.log", out);
            remove(conv_log);
        }
        if (rmdir(work) != 0 && !o.quiet && rc == 0)
            fprintf(stderr, "partray crosscheck: left files in %s\n", work);
    }
    if (g_stop) rc = g_stop == SIGTERM ? 143 : 130;
    return rc;
}
