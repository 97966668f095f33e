/* anim.c - an animation's frames as POV-Ray 3.7's front end computes them
 * (source/frontend/animationprocessing.cpp, AnimationProcessing):
 *  - final frame at least the initial frame; +KC counts one frame more for
 *    the clock (the last frame is not the first again) and renders KFI..KFF;
 *  - a subset bound of 0 or >= 1 is a frame number, one in (0,1) a fraction
 *    of the frames: int((final - initial + 1) * f); the start is at least
 *    the initial frame, the end between the start and the final frame;
 *  - output numbers are zero-padded to the digits of the final frame (the
 *    one +KC adds included), after the output's stem
 *    (imageprocessing.cpp GetOutputFilename).
 * The language values come from sdl_set_frame (parser), one implementation
 * for `render`, `parse` and `farm`. */
#include "anim.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* POV-Ray keeps the subset bounds as POVMSFloat (32-bit float). */
static int subset_bound(double v, int initial, int final)
{
    v = (float)v;
    if (v < 0) v = 0;
    if (v == 0.0 || v >= 1.0) return v > 2147483647.0 ? 2147483647 : (int)v;
    return (int)((final - initial + 1) * v);
}

int anim_plan_make(anim_plan *p, int kfi, int kfi_given, int kff, int kff_given, double ki, double kf, int cyclic,
                   double sf, double ef, char *err, int errlen)
{
    memset(p, 0, sizeof *p);
    if (kfi_given && !kff_given && kff < kfi) kff = kfi; /* +KFI3 alone: frames 3..3 */
    p->animated = (kfi_given || kff_given) && !(kfi == 1 && kff == 1 && !cyclic);
    p->initial_frame = kfi;
    p->final_frame = kff;
    p->initial_clock = ki;
    p->final_clock = kf;
    p->cyclic = cyclic;
    if (!p->animated) {
        if (sf >= 0 || ef >= 0) {
            snprintf(err, (size_t)errlen, "+SF/+EF/--frame need an animation (+KFI and +KFF)");
            return -1;
        }
        p->first = p->last = 0;
        return 0;
    }
    if (kfi < 0 || kff < kfi) {
        snprintf(err, (size_t)errlen, "the animation's frames %d..%d are not a range of frames from 0 up", kfi, kff);
        return -1;
    }
    int final = kff + (cyclic ? 1 : 0); /* the clock's final frame */
    int first = sf >= 0 ? subset_bound(sf, kfi, final) : kfi;
    if (first < kfi) first = kfi;
    int last = ef >= 0 ? subset_bound(ef, kfi, final) : kff;
    if (ef >= 0 && last < first) last = first;
    if (first > kff || last > kff) {
        snprintf(err, (size_t)errlen, "frame %d is outside the animation's frames %d..%d", first > kff ? first : last,
                 kfi, kff);
        return -1;
    }
    p->first = first;
    p->last = last;
    p->digits = 1;
    for (int i = final; i >= 10; i /= 10) p->digits++;
    return 0;
}

void anim_frame_options(const anim_plan *p, int frame, sdl_options *so)
{
    if (!p->animated) return;
    sdl_set_frame(so, p->initial_frame, p->final_frame, p->initial_clock, p->final_clock, p->cyclic, frame);
}

char *anim_output_name(const char *path, int frame, int digits)
{
    size_t n = strlen(path);
    char *s = malloc(n + 32);
    if (!s) return NULL;
    if (digits <= 0) {
        memcpy(s, path, n + 1);
        return s;
    }
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    size_t stem = dot && (!slash || dot > slash) ? (size_t)(dot - path) : n;
    char num[24];
    snprintf(num, sizeof num, "%0*d", digits > 12 ? 12 : digits, frame);
    memcpy(s, path, stem);
    snprintf(s + stem, n + 32 - stem, "%s%s", num, path + stem);
    return s;
}
