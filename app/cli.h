/* cli.h - command-line parsing for `partray render` (GNU-style and POV-Ray
 * style options), kept apart from main.c so it can be unit-tested. */
#ifndef PT_CLI_H
#define PT_CLI_H
#include <stdint.h>
#include "anim.h"
#include "sdl.h"

#define CLI_MAX_LIST 64

/* Exit codes of every partray command: the one list (README's "Exit codes"
 * and `partray --help` print cli_exit_codes). A file the scene names
 * (include, image, font, data file) that cannot be read is a scene error
 * (1) like any other; 3 is for the files the command line names: the scene
 * file itself, outputs, stats. */
enum {
    CLI_EXIT_OK = 0,
    CLI_EXIT_SCENE = 1,
    CLI_EXIT_USAGE = 2,
    CLI_EXIT_IO = 3,
    CLI_EXIT_INTERRUPTED = 130, /* 128 + SIGINT */
    CLI_EXIT_TERMINATED = 143   /* 128 + SIGTERM */
};
extern const char cli_exit_codes[];
/* The exit code for a status: PT_OK 0, PT_ERR_IO 3, PT_ERR_USAGE 2, else 1. */
int cli_exit_status(pt_status st);
/* 1 when argv holds --help or -h (a command then prints its help on stdout
 * and exits 0, whatever else is on the line). */
int cli_wants_help(int argc, char **argv);
/* Whether `path` can be written, checked before any work is done: its
 * directory exists and takes a new file (a probe file is created there and
 * removed), and the path is not a directory. Returns 0, or writes why into
 * err and returns CLI_EXIT_IO. */
int cli_check_output(const char *path, char *err, int errlen);
/* Prints d's messages from index `from` on to stderr, one a line as
 * diag_format writes them (errors_only: the errors alone); returns
 * diag_count(d), the `from` of the next call. */
int cli_print_diags(const diag *d, int from, int errors_only);
/* Help texts: `partray render --help`, `partray parse --help`. */
extern const char cli_render_help[];
extern const char cli_parse_help[];

typedef struct {
    const char *scene;
    const char *outputs[8];
    int noutputs;
    int width, height;      /* 0 = default (POV-Ray's 320x240 unless the scene says) */
    const char *gi;         /* NULL = from the scene */
    int spp;                /* 0 = not given: the mode's default (render_gi_opts.spp) */
    int threads;
    uint64_t seed;
    const char *stats;
    const char *defines[CLI_MAX_LIST];
    int ndefines;
    const char *libs[CLI_MAX_LIST];
    int nlibs;
    int antialias;          /* 0 off, 1 +A adaptive */
    double aa_threshold;
    int aa_depth;
    double aa_jitter;       /* +J amount, default 1; -J: 0 */
    int exr_float;
    int quiet;
    long max_loop;
    /* colour management (io/img_ocio.h) */
    const char *display, *view, *look, *working_space, *ocio_config;
    double exposure;
    int png16;
    int exr_compression;    /* -1 = default (zip) */
    const char *false_color;/* luminance false-colour PNG */
    double fc_lo, fc_hi;    /* false-colour range, 0 = automatic */
    int max_include_depth, max_macro_depth;
    /* parser work/memory limits (sdl_options), 0 = the parser's default */
    long long max_tokens, max_memory_mib, max_array;
    long long max_image_pixels; /* images read and the image rendered; 0 = default (2^28) */
    long max_string;
    /* GI settings (render_gi.h); 0 = the mode's default */
    long particles;
    double photon_scale;    /* --photon-scale: the caustic layer's photons times this (0 = 1) */
    int photon_roulette;    /* --photon-roulette: the caustic layer's photons end by Russian roulette */
    double gi_quality;      /* --gi-quality: scales the GI method's effort from the scene's settings (0 = 1) */
    int bounces, fg_rays, max_depth;
    long photons;
    double detp_radius;     /* --detp-radius: DETP disc radius, world units (0 = default) */
    int detp_full;          /* --detp-full: every frame traces and estimates everything anew */
    long vpls;              /* --vpls: VPL count (render_vpl.h; 0 = default) */
    int vpl_cut;            /* --vpl-cut minmax|full|brute: RENDER_VPL_* */
    int vpl_adaptive;       /* --vpl-adaptive on|off: 1 on (default), 2 off */
    const char *cl_device;  /* particle GI: OpenCL device (NULL/"auto", "c", "P:D" or part of a name) */
    long long cl_max_memory_mib; /* particle GI: OpenCL device memory it may use (0 = the device's) */
    const char *gi_cache;   /* --gi-cache FILE: particle GI's geometry stage read from FILE when it
                               exists, else computed and saved there (gi_particle_save) */
    /* lighting studies (app/lighting_study.h, docs/units.md) */
    const char *aovs;       /* --aovs LIST: extra EXR layers */
    const char *units;      /* --units m|cm|mm|ft|...|METRES: photometric lights */
    const char *fc_quantity;/* --false-color-quantity luminance|illuminance */
    /* clock and animation (POV-Ray 3.7: +K, +KFI, +KFF, +KI, +KF, +KC, +SF, +EF) */
    double clock;           /* --clock V / +KV: a still's clock */
    int clock_given;
    int kfi, kff;           /* initial/final frame (default 1, 1) */
    int kfi_given, kff_given;
    double ki, kf;          /* initial/final clock (default 0, 1) */
    int cyclic;
    double sf, ef;          /* subset start/end frame (--frame N sets both); in (0,1): a fraction */
    int sf_given, ef_given;
    /* render window (POV-Ray 3.7 +SC +EC +SR +ER): a value in [0,1) (start)
     * or [0,1] (end) is a fraction of the width or height, others a 1-based
     * pixel (cli_window) */
    double sc, ec, sr, er;
    int sc_given, ec_given, sr_given, er_given;
    char format;            /* +F: 'N' PNG, 'E' EXR, 0 = from the output name */
    int quality;            /* +Qn: POV-Ray's quality 0..9 (default 9; 10 and 11 are 9, as POV-Ray clips) */
    int quality_given;
    int alpha;              /* +UA: an alpha channel in PNG and EXR outputs (shade_alpha) */
} cli_render;

/* The render window the options ask for, as pixels [x0,x1) x [y0,y1) of a
 * w x h image (POV-Ray 3.7 backend/scene/view.cpp: start v in [0,1) ->
 * int(w v), else int(v) - 1; end v in [0,1] -> int(w v) - 1, else
 * int(v) - 1, inclusive). Returns 0 (the whole image when no bound is
 * given), or 2 with a message when the window is empty or outside. */
int cli_window(const cli_render *o, int w, int h, int win[4], char *err, int errlen);

/* The frames the options ask for (anim.h): a still, or the frames of an
 * animation (+SF/+EF or --frame choose a subset). Returns 0, or 2 with a
 * message. */
int cli_frames(const cli_render *o, anim_plan *p, char *err, int errlen);
/* The parser's options for frame `frame` of plan p (a still: +K's clock). */
void cli_frame_options(const cli_render *o, const anim_plan *p, int frame, sdl_options *so);

/* Parses argv (after the subcommand). Returns 0 on success, otherwise writes
 * a message into err and returns 2 (usage). */
int cli_parse_render(int argc, char **argv, cli_render *o, char *err, int errlen);

#endif
