/* anim.h - the frames of an animation as POV-Ray 3.7 runs them (initial and
 * final frame and clock, cyclic, subset), the language values of each frame
 * and the numbered output names. Used by every command that renders frames
 * (render, farm). */
#ifndef PT_ANIM_H
#define PT_ANIM_H
#include "sdl.h"

typedef struct {
    int animated;                /* 0: a still (no +KFI/+KFF, or frames 1..1) */
    int initial_frame, final_frame; /* as given, final_frame >= initial_frame */
    double initial_clock, final_clock;
    int cyclic;
    int first, last;             /* the frames rendered (the subset) */
    int digits;                  /* width of the numbers in output names */
} anim_plan;

/* The plan for +KFI kfi +KFF kff +KI ki +KF kf [+KC] [+SF sf] [+EF ef];
 * kfi_given/kff_given say which of the first two were given, sf/ef < 0
 * when not given (a value in (0,1) is a fraction of the frames). Returns 0,
 * or -1 with a message in err. */
int anim_plan_make(anim_plan *p, int kfi, int kfi_given, int kff, int kff_given, double ki, double kf, int cyclic,
                   double sf, double ef, char *err, int errlen);
/* clock, clock_delta, frame_number... of `frame` into so (a still: left as
 * sdl_default_options or sdl_set_still_clock made them). */
void anim_frame_options(const anim_plan *p, int frame, sdl_options *so);
/* The file name POV-Ray gives frame `frame` of output `path`: the stem,
 * the frame number zero-padded to `digits`, the extension (digits 0: path
 * unchanged). malloc'd. */
char *anim_output_name(const char *path, int frame, int digits);

#endif
