/* sdl.h - POV-Ray 3.7 scene description language -> scene IR (core/scene.h).
 * The parser builds IR only; it never creates render objects. */
#ifndef PT_SDL_H
#define PT_SDL_H
#include "diag.h"
#include "progress.h"
#include "scene.h"

typedef struct {
    const char *const *lib_paths; /* extra include directories (-L), searched in order */
    int nlib_paths;
    int no_default_lib;           /* 1: do not add /usr/share/povray-3.7/include */
    const char *const *defines;   /* "NAME=VALUE" (-D): declared before parsing; VALUE a float or a string */
    int ndefines;
    /* Animation values as POV-Ray 3.7's front end sets them: `clock`,
     * `clock_on`, `clock_delta`, `frame_number`, `initial_frame`,
     * `final_frame`, `initial_clock`, `final_clock`. sdl_default_options
     * gives a still without +K (all 0); sdl_set_still_clock and
     * sdl_set_frame fill them for +K and for a frame of an animation. */
    double clock;
    int clock_on;
    double clock_delta, initial_clock, final_clock;
    int frame_number, initial_frame, final_frame;
    int image_width, image_height;/* values of image_width/image_height */
    long max_loop_iterations;     /* per #while/#for loop, 0 = default (10,000,000) */
    int max_include_depth;        /* 0 = default (64) */
    int max_macro_depth;          /* 0 = default (256) */
    /* Work and memory limits (0 = default); hitting one is a located
     * PT_ERR_LIMIT error. */
    long long max_tokens;         /* tokens read in all, loop repeats, macro bodies and
                                     skipped branches included (default 10^10) */
    long long max_memory;         /* bytes the scene may take while parsing, meshes being
                                     built included (default: half the physical memory) */
    long max_string_length;       /* bytes in one string value (default 1 MiB) */
    long long max_array_elements; /* elements in one array (default 10^8) */
    long long max_image_pixels;   /* pixels in one image file read (image_map, height_field;
                                     default and upper bound 2^28) */
    const char *write_dir;        /* NULL: #fopen ... write/append writes beside the scene
                                     (scene or working directory only); else every
                                     written file goes into this directory */
    const struct func_env *func_env; /* evaluators for pigment/pattern functions, noise and
                                     vturbulence at parse time (core/func.h); NULL: such
                                     calls are located PT_ERR_UNSUPPORTED errors */
    int threads;                  /* parse-time work split over threads (a height_field
                                     function's rows); 0: the machine's cores */
    progress *progress;           /* stage "parse": bytes of the scene file read (its
                                     position outside includes and macro bodies); NULL: none */
    /* Out (NULL = not wanted): set to 1 when a value that changes from
     * frame to frame (clock, frame_number, now) was read anywhere but
     * inside a camera{} or light_source{} block, else 0. With 0 the scene
     * apart from its camera and lights is the same in every frame of the
     * animation (same files, same options): what an animation's renders
     * may keep from frame to frame (GI reused across frames). */
    int *frame_dependent;
} sdl_options;

void sdl_default_options(sdl_options *o);
/* A still rendered with +K<clock>: clock = v, clock_on = 1, the frame
 * values 0. */
void sdl_set_still_clock(sdl_options *o, double clock);
/* Frame `frame` of the animation +KFI<initial_frame> +KFF<final_frame>
 * +KI<initial_clock> +KF<final_clock> [+KC]: clock_delta = (KF - KI) /
 * (KFF - KFI), or / (KFF - KFI + 1) and final_frame = KFF + 1 when cyclic;
 * clock = KI + (frame - KFI) * clock_delta (as povray 3.7.0 computes it,
 * tests/test_sdl_lang.c). A single frame 1..1 is a still, as in POV-Ray; any
 * other single frame gets clock = KI (POV-Ray divides by zero there).
 * Returns 0, or -1 (nothing changed) when frame is outside KFI..KFF or
 * KFF < KFI. */
int sdl_set_frame(sdl_options *o, int initial_frame, int final_frame, double initial_clock, double final_clock, int cyclic,
                  int frame);

/* Parse a file. On success *out holds a new scene (caller frees with
 * scene_free). On error, messages with locations and the include/macro chain
 * are in `d`, *out is NULL and the status says why (PT_ERR_SYNTAX, PT_ERR_LIMIT...;
 * PT_ERR_IO only when the scene file itself cannot be read: a file the scene
 * names that is missing is PT_ERR_SYNTAX, a scene error). Warnings (e.g. unsupported features) go to `d` too. */
pt_status sdl_parse_file(const char *path, const sdl_options *opt, scene **out, diag *d);
/* Same, from a string in memory; `name` is used in locations. */
pt_status sdl_parse_string(const char *name, const char *text, const sdl_options *opt, scene **out, diag *d);

#endif
