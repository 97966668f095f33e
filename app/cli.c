/* cli.c - option parsing for `partray render`.
 *
 * POV-Ray style switches accepted (POV-Ray 3.7 reference, "Command-line
 * options"): +Wn +Hn (size), +Ofile (output), +Ifile (input), +A[t] / -A
 * (antialiasing with threshold t, default 0.3), +Rn (AA depth), +Lpath
 * (library path), +FE/+FN (format of an output named without extension),
 * +WTn (work threads), +Kc (clock), +KFIn +KFFn +KIc +KFc +KC (animation
 * frames and clocks, cyclic), +SFn +EFn (frame subset), +SCn +ECn +SRn +ERn
 * (render window), +Qn (quality 0-11, shade.h), +UA (alpha). Switches that only
 * concern POV-Ray's display or its own files (+D, -D, +P, +V, +J...) are accepted and ignored. INI files and
 * Key=value options are expanded into these switches first (ini.h). */
#include "cli.h"
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static int parse_int(const char *s, int *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || end == s || *end || v < -2147483647L || v > 2147483647L) return 0;
    *out = (int)v;
    return 1;
}

/* A positive integer up to `max`. */
static int parse_count(const char *s, long long max, long long *out)
{
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (errno || end == s || *end || v < 1 || v > max) return 0;
    *out = v;
    return 1;
}

static int parse_double(const char *s, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end) return 0;
    *out = v;
    return 1;
}

static int add_list(const char **list, int *n, const char *v)
{
    if (*n >= CLI_MAX_LIST) return 0;
    list[(*n)++] = v;
    return 1;
}

static int add_output(cli_render *o, const char *v)
{
    if (o->noutputs >= 8) return 0;
    o->outputs[o->noutputs++] = v;
    return 1;
}

/* One POV-Ray style switch: "+W640", "-A", "+A0.3", "+Oout.png"... */
static int pov_switch(const char *arg, cli_render *o, char *err, int errlen)
{
    int on = arg[0] == '+';
    const char *k = arg + 1;
    char c = (char)(k[0] >= 'a' && k[0] <= 'z' ? k[0] - 32 : k[0]);
    const char *v = k + 1;
    switch (c) {
    case 'W':
        if ((v[0] == 'T' || v[0] == 't') && parse_int(v + 1, &o->threads)) return 0;
        if (parse_int(v, &o->width) && o->width > 0) return 0;
        break;
    case 'H':
        if (parse_int(v, &o->height) && o->height > 0) return 0;
        break;
    case 'A':
        o->antialias = on;
        if (*v && !parse_double(v, &o->aa_threshold)) break;
        return 0;
    case 'R':
        if (parse_int(v, &o->aa_depth) && o->aa_depth >= 1 && o->aa_depth <= 9) return 0;
        break;
    case 'O':
        if (*v && add_output(o, v)) return 0;
        break;
    case 'I':
        if (*v) { o->scene = v; return 0; }
        break;
    case 'L':
        if (*v && add_list(o->libs, &o->nlibs, v)) return 0;
        break;
    case 'K': /* +KFIn +KFFn +KIc +KFc +KC +Kc (POV-Ray 3.7 "Animation Options") */
        if ((v[0] == 'F' || v[0] == 'f') && (v[1] == 'I' || v[1] == 'i')) {
            if (parse_int(v + 2, &o->kfi)) { o->kfi_given = 1; return 0; }
        } else if ((v[0] == 'F' || v[0] == 'f') && (v[1] == 'F' || v[1] == 'f')) {
            if (parse_int(v + 2, &o->kff)) { o->kff_given = 1; return 0; }
        } else if (v[0] == 'I' || v[0] == 'i') {
            if (parse_double(v + 1, &o->ki)) return 0;
        } else if (v[0] == 'F' || v[0] == 'f') {
            if (parse_double(v + 1, &o->kf)) return 0;
        } else if ((v[0] == 'C' || v[0] == 'c') && !v[1]) {
            o->cyclic = on;
            return 0;
        } else if (!*v) {
            return 0; /* "+K" alone: clock_on with the current clock */
        } else if (parse_double(v, &o->clock)) {
            o->clock_given = 1;
            return 0;
        }
        break;
    case 'S': case 'E': { /* +SFn +EFn: subset of frames (n in (0,1): a fraction); +SC +EC +SR +ER: render window */
        char w = (char)(v[0] >= 'a' && v[0] <= 'z' ? v[0] - 32 : v[0]);
        double *dst = NULL;
        int *given = NULL;
        if (w == 'F') { dst = c == 'S' ? &o->sf : &o->ef; given = c == 'S' ? &o->sf_given : &o->ef_given; }
        else if (w == 'C') { dst = c == 'S' ? &o->sc : &o->ec; given = c == 'S' ? &o->sc_given : &o->ec_given; }
        else if (w == 'R') { dst = c == 'S' ? &o->sr : &o->er; given = c == 'S' ? &o->sr_given : &o->er_given; }
        if (dst && parse_double(v + 1, dst) && *dst >= 0) {
            *given = 1;
            return 0;
        }
        break;
    }
    case 'F': { /* +F[type][bits] (POV-Ray 3.7 "Output File Type"): N PNG, E OpenEXR, S the system's
                   format (PNG on Unix); +FNn: n bits per colour (above 8: 16-bit PNG) */
        char t = (char)(v[0] >= 'a' && v[0] <= 'z' ? v[0] - 32 : v[0]);
        if (!*v) return 0;
        if (t == 'N' || t == 'S' || t == 'E') {
            o->format = t == 'E' ? 'E' : 'N';
            if (!v[1]) return 0;
            int bits;
            if (o->format == 'N' && parse_int(v + 1, &bits) && bits >= 1 && bits <= 16) {
                o->png16 = bits > 8;
                return 0;
            }
            break;
        }
        const char *name = t == 'C' || t == 'T' ? "Targa" : t == 'P' ? "PPM" : t == 'B' ? "BMP" : t == 'J' ? "JPEG" : t == 'H' ? "Radiance HDR" : NULL;
        if (name) {
            snprintf(err, (size_t)errlen, "%s: %s output is not written; +FN (PNG), +FE (OpenEXR) or an output named .pfm are", arg,
                     name);
            return 2;
        }
        break;
    }
    case 'Q': { /* +Qn, POV-Ray 3.7 view.cpp: clip(Quality, 0, 9) */
        int q;
        if (parse_int(v, &q) && q >= 0 && q <= 11) {
            o->quality = q > 9 ? 9 : q;
            o->quality_given = 1;
            return 0;
        }
        snprintf(err, (size_t)errlen, "+Q wants a quality level 0 to 11, got '%s'", arg);
        return 2;
    }
    case 'U': /* +UA alpha (Output_Alpha); +UD +UL +UV +UR +UO: POV-Ray's vista, light buffers, bounds: nothing here */
        if ((v[0] == 'A' || v[0] == 'a') && !v[1]) {
            o->alpha = on;
            return 0;
        }
        if (v[0] && !v[1] && strchr("DdLlVvRrOo", v[0])) return 0;
        break;
    case 'J': /* +J[n.n] jitter on (amount n.n, clipped to [0, 1]), -J off: POV-Ray's view.cpp */
        if (!on) {
            o->aa_jitter = 0.0;
            return 0;
        }
        if (!*v) {
            o->aa_jitter = 1.0;
            return 0;
        }
        if (parse_double(v, &o->aa_jitter)) {
            o->aa_jitter = o->aa_jitter < 0.0 ? 0.0 : o->aa_jitter > 1.0 ? 1.0 : o->aa_jitter;
            return 0;
        }
        break;
    case 'D': case 'P': case 'V': case 'X': case 'G': case 'B': case 'C':
        return 0; /* display, pause, verbose...: ignored */
    default:
        break;
    }
    snprintf(err, (size_t)errlen, "bad or unknown option '%s'", arg);
    return 2;
}

static int has_value(const char *opt, const char *next, char *err, int errlen)
{
    if (next) return 1;
    snprintf(err, (size_t)errlen, "option '%s' needs a value", opt);
    return 0;
}

/* WxH, each a positive integer; how large an image may be is checked later
 * (main.c: check_image_size), which says why a size is refused. */
static int parse_size(const char *v, cli_render *o)
{
    char *end;
    errno = 0;
    long w = strtol(v, &end, 10);
    if (errno || end == v || (*end != 'x' && *end != 'X') || w <= 0 || w > 2147483647L) return 0;
    const char *hv = end + 1;
    long h = strtol(hv, &end, 10);
    if (errno || end == hv || *end || h <= 0 || h > 2147483647L) return 0;
    o->width = (int)w;
    o->height = (int)h;
    return 1;
}

int cli_parse_render(int argc, char **argv, cli_render *o, char *err, int errlen)
{
    /* POV-Ray's Initial_Frame, Final_Frame, Initial_Clock, Final_Clock, +A threshold, +R, +Q */
    *o = (cli_render){.kfi = 1, .kff = 1, .kf = 1, .aa_threshold = 0.3, .aa_depth = 3, .aa_jitter = 1.0, .quality = 9,
                      .exr_compression = -1};
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        const char *next = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            if (!add_output(o, next)) { snprintf(err, (size_t)errlen, "too many outputs"); return 2; }
            i++;
        } else if (strcmp(a, "--size") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            if (!parse_size(next, o)) { snprintf(err, (size_t)errlen, "--size wants WxH, got '%s'", next); return 2; }
            i++;
        } else if (strcmp(a, "--gi") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            o->gi = next;
            i++;
        } else if (strcmp(a, "--spp") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            if (!parse_int(next, &o->spp) || o->spp < 1) { snprintf(err, (size_t)errlen, "--spp wants a positive integer"); return 2; }
            i++;
        } else if (strcmp(a, "--threads") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            if (!parse_int(next, &o->threads) || o->threads < 0) { snprintf(err, (size_t)errlen, "--threads wants a non-negative integer"); return 2; }
            i++;
        } else if (strcmp(a, "--seed") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            char *end;
            errno = 0;
            unsigned long long s = strtoull(next, &end, 10);
            if (errno || *end || end == next) { snprintf(err, (size_t)errlen, "--seed wants an integer"); return 2; }
            o->seed = s;
            i++;
        } else if (strcmp(a, "--stats") == 0 || strcmp(a, "--gi-cache") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            if (strcmp(a, "--stats") == 0) o->stats = next;
            else o->gi_cache = next;
            i++;
        } else if (strcmp(a, "--display") == 0 || strcmp(a, "--view") == 0 || strcmp(a, "--look") == 0 ||
                   strcmp(a, "--working-space") == 0 || strcmp(a, "--ocio-config") == 0 ||
                   strcmp(a, "--false-color") == 0 || strcmp(a, "--aovs") == 0 || strcmp(a, "--units") == 0 ||
                   strcmp(a, "--false-color-quantity") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            if (strcmp(a, "--display") == 0) o->display = next;
            else if (strcmp(a, "--view") == 0) o->view = next;
            else if (strcmp(a, "--look") == 0) o->look = next;
            else if (strcmp(a, "--working-space") == 0) o->working_space = next;
            else if (strcmp(a, "--ocio-config") == 0) o->ocio_config = next;
            else if (strcmp(a, "--aovs") == 0) o->aovs = next;
            else if (strcmp(a, "--units") == 0) o->units = next;
            else if (strcmp(a, "--false-color-quantity") == 0) o->fc_quantity = next;
            else o->false_color = next;
            i++;
        } else if (strcmp(a, "--exposure") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            if (!parse_double(next, &o->exposure)) { snprintf(err, (size_t)errlen, "--exposure wants a number of stops"); return 2; }
            i++;
        } else if (strcmp(a, "--false-color-range") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            if (sscanf(next, "%lf,%lf", &o->fc_lo, &o->fc_hi) != 2 || !(o->fc_lo > 0) || !(o->fc_hi > o->fc_lo)) {
                snprintf(err, (size_t)errlen, "--false-color-range wants LO,HI with 0 < LO < HI");
                return 2;
            }
            i++;
        } else if (strcmp(a, "--png16") == 0) {
            o->png16 = 1;
        } else if (strcmp(a, "--exr-compression") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            if (strcmp(next, "none") == 0) o->exr_compression = 0;
            else if (strcmp(next, "zip") == 0) o->exr_compression = 1;
            else if (strcmp(next, "piz") == 0) o->exr_compression = 2;
            else { snprintf(err, (size_t)errlen, "--exr-compression wants none, zip or piz"); return 2; }
            i++;
        } else if (strcmp(a, "--cl-device") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            o->cl_device = next;
            i++;
        } else if (strcmp(a, "--particles") == 0 || strcmp(a, "--photons") == 0 || strcmp(a, "--nb") == 0 ||
                   strcmp(a, "--fg-rays") == 0 || strcmp(a, "--max-depth") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            int v;
            if (!parse_int(next, &v) || v < 1) { snprintf(err, (size_t)errlen, "%s wants a positive integer", a); return 2; }
            if (strcmp(a, "--particles") == 0) o->particles = v;
            else if (strcmp(a, "--photons") == 0) o->photons = v;
            else if (strcmp(a, "--nb") == 0) o->bounces = v;
            else if (strcmp(a, "--fg-rays") == 0) o->fg_rays = v;
            else o->max_depth = v;
            i++;
        } else if (strcmp(a, "--vpls") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            int v;
            if (!parse_int(next, &v) || v < 1) { snprintf(err, (size_t)errlen, "--vpls wants a positive integer"); return 2; }
            o->vpls = v;
            i++;
        } else if (strcmp(a, "--vpl-cut") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            if (strcmp(next, "minmax") == 0) o->vpl_cut = 0;
            else if (strcmp(next, "full") == 0) o->vpl_cut = 1;
            else if (strcmp(next, "brute") == 0) o->vpl_cut = 2;
            else { snprintf(err, (size_t)errlen, "--vpl-cut wants minmax, full or brute"); return 2; }
            i++;
        } else if (strcmp(a, "--vpl-adaptive") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            if (strcmp(next, "on") == 0) o->vpl_adaptive = 1;
            else if (strcmp(next, "off") == 0) o->vpl_adaptive = 2;
            else { snprintf(err, (size_t)errlen, "--vpl-adaptive wants on or off"); return 2; }
            i++;
        } else if (strcmp(a, "--detp-full") == 0) {
            o->detp_full = 1;
        } else if (strcmp(a, "--detp-radius") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            if (!parse_double(next, &o->detp_radius) || !(o->detp_radius > 0.0) || !isfinite(o->detp_radius)) {
                snprintf(err, (size_t)errlen, "--detp-radius wants a positive number");
                return 2;
            }
            i++;
        } else if (strcmp(a, "--gi-quality") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            if (!parse_double(next, &o->gi_quality) || !(o->gi_quality > 0.0) || o->gi_quality > 64.0) {
                snprintf(err, (size_t)errlen, "--gi-quality wants a number in (0, 64]");
                return 2;
            }
            i++;
        } else if (strcmp(a, "--photon-scale") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            if (!parse_double(next, &o->photon_scale) || !(o->photon_scale > 0.0) || o->photon_scale > 1024.0) {
                snprintf(err, (size_t)errlen, "--photon-scale wants a number in (0, 1024]");
                return 2;
            }
            i++;
        } else if (strcmp(a, "--photon-roulette") == 0) {
            o->photon_roulette = 1;
        } else if (strcmp(a, "--clock") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            if (!parse_double(next, &o->clock)) { snprintf(err, (size_t)errlen, "--clock wants a number"); return 2; }
            o->clock_given = 1;
            i++;
        } else if (strcmp(a, "--frame") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            int fr;
            if (!parse_int(next, &fr) || fr < 0) { snprintf(err, (size_t)errlen, "--frame wants a frame number"); return 2; }
            o->sf = o->ef = fr;
            o->sf_given = o->ef_given = 1;
            i++;
        } else if (strcmp(a, "--aa-threshold") == 0 || strncmp(a, "--aa-threshold=", 15) == 0) {
            /* INI Antialias_Threshold: the threshold without switching +A on or off */
            const char *v = a[14] == '=' ? a + 15 : next;
            if (!v) { snprintf(err, (size_t)errlen, "option '%s' needs a value", a); return 2; }
            if (!parse_double(v, &o->aa_threshold) || o->aa_threshold < 0) {
                snprintf(err, (size_t)errlen, "--aa-threshold wants a non-negative number");
                return 2;
            }
            if (a[14] != '=') i++;
        } else if (strcmp(a, "--float") == 0) {
            o->exr_float = 1;
        } else if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) {
            o->quiet = 1;
        } else if (strcmp(a, "--max-loop") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            int v;
            if (!parse_int(next, &v) || v < 1) { snprintf(err, (size_t)errlen, "--max-loop wants a positive integer"); return 2; }
            o->max_loop = v;
            i++;
        } else if (strcmp(a, "--max-include-depth") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            if (!parse_int(next, &o->max_include_depth) || o->max_include_depth < 1) { snprintf(err, (size_t)errlen, "bad --max-include-depth"); return 2; }
            i++;
        } else if (strcmp(a, "--max-macro-depth") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            if (!parse_int(next, &o->max_macro_depth) || o->max_macro_depth < 1) { snprintf(err, (size_t)errlen, "bad --max-macro-depth"); return 2; }
            i++;
        } else if (strcmp(a, "--max-tokens") == 0 || strcmp(a, "--max-memory") == 0 ||
                   strcmp(a, "--max-string") == 0 || strcmp(a, "--max-array") == 0 ||
                   strcmp(a, "--max-image-pixels") == 0 ||
                   strcmp(a, "--cl-max-memory") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            long long v;
            if (!parse_count(next, 1LL << 53, &v)) {
                snprintf(err, (size_t)errlen, "%s wants a positive integer%s", a,
                         strcmp(a, "--max-memory") == 0 || strcmp(a, "--cl-max-memory") == 0 ? " (MiB)" : "");
                return 2;
            }
            if (strcmp(a, "--max-tokens") == 0) o->max_tokens = v;
            else if (strcmp(a, "--max-memory") == 0) o->max_memory_mib = v;
            else if (strcmp(a, "--max-array") == 0) o->max_array = v;
            else if (strcmp(a, "--max-image-pixels") == 0) o->max_image_pixels = v;
            else if (strcmp(a, "--cl-max-memory") == 0) o->cl_max_memory_mib = v > (1LL << 40) ? (1LL << 40) : v;
            else o->max_string = v > 0x7fffffffL ? 0x7fffffffL : (long)v;
            i++;
        } else if (strncmp(a, "-D", 2) == 0 && a[2]) {
            if (!strchr(a + 2, '=') || !add_list(o->defines, &o->ndefines, a + 2)) {
                snprintf(err, (size_t)errlen, "-D wants NAME=VALUE, got '%s'", a + 2);
                return 2;
            }
        } else if (strcmp(a, "-D") == 0 && next && strchr(next, '=')) {
            if (!add_list(o->defines, &o->ndefines, next)) { snprintf(err, (size_t)errlen, "too many -D"); return 2; }
            i++;
        } else if (strcmp(a, "-D") == 0) {
            /* POV-Ray's "display off" switch: nothing to do */
        } else if (strcmp(a, "-L") == 0) {
            if (!has_value(a, next, err, errlen)) return 2;
            if (!add_list(o->libs, &o->nlibs, next)) { snprintf(err, (size_t)errlen, "too many -L"); return 2; }
            i++;
        } else if (strncmp(a, "-L", 2) == 0 && a[2] && a[1] == 'L') {
            if (!add_list(o->libs, &o->nlibs, a + 2)) { snprintf(err, (size_t)errlen, "too many -L"); return 2; }
        } else if ((a[0] == '+' || a[0] == '-') && a[1] && a[1] != '-') {
            int rc = pov_switch(a, o, err, errlen);
            if (rc) return rc;
        } else if (a[0] == '-' && a[1]) {
            snprintf(err, (size_t)errlen, "unknown option '%s'", a);
            return 2;
        } else if (!o->scene) {
            o->scene = a;
        } else {
            snprintf(err, (size_t)errlen, "unexpected argument '%s' (scene already given as '%s')", a, o->scene);
            return 2;
        }
    }
    if (!o->scene) {
        snprintf(err, (size_t)errlen, "no scene file given");
        return 2;
    }
    anim_plan plan;
    return cli_frames(o, &plan, err, errlen);
}

int cli_frames(const cli_render *o, anim_plan *p, char *err, int errlen)
{
    if (anim_plan_make(p, o->kfi, o->kfi_given, o->kff, o->kff_given, o->ki, o->kf, o->cyclic, o->sf_given ? o->sf : -1,
                       o->ef_given ? o->ef : -1, err, errlen))
        return 2;
    return 0;
}

void cli_frame_options(const cli_render *o, const anim_plan *p, int frame, sdl_options *so)
{
    if (p->animated) anim_frame_options(p, frame, so);
    else if (o->clock_given) sdl_set_still_clock(so, o->clock);
}

int cli_window(const cli_render *o, int w, int h, int win[4], char *err, int errlen)
{
    /* POV-Ray keeps these as POVMSFloat (32-bit float): +SR0.7 of 10 rows
     * is int(10 * 0.7f) - 1 = 5, not 6 */
    double sc = (float)(o->sc_given ? o->sc : 1.0), sr = (float)(o->sr_given ? o->sr : 1.0);
    double ec = (float)(o->ec_given ? o->ec : w), er = (float)(o->er_given ? o->er : h);
    int x0 = sc < 1.0 ? (int)(w * sc) : (int)sc - 1;
    int y0 = sr < 1.0 ? (int)(h * sr) : (int)sr - 1;
    int x1 = ec <= 1.0 ? (int)(w * ec) - 1 : (int)ec - 1;
    int y1 = er <= 1.0 ? (int)(h * er) - 1 : (int)er - 1;
    if (x0 < 0 || y0 < 0 || x0 >= w || y0 >= h) {
        snprintf(err, (size_t)errlen, "start column/row (+SC/+SR) outside the %dx%d image", w, h);
        return 2;
    }
    if (x1 >= w || y1 >= h || x1 < x0 || y1 < y0) {
        snprintf(err, (size_t)errlen, "end column/row (+EC/+ER) outside the %dx%d image or before the start", w, h);
        return 2;
    }
    win[0] = x0;
    win[1] = y0;
    win[2] = x1 + 1;
    win[3] = y1 + 1;
    return 0;
}

const char cli_exit_codes[] =
    "Exit codes (every command):\n"
    "  0    done\n"
    "  1    scene error: the scene's text, or a file it names (include, image, font,\n"
    "       data file), is wrong or missing (file:line:col: error: ...)\n"
    "  2    usage: a bad command line (nothing was read or written)\n"
    "  3    I/O: the scene file named on the command line cannot be read, or an\n"
    "       output cannot be written (checked before the scene is parsed)\n"
    "  130  interrupted (Ctrl-C); 143 terminated (SIGTERM): what was rendered is\n"
    "       kept as NAME.partial.EXT\n";

int cli_exit_status(pt_status st)
{
    switch (st) {
    case PT_OK: return CLI_EXIT_OK;
    case PT_ERR_IO: return CLI_EXIT_IO;
    case PT_ERR_USAGE: return CLI_EXIT_USAGE;
    default: return CLI_EXIT_SCENE;
    }
}

int cli_wants_help(int argc, char **argv)
{
    for (int i = 0; i < argc; i++)
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) return 1;
    return 0;
}

int cli_print_diags(const diag *d, int from, int errors_only)
{
    for (int i = from; i < diag_count(d); i++) {
        const diag_msg *m = diag_get(d, i);
        if (errors_only && m->severity != DIAG_ERROR) continue;
        char *s = diag_format(m);
        if (s) fprintf(stderr, "%s\n", s);
        free(s);
    }
    return diag_count(d);
}

int cli_check_output(const char *path, char *err, int errlen)
{
    struct stat st;
    if (!path || !*path) {
        snprintf(err, (size_t)errlen, "an output name is empty");
        return CLI_EXIT_IO;
    }
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) {
        snprintf(err, (size_t)errlen, "cannot write '%s': it is a directory", path);
        return CLI_EXIT_IO;
    }
    size_t n = strlen(path);
    char *dir = malloc(n + 2);
    if (!dir) {
        snprintf(err, (size_t)errlen, "out of memory");
        return CLI_EXIT_IO;
    }
    const char *slash = strrchr(path, '/');
    if (!slash) {
        strcpy(dir, ".");
    } else if (slash == path) {
        strcpy(dir, "/");
    } else {
        memcpy(dir, path, (size_t)(slash - path));
        dir[slash - path] = 0;
    }
    int rc = 0;
    if (stat(dir, &st) != 0) {
        snprintf(err, (size_t)errlen, "cannot write '%s': directory '%s' %s", path, dir,
                 errno == ENOENT ? "does not exist" : strerror(errno));
        rc = CLI_EXIT_IO;
    } else if (!S_ISDIR(st.st_mode)) {
        snprintf(err, (size_t)errlen, "cannot write '%s': '%s' is not a directory", path, dir);
        rc = CLI_EXIT_IO;
    } else {
        /* The writers create a temporary file in this directory and rename
         * it (io/img_io.h): probe exactly that, rather than trust access(2)
         * (read-only mounts, ACLs, root). */
        size_t pn = strlen(dir) + 64;
        char *probe = malloc(pn);
        int fd = -1;
        if (probe) {
            snprintf(probe, pn, "%s/.partray-probe-%ld", dir, (long)getpid());
            fd = open(probe, O_WRONLY | O_CREAT | O_EXCL, 0600);
        }
        if (fd < 0) {
            snprintf(err, (size_t)errlen, "cannot write '%s': cannot create a file in '%s': %s", path, dir,
                     probe ? strerror(errno) : "out of memory");
            rc = CLI_EXIT_IO;
        } else {
            close(fd);
            unlink(probe);
        }
        free(probe);
    }
    free(dir);
    return rc;
}

const char cli_parse_help[] =
    "usage: partray parse SCENE.pov [options]\n"
    "Parses the scene and prints a summary (objects, lights, triangles, what is not\n"
    "modelled) or the first error with its location and include/macro chain.\n"
    "  -D NAME=VALUE                 declare NAME before the scene is read (POV-Ray's Declare=)\n"
    "  -L DIR, +LDIR                 add DIR to the include path\n"
    "  --clock V, +KV                the clock of a still\n"
    "  +KFIn +KFFn +KIv +KFv +KC     an animation's frames and clocks; --frame N (+SFn +EFn) picks one\n"
    "  --max-loop N --max-include-depth N --max-macro-depth N --max-tokens N\n"
    "  --max-memory MIB --max-string BYTES --max-array N --max-image-pixels N\n"
    "                                the parser's limits (README: Reliability)\n"
    "  -q, --quiet                   errors only\n";

const char cli_render_help[] =
    "usage: partray render SCENE.pov [options]      (also: partray SCENE.pov +W640 +H480 ...)\n"
    "Renders SCENE.pov. Without -o (or +O) it writes SCENE.png in the current directory;\n"
    "without a size, 320x240 (POV-Ray's default). Both are stated when used.\n"
    "\n"
    "Output\n"
    "  -o OUT, --output OUT, +OOUT\n"
    "                         output file, .exr (scene-linear), .png (sRGB or an OCIO view),\n"
    "                         .pfm (linear float); repeat for several outputs of one render.\n"
    "                         +O without an extension takes the +F type's (POV-Ray)\n"
    "  +FN[n] +FE +FS         output type of +O: PNG (n bits a colour, above 8: 16-bit PNG),\n"
    "                         OpenEXR, the system's (PNG); Targa, PPM, BMP, JPEG, HDR refused\n"
    "  +UA                    alpha channel (PNG RGBA straight, EXR A associated): each\n"
    "                         pixel's coverage; the background is clear unless a 3.7\n"
    "                         scene declares an opaque background{}\n"
    "  --float                32-bit EXR (default half)\n"
    "  --exr-compression none|zip|piz    --png16   16-bit PNG\n"
    "  --stats FILE.json      stage times, ray counts, what was built\n"
    "\n"
    "Image\n"
    "  --size WxH, +Wn +Hn    image size (at most 65536 a side, 2^28 pixels)\n"
    "  +A[t], -A              adaptive antialiasing, threshold t (default 0.3); +Rn its depth (1-9);\n"
    "  --aa-threshold T       the threshold alone (INI Antialias_Threshold)\n"
    "  +Qn                    POV-Ray's quality 0-11 (default 9): 0-1 pigment colour only,\n"
    "                         2-3 no shadows, 4 shadows (area lights as points), 5 area\n"
    "                         lights, 6-7 refraction, 8 reflection and normals, 9-11 media\n"
    "                         and radiosity (10, 11 are 9); quick colours are not modelled\n"
    "  --spp N                samples per pixel: fixed supersampling (default 1: none);\n"
    "                         path 1; pmfg eye samples (default 64); vpl (default 16)\n"
    "  --seed N               random seed (renders are repeatable for a seed)\n"
    "  --threads N, +WTn      worker threads (default: every CPU)\n"
    "\n"
    "Global illumination\n"
    "  --gi MODE              none (direct light + Whitted, POV-Ray's model), particle,\n"
    "                         path (path tracer), pmfg (photon map + final gather), detp, vpl, links;\n"
    "                         default: particle when the scene has radiosity{}, else none\n"
    "  --particles N --nb N   particle: particles, bounces (links: gathering sweeps)\n"
    "  --gi-quality Q         particle: Q times the particles the scene's radiosity{} asks for\n"
    "                         (default 1; 0.5 faster and coarser, 2 or 4 slower and closer to converged)\n"
    "  --cl-device NAME --cl-max-memory MIB    particle: OpenCL device and its memory\n"
    "  --gi-cache FILE        particle: read the geometry stage from FILE when it exists (refused\n"
    "                         when made for another scene or settings), else compute and save it\n"
    "  --max-depth N          path: vertices per path\n"
    "  --fg-rays N --photons N    pmfg: final-gather rays per pixel, photon paths\n"
    "  --gi detp [--photons N] [--detp-radius R] [--detp-full]\n"
    "                         incremental photon paths across an animation's frames, fixed-radius\n"
    "                         estimate (docs/motion.md); --detp-full recomputes every frame\n"
    "  --gi vpl [--vpls N] [--nb N] [--vpl-cut minmax|full|brute] [--vpl-adaptive on|off]\n"
    "                         VPL reflectance filtering (glossy interreflection, docs/gi.md): VPL count\n"
    "                         (16384), bounces at the VPLs (1), the cut walked per pixel, adaptive sampling\n"
    "  --photon-scale F       none, particle: F times the photons the scene's photons{} asks for\n"
    "                         (caustic layer, docs/caustics.md; default 1)\n"
    "  --photon-roulette      none, particle: end photons by seed 002's Russian roulette instead of\n"
    "                         POV-Ray's weights (same expected light, noisier; docs/caustics.md)\n"
    "\n"
    "Colour and light (docs/guide.md, docs/units.md)\n"
    "  --display NAME --view NAME --look NAME --exposure STOPS --working-space NAME\n"
    "  --ocio-config FILE     OCIO display/view for PNG (default: the shipped config)\n"
    "  --false-color OUT.png  false-colour image of luminance or illuminance\n"
    "  --false-color-range LO,HI   --false-color-quantity luminance|illuminance\n"
    "  --aovs LIST            EXR layers: direct,indirect,albedo,normal,depth,illuminance\n"
    "  --units m|cm|mm|ft|METRES  scene units: lights in photometric units\n"
    "\n"
    "Scene\n"
    "  -D NAME=VALUE          declare NAME before the scene is read\n"
    "  -L DIR, +LDIR          include path (POV-Ray's include directory is on it)\n"
    "  +IFILE                 the scene file\n"
    "  --clock V, +KV         the clock of a still\n"
    "  +KFIn +KFFn +KIv +KFv +KC   an animation: every frame in one run, named as POV-Ray names them\n"
    "  +SFn +EFn, --frame N   a subset of its frames, or one\n"
    "  +SC +EC +SR +ER        a render window (pixels or fractions); partray merge joins the tiles\n"
    "  FILE.ini, Key=value    POV-Ray's INI files and options (partray render anim.ini)\n"
    "  --max-loop N --max-include-depth N --max-macro-depth N --max-tokens N --max-memory MIB\n"
    "  --max-string BYTES --max-array N --max-image-pixels N    limits (README: Reliability)\n"
    "\n"
    "Messages\n"
    "  -q, --quiet            no progress and no summary: errors only\n"
    "  A progress bar per stage (parse, accel, GI stages, render) is redrawn on a\n"
    "  terminal; elsewhere a plain line every few seconds. The scene's #debug and\n"
    "  #warning text appears as the parse produces it.\n"
    "  POV-Ray switches about its own display and files (+D -D +P +V +X +GA ...) are\n"
    "  accepted and ignored.\n"
    "\n";
