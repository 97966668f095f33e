/* cmd_sweep.c - `partray sweep SCENE.pov --gi MODE[,MODE...] --vary KEY=v1,v2,...
 *                [--vary ...] --ref REF.exr [--out DIR] [--size WxH]
 *                [--metric M] [--time T] [--plot-size WxH] [--quiet]
 *                [render options...]`
 *
 * Every combination of the --vary values (their cartesian product) is
 * rendered once per GI mode by running this binary again (`partray render`,
 * through /proc/self/exe) with its --stats file, so a sweep measures exactly
 * what a user's render costs and keeps working as render grows options.
 * Each image is compared with the reference: on linear values (HDR-FLIP)
 * when the reference is EXR or PFM, on display values (LDR-FLIP) when it
 * is a PNG. A render whose size differs from the reference's (a sweep over
 * `size`) is resampled to the reference's size first: box-filtered when it
 * is larger, bilinearly interpolated when it is smaller.
 *
 * KEY -> render option:
 *   size=WxH        --size WxH
 *   aa=T | aa=off   +AT (adaptive antialiasing, threshold T) | -A
 *   one capital letter K (A, R, W, H...)   +K<value> (POV-Ray style switch)
 *   D:NAME          -D NAME=value (a scene #declare)
 *   anything else   --KEY value (spp, seed, threads, and the GI modes'
 *                   own settings such as particles, nb, fg-rays)
 * MODE/KEY=... applies only to that mode's renders, so two modes can each
 * sweep their own quality setting: --gi particle,path
 * --vary particle/particles=1e4,1e5 --vary path/spp=4,16.
 *
 * Outputs in DIR (default ./sweep):
 *   sweep.csv   one row per render: mode, settings ("k=v;k=v"), render_s
 *               (stats timings.render), total_s (timings.total), rmse,
 *               relmse, psnr, ssim, flip_mean, flip_wmedian, gi_s
 *               (timings.gi_geometry + gi_lighting), wall_s (the child's
 *               wall clock), width, height, status, image
 *   plot.png    the metric (--metric, default relmse) against time (--time:
 *               total = total_s, default; render = gi_s + render_s; wall),
 *               one curve per mode, log axes where the values span > 10x
 *   index.html  the plot and the reference, then per render its settings,
 *               times, metrics, image and FLIP heat map
 *   ref.png, runs/NNN_MODE.{exr,png,json,log}, runs/NNN_MODE_flip.png
 * Exit: 0 all renders done; else the first failing render's exit code
 * (outputs are still written for the others); 2 usage; 3 I/O; 130 (143)
 * after Ctrl-C (SIGTERM): the outputs then cover the renders done so far. */
#include "cmd_sweep.h"
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "cli.h"
#include "ini.h"
#include "diag.h"
#include "framebuffer.h"
#include "img_io.h"
#include "img_metrics.h"
#include "img_plot.h"
#include "stats_read.h"
#include "subproc.h"
#include "timer.h"

#define SW_MAX_VARY 16
#define SW_MAX_VALUES 64
#define SW_MAX_MODES 8
#define SW_MAX_RUNS 1000
#define SW_MAX_PASS 256

static const char *usage =
    "usage: partray sweep SCENE.pov --ref REF.exr|.pfm|.png [--gi MODE[,MODE...]]\n"
    "                     --vary [MODE/]KEY=v1,v2,... [--vary ...] [--out DIR] [--size WxH]\n"
    "                     [--metric relmse|rmse|flip|psnr|ssim] [--time total|render|wall]\n"
    "                     [--plot-size WxH] [--quiet] [render options passed on, e.g. --threads 4 +A0.3]\n"
    "KEY: size, aa (threshold or off), a POV-Ray switch letter (A, R...), D:NAME (-D NAME=v),\n"
    "     or any render option without its dashes (spp, seed, particles, fg-rays...)\n";

typedef struct {
    const char *mode; /* NULL: every mode */
    const char *key;
    const char *values[SW_MAX_VALUES];
    int nvalues;
    char *buf;        /* owned copy the pointers above point into */
} sweep_vary;

typedef struct {
    const char *mode;
    char settings[1024];
    char base[96];    /* runs/NNN_mode */
    int exit_code;    /* child's exit code, -1 not started */
    int compared;
    double render_s, gi_s, total_s, wall_s;
    int width, height;
    int idx[SW_MAX_VARY]; /* value index per --vary (unused for varies of other modes) */
    img_compare_result r;
} sweep_run;

static void av_addf(ini_args *a, const char *fmt, ...)
{
    char buf[4096];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    ini_args_push(a, buf);
}

/* Ctrl-C / SIGTERM reach the running render too (same process group); the
 * sweep notes them, stops after that render and still writes its outputs. */
static volatile sig_atomic_t g_stop = 0;
static void on_stop(int sig)
{
    g_stop = sig;
    subproc_forward_signal(sig);
}

static int exit_for(pt_status st) { return cli_exit_status(st); }

static int parse_wxh(const char *v, int *w, int *h)
{
    char x;
    return sscanf(v, "%d%c%d", w, &x, h) == 3 && (x == 'x' || x == 'X') && *w > 0 && *h > 0 && *w <= 65536 &&
           *h <= 65536;
}

/* Parses "[MODE/]KEY=v1,v2,..." into *vy. */
static int parse_vary(const char *arg, sweep_vary *vy, char *err, size_t errn)
{
    memset(vy, 0, sizeof *vy);
    vy->buf = strdup(arg);
    if (!vy->buf) return 0;
    char *eq = strchr(vy->buf, '=');
    if (!eq || eq == vy->buf || !eq[1]) {
        snprintf(err, errn, "--vary wants [MODE/]KEY=v1,v2,..., got '%s'", arg);
        return 0;
    }
    *eq = 0;
    char *key = vy->buf;
    char *slash = strchr(key, '/');
    if (slash) {
        *slash = 0;
        vy->mode = key;
        key = slash + 1;
        if (!*vy->mode || !*key) {
            snprintf(err, errn, "--vary '%s': empty mode or key", arg);
            return 0;
        }
    }
    while (*key == '-') key++;
    if (!*key) {
        snprintf(err, errn, "--vary '%s': empty key", arg);
        return 0;
    }
    vy->key = key;
    for (char *p = eq + 1;;) {
        char *c = strchr(p, ',');
        if (c) *c = 0;
        if (!*p) {
            snprintf(err, errn, "--vary '%s': empty value", arg);
            return 0;
        }
        if (vy->nvalues == SW_MAX_VALUES) {
            snprintf(err, errn, "--vary '%s': more than %d values", arg, SW_MAX_VALUES);
            return 0;
        }
        vy->values[vy->nvalues++] = p;
        if (!c) break;
        p = c + 1;
    }
    if (strcmp(vy->key, "size") == 0) {
        for (int i = 0; i < vy->nvalues; i++) {
            int w, h;
            if (!parse_wxh(vy->values[i], &w, &h)) {
                snprintf(err, errn, "--vary size: '%s' is not WxH", vy->values[i]);
                return 0;
            }
        }
    }
    return 1;
}

/* Appends the render option(s) for KEY=value. */
static void add_setting(ini_args *a, const char *key, const char *value)
{
    if (strcmp(key, "size") == 0) {
        ini_args_push(a, "--size");
        ini_args_push(a, value);
    } else if (strcmp(key, "aa") == 0) {
        if (strcmp(value, "off") == 0 || strcmp(value, "none") == 0)
            ini_args_push(a, "-A");
        else
            av_addf(a, "+A%s", value);
    } else if (key[0] >= 'A' && key[0] <= 'Z' && key[1] == 0) {
        av_addf(a, "+%s%s", key, value);
    } else if (strncmp(key, "D:", 2) == 0 && key[2]) {
        ini_args_push(a, "-D");
        av_addf(a, "%s=%s", key + 2, value);
    } else {
        av_addf(a, "--%s", key);
        ini_args_push(a, value);
    }
}

/* Options the sweep sets itself and so refuses to pass on. */
static int reserved_option(const char *a)
{
    static const char *const r[] = {"-o", "--output", "--stats", "--gi", "--float", "--false-color", NULL};
    for (int i = 0; r[i]; i++)
        if (strcmp(a, r[i]) == 0) return 1;
    return (a[0] == '+' || a[0] == '-') && (a[1] == 'O' || a[1] == 'o' || a[1] == 'I' || a[1] == 'i') && a[2];
}

/* Box filter down to w x h: each output pixel is the mean of the source
 * pixels whose centres fall inside its footprint. */
static framebuffer *downsample(const framebuffer *src, int w, int h)
{
    framebuffer *dst = fb_new(w, h);
    if (!dst) return NULL;
    double sx = (double)src->width / w, sy = (double)src->height / h;
    for (int y = 0; y < h; y++) {
        int y0 = (int)ceil(y * sy - 0.5), y1 = (int)ceil((y + 1) * sy - 0.5);
        if (y1 <= y0) y1 = y0 + 1;
        if (y1 > src->height) y1 = src->height;
        for (int x = 0; x < w; x++) {
            int x0 = (int)ceil(x * sx - 0.5), x1 = (int)ceil((x + 1) * sx - 0.5);
            if (x1 <= x0) x1 = x0 + 1;
            if (x1 > src->width) x1 = src->width;
            double acc[3] = {0, 0, 0};
            int n = 0;
            for (int j = y0; j < y1; j++)
                for (int i = x0; i < x1; i++, n++)
                    for (int c = 0; c < 3; c++) acc[c] += src->rgb[((size_t)j * (size_t)src->width + (size_t)i) * 3 + (size_t)c];
            float *o = fb_px(dst, x, y);
            for (int c = 0; c < 3; c++) o[c] = n ? (float)(acc[c] / n) : 0.0f;
        }
    }
    return dst;
}

/* To w x h: box filter where the source is larger in both directions,
 * bilinear interpolation (pixel centres aligned) otherwise. */
static framebuffer *resample(const framebuffer *src, int w, int h)
{
    if (src->width >= w && src->height >= h) return downsample(src, w, h);
    framebuffer *dst = fb_new(w, h);
    if (dst) fb_resample_bilinear(src, dst);
    return dst;
}

static void html_escape(FILE *f, const char *s)
{
    for (; s && *s; s++) {
        switch (*s) {
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '&': fputs("&amp;", f); break;
        case '"': fputs("&quot;", f); break;
        default: fputc(*s, f);
        }
    }
}

static void csv_field(FILE *f, const char *s)
{
    if (!strpbrk(s, ",\"\n")) {
        fputs(s, f);
        return;
    }
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"') fputc('"', f);
        fputc(*s, f);
    }
    fputc('"', f);
}

static void csv_num(FILE *f, double v)
{
    if (isnan(v)) return;
    if (isinf(v)) fputs(v > 0 ? "inf" : "-inf", f);
    else fprintf(f, "%.9g", v);
}

static double metric_of(const sweep_run *r, const char *metric)
{
    if (!r->compared) return NAN;
    if (strcmp(metric, "rmse") == 0) return r->r.rmse;
    if (strcmp(metric, "flip") == 0) return r->r.flip_mean;
    if (strcmp(metric, "psnr") == 0) return r->r.psnr;
    if (strcmp(metric, "ssim") == 0) return r->r.ssim;
    return r->r.relmse;
}

static double time_of(const sweep_run *r, const char *t)
{
    if (strcmp(t, "render") == 0) return r->render_s + r->gi_s;
    if (strcmp(t, "wall") == 0) return r->wall_s;
    return r->total_s;
}

/* Writes path through a temporary name: fopen(tmp), then rename. */
static FILE *open_tmp(const char *path, char *tmp, size_t n)
{
    snprintf(tmp, n, "%s.tmp", path);
    return fopen(tmp, "wb");
}

static int close_tmp(FILE *f, const char *tmp, const char *path)
{
    int ok = !ferror(f);
    ok = (fclose(f) == 0) && ok;
    if (ok) ok = rename(tmp, path) == 0;
    if (!ok) remove(tmp);
    return ok;
}

static int write_csv(const char *dir, const sweep_run *runs, int nruns)
{
    char path[4200], tmp[4300];
    snprintf(path, sizeof path, "%s/sweep.csv", dir);
    FILE *f = open_tmp(path, tmp, sizeof tmp);
    if (!f) return 0;
    fputs("mode,settings,render_s,total_s,rmse,relmse,psnr,ssim,flip_mean,flip_wmedian,gi_s,wall_s,width,height,status,"
          "image\n",
          f);
    for (int i = 0; i < nruns; i++) {
        const sweep_run *r = &runs[i];
        int ok = r->exit_code == 0;
        csv_field(f, r->mode);
        fputc(',', f);
        csv_field(f, r->settings);
        fputc(',', f);
        double m[8] = {r->render_s, r->total_s, r->r.rmse, r->r.relmse, r->r.psnr, r->r.ssim, r->r.flip_mean,
                       r->r.flip_wmedian};
        for (int k = 0; k < 8; k++) {
            if (ok && (k < 2 || r->compared)) csv_num(f, m[k]);
            fputc(',', f);
        }
        if (ok) csv_num(f, r->gi_s);
        fputc(',', f);
        csv_num(f, r->wall_s);
        fprintf(f, ",%d,%d,", r->width, r->height);
        if (ok && r->compared) fputs("ok", f);
        else if (ok) fputs("not compared", f);
        else fprintf(f, "exit %d", r->exit_code);
        fprintf(f, ",%s.exr\n", r->base);
    }
    return close_tmp(f, tmp, path);
}

static pt_status write_plot(const char *dir, const sweep_run *runs, int nruns, const char *const *modes, int nmodes,
                            const char *metric, const char *tname, int pw, int ph, diag *d)
{
    double *xs = malloc((size_t)(nruns + 1) * sizeof *xs), *ys = malloc((size_t)(nruns + 1) * sizeof *ys);
    img_plot_series s[SW_MAX_MODES];
    if (!xs || !ys) {
        free(xs);
        free(ys);
        return PT_ERR_NOMEM;
    }
    int k = 0;
    for (int m = 0; m < nmodes; m++) {
        s[m].name = modes[m];
        s[m].x = xs + k;
        s[m].y = ys + k;
        s[m].n = 0;
        for (int i = 0; i < nruns; i++) {
            if (strcmp(runs[i].mode, modes[m]) != 0 || runs[i].exit_code != 0 || !runs[i].compared) continue;
            xs[k] = time_of(&runs[i], tname);
            ys[k] = metric_of(&runs[i], metric);
            k++;
            s[m].n++;
        }
    }
    img_plot_opts o;
    img_plot_default_opts(&o);
    o.width = pw;
    o.height = ph;
    char xl[64], yl[64];
    snprintf(xl, sizeof xl, "%s seconds", strcmp(tname, "render") == 0 ? "gi + render" : tname);
    snprintf(yl, sizeof yl, "%s", strcmp(metric, "flip") == 0 ? "flip mean" : metric);
    o.x_label = xl;
    o.y_label = yl;
    framebuffer *fb = NULL;
    pt_status st = img_plot(s, nmodes, &o, &fb, d);
    if (st == PT_OK) {
        char path[4200];
        snprintf(path, sizeof path, "%s/plot.png", dir);
        st = img_write(path, fb, NULL, d);
    }
    fb_free(fb);
    free(xs);
    free(ys);
    return st;
}

static void html_num(FILE *f, const char *name, double v, const char *fmt)
{
    fprintf(f, "%s ", name);
    if (isnan(v)) fputs("-", f);
    else if (isinf(v)) fputs("inf", f);
    else fprintf(f, fmt, v);
    fputs("<br>", f);
}

static int write_html(const char *dir, const char *scene, const char *ref_path, const sweep_run *runs, int nruns,
                      const char *metric, const char *tname, int ref_w, int ref_h)
{
    char path[4200], tmp[4300];
    snprintf(path, sizeof path, "%s/index.html", dir);
    FILE *f = open_tmp(path, tmp, sizeof tmp);
    if (!f) return 0;
    int dw = ref_w > 384 ? 384 : ref_w < 192 ? 192 : ref_w; /* small images shown enlarged, pixels kept sharp */
    fputs("<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>partray sweep: ", f);
    html_escape(f, scene);
    fputs("</title>\n<style>body{font-family:sans-serif;margin:1em}table{border-collapse:collapse}"
          "td,th{border:1px solid #ccc;padding:4px;vertical-align:top;text-align:left}"
          "figure{margin:0}.row{display:flex;gap:16px;flex-wrap:wrap;align-items:flex-start}"
          "td.m{font-family:monospace;white-space:nowrap}img.px{image-rendering:pixelated}</style></head><body>\n<h1>partray sweep</h1>\n<p>scene ",
          f);
    html_escape(f, scene);
    fputs(", reference ", f);
    html_escape(f, ref_path);
    fprintf(f, " (%dx%d); plot: %s against %s seconds, one curve per mode; data in <a href=\"sweep.csv\">sweep.csv</a>.</p>\n",
            ref_w, ref_h, metric, tname);
    fprintf(f,
            "<div class=\"row\"><figure><img src=\"plot.png\" alt=\"error against time\"><figcaption>%s against %s "
            "seconds</figcaption></figure>\n<figure><img class=\"px\" src=\"ref.png\" width=\"%d\" alt=\"reference\"><figcaption>reference</figcaption></figure></div>\n",
            metric, tname, dw);
    fputs("<table>\n<tr><th>mode</th><th>settings</th><th>seconds</th><th>error</th><th>image</th><th>FLIP heat map</th></tr>\n",
          f);
    for (int i = 0; i < nruns; i++) {
        const sweep_run *r = &runs[i];
        fputs("<tr><td>", f);
        html_escape(f, r->mode);
        fputs("</td><td>", f);
        html_escape(f, r->settings[0] ? r->settings : "(base)");
        fputs("</td><td class=\"m\">", f);
        if (r->exit_code == 0) {
            html_num(f, "total", r->total_s, "%.3f");
            html_num(f, "render", r->render_s, "%.3f");
            html_num(f, "gi", r->gi_s, "%.3f");
        }
        html_num(f, "wall", r->wall_s, "%.3f");
        fputs("</td><td class=\"m\">", f);
        if (r->compared) {
            html_num(f, "rmse", r->r.rmse, "%.5g");
            html_num(f, "relmse", r->r.relmse, "%.5g");
            html_num(f, "psnr", r->r.psnr, "%.2f");
            html_num(f, "ssim", r->r.ssim, "%.4f");
            html_num(f, "flip", r->r.flip_mean, "%.4f");
        } else {
            fprintf(f, "render failed (exit %d), see <a href=\"%s.log\">log</a>", r->exit_code, r->base);
        }
        fputs("</td>", f);
        if (r->compared) {
            fprintf(f, "<td><a href=\"%s.exr\"><img class=\"px\" src=\"%s.png\" width=\"%d\" alt=\"render\"></a></td>", r->base, r->base, dw);
            fprintf(f, "<td><img class=\"px\" src=\"%s_flip.png\" width=\"%d\" alt=\"FLIP\"></td>", r->base, dw);
        } else {
            fputs("<td></td><td></td>", f);
        }
        fputs("</tr>\n", f);
    }
    fputs("</table>\n</body></html>\n", f);
    return close_tmp(f, tmp, path);
}

/* Reads the times of a render from its stats file. */
static void read_times(const char *stats_path, sweep_run *r)
{
    char *js = subproc_read_text(stats_path, NULL);
    double g0 = 0, g1 = 0, v;
    r->render_s = r->total_s = NAN;
    r->gi_s = 0.0;
    if (!js) return;
    if (stats_read_num(js, "timings.render", &v)) r->render_s = v;
    if (stats_read_num(js, "timings.total", &v)) r->total_s = v;
    if (stats_read_num(js, "timings.gi_geometry", &g0) && isfinite(g0)) r->gi_s += g0;
    if (stats_read_num(js, "timings.gi_lighting", &g1) && isfinite(g1)) r->gi_s += g1;
    double w, h;
    if (stats_read_num(js, "width", &w) && stats_read_num(js, "height", &h)) {
        r->width = (int)w;
        r->height = (int)h;
    }
    free(js);
}

/* Compares one render with the reference; writes its FLIP heat map. */
static pt_status compare_run(const char *dir, sweep_run *r, const framebuffer *ref, int hdr, diag *d)
{
    char img_path[4200], map_path[4200];
    snprintf(img_path, sizeof img_path, "%s/%s.%s", dir, r->base, hdr ? "exr" : "png");
    snprintf(map_path, sizeof map_path, "%s/%s_flip.png", dir, r->base);
    framebuffer *test = NULL, *map = NULL;
    pt_status st = img_read(img_path, !hdr, &test, d);
    if (st == PT_OK && (test->width != ref->width || test->height != ref->height)) {
        framebuffer *rs = resample(test, ref->width, ref->height);
        fb_free(test);
        test = rs;
        if (!test) st = PT_ERR_NOMEM;
    }
    if (st == PT_OK) st = img_compare(ref, test, hdr, &r->r, &map, d);
    if (st == PT_OK) st = img_write(map_path, map, NULL, d);
    if (st == PT_OK) r->compared = 1;
    fb_free(test);
    fb_free(map);
    return st;
}

/* A file-name-safe copy of a mode name. */
static void safe_name(const char *s, char *out, size_t n)
{
    size_t k = 0;
    for (; *s && k + 1 < n; s++)
        out[k++] = (char)((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') || (*s >= '0' && *s <= '9') ? *s : '_');
    out[k] = 0;
}

int cmd_sweep(int argc, char **argv)
{
    const char *scene = NULL, *ref_path = NULL, *out_dir = "sweep", *gi_list = NULL, *size = NULL;
    const char *metric = "relmse", *tname = "total";
    int quiet = 0, pw = 720, ph = 480;
    sweep_vary vary[SW_MAX_VARY];
    int nvary = 0;
    const char *pass[SW_MAX_PASS];
    int npass = 0;
    char err[512];
    int rc = 0;
    char *gi_buf = NULL;
    sweep_run *runs = NULL;
    framebuffer *ref = NULL;
    diag *d = diag_new();
    int printed = 0;

    if (cli_wants_help(argc, argv)) {
        fputs(usage, stdout);
        fputs("Writes DIR/sweep.csv, DIR/plot.png (metric against time, one curve per mode)\n"
              "and DIR/index.html; docs/measuring.md describes them.\n", stdout);
        fputs(cli_exit_codes, stdout);
        diag_free(d);
        return CLI_EXIT_OK;
    }
    if (argc < 1 || argv[0][0] == '-' || argv[0][0] == '+') {
        fprintf(stderr, "partray sweep: the scene file comes first\n%s", usage);
        rc = 2;
        goto done;
    }
    scene = argv[0];
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *next = i + 1 < argc ? argv[i + 1] : NULL;
        int takes = strcmp(a, "--ref") == 0 || strcmp(a, "--out") == 0 || strcmp(a, "--gi") == 0 ||
                    strcmp(a, "--vary") == 0 || strcmp(a, "--size") == 0 || strcmp(a, "--metric") == 0 ||
                    strcmp(a, "--time") == 0 || strcmp(a, "--plot-size") == 0;
        if (takes && !next) {
            fprintf(stderr, "partray sweep: option '%s' needs a value\n%s", a, usage);
            rc = 2;
            goto done;
        }
        if (strcmp(a, "--ref") == 0) ref_path = argv[++i];
        else if (strcmp(a, "--out") == 0) out_dir = argv[++i];
        else if (strcmp(a, "--gi") == 0) gi_list = argv[++i];
        else if (strcmp(a, "--size") == 0) size = argv[++i];
        else if (strcmp(a, "--metric") == 0) metric = argv[++i];
        else if (strcmp(a, "--time") == 0) tname = argv[++i];
        else if (strcmp(a, "--plot-size") == 0) {
            if (!parse_wxh(argv[++i], &pw, &ph) || pw < 160 || ph < 120 || pw > 8192 || ph > 8192) {
                fprintf(stderr, "partray sweep: --plot-size wants WxH between 160x120 and 8192x8192\n");
                rc = 2;
                goto done;
            }
        } else if (strcmp(a, "--vary") == 0) {
            if (nvary == SW_MAX_VARY) {
                fprintf(stderr, "partray sweep: at most %d --vary options\n", SW_MAX_VARY);
                rc = 2;
                goto done;
            }
            if (!parse_vary(argv[++i], &vary[nvary], err, sizeof err)) {
                free(vary[nvary].buf);
                fprintf(stderr, "partray sweep: %s\n", err);
                rc = 2;
                goto done;
            }
            nvary++;
        } else if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) {
            quiet = 1;
        } else if (reserved_option(a)) {
            fprintf(stderr, "partray sweep: '%s' is set by the sweep itself\n", a);
            rc = 2;
            goto done;
        } else {
            if (npass == SW_MAX_PASS) {
                fprintf(stderr, "partray sweep: too many render options\n");
                rc = 2;
                goto done;
            }
            pass[npass++] = a;
        }
    }
    if (!ref_path) {
        fprintf(stderr, "partray sweep: --ref REF is required\n%s", usage);
        rc = 2;
        goto done;
    }
    if (strcmp(metric, "relmse") && strcmp(metric, "rmse") && strcmp(metric, "flip") && strcmp(metric, "psnr") &&
        strcmp(metric, "ssim")) {
        fprintf(stderr, "partray sweep: --metric wants relmse, rmse, flip, psnr or ssim\n");
        rc = 2;
        goto done;
    }
    if (strcmp(tname, "total") && strcmp(tname, "render") && strcmp(tname, "wall")) {
        fprintf(stderr, "partray sweep: --time wants total, render or wall\n");
        rc = 2;
        goto done;
    }
    int sw, sh;
    if (size && !parse_wxh(size, &sw, &sh)) {
        fprintf(stderr, "partray sweep: --size wants WxH, got '%s'\n", size);
        rc = 2;
        goto done;
    }
    img_format rf = img_format_from_path(ref_path);
    if (rf == IMG_FMT_UNKNOWN) {
        fprintf(stderr, "partray sweep: reference '%s': unknown format (use .exr, .pfm or .png)\n", ref_path);
        rc = 2;
        goto done;
    }

    /* Modes. */
    const char *modes[SW_MAX_MODES];
    int nmodes = 0;
    if (gi_list) {
        gi_buf = strdup(gi_list);
        for (char *p = gi_buf; p && *p;) {
            char *c = strchr(p, ',');
            if (c) *c = 0;
            if (!*p || nmodes == SW_MAX_MODES) {
                fprintf(stderr, "partray sweep: --gi wants 1 to %d comma-separated modes\n", SW_MAX_MODES);
                rc = 2;
                goto done;
            }
            modes[nmodes++] = p;
            p = c ? c + 1 : NULL;
        }
    }
    if (nmodes == 0) modes[nmodes++] = "default";
    for (int v = 0; v < nvary; v++) {
        if (!vary[v].mode) continue;
        int found = 0;
        for (int m = 0; m < nmodes; m++) found |= strcmp(vary[v].mode, modes[m]) == 0;
        if (!found) {
            fprintf(stderr, "partray sweep: --vary %s/%s: '%s' is not one of the --gi modes\n", vary[v].mode, vary[v].key,
                    vary[v].mode);
            rc = 2;
            goto done;
        }
    }

    /* The reference. */
    int hdr = rf != IMG_FMT_PNG;
    pt_status st = img_read(ref_path, !hdr, &ref, d);
    if (st != PT_OK) {
        printed = cli_print_diags(d, printed, 0);
        rc = exit_for(st);
        goto done;
    }
    if (size && (sw != ref->width || sh != ref->height) && !quiet)
        fprintf(stderr, "partray sweep: renders at %s are resampled to the reference's %dx%d for comparison\n", size,
                ref->width, ref->height);

    /* Runs: per mode, the cartesian product of the varies that apply to it. */
    int nruns = 0, cap = 0;
    for (int m = 0; m < nmodes; m++) {
        long count = 1;
        for (int v = 0; v < nvary; v++)
            if (!vary[v].mode || strcmp(vary[v].mode, modes[m]) == 0) count *= vary[v].nvalues;
        if (count + cap > SW_MAX_RUNS) {
            fprintf(stderr, "partray sweep: more than %d renders asked for\n", SW_MAX_RUNS);
            rc = 2;
            goto done;
        }
        cap += (int)count;
    }
    runs = calloc((size_t)cap, sizeof *runs);
    if (!runs) {
        rc = 1;
        goto done;
    }
    for (int m = 0; m < nmodes; m++) {
        int idx[SW_MAX_VARY] = {0};
        for (;;) {
            sweep_run *r = &runs[nruns];
            r->mode = modes[m];
            r->exit_code = -1;
            memcpy(r->idx, idx, sizeof idx);
            char mname[64];
            safe_name(modes[m], mname, sizeof mname);
            snprintf(r->base, sizeof r->base, "runs/%03d_%s", nruns, mname);
            size_t off = 0;
            for (int v = 0; v < nvary; v++) {
                if (vary[v].mode && strcmp(vary[v].mode, modes[m]) != 0) continue;
                off += (size_t)snprintf(r->settings + off, off < sizeof r->settings ? sizeof r->settings - off : 0, "%s%s=%s",
                                        off ? ";" : "", vary[v].key, vary[v].values[idx[v]]);
                if (off >= sizeof r->settings) off = sizeof r->settings - 1;
            }
            nruns++;
            /* odometer over the applicable varies */
            int v = nvary - 1;
            for (; v >= 0; v--) {
                if (vary[v].mode && strcmp(vary[v].mode, modes[m]) != 0) continue;
                if (++idx[v] < vary[v].nvalues) break;
                idx[v] = 0;
            }
            if (v < 0) break;
        }
    }

    char runs_dir[4200], self[4096];
    snprintf(runs_dir, sizeof runs_dir, "%s/runs", out_dir);
    if (!subproc_mkdirs(runs_dir)) {
        fprintf(stderr, "partray sweep: cannot create directory '%s'\n", runs_dir);
        rc = 3;
        goto done;
    }
    if (!subproc_self_exe(self, sizeof self)) {
        fprintf(stderr, "partray sweep: cannot find the partray binary (/proc/self/exe)\n");
        rc = 3;
        goto done;
    }
    {
        char ref_png[4200];
        snprintf(ref_png, sizeof ref_png, "%s/ref.png", out_dir);
        framebuffer *show = ref;
        if (!hdr) { /* raw display values: write them back as linear so the PNG shows the same codes */
            show = fb_new(ref->width, ref->height);
            if (show)
                for (size_t i = 0; i < (size_t)ref->width * (size_t)ref->height * 3u; i++)
                    show->rgb[i] = (float)img_srgb_decode(ref->rgb[i]);
        }
        st = show ? img_write(ref_png, show, NULL, d) : PT_ERR_NOMEM;
        if (show != ref) fb_free(show);
        if (st != PT_OK) {
            printed = cli_print_diags(d, printed, 0);
            rc = exit_for(st);
            goto done;
        }
    }

    /* Render and compare. */
    int first_fail = 0, interrupted = 0;
    double t_sweep = timer_now();
    g_stop = 0;
    signal(SIGINT, on_stop);
    signal(SIGTERM, on_stop);
    for (int i = 0; i < nruns; i++) {
        sweep_run *r = &runs[i];
        char exr[4200], png[4200], js[4200], log[4200];
        snprintf(exr, sizeof exr, "%s/%s.exr", out_dir, r->base);
        snprintf(png, sizeof png, "%s/%s.png", out_dir, r->base);
        snprintf(js, sizeof js, "%s/%s.json", out_dir, r->base);
        snprintf(log, sizeof log, "%s/%s.log", out_dir, r->base);
        remove(log);
        remove(js);
        ini_args *a = ini_args_new();
        if (!a) {
            rc = exit_for(PT_ERR_NOMEM);
            goto done;
        }
        ini_args_push(a, self);
        ini_args_push(a, "render");
        ini_args_push(a, scene);
        if (strcmp(r->mode, "default") != 0) {
            ini_args_push(a, "--gi");
            ini_args_push(a, r->mode);
        }
        int size_varied = 0;
        for (int v = 0; v < nvary; v++)
            if (strcmp(vary[v].key, "size") == 0 && (!vary[v].mode || strcmp(vary[v].mode, r->mode) == 0)) size_varied = 1;
        if (!size_varied) {
            ini_args_push(a, "--size");
            if (size) ini_args_push(a, size);
            else av_addf(a, "%dx%d", ref->width, ref->height);
        }
        ini_args_push(a, "-o");
        ini_args_push(a, exr);
        ini_args_push(a, "-o");
        ini_args_push(a, png);
        ini_args_push(a, "--float");
        ini_args_push(a, "--stats");
        ini_args_push(a, js);
        ini_args_push(a, "--quiet");
        for (int k = 0; k < npass; k++) ini_args_push(a, pass[k]);
        /* the settings of this run, in the order of the --vary options */
        for (int v = 0; v < nvary; v++)
            if (!vary[v].mode || strcmp(vary[v].mode, r->mode) == 0) add_setting(a, vary[v].key, vary[v].values[r->idx[v]]);
        FILE *lf = fopen(log, "wb");
        if (lf) {
            fputs("#", lf);
            for (int k = 0; k < ini_argc(a); k++) fprintf(lf, " %s", ini_argv(a)[k]);
            fputs("\n", lf);
            fclose(lf);
        }
        r->exit_code = subproc_run((const char *const *)ini_argv(a), NULL, log, &r->wall_s, d);
        ini_free(a);
        if (r->exit_code == 0) {
            read_times(js, r);
            st = compare_run(out_dir, r, ref, hdr, d);
            if (st != PT_OK) {
                printed = cli_print_diags(d, printed, 0);
                if (!first_fail) first_fail = exit_for(st);
            }
        } else {
            if (!first_fail) first_fail = r->exit_code < 0 ? 3 : r->exit_code;
            char *text = subproc_read_text(log, NULL);
            fprintf(stderr, "partray sweep: render %s %s failed (exit %d); log %s\n", r->mode, r->settings, r->exit_code, log);
            if (text && !quiet) {
                size_t n = strlen(text);
                fprintf(stderr, "%s", n > 2000 ? text + n - 2000 : text);
            }
            free(text);
            if (r->exit_code == 130 || r->exit_code == 143) interrupted = 1;
        }
        if (g_stop) interrupted = 1;
        if (!quiet) {
            fprintf(stderr, "[%d/%d] %s %s: ", i + 1, nruns, r->mode, r->settings[0] ? r->settings : "(base)");
            if (r->compared)
                fprintf(stderr, "total %.3f s, render %.3f s, relmse %.4g, rmse %.4g, flip %.4f\n", r->total_s, r->render_s,
                        r->r.relmse, r->r.rmse, r->r.flip_mean);
            else
                fprintf(stderr, "failed\n");
        }
        if (interrupted) {
            nruns = i + 1;
            break;
        }
    }

    /* Outputs. */
    if (!write_csv(out_dir, runs, nruns)) {
        fprintf(stderr, "partray sweep: cannot write %s/sweep.csv\n", out_dir);
        rc = 3;
        goto done;
    }
    st = write_plot(out_dir, runs, nruns, modes, nmodes, metric, tname, pw, ph, d);
    if (st != PT_OK) {
        printed = cli_print_diags(d, printed, 0);
        rc = exit_for(st);
        goto done;
    }
    if (!write_html(out_dir, scene, ref_path, runs, nruns, metric, tname, ref->width, ref->height)) {
        fprintf(stderr, "partray sweep: cannot write %s/index.html\n", out_dir);
        rc = 3;
        goto done;
    }
    if (!quiet)
        fprintf(stderr, "partray sweep: %d renders in %.1f s; %s/sweep.csv, %s/plot.png, %s/index.html\n", nruns,
                timer_now() - t_sweep, out_dir, out_dir, out_dir);
    rc = interrupted ? (g_stop == SIGTERM ? 143 : 130) : first_fail;

done:
    for (int v = 0; v < nvary; v++) free(vary[v].buf);
    free(gi_buf);
    free(runs);
    fb_free(ref);
    diag_free(d);
    return rc;
}
